//! The options W7 (k nearest) and W8 (sphere sweeps) share, and the timing
//! loop both use: a static set built once into every structure, then batches
//! of queries timed round-robin.

use crate::run::{median, num, Clock};
use std::time::Duration;

/// Options of `proxima-bench w7` and `w8`.
#[derive(Clone, Debug)]
pub struct Args {
    /// Number of stored objects.
    pub n: usize,
    /// Queries per batch.
    pub queries: usize,
    /// Queries checked against the reference before timing (the first ones
    /// of the batch).
    pub check: usize,
    /// Repetitions of every batch (the median is reported).
    pub reps: usize,
    /// Seed of the set and the queries.
    pub seed: u64,
    /// Clock (the thread's CPU time by default).
    pub clock: Clock,
    /// JSON instead of the table.
    pub json: bool,
    /// Only these structures (all when empty; Proxima's reference index always
    /// runs, as the answers are checked against it).
    pub only: Vec<String>,
    /// W7: the `k` of each batch.
    pub ks: Vec<usize>,
    /// W7: the sets (`points`, `spheres`).
    pub sets: Vec<String>,
}

impl Args {
    /// Whether the structure called `name` runs.
    pub fn wants(&self, name: &str) -> bool {
        self.only.is_empty() || self.only.iter().any(|o| o.eq_ignore_ascii_case(name))
    }
}

fn list(s: &str) -> Vec<String> {
    s.split(',')
        .filter(|s| !s.is_empty())
        .map(String::from)
        .collect()
}

/// Parses the arguments after `w7` (`knn` true: `--k` and `--set` allowed) or
/// `w8`, starting from `queries` queries per batch.
pub fn parse(
    mut it: impl Iterator<Item = String>,
    knn: bool,
    queries: usize,
) -> Result<Args, String> {
    let mut a = Args {
        n: 100_000,
        queries,
        check: 1000,
        reps: 5,
        seed: 1,
        clock: Clock::ThreadCpu,
        json: false,
        only: Vec::new(),
        ks: vec![1, 10, 100],
        sets: vec!["points".into(), "spheres".into()],
    };
    while let Some(flag) = it.next() {
        let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        match flag.as_str() {
            "--n" => a.n = num(&value("--n")?)?,
            "--queries" => a.queries = num(&value("--queries")?)?,
            "--check" => a.check = num(&value("--check")?)?,
            "--reps" => a.reps = num(&value("--reps")?)?,
            "--seed" => a.seed = num(&value("--seed")?)?,
            "--clock" => a.clock = Clock::parse(&value("--clock")?)?,
            "--json" => a.json = true,
            "--only" => a.only = list(&value("--only")?),
            "--k" if knn => {
                a.ks = list(&value("--k")?)
                    .iter()
                    .map(|k| num(k))
                    .collect::<Result<_, _>>()?
            }
            "--set" if knn => {
                a.sets = list(&value("--set")?);
                if let Some(s) = a.sets.iter().find(|s| *s != "points" && *s != "spheres") {
                    return Err(format!("--set takes points and/or spheres, not {s:?}"));
                }
            }
            "-h" | "--help" => return Err(String::new()),
            other => return Err(format!("unknown argument {other:?}")),
        }
    }
    if a.n == 0 || a.queries == 0 || a.reps == 0 || a.ks.is_empty() || a.sets.is_empty() {
        return Err("--n, --queries, --reps, --k and --set must not be zero or empty".into());
    }
    Ok(a)
}

/// Times `batch(k, i)` — batch `k` on structure `i` — `reps` times each,
/// round-robin (every round runs every batch on every structure once, so load
/// from elsewhere hits them alike), skipping the pairs `runs` rejects. Returns
/// the median per `[k][i]`, `None` where skipped.
pub fn time_round_robin(
    clock: Clock,
    reps: usize,
    batches: usize,
    structures: usize,
    runs: impl Fn(usize, usize) -> bool,
    mut batch: impl FnMut(usize, usize),
) -> Vec<Vec<Option<Duration>>> {
    let mut times = vec![vec![Vec::with_capacity(reps); structures]; batches];
    for round in 0..reps {
        eprintln!("round {} of {reps} ...", round + 1);
        for (k, row) in times.iter_mut().enumerate() {
            for (i, t) in row.iter_mut().enumerate() {
                if runs(k, i) {
                    t.push(clock.time(|| batch(k, i)).1);
                }
            }
        }
    }
    times
        .iter()
        .map(|row| {
            row.iter()
                .map(|t| (!t.is_empty()).then(|| median(t)))
                .collect()
        })
        .collect()
}

/// Microseconds per query of a batch of `n` that took `d`.
pub fn us_per_query(d: Duration, n: usize) -> f64 {
    d.as_secs_f64() * 1e6 / n.max(1) as f64
}

/// `1.23x`, or `-`.
pub fn fmt_ratio(x: Option<f64>) -> String {
    x.map_or("-".into(), |x| format!("{x:.2}x"))
}

/// A JSON number, or `null`.
pub fn json_num(x: Option<f64>) -> String {
    x.map_or("null".into(), |v| format!("{v:.6}"))
}

/// The command of W7 (`knn`) or W8: parses the arguments (exit 2 with `usage`
/// on bad ones), runs `run`, which returns what to print and the
/// disagreements, prints them (the disagreements on stderr), and exits 1 if
/// there were any, 0 otherwise.
pub fn main(
    args: impl Iterator<Item = String>,
    knn: bool,
    queries: usize,
    usage: &str,
    run: impl FnOnce(&Args) -> (String, Vec<String>),
) -> std::process::ExitCode {
    use std::process::ExitCode;
    let a = match parse(args, knn, queries) {
        Ok(a) => a,
        Err(e) => {
            if !e.is_empty() {
                eprintln!("error: {e}");
            }
            eprintln!("{usage}");
            return ExitCode::from(2);
        }
    };
    let (out, errors) = run(&a);
    print!("{out}");
    for e in &errors {
        eprintln!("{e}");
    }
    if errors.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

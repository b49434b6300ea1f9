//! The collision world's workloads (issue 13) [sources: world, world-trace]:
//! `proxima-bench world [--scenes A,B] [--n N] [--arms K] [--frames F] [--seed S]
//! [--reps R] [--first] [--cut-limit C] [--no-coherence] [--out DIR] [--no-fcl]
//! [--json]`.
//!
//! Each scene ([`scenes::SCENES`]: tumble, arm, deep, churn; every object moving
//! or a tenth) is generated, written as a world trace under `--out` (default
//! `target/bench-world`), run on Proxima's [`World`](proxima::world::World)
//! (default configuration: lazily built loose k-d tree, coherence on, k-DOP18
//! trees) and, in the same run, on FCL 0.7 through the `fcl_world` harness with
//! both of its broad-phase update modes (`update()` of every object, or of the
//! moved ones), the faster being the denominator. A frame is the `pose` lines
//! since the previous `contacts` plus that `contacts`, for both; times are wall
//! clock medians over every frame of `--reps` runs (run on a quiet machine). The
//! answers (`contacts P T` per frame) are compared and the frames that differ
//! are counted and listed: Proxima decides a mesh pair exactly on `f32`
//! vertices moved into the other mesh's frame, FCL in `f64` on its own
//! transforms, so the two may part on triangle pairs that touch within rounding
//! (`proxima world TRACE --check` confirms Proxima's answers against its
//! brute-force world). A failing harness makes the exit status 1.

pub mod fcl;
pub mod ours;
pub mod scenes;

use crate::run::median;
use proxima::narrow::Kdop18;
use proxima::world::WorldConfig;
use scenes::{Scene, Sizes, SCENES};
use std::path::PathBuf;
use std::process::ExitCode;

const USAGE: &str = "usage: proxima-bench world [--scenes NAME,NAME] [--n N] [--arms K] [--frames F] [--seed S] [--reps R] [--first] [--cut-limit C] [--no-coherence] [--out DIR] [--no-fcl] [--json]";

struct Args {
    scenes: Vec<String>,
    sizes: Sizes,
    seed: u64,
    reps: usize,
    first: bool,
    /// The world's configuration (`--cut-limit`, `--no-coherence`: what
    /// coherence saves is measured by turning it off or changing it).
    config: WorldConfig,
    out: PathBuf,
    fcl: bool,
    json: bool,
}

fn parse(mut it: impl Iterator<Item = String>) -> Result<Args, String> {
    let mut a = Args {
        scenes: SCENES.iter().map(|s| s.to_string()).collect(),
        sizes: Sizes {
            n: 300,
            arms: 10,
            frames: 60,
        },
        seed: 1,
        reps: 3,
        first: false,
        config: WorldConfig::default(),
        out: PathBuf::from(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../target/bench-world"
        )),
        fcl: true,
        json: false,
    };
    let num = |s: String| {
        s.replace('_', "")
            .parse::<u64>()
            .map_err(|_| format!("not a number: {s:?}"))
    };
    while let Some(flag) = it.next() {
        let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        match flag.as_str() {
            "--scenes" => {
                a.scenes = value("--scenes")?
                    .split(',')
                    .filter(|s| !s.is_empty())
                    .map(String::from)
                    .collect();
                if let Some(s) = a.scenes.iter().find(|s| !SCENES.contains(&s.as_str())) {
                    return Err(format!(
                        "unknown scene {s:?} (known: {})",
                        SCENES.join(", ")
                    ));
                }
            }
            "--n" => a.sizes.n = num(value("--n")?)? as usize,
            "--arms" => a.sizes.arms = num(value("--arms")?)? as usize,
            "--frames" => a.sizes.frames = num(value("--frames")?)? as usize,
            "--seed" => a.seed = num(value("--seed")?)?,
            "--reps" => a.reps = num(value("--reps")?)? as usize,
            "--first" => a.first = true,
            "--cut-limit" => a.config.cut_limit = num(value("--cut-limit")?)? as usize,
            "--no-coherence" => a.config.coherence = false,
            "--out" => a.out = PathBuf::from(value("--out")?),
            "--no-fcl" => a.fcl = false,
            "--json" => a.json = true,
            "-h" | "--help" => return Err(String::new()),
            o => return Err(format!("unknown argument {o:?}")),
        }
    }
    if a.sizes.n < 10 || a.sizes.arms == 0 || a.sizes.frames == 0 || a.reps == 0 {
        return Err("--n must be at least 10, --arms, --frames and --reps at least 1".into());
    }
    Ok(a)
}

/// One scene's row.
struct Row {
    scene: Scene,
    ours: ours::OursRun,
    fcl: Option<Result<fcl::FclRun, String>>,
}

impl Row {
    fn ours_us(&self) -> f64 {
        median(&self.ours.frames).as_secs_f64() * 1e6
    }
    /// Frames whose answers differ from FCL's, if FCL ran.
    fn differ(&self) -> Option<usize> {
        let f = self.fcl.as_ref()?.as_ref().ok()?;
        let n = self.ours.answers.len().max(f.answers.len());
        Some(
            (0..n)
                .filter(|&i| self.ours.answers.get(i) != f.answers.get(i))
                .count(),
        )
    }
}

/// Runs `proxima-bench world`.
pub fn main(args: impl Iterator<Item = String>) -> ExitCode {
    let a = match parse(args) {
        Ok(a) => a,
        Err(e) => {
            if !e.is_empty() {
                eprintln!("error: {e}");
            }
            eprintln!("{USAGE}");
            return ExitCode::from(2);
        }
    };
    match run(&a) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

fn run(a: &Args) -> Result<bool, String> {
    let bin = if a.fcl { fcl::harness() } else { None };
    if a.fcl && bin.is_none() {
        eprintln!("fcl_world not found (run scripts/peers.sh, or set PEERS_OUT): Proxima only");
    }
    std::fs::create_dir_all(&a.out).map_err(|e| format!("{}: {e}", a.out.display()))?;
    let mut rows = Vec::new();
    for name in &a.scenes {
        eprintln!("world {name} ...");
        let scene = scenes::generate(name, &a.out, a.sizes, a.seed)?;
        let trace = a.out.join(format!("{name}.trace"));
        std::fs::write(&trace, scene.trace()).map_err(|e| format!("{}: {e}", trace.display()))?;
        let ours = ours::run::<Kdop18>(&scene, a.config, a.first, a.reps)?;
        let fcl = bin.as_ref().map(|b| {
            let runs = ["all", "moved"]
                .iter()
                .map(|u| fcl::run(b, &trace, a.first, a.reps, u))
                .collect::<Result<Vec<_>, _>>()?;
            Ok(runs
                .into_iter()
                .min_by(|x, y| x.median_us.total_cmp(&y.median_us))
                .expect("two runs"))
        });
        rows.push(Row { scene, ours, fcl });
    }
    let ok = rows.iter().all(|r| r.differ().unwrap_or(0) == 0)
        && rows.iter().all(|r| !matches!(r.fcl, Some(Err(_))));
    if a.json {
        let json: Vec<_> = rows
            .iter()
            .map(|r| {
                let f = r.fcl.as_ref().and_then(|f| f.as_ref().ok());
                serde_json::json!({
                    "scene": r.scene.name,
                    "objects": r.scene.objects,
                    "moving_per_frame": r.scene.moving,
                    "frames": r.scene.frames(),
                    "ours_frame_us_median": r.ours_us(),
                    "ours_build_ms": r.ours.build.as_secs_f64() * 1e3,
                    "fcl_frame_us_median": f.map(|f| f.median_us),
                    "fcl_update": f.map(|f| f.update.clone()),
                    "frames_differing": r.differ(),
                    "pairs": r.ours.answers.iter().map(|x| x.0).sum::<usize>(),
                    "triangle_pairs": r.ours.answers.iter().map(|x| x.1).sum::<usize>(),
                    "narrow_pairs": r.ours.counters.narrow_pairs,
                    "coherent_pairs": r.ours.counters.coherent_pairs,
                    "cut_starts": r.ours.counters.cut_starts,
                    "nv": r.ours.counters.cost.nv,
                    "np": r.ours.counters.cost.np,
                    "nu": r.ours.counters.cost.nu,
                })
            })
            .collect();
        println!(
            "{}",
            serde_json::json!({
                "first": a.first,
                "reps": a.reps,
                "coherence": a.config.coherence,
                "cut_limit": a.config.cut_limit,
                "scenes": json,
            })
        );
        return Ok(ok);
    }
    println!(
        "world scenes{}: frame = poses since the last contacts + contacts; wall-clock medians over {} reps (quiet machine only)",
        if a.first { " (first contact)" } else { "" },
        a.reps
    );
    println!(
        "{:<11} {:>7} {:>8} {:>6} {:>9} {:>11} {:>11} {:>9} {:>7}  fcl mode",
        "scene",
        "objects",
        "moving/f",
        "frames",
        "pairs/f",
        "ours us/f",
        "fcl us/f",
        "ours/fcl",
        "differ",
    );
    for r in &rows {
        let frames = r.scene.frames().max(1);
        let pairs = r.ours.answers.iter().map(|x| x.0).sum::<usize>() as f64 / frames as f64;
        let (fcl_us, mode) = match &r.fcl {
            Some(Ok(f)) => (
                format!("{:.1}", f.median_us),
                format!("update {}", f.update),
            ),
            Some(Err(e)) => ("error".into(), e.clone()),
            None => ("-".into(), String::new()),
        };
        let ratio = match &r.fcl {
            Some(Ok(f)) if f.median_us > 0.0 => format!("{:.2}", r.ours_us() / f.median_us),
            _ => "-".into(),
        };
        println!(
            "{:<11} {:>7} {:>8.1} {:>6} {:>9.1} {:>11.1} {:>11} {:>9} {:>7}  {}",
            r.scene.name,
            r.scene.objects,
            r.scene.moving,
            frames,
            pairs,
            r.ours_us(),
            fcl_us,
            ratio,
            r.differ().map_or("-".into(), |d| d.to_string()),
            mode
        );
    }
    for r in &rows {
        if let Some(Ok(f)) = &r.fcl {
            let shown: Vec<String> = (0..r.ours.answers.len().max(f.answers.len()))
                .filter(|&i| r.ours.answers.get(i) != f.answers.get(i))
                .take(5)
                .map(|i| {
                    format!(
                        "frame {i}: ours {:?}, fcl {:?}",
                        r.ours.answers.get(i),
                        f.answers.get(i)
                    )
                })
                .collect();
            if !shown.is_empty() {
                println!("{} differs from FCL on {}", r.scene.name, shown.join("; "));
            }
        }
    }
    // The coherence target: a tenth moving costs at most a quarter of all moving.
    for base in ["tumble", "arm", "churn"] {
        let find = |v: &str| rows.iter().find(|r| r.scene.name == format!("{base}-{v}"));
        if let (Some(all), Some(ten)) = (find("all"), find("10")) {
            println!(
                "{base}: 10% moving / all moving = {:.2} (ours)",
                ten.ours_us() / all.ours_us().max(1e-9)
            );
        }
    }
    println!("traces: {}", a.out.display());
    Ok(ok)
}

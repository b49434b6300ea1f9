//! `proxima demo`, the main job and what `proxima` does without a command
//! [sources: cli]: a generated scene of moving spheres [sources: w1, w2, w3, w9]
//! through every broad-phase index, with a progress bar per index, a comparison
//! table and pictures.
//!
//! The scenes are the benchmarks' workloads, with their one motion model
//! ([`proxima_harness::workloads`]): `--scene uniform|flat|clustered|mixed` is
//! W1, W2, W3 or W9, so a demo run and a `proxima-bench` run of the same size and
//! seed see the same frames.
//!
//! A frame = update every sphere, then find all overlapping pairs. Every index
//! replays the same frames (the scene is regenerated from its seed for each
//! index, outside the timed sections, so memory stays O(n)). Brute force is
//! O(n²) per frame, so it finds pairs only on a few *sampled* frames, spread over
//! the run within a fixed budget of sphere tests; every other index's pair count
//! must equal it on those frames and equal each other on every frame, otherwise
//! the run fails with exit code 1.
//!
//! Then the world scene ([`crate::demo_world`]): a few hundred meshes tumbling
//! in a box, contacts, rays and culling every frame, checked against the
//! brute-force world on sampled frames.

use crate::demo_world;
use crate::draw::Canvas;
use crate::pictures::{self, Series};
use indicatif::{ProgressBar, ProgressStyle};
use proxima::broad::{AnyIndex, IndexKind, SpatialIndex};
use proxima_harness::indices::{self, BRUTE};
use proxima_harness::workloads::{Kind, Workload};
use std::io::IsTerminal;
use std::ops::ControlFlow;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// Number of spheres of the default scene.
pub const N: usize = 50_000;
/// Frames of the default scene.
pub const FRAMES: usize = 30;
/// Default scene seed.
pub const SEED: u64 = 1;
/// Sphere-pair tests brute force may spend over all its sampled frames: two
/// frames (the first and the last) of the default scene, where it used to check
/// three and took most of the default run.
const BRUTE_BUDGET: f64 = 2.6e9;
/// Largest accepted scene (the pictures and brute force stay bounded).
const MAX_OBJECTS: usize = 5_000_000;

/// The scene names `--scene` takes, in [`Kind::ALL`] order.
const SCENES: &str = "uniform, flat, clustered, mixed";

/// Parses `--scene` (a [`Kind::scene_name`]).
fn parse_scene(s: &str) -> Result<Kind, String> {
    Kind::from_scene_name(s).ok_or_else(|| format!("unknown scene '{s}' (known: {SCENES})"))
}

/// Options of `proxima demo` (also accepted by `proxima` without a command).
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Scene: uniform (W1, a cube), flat (W2, 1000 x 1000 x 10), clustered (W3)
    /// or mixed (W9, W1 with power-law radii from 0.25 to 16).
    #[arg(
        long,
        default_value = "uniform",
        value_name = "uniform|flat|clustered|mixed",
        value_parser = parse_scene
    )]
    pub scene: Kind,
    /// Number of spheres.
    #[arg(long, default_value_t = N, value_name = "N")]
    pub objects: usize,
    /// Number of frames (each: move every sphere, find all pairs).
    #[arg(long, default_value_t = FRAMES, value_name = "F")]
    pub frames: usize,
    /// Scene seed.
    #[arg(long, default_value_t = SEED, value_name = "S")]
    pub seed: u64,
    /// Index to run (brute force also runs, on sampled frames, to check it), or all.
    #[arg(long, default_value = "all", value_name = "NAME|all")]
    pub index: String,
    /// Print the results as one JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Write the pictures as SVG instead of PNG.
    #[arg(long)]
    pub svg: bool,
    /// Directory for the pictures (created if missing).
    #[arg(long, default_value = "proxima-out", value_name = "DIR")]
    pub out: PathBuf,
    /// Do not write pictures.
    #[arg(long)]
    pub no_pictures: bool,
    /// Meshes of the world scene (0: no world scene).
    #[arg(long, default_value_t = demo_world::OBJECTS, value_name = "N")]
    pub world_objects: usize,
    /// Frames of the world scene.
    #[arg(long, default_value_t = demo_world::FRAMES, value_name = "F")]
    pub world_frames: usize,
    /// Folder of the world scene's meshes (default: ../shared/data).
    #[arg(long, value_name = "DIR")]
    pub data: Option<PathBuf>,
}

impl Default for Args {
    fn default() -> Self {
        Args {
            scene: Kind::W1,
            objects: N,
            frames: FRAMES,
            seed: SEED,
            index: "all".into(),
            json: false,
            svg: false,
            out: PathBuf::from("proxima-out"),
            no_pictures: false,
            world_objects: demo_world::OBJECTS,
            world_frames: demo_world::FRAMES,
            data: None,
        }
    }
}

/// One index's figures.
#[derive(Clone, Debug)]
pub struct Row {
    /// Index name.
    pub name: &'static str,
    /// Time to insert the first frame into an empty index.
    pub build: Duration,
    /// Total update time over all frames.
    pub update: Duration,
    /// Total pair-finding time over the frames where pairs were searched.
    pub pairs: Duration,
    /// Per frame: the pairs found, `None` where this index did not search.
    pub pair_counts: Vec<Option<usize>>,
    /// Per frame: update + pair time in ms, `None` where pairs were not searched.
    pub frame_ms: Vec<Option<f64>>,
    /// `memory_bytes()` after the last frame.
    pub bytes: usize,
}

impl Row {
    /// Frames where this index searched pairs.
    pub fn searched(&self) -> usize {
        self.pair_counts.iter().flatten().count()
    }
    /// Mean update time per frame, ms.
    pub fn update_ms(&self) -> f64 {
        self.update.as_secs_f64() * 1e3 / self.pair_counts.len().max(1) as f64
    }
    /// Mean pair-search time per searched frame, ms.
    pub fn pairs_ms(&self) -> f64 {
        self.pairs.as_secs_f64() * 1e3 / self.searched().max(1) as f64
    }
}

/// Runs a scene through one index: build from frame 0, then frames `1..=frames`,
/// searching pairs on the frames where `search[f - 1]` is true.
struct Frames<'a> {
    kind: Kind,
    n: usize,
    seed: u64,
    search: &'a [bool],
    bar: &'a ProgressBar,
}

impl Frames<'_> {
    /// Runs the scene on the empty `index` called `name`.
    fn run(&self, name: &'static str, mut index: AnyIndex<u64>) -> proxima::Result<Row> {
        let mut w = Workload::new(self.kind, self.n, self.seed);
        let start = Instant::now();
        let handles = w
            .spheres
            .iter()
            .enumerate()
            .map(|(i, s)| index.insert(*s, i as u64))
            .collect::<proxima::Result<Vec<_>>>()?;
        let build = start.elapsed();
        let (mut update, mut pairs) = (Duration::ZERO, Duration::ZERO);
        let mut pair_counts = Vec::with_capacity(self.search.len());
        let mut frame_ms = Vec::with_capacity(self.search.len());
        for &search in self.search {
            w.step();
            let start = Instant::now();
            for (h, s) in handles.iter().zip(&w.spheres) {
                index.update(*h, *s)?;
            }
            let up = start.elapsed();
            update += up;
            if search {
                let start = Instant::now();
                let mut n = 0usize;
                let _ = index.for_each_pair(|_, _, _, _| {
                    n += 1;
                    ControlFlow::Continue(())
                });
                let p = start.elapsed();
                pairs += p;
                pair_counts.push(Some(n));
                frame_ms.push(Some((up + p).as_secs_f64() * 1e3));
            } else {
                pair_counts.push(None);
                frame_ms.push(None);
            }
            self.bar.inc(1);
        }
        Ok(Row {
            name,
            build,
            update,
            pairs,
            pair_counts,
            frame_ms,
            bytes: index.memory_bytes(),
        })
    }
}

/// How many frames brute force can search at `n` spheres within its budget (at
/// least one: the cross-check needs it; large scenes then just take longer).
fn brute_frames(n: usize, frames: usize) -> usize {
    let per_frame = (n as f64) * (n as f64 - 1.0) / 2.0;
    ((BRUTE_BUDGET / per_frame.max(1.0)) as usize).clamp(1, frames.max(1))
}

/// `k` frames spread evenly over `1..=frames`, always including the first and the
/// last (as a mask over the frames).
pub(crate) fn sample_frames(frames: usize, k: usize) -> Vec<bool> {
    let mut mask = vec![false; frames];
    if frames == 0 {
        return mask;
    }
    let k = k.clamp(1, frames);
    for i in 0..k {
        let f = if k == 1 {
            0
        } else {
            (i * (frames - 1) + (k - 1) / 2) / (k - 1)
        };
        mask[f] = true;
    }
    mask
}

/// The first frame (1-based) where two rows that both searched it report different
/// pair counts: `(frame, row a, row b)`.
pub fn pair_mismatch(rows: &[Row]) -> Option<(usize, &Row, &Row)> {
    let frames = rows.iter().map(|r| r.pair_counts.len()).max().unwrap_or(0);
    (0..frames).find_map(|f| {
        let count = |r: &Row| r.pair_counts.get(f).copied().flatten();
        let mut ran = rows.iter().filter(|r| count(r).is_some());
        let first = ran.next()?;
        ran.find(|r| count(r) != count(first))
            .map(|r| (f + 1, first, r))
    })
}

/// Runs the demo; returns the exit code (0 ok, 1 an index failed or disagreed,
/// 2 bad options or an unwritable output).
pub fn main(args: &Args) -> ExitCode {
    match run(args) {
        Ok(code) => code,
        Err(msg) => {
            eprintln!("proxima demo: {msg}");
            ExitCode::from(2)
        }
    }
}

fn run(args: &Args) -> Result<ExitCode, String> {
    if args.objects == 0 || args.objects > MAX_OBJECTS {
        return Err(format!(
            "--objects must be in 1..={MAX_OBJECTS}, got {}",
            args.objects
        ));
    }
    if args.frames == 0 || args.frames > 100_000 {
        return Err(format!(
            "--frames must be in 1..=100000, got {}",
            args.frames
        ));
    }
    if args.world_objects > demo_world::MAX_OBJECTS {
        return Err(format!(
            "--world-objects must be in 0..={}, got {}",
            demo_world::MAX_OBJECTS,
            args.world_objects
        ));
    }
    if args.world_objects > 0 && (args.world_frames == 0 || args.world_frames > 100_000) {
        return Err(format!(
            "--world-frames must be in 1..=100000, got {}",
            args.world_frames
        ));
    }
    if args.world_objects > 0 {
        // Before the long sphere scene: a missing mesh folder fails at once.
        demo_world::data_dir(args.data.as_deref())?;
    }
    let chosen: Vec<&'static str> = if args.index == "all" {
        indices::NAMES.to_vec()
    } else if let Some(&name) = indices::NAMES.iter().find(|&&n| n == args.index) {
        if name == BRUTE {
            vec![BRUTE]
        } else {
            vec![BRUTE, name]
        }
    } else {
        return Err(format!(
            "unknown index '{}' (known: {}, all)",
            args.index,
            indices::NAMES.join(", ")
        ));
    };
    let (n, frames) = (args.objects, args.frames);
    let w0 = Workload::new(args.scene, n, args.seed);
    let hint = w0.scene().hint();
    let describe = w0.describe();
    drop(w0);
    let brute_mask = sample_frames(frames, brute_frames(n, frames));
    let all_mask = vec![true; frames];
    let checked: Vec<usize> = (1..=frames).filter(|f| brute_mask[f - 1]).collect();

    if !args.json {
        println!(
            "{describe}; {frames} frames (move all, then find all pairs), seed {}",
            args.seed
        );
    }
    let terminal = std::io::stderr().is_terminal();
    let mut rows = Vec::new();
    for &name in &chosen {
        let mask = if name == BRUTE {
            &brute_mask
        } else {
            &all_mask
        };
        let bar = if terminal {
            ProgressBar::new(frames as u64).with_style(
                ProgressStyle::with_template(
                    "{prefix:>9} [{bar:32.cyan/blue}] {pos:>4}/{len} frames {elapsed:>4}",
                )
                .map_err(|e| e.to_string())?
                .progress_chars("=> "),
            )
        } else {
            ProgressBar::hidden()
        };
        bar.set_prefix(name);
        let start = Instant::now();
        let job = Frames {
            kind: args.scene,
            n,
            seed: args.seed,
            search: mask,
            bar: &bar,
        };
        let kind: IndexKind = name.parse().map_err(|e| format!("{e}"))?;
        let row = match kind.build(&hint).map(|index| job.run(name, index)) {
            Ok(Ok(row)) => row,
            Ok(Err(e)) => {
                bar.abandon();
                eprintln!("proxima demo: index {name} failed on the scene: {e}");
                return Ok(ExitCode::from(1));
            }
            Err(e) => {
                bar.abandon();
                eprintln!("proxima demo: index {name} rejects the scene: {e}");
                return Ok(ExitCode::from(1));
            }
        };
        bar.finish();
        if terminal {
            // indicatif leaves the cursor at the end of the finished bar.
            eprintln!();
        } else {
            eprintln!(
                "{name:>9}: {frames} frames ({} with pairs) in {:.2} s",
                row.searched(),
                start.elapsed().as_secs_f64()
            );
        }
        rows.push(row);
    }

    if let Some((f, a, b)) = pair_mismatch(&rows) {
        eprintln!(
            "proxima demo: frame {f}: {} finds {} pairs but {} finds {}",
            a.name,
            a.pair_counts[f - 1].unwrap_or(0),
            b.name,
            b.pair_counts[f - 1].unwrap_or(0)
        );
        return Ok(ExitCode::from(1));
    }

    // Pairs per frame, averaged over the frames brute force checked (so the
    // column is equal for every index, and checked).
    let mean_pairs = |r: &Row| {
        checked
            .iter()
            .filter_map(|&f| r.pair_counts[f - 1])
            .sum::<usize>() as f64
            / checked.len().max(1) as f64
    };
    let total = |r: &Row| r.update_ms() + r.pairs_ms();
    let fastest = rows
        .iter()
        .filter(|r| r.name != BRUTE || rows.len() == 1)
        .min_by(|a, b| total(a).total_cmp(&total(b)));

    let mut pictures = if args.no_pictures {
        Vec::new()
    } else {
        write_pictures(args, &rows, &describe)?
    };

    let world = if args.world_objects > 0 {
        let opt = demo_world::Options {
            objects: args.world_objects,
            frames: args.world_frames,
            seed: args.seed,
            data: args.data.as_deref(),
            out: (!args.no_pictures).then_some(args.out.as_path()),
            svg: args.svg,
            terminal,
        };
        match demo_world::run(&opt) {
            Ok(row) => {
                pictures.extend(row.picture.clone());
                Some(row)
            }
            Err(demo_world::Failure::Input(e)) => return Err(e),
            Err(demo_world::Failure::Wrong(e)) => {
                eprintln!("proxima demo: {e}");
                return Ok(ExitCode::from(1));
            }
        }
    } else {
        None
    };

    if args.json {
        let json = serde_json::json!({
            "scene": args.scene.scene_name(),
            "objects": n,
            "frames": frames,
            "seed": args.seed,
            "checked_frames": checked,
            "fastest": fastest.map(|r| r.name),
            "indices": rows.iter().map(|r| serde_json::json!({
                "name": r.name,
                "build_ms": r.build.as_secs_f64() * 1e3,
                "update_ms_per_frame": r.update_ms(),
                "pairs_ms_per_frame": r.pairs_ms(),
                "frames_with_pairs": r.searched(),
                "pairs_per_frame": mean_pairs(r),
                "bytes_per_object": r.bytes as f64 / n as f64,
                "pair_counts": r.pair_counts,
                "frame_ms": r.frame_ms,
            })).collect::<Vec<_>>(),
            "pictures": pictures.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
            "world": world.as_ref().map(demo_world::WorldRow::json),
        });
        println!("{json}");
        return Ok(ExitCode::SUCCESS);
    }

    println!(
        "{:<9} {:>9} {:>10} {:>12} {:>11} {:>11} {:>12} {:>9}",
        "index",
        "frames",
        "build ms",
        "update ms/f",
        "pairs ms/f",
        "total ms/f",
        "pairs/frame*",
        "bytes/obj"
    );
    for r in &rows {
        let mark = if fastest.is_some_and(|f| f.name == r.name) {
            "  <- fastest"
        } else {
            ""
        };
        println!(
            "{:<9} {:>9} {:>10.1} {:>12.2} {:>11.2} {:>11.2} {:>12.1} {:>9.1}{mark}",
            r.name,
            if r.searched() == frames {
                frames.to_string()
            } else {
                format!("{}/{frames}", r.searched())
            },
            r.build.as_secs_f64() * 1e3,
            r.update_ms(),
            r.pairs_ms(),
            total(r),
            mean_pairs(r),
            r.bytes as f64 / n as f64,
        );
    }
    let list = if checked.len() <= 8 {
        checked
            .iter()
            .map(|f| f.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    } else {
        format!("{} frames", checked.len())
    };
    println!(
        "* mean over the frames brute force searched ({list}); there every index found \
         exactly the brute-force pair count, and all indices agree on every frame."
    );
    if let (Some(f), Some(b)) = (fastest, rows.iter().find(|r| r.name == BRUTE)) {
        if f.name != BRUTE {
            println!(
                "fastest here: {} at {:.2} ms per frame, {:.0}x faster than brute force.",
                f.name,
                total(f),
                total(b) / total(f).max(1e-9)
            );
        }
    }
    if let Some(w) = &world {
        println!();
        w.print();
    }
    if !pictures.is_empty() {
        println!("pictures:");
        for p in &pictures {
            println!("  {}", p.display());
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Writes the partition pictures (final frame) and the time chart; returns paths.
fn write_pictures(args: &Args, rows: &[Row], describe: &str) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(&args.out)
        .map_err(|e| format!("cannot create {}: {e}", args.out.display()))?;
    let mut w = Workload::new(args.scene, args.objects, args.seed);
    for _ in 0..args.frames {
        w.step();
    }
    let hint = w.scene().hint();
    let ext = if args.svg { "svg" } else { "png" };
    let name = args.scene.scene_name();
    let mut out = Vec::new();
    let mut save = |c: Canvas, what: &str| -> Result<(), String> {
        let p = args.out.join(format!("{name}-{what}.{ext}"));
        c.save(&p)?;
        out.push(p);
        Ok(())
    };
    save(pictures::kd_partition(&w.spheres, &hint)?, "loose-kd")?;
    save(pictures::octree_partition(&w.spheres, &hint)?, "octree")?;
    let series: Vec<Series> = rows
        .iter()
        .map(|r| Series {
            name: r.name.to_string(),
            points: r
                .frame_ms
                .iter()
                .enumerate()
                .filter_map(|(i, ms)| ms.map(|m| (i + 1, m)))
                .collect(),
        })
        .collect();
    let short = describe.split(':').next().unwrap_or(describe);
    save(
        pictures::time_chart(
            &format!(
                "{short}, {} spheres: update + pairs per frame",
                args.objects
            ),
            &series,
        ),
        "time",
    )?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(name: &'static str, pair_counts: Vec<Option<usize>>) -> Row {
        Row {
            name,
            build: Duration::ZERO,
            update: Duration::ZERO,
            pairs: Duration::ZERO,
            frame_ms: vec![None; pair_counts.len()],
            pair_counts,
            bytes: 0,
        }
    }

    #[test]
    fn mismatch_compares_only_frames_both_searched() {
        let ok = [
            row(BRUTE, vec![Some(5), None]),
            row("a", vec![Some(5), Some(7)]),
            row("b", vec![Some(5), Some(7)]),
        ];
        assert!(pair_mismatch(&ok).is_none());
        let bad = [
            row(BRUTE, vec![Some(5), None]),
            row("a", vec![Some(5), Some(7)]),
            row("b", vec![Some(5), Some(8)]),
        ];
        let (f, a, b) = pair_mismatch(&bad).unwrap();
        assert_eq!((f, a.name, b.name), (2, "a", "b"));
        let bad = [row(BRUTE, vec![Some(4)]), row("a", vec![Some(5), Some(7)])];
        assert_eq!(pair_mismatch(&bad).unwrap().0, 1);
    }

    #[test]
    fn brute_samples_spread_over_the_run() {
        assert_eq!(brute_frames(100, 20), 20);
        assert_eq!(brute_frames(10_000_000, 20), 1);
        let m = sample_frames(30, 3);
        assert_eq!(m.iter().filter(|x| **x).count(), 3);
        assert!(m[0] && m[29] && m[14..=15].iter().any(|x| *x));
        assert_eq!(sample_frames(5, 9), vec![true; 5]);
        assert_eq!(sample_frames(4, 1), vec![true, false, false, false]);
    }

    #[test]
    fn every_index_runs_a_small_scene_alike() {
        for kind in Kind::ALL {
            let w = Workload::new(kind, 400, 5);
            let bar = ProgressBar::hidden();
            let search = [true, false, true];
            let rows: Vec<Row> = indices::NAMES
                .iter()
                .map(|n| {
                    let job = Frames {
                        kind,
                        n: 400,
                        seed: 5,
                        search: &search,
                        bar: &bar,
                    };
                    let index = n
                        .parse::<IndexKind>()
                        .unwrap()
                        .build(&w.scene().hint())
                        .unwrap();
                    job.run(n, index).unwrap()
                })
                .collect();
            assert!(pair_mismatch(&rows).is_none());
            assert_eq!(rows[0].pair_counts[1], None);
            if kind != Kind::W2 {
                assert!(rows[0].pair_counts[0].unwrap() > 0);
            }
        }
    }

    #[test]
    fn pictures_are_written() {
        let dir = std::env::temp_dir().join(format!("proxima-demo-test-{}", std::process::id()));
        let args = Args {
            objects: 300,
            frames: 2,
            out: dir.clone(),
            ..Args::default()
        };
        let rows = [row("a", vec![Some(1), Some(1)])];
        let paths = write_pictures(&args, &rows, "W1 uniform: x").unwrap();
        assert_eq!(paths.len(), 3);
        assert!(paths.iter().all(|p| p.exists()));
        let _ = std::fs::remove_dir_all(dir);
    }
}

//! What `proxima` does without a command (until `demo` exists): the W1 scene of
//! design §5 through every registered index, and a comparison table.
//!
//! Every index replays the same precomputed frames (a frame = update every sphere,
//! then find all overlapping pairs). Brute force is O(n²) per frame, so it runs
//! only as many frames as a fixed budget of sphere tests allows (at least one, the
//! cross-check frame, unless the scene is too large for even that). Pair counts
//! must be equal for every index on every frame they both ran; otherwise the run
//! fails with exit code 1.

use crate::indices::{self, IndexJob, BRUTE};
use crate::scene::W1;
use proxima::broad::SpatialIndex;
use proxima::geom::Sphere;
use std::ops::ControlFlow;
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// Number of spheres of the default scene.
pub const N: usize = 20_000;
/// Frames run by every index (brute force may run fewer).
pub const FRAMES: usize = 20;
/// Scene seed.
pub const SEED: u64 = 1;
/// Sphere-pair tests brute force may spend over all its frames.
const BRUTE_BUDGET: f64 = 6e8;

/// One index's figures.
#[derive(Clone, Debug)]
pub struct Row {
    /// Index name.
    pub name: &'static str,
    /// Time to insert the first frame into an empty index.
    pub build: Duration,
    /// Total update time over the frames run.
    pub update: Duration,
    /// Total pair-finding time over the frames run.
    pub pairs: Duration,
    /// Pairs found in frames `1..=pair_counts.len()`.
    pub pair_counts: Vec<usize>,
    /// `memory_bytes()` after the last frame.
    pub bytes: usize,
}

/// Runs the frames `1..=frames` of a precomputed scene (`scene[0]` is the build).
struct Frames<'a> {
    scene: &'a [Vec<Sphere>],
    frames: usize,
}

impl IndexJob for Frames<'_> {
    type Output = proxima::Result<Row>;

    fn run<I: SpatialIndex<u64>>(&mut self, name: &'static str, mut index: I) -> Self::Output {
        let start = Instant::now();
        let handles = self.scene[0]
            .iter()
            .enumerate()
            .map(|(i, s)| index.insert(*s, i as u64))
            .collect::<proxima::Result<Vec<_>>>()?;
        let build = start.elapsed();
        let (mut update, mut pairs) = (Duration::ZERO, Duration::ZERO);
        let mut pair_counts = Vec::with_capacity(self.frames);
        for frame in &self.scene[1..=self.frames] {
            let start = Instant::now();
            for (h, s) in handles.iter().zip(frame) {
                index.update(*h, *s)?;
            }
            update += start.elapsed();
            let start = Instant::now();
            let mut n = 0usize;
            let _ = index.for_each_pair(|_, _, _, _| {
                n += 1;
                ControlFlow::Continue(())
            });
            pairs += start.elapsed();
            pair_counts.push(n);
        }
        Ok(Row {
            name,
            build,
            update,
            pairs,
            pair_counts,
            bytes: index.memory_bytes(),
        })
    }
}

/// How many frames brute force can afford at `n` spheres (0: not even one).
fn brute_frames(n: usize, frames: usize) -> usize {
    let per_frame = (n as f64) * (n as f64 - 1.0) / 2.0;
    ((BRUTE_BUDGET / per_frame.max(1.0)) as usize).clamp(0, frames)
}

/// The first frame (1-based) where two rows that both ran it report different pair
/// counts: `(frame, row a, row b)`.
pub fn pair_mismatch(rows: &[Row]) -> Option<(usize, &Row, &Row)> {
    let frames = rows.iter().map(|r| r.pair_counts.len()).max().unwrap_or(0);
    (0..frames).find_map(|f| {
        let mut ran = rows.iter().filter(|r| f < r.pair_counts.len());
        let first = ran.next()?;
        ran.find(|r| r.pair_counts[f] != first.pair_counts[f])
            .map(|r| (f + 1, first, r))
    })
}

/// Runs the default scene and prints the table.
pub fn main() -> ExitCode {
    let mut w = W1::new(N, SEED);
    let hint = w.hint();
    let mut scene = Vec::with_capacity(FRAMES + 1);
    scene.push(w.spheres().to_vec());
    for _ in 0..FRAMES {
        w.step();
        scene.push(w.spheres().to_vec());
    }
    println!(
        "W1: {N} spheres, radii uniform in [0.5, 2], cube side {:.1}, {FRAMES} frames \
         (update all + find all pairs), seed {SEED}",
        w.side()
    );
    println!(
        "{:<10} {:>7} {:>10} {:>12} {:>12} {:>13} {:>10}",
        "index", "frames", "build ms", "update ms/f", "pairs ms/f", "pairs/frame*", "bytes/obj"
    );
    let frames_of = |name: &str| {
        if name == BRUTE {
            brute_frames(N, FRAMES)
        } else {
            FRAMES
        }
    };
    // Pairs are averaged over the frames every index ran, so the column is equal
    // for all indices (a different figure is a bug, also caught below).
    let common = indices::NAMES
        .iter()
        .map(|n| frames_of(n))
        .filter(|&f| f > 0)
        .min()
        .unwrap_or(FRAMES);
    let mut rows = Vec::new();
    for &name in indices::NAMES {
        let frames = frames_of(name);
        if frames == 0 {
            println!("{name:<10} skipped: too slow at {N} spheres");
            continue;
        }
        let row = match indices::with_index(
            name,
            &hint,
            &mut Frames {
                scene: &scene,
                frames,
            },
        ) {
            Some(Ok(Ok(row))) => row,
            Some(Ok(Err(e))) => {
                eprintln!("proxima: index {name} failed on the default scene: {e}");
                return ExitCode::from(1);
            }
            Some(Err(e)) => {
                eprintln!("proxima: index {name} rejects the default scene: {e}");
                return ExitCode::from(1);
            }
            None => {
                eprintln!("proxima: index {name} is listed but not buildable");
                return ExitCode::from(1);
            }
        };
        let per_frame = |d: Duration| d.as_secs_f64() * 1e3 / frames as f64;
        let mean_pairs = row.pair_counts[..common].iter().sum::<usize>() as f64 / common as f64;
        println!(
            "{:<10} {:>7} {:>10.2} {:>12.3} {:>12.3} {:>13.1} {:>10.1}",
            name,
            frames,
            row.build.as_secs_f64() * 1e3,
            per_frame(row.update),
            per_frame(row.pairs),
            mean_pairs,
            row.bytes as f64 / N as f64,
        );
        rows.push(row);
    }
    if let Some((f, a, b)) = pair_mismatch(&rows) {
        eprintln!(
            "proxima: frame {f}: {} finds {} pairs but {} finds {}",
            a.name,
            a.pair_counts[f - 1],
            b.name,
            b.pair_counts[f - 1]
        );
        return ExitCode::from(1);
    }
    let checked = rows
        .iter()
        .find(|r| r.name == BRUTE)
        .map_or("no brute-force check: scene too large".to_string(), |r| {
            format!("brute force checked frames 1-{}", r.pair_counts.len())
        });
    println!(
        "* mean over frames 1-{common}, run by every index. Pair counts agree between \
         all {} indices on every frame ({checked}).",
        rows.len()
    );
    ExitCode::SUCCESS
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(name: &'static str, pair_counts: Vec<usize>) -> Row {
        Row {
            name,
            build: Duration::ZERO,
            update: Duration::ZERO,
            pairs: Duration::ZERO,
            pair_counts,
            bytes: 0,
        }
    }

    #[test]
    fn mismatch_compares_only_frames_both_ran() {
        let ok = [
            row(BRUTE, vec![5]),
            row("a", vec![5, 7]),
            row("b", vec![5, 7]),
        ];
        assert!(pair_mismatch(&ok).is_none());
        let bad = [
            row(BRUTE, vec![5]),
            row("a", vec![5, 7]),
            row("b", vec![5, 8]),
        ];
        let (f, a, b) = pair_mismatch(&bad).unwrap();
        assert_eq!((f, a.name, b.name), (2, "a", "b"));
        let bad = [row(BRUTE, vec![4]), row("a", vec![5, 7])];
        assert_eq!(pair_mismatch(&bad).unwrap().0, 1);
    }

    #[test]
    fn brute_budget_shrinks_with_n() {
        assert_eq!(brute_frames(100, 20), 20);
        assert!(brute_frames(20_000, 20) >= 1);
        assert_eq!(brute_frames(10_000_000, 20), 0);
    }

    #[test]
    fn every_index_runs_a_small_scene_alike() {
        let mut w = W1::new(300, 5);
        let mut scene = vec![w.spheres().to_vec()];
        for _ in 0..3 {
            w.step();
            scene.push(w.spheres().to_vec());
        }
        let rows: Vec<Row> = indices::NAMES
            .iter()
            .map(|n| {
                let job = &mut Frames {
                    scene: &scene,
                    frames: 3,
                };
                indices::with_index(n, &w.hint(), job)
                    .unwrap()
                    .unwrap()
                    .unwrap()
            })
            .collect();
        assert!(pair_mismatch(&rows).is_none());
        assert!(rows[0].pair_counts.iter().all(|&c| c > 0));
    }
}

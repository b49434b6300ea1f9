//! A world scene on Proxima's [`World`]: the same frames as the peers' harness
//! measures (a frame = the `pose` lines since the previous `contacts`, then that
//! `contacts`), wall clock, with the answer of every `contacts`.

use super::scenes::{Op, Scene};
use proxima::glam::Affine3A;
use proxima::narrow::{BoundingVolume, BuildOptions, Mesh};
use proxima::world::{ContactMode, ContactReport, Shape, World, WorldConfig, WorldCounters};
use proxima::Handle;
use std::collections::HashMap;
use std::time::{Duration, Instant};

/// What a run of a scene gave.
#[derive(Clone, Debug, Default)]
pub struct OursRun {
    /// `(P, T)` per `contacts` line (`T` is 0 in first-contact mode).
    pub answers: Vec<(usize, usize)>,
    /// Every frame's time, over all repetitions.
    pub frames: Vec<Duration>,
    /// Time of `add`/`remove`/`ignore` lines per repetition.
    pub other: Duration,
    /// Mesh trees' build time (once).
    pub build: Duration,
    /// Counters summed over the frames of the first repetition.
    pub counters: WorldCounters,
}

/// Runs `scene` `reps` times, each from an empty world built with `config`.
pub fn run<BV: BoundingVolume>(
    scene: &Scene,
    config: WorldConfig,
    first: bool,
    reps: usize,
) -> Result<OursRun, String> {
    let err = |e: proxima::Error| format!("{}: {e}", scene.name);
    let start = Instant::now();
    let shapes: Vec<Shape<BV>> = scene
        .meshes
        .iter()
        .map(|m| Mesh::from_trimesh(m.mesh.clone(), BuildOptions::default()).map(Shape::from))
        .collect::<proxima::Result<_>>()
        .map_err(err)?;
    let mut out = OursRun {
        build: start.elapsed(),
        ..OursRun::default()
    };
    let mode = if first {
        ContactMode::First
    } else {
        ContactMode::All
    };
    let mut report = ContactReport::default();
    for rep in 0..reps.max(1) {
        let mut world: World<u64, BV> = World::new(config).map_err(err)?;
        let mut handles: HashMap<u64, Handle> = HashMap::new();
        let mut frame = Duration::ZERO;
        let mut answers = Vec::new();
        for op in &scene.ops {
            let t = Instant::now();
            match *op {
                Op::Add { id, mesh } => {
                    let h = world
                        .insert(shapes[mesh].clone(), Affine3A::IDENTITY, id)
                        .map_err(err)?;
                    handles.insert(id, h);
                    out.other += t.elapsed();
                }
                Op::Remove { id } => {
                    let h = handles.remove(&id).ok_or("remove of an unknown id")?;
                    world.remove(h).map_err(err)?;
                    out.other += t.elapsed();
                }
                Op::Ignore(a, b) => {
                    world.ignore(handles[&a], handles[&b]).map_err(err)?;
                    out.other += t.elapsed();
                }
                Op::Pose { id, pose } => {
                    world.set_pose(handles[&id], pose).map_err(err)?;
                    frame += t.elapsed();
                }
                Op::Contacts => {
                    world.contacts_into(mode, &mut report).map_err(err)?;
                    frame += t.elapsed();
                    out.frames.push(frame);
                    frame = Duration::ZERO;
                    answers.push((
                        report.pairs.len(),
                        if first { 0 } else { report.triangles.len() },
                    ));
                    if rep == 0 {
                        let (s, c) = (&mut out.counters, &report.counters);
                        s.broad_pairs += c.broad_pairs;
                        s.narrow_pairs += c.narrow_pairs;
                        s.coherent_pairs += c.coherent_pairs;
                        s.cut_starts += c.cut_starts;
                        s.cost.nv += c.cost.nv;
                        s.cost.np += c.cost.np;
                        s.cost.nu += c.cost.nu;
                    }
                }
            }
        }
        if rep == 0 {
            out.answers = answers;
        } else if answers != out.answers {
            return Err(format!(
                "{}: repetition {rep} answers differently",
                scene.name
            ));
        }
    }
    out.other /= reps.max(1) as u32;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::scenes::{generate, Sizes};
    use super::*;
    use proxima::narrow::Kdop18;

    /// Repetitions answer alike, first contact finds the same object pairs, and
    /// coherence off answers as on.
    #[test]
    fn runs_repeat_and_modes_agree() {
        let dir = std::env::temp_dir().join(format!("proxima-bench-ours-{}", std::process::id()));
        let sizes = Sizes {
            n: 40,
            arms: 2,
            frames: 4,
        };
        let s = generate("tumble-10", &dir, sizes, 2).unwrap();
        let all = run::<Kdop18>(&s, WorldConfig::default(), false, 2).unwrap();
        assert_eq!(all.frames.len(), 2 * s.frames());
        assert!(all.answers.iter().any(|a| a.0 > 0));
        let first = run::<Kdop18>(&s, WorldConfig::default(), true, 1).unwrap();
        let pairs = |r: &OursRun| r.answers.iter().map(|a| a.0).collect::<Vec<_>>();
        assert_eq!(pairs(&first), pairs(&all));
        let off = WorldConfig {
            coherence: false,
            ..WorldConfig::default()
        };
        assert_eq!(
            run::<Kdop18>(&s, off, false, 1).unwrap().answers,
            all.answers
        );
        assert!(all.counters.coherent_pairs > 0);
        let _ = std::fs::remove_dir_all(dir);
    }
}

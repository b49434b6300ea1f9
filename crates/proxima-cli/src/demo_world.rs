//! The demo's world scene [sources: world]: a few hundred meshes from
//! `shared/data` (scaled to a longest side of 1) tumbling in a box, a quarter of
//! them at rest. Every frame: the moving objects' poses in one batch, all
//! contacts (every intersecting triangle pair), a fan of rays across the box and
//! a camera's culling. On a few sampled frames the brute-force world of
//! `proxima world --check` answers the same questions and every count must be
//! equal (contact pairs, triangle pairs, each ray's object and triangle, the
//! culled set), otherwise the demo fails with exit code 1. A table of times and
//! counters follows, and a picture of the last frame with its touching triangles
//! in red.

use crate::draw::Canvas;
use crate::world_picture::{closed_outward, world_frame, Drawn};
use indicatif::{ProgressBar, ProgressStyle};
use proxima::broad::Filter;
use proxima::geom::{Frustum, Ray, Relation};
use proxima::glam::{Affine3A, Mat4, Quat, Vec3};
use proxima::narrow::{BuildOptions, Kdop18, Mesh, TriMesh};
use proxima::world::{ContactMode, ContactReport, Shape, World, WorldConfig, WorldCounters};
use proxima::Handle;
use proxima_harness::world_oracle::BruteWorld;
use proxima_harness::world_replay::WorldAnswer;
use proxima_harness::world_trace::{WorldOp, WorldTrace};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Objects of the default world scene.
pub const OBJECTS: usize = 300;
/// Frames of the default world scene.
pub const FRAMES: usize = 60;
/// The meshes, from the data folder, used in turn.
const MESHES: [&str; 5] = [
    "bunny.obj",
    "teapot.obj",
    "rob.obj",
    "hand_3finger.stl",
    "forearm.stl",
];
/// Rays cast per frame.
const RAYS: usize = 32;
/// Frames the brute-force world checks (spread over the run, first and last
/// included).
const CHECKED: usize = 3;
/// Largest accepted world scene.
pub const MAX_OBJECTS: usize = 5_000;

/// Where the meshes are: `--data`, else `../shared/data` from the current
/// folder (the repository root under `cargo run`), else beside the sources.
pub fn data_dir(explicit: Option<&Path>) -> Result<PathBuf, String> {
    if let Some(d) = explicit {
        return match MESHES.iter().find(|m| !d.join(m).is_file()) {
            None => Ok(d.to_path_buf()),
            Some(m) => Err(format!("--data {}: no {m} there", d.display())),
        };
    }
    let here = PathBuf::from("../shared/data");
    let built = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data"));
    [here, built]
        .into_iter()
        .find(|d| d.join(MESHES[0]).is_file())
        .ok_or_else(|| {
            "no meshes for the world scene: ../shared/data not found (give --data DIR, or \
             --world-objects 0 to skip the scene)"
                .to_string()
        })
}

/// Loads a mesh and scales it to a longest side of 1 about its box's centre.
fn unit_mesh(path: &Path) -> Result<TriMesh, String> {
    let m = proxima::io::load(path).map_err(|e| {
        let s = e.to_string();
        let name = path.display().to_string();
        if s.contains(&name) {
            s
        } else {
            format!("{name}: {s}")
        }
    })?;
    let (lo, hi) = m
        .vertices()
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(*v), hi.max(*v))
        });
    let (c, s) = ((lo + hi) * 0.5, 1.0 / (hi - lo).max_element().max(1e-30));
    let v = m.vertices().iter().map(|p| (*p - c) * s).collect();
    TriMesh::new(v, m.triangles().to_vec()).map_err(|e| format!("{}: {e}", path.display()))
}

/// One object's motion: it starts at `pos` with rotation `axis`·`angle` and
/// moves by `vel` and `spin` per frame, bouncing off the walls.
#[derive(Clone, Copy, Debug)]
struct Motion {
    kind: usize,
    pos: Vec3,
    vel: Vec3,
    axis: Vec3,
    angle: f32,
    spin: f32,
}

impl Motion {
    fn pose(&self) -> Affine3A {
        Affine3A::from_rotation_translation(Quat::from_axis_angle(self.axis, self.angle), self.pos)
    }

    /// One frame: move, turn, bounce (the centre stays half a unit inside).
    fn step(&mut self, side: f32) {
        self.pos += self.vel;
        self.angle = (self.angle + self.spin) % std::f32::consts::TAU;
        for k in 0..3 {
            if self.pos[k] < 0.5 || self.pos[k] > side - 0.5 {
                self.vel[k] = -self.vel[k];
                self.pos[k] = self.pos[k].clamp(0.5, side - 0.5);
            }
        }
    }
}

fn unit(rng: &mut Pcg64) -> Vec3 {
    loop {
        let v = Vec3::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        );
        let l = v.length();
        if l > 0.1 && l <= 1.0 {
            return v / l;
        }
    }
}

/// The box side for `n` objects: about 4 unit cells of volume each (a third
/// of the objects touch another).
fn box_side(n: usize) -> f32 {
    (n as f32 * 4.0).cbrt().max(3.0)
}

/// The rays of frame `f`: from the box's `x = 0` face across it.
fn rays(seed: u64, f: usize, side: f32) -> Vec<Ray> {
    let mut rng = Pcg64::seed_from_u64(seed ^ (f as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    (0..RAYS)
        .map(|_| {
            let o = Vec3::new(-0.5, rng.gen_range(0.0..side), rng.gen_range(0.0..side));
            let d = Vec3::new(1.0, rng.gen_range(-0.3..0.3), rng.gen_range(-0.3..0.3));
            Ray::with_max_t(o, d, side + 1.0)
        })
        .collect()
}

/// The camera: from outside a corner, a 22° cone on the box's centre, so the
/// box's corners are culled.
fn camera(side: f32) -> Result<Frustum, String> {
    let centre = Vec3::splat(side / 2.0);
    let eye = centre + Vec3::new(-1.0, -1.6, 1.2) * side;
    let view = Mat4::look_at_rh(eye, centre, Vec3::Z);
    let proj = Mat4::perspective_rh(22f32.to_radians(), 1.0, 0.1, 10.0 * side);
    Frustum::from_view_projection(proj * view).map_err(|e| e.to_string())
}

/// The figures of a world-scene run.
#[derive(Clone, Debug, Default)]
pub struct WorldRow {
    pub objects: usize,
    pub moving: usize,
    pub frames: usize,
    pub side: f32,
    pub kinds: Vec<String>,
    pub triangles: usize,
    pub build: Duration,
    pub poses: Duration,
    pub contacts: Duration,
    pub rays: Duration,
    pub cull: Duration,
    /// Sums over the frames.
    pub pairs: usize,
    pub tri_pairs: usize,
    pub hits: usize,
    pub visible: usize,
    pub counters: WorldCounters,
    /// The frames (1-based) the brute-force world checked.
    pub checked: Vec<usize>,
    pub brute: Duration,
    pub picture: Option<PathBuf>,
}

impl WorldRow {
    fn per_frame(&self, d: Duration) -> f64 {
        d.as_secs_f64() * 1e3 / self.frames.max(1) as f64
    }
    fn mean(&self, x: u64) -> f64 {
        x as f64 / self.frames.max(1) as f64
    }

    /// The table of the world scene.
    pub fn print(&self) {
        println!(
            "world: {} meshes ({}; {} triangles) tumbling in a {s:.1} x {s:.1} x {s:.1} box, {} \
             moving, {} frames",
            self.objects,
            self.kinds.join(", "),
            self.triangles,
            self.moving,
            self.frames,
            s = self.side,
        );
        let c = &self.counters;
        let rows = [
            (
                "poses",
                self.poses,
                format!("{} poses set in one batch", self.moving),
            ),
            (
                "contacts",
                self.contacts,
                format!(
                    "{:.1} object pairs touching, {:.1} triangle pairs; broad {:.1} candidates, \
                     {:.1} narrow tests, {:.1} skipped by coherence, {:.1} from a cached cut; \
                     Nv {:.0}, Np {:.0}",
                    self.mean(self.pairs as u64),
                    self.mean(self.tri_pairs as u64),
                    self.mean(c.broad_pairs),
                    self.mean(c.narrow_pairs),
                    self.mean(c.coherent_pairs),
                    self.mean(c.cut_starts),
                    self.mean(c.cost.nv),
                    self.mean(c.cost.np),
                ),
            ),
            (
                "rays",
                self.rays,
                format!("{RAYS} rays, {:.1} hit a mesh", self.mean(self.hits as u64)),
            ),
            (
                "cull",
                self.cull,
                format!(
                    "{:.1} of {} objects visible",
                    self.mean(self.visible as u64),
                    self.objects
                ),
            ),
        ];
        println!("{:<9} {:>9}  per frame (mean)", "stage", "ms/frame");
        for (name, d, what) in rows {
            println!("{name:<9} {:>9.3}  {what}", self.per_frame(d));
        }
        println!(
            "checked frames {}: the brute-force world (every object and triangle pair, every \
             triangle per ray, every sphere against the frustum; {:.2} s) gives the same \
             contacts, triangle pairs, ray hits and culled sets.",
            self.checked
                .iter()
                .map(|f| f.to_string())
                .collect::<Vec<_>>()
                .join(", "),
            self.brute.as_secs_f64()
        );
    }

    /// The figures as JSON.
    pub fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "objects": self.objects,
            "moving": self.moving,
            "frames": self.frames,
            "meshes": self.kinds,
            "triangles": self.triangles,
            "build_ms": self.build.as_secs_f64() * 1e3,
            "poses_ms_per_frame": self.per_frame(self.poses),
            "contacts_ms_per_frame": self.per_frame(self.contacts),
            "rays_ms_per_frame": self.per_frame(self.rays),
            "cull_ms_per_frame": self.per_frame(self.cull),
            "pairs_per_frame": self.mean(self.pairs as u64),
            "triangle_pairs_per_frame": self.mean(self.tri_pairs as u64),
            "ray_hits_per_frame": self.mean(self.hits as u64),
            "visible_per_frame": self.mean(self.visible as u64),
            "broad_pairs_per_frame": self.mean(self.counters.broad_pairs),
            "narrow_pairs_per_frame": self.mean(self.counters.narrow_pairs),
            "coherent_pairs_per_frame": self.mean(self.counters.coherent_pairs),
            "checked_frames": self.checked,
            "brute_s": self.brute.as_secs_f64(),
            "picture": self.picture.as_ref().map(|p| p.display().to_string()),
        })
    }
}

/// What the world scene needs from the demo's options.
pub struct Options<'a> {
    pub objects: usize,
    pub frames: usize,
    pub seed: u64,
    pub data: Option<&'a Path>,
    /// Where to write the picture (`None`: no picture), and as SVG.
    pub out: Option<&'a Path>,
    pub svg: bool,
    pub terminal: bool,
}

/// A failure of the scene: bad input (exit 2) or a wrong answer (exit 1).
#[derive(Debug)]
pub enum Failure {
    Input(String),
    Wrong(String),
}

/// Runs the world scene.
pub fn run(opt: &Options<'_>) -> Result<WorldRow, Failure> {
    let input = Failure::Input;
    let dir = data_dir(opt.data).map_err(input)?;
    let meshes: Vec<Arc<TriMesh>> = MESHES
        .iter()
        .map(|m| unit_mesh(&dir.join(m)).map(Arc::new))
        .collect::<Result<_, _>>()
        .map_err(Failure::Input)?;
    let n = opt.objects;
    let side = box_side(n);
    let mut rng = Pcg64::seed_from_u64(opt.seed);
    let mut motions: Vec<Motion> = (0..n)
        .map(|i| {
            let resting = i % 4 == 3;
            let pos = Vec3::new(
                rng.gen_range(0.5..side - 0.5),
                rng.gen_range(0.5..side - 0.5),
                rng.gen_range(0.5..side - 0.5),
            );
            let speed = rng.gen_range(0.02..0.08);
            let vel = unit(&mut rng) * speed;
            let axis = unit(&mut rng);
            let angle = rng.gen_range(0.0..std::f32::consts::TAU);
            let spin = rng.gen_range(0.02..0.1);
            Motion {
                kind: i % MESHES.len(),
                pos,
                vel: if resting { Vec3::ZERO } else { vel },
                axis,
                angle,
                spin: if resting { 0.0 } else { spin },
            }
        })
        .collect();
    let moving: Vec<usize> = (0..n).filter(|&i| motions[i].spin != 0.0).collect();

    // The world: shared shapes, one object per motion, payload = its number.
    let start = Instant::now();
    let shapes: Vec<Shape<Kdop18>> = meshes
        .iter()
        .map(|m| {
            let mesh = Mesh::from_trimesh((**m).clone(), BuildOptions::default())?;
            mesh.ray_bvh();
            Ok(Shape::from(mesh))
        })
        .collect::<proxima::Result<_>>()
        .map_err(|e: proxima::Error| Failure::Input(e.to_string()))?;
    let wrong = |e: proxima::Error| Failure::Wrong(format!("the world failed: {e}"));
    let mut world: World<u64> = World::new(WorldConfig::default()).map_err(wrong)?;
    let handles: Vec<Handle> = motions
        .iter()
        .enumerate()
        .map(|(i, m)| world.insert(shapes[m.kind].clone(), m.pose(), i as u64))
        .collect::<proxima::Result<_>>()
        .map_err(wrong)?;
    let build = start.elapsed();

    // The brute-force world over the same meshes and objects.
    let trace = WorldTrace {
        meshes: meshes.clone(),
        ids: (0..n as u64).collect(),
        max_live: n,
        ..WorldTrace::default()
    };
    let mut brute = BruteWorld::new(&trace, false);
    for (i, m) in motions.iter().enumerate() {
        brute.apply(&WorldOp::Add {
            slot: i as u32,
            mesh: m.kind as u32,
        });
    }
    let checked = crate::demo::sample_frames(opt.frames, CHECKED);
    let frustum = camera(side).map_err(Failure::Input)?;

    let bar = if opt.terminal {
        ProgressBar::new(opt.frames as u64).with_style(
            ProgressStyle::with_template(
                "{prefix:>9} [{bar:32.cyan/blue}] {pos:>4}/{len} frames {elapsed:>4}",
            )
            .map_err(|e| Failure::Input(e.to_string()))?
            .progress_chars("=> "),
        )
    } else {
        ProgressBar::hidden()
    };
    bar.set_prefix("world");
    let mut row = WorldRow {
        objects: n,
        moving: moving.len(),
        frames: opt.frames,
        side,
        kinds: MESHES.iter().map(|m| m.to_string()).collect(),
        triangles: motions.iter().map(|m| meshes[m.kind].len()).sum(),
        build,
        ..WorldRow::default()
    };
    let mut report = ContactReport::default();
    let mut batch: Vec<(Handle, Affine3A)> = Vec::with_capacity(moving.len());
    let run_start = Instant::now();
    for f in 1..=opt.frames {
        batch.clear();
        for &i in &moving {
            motions[i].step(side);
            batch.push((handles[i], motions[i].pose()));
        }
        let t = Instant::now();
        world.set_poses(&batch).map_err(wrong)?;
        row.poses += t.elapsed();

        let t = Instant::now();
        world
            .contacts_into(ContactMode::All, &mut report)
            .map_err(wrong)?;
        row.contacts += t.elapsed();
        row.pairs += report.pairs.len();
        row.tri_pairs += report.triangles.len();
        add_counters(&mut row.counters, &report.counters);

        let frame_rays = rays(opt.seed, f, side);
        let t = Instant::now();
        let mut hits = Vec::with_capacity(RAYS);
        for r in &frame_rays {
            hits.push(world.ray_cast(r, Filter::ALL).map_err(wrong)?);
        }
        row.rays += t.elapsed();
        row.hits += hits.iter().flatten().count();

        let t = Instant::now();
        let visible = world.cull(&frustum, Filter::ALL).map_err(wrong)?;
        row.cull += t.elapsed();
        row.visible += visible.len();

        if checked[f - 1] {
            let t = Instant::now();
            let hits: Vec<Option<(u64, u32)>> = hits
                .iter()
                .map(|h| h.map(|h| (*world.get(h.object).expect("live"), h.triangle)))
                .collect();
            let got = (
                report.pairs.len(),
                report.triangles.len(),
                hits,
                ids(&world, &visible),
            );
            check_frame(&mut brute, &motions, &world, &frame_rays, &frustum, f, got)?;
            row.checked.push(f);
            row.brute += t.elapsed();
        }
        bar.inc(1);
    }
    bar.finish();
    if opt.terminal {
        eprintln!();
    } else {
        eprintln!(
            "{:>9}: {} frames ({} checked by the brute-force world) in {:.2} s",
            "world",
            opt.frames,
            row.checked.len(),
            run_start.elapsed().as_secs_f64()
        );
    }
    world.validate().map_err(wrong)?;

    if let Some(out) = opt.out {
        let hit = hit_triangles(&world, &report, &handles, &meshes, &motions);
        let drawn: Vec<Drawn<'_>> = motions
            .iter()
            .zip(hit)
            .map(|(m, hit)| Drawn {
                mesh: &meshes[m.kind],
                pose: m.pose(),
                kind: m.kind,
                hit,
            })
            .collect();
        let skip_back: Vec<bool> = meshes.iter().map(|m| closed_outward(m)).collect();
        let canvas: Canvas = world_frame(
            &format!(
                "world, frame {}: {} meshes, touching triangles in red",
                opt.frames, n
            ),
            &drawn,
            side,
            &row.kinds,
            &skip_back,
            &format!(
                "{} object pairs touch along {} triangle pairs",
                report.pairs.len(),
                report.triangles.len()
            ),
        );
        std::fs::create_dir_all(out)
            .map_err(|e| Failure::Input(format!("cannot create {}: {e}", out.display())))?;
        let p = out.join(format!("world.{}", if opt.svg { "svg" } else { "png" }));
        canvas.save(&p).map_err(Failure::Input)?;
        row.picture = Some(p);
    }
    Ok(row)
}

fn add_counters(sum: &mut WorldCounters, c: &WorldCounters) {
    sum.broad_pairs += c.broad_pairs;
    sum.filtered += c.filtered;
    sum.narrow_pairs += c.narrow_pairs;
    sum.coherent_pairs += c.coherent_pairs;
    sum.cut_starts += c.cut_starts;
    sum.cost.nv += c.cost.nv;
    sum.cost.np += c.cost.np;
    sum.cost.nu += c.cost.nu;
}

/// The payloads (object numbers) of `handles`, sorted.
fn ids(world: &World<u64>, handles: &[Handle]) -> Vec<u64> {
    let mut v: Vec<u64> = handles
        .iter()
        .map(|h| *world.get(*h).expect("live"))
        .collect();
    v.sort_unstable();
    v
}

/// The world's answers of one frame: contact pairs, triangle pairs, each ray's
/// first `(object, triangle)`, the visible objects.
type Answers = (usize, usize, Vec<Option<(u64, u32)>>, Vec<u64>);

/// Compares one frame's answers with the brute-force world's.
fn check_frame(
    brute: &mut BruteWorld<'_>,
    motions: &[Motion],
    world: &World<u64>,
    rays: &[Ray],
    frustum: &Frustum,
    f: usize,
    (pairs, tris, hits, visible): Answers,
) -> Result<(), Failure> {
    for (i, m) in motions.iter().enumerate() {
        brute.apply(&WorldOp::Pose {
            slot: i as u32,
            pose: m.pose(),
        });
    }
    let fail = |what: String| Err(Failure::Wrong(format!("world frame {f}: {what}")));
    let want = brute.apply(&WorldOp::Contacts);
    if want != Some(WorldAnswer::Contacts(pairs, Some(tris))) {
        return fail(format!(
            "the world finds `contacts {pairs} {tris}`, the brute-force world `{}`",
            want.map_or("nothing".into(), |a| a.to_string())
        ));
    }
    for (k, (r, got)) in rays.iter().zip(&hits).enumerate() {
        let want = brute.apply(&WorldOp::Ray(*r));
        if want != Some(WorldAnswer::Ray(*got)) {
            return fail(format!(
                "ray {k}: the world answers `{}`, the brute-force world `{}`",
                WorldAnswer::Ray(*got),
                want.map_or("nothing".into(), |a| a.to_string())
            ));
        }
    }
    let mut want: Vec<u64> = world
        .iter()
        .filter(|o| frustum.classify_sphere(&o.bounding_sphere) != Relation::Outside)
        .map(|o| *o.value)
        .collect();
    want.sort_unstable();
    if want != visible {
        return fail(format!(
            "the world culls to {} objects, every sphere against the frustum to {}",
            visible.len(),
            want.len()
        ));
    }
    Ok(())
}

/// Per object, which of its triangles touch another object in `report`.
fn hit_triangles(
    world: &World<u64>,
    report: &ContactReport,
    handles: &[Handle],
    meshes: &[Arc<TriMesh>],
    motions: &[Motion],
) -> Vec<Vec<bool>> {
    let mut hit: Vec<Vec<bool>> = motions
        .iter()
        .map(|m| vec![false; meshes[m.kind].len()])
        .collect();
    let number = |h: Handle| *world.get(h).expect("live") as usize;
    debug_assert!(handles.iter().enumerate().all(|(i, h)| number(*h) == i));
    for c in &report.pairs {
        let (a, b) = (number(c.a), number(c.b));
        for &(ta, tb) in report.triangles_of(c) {
            hit[a][ta as usize] = true;
            hit[b][tb as usize] = true;
        }
    }
    hit
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_scene_agrees_with_the_brute_force_world_on_every_frame() {
        let dir = std::env::temp_dir().join(format!("proxima-world-demo-{}", std::process::id()));
        let opt = Options {
            objects: 40,
            frames: 4,
            seed: 7,
            data: None,
            out: Some(&dir),
            svg: false,
            terminal: false,
        };
        let row = run(&opt).unwrap_or_else(|e| panic!("{e:?}"));
        assert_eq!(row.checked, [1, 3, 4]);
        assert_eq!(row.moving, 30);
        assert!(row.pairs > 0 && row.tri_pairs > row.pairs, "{row:?}");
        assert!(row.counters.coherent_pairs > 0, "resting pairs are skipped");
        assert!(
            row.hits > 0 && row.visible > 0 && row.visible <= 4 * 40,
            "{row:?}"
        );
        assert!(row.picture.as_ref().is_some_and(|p| p.exists()));
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn meshes_are_unit_sized_and_motions_stay_in_the_box() {
        let dir = data_dir(None).unwrap();
        let m = unit_mesh(&dir.join("teapot.obj")).unwrap();
        let (lo, hi) = m
            .vertices()
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), v| {
                (l.min(*v), h.max(*v))
            });
        assert!(((hi - lo).max_element() - 1.0).abs() < 1e-5);
        assert!(((hi + lo) * 0.5).abs().max_element() < 1e-5);
        let mut m = Motion {
            kind: 0,
            pos: Vec3::splat(1.0),
            vel: Vec3::new(-0.3, 0.2, 0.0),
            axis: Vec3::Z,
            angle: 0.0,
            spin: 0.1,
        };
        for _ in 0..100 {
            m.step(4.0);
            assert!(m.pos.cmpge(Vec3::splat(0.5)).all() && m.pos.cmple(Vec3::splat(3.5)).all());
        }
        assert!(data_dir(Some(Path::new("/nonexistent"))).is_err());
        assert_eq!(data_dir(Some(&dir)).unwrap(), dir);
        assert!(matches!(
            run(&Options {
                objects: 3,
                frames: 1,
                seed: 1,
                data: Some(Path::new("/nonexistent")),
                out: None,
                svg: false,
                terminal: false
            }),
            Err(Failure::Input(_))
        ));
    }
}

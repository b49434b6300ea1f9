//! `proxima collide --distance` and `--within D` against a brute force over all
//! triangle pairs (the library's `triangle_distance` on the posed triangles),
//! with every bounding volume; `--within` agreeing with the distance on every
//! pose, margins equal to the distance included.

mod common;

use common::{proxima, Out};
use proxima::glam::{Affine3A, Mat3, Quat, Vec3};
use proxima::narrow::{triangle_distance, TriMesh};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::path::PathBuf;

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/");
const BVS: [&str; 6] = ["aabb", "kdop14", "kdop18", "kdop26", "obb", "sphere"];

/// A file in the test temp dir named after `name`.
fn temp(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("{name}-{}", std::process::id()))
}

/// Writes `m` as an OBJ file; returns its path.
fn write_obj(name: &str, m: &TriMesh) -> String {
    let mut s = String::new();
    for v in m.vertices() {
        s += &format!("v {} {} {}\n", v.x, v.y, v.z);
    }
    for t in m.triangles() {
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    let p = temp(&format!("{name}.obj"));
    std::fs::write(&p, s).unwrap();
    p.to_str().unwrap().to_string()
}

/// The closed unit cube `[0, 1]³`, scaled by `s`.
fn cube(s: f32) -> TriMesh {
    let v = (0..8)
        .map(|i| Vec3::new((i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2 & 1) as f32) * s)
        .collect();
    let t = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    TriMesh::new(v, t).unwrap()
}

/// A tetrahedron with a sliver face, around the origin.
fn tetra() -> TriMesh {
    let v = vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.7, 0.1, 0.0),
        Vec3::new(0.2, 0.6, 0.05),
        Vec3::new(0.3, 0.3, 0.8),
    ];
    TriMesh::new(v, vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]]).unwrap()
}

/// The pose file's 12 numbers (row-major rotation, translation) of `r`, `t`,
/// and the pose the CLI reads from them (the same construction as its parser).
fn pose_line(r: Mat3, t: Vec3) -> (String, Affine3A) {
    let rows = [r.row(0), r.row(1), r.row(2)];
    let nums: Vec<f32> = rows
        .iter()
        .flat_map(|row| row.to_array())
        .chain(t.to_array())
        .collect();
    let line = nums.iter().map(|x| format!("{x}")).collect::<Vec<_>>();
    let m = Mat3::from_cols_array(&[
        nums[0], nums[3], nums[6], nums[1], nums[4], nums[7], nums[2], nums[5], nums[8],
    ]);
    (line.join(" "), Affine3A::from_mat3_translation(m, t))
}

/// The minimum over all triangle pairs of `a` moved by `pose` and `b`.
fn brute(a: &TriMesh, pose: &Affine3A, b: &TriMesh) -> f64 {
    let moved: Vec<[Vec3; 3]> = (0..a.len())
        .map(|i| a.triangle(i).map(|v| pose.transform_point3(v)))
        .collect();
    let mut best = f64::INFINITY;
    for ta in &moved {
        for j in 0..b.len() {
            best = best.min(triangle_distance(ta, &b.triangle(j)).distance);
        }
    }
    best
}

fn run_ok(args: &[&str]) -> Vec<String> {
    let out: Out = proxima(args);
    assert_eq!(out.code, 0, "{args:?}: {}", out.stderr);
    out.stdout.lines().map(str::to_string).collect()
}

/// Checks `--distance` (every volume) and `--within` (margins at, just below
/// and between the poses' distances, and 0) for `a` and `b` over `poses`.
fn check(name: &str, a_path: &str, b_path: &str, poses: &[(String, Affine3A)]) {
    let a = proxima::io::load(a_path).unwrap();
    let b = proxima::io::load(b_path).unwrap();
    let file = temp(&format!("{name}.poses"));
    let text: String = poses.iter().map(|(l, _)| format!("{l}\n")).collect();
    std::fs::write(&file, format!("# {name}\n{text}")).unwrap();
    let file = file.to_str().unwrap();
    let wants: Vec<f64> = poses.iter().map(|(_, p)| brute(&a, p, &b)).collect();
    assert!(wants.contains(&0.0) && wants.iter().any(|&d| d > 0.0));

    for bv in BVS {
        let lines = run_ok(&[
            "collide",
            a_path,
            b_path,
            "--poses",
            file,
            "--distance",
            "--bv",
            bv,
        ]);
        assert_eq!(lines.len(), poses.len(), "{name} {bv}");
        for (k, (line, &want)) in lines.iter().zip(&wants).enumerate() {
            let ctx = format!("{name} {bv} pose {k}: '{line}', brute force {want}");
            let f: Vec<&str> = line.split(' ').collect();
            assert_eq!((f.len(), f[0]), (4, "distance"), "{ctx}");
            let d: f64 = f[1].parse().unwrap();
            let (i, j): (usize, usize) = (f[2].parse().unwrap(), f[3].parse().unwrap());
            // 9 significant digits: within half a unit of the ninth.
            assert_eq!(d == 0.0, want == 0.0, "{ctx}");
            assert!((d - want).abs() <= 5e-9 * want, "{ctx}");
            let mantissa = f[1].split('e').next().unwrap();
            let digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
            assert!(digits.trim_start_matches('0').len() <= 9, "{ctx}");
            // The witness triangles are a nearest pair.
            let ta = a.triangle(i).map(|v| poses[k].1.transform_point3(v));
            assert_eq!(
                triangle_distance(&ta, &b.triangle(j)).distance,
                want,
                "{ctx}"
            );
        }
    }

    // Margins: each distance exactly (closed: within), the f64 just below it,
    // half way to the next, and 0.
    let mut margins = vec![0.0f64];
    let mut sorted = wants.clone();
    sorted.sort_by(f64::total_cmp);
    sorted.dedup();
    for w in sorted.windows(2) {
        margins.push(0.5 * (w[0] + w[1]));
    }
    for &d in &sorted {
        margins.push(d);
        if d > 0.0 {
            margins.push(f64::from_bits(d.to_bits() - 1));
        }
    }
    margins.push(2.0 * sorted[sorted.len() - 1]);
    for (n, m) in margins.iter().enumerate() {
        // Every volume over the margins; the margin as Rust prints it (exact).
        let bv = BVS[n % BVS.len()];
        let m_text = format!("{m}");
        let lines = run_ok(&[
            "collide", a_path, b_path, "--poses", file, "--within", &m_text, "--bv", bv,
        ]);
        assert_eq!(lines.len(), poses.len());
        for (k, (line, &want)) in lines.iter().zip(&wants).enumerate() {
            let expect = format!("within {}", (want <= *m) as u8);
            assert_eq!(
                *line, expect,
                "{name} {bv} margin {m_text} pose {k} (distance {want})"
            );
        }
    }
    // --stats appends the counters to both forms.
    for q in [&["--distance"][..], &["--within", "1"]] {
        let mut args = vec!["collide", a_path, b_path, "--poses", file, "--stats"];
        args.extend_from_slice(q);
        for line in run_ok(&args) {
            let f: Vec<&str> = line.split(' ').collect();
            let n = f.len();
            assert!(n >= 8, "{line}");
            assert_eq!([f[n - 6], f[n - 4], f[n - 2]], ["nv", "np", "nu"], "{line}");
            for k in [n - 5, n - 3, n - 1] {
                assert!(f[k].parse::<u64>().is_ok(), "{line}");
            }
        }
    }
    let _ = std::fs::remove_file(file);
}

/// Random rotations with translations spread around `scale` (some intersecting
/// poses, some apart), after the given fixed poses.
fn random_poses(
    seed: u64,
    n: usize,
    scale: f32,
    fixed: &[(Mat3, Vec3)],
) -> Vec<(String, Affine3A)> {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut out: Vec<_> = fixed.iter().map(|&(r, t)| pose_line(r, t)).collect();
    for _ in 0..n {
        let q = Quat::from_xyzw(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        )
        .normalize();
        let t = Vec3::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        ) * scale
            * rng.gen_range(0.2f32..2.5);
        out.push(pose_line(Mat3::from_quat(q), t));
    }
    out
}

#[test]
fn small_meshes_match_brute_force() {
    let (cube_path, tetra_path) = (write_obj("cube", &cube(1.0)), write_obj("tetra", &tetra()));
    let quarter = Mat3::from_cols(Vec3::Y, -Vec3::X, Vec3::Z);
    let i = Mat3::IDENTITY;
    let fixed = [
        (i, Vec3::ZERO),                // the same cube: intersecting
        (i, Vec3::new(1.0, 0.0, 0.0)),  // a shared face: touching, 0
        (i, Vec3::new(1.0, 1.0, 1.0)),  // a shared corner
        (i, Vec3::new(1.5, 0.25, 0.0)), // 0.5 apart
        (quarter, Vec3::new(3.0, 0.5, 2.0)),
        (i, Vec3::new(0.0, 0.0, -1.0e-3)), // just intersecting
        (i, Vec3::new(0.0, 0.0, 1.0 + 1.0 / 1024.0)), // 2⁻¹⁰ above
    ];
    check(
        "cubes",
        &cube_path,
        &cube_path,
        &random_poses(1, 14, 1.5, &fixed),
    );
    check(
        "tetra-cube",
        &tetra_path,
        &cube_path,
        &random_poses(2, 14, 1.2, &fixed),
    );
    let _ = std::fs::remove_file(cube_path);
    let _ = std::fs::remove_file(tetra_path);
}

#[test]
fn rob_against_rob_and_a_cube_match_brute_force() {
    let rob = format!("{DATA}rob.obj");
    let big_cube = write_obj("big-cube", &cube(400.0));
    let i = Mat3::IDENTITY;
    let fixed = [(i, Vec3::ZERO), (i, Vec3::new(1500.0, 0.0, 0.0))];
    check("rob-rob", &rob, &rob, &random_poses(3, 10, 900.0, &fixed));
    check(
        "rob-cube",
        &rob,
        &big_cube,
        &random_poses(4, 10, 900.0, &fixed),
    );
    let _ = std::fs::remove_file(big_cube);
}

#[test]
fn bad_distance_input_is_one_line_and_exit_2() {
    let rob = format!("{DATA}rob.obj");
    let huge = write_obj("huge-cube", &cube(3e38));
    let far = temp("far.poses");
    // Moves the huge cube's vertices beyond the f32 range.
    std::fs::write(&far, "1 0 0 0 1 0 0 0 1 3e38 0 0\n").unwrap();
    let far = far.to_str().unwrap();
    for args in [
        vec!["collide", &rob, &rob, "--within"],
        vec!["collide", &rob, &rob, "--within", "-1"],
        vec!["collide", &rob, &rob, "--within", "NaN"],
        vec!["collide", &rob, &rob, "--within", "inf"],
        vec!["collide", &rob, &rob, "--within", "1e999"],
        vec!["collide", &rob, &rob, "--within", "one"],
        vec!["collide", &rob, &rob, "--distance", "--first"],
        vec!["collide", &rob, &rob, "--within", "1", "--distance"],
        vec!["collide", &huge, &rob, "--distance", "--poses", far],
        vec!["collide", &huge, &rob, "--within", "2", "--poses", far],
    ] {
        let out = proxima(&args);
        assert_eq!(out.code, 2, "{args:?}: {}", out.stderr);
        assert!(out.stdout.is_empty(), "{args:?}: {}", out.stdout);
        assert_eq!(out.stderr.trim_end().lines().count(), 1, "{}", out.stderr);
        assert!(
            out.stderr.starts_with("proxima collide: "),
            "{}",
            out.stderr
        );
        assert!(!out.stderr.contains("panicked"), "{}", out.stderr);
    }
    let _ = std::fs::remove_file(far);
    let _ = std::fs::remove_file(huge);
}

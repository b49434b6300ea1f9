//! Bad input at the command line: one line on stderr naming what and where, exit
//! code 2, never a panic message; and the regression traces found by fuzzing.

mod common;

use common::{proxima, replay};

/// One line, no panic banner.
fn one_clean_line(stderr: &str) {
    assert_eq!(stderr.trim_end().lines().count(), 1, "stderr: {stderr}");
    assert!(!stderr.contains("panicked"), "stderr: {stderr}");
    assert!(!stderr.contains("internal error"), "stderr: {stderr}");
}

#[test]
fn bad_trace_lines_are_one_line_errors_with_exit_2() {
    for (text, what) in [
        ("insert 1 0 0 0 nan\n", "line 1"),
        ("insert 1 0 0 0 1\ninsert 1 0 0 0 1\n", "line 2"),
        ("insert 1 0 0 0 -1\n", "line 1"),
        ("move 7 0 0 0 1\n", "line 1"),
        ("ray 0 0 0 0 0 0 1\n", "line 1"),
        ("aabb 1 1 1 0 0 0\n", "line 1"),
        ("insert 1 0 0 0 1e39\n", "line 1"),
        ("\u{0}\u{ff}garbage\n", "line 1"),
    ] {
        let out = replay("bad", text, &["--index", "all"]);
        assert_eq!(out.code, 2, "{text:?}: {}", out.stderr);
        one_clean_line(&out.stderr);
        assert!(out.stderr.contains(what), "{text:?}: {}", out.stderr);
    }
}

#[test]
fn missing_files_and_garbage_meshes_exit_2() {
    let out = proxima(&["replay", "/nonexistent/x.trace"]);
    assert_eq!(out.code, 2);
    one_clean_line(&out.stderr);
    assert!(out.stderr.contains("/nonexistent/x.trace"));

    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let stl = dir.join(format!("lying-{}.stl", std::process::id()));
    // A binary STL header promising 1000 triangles, with one.
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&1000u32.to_le_bytes());
    b.extend_from_slice(&[0u8; 50]);
    std::fs::write(&stl, &b).unwrap();
    let p = stl.to_str().unwrap();
    let out = proxima(&["collide", p, p]);
    assert_eq!(out.code, 2, "{}", out.stderr);
    one_clean_line(&out.stderr);
    assert!(
        out.stderr.contains(p) && out.stderr.contains("byte offset"),
        "{}",
        out.stderr
    );
    let _ = std::fs::remove_file(&stl);

    let out = proxima(&["collide", "/nonexistent/a.obj", "/nonexistent/b.obj"]);
    assert_eq!(out.code, 2);
    one_clean_line(&out.stderr);
}

/// Found by the `replay` fuzz target: a centre near 2e38 made the world box's
/// centre overflow (`(min + max) / 2`), so the octree refused the scene.
#[test]
fn replay_octree_world_center_overflow() {
    let text = "# W# .531255\ninsert 22 47.5625 455.56 2130.64e35  57\nsphere 0 0 0 1\npairs\n";
    let out = replay("huge", text, &["--index", "all"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert_eq!(out.stdout, "sphere 0\npairs 0\n");
}

/// Found by the replay fuzzer: a radius near f32::MAX and a world wider than
/// f32's range. Every grid used to refuse the scene (cell size 2r or the world's
/// extent overflowed to ∞); now each one takes it and agrees with brute force.
#[test]
fn replay_radius_near_f32_max_every_index_accepts() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/found/replay-radius-near-f32-max"
    );
    let out = proxima(&["replay", path, "--index", "all", "--check"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
}

/// Objects at ±1e30 with radii up to 1e30: every index agrees with brute force.
#[test]
fn replay_extreme_coordinates_all_indices_agree() {
    let text = "insert 1 1e30 0 0 0\ninsert 2 -1e30 0 0 1e30\ninsert 3 0 0 0 1e30\n\
                insert 4 5 5 5 0\npairs\nsphere 1e30 0 0 0\nray -1e30 0 0 1 0 0 1e31\n\
                aabb -1 -1 -1 1 1 1\nmove 4 1e30 1e30 1e30 1\npairs\nremove 3\npairs\n";
    let out = replay("extreme", text, &["--index", "all"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert_eq!(
        out.stdout,
        "pairs 3\nsphere 2\nray 3 2\naabb 2\npairs 2\npairs 0\n"
    );
}

/// Every command's bad options and values: exit 2 and one line naming the
/// problem, never a panic; a run that checks and passes exits 0.
#[test]
fn bad_options_of_every_command_exit_2_with_one_line() {
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/");
    let mesh = format!("{data}rob.obj");
    let mesh = mesh.as_str();
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let poses = dir.join(format!("bad-poses-{}.txt", std::process::id()));
    std::fs::write(&poses, "1 2 nan\n").unwrap();
    let poses = poses.to_str().unwrap();
    let trace = common::write_trace("ok", "insert 1 0 0 0 1\ninsert 2 1 0 0 1\npairs\n");
    let trace = trace.to_str().unwrap();
    for args in [
        vec!["--no-such-flag"],
        vec!["replay"],
        vec!["replay", trace, "--index", "no-such-index"],
        vec!["collide", mesh],
        vec!["collide", mesh, mesh, "--bv", "cube"],
        vec!["collide", mesh, mesh, "--split", "nope"],
        vec!["collide", mesh, mesh, "--leaf", "0"],
        vec!["collide", mesh, mesh, "--leaf", "-3"],
        vec!["collide", mesh, mesh, "--rotation", "sideways"],
        vec!["collide", mesh, mesh, "--poses", "/nonexistent/poses.txt"],
        vec!["collide", mesh, mesh, "--poses", poses],
        vec!["collide", mesh, mesh, "--bogus"],
        vec!["render", "/nonexistent/x.trace"],
        vec!["demo", "--objects", "many"],
    ] {
        let out = proxima(&args);
        assert_eq!(out.code, 2, "{args:?}: {}", out.stderr);
        one_clean_line(&out.stderr);
    }
    let out = proxima(&["replay", trace, "--index", "all", "--check"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let _ = std::fs::remove_file(poses);
}

//! `proxima demo` (and the no-command default), `proxima render`, and the CLI's
//! handling of bad flags and missing files, on small inputs.

mod common;

use common::{indices::NAMES, proxima};
use std::path::{Path, PathBuf};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data");
const TRACES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/traces");

/// A fresh, empty output directory for one test.
fn out_dir(name: &str) -> PathBuf {
    let d =
        PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Decodes a PNG and checks it is a real picture: a sensible size and more than
/// one colour (something was drawn on the white background).
fn check_png(p: &Path) {
    let file = std::fs::File::open(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .expect("a PNG header");
    let mut buf = vec![0; reader.output_buffer_size().expect("a size")];
    let info = reader.next_frame(&mut buf).expect("PNG data decodes");
    assert!(info.width >= 300 && info.height >= 300, "{info:?}");
    let px = info.color_type.samples();
    let first = &buf[..px];
    let distinct = buf[..info.buffer_size()]
        .chunks(px)
        .filter(|c| *c != first)
        .count();
    assert!(distinct > 1000, "{}: almost blank", p.display());
}

/// The picture paths printed after `pictures:` (demo) or `wrote ` (render).
fn printed_paths(stdout: &str) -> Vec<PathBuf> {
    let mut v = Vec::new();
    let mut in_list = false;
    for line in stdout.lines() {
        if let Some(p) = line.strip_prefix("wrote ") {
            v.push(PathBuf::from(p));
        } else if line == "pictures:" {
            in_list = true;
        } else if in_list {
            v.push(PathBuf::from(line.trim()));
        }
    }
    v
}

#[test]
fn demo_prints_a_table_with_equal_pairs_and_writes_pngs() {
    let dir = out_dir("demo-table");
    let o = proxima(&[
        "demo",
        "--objects",
        "1500",
        "--frames",
        "3",
        "--world-objects",
        "30",
        "--world-frames",
        "3",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(
        o.stdout.starts_with("W1 uniform: 1500 spheres"),
        "{}",
        o.stdout
    );
    // One row per registered index; the pairs column is the same for all.
    let mut pairs = Vec::new();
    for name in NAMES {
        let row = o
            .stdout
            .lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .unwrap_or_else(|| panic!("no row for {name}:\n{}", o.stdout));
        let cols: Vec<&str> = row.split_whitespace().collect();
        assert!(cols.len() >= 8, "{row}");
        pairs.push(cols[6].to_string());
        for c in &cols[2..8] {
            c.parse::<f64>().unwrap_or_else(|_| panic!("{row}"));
        }
    }
    assert!(pairs.iter().all(|p| *p == pairs[0]), "{pairs:?}");
    assert!(pairs[0].parse::<f64>().unwrap() > 0.0);
    assert!(o.stdout.contains("<- fastest"));
    assert!(o.stdout.contains("exactly the brute-force pair count"));
    // The world scene's table, checked against the brute-force world.
    assert!(
        o.stdout.contains("world: 30 meshes (bunny.obj"),
        "{}",
        o.stdout
    );
    for stage in ["poses ", "contacts ", "rays ", "cull "] {
        assert!(
            o.stdout.lines().any(|l| l.starts_with(stage)),
            "{stage}: {}",
            o.stdout
        );
    }
    assert!(o
        .stdout
        .contains("checked frames 1, 2, 3: the brute-force world"));
    // Not a terminal: one plain progress line per index and one for the world.
    assert_eq!(o.stderr.lines().count(), NAMES.len() + 1, "{}", o.stderr);
    assert!(o.stderr.lines().last().unwrap().contains("world: 3 frames"));
    let paths = printed_paths(&o.stdout);
    assert_eq!(paths.len(), 4, "{}", o.stdout);
    assert!(paths[3].ends_with("world.png"));
    for p in &paths {
        assert!(p.starts_with(&dir) && p.extension().unwrap() == "png");
        check_png(p);
    }
}

#[test]
fn demo_json_parses_for_each_scene() {
    for scene in ["uniform", "flat", "clustered", "mixed"] {
        let o = proxima(&[
            "demo",
            "--scene",
            scene,
            "--objects",
            "800",
            "--frames",
            "2",
            "--json",
            "--no-pictures",
            "--seed",
            "3",
            "--world-objects",
            if scene == "uniform" { "20" } else { "0" },
            "--world-frames",
            "2",
        ]);
        assert_eq!(o.code, 0, "{}", o.stderr);
        let v: serde_json::Value = serde_json::from_str(&o.stdout).expect("one JSON object");
        assert_eq!(v["scene"], scene);
        assert_eq!(v["objects"], 800);
        let rows = v["indices"].as_array().unwrap();
        assert_eq!(rows.len(), NAMES.len());
        let p0 = rows[0]["pairs_per_frame"].as_f64().unwrap();
        for r in rows {
            assert_eq!(r["pairs_per_frame"].as_f64().unwrap(), p0, "{r}");
            assert_eq!(r["pair_counts"].as_array().unwrap().len(), 2);
            assert!(r["bytes_per_object"].as_f64().unwrap() > 0.0);
        }
        assert!(v["pictures"].as_array().unwrap().is_empty());
        assert!(NAMES.contains(&v["fastest"].as_str().unwrap()));
        if scene == "uniform" {
            let w = &v["world"];
            assert_eq!(w["objects"], 20);
            assert_eq!(w["frames"], 2);
            assert_eq!(w["checked_frames"], serde_json::json!([1, 2]));
            assert!(w["contacts_ms_per_frame"].as_f64().unwrap() >= 0.0);
            assert!(w["picture"].is_null());
        } else {
            assert!(v["world"].is_null());
        }
    }
}

#[test]
fn no_command_runs_the_demo_with_its_options_and_one_index() {
    let dir = out_dir("demo-default");
    let o = proxima(&[
        "--objects",
        "500",
        "--frames",
        "2",
        "--index",
        "octree",
        "--world-objects",
        "8",
        "--world-frames",
        "1",
        "--svg",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    // The chosen index, and brute force to check it.
    assert!(o.stdout.lines().any(|l| l.starts_with("octree ")));
    assert!(o.stdout.lines().any(|l| l.starts_with("brute ")));
    assert!(!o.stdout.lines().any(|l| l.starts_with("grid2d ")));
    let paths = printed_paths(&o.stdout);
    assert_eq!(paths.len(), 4);
    for p in paths {
        let svg = std::fs::read_to_string(&p).unwrap();
        assert!(
            svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
            "{}",
            p.display()
        );
    }
}

#[test]
fn render_draws_a_trace_end_state() {
    let dir = out_dir("render-trace");
    let trace = format!("{TRACES}/w3-sample.trace");
    let o = proxima(&["render", &trace, "--out", dir.to_str().unwrap()]);
    assert_eq!(o.code, 0, "{}", o.stderr);
    let paths = printed_paths(&o.stdout);
    assert_eq!(paths.len(), 2, "{}", o.stdout);
    for p in &paths {
        check_png(p);
    }
}

#[test]
fn render_collide_counts_pairs_like_collide_and_draws_them() {
    let dir = out_dir("render-collide");
    let (a, b) = (format!("{DATA}/rob.obj"), format!("{DATA}/env.obj"));
    let pose = "1 0 0 0 1 0 0 0 1 -1500 -1500 450";
    let poses = out_dir("render-pose-file").with_extension("txt");
    std::fs::write(&poses, format!("{pose}\n")).unwrap();
    let reference = proxima(&["collide", &a, &b, "--poses", poses.to_str().unwrap()]);
    assert_eq!(reference.code, 0, "{}", reference.stderr);
    let mut args = vec![
        "render",
        "--collide",
        &a,
        &b,
        "--out",
        dir.to_str().unwrap(),
        "--pose",
    ];
    args.extend(pose.split(' '));
    let o = proxima(&args);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert_eq!(o.stdout.lines().next(), reference.stdout.lines().next());
    assert_ne!(o.stdout.lines().next(), Some("pairs 0"));
    let paths = printed_paths(&o.stdout);
    assert_eq!(paths.len(), 1);
    check_png(&paths[0]);
}

/// Every bad invocation: exit code 2, exactly one line on stderr, no panic.
#[test]
fn bad_flags_and_missing_files_give_one_line_and_exit_2() {
    let missing = format!("{DATA}/no-such-mesh.obj");
    let rob = format!("{DATA}/rob.obj");
    let cases: Vec<Vec<&str>> = vec![
        vec!["--bogus"],
        vec!["demo", "--objects", "x"],
        vec!["demo", "--objects", "0"],
        vec!["demo", "--frames", "0"],
        vec!["demo", "--scene", "cube"],
        vec!["demo", "--index", "rtree"],
        vec!["demo", "--world-objects", "100000"],
        vec!["demo", "--world-frames", "0"],
        vec![
            "demo",
            "--objects",
            "10",
            "--frames",
            "1",
            "--no-pictures",
            "--data",
            "/no/such/dir",
        ],
        vec!["render"],
        vec!["render", "/no/such.trace"],
        vec!["render", "--collide", &rob, &missing],
        vec!["render", "--collide", &rob, &rob, "--pose", "1", "2"],
        vec![
            "render",
            "--collide",
            &rob,
            &rob,
            "--pose",
            "2",
            "0",
            "0",
            "0",
            "1",
            "0",
            "0",
            "0",
            "1",
            "0",
            "0",
            "0",
        ],
        vec!["replay", "/no/such.trace"],
        vec!["collide", &rob],
        vec!["frobnicate"],
    ];
    for args in cases {
        let o = proxima(&args);
        assert_eq!(o.code, 2, "{args:?}: {}{}", o.stdout, o.stderr);
        assert_eq!(o.stderr.lines().count(), 1, "{args:?}: {}", o.stderr);
        assert!(!o.stderr.contains("panicked"), "{args:?}");
    }
}

//! `proxima replay` on small hand-checked traces, bad input, and the
//! `--index all` / `--check` modes.

mod common;

use common::{indices::NAMES, proxima, replay};

/// Four spheres on the x axis; answers worked out by hand in the comments.
const SCENE: &str = "\
# id x y z r
insert 1 0 0 0 1
insert 2 2 0 0 1      # touches 1 (distance 2 = 1 + 1)
insert 3 5 0 0 1      # 3 from sphere 2: apart
insert 4 0 0 0 0.5    # inside 1
pairs                 # (1,2) (1,4)
sphere 3.5 0 0 0.5    # touches 2 and 3 (distance 1.5 = 0.5 + 1)
aabb 1.5 -1 -1 4 1 1  # 2 inside, 3 touches x = 4; 1 is 0.5 away
ray -10 0 0 1 0 0 100 # 1 at t=9, 4 at 9.5, 2 at 11, 3 at 14
ray -10 0 0 1 0 0 9   # only 1, entered exactly at TMAX
ray -10 0 0 1 0 0 8.9 # nothing
ray -10 0 0 2 0 0 4.5 # t in units of dir: 1 at 4.5, 4 at 4.75 > TMAX
ray 5 0 0 -1 0 0 100  # origin inside 3 (t=0): 3 first, then 2, 1, 4
ray 0 0 0 0 1 0 0     # origin inside 1 and 4, both t=0: the smaller id
frustum 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1   # box [-1,1]x[-1,1]x[0,1]: 1, 4, 2 touches
frustum 1 0 0 0 0 1 0 0 0 0 1 0 -5 0 0 1  # translated to x in [4,6]: only 3
move 3 0 0 0 1
pairs                 # (1,2) (1,3) (1,4) (2,3) (3,4)
remove 1
pairs                 # (2,3) (3,4)
insert 1 100 100 100 1
sphere 100 100 102 1  # touches the re-inserted 1
";

const SCENE_OUT: &str = "\
pairs 2
sphere 2
aabb 2
ray 4 1
ray 1 1
ray 0 -
ray 1 1
ray 4 3
ray 2 1
frustum 3
frustum 1
pairs 5
pairs 2
sphere 1
";

#[test]
fn every_index_gives_the_hand_computed_answers() {
    for name in NAMES {
        let out = replay("scene", SCENE, &["--index", name]);
        assert_eq!(out.code, 0, "{name}: {}", out.stderr);
        assert_eq!(out.stdout, SCENE_OUT, "{name}");
    }
}

#[test]
fn ray_ties_go_to_the_smaller_user_id_not_the_first_inserted() {
    // Two equal spheres: 20 is inserted first (smaller handle), 15 has the smaller id.
    let t = "insert 20 0 10 0 1\ninsert 15 0 10 0 1\nray -10 10 0 1 0 0 100\n\
             ray 0 10 0 0 0 1 1\nray 0 20 0 0 1 0 100\n";
    for name in NAMES {
        let out = replay("ties", t, &["--index", name]);
        assert_eq!(out.code, 0, "{name}: {}", out.stderr);
        assert_eq!(out.stdout, "ray 2 15\nray 2 15\nray 0 -\n", "{name}");
    }
}

#[test]
fn all_and_check_agree_and_print_brute_answers() {
    for args in [vec!["--index", "all"], vec!["--index", "all", "--check"]] {
        let out = replay("all", SCENE, &args);
        assert_eq!(out.code, 0, "{args:?}: {}", out.stderr);
        assert_eq!(out.stdout, SCENE_OUT);
    }
    for name in NAMES {
        let out = replay("check", SCENE, &["--index", name, "--check"]);
        assert_eq!(out.code, 0, "{name}: {}", out.stderr);
        assert_eq!(out.stdout, SCENE_OUT);
    }
}

#[test]
fn time_adds_only_comment_lines() {
    let out = replay("time", SCENE, &["--index", "all", "--time"]);
    assert_eq!(out.code, 0);
    let answers: String = out
        .stdout
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_eq!(answers, SCENE_OUT);
    for name in NAMES {
        assert!(
            out.stdout.contains(&format!("# {name:<10} pairs")),
            "{}",
            out.stdout
        );
    }
}

/// A bad trace: exit 2, one `line N:` message on stderr, no output, no panic.
fn assert_bad(text: &str, line: usize, what: &str) {
    for name in NAMES {
        let out = replay("bad", text, &["--index", name]);
        assert_eq!(out.code, 2, "{text:?}: {}", out.stderr);
        assert!(!out.stderr.contains("panicked"), "{}", out.stderr);
        assert_eq!(out.stderr.lines().count(), 1, "{}", out.stderr);
        let tag = format!("line {line}: ");
        assert!(out.stderr.contains(&tag), "{text:?}: {}", out.stderr);
        assert!(out.stderr.contains(what), "{text:?}: {}", out.stderr);
        assert!(out.stdout.is_empty(), "{}", out.stdout);
    }
}

#[test]
fn malformed_lines_stop_with_exit_2_and_the_line_number() {
    let ok = "insert 1 0 0 0 1\n# fine\n";
    let cases: &[(&str, &str)] = &[
        ("jump 1 2 3", "unknown command 'jump'"),
        ("insert 2 0 0 0", "insert expects 5 fields"),
        ("insert 2 0 0 0 1 7", "insert expects 5 fields"),
        ("pairs now", "pairs takes no fields"),
        ("sphere 0 0 0", "sphere expects 4 fields"),
        ("ray 0 0 0 1 0 0", "ray expects 7 fields"),
        ("frustum 1 0 0 0", "frustum expects 16 fields"),
        ("insert 2 0 NaN 0 1", "not finite"),
        ("move 1 0 0 inf 1", "not finite"),
        ("sphere 0 0 0 1e40", "not finite"),
        ("insert 2 0 0 0 -1", "negative radius"),
        ("sphere 0 0 0 -0.5", "negative radius"),
        ("insert 1 5 5 5 1", "id 1 is already present"),
        ("move 9 0 0 0 1", "unknown id 9"),
        ("remove 9", "unknown id 9"),
        ("insert x 0 0 0 1", "bad id 'x'"),
        ("insert -3 0 0 0 1", "bad id '-3'"),
        ("sphere 0 0 zero 1", "bad number 'zero'"),
        ("ray 0 0 0 1 0 0 -1", "max_t"),
        ("ray 0 0 0 1 0 0 nan", "TMAX is not finite"),
        ("ray 0 0 0 0 0 0 5", "zero"),
        ("aabb 1 0 0 0 1 1", "min exceeds max"),
    ];
    for (bad, what) in cases {
        assert_bad(&format!("{ok}{bad}\npairs\n"), 3, what);
    }
    // An id removed is unknown afterwards.
    assert_bad("insert 1 0 0 0 1\nremove 1\nremove 1\n", 3, "unknown id 1");
}

#[test]
fn missing_file_and_bad_options_exit_2_in_one_line() {
    let out = proxima(&["replay", "/nonexistent/dir/scene.trace"]);
    assert_eq!(out.code, 2);
    assert_eq!(out.stderr.lines().count(), 1, "{}", out.stderr);
    assert!(out.stderr.contains("/nonexistent/dir/scene.trace"));
    assert!(!out.stderr.contains("panicked"));

    let out = replay("opt", "pairs\n", &["--index", "no-such-index"]);
    assert_eq!(out.code, 2);
    assert!(out.stderr.contains("unknown index 'no-such-index'"));

    assert_eq!(proxima(&["frobnicate"]).code, 2);
    assert_eq!(proxima(&["replay"]).code, 2);
}

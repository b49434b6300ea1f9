//! `proxima world`: the shared world traces against their `.expected` files by
//! the rules of `shared/traces/world/check_world.py` (ported), for every index
//! and every bounding volume, with and without `--first`; `--check` against the
//! brute-force world; `--time`; bad input (exit 2, one `FILE: line N:` line).

mod common;

use common::{indices::NAMES, proxima, write_trace, Out};
use std::path::PathBuf;

fn world_dir() -> PathBuf {
    PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/traces/world"
    ))
}

fn mesh(name: &str) -> String {
    world_dir()
        .join("meshes")
        .join(format!("small-{name}.obj"))
        .to_str()
        .unwrap()
        .to_string()
}

/// One expectation line of a world `.expected` file.
#[derive(Debug, PartialEq)]
enum Exp {
    /// `contacts P SP T ST`.
    Contacts(i64, i64, i64, i64),
    /// `contacts-first P SP`.
    First(i64, i64),
    /// `ray ID TRI`, `ray -` (`None`) or `ray *` (`Some(None)` never: see `AnyRay`).
    Ray(Option<(i64, i64)>),
    /// `ray *`: any answer.
    AnyRay,
    /// `sphere K SK`.
    Sphere(i64, i64),
}

/// The expectations used with (`first`) or without `--first`, as
/// `check_world.py` selects them.
fn expected(text: &str, first: bool) -> Vec<Exp> {
    let mut rows = Vec::new();
    for line in text.lines() {
        let t: Vec<&str> = line.split_whitespace().collect();
        if t.is_empty() || t[0].starts_with('#') {
            continue;
        }
        let n = |i: usize| t[i].parse::<i64>().expect("numeric expectation");
        match (t[0], t.len()) {
            ("contacts", 5) => {
                if !first {
                    rows.push(Exp::Contacts(n(1), n(2), n(3), n(4)));
                }
            }
            ("contacts-first", 3) => {
                if first {
                    rows.push(Exp::First(n(1), n(2)));
                }
            }
            ("ray", 2) if t[1] == "-" => rows.push(Exp::Ray(None)),
            ("ray", 2) if t[1] == "*" => rows.push(Exp::AnyRay),
            ("ray", 3) => rows.push(Exp::Ray(Some((n(1), n(2))))),
            ("sphere", 3) => rows.push(Exp::Sphere(n(1), n(2))),
            _ => panic!("malformed expectation: {line}"),
        }
    }
    rows
}

/// Whether the result line `got` satisfies `e` (only the first words count).
fn check(e: &Exp, got: &str) -> bool {
    let t: Vec<&str> = got.split_whitespace().collect();
    let int = |i: usize| t.get(i).and_then(|s| s.parse::<i64>().ok());
    let within = |i: usize, v: i64, s: i64| int(i).is_some_and(|x| (x - v).abs() <= s);
    match *e {
        Exp::Contacts(p, sp, tt, st) => t[0] == "contacts" && within(1, p, sp) && within(2, tt, st),
        Exp::First(p, sp) => t[0] == "contacts" && within(1, p, sp),
        Exp::Ray(None) => t[0] == "ray" && t.get(1) == Some(&"-"),
        Exp::Ray(Some((id, tri))) => t[0] == "ray" && int(1) == Some(id) && int(2) == Some(tri),
        Exp::AnyRay => t[0] == "ray",
        Exp::Sphere(k, sk) => t[0] == "sphere" && within(1, k, sk),
    }
}

/// The result lines of a run (first word `contacts`, `ray` or `sphere`).
fn results(out: &Out) -> Vec<&str> {
    out.stdout
        .lines()
        .map(str::trim)
        .filter(|l| {
            matches!(
                l.split_whitespace().next(),
                Some("contacts" | "ray" | "sphere")
            )
        })
        .collect()
}

fn traces() -> Vec<PathBuf> {
    let mut v: Vec<_> = std::fs::read_dir(world_dir())
        .expect("shared/traces/world exists")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "trace"))
        .collect();
    v.sort();
    assert!(!v.is_empty());
    v
}

/// The bounding volumes the binary knows, from its own error message, so the
/// test always covers every one.
fn bvs() -> Vec<String> {
    let out = proxima(&["world", "x.trace", "--bv", "no-such-bv"]);
    assert_eq!(out.code, 2);
    let known = out
        .stderr
        .split("(known: ")
        .nth(1)
        .and_then(|s| s.split(')').next())
        .expect("the error lists the known bounding volumes");
    let v: Vec<String> = known.split(", ").map(String::from).collect();
    for bv in ["aabb", "kdop18", "obb", "sphere"] {
        assert!(v.iter().any(|b| b == bv), "{v:?}");
    }
    v
}

#[test]
fn sample_traces_match_for_every_index_and_bv_with_and_without_first() {
    let bvs = bvs();
    for trace in traces() {
        let text = std::fs::read_to_string(trace.with_extension("expected")).unwrap();
        let path = trace.to_str().unwrap();
        for first in [false, true] {
            let exp = expected(&text, first);
            for index in NAMES {
                for bv in &bvs {
                    let mut args = vec!["world", path, "--index", index, "--bv", bv];
                    if first {
                        args.push("--first");
                    }
                    let out = proxima(&args);
                    let what = format!("{args:?}");
                    assert_eq!(out.code, 0, "{what}: {}", out.stderr);
                    let got = results(&out);
                    assert_eq!(got.len(), exp.len(), "{what}");
                    for (i, (e, g)) in exp.iter().zip(&got).enumerate() {
                        assert!(
                            check(e, g),
                            "{what}: query {}: expected {e:?}, got {g}",
                            i + 1
                        );
                        // --first prints object pairs only.
                        let words = g.split_whitespace().count();
                        if g.starts_with("contacts") {
                            assert_eq!(words, if first { 2 } else { 3 }, "{what}: {g}");
                        }
                    }
                }
            }
        }
        // The default index and BV, and every index checked against the
        // brute-force world: exit 0.
        let out = proxima(&["world", path]);
        assert_eq!(out.code, 0, "{}", out.stderr);
        assert_eq!(results(&out).len(), expected(&text, false).len());
        for index in NAMES {
            for first in [false, true] {
                let mut args = vec!["world", path, "--index", index, "--check"];
                if first {
                    args.push("--first");
                }
                let out = proxima(&args);
                assert_eq!(out.code, 0, "{args:?}: {}", out.stderr);
            }
        }
    }
}

#[test]
fn the_port_of_the_checker_rejects_what_it_should() {
    let e = expected(
        "contacts 16 0 2354 3\ncontacts-first 16 1\nray 10 299\nray -\nray *\nsphere 5 1\n",
        false,
    );
    assert_eq!(e.len(), 5);
    assert!(check(&e[0], "contacts 16 2354") && check(&e[0], "contacts 16 2357 extra"));
    assert!(!check(&e[0], "contacts 17 2354") && !check(&e[0], "contacts 16 2358"));
    assert!(!check(&e[0], "contacts 16") && !check(&e[0], "sphere 16 2354"));
    assert!(check(&e[1], "ray 10 299") && !check(&e[1], "ray 10 298") && !check(&e[1], "ray -"));
    assert!(check(&e[2], "ray -") && !check(&e[2], "ray 1 2"));
    assert!(check(&e[3], "ray 3 4") && check(&e[3], "ray -") && !check(&e[3], "sphere 1"));
    assert!(check(&e[4], "sphere 4") && check(&e[4], "sphere 6") && !check(&e[4], "sphere 7"));
    let f = expected("contacts 16 0 2354 0\ncontacts-first 16 1\n", true);
    assert_eq!(f, [Exp::First(16, 1)]);
    assert!(check(&f[0], "contacts 17") && !check(&f[0], "contacts 18"));
}

#[test]
fn time_adds_only_comment_lines_with_a_row_per_kind() {
    let trace = traces().remove(0);
    let path = trace.to_str().unwrap();
    let plain = proxima(&["world", path, "--index", "octree"]);
    let timed = proxima(&["world", path, "--index", "octree", "--time", "--check"]);
    assert_eq!(timed.code, 0, "{}", timed.stderr);
    let body: Vec<_> = timed
        .stdout
        .lines()
        .filter(|l| !l.starts_with('#'))
        .collect();
    assert_eq!(body, plain.stdout.lines().collect::<Vec<_>>());
    let rows: Vec<Vec<&str>> = timed
        .stdout
        .lines()
        .filter(|l| l.starts_with("# ") && !l.starts_with("# time"))
        .map(|l| l[2..].split_whitespace().collect())
        .collect();
    // The world and the brute-force world, each with its kinds and a total.
    for run in ["octree", "oracle"] {
        let kinds: Vec<&str> = rows.iter().filter(|r| r[0] == run).map(|r| r[1]).collect();
        for k in ["mesh", "add", "pose", "contacts", "ray", "sphere", "total"] {
            assert!(kinds.contains(&k), "{run} {k}: {}", timed.stdout);
        }
    }
}

/// A bad trace: exit 2, one line `FILE: line N: …what…`, nothing on stdout.
fn assert_bad(name: &str, text: &str, line: usize, what: &str) {
    let p = write_trace(name, text);
    let path = p.to_str().unwrap();
    for index in ["brute", "octree"] {
        for extra in [&[][..], &["--check"][..], &["--first", "--bv", "obb"][..]] {
            let mut args = vec!["world", path, "--index", index];
            args.extend_from_slice(extra);
            let out = proxima(&args);
            assert_eq!(out.code, 2, "{text:?}: {}", out.stderr);
            assert!(!out.stderr.contains("panicked"), "{}", out.stderr);
            assert_eq!(out.stderr.trim_end().lines().count(), 1, "{}", out.stderr);
            let tag = format!("{path}: line {line}: ");
            assert!(out.stderr.contains(&tag), "{text:?}: {}", out.stderr);
            assert!(out.stderr.contains(what), "{text:?}: {}", out.stderr);
            assert!(out.stdout.is_empty(), "{}", out.stdout);
        }
    }
    let _ = std::fs::remove_file(&p);
}

#[test]
fn malformed_lines_stop_with_exit_2_and_the_line_number() {
    let ok = format!(
        "mesh c {}\nmesh b {}\nadd 1 c\nadd 2 b\n",
        mesh("crate"),
        mesh("bunny")
    );
    let cases: &[(&str, &str)] = &[
        ("jump 1", "unknown command 'jump'"),
        ("mesh c2", "mesh expects 2 fields"),
        ("mesh d /nonexistent/x.obj", "cannot load mesh"),
        ("mesh d /nonexistent/x.obj extra", "mesh expects 2 fields"),
        ("mesh c /nonexistent/x.obj", "mesh 'c' is already defined"),
        ("add 3 nomesh", "unknown mesh 'nomesh'"),
        ("add 1 c", "id 1 is already in use"),
        ("add -1 c", "bad id '-1'"),
        ("add 18446744073709551616 c", "bad id"),
        ("pose 9 1 0 0 0 1 0 0 0 1 0 0 0", "unknown id 9"),
        ("pose 1 1 0 0 0 1 0 0 0 1 0 0", "pose expects 13 fields"),
        ("pose 1 1 0 0 0 1 0 0 0 1 0 0 nan", "tz is not finite"),
        ("pose 1 1 0 0 0 1 0 0 0 1 0 inf 0", "ty is not finite"),
        ("pose 1 2 0 0 0 1 0 0 0 1 0 0 0", "rotation"),
        ("pose 1 -1 0 0 0 1 0 0 0 1 0 0 0", "rotation"),
        ("pose 1 1 0 0 0 1 0 0 0 1 x 0 0", "bad number 'x' for tx"),
        ("remove 9", "unknown id 9"),
        ("ignore 1 1", "two different ids"),
        ("ignore 1 9", "unknown id 9"),
        ("contacts now", "contacts takes no fields"),
        ("ray 0 0 0 1 0 0", "ray expects 7 fields"),
        ("ray 0 0 0 0 0 0 5", "zero"),
        ("ray 0 0 0 1 0 0 -1", "max_t"),
        ("sphere 0 0 0 -0.5", "negative radius"),
        ("sphere 0 0 0 1e40", "not finite"),
        // The parser accepts it; the world refuses coordinates beyond its limit.
        ("pose 1 1 0 0 0 1 0 0 0 1 1e38 0 0", "beyond ±1e30"),
        ("\u{0}\u{ff}garbage", "line 5"),
    ];
    for (bad, what) in cases {
        assert_bad("bad-world", &format!("{ok}{bad}\ncontacts\n"), 5, what);
    }
    // A removed id is unknown afterwards; its pairs are no longer ignorable.
    assert_bad(
        "bad-world",
        &format!("{ok}remove 2\nignore 1 2\n"),
        6,
        "unknown id 2",
    );
}

#[test]
fn missing_file_and_bad_options_exit_2_in_one_line() {
    let out = proxima(&["world", "/nonexistent/dir/scene.trace"]);
    assert_eq!(out.code, 2);
    assert_eq!(out.stderr.trim_end().lines().count(), 1, "{}", out.stderr);
    assert!(out.stderr.contains("/nonexistent/dir/scene.trace"));
    let trace = traces().remove(0);
    let path = trace.to_str().unwrap();
    for args in [
        &["--index", "no-such-index"][..],
        &["--bv", "kdop7"][..],
        &["--frob"][..],
    ] {
        let mut a = vec!["world", path];
        a.extend_from_slice(args);
        let out = proxima(&a);
        assert_eq!(out.code, 2, "{a:?}: {}", out.stderr);
        assert!(!out.stderr.contains("panicked"), "{}", out.stderr);
    }
    assert_eq!(proxima(&["world"]).code, 2);
}

/// Hand-computed answers on crates (unit cubes centred at the origin): faces
/// touching count, a removed object's ignored pair is dropped, a re-added id is
/// a new object, and ray ties go to the smaller id.
#[test]
fn hand_computed_answers_on_touching_crates() {
    let c = mesh("crate");
    let text = format!(
        "mesh c {c}\n\
         add 7 c\nadd 3 c\npose 3 1 0 0 0 1 0 0 0 1 1 0 0\n\
         add 5 c\npose 5 1 0 0 0 1 0 0 0 1 5 0 0\n\
         contacts\n\
         ignore 7 3\ncontacts\n\
         remove 3\nadd 3 c\npose 3 1 0 0 0 1 0 0 0 1 1 0 0\ncontacts\n\
         ray 0.5 3 0 0 -1 0 10\n\
         ray 5 0 3 0 0 -1 10\n\
         ray 3 3 3 0 0 1 10\n\
         sphere 3 0 0 1.5\nsphere 3 0 0 1.4999\n"
    );
    let p = write_trace("crates", &text);
    let path = p.to_str().unwrap();
    let out = proxima(&["world", path, "--check"]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    let got = results(&out);
    assert_eq!(got.len(), 8, "{}", out.stdout);
    // Touching faces: one object pair, then ignored, then a new object 3.
    assert!(got[0].starts_with("contacts 1 ") && got[0] != "contacts 1 0");
    assert_eq!(got[1], "contacts 0 0");
    assert_eq!(got[2], got[0]);
    // x = 0.5 is the shared face of 7 and 3: both are hit at t = 2.5; 3 < 7.
    assert!(got[3].starts_with("ray 3 "), "{}", got[3]);
    assert!(got[4].starts_with("ray 5 "), "{}", got[4]);
    assert_eq!(got[5], "ray -");
    // The faces of 3 (x = 1.5) and 5 (x = 4.5) are 1.5 from (3, 0, 0).
    assert_eq!(&got[6..], ["sphere 2", "sphere 0"]);
    let first = proxima(&["world", path, "--first", "--check"]);
    assert_eq!(first.code, 0, "{}", first.stderr);
    assert_eq!(
        results(&first)[..3],
        ["contacts 1", "contacts 0", "contacts 1"]
    );
    let _ = std::fs::remove_file(&p);
}

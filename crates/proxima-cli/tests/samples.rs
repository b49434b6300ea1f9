//! Every shared sample trace through every registered index, compared with its
//! `.expected` file by the rules of `shared/traces/check_replay.py` (ported).

mod common;

use common::{indices::NAMES, proxima};
use std::path::PathBuf;

fn traces_dir() -> PathBuf {
    PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/traces"
    ))
}

/// `KIND COUNT SLACK [FIRST]` lines of an `.expected` file.
fn expected(text: &str) -> Vec<(String, i64, i64, Option<String>)> {
    text.lines()
        .map(str::split_whitespace)
        .map(Iterator::collect::<Vec<_>>)
        .filter(|t| !t.is_empty() && !t[0].starts_with('#'))
        .map(|t| {
            let n = |i: usize| t[i].parse::<i64>().expect("numeric expectation");
            let first = (t[0] == "ray").then(|| t[3].to_string());
            (t[0].to_string(), n(1), n(2), first)
        })
        .collect()
}

/// Whether `got` satisfies the expectation.
fn check(exp: &(String, i64, i64, Option<String>), got: &str) -> bool {
    let (kind, count, slack, first) = exp;
    let t: Vec<_> = got.split_whitespace().collect();
    let arity = if kind == "ray" { 3 } else { 2 };
    if t.len() != arity || t[0] != kind {
        return false;
    }
    let Ok(c) = t[1].parse::<i64>() else {
        return false;
    };
    (c - count).abs() <= *slack
        && match first {
            Some(f) => f == "*" || t[2] == f,
            None => true,
        }
}

#[test]
fn sample_traces_match_their_expectations_for_every_index() {
    let mut traces: Vec<_> = std::fs::read_dir(traces_dir())
        .expect("shared/traces exists")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "trace"))
        .collect();
    traces.sort();
    assert!(!traces.is_empty());
    for trace in &traces {
        let exp = expected(&std::fs::read_to_string(trace.with_extension("expected")).unwrap());
        for name in NAMES {
            let out = proxima(&["replay", trace.to_str().unwrap(), "--index", name]);
            assert_eq!(out.code, 0, "{name} {}: {}", trace.display(), out.stderr);
            let got: Vec<_> = out
                .stdout
                .lines()
                .map(str::trim)
                .filter(|l| !l.is_empty() && !l.starts_with('#'))
                .collect();
            assert_eq!(got.len(), exp.len(), "{name} {}", trace.display());
            for (i, (e, g)) in exp.iter().zip(&got).enumerate() {
                assert!(
                    check(e, g),
                    "{name} {} output line {}: expected {e:?}, got {g}",
                    trace.display(),
                    i + 1
                );
            }
        }
        // Every index at once, checked against brute force: exit 0.
        let out = proxima(&[
            "replay",
            trace.to_str().unwrap(),
            "--index",
            "all",
            "--check",
        ]);
        assert_eq!(out.code, 0, "all {}: {}", trace.display(), out.stderr);
    }
}

#[test]
fn the_port_of_the_checker_rejects_what_it_should() {
    let e = expected("pairs 10 2\nray 3 0 7\nray 1 0 *\n");
    assert!(check(&e[0], "pairs 12") && check(&e[0], "pairs 8"));
    assert!(!check(&e[0], "pairs 13") && !check(&e[0], "sphere 10"));
    assert!(!check(&e[0], "pairs 10 1") && !check(&e[0], "pairs x"));
    assert!(check(&e[1], "ray 3 7") && !check(&e[1], "ray 3 8") && !check(&e[1], "ray 3"));
    assert!(check(&e[2], "ray 1 99") && !check(&e[2], "ray 2 99"));
}

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
            let first = (t[0] == "ray" || t[0] == "sweep").then(|| t[3].to_string());
            (t[0].to_string(), n(1), n(2), first)
        })
        .collect()
}

/// Whether `got` satisfies the expectation.
fn check(exp: &(String, i64, i64, Option<String>), got: &str) -> bool {
    let (kind, count, slack, first) = exp;
    let t: Vec<_> = got.split_whitespace().collect();
    let arity = if kind == "ray" || kind == "sweep" {
        3
    } else {
        2
    };
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
    let e = expected("sweep 2 0 5\nsweep 0 0 -\n");
    assert!(check(&e[0], "sweep 2 5") && !check(&e[0], "sweep 2 6") && !check(&e[0], "ray 2 5"));
    assert!(check(&e[1], "sweep 0 -") && !check(&e[1], "sweep 0 3"));
    let n = "nearest 4 12 {7,3=9@2-3}:2 40";
    assert!(check_nearest(n, "nearest 4 12 3 9 40") && check_nearest(n, "nearest 4 12 7 3 40"));
    assert!(!check_nearest(n, "nearest 4 12 40 3 9") && !check_nearest(n, "nearest 3 12 3 9"));
    assert!(!check_nearest(n, "nearest 4 12 3 3 40") && !check_nearest(n, "nearest 4 12 3 8 40"));
}

/// A `nearest COUNT ITEM…` expectation against an output line, by the rules
/// of `check_replay.py` except the order within `=` chains and the `@LO-HI`
/// windows: the count, distinct ids, each plain `ID` at its position, and each
/// `{…}` / `{…}:T` group's positions filled with ids it lists.
fn check_nearest(exp: &str, got: &str) -> bool {
    let e: Vec<&str> = exp.split_whitespace().collect();
    let g: Vec<&str> = got.split_whitespace().collect();
    if g.first() != Some(&"nearest") || g.get(1) != e.get(1) {
        return false;
    }
    let ids = &g[2..];
    let mut seen = ids.to_vec();
    seen.sort_unstable();
    seen.dedup();
    if Some(ids.len().to_string().as_str()) != e.get(1).copied() || seen.len() != ids.len() {
        return false;
    }
    let mut pos = 0;
    for item in &e[2..] {
        if let Some(body) = item.strip_prefix('{') {
            let (list, take) = match body.split_once('}') {
                Some((l, "")) => (l, None),
                Some((l, t)) => (l, t.strip_prefix(':').and_then(|t| t.parse().ok())),
                None => return false,
            };
            let listed: Vec<&str> = list
                .split([',', '='])
                .map(|x| x.split('@').next().unwrap_or(x))
                .collect();
            let n = take.unwrap_or(listed.len());
            if pos + n > ids.len() || !ids[pos..pos + n].iter().all(|id| listed.contains(id)) {
                return false;
            }
            pos += n;
        } else {
            if ids.get(pos) != Some(item) {
                return false;
            }
            pos += 1;
        }
    }
    pos == ids.len()
}

/// The traces with the lines of design §8 (`shared/traces/queries`): every
/// index within the expectations (`nearest` by [`check_nearest`]), and every
/// index agreeing with brute force exactly (`--index all --check`).
#[test]
fn query_traces_match_their_expectations_for_every_index() {
    let dir = traces_dir().join("queries");
    let mut traces: Vec<_> = std::fs::read_dir(&dir)
        .expect("shared/traces/queries exists")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "trace"))
        .collect();
    traces.sort();
    assert!(!traces.is_empty());
    for trace in &traces {
        let text = std::fs::read_to_string(trace.with_extension("expected")).unwrap();
        let lines: Vec<&str> = text
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty() && !l.starts_with('#'))
            .collect();
        for name in NAMES {
            let out = proxima(&["replay", trace.to_str().unwrap(), "--index", name]);
            assert_eq!(out.code, 0, "{name} {}: {}", trace.display(), out.stderr);
            let got: Vec<_> = out
                .stdout
                .lines()
                .map(str::trim)
                .filter(|l| !l.is_empty() && !l.starts_with('#'))
                .collect();
            assert_eq!(got.len(), lines.len(), "{name} {}", trace.display());
            for (i, (e, g)) in lines.iter().zip(&got).enumerate() {
                let ok = if e.starts_with("nearest") {
                    check_nearest(e, g)
                } else {
                    check(&expected(e)[0], g)
                };
                assert!(
                    ok,
                    "{name} {} output line {}: expected {e}, got {g}",
                    trace.display(),
                    i + 1
                );
            }
        }
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

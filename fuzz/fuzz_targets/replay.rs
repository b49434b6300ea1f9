//! `proxima replay` on arbitrary bytes: the trace parser must return a trace or a
//! one-line error, and every index must then replay the trace with the same answers
//! as brute force. The parser and the engine are the CLI's, from `proxima_harness`.
#![no_main]

use proxima_harness::{replay, trace};

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let Ok(t) = trace::Trace::parse(data) else {
        return;
    };
    let hint = t.scene_hint();
    let mut runs = Vec::new();
    for kind in proxima::broad::IndexKind::ALL {
        match replay::run_one(kind.name(), &hint, &t) {
            Ok(r) => runs.push(r),
            Err(e) => panic!("{kind} rejects a checked trace: {e}"),
        }
    }
    if let Some((i, r, _)) = replay::disagreement(&runs) {
        panic!("{} disagrees with brute force at query {i}", r.name);
    }
});

//! Every mesh loader on arbitrary bytes: an error or a valid mesh, never a panic,
//! and never an allocation beyond what the input size allows (libFuzzer's
//! `-rss_limit_mb` / `-malloc_limit_mb` catch those).
#![no_main]

use proxima::io::{parse, Format};

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    for format in [Format::Obj, Format::Stl, Format::Ply] {
        if let Ok(mesh) = parse("fuzz", data, format) {
            // A loaded mesh is valid: every index in range, every vertex finite.
            let n = mesh.vertices().len();
            assert!(!mesh.is_empty());
            assert!(mesh.triangles().iter().flatten().all(|&v| (v as usize) < n));
            assert!(mesh.vertices().iter().all(|v| v.is_finite()));
        }
    }
    if let Some(f) = Format::sniff(data) {
        let _ = parse("fuzz", data, f);
    }
});

//! Formats measurements as a text table or JSON (hand-written: no serde needed).

use crate::registry::PARRY;
use crate::run::{Clock, Measurement};
use std::fmt::Write;
use std::time::Duration;

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// Frame time (median update + pairs) of `m` divided by parry3d's, if parry3d ran.
pub fn ratio_to_parry(m: &Measurement, all: &[Measurement]) -> Option<f64> {
    let p = all.iter().find(|x| x.name == PARRY)?;
    let pf = ms(p.frame_median());
    (pf > 0.0).then(|| ms(m.frame_median()) / pf)
}

/// The table: one row per structure, times in milliseconds.
pub fn table(all: &[Measurement]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{:<16} {:>10} {:>12} {:>12} {:>12} {:>12} {:>10} {:>10}",
        "structure",
        "build ms",
        "update ms/f",
        "pairs ms/f",
        "frame ms",
        "pairs/frame",
        "bytes/obj",
        "vs parry"
    );
    for m in all {
        let ratio = ratio_to_parry(m, all)
            .map(|r| format!("{r:.2}x"))
            .unwrap_or_else(|| "-".into());
        let _ = writeln!(
            out,
            "{:<16} {:>10.2} {:>12.3} {:>12.3} {:>12.3} {:>12.1} {:>10.1} {:>10}",
            m.name,
            ms(m.build),
            ms(m.update_median()),
            ms(m.pairs_median()),
            ms(m.frame_median()),
            m.pairs_per_frame(),
            m.bytes_per_object(),
            ratio
        );
    }
    out
}

/// The same data as a JSON array of objects.
pub fn json(workload: &str, seed: u64, frames: usize, clock: Clock, all: &[Measurement]) -> String {
    let mut out = String::from("[\n");
    for (i, m) in all.iter().enumerate() {
        let ratio = ratio_to_parry(m, all)
            .map(|r| format!("{r:.4}"))
            .unwrap_or_else(|| "null".into());
        let _ = write!(
            out,
            "  {{\"workload\": \"{workload}\", \"n\": {}, \"seed\": {seed}, \"frames\": {frames}, \"clock\": \"{}\", \
             \"structure\": \"{}\", \"peer\": {}, \"build_ms\": {:.4}, \
             \"update_ms_median\": {:.4}, \"pairs_ms_median\": {:.4}, \"frame_ms_median\": {:.4}, \
             \"pairs_per_frame\": {:.1}, \"memory_bytes\": {}, \"bytes_per_object\": {:.2}, \
             \"frame_ratio_to_parry3d\": {ratio}}}",
            m.n,
            clock.name(),
            m.name,
            m.peer,
            ms(m.build),
            ms(m.update_median()),
            ms(m.pairs_median()),
            ms(m.frame_median()),
            m.pairs_per_frame(),
            m.memory,
            m.bytes_per_object(),
        );
        out.push_str(if i + 1 < all.len() { ",\n" } else { "\n" });
    }
    out.push_str("]\n");
    out
}

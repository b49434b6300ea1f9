//! Formats measurements as a text table or JSON (hand-written: no serde needed).
//!
//! Every ratio's denominator is the fastest mode in the same run: `vs parry` over
//! the fastest of parry3d's modes, `vs best peer` over the fastest peer row of any
//! crate and mode.

use crate::registry::PARRY;
use crate::run::{Clock, Measurement};
use std::fmt::Write;
use std::time::Duration;

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// The fastest (median frame) of the rows `keep` accepts.
fn fastest(all: &[Measurement], keep: impl Fn(&Measurement) -> bool) -> Option<&Measurement> {
    all.iter()
        .filter(|m| keep(m))
        .min_by_key(|m| m.frame_median())
}

/// The fastest peer row (any crate, any mode) of the run, if a peer ran.
pub fn best_peer(all: &[Measurement]) -> Option<&Measurement> {
    fastest(all, |m| m.peer)
}

fn ratio_to(m: &Measurement, best: Option<&Measurement>) -> Option<f64> {
    let pf = ms(best?.frame_median());
    (pf > 0.0).then(|| ms(m.frame_median()) / pf)
}

/// Frame time (median update + pairs) of `m` divided by that of parry3d's
/// fastest mode in the run, if parry3d ran.
pub fn ratio_to_parry(m: &Measurement, all: &[Measurement]) -> Option<f64> {
    ratio_to(m, fastest(all, |x| x.peer && x.name == PARRY))
}

/// Frame time of `m` divided by that of the fastest peer row ([`best_peer`]).
pub fn ratio_to_best_peer(m: &Measurement, all: &[Measurement]) -> Option<f64> {
    ratio_to(m, best_peer(all))
}

/// The table: one row per structure and mode, times in milliseconds, then a line
/// naming the best peer.
pub fn table(all: &[Measurement]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{:<16} {:<15} {:>10} {:>12} {:>12} {:>12} {:>12} {:>10} {:>10} {:>12}",
        "structure",
        "mode",
        "build ms",
        "update ms/f",
        "pairs ms/f",
        "frame ms",
        "pairs/frame",
        "bytes/obj",
        "vs parry",
        "vs best peer"
    );
    let fmt = |r: Option<f64>| r.map_or_else(|| "-".into(), |r| format!("{r:.2}x"));
    for m in all {
        let _ = writeln!(
            out,
            "{:<16} {:<15} {:>10.2} {:>12.3} {:>12.3} {:>12.3} {:>12.1} {:>10.1} {:>10} {:>12}",
            m.name,
            m.mode,
            ms(m.build),
            ms(m.update_median()),
            ms(m.pairs_median()),
            ms(m.frame_median()),
            m.pairs_per_frame(),
            m.bytes_per_object(),
            fmt(ratio_to_parry(m, all)),
            fmt(ratio_to_best_peer(m, all))
        );
    }
    if let Some(b) = best_peer(all) {
        let _ = writeln!(
            out,
            "best peer in this run: {} ({}), {:.3} ms/frame; ratios are over the fastest mode",
            b.name,
            b.mode,
            ms(b.frame_median())
        );
    }
    out
}

/// The same data as a JSON array of objects (with `mode`, the ratios to parry3d's
/// fastest mode and to the best peer, and which peer and mode that was).
pub fn json(workload: &str, seed: u64, frames: usize, clock: Clock, all: &[Measurement]) -> String {
    let mut out = String::from("[\n");
    let num = |r: Option<f64>| r.map_or_else(|| "null".into(), |r| format!("{r:.4}"));
    let best = best_peer(all).map_or_else(
        || "null".to_string(),
        |b| format!("\"{}:{}\"", b.name, b.mode),
    );
    for (i, m) in all.iter().enumerate() {
        let _ = write!(
            out,
            "  {{\"workload\": \"{workload}\", \"n\": {}, \"seed\": {seed}, \"frames\": {frames}, \"clock\": \"{}\", \
             \"structure\": \"{}\", \"mode\": \"{}\", \"peer\": {}, \"build_ms\": {:.4}, \
             \"update_ms_median\": {:.4}, \"pairs_ms_median\": {:.4}, \"frame_ms_median\": {:.4}, \
             \"pairs_per_frame\": {:.1}, \"memory_bytes\": {}, \"bytes_per_object\": {:.2}, \
             \"frame_ratio_to_parry3d\": {}, \"frame_ratio_to_best_peer\": {}, \"best_peer\": {best}}}",
            m.n,
            clock.name(),
            m.name,
            m.mode,
            m.peer,
            ms(m.build),
            ms(m.update_median()),
            ms(m.pairs_median()),
            ms(m.frame_median()),
            m.pairs_per_frame(),
            m.memory,
            m.bytes_per_object(),
            num(ratio_to_parry(m, all)),
            num(ratio_to_best_peer(m, all)),
        );
        out.push_str(if i + 1 < all.len() { ",\n" } else { "\n" });
    }
    out.push_str("]\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(name: &'static str, mode: &'static str, peer: bool, frame_ms: u64) -> Measurement {
        Measurement {
            name,
            mode,
            peer,
            build: Duration::ZERO,
            update: vec![Duration::ZERO],
            pairs: vec![Duration::from_millis(frame_ms)],
            pair_total: 1,
            memory: 1,
            n: 1,
        }
    }

    /// The denominators are the fastest mode, whichever row it is.
    #[test]
    fn ratios_use_the_fastest_mode() {
        let all = [
            row("Ours", "-", false, 10),
            row(PARRY, "refit", true, 20),
            row(PARRY, "optimize+refit", true, 40),
            row("other", "x", true, 16),
        ];
        assert_eq!(ratio_to_parry(&all[0], &all), Some(0.5));
        assert_eq!(ratio_to_best_peer(&all[0], &all), Some(0.625));
        assert_eq!(ratio_to_parry(&all[2], &all), Some(2.0));
        let t = table(&all);
        assert!(t.contains("optimize+refit"), "{t}");
        assert!(t.contains("best peer in this run: other (x)"), "{t}");
        let j = json("w1", 1, 1, Clock::Wall, &all);
        assert!(j.contains("\"mode\": \"refit\""), "{j}");
        assert!(j.contains("\"best_peer\": \"other:x\""), "{j}");
        assert!(serde_json::from_str::<serde_json::Value>(&j).is_ok(), "{j}");
    }
}

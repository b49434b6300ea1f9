//! `proxima-bench chart FILE.json... --out FILE.svg [--metric NAME] [--title T]`
//!
//! Draws the `--json` output of any workload as a bar chart in plain SVG (no
//! plotting dependency): one panel per group of rows that share every field other
//! than the structure and the measurements (workload, n, query kind, mesh, ...),
//! one bar per structure, each panel scaled to its own largest bar so that
//! workloads of very different cost sit in one picture. Peers are drawn grey,
//! Proxima's structures blue, and each bar is labelled with its value.

use serde_json::Value;
use std::fmt::Write;

/// Fields that identify a group of rows to compare (in this order, when present).
const GROUP_KEYS: &[&str] = &["workload", "n", "kind", "mesh", "pair", "threads"];

/// One bar.
#[derive(Clone, Debug, PartialEq)]
pub struct Bar {
    /// Structure name.
    pub label: String,
    /// Whether the structure is a peer (drawn grey).
    pub peer: bool,
    /// The metric's value.
    pub value: f64,
}

/// One panel: a group title and its bars in input order.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// "w1 n=100000", etc.
    pub title: String,
    /// Bars of the panel.
    pub bars: Vec<Bar>,
}

/// Groups the rows of one or more `--json` outputs into panels. Rows without the
/// metric (or with a non-numeric one) are left out; an error names the file whose
/// text is not a JSON array of objects.
pub fn panels(files: &[(String, String)], metric: &str) -> Result<Vec<Panel>, String> {
    let mut out: Vec<Panel> = Vec::new();
    for (name, text) in files {
        let v: Value = serde_json::from_str(text).map_err(|e| format!("{name}: {e}"))?;
        let rows = v
            .as_array()
            .ok_or_else(|| format!("{name}: expected a JSON array of rows"))?;
        for row in rows {
            let obj = row
                .as_object()
                .ok_or_else(|| format!("{name}: a row is not a JSON object"))?;
            let Some(value) = obj.get(metric).and_then(Value::as_f64) else {
                continue;
            };
            let title = GROUP_KEYS
                .iter()
                .filter_map(|k| {
                    let v = obj.get(*k)?;
                    let s = match v {
                        Value::String(s) => s.clone(),
                        Value::Null => return None,
                        other => other.to_string(),
                    };
                    Some(if *k == "workload" || *k == "kind" {
                        s
                    } else {
                        format!("{k}={s}")
                    })
                })
                .collect::<Vec<_>>()
                .join(" ");
            let bar = Bar {
                label: label(obj),
                peer: obj.get("peer").and_then(Value::as_bool).unwrap_or(false),
                value,
            };
            match out.iter_mut().find(|p| p.title == title) {
                Some(p) => p.bars.push(bar),
                None => out.push(Panel {
                    title,
                    bars: vec![bar],
                }),
            }
        }
    }
    if out.is_empty() {
        return Err(format!("no row has a numeric {metric:?} field"));
    }
    Ok(out)
}

/// A bar's label: the structure, with its mode when the row has one (a peer
/// run in several modes has one bar per mode).
fn label(obj: &serde_json::Map<String, Value>) -> String {
    let name = obj.get("structure").and_then(Value::as_str).unwrap_or("?");
    match obj.get("mode").and_then(Value::as_str) {
        Some(mode) if mode != "-" => format!("{name} ({mode})"),
        _ => name.to_string(),
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// Renders the panels as one SVG document.
pub fn svg(panels: &[Panel], metric: &str, title: &str) -> String {
    const W: f64 = 760.0;
    const LABEL_W: f64 = 150.0;
    const BAR_H: f64 = 16.0;
    const GAP: f64 = 4.0;
    const PANEL_HEAD: f64 = 26.0;
    const PANEL_GAP: f64 = 14.0;
    let plot_w = W - LABEL_W - 90.0;
    let height: f64 = 40.0
        + panels
            .iter()
            .map(|p| PANEL_HEAD + p.bars.len() as f64 * (BAR_H + GAP) + PANEL_GAP)
            .sum::<f64>();
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{height}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(
        s,
        r#"<rect width="100%" height="100%" fill="white"/><text x="10" y="22" font-size="15" font-weight="bold">{} ({}; shorter is faster; blue = Proxima, grey = peer)</text>"#,
        escape(title),
        escape(metric)
    );
    let mut y = 40.0;
    for p in panels {
        let _ = writeln!(
            s,
            r#"<text x="10" y="{}" font-weight="bold">{}</text>"#,
            y + 16.0,
            escape(&p.title)
        );
        y += PANEL_HEAD;
        let max = p.bars.iter().map(|b| b.value).fold(0.0, f64::max);
        for b in &p.bars {
            let w = if max > 0.0 {
                (b.value / max * plot_w).max(1.0)
            } else {
                1.0
            };
            let fill = if b.peer { "#9a9a9a" } else { "#3b73b9" };
            let _ = writeln!(
                s,
                r#"<text x="{}" y="{}" text-anchor="end">{}</text><rect x="{LABEL_W}" y="{y}" width="{w:.1}" height="{BAR_H}" fill="{fill}"/><text x="{}" y="{}">{}</text>"#,
                LABEL_W - 6.0,
                y + BAR_H - 4.0,
                escape(&b.label),
                LABEL_W + w + 5.0,
                y + BAR_H - 4.0,
                fmt_value(b.value)
            );
            y += BAR_H + GAP;
        }
        y += PANEL_GAP;
    }
    s.push_str("</svg>\n");
    s
}

fn fmt_value(v: f64) -> String {
    if v >= 100.0 {
        format!("{v:.0}")
    } else if v >= 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// The `chart` subcommand: arguments after the word `chart`.
pub fn main(args: &[String]) -> Result<(), String> {
    let mut files = Vec::new();
    let mut out = None;
    let mut metric = "frame_ms_median".to_string();
    let mut title = "Proxima benchmarks".to_string();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = |flag: &str| it.next().cloned().ok_or(format!("{flag} needs a value"));
        match a.as_str() {
            "--out" => out = Some(value("--out")?),
            "--metric" => metric = value("--metric")?,
            "--title" => title = value("--title")?,
            f if f.starts_with("--") => return Err(format!("unknown argument {f:?}")),
            f => {
                let text = std::fs::read_to_string(f).map_err(|e| format!("{f}: {e}"))?;
                files.push((f.to_string(), text));
            }
        }
    }
    let out = out.ok_or("--out FILE.svg is required")?;
    if files.is_empty() {
        return Err("no JSON file given".into());
    }
    let panels = panels(&files, &metric)?;
    std::fs::write(&out, svg(&panels, &metric, &title)).map_err(|e| format!("{out}: {e}"))?;
    eprintln!("wrote {out} ({} panels)", panels.len());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const ROWS: &str = r#"[
      {"workload": "w1", "n": 10000, "structure": "LooseKdTree", "peer": false, "frame_ms_median": 2.0},
      {"workload": "w1", "n": 10000, "structure": "parry3d", "peer": true, "frame_ms_median": 1.5},
      {"workload": "w1", "n": 100000, "structure": "LooseKdTree", "peer": false, "frame_ms_median": 20.0},
      {"workload": "w1", "n": 100000, "structure": "broken", "peer": false}
    ]"#;

    #[test]
    fn rows_group_by_everything_but_structure() {
        let p = panels(&[("a.json".into(), ROWS.into())], "frame_ms_median").unwrap();
        assert_eq!(p.len(), 2);
        assert_eq!(p[0].title, "w1 n=10000");
        assert_eq!(p[0].bars.len(), 2);
        assert!(p[0].bars[1].peer);
        assert_eq!(p[1].bars.len(), 1, "a row without the metric is left out");
        let s = svg(&p, "frame_ms_median", "t");
        assert_eq!(s.matches("<rect x=").count(), 3);
        assert!(s.contains("LooseKdTree") && s.contains("20.0"));
    }

    #[test]
    fn bad_input_is_an_error_naming_the_file() {
        let e = panels(&[("x.json".into(), "{".into())], "m").unwrap_err();
        assert!(e.starts_with("x.json:"), "{e}");
        let e = panels(&[("y.json".into(), "[1]".into())], "m").unwrap_err();
        assert!(e.starts_with("y.json:"), "{e}");
        assert!(panels(&[("z.json".into(), ROWS.into())], "nope").is_err());
    }
}

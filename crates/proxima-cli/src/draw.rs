//! A minimal vector canvas with two outputs: PNG (rasterized with `tiny-skia`,
//! text from the public-domain 8×8 bitmap font of `font8x8`) and SVG (written by
//! hand). Pictures are described once as a list of shapes, so both formats show
//! the same thing, and no system font is needed.

use std::fmt::Write as _;
use std::path::Path;
use tiny_skia::{FillRule, Paint, PathBuilder, Pixmap, Rect, Stroke, Transform};

/// A colour with alpha (0 transparent, 255 opaque).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rgba(pub u8, pub u8, pub u8, pub u8);

impl Rgba {
    /// An opaque colour.
    pub const fn rgb(r: u8, g: u8, b: u8) -> Rgba {
        Rgba(r, g, b, 255)
    }
    /// The same colour with alpha `a`.
    pub const fn alpha(self, a: u8) -> Rgba {
        Rgba(self.0, self.1, self.2, a)
    }
    /// The colour scaled towards black by `k` in `[0, 1]` (flat shading).
    pub fn shade(self, k: f32) -> Rgba {
        let f = |c: u8| (c as f32 * k.clamp(0.0, 1.0)).round() as u8;
        Rgba(f(self.0), f(self.1), f(self.2), self.3)
    }
}

/// Black.
pub const BLACK: Rgba = Rgba::rgb(0, 0, 0);
/// Mid grey for axes and light text.
pub const GREY: Rgba = Rgba::rgb(120, 120, 120);

/// A colour per series or depth: a qualitative palette (Tableau 10).
pub fn palette(i: usize) -> Rgba {
    const P: [Rgba; 10] = [
        Rgba::rgb(31, 119, 180),
        Rgba::rgb(255, 127, 14),
        Rgba::rgb(44, 160, 44),
        Rgba::rgb(214, 39, 40),
        Rgba::rgb(148, 103, 189),
        Rgba::rgb(140, 86, 75),
        Rgba::rgb(227, 119, 194),
        Rgba::rgb(127, 127, 127),
        Rgba::rgb(188, 189, 34),
        Rgba::rgb(23, 190, 207),
    ];
    P[i % P.len()]
}

/// Horizontal alignment of a text relative to its anchor point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Anchor {
    /// The text starts at the point.
    Start,
    /// The text is centred on the point.
    Middle,
    /// The text ends at the point.
    End,
}

#[derive(Clone, Debug)]
enum Geometry {
    Rect { x: f32, y: f32, w: f32, h: f32 },
    Circle { cx: f32, cy: f32, r: f32 },
    Path { pts: Vec<(f32, f32)>, closed: bool },
}

#[derive(Clone, Debug)]
enum Element {
    Shape {
        geometry: Geometry,
        fill: Option<Rgba>,
        stroke: Option<(Rgba, f32)>,
    },
    Text {
        x: f32,
        y: f32,
        scale: u32,
        text: String,
        color: Rgba,
        anchor: Anchor,
    },
}

/// A picture in pixel coordinates (origin top left, y down).
#[derive(Clone, Debug)]
pub struct Canvas {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    elements: Vec<Element>,
}

/// Glyph cell of the bitmap font at scale 1 (pixels).
pub const GLYPH: f32 = 8.0;

impl Canvas {
    /// An empty white canvas.
    pub fn new(width: u32, height: u32) -> Canvas {
        Canvas {
            width,
            height,
            elements: Vec::new(),
        }
    }

    /// A rectangle.
    pub fn rect(
        &mut self,
        x: f32,
        y: f32,
        w: f32,
        h: f32,
        fill: Option<Rgba>,
        stroke: Option<(Rgba, f32)>,
    ) {
        self.elements.push(Element::Shape {
            geometry: Geometry::Rect { x, y, w, h },
            fill,
            stroke,
        });
    }

    /// A circle.
    pub fn circle(
        &mut self,
        cx: f32,
        cy: f32,
        r: f32,
        fill: Option<Rgba>,
        stroke: Option<(Rgba, f32)>,
    ) {
        self.elements.push(Element::Shape {
            geometry: Geometry::Circle { cx, cy, r },
            fill,
            stroke,
        });
    }

    /// An open polyline.
    pub fn polyline(&mut self, pts: Vec<(f32, f32)>, color: Rgba, width: f32) {
        self.elements.push(Element::Shape {
            geometry: Geometry::Path { pts, closed: false },
            fill: None,
            stroke: Some((color, width)),
        });
    }

    /// A closed polygon.
    pub fn polygon(
        &mut self,
        pts: Vec<(f32, f32)>,
        fill: Option<Rgba>,
        stroke: Option<(Rgba, f32)>,
    ) {
        self.elements.push(Element::Shape {
            geometry: Geometry::Path { pts, closed: true },
            fill,
            stroke,
        });
    }

    /// A line of text whose baseline-ish bottom is at `y`, `scale` × 8 pixels tall.
    pub fn text(&mut self, x: f32, y: f32, scale: u32, text: &str, color: Rgba, anchor: Anchor) {
        self.elements.push(Element::Text {
            x,
            y,
            scale: scale.max(1),
            text: text.to_string(),
            color,
            anchor,
        });
    }

    /// Width in pixels of `text` at `scale`.
    pub fn text_width(text: &str, scale: u32) -> f32 {
        text.chars().count() as f32 * GLYPH * scale.max(1) as f32
    }

    /// Writes the picture, as SVG if `path` ends in `.svg`, else as PNG.
    pub fn save(&self, path: &Path) -> Result<(), String> {
        let svg = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("svg"));
        let bytes = if svg {
            self.to_svg().into_bytes()
        } else {
            self.to_png()?
        };
        std::fs::write(path, bytes).map_err(|e| format!("cannot write {}: {e}", path.display()))
    }

    /// The picture as PNG bytes.
    pub fn to_png(&self) -> Result<Vec<u8>, String> {
        let mut pm = Pixmap::new(self.width.max(1), self.height.max(1))
            .ok_or_else(|| "picture too large".to_string())?;
        pm.fill(tiny_skia::Color::WHITE);
        for e in &self.elements {
            match e {
                Element::Shape {
                    geometry,
                    fill,
                    stroke,
                } => {
                    let Some(path) = skia_path(geometry) else {
                        continue;
                    };
                    if let Some(c) = fill {
                        pm.fill_path(
                            &path,
                            &paint(*c),
                            FillRule::Winding,
                            Transform::identity(),
                            None,
                        );
                    }
                    if let Some((c, w)) = stroke {
                        let s = Stroke {
                            width: *w,
                            ..Stroke::default()
                        };
                        pm.stroke_path(&path, &paint(*c), &s, Transform::identity(), None);
                    }
                }
                Element::Text {
                    x,
                    y,
                    scale,
                    text,
                    color,
                    anchor,
                } => {
                    let s = *scale as f32;
                    let x0 = x - offset(text, *scale, *anchor);
                    let top = y - GLYPH * s;
                    let mut p = paint(*color);
                    p.anti_alias = false;
                    for (i, ch) in text.chars().enumerate() {
                        let glyph = font8x8::legacy::BASIC_LEGACY
                            .get(ch as usize)
                            .copied()
                            .unwrap_or([0; 8]);
                        let gx = x0 + i as f32 * GLYPH * s;
                        for (row, bits) in glyph.iter().enumerate() {
                            for col in 0..8 {
                                if bits >> col & 1 == 1 {
                                    if let Some(r) = Rect::from_xywh(
                                        gx + col as f32 * s,
                                        top + row as f32 * s,
                                        s,
                                        s,
                                    ) {
                                        pm.fill_rect(r, &p, Transform::identity(), None);
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        pm.encode_png()
            .map_err(|e| format!("PNG encoding failed: {e}"))
    }

    /// The picture as an SVG document.
    pub fn to_svg(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}">"#,
            w = self.width,
            h = self.height
        );
        let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
        for e in &self.elements {
            match e {
                Element::Shape {
                    geometry,
                    fill,
                    stroke,
                } => {
                    let style = svg_style(*fill, *stroke);
                    let _ = match geometry {
                        Geometry::Rect { x, y, w, h } => writeln!(
                            s,
                            r#"<rect x="{x:.2}" y="{y:.2}" width="{w:.2}" height="{h:.2}" {style}/>"#
                        ),
                        Geometry::Circle { cx, cy, r } => writeln!(
                            s,
                            r#"<circle cx="{cx:.2}" cy="{cy:.2}" r="{r:.2}" {style}/>"#
                        ),
                        Geometry::Path { pts, closed } => {
                            let tag = if *closed { "polygon" } else { "polyline" };
                            let p: Vec<String> =
                                pts.iter().map(|(x, y)| format!("{x:.2},{y:.2}")).collect();
                            writeln!(s, r#"<{tag} points="{}" {style}/>"#, p.join(" "))
                        }
                    };
                }
                Element::Text {
                    x,
                    y,
                    scale,
                    text,
                    color,
                    anchor,
                } => {
                    let a = match anchor {
                        Anchor::Start => "start",
                        Anchor::Middle => "middle",
                        Anchor::End => "end",
                    };
                    let _ = writeln!(
                        s,
                        r#"<text x="{x:.1}" y="{y:.1}" font-family="monospace" font-size="{}" text-anchor="{a}" fill="{}">{}</text>"#,
                        GLYPH * 1.25 * *scale as f32,
                        svg_color(*color),
                        escape(text)
                    );
                }
            }
        }
        s.push_str("</svg>\n");
        s
    }
}

fn offset(text: &str, scale: u32, anchor: Anchor) -> f32 {
    let w = Canvas::text_width(text, scale);
    match anchor {
        Anchor::Start => 0.0,
        Anchor::Middle => w / 2.0,
        Anchor::End => w,
    }
}

fn paint(c: Rgba) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color_rgba8(c.0, c.1, c.2, c.3);
    p.anti_alias = true;
    p
}

fn skia_path(g: &Geometry) -> Option<tiny_skia::Path> {
    match g {
        Geometry::Rect { x, y, w, h } => {
            Rect::from_xywh(*x, *y, w.max(0.01), h.max(0.01)).map(PathBuilder::from_rect)
        }
        Geometry::Circle { cx, cy, r } => PathBuilder::from_circle(*cx, *cy, r.max(0.01)),
        Geometry::Path { pts, closed } => {
            let mut pb = PathBuilder::new();
            let (first, rest) = pts.split_first()?;
            pb.move_to(first.0, first.1);
            for p in rest {
                pb.line_to(p.0, p.1);
            }
            if *closed {
                pb.close();
            }
            pb.finish()
        }
    }
}

fn svg_color(c: Rgba) -> String {
    format!("#{:02x}{:02x}{:02x}", c.0, c.1, c.2)
}

fn svg_style(fill: Option<Rgba>, stroke: Option<(Rgba, f32)>) -> String {
    let mut s = match fill {
        Some(c) => format!(
            r#"fill="{}" fill-opacity="{:.3}""#,
            svg_color(c),
            c.3 as f32 / 255.0
        ),
        None => r#"fill="none""#.to_string(),
    };
    if let Some((c, w)) = stroke {
        let _ = write!(
            s,
            r#" stroke="{}" stroke-opacity="{:.3}" stroke-width="{w:.2}""#,
            svg_color(c),
            c.3 as f32 / 255.0
        );
    }
    s
}

fn escape(t: &str) -> String {
    t.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Canvas {
        let mut c = Canvas::new(64, 32);
        c.rect(1.0, 1.0, 10.0, 10.0, Some(BLACK), Some((GREY, 1.0)));
        c.circle(30.0, 10.0, 5.0, Some(palette(3).alpha(128)), None);
        c.polygon(vec![(0.0, 0.0), (5.0, 0.0), (0.0, 5.0)], Some(GREY), None);
        c.polyline(vec![(0.0, 30.0), (60.0, 30.0)], BLACK, 1.0);
        c.text(32.0, 28.0, 1, "A<&>", BLACK, Anchor::Middle);
        c
    }

    #[test]
    fn png_is_a_png_with_ink() {
        let png = sample().to_png().unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    }

    #[test]
    fn svg_has_every_element_and_escapes_text() {
        let svg = sample().to_svg();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        for tag in ["<rect x", "<circle", "<polygon", "<polyline", "<text"] {
            assert!(svg.contains(tag), "{tag}");
        }
        assert!(svg.contains("A&lt;&amp;&gt;"));
    }
}

//! The pictures of `proxima demo` and `proxima render`: the loose k-d tree's and
//! the octree's partitions cut by a horizontal plane (as in the figures of
//! [sources: figures]), a chart of time per frame, and two posed meshes with their
//! intersecting triangles.

use crate::draw::{palette, Anchor, Canvas, Rgba, BLACK, GREY};
use proxima::broad::{
    LinearOctree, LooseKdConfig, LooseKdTree, OctreeConfig, SceneHint, SpatialIndex,
};
use proxima::geom::{Aabb, Sphere};
use proxima::glam::{Affine3A, Vec3};
use proxima::narrow::TriMesh;

/// Side of the square drawing area of the partition pictures, in pixels.
const AREA: f32 = 900.0;
/// Margins: left/right, top (title), bottom (legend).
const MARGIN: f32 = 30.0;
const TOP: f32 = 70.0;
const BOTTOM: f32 = 110.0;

/// Maps world XY to pixels (y up in the world, down on the canvas).
struct View {
    min: (f32, f32),
    scale: f32,
    x0: f32,
    y0: f32,
    h: f32,
}

impl View {
    fn new(world: &Aabb) -> View {
        let e = world.extent();
        let scale = AREA / e.x.max(e.y).max(1e-6);
        View {
            min: (world.min.x, world.min.y),
            scale,
            x0: MARGIN,
            y0: TOP,
            h: e.y * scale,
        }
    }
    fn x(&self, x: f32) -> f32 {
        self.x0 + (x - self.min.0) * self.scale
    }
    fn y(&self, y: f32) -> f32 {
        self.y0 + self.h - (y - self.min.1) * self.scale
    }
    fn len(&self, d: f32) -> f32 {
        d * self.scale
    }
    /// The rectangle of `[x0, x1] × [y0, y1]` as `(x, y, w, h)` in pixels.
    fn rect(&self, x0: f32, x1: f32, y0: f32, y1: f32) -> (f32, f32, f32, f32) {
        (self.x(x0), self.y(y1), self.len(x1 - x0), self.len(y1 - y0))
    }
}

/// A canvas sized for a partition picture of `world`, with its title.
fn partition_canvas(world: &Aabb, title: &str, subtitle: &str) -> (Canvas, View) {
    let v = View::new(world);
    let w = (2.0 * MARGIN + v.len(world.extent().x)).max(700.0);
    let h = TOP + v.h + BOTTOM;
    let mut c = Canvas::new(w as u32, h as u32);
    c.text(MARGIN, 28.0, 2, title, BLACK, Anchor::Start);
    c.text(MARGIN, 52.0, 1, subtitle, GREY, Anchor::Start);
    (c, v)
}

/// The plane `z = z0` used for the cuts: the middle of the world.
fn cut_z(world: &Aabb) -> f32 {
    world.center().z
}

/// Radius of the circle where `s` meets the plane `z = z0`, if it does.
fn cut_radius(s: &Sphere, z0: f32) -> Option<f32> {
    let dz = s.center.z - z0;
    let r2 = s.radius * s.radius - dz * dz;
    (r2 > 0.0).then(|| r2.sqrt())
}

/// A colour on a light-to-dark ramp, `t` in `[0, 1]`.
fn ramp(t: f32) -> Rgba {
    const STOPS: [(f32, f32, f32); 4] = [
        (253.0, 231.0, 37.0),
        (53.0, 183.0, 121.0),
        (49.0, 104.0, 142.0),
        (68.0, 1.0, 84.0),
    ];
    let t = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f32;
    let i = (t.floor() as usize).min(STOPS.len() - 2);
    let f = t - i as f32;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let mix = |x: f32, y: f32| (x + (y - x) * f).round() as u8;
    Rgba::rgb(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// A horizontal colour bar from `lo` to `hi` labelled `label`, at `(x, y)`.
fn ramp_legend(c: &mut Canvas, x: f32, y: f32, label: &str, lo: usize, hi: usize) {
    let steps = (hi - lo + 1).clamp(2, 24);
    let w = 16.0;
    for i in 0..steps {
        let t = i as f32 / (steps - 1) as f32;
        c.rect(x + i as f32 * w, y, w, 14.0, Some(ramp(t)), None);
    }
    c.rect(x, y, w * steps as f32, 14.0, None, Some((GREY, 1.0)));
    c.text(x, y + 30.0, 1, &lo.to_string(), BLACK, Anchor::Start);
    c.text(
        x + w * steps as f32,
        y + 30.0,
        1,
        &hi.to_string(),
        BLACK,
        Anchor::End,
    );
    c.text(
        x + w * steps as f32 + 12.0,
        y + 12.0,
        1,
        label,
        BLACK,
        Anchor::Start,
    );
}

/// The loose k-d tree over `spheres`, cut by the horizontal plane through the
/// middle of the world: split lines of the nodes that plane meets, their border
/// zones (where the two children overlap) shaded, and the spheres cut by the plane
/// coloured by the depth of the node holding them [sources: figures].
pub fn kd_partition(spheres: &[Sphere], hint: &SceneHint) -> Result<Canvas, String> {
    let mut tree =
        LooseKdTree::with_config(LooseKdConfig::for_scene(hint)).map_err(|e| e.to_string())?;
    let handles = spheres
        .iter()
        .enumerate()
        .map(|(i, s)| tree.insert(*s, i as u64))
        .collect::<proxima::Result<Vec<_>>>()
        .map_err(|e| e.to_string())?;
    let world = hint.world;
    let z0 = cut_z(&world);
    let stats = tree.stats();
    // A window at the world's corner, about 25 of the largest spheres wide: the
    // whole world of a large scene is too dense to read.
    let side = (25.0 * hint.r_max).max(1.0);
    let e = world.extent();
    let (full, win) = if e.x.max(e.y) <= side * 1.5 {
        (true, world)
    } else {
        let mut w = world;
        w.max.x = w.min.x + side.min(e.x);
        w.max.y = w.min.y + side.min(e.y);
        (false, w)
    };
    let place = if full {
        format!("plane z = {z0:.1}")
    } else {
        format!(
            "shown x, y in [{:.0}, {:.0}] of a {:.0} x {:.0} world; plane z = {z0:.1}",
            win.min.x, win.max.x, e.x, e.y
        )
    };
    // Title and subtitle are drawn last, over the clipping margins.
    let (mut c, v) = partition_canvas(&win, "", "");
    let world = win;
    let (wx, wy, ww, wh) = v.rect(world.min.x, world.max.x, world.min.y, world.max.y);
    c.rect(wx, wy, ww, wh, Some(Rgba::rgb(250, 250, 250)), None);
    // Nodes whose cell meets the plane partition it; x and y splits show as
    // lines, z splits only choose which child the plane goes through.
    let mut splits = Vec::new();
    tree.for_each_node(|n| {
        let on_plane = n.cell.min.z <= z0 && z0 <= n.cell.max.z;
        if on_plane && n.axis < 2 && n.children != [false, false] {
            splits.push(*n);
        }
    });
    let zone = Rgba::rgb(150, 80, 200).alpha(45);
    for n in &splits {
        let (lo, hi) = (n.mid - n.half_width, n.mid + n.half_width);
        let r = if n.axis == 0 {
            v.rect(lo, hi, n.cell.min.y, n.cell.max.y)
        } else {
            v.rect(n.cell.min.x, n.cell.max.x, lo, hi)
        };
        c.rect(r.0, r.1, r.2, r.3, Some(zone), None);
    }
    let max_depth = stats.max_depth.max(1);
    let mut cut = 0;
    for (s, h) in spheres.iter().zip(&handles) {
        if let Some(r) = cut_radius(s, z0) {
            if !world.grown(r).contains_point(s.center.with_z(world.min.z)) {
                continue;
            }
            cut += 1;
            let d = tree.placement(*h).map(|p| p.depth).unwrap_or(0);
            let col = ramp(d as f32 / max_depth as f32);
            c.circle(
                v.x(s.center.x),
                v.y(s.center.y),
                v.len(r).max(1.0),
                Some(col.alpha(200)),
                Some((BLACK.alpha(120), 0.6)),
            );
        }
    }
    let top = splits.iter().map(|n| n.depth).min().unwrap_or(0);
    for n in &splits {
        let w = (3.0 - 0.3 * (n.depth - top) as f32).max(0.8);
        let line = if n.axis == 0 {
            vec![
                (v.x(n.mid), v.y(n.cell.min.y)),
                (v.x(n.mid), v.y(n.cell.max.y)),
            ]
        } else {
            vec![
                (v.x(n.cell.min.x), v.y(n.mid)),
                (v.x(n.cell.max.x), v.y(n.mid)),
            ]
        };
        c.polyline(line, BLACK, w);
    }
    // Clip: cover what was drawn outside the window.
    let white = Some(Rgba::rgb(255, 255, 255));
    let (cw, ch) = (c.width as f32, c.height as f32);
    c.rect(0.0, 0.0, cw, wy, white, None);
    c.rect(0.0, wy + wh, cw, ch - wy - wh, white, None);
    c.rect(0.0, 0.0, wx, ch, white, None);
    c.rect(wx + ww, 0.0, cw - wx - ww, ch, white, None);
    c.rect(wx, wy, ww, wh, None, Some((BLACK, 2.0)));
    c.text(
        MARGIN,
        28.0,
        2,
        "Loose k-d tree, cut by the plane z = const",
        BLACK,
        Anchor::Start,
    );
    c.text(
        MARGIN,
        52.0,
        1,
        &format!(
            "{} spheres, {} nodes, depth {}; {place}",
            spheres.len(),
            stats.nodes,
            stats.max_depth,
        ),
        GREY,
        Anchor::Start,
    );
    let y = TOP + v.h + 28.0;
    c.rect(MARGIN, y - 2.0, 28.0, 14.0, Some(zone), None);
    c.polyline(
        vec![(MARGIN + 14.0, y - 4.0), (MARGIN + 14.0, y + 14.0)],
        BLACK,
        1.5,
    );
    c.text(
        MARGIN + 40.0,
        y + 10.0,
        1,
        &format!(
            "split plane of a node (thicker = nearer the root), border zone [m-h, m+h] \
             (h <= R_max = {}),",
            hint.r_max
        ),
        BLACK,
        Anchor::Start,
    );
    c.text(
        MARGIN + 40.0,
        y + 24.0,
        1,
        "shared by both children: a sphere goes to the side of its centre, never to both",
        BLACK,
        Anchor::Start,
    );
    ramp_legend(
        &mut c,
        MARGIN,
        y + 44.0,
        &format!("depth of the node holding a sphere ({cut} spheres cut by the plane shown)"),
        0,
        max_depth,
    );
    Ok(c)
}

/// The linear octree over `spheres`, cut by the horizontal plane through the
/// middle of the world: the leaf cells the plane meets, shaded by how many objects
/// they hold, and the bounding boxes of the objects cut by the plane
/// [sources: figures].
pub fn octree_partition(spheres: &[Sphere], hint: &SceneHint) -> Result<Canvas, String> {
    let mut tree =
        LinearOctree::with_config(OctreeConfig::for_scene(hint)).map_err(|e| e.to_string())?;
    for (i, s) in spheres.iter().enumerate() {
        tree.insert(*s, i as u64).map_err(|e| e.to_string())?;
    }
    let world = *tree.root_cell();
    let z0 = cut_z(&hint.world);
    let cap = tree.config().max_per_leaf;
    let mut leaves = Vec::new();
    let mut all_leaves = 0;
    tree.for_each_leaf(|code, n| {
        all_leaves += 1;
        let b = tree.cell_box(code);
        if b.min.z <= z0 && z0 < b.max.z {
            leaves.push((b, n, code.depth()));
        }
    });
    let max_depth = leaves.iter().map(|l| l.2).max().unwrap_or(0);
    let (mut c, v) = partition_canvas(
        &world,
        "Linear octree, leaf cells cut by the plane z = const",
        &format!(
            "{} spheres, {all_leaves} leaves (depth <= {max_depth}); plane z = {z0:.1}; \
             a leaf splits above {cap} objects",
            spheres.len()
        ),
    );
    for (b, n, _) in &leaves {
        let t = *n as f32 / cap as f32;
        let (x, y, w, h) = v.rect(b.min.x, b.max.x, b.min.y, b.max.y);
        let fill = Rgba::rgb(255, 255, 255).shade(1.0 - 0.35 * t.min(1.0));
        let fill = Rgba(fill.0, fill.1, ((fill.2 as f32) * 0.5 + 127.0) as u8, 255);
        c.rect(x, y, w, h, Some(fill), None);
    }
    let boxes = palette(3).alpha(200);
    let mut cut = 0;
    for s in spheres {
        if let Some(r) = cut_radius(s, z0) {
            cut += 1;
            let (x, y, w, h) = v.rect(
                s.center.x - r,
                s.center.x + r,
                s.center.y - r,
                s.center.y + r,
            );
            c.rect(x, y, w, h, None, Some((boxes, 1.0)));
        }
    }
    for (b, _, d) in &leaves {
        let (x, y, w, h) = v.rect(b.min.x, b.max.x, b.min.y, b.max.y);
        let width = (2.6 - 0.3 * *d as f32).max(0.7);
        c.rect(x, y, w, h, None, Some((BLACK.alpha(220), width)));
    }
    let (wx, wy, ww, wh) = v.rect(world.min.x, world.max.x, world.min.y, world.max.y);
    c.rect(wx, wy, ww, wh, None, Some((BLACK, 2.0)));
    if hint.world.extent().y < world.extent().y * 0.999 {
        // The root cell is a cube around a flatter world: show the world too.
        let (x, y, w, h) = v.rect(
            hint.world.min.x,
            hint.world.max.x,
            hint.world.min.y,
            hint.world.max.y,
        );
        c.rect(x, y, w, h, None, Some((palette(0), 1.5)));
    }
    let y = TOP + v.h + 28.0;
    c.rect(
        MARGIN,
        y - 2.0,
        28.0,
        14.0,
        Some(Rgba::rgb(166, 166, 210)),
        Some((BLACK, 1.5)),
    );
    c.text(
        MARGIN + 40.0,
        y + 10.0,
        1,
        &format!(
            "leaf cell (thicker = larger), darker = more objects (0..{cap}); an object is \
             in the leaf of its centre"
        ),
        BLACK,
        Anchor::Start,
    );
    c.rect(MARGIN + 7.0, y + 28.0, 14.0, 14.0, None, Some((boxes, 1.0)));
    c.text(
        MARGIN + 40.0,
        y + 40.0,
        1,
        &format!(
            "box of an object cut by the plane ({cut}); queries grow a cell by the \
             largest object below it"
        ),
        BLACK,
        Anchor::Start,
    );
    Ok(c)
}

/// One series of the time chart: a name and `(frame, ms)` points.
pub struct Series {
    /// Legend text.
    pub name: String,
    /// Points, frames 1-based.
    pub points: Vec<(usize, f64)>,
}

/// Time per frame (update + pairs) per index, log scale, one line per index.
pub fn time_chart(title: &str, series: &[Series]) -> Canvas {
    let (w, h) = (960.0f32, 560.0f32);
    let (l, r, t, b) = (90.0f32, 200.0f32, 60.0f32, 60.0f32);
    let mut c = Canvas::new(w as u32, h as u32);
    c.text(l, 30.0, 2, title, BLACK, Anchor::Start);
    let pts = series.iter().flat_map(|s| s.points.iter());
    let frames = pts.clone().map(|p| p.0).max().unwrap_or(1).max(2);
    let lo = pts
        .clone()
        .map(|p| p.1)
        .filter(|v| *v > 0.0)
        .fold(f64::INFINITY, f64::min);
    let hi = pts.map(|p| p.1).fold(0.0, f64::max);
    let (lo, hi) = if lo.is_finite() && hi > 0.0 {
        (
            10f64.powf(lo.log10().floor()),
            10f64.powf(hi.log10().ceil()),
        )
    } else {
        (0.1, 10.0)
    };
    let hi = hi.max(lo * 10.0);
    let (pw, ph) = (w - l - r, h - t - b);
    let px = |f: usize| l + (f - 1) as f32 / (frames - 1) as f32 * pw;
    let py = |ms: f64| {
        let v = (ms.max(lo).log10() - lo.log10()) / (hi.log10() - lo.log10());
        t + ph - v as f32 * ph
    };
    // Grid: decades and their 2x, 5x.
    let mut d = lo;
    while d <= hi * 1.0001 {
        for (k, major) in [(1.0, true), (2.0, false), (5.0, false)] {
            let v = d * k;
            if v > hi * 1.0001 {
                break;
            }
            let y = py(v);
            c.polyline(
                vec![(l, y), (l + pw, y)],
                if major {
                    GREY.alpha(160)
                } else {
                    GREY.alpha(60)
                },
                1.0,
            );
            if major || ph / ((hi / lo).log10() as f32) > 120.0 {
                c.text(l - 8.0, y + 4.0, 1, &fmt_ms(v), BLACK, Anchor::End);
            }
        }
        d *= 10.0;
    }
    let step = ((frames as f32 / 10.0).ceil() as usize).max(1);
    for f in (1..=frames).filter(|f| (f - 1) % step == 0 || *f == frames) {
        c.polyline(vec![(px(f), t + ph), (px(f), t + ph + 5.0)], BLACK, 1.0);
        c.text(
            px(f),
            t + ph + 20.0,
            1,
            &f.to_string(),
            BLACK,
            Anchor::Middle,
        );
    }
    c.rect(l, t, pw, ph, None, Some((BLACK, 1.0)));
    c.text(l + pw / 2.0, h - 14.0, 1, "frame", BLACK, Anchor::Middle);
    c.text(
        l - 80.0,
        t - 12.0,
        1,
        "ms per frame (log)",
        BLACK,
        Anchor::Start,
    );
    for (i, s) in series.iter().enumerate() {
        let col = palette(i);
        let line: Vec<_> = s.points.iter().map(|&(f, v)| (px(f), py(v))).collect();
        if line.len() > 1 {
            c.polyline(line.clone(), col, 2.0);
        }
        for p in &line {
            c.circle(p.0, p.1, 3.0, Some(col), None);
        }
        let ly = t + 20.0 + i as f32 * 24.0;
        c.polyline(
            vec![(l + pw + 16.0, ly - 4.0), (l + pw + 40.0, ly - 4.0)],
            col,
            3.0,
        );
        c.text(l + pw + 48.0, ly, 1, &s.name, BLACK, Anchor::Start);
    }
    c
}

fn fmt_ms(v: f64) -> String {
    if v >= 1.0 {
        format!("{v:.0}")
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').to_string()
    }
}

/// A projected triangle: depth along the view, 2D corners, colour.
type Tri2 = (f32, [(f32, f32); 3], Rgba);

/// Cuts `t` into 4 at its edge midpoints until no edge is longer than `limit`
/// (at most `levels` times).
fn subdivide(t: [Vec3; 3], limit: f32, levels: u32, out: &mut Vec<[Vec3; 3]>) {
    let longest = (t[0] - t[1])
        .length()
        .max((t[1] - t[2]).length())
        .max((t[2] - t[0]).length());
    if longest <= limit || levels == 0 {
        out.push(t);
        return;
    }
    let m = [
        (t[0] + t[1]) * 0.5,
        (t[1] + t[2]) * 0.5,
        (t[2] + t[0]) * 0.5,
    ];
    for piece in [
        [t[0], m[0], m[2]],
        [m[0], t[1], m[1]],
        [m[2], m[1], t[2]],
        [m[0], m[1], m[2]],
    ] {
        subdivide(piece, limit, levels - 1, out);
    }
}

/// Two meshes, `a` moved by `pose`, in an orthographic view from above at
/// `(1, -1.5, 1)` (flat shading, painter's order, farthest first), framed on `a`
/// and the part of `b` near it. Triangles listed in `pairs` (indices into `a` and `b`)
/// are filled red (those of `b` lighter, since they may be large) and outlined on
/// top, so that hidden ones still show.
pub fn meshes(
    title: &str,
    a: &TriMesh,
    pose: &Affine3A,
    b: &TriMesh,
    pairs: &[(u32, u32)],
) -> Canvas {
    let (w, h) = (900.0f32, 800.0f32);
    let eye = Vec3::new(1.0, -1.5, 1.0).normalize();
    let right = Vec3::Z.cross(eye).normalize();
    let upv = eye.cross(right).normalize();
    let light = (eye + upv * 0.5 + right * 0.3).normalize();
    let mut hit_a = vec![false; a.len()];
    let mut hit_b = vec![false; b.len()];
    for &(i, j) in pairs {
        if let Some(x) = hit_a.get_mut(i as usize) {
            *x = true;
        }
        if let Some(x) = hit_b.get_mut(j as usize) {
            *x = true;
        }
    }
    let col_a = Rgba::rgb(70, 130, 220);
    let col_b = Rgba::rgb(215, 195, 150);
    let red = Rgba::rgb(235, 20, 20);
    let pink = Rgba::rgb(250, 150, 140);
    // Only the part of `b` near `a` is drawn (a room around a robot would hide it):
    // triangles whose box meets `a`'s box grown by half its size, and every hit.
    let posed: Vec<[Vec3; 3]> = (0..a.len())
        .map(|i| a.triangle(i).map(|p| pose.transform_point3(p)))
        .collect();
    let mut abox = Aabb::EMPTY;
    for p in posed.iter().flatten() {
        abox = abox.union(&Aabb::new(*p, *p));
    }
    let size = abox.extent().max_element().max(1e-6);
    let near = abox.grown(size * 0.5);
    let shown: Vec<(usize, [Vec3; 3])> = (0..b.len())
        .map(|i| (i, b.triangle(i)))
        .filter(|(i, t)| {
            let bb = Aabb::new(t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
            hit_b[*i] || bb.intersects_aabb(&near)
        })
        .collect();
    let project = |p: Vec3| (p.dot(right), p.dot(upv));
    // Frame: `a` with room around it (three times its size), or everything drawn
    // if that is smaller.
    let mut union = (
        (f32::INFINITY, f32::INFINITY),
        (f32::NEG_INFINITY, f32::NEG_INFINITY),
    );
    let grow = |r: &mut ((f32, f32), (f32, f32)), q: (f32, f32)| {
        r.0 = (r.0 .0.min(q.0), r.0 .1.min(q.1));
        r.1 = (r.1 .0.max(q.0), r.1 .1.max(q.1));
    };
    let mut around = union;
    for p in posed.iter().flatten() {
        grow(&mut around, project(*p));
    }
    for p in posed.iter().chain(shown.iter().map(|(_, t)| t)).flatten() {
        grow(&mut union, project(*p));
    }
    let pad = (around.1 .0 - around.0 .0)
        .max(around.1 .1 - around.0 .1)
        .max(1e-6);
    let around = (
        (around.0 .0 - pad, around.0 .1 - pad),
        (around.1 .0 + pad, around.1 .1 + pad),
    );
    let area = |r: ((f32, f32), (f32, f32))| (r.1 .0 - r.0 .0) * (r.1 .1 - r.0 .1);
    let (lo, hi) = if area(union) <= area(around) {
        union
    } else {
        around
    };
    // Widen the frame to the drawing area's aspect ratio.
    let (top, bottom, side) = (60.0, 70.0, 30.0);
    let (aw, ah) = (w - 2.0 * side, h - top - bottom);
    let (fw, fh) = ((hi.0 - lo.0).max(1e-6), (hi.1 - lo.1).max(1e-6));
    let (lo, hi) = if fw / fh < aw / ah {
        let extra = (fh * aw / ah - fw) / 2.0;
        ((lo.0 - extra, lo.1), (hi.0 + extra, hi.1))
    } else {
        let extra = (fw * ah / aw - fh) / 2.0;
        ((lo.0, lo.1 - extra), (hi.0, hi.1 + extra))
    };
    // Painter's order fails when a huge triangle (a floor) is sorted as one piece,
    // so triangles are cut into pieces no larger than a tenth of `a`, and only
    // pieces inside the frame are kept.
    let limit = size / 10.0;
    let in_frame = |t: &[Vec3; 3]| {
        let q = t.map(project);
        let (x0, x1) = (
            q[0].0.min(q[1].0).min(q[2].0),
            q[0].0.max(q[1].0).max(q[2].0),
        );
        let (y0, y1) = (
            q[0].1.min(q[1].1).min(q[2].1),
            q[0].1.max(q[1].1).max(q[2].1),
        );
        x1 >= lo.0 && x0 <= hi.0 && y1 >= lo.1 && y0 <= hi.1
    };
    let mut tris: Vec<Tri2> = Vec::new();
    let mut outlines = Vec::new();
    let mut pieces = Vec::new();
    let items = posed
        .iter()
        .enumerate()
        .map(|(i, t)| (t, hit_a[i], col_a, red))
        .chain(shown.iter().map(|(i, t)| (t, hit_b[*i], col_b, pink)));
    for (t, hit, base, hit_col) in items {
        if !in_frame(t) {
            continue;
        }
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        let shade = if n.length_squared() > 0.0 {
            0.45 + 0.55 * n.normalize().dot(light).abs()
        } else {
            0.45
        };
        let colour = if hit { hit_col } else { base }.shade(shade);
        if hit {
            outlines.push(t.map(project));
        }
        pieces.clear();
        subdivide(*t, limit, 6, &mut pieces);
        for p in pieces.iter().filter(|p| in_frame(p)) {
            // Distance from the eye grows as the dot with `eye` falls.
            let depth = -(p[0] + p[1] + p[2]).dot(eye) / 3.0;
            tris.push((depth, p.map(project), colour));
        }
    }
    let shown_b = shown.len();
    let span = ((hi.0 - lo.0) / (w - 2.0 * side)).max((hi.1 - lo.1) / (h - top - bottom));
    let scale = if span > 0.0 && span.is_finite() {
        1.0 / span
    } else {
        1.0
    };
    let ox = side + ((w - 2.0 * side) - (hi.0 - lo.0) * scale) / 2.0;
    let oy = top + ((h - top - bottom) - (hi.1 - lo.1) * scale) / 2.0;
    let map = |p: (f32, f32)| (ox + (p.0 - lo.0) * scale, oy + (hi.1 - p.1) * scale);
    let mut c = Canvas::new(w as u32, h as u32);
    tris.sort_by(|x, y| y.0.total_cmp(&x.0));
    for (_, p, col) in &tris {
        let pts = p.iter().map(|q| map(*q)).collect();
        // Stroked in their own colour: hides the seams between pieces.
        c.polygon(pts, Some(*col), Some((*col, 0.8)));
    }
    for p in &outlines {
        let pts = p.iter().map(|q| map(*q)).collect();
        c.polygon(pts, None, Some((red, 1.5)));
    }
    // Clip to the drawing area; title and legend go on white bands.
    let white = Some(Rgba::rgb(255, 255, 255));
    c.rect(0.0, 0.0, w, top - 10.0, white, None);
    c.rect(0.0, h - bottom + 10.0, w, bottom, white, None);
    c.rect(0.0, 0.0, side, h, white, None);
    c.rect(w - side, 0.0, side, h, white, None);
    c.text(30.0, 28.0, 2, title, BLACK, Anchor::Start);
    let y = h - 40.0;
    c.rect(side, y - 12.0, 14.0, 14.0, Some(col_a), None);
    c.text(
        side + 22.0,
        y,
        1,
        &format!("A: {} triangles (posed)", a.len()),
        BLACK,
        Anchor::Start,
    );
    c.rect(side + 300.0, y - 12.0, 14.0, 14.0, Some(col_b), None);
    c.text(
        side + 322.0,
        y,
        1,
        &format!("B: {} triangles, the {shown_b} near A shown", b.len()),
        BLACK,
        Anchor::Start,
    );
    c.rect(side, y + 8.0, 14.0, 14.0, Some(red), None);
    c.rect(side + 16.0, y + 8.0, 14.0, 14.0, Some(pink), None);
    c.text(
        side + 38.0,
        y + 20.0,
        1,
        &format!(
            "intersecting triangles of A and B: {} pairs, {} of A, {} of B (outlined even if hidden)",
            pairs.len(),
            hit_a.iter().filter(|x| **x).count(),
            hit_b.iter().filter(|x| **x).count()
        ),
        BLACK,
        Anchor::Start,
    );
    c
}

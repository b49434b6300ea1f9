//! The picture of one frame of the demo's world scene: every object's posed
//! mesh in an orthographic view from above a corner of the box (flat shading,
//! painter's order, farthest first), the touching triangles in red and outlined
//! on top (most lie inside the meshes), the box's edges, a title and a legend
//! [sources: world].

use crate::draw::{Anchor, Canvas, Rgba, BLACK, GREY};

/// Colours of the mesh kinds (no red: red marks touching triangles).
const KINDS: [Rgba; 6] = [
    Rgba::rgb(70, 130, 200),
    Rgba::rgb(230, 170, 60),
    Rgba::rgb(80, 170, 90),
    Rgba::rgb(150, 110, 200),
    Rgba::rgb(60, 190, 200),
    Rgba::rgb(170, 170, 170),
];

fn kind_colour(k: usize) -> Rgba {
    KINDS[k % KINDS.len()]
}
use proxima::glam::{Affine3A, Vec3};
use proxima::narrow::TriMesh;

/// A projected triangle: depth along the view, 2D corners, colour.
type Tri2 = (f32, [(f32, f32); 3], Rgba);

/// One object to draw: its mesh, its pose, its mesh kind (colour), and which
/// of its triangles touch another object.
pub struct Drawn<'a> {
    pub mesh: &'a TriMesh,
    pub pose: Affine3A,
    pub kind: usize,
    pub hit: Vec<bool>,
}

/// Whether every triangle of `mesh` faces outwards in a closed, consistently
/// oriented surface (each directed edge once, its reverse once, positive
/// volume): then its back faces are hidden and need not be drawn. O(t log t).
pub fn closed_outward(mesh: &TriMesh) -> bool {
    let mut edges: Vec<(u32, u32)> = mesh
        .triangles()
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .collect();
    edges.sort_unstable();
    let unique = edges.windows(2).all(|w| w[0] != w[1]);
    let paired = edges
        .iter()
        .all(|&(a, b)| edges.binary_search(&(b, a)).is_ok());
    let volume: f64 = (0..mesh.len())
        .map(|i| {
            let [a, b, c] = mesh.triangle(i).map(|p| p.as_dvec3());
            a.dot(b.cross(c))
        })
        .sum();
    unique && paired && volume > 0.0
}

/// Draws `objects` inside the box `[0, side]³`. `skip_back[kind]`: that kind's
/// back faces are hidden ([`closed_outward`]). Triangles smaller than a
/// twentieth of a pixel (area) are dropped: invisible. The legend names the kinds.
pub fn world_frame(
    title: &str,
    objects: &[Drawn<'_>],
    side: f32,
    kinds: &[String],
    skip_back: &[bool],
    legend: &str,
) -> Canvas {
    let (w, h) = (900.0f32, 900.0f32);
    let (top, bottom, margin) = (50.0, 80.0, 20.0);
    let eye = Vec3::new(1.0, -1.4, 1.1).normalize();
    let right = Vec3::Z.cross(eye).normalize();
    let up = eye.cross(right).normalize();
    let light = (eye + up * 0.6 + right * 0.3).normalize();
    let project = |p: Vec3| (p.dot(right), p.dot(up));
    // Frame: the box's eight corners.
    let (mut lo, mut hi) = (
        (f32::INFINITY, f32::INFINITY),
        (f32::NEG_INFINITY, f32::NEG_INFINITY),
    );
    let corners: Vec<Vec3> = (0..8)
        .map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, (i >> 2) as f32) * side)
        .collect();
    for c in &corners {
        let q = project(*c);
        lo = (lo.0.min(q.0), lo.1.min(q.1));
        hi = (hi.0.max(q.0), hi.1.max(q.1));
    }
    let scale = ((w - 2.0 * margin) / (hi.0 - lo.0)).min((h - top - bottom) / (hi.1 - lo.1));
    let ox = margin + ((w - 2.0 * margin) - (hi.0 - lo.0) * scale) / 2.0;
    let oy = top + ((h - top - bottom) - (hi.1 - lo.1) * scale) / 2.0;
    let map = |p: Vec3| {
        let q = project(p);
        (ox + (q.0 - lo.0) * scale, oy + (hi.1 - q.1) * scale)
    };
    let red = Rgba::rgb(235, 20, 20);
    let mut tris: Vec<Tri2> = Vec::new();
    // Touching triangles are outlined on top too: most lie inside the meshes.
    let mut outlines: Vec<[(f32, f32); 3]> = Vec::new();
    for o in objects {
        let base = kind_colour(o.kind);
        let cull = skip_back.get(o.kind).copied().unwrap_or(false);
        for i in 0..o.mesh.len() {
            let t = o.mesh.triangle(i).map(|p| o.pose.transform_point3(p));
            let n = (t[1] - t[0]).cross(t[2] - t[0]);
            let hit = o.hit.get(i).copied().unwrap_or(false);
            if cull && !hit && n.dot(eye) < 0.0 {
                continue;
            }
            let p = t.map(map);
            let area = ((p[1].0 - p[0].0) * (p[2].1 - p[0].1)
                - (p[2].0 - p[0].0) * (p[1].1 - p[0].1))
                .abs();
            if area < 0.1 && !hit {
                continue;
            }
            let shade = if n.length_squared() > 0.0 {
                0.4 + 0.6 * n.normalize().dot(light).abs()
            } else {
                0.4
            };
            let colour = if hit { red } else { base }.shade(shade);
            if hit {
                outlines.push(p);
            }
            tris.push(((t[0] + t[1] + t[2]).dot(eye), p, colour));
        }
    }
    // Farthest first: the smallest dot with `eye`.
    tris.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut c = Canvas::new(w as u32, h as u32);
    // The box's hidden edges first (behind everything), its visible ones last.
    let edges: Vec<(usize, usize)> = (0..8usize)
        .flat_map(|i| [1usize, 2, 4].map(|b| (i, i | b)))
        .filter(|&(i, j)| i != j)
        .collect();
    let depth = |i: usize, j: usize| (corners[i] + corners[j]).dot(eye);
    let mid = (corners[0] + corners[7]).dot(eye);
    for &(i, j) in edges.iter().filter(|&&(i, j)| depth(i, j) < mid) {
        c.polyline(vec![map(corners[i]), map(corners[j])], GREY, 1.0);
    }
    let drawn = tris.len();
    for (_, p, col) in tris {
        c.polygon(p.to_vec(), Some(col), Some((col, 0.6)));
    }
    for p in outlines {
        c.polygon(p.to_vec(), None, Some((red, 0.8)));
    }
    for &(i, j) in edges.iter().filter(|&&(i, j)| depth(i, j) >= mid) {
        c.polyline(vec![map(corners[i]), map(corners[j])], GREY, 1.0);
    }
    c.text(margin, 32.0, 2, title, BLACK, Anchor::Start);
    let mut x = margin;
    let y = h - 48.0;
    for (k, name) in kinds.iter().enumerate() {
        c.rect(x, y - 12.0, 14.0, 14.0, Some(kind_colour(k)), None);
        c.text(x + 20.0, y, 1, name, BLACK, Anchor::Start);
        x += 40.0 + Canvas::text_width(name, 1);
    }
    c.rect(x, y - 12.0, 14.0, 14.0, Some(red), None);
    c.text(
        x + 20.0,
        y,
        1,
        "touching (outlined on top)",
        BLACK,
        Anchor::Start,
    );
    c.text(
        margin,
        h - 22.0,
        1,
        &format!("{legend}; {drawn} triangles drawn"),
        BLACK,
        Anchor::Start,
    );
    c
}

//! Constructed meshes with exact coordinates: subdivided cubes (closed, with
//! parallel faces and shared edges and corners between copies) and meshes of
//! degenerate triangles.

use proxima::glam::Vec3;
use proxima::narrow::TriMesh;

/// The cube `[0, s]³` with each face split into `n × n` squares of two
/// triangles: closed, every edge shared by exactly two triangles. Coordinates
/// are multiples of `s / n` (exact for powers of two).
pub fn cube(n: u32, s: f32) -> TriMesh {
    let mut v = Vec::new();
    let mut t = Vec::new();
    // Each face: a grid on (u, w) at fixed coordinate `axis` = 0 or s, wound so
    // the normal points out.
    for axis in 0..3 {
        for side in [0.0f32, 1.0] {
            let base = v.len() as u32;
            for j in 0..=n {
                for i in 0..=n {
                    let mut p = [0.0f32; 3];
                    p[axis] = side * s;
                    p[(axis + 1) % 3] = s * i as f32 / n as f32;
                    p[(axis + 2) % 3] = s * j as f32 / n as f32;
                    v.push(Vec3::from_array(p));
                }
            }
            let id = |i: u32, j: u32| base + j * (n + 1) + i;
            for j in 0..n {
                for i in 0..n {
                    let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                    if side == 1.0 {
                        t.push([a, b, c]);
                        t.push([a, c, d]);
                    } else {
                        t.push([a, c, b]);
                        t.push([a, d, c]);
                    }
                }
            }
        }
    }
    // Weld the duplicated vertices of the face grids (exact coordinates).
    weld(v, t)
}

/// Merges vertices with identical coordinates.
pub fn weld(v: Vec<Vec3>, t: Vec<[u32; 3]>) -> TriMesh {
    let mut keys: Vec<(u32, u32, u32)> = v
        .iter()
        .map(|p| (p.x.to_bits(), p.y.to_bits(), p.z.to_bits()))
        .collect();
    let mut uniq = keys.clone();
    uniq.sort_unstable();
    uniq.dedup();
    let index = |k: &(u32, u32, u32)| uniq.binary_search(k).unwrap() as u32;
    let verts: Vec<Vec3> = uniq
        .iter()
        .map(|&(x, y, z)| Vec3::new(f32::from_bits(x), f32::from_bits(y), f32::from_bits(z)))
        .collect();
    let map: Vec<u32> = keys.iter_mut().map(|k| index(k)).collect();
    let tris = t.iter().map(|tr| tr.map(|i| map[i as usize])).collect();
    TriMesh::new(verts, tris).unwrap()
}

/// `m` with its triangles' orientation flipped (the same surface).
pub fn flipped(m: &TriMesh) -> TriMesh {
    let t = m.triangles().iter().map(|&[a, b, c]| [a, c, b]).collect();
    TriMesh::new(m.vertices().to_vec(), t).unwrap()
}

/// `m` plus degenerate triangles on its vertices: a point `[i, i, i]`, a
/// segment `[i, j, j]` and a collinear triple (with a midpoint vertex) for every
/// `step`-th vertex.
pub fn with_degenerate(m: &TriMesh, step: usize) -> TriMesh {
    let mut v = m.vertices().to_vec();
    let mut t = m.triangles().to_vec();
    let n = v.len();
    for i in (0..n).step_by(step) {
        let j = (i * 7 + 3) % n;
        t.push([i as u32; 3]);
        t.push([i as u32, j as u32, j as u32]);
        v.push((v[i] + v[j]) * 0.5);
        t.push([i as u32, (v.len() - 1) as u32, j as u32]);
    }
    TriMesh::new(v, t).unwrap()
}

/// Only degenerate triangles: points and segments between `m`'s vertices.
pub fn degenerate_only(m: &TriMesh, step: usize) -> TriMesh {
    let n = m.vertices().len();
    let t = (0..n)
        .step_by(step)
        .flat_map(|i| {
            [
                [i as u32; 3],
                [i as u32, ((i * 13 + 5) % n) as u32, i as u32],
            ]
        })
        .collect();
    TriMesh::new(m.vertices().to_vec(), t).unwrap()
}

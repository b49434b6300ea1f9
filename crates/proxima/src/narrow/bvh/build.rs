//! Top-down binary build [sources: bvh-build].

use super::options::{BuildOptions, SplitRule};
use super::tree::{coord_bound, subtree_sizes, Bvh, Node};
use crate::geom::Aabb;
use crate::narrow::bv::BoundingVolume;
use crate::narrow::TriMesh;
use crate::Result;
use glam::Vec3;

const BINS: usize = 16;

impl<BV: BoundingVolume> Bvh<BV> {
    /// Builds the hierarchy of `mesh` top-down: each node's volume is fitted to its
    /// triangles, and nodes with more than `leaf_size` triangles are split by
    /// `options.split`. O(n log n) for the median and SAH rules (each level fits
    /// every triangle once); the mean rule may build deeper trees on clustered input.
    ///
    /// Fails with [`Error::InvalidParameter`](crate::Error::InvalidParameter) on
    /// `leaf_size == 0`.
    pub fn build(mesh: &TriMesh, options: BuildOptions) -> Result<Bvh<BV>> {
        options.check()?;
        Ok(Bvh::build_valid(mesh, options))
    }

    /// [`Bvh::build`] with options already checked.
    pub(crate) fn build_valid(mesh: &TriMesh, options: BuildOptions) -> Bvh<BV> {
        let n = mesh.len();
        let centroids: Vec<Vec3> = (0..n)
            .map(|i| {
                let [a, b, c] = mesh.triangle(i);
                (a + b + c) / 3.0
            })
            .collect();
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes: Vec<Node<BV>> = Vec::with_capacity(2 * n);
        let mut scratch: Vec<[Vec3; 3]> = Vec::new();
        // (start, end, parent whose right child this is)
        let mut stack: Vec<(usize, usize, Option<usize>)> = vec![(0, n, None)];
        while let Some((start, end, right_of)) = stack.pop() {
            let idx = nodes.len();
            if let Some(p) = right_of {
                nodes[p].start = idx as u32;
            }
            scratch.clear();
            scratch.extend(order[start..end].iter().map(|&t| mesh.triangle(t as usize)));
            let bv = BV::from_triangles(&scratch);
            let count = end - start;
            if count <= options.leaf_size {
                nodes.push(Node {
                    bv,
                    start: start as u32,
                    count: count as u32,
                });
                continue;
            }
            let mid = split(mesh, &centroids, &mut order[start..end], options.split) + start;
            nodes.push(Node {
                bv,
                start: 0,
                count: 0,
            });
            // Left child popped first, so it lands at idx + 1.
            stack.push((mid, end, Some(idx)));
            stack.push((start, mid, None));
        }
        let tris = order
            .iter()
            .map(|&t| mesh.triangles()[t as usize])
            .collect();
        Bvh {
            subtree: subtree_sizes(&nodes),
            nodes,
            tris,
            ids: order,
            mesh: mesh.stamp(),
            coord_bound: coord_bound(mesh.vertices()),
            options,
        }
    }
}

/// Partitions `order` (at least 2 triangles) and returns the size of the left part,
/// always in `1..order.len()`.
fn split(mesh: &TriMesh, centroids: &[Vec3], order: &mut [u32], rule: SplitRule) -> usize {
    let mut cb = Aabb::EMPTY;
    for &t in order.iter() {
        let c = centroids[t as usize];
        cb.min = cb.min.min(c);
        cb.max = cb.max.max(c);
    }
    let axis = cb.longest_axis();
    let n = order.len();
    if cb.extent()[axis] <= 0.0 {
        // All centroids coincide: any halving is as good.
        return n / 2;
    }
    match rule {
        SplitRule::Median => median_split(centroids, order, axis),
        SplitRule::Mean => {
            let mean = order
                .iter()
                .map(|&t| centroids[t as usize][axis] as f64)
                .sum::<f64>()
                / n as f64;
            let k = partition(order, |t| (centroids[t as usize][axis] as f64) < mean);
            if k == 0 || k == n {
                median_split(centroids, order, axis)
            } else {
                k
            }
        }
        SplitRule::Sah => sah_split(mesh, centroids, order, &cb)
            .unwrap_or_else(|| median_split(centroids, order, axis)),
    }
}

fn median_split(centroids: &[Vec3], order: &mut [u32], axis: usize) -> usize {
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&a, &b| {
        centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
    });
    mid
}

/// Stable-enough in-place partition; returns the number of elements satisfying `pred`.
fn partition(order: &mut [u32], pred: impl Fn(u32) -> bool) -> usize {
    let mut k = 0;
    for i in 0..order.len() {
        if pred(order[i]) {
            order.swap(i, k);
            k += 1;
        }
    }
    k
}

fn area(b: &Aabb) -> f32 {
    let e = b.extent();
    e.x * e.y + e.y * e.z + e.z * e.x
}

/// Binned SAH over the centroid bounds `cb`; `None` if no bin boundary separates
/// the centroids.
fn sah_split(mesh: &TriMesh, centroids: &[Vec3], order: &mut [u32], cb: &Aabb) -> Option<usize> {
    let ext = cb.extent();
    let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, first right bin)
    for axis in 0..3 {
        if ext[axis] <= 0.0 {
            continue;
        }
        let scale = BINS as f32 / ext[axis];
        let bin_of = |c: Vec3| (((c[axis] - cb.min[axis]) * scale) as usize).min(BINS - 1);
        let mut boxes = [Aabb::EMPTY; BINS];
        let mut counts = [0usize; BINS];
        for &t in order.iter() {
            let b = bin_of(centroids[t as usize]);
            counts[b] += 1;
            for p in mesh.triangle(t as usize) {
                boxes[b].min = boxes[b].min.min(p);
                boxes[b].max = boxes[b].max.max(p);
            }
        }
        // Sweep from the right to get the suffix areas.
        let mut right_area = [0.0f32; BINS];
        let mut right_count = [0usize; BINS];
        let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
        for i in (1..BINS).rev() {
            acc = acc.union(&boxes[i]);
            cnt += counts[i];
            right_area[i] = if cnt > 0 { area(&acc) } else { 0.0 };
            right_count[i] = cnt;
        }
        let (mut acc, mut cnt) = (Aabb::EMPTY, 0);
        for i in 0..BINS - 1 {
            acc = acc.union(&boxes[i]);
            cnt += counts[i];
            let rc = right_count[i + 1];
            if cnt == 0 || rc == 0 {
                continue;
            }
            let cost = area(&acc) * cnt as f32 + right_area[i + 1] * rc as f32;
            if best.is_none_or(|b| cost < b.0) {
                best = Some((cost, axis, i + 1));
            }
        }
    }
    let (_, axis, boundary) = best?;
    // The same bin function as above, so the partition matches the counted bins.
    let scale = BINS as f32 / ext[axis];
    let k = partition(order, |t| {
        let c = centroids[t as usize];
        (((c[axis] - cb.min[axis]) * scale) as usize).min(BINS - 1) < boundary
    });
    (k > 0 && k < order.len()).then_some(k)
}

//! The descents of the distance queries: two trees (mesh–mesh) or one tree
//! against a point, visiting node pairs whose lower bound passes a [`Cut`] that
//! the leaves may lower as they find nearer triangles.

use crate::narrow::bv::{positive, BoundingVolume};
use crate::narrow::bvh::moving::LowerBounds;
use crate::narrow::bvh::Node;
use crate::narrow::Bvh;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// The order in which node pairs are visited.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Order {
    /// Smallest lower bound first (a priority queue): never expands a pair whose
    /// bound exceeds the final distance. The nearest-pair queries use it (on
    /// W5's rob × env, k-DOP18, a third of depth-first's instructions).
    BestFirst,
    /// Depth first, the child pair with the smaller bound first (a stack):
    /// cheaper per pair, but may expand pairs a better answer found later would
    /// have cut. The queries with a fixed cut (within a margin) use it: there
    /// every order visits the same pairs, or stops at the first one found.
    DepthFirst,
}

/// Which lower bounds a descent keeps: `lb < value`, or `lb <= value` when
/// `inclusive`. The leaves lower `value` as they find nearer triangles.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Cut {
    pub value: f64,
    pub inclusive: bool,
}

impl Cut {
    /// Whether a volume pair with lower bound `lb` may hold a pair the query wants.
    #[inline(always)]
    pub(crate) fn keeps(&self, lb: f32) -> bool {
        self.keeps_distance(lb as f64)
    }

    /// Whether a triangle pair at distance `d` is one the query wants.
    #[inline(always)]
    pub(crate) fn keeps_distance(&self, d: f64) -> bool {
        d < self.value || (self.inclusive && d == self.value)
    }
}

/// Heap key, one `u128` (cheap to compare and move): the bound's bits (bounds
/// are non-negative, so their bits sort like their values), then the complements
/// of the node indices, so that among equal bounds the deeper pairs (larger
/// pre-order indices) come first and ties at `0` (overlapping volumes) dive to
/// the leaves.
#[inline(always)]
fn key(lb: f32, ia: u32, ib: u32) -> Reverse<u128> {
    Reverse(((lb.to_bits() as u128) << 64) | ((!ia as u128) << 32) | (!ib as u128))
}

#[inline(always)]
fn unkey(Reverse(k): Reverse<u128>) -> (f32, u32, u32) {
    (
        f32::from_bits((k >> 64) as u32),
        !((k >> 32) as u32),
        !(k as u32),
    )
}

/// A kept node pair: its lower bound, then the nodes.
type Entry = (f32, u32, u32);

/// The scratch space of the descents (kept by the query object: no allocation
/// per query once warm).
#[derive(Clone, Debug, Default)]
pub(crate) struct Frontier {
    heap: BinaryHeap<Reverse<u128>>,
    stack: Vec<Entry>,
}

impl Frontier {
    fn clear(&mut self) {
        self.heap.clear();
        self.stack.clear();
    }

    #[inline(always)]
    fn push(&mut self, order: Order, (lb, ia, ib): Entry) {
        match order {
            Order::BestFirst => self.heap.push(key(lb, ia, ib)),
            Order::DepthFirst => self.stack.push((lb, ia, ib)),
        }
    }

    /// The next pair, or `None` when the rest is cut (best-first: every pair left
    /// has a bound at least the popped one's).
    #[inline(always)]
    fn pop(&mut self, order: Order, cut: &Cut) -> Option<Entry> {
        match order {
            Order::BestFirst => {
                let e = unkey(self.heap.pop()?);
                cut.keeps(e.0).then_some(e)
            }
            Order::DepthFirst => loop {
                let e = self.stack.pop()?;
                if cut.keeps(e.0) {
                    return Some(e);
                }
            },
        }
    }

    /// Of the two child pairs `x` and `y`, pushes those kept by the cut except
    /// the one to visit next, returned: the nearer, if nothing waiting is nearer
    /// (best-first; always for depth first). Continuing with it directly saves a
    /// push and a pop without changing the visiting order.
    #[inline(always)]
    fn split(&mut self, order: Order, cut: &Cut, x: Entry, y: Entry) -> Option<Entry> {
        let (near, far) = if y.0 < x.0 { (y, x) } else { (x, y) };
        if cut.keeps(far.0) {
            self.push(order, far);
        }
        if !cut.keeps(near.0) {
            return None;
        }
        let first = match order {
            Order::BestFirst => self.heap.peek().is_none_or(|&top| near.0 <= unkey(top).0),
            Order::DepthFirst => true,
        };
        if first {
            Some(near)
        } else {
            self.push(order, near);
            None
        }
    }
}

/// What a descent hands to its visitor.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Visit {
    /// A kept pair of leaves `(a_node, b_node)` and its lower bound.
    Leaf(usize, usize, f32),
    /// Every pair with bound `0` has been visited (best-first: before the first
    /// pair with a positive bound; depth first: at the end). Sent once.
    Settle,
}

/// Descends the moving tree `a` (volumes from `src`) and the fixed tree `b` from
/// their roots. A kept pair of internal nodes is split on the larger volume (or
/// the side that is not a leaf), as in collision; each child pair's bound is one
/// volume test (`nv`). A kept pair of leaves goes to `visit(Visit::Leaf(..),
/// cut)`, which may lower the cut and returns true to stop; so does
/// [`Visit::Settle`]. Each leaf pair is reached at most once. Returns true if
/// stopped.
#[allow(clippy::too_many_arguments)]
pub(crate) fn descend<BV: BoundingVolume>(
    a: &Bvh<BV>,
    src: &mut impl LowerBounds<BV>,
    b: &Bvh<BV>,
    order: Order,
    frontier: &mut Frontier,
    nv: &mut u64,
    cut: &mut Cut,
    mut visit: impl FnMut(Visit, &mut Cut) -> bool,
) -> bool {
    frontier.clear();
    *nv += 1;
    let root = positive(src.lower_bound(0, &b.nodes[0].bv));
    let mut next = cut.keeps(root).then_some((root, 0, 0));
    let mut settled = false;
    while let Some((lb, ia, ib)) = next.take().or_else(|| frontier.pop(order, cut)) {
        if lb > 0.0 && !settled && order == Order::BestFirst {
            settled = true;
            if visit(Visit::Settle, cut) {
                return true;
            }
            if !cut.keeps(lb) {
                break; // every pair left has a bound >= lb
            }
        }
        let (na, nb) = (&a.nodes[ia as usize], &b.nodes[ib as usize]);
        let split_a = match (na.is_leaf(), nb.is_leaf()) {
            (true, true) => {
                if visit(Visit::Leaf(ia as usize, ib as usize, lb), cut) {
                    return true;
                }
                continue;
            }
            (false, true) => true,
            (true, false) => false,
            (false, false) => src.size(ia as usize) >= nb.bv.size(),
        };
        *nv += 2;
        next = if split_a {
            let (l, r) = na.children(ia);
            let x = positive(src.lower_bound(l as usize, &nb.bv));
            let y = positive(src.lower_bound(r as usize, &nb.bv));
            frontier.split(order, cut, (x, l, ib), (y, r, ib))
        } else {
            let (l, r) = nb.children(ib);
            let x = positive(src.lower_bound(ia as usize, &b.nodes[l as usize].bv));
            let y = positive(src.lower_bound(ia as usize, &b.nodes[r as usize].bv));
            frontier.split(order, cut, (x, ia, l), (y, ia, r))
        };
    }
    !settled && visit(Visit::Settle, cut)
}

/// Descends one tree against a fixed volume `probe` (a point or a ball, inflated
/// by the rounding slack): the single-tree form of [`descend`]. `leaf(node, lb,
/// cut)` returns true to stop. Returns true if stopped.
pub(crate) fn descend_one<BV: BoundingVolume>(
    nodes: &[Node<BV>],
    probe: &BV,
    order: Order,
    frontier: &mut Frontier,
    nv: &mut u64,
    cut: &mut Cut,
    mut leaf: impl FnMut(usize, f32, &mut Cut) -> bool,
) -> bool {
    frontier.clear();
    *nv += 1;
    let root = positive(nodes[0].bv.distance_lower_bound_fixed(probe));
    let mut next = cut.keeps(root).then_some((root, 0, 0));
    while let Some((lb, i, _)) = next.take().or_else(|| frontier.pop(order, cut)) {
        let n = &nodes[i as usize];
        if n.is_leaf() {
            if leaf(i as usize, lb, cut) {
                return true;
            }
            continue;
        }
        *nv += 2;
        let (l, r) = n.children(i);
        let x = positive(nodes[l as usize].bv.distance_lower_bound_fixed(probe));
        let y = positive(nodes[r as usize].bv.distance_lower_bound_fixed(probe));
        next = frontier.split(order, cut, (x, l, 0), (y, r, 0));
    }
    false
}

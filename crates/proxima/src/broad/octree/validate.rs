//! `validate()`: every invariant of the octree, checked from scratch.

use super::code::{LocationCode, MAX_DEPTH};
use super::node::{bit, octant_of, NONE};
use super::query::child_coords;
use super::LinearOctree;
use crate::{Error, Result};

fn fail<R>(msg: String) -> Result<R> {
    Err(Error::Invalid(format!("octree: {msg}")))
}

/// `a <= b`, false when either is NaN.
fn le(a: f32, b: f32) -> bool {
    a.partial_cmp(&b).is_some_and(|o| o.is_le())
}

/// What a subtree check returns to its parent.
struct Sub {
    count: u32,
    nodes: usize,
    items: usize,
    max_ext: f32,
}

impl<T> LinearOctree<T> {
    /// Checks: the arena; the map and the node pool agree (every map entry names a
    /// node with that code, every reachable node is in the map and nothing else is
    /// live); parent/child links and codes; leaves hold items and no children,
    /// inner nodes children and no items; counts are exact; every non-root node
    /// holds at least one object and every inner node at least `merge_below`
    /// (hysteresis state: nothing is left that should have merged); no leaf above
    /// `max_depth` holds more than `max_per_leaf`; each object is in the leaf of its
    /// (clamped) centre, with its slot, sphere, key and extent recorded
    /// consistently; `max_extent` is never below any extent in the subtree; every
    /// sphere lies inside its leaf's loose box; per-depth counts; spare lists empty;
    /// the inert count.
    /// O(n + nodes).
    pub(super) fn validate_tree(&self) -> Result<()> {
        self.objects.validate()?;
        if self.map.len() != self.nodes.len() {
            return fail(format!(
                "map has {} entries, pool {} live nodes",
                self.map.len(),
                self.nodes.len()
            ));
        }
        for (&code, &i) in &self.map {
            if i as usize >= self.nodes.slot_count() || self.nodes.free_slots().contains(&i) {
                return fail(format!("map entry {code:#x} names a free node {i}"));
            }
            if self.nodes[i].code.raw() != code {
                return fail(format!(
                    "map entry {code:#x} names node of code {:?}",
                    self.nodes[i].code
                ));
            }
        }
        if self.map.get(&LocationCode::ROOT.raw()) != Some(&self.root)
            || self.nodes[self.root].parent != NONE
        {
            return fail("root not registered or has a parent".into());
        }
        let mut per_depth = [0u32; MAX_DEPTH as usize + 1];
        let sub = self.check_node(self.root, [0; 3], 0, &mut per_depth)?;
        if sub.nodes != self.map.len() {
            return fail(format!(
                "{} nodes reachable, {} registered",
                sub.nodes,
                self.map.len()
            ));
        }
        if sub.items != self.objects.len() || sub.count as usize != self.objects.len() {
            return fail(format!(
                "{} items in leaves, count {}, {} objects",
                sub.items,
                sub.count,
                self.objects.len()
            ));
        }
        if per_depth != self.per_depth {
            return fail("per-depth node counts are stale".into());
        }
        if self.spare.iter().any(|v| !v.is_empty()) {
            return fail("a spare item list is not empty".into());
        }
        self.inert.check(self.objects.iter().map(|(_, o)| o.filter))
    }

    fn check_node(&self, i: u32, c: [u32; 3], d: u32, per_depth: &mut [u32]) -> Result<Sub> {
        let n = &self.nodes[i];
        let expect = LocationCode::from_coords(d, c).expect("coords in range");
        if n.code != expect {
            return fail(format!(
                "node {i} has code {:?}, expected {expect:?}",
                n.code
            ));
        }
        if d > self.config.max_depth {
            return fail(format!("node {:?} deeper than max_depth", n.code));
        }
        per_depth[d as usize] += 1;
        if !le(0.0, n.max_extent) {
            return fail(format!("node {:?} max_extent {}", n.code, n.max_extent));
        }
        let mut sub = Sub {
            count: 0,
            nodes: 1,
            items: 0,
            max_ext: 0.0,
        };
        if n.leaf {
            if n.children.iter().any(|&ch| ch != NONE) {
                return fail(format!("leaf {:?} has children", n.code));
            }
            if n.items.len() > self.config.max_per_leaf as usize && d < self.config.max_depth {
                return fail(format!(
                    "leaf {:?} holds {} > max_per_leaf above max_depth",
                    n.code,
                    n.items.len()
                ));
            }
            let loose = self.loose_of(c, d, n.max_extent);
            // First-hit scans take only the slots of the octants a cast
            // reaches, judged by the octants' loose boxes (`child_halves`).
            let halves = (d < MAX_DEPTH).then(|| self.child_halves(n, c, d));
            let mut octants = [0u64; 8];
            for (slot, it) in n.items.iter().enumerate() {
                let Ok(o) = self.objects.get(it.handle) else {
                    return fail(format!("leaf {:?} holds a dead handle", n.code));
                };
                if o.leaf != i || o.slot as usize != slot {
                    return fail(format!(
                        "object's leaf/slot record is wrong in {:?}",
                        n.code
                    ));
                }
                if o.sphere != it.sphere || o.ext != it.ext {
                    return fail("item copy differs from the object".into());
                }
                if self.placement(&o.sphere) != (o.key, o.ext) {
                    return fail("stored key/extent differ from the sphere's placement".into());
                }
                if o.key >> (3 * (MAX_DEPTH - d)) != n.code.raw() {
                    return fail(format!(
                        "object not in the leaf of its centre ({:?})",
                        n.code
                    ));
                }
                if !le(it.ext, n.max_extent) {
                    return fail(format!("max_extent of leaf {:?} too small", n.code));
                }
                // Filtered walks skip a node on its filter bits.
                if o.filter.group & !n.groups != 0 || o.filter.mask & !n.masks != 0 {
                    return fail(format!("filter bits of leaf {:?} miss an object's", n.code));
                }
                if !loose.contains_aabb(&o.sphere.aabb()) {
                    return fail(format!(
                        "sphere {:?} outside loose box of {:?}",
                        o.sphere, n.code
                    ));
                }
                if let (Some(k), Some(h)) = (octant_of(o.key, d), halves) {
                    octants[k] |= bit(slot);
                    let b = o.sphere.aabb();
                    let inside = (0..3).all(|a| {
                        let (l, u) = h[a][(k >> a) & 1];
                        le(l, b.min[a]) && le(b.max[a], u)
                    });
                    if !inside {
                        return fail(format!(
                            "sphere {:?} outside the loose box of its octant {k} of {:?}",
                            o.sphere, n.code
                        ));
                    }
                }
                sub.max_ext = sub.max_ext.max(it.ext);
            }
            if octants != self.octants[i as usize] {
                return fail(format!("octant masks of leaf {:?} are wrong", n.code));
            }
            sub.count = n.items.len() as u32;
            sub.items = n.items.len();
        } else {
            if !n.items.is_empty() {
                return fail(format!("inner node {:?} holds items", n.code));
            }
            if self.octants[i as usize] != [0; 8] {
                return fail(format!("inner node {:?} has octant masks", n.code));
            }
            if n.children.iter().all(|&ch| ch == NONE) {
                return fail(format!("inner node {:?} has no children", n.code));
            }
            for (k, &ch) in n.children.iter().enumerate() {
                if ch == NONE {
                    continue;
                }
                if self.nodes[ch].parent != i {
                    return fail(format!("child of {:?} has a wrong parent", n.code));
                }
                let cn = &self.nodes[ch];
                if cn.groups & !n.groups != 0 || cn.masks & !n.masks != 0 {
                    return fail(format!("filter bits of {:?} miss a child's", n.code));
                }
                let s = self.check_node(ch, child_coords(c, k), d + 1, per_depth)?;
                if !le(s.max_ext, n.max_extent) || !le(self.nodes[ch].max_extent, n.max_extent) {
                    return fail(format!("max_extent of {:?} below a child's", n.code));
                }
                sub.count += s.count;
                sub.nodes += s.nodes;
                sub.items += s.items;
                sub.max_ext = sub.max_ext.max(s.max_ext);
            }
            if sub.count < self.config.merge_below {
                return fail(format!(
                    "inner node {:?} holds {} < merge_below objects (missed merge)",
                    n.code, sub.count
                ));
            }
        }
        if sub.count != n.count {
            return fail(format!(
                "node {:?} count {} != {}",
                n.code, n.count, sub.count
            ));
        }
        if i != self.root && sub.count == 0 {
            return fail(format!("empty node {:?} kept", n.code));
        }
        if i == self.root && !n.leaf && sub.count == 0 {
            return fail("empty inner root".into());
        }
        Ok(sub)
    }
}

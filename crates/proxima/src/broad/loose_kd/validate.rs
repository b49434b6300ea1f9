//! `validate()`: every structural invariant, checked from scratch.

use super::node::{all_space, slack, split_of, NIL};
use super::store::CHUNK;
use super::LooseKdTree;
use crate::{Error, Result};

fn fail(msg: String) -> Result<()> {
    Err(Error::Invalid(msg))
}

impl<T> LooseKdTree<T> {
    /// Checks: arena and pool free lists; parent/child links; each node's box,
    /// cell, split axis, `m`, `h` and `h_up` re-derived from its parent (the root's
    /// from the world box); `h` never growing downwards; the depth cap; no empty
    /// node; every stored object's handle live and locating exactly its slot, and
    /// every object placed exactly where the placement rule puts it (with the
    /// object count, this makes handles and slots a bijection); node ranges inside the object array,
    /// disjoint, live positions filled and the rest empty, the dead count exact;
    /// `span` covering the world and every sphere. O(nodes + array length).
    pub(super) fn validate_impl(&self) -> Result<()> {
        self.items.validate()?;
        let slots = self.nodes.slot_count();
        let mut free = vec![false; slots];
        for &i in self.nodes.free_slots() {
            let Some(seen) = free.get_mut(i as usize) else {
                return fail(format!("free node slot {i} out of range"));
            };
            if *seen {
                return fail(format!("node slot {i} freed twice"));
            }
            *seen = true;
        }
        if self.store.chunk.len() != self.store.sphere.len().div_ceil(CHUNK) {
            return fail("chunk bounds do not match the object array".into());
        }
        if self.store.sphere.len() != self.store.entry.len() {
            return fail("object array columns differ in length".into());
        }
        let mut owned = vec![false; self.store.len()];
        if !self.span.contains_aabb(&self.world) || self.eps != slack(&self.span) {
            return fail("span does not cover the world or eps is stale".into());
        }
        if self.root == NIL {
            if !self.nodes.is_empty() || !self.items.is_empty() || self.inert.any() {
                return fail("no root but live nodes, items or inert count".into());
            }
            return Ok(());
        }
        let mut reached = 0usize;
        let mut items_seen = 0usize;
        let mut stack = vec![self.root];
        while let Some(n) = stack.pop() {
            if (n as usize) >= slots || free[n as usize] {
                return fail(format!("node {n} is free or out of range but linked"));
            }
            reached += 1;
            if reached > self.nodes.len() {
                return fail("cycle in the node links".into());
            }
            let node = &self.nodes[n];
            // Derivation from the parent (or the world box for the root).
            let (bbox, cell, h_up, depth) = if n == self.root {
                if node.parent != NIL {
                    return fail("root has a parent".into());
                }
                (self.world, all_space(), f32::INFINITY, 0u8)
            } else {
                let p = &self.nodes[node.parent];
                let side = match p.child {
                    [a, _] if a == n => 0,
                    [_, b] if b == n => 1,
                    _ => return fail(format!("node {n} is not a child of its parent")),
                };
                let (b, c) = p.child_bounds(side);
                (b, c, p.h, p.depth + 1)
            };
            let (axis, m, h) = split_of(&bbox, self.r_max, self.density);
            if node.bbox != bbox
                || node.cell != cell
                || node.h_up != h_up
                || node.depth != depth
                || (node.axis, node.m, node.h) != (axis, m, h)
            {
                return fail(format!(
                    "node {n}: box, cell or split not derived from parent"
                ));
            }
            if node.h > node.h_up {
                return fail(format!("node {n}: h grows downwards"));
            }
            if node.depth > self.max_depth
                || (node.depth == self.max_depth && node.child != [NIL, NIL])
            {
                return fail(format!("node {n}: depth cap exceeded"));
            }
            if node.is_empty() {
                return fail(format!("node {n}: empty node not freed"));
            }
            // Objects: each one's handle is live and locates exactly this slot,
            // and it sits where the placement rule puts it.
            let (start, cap) = (node.start as usize, node.cap as usize);
            if node.len > node.cap || start + cap > owned.len() {
                return fail(format!("node {n}: range out of the array or overfull"));
            }
            for (p, o) in owned.iter_mut().enumerate().skip(start).take(cap) {
                if std::mem::replace(o, true) {
                    return fail(format!("node {n}: range overlaps another"));
                }
                if p >= start + node.len as usize && self.store.entry[p].is_some() {
                    return fail(format!("node {n}: spare position {p} not empty"));
                }
            }
            for (pos, p) in node.range().enumerate() {
                let Some((handle, filter, _)) = &self.store.entry[p] else {
                    return fail(format!("node {n}: live position {p} empty"));
                };
                // Filtered walks skip a node on its filter bits.
                if filter.group & !node.groups != 0 || filter.mask & !node.masks != 0 {
                    return fail(format!("node {n}: filter bits miss an object's"));
                }
                match self.items.get(*handle) {
                    Ok(loc) if loc.node == n && loc.pos as usize == pos => {}
                    _ => {
                        return fail(format!(
                            "node {n} slot {pos}: handle dead or located elsewhere"
                        ))
                    }
                }
                let s = &self.store.sphere[p];
                let here = s.radius >= node.h || node.depth >= self.max_depth;
                if !node.routes(s) || !here {
                    return fail(format!(
                        "object in node {n} (depth {}) breaks the placement rule",
                        node.depth
                    ));
                }
                if !self.span.contains_aabb(&s.aabb()) {
                    return fail(format!("object in node {n} outside span"));
                }
                // Queries skip a chunk on its bound (`store.rs`).
                if !node.loose && !self.store.chunk[p / CHUNK].contains_aabb(&s.aabb()) {
                    return fail(format!("object at {p} outside its chunk bound"));
                }
            }
            items_seen += node.len as usize;
            for c in node.child {
                if c != NIL {
                    if (c as usize) >= slots || free[c as usize] || self.nodes[c].parent != n {
                        return fail(format!("node {n}: child {c} bad or not linked back"));
                    }
                    let ch = &self.nodes[c];
                    if ch.groups & !node.groups != 0 || ch.masks & !node.masks != 0 {
                        return fail(format!("node {n}: filter bits miss child {c}'s"));
                    }
                    stack.push(c);
                }
            }
        }
        if reached != self.nodes.len() {
            return fail(format!(
                "{reached} nodes reachable but {} live",
                self.nodes.len()
            ));
        }
        if items_seen != self.items.len() {
            return fail(format!(
                "{items_seen} objects in nodes but {} stored",
                self.items.len()
            ));
        }
        let dead = owned.iter().filter(|&&o| !o).count();
        if dead != self.store.dead {
            return fail(format!(
                "{dead} dead positions but {} counted",
                self.store.dead
            ));
        }
        for (p, o) in owned.iter().enumerate() {
            if !o && self.store.entry[p].is_some() {
                return fail(format!("dead position {p} not empty"));
            }
        }
        // Every other position is empty (checked above): these are the live ones.
        (self.inert).check(self.store.entry.iter().flatten().map(|(_, f, _)| *f))
    }
}

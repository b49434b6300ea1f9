//! The brute-force index: a flat list scanned by every query. It is the oracle the
//! other indices are tested against, and the baseline of the benchmarks.

use crate::arena::{Arena, Handle};
use crate::broad::{Selection, SpatialIndex};
use crate::geom::{overlap, Sphere};
use crate::Result;
use std::ops::ControlFlow;

/// Stores spheres in an [`Arena`] and answers every query by testing each one.
///
/// Insert, remove and update are O(1); queries are O(n); pairs are O(n²). Its
/// answers are the definition of right for every other index (same closed tests
/// from [`geom::overlap`](crate::geom::overlap)).
#[derive(Clone, Debug)]
pub struct BruteForce<T> {
    items: Arena<(Sphere, T)>,
}

impl<T> Default for BruteForce<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T> BruteForce<T> {
    /// An empty index.
    pub fn new() -> Self {
        BruteForce {
            items: Arena::new(),
        }
    }
}

impl<T: Send + Sync> SpatialIndex<T> for BruteForce<T> {
    fn insert(&mut self, sphere: Sphere, value: T) -> Result<Handle> {
        sphere.validate()?;
        Ok(self.items.insert((sphere, value)))
    }

    fn remove(&mut self, handle: Handle) -> Result<T> {
        self.items.remove(handle).map(|(_, v)| v)
    }

    fn update(&mut self, handle: Handle, sphere: Sphere) -> Result<()> {
        sphere.validate()?;
        self.items.get_mut(handle)?.0 = sphere;
        Ok(())
    }

    fn get(&self, handle: Handle) -> Result<(Sphere, &T)> {
        self.items.get(handle).map(|(s, v)| (*s, v))
    }

    fn get_mut(&mut self, handle: Handle) -> Result<&mut T> {
        self.items.get_mut(handle).map(|(_, v)| v)
    }

    fn len(&self) -> usize {
        self.items.len()
    }

    fn clear(&mut self) {
        self.items.clear();
    }

    fn for_each(&self, mut f: impl FnMut(Handle, &Sphere, &T)) {
        for (h, (s, v)) in self.items.iter() {
            f(h, s, v);
        }
    }

    fn visit<Q: Selection + ?Sized>(
        &self,
        query: &Q,
        mut f: impl FnMut(Handle, &Sphere, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        for (h, (s, v)) in self.items.iter() {
            if query.selects(s) {
                f(h, s, v)?;
            }
        }
        ControlFlow::Continue(())
    }

    fn for_each_pair(
        &self,
        mut f: impl FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>,
    ) -> ControlFlow<()> {
        let all: Vec<_> = self.items.iter().collect();
        for (i, (ha, (sa, va))) in all.iter().enumerate() {
            for (hb, (sb, vb)) in &all[i + 1..] {
                if overlap::sphere_sphere(sa, sb) {
                    f(*ha, va, *hb, vb)?;
                }
            }
        }
        ControlFlow::Continue(())
    }

    fn validate(&self) -> Result<()> {
        self.items.validate()
    }

    fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>() + self.items.heap_bytes()
    }
}

//! Parallel pair finding [sources: parallel]: the node-vs-node walk of `pairs.rs` split
//! into independent rayon tasks near the top of the tree.
//!
//! At a node, once its own objects are tested (against each other and the active
//! set carried down from its ancestors), three jobs remain that share nothing but
//! the read-only tree: the walk of the negative child, the walk of the positive
//! child, and `cross` between them. Down to [`TASK_DEPTH`] they run under
//! `rayon::join`, each with its own buffers (a child task gets a copy of the
//! carried set, narrowed to what reaches the child) and its own accumulator;
//! below it a task runs the sequential walk. Every pair is found by exactly one
//! task, the same one that finds it in the sequential walk, so the reported set
//! is identical.

use super::node::NIL;
use super::pairs::Buffers;
use super::LooseKdTree;
use crate::broad::ParallelPairs;
use crate::Handle;
use std::ops::ControlFlow;

/// Nodes at this depth or deeper (root = 0) run their whole subtree as one task:
/// up to 2⁶ subtree tasks plus the `cross` tasks above them, enough for rayon to
/// balance a few threads while each task stays long compared with a `join`.
const TASK_DEPTH: u8 = 6;

/// Runs `job` with a callback that folds every reported pair into `acc`.
fn folding<T, A>(
    acc: A,
    fold: &(impl Fn(A, Handle, &T, Handle, &T) -> A + Sync),
    job: impl FnOnce(&mut dyn FnMut(Handle, &T, Handle, &T) -> ControlFlow<()>),
) -> Option<A> {
    let mut acc = Some(acc);
    job(&mut |ha, va, hb, vb| {
        acc = acc.take().map(|a| fold(a, ha, va, hb, vb));
        ControlFlow::Continue(())
    });
    acc
}

/// Cost: the sequential node-vs-node walk divided over the pool's threads, plus a
/// copy of the carried set per task near the top (small: few objects stop that
/// high) and one `reduce` per task. With one thread it is the sequential walk.
impl<T: Send + Sync> ParallelPairs<T> for LooseKdTree<T> {
    fn par_fold_pairs<A, I, F, R>(&self, init: I, fold: F, reduce: R) -> A
    where
        A: Send,
        I: Fn() -> A + Sync + Send,
        F: Fn(A, Handle, &T, Handle, &T) -> A + Sync + Send,
        R: Fn(A, A) -> A + Sync + Send,
    {
        if self.root == NIL {
            return init();
        }
        let split = rayon::current_num_threads() > 1;
        self.par_node(
            self.root,
            0,
            Buffers::default(),
            split,
            &init,
            &fold,
            &reduce,
        )
    }
}

impl<T: Send + Sync> LooseKdTree<T> {
    /// All pairs within the subtree of `n` plus its objects against the active
    /// set `b.c[active..]`, as the sequential `self_pairs`, folded into one value.
    #[allow(clippy::too_many_arguments)]
    fn par_node<A, I, F, R>(
        &self,
        n: u32,
        active: usize,
        mut b: Buffers,
        split: bool,
        init: &I,
        fold: &F,
        reduce: &R,
    ) -> A
    where
        A: Send,
        I: Fn() -> A + Sync + Send,
        F: Fn(A, Handle, &T, Handle, &T) -> A + Sync + Send,
        R: Fn(A, A) -> A + Sync + Send,
    {
        let node = &self.nodes[n];
        if !split || node.depth >= TASK_DEPTH {
            return folding(init(), fold, |f| {
                let _ = self.self_pairs(n, active, &mut b, &mut &mut *f);
            })
            .unwrap_or_else(init);
        }
        let own = folding(init(), fold, |f| {
            let _ = self.own_pairs(n, active, &mut b, &mut &mut *f);
        })
        .unwrap_or_else(init);
        let end = b.c.len();
        let b = &b;
        let child = |side: usize| -> A {
            let c = node.child[side];
            if c == NIL {
                return init();
            }
            let mut cb = Buffers::default();
            cb.c.copy_from(&b.c, end);
            let child_active = self.narrow(n, side, active, end, &mut cb.c);
            self.par_node(c, child_active, cb, split, init, fold, reduce)
        };
        let cross = || -> A {
            if node.child[0] == NIL || node.child[1] == NIL {
                return init();
            }
            let mut cb = Buffers::default();
            folding(init(), fold, |f| {
                let _ = self.cross(n, &mut cb, &mut &mut *f);
            })
            .unwrap_or_else(init)
        };
        let ((neg, pos), across) = rayon::join(|| rayon::join(|| child(0), || child(1)), cross);
        reduce(reduce(reduce(own, neg), pos), across)
    }
}

//! Counts node (box) tests and sphere tests per query of W4's batches, per index.
use proxima::broad::{loose_kd, LinearOctree, LooseKdTree, OctreeConfig, Selection, SpatialIndex};
use proxima::geom::{Aabb, Relation, Sphere};
use proxima_bench::w4::queries;
use proxima_bench::workloads::{cube_side, Kind, Workload};
use std::cell::Cell;

struct Count<'a, Q>(&'a Q, Cell<u64>, Cell<u64>);
impl<Q: Selection> Selection for Count<'_, Q> {
    fn validate(&self) -> proxima::Result<()> {
        self.0.validate()
    }
    fn selects(&self, s: &Sphere) -> bool {
        self.2.set(self.2.get() + 1);
        self.0.selects(s)
    }
    fn classify_box(&self, b: &Aabb, m: u8) -> (Relation, u8) {
        self.1.set(self.1.get() + 1);
        self.0.classify_box(b, m)
    }
    fn bounds(&self) -> Option<Aabb> {
        self.0.bounds()
    }
}

fn probe<I: SpatialIndex<u32>>(name: &str, idx: &I, b: &queries::Batches) {
    let run = |qs: &mut dyn Iterator<Item = (u64, u64, u64)>, kind: &str| {
        let (mut boxes, mut tests, mut hits, mut n) = (0, 0, 0, 0);
        for (x, y, z) in qs {
            boxes += x;
            tests += y;
            hits += z;
            n += 1;
        }
        println!(
            "{name:<12} {kind:<7} boxes/q {:>7.1} tests/q {:>7.1} hits/q {:>6.2}",
            boxes as f64 / n as f64,
            tests as f64 / n as f64,
            hits as f64 / n as f64
        );
    };
    run(
        &mut b.spheres.iter().map(|q| {
            let c = Count(q, Cell::new(0), Cell::new(0));
            let mut h = 0;
            let _ = idx.visit(&c, |_, _, _| {
                h += 1;
                std::ops::ControlFlow::Continue(())
            });
            (c.1.get(), c.2.get(), h)
        }),
        "sphere",
    );
    run(
        &mut b.boxes.iter().map(|q| {
            let c = Count(q, Cell::new(0), Cell::new(0));
            let mut h = 0;
            let _ = idx.visit(&c, |_, _, _| {
                h += 1;
                std::ops::ControlFlow::Continue(())
            });
            (c.1.get(), c.2.get(), h)
        }),
        "aabb",
    );
}

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(100_000, |s| s.parse().unwrap());
    let density: f32 = std::env::args()
        .nth(2)
        .map_or(loose_kd::DEFAULT_DENSITY, |s| s.parse().unwrap());
    let w = Workload::new(Kind::W1, n, 1);
    let sc = w.scene();
    let b = queries::generate(cube_side(n), 2000, 10, 1);
    let mut kd = LooseKdTree::new(sc.world, sc.r_max, density).unwrap();
    let mut oc = LinearOctree::new(sc.world, OctreeConfig::default()).unwrap();
    for (i, s) in w.spheres.iter().enumerate() {
        kd.insert(*s, i as u32).unwrap();
        oc.insert(*s, i as u32).unwrap();
    }
    println!("kd stats: {:?}", kd.stats());
    probe("LooseKdTree", &kd, &b);
    probe("LinearOctree", &oc, &b);
}

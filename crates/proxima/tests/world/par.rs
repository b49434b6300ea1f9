//! Parallel contacts equal the sequential ones.

use super::oracle::Sim;
use proxima::narrow::{Kdop18, Obb};
use proxima::world::{ContactMode, ContactReport, WorldConfig};
use proxima::Handle;

/// A report with each handle as `(slot, generation)`: two worlds' handles carry
/// different structure tags, the slots and generations are comparable.
fn slots(r: &ContactReport) -> impl PartialEq + std::fmt::Debug + '_ {
    let h = |h: Handle| (h.index(), h.generation());
    let pairs: Vec<_> = r
        .pairs
        .iter()
        .map(|c| (h(c.a), h(c.b), c.triangles.clone()))
        .collect();
    (pairs, &r.triangles, r.counters)
}

#[test]
fn parallel_contacts_equal_sequential() {
    let mut seq = Sim::<Kdop18>::new(WorldConfig::default(), 11);
    let mut par = Sim::<Kdop18>::new(WorldConfig::default(), 11);
    let mut pairs = 0;
    for step in 0..400 {
        seq.step(30);
        par.step(30);
        if step % 10 == 0 {
            let mode = if step % 20 == 0 {
                ContactMode::All
            } else {
                ContactMode::First
            };
            let mut a = ContactReport::default();
            let mut b = ContactReport::default();
            seq.world.contacts_into(mode, &mut a).unwrap();
            par.world.par_contacts_into(mode, &mut b).unwrap();
            assert_eq!(slots(&a), slots(&b));
            pairs += a.pairs.len();
        }
    }
    assert!(pairs > 0);
    let mut o = Sim::<Obb>::new(WorldConfig::default(), 12);
    for _ in 0..25 {
        o.insert();
    }
    let a = o.world.par_contacts().unwrap();
    o.world.validate().unwrap();
    let b = o.world.contacts().unwrap();
    assert_eq!((a.pairs, a.triangles), (b.pairs, b.triangles), "one world");
}

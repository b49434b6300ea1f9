//! Parallel contacts equal the sequential ones.

use super::oracle::Sim;
use proxima::narrow::{Kdop18, Obb};
use proxima::world::{ContactMode, ContactReport, WorldConfig};

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
            assert_eq!(a, b);
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
    assert_eq!((a.pairs, a.triangles), (b.pairs, b.triangles));
}

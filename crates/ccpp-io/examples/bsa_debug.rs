//! Debug: first collision of basic BSA on one map.
use ccpp_core::planners::bsa::{Bsa, BsaOptions};
use ccpp_core::sim::{simulate, SimConfig};
use ccpp_core::trace::{Event, Record};
use ccpp_core::world::{Robot, World};
use ccpp_io::{load_map, LoadOptions};
fn main() {
    let p = std::env::args().nth(1).unwrap();
    let loaded = load_map(std::path::Path::new(&p), &LoadOptions::default()).unwrap();
    let world = World::new(loaded.grid, Robot::new(0.15), None).unwrap();
    println!("start {:?}", world.start());
    let out = simulate(&world, &mut Bsa::new(BsaOptions::default()), &SimConfig::default());
    let recs = &out.trace.records;
    let k = recs.iter().position(|r| matches!(r, Record::Event { event: Event::Collision { .. }, .. })).unwrap();
    for r in &recs[k.saturating_sub(12)..=k] {
        println!("{r:?}");
    }
}

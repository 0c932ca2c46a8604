//! A bare PGM/PNG image through the map loader (`ccpp_io::load_map_bytes` without a YAML):
//! format detection, decoding and the trinary classification.
#![no_main]

use std::path::Path;

use ccpp_io::map::{load_map_bytes, LoadOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(m) = load_map_bytes(
        Path::new("fuzz/map.png"),
        None,
        data,
        &LoadOptions::default(),
    ) {
        let f = m.grid.frame();
        assert_eq!(m.grid.cells().len(), f.width * f.height);
        // A decoded map is accepted by the world builder or refused with an error, never a panic.
        let _ = ccpp_core::world::World::new(m.grid, ccpp_core::world::Robot::new(0.15), None);
    }
});

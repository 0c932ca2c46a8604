//! The map loader's public in-memory path: `ccpp_io::load_map_bytes` with a YAML and an image.
//! Input: YAML text, a NUL byte, then the image bytes (PGM or PNG).
#![no_main]

use std::path::Path;

use ccpp_io::map::{load_map_bytes, LoadOptions};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((yaml, image)) = ccpp_fuzz::split_text(data) else {
        return;
    };
    if let Ok(m) = load_map_bytes(
        Path::new("fuzz/map.yaml"),
        Some(yaml),
        image,
        &LoadOptions::default(),
    ) {
        let f = m.grid.frame();
        assert_eq!(m.grid.cells().len(), f.width * f.height);
        assert!(f.resolution.is_finite() && f.resolution > 0.0);
    }
});

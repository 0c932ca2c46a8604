//! `--georef` files: `ccpp_io::georef::parse_georef`, then the affine fit the loader runs.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(pairs) = ccpp_io::georef::parse_georef(text) {
        if let Ok(fit) = ccpp_core::georef::fit_affine(&pairs) {
            assert!(fit.affine.m.iter().all(|v| v.is_finite()), "{fit:?}");
        }
    }
});

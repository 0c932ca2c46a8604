//! `--landmarks` files (CSV or JSON): `ccpp_io::landmarks::parse_landmarks`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(list) = ccpp_io::landmarks::parse_landmarks(text) {
        assert!(list
            .iter()
            .all(|l| l.x.is_finite() && l.y.is_finite() && l.theta.is_finite()));
    }
});

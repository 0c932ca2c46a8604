//! Memory a map's decoding allocates, bounded by this binary's own global allocator (a test
//! binary of its own: the bound covers only the one test it runs).
//!
//! A PNG's colour profile (`iCCP`) is inflated whole by the decoder, and its cap was at least
//! the decoder's 512 MiB default: a 0.5 MB file of 100 x 100 pixels whose profile inflates to
//! 500 MiB peaked at 531 MB under `--max-memory 17`. The cap now follows the image's size.
#![allow(clippy::unwrap_used)]

use std::alloc::System;
use std::path::Path;

use cap::Cap;
use ccpp_io::map::{load_map_bytes, LoadOptions};

#[global_allocator]
static ALLOCATOR: Cap<System> = Cap::new(System, usize::MAX);

#[test]
fn a_colour_profile_bomb_is_not_inflated() {
    let (w, h) = (100u32, 100u32);
    let png = {
        let mut info = png::Info::with_size(w, h);
        info.color_type = png::ColorType::Grayscale;
        info.bit_depth = png::BitDepth::Eight;
        info.icc_profile = Some(std::borrow::Cow::Owned(vec![b'A'; 96 << 20]));
        let mut out = Vec::new();
        let mut e = png::Encoder::with_info(&mut out, info)
            .unwrap()
            .write_header()
            .unwrap();
        e.write_image_data(&vec![254u8; (w * h) as usize]).unwrap();
        drop(e);
        out
    };
    assert!(png.len() < 1 << 20, "{}", png.len());
    let opts = LoadOptions {
        resolution: Some(0.05),
        max_pixels: Some(1 << 24),
        ..LoadOptions::default()
    };
    // The profile (96 MiB inflated) is not inflated: the decoder's cap for 10 000 pixels is
    // its room, 4 MiB, whether the chunk is then skipped or the file refused. Beyond 32 MiB
    // more than now an allocation fails (and the test with it).
    ALLOCATOR
        .set_limit(ALLOCATOR.allocated() + (32 << 20))
        .unwrap();
    let loaded = load_map_bytes(Path::new("bomb.png"), None, &png, &opts);
    ALLOCATOR.set_limit(usize::MAX).unwrap();
    match loaded {
        Ok(m) => assert_eq!(m.grid.frame().width, 100),
        Err(e) => assert!(e.to_string().contains("bomb.png"), "{e}"),
    }
}

//! Memory a map's decoding allocates, bounded by this binary's own global allocator (a test
//! binary of its own, whose tests take turns: the bound covers only the one test running).
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

/// The cap is the whole binary's: its tests take turns (another test's allocations would
/// count against it).
static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// A 100 x 100 grey PNG of free pixels (254) whose colour profile inflates to 96 MiB.
fn bomb_png() -> Vec<u8> {
    let (w, h) = (100u32, 100u32);
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
}

/// Runs `f` with allocations capped at 32 MiB beyond what is allocated now (one beyond it
/// fails, and the test with it).
fn within_32_mib<T>(f: impl FnOnce() -> T) -> T {
    ALLOCATOR
        .set_limit(ALLOCATOR.allocated() + (32 << 20))
        .unwrap();
    let out = f();
    ALLOCATOR.set_limit(usize::MAX).unwrap();
    out
}

#[test]
fn a_colour_profile_bomb_is_not_inflated() {
    let _turn = SERIAL
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let png = bomb_png();
    assert!(png.len() < 1 << 20, "{}", png.len());
    let opts = LoadOptions {
        resolution: Some(0.05),
        max_pixels: Some(1 << 24),
        ..LoadOptions::default()
    };
    // The profile (96 MiB inflated) is not inflated: the decoder's cap for 10 000 pixels is
    // its room, 4 MiB (plus the file's size), whether the chunk is then skipped or the file
    // refused.
    let loaded = within_32_mib(|| load_map_bytes(Path::new("bomb.png"), None, &png, &opts));
    match loaded {
        Ok(m) => assert_eq!(m.grid.frame().width, 100),
        Err(e) => assert!(e.to_string().contains("bomb.png"), "{e}"),
    }
}

/// The same bomb as a Nav2 keep-out mask: its size was read with the decoder's default cap
/// (512 MiB), which inflated the profile (520 MB under `--max-memory 30`).
#[test]
fn a_colour_profile_bomb_in_a_keepout_mask_is_not_inflated() {
    let _turn = SERIAL
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let dir = std::env::temp_dir().join(format!("ccpp-mask-bomb-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("mask.png"), bomb_png()).unwrap();
    std::fs::write(
        dir.join("mask.yaml"),
        "image: mask.png\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
    )
    .unwrap();
    let frame = ccpp_core::grid::MapFrame::new(100, 100, 0.05);
    let spec = ccpp_io::zones::ZoneSpec::File(dir.join("mask.yaml"));
    let loaded = within_32_mib(|| spec.load(&frame, true));
    std::fs::remove_dir_all(&dir).ok();
    // A mask of free pixels keeps out nothing: loaded (as an empty mask) or refused, never
    // inflated.
    if let Err(e) = loaded {
        assert!(!e.to_string().contains("Memory limit"), "{e}");
    }
}

/// A PGM whose header claims 20000 x 20000 pixels (400 MB decoded) over a few bytes of data,
/// loaded with a pixel budget that admits it: the decoded buffer that cannot be had is an
/// error naming the file, not an aborted process (the decoder allocates it whole, infallibly,
/// before reading a pixel).
#[test]
fn a_decoded_buffer_that_cannot_be_had_is_an_error() {
    let _turn = SERIAL
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let pgm = b"P5\n20000 20000\n255\n\xfe\xfe".to_vec();
    let opts = LoadOptions {
        resolution: Some(0.05),
        max_pixels: Some(1 << 30),
        ..LoadOptions::default()
    };
    let e = within_32_mib(|| load_map_bytes(Path::new("huge.pgm"), None, &pgm, &opts))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("huge.pgm"), "{e}");
    assert!(
        e.contains("20000 x 20000 pixels take 400000000 bytes decoded, which cannot be allocated"),
        "{e}"
    );
}

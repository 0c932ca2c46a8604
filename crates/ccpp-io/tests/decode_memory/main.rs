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

/// A 40 x 30 px grey PNG of free pixels carrying a `tEXt` chunk of `text_mib` MiB.
fn text_png(text_mib: usize) -> Vec<u8> {
    let (w, h) = (40u32, 30u32);
    let mut info = png::Info::with_size(w, h);
    info.color_type = png::ColorType::Grayscale;
    info.bit_depth = png::BitDepth::Eight;
    info.uncompressed_latin1_text
        .push(png::text_metadata::TEXtChunk::new(
            "Comment",
            "A".repeat(text_mib << 20),
        ));
    let mut out = Vec::new();
    let mut e = png::Encoder::with_info(&mut out, info)
        .unwrap()
        .write_header()
        .unwrap();
    e.write_image_data(&vec![254u8; (w * h) as usize]).unwrap();
    drop(e);
    out
}

/// A file far larger than its pixels can take is refused before the decoder reads its
/// metadata: a 40 x 30 px PNG with a 500 MiB `eXIf` chunk took 1 GB under `--max-memory 20`
/// (the decoder's cap admitted three times the file's size). Within 16 MiB of metadata the
/// file loads (a 6 MB `tEXt` chunk in a small map must).
#[test]
fn metadata_far_beyond_the_pixels_is_refused_unread() {
    let _turn = SERIAL
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let opts = LoadOptions {
        resolution: Some(0.05),
        max_pixels: Some(1 << 24),
        ..LoadOptions::default()
    };
    let big = text_png(40);
    let e = within_32_mib(|| load_map_bytes(Path::new("text.png"), None, &big, &opts))
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("text.png") && e.contains("for 40 x 30 px, more than such an image takes"),
        "{e}"
    );
    drop(big);
    let small = text_png(6);
    let m = within_32_mib(|| load_map_bytes(Path::new("text.png"), None, &small, &opts)).unwrap();
    assert_eq!(m.grid.frame().width, 40);
}

/// A PNM header comment is skipped, not read into memory: a 500 MiB comment took 518 MB. Here
/// a 1000 x 1000 px PGM (room for 40 MiB of file) with a 30 MiB comment loads within 32 MiB.
#[test]
fn a_long_pnm_comment_is_skipped_unread() {
    let _turn = SERIAL
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let (w, h) = (1000usize, 1000usize);
    let mut pgm = b"P5\n# ".to_vec();
    pgm.resize(pgm.len() + (30 << 20), b'x');
    pgm.extend_from_slice(format!("\n{w} {h}\n255\n").as_bytes());
    pgm.resize(pgm.len() + w * h, 254);
    let opts = LoadOptions {
        resolution: Some(0.05),
        max_pixels: Some(1 << 24),
        ..LoadOptions::default()
    };
    let m = within_32_mib(|| load_map_bytes(Path::new("comment.pgm"), None, &pgm, &opts)).unwrap();
    assert_eq!(m.grid.frame().width, 1000);
}

/// A PAM's header lines are read whole by the decoder: a 100 MiB comment line in a 4 x 4 px
/// PAM took 108 MB before the file was refused. A header line beyond 64 KiB is now refused
/// before any reader keeps it.
#[test]
fn a_long_pam_header_line_is_refused_unread() {
    let _turn = SERIAL
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    let mut pam = b"P7\n# ".to_vec();
    pam.resize(pam.len() + (40 << 20), b'x');
    pam.extend_from_slice(
        b"\nWIDTH 4\nHEIGHT 4\nDEPTH 1\nMAXVAL 255\nTUPLTYPE GRAYSCALE\nENDHDR\n",
    );
    pam.resize(pam.len() + 16, 254);
    let opts = LoadOptions {
        resolution: Some(0.05),
        max_pixels: Some(1 << 24),
        ..LoadOptions::default()
    };
    let e = within_32_mib(|| load_map_bytes(Path::new("long.pam"), None, &pam, &opts))
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("long.pam") && e.contains("a PAM header line is longer than 65536 bytes"),
        "{e}"
    );
    // A PAM with a short comment loads.
    let ok =
        b"P7\n# made by hand\nWIDTH 4\nHEIGHT 4\nDEPTH 1\nMAXVAL 255\nTUPLTYPE GRAYSCALE\nENDHDR\n"
            .iter()
            .copied()
            .chain(std::iter::repeat_n(254u8, 16))
            .collect::<Vec<u8>>();
    let m = load_map_bytes(Path::new("ok.pam"), None, &ok, &opts).unwrap();
    assert_eq!(m.grid.frame().width, 4);
}

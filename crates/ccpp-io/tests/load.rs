//! Loader behaviour on small generated files: formats, row order, overrides, embedded bytes and
//! every error variant.

#![allow(clippy::unwrap_used)] // tests may panic on broken fixtures

use std::path::{Path, PathBuf};

use ccpp_core::grid::Cell;
use ccpp_io::map::{load_map, load_map_bytes, LoadOptions, MapError, Thresholds};
use image::{DynamicImage, ImageBuffer, Luma, Rgb, Rgba};
use tempfile::TempDir;

const O: Cell = Cell::Occupied;
const F: Cell = Cell::Free;
const U: Cell = Cell::Unknown;

fn write(dir: &TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.path().join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn load(p: &Path) -> Result<ccpp_io::LoadedMap, MapError> {
    load_map(p, &LoadOptions::default())
}

fn cells(p: &Path) -> Vec<Cell> {
    load(p)
        .unwrap_or_else(|e| panic!("{e}"))
        .grid
        .cells()
        .to_vec()
}

/// Asserts the message is one line and names `file`.
fn names(e: &MapError, file: &str) {
    let msg = e.to_string();
    assert!(msg.contains(file), "message {msg:?} does not name {file}");
    assert!(!msg.contains('\n'), "message {msg:?} is not one line");
}

const YAML_TAIL: &str = "resolution: 0.5\norigin: [1.0, 2.0, 0.0]\n";

// ---------------------------------------------------------------- formats

#[test]
fn ascii_p2_pgm_with_comments() {
    let d = TempDir::new().unwrap();
    let p = write(
        &d,
        "a.pgm",
        b"P2\n# a comment\n3 2\n# another\n255\n0 205 254\n 90 89 206\n",
    );
    assert_eq!(cells(&p), [O, U, F, U, O, F]);
    let p = write(&d, "bits.pgm", b"P2 2 1 1\n0 1\n"); // maxval 1 is rescaled to 0/255
    assert_eq!(cells(&p), [O, F]);
}

#[test]
fn binary_p5_with_comment_and_16_bit() {
    let d = TempDir::new().unwrap();
    let mut p5 = b"P5\n# CREATOR: test\n4 1\n255\n".to_vec();
    p5.extend([0u8, 205, 206, 254]);
    assert_eq!(cells(&write(&d, "a.pgm", &p5)), [O, U, F, F]);

    // 16-bit: values v * 257 behave as the 8-bit v; 52685 = 205 * 257 stays unknown.
    let mut p16 = b"P5\n5 1\n65535\n".to_vec();
    for v in [0u16, 205 * 257, 205 * 257 + 200, 206 * 257, 65535] {
        p16.extend(v.to_be_bytes());
    }
    // 205*257+200 -> level 205.78 -> p = 0.1930 < 0.196 -> free (not truncated to 205).
    assert_eq!(cells(&write(&d, "b16.pgm", &p16)), [O, U, F, F, F]);
}

#[test]
fn png_16_bit_grey_and_rgba() {
    let d = TempDir::new().unwrap();
    let l16: ImageBuffer<Luma<u16>, Vec<u16>> =
        ImageBuffer::from_raw(3, 1, vec![0, 205 * 257, 65535]).unwrap();
    let p = d.path().join("l16.png");
    DynamicImage::ImageLuma16(l16).save(&p).unwrap();
    assert_eq!(cells(&p), [O, U, F]);

    let v = 205 * 257;
    let rgba16: ImageBuffer<Rgba<u16>, Vec<u16>> =
        ImageBuffer::from_raw(2, 1, vec![v, v, v, 0, 0, 0, 0, 0]).unwrap();
    let p = d.path().join("rgba16.png");
    DynamicImage::ImageRgba16(rgba16).save(&p).unwrap();
    assert_eq!(cells(&p), [U, O]);
}

#[test]
fn rgb_uses_the_exact_mean_and_alpha_is_ignored() {
    let d = TempDir::new().unwrap();
    // (255,255,100): mean 203.33 -> unknown; (255,255,106): mean 205.33 -> p 0.1948 -> free
    // (rounding that mean to 205 would make it unknown).
    let rgb: ImageBuffer<Rgb<u8>, Vec<u8>> =
        ImageBuffer::from_raw(3, 1, vec![255, 255, 100, 255, 255, 106, 10, 20, 30]).unwrap();
    let p = d.path().join("rgb.png");
    rgb.save(&p).unwrap();
    assert_eq!(cells(&p), [U, F, O]);

    // Alpha never matters: ROS would average it in and turn opaque 205 into free.
    let rgba: ImageBuffer<Rgba<u8>, Vec<u8>> = ImageBuffer::from_raw(
        4,
        1,
        vec![
            205, 205, 205, 255, 205, 205, 205, 0, 0, 0, 0, 0, 254, 254, 254, 128,
        ],
    )
    .unwrap();
    let p = d.path().join("rgba.png");
    rgba.save(&p).unwrap();
    assert_eq!(cells(&p), [U, U, O, F]);
}

/// Writes a PNG with the `png` crate (for colour types `image` cannot write).
fn png_bytes(
    w: u32,
    h: u32,
    color: png::ColorType,
    depth: png::BitDepth,
    palette: Option<Vec<u8>>,
    data: &[u8],
) -> Vec<u8> {
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(color);
        enc.set_depth(depth);
        if let Some(p) = palette {
            enc.set_palette(p);
        }
        let mut wr = enc.write_header().unwrap();
        wr.write_image_data(data).unwrap();
    }
    out
}

#[test]
fn png_palette_one_bit_and_grey_alpha() {
    let d = TempDir::new().unwrap();
    let palette = vec![0, 0, 0, 205, 205, 205, 254, 254, 254];
    let pal = png_bytes(
        3,
        1,
        png::ColorType::Indexed,
        png::BitDepth::Eight,
        Some(palette),
        &[2, 1, 0],
    );
    assert_eq!(cells(&write(&d, "pal.png", &pal)), [F, U, O]);

    // 1-bit grey: bits 1,0,1 (MSB first) -> white, black, white.
    let bit = png_bytes(
        3,
        1,
        png::ColorType::Grayscale,
        png::BitDepth::One,
        None,
        &[0b1010_0000],
    );
    assert_eq!(cells(&write(&d, "bit.png", &bit)), [F, O, F]);

    let la = png_bytes(
        3,
        1,
        png::ColorType::GrayscaleAlpha,
        png::BitDepth::Eight,
        None,
        &[205, 0, 0, 255, 254, 7],
    );
    assert_eq!(cells(&write(&d, "la.png", &la)), [U, O, F]);
}

// ---------------------------------------------------------------- frame and options

#[test]
fn row_order_top_row_is_row_zero() {
    let d = TempDir::new().unwrap();
    let mut pgm = b"P5\n2 2\n255\n".to_vec();
    pgm.extend([0u8, 254, 254, 254]); // top-left black
    write(&d, "rows.pgm", &pgm);
    let y = write(
        &d,
        "rows.yaml",
        format!("image: rows.pgm\n{YAML_TAIL}").as_bytes(),
    );
    let m = load(&y).unwrap();
    assert_eq!(m.grid.get(0, 0), O);
    assert_eq!(m.grid.get(1, 0), F);
    assert_eq!(m.grid.get(0, 1), F);
    let c = m.grid.frame().pixel_center(0, 0);
    assert!((c.x - (1.0 + 0.5 * 0.5)).abs() < 1e-12, "{c:?}");
    assert!((c.y - (2.0 + 1.5 * 0.5)).abs() < 1e-12, "{c:?}");
    assert_eq!(m.source, y);
    assert_eq!(m.image_path, d.path().join("rows.pgm"));
}

#[test]
fn yaml_paths_yaw_and_extensions() {
    let d = TempDir::new().unwrap();
    std::fs::create_dir(d.path().join("sub")).unwrap();
    write(&d, "sub/img.pgm", b"P5 1 1 255\n\x00");
    // Relative to the YAML's folder, with a yaw kept in the frame.
    let y = write(
        &d,
        "a.YML",
        b"image: sub/img.pgm\nresolution: 0.1\norigin: [0, 0, 2.5]\n",
    );
    let m = load(&y).unwrap();
    assert!((m.grid.frame().origin.theta - 2.5).abs() < 1e-12);
    assert_eq!(m.grid.cells(), [O]);
    // Absolute image path.
    let abs = d.path().join("sub/img.pgm");
    let y = write(
        &d,
        "b.yaml",
        format!("image: {}\n{YAML_TAIL}", abs.display()).as_bytes(),
    );
    assert_eq!(load(&y).unwrap().image_path, abs);
    // `mode: trinary` is accepted in any case.
    let y = write(
        &d,
        "c.yaml",
        format!("image: sub/img.pgm\nmode: Trinary\n{YAML_TAIL}").as_bytes(),
    );
    assert!(load(&y).is_ok());
}

#[test]
fn bare_image_defaults_and_overrides() {
    let d = TempDir::new().unwrap();
    let p = write(&d, "bare.pgm", b"P5 3 1 255\n\x00\xcd\xfe");
    let m = load(&p).unwrap();
    let f = m.grid.frame();
    assert_eq!(
        (f.resolution, f.origin.x, f.origin.y, f.origin.theta),
        (0.05, 0.0, 0.0, 0.0)
    );
    assert_eq!(m.thresholds, Thresholds::default());
    assert_eq!(
        (m.source.as_path(), m.image_path.as_path()),
        (p.as_path(), p.as_path())
    );
    assert_eq!(m.grid.cells(), [O, U, F]);

    let opts = LoadOptions {
        resolution: Some(0.2),
        origin: Some([1.0, -1.0, 0.5]),
        free_thresh: Some(0.25),
        occupied_thresh: Some(0.9),
        negate: Some(true),
        max_pixels: None,
    };
    let m = load_map(&p, &opts).unwrap();
    let f = m.grid.frame();
    assert_eq!(
        (f.resolution, f.origin.x, f.origin.y, f.origin.theta),
        (0.2, 1.0, -1.0, 0.5)
    );
    // negate: p = v / 255 -> 0 free, 205 (0.80) unknown, 254 (0.996) occupied.
    assert_eq!(m.grid.cells(), [F, U, O]);

    // Overrides apply on top of a YAML too, and are validated.
    let y = write(
        &d,
        "m.yaml",
        format!("image: bare.pgm\n{YAML_TAIL}").as_bytes(),
    );
    let m = load_map(
        &y,
        &LoadOptions {
            free_thresh: Some(0.25),
            ..LoadOptions::default()
        },
    );
    assert_eq!(m.unwrap().grid.cells(), [O, F, F]);
    for bad in [
        LoadOptions {
            resolution: Some(-1.0),
            ..LoadOptions::default()
        },
        LoadOptions {
            resolution: Some(f64::NAN),
            ..LoadOptions::default()
        },
        LoadOptions {
            origin: Some([0.0, f64::INFINITY, 0.0]),
            ..LoadOptions::default()
        },
        LoadOptions {
            free_thresh: Some(0.7),
            ..LoadOptions::default()
        },
        LoadOptions {
            occupied_thresh: Some(1.5),
            ..LoadOptions::default()
        },
    ] {
        let e = load_map(&y, &bad).unwrap_err();
        assert!(matches!(e, MapError::BadValue { .. }), "{e}");
        names(&e, "m.yaml");
    }
}

#[test]
fn embedded_map_equals_the_file() {
    const YAML: &str = include_str!("data/teb_empty_box.yaml");
    const PNG: &[u8] = include_bytes!("data/teb_empty_box.png");
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let from_file = load(&dir.join("teb_empty_box.yaml")).unwrap();
    let name = Path::new("embedded/teb_empty_box.yaml");
    let m = load_map_bytes(name, Some(YAML), PNG, &LoadOptions::default()).unwrap();
    assert_eq!(m.grid, from_file.grid);
    assert_eq!(m.source, name);
    assert_eq!(m.image_path, Path::new("embedded/teb_empty_box.png"));
    assert_eq!(m.grid.frame().origin.x, -3.0);

    let bare = load_map_bytes(Path::new("demo.png"), None, PNG, &LoadOptions::default()).unwrap();
    assert_eq!(bare.grid.cells(), from_file.grid.cells());
    assert_eq!(bare.grid.frame().resolution, 0.05);

    let e = load_map_bytes(name, Some(YAML), b"garbage", &LoadOptions::default()).unwrap_err();
    assert!(matches!(e, MapError::Decode { .. }), "{e}");
    names(&e, "teb_empty_box.png");
    let e = load_map_bytes(name, Some("image: x.png\n"), PNG, &LoadOptions::default()).unwrap_err();
    assert!(
        matches!(
            e,
            MapError::MissingField {
                field: "resolution",
                ..
            }
        ),
        "{e}"
    );
    names(&e, "teb_empty_box.yaml");
}

// ---------------------------------------------------------------- errors

#[test]
fn missing_file() {
    let d = TempDir::new().unwrap();
    for name in ["nope.yaml", "nope.png"] {
        let e = load(&d.path().join(name)).unwrap_err();
        assert!(matches!(e, MapError::NotFound { .. }), "{e}");
        names(&e, name);
    }
    let e = load(d.path()).unwrap_err();
    assert!(matches!(e, MapError::Io { .. }), "{e}");
}

#[test]
fn yaml_missing_resolution() {
    let d = TempDir::new().unwrap();
    write(&d, "img.pgm", b"P5 1 1 255\n\x00");
    let y = write(&d, "nores.yaml", b"image: img.pgm\norigin: [0, 0, 0]\n");
    let e = load(&y).unwrap_err();
    assert!(
        matches!(
            e,
            MapError::MissingField {
                field: "resolution",
                ..
            }
        ),
        "{e}"
    );
    names(&e, "nores.yaml");
    assert!(e.to_string().contains("resolution"));
}

#[test]
fn yaml_naming_an_absent_image() {
    let d = TempDir::new().unwrap();
    let y = write(
        &d,
        "orphan.yaml",
        format!("image: empty.pgm\n{YAML_TAIL}").as_bytes(),
    );
    let e = load(&y).unwrap_err();
    assert!(matches!(e, MapError::ImageNotFound { .. }), "{e}");
    names(&e, "orphan.yaml");
    names(&e, "empty.pgm");
}

#[test]
fn corrupt_images() {
    let d = TempDir::new().unwrap();
    let real = include_bytes!("data/teb_empty_box.png");
    let mut sig_junk = b"\x89PNG\r\n\x1a\n".to_vec();
    sig_junk.extend([7u8; 64]);
    let cases: [(&str, &[u8]); 5] = [
        ("sig_junk.png", &sig_junk),
        ("truncated.png", &real[..real.len() / 2]),
        ("text.png", b"this is not an image"),
        ("short.pgm", b"P5\n10 10\n255\n\x00\x00\x00"),
        ("empty.pgm", b""),
    ];
    for (name, bytes) in cases {
        let p = write(&d, name, bytes);
        let e = load(&p).unwrap_err();
        assert!(matches!(e, MapError::Decode { .. }), "{name}: {e}");
        names(&e, name);
        // Through a YAML too: the error names the image.
        let y = write(
            &d,
            "via.yaml",
            format!("image: {name}\n{YAML_TAIL}").as_bytes(),
        );
        let e = load(&y).unwrap_err();
        assert!(matches!(e, MapError::Decode { .. }), "{name}: {e}");
        names(&e, name);
    }
}

#[test]
fn malformed_yaml() {
    let d = TempDir::new().unwrap();
    for (i, text) in [
        "image: [unclosed\nresolution: 0.05\n",
        "resolution: abc\n",
        "origin: {x: 1}\n",
        "\u{0}",
    ]
    .iter()
    .enumerate()
    {
        let name = format!("bad{i}.yaml");
        let y = write(&d, &name, text.as_bytes());
        let e = load(&y).unwrap_err();
        assert!(matches!(e, MapError::Yaml { .. }), "{text:?}: {e}");
        names(&e, &name);
    }
    let y = write(&d, "latin1.yaml", b"image: \xe9.pgm\n");
    let e = load(&y).unwrap_err();
    assert!(matches!(e, MapError::Yaml { .. }), "{e}");
    names(&e, "latin1.yaml");
}

#[test]
fn bad_resolution_and_thresholds() {
    let d = TempDir::new().unwrap();
    write(&d, "img.pgm", b"P5 1 1 255\n\x00");
    let cases = [
        (
            "neg.yaml",
            "resolution: -0.05\norigin: [0, 0, 0]\n",
            "resolution",
        ),
        (
            "nan.yaml",
            "resolution: .nan\norigin: [0, 0, 0]\n",
            "resolution",
        ),
        (
            "thr.yaml",
            "resolution: 0.05\norigin: [0, 0, 0]\noccupied_thresh: 0.3\nfree_thresh: 0.5\n",
            "free_thresh",
        ),
    ];
    for (name, tail, field) in cases {
        let y = write(&d, name, format!("image: img.pgm\n{tail}").as_bytes());
        let e = load(&y).unwrap_err();
        assert!(
            matches!(e, MapError::BadValue { field: f, .. } if f == field),
            "{name}: {e}"
        );
        names(&e, name);
    }
}

#[test]
fn unsupported_mode() {
    let d = TempDir::new().unwrap();
    write(&d, "img.pgm", b"P5 1 1 255\n\x00");
    for mode in ["likelihood", "tri nary"] {
        let name = format!("{}.yaml", mode.replace(' ', "_"));
        let y = write(
            &d,
            &name,
            format!("image: img.pgm\nmode: {mode}\n{YAML_TAIL}").as_bytes(),
        );
        let e = load(&y).unwrap_err();
        assert!(
            matches!(&e, MapError::UnsupportedMode { mode: m, .. } if m == mode),
            "{e}"
        );
        assert!(e.to_string().contains("trinary, scale and raw"), "{e}");
        names(&e, &name);
    }
}

#[test]
fn scale_mode_makes_transparent_pixels_unknown() {
    let d = TempDir::new().unwrap();
    // Opaque free, occupied, grey-205 unknown; then the same three transparent or half so.
    let rgba: ImageBuffer<Rgba<u8>, Vec<u8>> = ImageBuffer::from_raw(
        6,
        1,
        vec![
            254, 254, 254, 255, 0, 0, 0, 255, 205, 205, 205, 255, 254, 254, 254, 0, 0, 0, 0, 128,
            205, 205, 205, 0,
        ],
    )
    .unwrap();
    rgba.save(d.path().join("rgba.png")).unwrap();
    let la: ImageBuffer<image::LumaA<u16>, Vec<u16>> =
        ImageBuffer::from_raw(2, 1, vec![65535, 65535, 65535, 65534]).unwrap();
    DynamicImage::ImageLumaA16(la)
        .save(d.path().join("la16.png"))
        .unwrap();
    for (mode, rgba_cells, la_cells) in [
        ("trinary", [F, O, U, F, O, U], [F, F]),
        ("scale", [F, O, U, U, U, U], [F, U]),
        ("Scale", [F, O, U, U, U, U], [F, U]),
    ] {
        for (image, want) in [("rgba.png", &rgba_cells[..]), ("la16.png", &la_cells[..])] {
            let y = write(
                &d,
                "m.yaml",
                format!("image: {image}\nmode: {mode}\n{YAML_TAIL}").as_bytes(),
            );
            assert_eq!(cells(&y), want, "{mode} {image}");
        }
    }
}

#[test]
fn raw_mode_reads_the_occupancy_in_percent() {
    let d = TempDir::new().unwrap();
    // Levels 0, 19, 20, 65, 66, 100, 101, 255 under the default thresholds (0.196, 0.65).
    write(
        &d,
        "raw.pgm",
        b"P5 8 1 255\n\x00\x13\x14\x41\x42\x64\x65\xff",
    );
    let y = write(
        &d,
        "raw.yaml",
        format!("image: raw.pgm\nmode: raw\n{YAML_TAIL}").as_bytes(),
    );
    assert_eq!(cells(&y), [F, F, U, U, O, O, U, U]);
    // The same image in trinary mode: dark is occupied.
    let t = write(
        &d,
        "tri.yaml",
        format!("image: raw.pgm\n{YAML_TAIL}").as_bytes(),
    );
    assert_eq!(cells(&t), [O, O, O, O, O, U, U, F]);
    // Raw with negate means two things (ROS 1 inverts, Nav2 does not): refused.
    let n = write(
        &d,
        "rawneg.yaml",
        format!("image: raw.pgm\nmode: raw\nnegate: 1\n{YAML_TAIL}").as_bytes(),
    );
    let e = load(&n).unwrap_err();
    assert!(
        matches!(
            &e,
            MapError::BadValue {
                field: "negate",
                ..
            }
        ),
        "{e}"
    );
    names(&e, "rawneg.yaml");
}

#[test]
fn an_image_with_more_pixels_than_allowed_is_refused_from_its_header() {
    let d = tempfile::tempdir().unwrap();
    let p = write(&d, "three.pgm", b"P5 3 1 255\n\x00\x80\xfe");
    let with = |max| LoadOptions {
        max_pixels: Some(max),
        ..LoadOptions::default()
    };
    assert_eq!(load_map(&p, &with(3)).unwrap().grid.cells().len(), 3);
    let e = load_map(&p, &with(2)).unwrap_err();
    assert!(
        matches!(
            e,
            MapError::TooLarge {
                width: 3,
                height: 1,
                max_pixels: 2,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("three.pgm is 3 x 1 px"), "{e}");
    // The header of a PNG is enough too: a 20000 x 20000 px header over a few bytes of data.
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend(20_000u32.to_be_bytes());
    ihdr.extend(20_000u32.to_be_bytes());
    ihdr.extend([8, 0, 0, 0, 0]);
    png.extend(13u32.to_be_bytes());
    png.extend(&ihdr);
    png.extend(crc32(&ihdr).to_be_bytes());
    // The decoder reads the header up to the first data chunk: an empty one.
    png.extend(0u32.to_be_bytes());
    png.extend(b"IDAT");
    png.extend(crc32(b"IDAT").to_be_bytes());
    let q = write(&d, "big.png", &png);
    let e = load_map(&q, &with(1 << 20)).unwrap_err();
    assert!(e.to_string().contains("big.png is 20000 x 20000 px"), "{e}");
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut c = 0xffff_ffffu32;
    for &b in bytes {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 == 1 {
                0xedb8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}

//! Loads every map of `shared/maps` and checks it against an independent classification:
//! a hand-written P5 parser (PGM) or the `image` crate's raw buffer (PNG), the YAML read with a
//! line parser, and the trinary rule evaluated with exact integer arithmetic on rationals.

#![allow(clippy::unwrap_used)] // tests may panic on broken fixtures

use std::path::{Path, PathBuf};
use std::time::Instant;

use ccpp_core::grid::Cell;
use ccpp_io::map::{load_map, LoadOptions};

/// `<repo>/../shared/maps`, valid from any worktree that sits beside `shared/`.
const MAPS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/maps");

/// free / occupied / unknown percentages copied from the table in `shared/maps/SOURCES.md`.
const TABLE: &[(&str, f64, f64, f64)] = &[
    ("teb_empty_box", 90.2, 6.6, 3.2),
    ("teb_corridor", 93.9, 6.1, 0.0),
    ("teb_maze", 96.3, 3.7, 0.0),
    ("nobleo_grid", 95.1, 4.9, 0.0),
    ("tuw_single_corridors", 12.7, 2.2, 85.1),
    ("aws_small_house", 25.2, 1.4, 73.4),
    ("aws_bookstore", 42.0, 3.4, 54.7),
    ("nobleo_basement", 33.5, 2.5, 64.0),
    ("rmf_office_scan", 38.3, 4.1, 57.7),
    ("mit_building_31", 96.0, 3.9, 0.1),
    ("stage_willow_full", 43.6, 2.7, 53.8),
    ("nav2_depot", 96.8, 3.2, 0.0),
    ("tuw_freihaus_eg", 96.8, 3.2, 0.0),
    ("aws_small_warehouse_002", 25.3, 0.6, 74.0),
];

fn maps_dir() -> Option<PathBuf> {
    let dir = PathBuf::from(MAPS);
    if dir.is_dir() {
        Some(dir)
    } else {
        println!("note: {MAPS} is absent; skipping the shared-map tests");
        None
    }
}

/// The YAML's fields as strings, read line by line (`key: value`, `#` comments).
fn yaml_fields(path: &Path) -> Vec<(String, String)> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .map(|l| l.split('#').next().unwrap())
        .filter_map(|l| l.split_once(':'))
        .map(|(k, v)| (k.trim().to_owned(), v.trim().to_owned()))
        .collect()
}

fn field<'a>(fields: &'a [(String, String)], key: &str) -> Option<&'a str> {
    fields
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
}

/// A non-negative decimal such as `0.196` as the exact fraction `(196, 1000)`.
fn rational(s: &str) -> (u128, u128) {
    let (int, frac) = s.split_once('.').unwrap_or((s, ""));
    let den = 10u128.pow(u32::try_from(frac.len()).unwrap());
    let int: u128 = if int.is_empty() {
        0
    } else {
        int.parse().unwrap()
    };
    let frac_v: u128 = if frac.is_empty() {
        0
    } else {
        frac.parse().unwrap()
    };
    (int * den + frac_v, den)
}

/// The trinary rule on `sum` = R + G + B (grey counted three times), exactly:
/// `p = dark / 765` where `dark = 765 - sum` (or `sum` when negated).
fn classify_exact(sum: u32, occ: (u128, u128), free: (u128, u128), negate: bool) -> Cell {
    let dark = u128::from(if negate { sum } else { 765 - sum });
    if dark * occ.1 > occ.0 * 765 {
        Cell::Occupied
    } else if dark * free.1 < free.0 * 765 {
        Cell::Free
    } else {
        Cell::Unknown
    }
}

/// A minimal binary PGM (P5, maxval 255) reader: `(width, height, pixels)`.
fn parse_p5(bytes: &[u8]) -> (usize, usize, Vec<u8>) {
    assert_eq!(
        &bytes[..2],
        b"P5",
        "only P5 PGMs are expected in shared/maps"
    );
    let mut i = 2;
    let mut nums = Vec::new();
    while nums.len() < 3 {
        loop {
            if bytes[i].is_ascii_whitespace() {
                i += 1;
            } else if bytes[i] == b'#' {
                while bytes[i] != b'\n' {
                    i += 1;
                }
            } else {
                break;
            }
        }
        let start = i;
        while bytes[i].is_ascii_digit() {
            i += 1;
        }
        nums.push(
            std::str::from_utf8(&bytes[start..i])
                .unwrap()
                .parse::<usize>()
                .unwrap(),
        );
    }
    i += 1; // exactly one whitespace byte after maxval
    let (w, h, maxval) = (nums[0], nums[1], nums[2]);
    assert_eq!(maxval, 255);
    (w, h, bytes[i..i + w * h].to_vec())
}

/// Per-pixel `(R + G + B, alpha)` of an image, row-major from the top: grey counts three times.
fn pixel_sums(image: &Path) -> (usize, usize, Vec<(u32, u8)>) {
    if image.extension().is_some_and(|e| e == "pgm") {
        let (w, h, px) = parse_p5(&std::fs::read(image).unwrap());
        (w, h, px.iter().map(|&v| (3 * u32::from(v), 255)).collect())
    } else {
        let img = image::open(image).unwrap();
        let (w, h) = (img.width() as usize, img.height() as usize);
        let px = match img {
            image::DynamicImage::ImageLuma8(b) => b
                .as_raw()
                .iter()
                .map(|&v| (3 * u32::from(v), 255))
                .collect(),
            image::DynamicImage::ImageRgb8(b) => b
                .as_raw()
                .chunks_exact(3)
                .map(|p| (p.iter().map(|&v| u32::from(v)).sum(), 255))
                .collect(),
            image::DynamicImage::ImageRgba8(b) => b
                .as_raw()
                .chunks_exact(4)
                .map(|p| (p[..3].iter().map(|&v| u32::from(v)).sum(), p[3]))
                .collect(),
            other => panic!(
                "unexpected colour type {:?} in {}",
                other.color(),
                image.display()
            ),
        };
        (w, h, px)
    }
}

struct Checked {
    name: String,
    sums: Vec<(u32, u8)>,
    cells: Vec<Cell>,
}

fn check_map(yaml: &Path) -> Checked {
    let name = yaml.file_stem().unwrap().to_string_lossy().into_owned();
    let fields = yaml_fields(yaml);
    let image = yaml
        .parent()
        .unwrap()
        .join(field(&fields, "image").unwrap());
    let occ = rational(field(&fields, "occupied_thresh").unwrap_or("0.65"));
    let free = rational(field(&fields, "free_thresh").unwrap_or("0.196"));
    let negate = matches!(field(&fields, "negate"), Some("1" | "true"));
    let resolution: f64 = field(&fields, "resolution").unwrap().parse().unwrap();

    let t0 = Instant::now();
    let loaded = load_map(yaml, &LoadOptions::default())
        .unwrap_or_else(|e| panic!("{}: {e}", yaml.display()));
    let elapsed = t0.elapsed();

    let (w, h, sums) = pixel_sums(&image);
    let expected: Vec<Cell> = sums
        .iter()
        .map(|&(s, _)| classify_exact(s, occ, free, negate))
        .collect();
    let f = loaded.grid.frame();
    assert_eq!((f.width, f.height), (w, h), "{name}: size");
    assert_eq!(f.resolution, resolution, "{name}: resolution");
    assert_eq!(loaded.source, yaml);
    assert_eq!(loaded.image_path, image);

    let count = |cells: &[Cell], c: Cell| cells.iter().filter(|&&x| x == c).count();
    let got = loaded.grid.counts();
    let want = (
        count(&expected, Cell::Free),
        count(&expected, Cell::Occupied),
        count(&expected, Cell::Unknown),
    );
    assert_eq!(got, want, "{name}: (free, occupied, unknown) counts");
    let first_diff = loaded
        .grid
        .cells()
        .iter()
        .zip(&expected)
        .position(|(a, b)| a != b);
    assert_eq!(first_diff, None, "{name}: first differing pixel index");

    let n = (w * h) as f64;
    let pct = |k: usize| 100.0 * k as f64 / n;
    println!(
        "{name:>24}: {w}x{h} free {:.2}% occ {:.2}% unk {:.2}% loaded in {:.1} ms",
        pct(got.0),
        pct(got.1),
        pct(got.2),
        elapsed.as_secs_f64() * 1e3
    );
    if let Some(&(_, tf, to, tu)) = TABLE.iter().find(|(m, ..)| *m == name) {
        for (what, have, table) in [
            ("free", pct(got.0), tf),
            ("occupied", pct(got.1), to),
            ("unknown", pct(got.2), tu),
        ] {
            assert!(
                (have - table).abs() <= 0.1,
                "{name}: {what} {have:.3}% vs SOURCES.md {table}%"
            );
        }
    } else {
        println!("note: {name} is not in the SOURCES.md table copy");
    }
    Checked {
        name,
        sums,
        cells: loaded.grid.cells().to_vec(),
    }
}

#[test]
fn every_shared_map_matches_an_independent_classification() {
    let Some(dir) = maps_dir() else { return };
    let mut yamls: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "yaml"))
        .collect();
    yamls.sort();
    assert!(
        yamls.len() >= TABLE.len(),
        "expected at least {} maps",
        TABLE.len()
    );
    let checked: Vec<Checked> = yamls.iter().map(|y| check_map(y)).collect();
    for (name, ..) in TABLE {
        assert!(
            checked.iter().any(|c| c.name == *name),
            "{name} missing from {MAPS}"
        );
    }

    let by_name = |n: &str| checked.iter().find(|c| c.name == n).unwrap();
    // Pixels of a given grey (all three channels equal) and the cells they became.
    let cells_of_grey = |c: &Checked, v: u32| -> Vec<Cell> {
        c.sums
            .iter()
            .zip(&c.cells)
            .filter(|((s, _), _)| *s == 3 * v)
            .map(|(_, &x)| x)
            .collect()
    };

    // stage_willow_full: background 206 must be unknown under its free_thresh 0.1.
    let willow = cells_of_grey(by_name("stage_willow_full"), 206);
    assert!(
        willow.len() > 100_000,
        "willow has {} px of 206",
        willow.len()
    );
    assert!(willow.iter().all(|&c| c == Cell::Unknown));

    // nobleo_basement (RGBA): grey 205 is unknown (alpha ignored), black occupied.
    let basement = by_name("nobleo_basement");
    assert!(
        basement.sums.iter().all(|&(_, a)| a == 255),
        "basement alpha is opaque"
    );
    let b205 = cells_of_grey(basement, 205);
    assert!(b205.len() > 100_000 && b205.iter().all(|&c| c == Cell::Unknown));
    let b0 = cells_of_grey(basement, 0);
    assert!(!b0.is_empty() && b0.iter().all(|&c| c == Cell::Occupied));

    // nav2_depot: free_thresh 0.25 makes its 205 grey FREE, as Nav2 does.
    let depot = cells_of_grey(by_name("nav2_depot"), 205);
    assert!(!depot.is_empty() && depot.iter().all(|&c| c == Cell::Free));
}

#[test]
fn threshold_overrides_change_the_trap_pixels() {
    let Some(dir) = maps_dir() else { return };
    // Willow at the usual 0.196 turns its 206 background free (the trap SOURCES.md describes).
    let usual = LoadOptions {
        free_thresh: Some(0.196),
        ..LoadOptions::default()
    };
    let willow = load_map(&dir.join("stage_willow_full.yaml"), &usual).unwrap();
    let (free, _, unknown) = willow.grid.counts();
    let n = willow.grid.cells().len() as f64;
    assert!(
        free as f64 / n > 0.9 && (unknown as f64 / n) < 0.05,
        "{free} {unknown}"
    );
    assert_eq!(willow.thresholds.free, 0.196);
    // Depot at 0.196 keeps its 8894 pixels of 205 unknown.
    let depot = load_map(&dir.join("nav2_depot.yaml"), &usual).unwrap();
    assert_eq!(depot.grid.counts().2, 8894);
}

#[test]
fn warehouse_loads_fast() {
    let Some(dir) = maps_dir() else { return };
    let path = dir.join("aws_small_warehouse_002.yaml");
    let _warm = load_map(&path, &LoadOptions::default()).unwrap();
    let t0 = Instant::now();
    let m = load_map(&path, &LoadOptions::default()).unwrap();
    let ms = t0.elapsed().as_secs_f64() * 1e3;
    println!("aws_small_warehouse_002 (1536x1504) loaded in {ms:.1} ms");
    assert_eq!(m.grid.cells().len(), 1536 * 1504);
    // Generous bound: the test profile is optimised, but CI machines are shared.
    assert!(ms < 1000.0, "took {ms} ms");
}

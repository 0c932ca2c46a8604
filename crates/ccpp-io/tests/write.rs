//! Atomic writers and the `map_saver`-style map writer.

#![allow(clippy::unwrap_used)] // tests may panic on broken fixtures

use std::path::Path;

use ccpp_core::geometry::Pose;
use ccpp_core::grid::GridMap;
use ccpp_io::map::{load_map, LoadOptions};
use ccpp_io::write::{encode_pgm, map_yaml, save_map, write_atomic, write_atomic_with, WriteError};
use tempfile::TempDir;

fn no_tmp_left(dir: &Path) {
    let tmps: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "tmp"))
        .collect();
    assert!(tmps.is_empty(), "left behind: {tmps:?}");
}

#[test]
fn write_atomic_creates_and_replaces() {
    let d = TempDir::new().unwrap();
    let p = d.path().join("out.json");
    write_atomic(&p, b"first").unwrap();
    assert_eq!(std::fs::read(&p).unwrap(), b"first");
    write_atomic(&p, b"second").unwrap();
    assert_eq!(std::fs::read(&p).unwrap(), b"second");
    no_tmp_left(d.path());
}

#[test]
fn failed_write_leaves_the_old_file_untouched() {
    let d = TempDir::new().unwrap();
    let p = d.path().join("out.txt");
    std::fs::write(&p, b"old").unwrap();
    let e = write_atomic_with(&p, |w| {
        w.write_all(b"half of the new con")?;
        Err(std::io::Error::other("simulated failure"))
    })
    .unwrap_err();
    assert!(matches!(e, WriteError::Io { .. }));
    let msg = e.to_string();
    assert!(
        msg.contains("out.txt") && msg.contains("simulated failure"),
        "{msg}"
    );
    assert_eq!(std::fs::read(&p).unwrap(), b"old");
    no_tmp_left(d.path());
}

#[test]
fn write_into_a_missing_folder_fails_cleanly() {
    let d = TempDir::new().unwrap();
    let p = d.path().join("no/such/dir/out.txt");
    let e = write_atomic(&p, b"x").unwrap_err();
    assert!(matches!(e, WriteError::Io { .. }));
    assert!(e.to_string().contains("out.txt"));
    assert!(!p.exists());
    let e = write_atomic(Path::new("/"), b"x").unwrap_err();
    assert!(matches!(e, WriteError::NoFileName { .. }), "{e}");
}

#[test]
fn pgm_uses_map_saver_values() {
    let g: GridMap = "#.?\n.#.".parse().unwrap();
    let pgm = encode_pgm(&g);
    let header_end = pgm.len() - 6;
    assert!(pgm.starts_with(b"P5\n"));
    assert!(std::str::from_utf8(&pgm[..header_end])
        .unwrap()
        .ends_with("\n3 2\n255\n"));
    assert_eq!(&pgm[header_end..], [0, 254, 205, 254, 0, 254]);
}

#[test]
fn save_map_round_trips_through_load_map() {
    let d = TempDir::new().unwrap();
    let g = GridMap::from_ascii_scaled("#####\n#..?#\n#.#.#\n#####", 2, 0.05)
        .unwrap()
        .with_placement(0.037, Pose::new(-1.25, 3.1, 0.3))
        .unwrap();
    let yaml = d.path().join("inflated map.yaml");
    let image = save_map(&g, &yaml).unwrap();
    assert_eq!(image, d.path().join("inflated map.pgm"));
    let back = load_map(&yaml, &LoadOptions::default()).unwrap();
    assert_eq!(back.grid, g);
    assert_eq!(back.image_path, image);
    no_tmp_left(d.path());
    // Overwriting keeps working.
    save_map(&g, &yaml).unwrap();
}

#[test]
fn yaml_quotes_awkward_image_names() {
    let f = *"..".parse::<GridMap>().unwrap().frame();
    let y = map_yaml(&f, "we\"ird: #name\\.pgm");
    assert!(
        y.starts_with("image: \"we\\\"ird: #name\\\\.pgm\"\n"),
        "{y}"
    );
    assert!(
        y.contains("resolution: 1\n") && y.contains("origin: [0, 0, 0]\n"),
        "{y}"
    );
    let parsed = ccpp_io::MapYaml::parse(&y, Path::new("w.yaml")).unwrap();
    assert_eq!(parsed.image, "we\"ird: #name\\.pgm");
    assert_eq!(parsed.mode.as_deref(), Some("trinary"));
}

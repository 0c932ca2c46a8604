//! The maps of a sweep (`ccpp bench --maps`, Python's `ccpp.sweep`) and their names: the map
//! files that folders and files given stand for ([`expand_maps`]), and one name a map for its
//! run folders (`runs/MAP/PLANNER`), rows and plots ([`name_maps`]). The command line and Python
//! both use these, so that they take the same maps and their rows and folders agree.
//!
//! ```
//! let dir = tempfile::tempdir().unwrap();
//! let (a, b) = (dir.path().join("x/map.yaml"), dir.path().join("y/map.yaml"));
//! for p in [&a, &b] {
//!     std::fs::create_dir_all(p.parent().unwrap()).unwrap();
//!     std::fs::write(p, "").unwrap();
//! }
//! let named = ccpp_io::names::name_maps(vec![a.clone(), b, a]);
//! let names: Vec<&str> = named.iter().map(|(_, n)| n.as_str()).collect();
//! assert_eq!(names, ["x-map", "y-map"]);
//! ```

use std::path::{Path, PathBuf};

/// Why the path `path` (of a `what`: `map`, `georef`, ...) cannot be recorded as ccpp records
/// paths, as text (`run.json`, `bench-key.txt`, the exports), or printed in a one-line
/// message: not valid UTF-8, or holding a control character (a newline cut the message naming
/// it, and a bench's error cell, short: `map maps/new`). `None` when it can.
pub fn path_text_problem(path: &Path, what: &str) -> Option<String> {
    let Some(text) = path.to_str() else {
        return Some(format!(
            "{what} {}: not valid UTF-8 (ccpp records paths as text, in run.json and the exports); rename it",
            path.display()
        ));
    };
    let c = text.chars().find(|c| c.is_control())?;
    Some(format!(
        "{what} {text:?}: holds a control character (U+{:04X}); rename it",
        u32::from(c)
    ))
}

/// Why the maps given to a sweep are not a list of map files.
#[derive(Debug, thiserror::Error)]
pub enum MapListError {
    /// Nothing given.
    #[error("maps is empty: give map files or folders")]
    Empty,
    /// A folder that cannot be listed.
    #[error("cannot read map folder {}: {source}", folder.display())]
    Unreadable {
        /// The folder.
        folder: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A map in a folder whose name is not UTF-8: paths are recorded as text (`run.json`), so
    /// its runs would fail late, unnamed.
    #[error("map folder {} holds {}, whose name is not valid UTF-8; rename it", folder.display(), file.display())]
    NotUtf8 {
        /// The folder.
        folder: PathBuf,
        /// The map file.
        file: PathBuf,
    },
    /// A file given by name that is no map: neither a YAML naming an image nor a PNG or
    /// PNM/PGM image (a landmarks CSV given as a map became a failed run after the others).
    #[error("maps: {} is not a map: {why}", file.display())]
    NotAMap {
        /// The file as given.
        file: PathBuf,
        /// What it is instead.
        why: &'static str,
    },
    /// An item that is neither a file nor a folder.
    #[error("maps: {}: no such file or folder", item.display())]
    Missing {
        /// The item as given.
        item: PathBuf,
    },
    /// Folders without a map in them.
    #[error("no map found in {items}")]
    NoMap {
        /// The items given, comma-separated.
        items: String,
    },
}

/// The map files of `items`: a folder gives its `*.yaml`/`*.yml` maps (or, when it has none,
/// its PNG/PGM images), sorted; a file is taken as it is.
///
/// # Errors
/// An empty list, an item that is neither file nor folder, a folder that cannot be read or
/// holds a map whose name is not UTF-8, or no map at all.
pub fn expand_maps(items: &[PathBuf]) -> Result<Vec<PathBuf>, MapListError> {
    expand_maps_noting(items).map(|(maps, _)| maps)
}

/// Whether the YAML file `p` reads as a mapping without an `image` key: a planner options,
/// zone or other YAML file beside the maps, not a `map_server` map. A file that cannot be read
/// or parsed is kept (its run reports the problem), and so is a file over 1 MiB.
fn yaml_without_image(p: &Path) -> bool {
    const MAX: u64 = 1 << 20;
    if std::fs::metadata(p).map_or(true, |m| m.len() > MAX) {
        return false;
    }
    let Ok(text) = std::fs::read_to_string(p) else {
        return false;
    };
    match serde_saphyr::from_str::<serde_json::Value>(text.trim_start_matches('\u{feff}')) {
        Ok(serde_json::Value::Object(o)) => !o.contains_key("image"),
        _ => false,
    }
}

/// Why the file `p`, given by name, is no map (`yaml`: named as a YAML): a YAML that reads as
/// a mapping without an `image` key, or another file that the map loader's content guess
/// does not take for a PNG or PNM image. `None` for anything else, left to the map loader (a YAML that
/// does not parse, an image that does not decode: their runs say why).
fn not_a_map(p: &Path, yaml: bool) -> Option<&'static str> {
    if yaml {
        return yaml_without_image(p)
            .then_some("a YAML naming no image (an options or zone file?), not a map_server map");
    }
    (!crate::map::pixels::decodable_format(p))
        .then_some("neither a map_server YAML (.yaml/.yml) nor a PNG or PNM/PGM image")
}

/// [`expand_maps`], with the YAML files of the folders that were left out because they name
/// no image (a mapping without an `image` key: a bench's options file in its maps folder became a failed
/// run); files given by name are taken as they are.
///
/// # Errors
/// As [`expand_maps`].
pub fn expand_maps_noting(items: &[PathBuf]) -> Result<(Vec<PathBuf>, Vec<PathBuf>), MapListError> {
    let mut skipped = Vec::new();
    if items.is_empty() {
        return Err(MapListError::Empty);
    }
    let has_ext = |p: &Path, exts: &[&str]| {
        p.extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| exts.iter().any(|x| e.eq_ignore_ascii_case(x)))
    };
    let mut out = Vec::new();
    for item in items {
        if item.is_dir() {
            let unreadable = |source| MapListError::Unreadable {
                folder: item.clone(),
                source,
            };
            let mut files = Vec::new();
            for e in std::fs::read_dir(item).map_err(unreadable)? {
                files.push(e.map_err(unreadable)?.path());
            }
            files.sort();
            if let Some(bad) = files.iter().find(|p| {
                p.file_name().is_some_and(|n| n.to_str().is_none())
                    && has_ext(p, &["yaml", "yml", "png", "pgm", "pnm"])
            }) {
                return Err(MapListError::NotUtf8 {
                    folder: item.clone(),
                    file: bad.clone(),
                });
            }
            let (yamls, others): (Vec<PathBuf>, Vec<PathBuf>) = files
                .iter()
                .filter(|p| has_ext(p, &["yaml", "yml"]))
                .cloned()
                .partition(|p| !yaml_without_image(p));
            skipped.extend(others);
            if yamls.is_empty() {
                out.extend(
                    files
                        .into_iter()
                        .filter(|p| has_ext(p, &["png", "pgm", "pnm"])),
                );
            } else {
                out.extend(yamls);
            }
        } else if item.is_file() {
            if let Some(why) = not_a_map(item, has_ext(item, &["yaml", "yml"])) {
                return Err(MapListError::NotAMap {
                    file: item.clone(),
                    why,
                });
            }
            out.push(item.clone());
        } else {
            return Err(MapListError::Missing { item: item.clone() });
        }
    }
    if out.is_empty() {
        return Err(MapListError::NoMap {
            items: items
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    Ok((out, skipped))
}

/// A map's name from its file stem. A stem that is not a usable folder name (`..yaml` and
/// `...yaml` have the stems `.` and `..`, which would put the run folders beside `runs/`)
/// becomes `map`, and `summary` becomes `summary-map`: the per-map plot `tradeoff_<map>`
/// would otherwise be the summary's `tradeoff_summary`.
fn map_name(p: &Path) -> String {
    let stem = p
        .file_stem()
        .map_or_else(String::new, |s| shown_name(&s.to_string_lossy()));
    if stem.chars().all(|c| c == '.') {
        "map".into()
    } else if stem == "summary" {
        "summary-map".into()
    } else {
        stem
    }
}

/// `name` with every character a terminal or an XML parser would act on
/// ([`crate::message::hidden`]: controls, bidirectional overrides, U+FFFE, U+FFFF) replaced by
/// `_`: a map's name becomes a folder name and goes into pictures, SVG plots, Markdown and
/// messages. A folder holding an escape sequence named a bench map `<folder>-<stem>` (the
/// given path, checked for control characters, did not hold it: a link led there), which
/// reached the terminal raw and made the SVG plots invalid XML (hostile pass).
fn shown_name(name: &str) -> String {
    name.chars()
        .map(|c| if crate::message::hidden(c) { '_' } else { c })
        .collect()
}

/// Drops repeated maps (the same file named twice) and gives every map a distinct name, used
/// for its run folders, rows and plots: the file stem, or, when two maps in different folders
/// share a stem, `<folder>-<stem>` (then `-2`, `-3`, ... if that still repeats).
pub fn name_maps(maps: Vec<PathBuf>) -> Vec<(PathBuf, String)> {
    let named = name_maps_indexed(&maps);
    let mut maps: Vec<Option<PathBuf>> = maps.into_iter().map(Some).collect();
    named
        .into_iter()
        .filter_map(|(i, name)| Some((maps[i].take()?, name)))
        .collect()
}

/// [`name_maps`] by position: `(index in maps, name)` for every map kept, in order. In
/// `O(n log n)` for `n` maps (ordered sets and counts; a sweep may name thousands).
pub fn name_maps_indexed(maps: &[PathBuf]) -> Vec<(usize, String)> {
    use std::collections::{BTreeMap, BTreeSet};
    fn add(counts: &mut BTreeMap<String, usize>, name: &str) {
        *counts.entry(name.to_string()).or_default() += 1;
    }
    fn remove(counts: &mut BTreeMap<String, usize>, name: &str) {
        if let Some(c) = counts.get_mut(name) {
            *c -= 1;
            if *c == 0 {
                counts.remove(name);
            }
        }
    }
    let mut seen = BTreeSet::new();
    // (index, canonical path) of the maps kept.
    let mut kept: Vec<(usize, PathBuf)> = Vec::new();
    for (i, m) in maps.iter().enumerate() {
        let canon = std::fs::canonicalize(m).unwrap_or_else(|_| m.clone());
        if seen.insert(canon.clone()) {
            kept.push((i, canon));
        }
    }
    let stems: Vec<String> = kept.iter().map(|&(i, _)| map_name(&maps[i])).collect();
    let mut stem_count: BTreeMap<String, usize> = BTreeMap::new();
    for stem in &stems {
        add(&mut stem_count, stem);
    }
    let mut names: Vec<String> = kept
        .iter()
        .zip(&stems)
        .map(|((_, canon), stem)| {
            if stem_count[stem] == 1 {
                return stem.clone();
            }
            match canon
                .parent()
                .and_then(Path::file_name)
                .map(|n| shown_name(&n.to_string_lossy()))
            {
                Some(folder) => format!("{folder}-{stem}"),
                None => stem.clone(),
            }
        })
        .collect();
    // A name that repeats an earlier one gets the first free `-k` (k from the number of
    // earlier holders + 1), free among all the names as they stand.
    let mut current: BTreeMap<String, usize> = BTreeMap::new();
    for n in &names {
        add(&mut current, n);
    }
    let mut before: BTreeMap<String, usize> = BTreeMap::new();
    // Per repeated name, the `k` after the last one it was given. A name taken is never freed
    // (its first holder keeps it), and a name's count of earlier holders never falls, so the
    // next search for it may start there: each `-k` is tried once, not once per repeat (many
    // `maps/map.yaml` in different sweep folders are all `maps-map`).
    let mut next_k: BTreeMap<String, usize> = BTreeMap::new();
    for name in &mut names {
        let earlier = before.get(name.as_str()).copied().unwrap_or(0);
        if earlier > 0 {
            let mut k = (earlier + 1).max(next_k.get(name.as_str()).copied().unwrap_or(0));
            while current.contains_key(&format!("{name}-{k}")) {
                k += 1;
            }
            next_k.insert(name.clone(), k + 1);
            let renamed = format!("{name}-{k}");
            remove(&mut current, name);
            add(&mut current, &renamed);
            *name = renamed;
        }
        add(&mut before, name);
    }
    kept.into_iter().map(|(i, _)| i).zip(names).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A folder's YAML files that name no image (an options file beside the maps) are left
    /// out and listed; one that does not parse is kept; a file given by name that is no map
    /// is refused.
    #[test]
    fn a_folders_yaml_without_an_image_is_no_map() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        for (f, text) in [
            (
                "a.yaml",
                "image: a.png\nresolution: 0.05\norigin: [0, 0, 0]\n",
            ),
            ("bench.yaml", "bcd:\n  turn_cost_m: 0.5\n"),
            ("broken.yaml", "image: [\n"),
        ] {
            std::fs::write(d.join(f), text).unwrap();
        }
        let (maps, skipped) = expand_maps_noting(&[d.to_path_buf()]).unwrap();
        assert_eq!(maps, [d.join("a.yaml"), d.join("broken.yaml")]);
        assert_eq!(skipped, [d.join("bench.yaml")]);
        // Given by name, a file that is no map is refused before any run.
        let e = expand_maps_noting(&[d.join("bench.yaml")])
            .unwrap_err()
            .to_string();
        assert!(e.ends_with("bench.yaml is not a map: a YAML naming no image (an options or zone file?), not a map_server map"), "{e}");
        std::fs::write(d.join("lm.csv"), "id,x,y\n1,0,0\n").unwrap();
        let e = expand_maps_noting(&[d.join("lm.csv")])
            .unwrap_err()
            .to_string();
        assert!(e.ends_with("lm.csv is not a map: neither a map_server YAML (.yaml/.yml) nor a PNG or PNM/PGM image"), "{e}");
        // An image of a format ccpp does not decode (JPEG) is no map either.
        std::fs::write(d.join("photo.jpg"), b"\xff\xd8\xff\xe0\0\x10JFIF\0").unwrap();
        let e = expand_maps_noting(&[d.join("photo.jpg")])
            .unwrap_err()
            .to_string();
        assert!(e.contains("photo.jpg is not a map"), "{e}");
        std::fs::write(d.join("m.pgm"), "P5\n1 1\n255\n\0").unwrap();
        assert!(expand_maps_noting(&[d.join("m.pgm"), d.join("broken.yaml")]).is_ok());
    }

    /// A folder gives its YAML maps, or its images when it has none, sorted; what is neither
    /// file nor folder, a folder without maps and a map whose name is not UTF-8 are refused.
    #[test]
    fn folders_expand_to_their_maps() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a"), dir.path().join("b"));
        for (folder, files) in [
            (&a, &["z.yaml", "m.YML", "x.png"][..]),
            (&b, &["q.pgm", "n.txt"]),
        ] {
            std::fs::create_dir(folder).unwrap();
            for f in files {
                // (an image begins as one: a file given by name is looked at)
                let head: &[u8] = if *f == "x.png" {
                    b"\x89PNG\r\n\x1a\n"
                } else {
                    b""
                };
                std::fs::write(folder.join(f), head).unwrap();
            }
        }
        let got = expand_maps(&[a.clone(), b.clone(), a.join("x.png")]).unwrap();
        assert_eq!(
            got,
            [
                a.join("m.YML"),
                a.join("z.yaml"),
                b.join("q.pgm"),
                a.join("x.png")
            ]
        );
        let missing = dir.path().join("none");
        let e = expand_maps(&[missing]).unwrap_err().to_string();
        assert!(e.ends_with("none: no such file or folder"), "{e}");
        let empty = dir.path().join("empty");
        std::fs::create_dir(&empty).unwrap();
        let e = expand_maps(&[empty]).unwrap_err().to_string();
        assert!(e.starts_with("no map found in "), "{e}");
        assert!(matches!(expand_maps(&[]), Err(MapListError::Empty)));
        #[cfg(unix)]
        {
            use std::os::unix::ffi::OsStrExt;
            let odd = dir.path().join("odd");
            std::fs::create_dir(&odd).unwrap();
            std::fs::write(odd.join(std::ffi::OsStr::from_bytes(b"\xff.yaml")), "").unwrap();
            let e = expand_maps(&[odd]).unwrap_err().to_string();
            assert!(
                e.contains("whose name is not valid UTF-8; rename it"),
                "{e}"
            );
        }
    }

    /// The names of the first, quadratic form of [`name_maps`] (kept here as the reference).
    fn reference_names(maps: Vec<PathBuf>) -> Vec<(PathBuf, String)> {
        let mut seen = Vec::new();
        let mut kept = Vec::new();
        for m in maps {
            let canon = std::fs::canonicalize(&m).unwrap_or_else(|_| m.clone());
            if !seen.contains(&canon) {
                seen.push(canon);
                kept.push(m);
            }
        }
        let stems: Vec<String> = kept.iter().map(|p| map_name(p)).collect();
        let mut names: Vec<String> = kept
            .iter()
            .zip(&stems)
            .map(|(p, stem)| {
                if stems.iter().filter(|s| *s == stem).count() == 1 {
                    return stem.clone();
                }
                let canon = std::fs::canonicalize(p).unwrap_or_else(|_| p.clone());
                match canon.parent().and_then(Path::file_name) {
                    Some(folder) => format!("{}-{stem}", folder.to_string_lossy()),
                    None => stem.clone(),
                }
            })
            .collect();
        for i in 0..names.len() {
            let earlier = names[..i].iter().filter(|n| **n == names[i]).count();
            if earlier > 0 {
                let mut k = earlier + 1;
                while names.contains(&format!("{}-{k}", names[i])) {
                    k += 1;
                }
                names[i] = format!("{}-{k}", names[i]);
            }
        }
        kept.into_iter().zip(names).collect()
    }

    /// Repeated files, shared stems in several folders, names that collide with a folder-stem
    /// name or with a `-k` suffix: the same names as the reference, and by index for Python.
    #[test]
    fn colliding_names_are_told_apart_as_before() {
        let dir = tempfile::tempdir().unwrap();
        let mut paths = Vec::new();
        for (folder, file) in [
            ("a", "x.yaml"),
            ("b", "x.yaml"),
            ("c", "a-x.yaml"),
            ("d", "a-x-2.yaml"),
            ("a", "x.pgm"),
            ("e", "x-2.yaml"),
            ("e", "x.png"),
            ("f", "y.yaml"),
            ("a", "summary.yaml"),
        ] {
            let f = dir.path().join(folder);
            std::fs::create_dir_all(&f).unwrap();
            std::fs::write(f.join(file), "").unwrap();
            paths.push(f.join(file));
        }
        // The same file twice (once through `..`), and a missing one.
        paths.push(dir.path().join("b/../a/x.yaml"));
        paths.push(dir.path().join("g/x.yaml"));
        paths.push(paths[1].clone());
        // Many maps of one stem: a sweep's folders of generated maps, in folders of their own
        // and in folders of one name (all `maps-map`, then numbered).
        for k in 0..300 {
            let f = dir.path().join(format!("m{k}"));
            std::fs::create_dir_all(&f).unwrap();
            std::fs::write(f.join("map.yaml"), "").unwrap();
            paths.push(f.join("map.yaml"));
            let g = dir.path().join(format!("run{k}")).join("maps");
            std::fs::create_dir_all(&g).unwrap();
            std::fs::write(g.join("map.yaml"), "").unwrap();
            paths.push(g.join("map.yaml"));
        }
        std::fs::create_dir_all(dir.path().join("x")).unwrap();
        std::fs::write(dir.path().join("x/maps-map-7.yaml"), "").unwrap();
        paths.insert(5, dir.path().join("x/maps-map-7.yaml"));
        let want = reference_names(paths.clone());
        assert_eq!(name_maps(paths.clone()), want);
        let by_index: Vec<(PathBuf, String)> = name_maps_indexed(&paths)
            .into_iter()
            .map(|(i, n)| (paths[i].clone(), n))
            .collect();
        assert_eq!(by_index, want);
        let distinct: std::collections::BTreeSet<&String> = want.iter().map(|(_, n)| n).collect();
        assert_eq!(distinct.len(), want.len());
        assert_eq!(want.len(), paths.len() - 2);
    }

    /// The stems `.` and `..` (files `..yaml`, `...yaml`) would put run folders beside
    /// `runs/`, and a map `summary` would share its trade-off plot with the summary's.
    #[test]
    fn map_names_are_folder_names_and_not_the_summary() {
        let dir = tempfile::tempdir().unwrap();
        let files = ["..yaml", "...yaml", "summary.yaml", "a.yaml"];
        let paths: Vec<PathBuf> = files.iter().map(|f| dir.path().join(f)).collect();
        for p in &paths {
            std::fs::write(p, "").unwrap();
        }
        let folder = dir
            .path()
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let names: Vec<String> = name_maps(paths).into_iter().map(|(_, n)| n).collect();
        assert_eq!(
            names,
            [
                format!("{folder}-map"),
                format!("{folder}-map-2"),
                "summary-map".to_string(),
                "a".to_string()
            ]
        );
    }

    /// A name made of a folder whose name holds an escape sequence and a line break (reached
    /// through a link, so the path given had none) has them as `_`; a stem with U+FFFE too.
    #[test]
    fn names_hold_no_hidden_characters() {
        let dir = tempfile::tempdir().unwrap();
        let odd = dir.path().join("b\u{1b}]0;T\u{7}\nerror: X");
        let plain = dir.path().join("a");
        for d in [&odd, &plain] {
            std::fs::create_dir(d).unwrap();
            std::fs::write(d.join("x.yaml"), "").unwrap();
        }
        std::fs::write(plain.join("c\u{fffe}d.yaml"), "").unwrap();
        let names: Vec<String> = name_maps(vec![
            plain.join("x.yaml"),
            odd.join("x.yaml"),
            plain.join("c\u{fffe}d.yaml"),
        ])
        .into_iter()
        .map(|(_, n)| n)
        .collect();
        assert_eq!(names, ["a-x", "b_]0;T__error: X-x", "c_d"]);
    }
}

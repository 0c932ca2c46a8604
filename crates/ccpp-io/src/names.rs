//! The names of the maps of a sweep (`ccpp bench`, Python's `ccpp.sweep`): one name a map, for
//! its run folders (`runs/MAP/PLANNER`), its rows and its plots. The command line and Python
//! name maps here, so that their rows and folders agree.
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

/// A map's name from its file stem. A stem that is not a usable folder name (`..yaml` and
/// `...yaml` have the stems `.` and `..`, which would put the run folders beside `runs/`)
/// becomes `map`, and `summary` becomes `summary-map`: the per-map plot `tradeoff_<map>`
/// would otherwise be the summary's `tradeoff_summary`.
fn map_name(p: &Path) -> String {
    let stem = p
        .file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    if stem.chars().all(|c| c == '.') {
        "map".into()
    } else if stem == "summary" {
        "summary-map".into()
    } else {
        stem
    }
}

/// Drops repeated maps (the same file named twice) and gives every map a distinct name, used
/// for its run folders, rows and plots: the file stem, or, when two maps in different folders
/// share a stem, `<folder>-<stem>` (then `-2`, `-3`, ... if that still repeats).
pub fn name_maps(maps: Vec<PathBuf>) -> Vec<(PathBuf, String)> {
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
            match canon
                .parent()
                .and_then(Path::file_name)
                .map(|n| n.to_string_lossy().into_owned())
            {
                Some(folder) => format!("{folder}-{stem}"),
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

#[cfg(test)]
mod tests {
    use super::*;

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
}

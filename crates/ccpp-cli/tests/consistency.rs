//! End-to-end checks that the same text is read and written the same way everywhere: planner
//! names with spaces around them, map names in `results.md`, huge numbers in messages.
#![allow(clippy::unwrap_used)]

use crate::common::{ccpp, data};

/// `ccpp planners --defaults "bsa, bcd"` took the space, `ccpp bench --planners "bsa, bcd"` and
/// `ccpp run --planner " bsa"` failed with `unknown planner " bcd"`. Whitespace around a planner
/// name is dropped wherever a name is read, and the bench's run folders and rows carry the name.
#[test]
fn planner_names_with_spaces_around_them_are_read_everywhere() {
    let dir = tempfile::tempdir().unwrap();
    let map = data("teb_empty_box.yaml");
    let out = dir.path().join("bench");
    ccpp()
        .args([
            "bench",
            "--quiet",
            "--planners",
            "bsa, bcd , bsa",
            "--maps",
        ])
        .arg(&map)
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    let mut runs: Vec<String> = std::fs::read_dir(out.join("runs/teb_empty_box"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    runs.sort();
    assert_eq!(runs, ["bcd", "bsa"]);
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let planners: Vec<&str> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap())
        .collect();
    assert_eq!(planners, ["bsa", "bcd"], "{csv}");
    let run = dir.path().join("run");
    ccpp()
        .args(["run", "--planner", " bsa ", "--map"])
        .arg(&map)
        .arg("--out")
        .arg(&run)
        .assert()
        .success();
    let json = crate::common::read_json(&run.join("metrics.json"));
    assert_eq!(json["planner"], "bsa");
    ccpp()
        .args(["plan", "--planner", " bcd", "--map"])
        .arg(&map)
        .arg("--out")
        .arg(dir.path().join("plan"))
        .assert()
        .success();
    // A name that is not a planner's is still refused, as given.
    let o = ccpp()
        .args(["run", "--planner", " bs a", "--map"])
        .arg(&map)
        .arg("--out")
        .arg(dir.path().join("bad"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("unknown planner \" bs a\""),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

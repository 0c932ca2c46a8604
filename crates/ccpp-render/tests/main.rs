//! The render crate's integration tests, in one binary: every file of `tests/` is a module of this
//! one, so a test is named `FILE::TEST` (`cargo test -p ccpp-render --test integration
//! replay_browser::`). One binary links once, where one per file linked the whole crate graph each
//! time. `autotests = false` in Cargo.toml: a new `tests/*.rs` file must be declared below
//! (`every_test_file_is_a_module` fails until it is).

mod heading_tick;
mod replay_browser;
mod replay_far_pose;
mod support {
    pub mod browser;
}

/// Every `tests/*.rs` file is a module of this binary (otherwise its tests would not run).
#[test]
fn every_test_file_is_a_module() {
    let main = include_str!("main.rs");
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    for entry in std::fs::read_dir(dir).expect("tests/") {
        let name = entry.expect("entry").file_name();
        let name = name.to_string_lossy();
        if let Some(stem) = name.strip_suffix(".rs").filter(|s| *s != "main") {
            assert!(
                main.lines().any(|l| l == format!("mod {stem};")),
                "tests/{name} is not a module of tests/main.rs: its tests would not run"
            );
        }
    }
}

//! The README's Rust code blocks are the bodies of `examples/library.rs` and
//! `examples/plan_nav_path.rs` (compiled here through `#[path]`), and both
//! run on the shared maps (skipped with a note when `../shared/maps` is absent).

use std::path::{Path, PathBuf};

#[path = "../examples/library.rs"]
mod library;
#[path = "../examples/plan_nav_path.rs"]
mod plan_nav_path;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The code lines of a Rust snippet: comments and blank lines dropped, whitespace trimmed.
fn code_lines(text: &str) -> Vec<String> {
    text.lines()
        .map(|l| l.split("//").next().unwrap_or("").trim().to_string())
        .filter(|l| !l.is_empty())
        .collect()
}

/// The code of the README's Rust blocks (fenced as `rust`), in order.
fn readme_rust_blocks() -> Vec<String> {
    let readme = std::fs::read_to_string(root().join("README.md")).expect("README.md");
    let mut blocks = Vec::new();
    let mut current: Option<String> = None;
    for line in readme.lines() {
        match &mut current {
            None if line.trim_start().starts_with("```rust") => current = Some(String::new()),
            Some(b) if line.trim_start().starts_with("```") => {
                blocks.push(std::mem::take(b));
                current = None;
            }
            Some(b) => {
                b.push_str(line);
                b.push('\n');
            }
            None => {}
        }
    }
    blocks
}

/// `code` without comments, whitespace or the trailing commas rustfmt adds (`a,)` -> `a)`).
fn normalized(code: &str) -> String {
    let flat: String = code_lines(code).concat().split_whitespace().collect();
    flat.replace(",)", ")")
}

/// Whether every code line of `block` occurs in `file`, in order (rustfmt may wrap the file's
/// lines differently from the README's).
fn contained_in_order(block: &str, file: &str) -> Result<(), String> {
    let file = normalized(file);
    let mut at = 0;
    for line in code_lines(block) {
        match file[at..].find(&normalized(&line)) {
            Some(i) => at += i + normalized(&line).len(),
            None => return Err(line),
        }
    }
    Ok(())
}

#[test]
fn readme_rust_blocks_are_the_examples() {
    let blocks = readme_rust_blocks();
    assert_eq!(blocks.len(), 2, "README.md has two Rust blocks: {blocks:?}");
    let examples = root().join("crates/ccpp-io/examples");
    for (block, file) in blocks.iter().zip(["plan_nav_path.rs", "library.rs"]) {
        let text = std::fs::read_to_string(examples.join(file)).expect("example");
        if let Err(line) = contained_in_order(block, &text) {
            panic!("README line `{line}` is not (in order) in examples/{file}");
        }
    }
}

#[test]
fn a_changed_readme_line_is_noticed() {
    let file = "let a = 1;\nlet b = f(\n    a,\n    1,\n); // two\n";
    assert!(contained_in_order("let a = 1;\n\nlet b = f(a, 1);", file).is_ok());
    assert!(contained_in_order("let b = f(a, 1);\nlet a = 1;", file).is_err());
    assert!(contained_in_order("let a = 2;", file).is_err());
}

#[test]
fn readme_examples_run() {
    let maps = root().join("../shared/maps");
    if !maps.is_dir() {
        eprintln!("note: {} absent, README examples not run", maps.display());
        return;
    }
    library::run(maps.join("teb_maze.yaml").to_str().unwrap()).expect("library example");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("nav_path.yaml");
    plan_nav_path::run(
        maps.join("nav2_depot.yaml").to_str().unwrap(),
        out.to_str().unwrap(),
    )
    .expect("plan example");
    let yaml = std::fs::read_to_string(&out).unwrap();
    assert!(
        yaml.contains("frame_id: map") && yaml.contains("poses:"),
        "{yaml}"
    );
}

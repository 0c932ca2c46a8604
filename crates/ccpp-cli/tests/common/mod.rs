//! Helpers shared by the CLI's end-to-end test modules (see `main.rs`).
#![allow(clippy::unwrap_used)]

use std::path::{Path, PathBuf};

use assert_cmd::Command;

/// Every planner, in the registry's order.
pub const ALL: [&str; 8] = [
    "random-bounce",
    "ba-star",
    "ba-star-extended",
    "bsa",
    "bsa-extended",
    "bsa-bfs",
    "bcd",
    "rect-boustrophedon",
];

/// The `ccpp` binary built for these tests.
pub fn ccpp() -> Command {
    Command::cargo_bin("ccpp").unwrap()
}

/// A file of `tests/data`.
pub fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// The shared maps folder (`../shared/maps` beside the checkout), when it is there.
pub fn shared_maps() -> Option<PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/maps");
    p.is_dir().then_some(p)
}

/// A JSON file, parsed.
pub fn read_json(p: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

/// Writes a PGM (0.05 m/px as a bare image) of `w` x `h` px: walls around, `blocked(x, y)`
/// inside (y down from the top row).
pub fn pgm(
    dir: &Path,
    name: &str,
    w: usize,
    h: usize,
    blocked: impl Fn(usize, usize) -> bool,
) -> PathBuf {
    let mut bytes = format!("P5\n{w} {h}\n255\n").into_bytes();
    for y in 0..h {
        for x in 0..w {
            let wall = x == 0 || y == 0 || x == w - 1 || y == h - 1 || blocked(x, y);
            bytes.push(if wall { 0 } else { 254 });
        }
    }
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// An 8 x 6 m room with three pillars: backtracking happens, and BA*-based planners cover it in
/// several regions.
pub fn pillars(dir: &Path) -> PathBuf {
    pgm(dir, "pillars.pgm", 160, 120, |x, y| {
        ((40..52).contains(&x) && (20..80).contains(&y))
            || ((90..104).contains(&x) && (50..110).contains(&y))
            || ((120..132).contains(&x) && (10..40).contains(&y))
    })
}

/// A 10 x 7 m flat (0.05 m/px) like a real scan: two rooms joined by a 0.8 m door, a pillar
/// and a table at pixel offsets off any tile lattice, a one-pixel diagonal wall and 25 specks of
/// salt noise.
pub fn rooms(dir: &Path) -> PathBuf {
    let mut salt = Vec::new();
    let mut x = 0x2545_f491_4f6c_dd1d_u64;
    for _ in 0..25 {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        salt.push((5 + (x % 190) as usize, 5 + ((x >> 32) % 130) as usize));
    }
    pgm(dir, "rooms.pgm", 200, 140, |x, y| {
        let (fx, fy) = (x as f64, y as f64);
        ((99..=100).contains(&x) && !(61..77).contains(&y))
            || ((30..43).contains(&x) && (23..57).contains(&y))
            || ((140..151).contains(&x) && (87..121).contains(&y))
            || ((157..181).contains(&x) && (17..29).contains(&y))
            || ((20..70).contains(&x) && ((fy - 80.0) - (fx - 20.0) * 0.6).abs() < 1.0)
            || salt.contains(&(x, y))
    })
}

/// Runs `ccpp SUBCOMMAND --planner P --map MAP ARGS --out DIR/SUB`, asserts success and returns
/// the output folder (`SUBCOMMAND` is `run` or `plan`).
pub fn ccpp_ok(
    subcommand: &str,
    dir: &Path,
    sub: &str,
    map: &Path,
    planner: &str,
    args: &[&str],
) -> PathBuf {
    let out = dir.join(sub);
    ccpp()
        .args([subcommand, "--planner", planner, "--map"])
        .arg(map)
        .args(args)
        .arg("--out")
        .arg(&out)
        .assert()
        .success();
    out
}

/// [`ccpp_ok`] for `ccpp run`.
pub fn run_ok(dir: &Path, sub: &str, map: &Path, planner: &str, args: &[&str]) -> PathBuf {
    ccpp_ok("run", dir, sub, map, planner, args)
}

/// [`ccpp_ok`] for `ccpp plan`.
pub fn plan_ok(dir: &Path, sub: &str, map: &Path, planner: &str, args: &[&str]) -> PathBuf {
    ccpp_ok("plan", dir, sub, map, planner, args)
}

/// A square room of `n` x `n` px at 0.05 m/px, a 2 px wall around and square pillars
/// (`n / 40` px wide, every `n / 5` px, from `n / 20` px in): big enough for a run or bench on
/// it to take a noticeable time.
pub fn pillared_room(dir: &Path, name: &str, n: u32) -> PathBuf {
    let mut img = image::GrayImage::from_pixel(n, n, image::Luma([254]));
    let (period, side, margin) = (n / 5, n / 40, n / 20);
    for (x, y, p) in img.enumerate_pixels_mut() {
        let wall = x < 2 || y < 2 || x >= n - 2 || y >= n - 2;
        let pillar = (x % period) < side && (y % period) < side && x > margin && y > margin;
        if wall || pillar {
            *p = image::Luma([0]);
        }
    }
    let p = dir.join(name);
    img.save(&p).unwrap();
    p
}

/// Waits (a minute at most) until `mark` exists: the file a paused ccpp creates as its pause
/// begins (`CCPP_TEST_PAUSED_FILE`), so a test acts during the pause on a loaded machine too.
///
/// # Panics
/// When the file never appears.
pub fn wait_for_pause(mark: &Path) {
    let t0 = std::time::Instant::now();
    while !mark.exists() {
        assert!(
            t0.elapsed() < std::time::Duration::from_mins(1),
            "ccpp never reached its pause ({})",
            mark.display()
        );
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
}

/// The page tests' browser helpers, shared with `ccpp-render`'s tests.
#[path = "../../../ccpp-render/tests/support/browser.rs"]
mod browser;
pub use browser::{headless, output_within_limit, require_chromium};

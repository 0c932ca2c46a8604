//! Helpers shared by the fuzz targets in `fuzz_targets/`.

use std::sync::OnceLock;

use ccpp_core::grid::{Cell, GridMap, MapFrame};
use ccpp_core::world::{Robot, World};

/// Splits `data` at its first NUL byte: the text part (which must be UTF-8, else `None`) and the
/// rest. Without a NUL the whole input is the text and the rest is empty.
pub fn split_text(data: &[u8]) -> Option<(&str, &[u8])> {
    let cut = data.iter().position(|&b| b == 0).unwrap_or(data.len());
    let text = std::str::from_utf8(&data[..cut]).ok()?;
    let rest = data.get(cut + 1..).unwrap_or(&[]);
    Some((text, rest))
}

/// A small fixed map (24 x 16 px at 0.1 m/px): a walled room with a pillar and an unknown
/// patch, so every cell kind and a non-convex free space occur.
pub fn tiny_grid() -> GridMap {
    let (w, h) = (24usize, 16usize);
    let mut cells = vec![Cell::Free; w * h];
    for r in 0..h {
        for c in 0..w {
            let wall = r == 0 || c == 0 || r == h - 1 || c == w - 1;
            let pillar = (6..9).contains(&r) && (10..13).contains(&c);
            let unknown = (2..4).contains(&r) && (18..21).contains(&c);
            cells[r * w + c] = if wall || pillar {
                Cell::Occupied
            } else if unknown {
                Cell::Unknown
            } else {
                Cell::Free
            };
        }
    }
    #[allow(clippy::unwrap_used)]
    GridMap::new(MapFrame::new(w, h, 0.1), cells).unwrap()
}

/// The world of [`tiny_grid`] with a 0.15 m robot at the default start (built once).
pub fn tiny_world() -> &'static World {
    static WORLD: OnceLock<World> = OnceLock::new();
    #[allow(clippy::unwrap_used)]
    WORLD.get_or_init(|| World::new(tiny_grid(), Robot::new(0.15), None).unwrap())
}

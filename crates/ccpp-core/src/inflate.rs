//! Obstacle inflation by a distance transform (not by repeated erosion).

use crate::dt::squared_edt;
use crate::grid::{Cell, GridMap};

/// Returns a copy of `map` where every free pixel whose centre lies within `radius_m` of a
/// non-free (occupied or unknown) pixel centre becomes occupied; unknown pixels stay unknown.
/// Unknown pixels grow because the robot may not enter them either (every collision test
/// counts a non-free pixel as an obstacle): a floor bounded by unknown pixels, as in many
/// scanned maps, got no margin at all (`teb_empty_box` at `--inflate 0.05` lost no pixel, and
/// the run said it had been inflated). A navigation stack that drives into unknown space
/// chooses otherwise (Nav2's inflation layer grows unknown cells only with its
/// `inflate_unknown` parameter, off by default). The image border is not inflated: outside the
/// image is occupied by convention and every collision check already accounts for it.
///
/// One exact Euclidean distance transform, O(pixels) whatever the radius.
pub fn inflate(map: &GridMap, radius_m: f64) -> GridMap {
    let mut out = map.clone();
    if radius_m.is_nan() || radius_m <= 0.0 {
        return out;
    }
    let f = *map.frame();
    let cells = map.cells();
    let dt = squared_edt(f.width, f.height, |i| cells[i] != Cell::Free, false);
    let r = radius_m / f.resolution;
    let r2 = r * r + 1e-9;
    for (c, &d2) in out.cells_mut().iter_mut().zip(&dt) {
        if *c == Cell::Free && f64::from(d2) <= r2 {
            *c = Cell::Occupied;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grows_by_radius() {
        let g: GridMap = ".......\n.......\n...#...\n.......\n......."
            .parse()
            .unwrap();
        let i = inflate(&g, 1.0);
        assert_eq!(i.counts().1, 5); // plus shape
        let i = inflate(&g, 1.5);
        assert_eq!(i.counts().1, 9); // 3x3 (diagonal sqrt 2 <= 1.5)
        assert_eq!(inflate(&g, 0.0), g);
    }

    /// Unknown pixels grow like occupied ones (the robot may not enter them either) and stay
    /// unknown.
    #[test]
    fn unknown_pixels_grow_too() {
        let g: GridMap = ".......\n.......\n...?...\n.......\n......."
            .parse()
            .unwrap();
        let i = inflate(&g, 1.0);
        assert_eq!(
            format!("{i:?}"),
            format!(
                "{:?}",
                ".......\n...#...\n..#?#..\n...#...\n......."
                    .parse::<GridMap>()
                    .unwrap()
            )
        );
    }
}

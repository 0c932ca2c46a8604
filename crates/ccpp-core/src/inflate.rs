//! Obstacle inflation by a distance transform (not by repeated erosion).

use crate::dt::squared_edt;
use crate::grid::{Cell, GridMap};

/// Returns a copy of `map` where every free pixel whose centre lies within `radius_m` of an
/// occupied pixel centre becomes occupied. Unknown pixels are left as they are and do not grow
/// (they are already non-traversable). The image border is not inflated: outside the image is
/// occupied by convention and every collision check already accounts for it.
///
/// One exact Euclidean distance transform, O(pixels) whatever the radius.
pub fn inflate(map: &GridMap, radius_m: f64) -> GridMap {
    let mut out = map.clone();
    if radius_m.is_nan() || radius_m <= 0.0 {
        return out;
    }
    let f = *map.frame();
    let cells = map.cells();
    let dt = squared_edt(f.width, f.height, |i| cells[i] == Cell::Occupied, false);
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
}

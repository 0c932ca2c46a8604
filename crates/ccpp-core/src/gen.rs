//! Synthetic maps for tests and benchmarks.
//!
//! [`office`] draws an office floor: an outer wall, double-loaded horizontal corridors (rooms on
//! both sides, one door each onto the corridor), vertical corridors joining them, and furniture
//! blocks inside the rooms. Deterministic from its seed (the in-tree [`SplitMix64`]).
//!
//! ```
//! let m = ccpp_core::gen::office(400, 300, 0.05, 7);
//! assert_eq!(m.frame().width, 400);
//! assert_eq!(m, ccpp_core::gen::office(400, 300, 0.05, 7));
//! let (free, occupied, unknown) = m.counts();
//! assert!(free > occupied && occupied > 0 && unknown == 0);
//! ```

use crate::grid::{Cell, GridMap, MapFrame};
use crate::rng::SplitMix64;

/// Pixel canvas with y up (row 0 of the image is the top).
struct Canvas {
    w: usize,
    h: usize,
    cells: Vec<Cell>,
}

impl Canvas {
    /// Fills `[x0, x1) x [y0, y1)` (pixels, y up), clipped to the canvas.
    fn fill(&mut self, x0: i64, y0: i64, x1: i64, y1: i64, v: Cell) {
        let x0 = x0.clamp(0, self.w as i64) as usize;
        let x1 = x1.clamp(0, self.w as i64) as usize;
        let y0 = y0.clamp(0, self.h as i64) as usize;
        let y1 = y1.clamp(0, self.h as i64) as usize;
        for y in y0..y1 {
            let row = self.h - 1 - y;
            self.cells[row * self.w + x0..row * self.w + x1].fill(v);
        }
    }
}

/// An office floor of `width_px` x `height_px` pixels at `resolution` m/px (see the module
/// docs). Rooms are 3–7 m wide and 4–6 m deep, corridors 2 m wide, doors 1 m, walls 0.15 m;
/// furniture blocks of 0.4–1.6 m keep at least 0.7 m from the room walls. Maps smaller than a
/// few metres degenerate to a walled empty room.
///
/// # Panics
/// When `width_px` or `height_px` is 0, or `resolution` is not a positive finite number.
pub fn office(width_px: usize, height_px: usize, resolution: f64, seed: u64) -> GridMap {
    assert!(width_px > 0 && height_px > 0, "empty map");
    assert!(resolution.is_finite() && resolution > 0.0, "bad resolution");
    let mut rng = SplitMix64::new(seed);
    // At most 1e12 px: sums of a few stay far from overflowing (at resolution 1e-300 every
    // length saturated at i64::MAX and the first sum overflowed: hostile pass); a length
    // beyond the map leaves a walled empty room, as on any map too small.
    let px = |m: f64| ((m / resolution).round().min(1e12) as i64).max(1);
    let (w, h) = (width_px as i64, height_px as i64);
    let mut c = Canvas {
        w: width_px,
        h: height_px,
        cells: vec![Cell::Free; width_px * height_px],
    };
    let t = px(0.15);
    let corridor = px(2.0);
    let door = px(1.0);
    // Outer wall.
    c.fill(0, 0, w, t, Cell::Occupied);
    c.fill(0, h - t, w, h, Cell::Occupied);
    c.fill(0, 0, t, h, Cell::Occupied);
    c.fill(w - t, 0, w, h, Cell::Occupied);

    // Vertical corridors: x intervals [vx, vx + corridor).
    let mut verticals = Vec::new();
    let mut x = t + px(rng.range(0.0, 8.0));
    while x + corridor + t < w - t {
        verticals.push(x);
        x += corridor + px(rng.range(25.0, 45.0));
    }
    // Horizontal structure: (y0, y1) of room bands and corridors.
    let mut corridors = Vec::new();
    let mut bands: Vec<(i64, i64, bool)> = Vec::new(); // (y0, y1, door on top side)
    let mut y = t;
    loop {
        let d1 = px(rng.range(4.0, 6.0));
        let d2 = px(rng.range(4.0, 6.0));
        let need = d1 + t + corridor + t + d2 + t;
        if y + need > h - t {
            break;
        }
        bands.push((y, y + d1, true));
        c.fill(0, y + d1, w, y + d1 + t, Cell::Occupied);
        let cy = y + d1 + t;
        corridors.push((cy, cy + corridor));
        c.fill(0, cy + corridor, w, cy + corridor + t, Cell::Occupied);
        let b0 = cy + corridor + t;
        bands.push((b0, b0 + d2, false));
        c.fill(0, b0 + d2, w, b0 + d2 + t, Cell::Occupied);
        y = b0 + d2 + t;
    }

    // Rooms: split every band between vertical corridors.
    let mut edges = vec![t];
    for &vx in &verticals {
        edges.push(vx - t);
        edges.push(vx + corridor + t);
    }
    edges.push(w - t);
    for &(y0, y1, door_top) in &bands {
        for seg in edges.chunks(2) {
            let (sx0, sx1) = (seg[0], seg[1]);
            if sx1 - sx0 < px(1.0) {
                continue;
            }
            let mut rx = sx0;
            while rx < sx1 {
                let mut rw = px(rng.range(3.0, 7.0));
                if sx1 - (rx + rw) < px(3.0) {
                    rw = sx1 - rx;
                }
                let rx1 = rx + rw;
                if rx1 < sx1 {
                    c.fill(rx1, y0, rx1 + t, y1, Cell::Occupied);
                }
                // Door onto the corridor.
                let inner = (rx1 - rx - door).max(0);
                let dx = rx + (rng.next_f64() * inner as f64) as i64;
                if door_top && !corridors.is_empty() {
                    c.fill(dx, y1, dx + door.min(rx1 - rx), y1 + t, Cell::Free);
                } else if !door_top {
                    c.fill(dx, y0 - t, dx + door.min(rx1 - rx), y0, Cell::Free);
                }
                // Furniture.
                let margin = px(0.7);
                let n = (rng.next_u64() % 4) as usize;
                for _ in 0..n {
                    let fw = px(rng.range(0.4, 1.6));
                    let fh = px(rng.range(0.4, 1.6));
                    let ax0 = rx + margin;
                    let ax1 = rx1 - margin - fw;
                    let ay0 = y0 + margin;
                    let ay1 = y1 - margin - fh;
                    if ax1 <= ax0 || ay1 <= ay0 {
                        continue;
                    }
                    let fx = ax0 + (rng.next_f64() * (ax1 - ax0) as f64) as i64;
                    let fy = ay0 + (rng.next_f64() * (ay1 - ay0) as f64) as i64;
                    c.fill(fx, fy, fx + fw, fy + fh, Cell::Occupied);
                }
                rx = rx1 + t;
            }
        }
    }
    // Vertical corridors: carve, then wall their sides except where they cross corridors.
    for &vx in &verticals {
        c.fill(vx, t, vx + corridor, h - t, Cell::Free);
        let mut yy = t;
        for &(cy0, cy1) in corridors.iter().chain(std::iter::once(&(h - t, h - t))) {
            c.fill(vx - t, yy, vx, cy0, Cell::Occupied);
            c.fill(vx + corridor, yy, vx + corridor + t, cy0, Cell::Occupied);
            yy = cy1;
        }
    }
    GridMap::new(MapFrame::new(width_px, height_px, resolution), c.cells)
        .expect("cells match the frame")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A resolution so fine that every length is more pixels than a map has gives a walled
    /// room, not an integer overflow (hostile pass: `office(20, 20, 1e-300, 0)` panicked in
    /// debug builds).
    #[test]
    fn a_resolution_too_fine_for_any_room_gives_a_walled_map() {
        for res in [1e-300, 1e-12] {
            let m = office(20, 20, res, 0);
            assert_eq!((m.frame().width, m.frame().height), (20, 20));
        }
        let m = office(200, 150, 0.05, 3);
        assert!(m.cells().contains(&Cell::Free));
    }
}

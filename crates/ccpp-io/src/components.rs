//! The free area holding the start: its size, the map's free area, and whether it reaches the
//! image border (then the start may lie outside the building). `info`, `run`, `plan`, `bench`
//! and Python's `RunResult.warnings` report it; the fill runs over horizontal runs
//! ([`ccpp_core::search::fill_runs`]).

use ccpp_core::grid::{Cell, GridMap};
use ccpp_core::search::{fill_runs, Connectivity};
use ccpp_core::Point;

/// Fills the 4-connected free component holding `seed` by horizontal runs
/// ([`ccpp_core::search::fill_runs`]), marking `seen`; returns the component's pixel count and
/// whether it touches the image border.
pub fn flood_runs(g: &GridMap, seed: usize, seen: &mut fixedbitset::FixedBitSet) -> (usize, bool) {
    let f = *g.frame();
    let (w, h) = (f.width, f.height);
    let cells = g.cells();
    let (mut size, mut border) = (0usize, false);
    fill_runs(
        w,
        h,
        |i| cells[i] == Cell::Free,
        seed,
        Connectivity::Four,
        seen,
        |row, lo, hi| {
            size += hi - lo + 1;
            border |= lo == 0 || hi + 1 == w || row == 0 || row + 1 == h;
        },
    );
    (size, border)
}

/// Counts 4-connected components of free pixels and the size of the largest.
pub fn free_components(g: &GridMap) -> (usize, usize) {
    let cells = g.cells();
    let mut seen = fixedbitset::FixedBitSet::with_capacity(cells.len());
    let (mut n, mut largest) = (0usize, 0usize);
    for i in 0..cells.len() {
        if cells[i] != Cell::Free || seen.contains(i) {
            continue;
        }
        n += 1;
        let (size, _) = flood_runs(g, i, &mut seen);
        largest = largest.max(size);
    }
    (n, largest)
}

/// Least free floor the zones cut off from the start, m^2, for [`zone_cut_off_warning`].
pub const CUT_OFF_MIN_M2: f64 = 1.0;

/// Least share of the allowed free floor beside the start that the zones cut off, for
/// [`zone_cut_off_warning`].
pub const CUT_OFF_MIN_SHARE: f64 = 0.1;

/// The warning (without `warning: `) when the zones of `world` cut much of the floor they
/// allow apart from the start ([`ccpp_core::world::World::zone_cut_off_px`]: floor inside the
/// area and outside the keep-outs that the robot could sweep were the zones no walls on its
/// way, but cannot with them), at least [`CUT_OFF_MIN_M2`] and [`CUT_OFF_MIN_SHARE`] of that
/// floor. A keep-out that cut an area in two, or an area of two rooms joined only outside it,
/// left one part unswept while the run said "99.6 % covered" (coverage is of the part the
/// start reaches) without a word (hostile pass); so did a gap between keep-outs narrower than
/// the robot. Floor that walls already part from the start is not the zones' doing and not
/// counted (an area over a whole map with rooms apart behind walls warned of them). `None`
/// without zones.
pub fn zone_cut_off_warning(world: &ccpp_core::world::World) -> Option<String> {
    let (allowed, apart) = world.zone_cut_off_px()?;
    let f = *world.frame();
    let res2 = f.resolution * f.resolution;
    let (apart_m2, allowed_m2) = (apart as f64 * res2, allowed as f64 * res2);
    (apart_m2 >= CUT_OFF_MIN_M2 && apart_m2 >= CUT_OFF_MIN_SHARE * allowed_m2).then(|| {
        format!(
            "the zones cut {apart_m2:.1} m2 of the {allowed_m2:.1} m2 of floor they allow \
             beside the start ({:.0} %) off from it (a {:.2} m wide robot cannot get past them); \
             no path from the start reaches that floor (a run's coverage figures are of the \
             part the start reaches): plan or run again with --start X,Y there to cover it",
            100.0 * apart_m2 / allowed_m2,
            2.0 * world.robot().radius
        )
    })
}

/// Whether the floor `accessible` (the robot's accessible surface, `frame`-sized) comes
/// within a pixel of a free pixel of the image's outer rows or columns (`free`): the robot
/// sweeps up to the image's edge there, as around a building drawn with its outside free. (Not
/// the border pixels themselves: outside the image counts as obstacle, so the robot's reach
/// ends a pixel or so short of it.)
pub fn reaches_image_border(
    frame: &ccpp_core::grid::MapFrame,
    accessible: &fixedbitset::FixedBitSet,
    free: impl Fn(usize, usize) -> bool,
) -> bool {
    let (w, h) = (frame.width, frame.height);
    if w == 0 || h == 0 {
        return false;
    }
    let near = |c: usize, r: usize| {
        free(c, r)
            && (r.saturating_sub(1)..=(r + 1).min(h - 1)).any(|rr| {
                (c.saturating_sub(1)..=(c + 1).min(w - 1))
                    .any(|cc| accessible.contains(frame.index(cc, rr)))
            })
    };
    (0..w).any(|c| near(c, 0) || near(c, h - 1)) || (0..h).any(|r| near(0, r) || near(w - 1, r))
}

/// The free component holding a start position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StartComponent {
    /// Its area, m^2 (0 when the start pixel is not free).
    pub area_m2: f64,
    /// All free area of the map, m^2.
    pub free_m2: f64,
    /// Whether it reaches the image border.
    pub touches_border: bool,
}

impl StartComponent {
    /// The 4-connected free component of `g` holding `start`.
    pub fn of(g: &GridMap, start: Point) -> Self {
        let f = *g.frame();
        let res2 = f.resolution * f.resolution;
        let free_m2 = g.counts().0 as f64 * res2;
        let Some((c, r)) = f.pixel_of(start) else {
            return Self {
                area_m2: 0.0,
                free_m2,
                touches_border: false,
            };
        };
        let seed = f.index(c, r);
        if g.cells()[seed] != Cell::Free {
            return Self {
                area_m2: 0.0,
                free_m2,
                touches_border: false,
            };
        }
        let mut seen = fixedbitset::FixedBitSet::with_capacity(f.len());
        let (size, touches_border) = flood_runs(g, seed, &mut seen);
        Self {
            area_m2: size as f64 * res2,
            free_m2,
            touches_border,
        }
    }

    /// [`Self::of`] on `world`'s map and start, where the component reaches the image
    /// border only when the floor the robot can reach from the start does (its accessible
    /// surface): free pixels that join the border through gaps narrower than the robot are
    /// no way out of the building (`nav2_depot`'s start was warned about as maybe outside,
    /// though its robot never comes within 5 px of the border: hostile pass).
    pub fn of_world(world: &ccpp_core::world::World) -> Self {
        let mut c = Self::of(world.map(), world.start().position());
        if c.touches_border {
            let map = world.map();
            c.touches_border = reaches_image_border(world.frame(), world.accessible(), |c, r| {
                map.get(c, r).is_free()
            });
        }
        c
    }

    /// One line: the component's area next to all free area.
    pub fn line(&self) -> String {
        let share = if self.free_m2 > 0.0 {
            100.0 * self.area_m2 / self.free_m2
        } else {
            0.0
        };
        format!(
            "{:.1} m2 of {:.1} m2 free ({share:.0} %) in the free area holding the start",
            self.area_m2, self.free_m2
        )
    }

    /// The warning (without `warning: `) when the start's free area reaches the image border.
    pub fn warning(&self) -> Option<String> {
        self.touches_border.then(|| {
            "the floor open to the robot from the start reaches the map's border, so the start may be \
             outside the building (only that area is covered); pass --start X,Y (Python: \
             start=(x, y)) to start inside"
                .to_string()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference: flood-fills the 4-connected free pixels pixel by pixel from `seed` (marking `seen`); returns the
    /// component's pixel count and whether it touches the image border.
    fn flood(g: &GridMap, seed: usize, seen: &mut [bool], stack: &mut Vec<usize>) -> (usize, bool) {
        let f = *g.frame();
        let cells = g.cells();
        let (mut size, mut border) = (0usize, false);
        seen[seed] = true;
        stack.push(seed);
        while let Some(k) = stack.pop() {
            size += 1;
            let (c, r) = f.col_row(k);
            border |= c == 0 || r == 0 || c + 1 == f.width || r + 1 == f.height;
            let mut visit = |j: usize| {
                if cells[j] == Cell::Free && !seen[j] {
                    seen[j] = true;
                    stack.push(j);
                }
            };
            if c > 0 {
                visit(k - 1);
            }
            if c + 1 < f.width {
                visit(k + 1);
            }
            if r > 0 {
                visit(k - f.width);
            }
            if r + 1 < f.height {
                visit(k + f.width);
            }
        }
        (size, border)
    }

    /// The run-based fill finds the same component as the pixel-by-pixel one, on random maps
    /// with rooms, thin walls and the border.
    #[test]
    fn run_flood_matches_pixel_flood() {
        let mut seed = 0x00c0_ffeeu64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            seed >> 33
        };
        for trial in 0..60usize {
            let (w, h) = (1 + (trial % 23), 1 + (trial * 7 % 19));
            let density = 2 + (trial % 5) as u64;
            let mut art = String::new();
            for _ in 0..h {
                for _ in 0..w {
                    art.push(if next() % density == 0 { '#' } else { '.' });
                }
                art.push('\n');
            }
            let g = GridMap::from_ascii_scaled(&art, 1, 0.1).unwrap();
            // Components counted pixel by pixel, as `free_components` counts them by runs.
            let mut seen = vec![false; w * h];
            let (mut n, mut largest) = (0usize, 0usize);
            for i in 0..w * h {
                if g.cells()[i] == Cell::Free && !seen[i] {
                    n += 1;
                    largest = largest.max(flood(&g, i, &mut seen, &mut Vec::new()).0);
                }
            }
            assert_eq!(free_components(&g), (n, largest), "trial {trial}\n{art}");
            for i in 0..w * h {
                if g.cells()[i] != Cell::Free {
                    continue;
                }
                seen.fill(false);
                let want = flood(&g, i, &mut seen, &mut Vec::new());
                let mut bits = fixedbitset::FixedBitSet::with_capacity(w * h);
                assert_eq!(
                    flood_runs(&g, i, &mut bits),
                    want,
                    "trial {trial} seed pixel {i}\n{art}"
                );
            }
        }
    }
}

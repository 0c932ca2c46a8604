//! Tiles: squares of side `2 r` (by default) anchored so that the start position is a tile
//! centre; tile `(i, j)` with `i` east and `j` north in the world frame.

use std::collections::VecDeque;

use fixedbitset::FixedBitSet;

use crate::geometry::{round_i32, Point};
use crate::world::World;

/// A tile index: `i` east, `j` north.
pub type Tile = (i32, i32);

/// Neighbour offsets s1..s8 (counter-clockwise from east): E, NE, N, NW, W, SW, S, SE.
pub const N8: [Tile; 8] = [
    (1, 0),
    (1, 1),
    (0, 1),
    (-1, 1),
    (-1, 0),
    (-1, -1),
    (0, -1),
    (1, -1),
];

/// The tiling: where tile centres are.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TileGrid {
    /// World position of the centre of tile (0, 0).
    pub anchor: Point,
    /// Tile side, metres.
    pub side: f64,
}

impl TileGrid {
    /// A tiling with tile (0, 0) centred on `anchor`.
    pub fn new(anchor: Point, side: f64) -> Self {
        Self { anchor, side }
    }

    /// World centre of tile `t`.
    #[inline]
    pub fn center(&self, t: Tile) -> Point {
        Point::new(
            self.anchor.x + f64::from(t.0) * self.side,
            self.anchor.y + f64::from(t.1) * self.side,
        )
    }

    /// [`Self::tile_of`] for a point that may lie on a tile boundary up to the rounding of
    /// its world coordinates (a pixel centre: with tiles of `2 r` an odd number of pixels
    /// wide, half a tile from a centre is a pixel centre): within [`Self::BOUNDARY_TOL`] tile
    /// of a boundary it counts as on it (half away from the anchor, as `tile_of` rounds an
    /// exact half). `tile_of` decided such pixels by the last bits of their coordinates, so
    /// ba-star-extended asking which pixels BA* will sweep took another path when the map was
    /// moved (`mit_building_31` at +1000 m: 2 % longer).
    pub fn tile_of_near_boundary(&self, p: Point) -> Tile {
        let at = |u: f64| -> i32 {
            let a = u.abs();
            let f = a.floor();
            let k = if a - f >= 0.5 - Self::BOUNDARY_TOL {
                f + 1.0
            } else {
                f
            };
            k.copysign(u)
                .clamp(f64::from(i32::MIN), f64::from(i32::MAX)) as i32
        };
        (
            at((p.x - self.anchor.x) / self.side),
            at((p.y - self.anchor.y) / self.side),
        )
    }

    /// Distance from a tile boundary, in tiles, within which
    /// [`Self::tile_of_near_boundary`] takes a point as on it: far above the rounding of world
    /// coordinates (about 1e-9 tile at 1e6 m) and far below a pixel of any real map.
    pub const BOUNDARY_TOL: f64 = 1e-6;

    /// The tile containing world point `p` (nearest centre; boundaries round half away).
    #[inline]
    pub fn tile_of(&self, p: Point) -> Tile {
        (
            round_i32((p.x - self.anchor.x) / self.side),
            round_i32((p.y - self.anchor.y) / self.side),
        )
    }

    /// Inclusive tile index bounds `(i0, i1, j0, j1)` whose centres can lie on the map of `world`.
    pub fn bounds_for(&self, world: &World) -> (i32, i32, i32, i32) {
        self.bounds_for_frame(world.frame())
    }

    /// Inclusive tile index bounds `(i0, i1, j0, j1)` whose centres can lie on a map of frame
    /// `f` (what an online planner may know: the frame, not the contents).
    pub fn bounds_for_frame(&self, f: &crate::grid::MapFrame) -> (i32, i32, i32, i32) {
        let (lo, hi) = f.world_bounds();
        let a = self.tile_of(lo);
        let b = self.tile_of(hi);
        (a.0 - 1, b.0 + 1, a.1 - 1, b.1 + 1)
    }
}

/// A dense boolean set over a rectangular range of tiles (deterministic, no hashing).
#[derive(Clone, Debug)]
pub struct TileSet {
    i0: i32,
    j0: i32,
    w: usize,
    h: usize,
    bits: FixedBitSet,
}

impl TileSet {
    /// An empty set over tiles `i0..=i1`, `j0..=j1`.
    pub fn new(i0: i32, i1: i32, j0: i32, j1: i32) -> Self {
        let w = usize::try_from(i64::from(i1) - i64::from(i0) + 1).unwrap_or(0);
        let h = usize::try_from(i64::from(j1) - i64::from(j0) + 1).unwrap_or(0);
        Self {
            i0,
            j0,
            w,
            h,
            bits: FixedBitSet::with_capacity(w * h),
        }
    }

    #[inline]
    fn idx(&self, t: Tile) -> Option<usize> {
        // In 64 bits: the tile of a pose far off the map saturates at `i32::MAX`, and the
        // difference overflowed 32 bits (a hand-made trace's metrics panicked).
        let di = i64::from(t.0) - i64::from(self.i0);
        let dj = i64::from(t.1) - i64::from(self.j0);
        if di < 0 || dj < 0 || di as usize >= self.w || dj as usize >= self.h {
            None
        } else {
            Some(dj as usize * self.w + di as usize)
        }
    }

    /// Membership (tiles outside the range are not members).
    #[inline]
    pub fn contains(&self, t: Tile) -> bool {
        self.idx(t).is_some_and(|i| self.bits.contains(i))
    }

    /// Inserts; returns `false` if `t` is outside the range.
    #[inline]
    pub fn insert(&mut self, t: Tile) -> bool {
        match self.idx(t) {
            Some(i) => {
                self.bits.insert(i);
                true
            }
            None => false,
        }
    }

    /// Removes `t` (no-op outside the range).
    #[inline]
    pub fn remove(&mut self, t: Tile) {
        if let Some(i) = self.idx(t) {
            self.bits.set(i, false);
        }
    }

    /// Inclusive index bounds `(i0, i1, j0, j1)` of the range.
    pub fn bounds(&self) -> (i32, i32, i32, i32) {
        (
            self.i0,
            self.i0 + self.w as i32 - 1,
            self.j0,
            self.j0 + self.h as i32 - 1,
        )
    }

    /// Number of members.
    pub fn len(&self) -> usize {
        self.bits.count_ones(..)
    }

    /// `true` when empty.
    pub fn is_empty(&self) -> bool {
        self.bits.is_clear()
    }

    /// Members in (j, i) row-major order.
    pub fn iter(&self) -> impl Iterator<Item = Tile> + '_ {
        self.bits
            .ones()
            .map(|k| (self.i0 + (k % self.w) as i32, self.j0 + (k / self.w) as i32))
    }
}

/// Ground truth for `coverage_rate`: the tiles reachable from the start tile by collision-free
/// 4-neighbour moves (a tile is free when the robot can stand at its centre; a move when the
/// straight segment between the centres is free).
pub fn reachable_tiles(world: &World, grid: &TileGrid) -> TileSet {
    let (i0, i1, j0, j1) = grid.bounds_for(world);
    let mut set = TileSet::new(i0, i1, j0, j1);
    let mut standable = TileSet::new(i0, i1, j0, j1);
    let mut rejected = TileSet::new(i0, i1, j0, j1);
    let start = grid.tile_of(world.start().position());
    if world.disk_collides(grid.center(start)) {
        return set;
    }
    set.insert(start);
    let mut q = VecDeque::from([start]);
    while let Some(t) = q.pop_front() {
        for (di, dj) in [(1, 0), (0, 1), (-1, 0), (0, -1)] {
            let n = (t.0 + di, t.1 + dj);
            if set.contains(n) || rejected.contains(n) {
                continue;
            }
            if n.0 < i0 || n.0 > i1 || n.1 < j0 || n.1 > j1 {
                continue;
            }
            if !standable.contains(n) {
                if world.disk_collides(grid.center(n)) {
                    rejected.insert(n);
                    continue;
                }
                standable.insert(n);
            }
            if world.segment_free(grid.center(t), grid.center(n)) {
                set.insert(n);
                q.push_back(n);
            }
        }
    }
    set
}

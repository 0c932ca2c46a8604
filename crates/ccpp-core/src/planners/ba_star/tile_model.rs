//! The discovered tiling `M̂`: per-tile states and cached move judgements, dense over the
//! frame's tile extent, and the backtracking graph read off it.

use crate::bits::IndexSet;
use crate::collide::contact_radius_px;
use crate::grid::MapFrame;
use crate::planner::KnownMap;
use crate::tiles::{Tile, TileGrid, N8};

use super::judge::{judge_motion, Judgement};
use super::search::{graph_edge, TileGraph};

// Tile state bits.
pub(super) const ST_STAND: u8 = 0b0011; // Judgement of standing at the centre
pub(super) const ST_COVERED: u8 = 0b0100;
/// The tile's contact disk is in the [`DiskCache`](super::sensing::DiskCache).
pub(super) const ST_DISK: u8 = 0b1000;
/// A smoothed backtracking move from the tile was stopped by the bumper: moves from it are
/// not smoothed any more ([`Mind::bumped_leg`](super::sensing::Mind::bumped_leg)).
pub(super) const ST_ROUGH: u8 = 0b1_0000;

/// The discovered tiling `M̂` with cached judgements, dense over the frame's tile extent.
#[derive(Clone, Debug)]
pub(super) struct TileModel {
    pub(super) grid: TileGrid,
    pub(super) i0: i32,
    pub(super) j0: i32,
    pub(super) w: usize,
    pub(super) h: usize,
    /// Per tile: standability (2 bits), covered.
    pub(super) state: Vec<u8>,
    /// Per tile: judgements (2 bits each) of the moves towards s1..s4 (E, NE, N, NW); the
    /// moves towards s5..s8 are stored at the neighbour.
    pub(super) moves: Vec<u8>,
    /// The backtracking list `L` (row-major tile indices), listed in `O(|L|)`.
    pub(super) l: IndexSet,
    /// Add [`lane_end_score`](super::lane_end_score) to `mu`.
    pub(super) lane_end_corners: bool,
}

impl TileModel {
    pub(super) fn new(grid: TileGrid, frame: &MapFrame) -> Self {
        let (lo, hi) = frame.world_bounds();
        let a = grid.tile_of(lo);
        let b = grid.tile_of(hi);
        let w = (b.0 - a.0 + 1).max(1) as usize;
        let h = (b.1 - a.1 + 1).max(1) as usize;
        Self {
            grid,
            i0: a.0,
            j0: a.1,
            w,
            h,
            state: vec![0; w * h],
            moves: vec![0; w * h],
            l: IndexSet::new(w * h),
            lane_end_corners: true,
        }
    }

    /// Tiles whose disk reaches outside the image are obstacles from the frame alone (the
    /// outside of the map is occupied): judge them once, before any scan.
    pub(super) fn judge_frame_edges(&mut self, known: &KnownMap, r: f64) {
        let by_lines = known.frame().origin.theta == 0.0;
        self.judge_frame_edges_with(known, r, by_lines);
    }

    /// [`TileModel::judge_frame_edges`]; `by_lines` (only for an unrotated frame) takes the
    /// test a column and a row at a time instead of tile by tile (tests compare the two).
    pub(super) fn judge_frame_edges_with(&mut self, known: &KnownMap, r: f64, by_lines: bool) {
        let frame = *known.frame();
        let rc = contact_radius_px(r / frame.resolution) + 1.0;
        let (w, h) = (frame.width as f64, frame.height as f64);
        let inner_x = |x: f64| x - rc > 0.0 && x + rc < w;
        let inner_y = |y: f64| y - rc > 0.0 && y + rc < h;
        let grid = self.grid;
        let state = &mut self.state;
        let mut judge = |k: usize, t: Tile| {
            let p = grid.center(t);
            let j = judge_motion(known, p, p, r);
            state[k] = (state[k] & !ST_STAND) | j as u8;
        };
        if by_lines {
            // Unrotated: a centre's grid x depends on its tile column alone and its y on its
            // row alone (as `Mind::gx`, `Mind::gy`), so the test splits into one per column
            // and one per row, and only the tiles failing one are visited.
            let (i0, j0, w) = (self.i0, self.j0, self.w);
            let cols: Vec<bool> = (0..w)
                .map(|di| inner_x(frame.world_to_grid(grid.center((i0 + di as i32, j0))).x))
                .collect();
            for dj in 0..self.h {
                let j = j0 + dj as i32;
                let row_inner = inner_y(frame.world_to_grid(grid.center((i0, j))).y);
                for (di, &col_inner) in cols.iter().enumerate() {
                    if !(row_inner && col_inner) {
                        judge(dj * w + di, (i0 + di as i32, j));
                    }
                }
            }
            return;
        }
        let (i0, j0, w) = (self.i0, self.j0, self.w);
        for k in 0..w * self.h {
            let t = (i0 + (k % w) as i32, j0 + (k / w) as i32);
            let g = frame.world_to_grid(grid.center(t));
            if !(inner_x(g.x) && inner_y(g.y)) {
                judge(k, t);
            }
        }
    }

    pub(super) fn bounds(&self) -> (i32, i32, i32, i32) {
        (
            self.i0,
            self.i0 + self.w as i32 - 1,
            self.j0,
            self.j0 + self.h as i32 - 1,
        )
    }

    #[inline]
    pub(super) fn idx(&self, t: Tile) -> Option<usize> {
        let di = t.0 - self.i0;
        let dj = t.1 - self.j0;
        if di < 0 || dj < 0 || di as usize >= self.w || dj as usize >= self.h {
            None
        } else {
            Some(dj as usize * self.w + di as usize)
        }
    }

    #[inline]
    pub(super) fn covered(&self, t: Tile) -> bool {
        self.idx(t).is_some_and(|k| self.state[k] & ST_COVERED != 0)
    }

    #[inline]
    pub(super) fn stand(&self, t: Tile) -> Judgement {
        match self.idx(t) {
            Some(k) => Judgement::from_bits(self.state[k] & ST_STAND),
            None => Judgement::Blocked,
        }
    }

    /// Was a smoothed move from `t` stopped by the bumper ([`ST_ROUGH`])?
    #[inline]
    pub(super) fn rough(&self, t: Tile) -> bool {
        self.idx(t).is_some_and(|k| self.state[k] & ST_ROUGH != 0)
    }

    #[inline]
    pub(super) fn in_l(&self, t: Tile) -> bool {
        self.idx(t).is_some_and(|k| self.l.contains(k))
    }

    /// `(owner tile, slot 0..4)` of the move `t -> t + N8[k]`.
    #[inline]
    pub(super) fn move_slot(t: Tile, k: usize) -> (Tile, usize) {
        if k < 4 {
            (t, k)
        } else {
            ((t.0 + N8[k].0, t.1 + N8[k].1), k - 4)
        }
    }

    #[inline]
    pub(super) fn cached_move(&self, t: Tile, k: usize) -> Judgement {
        let (o, s) = Self::move_slot(t, k);
        match self.idx(o) {
            Some(i) => Judgement::from_bits(self.moves[i] >> (2 * s)),
            None => Judgement::Blocked,
        }
    }

    #[inline]
    pub(super) fn set_move(&mut self, t: Tile, k: usize, j: Judgement) {
        let (o, s) = Self::move_slot(t, k);
        if let Some(i) = self.idx(o) {
            self.moves[i] = (self.moves[i] & !(3 << (2 * s))) | ((j as u8) << (2 * s));
        }
    }

    /// Is `M̂(t)` blocked (covered or obstacle)? Out-of-frame tiles are obstacles.
    #[inline]
    pub(super) fn blocked(&self, t: Tile) -> bool {
        match self.idx(t) {
            Some(k) => {
                self.state[k] & ST_COVERED != 0
                    || Judgement::from_bits(self.state[k] & ST_STAND) == Judgement::Blocked
            }
            None => true,
        }
    }

    /// Free-uncovered 4-neighbour `k` of `s`: not covered and the move `s -> it` judged free.
    #[inline]
    pub(super) fn free_uncovered(&self, s: Tile, k: usize) -> bool {
        let n = (s.0 + N8[k].0, s.1 + N8[k].1);
        !self.covered(n) && self.cached_move(s, k) == Judgement::Free
    }
}

impl TileGraph for TileModel {
    fn bounds(&self) -> (i32, i32, i32, i32) {
        TileModel::bounds(self)
    }
    fn covered(&self, t: Tile) -> bool {
        TileModel::covered(self, t)
    }
    fn move_free(&self, t: Tile, k: usize) -> bool {
        self.cached_move(t, k) == Judgement::Free
    }
    /// [`graph_edge`] for all eight neighbours at once, read off the dense arrays (interior
    /// tiles; tiles on the border of the range take the generic path).
    fn edge_mask(&self, t: Tile) -> u8 {
        let di = t.0 - self.i0;
        let dj = t.1 - self.j0;
        if di < 1 || dj < 1 || di as usize + 1 >= self.w || dj as usize + 1 >= self.h {
            return (0..8).fold(0, |m, k| {
                if graph_edge(self, t, k) {
                    m | 1 << k
                } else {
                    m
                }
            });
        }
        let w = self.w;
        let k = dj as usize * w + di as usize;
        // Row-major index of each neighbour s1..s8 (j grows with the index).
        let nb = [
            k + 1,
            k + w + 1,
            k + w,
            k + w - 1,
            k - 1,
            k - w - 1,
            k - w,
            k - w + 1,
        ];
        let cov = |i: usize| self.state[i] & ST_COVERED != 0;
        let mut covered = 0u8;
        for (n, &i) in nb.iter().enumerate() {
            if cov(i) {
                covered |= 1 << n;
            }
        }
        // Move judgements: s1..s4 at `k` (slots 0..3); s5..s8 at the neighbour, slot n - 4.
        let free =
            |i: usize, slot: usize| (self.moves[i] >> (2 * slot)) & 3 == Judgement::Free as u8;
        let mut mask = 0u8;
        for n in 0..8 {
            if covered & (1 << n) == 0 {
                continue;
            }
            // A diagonal needs both orthogonal tiles beside it covered (no corner cutting).
            if n % 2 == 1 && (covered & (1 << (n - 1)) == 0 || covered & (1 << ((n + 1) % 8)) == 0)
            {
                continue;
            }
            let ok = if n < 4 {
                free(k, n)
            } else {
                free(nb[n], n - 4)
            };
            if ok {
                mask |= 1 << n;
            }
        }
        mask
    }
}

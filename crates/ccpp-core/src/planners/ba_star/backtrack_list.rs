//! The backtracking list `L`: the corner score `mu` (the paper's pairs and the lane-end
//! extension) and its incremental maintenance on the tile model ([`Block3`]).

use crate::tiles::{Tile, N8};

use super::judge::Judgement;
use super::tile_model::{TileModel, ST_COVERED, ST_STAND};

/// The pairs `(a, b)` of neighbour indices (0-based: `s1` = 0 ... `s8` = 7) summed by `mu`:
/// `(s1,s8), (s1,s2), (s5,s6), (s5,s4), (s7,s6), (s7,s8)`.
pub const MU_PAIRS: [(usize, usize); 6] = [(0, 7), (0, 1), (4, 5), (4, 3), (6, 5), (6, 7)];

/// The pairs `(a, b)` of the lane-end extension counted against an *obstacle* `b`
/// ([`lane_end_score`]): `(s1,s3), (s1,s7), (s5,s3), (s5,s7)`.
pub const LANE_END_PAIRS: [(usize, usize); 4] = [(0, 2), (0, 6), (4, 2), (4, 6)];

/// The pairs `(a, b)` of the lane-end extension counted against a *blocked* `b`
/// ([`lane_end_score`]): `(s7,s1), (s7,s5)`.
pub const START_PAIRS: [(usize, usize); 2] = [(6, 0), (6, 4)];

/// The pairs `(a, b)` of the pixel-level lane-end extension (see `TileModel::open_lane_ends`):
/// the free side `a` (E, W or S) and the lane direction `b` along which it must continue:
/// `(s1,s3), (s1,s7), (s5,s3), (s5,s7), (s7,s1), (s7,s5)`.
pub const SIDE_END_PAIRS: [(usize, usize); 6] = [(0, 2), (0, 6), (4, 2), (4, 6), (6, 0), (6, 4)];

/// The lane-end extension of `mu` (a deviation from the paper, on by default, see
/// [`BaStarOptions::lane_end_corners`]): the pairs of [`LANE_END_PAIRS`] with
/// `free[a] && obstacle[b]` (a side neighbour is free-uncovered while the lane of `s` ends at an
/// obstacle) plus the pairs of [`START_PAIRS`] with `free[a] && blocked[b]` (the south neighbour
/// is free-uncovered while `s` is flanked by a blocked tile).
///
/// Why: the paper's six pairs need a blocked *diagonal*. Property tests found two frontiers
/// without one, where coverage stalls with `L` empty (both kept as regression tests): (1) a lane
/// that ends at obstacles next to an uncovered lane running past both of its ends; (2) the start
/// tile, whose south neighbour BM leaves behind when it goes north first (every other covered
/// tile with a free south neighbour was entered sideways from a tile whose south was blocked, so
/// the paper's `(s7,s6)` / `(s7,s8)` see it). With the extension, every covered tile with a
/// free-uncovered neighbour is in `L` or shares a lane with one that is — on tile-aligned
/// obstacles. Pixel clutter can make a standable neighbour unenterable; the planner then also
/// counts the [`SIDE_END_PAIRS`], judged by moves (a lane that ends at a standable tile it cannot
/// enter was missed, see the regression map `ba_star_pixel_clutter`).
///
/// [`BaStarOptions::lane_end_corners`]: super::BaStarOptions::lane_end_corners
pub fn lane_end_score(free: [bool; 8], obstacle: [bool; 8], blocked: [bool; 8]) -> u32 {
    let a = LANE_END_PAIRS
        .iter()
        .filter(|&&(a, b)| free[a] && obstacle[b])
        .count();
    let b = START_PAIRS
        .iter()
        .filter(|&&(a, b)| free[a] && blocked[b])
        .count();
    (a + b) as u32
}

/// The corner score `mu(s)`: the number of pairs of [`MU_PAIRS`] with `free[a] && blocked[b]`.
/// `free[k]`: neighbour `s(k+1)` is free-uncovered (only read for the 4-neighbours E, W, S);
/// `blocked[k]`: neighbour `s(k+1)` is covered or an obstacle.
pub fn corner_score(free: [bool; 8], blocked: [bool; 8]) -> u32 {
    MU_PAIRS
        .iter()
        .filter(|&&(a, b)| free[a] && blocked[b])
        .count() as u32
}

impl TileModel {
    /// `mu(s)` from the cached judgements (plus the lane-end extension when enabled).
    pub(super) fn mu(&self, s: Tile) -> u32 {
        let mut free = [false; 8];
        let mut blocked = [false; 8];
        for k in [0, 4, 6] {
            free[k] = self.free_uncovered(s, k);
        }
        if !(free[0] || free[4] || free[6]) {
            return 0;
        }
        for (k, &(di, dj)) in N8.iter().enumerate() {
            blocked[k] = self.blocked((s.0 + di, s.1 + dj));
        }
        let mut mu = corner_score(free, blocked);
        if self.lane_end_corners {
            let mut obstacle = [false; 8];
            for k in [2, 6] {
                obstacle[k] = self.stand((s.0 + N8[k].0, s.1 + N8[k].1)) == Judgement::Blocked;
            }
            mu += lane_end_score(free, obstacle, blocked);
            mu += self.open_lane_ends(s, free);
        }
        mu
    }

    /// Does the lane of the covered tile `s` carry its free side `a` on to the neighbour
    /// `n = s + N8[b]`: `n` covered, the move `s -> n` free and `n`'s side `a` free-uncovered?
    #[inline]
    fn side_continues(&self, s: Tile, b: usize, a: usize) -> bool {
        let n = (s.0 + N8[b].0, s.1 + N8[b].1);
        self.covered(n) && self.cached_move(s, b) == Judgement::Free && self.free_uncovered(n, a)
    }

    /// The pixel-level part of the lane-end extension: the pairs `(a, b)` of [`SIDE_END_PAIRS`]
    /// with `a` free-uncovered, `b` not free-uncovered, and the lane not carrying the free side
    /// `a` on to `b` ([`TileModel::side_continues`]).
    ///
    /// Why: [`corner_score`] and [`lane_end_score`] judge the tiles `b` and the diagonals by
    /// *standability* alone. On tile-aligned obstacles a standable neighbour can always be
    /// entered by the straight move, so "not standable" is the same as "not enterable"; pixel
    /// clutter breaks that. A single pixel beside the segment between two standable tile
    /// centres blocks the move while both disks are free, so a lane could end at a standable
    /// but unenterable tile (the regression map `ba_star_pixel_clutter`: the lane end at
    /// `(-2, -1)` with its whole west side uncovered was never put in `L`, BA* stopped at 2/3 of
    /// the reachable tiles), or a standable diagonal could be unenterable from the lane's next
    /// tile. Judged by moves instead, the rule is complete: every covered tile with a
    /// free-uncovered neighbour `a` in E, W, S leads, walking along the lane (N for a side E/W,
    /// E for S) while the free side continues, to a tile where it stops; that tile has a pair
    /// here unless its own next neighbour is free-uncovered, which can only be E for side S
    /// (BM never leaves a covered tile with a free-uncovered north: it goes there first), and
    /// then the E side starts a walk of the first kind. On tile-aligned maps every such pair is
    /// also a pair of [`corner_score`] or [`lane_end_score`], so `L` is unchanged there.
    fn open_lane_ends(&self, s: Tile, free: [bool; 8]) -> u32 {
        SIDE_END_PAIRS
            .iter()
            .filter(|&&(a, b)| {
                free[a] && !self.free_uncovered(s, b) && !self.side_continues(s, b, a)
            })
            .count() as u32
    }

    /// The 3 x 3 block of tile states and move bytes centred on `s` (see [`Block3`]).
    #[inline]
    fn block3(&self, s: Tile) -> Block3 {
        let di = s.0 - self.i0;
        let dj = s.1 - self.j0;
        let mut b = Block3 {
            state: [BLOCK3_OUTSIDE_STATE; 25],
            moves: [BLOCK3_OUTSIDE_MOVES; 25],
            c: 12,
        };
        if di >= 1 && dj >= 1 && di as usize + 1 < self.w && dj as usize + 1 < self.h {
            let sw = (dj as usize - 1) * self.w + di as usize - 1;
            for r in 0..3 {
                let k = sw + r * self.w;
                b.state[6 + 5 * r..9 + 5 * r].copy_from_slice(&self.state[k..k + 3]);
                b.moves[6 + 5 * r..9 + 5 * r].copy_from_slice(&self.moves[k..k + 3]);
            }
        } else {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    if let Some(k) = self.idx((s.0 + dx, s.1 + dy)) {
                        let at = b.at((dx, dy));
                        b.state[at] = self.state[k];
                        b.moves[at] = self.moves[k];
                    }
                }
            }
        }
        b
    }

    /// Recomputes the L membership of `t` (`mu` read off the [`Block3`] around `t`: the same
    /// value as [`TileModel::mu`], which tests check through [`BaStar::backtrack_list_full`]).
    ///
    /// [`BaStar::backtrack_list_full`]: super::BaStar::backtrack_list_full
    fn update_l(&mut self, t: Tile) {
        let Some(k) = self.idx(t) else { return };
        if self.state[k] & ST_COVERED != 0 && self.block3(t).in_l(self.lane_end_corners) {
            self.l.insert(k);
        } else {
            self.l.remove(k);
        }
    }

    /// [`TileModel::update_l`] of `t` and its eight neighbours. Away from the border of the
    /// range the 5 x 5 block of states and moves they read is copied once, and each tile's
    /// [`Block3`] taken from the copy.
    pub(super) fn update_l_around(&mut self, t: Tile) {
        let di = t.0 - self.i0;
        let dj = t.1 - self.j0;
        if !(di >= 2 && dj >= 2 && di as usize + 2 < self.w && dj as usize + 2 < self.h) {
            self.update_l(t);
            for (di, dj) in N8 {
                self.update_l((t.0 + di, t.1 + dj));
            }
            return;
        }
        let w = self.w;
        let k = dj as usize * w + di as usize;
        let mut b = Block3 {
            state: [0; 25],
            moves: [0; 25],
            c: 12,
        };
        for r in 0..5 {
            let base = k - 2 * w - 2 + r * w;
            b.state[5 * r..5 * r + 5].copy_from_slice(&self.state[base..base + 5]);
            b.moves[5 * r..5 * r + 5].copy_from_slice(&self.moves[base..base + 5]);
        }
        for (dx, dy) in std::iter::once((0, 0)).chain(N8) {
            // The tile's index in the copy and in the dense arrays.
            let c = ((dy + 2) * 5 + dx + 2) as usize;
            let kc = (k as isize + dy as isize * w as isize + dx as isize) as usize;
            if b.state[c] & ST_COVERED == 0 {
                self.l.remove(kc);
                continue;
            }
            b.c = c;
            if b.in_l(self.lane_end_corners) {
                self.l.insert(kc);
            } else {
                self.l.remove(kc);
            }
        }
    }

    pub(super) fn l_tiles(&self) -> Vec<Tile> {
        let mut v = Vec::with_capacity(self.l.len());
        self.l
            .for_each(|k| v.push((self.i0 + (k % self.w) as i32, self.j0 + (k / self.w) as i32)));
        v
    }
}

/// State of a tile outside the tiling's range in a [`Block3`]: an obstacle, not covered (as
/// [`TileModel::stand`] and [`TileModel::covered`] read it).
const BLOCK3_OUTSIDE_STATE: u8 = Judgement::Blocked as u8;
/// Move byte of a tile outside the range in a [`Block3`]: all four moves blocked (as
/// [`TileModel::cached_move`] reads it).
const BLOCK3_OUTSIDE_MOVES: u8 = 0b1010_1010;

/// A copy of the tile states and move bytes of a 5 x 5 block of tiles (index
/// `(dj + 2) * 5 + di + 2` for the offset `(di, dj)` from the middle tile), read around the
/// tile at index `c` (whose 3 x 3 tiles must lie in the block): everything `mu` of that tile
/// reads, so `mu` runs on a small local copy instead of bounds-checked lookups into the dense
/// arrays, and the nine tiles around a newly covered one share one copy.
pub(super) struct Block3 {
    pub(super) state: [u8; 25],
    pub(super) moves: [u8; 25],
    pub(super) c: usize,
}

impl Block3 {
    #[inline]
    fn at(&self, d: Tile) -> usize {
        (self.c as isize + (d.1 * 5 + d.0) as isize) as usize
    }

    #[inline]
    fn covered(&self, d: Tile) -> bool {
        self.state[self.at(d)] & ST_COVERED != 0
    }

    #[inline]
    fn stand_blocked(&self, d: Tile) -> bool {
        Judgement::from_bits(self.state[self.at(d)] & ST_STAND) == Judgement::Blocked
    }

    /// [`TileModel::cached_move`] of the move `d -> d + N8[k]` is free (its owner tile must lie
    /// in the block: true for every move `mu` reads).
    #[inline]
    fn move_free(&self, d: Tile, k: usize) -> bool {
        let (o, slot) = TileModel::move_slot(d, k);
        Judgement::from_bits(self.moves[self.at(o)] >> (2 * slot)) == Judgement::Free
    }

    /// [`TileModel::free_uncovered`] for the neighbour `k` of the block tile `d`.
    #[inline]
    fn free_uncovered(&self, d: Tile, k: usize) -> bool {
        !self.covered((d.0 + N8[k].0, d.1 + N8[k].1)) && self.move_free(d, k)
    }

    /// `mu >= 1` for the centre tile ([`TileModel::mu`]): the same pairs, stopping at the
    /// first that counts.
    #[inline]
    pub(super) fn in_l(&self, lane_end_corners: bool) -> bool {
        let s = (0, 0);
        let f0 = self.free_uncovered(s, 0);
        let f4 = self.free_uncovered(s, 4);
        let f6 = self.free_uncovered(s, 6);
        if !(f0 || f4 || f6) {
            return false;
        }
        let blocked = |k: usize| self.covered(N8[k]) || self.stand_blocked(N8[k]);
        // corner_score: (s1,s8), (s1,s2), (s5,s6), (s5,s4), (s7,s6), (s7,s8).
        if (f0 && (blocked(7) || blocked(1)))
            || (f4 && (blocked(5) || blocked(3)))
            || (f6 && (blocked(5) || blocked(7)))
        {
            return true;
        }
        if !lane_end_corners {
            return false;
        }
        // lane_end_score: (s1,s3), (s1,s7), (s5,s3), (s5,s7) against obstacles; (s7,s1),
        // (s7,s5) against blocked tiles.
        if ((f0 || f4) && (self.stand_blocked(N8[2]) || self.stand_blocked(N8[6])))
            || (f6 && (blocked(0) || blocked(4)))
        {
            return true;
        }
        let free = [f0, false, false, false, f4, false, f6, false];
        SIDE_END_PAIRS.iter().any(|&(a, b)| {
            free[a] && !self.free_uncovered(s, b) && {
                // Not [`TileModel::side_continues`].
                let n = N8[b];
                !(self.covered(n) && self.move_free(s, b) && self.free_uncovered(n, a))
            }
        })
    }

    /// [`TileModel::mu`] of the centre tile.
    #[cfg(test)]
    pub(super) fn mu(&self, lane_end_corners: bool) -> u32 {
        let s = (0, 0);
        let mut free = [false; 8];
        for k in [0, 4, 6] {
            free[k] = self.free_uncovered(s, k);
        }
        if !(free[0] || free[4] || free[6]) {
            return 0;
        }
        let mut blocked = [false; 8];
        for (k, &d) in N8.iter().enumerate() {
            blocked[k] = self.covered(d) || self.stand_blocked(d);
        }
        let mut mu = corner_score(free, blocked);
        if lane_end_corners {
            let mut obstacle = [false; 8];
            for k in [2, 6] {
                obstacle[k] = self.stand_blocked(N8[k]);
            }
            mu += lane_end_score(free, obstacle, blocked);
            mu += SIDE_END_PAIRS
                .iter()
                .filter(|&&(a, b)| {
                    free[a] && !self.free_uncovered(s, b) && {
                        // Not [`TileModel::side_continues`].
                        let n = N8[b];
                        !(self.covered(n) && self.move_free(s, b) && self.free_uncovered(n, a))
                    }
                })
                .count() as u32;
        }
        mu
    }
}

//! The position graph: pixel coordinates, where the robot fits (`S0`, `S1`, memoised), which
//! 8-neighbour moves are known free (memoised both ways), and the contour of `S0`.

use super::{Extension, Px};
use crate::geometry::Point;
use crate::planner::{DiskState, KnownMap};
use crate::planners::ba_star::{judge_motion, motion_known_free, Judgement};

/// Index of the known-free bits in a pixel's move memo (`Extension::edges`).
pub(super) const FREE: usize = 0;
/// Index of the known-blocked bits in a pixel's move memo (`Extension::edges`).
pub(super) const BLOCKED: usize = 1;

/// The 8 neighbour offsets `(dcol, drow)`: E, NE, N, NW, W, SW, S, SE (rows grow downwards).
pub(super) const NB: [(i64, i64); 8] = [
    (1, 0),
    (1, -1),
    (0, -1),
    (-1, -1),
    (-1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

impl Extension {
    pub(super) fn idx(&self, p: Px) -> Option<usize> {
        self.frame
            .checked(p.0, p.1)
            .map(|(c, r)| self.frame.index(c, r))
    }

    pub(super) fn center(&self, p: Px) -> Point {
        Point::new(
            p.0 as f64 + 0.5,
            (self.frame.height as i64 - p.1) as f64 - 0.5,
        )
    }

    pub(super) fn px_of(&self, i: usize) -> Px {
        // Searches turn every settled index back into a pixel: a 32-bit division where the
        // index fits (any image up to 4 G pixels) is several times cheaper than a 64-bit one.
        if let (Ok(i), Ok(w)) = (u32::try_from(i), u32::try_from(self.frame.width)) {
            return (i64::from(i % w), i64::from(i / w));
        }
        let (c, r) = self.frame.col_row(i);
        (c as i64, r as i64)
    }

    pub(super) fn world(&self, g: Point) -> Point {
        self.frame.grid_to_world(g)
    }

    /// Does the robot fit at the centre of pixel `p` (known map, clearance 0)? `None` while an
    /// unseen pixel decides.
    pub(super) fn in_s0(&mut self, known: &KnownMap, p: Px) -> Option<bool> {
        let i = self.idx(p)?;
        match self.s0[i] {
            1 => return Some(true),
            2 => return Some(false),
            _ => {}
        }
        // The `S1` disk holds the `S0` disk: where it is free (most positions, away from
        // walls) both are decided by one look, and `S1` is memoised as `in_s1` would.
        if self.s1[i] == 0 {
            match known.disk_state_px(p.0, p.1, &self.s1_disk) {
                DiskState::Free => {
                    self.s1[i] = 1;
                    self.s0[i] = 1;
                    return Some(true);
                }
                DiskState::Blocked => self.s1[i] = 2,
                DiskState::Unseen => {}
            }
        }
        match known.disk_state_px(p.0, p.1, &self.s0_disk) {
            DiskState::Free => {
                self.s0[i] = 1;
                Some(true)
            }
            DiskState::Blocked => {
                self.s0[i] = 2;
                Some(false)
            }
            DiskState::Unseen => None,
        }
    }

    /// Does pixel `p` lie in `S1` (see the field)? Unseen counts as no.
    fn in_s1(&mut self, known: &KnownMap, p: Px) -> bool {
        let Some(i) = self.idx(p) else { return false };
        match self.s1[i] {
            1 => return true,
            2 => return false,
            _ => {}
        }
        match known.disk_state_px(p.0, p.1, &self.s1_disk) {
            DiskState::Free => {
                self.s1[i] = 1;
                true
            }
            DiskState::Blocked => {
                self.s1[i] = 2;
                false
            }
            DiskState::Unseen => false,
        }
    }

    /// Is the straight move between grid points `a` and `b` known free?
    pub(super) fn seg_free(&self, known: &KnownMap, a: Point, b: Point) -> bool {
        self.seg_free_with(known, a, b, &mut None)
    }

    /// [`Self::seg_free`], first asking the pixel in `witness` (one that made an earlier move
    /// not free; the known map unchanged since), which the answer "no" then keeps.
    pub(super) fn seg_free_with(
        &self,
        known: &KnownMap,
        a: Point,
        b: Point,
        witness: &mut Option<(i64, i64)>,
    ) -> bool {
        motion_known_free(known, self.world(a), self.world(b), self.r, witness)
    }

    /// Is position `p` usable and the move from `p` to its neighbour `NB[k]` known free?
    pub(super) fn edge(&mut self, known: &KnownMap, p: Px, k: usize) -> bool {
        let q = (p.0 + NB[k].0, p.1 + NB[k].1);
        let (Some(i), Some(j)) = (self.idx(p), self.idx(q)) else {
            return false;
        };
        if self.edges[i][FREE] & (1 << k) != 0 {
            return true;
        }
        if self.edges[i][BLOCKED] & (1 << k) != 0 {
            return false;
        }
        match self.in_s0(known, q) {
            Some(true) => {}
            Some(false) => {
                // The robot never fits at `q` (a seen obstacle stays one): the move stays
                // blocked.
                self.edges[i][BLOCKED] |= 1 << k;
                return false;
            }
            None => return false,
        }
        // Between two `S1` positions a move is free; else check it on the known map (once free
        // or blocked, it stays so).
        let judged = if self.in_s1(known, p) && self.in_s1(known, q) {
            Judgement::Free
        } else {
            judge_motion(
                known,
                self.world(self.center(p)),
                self.world(self.center(q)),
                self.r,
            )
        };
        match judged {
            Judgement::Free => {
                self.edges[i][FREE] |= 1 << k;
                self.edges[j][FREE] |= 1 << ((k + 4) % 8);
                true
            }
            Judgement::Blocked => {
                self.edges[i][BLOCKED] |= 1 << k;
                self.edges[j][BLOCKED] |= 1 << ((k + 4) % 8);
                false
            }
            Judgement::Undetermined => false,
        }
    }

    /// Is `p` on the contour of `S0` (a neighbour known not to fit)?
    pub(super) fn on_contour(&mut self, known: &KnownMap, p: Px) -> bool {
        (0..8).any(|k| {
            let q = (p.0 + NB[k].0, p.1 + NB[k].1);
            self.idx(q).is_none() || self.in_s0(known, q) == Some(false)
        })
    }
}

//! Memos filled in bulk when the final clean-up begins: where the robot fits (`S0`, `S1`),
//! which moves between `S1` positions are free, which moves lead where the robot does not
//! fit, and which positions gain nothing (no target within the tool radius).
//!
//! The final clean-up's searches sweep most of the known floor, and each position they reach
//! for the first time used to be judged alone (a disk of row runs on the known map per memo).
//! Here the same answers come from one pass over the image per question: a disk lies inside a
//! pixel set exactly when, in every row of the disk, the pixel set's run through the disk's
//! column reaches the row's half-width on both sides (a morphological erosion by row runs):
//!
//! ```text
//!   row runs of the set (min of the run to the left and to the right, per pixel):
//!     . # # # # # . .        0 1 2 3 3 2 1 0 0      disk rows with half-widths 1, 2, 1:
//!     . # # # # # # .   ->   0 1 2 3 3 3 2 1 0      the centre pixel fits where the run
//!     . . # # # # . .        0 0 1 2 2 1 0 0 0      exceeds the half-width in every row
//! ```
//!
//! The project's exact distance transform ([`crate::dt::squared_edt_compact`]) answers the same
//! questions (a disk of all pixels nearer than a radius holds no feature exactly when the
//! nearest feature is as far as the nearest pixel outside the disk) and gives the same plans,
//! but for these disks of a few pixels it made `ba-star-extended` on `tuw_freihaus_eg` 1.3x
//! slower (whole process, median of 5 alternating runs) and its peak memory 48 -> 55 MiB: the
//! row runs here cost a few bit operations per pixel and disk row.
//!
//! Every memo filled here is a fact the lazy judgement would have found (the known map only
//! gains pixels, a seen obstacle stays one, targets only disappear until the memo is dropped
//! around new ones), so plans do not change; only undecided entries are written.

use fixedbitset::FixedBitSet;

use super::graph::NB;
use super::Extension;
use crate::grid::MapFrame;
use crate::planner::KnownMap;

/// Calls `out` with every pixel whose disk (row half-widths `rows`, entry `|drow|`, `-1`: the
/// row is empty) lies in the pixel set whose block `k` of bits is `word(k)`; pixels beyond the
/// image count as in the set when `outside` holds.
fn erode(
    frame: &MapFrame,
    rows: &[i64],
    outside: bool,
    word: impl Fn(usize) -> usize,
    mut out: impl FnMut(usize),
) {
    let (w, h) = (frame.width, frame.height);
    if w == 0 || h == 0 {
        return;
    }
    let bits = crate::bits::BLOCK_BITS;
    let edge: u16 = if outside { u16::MAX } else { 0 };
    // Per pixel: the shorter of the set's runs from it to the left and to the right (itself
    // included), saturated.
    let mut run = vec![0u16; w * h];
    for r in 0..h {
        let line = &mut run[r * w..(r + 1) * w];
        let base = r * w;
        let mut l = edge;
        let mut blk = usize::MAX;
        let mut cur = 0;
        for (c, v) in line.iter_mut().enumerate() {
            let i = base + c;
            if i / bits != blk {
                blk = i / bits;
                cur = word(blk);
            }
            l = if cur >> (i % bits) & 1 != 0 {
                l.saturating_add(1)
            } else {
                0
            };
            *v = l;
        }
        let mut rr = edge;
        for v in line.iter_mut().rev() {
            rr = if *v != 0 { rr.saturating_add(1) } else { 0 };
            *v = (*v).min(rr);
        }
    }
    let reach = rows.len() as i64 - 1;
    let mut acc = vec![0u8; w];
    for r in 0..h as i64 {
        acc.fill(1);
        let mut any = true;
        for dr in -reach..=reach {
            let hw = rows[dr.unsigned_abs() as usize];
            if hw < 0 {
                continue;
            }
            let rr = r + dr;
            if rr < 0 || rr >= h as i64 {
                if outside {
                    continue;
                }
                any = false;
                break;
            }
            // The run must reach `hw` pixels past the centre on both sides.
            let need = u16::try_from(hw + 1).unwrap_or(u16::MAX);
            let line = &run[rr as usize * w..(rr as usize + 1) * w];
            for (a, &v) in acc.iter_mut().zip(line) {
                *a &= u8::from(v >= need);
            }
        }
        if !any {
            continue;
        }
        let base = r as usize * w;
        for (c, &a) in acc.iter().enumerate() {
            if a != 0 {
                out(base + c);
            }
        }
    }
}

impl Extension {
    /// Fills the undecided `S0` / `S1` memos, the move memos they decide and the `no_gain`
    /// memo from the known map in one pass each (see the module docs); called once, when the
    /// final clean-up's memo of positions that gain nothing is first built (empty then).
    pub(super) fn fill_memos(&mut self, known: &KnownMap) {
        let f = self.frame;
        let n = f.len();
        let free = known.known_free().as_slice();
        let seen = known.seen().as_slice();
        // Fits: the disk in the image and known free.
        let mut fits = FixedBitSet::with_capacity(n);
        for (disk, s1) in [(&self.s1_disk, true), (&self.s0_disk, false)] {
            fits.clear();
            erode(&f, disk, false, |k| free[k], |i| fits.insert(i));
            for i in fits.ones() {
                if s1 && self.s1[i] == 0 {
                    self.s1[i] = 1;
                }
                if self.s0[i] == 0 {
                    self.s0[i] = 1;
                }
            }
            // Does not fit: a seen blocked pixel in the disk, or the disk leaves the image.
            fits.clear();
            erode(&f, disk, false, |k| !seen[k] | free[k], |i| fits.insert(i));
            let memo = if s1 { &mut self.s1 } else { &mut self.s0 };
            for (i, m) in memo.iter_mut().enumerate() {
                if *m == 0 && !fits.contains(i) {
                    *m = 2;
                }
            }
        }
        // Moves: free between two `S1` positions, blocked towards a pixel where the robot
        // does not fit (as `edge` finds them).
        let (w, h) = (f.width as i64, f.height as i64);
        for i in 0..n {
            let p = self.px_of(i);
            let interior = p.0 > 0 && p.1 > 0 && p.0 < w - 1 && p.1 < h - 1;
            for (k, d) in NB.iter().enumerate() {
                let j = if interior {
                    i.wrapping_add_signed((d.1 * w + d.0) as isize)
                } else {
                    match self.idx((p.0 + d.0, p.1 + d.1)) {
                        Some(j) => j,
                        None => continue,
                    }
                };
                if self.s0[j] == 2 {
                    self.edge_blocked[i] |= 1 << k;
                } else if self.s1[i] == 1 && self.s1[j] == 1 {
                    self.edge_free[i] |= 1 << k;
                }
            }
        }
        // Gains nothing: no target (known free, not swept) within the tool radius.
        let swept = self.swept.as_slice();
        let mut none = std::mem::take(&mut self.no_gain);
        erode(
            &f,
            &self.tool_rows,
            true,
            |k| !(free[k] & !swept[k]),
            |i| none.insert(i),
        );
        self.no_gain = none;
    }
}

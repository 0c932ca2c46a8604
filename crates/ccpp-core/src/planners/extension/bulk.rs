//! Memos filled in bulk when the final clean-up begins: where the robot fits (`S0`, `S1`),
//! which moves between `S1` positions are free, which moves lead where the robot does not
//! fit, and which positions gain nothing (no target within the tool radius).
//!
//! The final clean-up's searches sweep most of the known floor, and each position they reach
//! for the first time used to be judged alone (a disk of row runs on the known map per memo).
//! Here the same answers come from one pass over the image per question: a disk lies inside a
//! pixel set exactly when, in every row of the disk, the pixel set's run through the disk's
//! column reaches the row's half-width on both sides (a morphological erosion by row runs).
//! With `E_k` the pixels whose run reaches `k` pixels to either side, `E_0` the set and
//! `E_k = E_(k-1) & (set shifted k left) & (set shifted k right)`, a pixel fits where, for each
//! disk row `drow` of half-width `k`, the pixel `drow` rows away is in `E_k`: whole blocks of
//! 64 pixels per operation.
//!
//! ```text
//!   set           E_1 (runs reach 1 either side)     disk rows with half-widths 1, 2, 1:
//!     . # # # # # . .     . . # # # . . .            the centre fits where the rows above
//!     . # # # # # # .     . . # # # # . .            and below are in E_1 and its own row
//!     . . # # # # . .     . . . # # . . .            in E_2
//! ```
//!
//! The project's exact distance transform ([`crate::dt::squared_edt_compact`]) answers the same
//! questions (a disk of all pixels nearer than a radius holds no feature exactly when the
//! nearest feature is as far as the nearest pixel outside the disk) and gives the same plans,
//! but for these disks of a few pixels it made `ba-star-extended` on `tuw_freihaus_eg` 1.3x
//! slower (whole process, median of 5 alternating runs) and its peak memory 48 -> 55 MiB than
//! a per-pixel row-run erosion, which the block-parallel one replaced (whole process 0.84x on
//! `aws_small_warehouse_002`, same plans).
//!
//! Every memo filled here is a fact the lazy judgement would have found (the known map only
//! gains pixels, a seen obstacle stays one, targets only disappear until the memo is dropped
//! around new ones), so plans do not change; only undecided entries are written.

use fixedbitset::FixedBitSet;

use super::graph::{BLOCKED, FREE, NB};
use super::Extension;
use crate::grid::MapFrame;
use crate::planner::KnownMap;

/// Sets in `out` every pixel whose disk (row half-widths `rows`, entry `|drow|`, `-1`: the
/// row is empty) lies in the pixel set whose block `k` of bits is `word(k)`; pixels beyond the
/// image count as in the set when `outside` holds.
///
/// Bit-parallel, a block of pixels at a time: the set is copied into rows of blocks (padded
/// with `outside` bits); `E_k`, the pixels whose row run reaches `k` pixels to either side,
/// is `E_(k-1)` and the set shifted by `k` either way; a pixel's disk lies in the set exactly
/// when, for every disk row `drow`, the pixel `drow` rows away is in `E_(half-width)`.
fn erode(
    frame: &MapFrame,
    rows: &[i64],
    outside: bool,
    word: impl Fn(usize) -> usize,
    out: &mut FixedBitSet,
) {
    use crate::bits::BLOCK_BITS as B;
    let (w, h) = (frame.width, frame.height);
    if w == 0 || h == 0 {
        return;
    }
    let max_hw = rows.iter().copied().max().unwrap_or(-1);
    // Blocks of one image row, and of padding on either side (at least the widest reach).
    let ww = w.div_ceil(B);
    let pad = usize::try_from(max_hw.max(0)).unwrap_or(0) / B + 1;
    let pw = ww + 2 * pad;
    let fill: usize = if outside { usize::MAX } else { 0 };
    // The set, row by row: image column `c` at bit `pad * B + c` of its row.
    let mut x = vec![fill; h * pw];
    for r in 0..h {
        let line = &mut x[r * pw + pad..r * pw + pad + ww];
        let base = r * w;
        for (k, v) in line.iter_mut().enumerate() {
            let pos = base + k * B;
            let nb = (w - k * B).min(B);
            let (blk, off) = (pos / B, pos % B);
            let mut bits = word(blk) >> off;
            if off != 0 && nb > B - off {
                bits |= word(blk + 1) << (B - off);
            }
            if nb < B {
                let m = (1usize << nb) - 1;
                bits = bits & m | fill & !m;
            }
            *v = bits;
        }
    }
    // The `B` bits of padded row `r` from bit `pos` on.
    let get = |x: &[usize], r: usize, pos: usize| -> usize {
        let line = &x[r * pw..(r + 1) * pw];
        let (k, off) = (pos / B, pos % B);
        if off == 0 {
            line[k]
        } else {
            line[k] >> off | line[k + 1] << (B - off)
        }
    };
    let mut e: Vec<usize> = (0..h)
        .flat_map(|r| x[r * pw + pad..r * pw + pad + ww].iter().copied())
        .collect();
    let mut acc = vec![usize::MAX; h * ww];
    let reach = rows.len() as i64 - 1;
    // Rows whose disk leaves the image (not in the set there): nothing.
    for r in 0..h as i64 {
        let leaves = (-reach..=reach)
            .any(|dr| rows[dr.unsigned_abs() as usize] >= 0 && (r + dr < 0 || r + dr >= h as i64));
        if leaves && !outside {
            acc[r as usize * ww..(r as usize + 1) * ww].fill(0);
        }
    }
    for k in 0..=max_hw {
        if k > 0 {
            let ku = k as usize;
            for r in 0..h {
                for i in 0..ww {
                    let c = pad * B + i * B;
                    e[r * ww + i] &= get(&x, r, c + ku) & get(&x, r, c - ku);
                }
            }
        }
        for dr in -reach..=reach {
            if rows[dr.unsigned_abs() as usize] != k {
                continue;
            }
            for r in 0..h as i64 {
                let rr = r + dr;
                if rr < 0 || rr >= h as i64 {
                    continue;
                }
                let (a, b) = (r as usize * ww, rr as usize * ww);
                for i in 0..ww {
                    acc[a + i] &= e[b + i];
                }
            }
        }
    }
    let slice = out.as_mut_slice();
    for r in 0..h {
        let base = r * w;
        for i in 0..ww {
            let nb = (w - i * B).min(B);
            let mut v = acc[r * ww + i];
            if nb < B {
                v &= (1usize << nb) - 1;
            }
            if v == 0 {
                continue;
            }
            let pos = base + i * B;
            let (blk, off) = (pos / B, pos % B);
            slice[blk] |= v << off;
            if off != 0 {
                let hi = v >> (B - off);
                if hi != 0 {
                    slice[blk + 1] |= hi;
                }
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
            erode(&f, disk, false, |k| free[k], &mut fits);
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
            erode(&f, disk, false, |k| !seen[k] | free[k], &mut fits);
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
        let (s0, s1) = (&self.s0, &self.s1);
        let edges = &mut self.edges;
        // Pixel `p` (index `i`) on the image's rim: neighbours checked one by one.
        let rim = |edges: &mut [[u8; 2]], i: usize, p: (i64, i64)| {
            for (k, d) in NB.iter().enumerate() {
                let q = (p.0 + d.0, p.1 + d.1);
                if q.0 < 0 || q.1 < 0 || q.0 >= w || q.1 >= h {
                    continue;
                }
                let j = (q.1 * w + q.0) as usize;
                if s0[j] == 2 {
                    edges[i][BLOCKED] |= 1 << k;
                } else if s1[i] == 1 && s1[j] == 1 {
                    edges[i][FREE] |= 1 << k;
                }
            }
        };
        for r in 0..h {
            if r == 0 || r == h - 1 || w < 3 {
                for c in 0..w {
                    rim(edges, (r * w + c) as usize, (c, r));
                }
                continue;
            }
            let (lo, hi) = ((r * w + 1) as usize, (r * w + w - 1) as usize);
            rim(edges, lo - 1, (0, r));
            rim(edges, hi, (w - 1, r));
            // Inside the rim, one neighbour direction at a time over the row (branch-free).
            for (k, d) in NB.iter().enumerate() {
                let off = (d.1 * w + d.0) as isize;
                let (jlo, jhi) = (lo.wrapping_add_signed(off), hi.wrapping_add_signed(off));
                let (s0j, s1j) = (&s0[jlo..jhi], &s1[jlo..jhi]);
                for (((e, &si), &s0v), &s1v) in
                    edges[lo..hi].iter_mut().zip(&s1[lo..hi]).zip(s0j).zip(s1j)
                {
                    let blocked = u8::from(s0v == 2);
                    e[BLOCKED] |= blocked << k;
                    e[FREE] |= (u8::from(si == 1) & u8::from(s1v == 1) & (blocked ^ 1)) << k;
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
            &mut none,
        );
        self.no_gain = none;
    }
}

#[cfg(test)]
mod tests {
    use super::erode;
    use crate::grid::MapFrame;
    use fixedbitset::FixedBitSet;

    /// Calls `out` with every pixel whose disk (row half-widths `rows`, entry `|drow|`, `-1`: the
    /// row is empty) lies in the pixel set whose block `k` of bits is `word(k)`; pixels beyond the
    /// image count as in the set when `outside` holds.
    fn erode_runs(
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

    /// The bit-parallel erosion finds exactly the pixels the row-run erosion finds: random
    /// sets of several densities, image widths around a block, disks with empty rows, pixels
    /// beyond the image in the set or not.
    #[test]
    fn erode_matches_row_runs() {
        let mut rng = crate::rng::SplitMix64::new(0xe70d_e5ee);
        let disks: [&[i64]; 5] = [&[0], &[1, 0], &[3, 3, 2, 0], &[2, 1, -1], &[70, 69, 60]];
        for round in 0..120 {
            let w = [1, 5, 63, 64, 65, 127, 130, 200][round % 8];
            let h = 1 + round % 13 + (round / 40) * 5;
            let frame = MapFrame::new(w, h, 0.05);
            let n = w * h;
            let density = [0.5, 0.9, 0.98, 1.0][round % 4];
            let mut set = FixedBitSet::with_capacity(n);
            for i in 0..n {
                if rng.next_f64() < density {
                    set.insert(i);
                }
            }
            let words = set.as_slice().to_vec();
            for rows in disks {
                for outside in [false, true] {
                    let mut want = FixedBitSet::with_capacity(n);
                    erode_runs(&frame, rows, outside, |k| words[k], |i| want.insert(i));
                    let mut got = FixedBitSet::with_capacity(n);
                    erode(&frame, rows, outside, |k| words[k], &mut got);
                    assert_eq!(got, want, "w {w} h {h} rows {rows:?} outside {outside}");
                }
            }
        }
    }
}

//! A cleaning pass, chunk by chunk, and the final clean-up's judgement of which chunks to
//! leave: yield, groups of chunks planned together, and the leave budget.

#[cfg(doc)]
use super::ExtensionOptions;
use super::{Chunk, Extension, Wanted};
use crate::geometry::Point;
use crate::planner::KnownMap;

/// With [`Extension::set_speck_fields`], a chunk whose start lies within this many tool radii
/// of the end of the chunk before it in a group belongs to the same field of specks and does
/// not count towards [`ExtensionOptions::leave_group`]: on `aws_small_warehouse_002` a field
/// of one-pixel specks filled the 12 places of a group 7.6 m away, so the group was driven
/// (`leave_group` reached) although its 14 pixels did not pay for the trip (10 m). With the
/// field counted once the mean path ratio on the 14 shared maps went from 1.3128 to 1.3109
/// (`aws_small_warehouse_002` 1.303 -> 1.290, `mit_building_31` 1.299 -> 1.284, the other
/// maps unchanged); 1 or 4 tool radii gave the same plans within 0.0001.
const SAME_FIELD_R: f64 = 2.0;
/// However close its chunks, a group holds at most this many times
/// [`ExtensionOptions::leave_group`] chunks (2 gave 1.3116, 4 and 8 the same plans).
const MAX_GROUP_FACTOR: usize = 4;

/// Metres added to a bound on the path a group's leaving saves (rounding of the lengths
/// summed; far below any length that decides).
const SAVING_SLACK: f64 = 1e-6;

impl Extension {
    /// Plans the next chunk of a cleaning pass from world point `pos`: the transfer to the rim
    /// (waypoints that reach the first sweeping position) and the sweep along it; both empty
    /// when no rim within `reach_r` robot radii (`bounded`; else anywhere) gains.
    ///
    /// After the host's coverage (`!bounded`) a chunk whose yield is below
    /// [`ExtensionOptions::min_yield`] is left (its pixels stay claimed, so no later search
    /// returns to them) while the pixels left stay within [`ExtensionOptions::leave_fraction`]
    /// of the known free floor, and the next chunk is planned from `pos` instead.
    pub(crate) fn plan_pass(
        &mut self,
        known: &KnownMap,
        pos: Point,
        bounded: bool,
        wanted: Wanted,
    ) -> Chunk {
        let chunk = self.plan_pass_inner(known, pos, bounded, wanted);
        self.simplified += chunk.simplified;
        chunk
    }

    /// One chunk planned from world point `pos` as at the end of a host region but within
    /// `reach_r` robot radii whatever [`ExtensionOptions::reach_r`] says (used by
    /// `ba-star-extended`'s rims swept on the way back, [`Self::drop_chunk`] when it is not
    /// driven as planned).
    pub(crate) fn plan_near(
        &mut self,
        known: &KnownMap,
        pos: Point,
        reach_r: f64,
        wanted: Wanted,
    ) -> Chunk {
        let keep = self.opts.reach_r;
        self.opts.reach_r = reach_r;
        let chunk = self.plan_pass(known, pos, true, wanted);
        self.opts.reach_r = keep;
        chunk
    }

    /// Forgets a planned chunk that will not be driven as planned: its claims are given back
    /// (what the robot drives is stamped as it goes) and its simplification is not counted.
    pub(crate) fn drop_chunk(&mut self, chunk: &Chunk) {
        self.unclaim(chunk);
        self.simplified -= chunk.simplified;
    }

    /// [`Self::plan_pass`] before the chunk's simplification is counted.
    fn plan_pass_inner(
        &mut self,
        known: &KnownMap,
        pos: Point,
        bounded: bool,
        wanted: Wanted,
    ) -> Chunk {
        let mut cur = self.plan_chunk(known, pos, bounded, wanted, false);
        loop {
            if bounded
                || cur.gained == 0
                || cur.owed
                || self.opts.min_yield <= 0.0
                || self.pays(
                    cur.gained,
                    2.0 * cur.trip_len(pos) + 2.0 * cur.walk_len(pos),
                )
            {
                return cur;
            }
            // Leave it, alone or together with the chunks planned after it (nearest first from
            // here: the search goes on where it stopped) when those lie close together and far
            // away — a cluster of specks whose trip does not pay as a whole although each
            // speck, seen from the next one, is on the way.
            let mut group = vec![cur];
            let mut places = 1;
            let next = loop {
                let gained: usize = group.iter().map(|c| c.gained).sum();
                // Whatever chunk comes next, the group pays (leaving it saves at most its tour
                // and the way back from its end: the trip to the next chunk is at least the
                // straight way from here) and is full: it is driven, and the next chunk would
                // only be planned to be given back.
                let last = &group[group.len() - 1];
                if (places >= self.opts.leave_group
                    || group.len() >= MAX_GROUP_FACTOR * self.opts.leave_group
                    || self.left + gained >= self.leave_budget(known))
                    && self.pays(
                        gained,
                        group_saving(pos, &group, &Chunk::default())
                            + last.end(pos).dist(pos)
                            + SAVING_SLACK,
                    )
                {
                    break None;
                }
                let next = self.plan_chunk(known, pos, bounded, wanted, true);
                if !self.pays(gained, group_saving(pos, &group, &next)) {
                    if self.charge(known, pos, &group) {
                        break Some(next);
                    }
                    self.unclaim(&next);
                    break None;
                }
                if places >= self.opts.leave_group
                    || group.len() >= MAX_GROUP_FACTOR * self.opts.leave_group
                    || next.gained == 0
                    || next.owed
                    || self.left + gained + next.gained > self.leave_budget(known)
                {
                    self.unclaim(&next);
                    break None;
                }
                // A chunk next to the one before it (the same field of specks) does not count
                // towards `leave_group` when the host asks so (`set_speck_fields`).
                let last = &group[group.len() - 1];
                if !self.speck_fields
                    || last.end(pos).dist(next.start(pos))
                        > SAME_FIELD_R * self.rt * self.frame.resolution
                {
                    places += 1;
                }
                group.push(next);
            };
            let Some(next) = next else {
                for c in &group[1..] {
                    self.unclaim(c);
                }
                return group.swap_remove(0);
            };
            cur = next;
        }
    }

    /// Does `chunk`'s walk gain at least [`ExtensionOptions::min_yield`] of what a full-width
    /// lane of `len` metres sweeps?
    fn pays(&self, gained: usize, len: f64) -> bool {
        let res = self.frame.resolution;
        gained as f64 * res * res >= self.opts.min_yield * 2.0 * self.rt * res * len
    }

    /// The known free floor [`ExtensionOptions::leave_fraction`] allows the final clean-up
    /// to leave, in pixels.
    fn leave_budget(&self, known: &KnownMap) -> usize {
        (self.opts.leave_fraction * self.known_free_count(known) as f64) as usize
    }

    /// Counts the chunks of `group` (planned from world point `pos`) as left when the budget
    /// ([`ExtensionOptions::leave_fraction`]) allows; whether it did.
    fn charge(&mut self, known: &KnownMap, pos: Point, group: &[Chunk]) -> bool {
        // Charged: the walks' pixels and the targets the ways there would sweep on the side
        // (specks too small for a pass of their own, which leaving the trips leaves as well).
        // The ways of one pass's chunks share their first segments (the search tree's, see
        // `merge_transfer`): a segment charged before in the pass sweeps no target any more
        // (its targets became swept then, and targets only disappear during a pass), so only
        // the others are stamped.
        let f = self.frame;
        let mut side: Vec<usize> = Vec::new();
        let mut segs: Vec<SegKey> = Vec::new();
        for chunk in group {
            let way: Vec<Point> = std::iter::once(pos)
                .chain(chunk.transfer.iter().copied())
                .map(|p| f.world_to_grid_snapped(p))
                .collect();
            for s in way.windows(2) {
                let key = seg_key(s[0], s[1]);
                if self.charged_segs.contains(&key) || segs.contains(&key) {
                    continue;
                }
                segs.push(key);
                side.extend(self.polyline_gains(known, s).concat());
            }
        }
        side.sort_unstable();
        side.dedup();
        let charged = group.iter().map(|c| c.gained).sum::<usize>() + side.len();
        if self.left + charged > self.leave_budget(known) {
            return false;
        }
        self.left += charged;
        self.charged_segs.extend(segs);
        // Left with them: no later pass goes out for them alone.
        for i in side {
            self.swept.insert(i);
        }
        true
    }

    /// Gives the pixels `chunk` claimed back (it will not be driven now).
    fn unclaim(&mut self, chunk: &Chunk) {
        let f = self.frame;
        let (w, h) = (f.width as i64, f.height as i64);
        let reach = self.strip_rows.len() as i64 - 1;
        // Positions judged without these targets may gain again: the memo is dropped in the
        // square of side `2 reach + 1` around each pixel, the pixels' column ranges merged
        // per image row first (a walk's pixels crowd a few rows), so each range is cleared
        // once per row within `reach` (the same union of squares).
        let mut runs: Vec<(i64, i64, i64)> = chunk
            .claimed
            .iter()
            .map(|&i| {
                self.swept.set(i, false);
                let (c, r) = self.px_of(i);
                (r, (c - reach).max(0), (c + reach).min(w - 1))
            })
            .collect();
        if runs.is_empty() {
            return;
        }
        runs.sort_unstable();
        let mut merged: Vec<(i64, i64, i64)> = Vec::with_capacity(runs.len());
        for (r, c0, c1) in runs {
            match merged.last_mut() {
                Some(last) if last.0 == r && c0 <= last.2 + 1 => last.2 = last.2.max(c1),
                _ => merged.push((r, c0, c1)),
            }
        }
        // Only the memo entries made since the chunk claimed its pixels were judged without
        // them (targets only disappear meanwhile, but for chunks given back, whose own
        // entries go the same way, and new known free pixels, `refresh_no_gain`'s): while
        // the log reaches back that far, those entries in the squares are dropped, else every
        // entry in the squares.
        let logged = chunk.log_at >= self.no_gain_log_base;
        let set = if logged {
            &mut self.met
        } else {
            &mut self.no_gain
        };
        for &(r, c0, c1) in &merged {
            for row in (r - reach).max(0)..=(r + reach).min(h - 1) {
                let base = row as usize * f.width;
                let range = base + c0 as usize..base + c1 as usize + 1;
                if logged {
                    set.insert_range(range);
                } else {
                    set.remove_range(range);
                }
            }
        }
        if !logged {
            return;
        }
        for &j in &self.no_gain_log[chunk.log_at - self.no_gain_log_base..] {
            if self.met.contains(j) {
                self.no_gain.set(j, false);
            }
        }
        for (r, c0, c1) in merged {
            for row in (r - reach).max(0)..=(r + reach).min(h - 1) {
                let base = row as usize * f.width;
                self.met
                    .remove_range(base + c0 as usize..base + c1 as usize + 1);
            }
        }
    }
}

/// A grid segment, exactly (its ends' bits), for [`Extension::charge`]'s memo.
pub(super) type SegKey = [u64; 4];

fn seg_key(a: Point, b: Point) -> SegKey {
    [a.x.to_bits(), a.y.to_bits(), b.x.to_bits(), b.y.to_bits()]
}

/// The path leaving `group` saves (chunks planned from world point `pos`, nearest first),
/// with `next` the chunk planned after them: their tour (the first trip, the walks and the
/// straight ways between them, a lower bound) and the way on from the last to `next`, less
/// the (longer) trip from `pos` to `next`.
fn group_saving(pos: Point, group: &[Chunk], next: &Chunk) -> f64 {
    let mut tour = group[0].trip_len(pos);
    for (k, c) in group.iter().enumerate() {
        if k > 0 {
            tour += group[k - 1].end(pos).dist(c.start(pos));
        }
        tour += c.walk_len(pos);
    }
    if next.gained == 0 {
        return tour;
    }
    let last = group[group.len() - 1].end(pos);
    tour + last.dist(next.start(pos)) - next.trip_len(pos)
}

//! Simplifying a merged chunk: dropping the vertices whose removal loses fewest of the walk's
//! pixels, within a budget of the known free floor.

use super::merge::MAX_MERGE;
use super::Extension;
#[cfg(doc)]
use super::ExtensionOptions;
use crate::geometry::{point_segment_dist2, Point};
use crate::planner::KnownMap;

impl Extension {
    /// Drops vertices of the merged chunk `kept` (indices into `pts`, the first point excluded)
    /// whose removal leaves few of the walk's gained pixels unswept: cheapest loss first
    /// (Visvalingam-style on the pixels lost), each removal losing at most
    /// [`ExtensionOptions::simplify_loss`] tool radii of pixels, all removals within the budget
    /// ([`ExtensionOptions::simplify_fraction`] of the known free floor). The straight way
    /// that replaces a vertex must be known free. Lost pixels stay claimed (no later pass goes
    /// out for them alone) and count as left. Returns the kept indices and how many pixels
    /// they leave.
    pub(super) fn simplify(
        &mut self,
        known: &KnownMap,
        pts: &[Point],
        gains: &[Vec<usize>],
        kept: Vec<usize>,
    ) -> (Vec<usize>, usize) {
        if kept.len() < 2 {
            return (kept, 0);
        }
        let mut spent = 0;
        // Counted only when a removal loses a pixel (most lose none).
        let mut budget: Option<usize> = None;
        let per_turn = self.simplify_per_turn;
        let rt2 = self.rt * self.rt;
        // Vertices: the walk's start (index 0) and the kept points; a doubly linked list.
        let verts: Vec<usize> = std::iter::once(0).chain(kept.iter().copied()).collect();
        let n = verts.len();
        let mut prev: Vec<usize> = (0..n).map(|k| k.wrapping_sub(1)).collect();
        let mut next: Vec<usize> = (1..=n).collect();
        let mut alive = vec![true; n];
        let mut version = vec![0u32; n];
        let mut lost: Vec<usize> = Vec::new();
        // Pixels lost so far are marked in `scratch` (cleared before returning).
        let cost = |s: &Self, u: usize, w: usize| -> Option<usize> {
            let (a, b) = (verts[u], verts[w]);
            if b - a > 4 * MAX_MERGE {
                return None;
            }
            let mut c = 0;
            for g in &gains[a + 1..=b] {
                for &i in g {
                    if !s.scratch.contains(i)
                        && point_segment_dist2(s.center(s.px_of(i)), pts[a], pts[b]) > rt2
                    {
                        c += 1;
                    }
                }
            }
            (c <= per_turn && s.seg_free(known, pts[a], pts[b])).then_some(c)
        };
        let mut heap: std::collections::BinaryHeap<std::cmp::Reverse<(usize, usize, u32)>> =
            std::collections::BinaryHeap::new();
        for v in 1..n - 1 {
            if let Some(c) = cost(self, v - 1, v + 1) {
                heap.push(std::cmp::Reverse((c, v, 0)));
            }
        }
        while let Some(std::cmp::Reverse((c, v, ver))) = heap.pop() {
            if !alive[v] || ver != version[v] {
                continue;
            }
            if c > 0 {
                let b = *budget.get_or_insert_with(|| {
                    (self.opts.simplify_fraction * self.known_free_count(known) as f64) as usize
                });
                if self.simplified + spent + c > b {
                    continue;
                }
            }
            let (u, w) = (prev[v], next[v]);
            // Mark what the straight u-w no longer sweeps.
            let (a, b) = (verts[u], verts[w]);
            for g in &gains[a + 1..=b] {
                for &i in g {
                    if !self.scratch.contains(i)
                        && point_segment_dist2(self.center(self.px_of(i)), pts[a], pts[b]) > rt2
                    {
                        self.scratch.insert(i);
                        lost.push(i);
                    }
                }
            }
            spent += c;
            alive[v] = false;
            next[u] = w;
            prev[w] = u;
            for x in [u, w] {
                if x == 0 || x == n - 1 {
                    continue;
                }
                version[x] += 1;
                if let Some(c) = cost(self, prev[x], next[x]) {
                    heap.push(std::cmp::Reverse((c, x, version[x])));
                }
            }
        }
        for i in lost {
            self.scratch.set(i, false);
        }
        (
            (1..n).filter(|&k| alive[k]).map(|k| verts[k]).collect(),
            spent,
        )
    }
}

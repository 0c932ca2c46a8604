//! BCD: boustrophedon cellular decomposition, the offline (known-map) baseline.
//!
//! H. Choset and P. Pignon, "Coverage path planning: the boustrophedon cellular decomposition",
//! *Field and Service Robotics*, 1998; named by seed 000 as the offline reference for BA*.
//!
//! **Offline**: it reads the whole true map (through the [`World`]) before moving. It decomposes
//! the robot's *configuration space* — the reachable C-free pixel centres, so every lane is
//! drivable by construction — with a vertical sweep line moving east:
//! 1. each image column is cut into runs of C-free pixels; a cell continues while exactly one run
//!    of the previous column overlaps exactly one run of the current column; at every other
//!    event (split, merge, birth, death) the involved cells close and new ones open;
//! 2. cells touching across an event are adjacent; the order is greedy from the start's cell:
//!    next comes the unvisited neighbour (in the adjacency graph) nearest by path length over
//!    C-free, or, when all neighbours are done, the nearest unvisited cell (short transfers);
//! 3. each cell is covered by vertical lanes spaced `2 r_tool` (floor to whole pixels, first and
//!    last lane on the cell's edges), alternating up and down, entered at the corner nearest the
//!    robot;
//! 4. lanes and cells are joined by shortest 8-connected pixel paths (A*, octile integer costs)
//!    over a slightly safer C-free set (clearance margin a quarter pixel, so straight steps
//!    between pixel centres stay clear), shortened by line-of-sight checks on the true map.
//!
//! Regions = cells (`RegionStart` per cell); transfers between cells are marked as backtracks.
//!
//! ```
//! use ccpp_core::{GridMap, Pose};
//! use ccpp_core::world::{Robot, World};
//! use ccpp_core::planners::bcd::{Bcd, BcdOptions};
//! use ccpp_core::sim::{simulate, SimConfig};
//! let art = "##########\n#........#\n#..##....#\n#..##....#\n#........#\n##########";
//! let map = GridMap::from_ascii_scaled(art, 10, 0.02).unwrap();
//! let world = World::new(map, Robot::new(0.08), Some(Pose::new(0.3, 0.3, 0.0))).unwrap();
//! let mut p = Bcd::new(&world, &BcdOptions::default());
//! let out = simulate(&world, &mut p, &SimConfig::default());
//! let m = ccpp_core::metrics::compute(&world, &out, "box");
//! assert_eq!(m.collisions, 0);
//! assert!(m.effective_coverage > 0.95, "{}", m.effective_coverage);
//! assert!(m.regions >= 3); // split and merge around the block
//! ```

use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};

use serde::{Deserialize, Serialize};

use crate::geometry::Point;
use crate::planner::{Planner, Sensor, Step};
use crate::trace::Event;
use crate::world::World;

/// Options of [`Bcd`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BcdOptions {
    /// Lane spacing in metres; `None` = `2 r_tool`.
    pub lane_spacing_m: Option<f64>,
    /// Extra clearance (pixels) of the set the connecting paths run through.
    pub margin_px: f64,
}

impl Default for BcdOptions {
    fn default() -> Self {
        Self {
            lane_spacing_m: None,
            margin_px: 0.0,
        }
    }
}

/// One cell: its column range and, per column, the run `[r0, r1]` of C-free rows.
#[derive(Clone, Debug)]
struct CellSlices {
    c0: usize,
    runs: Vec<(usize, usize)>,
}

/// The BCD planner: a precomputed list of steps.
pub struct Bcd {
    steps: VecDeque<Step>,
}

/// The decomposition: cells and adjacency.
struct Decomposition {
    cells: Vec<CellSlices>,
    adj: Vec<Vec<usize>>,
    /// Cell of each (col, row) working pixel, `u32::MAX` if none.
    cell_of: Vec<u32>,
}

fn decompose(width: usize, height: usize, free: &dyn Fn(usize, usize) -> bool) -> Decomposition {
    let mut cells: Vec<CellSlices> = Vec::new();
    let mut adj: Vec<Vec<usize>> = Vec::new();
    let mut cell_of = vec![u32::MAX; width * height];
    // Runs of the previous column with their cell.
    let mut prev: Vec<(usize, usize, usize)> = Vec::new();
    for c in 0..width {
        let mut runs: Vec<(usize, usize)> = Vec::new();
        let mut r = 0;
        while r < height {
            if free(c, r) {
                let s = r;
                while r + 1 < height && free(c, r + 1) {
                    r += 1;
                }
                runs.push((s, r));
            }
            r += 1;
        }
        let overl = |a: (usize, usize), b: (usize, usize)| a.0 <= b.1 && b.0 <= a.1;
        let mut cur: Vec<(usize, usize, usize)> = Vec::with_capacity(runs.len());
        for &run in &runs {
            let ov: Vec<usize> = (0..prev.len())
                .filter(|&k| overl((prev[k].0, prev[k].1), run))
                .collect();
            let continues = ov.len() == 1 && {
                let p = prev[ov[0]];
                runs.iter().filter(|&&q| overl((p.0, p.1), q)).count() == 1
            };
            let id = if continues {
                let id = prev[ov[0]].2;
                cells[id].runs.push(run);
                id
            } else {
                let id = cells.len();
                cells.push(CellSlices {
                    c0: c,
                    runs: vec![run],
                });
                adj.push(Vec::new());
                for k in ov {
                    let o = prev[k].2;
                    if !adj[o].contains(&id) {
                        adj[o].push(id);
                        adj[id].push(o);
                    }
                }
                id
            };
            for rr in run.0..=run.1 {
                cell_of[rr * width + c] = id as u32;
            }
            cur.push((run.0, run.1, id));
        }
        prev = cur;
    }
    Decomposition {
        cells,
        adj,
        cell_of,
    }
}

/// Pixel path search over the working set.
struct Search<'a> {
    width: usize,
    height: usize,
    ok: &'a [bool],
    stamp: Vec<u32>,
    gen: u32,
    g: Vec<u32>,
    parent: Vec<u32>,
}

impl Search<'_> {
    fn octile(a: (usize, usize), b: (usize, usize)) -> u32 {
        let dx = a.0.abs_diff(b.0) as u32;
        let dy = a.1.abs_diff(b.1) as u32;
        10 * dx.max(dy) + 4 * dx.min(dy)
    }

    /// Dijkstra from `s` over the working set to the nearest pixel satisfying `goal`.
    fn nearest(&mut self, s: (usize, usize), goal: &dyn Fn(usize) -> bool) -> Option<usize> {
        self.search(s, None, goal)
    }

    /// A* from `s` to `t` (both working pixels), 8-connected, no corner cutting.
    fn path(&mut self, s: (usize, usize), t: (usize, usize)) -> Option<Vec<(usize, usize)>> {
        let w = self.width;
        let ti = t.1 * w + t.0;
        let end = self.search(s, Some(t), &|i| i == ti)?;
        let mut out = vec![(end % w, end / w)];
        let mut k = end;
        while self.parent[k] != u32::MAX {
            k = self.parent[k] as usize;
            out.push((k % w, k / w));
        }
        out.reverse();
        Some(out)
    }

    /// Best-first search from `s` until a pixel satisfies `goal`: A* with the octile heuristic
    /// towards `target` when given, Dijkstra otherwise. Integer costs 10 / 14, no corner cutting;
    /// ties by cost, then pixel index. Leaves the search tree in `parent`.
    fn search(
        &mut self,
        s: (usize, usize),
        target: Option<(usize, usize)>,
        goal: &dyn Fn(usize) -> bool,
    ) -> Option<usize> {
        self.gen = self.gen.wrapping_add(1);
        if self.gen == 0 {
            self.stamp.iter_mut().for_each(|x| *x = 0);
            self.gen = 1;
        }
        let w = self.width;
        let h_of = |p: (usize, usize)| target.map_or(0, |t| Self::octile(p, t));
        let mut heap = BinaryHeap::new();
        let si = s.1 * w + s.0;
        self.stamp[si] = self.gen;
        self.g[si] = 0;
        self.parent[si] = u32::MAX;
        heap.push(Reverse((h_of(s), 0u32, si as u32)));
        while let Some(Reverse((_, g, i))) = heap.pop() {
            let i = i as usize;
            if g > self.g[i] {
                continue;
            }
            if goal(i) {
                return Some(i);
            }
            let (c, r) = ((i % w) as i64, (i / w) as i64);
            for (dc, dr) in [
                (1, 0),
                (0, -1),
                (-1, 0),
                (0, 1),
                (1, -1),
                (-1, -1),
                (-1, 1),
                (1, 1),
            ] {
                let (nc, nr) = (c + dc, r + dr);
                if nc < 0 || nr < 0 || nc >= self.width as i64 || nr >= self.height as i64 {
                    continue;
                }
                let j = nr as usize * w + nc as usize;
                if !self.ok[j] {
                    continue;
                }
                let diag = dc != 0 && dr != 0;
                if diag
                    && !(self.ok[r as usize * w + nc as usize]
                        && self.ok[nr as usize * w + c as usize])
                {
                    continue;
                }
                let ng = g + if diag { 14 } else { 10 };
                if self.stamp[j] != self.gen || ng < self.g[j] {
                    self.stamp[j] = self.gen;
                    self.g[j] = ng;
                    self.parent[j] = i as u32;
                    heap.push(Reverse((
                        ng + h_of((nc as usize, nr as usize)),
                        ng,
                        j as u32,
                    )));
                }
            }
        }
        None
    }
}

impl Bcd {
    /// Plans the whole coverage of `world` (offline).
    pub fn new(world: &World, opts: &BcdOptions) -> Self {
        let frame = *world.frame();
        let (w, h) = (frame.width, frame.height);
        let robot = world.robot();
        let res = frame.resolution;
        let r_px = robot.radius / res;
        let need = crate::collide::contact_radius_px(r_px) + opts.margin_px.max(0.0);
        let reach = world.reachable();
        let ok: Vec<bool> = (0..w * h)
            .map(|i| {
                let (c, r) = (i % w, i / w);
                reach.contains(i) && world.pixel_clearance(c, r) / res + 0.5 >= need
            })
            .collect();
        let dec = decompose(w, h, &|c, r| ok[r * w + c]);
        let spacing = opts.lane_spacing_m.unwrap_or(2.0 * robot.tool_radius);
        let sp = ((spacing / res) + 1e-9).floor().max(1.0) as usize;
        let mut search = Search {
            width: w,
            height: h,
            ok: &ok,
            stamp: vec![0; w * h],
            gen: 0,
            g: vec![0; w * h],
            parent: vec![u32::MAX; w * h],
        };
        let mut steps = VecDeque::new();
        let px = |c: usize, r: usize| frame.pixel_center(c, r);
        let start = world.start().position();
        // The working pixel nearest the start (a short free move joins them).
        let mut cur: Option<(usize, usize)> = None;
        if let Some((c0, r0)) = frame.pixel_of(start) {
            let mut best: Option<(f64, (usize, usize))> = None;
            // No farther than the image (a huge `margin_px` overflowed `i64` here).
            let rad = need.ceil().min(w.max(h) as f64) as i64 + 3;
            for dr in -rad..=rad {
                for dc in -rad..=rad {
                    let (c, r) = (c0 as i64 + dc, r0 as i64 + dr);
                    if c < 0 || r < 0 || c >= w as i64 || r >= h as i64 {
                        continue;
                    }
                    let (c, r) = (c as usize, r as usize);
                    if ok[r * w + c] && world.segment_free(start, px(c, r)) {
                        let d = px(c, r).dist(start);
                        if best.is_none_or(|b| d < b.0) {
                            best = Some((d, (c, r)));
                        }
                    }
                }
            }
            if let Some((_, p)) = best {
                steps.push_back(Step::MoveTo(px(p.0, p.1)));
                cur = Some(p);
            }
        }
        let Some(mut here) = cur else {
            return Self { steps };
        };
        // Cell order, greedy: the nearest (by path length over the working set) unvisited cell
        // among the current cell's neighbours in the adjacency graph, else among all cells.
        let n = dec.cells.len();
        let mut visited = vec![false; n];
        let mut next = Some(dec.cell_of[here.1 * w + here.0] as usize);
        let mut region = 0u32;
        while let Some(cid) = next.take() {
            visited[cid] = true;
            let cell = &dec.cells[cid];
            let c0 = cell.c0;
            let c1 = c0 + cell.runs.len() - 1;
            let mut lanes: Vec<usize> = if c1 - c0 < sp {
                vec![usize::midpoint(c0, c1)]
            } else {
                let mut v: Vec<usize> = (c0..=c1).step_by(sp).collect();
                if *v.last().unwrap_or(&c0) != c1 {
                    v.push(c1);
                }
                v
            };
            // Enter at the corner nearest the robot.
            let corners = {
                let (l, r) = (lanes[0], lanes[lanes.len() - 1]);
                let rl = cell.runs[l - c0];
                let rr = cell.runs[r - c0];
                [
                    (l, rl.0, false, true),
                    (l, rl.1, false, false),
                    (r, rr.0, true, true),
                    (r, rr.1, true, false),
                ]
            };
            let hp = px(here.0, here.1);
            let best = corners
                .iter()
                .min_by(|a, b| px(a.0, a.1).dist(hp).total_cmp(&px(b.0, b.1).dist(hp)))
                .copied()
                .unwrap_or(corners[0]);
            if best.2 {
                lanes.reverse();
            }
            // `down` = start at the top row (smaller row index) and go down.
            let mut down = best.3;
            let entry = best.1;
            let entry_px = (lanes[0], entry);
            if entry_px != here {
                steps.push_back(Step::Mark(Event::BacktrackStart));
                let ok = push_path(&mut steps, world, &mut search, here, entry_px, &px);
                steps.push_back(Step::Mark(Event::BacktrackEnd));
                if !ok {
                    continue;
                }
                here = entry_px;
            }
            region += 1;
            steps.push_back(Step::Mark(Event::RegionStart { region }));
            for &lane in &lanes {
                let run = cell.runs[lane - c0];
                let (a, b) = if down { (run.0, run.1) } else { (run.1, run.0) };
                if (lane, a) != here
                    && !push_path(&mut steps, world, &mut search, here, (lane, a), &px)
                {
                    continue;
                }
                here = (lane, a);
                if push_path(&mut steps, world, &mut search, here, (lane, b), &px) {
                    here = (lane, b);
                }
                down = !down;
            }
            steps.push_back(Step::Mark(Event::RegionEnd { region }));
            let cell_at = |i: usize| dec.cell_of[i] as usize;
            let unvisited_nb: Vec<usize> = dec.adj[cid]
                .iter()
                .copied()
                .filter(|&k| !visited[k])
                .collect();
            let found = if unvisited_nb.is_empty() {
                search.nearest(here, &|i| {
                    dec.cell_of[i] != u32::MAX && !visited[cell_at(i)]
                })
            } else {
                search
                    .nearest(here, &|i| {
                        dec.cell_of[i] != u32::MAX && unvisited_nb.contains(&cell_at(i))
                    })
                    .or_else(|| {
                        search.nearest(here, &|i| {
                            dec.cell_of[i] != u32::MAX && !visited[cell_at(i)]
                        })
                    })
            };
            next = found.map(cell_at);
        }
        Self { steps }
    }
}

/// Appends moves from pixel `a` to pixel `b`: straight when free, else an A* pixel path
/// shortened by line of sight on the true map. Every emitted move is checked against the true
/// map; returns `false` (having emitted only a verified prefix) when no verified path exists.
fn push_path(
    steps: &mut VecDeque<Step>,
    world: &World,
    search: &mut Search<'_>,
    a: (usize, usize),
    b: (usize, usize),
    px: &dyn Fn(usize, usize) -> Point,
) -> bool {
    if world.segment_free(px(a.0, a.1), px(b.0, b.1)) {
        steps.push_back(Step::MoveTo(px(b.0, b.1)));
        return true;
    }
    let Some(path) = search.path(a, b) else {
        return false;
    };
    if !world.segment_free(px(a.0, a.1), px(path[0].0, path[0].1)) {
        return false;
    }
    let pts: Vec<Point> = path.iter().map(|&(c, r)| px(c, r)).collect();
    let mut i = 0;
    while i + 1 < pts.len() {
        // Exponential then binary search for the farthest visible point.
        let mut lo = i + 1;
        let mut step = 1;
        let mut hi = None;
        loop {
            let j = (i + step).min(pts.len() - 1);
            if world.segment_free(pts[i], pts[j]) {
                lo = j;
                if j == pts.len() - 1 {
                    break;
                }
                step *= 2;
            } else {
                hi = Some(j);
                break;
            }
        }
        if let Some(mut hi) = hi {
            if hi == i + 1 {
                // Not even the next pixel is reachable in a straight line: give up honestly.
                return false;
            }
            while hi - lo > 1 {
                let mid = usize::midpoint(lo, hi);
                if world.segment_free(pts[i], pts[mid]) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
        }
        steps.push_back(Step::MoveTo(pts[lo]));
        i = lo;
    }
    true
}

impl Planner for Bcd {
    fn name(&self) -> &'static str {
        "bcd"
    }
    fn is_offline(&self) -> bool {
        true
    }
    fn next(&mut self, _sensor: &dyn Sensor) -> Step {
        self.steps.pop_front().unwrap_or(Step::Done)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decomposition_splits_and_merges_around_a_block() {
        let art = "........\n..##....\n..##....\n........";
        let g: crate::grid::GridMap = art.parse().unwrap();
        let d = decompose(8, 4, &|c, r| g.get(c, r).is_free());
        // Left part, above the block, below the block, right part.
        assert_eq!(d.cells.len(), 4);
        assert_eq!(d.adj[0].len(), 2);
        assert_eq!(d.adj[3].len(), 2);
    }
}

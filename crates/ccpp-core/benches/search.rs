//! Criterion bench: the shared search module ([`ccpp_core::search`]) against the search code
//! the planners used before it, on a large grid (a generated 2000 x 2000 px office, one node
//! per free pixel, 8-connected, BA*'s fixed-point step costs and no corner cutting).
//!
//! * `dijkstra/*`: the nearest of a set of far targets (BA*'s backtracking selection shape):
//!   [`TileSearch::nearest`] (BA*'s own scratch) against [`SearchSpace`] driven the same way.
//! * `nearest_sparse/*`: the nearest of a sparse listed set (every 101st free pixel of the far
//!   rows, as sparse as BA*'s backtracking list `L`): [`TileSearch::nearest`] (Dijkstra)
//!   against [`TileSearch::nearest_of`] (A* towards the set, the same answer).
//! * `astar/*`: corner to corner: [`TileSearch::astar`] against [`SearchSpace`], and
//!   [`TileSearch::astar_bounded`] given the path's cost (as BA* calls it after its nearest
//!   search), which labels no tile keyed above that cost.
//! * `bfs/*`: a 4-connected flood of the whole component: the former BSA-BFS pattern (a fresh
//!   parent array and a `VecDeque` per search) against [`SearchSpace::flood_fill`] and the
//!   same flood through the driver calls ([`SearchSpace::pop_fifo`], [`SearchSpace::discover`]).
//!
//! Before timing, each pair is checked to give the same cost and the same path.

use std::collections::VecDeque;

use ccpp_core::gen::office;
use ccpp_core::planners::ba_star::{
    graph_edge, heuristic, TileGraph, TileSearch, COST_DIAG, COST_ORTHO,
};
use ccpp_core::search::SearchSpace;
use ccpp_core::tiles::{Tile, N8};
use criterion::{criterion_group, criterion_main, Criterion};

/// Free pixels of a grid as a tile graph (tile `(i, j)` = pixel column `i`, row `j`).
struct Pixels {
    w: i32,
    h: i32,
    free: Vec<bool>,
}

impl Pixels {
    fn idx(&self, t: Tile) -> Option<u32> {
        (t.0 >= 0 && t.1 >= 0 && t.0 < self.w && t.1 < self.h).then(|| (t.1 * self.w + t.0) as u32)
    }
    fn tile(&self, k: u32) -> Tile {
        (k as i32 % self.w, k as i32 / self.w)
    }
}

impl TileGraph for Pixels {
    fn bounds(&self) -> (i32, i32, i32, i32) {
        (0, self.w - 1, 0, self.h - 1)
    }
    fn covered(&self, t: Tile) -> bool {
        self.idx(t).is_some_and(|k| self.free[k as usize])
    }
    fn move_free(&self, _: Tile, _: usize) -> bool {
        true
    }
}

fn grid() -> Pixels {
    let map = office(2000, 2000, 0.05, 7);
    let f = *map.frame();
    Pixels {
        w: f.width as i32,
        h: f.height as i32,
        free: map.cells().iter().map(|c| c.is_free()).collect(),
    }
}

/// The first free pixel at or after `t` in index order.
fn free_near(g: &Pixels, t: Tile) -> Tile {
    let k0 = g.idx(t).expect("in range");
    let k = (k0..g.free.len() as u32)
        .find(|&k| g.free[k as usize])
        .expect("a free pixel");
    g.tile(k)
}

/// Best-first search on the shared module, expanded like [`TileSearch`] (settled neighbours
/// skipped before the edge check). `goal`: A* towards it; else Dijkstra to the first `target`.
fn module_search(
    s: &mut SearchSpace<u64>,
    g: &Pixels,
    from: Tile,
    goal: Option<Tile>,
    target: &dyn Fn(Tile) -> bool,
) -> Option<(u32, u64)> {
    let h = |v: Tile| goal.map_or(0, |gl| heuristic(v, gl));
    s.begin();
    let src = g.idx(from)?;
    s.push_source(src, 0, h(from));
    while let Some(x) = s.pop() {
        let t = g.tile(x.node);
        if goal.map_or_else(|| target(t), |gl| gl == t) {
            return Some((x.node, x.g));
        }
        for (k, &(di, dj)) in N8.iter().enumerate() {
            let v = (t.0 + di, t.1 + dj);
            let Some(kv) = g.idx(v) else { continue };
            if s.is_settled(kv) || !graph_edge(g, t, k) {
                continue;
            }
            let nd = x.g + if k % 2 == 1 { COST_DIAG } else { COST_ORTHO };
            s.relax(x.node, kv, nd, || h(v));
        }
    }
    None
}

/// The former BSA-BFS search: a fresh parent array per call, a `VecDeque`, 4 neighbours.
fn legacy_flood(g: &Pixels, from: Tile) -> usize {
    let n = g.free.len();
    let mut parent = vec![u32::MAX; n];
    let s = g.idx(from).expect("in range") as usize;
    parent[s] = s as u32;
    let mut q = VecDeque::from([from]);
    let mut count = 0;
    while let Some(c) = q.pop_front() {
        count += 1;
        let kc = g.idx(c).expect("in range");
        for (di, dj) in [(1, 0), (0, 1), (-1, 0), (0, -1)] {
            let nb = (c.0 + di, c.1 + dj);
            let Some(k) = g.idx(nb) else { continue };
            if parent[k as usize] != u32::MAX || !g.free[k as usize] {
                continue;
            }
            parent[k as usize] = kc;
            q.push_back(nb);
        }
    }
    count
}

fn module_flood(s: &mut SearchSpace<u32>, g: &Pixels, from: Tile) -> usize {
    let src = g.idx(from).expect("in range");
    s.flood_fill([src], |v, out| {
        let t = g.tile(v);
        for (di, dj) in [(1, 0), (0, 1), (-1, 0), (0, -1)] {
            if let Some(k) = g.idx((t.0 + di, t.1 + dj)) {
                if g.free[k as usize] {
                    out.push(k);
                }
            }
        }
    })
    .len()
}

/// The same flood through the driver calls (no neighbour buffer).
fn module_flood_driver(s: &mut SearchSpace<u32>, g: &Pixels, from: Tile) -> usize {
    s.begin();
    s.push_fifo_source(g.idx(from).expect("in range"));
    while let Some((v, _)) = s.pop_fifo() {
        let t = g.tile(v);
        for (di, dj) in [(1, 0), (0, 1), (-1, 0), (0, -1)] {
            if let Some(k) = g.idx((t.0 + di, t.1 + dj)) {
                if g.free[k as usize] {
                    s.discover(v, k);
                }
            }
        }
    }
    s.fifo_order().len()
}

fn bench(c: &mut Criterion) {
    let g = grid();
    let from = free_near(&g, (g.w / 2, g.h / 2));
    // The ends of the start's component in index order: A* from its first to its last pixel.
    let comp = {
        let mut s: SearchSpace<u32> = SearchSpace::new(g.free.len());
        module_flood(&mut s, &g, from);
        let order = s.fifo_order();
        (
            *order.iter().min().expect("non-empty"),
            *order.iter().max().expect("non-empty"),
            order.len(),
        )
    };
    let (corner, far) = (g.tile(comp.0), g.tile(comp.1));
    // Targets: the rows near the component's last row (the nearest wins, ties by (j, i)).
    let target = |t: Tile| t.1 >= far.1 - 30;
    let mut old = TileSearch::new(g.bounds());
    let mut new: SearchSpace<u64> = SearchSpace::new(g.free.len());
    // BFS depths fit in u32 (12-byte records, as BSA-BFS uses).
    let mut new_bfs: SearchSpace<u32> = SearchSpace::new(g.free.len());

    // Same answers before timing.
    let a = old.nearest(&g, from, target).expect("reachable band");
    let b = module_search(&mut new, &g, from, None, &target).expect("reachable band");
    println!(
        "office 2000 x 2000: component of {} px, A* {corner:?} -> {far:?}",
        comp.2
    );
    assert_eq!((g.idx(a.0).expect("in range"), a.1), b, "dijkstra differs");
    let a = old.astar(&g, corner, far).expect("connected");
    let bounded = old.astar_bounded(&g, corner, far, a.1).expect("connected");
    assert_eq!(a, bounded, "bounded astar differs");
    let cost = a.1;
    let b = module_search(&mut new, &g, corner, Some(far), &|_| false).expect("connected");
    let path: Vec<Tile> = new.path_to(b.0).iter().map(|&k| g.tile(k)).collect();
    assert_eq!((a.0, a.1), (path, b.1), "astar differs");
    assert_eq!(legacy_flood(&g, from), module_flood(&mut new_bfs, &g, from));
    assert_eq!(
        legacy_flood(&g, from),
        module_flood_driver(&mut new_bfs, &g, from)
    );

    let sparse: Vec<Tile> = (0..g.free.len() as u32)
        .filter(|&k| g.free[k as usize] && k % 101 == 0)
        .map(|k| g.tile(k))
        .filter(|&t| target(t))
        .collect();
    let is_sparse = |t: Tile| target(t) && g.idx(t).is_some_and(|k| k % 101 == 0);
    let a = old.nearest(&g, from, is_sparse).expect("reachable target");
    assert_eq!(
        old.nearest_of(&g, from, &sparse, is_sparse),
        Some(a),
        "nearest_of differs"
    );

    let mut grp = c.benchmark_group("search_office_2000");
    grp.sample_size(10);
    grp.bench_function("dijkstra/ba_star_tile_search", |bch| {
        bch.iter(|| old.nearest(&g, from, target));
    });
    grp.bench_function("dijkstra/search_space", |bch| {
        bch.iter(|| module_search(&mut new, &g, from, None, &target));
    });
    grp.bench_function("nearest_sparse/dijkstra", |bch| {
        bch.iter(|| old.nearest(&g, from, is_sparse));
    });
    grp.bench_function("nearest_sparse/astar_to_set", |bch| {
        bch.iter(|| old.nearest_of(&g, from, &sparse, is_sparse));
    });
    grp.bench_function("astar/ba_star_tile_search", |bch| {
        bch.iter(|| old.astar(&g, corner, far));
    });
    grp.bench_function("astar/ba_star_tile_search_bounded", |bch| {
        bch.iter(|| old.astar_bounded(&g, corner, far, cost));
    });
    grp.bench_function("astar/search_space", |bch| {
        bch.iter(|| module_search(&mut new, &g, corner, Some(far), &|_| false));
    });
    grp.bench_function("bfs/legacy_alloc_per_search", |bch| {
        bch.iter(|| legacy_flood(&g, from));
    });
    grp.bench_function("bfs/search_space_flood_fill", |bch| {
        bch.iter(|| module_flood(&mut new_bfs, &g, from));
    });
    grp.bench_function("bfs/search_space_driver", |bch| {
        bch.iter(|| module_flood_driver(&mut new_bfs, &g, from));
    });
    grp.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

//! Cell decomposition (step 1 of the module docs): the sweep over a lattice's lines, its
//! cells, and the cuts of elongated cells (`split_ends`) and of abrupt run changes (`split_jumps`).

/// One cell of a decomposition: lines `u0..u0 + runs.len()`, and on each line the run
/// `[v0, v1]` of pixels. `cols`: the lines are image columns (`u` = column, `v` = row),
/// otherwise image rows (`u` = row, `v` = column).
#[derive(Clone, Debug)]
pub(super) struct Cell {
    pub(super) cols: bool,
    pub(super) u0: usize,
    pub(super) runs: Vec<(usize, usize)>,
}

impl Cell {
    pub(super) fn u1(&self) -> usize {
        self.u0 + self.runs.len() - 1
    }

    /// Pixel `(col, row)` of line `u`, position `v`.
    pub(super) fn px(&self, u: usize, v: usize) -> (usize, usize) {
        if self.cols {
            (u, v)
        } else {
            (v, u)
        }
    }

    /// The same pixels with lines the other way, if every such line meets the cell in one run.
    pub(super) fn transposed(&self) -> Option<Cell> {
        self.transposed_trim(0)
    }

    /// The same pixels with lines the other way ([`Cell::transposed`]), or when some lines
    /// would meet the cell in several runs only among the first or last `max` positions along
    /// the lines (a jagged wall along one side, whose bumps split the lines
    /// across), the transposed cell without them. The band left out is at most `max` pixels
    /// deep: the edge lane beside it sweeps most of it and the rim passes the rest.
    pub(super) fn transposed_trim(&self, max: usize) -> Option<Cell> {
        let lo = self.runs.iter().map(|r| r.0).min()?;
        let hi = self.runs.iter().map(|r| r.1).max()?;
        let n = hi - lo + 1;
        let mut runs: Vec<Option<(usize, usize)>> = vec![None; n];
        // Per position `v`: the first and last line whose run holds it; a line that holds it
        // after a gap makes it two runs (`bad`).
        let mut bad = vec![false; n];
        for (k, &(a, b)) in self.runs.iter().enumerate() {
            let u = self.u0 + k;
            for (r, bad) in runs[a - lo..=b - lo]
                .iter_mut()
                .zip(&mut bad[a - lo..=b - lo])
            {
                match r {
                    None => *r = Some((u, u)),
                    Some((_, last)) if *last + 1 == u => *last = u,
                    Some(_) if max == 0 => return None,
                    Some(_) => *bad = true,
                }
            }
        }
        let band = max.min(n);
        let cut_lo = (0..band).rev().find(|&j| bad[j]).map_or(0, |j| j + 1);
        let cut_hi = (n - band..n).find(|&j| bad[j]).map_or(0, |j| n - j);
        if cut_lo + cut_hi >= n || bad[cut_lo..n - cut_hi].iter().any(|&b| b) {
            return None;
        }
        let runs = runs[cut_lo..n - cut_hi]
            .iter()
            .copied()
            .collect::<Option<Vec<_>>>()?;
        Some(Cell {
            cols: !self.cols,
            u0: lo + cut_lo,
            runs,
        })
    }
}

/// Cells elongated along their lines (more lines than twice their longest run) that are not
/// monotone the other way only because of their ends (rounded C-free corners) are cut into the
/// two ends (at most `max` lines each) and a middle that can take lanes across (module docs,
/// step 2).
pub(super) fn split_ends(cells: Vec<Cell>, max: usize) -> Vec<Cell> {
    let mut out = Vec::with_capacity(cells.len());
    for c in cells {
        let n = c.runs.len();
        let longest = c.runs.iter().map(|r| r.1 - r.0 + 1).max().unwrap_or(0);
        if n <= 2 * longest
            || n <= max.saturating_mul(2).saturating_add(1)
            || c.transposed().is_some()
        {
            out.push(c);
            continue;
        }
        let sub = |a: usize, b: usize| Cell {
            cols: c.cols,
            u0: c.u0 + a,
            runs: c.runs[a..b].to_vec(),
        };
        let mut cut = None;
        'search: for t in 1..=max {
            for (a, b) in [(t, t), (t, 0), (0, t)] {
                if sub(a, n - b).transposed().is_some() {
                    cut = Some((a, b));
                    break 'search;
                }
            }
        }
        match cut {
            Some((a, b)) => {
                if a > 0 {
                    out.push(sub(0, a));
                }
                out.push(sub(a, n - b));
                if b > 0 {
                    out.push(sub(n - b, n));
                }
            }
            None => out.push(c),
        }
    }
    out
}

/// Cuts cells whose runs change length abruptly (by more than `jump` pixels from one line to
/// the next, as where a corridor leaves a room inside one cell) into the parts on either side
/// where that lowers the estimated cost, so that each part takes its own lane direction
/// (module docs, step 2). `cost` prices a cell (its cheaper view plus the cost of reaching
/// it); the cheapest cut is taken first and both parts are cut again.
pub(super) fn split_jumps(cells: Vec<Cell>, jump: usize, cost: &dyn Fn(&Cell) -> f64) -> Vec<Cell> {
    let mut out = Vec::with_capacity(cells.len());
    let mut todo: Vec<Cell> = cells.into_iter().rev().collect();
    while let Some(c) = todo.pop() {
        let n = c.runs.len();
        let len = |k: usize| c.runs[k].1 - c.runs[k].0;
        let cuts: Vec<usize> = (1..n)
            .filter(|&k| len(k).abs_diff(len(k - 1)) > jump)
            .collect();
        if cuts.is_empty() {
            out.push(c);
            continue;
        }
        let sub = |a: usize, b: usize| Cell {
            cols: c.cols,
            u0: c.u0 + a,
            runs: c.runs[a..b].to_vec(),
        };
        let whole = cost(&c);
        let mut best: Option<(f64, usize)> = None;
        for &k in &cuts {
            let e = cost(&sub(0, k)) + cost(&sub(k, n));
            if e < whole - 1e-9 && best.is_none_or(|b| e < b.0) {
                best = Some((e, k));
            }
        }
        match best {
            Some((_, k)) => {
                // Second part first on the stack's far side: parts stay in line order.
                todo.push(sub(k, n));
                todo.push(sub(0, k));
            }
            None => out.push(c),
        }
    }
    out
}

/// Decomposes the pixels where `free(u, v)` over lines `u < nu` of length `nv` (module docs,
/// step 1). Cells are numbered in the order they open.
pub(super) fn decompose(
    nu: usize,
    nv: usize,
    cols: bool,
    free: &dyn Fn(usize, usize) -> bool,
) -> Vec<Cell> {
    let mut cells: Vec<Cell> = Vec::new();
    // Runs of the previous line with their cell.
    let mut prev: Vec<(usize, usize, usize)> = Vec::new();
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for u in 0..nu {
        runs.clear();
        let mut v = 0;
        while v < nv {
            if free(u, v) {
                let s = v;
                while v + 1 < nv && free(u, v + 1) {
                    v += 1;
                }
                runs.push((s, v));
            }
            v += 1;
        }
        let overl = |a: (usize, usize), b: (usize, usize)| a.0 <= b.1 && b.0 <= a.1;
        let mut cur: Vec<(usize, usize, usize)> = Vec::with_capacity(runs.len());
        for &run in &runs {
            let mut ov = prev.iter().filter(|p| overl((p.0, p.1), run));
            let continues = match (ov.next(), ov.next()) {
                (Some(p), None) => runs.iter().filter(|&&q| overl((p.0, p.1), q)).count() == 1,
                _ => false,
            };
            let id = if continues {
                let p = prev
                    .iter()
                    .find(|p| overl((p.0, p.1), run))
                    .map_or(0, |p| p.2);
                cells[p].runs.push(run);
                p
            } else {
                cells.push(Cell {
                    cols,
                    u0: u,
                    runs: vec![run],
                });
                cells.len() - 1
            };
            cur.push((run.0, run.1, id));
        }
        prev = cur;
    }
    cells
}

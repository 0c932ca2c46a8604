//! Sensing integration: the planner's [`Mind`] (known map, tile model, searches) and the
//! refresh of tile and move judgements after each scan (touch boxes, per-row/column tables,
//! the disk cache).

use crate::geometry::{ceil_i64, floor_i64, Point};
use crate::planner::{disk_row_span, disk_rows, KnownMap, Sensor};
use crate::tiles::{Tile, N8};

use super::judge::{judge_motion_px, judge_point, Judgement};
use super::search::TileSearch;
use super::smoothing::{all_swept_tiles, for_each_centre_tile};
use super::tile_model::{TileModel, ST_COVERED, ST_DISK, ST_STAND};

/// Margin (pixels) added to the contact radius when [`Mind::sense`] bounds the tiles a new
/// pixel can affect: covers the rounding of the world/grid/tile conversions (the exact test
/// follows; a larger margin only costs time).
const CANDIDATE_MARGIN_PX: f64 = 0.01;

/// Margin (pixels) of the box of pixels that can touch a tile's contact disk in
/// [`Mind::sense`] (a pixel centre `q` touches when `|q - g|^2 < rc^2`, so `|q.x - g.x| < rc`
/// and `|q.y - g.y| < rc` up to rounding): far above the rounding of grid coordinates of a
/// few thousand pixels, far below a pixel.
const TIGHT_BOX_MARGIN_PX: f64 = 1e-7;

/// Everything the planner knows once it has seen its first scan.
#[derive(Clone)]
pub(super) struct Mind {
    /// Backtracking-list points the trace may still hold ([`LIST_POINTS_PER_TILE`] per tile
    /// of the model; `None` once a list did not fit and that was said).
    ///
    /// [`LIST_POINTS_PER_TILE`]: super::LIST_POINTS_PER_TILE
    pub(super) list_room: Option<usize>,
    pub(super) known: KnownMap,
    pub(super) tiles: TileModel,
    pub(super) search: TileSearch,
    pub(super) r: f64,
    /// Contact radius in pixels.
    pub(super) rc_px: f64,
    /// Where the last scan was integrated.
    pub(super) last_scan: Option<Point>,
    /// The disk of the last scan integrated ([`crate::planner::Scan::disk_px`]): the rows a
    /// new scan shares with it hold nothing new.
    pub(super) last_disk: Option<(Point, f64)>,
    /// Scratch for [`Mind::sense`]: per row of the last scan, the column span of the pixels
    /// seen for the first time (`(usize::MAX, 0)` when none).
    pub(super) new_spans: Vec<(usize, usize)>,
    /// Scratch for [`Mind::sense`]: per tile row of the candidate box, the hull of the
    /// candidate tile columns (`(i32::MAX, i32::MIN)` when none).
    pub(super) candidate_rows: Vec<(i32, i32)>,
    /// Rows of new pixels per candidate band in [`Mind::sense`]: about one tile side.
    pub(super) band_rows: usize,
    /// Per-tile cache of the contact disk's pixel spans for [`Mind::judge_tile_first`] and
    /// [`Mind::sense`].
    pub(super) disk: DiskCache,
    /// Grid x of the centre of each tile column (from the tiling's first column) and grid y
    /// of each tile row, when the frame is not rotated (a centre's grid x then depends on its
    /// world x alone, its y on its world y alone); empty otherwise. Exactly
    /// `frame.world_to_grid(center(t))`, computed once.
    pub(super) gx: Vec<f64>,
    pub(super) gy: Vec<f64>,
    /// [`Mind::touch_box`] per tile column and per tile row (from `gx`, `gy`).
    pub(super) touch_cols: Vec<(i64, i64)>,
    pub(super) touch_rows: Vec<(i64, i64)>,
    /// Per image column `c`: the tile columns `i` (inclusive) whose touch box can hold `c`,
    /// as `(first i whose box ends at or after c, last i whose box starts at or before c)`
    /// (boxes move right with `i`); per image row the same for tile rows. Empty when the
    /// frame is rotated.
    pub(super) col_tiles: Vec<(i32, i32)>,
    pub(super) row_tiles: Vec<(i32, i32)>,
    /// The tile of the last BM move sent ([`Mind::robot_tile`]).
    pub(super) sent_to: Option<Tile>,
    /// The last BM move sent, as its tile and direction (index into `N8`): blocked when the
    /// bumper stops it ([`BaStar::bm_step`](super::BaStar)).
    pub(super) sent_move: Option<(Tile, usize)>,
    /// The tile the robot is taken to stand on at its next decision instead of the tile of
    /// its pose: the last tile of a backtracking way the bumper cut short
    /// ([`Mind::bumped_leg`]), which the covered tiles reach.
    pub(super) held: Option<Tile>,
    /// The tiling is one where a tile centre lies in its own tile by the rounding of
    /// [`TileGrid::tile_of`] ([`centres_round_home`]).
    ///
    /// [`TileGrid::tile_of`]: crate::tiles::TileGrid::tile_of
    pub(super) centres_home: bool,
}

/// Does `grid.tile_of(grid.center(t)) == t` hold for every tile `t` with `|i|, |j| < 2^30`?
/// Sufficient (and checked here): a finite anchor below 1e15 in magnitude and a side in
/// `(1e-9 max(|anchor|, 1), 1e15)`. Then `center(t).x = a + i side` (two roundings) and
/// `tile_of` divides `center(t).x - a` (one more) by `side` (one more): the quotient is `i`
/// within a few ulps of `2^30` plus a few ulps of `a / side < 1e9`, below 1e-6, so it rounds to
/// `i`. The same for `j`.
pub(super) fn centres_round_home(grid: &crate::tiles::TileGrid) -> bool {
    let (a, s) = (grid.anchor, grid.side);
    let scale = a.x.abs().max(a.y.abs()).max(1.0);
    a.x.abs() < 1e15 && a.y.abs() < 1e15 && s < 1e15 && s > scale * 1e-9
}

/// [`Mind::col_tiles`] / [`Mind::row_tiles`]: for each of `n` pixel indices `p`, the range of
/// tile indices (from `first`) whose pixel range `boxes[k]` can hold `p`: `lo(k)` and `hi(k)`
/// must be non-decreasing in `k` (`rev`: non-increasing, the rows).
pub(super) fn pixel_to_tiles(
    boxes: &[(i64, i64)],
    n: usize,
    first: i32,
    rev: bool,
) -> Vec<(i32, i32)> {
    (0..n as i64)
        .map(|p| {
            if rev {
                // Boxes move up (to smaller rows) with k: the first k starting at or above p,
                // the last k ending at or below p.
                let a = boxes.partition_point(|b| b.0 > p);
                let b = boxes.partition_point(|b| b.1 >= p);
                (first + a as i32, first + b as i32 - 1)
            } else {
                let a = boxes.partition_point(|b| b.1 < p);
                let b = boxes.partition_point(|b| b.0 <= p);
                (first + a as i32, first + b as i32 - 1)
            }
        })
        .collect()
}

/// The rows and columns of [`Mind::touch_box`] for a disk of contact radius `rc` pixels at grid
/// point `g` in an image of height `h` pixels: `((row_lo, row_hi), (col_lo, col_hi))`.
#[inline]
pub(super) fn touch_box_of(g: Point, rc: f64, h: f64) -> ((i64, i64), (i64, i64)) {
    let m = TIGHT_BOX_MARGIN_PX;
    (
        (
            ceil_i64(h - g.y - rc - 0.5 - m),
            floor_i64(h - g.y + rc - 0.5 + m),
        ),
        (ceil_i64(g.x - rc - 0.5 - m), floor_i64(g.x + rc - 0.5 + m)),
    )
}

/// The contact disk of each tile as pixel spans: `rows` slots per tile of `[lo, hi]` column
/// offsets from `col0[k]` for rows `row0[k]..` (`lo > hi`: no pixel in that row). Valid only
/// for tiles with [`ST_DISK`] set; the slots of the others are never read (zero-initialised:
/// pages of tiles never left undetermined by a judgement cost no memory).
#[derive(Clone)]
pub(super) struct DiskCache {
    rows: usize,
    row0: Vec<i32>,
    col0: Vec<i32>,
    spans: Vec<[u8; 2]>,
    /// One tile's slots while it is judged for the first time.
    scratch: Vec<[u8; 2]>,
}

impl DiskCache {
    pub(super) fn new(n_tiles: usize, rc_px: f64) -> Self {
        // Rows a disk's span test visits: 2 rc plus the rounding and margin rows.
        let rows = (2.0 * rc_px).ceil() as usize + 4;
        Self {
            rows,
            row0: vec![0; n_tiles],
            col0: vec![0; n_tiles],
            spans: vec![[0, 0]; n_tiles * rows],
            scratch: Vec::with_capacity(rows),
        }
    }
}

impl std::fmt::Debug for Mind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Mind")
            .field("seen_px", &self.known.seen().count_ones(..))
            .field("tiles", &(self.tiles.w, self.tiles.h))
            .field("l", &self.tiles.l.len())
            .finish_non_exhaustive()
    }
}

impl Mind {
    pub(super) fn center(&self, t: Tile) -> Point {
        self.tiles.grid.center(t)
    }

    /// The tile holding the robot at `p` ([`TileGrid::tile_of`]): without the divisions when
    /// `p` is exactly the centre of the tile of the last BM move (`tile_of` gives that tile
    /// there, see [`centres_round_home`]).
    ///
    /// [`TileGrid::tile_of`]: crate::tiles::TileGrid::tile_of
    #[inline]
    pub(super) fn robot_tile(&self, p: Point) -> Tile {
        if let Some(t) = self.sent_to {
            let c = self.center(t);
            if self.centres_home
                && t.0.unsigned_abs() < 1 << 30
                && t.1.unsigned_abs() < 1 << 30
                && c.x.to_bits() == p.x.to_bits()
                && c.y.to_bits() == p.y.to_bits()
            {
                return t;
            }
        }
        self.tiles.grid.tile_of(p)
    }

    /// The image rows and columns (inclusive, signed) whose pixel centres lie within the
    /// contact radius of tile `t`'s centre in each coordinate, with a margin of
    /// [`TIGHT_BOX_MARGIN_PX`]: every pixel that can touch the tile's disk lies in them.
    #[inline]
    fn touch_box(&self, t: Tile) -> ((i64, i64), (i64, i64)) {
        let (di, dj) = (t.0 - self.tiles.i0, t.1 - self.tiles.j0);
        if let (Some(&c), Some(&r)) = (
            usize::try_from(di)
                .ok()
                .and_then(|i| self.touch_cols.get(i)),
            usize::try_from(dj)
                .ok()
                .and_then(|j| self.touch_rows.get(j)),
        ) {
            return (r, c);
        }
        self.touch_box_far(t)
    }

    /// [`Mind::touch_box`] off the tables (a rotated frame, or a tile outside the tiling):
    /// out of line, so that the hot callers do not evaluate the rotation's sine and cosine
    /// ahead of the table lookup.
    #[cold]
    #[inline(never)]
    fn touch_box_far(&self, t: Tile) -> ((i64, i64), (i64, i64)) {
        let h = self.known.frame().height as f64;
        touch_box_of(self.grid_center(t), self.rc_px, h)
    }

    /// [`judge_motion`] from the centre of tile `t` to that of its neighbour `n`. First the
    /// fast path of [`judge_motion_px`] on the union of the two tiles' [`Mind::touch_box`]es
    /// (every pixel that touches the swept disk lies within the contact radius of the segment
    /// in each coordinate, so in that box): inside the image and all known free, the move is
    /// free, as the exact test would find.
    ///
    /// [`judge_motion`]: super::judge_motion
    fn judge_step(&self, t: Tile, n: Tile) -> Judgement {
        let ((ra, rb), (ca, cb)) = self.touch_box(t);
        let ((rc, rd), (cc, cd)) = self.touch_box(n);
        if self.box_known_free((ra.min(rc), rb.max(rd)), (ca.min(cc), cb.max(cd))) {
            return Judgement::Free;
        }
        judge_motion_px(
            &self.known,
            self.grid_center(t),
            self.grid_center(n),
            self.rc_px,
        )
    }

    /// Are the image rows `r0..=r1` and columns `c0..=c1` (signed) inside the image, at most
    /// 1024 pixels, and all known free?
    #[inline]
    fn box_known_free(&self, (r0, r1): (i64, i64), (c0, c1): (i64, i64)) -> bool {
        let frame = self.known.frame();
        0 <= r0
            && r0 <= r1
            && r1 < frame.height as i64
            && 0 <= c0
            && c0 <= c1
            && c1 < frame.width as i64
            && (r1 - r0 + 1) * (c1 - c0 + 1) <= 1024
            && self
                .known
                .rect_known_free(r0 as usize, r1 as usize, c0 as usize, c1 as usize)
    }

    /// The centre of tile `t` in continuous grid coordinates: `world_to_grid(center(t))`.
    #[inline]
    fn grid_center(&self, t: Tile) -> Point {
        let (di, dj) = (t.0 - self.tiles.i0, t.1 - self.tiles.j0);
        if let (Some(&x), Some(&y)) = (
            usize::try_from(di).ok().and_then(|i| self.gx.get(i)),
            usize::try_from(dj).ok().and_then(|j| self.gy.get(j)),
        ) {
            return Point::new(x, y);
        }
        self.grid_center_far(t)
    }

    /// [`Mind::grid_center`] off the tables (out of line, as [`Mind::touch_box_far`]).
    #[cold]
    #[inline(never)]
    fn grid_center_far(&self, t: Tile) -> Point {
        self.known.frame().world_to_grid(self.center(t))
    }

    /// Judges move `t -> t + N8[k]` (cached once decided).
    pub(super) fn judge_move(&mut self, t: Tile, k: usize) -> Judgement {
        let c = self.tiles.cached_move(t, k);
        if c != Judgement::Undetermined {
            return c;
        }
        let n = (t.0 + N8[k].0, t.1 + N8[k].1);
        let j = if self.tiles.stand(t) == Judgement::Blocked
            || self.tiles.stand(n) == Judgement::Blocked
        {
            Judgement::Blocked
        } else {
            self.judge_step(t, n)
        };
        if j != Judgement::Undetermined {
            self.tiles.set_move(t, k, j);
        }
        j
    }

    fn set_stand(&mut self, k: usize, t: Tile, j: Judgement) {
        self.tiles.state[k] = (self.tiles.state[k] & !ST_STAND) | j as u8;
        // `mu` reads a standability only as "is it Blocked?" (`blocked`, the lane-end
        // obstacles), so a tile judged Free changes no tile's L membership.
        if j == Judgement::Blocked {
            self.tiles.update_l_around(t);
        }
    }

    /// Integrates a scan taken at `pose` and refreshes every judgement it can change.
    ///
    /// A tile's standability can change only when a pixel of its contact disk is seen for the
    /// first time. The newly seen pixels are kept as one column span per row; an undetermined
    /// tile is judged again — with [`judge_motion`]'s predicate at the tile centre, the
    /// definition itself (tests check the cache against it after every step) — only when its
    /// cached disk runs (before the first judgement: the bounding box of its disk) meet one of
    /// those spans.
    ///
    /// [`judge_motion`]: super::judge_motion
    pub(super) fn sense(&mut self, sensor: &dyn Sensor) {
        // The sensor sees a disk around the robot: turning in place shows nothing new.
        let at = sensor.pose().position();
        if self.last_scan == Some(at) {
            return;
        }
        self.last_scan = Some(at);
        let scan = sensor.scan();
        // Rows come top to bottom, each row's new pixels left to right.
        let mut spans = std::mem::take(&mut self.new_spans);
        spans.clear();
        let mut first_row = 0usize;
        let prev = self.last_disk.replace(scan.disk_px());
        self.known.integrate_rows(&scan, prev, |r, lo, hi| {
            if spans.is_empty() {
                first_row = r;
            }
            let k = r - first_row;
            spans.resize(k, (usize::MAX, 0));
            spans.push((lo, hi));
        });
        if spans.is_empty() {
            self.new_spans = spans;
            return;
        }
        let last_row = first_row + spans.len() - 1;
        // Candidate tiles: a tile's standability can change only when a new pixel lies in its
        // contact disk, i.e. when its centre lies within `rc` of a new pixel's centre. The new
        // pixels are taken in bands of rows about one tile high; each band's box, grown by
        // `rc` plus a margin for rounding, gives (as the hull of its corners in tile indices:
        // tiles are axis-aligned in the world frame) a range of tiles per tile row, kept as the
        // hull per tile row. Tiles are then visited row by row, each at most once.
        let frame = *self.known.frame();
        let h = frame.height as f64;
        let rc = self.rc_px;
        let m = rc + CANDIDATE_MARGIN_PX;
        let grid = self.tiles.grid;
        let unrotated = frame.origin.theta == 0.0;
        let tile_box = |c0: usize, c1: usize, r0: usize, r1: usize| {
            let (x0, x1) = (c0 as f64 + 0.5 - m, c1 as f64 + 0.5 + m);
            let (y0, y1) = (h - r1 as f64 - 0.5 - m, h - r0 as f64 - 0.5 + m);
            let (mut i0, mut i1, mut j0, mut j1) = (i32::MAX, i32::MIN, i32::MAX, i32::MIN);
            // Without rotation a corner's tile column depends on its x alone and its row on
            // its y alone: two opposite corners give the same hull as four.
            let corners: &[(f64, f64)] = if unrotated {
                &[(x0, y0), (x1, y1)]
            } else {
                &[(x0, y0), (x1, y0), (x0, y1), (x1, y1)]
            };
            for &(x, y) in corners {
                let t = grid.tile_of(frame.grid_to_world(Point::new(x, y)));
                i0 = i0.min(t.0);
                i1 = i1.max(t.0);
                j0 = j0.min(t.1);
                j1 = j1.max(t.1);
            }
            (i0, i1, j0, j1)
        };
        let mut ranges = std::mem::take(&mut self.candidate_rows);
        ranges.clear();
        let j0 = if self.row_tiles.is_empty() {
            let (c0, c1) = spans
                .iter()
                .fold((usize::MAX, 0), |(a, b), s| (a.min(s.0), b.max(s.1)));
            let (_, _, j0, j1) = tile_box(c0, c1, first_row, last_row);
            ranges.resize((j1 - j0 + 1) as usize, (i32::MAX, i32::MIN));
            self.band_candidates(&spans, first_row, j0, &mut ranges, tile_box);
            j0
        } else {
            // Unrotated: the tiles whose touch box meets a row's new span, from the tables.
            let (j0, j1) = (self.row_tiles[last_row].0, self.row_tiles[first_row].1);
            if j0 <= j1 {
                ranges.resize((j1 - j0 + 1) as usize, (i32::MAX, i32::MIN));
                for (row, &(lo, hi)) in (first_row..).zip(spans.iter()) {
                    if lo > hi {
                        continue;
                    }
                    let (bj0, bj1) = self.row_tiles[row];
                    let (bi0, bi1) = (self.col_tiles[lo].0, self.col_tiles[hi].1);
                    if bi0 > bi1 {
                        continue;
                    }
                    for j in bj0.max(j0)..=bj1.min(j1) {
                        let r = &mut ranges[(j - j0) as usize];
                        r.0 = r.0.min(bi0);
                        r.1 = r.1.max(bi1);
                    }
                }
            }
            j0
        };
        for (j, &(i0, i1)) in (j0..).zip(ranges.iter()) {
            for i in i0..=i1 {
                let t = (i, j);
                let Some(k) = self.tiles.idx(t) else { continue };
                if self.tiles.state[k] & ST_STAND != Judgement::Undetermined as u8 {
                    continue;
                }
                let judged = if self.tiles.state[k] & ST_DISK == 0 {
                    // Not cached yet: the rows and columns whose pixel centres lie within
                    // `rc` of the centre in each coordinate (every pixel that touches the disk
                    // does), with a margin far above the rounding of the centre and of the
                    // touch test.
                    let ((r_lo, r_hi), (c_lo, c_hi)) = self.touch_box(t);
                    let rows = r_lo.max(first_row as i64)..=r_hi.min(last_row as i64);
                    let hit = rows.into_iter().any(|row| {
                        let s = spans[(row - first_row as i64) as usize];
                        s.0 <= s.1 && (s.0 as i64) <= c_hi && (s.1 as i64) >= c_lo
                    });
                    if !hit {
                        continue;
                    }
                    if self.box_known_free((r_lo, r_hi), (c_lo, c_hi)) {
                        // Every pixel that can touch the disk is known free: free, as the
                        // exact test finds (nothing to cache: the judgement is final).
                        Judgement::Free
                    } else {
                        self.judge_tile_first(k, self.grid_center(t))
                    }
                } else {
                    // Cached: the disk's own pixel runs against the new ones.
                    let n = self.disk.rows;
                    let (row0, col0) = (self.disk.row0[k] as usize, self.disk.col0[k] as usize);
                    let hit = self.disk.spans[k * n..(k + 1) * n].iter().enumerate().any(
                        |(i, &[a, b])| {
                            let row = row0 + i;
                            a <= b && (first_row..=last_row).contains(&row) && {
                                let s = spans[row - first_row];
                                s.0 <= s.1
                                    && s.0 <= col0 + usize::from(b)
                                    && s.1 >= col0 + usize::from(a)
                            }
                        },
                    );
                    if !hit {
                        continue;
                    }
                    let (row0, col0) = (i64::from(self.disk.row0[k]), i64::from(self.disk.col0[k]));
                    Self::spans_state(
                        &self.known,
                        &self.disk.spans[k * n..(k + 1) * n],
                        row0,
                        col0,
                    )
                };
                if judged != Judgement::Undetermined {
                    self.set_stand(k, t, judged);
                }
            }
        }
        self.new_spans = spans;
        self.candidate_rows = ranges;
    }

    /// The candidate tiles of [`Mind::sense`] for a rotated frame: the new pixels of `spans`
    /// (from image row `first_row`) in bands of rows about one tile high, each band's box
    /// given by `tile_box` as tile ranges; the hull per tile row (from tile row `j0`) is kept
    /// in `ranges`.
    fn band_candidates(
        &self,
        spans: &[(usize, usize)],
        first_row: usize,
        j0: i32,
        ranges: &mut [(i32, i32)],
        tile_box: impl Fn(usize, usize, usize, usize) -> (i32, i32, i32, i32),
    ) {
        let j1 = j0 + ranges.len() as i32 - 1;
        for (b, band) in spans.chunks(self.band_rows).enumerate() {
            let (bc0, bc1) = band
                .iter()
                .fold((usize::MAX, 0), |(a, b), s| (a.min(s.0), b.max(s.1)));
            if bc0 > bc1 {
                continue;
            }
            let r0 = first_row + b * self.band_rows;
            let (bi0, bi1, bj0, bj1) = tile_box(bc0, bc1, r0, r0 + band.len() - 1);
            for j in bj0.max(j0)..=bj1.min(j1) {
                let r = &mut ranges[(j - j0) as usize];
                r.0 = r.0.min(bi0);
                r.1 = r.1.max(bi1);
            }
        }
    }

    /// [`judge_point`] for tile `k`, not in the [`DiskCache`] yet, whose centre is at grid
    /// point `g`: the disk's pixel spans are computed by the same predicate and, while the
    /// tile stays undetermined, cached (a tile is judged again each time new pixels reach its
    /// disk, until it is decided; [`Mind::sense`] then reads the cached spans). A tile decided
    /// at its first judgement (the common case for small tiles) never writes the cache, whose
    /// pages then cost no memory.
    ///
    /// The slots start at the first row of [`disk_rows`] and take their column offsets from
    /// one column of margin left of the disk (clamped at 0: any touching column is >= 0, else
    /// blocked).
    fn judge_tile_first(&mut self, k: usize, g: Point) -> Judgement {
        let n = self.disk.rows;
        let frame = *self.known.frame();
        let rc = self.rc_px;
        let (w, hh) = (frame.width as i64, frame.height as i64);
        let rows = disk_rows(&frame, g, rc);
        let (row0, row1) = (*rows.start(), *rows.end());
        let col0 = (floor_i64(g.x - rc - 0.5) - 1).max(0);
        if row1 - row0 + 1 > n as i64 || !(0..=i64::from(i32::MAX)).contains(&row0) {
            return judge_point(&self.known, g, rc);
        }
        let slots = &mut self.disk.scratch;
        slots.clear();
        slots.resize(n, [1, 0]);
        for (slot, row) in slots.iter_mut().zip(rows) {
            let Some((lo, hi)) = disk_row_span(&frame, g, rc, row) else {
                continue;
            };
            if row >= hh || lo < 0 || hi >= w || hi - col0 > 250 {
                // Reaches outside the image (blocked), or too wide to cache.
                return judge_point(&self.known, g, rc);
            }
            *slot = [(lo - col0) as u8, (hi - col0) as u8];
        }
        let j = Self::spans_state(&self.known, slots, row0, col0);
        if j == Judgement::Undetermined {
            self.disk.spans[k * n..(k + 1) * n].copy_from_slice(&self.disk.scratch);
            self.disk.row0[k] = row0 as i32;
            self.disk.col0[k] = col0 as i32;
            self.tiles.state[k] |= ST_DISK;
        }
        j
    }

    /// What `known` says of the disk given as [`DiskCache`] slots from image row `row0`, column
    /// offsets from `col0`.
    #[inline]
    fn spans_state(known: &KnownMap, slots: &[[u8; 2]], row0: i64, col0: i64) -> Judgement {
        let runs = slots
            .iter()
            .zip(row0..)
            .filter(|(&[a, b], _)| a <= b)
            .map(|(&[a, b], row)| (row, col0 + i64::from(a), col0 + i64::from(b)));
        known.runs_state(runs).into()
    }

    /// The bumper stopped the BM move `t -> t + N8[k]`: the move is judged blocked, whatever
    /// the known map says, and `L` is updated around both tiles.
    ///
    /// Why: under odometry noise the pose estimate drifts from the truth, so a move that is
    /// free on the known map can run the real robot into a wall. Left free, the same move was
    /// sent again at every step (BA* on `teb_maze` at `--odometry-noise 0.02`: 1002 bumper
    /// contacts in one place, then the simulator's stall stop at 20 % of the floor). Blocked,
    /// BM takes the next direction or ends the region, and `L` (which reads move judgements)
    /// no longer lists a tile for a neighbour it cannot enter, so backtracking does not
    /// return to it. A move once blocked stays blocked (judgements are cached for good), so
    /// every bump removes one of finitely many moves: the planner terminates. Under ideal
    /// execution a correct BA* never bumps, so nothing changes there.
    pub(super) fn block_bumped_move(&mut self, t: Tile, k: usize) {
        let n = (t.0 + N8[k].0, t.1 + N8[k].1);
        self.tiles.set_move(t, k, Judgement::Blocked);
        self.tiles.update_l_around(t);
        self.tiles.update_l_around(n);
    }

    /// The bumper stopped the backtracking move from tile `a` to tile `b`: a move between
    /// neighbours is judged blocked ([`Mind::block_bumped_move`]), and `a` is marked rough
    /// ([`ST_ROUGH`](super::tile_model::ST_ROUGH)), so the ways from `a` are driven tile by
    /// tile from then on, and a step of them that bumps is blocked in turn.
    /// The robot is then taken to stand on `a`, the last tile of the way it reached
    /// ([`Mind::held`]).
    ///
    /// Why: under odometry noise the way to `s_sp` can run the real robot into a wall however
    /// free it is on the known map. Chosen again, the same way was driven again from the same
    /// place (BA* on `teb_maze` at `--odometry-noise 0.02`: the same backtrack and the same
    /// contact 1000 times, then the simulator's stall stop). Giving up `s_sp` instead left
    /// the shared first leg of every later way in place (600 contacts at one spot on
    /// `tuw_freihaus_eg`), and starting the next region at the tile the drifted estimate
    /// lay in cut it off from the covered tiles (the run ended "done" at a fifth of the floor:
    /// hostile pass). Every bump now marks one of finitely many tiles or blocks one of
    /// finitely many moves, so the planner terminates; a correct BA* never bumps under ideal
    /// execution.
    pub(super) fn bumped_leg(&mut self, a: Tile, b: Tile) {
        let d = (b.0 - a.0, b.1 - a.1);
        if let Some(k) = N8.iter().position(|&n| n == d) {
            self.block_bumped_move(a, k);
        }
        // (also after a move between neighbours: smoothing judges by line of sight, not by
        // the move's judgement, and a diagonal move blocked was smoothed again)
        if let Some(k) = self.tiles.idx(a) {
            self.tiles.state[k] |= super::tile_model::ST_ROUGH;
        }
        self.held = Some(a);
    }

    /// Marks `t` covered (the robot stands on it), decides its moves and updates L.
    #[inline]
    pub(super) fn cover(&mut self, t: Tile) {
        let Some(k) = self.tiles.idx(t) else { return };
        if self.tiles.state[k] & ST_COVERED != 0 {
            return;
        }
        self.tiles.state[k] |= ST_COVERED;
        // The touch boxes of the 3 x 3 tiles around `t` hold every pixel any of its moves can
        // touch: all known free (and inside the image), every move is free, as
        // `Mind::judge_move` would find (no neighbour can be judged blocked then). The boxes
        // are one box moved with the tile centre, so their hull is that of the four corner
        // tiles' boxes (in a rotated frame too).
        let (mut r0, mut r1, mut c0, mut c1) = (i64::MAX, i64::MIN, i64::MAX, i64::MIN);
        for (di, dj) in [(-1, -1), (1, -1), (-1, 1), (1, 1)] {
            let ((ra, rb), (ca, cb)) = self.touch_box((t.0 + di, t.1 + dj));
            (r0, r1, c0, c1) = (r0.min(ra), r1.max(rb), c0.min(ca), c1.max(cb));
        }
        let all_free = self.box_known_free((r0, r1), (c0, c1));
        for n in 0..8 {
            let v = (t.0 + N8[n].0, t.1 + N8[n].1);
            if n % 2 == 0 || self.tiles.covered(v) {
                if all_free {
                    if self.tiles.cached_move(t, n) == Judgement::Undetermined {
                        self.tiles.set_move(t, n, Judgement::Free);
                    }
                } else {
                    self.judge_move(t, n);
                }
            }
        }
        self.tiles.update_l_around(t);
    }

    /// Line of sight for A*SPT.
    pub(super) fn visible(&self, a: Tile, b: Tile) -> bool {
        let rho = self.r / self.tiles.grid.side;
        let tiles = &self.tiles;
        // The tiles along the centre line first: one of them uncovered, a swept tile is.
        if rho > 1e-3 && !for_each_centre_tile(a, b, |t| tiles.covered(t)) {
            return false;
        }
        all_swept_tiles(a, b, rho, |t| tiles.covered(t))
            && judge_motion_px(
                &self.known,
                self.grid_center(a),
                self.grid_center(b),
                self.rc_px,
            ) == Judgement::Free
    }
}

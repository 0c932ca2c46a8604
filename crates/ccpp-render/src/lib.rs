//! # ccpp-render
//!
//! Pictures of ccpp runs, as pure functions of (world, trace): the coverage PNG today; plots,
//! GIF and the HTML replay build on the same pieces.
//!
//! Colours of [`coverage_png`]:
//! - floor the tool swept: light blue; floor it could reach but missed: salmon;
//! - floor it could never reach (other components, too narrow): pale grey-white;
//! - obstacles: near black; unknown: mid grey;
//! - the executed path: one colour per region (boustrophedon region, spiral, cell), thin;
//!   backtracking transfers dashed near-black over a white casing;
//! - start: green disc with a heading tick; critical points: orange squares; chosen restart
//!   points: purple rings; collisions: red crosses; final pose: black ring.
//!
//! The legend under the map lists exactly the classes and markers that the picture shows (with
//! counts), and the header carries a coloured badge with the effective coverage (green from
//! 95 %, amber from 80 %, red below) and the collision count, so a bad run stands out.

pub mod chart;
mod font;
pub mod replay;
pub mod run_files;

use chart::{Chart, LegendEntry, Swatch};

use ccpp_core::grid::Cell;
use ccpp_core::metrics::swept_pixels;
use ccpp_core::trace::{Entry, Event, Piece, Trace};
use ccpp_core::world::World;
use ccpp_core::Point;
use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Rect, Stroke, StrokeDash, Transform};

/// Rendering failures.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The canvas could not be allocated (zero or huge size).
    #[error("cannot allocate a {0}x{1} canvas")]
    Canvas(u32, u32),
    /// PNG encoding failed.
    #[error("PNG encoding failed: {0}")]
    Encode(String),
}

/// Options of [`coverage_png`].
#[derive(Clone, Debug)]
pub struct CoverageStyle {
    /// Target width in pixels for small maps (maps are scaled up by an integer factor to reach
    /// it; large maps are drawn 1:1 or scaled down to `max_side`). The canvas is at least
    /// this wide up to 480 px: a map drawn narrower stands in its middle.
    pub min_width: u32,
    /// Largest canvas side.
    pub max_side: u32,
    /// Title printed in the header (planner, map, figures).
    pub title: Vec<String>,
    /// Draw the legend under the map (off for small panels that share one legend).
    pub legend: bool,
    /// The run's warnings (as `ccpp run` prints them without `warning: `): with any, an
    /// amber badge counts them beside the coverage badge and the first is written under the
    /// title (a run that swept the yard around a building, its start outside, showed a green
    /// "99.5% covered" and nothing else).
    pub warnings: Vec<String>,
}

impl Default for CoverageStyle {
    fn default() -> Self {
        Self {
            min_width: 900,
            max_side: 3000,
            title: Vec::new(),
            legend: true,
            warnings: Vec::new(),
        }
    }
}

/// Colours of the coverage picture's areas and markers.
pub mod colours {
    /// Swept reachable floor.
    pub const SWEPT: [u8; 3] = [170, 215, 250];
    /// Reachable floor the run missed.
    pub const MISSED: [u8; 3] = [250, 150, 130];
    /// Swept floor outside the reachable area.
    pub const SWEPT_OUTSIDE: [u8; 3] = [200, 225, 245];
    /// Free floor the robot can never reach.
    pub const UNREACHABLE: [u8; 3] = [246, 246, 242];
    /// Obstacles.
    pub const OBSTACLE: [u8; 3] = [30, 30, 30];
    /// Unknown map pixels.
    pub const UNKNOWN: [u8; 3] = [170, 170, 170];
    /// Backtracking transfers (dashed, over a white casing).
    pub const BACKTRACK: [u8; 3] = [20, 20, 20];
    /// Start disc.
    pub const START: [u8; 3] = [0, 170, 60];
    /// Final pose ring.
    pub const END: [u8; 3] = [0, 0, 0];
    /// Critical points.
    pub const CRITICAL: [u8; 3] = [240, 140, 0];
    /// Chosen restart points.
    pub const RESTART: [u8; 3] = [130, 40, 160];
    /// Collisions.
    pub const COLLISION: [u8; 3] = [230, 0, 0];
    /// Keep-out floor (tint; hatched with [`KEEPOUT_HATCH`]).
    pub const KEEPOUT: [u8; 3] = [250, 215, 215];
    /// Hatching over keep-out floor.
    pub const KEEPOUT_HATCH: [u8; 3] = [200, 40, 40];
    /// Free floor outside the work area.
    pub const OUTSIDE_AREA: [u8; 3] = [226, 222, 208];
    /// Work-area border.
    pub const AREA_BORDER: [u8; 3] = [110, 40, 150];
    /// The approach to the work area from a start outside it (dotted, over a white casing).
    pub const APPROACH: [u8; 3] = [105, 105, 105];
    /// The badge of a run the simulator stopped before the planner finished.
    pub const STOPPED: [u8; 3] = [200, 30, 30];
    /// The warnings badge and line: amber (dark enough for white text on it).
    pub const WARNING: [u8; 3] = [176, 96, 0];
}

/// Where the approach to the work area ends (a start outside the area: the simulator drives
/// [`World::approach`] before the planner starts, all at step 0): the index among the trace's
/// poses and the pose of the first one at [`World::start`]. `None` without an approach (or a
/// trace that never reaches its end).
pub fn approach_end(world: &World, trace: &Trace) -> Option<(usize, ccpp_core::Pose)> {
    if world.approach().is_empty() {
        return None;
    }
    let target = world.start().position();
    // The approach is driven exactly: its end is the target up to rounding.
    let tol = world.frame().resolution * 1e-3;
    trace
        .poses()
        .enumerate()
        .find(|(_, pose)| pose.position().dist(target) <= tol)
}

/// Why the simulator stopped a run the planner did not finish (`stalled`, `max_steps`): the
/// reason of the trace's `finished` event when it is not `done`.
pub fn stop_reason(trace: &Trace) -> Option<String> {
    unfinished(finished_record(trace)).map(str::to_string)
}

/// The reason of a `finished` record ([`finished_record`]) when it is not `done`.
pub(crate) fn unfinished(finished: Option<(u64, &str)>) -> Option<&str> {
    finished.map(|(_, reason)| reason).filter(|r| *r != "done")
}

/// The step and reason of the trace's `finished` event, when it has one.
pub(crate) fn finished_record(trace: &Trace) -> Option<(u64, &str)> {
    trace.events().find_map(|(t, e)| match e {
        Event::Finished { reason } => Some((t, reason.as_str())),
        _ => None,
    })
}

/// Zone class of map pixel `i` for the pictures: 1 = keep-out, 2 = outside the area, 0 = none.
pub(crate) fn zone_class(world: &World, i: usize) -> u8 {
    match world.zones() {
        Some(z) if z.keepout.contains(i) => 1,
        Some(z) if z.area.as_ref().is_some_and(|a| !a.contains(i)) => 2,
        _ => 0,
    }
}

/// Region colours (colour-blind-friendly-ish, distinct on light blue, at least 60 apart in
/// RGB). No red: red marks collisions, keep-outs and a stopped run (the second region's path
/// was the keep-out hatching's red, and the first replacement's brown 24.5 from the olive).
/// At least 60 from the markers too: an orange lane ran into the critical points' orange
/// squares (14 apart), a purple one under the restart rings and the area border (30 and 49),
/// a green one past the start (32).
const PALETTE: [[u8; 3]; 10] = [
    [0, 90, 181],
    [230, 0, 250],
    [0, 110, 90],
    [120, 120, 200],
    [180, 120, 0],
    [0, 150, 160],
    [130, 190, 0],
    [210, 60, 140],
    [90, 90, 20],
    [40, 40, 140],
];

fn rgb(c: [u8; 3]) -> Color {
    Color::from_rgba8(c[0], c[1], c[2], 255)
}

fn paint(c: Color) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color(c);
    p.anti_alias = true;
    p
}

/// Map-to-canvas placement.
#[derive(Clone, Copy)]
struct View {
    scale: f32,
    height: f64,
    /// Canvas columns left of the map (a narrow map stands in the middle of the canvas).
    left: f32,
    top: f32,
    col0: f64,
    row0: f64,
}

impl View {
    fn to_canvas(self, world: &World, p: Point) -> (f32, f32) {
        let g = world.frame().world_to_grid(p);
        (
            ((g.x - self.col0) as f32) * self.scale + self.left,
            ((self.height - g.y - self.row0) as f32) * self.scale + self.top,
        )
    }

    /// [`View::to_canvas`] in `f64`, for points that may lie far off the picture (clipped
    /// before they are drawn).
    fn to_canvas_f64(self, world: &World, p: Point) -> (f64, f64) {
        let g = world.frame().world_to_grid(p);
        let s = f64::from(self.scale);
        (
            (g.x - self.col0) * s + f64::from(self.left),
            (self.height - g.y - self.row0) * s + f64::from(self.top),
        )
    }
}

/// The part of the map worth drawing: the bounding box of known (free or occupied) pixels and
/// of the path, with a small margin. Returns `(col0, row0, cols, rows)`.
pub fn crop_box(world: &World, trace: &Trace) -> (usize, usize, usize, usize) {
    let f = *world.frame();
    let (mut c0, mut c1, mut r0, mut r1) = (usize::MAX, 0usize, usize::MAX, 0usize);
    let mut add = |c: usize, r: usize| {
        c0 = c0.min(c);
        c1 = c1.max(c);
        r0 = r0.min(r);
        r1 = r1.max(r);
    };
    for (r, row) in world.map().cells().chunks(f.width.max(1)).enumerate() {
        let known = |c: &Cell| *c != Cell::Unknown;
        if let (Some(a), Some(b)) = (row.iter().position(known), row.iter().rposition(known)) {
            add(a, r);
            add(b, r);
        }
    }
    // A straight run's poses lie between its ends: when both ends are on the map, the ends
    // bound its pixels (the map is convex in grid coordinates).
    let lattice = trace.lattice();
    for piece in trace.pieces() {
        match piece {
            Piece::Pose { pose, .. } => {
                if let Some((c, r)) = f.pixel_of(pose.position()) {
                    add(c, r);
                }
            }
            Piece::Run(run) => {
                let ends = [run.from, run.to(lattice)].map(|[x, y]| f.pixel_of(Point::new(x, y)));
                if let [Some(a), Some(b)] = ends {
                    add(a.0, a.1);
                    add(b.0, b.1);
                } else {
                    for (_, p) in run.poses(lattice) {
                        if let Some((c, r)) = f.pixel_of(p.position()) {
                            add(c, r);
                        }
                    }
                }
            }
            Piece::Event { .. } => {}
        }
    }
    if c0 == usize::MAX {
        return (0, 0, f.width, f.height);
    }
    let m = (f.width.max(f.height) / 50).max(4);
    let c0 = c0.saturating_sub(m);
    let r0 = r0.saturating_sub(m);
    let c1 = (c1 + m).min(f.width - 1);
    let r1 = (r1 + m).min(f.height - 1);
    (c0, r0, c1 - c0 + 1, r1 - r0 + 1)
}

/// Draws the coverage picture of a run and returns PNG bytes.
///
/// # Errors
/// When the canvas cannot be allocated or encoded.
pub fn coverage_png(
    world: &World,
    trace: &Trace,
    style: &CoverageStyle,
) -> Result<Vec<u8>, RenderError> {
    let pixmap = coverage_pixmap(world, trace, style)?;
    encode_png(&pixmap)
}

/// [`coverage_png`] with the swept pixels already computed (`swept` must be
/// [`swept_pixels`]`(world, trace)`, as the metrics computed them): the same bytes without
/// sweeping the trace again.
///
/// # Errors
/// As [`coverage_png`].
pub fn coverage_png_swept(
    world: &World,
    trace: &Trace,
    style: &CoverageStyle,
    swept: &fixedbitset::FixedBitSet,
) -> Result<Vec<u8>, RenderError> {
    let pixmap = ccpp_io::phase::time("coverage.png draw", || {
        coverage_pixmap_swept(world, trace, style, swept)
    })?;
    ccpp_io::phase::time("coverage.png encode", || encode_png(&pixmap))
}

/// Encodes a picture as PNG bytes, fast: an opaque canvas (every picture of this crate) is
/// written as 8-bit RGB, streamed row by row from the pixmap (no copy of the canvas), with
/// `png`'s fast DEFLATE mode and its fixed filter; a canvas with any translucent pixel goes
/// through tiny-skia's RGBA encoder. Same pixels as [`Pixmap::encode_png`] decodes to; the
/// bytes are a pure function of the pixels.
///
/// # Errors
/// When encoding fails.
pub fn encode_png(pixmap: &Pixmap) -> Result<Vec<u8>, RenderError> {
    use std::io::Write as _;
    let err = |e: &dyn std::fmt::Display| RenderError::Encode(e.to_string());
    let (w, h) = (pixmap.width(), pixmap.height());
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, w, h);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Fast);
    let mut writer = encoder.write_header().map_err(|e| err(&e))?;
    // Every pixel's alpha ANDed while its row is copied (no early exit: a reduction the
    // compiler vectorizes). A canvas with a translucent pixel is encoded again as RGBA below.
    let mut alpha = u8::MAX;
    {
        let mut stream = writer.stream_writer().map_err(|e| err(&e))?;
        // One spare byte: each pixel is copied whole (4 bytes, one store), its alpha byte
        // then overwritten by the next pixel's red (the last one's lands in the spare byte).
        let n = w as usize * 3;
        let mut row = vec![0u8; n + 1];
        // Opaque premultiplied pixels are their straight colours.
        for src in pixmap.data().chunks_exact(w as usize * 4) {
            alpha &= src.chunks_exact(4).fold(u8::MAX, |all, p| all & p[3]);
            if alpha != u8::MAX {
                break;
            }
            for (k, s) in src.chunks_exact(4).enumerate() {
                row[3 * k..3 * k + 4].copy_from_slice(s);
            }
            stream.write_all(&row[..n]).map_err(|e| err(&e))?;
        }
        if alpha == u8::MAX {
            stream.finish().map_err(|e| err(&e))?;
        }
    }
    if alpha != u8::MAX {
        return pixmap.encode_png().map_err(|e| err(&e));
    }
    writer.finish().map_err(|e| err(&e))?;
    Ok(out)
}

/// Counts of what a run's picture shows, for its legend.
#[derive(Clone, Debug, Default, PartialEq)]
#[allow(clippy::struct_excessive_bools)] // one flag per area class, read by `entries_of`
struct Shown {
    swept: bool,
    missed: bool,
    swept_outside: bool,
    /// Floor outside the work area that the tool swept (the approach, mostly).
    swept_outside_area: bool,
    unreachable: bool,
    obstacle: bool,
    unknown: bool,
    /// Regions with at least one move (each drawn in its colour).
    regions: usize,
    /// Regions started (`RegionStart` events), as `metrics.json` counts them; a region can
    /// end without a move (an online planner finding its start already covered or blocked).
    regions_started: usize,
    backtrack: bool,
    critical: usize,
    restart: usize,
    collisions: usize,
    poses: usize,
    keepout: bool,
    outside_area: bool,
    area_border: bool,
    /// Keep-out polygons are outlined ([`draw_zone_borders`]; a mask keep-out is not).
    keepout_border: bool,
    /// The robot drove an approach to the work area.
    approach: bool,
}

fn shown(world: &World, trace: &Trace, crop: (usize, usize, usize, usize)) -> Shown {
    shown_with(world, trace, crop, &swept_pixels(world, trace))
}

/// [`shown`] with the swept pixels already computed.
fn shown_with(
    world: &World,
    trace: &Trace,
    crop: (usize, usize, usize, usize),
    swept: &fixedbitset::FixedBitSet,
) -> Shown {
    let f = *world.frame();
    let acc = world.accessible();
    let cells = world.true_map().cells();
    let mut s = Shown {
        area_border: world.zones().is_some_and(|z| !z.area_polygons.is_empty()),
        keepout_border: world
            .zones()
            .is_some_and(|z| !z.keepout_polygons.is_empty()),
        ..Shown::default()
    };
    let (c0, r0, w, h) = crop;
    if world.zones().is_some() {
        for r in r0..r0 + h {
            for c in c0..c0 + w {
                let i = f.index(c, r);
                match cells[i] {
                    Cell::Occupied => s.obstacle = true,
                    Cell::Unknown => s.unknown = true,
                    Cell::Free if zone_class(world, i) == 1 => s.keepout = true,
                    Cell::Free if zone_class(world, i) == 2 => {
                        if swept.contains(i) {
                            s.swept_outside_area = true;
                        } else {
                            s.outside_area = true;
                        }
                    }
                    Cell::Free => s.free_class(acc.contains(i), swept.contains(i)),
                }
            }
        }
    } else {
        shown_classes(&mut s, &f, cells, acc, swept, crop);
    }
    s.approach = approach_end(world, trace)
        .is_some_and(|(_, end)| world.initial_pose().position() != end.position());
    let mut in_bt = false;
    let mut regions = std::collections::BTreeSet::new();
    let mut region = 0u32;
    // The region last inserted: a region's poses follow one another, so most inserts repeat it.
    let mut inserted: Option<u32> = None;
    let mut last: Option<[f64; 2]> = None;
    // A move (a pose at another position than the one before) marks the backtracking or the
    // region in force; marking twice changes nothing. A move before the first region (bcd's
    // rim pass when its tour starts with one) is drawn but is no region: `metrics.json`
    // counts regions by their starts, and the legend's count must agree with it.
    let mut moved = |in_bt: bool, region: u32, s: &mut Shown| {
        if in_bt {
            s.backtrack = true;
        } else if s.regions_started > 0 && inserted != Some(region) {
            regions.insert(region);
            inserted = Some(region);
        }
    };
    let lattice = trace.lattice();
    for piece in trace.pieces() {
        match piece {
            Piece::Pose { pose, .. } => {
                let p = [pose.x, pose.y];
                if last.is_some_and(|l| l != p) {
                    moved(in_bt, region, &mut s);
                }
                last = Some(p);
                s.poses += 1;
            }
            Piece::Run(run) => {
                // A run whose ends differ holds a move; otherwise its poses are compared one
                // by one.
                let to = run.to(lattice);
                if run.from == to {
                    for (_, pose) in run.poses(lattice) {
                        let p = [pose.x, pose.y];
                        if last.is_some_and(|l| l != p) {
                            moved(in_bt, region, &mut s);
                        }
                        last = Some(p);
                    }
                } else {
                    moved(in_bt, region, &mut s);
                }
                last = Some(to);
                s.poses += run.n as usize;
            }
            Piece::Event { event, .. } => match event {
                Event::RegionStart { region: k } => {
                    region = *k;
                    s.regions_started += 1;
                }
                Event::BacktrackStart => in_bt = true,
                Event::BacktrackEnd => in_bt = false,
                Event::CriticalPoint { .. } => s.critical += 1,
                Event::StartPoint { .. } => s.restart += 1,
                Event::Collision { .. } => s.collisions += 1,
                _ => {}
            },
        }
    }
    s.regions = regions.len();
    s
}

impl Shown {
    /// Marks the class of a free pixel outside every zone.
    fn free_class(&mut self, accessible: bool, swept: bool) {
        match (accessible, swept) {
            (true, true) => self.swept = true,
            (true, false) => self.missed = true,
            (false, true) => self.swept_outside = true,
            (false, false) => self.unreachable = true,
        }
    }

    /// Whether every class a map without zones can show is already marked.
    fn all_classes(&self) -> bool {
        self.swept
            && self.missed
            && self.swept_outside
            && self.unreachable
            && self.obstacle
            && self.unknown
    }
}

/// `n <= usize::BITS` bits of `blocks` from bit `start` on, the first in the lowest bit (bits
/// past the end read 0).
fn bits_at(blocks: &[usize], start: usize, n: usize) -> usize {
    let b = usize::BITS as usize;
    let (k, off) = (start / b, start % b);
    let mut v = blocks.get(k).copied().unwrap_or(0) >> off;
    if off > 0 && off + n > b {
        v |= blocks.get(k + 1).copied().unwrap_or(0) << (b - off);
    }
    if n < b {
        v & ((1usize << n) - 1)
    } else {
        v
    }
}

/// The area classes of the pixels of `crop` on a map without zones, a machine word of pixels
/// at a time (the same flags as classifying pixel by pixel): the accessible pixels are all
/// free, so a word's free, accessible and swept masks give its classes. Stops once every
/// class is marked.
fn shown_classes(
    s: &mut Shown,
    f: &ccpp_core::grid::MapFrame,
    cells: &[Cell],
    acc: &fixedbitset::FixedBitSet,
    swept: &fixedbitset::FixedBitSet,
    crop: (usize, usize, usize, usize),
) {
    let b = usize::BITS as usize;
    let (c0, r0, w, h) = crop;
    let (acc, swept) = (acc.as_slice(), swept.as_slice());
    for r in r0..r0 + h {
        let start = f.index(c0, r);
        for (k, chunk) in cells[start..start + w].chunks(b).enumerate() {
            let at = start + k * b;
            let n = chunk.len();
            // Which cell kinds occur (bit = the kind's discriminant) and the free mask.
            let kinds = chunk.iter().fold(0u8, |m, c| m | (1u8 << (*c as u8)));
            s.obstacle |= kinds & (1 << Cell::Occupied as u8) != 0;
            s.unknown |= kinds & (1 << Cell::Unknown as u8) != 0;
            if kinds & (1 << Cell::Free as u8) != 0 {
                let free = chunk
                    .iter()
                    .enumerate()
                    .fold(0usize, |m, (j, c)| m | (usize::from(*c == Cell::Free) << j));
                let a = bits_at(acc, at, n) & free;
                let sw = bits_at(swept, at, n);
                let outside = free & !a;
                s.swept |= a & sw != 0;
                s.missed |= a & !sw != 0;
                s.swept_outside |= outside & sw != 0;
                s.unreachable |= outside & !sw != 0;
            }
        }
        if s.all_classes() {
            return;
        }
    }
}

/// Greedy wrap of `lines` (one line, or none) at size `px`: the first output line at most
/// `first_width` wide, the others at most `width`. Lines break between fields (runs of two
/// spaces, as in "planner on map  r=0.15 m"), inside a field at single spaces only when the
/// field alone is too wide; a single word wider than its line stays whole.
fn wrap_words(lines: &[String], first_width: f32, width: f32, px: f32) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    let fits = |text: &str, out: &Vec<String>| {
        let limit = if out.is_empty() { first_width } else { width };
        font::text_width(text, px) <= limit
    };
    for line in lines {
        let mut cur = String::new();
        for field in line.split("  ").filter(|f| !f.trim().is_empty()) {
            let field = field.trim();
            let joined = if cur.is_empty() {
                field.to_string()
            } else {
                format!("{cur}  {field}")
            };
            if fits(&joined, &out) {
                cur = joined;
                continue;
            }
            if !cur.is_empty() {
                out.push(std::mem::take(&mut cur));
                if fits(field, &out) {
                    cur = field.to_string();
                    continue;
                }
            }
            for word in field.split(' ').filter(|w| !w.is_empty()) {
                let joined = if cur.is_empty() {
                    word.to_string()
                } else {
                    format!("{cur} {word}")
                };
                if cur.is_empty() || fits(&joined, &out) {
                    cur = joined;
                } else {
                    out.push(std::mem::replace(&mut cur, word.to_string()));
                }
            }
        }
        out.push(cur);
    }
    out
}

fn plural(n: usize, one: &str, many: &str) -> String {
    if n == 1 {
        format!("{n} {one}")
    } else {
        format!("{n} {many}")
    }
}

/// The legend of a run's coverage picture: every area class and marker the picture shows,
/// with counts, in a fixed order.
pub fn legend_entries(world: &World, trace: &Trace) -> Vec<LegendEntry> {
    entries_of(&shown(world, trace, crop_box(world, trace)))
}

/// What one run's coverage picture shows, kept for a legend shared by several pictures
/// ([`legend_entries_union_of`]) without keeping the run's trace.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LegendShown(Shown);

impl LegendShown {
    /// What the picture of (`world`, `trace`) shows; `swept` must be
    /// [`swept_pixels`]`(world, trace)`.
    pub fn of(world: &World, trace: &Trace, swept: &fixedbitset::FixedBitSet) -> Self {
        Self(shown_with(world, trace, crop_box(world, trace), swept))
    }
}

/// The union of several runs' legends (for a grid of pictures sharing one legend), without
/// counts.
pub fn legend_entries_union(runs: &[(&World, &Trace)]) -> Vec<LegendEntry> {
    let shown: Vec<LegendShown> = runs
        .iter()
        .map(|(w, t)| LegendShown(shown(w, t, crop_box(w, t))))
        .collect();
    legend_entries_union_of(&shown)
}

/// [`legend_entries_union`] of what each run's picture shows.
pub fn legend_entries_union_of(runs: &[LegendShown]) -> Vec<LegendEntry> {
    let mut all = Shown::default();
    for LegendShown(s) in runs {
        all.swept |= s.swept;
        all.missed |= s.missed;
        all.swept_outside |= s.swept_outside;
        all.swept_outside_area |= s.swept_outside_area;
        all.unreachable |= s.unreachable;
        all.obstacle |= s.obstacle;
        all.unknown |= s.unknown;
        all.regions = all.regions.max(s.regions);
        all.regions_started = all.regions_started.max(s.regions_started);
        all.backtrack |= s.backtrack;
        all.critical = all.critical.max(s.critical.min(1));
        all.restart = all.restart.max(s.restart.min(1));
        all.collisions = all.collisions.max(s.collisions.min(1));
        all.poses = all.poses.max(s.poses);
        all.keepout |= s.keepout;
        all.outside_area |= s.outside_area;
        all.area_border |= s.area_border;
        all.keepout_border |= s.keepout_border;
        all.approach |= s.approach;
    }
    let mut e = entries_of(&all);
    // Counts differ per run: drop them from the shared legend.
    for x in &mut e {
        if let Some(k) = x.label.find(" (") {
            x.label.truncate(k);
        }
    }
    e
}

fn entries_of(s: &Shown) -> Vec<LegendEntry> {
    use colours as c;
    let mut e = Vec::new();
    let mut add = |on: bool, sw: Swatch, label: String| {
        if on {
            e.push(LegendEntry::new(sw, label));
        }
    };
    add(s.swept, Swatch::Fill(c::SWEPT), "swept floor".into());
    add(s.missed, Swatch::Fill(c::MISSED), "missed floor".into());
    add(
        s.swept_outside || s.swept_outside_area,
        Swatch::Fill(c::SWEPT_OUTSIDE),
        match (s.swept_outside, s.swept_outside_area) {
            (true, false) => "swept, outside reachable floor",
            (false, true) => "swept, outside the area",
            _ => "swept, outside the area or reachable floor",
        }
        .into(),
    );
    add(
        s.unreachable,
        Swatch::Fill(c::UNREACHABLE),
        "floor out of reach".into(),
    );
    add(s.obstacle, Swatch::Fill(c::OBSTACLE), "obstacle".into());
    add(s.unknown, Swatch::Fill(c::UNKNOWN), "unknown".into());
    add(
        s.keepout,
        Swatch::Hatched {
            fill: c::KEEPOUT,
            hatch: c::KEEPOUT_HATCH,
        },
        "keep-out zone (hatched)".into(),
    );
    add(
        s.outside_area,
        Swatch::Fill(c::OUTSIDE_AREA),
        "floor outside the area".into(),
    );
    add(
        s.area_border,
        Swatch::Line {
            rgb: c::AREA_BORDER,
            dashed: false,
        },
        "area border".into(),
    );
    add(
        s.keepout_border,
        Swatch::Line {
            rgb: c::KEEPOUT_HATCH,
            dashed: false,
        },
        "keep-out border".into(),
    );
    add(
        s.regions > 0,
        Swatch::Regions(PALETTE[..s.regions.clamp(1, 5)].to_vec()),
        if s.regions_started > s.regions && s.regions_started > 1 {
            // Said so that the count matches metrics.json's `regions`.
            let empty = s.regions_started - s.regions;
            format!(
                "path, one colour per region ({} regions, {} without a move)",
                s.regions_started, empty
            )
        } else if s.regions > 1 {
            format!("path, one colour per region ({} regions)", s.regions)
        } else {
            "path".into()
        },
    );
    add(
        s.approach,
        Swatch::Dotted(c::APPROACH),
        "approach to the area".into(),
    );
    add(
        s.backtrack,
        Swatch::Line {
            rgb: c::BACKTRACK,
            dashed: true,
        },
        "backtracking transfer".into(),
    );
    add(s.poses > 0, Swatch::Disc(c::START), "start".into());
    add(s.poses > 0, Swatch::Ring(c::END), "end".into());
    add(
        s.critical > 0,
        Swatch::Square(c::CRITICAL),
        format!("critical point ({})", s.critical),
    );
    add(
        s.restart > 0,
        Swatch::Ring(c::RESTART),
        format!("chosen restart point ({})", s.restart),
    );
    add(
        s.collisions > 0,
        Swatch::Cross(c::COLLISION),
        format!("collision ({})", s.collisions),
    );
    e
}

/// Effective coverage as the picture shows it: swept reachable pixels over reachable pixels.
fn effective_coverage(world: &World, swept: &fixedbitset::FixedBitSet) -> f64 {
    let acc = world.accessible();
    let hit = acc.intersection(swept).count();
    hit as f64 / world.accessible_count().max(1) as f64
}

/// A share (`0..=1`) as a percentage with one decimal, rounded *down*: a run that misses any
/// floor never reads "100.0%", and one just under a verdict threshold of
/// [`coverage_verdict_colour`] (0.79993 is red) never reads as the threshold ("80.0%").
pub fn percent(share: f64) -> String {
    if !share.is_finite() {
        return "-".to_string();
    }
    // The epsilon keeps shares that are exact in decimal (0.995) from flooring a step lower
    // through binary rounding (994.9999...).
    let tenths = (share * 1000.0 + 1e-6).floor().clamp(0.0, 1000.0);
    format!("{:.1}%", tenths / 10.0)
}

/// Least width (pixels) of a coverage picture (or [`CoverageStyle::min_width`] when smaller):
/// a map narrower than that on the canvas stands in its middle, with white either side, so
/// that the title and the legend keep a readable width.
const MIN_CANVAS_WIDTH: u32 = 480;

/// Least width (pixels) the title's first line keeps beside the header's badges; on a
/// narrower canvas the badges stand one per line above the title.
const MIN_TITLE_BESIDE_BADGES: f32 = 160.0;

/// Badge colour of an effective coverage: green from 95 %, amber from 80 %, red below.
pub fn coverage_verdict_colour(coverage: f64) -> [u8; 3] {
    if coverage >= 0.95 {
        [20, 130, 60]
    } else if coverage >= 0.80 {
        [200, 120, 0]
    } else {
        [200, 30, 30]
    }
}

/// Canvases of at least this many map pixels paint their background in bands on several
/// threads.
const BAND_MIN_PX: usize = 1 << 16;
/// At most this many background bands.
const MAX_BANDS: usize = 4;

/// Draws the coverage picture of a run.
///
/// # Errors
/// When the canvas cannot be allocated.
pub fn coverage_pixmap(
    world: &World,
    trace: &Trace,
    style: &CoverageStyle,
) -> Result<Pixmap, RenderError> {
    coverage_pixmap_swept(world, trace, style, &swept_pixels(world, trace))
}

/// [`coverage_pixmap`] with the swept pixels already computed (see [`coverage_png_swept`]).
///
/// # Errors
/// When the canvas cannot be allocated.
pub fn coverage_pixmap_swept(
    world: &World,
    trace: &Trace,
    style: &CoverageStyle,
    swept: &fixedbitset::FixedBitSet,
) -> Result<Pixmap, RenderError> {
    let frame = *world.frame();
    let crop = ccpp_io::phase::time("coverage.png crop", || crop_box(world, trace));
    let (col0, row0, cols, rows) = crop;
    let (w, h) = (cols as u32, rows as u32);
    let scale = if w < style.min_width {
        (style.min_width as f32 / w as f32).ceil().min(16.0)
    } else {
        1.0
    };
    let scale = scale.min(style.max_side as f32 / w.max(h) as f32).max(0.05);
    // The map's width on the canvas, and the canvas's: a map much taller than wide (a
    // corridor 9 px wide and 4000 long was drawn 7 px wide, its title and legend squeezed into
    // that) stands in the middle of a canvas at least [`MIN_CANVAS_WIDTH`] wide.
    let mw = ((w as f32 * scale).round() as u32).max(1);
    let cw = mw.max(MIN_CANVAS_WIDTH.min(style.min_width));
    let left = (cw - mw) / 2;
    let ch_map = ((h as f32 * scale).round() as u32).max(1);
    // Text sizes follow the canvas width (about 60 characters per line).
    let px = (cw as f32 / 62.0).clamp(13.0, 30.0).round();
    let title_px = (px * 1.25).round();
    let mut head = Chart::new(cw, 0);
    let mut header = 0u32;
    if !style.title.is_empty() {
        let mut y = 6.0f32;
        let cov = effective_coverage(world, swept);
        let collisions = trace
            .events()
            .filter(|(_, e)| matches!(e, Event::Collision { .. }))
            .count();
        // Badges, right-aligned on the first line; a run the simulator stopped says so first.
        let stopped = stop_reason(trace).map(|why| (format!("stopped: {why}"), colours::STOPPED));
        let badges = [
            (
                format!("{} covered", percent(cov)),
                coverage_verdict_colour(cov),
            ),
            (
                plural(collisions, "collision", "collisions"),
                if collisions == 0 {
                    [20, 130, 60]
                } else {
                    [200, 30, 30]
                },
            ),
        ];
        let warned = (!style.warnings.is_empty()).then(|| {
            (
                plural(style.warnings.len(), "warning", "warnings"),
                colours::WARNING,
            )
        });
        let badges: Vec<(String, [u8; 3])> =
            stopped.into_iter().chain(badges).chain(warned).collect();
        let mut bx = cw as f32 - 6.0;
        let widths: Vec<f32> = badges
            .iter()
            .map(|(text, _)| font::text_width(text, title_px) + 16.0)
            .collect();
        let in_a_row = widths.iter().sum::<f32>() + 8.0 * (widths.len() as f32 - 1.0);
        // Each badge's left edge, top line, width and type size.
        let mut placed: Vec<(f32, f32, f32, f32)> = Vec::with_capacity(badges.len());
        if in_a_row <= cw as f32 - 12.0 - MIN_TITLE_BESIDE_BADGES {
            // In a row, right-aligned beside the title.
            for tw in widths.iter().rev() {
                bx -= tw;
                placed.push((bx, y, *tw, title_px));
                bx -= 8.0;
            }
            placed.reverse();
        } else {
            // A canvas too narrow for the badges beside the title (a map a few pixels wide):
            // one badge per line, the title under them (they were drawn over each other and
            // over the title). A badge wider than the canvas is set in a smaller type that
            // fits (a 5 px wide map's read "99.1% co...").
            let room = cw as f32 - 4.0;
            for ((text, _), tw) in badges.iter().zip(&widths) {
                let (fpx, tw) = if *tw > room {
                    let f = (title_px * (room - 16.0) / (tw - 16.0)).floor().max(6.0);
                    (f, font::text_width(text, f) + 16.0)
                } else {
                    (title_px, *tw)
                };
                placed.push(((cw as f32 - 2.0 - tw).max(2.0), y, tw, fpx));
                y += font::line_height(fpx) + 8.0;
            }
        }
        for ((text, colour), &(x, top, tw, fpx)) in badges.iter().zip(&placed) {
            let bh = font::line_height(fpx) + 4.0;
            head.rect(x, top - 2.0, tw, bh, Some(*colour), None);
            head.text(
                x + 8.0,
                top + 1.0,
                fpx as u32,
                text.clone(),
                [255, 255, 255],
                chart::Anchor::Start,
            );
        }
        let bh = font::line_height(title_px) + 4.0;
        // The first title line wraps at spaces so that no word runs under the badges; its
        // continuation lines take the whole width.
        let first = style
            .title
            .first()
            .map_or(&[][..], |t| std::slice::from_ref(t));
        let wrapped = wrap_words(first, bx - 12.0, cw as f32 - 16.0, title_px);
        for (k, line) in wrapped.iter().enumerate() {
            head.text(
                8.0,
                y + 1.0,
                title_px as u32,
                line.clone(),
                [20, 20, 20],
                chart::Anchor::Start,
            );
            y += if k == 0 {
                bh + 4.0
            } else {
                font::line_height(title_px)
            };
        }
        // The other lines wrap at spaces too (on a canvas a few map pixels wide they ran off
        // its edge).
        let width = cw as f32 - 16.0;
        for line in wrap_words(&style.title[1.min(style.title.len())..], width, width, px) {
            head.text(8.0, y, px as u32, line, [20, 20, 20], chart::Anchor::Start);
            y += font::line_height(px);
        }
        // The first warning, in amber, whole (wrapped); the others are counted.
        if let Some(first) = style.warnings.first() {
            let more = style.warnings.len() - 1;
            let text = if more == 0 {
                format!("warning: {first}")
            } else {
                format!("warning: {first} (and {more} more: see the run's output)")
            };
            for line in wrap_words(&[text], width, width, px) {
                head.text(
                    8.0,
                    y,
                    px as u32,
                    line,
                    colours::WARNING,
                    chart::Anchor::Start,
                );
                y += font::line_height(px);
            }
        }
        header = (y + 6.0).ceil() as u32;
    }
    let mut foot = Chart::new(cw, 0);
    let legend_h = if style.legend {
        let entries = ccpp_io::phase::time("coverage.png shown", || {
            entries_of(&shown_with(world, trace, crop, swept))
        });
        let top = ch_map + header + 8;
        (foot.legend(8.0, top as f32, cw as f32 - 16.0, px as u32, &entries) + 8.0).ceil() as u32
    } else {
        0
    };
    let ch = ch_map + header + legend_h;
    let mut pm = Pixmap::new(cw, ch).ok_or(RenderError::Canvas(cw, ch))?;
    // White above and below the map; the map rows are all painted just below.
    {
        let row = cw as usize * 4;
        let (top, rest) = pm.data_mut().split_at_mut(header as usize * row);
        top.fill(u8::MAX);
        rest[ch_map as usize * row..].fill(u8::MAX);
    }

    // Background: classify each map pixel, then nearest-neighbour scale.
    let acc = world.accessible();
    let cells = world.true_map().cells();
    let colour_of = |i: usize, x: u32, y: u32| -> [u8; 3] {
        match cells[i] {
            Cell::Occupied => colours::OBSTACLE,
            Cell::Unknown => colours::UNKNOWN,
            Cell::Free if zone_class(world, i) == 1 => {
                // Diagonal hatching in canvas pixels, 3 of every 9 on.
                if (x + y) % 9 < 3 {
                    colours::KEEPOUT_HATCH
                } else {
                    colours::KEEPOUT
                }
            }
            Cell::Free if zone_class(world, i) == 2 => {
                // The approach sweeps floor outside the area: shown as swept.
                if swept.contains(i) {
                    colours::SWEPT_OUTSIDE
                } else {
                    colours::OUTSIDE_AREA
                }
            }
            Cell::Free => match (acc.contains(i), swept.contains(i)) {
                (true, true) => colours::SWEPT,
                (true, false) => colours::MISSED,
                (false, true) => colours::SWEPT_OUTSIDE,
                (false, false) => colours::UNREACHABLE,
            },
        }
    };
    ccpp_io::phase::time("coverage.png background", || {
        // The map column of each canvas column, computed once (same formula per pixel).
        let cols: Vec<usize> = (0..mw)
            .map(|x| (col0 + ((x as f32 + 0.5) / scale) as usize).min(frame.width - 1))
            .collect();
        // The map's bytes in a canvas row; white either side of a map narrower than the canvas.
        let (m0, m1) = (left as usize * 4, (left + mw) as usize * 4);
        let stride = cw as usize * 4;
        // Paints the canvas map rows `y0..` into `rows` (those rows, `stride` bytes each).
        let paint = |y0: u32, rows: &mut [u8]| {
            // A canvas row showing the same map row as the one above, without keep-out
            // hatching (which follows the canvas diagonal), is a copy of it.
            let mut above: Option<(usize, bool)> = None;
            for (y, line) in (y0..).zip(0..rows.len() / stride) {
                let row = ((y as f32 + 0.5) / scale) as usize;
                let row = (row0 + row).min(frame.height - 1);
                let o = line * stride;
                if above == Some((row, false)) {
                    rows.copy_within(o - stride..o, o);
                    continue;
                }
                let mut hatched = false;
                let out = &mut rows[o..o + stride];
                out[..m0].fill(u8::MAX);
                out[m1..].fill(u8::MAX);
                let out = &mut out[m0..m1];
                // The last map pixel classified and its colour, when it is not hatched (its
                // colour then depends on the pixel alone): the canvas pixels showing the same
                // map pixel next to it take that colour.
                let mut last: Option<(usize, [u8; 4])> = None;
                for ((x, &col), d) in (left..).zip(&cols).zip(out.chunks_exact_mut(4)) {
                    let i = frame.index(col, row);
                    if let Some((j, c)) = last {
                        if j == i {
                            d.copy_from_slice(&c);
                            continue;
                        }
                    }
                    let hatch = cells[i] == Cell::Free && zone_class(world, i) == 1;
                    hatched |= hatch;
                    let c = colour_of(i, x, y);
                    let c = [c[0], c[1], c[2], 255];
                    last = (!hatch).then_some((i, c));
                    d.copy_from_slice(&c);
                }
                above = Some((row, hatched));
            }
        };
        let map_rows = &mut pm.data_mut()[header as usize * stride..][..ch_map as usize * stride];
        // Horizontal bands on the machine's cores (each pixel's colour is a function of its
        // own position: the same bytes however the rows are split).
        let bands = if cw as usize * ch_map as usize >= BAND_MIN_PX {
            std::thread::available_parallelism().map_or(1, |n| n.get().min(MAX_BANDS))
        } else {
            1
        };
        let band_rows = (ch_map as usize).div_ceil(bands).max(1);
        std::thread::scope(|s| {
            let mut chunks = map_rows.chunks_mut(band_rows * stride).enumerate();
            let first = chunks.next();
            let others: Vec<_> = chunks
                .map(|(k, rows)| {
                    let paint = &paint;
                    s.spawn(move || paint((k * band_rows) as u32, rows))
                })
                .collect();
            if let Some((_, rows)) = first {
                paint(0, rows);
            }
            for h in others {
                if let Err(panic) = h.join() {
                    std::panic::resume_unwind(panic);
                }
            }
        });
    });
    let view = View {
        scale,
        height: frame.height as f64,
        left: left as f32,
        top: header as f32,
        col0: col0 as f64,
        row0: row0 as f64,
    };
    draw_zone_borders(&mut pm, world, view, (mw, ch_map));
    ccpp_io::phase::time("coverage.png path", || {
        draw_path(&mut pm, world, trace, view);
    });
    ccpp_io::phase::time("coverage.png markers", || {
        draw_markers(&mut pm, world, trace, view);
    });
    ccpp_io::phase::time("coverage.png text", || {
        head.draw_onto(&mut pm);
        foot.draw_onto(&mut pm);
    });
    Ok(pm)
}

/// Outlines of the area polygons (solid) and keep-out polygons (hatch colour), clipped to the
/// map's `mw` x `ch` picture below the header: a polygon reaching past the map's picture was
/// drawn over the title and the legend.
fn draw_zone_borders(pm: &mut Pixmap, world: &World, view: View, (mw, ch): (u32, u32)) {
    let Some(z) = world.zones() else { return };
    let width = (view.scale * 0.8).clamp(1.5, 4.0);
    let clip = Rect::from_xywh(view.left, view.top, mw as f32, ch as f32).and_then(|r| {
        let mut mask = tiny_skia::Mask::new(pm.width(), pm.height())?;
        mask.fill_path(
            &PathBuilder::from_rect(r),
            FillRule::Winding,
            false,
            Transform::identity(),
        );
        Some(mask)
    });
    // Edges are cut to the picture plus a margin wider than the stroke (a zone reaching 1e9 m
    // off the map made the rasterizer panic on its coordinates).
    let margin = f64::from(width) + 4.0;
    let lo = (f64::from(view.left) - margin, f64::from(view.top) - margin);
    let hi = (
        f64::from(view.left) + f64::from(mw) + margin,
        f64::from(view.top) + f64::from(ch) + margin,
    );
    for (polys, colour) in [
        (&z.area_polygons, colours::AREA_BORDER),
        (&z.keepout_polygons, colours::KEEPOUT_HATCH),
    ] {
        for poly in polys {
            let pts: Vec<(f64, f64)> = poly
                .ring()
                .iter()
                .map(|p| view.to_canvas_f64(world, *p))
                .collect();
            if let Some(path) = ring_path(&pts, (lo, hi)) {
                let stroke = Stroke {
                    width,
                    ..Stroke::default()
                };
                pm.stroke_path(
                    &path,
                    &paint(rgb(colour)),
                    &stroke,
                    Transform::identity(),
                    clip.as_ref(),
                );
            }
        }
    }
}

/// The closed ring `pts` (canvas coordinates) as a path of its parts inside the box `lo`-`hi`:
/// the whole ring, closed, when it lies inside; else each run of edges that stays inside as
/// one polyline (an edge crossing the box's side starts or ends one there). `None` when no
/// edge reaches the box.
fn ring_path(pts: &[(f64, f64)], (lo, hi): ((f64, f64), (f64, f64))) -> Option<tiny_skia::Path> {
    let n = pts.len();
    let mut pb = PathBuilder::new();
    let inside = |p: (f64, f64)| p.0 >= lo.0 && p.0 <= hi.0 && p.1 >= lo.1 && p.1 <= hi.1;
    if pts.iter().all(|&p| inside(p)) {
        for (k, &(x, y)) in pts.iter().enumerate() {
            if k == 0 {
                pb.move_to(x as f32, y as f32);
            } else {
                pb.line_to(x as f32, y as f32);
            }
        }
        pb.close();
        return pb.finish();
    }
    let mut end: Option<(f64, f64)> = None;
    for k in 0..n {
        let Some((a, b)) = replay::clip_segment(pts[k], pts[(k + 1) % n], lo, hi) else {
            end = None;
            continue;
        };
        if end != Some(a) {
            pb.move_to(a.0 as f32, a.1 as f32);
        }
        pb.line_to(b.0 as f32, b.1 as f32);
        end = Some(b);
    }
    pb.finish()
}

/// The entries of a trace with each straight run reduced to its first and last pose (what a
/// drawn polyline needs), each with the index of its pose among the trace's poses (an event:
/// the number of poses before it).
fn path_entries(trace: &Trace) -> impl Iterator<Item = (usize, Entry<'_>)> + '_ {
    let lattice = trace.lattice();
    let mut poses = 0usize;
    trace.pieces().flat_map(move |piece| {
        let pair = match piece {
            Piece::Pose { t, pose } => {
                poses += 1;
                [Some((poses - 1, Entry::Pose { t, pose })), None]
            }
            Piece::Event { t, event } => [Some((poses, Entry::Event { t, event })), None],
            Piece::Run(run) => {
                let [x, y] = run.to(lattice);
                let first = Entry::Pose {
                    t: run.t,
                    pose: ccpp_core::Pose::new(run.from[0], run.from[1], run.theta),
                };
                let last = Entry::Pose {
                    t: run.t + u64::from(run.n) - 1,
                    pose: ccpp_core::Pose::new(x, y, run.theta),
                };
                let n = run.n as usize;
                poses += n;
                [Some((poses - n, first)), Some((poses - 1, last))]
            }
        };
        pair.into_iter().flatten()
    })
}

/// How a stretch of the path is drawn: a region's colour, a backtracking transfer (dashed) or
/// the approach to the work area (dotted).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum PathStyle {
    Region(usize),
    Backtrack,
    Approach,
}

/// Most segments stroked as one path by [`draw_path`] (see there).
const STROKE_PIECE: usize = 2048;

fn draw_path(pm: &mut Pixmap, world: &World, trace: &Trace, view: View) {
    let width = (view.scale * 0.6).clamp(1.0, 3.0);
    let mut region = 0usize;
    let mut in_backtrack = false;
    // The approach (a start outside the area) ends at this step and pose.
    let mut approach = approach_end(world, trace);
    let mut last: Option<(f32, f32)> = None;
    // Collect runs of segments with the same style, then stroke each run once.
    let mut run: Vec<(f32, f32)> = Vec::new();
    let mut run_style = PathStyle::Region(0);
    let mut lanes = LaneBlitter::default();
    let mut stroke_run = |pm: &mut Pixmap, run: &[(f32, f32)], style: PathStyle| {
        if run.len() >= 2 {
            let mut stroke = Stroke {
                width,
                ..Stroke::default()
            };
            stroke.line_join = tiny_skia::LineJoin::Round;
            if let PathStyle::Region(k) = style {
                // A region's lanes: the axis-aligned segments (nearly all of a coverage path)
                // are filled with their exact area coverage, the others stroked.
                let colour = PALETTE[k.saturating_sub(1) % PALETTE.len()];
                if let Some(path) = lanes.draw(pm, run, width, colour) {
                    pm.stroke_path(
                        &path,
                        &paint(rgb(colour)),
                        &stroke,
                        Transform::identity(),
                        None,
                    );
                }
            } else {
                let mut pb = PathBuilder::new();
                pb.move_to(run[0].0, run[0].1);
                for &(x, y) in &run[1..] {
                    pb.line_to(x, y);
                }
                if let Some(path) = pb.finish() {
                    let casing = Stroke {
                        width: width * 2.0,
                        ..stroke.clone()
                    };
                    pm.stroke_path(
                        &path,
                        &paint(Color::WHITE),
                        &casing,
                        Transform::identity(),
                        None,
                    );
                    let (dash, colour) = if style == PathStyle::Approach {
                        (vec![width * 1.5, width * 1.5], colours::APPROACH)
                    } else {
                        (vec![width * 4.0, width * 3.0], colours::BACKTRACK)
                    };
                    stroke.dash = StrokeDash::new(dash, 0.0);
                    pm.stroke_path(
                        &path,
                        &paint(rgb(colour)),
                        &stroke,
                        Transform::identity(),
                        None,
                    );
                }
            }
        }
    };
    // A run is stroked in pieces of at most `STROKE_PIECE` points (each piece starting where
    // the last ended): one path's fill costs about the square of its segments where they
    // cross each other (a random-bounce run of 1e6 m drew for 200 s, 2e5 m for 11 s).
    let mut flush = |pm: &mut Pixmap, run: &mut Vec<(f32, f32)>, style: PathStyle| {
        let mut i = 0;
        while i + 1 < run.len() {
            let j = (i + STROKE_PIECE).min(run.len() - 1);
            stroke_run(pm, &run[i..=j], style);
            i = j;
        }
        run.clear();
    };
    let mut add = |pm: &mut Pixmap, p: (f32, f32), style: PathStyle| {
        if last == Some(p) {
            return;
        }
        if style != run_style {
            let keep = run.last().copied();
            flush(pm, &mut run, run_style);
            if let Some(k) = keep {
                run.push(k);
            }
            run_style = style;
        }
        if run.is_empty() {
            if let Some(l) = last {
                run.push(l);
            }
        }
        run.push(p);
        last = Some(p);
    };
    for (i, r) in path_entries(trace) {
        match r {
            Entry::Pose { pose, .. } => {
                if let Some((end_i, end)) = approach {
                    if i < end_i {
                        add(
                            pm,
                            view.to_canvas(world, pose.position()),
                            PathStyle::Approach,
                        );
                        continue;
                    }
                    // The approach's end (inside a straight run that goes on, it is no
                    // drawn pose of its own).
                    add(
                        pm,
                        view.to_canvas(world, end.position()),
                        PathStyle::Approach,
                    );
                    approach = None;
                }
                let style = if in_backtrack {
                    PathStyle::Backtrack
                } else {
                    PathStyle::Region(region)
                };
                add(pm, view.to_canvas(world, pose.position()), style);
            }
            Entry::Event { event, .. } => match event {
                Event::RegionStart { region: k } => region = *k as usize,
                Event::BacktrackStart => in_backtrack = true,
                Event::BacktrackEnd => in_backtrack = false,
                _ => {}
            },
        }
    }
    flush(pm, &mut run, run_style);
}

/// Draws the axis-aligned segments of a polyline stroke (a coverage path's lanes) as filled
/// rectangles with exact area coverage: what an antialiased stroke of the same width looks
/// like, at a fraction of the cost of stroking a polyline of thousands of turns. Consecutive
/// segments' rectangles abut (the corner square goes to the segment before the turn), so a
/// pixel's coverage is the sum of its parts, and each group of rectangles is blended once.
#[derive(Default)]
struct LaneBlitter {
    /// Coverage of the current group's bounding box, row-major.
    cov: Vec<f32>,
    /// The current group: `[x0, y0, x1, y1]` canvas rectangles.
    rects: Vec<[f32; 4]>,
    /// The group's bounding box `[x0, y0, x1, y1]`.
    bbox: [f32; 4],
    /// Scratch: the horizontal coverage of a rectangle's columns.
    fx: Vec<f32>,
    /// Scratch: the blend weight of each pixel of a row of the box.
    pixel_weight: Vec<u8>,
    /// Scratch: the blend weight of each byte of a row of the box.
    weight_row: Vec<u8>,
    /// Scratch: the colour of each byte of a row of the box.
    colour_row: Vec<u8>,
    /// Scratch: per row of the box, the columns `[lo, hi)` (box-relative) any rectangle
    /// touches; the pixels outside have no coverage and keep their colour.
    spans: Vec<(usize, usize)>,
}

/// Largest bounding box (pixels) of a group of lane rectangles blended at once.
const LANE_GROUP_PX: f32 = (1 << 18) as f32;

impl LaneBlitter {
    /// Fills the axis-aligned segments of `run` (butt ends at the run's two ends, square
    /// corners at its turns) in `colour`; returns the other segments as a path to stroke.
    fn draw(
        &mut self,
        pm: &mut Pixmap,
        run: &[(f32, f32)],
        width: f32,
        colour: [u8; 3],
    ) -> Option<tiny_skia::Path> {
        const AXIS_EPS: f32 = 1e-3;
        let h = width / 2.0;
        let mut pb = PathBuilder::new();
        let mut pen: Option<(f32, f32)> = None;
        let mut prev_axis = false;
        let n = run.len() - 1;
        for (k, w) in run.windows(2).enumerate() {
            let (a, b) = (w[0], w[1]);
            let horizontal = (a.1 - b.1).abs() < AXIS_EPS;
            let vertical = (a.0 - b.0).abs() < AXIS_EPS;
            if horizontal == vertical {
                // A diagonal (or a point): stroked.
                if pen != Some(a) {
                    pb.move_to(a.0, a.1);
                }
                pb.line_to(b.0, b.1);
                pen = Some(b);
                prev_axis = false;
                continue;
            }
            // Along the segment's axis: from `a` (pulled back over a diagonal's end, moved
            // past the corner square a previous lane filled) to `b` (past the corner).
            let (a0, b0, c) = if horizontal {
                (a.0, b.0, a.1)
            } else {
                (a.1, b.1, a.0)
            };
            let s = if b0 > a0 { 1.0 } else { -1.0 };
            let start = match (k, prev_axis) {
                (0, _) => a0,
                (_, true) => a0 + h * s,
                (_, false) => a0 - h * s,
            };
            let end = if k + 1 == n { b0 } else { b0 + h * s };
            prev_axis = true;
            if (end - start) * s <= 0.0 {
                continue;
            }
            let (lo, hi) = (start.min(end), start.max(end));
            let rect = if horizontal {
                [lo, c - h, hi, c + h]
            } else {
                [c - h, lo, c + h, hi]
            };
            self.push(pm, rect, colour);
        }
        self.blend(pm, colour);
        pb.finish()
    }

    /// Adds a rectangle to the group (blending the group first when the box would grow
    /// beyond [`LANE_GROUP_PX`]).
    fn push(&mut self, pm: &mut Pixmap, r: [f32; 4], colour: [u8; 3]) {
        let (w, h) = (pm.width() as f32, pm.height() as f32);
        let r = [r[0].max(0.0), r[1].max(0.0), r[2].min(w), r[3].min(h)];
        if r[0] >= r[2] || r[1] >= r[3] {
            return;
        }
        if !self.rects.is_empty() {
            let b = self.bbox;
            let u = [
                b[0].min(r[0]),
                b[1].min(r[1]),
                b[2].max(r[2]),
                b[3].max(r[3]),
            ];
            if (u[2] - u[0] + 2.0) * (u[3] - u[1] + 2.0) > LANE_GROUP_PX {
                self.blend(pm, colour);
            } else {
                self.bbox = u;
            }
        }
        if self.rects.is_empty() {
            self.bbox = r;
        }
        self.rects.push(r);
    }

    /// Blends the group's coverage in `colour` onto the canvas and empties the group.
    fn blend(&mut self, pm: &mut Pixmap, colour: [u8; 3]) {
        if self.rects.is_empty() {
            return;
        }
        let b = self.bbox;
        let (x0, y0) = (b[0].floor() as usize, b[1].floor() as usize);
        let (x1, y1) = (b[2].ceil() as usize, b[3].ceil() as usize);
        let bw = x1 - x0;
        self.cov.clear();
        self.cov.resize(bw * (y1 - y0), 0.0);
        self.spans.clear();
        self.spans.resize(y1 - y0, (usize::MAX, 0));
        for r in &self.rects {
            let (cx0, cx1) = (r[0].floor() as usize, r[2].ceil() as usize);
            for span in &mut self.spans[r[1].floor() as usize - y0..r[3].ceil() as usize - y0] {
                *span = (span.0.min(cx0 - x0), span.1.max(cx1 - x0));
            }
            // Each column's horizontal coverage, computed once for all the rows (same values).
            self.fx.clear();
            self.fx
                .extend((cx0..cx1).map(|px| r[2].min(px as f32 + 1.0) - r[0].max(px as f32)));
            for py in r[1].floor() as usize..r[3].ceil() as usize {
                let fy = r[3].min(py as f32 + 1.0) - r[1].max(py as f32);
                let row = &mut self.cov[(py - y0) * bw + cx0 - x0..][..cx1 - cx0];
                for (c, &fx) in row.iter_mut().zip(&self.fx) {
                    *c += fx * fy;
                }
            }
        }
        self.rects.clear();
        let stride = pm.width() as usize * 4;
        let data = pm.data_mut();
        // The colour of each byte of a row (the alpha byte's is never used: its weight is 0).
        self.colour_row.clear();
        self.colour_row
            .extend((0..bw).flat_map(|_| [colour[0], colour[1], colour[2], 0]));
        // The weight of each byte of a row: the alpha bytes weigh 0 (and keep their value).
        self.weight_row.clear();
        self.weight_row.resize(bw * 4, 0);
        for ((y, row), &(lo, hi)) in (y0..y1).zip(self.cov.chunks_exact(bw)).zip(&self.spans) {
            if lo >= hi {
                continue;
            }
            // Only the touched columns: a weight of 0 keeps a byte as it is.
            let row = &row[lo..hi];
            // Coverage in 1/255 steps (none at or below 0, all at or above 1), per pixel, then
            // per byte (`[w, w, w, 0]` in one store).
            self.pixel_weight.clear();
            self.pixel_weight
                .extend(row.iter().map(|&a| lane_weight(a)));
            let weights = &mut self.weight_row[..row.len() * 4];
            for (q, &w) in weights.chunks_exact_mut(4).zip(&self.pixel_weight) {
                q.copy_from_slice(&(u32::from(w) * 0x01_01_01).to_le_bytes());
            }
            let line = &mut data[y * stride + (x0 + lo) * 4..][..row.len() * 4];
            for ((d, &w), &c) in line.iter_mut().zip(&*weights).zip(&self.colour_row) {
                *d = blend_255(*d, c, w);
            }
        }
    }
}

/// A lane pixel's coverage `a` as a weight in 1/255 steps: 0 at or below 0, 255 at or above 1,
/// rounded to nearest between.
#[inline]
fn lane_weight(a: f32) -> u8 {
    // In (0, 1) the clamp keeps `a`; the product and sum are the unclamped ones.
    (a.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

/// `(d * (255 - w) + c * w) / 255` rounded to nearest: `d` at weight 0, `c` at 255. In 16 bits
/// (at most 255 * 255 + 127 before the division, which is exact as `(x + 1 + (x >> 8)) >> 8`
/// for every such `x`), so that a row of bytes blends in wide vector steps.
#[inline]
fn blend_255(d: u8, c: u8, w: u8) -> u8 {
    let (d, c, w) = (u16::from(d), u16::from(c), u16::from(w));
    let x = d * (255 - w) + c * w + 127;
    ((x + 1 + (x >> 8)) >> 8) as u8
}

/// Markers drawn per batch (see [`MarkerBatch`]).
const MARKER_BATCH: usize = 256;

/// Markers of one kind gathered into one path, drawn (filled, or stroked with `stroke`) every
/// [`MARKER_BATCH`] markers and at the end.
struct MarkerBatch {
    path: PathBuilder,
    n: usize,
    colour: [u8; 3],
    stroke: Option<Stroke>,
}

impl MarkerBatch {
    fn new(colour: [u8; 3], stroke: Option<Stroke>) -> Self {
        Self {
            path: PathBuilder::new(),
            n: 0,
            colour,
            stroke,
        }
    }

    /// Adds one marker (`shape` draws it into the path).
    fn add(&mut self, pm: &mut Pixmap, shape: impl FnOnce(&mut PathBuilder)) {
        shape(&mut self.path);
        self.n += 1;
        if self.n == MARKER_BATCH {
            self.flush(pm);
        }
    }

    fn flush(&mut self, pm: &mut Pixmap) {
        self.n = 0;
        let Some(path) = std::mem::take(&mut self.path).finish() else {
            return;
        };
        let p = paint(rgb(self.colour));
        match &self.stroke {
            Some(stroke) => pm.stroke_path(&path, &p, stroke, Transform::identity(), None),
            None => pm.fill_path(&path, &p, FillRule::Winding, Transform::identity(), None),
        }
    }

    fn draw(mut self, pm: &mut Pixmap) {
        self.flush(pm);
    }
}

fn draw_markers(pm: &mut Pixmap, world: &World, trace: &Trace, view: View) {
    let rad = (world.robot().radius / world.frame().resolution) as f32 * view.scale;
    let m = rad.clamp(3.0, 14.0);
    let stroke = Stroke {
        width: (m / 4.0).max(1.5),
        ..Stroke::default()
    };
    // The markers of one kind drawn a batch of [`MARKER_BATCH`] at a time, one path each
    // (critical squares, then restart circles, then collision crosses): thousands of markers
    // on a large map cost a few calls, and the stroker's outline stays small.
    let mut critical = MarkerBatch::new(colours::CRITICAL, None);
    let mut restart = MarkerBatch::new(colours::RESTART, Some(stroke.clone()));
    let mut collision = MarkerBatch::new(colours::COLLISION, Some(stroke.clone()));
    for (_, e) in trace.events() {
        match e {
            Event::CriticalPoint { x, y } => {
                let (cx, cy) = view.to_canvas(world, Point::new(*x, *y));
                if let Some(r) = Rect::from_xywh(cx - m * 0.4, cy - m * 0.4, m * 0.8, m * 0.8) {
                    critical.add(pm, |pb| pb.push_rect(r));
                }
            }
            Event::StartPoint { x, y } => {
                let (cx, cy) = view.to_canvas(world, Point::new(*x, *y));
                restart.add(pm, |pb| pb.push_circle(cx, cy, m * 0.6));
            }
            Event::Collision { x, y } => {
                let (cx, cy) = view.to_canvas(world, Point::new(*x, *y));
                collision.add(pm, |pb| {
                    pb.move_to(cx - m, cy - m);
                    pb.line_to(cx + m, cy + m);
                    pb.move_to(cx - m, cy + m);
                    pb.line_to(cx + m, cy - m);
                });
            }
            _ => {}
        }
    }
    for batch in [critical, restart, collision] {
        batch.draw(pm);
    }
    // Start and end.
    let s = world.initial_pose();
    let (sx, sy) = view.to_canvas(world, s.position());
    if let Some(c) = PathBuilder::from_circle(sx, sy, rad.max(4.0)) {
        pm.fill_path(
            &c,
            &paint(rgb(colours::START)),
            FillRule::Winding,
            Transform::identity(),
            None,
        );
    }
    // The heading in the picture: through the map's placement (an origin yaw turns the
    // image against the world), not the world angle drawn on the image's axes.
    let res = world.frame().resolution;
    let ahead = Point::new(s.x + res * s.theta.cos(), s.y + res * s.theta.sin());
    let (ax, ay) = view.to_canvas(world, ahead);
    let (dx, dy) = (ax - sx, ay - sy);
    let len = dx.hypot(dy);
    let (ux, uy) = if len > 0.0 && len.is_finite() {
        (dx / len, dy / len)
    } else {
        (s.theta.cos() as f32, -(s.theta.sin() as f32))
    };
    let mut pb = PathBuilder::new();
    pb.move_to(sx, sy);
    pb.line_to(sx + rad.max(4.0) * 1.6 * ux, sy + rad.max(4.0) * 1.6 * uy);
    if let Some(p) = pb.finish() {
        pm.stroke_path(
            &p,
            &paint(rgb([0, 100, 30])),
            &stroke,
            Transform::identity(),
            None,
        );
    }
    if let Some(end) = trace.last_position() {
        let (ex, ey) = view.to_canvas(world, end);
        if let Some(c) = PathBuilder::from_circle(ex, ey, rad.max(4.0)) {
            pm.stroke_path(
                &c,
                &paint(Color::BLACK),
                &stroke,
                Transform::identity(),
                None,
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ccpp_core::grid::{GridMap, MapFrame};
    use ccpp_core::world::Robot;
    use ccpp_core::Pose;

    /// A walled 120x80 room (0.05 m pixels) with a pillar; lanes over the first `lanes` rows,
    /// a backtracking transfer into a second region, and one marker of each kind.
    fn run(lanes: usize) -> (World, Trace) {
        let (w, h) = (120usize, 80usize);
        let mut cells = vec![Cell::Free; w * h];
        for r in 0..h {
            for c in 0..w {
                if r < 2
                    || c < 2
                    || r >= h - 2
                    || c >= w - 2
                    || ((50..70).contains(&c) && (30..50).contains(&r))
                {
                    cells[r * w + c] = Cell::Occupied;
                }
            }
        }
        for c in 0..10 {
            cells[c] = Cell::Unknown;
        }
        let map = GridMap::new(MapFrame::new(w, h, 0.05), cells).unwrap();
        let world = World::new(map, Robot::new(0.15), Some(Pose::new(0.3, 0.3, 0.0))).unwrap();
        let mut t = Trace::default();
        t.push_event(0, Event::RegionStart { region: 1 });
        let mut k = 0;
        for lane in 0..lanes {
            let y = 0.3 + lane as f64 * 0.3;
            if lane == lanes / 2 {
                t.push_event(k, Event::CriticalPoint { x: 5.6, y });
                t.push_event(k, Event::BacktrackStart);
                t.push_pose(k, Pose::new(0.3, y - 0.3, 0.0));
                k += 1;
                t.push_event(k, Event::BacktrackEnd);
                t.push_event(k, Event::StartPoint { x: 0.3, y });
                t.push_event(k, Event::RegionStart { region: 2 });
                t.push_event(k, Event::Collision { x: 2.0, y });
            }
            let (a, b) = if lane % 2 == 0 {
                (0.3, 5.6)
            } else {
                (5.6, 0.3)
            };
            t.push_pose(k, Pose::new(a, y, 0.0));
            t.push_pose(k + 1, Pose::new(b, y, 0.0));
            k += 2;
        }
        (world, t)
    }

    /// The picture as coarse characters: one per `step` pixels, by nearest known colour.
    fn dump(png: &[u8], cols: u32) -> String {
        let pm = Pixmap::decode_png(png).unwrap();
        let step = (pm.width() / cols).max(1);
        let known: [([u8; 3], char); 8] = [
            ([255, 255, 255], ' '),
            (colours::SWEPT, '.'),
            (colours::MISSED, 'x'),
            (colours::OBSTACLE, '#'),
            (colours::UNKNOWN, '?'),
            (colours::UNREACHABLE, 'o'),
            ([20, 130, 60], 'G'),
            ([200, 30, 30], 'R'),
        ];
        let mut s = format!("{}x{}\n", pm.width(), pm.height());
        for y in (step / 2..pm.height()).step_by(step as usize) {
            for x in (step / 2..pm.width()).step_by(step as usize) {
                let p = pm.pixel(x, y).unwrap();
                let c = [p.red(), p.green(), p.blue()];
                let d = |k: [u8; 3]| {
                    (0..3)
                        .map(|i| (i32::from(c[i]) - i32::from(k[i])).abs())
                        .max()
                        .unwrap()
                };
                let ch = known.iter().find(|(k, _)| d(*k) <= 12).map_or(
                    if c.iter().map(|&v| u32::from(v)).sum::<u32>() < 300 {
                        '*'
                    } else {
                        '+'
                    },
                    |x| x.1,
                );
                s.push(ch);
            }
            s.push('\n');
        }
        s
    }

    fn style() -> CoverageStyle {
        CoverageStyle {
            title: vec![
                "synthetic on room  r=0.15 m".into(),
                "effective coverage and friends".into(),
            ],
            ..CoverageStyle::default()
        }
    }

    /// The area classes found a word at a time are those of classifying pixel by pixel, for
    /// random maps, swept sets and crops (words cut anywhere).
    #[test]
    fn word_classes_match_pixel_classes() {
        let mut rng = ccpp_core::rng::SplitMix64::new(11);
        let mut checked = 0;
        for case in 0..60 {
            let (w, h) = (70 + case % 7 * 13, 20 + case % 5);
            let mut cells = vec![Cell::Free; w * h];
            for (i, c) in cells.iter_mut().enumerate() {
                let (x, y) = (i % w, i / w);
                let wall = x == 0 || y == 0 || x == w - 1 || y == h - 1;
                let u = rng.range(0.0, 1.0);
                *c = if wall || u < 0.04 * (case % 3) as f64 {
                    Cell::Occupied
                } else if case % 4 == 0 && u > 0.97 {
                    Cell::Unknown
                } else {
                    Cell::Free
                };
            }
            cells[(h - 2) * w + 1] = Cell::Free;
            let map = GridMap::new(MapFrame::new(w, h, 0.05), cells).unwrap();
            let Ok(world) = World::new(map, Robot::new(0.025), Some(Pose::new(0.075, 0.075, 0.0)))
            else {
                continue;
            };
            let mut swept = fixedbitset::FixedBitSet::with_capacity(w * h);
            for i in 0..w * h {
                if rng.range(0.0, 1.0) < [0.0, 0.5, 0.99][case % 3] {
                    swept.insert(i);
                }
            }
            let c0 = (rng.range(0.0, 1.0) * 30.0) as usize;
            let r0 = case % 3;
            let crop = (c0, r0, w - c0 - case % 11, h - r0 - case % 2);
            let mut by_words = Shown::default();
            shown_classes(
                &mut by_words,
                world.frame(),
                world.true_map().cells(),
                world.accessible(),
                &swept,
                crop,
            );
            let mut by_pixels = Shown::default();
            for r in crop.1..crop.1 + crop.3 {
                for c in crop.0..crop.0 + crop.2 {
                    let i = world.frame().index(c, r);
                    match world.true_map().cells()[i] {
                        Cell::Occupied => by_pixels.obstacle = true,
                        Cell::Unknown => by_pixels.unknown = true,
                        Cell::Free => {
                            by_pixels.free_class(world.accessible().contains(i), swept.contains(i));
                        }
                    }
                }
            }
            assert_eq!(by_words, by_pixels, "case {case}");
            checked += 1;
        }
        assert_eq!(checked, 60);
    }

    /// The room of [`run`] with a work area over its left part and a keep-out square in it,
    /// the start at `(5.0, 1.0)` outside the area: the simulator drives the approach, then a
    /// few lanes inside the area, and the run ends with `reason`.
    fn approach_run(reason: &str) -> (World, Trace) {
        use ccpp_core::zones::{Polygon, ZoneMasks};
        let (room, _) = run(1);
        let map = room.true_map().clone();
        let area = [Polygon::rect([0.1, 0.1, 2.4, 3.9])];
        let keepout = [Polygon::rect([1.0, 2.5, 1.6, 3.1])];
        let zones = ZoneMasks::new(map.frame(), Some(&area), &keepout, &[]);
        let world = World::with_zones(
            map,
            Robot::new(0.15),
            Some(Pose::new(5.0, 1.0, 0.0)),
            Some(zones),
        )
        .unwrap();
        assert!(
            !world.approach().is_empty(),
            "the start is outside the area"
        );
        let sim = ccpp_core::sim::Simulator::new(&world, &ccpp_core::sim::SimConfig::default());
        let mut t = sim.trace().clone();
        let s = world.start();
        t.push_event(1, Event::RegionStart { region: 1 });
        let mut k = 1;
        for lane in 0..4 {
            let y = s.y - f64::from(lane) * 0.3;
            let (a, b) = if lane % 2 == 0 {
                (s.x, 0.3)
            } else {
                (0.3, s.x)
            };
            t.push_pose(k, Pose::new(a, y, 0.0));
            t.push_pose(k + 1, Pose::new(b, y, 0.0));
            k += 2;
        }
        t.push_event(
            k,
            Event::Finished {
                reason: reason.into(),
            },
        );
        (world, t)
    }

    fn count_colour(pm: &Pixmap, rows: std::ops::Range<u32>, colour: [u8; 3]) -> usize {
        rows.flat_map(|y| (0..pm.width()).map(move |x| (x, y)))
            .filter(|&(x, y)| {
                let p = pm.pixel(x, y).unwrap();
                [p.red(), p.green(), p.blue()] == colour
            })
            .count()
    }

    /// A start outside the area: the approach is drawn as the approach (dotted, its own
    /// legend entry, not region 1's colour), the floor it swept shows as swept outside the
    /// area (it was painted as unswept floor outside the area), and the start marker is where
    /// the robot was placed.
    #[test]
    fn the_approach_to_the_area_is_drawn_and_its_swept_floor_shown() {
        let (world, trace) = approach_run("done");
        let labels: Vec<String> = legend_entries(&world, &trace)
            .into_iter()
            .map(|e| e.label)
            .collect();
        assert!(
            labels.iter().any(|l| l == "approach to the area"),
            "{labels:?}"
        );
        assert!(
            labels
                .iter()
                .any(|l| l.starts_with("swept, outside the area")),
            "{labels:?}"
        );
        let pm = coverage_pixmap(&world, &trace, &style()).unwrap();
        let all = 0..pm.height();
        assert!(count_colour(&pm, all.clone(), colours::SWEPT_OUTSIDE) > 500);
        assert!(count_colour(&pm, all.clone(), colours::APPROACH) > 20);
        // The approach's first stretch (from (5.0, 1.0)) is not in region 1's colour.
        let (end_i, end) = approach_end(&world, &trace).unwrap();
        assert!(end_i > 0);
        assert!((end.position().dist(world.start().position())) < 1e-9);
        assert!(world.initial_pose().position().dist(Point::new(5.0, 1.0)) < 1e-12);
        // The replay's start marker is the placed pose (it was the area entry point), and the
        // page knows where the approach ends.
        let data = replay::tests_support::data(&world, &trace);
        let f = world.frame();
        let (c0, r0, _, _) = crop_box(&world, &trace);
        let g = f.world_to_grid(Point::new(5.0, 1.0));
        let want = format!(
            r#""start":[{},{},0]"#,
            g.x - c0 as f64,
            f.height as f64 - g.y - r0 as f64
        );
        assert!(data.contains(&want), "{want} not in the page data");
        assert!(!data.contains(r#""approach":null"#));
    }

    /// An area polygon reaching past the map's picture was drawn over the title (and the
    /// legend): its border is clipped to the map's canvas.
    #[test]
    fn zone_borders_stay_on_the_map() {
        use ccpp_core::zones::{Polygon, ZoneMasks};
        let (room, trace) = run(1);
        let map = room.true_map().clone();
        // A triangle whose two long edges leave the map's top and go on far above it.
        let area = [Polygon {
            points: vec![[0.1, 0.1], [2.4, 0.1], [1.2, 60.0]],
            name: None,
        }];
        let zones = ZoneMasks::new(map.frame(), Some(&area), &[], &[]);
        let world = World::with_zones(map, Robot::new(0.15), None, Some(zones)).unwrap();
        let pm = coverage_pixmap(&world, &trace, &style()).unwrap();
        let header = 0..30;
        assert_eq!(count_colour(&pm, header, colours::AREA_BORDER), 0);
        assert!(count_colour(&pm, 0..pm.height(), colours::AREA_BORDER) > 50);
    }

    /// A keep-out reaching 1e9 m off the map is drawn cut to the picture (its coordinates
    /// made the rasterizer panic), its border where it crosses the map; the same keep-out
    /// within the map's reach draws the same pixels.
    #[test]
    fn a_zone_reaching_far_off_the_map_is_drawn_cut_to_the_picture() {
        use ccpp_core::zones::{Polygon, ZoneMasks};
        let (room, trace) = run(1);
        let drawn = |x0: f64| {
            let map = room.true_map().clone();
            let keepout = [Polygon {
                points: vec![[x0, 1.0], [1.0, 1.0], [1.0, 1.2], [x0, 1.2]],
                name: None,
            }];
            let zones = ZoneMasks::new(map.frame(), None, &keepout, &[]);
            let world = World::with_zones(map, Robot::new(0.15), None, Some(zones)).unwrap();
            let pm = coverage_pixmap(&world, &trace, &style()).unwrap();
            count_colour(&pm, 0..pm.height(), colours::KEEPOUT_HATCH)
        };
        let far = drawn(-1e9);
        assert!(far > 20, "{far} border pixels");
        assert_eq!(far, drawn(-50.0));
    }

    /// A run the simulator stopped says so in the header: one more red badge.
    #[test]
    fn a_stopped_run_says_so_in_the_header() {
        let header_red = |reason: &str| {
            let (world, trace) = approach_run(reason);
            let pm = coverage_pixmap(&world, &trace, &style()).unwrap();
            count_colour(&pm, 0..40, colours::STOPPED)
        };
        let (done, stalled) = (header_red("done"), header_red("stalled"));
        assert!(
            stalled > done + 200,
            "{done} vs {stalled} red header pixels"
        );
        let (_, trace) = approach_run("stalled");
        assert_eq!(stop_reason(&trace).as_deref(), Some("stalled"));
        let (_, trace) = approach_run("done");
        assert_eq!(stop_reason(&trace), None);
    }

    /// A run with warnings says so in the header: an amber badge counting them and the first
    /// one written out under the title, which grows by its lines (a run outside the building
    /// showed a green "99.5% covered" and nothing else).
    #[test]
    fn warnings_show_in_the_header() {
        let (world, trace) = approach_run("done");
        let plain = coverage_pixmap(&world, &trace, &style()).unwrap();
        let warned_style = CoverageStyle {
            warnings: vec![
                "the floor open to the robot from the start reaches the map's border".to_string(),
                "a second one".to_string(),
            ],
            ..style()
        };
        let warned = coverage_pixmap(&world, &trace, &warned_style).unwrap();
        assert_eq!(count_colour(&plain, 0..plain.height(), colours::WARNING), 0);
        let badge = count_colour(&warned, 0..40, colours::WARNING);
        assert!(badge > 200, "{badge} amber header pixels");
        assert!(
            warned.height() > plain.height(),
            "the warning line takes room"
        );
    }

    /// The keep-out's legend swatch is hatched like the zone (it was a solid square of the
    /// hatching colour).
    #[test]
    fn the_keepout_legend_swatch_is_hatched() {
        let (world, trace) = approach_run("done");
        let e = legend_entries(&world, &trace);
        let ko = e
            .iter()
            .find(|e| e.label == "keep-out zone (hatched)")
            .unwrap();
        assert_eq!(
            ko.swatch,
            Swatch::Hatched {
                fill: colours::KEEPOUT,
                hatch: colours::KEEPOUT_HATCH
            }
        );
    }

    /// On a canvas a few map pixels wide the header's badges stand one per line (they were
    /// drawn over each other and over the title, the hostile case a 9 x 77 px map).
    #[test]
    fn badges_of_a_narrow_map_do_not_overlap() {
        let map = GridMap::from_ascii_scaled("###\n#.#\n#.#\n#.#\n#.#\n###", 3, 0.01).unwrap();
        let world = World::new(map, Robot::new(0.01), Some(Pose::new(0.045, 0.045, 0.0))).unwrap();
        let mut trace = Trace::default();
        trace.push_pose(0, Pose::new(0.045, 0.045, 0.0));
        trace.push_pose(1, Pose::new(0.045, 0.06, 0.0));
        // A canvas this narrow takes a style asking for it (the default keeps 480 px).
        let narrow = CoverageStyle {
            min_width: 40,
            ..style()
        };
        let png = coverage_png(&world, &trace, &narrow).unwrap();
        let pm = Pixmap::decode_png(&png).unwrap();
        assert!(pm.width() < 100);
        let rows_of = |c: [u8; 3]| -> Vec<u32> {
            (0..pm.height())
                .filter(|&y| {
                    (0..pm.width()).any(|x| {
                        let p = pm.pixel(x, y).unwrap();
                        [p.red(), p.green(), p.blue()] == c
                    })
                })
                .collect()
        };
        let cov = rows_of(coverage_verdict_colour(effective_coverage(
            &world,
            &swept_pixels(&world, &trace),
        )));
        let ok = rows_of([20, 130, 60]);
        assert!(!cov.is_empty() && !ok.is_empty());
        assert!(cov.iter().all(|y| !ok.contains(y)), "badges share rows");
    }

    /// A map much taller than wide (a corridor 9 px by 4000 was drawn 7 px wide, its title and
    /// legend squeezed into that) stands in the middle of a canvas 480 px wide, white either
    /// side, with the path drawn where its floor is.
    #[test]
    fn a_narrow_map_stands_in_the_middle_of_a_readable_canvas() {
        let mut art = String::from("#####\n");
        for _ in 0..400 {
            art.push_str("#...#\n");
        }
        art.push_str("#####");
        let map = GridMap::from_ascii_scaled(&art, 1, 0.05).unwrap();
        let world = World::new(map, Robot::new(0.05), Some(Pose::new(0.125, 0.125, 0.0))).unwrap();
        let mut trace = Trace::default();
        trace.push_pose(0, Pose::new(0.125, 0.125, 0.0));
        trace.push_pose(1, Pose::new(0.125, 19.9, 0.0));
        let png = coverage_png(&world, &trace, &style()).unwrap();
        let pm = Pixmap::decode_png(&png).unwrap();
        assert_eq!(pm.width(), 480);
        // A map row halfway down: white, then the map (its walls and swept floor), then white,
        // symmetric about the middle.
        let y = pm.height() / 2;
        let rgb = |x: u32| {
            let p = pm.pixel(x, y).unwrap();
            [p.red(), p.green(), p.blue()]
        };
        let drawn: Vec<u32> = (0..pm.width())
            .filter(|&x| rgb(x) != [255, 255, 255])
            .collect();
        let (first, last) = (drawn[0], drawn[drawn.len() - 1]);
        assert!(first > 200 && last < 280, "map at columns {first}..={last}");
        // (an odd margin puts its extra column on the right)
        assert!(
            (first + last).abs_diff(pm.width() - 1) <= 1,
            "not centred: {first}..={last}"
        );
        assert!(
            (first..=last).any(|x| rgb(x) == colours::SWEPT),
            "no swept floor in the map"
        );
        assert!(
            (first..=last).all(|x| rgb(x) != [255, 255, 255]),
            "a white gap in the map"
        );
    }

    /// A keep-out polygon's outline is drawn, so the legend names it (the replay's did, the
    /// picture's did not); a run without zones has none.
    #[test]
    fn the_keepout_border_is_in_the_legend() {
        let (world, trace) = approach_run("done");
        let e = legend_entries(&world, &trace);
        let border = e.iter().find(|e| e.label == "keep-out border").unwrap();
        assert_eq!(
            border.swatch,
            Swatch::Line {
                rgb: colours::KEEPOUT_HATCH,
                dashed: false
            }
        );
        let (world, trace) = run(3);
        assert!(!legend_entries(&world, &trace)
            .iter()
            .any(|e| e.label.contains("keep-out")));
    }

    #[test]
    fn coverage_png_is_deterministic_and_matches_its_snapshot() {
        let (world, trace) = run(12);
        let a = coverage_png(&world, &trace, &style()).unwrap();
        let b = coverage_png(&world, &trace, &style()).unwrap();
        assert_eq!(a, b, "same inputs, same bytes");
        insta::assert_snapshot!("coverage_png_dump", dump(&a, 72));
    }

    #[test]
    fn no_region_colour_reads_as_a_red_marker() {
        // (the second region's path was [220, 50, 32], 23 from the keep-out hatching)
        let far = |a: [u8; 3], b: [u8; 3]| {
            let d: f64 = (0..3)
                .map(|k| (f64::from(a[k]) - f64::from(b[k])).powi(2))
                .sum();
            d.sqrt()
        };
        for p in PALETTE {
            for red in [colours::COLLISION, colours::KEEPOUT_HATCH, colours::STOPPED] {
                assert!(far(p, red) > 90.0, "{p:?} is close to {red:?}");
            }
            for q in PALETTE.iter().filter(|&&q| q != p) {
                assert!(far(p, *q) > 60.0, "{p:?} is close to {q:?}");
            }
            for m in [
                colours::START,
                colours::CRITICAL,
                colours::RESTART,
                colours::AREA_BORDER,
                colours::APPROACH,
            ] {
                assert!(far(p, m) > 60.0, "{p:?} is close to the marker {m:?}");
            }
        }
    }

    #[test]
    fn the_legend_lists_every_marker_and_colour_drawn_with_counts() {
        let (world, trace) = run(12);
        let labels: Vec<String> = legend_entries(&world, &trace)
            .into_iter()
            .map(|e| format!("{:?} {}", e.swatch, e.label))
            .collect();
        insta::assert_snapshot!("legend_entries", labels.join("\n"));
        // A run without backtracking or markers has no such entries.
        let (world, mut trace) = run(2);
        trace
            .retain_events(|e| !matches!(e, Event::Collision { .. } | Event::CriticalPoint { .. }));
        let labels: Vec<String> = legend_entries(&world, &trace)
            .into_iter()
            .map(|e| e.label)
            .collect();
        assert!(!labels
            .iter()
            .any(|l| l.starts_with("collision") || l.starts_with("critical")));
        assert!(labels.iter().any(|l| l == "missed floor"));
    }

    #[test]
    fn the_header_badge_is_green_for_a_good_run_and_red_for_a_bad_one() {
        let header_has = |lanes: usize, colour: [u8; 3]| {
            let (world, trace) = run(lanes);
            let pm = coverage_pixmap(&world, &trace, &style()).unwrap();
            (0..40).any(|y| {
                (0..pm.width()).any(|x| {
                    let p = pm.pixel(x, y).unwrap();
                    [p.red(), p.green(), p.blue()] == colour
                })
            })
        };
        assert!(header_has(2, [200, 30, 30]), "2 lanes: red coverage badge");
        assert!(!header_has(2, [200, 120, 0]), "2 lanes: no amber badge");
        assert!(
            header_has(12, [200, 120, 0]),
            "12 lanes (91 %): amber badge"
        );
        assert_eq!(coverage_verdict_colour(0.97), [20, 130, 60]);
        assert_eq!(coverage_verdict_colour(0.85), [200, 120, 0]);
        assert_eq!(coverage_verdict_colour(0.5), [200, 30, 30]);
    }

    #[test]
    fn percentages_round_down() {
        // The hostile tester's cases: red 0.79993 read "80.0%", 0.99992 read "100.0%".
        assert_eq!(percent(0.79993), "79.9%");
        assert_eq!(percent(0.99992), "99.9%");
        assert_eq!(percent(1.0), "100.0%");
        assert_eq!(percent(0.995), "99.5%");
        assert_eq!(percent(0.0), "0.0%");
        assert_eq!(percent(f64::NAN), "-");
        let (world, trace) = run(2);
        let labels: Vec<String> = legend_entries(&world, &trace)
            .into_iter()
            .map(|e| e.label)
            .collect();
        assert!(labels.iter().any(|l| l == "collision (1)"), "{labels:?}");
    }

    #[test]
    fn a_region_ended_without_a_move_is_counted_as_metrics_count_it() {
        let (world, mut trace) = run(12);
        let end = trace.len() as u64;
        trace.push_event(end, Event::RegionStart { region: 3 });
        trace.push_event(end, Event::RegionEnd { region: 3 });
        let labels: Vec<String> = legend_entries(&world, &trace)
            .into_iter()
            .map(|e| e.label)
            .collect();
        assert!(
            labels
                .iter()
                .any(|l| l == "path, one colour per region (3 regions, 1 without a move)"),
            "{labels:?}"
        );
        let (world, trace) = run(12);
        let labels: Vec<String> = legend_entries(&world, &trace)
            .into_iter()
            .map(|e| e.label)
            .collect();
        assert!(
            labels
                .iter()
                .any(|l| l == "path, one colour per region (2 regions)"),
            "{labels:?}"
        );
    }

    /// Moves before the first `RegionStart` (outside backtracking) are no region: the legend
    /// counts the regions `metrics.json` counts (bcd on `aws_bookstore` said 94 against 93).
    #[test]
    fn a_move_before_the_first_region_is_not_counted_as_a_region() {
        let (world, run_trace) = run(12);
        let mut trace = Trace::default();
        trace.push_pose(0, Pose::new(0.3, 0.3, 0.0));
        trace.push_pose(1, Pose::new(0.6, 0.3, 0.0));
        for r in run_trace.records() {
            trace.push(r);
        }
        let labels: Vec<String> = legend_entries(&world, &trace)
            .into_iter()
            .map(|e| e.label)
            .collect();
        assert!(
            labels
                .iter()
                .any(|l| l == "path, one colour per region (2 regions)"),
            "{labels:?}"
        );
    }

    #[test]
    fn a_long_title_wraps_between_fields_before_it_reaches_the_badges() {
        let px = 20.0;
        let line = "bsa-extended on aws_small_warehouse_002  r=0.15 m  tool=0.15 m".to_string();
        let whole = font::text_width(&line, px);
        // Room for everything: one line, unchanged.
        assert_eq!(
            wrap_words(std::slice::from_ref(&line), whole + 1.0, whole + 1.0, px),
            vec![line.clone()]
        );
        // Room on the first line for the first two fields only: the third moves down whole.
        let two = font::text_width("bsa-extended on aws_small_warehouse_002  r=0.15 m", px);
        let out = wrap_words(std::slice::from_ref(&line), two + 1.0, whole + 1.0, px);
        assert_eq!(
            out,
            vec![
                "bsa-extended on aws_small_warehouse_002  r=0.15 m".to_string(),
                "tool=0.15 m".to_string()
            ]
        );
        // A field wider than the line breaks at single spaces; every line fits its limit
        // unless it is a single word.
        let narrow = font::text_width("bsa-extended on", px) + 1.0;
        let out = wrap_words(std::slice::from_ref(&line), narrow, narrow, px);
        assert_eq!(out[0], "bsa-extended on");
        for l in &out {
            assert!(
                font::text_width(l, px) <= narrow || !l.contains(' '),
                "{out:?}"
            );
        }
        assert_eq!(out.join(" ").split_whitespace().count(), 7);
        assert!(wrap_words(&[], 10.0, 10.0, px).is_empty());
        // In the picture, a title that runs into the badges makes the header taller instead.
        let (world, trace) = run(12);
        let short = coverage_pixmap(&world, &trace, &style()).unwrap();
        let mut long = style();
        long.title[0] = format!("{} {}", long.title[0], "and a very long name ".repeat(4));
        let tall = coverage_pixmap(&world, &trace, &long).unwrap();
        assert!(
            tall.height() > short.height(),
            "{} vs {}",
            tall.height(),
            short.height()
        );
    }

    #[test]
    fn a_panel_style_picture_has_no_header_and_no_legend() {
        let (world, trace) = run(12);
        let full = coverage_pixmap(&world, &trace, &style()).unwrap();
        let bare = coverage_pixmap(
            &world,
            &trace,
            &CoverageStyle {
                legend: false,
                ..CoverageStyle::default()
            },
        )
        .unwrap();
        assert_eq!(full.width(), bare.width());
        assert!(bare.height() + 80 < full.height());
    }

    #[test]
    fn the_lane_blend_is_the_rounded_weighted_mean_for_every_byte_and_weight() {
        for w in 0..=255u32 {
            for d in 0..=255u32 {
                for c in [0u32, 1, 30, 127, 128, 200, 254, 255] {
                    let want = (d * (255 - w) + c * w + 127) / 255;
                    assert_eq!(u32::from(blend_255(d as u8, c as u8, w as u8)), want);
                }
            }
        }
    }

    #[test]
    fn a_lane_weight_is_none_at_or_below_zero_all_at_or_above_one_and_rounded_between() {
        assert_eq!(lane_weight(-0.25), 0);
        assert_eq!(lane_weight(0.0), 0);
        assert_eq!(lane_weight(1.0), 255);
        assert_eq!(lane_weight(1.75), 255);
        assert_eq!(lane_weight(0.5), 128);
        assert_eq!(lane_weight(0.4), 102);
        assert_eq!(lane_weight(0.001), 0);
        assert_eq!(lane_weight(0.999), 255);
    }

    #[test]
    fn an_opaque_picture_encodes_as_its_rgb_bytes_row_by_row() {
        // Odd width: each row's last pixel is copied into the spare byte of the row buffer.
        let (w, h) = (5u32, 3u32);
        let mut pm = Pixmap::new(w, h).unwrap();
        for (k, p) in pm.data_mut().chunks_exact_mut(4).enumerate() {
            let k = k as u8;
            p.copy_from_slice(&[k, k.wrapping_mul(7), k.wrapping_mul(31), u8::MAX]);
        }
        let bytes = encode_png(&pm).unwrap();
        let mut dec = png::Decoder::new(std::io::Cursor::new(bytes))
            .read_info()
            .unwrap();
        let mut buf = vec![0u8; dec.output_buffer_size().unwrap()];
        let info = dec.next_frame(&mut buf).unwrap();
        assert_eq!(info.color_type, png::ColorType::Rgb);
        let want: Vec<u8> = pm
            .data()
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect();
        assert_eq!(&buf[..info.buffer_size()], &want[..]);
        // One pixel not opaque, in the last row (found after the rows above were encoded as
        // RGB) or the first: the picture keeps its alpha channel.
        for at in [(w * h - 1) as usize * 4, 4] {
            pm.data_mut()[at + 3] = 128;
            pm.data_mut()[at..at + 3].fill(0);
            let bytes = encode_png(&pm).unwrap();
            let mut dec = png::Decoder::new(std::io::Cursor::new(bytes))
                .read_info()
                .unwrap();
            assert_eq!(dec.info().color_type, png::ColorType::Rgba);
            let mut buf = vec![0u8; dec.output_buffer_size().unwrap()];
            let info = dec.next_frame(&mut buf).unwrap();
            assert_eq!(buf[..info.buffer_size()][at + 3], 128);
        }
    }
}

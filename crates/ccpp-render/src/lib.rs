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
//!   backtracking transfers dashed dark grey;
//! - start: green disk; critical points: orange squares; chosen start points: purple rings;
//!   collisions: red crosses; final pose: black ring.

pub mod chart;
mod font;
pub mod replay;
pub mod run_files;

use ccpp_core::grid::Cell;
use ccpp_core::metrics::swept_pixels;
use ccpp_core::trace::{Event, Record, Trace};
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
    /// it; large maps are drawn 1:1 or scaled down to `max_side`).
    pub min_width: u32,
    /// Largest canvas side.
    pub max_side: u32,
    /// Title printed in the header (planner, map, figures).
    pub title: Vec<String>,
}

impl Default for CoverageStyle {
    fn default() -> Self {
        Self {
            min_width: 900,
            max_side: 3000,
            title: Vec::new(),
        }
    }
}

/// Region colours (colour-blind-friendly-ish, distinct on light blue).
const PALETTE: [[u8; 3]; 10] = [
    [0, 90, 181],
    [220, 50, 32],
    [0, 140, 70],
    [150, 60, 170],
    [230, 130, 0],
    [0, 150, 160],
    [170, 110, 40],
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
    top: f32,
    col0: f64,
    row0: f64,
}

impl View {
    fn to_canvas(self, world: &World, p: Point) -> (f32, f32) {
        let g = world.frame().world_to_grid(p);
        (
            ((g.x - self.col0) as f32) * self.scale,
            ((self.height - g.y - self.row0) as f32) * self.scale + self.top,
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
    for (i, cell) in world.map().cells().iter().enumerate() {
        if *cell != Cell::Unknown {
            add(i % f.width, i / f.width);
        }
    }
    for p in trace.poses() {
        if let Some((c, r)) = f.pixel_of(p.position()) {
            add(c, r);
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
    pixmap
        .encode_png()
        .map_err(|e| RenderError::Encode(e.to_string()))
}

/// Draws the coverage picture of a run.
///
/// # Errors
/// When the canvas cannot be allocated.
pub fn coverage_pixmap(
    world: &World,
    trace: &Trace,
    style: &CoverageStyle,
) -> Result<Pixmap, RenderError> {
    let frame = *world.frame();
    let (col0, row0, cols, rows) = crop_box(world, trace);
    let (w, h) = (cols as u32, rows as u32);
    let scale = if w < style.min_width {
        (style.min_width as f32 / w as f32).ceil().min(16.0)
    } else {
        1.0
    };
    let scale = scale.min(style.max_side as f32 / w.max(h) as f32).max(0.05);
    let cw = ((w as f32 * scale).round() as u32).max(1);
    let ch_map = ((h as f32 * scale).round() as u32).max(1);
    let line_h = font::GLYPH_H * text_scale(cw) + 4;
    let header = if style.title.is_empty() {
        0
    } else {
        line_h * style.title.len() as u32 + 6
    };
    let legend = line_h + 8;
    let ch = ch_map + header + legend;
    let mut pm = Pixmap::new(cw, ch).ok_or(RenderError::Canvas(cw, ch))?;
    pm.fill(Color::WHITE);

    // Background: classify each map pixel, then nearest-neighbour scale.
    let swept = swept_pixels(world, trace);
    let acc = world.accessible();
    let cells = world.map().cells();
    let colour_of = |i: usize| -> [u8; 3] {
        match cells[i] {
            Cell::Occupied => [30, 30, 30],
            Cell::Unknown => [170, 170, 170],
            Cell::Free => {
                if acc.contains(i) {
                    if swept.contains(i) {
                        [170, 215, 250]
                    } else {
                        [250, 150, 130]
                    }
                } else if swept.contains(i) {
                    [200, 225, 245]
                } else {
                    [246, 246, 242]
                }
            }
        }
    };
    {
        let data = pm.data_mut();
        for y in 0..ch_map {
            let row = ((y as f32 + 0.5) / scale) as usize;
            let row = (row0 + row).min(frame.height - 1);
            for x in 0..cw {
                let col = (col0 + ((x as f32 + 0.5) / scale) as usize).min(frame.width - 1);
                let c = colour_of(frame.index(col, row));
                let o = (((y + header) * cw + x) * 4) as usize;
                data[o] = c[0];
                data[o + 1] = c[1];
                data[o + 2] = c[2];
                data[o + 3] = 255;
            }
        }
    }
    let view = View {
        scale,
        height: frame.height as f64,
        top: header as f32,
        col0: col0 as f64,
        row0: row0 as f64,
    };
    draw_path(&mut pm, world, trace, view);
    draw_markers(&mut pm, world, trace, view);

    // Header and legend text.
    let ts = text_scale(cw);
    for (k, line) in style.title.iter().enumerate() {
        font::draw_text(&mut pm, 6, 4 + k as u32 * line_h, ts, line, [20, 20, 20]);
    }
    draw_legend(&mut pm, ch_map + header + 4, ts);
    Ok(pm)
}

fn text_scale(canvas_width: u32) -> u32 {
    (canvas_width / 450).clamp(1, 4)
}

fn draw_legend(pm: &mut Pixmap, y: u32, ts: u32) {
    let items: [([u8; 3], &str); 6] = [
        ([170, 215, 250], "SWEPT"),
        ([250, 150, 130], "MISSED"),
        ([246, 246, 242], "UNREACHABLE"),
        ([30, 30, 30], "OBSTACLE"),
        ([170, 170, 170], "UNKNOWN"),
        ([60, 60, 60], "BACKTRACK (DASHED)"),
    ];
    let mut x = 6u32;
    let box_side = font::GLYPH_H * ts;
    for (c, label) in items {
        if let Some(r) = Rect::from_xywh(x as f32, y as f32, box_side as f32, box_side as f32) {
            pm.fill_rect(r, &paint(rgb(c)), Transform::identity(), None);
            let border = PathBuilder::from_rect(r);
            pm.stroke_path(
                &border,
                &paint(rgb([80, 80, 80])),
                &Stroke::default(),
                Transform::identity(),
                None,
            );
        }
        x += box_side + 4;
        x = font::draw_text(pm, x, y, ts, label, [20, 20, 20]) + 12;
    }
}

fn draw_path(pm: &mut Pixmap, world: &World, trace: &Trace, view: View) {
    let width = (view.scale * 0.6).clamp(1.0, 3.0);
    let mut region = 0usize;
    let mut in_backtrack = false;
    let mut last: Option<(f32, f32)> = None;
    // Collect runs of segments with the same style, then stroke each run once.
    let mut run: Vec<(f32, f32)> = Vec::new();
    let mut run_style = (0usize, false);
    let flush = |pm: &mut Pixmap, run: &mut Vec<(f32, f32)>, style: (usize, bool)| {
        if run.len() >= 2 {
            let mut pb = PathBuilder::new();
            pb.move_to(run[0].0, run[0].1);
            for &(x, y) in &run[1..] {
                pb.line_to(x, y);
            }
            if let Some(path) = pb.finish() {
                let mut stroke = Stroke {
                    width,
                    ..Stroke::default()
                };
                stroke.line_join = tiny_skia::LineJoin::Round;
                let colour = if style.1 {
                    stroke.dash = StrokeDash::new(vec![width * 4.0, width * 3.0], 0.0);
                    rgb([60, 60, 60])
                } else {
                    rgb(PALETTE[style.0.saturating_sub(1) % PALETTE.len()])
                };
                pm.stroke_path(&path, &paint(colour), &stroke, Transform::identity(), None);
            }
        }
        run.clear();
    };
    for r in &trace.records {
        match r {
            Record::Pose { pose, .. } => {
                let p = view.to_canvas(world, Point::new(pose[0], pose[1]));
                if last == Some(p) {
                    continue;
                }
                let style = (region, in_backtrack);
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
            }
            Record::Event { event, .. } => match event {
                Event::RegionStart { region: k } => region = *k as usize,
                Event::BacktrackStart => in_backtrack = true,
                Event::BacktrackEnd => in_backtrack = false,
                _ => {}
            },
        }
    }
    flush(pm, &mut run, run_style);
}

fn draw_markers(pm: &mut Pixmap, world: &World, trace: &Trace, view: View) {
    let rad = (world.robot().radius / world.frame().resolution) as f32 * view.scale;
    let m = rad.clamp(3.0, 14.0);
    let stroke = Stroke {
        width: (m / 4.0).max(1.5),
        ..Stroke::default()
    };
    for (_, e) in trace.events() {
        match e {
            Event::CriticalPoint { x, y } => {
                let (cx, cy) = view.to_canvas(world, Point::new(*x, *y));
                if let Some(r) = Rect::from_xywh(cx - m * 0.4, cy - m * 0.4, m * 0.8, m * 0.8) {
                    pm.fill_rect(r, &paint(rgb([240, 140, 0])), Transform::identity(), None);
                }
            }
            Event::StartPoint { x, y } => {
                let (cx, cy) = view.to_canvas(world, Point::new(*x, *y));
                if let Some(c) = PathBuilder::from_circle(cx, cy, m * 0.6) {
                    pm.stroke_path(
                        &c,
                        &paint(rgb([130, 40, 160])),
                        &stroke,
                        Transform::identity(),
                        None,
                    );
                }
            }
            Event::Collision { x, y } => {
                let (cx, cy) = view.to_canvas(world, Point::new(*x, *y));
                let mut pb = PathBuilder::new();
                pb.move_to(cx - m, cy - m);
                pb.line_to(cx + m, cy + m);
                pb.move_to(cx - m, cy + m);
                pb.line_to(cx + m, cy - m);
                if let Some(p) = pb.finish() {
                    pm.stroke_path(
                        &p,
                        &paint(rgb([230, 0, 0])),
                        &stroke,
                        Transform::identity(),
                        None,
                    );
                }
            }
            _ => {}
        }
    }
    // Start and end.
    let s = world.start();
    let (sx, sy) = view.to_canvas(world, s.position());
    if let Some(c) = PathBuilder::from_circle(sx, sy, rad.max(4.0)) {
        pm.fill_path(
            &c,
            &paint(rgb([0, 170, 60])),
            FillRule::Winding,
            Transform::identity(),
            None,
        );
    }
    let mut pb = PathBuilder::new();
    pb.move_to(sx, sy);
    pb.line_to(
        sx + rad.max(4.0) * 1.6 * s.theta.cos() as f32,
        sy - rad.max(4.0) * 1.6 * s.theta.sin() as f32,
    );
    if let Some(p) = pb.finish() {
        pm.stroke_path(
            &p,
            &paint(rgb([0, 100, 30])),
            &stroke,
            Transform::identity(),
            None,
        );
    }
    if let Some(end) = trace.poses().last() {
        let (ex, ey) = view.to_canvas(world, end.position());
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

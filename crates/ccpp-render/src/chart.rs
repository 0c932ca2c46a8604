//! Small charts described once and drawn twice: as SVG text and as a PNG (tiny-skia + the
//! embedded `DejaVu Sans` font), so both files always show the same thing.

use std::fmt::Write as _;

use base64::Engine as _;
use tiny_skia::{
    Color, FillRule, Paint, PathBuilder, Pixmap, PixmapPaint, Rect, Stroke, StrokeDash, Transform,
};

use crate::font;
use crate::RenderError;

/// Series colours.
pub const SERIES: [[u8; 3]; 8] = [
    [0, 114, 178],
    [213, 94, 0],
    [0, 158, 115],
    [204, 121, 167],
    [230, 159, 0],
    [86, 180, 233],
    [120, 120, 120],
    [150, 40, 40],
];

/// Text anchor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Anchor {
    /// Left-aligned at x.
    Start,
    /// Centred on x.
    Middle,
    /// Right-aligned at x.
    End,
}

#[derive(Clone, Debug)]
enum Shape {
    Line {
        pts: Vec<(f32, f32)>,
        rgb: [u8; 3],
        width: f32,
        dashed: bool,
        cased: bool,
    },
    Circle {
        cx: f32,
        cy: f32,
        r: f32,
        fill: Option<[u8; 3]>,
        stroke: Option<[u8; 3]>,
        width: f32,
    },
    Rect {
        x: f32,
        y: f32,
        w: f32,
        h: f32,
        fill: Option<[u8; 3]>,
        stroke: Option<[u8; 3]>,
    },
    Text {
        x: f32,
        y: f32,
        px: u32,
        text: String,
        rgb: [u8; 3],
        anchor: Anchor,
    },
    Image {
        x: f32,
        y: f32,
        w: f32,
        h: f32,
        png: Vec<u8>,
    },
}

/// A chart: a canvas size and shapes in drawing order (y down, pixels).
#[derive(Clone, Debug, Default)]
pub struct Chart {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    shapes: Vec<Shape>,
}

impl Chart {
    /// An empty chart.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            shapes: Vec::new(),
        }
    }

    /// A polyline.
    pub fn line(&mut self, pts: Vec<(f32, f32)>, rgb: [u8; 3], width: f32, dashed: bool) {
        self.shapes.push(Shape::Line {
            pts,
            rgb,
            width,
            dashed,
            cased: false,
        });
    }

    /// A polyline drawn over a white casing twice its width (dashed backtracking transfers:
    /// the white gaps keep them apart from solid dark obstacles).
    pub fn line_cased(&mut self, pts: Vec<(f32, f32)>, rgb: [u8; 3], width: f32, dashed: bool) {
        self.shapes.push(Shape::Line {
            pts,
            rgb,
            width,
            dashed,
            cased: true,
        });
    }

    /// A circle, filled and/or stroked (`width` is the stroke width).
    pub fn circle(
        &mut self,
        cx: f32,
        cy: f32,
        r: f32,
        fill: Option<[u8; 3]>,
        stroke: Option<[u8; 3]>,
        width: f32,
    ) {
        self.shapes.push(Shape::Circle {
            cx,
            cy,
            r,
            fill,
            stroke,
            width,
        });
    }

    /// Lays out a legend from `(x, y)`, wrapping at `x + width`, with text of size `px`;
    /// returns its height.
    pub fn legend(&mut self, x: f32, y: f32, width: f32, px: u32, entries: &[LegendEntry]) -> f32 {
        let pxf = px as f32;
        let s = (pxf * 1.1).round();
        let row_h = (pxf * 1.6).round();
        let (mut cx, mut cy) = (x, y);
        for e in entries {
            let item_w = s * 1.6 + 5.0 + font::text_width(&e.label, pxf);
            if cx > x && cx + item_w > x + width {
                cx = x;
                cy += row_h;
            }
            let (sx, sy) = (cx, cy + (row_h - s) / 2.0 - pxf * 0.15);
            let (mx, my) = (sx + s * 0.8, sy + s / 2.0);
            match &e.swatch {
                Swatch::Fill(c) => {
                    self.rect(sx + s * 0.3, sy, s, s, Some(*c), Some([90, 90, 90]));
                }
                Swatch::Hatched { fill, hatch } => {
                    let (a, b) = (sx + s * 0.3, sy);
                    self.rect(a, b, s, s, Some(*fill), None);
                    // Diagonals x + y = c (up to the right, as the map's hatching), clipped
                    // to the square.
                    for k in 1..6 {
                        let c = a + b + 2.0 * s * k as f32 / 6.0;
                        let x0 = a.max(c - (b + s));
                        let x1 = (a + s).min(c - b);
                        self.line(
                            vec![(x0, c - x0), (x1, c - x1)],
                            *hatch,
                            (s / 8.0).max(1.5),
                            false,
                        );
                    }
                    self.rect(a, b, s, s, None, Some([90, 90, 90]));
                }
                Swatch::Dotted(c) => {
                    let w = (s / 6.0).max(2.0);
                    self.line(
                        vec![(sx, my), (sx + s * 1.6, my)],
                        [255, 255, 255],
                        2.0 * w,
                        false,
                    );
                    let n = 5;
                    for k in 0..n {
                        let a = sx + s * 1.6 * (2 * k) as f32 / (2 * n - 1) as f32;
                        let b = sx + s * 1.6 * (2 * k + 1) as f32 / (2 * n - 1) as f32;
                        self.line(vec![(a, my), (b, my)], *c, w, false);
                    }
                }
                Swatch::Line { rgb, dashed } => {
                    let pts = vec![(sx, my), (sx + s * 1.6, my)];
                    if *dashed {
                        self.line_cased(pts, *rgb, (s / 6.0).max(2.0), true);
                    } else {
                        self.line(pts, *rgb, (s / 6.0).max(2.0), false);
                    }
                }
                Swatch::Regions(cs) => {
                    let n = cs.len().max(1) as f32;
                    for (k, c) in cs.iter().enumerate() {
                        let a = sx + s * 1.6 * k as f32 / n;
                        self.line(
                            vec![(a, my), (a + s * 1.6 / n, my)],
                            *c,
                            (s / 4.0).max(2.0),
                            false,
                        );
                    }
                }
                Swatch::Disc(c) => self.circle(mx, my, s * 0.45, Some(*c), None, 1.0),
                Swatch::Ring(c) => {
                    self.circle(mx, my, s * 0.4, None, Some(*c), (s / 7.0).max(1.5));
                }
                Swatch::Square(c) => {
                    self.rect(
                        mx - s * 0.35,
                        my - s * 0.35,
                        s * 0.7,
                        s * 0.7,
                        Some(*c),
                        None,
                    );
                }
                Swatch::Cross(c) => {
                    let d = s * 0.38;
                    let w = (s / 7.0).max(1.5);
                    self.line(vec![(mx - d, my - d), (mx + d, my + d)], *c, w, false);
                    self.line(vec![(mx - d, my + d), (mx + d, my - d)], *c, w, false);
                }
            }
            let tx = sx + s * 1.6 + 5.0;
            self.text(
                tx,
                cy + (row_h - pxf * 1.2) / 2.0,
                px,
                e.label.clone(),
                [25, 25, 25],
                Anchor::Start,
            );
            cx = tx + font::text_width(&e.label, pxf) + pxf;
        }
        if entries.is_empty() {
            0.0
        } else {
            cy + row_h - y
        }
    }

    /// A rectangle.
    pub fn rect(
        &mut self,
        x: f32,
        y: f32,
        w: f32,
        h: f32,
        fill: Option<[u8; 3]>,
        stroke: Option<[u8; 3]>,
    ) {
        self.shapes.push(Shape::Rect {
            x,
            y,
            w,
            h,
            fill,
            stroke,
        });
    }

    /// Text whose line box starts at `y`, font size `px` (pixels per em).
    pub fn text(
        &mut self,
        x: f32,
        y: f32,
        px: u32,
        text: impl Into<String>,
        rgb: [u8; 3],
        anchor: Anchor,
    ) {
        self.shapes.push(Shape::Text {
            x,
            y,
            px,
            text: text.into(),
            rgb,
            anchor,
        });
    }

    /// An embedded PNG picture scaled into the box.
    pub fn image(&mut self, x: f32, y: f32, w: f32, h: f32, png: Vec<u8>) {
        self.shapes.push(Shape::Image { x, y, w, h, png });
    }

    /// The chart as a standalone SVG document.
    pub fn to_svg(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="DejaVu Sans, Verdana, sans-serif">"#,
            w = self.width,
            h = self.height
        );
        let _ = writeln!(s, r##"<rect width="100%" height="100%" fill="#ffffff"/>"##);
        for sh in &self.shapes {
            match sh {
                Shape::Line {
                    pts,
                    rgb,
                    width,
                    dashed,
                    cased,
                } => {
                    if pts.len() < 2 {
                        continue;
                    }
                    let mut d = String::new();
                    for (k, (x, y)) in pts.iter().enumerate() {
                        let _ = write!(d, "{}{:.2},{:.2}", if k == 0 { "M" } else { " L" }, x, y);
                    }
                    let dash = if *dashed {
                        format!(
                            r#" stroke-dasharray="{:.1},{:.1}""#,
                            width * 4.0,
                            width * 3.0
                        )
                    } else {
                        String::new()
                    };
                    if *cased {
                        let _ = writeln!(
                            s,
                            r##"<path d="{d}" fill="none" stroke="#ffffff" stroke-width="{:.2}" stroke-linejoin="round"/>"##,
                            width * 2.0
                        );
                    }
                    let _ = writeln!(
                        s,
                        r#"<path d="{d}" fill="none" stroke="{}" stroke-width="{width:.2}" stroke-linejoin="round"{dash}/>"#,
                        hex(*rgb)
                    );
                }
                Shape::Circle {
                    cx,
                    cy,
                    r,
                    fill,
                    stroke,
                    width,
                } => {
                    let fill = fill.map_or_else(|| "none".to_string(), hex);
                    let stroke = stroke.map_or_else(String::new, |c| {
                        format!(r#" stroke="{}" stroke-width="{width:.2}""#, hex(c))
                    });
                    let _ = writeln!(
                        s,
                        r#"<circle cx="{cx:.2}" cy="{cy:.2}" r="{r:.2}" fill="{fill}"{stroke}/>"#
                    );
                }
                Shape::Rect {
                    x,
                    y,
                    w,
                    h,
                    fill,
                    stroke,
                } => {
                    let fill = fill.map_or_else(|| "none".to_string(), hex);
                    let stroke = stroke.map_or_else(String::new, |c| {
                        format!(r#" stroke="{}" stroke-width="1""#, hex(c))
                    });
                    let _ = writeln!(
                        s,
                        r#"<rect x="{x:.2}" y="{y:.2}" width="{w:.2}" height="{h:.2}" fill="{fill}"{stroke}/>"#
                    );
                }
                Shape::Text {
                    x,
                    y,
                    px,
                    text,
                    rgb,
                    anchor,
                } => {
                    let a = match anchor {
                        Anchor::Start => "start",
                        Anchor::Middle => "middle",
                        Anchor::End => "end",
                    };
                    let _ = writeln!(
                        s,
                        r#"<text x="{x:.2}" y="{:.2}" font-size="{px}" fill="{}" text-anchor="{a}">{}</text>"#,
                        y + font::ascent(*px as f32),
                        hex(*rgb),
                        escape(text)
                    );
                }
                Shape::Image { x, y, w, h, png } => {
                    let b64 = base64::engine::general_purpose::STANDARD.encode(png);
                    let _ = writeln!(
                        s,
                        r#"<image x="{x:.2}" y="{y:.2}" width="{w:.2}" height="{h:.2}" preserveAspectRatio="xMidYMid meet" href="data:image/png;base64,{b64}"/>"#
                    );
                }
            }
        }
        s.push_str("</svg>\n");
        s
    }

    /// The chart as PNG bytes (through [`crate::encode_png`]: an opaque chart is written as
    /// 8-bit RGB with fast compression).
    ///
    /// # Errors
    /// When the canvas cannot be allocated or encoded.
    pub fn to_png(&self) -> Result<Vec<u8>, RenderError> {
        let mut pm = Pixmap::new(self.width, self.height)
            .ok_or(RenderError::Canvas(self.width, self.height))?;
        pm.fill(Color::WHITE);
        self.draw_onto(&mut pm);
        crate::encode_png(&pm)
    }

    /// Draws the shapes onto an existing pixmap (the chart's size is not checked).
    pub fn draw_onto(&self, pm: &mut Pixmap) {
        let id = Transform::identity();
        for sh in &self.shapes {
            match sh {
                Shape::Line {
                    pts,
                    rgb,
                    width,
                    dashed,
                    cased,
                } => {
                    let mut pb = PathBuilder::new();
                    let Some(first) = pts.first() else { continue };
                    pb.move_to(first.0, first.1);
                    for p in &pts[1..] {
                        pb.line_to(p.0, p.1);
                    }
                    if let Some(path) = pb.finish() {
                        let mut st = Stroke {
                            width: *width,
                            ..Stroke::default()
                        };
                        st.line_join = tiny_skia::LineJoin::Round;
                        if *cased {
                            let casing = Stroke {
                                width: width * 2.0,
                                ..st.clone()
                            };
                            pm.stroke_path(&path, &paint([255, 255, 255]), &casing, id, None);
                        }
                        if *dashed {
                            st.dash = StrokeDash::new(vec![width * 4.0, width * 3.0], 0.0);
                        }
                        pm.stroke_path(&path, &paint(*rgb), &st, id, None);
                    }
                }
                Shape::Circle {
                    cx,
                    cy,
                    r,
                    fill,
                    stroke,
                    width,
                } => {
                    if let Some(c) = PathBuilder::from_circle(*cx, *cy, *r) {
                        if let Some(f) = fill {
                            pm.fill_path(&c, &paint(*f), FillRule::Winding, id, None);
                        }
                        if let Some(s) = stroke {
                            let st = Stroke {
                                width: *width,
                                ..Stroke::default()
                            };
                            pm.stroke_path(&c, &paint(*s), &st, id, None);
                        }
                    }
                }
                Shape::Rect {
                    x,
                    y,
                    w,
                    h,
                    fill,
                    stroke,
                } => {
                    if let Some(r) = Rect::from_xywh(*x, *y, w.max(0.5), h.max(0.5)) {
                        if let Some(f) = fill {
                            pm.fill_rect(r, &paint(*f), id, None);
                        }
                        if let Some(c) = stroke {
                            let p = PathBuilder::from_rect(r);
                            pm.stroke_path(&p, &paint(*c), &Stroke::default(), id, None);
                        }
                    }
                }
                Shape::Text {
                    x,
                    y,
                    px,
                    text,
                    rgb,
                    anchor,
                } => {
                    let size = *px as f32;
                    let w = font::text_width(text, size);
                    let x0 = match anchor {
                        Anchor::Start => *x,
                        Anchor::Middle => x - w / 2.0,
                        Anchor::End => x - w,
                    };
                    font::draw_text(pm, x0.max(0.0), y.max(0.0), size, text, *rgb);
                }
                Shape::Image { x, y, w, h, png } => {
                    if let Ok(img) = Pixmap::decode_png(png) {
                        let sx = w / img.width() as f32;
                        let sy = h / img.height() as f32;
                        let k = sx.min(sy);
                        let ox = x + (w - img.width() as f32 * k) / 2.0;
                        let oy = y + (h - img.height() as f32 * k) / 2.0;
                        let pp = PixmapPaint {
                            quality: if k < 1.0 {
                                tiny_skia::FilterQuality::Bicubic
                            } else {
                                tiny_skia::FilterQuality::Bilinear
                            },
                            ..PixmapPaint::default()
                        };
                        pm.draw_pixmap(
                            0,
                            0,
                            img.as_ref(),
                            &pp,
                            Transform::from_row(k, 0.0, 0.0, k, ox, oy),
                            None,
                        );
                    }
                }
            }
        }
    }
}

/// What a legend entry shows next to its label.
#[derive(Clone, Debug, PartialEq)]
pub enum Swatch {
    /// A filled square (an area colour).
    Fill([u8; 3]),
    /// A filled square with diagonal hatching (the keep-out zones).
    Hatched {
        /// Background colour.
        fill: [u8; 3],
        /// Hatching colour.
        hatch: [u8; 3],
    },
    /// A dotted line sample over a white casing (the approach to the work area).
    Dotted([u8; 3]),
    /// A line sample; dashed lines are drawn over a white casing.
    Line {
        /// Colour.
        rgb: [u8; 3],
        /// Dashed.
        dashed: bool,
    },
    /// A line made of several colours (the path's per-region colours).
    Regions(Vec<[u8; 3]>),
    /// A filled disc.
    Disc([u8; 3]),
    /// A ring.
    Ring([u8; 3]),
    /// A small filled square marker.
    Square([u8; 3]),
    /// A cross marker.
    Cross([u8; 3]),
}

/// One legend entry: a swatch and its label.
#[derive(Clone, Debug, PartialEq)]
pub struct LegendEntry {
    /// What is drawn.
    pub swatch: Swatch,
    /// What it means.
    pub label: String,
}

impl LegendEntry {
    /// A new entry.
    pub fn new(swatch: Swatch, label: impl Into<String>) -> Self {
        Self {
            swatch,
            label: label.into(),
        }
    }
}

fn paint(rgb: [u8; 3]) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color(Color::from_rgba8(rgb[0], rgb[1], rgb[2], 255));
    p.anti_alias = true;
    p
}

fn hex(c: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2])
}

/// `s` as SVG (XML 1.0) text: markup characters as references, and the characters XML 1.0
/// does not allow at all (controls but tab and line breaks, U+FFFE, U+FFFF) as U+FFFD: a map
/// named with one made every plot of its map unparseable (hostile pass).
fn escape(s: &str) -> String {
    s.chars()
        .map(|c| match c {
            '\t' | '\n' | '\r' => c,
            c if u32::from(c) < 0x20 || c == '\u{fffe}' || c == '\u{ffff}' => '\u{fffd}',
            c => c,
        })
        .collect::<String>()
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A "nice" axis step for a range.
fn nice_step(range: f64, ticks: usize) -> f64 {
    if !(range.is_finite() && range > 0.0) {
        return 1.0;
    }
    let raw = range / ticks.max(1) as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let n = raw / mag;
    let k = if n < 1.5 {
        1.0
    } else if n < 3.5 {
        2.0
    } else if n < 7.5 {
        5.0
    } else {
        10.0
    };
    k * mag
}

/// A tick label with as many decimals as the step needs (a step of 0.005 needs three: at two
/// the coverage axis of a trade-off plot read 0.97, 0.98, 0.98, 0.99, 0.99, 1.00, and a point
/// at 0.9953 sat on a line labelled 0.99).
fn fmt_tick(v: f64, step: f64) -> String {
    let mut d = 0usize;
    while d < 9 {
        let scaled = step * 10f64.powi(d as i32);
        if (scaled - scaled.round()).abs() <= 1e-6 * scaled.max(1.0) {
            break;
        }
        d += 1;
    }
    format!("{v:.d$}")
}

/// The plotting box of a chart, in pixels from the top-left corner.
#[derive(Clone, Copy, Debug)]
struct Frame {
    /// Left edge.
    l: f32,
    /// Top edge.
    t: f32,
    /// Width.
    w: f32,
    /// Height.
    h: f32,
}

/// Colours, label size and label gap of a chart's grid lines and tick labels.
#[derive(Clone, Copy, Debug)]
struct TickStyle {
    grid: [u8; 3],
    text: [u8; 3],
    px: u32,
    gap: f32,
}

/// Ticks of a full-size chart.
const CHART_TICKS: TickStyle = TickStyle {
    grid: [225, 225, 225],
    text: [60, 60, 60],
    px: 12,
    gap: 6.0,
};

/// Ticks of a small panel.
const PANEL_TICKS: TickStyle = TickStyle {
    grid: [230, 230, 230],
    text: [80, 80, 80],
    px: 11,
    gap: 4.0,
};

impl Chart {
    /// The chart's title, centred at the top.
    fn title(&mut self, title: &str) {
        self.text(
            self.width as f32 / 2.0,
            10.0,
            20,
            title,
            [20, 20, 20],
            Anchor::Middle,
        );
    }

    /// A vertical grid line at `frac` (0 = left, 1 = right) of the frame, labelled below it.
    fn x_tick(&mut self, f: Frame, frac: f64, label: String, s: TickStyle) {
        let x = f.l + frac as f32 * f.w;
        self.line(vec![(x, f.t), (x, f.t + f.h)], s.grid, 1.0, false);
        self.text(x, f.t + f.h + 5.0, s.px, label, s.text, Anchor::Middle);
    }

    /// A horizontal grid line at `frac` (0 = bottom, 1 = top) of the frame, labelled at its left.
    fn y_tick(&mut self, f: Frame, frac: f64, label: String, s: TickStyle) {
        let y = f.t + f.h - frac as f32 * f.h;
        self.line(vec![(f.l, y), (f.l + f.w, y)], s.grid, 1.0, false);
        self.text(f.l - s.gap, y - 7.0, s.px, label, s.text, Anchor::End);
    }
}

/// A line chart: one polyline per named series of `[x, y]` points.
pub fn line_chart(
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[(String, Vec<[f64; 2]>)],
    y_max: Option<f64>,
) -> Chart {
    let (w, h) = (900u32, 520u32);
    let mut c = Chart::new(w, h);
    let (l, r, t, b) = (80.0f32, 200.0f32, 62.0f32, 60.0f32);
    let pw = w as f32 - l - r;
    let ph = h as f32 - t - b;
    let longest = series
        .iter()
        .flat_map(|s| s.1.iter().map(|p| p[0]))
        .fold(0.0f64, f64::max)
        .max(1e-9);
    let xmax = x_extent(series, longest);
    let ymax = y_max.unwrap_or_else(|| {
        series
            .iter()
            .flat_map(|s| s.1.iter().map(|p| p[1]))
            .fold(0.0f64, f64::max)
            .max(1e-9)
    });
    c.title(title);
    // Grid and ticks.
    let xs = nice_step(xmax, 6);
    let ys = nice_step(ymax, 5);
    let frame = Frame { l, t, w: pw, h: ph };
    let mut v = 0.0;
    while v <= xmax + 1e-9 {
        c.x_tick(frame, v / xmax, fmt_tick(v, xs), CHART_TICKS);
        v += xs;
    }
    let mut v = 0.0;
    while v <= ymax + 1e-9 {
        c.y_tick(frame, v / ymax, fmt_tick(v, ys), CHART_TICKS);
        v += ys;
    }
    c.rect(l, t, pw, ph, None, Some([120, 120, 120]));
    c.text(
        l + pw / 2.0,
        h as f32 - 28.0,
        14,
        x_label,
        [40, 40, 40],
        Anchor::Middle,
    );
    c.text(8.0, t - 24.0, 14, y_label, [40, 40, 40], Anchor::Start);
    for (k, (name, pts)) in series.iter().enumerate() {
        let col = SERIES[k % SERIES.len()];
        let to_canvas = |p: [f64; 2]| {
            (
                l + (p[0] / xmax) as f32 * pw,
                t + ph - (p[1].min(ymax) / ymax) as f32 * ph,
            )
        };
        // A series running past the axis is cut at its end, the cut interpolated.
        let mut poly: Vec<(f32, f32)> = Vec::with_capacity(pts.len());
        let mut cut = None;
        for (j, &p) in pts.iter().enumerate() {
            if p[0] <= xmax + 1e-9 {
                poly.push(to_canvas(p));
                continue;
            }
            if let Some(&q) = j.checked_sub(1).and_then(|i| pts.get(i)) {
                let f = ((xmax - q[0]) / (p[0] - q[0])).clamp(0.0, 1.0);
                poly.push(to_canvas([xmax, q[1] + f * (p[1] - q[1])]));
            }
            cut = pts.last().copied();
            break;
        }
        // Where a cut series ends, off the axis: said at the cut.
        if let (Some(e), Some(&(cx, cy))) = (cut, poly.last()) {
            c.text(
                cx - 4.0,
                cy - 18.0,
                12,
                format!("-> {} m", fmt_tick(e[0], nice_step(e[0], 6))),
                col,
                Anchor::End,
            );
        }
        c.line(poly, col, 2.0, false);
        let name = name.clone();
        let ly = t + 10.0 + k as f32 * 24.0;
        c.line(
            vec![(l + pw + 14.0, ly + 9.0), (l + pw + 40.0, ly + 9.0)],
            col,
            3.0,
            false,
        );
        c.text(l + pw + 46.0, ly, 14, name, [30, 30, 30], Anchor::Start);
    }
    c
}

/// The x axis of [`line_chart`]: to the longest series, unless it runs more than
/// [`X_OUTLIER`] times as far as the median series' end (random-bounce's budget of 6250 m
/// beside planners ending near 600 m squeezed them into the first tenth of the axis); then
/// to that bound, and the longer series are cut there.
fn x_extent(series: &[(String, Vec<[f64; 2]>)], longest: f64) -> f64 {
    let mut ends: Vec<f64> = series
        .iter()
        .filter_map(|s| s.1.last().map(|p| p[0]))
        .collect();
    if ends.len() < 3 {
        return longest;
    }
    ends.sort_by(f64::total_cmp);
    let median = ends[ends.len() / 2];
    if median > 0.0 && longest > X_OUTLIER * median {
        X_OUTLIER * median
    } else {
        longest
    }
}

/// How many times the median series' length the x axis of [`line_chart`] reaches at most.
const X_OUTLIER: f64 = 3.0;

/// Bar panels: for each metric a small bar chart with one bar per planner.
pub fn bar_panels(title: &str, planners: &[String], metrics: &[(String, Vec<f64>)]) -> Chart {
    let cols = 3usize;
    let rows = metrics.len().div_ceil(cols).max(1);
    let (pw, ph) = (300f32, 230f32);
    let w = (cols as f32 * pw) as u32;
    // Legend columns: four of 220 px, fewer when a name is wider ("random-bounce (warned on 2
    // maps)" ran into the next name).
    let item_w = planners
        .iter()
        .map(|p| 40.0 + font::text_width(p, 14.0))
        .fold(220.0f32, f32::max);
    let per_row = (((w as f32 - 40.0) / item_w).floor() as usize).clamp(1, 4);
    let h = (rows as f32 * ph + 60.0 + 24.0 * planners.len().div_ceil(per_row) as f32) as u32;
    let mut c = Chart::new(w, h);
    c.title(title);
    for (m, (name, vals)) in metrics.iter().enumerate() {
        let ox = (m % cols) as f32 * pw;
        let oy = 40.0 + (m / cols) as f32 * ph;
        let (l, t, iw, ih) = (ox + 50.0, oy + 24.0, pw - 70.0, ph - 50.0);
        c.text(
            ox + pw / 2.0,
            oy + 2.0,
            14,
            name.clone(),
            [30, 30, 30],
            Anchor::Middle,
        );
        let vmax = vals
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .fold(0.0f64, f64::max)
            .max(1e-9);
        let step = nice_step(vmax, 4);
        let top = (vmax / step).ceil() * step;
        let frame = Frame { l, t, w: iw, h: ih };
        let mut v = 0.0;
        while v <= top + 1e-9 {
            c.y_tick(frame, v / top, fmt_tick(v, step), PANEL_TICKS);
            v += step;
        }
        let n = vals.len().max(1) as f32;
        let bw = iw / n;
        for (k, v) in vals.iter().enumerate() {
            if !v.is_finite() {
                continue;
            }
            let bh = (v / top) as f32 * ih;
            c.rect(
                l + k as f32 * bw + bw * 0.15,
                t + ih - bh,
                bw * 0.7,
                bh,
                Some(SERIES[k % SERIES.len()]),
                None,
            );
        }
        c.rect(l, t, iw, ih, None, Some([150, 150, 150]));
    }
    let ly = 40.0 + rows as f32 * ph;
    for (k, p) in planners.iter().enumerate() {
        let x = 20.0 + (k % per_row) as f32 * item_w;
        let y = ly + (k / per_row) as f32 * 24.0;
        c.rect(x, y, 14.0, 14.0, Some(SERIES[k % SERIES.len()]), None);
        c.text(
            x + 20.0,
            y - 1.0,
            14,
            p.clone(),
            [30, 30, 30],
            Anchor::Start,
        );
    }
    c
}

/// Axis of a trade-off chart: linear, or logarithmic when the values span a wide range.
#[derive(Clone, Copy, Debug)]
struct Axis {
    lo: f64,
    hi: f64,
    log: bool,
}

impl Axis {
    /// The position in `0..=1` of value `v` along the axis.
    fn frac(&self, v: f64) -> f64 {
        if self.log {
            (v.ln() - self.lo.ln()) / (self.hi.ln() - self.lo.ln())
        } else {
            (v - self.lo) / (self.hi - self.lo)
        }
    }
}

/// A tick label with at most two decimals and no trailing zeros.
fn fmt_short(v: f64) -> String {
    let s = format!("{v:.2}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

/// Ticks of a logarithmic axis over `lo..=hi` spanning `len` pixels: the round mantissas first
/// (1, 2, 5), then finer ones while they stay `gap` pixels apart.
fn log_ticks(axis: &Axis, len: f32, gap: f32) -> Vec<f64> {
    let levels: [&[f64]; 3] = [&[1.0, 2.0, 5.0], &[1.5, 3.0], &[1.2, 4.0, 6.0, 8.0]];
    let mut kept: Vec<f64> = Vec::new();
    let (e0, e1) = (
        axis.lo.log10().floor() as i32,
        axis.hi.log10().ceil() as i32,
    );
    for level in levels {
        for e in e0..=e1 {
            for &m in level {
                let v = m * 10f64.powi(e);
                if v < axis.lo || v > axis.hi {
                    continue;
                }
                let x = axis.frac(v) as f32 * len;
                if kept
                    .iter()
                    .all(|&k| (axis.frac(k) as f32 * len - x).abs() >= gap)
                {
                    kept.push(v);
                }
            }
        }
    }
    kept.sort_by(f64::total_cmp);
    kept
}

/// An axis-aligned box `(x, y, w, h)`.
type Bbox = (f32, f32, f32, f32);

fn overlap(a: Bbox, b: Bbox) -> f32 {
    let w = (a.0 + a.2).min(b.0 + b.2) - a.0.max(b.0);
    let h = (a.1 + a.3).min(b.1 + b.3) - a.1.max(b.1);
    if w > 0.0 && h > 0.0 {
        w * h
    } else {
        0.0
    }
}

/// Places a label of size `(w, h)` next to each anchor `(x, y, r)` (a disc of radius `r`):
/// the first of 8 directions at growing distances whose box stays inside `area` and overlaps
/// no disc, no box in `blocked` and no label placed before; failing that the box of least
/// overlap. Returns each label's box and whether it was moved off its disc (needs a leader).
pub fn place_labels(
    anchors: &[(f32, f32, f32)],
    sizes: &[(f32, f32)],
    area: Bbox,
    blocked: &[Bbox],
) -> Vec<(Bbox, bool)> {
    let discs: Vec<Bbox> = anchors
        .iter()
        .map(|&(x, y, r)| (x - r - 2.0, y - r - 2.0, 2.0 * r + 4.0, 2.0 * r + 4.0))
        .collect();
    let mut placed: Vec<Bbox> = Vec::new();
    let mut out = Vec::new();
    for (&(x, y, r), &(w, h)) in anchors.iter().zip(sizes) {
        let mut best: Option<(f32, Bbox, bool)> = None;
        'rings: for (ring, d) in [r + 4.0, r + 18.0, r + 36.0, r + 60.0]
            .into_iter()
            .enumerate()
        {
            // Right, left, above, below, then the diagonals.
            let cands = [
                (x + d, y - h / 2.0),
                (x - d - w, y - h / 2.0),
                (x - w / 2.0, y - d - h),
                (x - w / 2.0, y + d),
                (x + d * 0.7, y - d * 0.7 - h),
                (x + d * 0.7, y + d * 0.7),
                (x - d * 0.7 - w, y - d * 0.7 - h),
                (x - d * 0.7 - w, y + d * 0.7),
            ];
            for (bx, by) in cands {
                let b = (bx, by, w, h);
                if bx < area.0
                    || by < area.1
                    || bx + w > area.0 + area.2
                    || by + h > area.1 + area.3
                {
                    continue;
                }
                let cost: f32 = discs
                    .iter()
                    .chain(blocked)
                    .chain(&placed)
                    .map(|&o| overlap(b, o))
                    .sum();
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, b, ring > 0));
                }
                if cost == 0.0 {
                    break 'rings;
                }
            }
        }
        let (_, b, far) = best.unwrap_or((0.0, (x + r + 4.0, y - h / 2.0, w, h), false));
        placed.push(b);
        out.push((b, far));
    }
    out
}

/// Mixes `c` with white (`t = 0`: `c`, `t = 1`: white).
fn faded(c: [u8; 3], t: f32) -> [u8; 3] {
    c.map(|v| (f32::from(v) + (255.0 - f32::from(v)) * t).round() as u8)
}

/// A trade-off chart: effective coverage (y, higher is better) against path ratio (x, lower
/// is better, on a logarithmic axis when the ratios span more than a factor 2.5), one labelled
/// disc per planner at `points[k]` (`[path_ratio, coverage]`; `None` or non-finite: not drawn)
/// in the colour of series `k`, with the better corner (top left) marked. `faint[k]`, when
/// given, are further points of planner `k` drawn small and pale behind (one per map in a
/// summary); the axes fit the main points, and faint points outside them are counted in a
/// note instead of drawn. A disc that would cover most of an earlier one is drawn as a ring
/// around it, so every point stays visible.
pub fn tradeoff_chart(
    title: &str,
    planners: &[String],
    points: &[Option<[f64; 2]>],
    faint: &[Vec<[f64; 2]>],
) -> Chart {
    let (w, h) = (900u32, 600u32);
    let mut c = Chart::new(w, h);
    let (l, r, t, b) = (80.0f32, 210.0f32, 62.0f32, 66.0f32);
    let (pw, ph) = (w as f32 - l - r, h as f32 - t - b);
    let ok = |p: &[f64; 2]| p[0].is_finite() && p[0] > 0.0 && p[1].is_finite();
    let mut all: Vec<[f64; 2]> = points.iter().flatten().copied().filter(ok).collect();
    if all.is_empty() {
        all = faint.iter().flatten().copied().filter(ok).collect();
    }
    let (mut x0, mut x1, mut y0, mut y1) = all.iter().fold(
        (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ),
        |a, p| (a.0.min(p[0]), a.1.max(p[0]), a.2.min(p[1]), a.3.max(p[1])),
    );
    if all.is_empty() {
        (x0, x1, y0, y1) = (1.0, 2.0, 0.0, 1.0);
    }
    let log = x1 / x0 > 2.5;
    let xa = if log {
        Axis {
            lo: x0 / 1.08,
            hi: x1 * 1.08,
            log,
        }
    } else {
        let pad = ((x1 - x0) * 0.08).max(0.05);
        Axis {
            lo: (x0 - pad).max(0.0),
            hi: x1 + pad,
            log,
        }
    };
    let ystep = nice_step((y1 - y0).max(0.02), 5);
    let ylo = ((y0 - ystep * 0.3) / ystep).floor() * ystep;
    let ytop = (y1 / ystep).ceil() * ystep;
    let ya = Axis {
        lo: ylo.max(0.0).min(y0),
        hi: ytop + ystep * 0.3,
        log: false,
    };
    let px = |p: &[f64; 2]| {
        (
            l + xa.frac(p[0]) as f32 * pw,
            t + ph - ya.frac(p[1]) as f32 * ph,
        )
    };
    c.title(title);
    // The better corner: pale green with an arrow into the corner (kept free of labels; the
    // legend names it).
    let green = [0, 130, 60];
    let shade = [226, 244, 230];
    let (cw, ch) = (pw * 0.22, ph * 0.2);
    c.rect(l, t, cw, ch, Some(shade), None);
    let arrow_box = (l, t, 24.0, 24.0);
    c.line(
        vec![(l + 20.0, t + 22.0), (l + 6.0, t + 8.0)],
        green,
        2.0,
        false,
    );
    c.line(
        vec![(l + 6.0, t + 8.0), (l + 14.0, t + 8.0)],
        green,
        2.0,
        false,
    );
    c.line(
        vec![(l + 6.0, t + 8.0), (l + 6.0, t + 16.0)],
        green,
        2.0,
        false,
    );
    // Grid and ticks.
    let xticks: Vec<f64> = if log {
        log_ticks(&xa, pw, 44.0)
    } else {
        let s = nice_step(xa.hi - xa.lo, 6);
        let mut v = (xa.lo / s).ceil() * s;
        let mut out = Vec::new();
        while v <= xa.hi + 1e-9 {
            out.push(v);
            v += s;
        }
        out
    };
    let frame = Frame { l, t, w: pw, h: ph };
    for v in xticks {
        c.x_tick(frame, xa.frac(v), fmt_short(v), CHART_TICKS);
    }
    let mut v = (ya.lo / ystep).ceil() * ystep;
    while v <= ya.hi + 1e-9 {
        c.y_tick(frame, ya.frac(v), fmt_tick(v, ystep), CHART_TICKS);
        v += ystep;
    }
    c.rect(l, t, pw, ph, None, Some([120, 120, 120]));
    let x_label = if log {
        "path ratio (log scale; lower is better)"
    } else {
        "path ratio (lower is better)"
    };
    c.text(
        l + pw / 2.0,
        h as f32 - 30.0,
        14,
        x_label,
        [40, 40, 40],
        Anchor::Middle,
    );
    c.text(
        8.0,
        t - 26.0,
        14,
        "effective coverage (higher is better)",
        [40, 40, 40],
        Anchor::Start,
    );
    // Faint points first, then the planners' discs, then their labels. A faint point beyond
    // the axes is a chevron on the frame's edge, pointing its way (they were only counted, so
    // a summary never showed its worst maps).
    let mut outside = 0usize;
    for (k, pts) in faint.iter().enumerate() {
        let col = faded(SERIES[k % SERIES.len()], 0.55);
        let edge = faded(SERIES[k % SERIES.len()], 0.3);
        for p in pts.iter().filter(|p| ok(p)) {
            let (x, y) = px(p);
            if x < l || x > l + pw || y < t || y > t + ph {
                outside += 1;
                let (cx, cy) = (
                    x.clamp(l + 4.0, l + pw - 4.0),
                    y.clamp(t + 4.0, t + ph - 4.0),
                );
                // Unit vector out of the frame (either axis, or a corner's diagonal).
                let dx = if x < l {
                    -1.0
                } else if x > l + pw {
                    1.0
                } else {
                    0.0
                };
                let dy = if y < t {
                    -1.0
                } else if y > t + ph {
                    1.0
                } else {
                    0.0
                };
                let (nx, ny) = (-dy, dx);
                c.line(
                    vec![
                        (cx - 4.0 * dx + 4.0 * nx, cy - 4.0 * dy + 4.0 * ny),
                        (cx, cy),
                        (cx - 4.0 * dx - 4.0 * nx, cy - 4.0 * dy - 4.0 * ny),
                    ],
                    edge,
                    2.0,
                    false,
                );
                continue;
            }
            c.circle(x, y, 3.5, Some(col), None, 1.0);
        }
    }
    if outside > 0 {
        // In the legend's column: under the plot it ran into the axis label.
        for (j, line) in [
            format!("{outside} per-map points beyond"),
            "the axes: chevrons on the edge".to_string(),
        ]
        .into_iter()
        .enumerate()
        {
            c.text(
                l + pw + 14.0,
                t + ph - 30.0 + j as f32 * 16.0,
                12,
                line,
                [110, 110, 110],
                Anchor::Start,
            );
        }
    }
    let rad = 7.0f32;
    let mut anchors = Vec::new();
    let mut sizes = Vec::new();
    let mut who = Vec::new();
    for (k, p) in points.iter().enumerate() {
        let Some(p) = p.filter(|p| ok(p)) else {
            continue;
        };
        let (x, y) = px(&p);
        let col = SERIES[k % SERIES.len()];
        let close = anchors
            .iter()
            .filter(|&&(ax, ay, _): &&(f32, f32, f32)| (ax - x).hypot(ay - y) < 1.4 * rad)
            .count();
        let r_here = rad + 3.5 * close as f32;
        if close == 0 {
            c.circle(x, y, rad, Some(col), Some([255, 255, 255]), 1.5);
        } else {
            c.circle(x, y, r_here, None, Some(col), 2.5);
        }
        let name = planners.get(k).cloned().unwrap_or_default();
        anchors.push((x, y, r_here));
        sizes.push((font::text_width(&name, 13.0), font::line_height(13.0)));
        who.push((k, name));
    }
    let area = (l + 2.0, t + 2.0, pw - 4.0, ph - 4.0);
    let boxes = place_labels(&anchors, &sizes, area, &[arrow_box]);
    for (((bx, by, bw, bh), far), (&(x, y, _), (k, name))) in
        boxes.into_iter().zip(anchors.iter().zip(who))
    {
        if far {
            let end = (x.clamp(bx, bx + bw), y.clamp(by, by + bh));
            c.line(vec![(x, y), end], [150, 150, 150], 1.0, false);
        }
        // The series colour darkened a quarter, for contrast on white.
        let ink = SERIES[k % SERIES.len()].map(|v| (u16::from(v) * 3 / 4) as u8);
        c.text(bx, by, 13, name, ink, Anchor::Start);
    }
    // Legend: planners, then the marks.
    let lx = l + pw + 16.0;
    let mut ly = t + 4.0;
    for (k, name) in planners.iter().enumerate() {
        let col = SERIES[k % SERIES.len()];
        c.circle(lx + 8.0, ly + 9.0, 6.0, Some(col), None, 1.0);
        // A name with a note wider than the margin ("random-bounce (warned on 2 maps)") goes
        // on two lines, the note smaller under the name; it ran off the picture.
        match name.split_once(" (") {
            Some((head, note)) if lx + 22.0 + font::text_width(name, 14.0) > w as f32 - 4.0 => {
                c.text(
                    lx + 22.0,
                    ly,
                    14,
                    head.to_string(),
                    [30, 30, 30],
                    Anchor::Start,
                );
                c.text(
                    lx + 22.0,
                    ly + 17.0,
                    12,
                    format!("({note}"),
                    [90, 90, 90],
                    Anchor::Start,
                );
                ly += 40.0;
            }
            _ => {
                c.text(lx + 22.0, ly, 14, name.clone(), [30, 30, 30], Anchor::Start);
                ly += 24.0;
            }
        }
    }
    ly += 10.0;
    c.rect(lx, ly + 2.0, 16.0, 14.0, Some(shade), Some([150, 190, 160]));
    c.text(lx + 22.0, ly, 13, "better corner:", green, Anchor::Start);
    c.text(
        lx + 22.0,
        ly + 17.0,
        13,
        "more coverage,",
        [60, 60, 60],
        Anchor::Start,
    );
    c.text(
        lx + 22.0,
        ly + 34.0,
        13,
        "shorter path",
        [60, 60, 60],
        Anchor::Start,
    );
    ly += 56.0;
    if faint.iter().any(|f| !f.is_empty()) {
        c.circle(lx + 8.0, ly + 9.0, 6.0, Some([90, 90, 90]), None, 1.0);
        c.text(
            lx + 22.0,
            ly,
            13,
            "mean over maps",
            [60, 60, 60],
            Anchor::Start,
        );
        ly += 22.0;
        c.circle(
            lx + 8.0,
            ly + 9.0,
            3.5,
            Some(faded([90, 90, 90], 0.55)),
            None,
            1.0,
        );
        c.text(lx + 22.0, ly, 13, "one map", [60, 60, 60], Anchor::Start);
    }
    c
}

/// Pictures side by side with labels (up to `cols` per row), each in a `cell_w x cell_h` box.
pub fn image_grid(
    title: &str,
    items: &[(String, Vec<u8>)],
    cols: usize,
    cell_w: u32,
    cell_h: u32,
) -> Chart {
    let cols = cols.max(1).min(items.len().max(1));
    let rows = items.len().div_ceil(cols).max(1);
    let w = cols as u32 * cell_w;
    let h = rows as u32 * (cell_h + 24) + 40;
    let mut c = Chart::new(w, h);
    c.title(title);
    for (k, (label, png)) in items.iter().enumerate() {
        let x = (k % cols) as f32 * cell_w as f32;
        let y = 40.0 + (k / cols) as f32 * (cell_h + 24) as f32;
        c.text(
            x + cell_w as f32 / 2.0,
            y - 2.0,
            15,
            label.clone(),
            [30, 30, 30],
            Anchor::Middle,
        );
        c.image(
            x + 4.0,
            y + 16.0,
            cell_w as f32 - 8.0,
            cell_h as f32 - 4.0,
            png.clone(),
        );
    }
    c
}

/// Width and height from a PNG header.
fn png_size(png: &[u8]) -> Option<(u32, u32)> {
    if png.len() < 24 || &png[..8] != b"\x89PNG\r\n\x1a\n" {
        return None;
    }
    let w = u32::from_be_bytes(png[16..20].try_into().ok()?);
    let h = u32::from_be_bytes(png[20..24].try_into().ok()?);
    Some((w, h))
}

/// One picture of [`image_grid_captioned`]: a label above, caption lines below.
#[derive(Clone, Debug, Default)]
pub struct Panel {
    /// Name above the picture.
    pub label: String,
    /// Lines below the picture (figures of the run).
    pub caption: Vec<String>,
    /// A coloured chip with white text above the caption (e.g. the effective coverage,
    /// coloured by [`crate::coverage_verdict_colour`]).
    pub badge: Option<(String, [u8; 3])>,
    /// The picture (PNG bytes).
    pub png: Vec<u8>,
}

/// Pictures side by side (up to `cols` per row), each in a `cell_w x cell_h` box with its label
/// above and its caption lines below at a legible size, and one shared legend at the bottom.
pub fn image_grid_captioned(
    title: &str,
    panels: &[Panel],
    legend: &[LegendEntry],
    cols: usize,
    cell_w: u32,
    cell_h: u32,
) -> Chart {
    let cols = cols.max(1).min(panels.len().max(1));
    let rows = panels.len().div_ceil(cols).max(1);
    // No taller than the tallest picture needs at the cell's width.
    let need = panels
        .iter()
        .filter_map(|p| png_size(&p.png))
        .map(|(w, h)| ((cell_w as f32 - 12.0) * h as f32 / w.max(1) as f32).ceil() as u32)
        .max();
    let cell_h = need.map_or(cell_h, |n| n.clamp(40, cell_h));
    let cap_lines = panels.iter().map(|p| p.caption.len()).max().unwrap_or(0) as u32;
    let (label_px, cap_px) = (16u32, 13u32);
    let label_h = font::line_height(label_px as f32) as u32 + 4;
    let badge_h = if panels.iter().any(|p| p.badge.is_some()) {
        font::line_height(cap_px as f32) as u32 + 8
    } else {
        0
    };
    let cap_h = badge_h + cap_lines * font::line_height(cap_px as f32) as u32 + 8;
    let row_h = label_h + cell_h + cap_h + 10;
    let w = cols as u32 * cell_w;
    // Measure the legend first to size the canvas.
    let mut probe = Chart::new(w, 0);
    let legend_h = probe.legend(12.0, 0.0, w as f32 - 24.0, 13, legend).ceil() as u32;
    let top = 44u32;
    let h = top + rows as u32 * row_h + legend_h + 16;
    let mut c = Chart::new(w, h);
    c.title(title);
    for (k, p) in panels.iter().enumerate() {
        let x = (k % cols) as f32 * cell_w as f32;
        let y = (top + (k / cols) as u32 * row_h) as f32;
        c.text(
            x + cell_w as f32 / 2.0,
            y,
            label_px,
            p.label.clone(),
            [20, 20, 20],
            Anchor::Middle,
        );
        c.image(
            x + 6.0,
            y + label_h as f32,
            cell_w as f32 - 12.0,
            cell_h as f32,
            p.png.clone(),
        );
        let cap_top = (label_h + cell_h + 4) as f32;
        if let Some((text, colour)) = &p.badge {
            let tw = font::text_width(text, cap_px as f32) + 14.0;
            let bx = x + (cell_w as f32 - tw) / 2.0;
            c.rect(
                bx,
                y + cap_top,
                tw,
                font::line_height(cap_px as f32) + 4.0,
                Some(*colour),
                None,
            );
            c.text(
                bx + 7.0,
                y + cap_top + 2.0,
                cap_px,
                text.clone(),
                [255, 255, 255],
                Anchor::Start,
            );
        }
        for (j, line) in p.caption.iter().enumerate() {
            c.text(
                x + cell_w as f32 / 2.0,
                y + cap_top + badge_h as f32 + j as f32 * font::line_height(cap_px as f32),
                cap_px,
                line.clone(),
                [40, 40, 40],
                Anchor::Middle,
            );
        }
    }
    let ly = (top + rows as u32 * row_h) as f32;
    c.line(
        vec![(8.0, ly - 4.0), (w as f32 - 8.0, ly - 4.0)],
        [210, 210, 210],
        1.0,
        false,
    );
    c.legend(12.0, ly, w as f32 - 24.0, 13, legend);
    c
}

#[cfg(test)]
mod tests {

    /// SVG text is XML 1.0: markup as references, characters XML refuses as U+FFFD.
    #[test]
    fn svg_text_is_always_xml() {
        assert_eq!(
            super::escape("a\u{1b}[31m<b>&\"\u{fffe}\u{ffff}\tc"),
            "a\u{fffd}[31m&lt;b&gt;&amp;&quot;\u{fffd}\u{fffd}\tc"
        );
    }

    /// Tick labels carry the decimals their step needs, so neighbouring ticks never read the
    /// same (a coverage axis in steps of 0.005 read 0.98 twice).
    #[test]
    fn tick_labels_are_distinct_at_any_step() {
        assert_eq!(fmt_tick(0.975, 0.005), "0.975");
        assert_eq!(fmt_tick(1.0, 0.005), "1.000");
        assert_eq!(fmt_tick(0.4, 0.2), "0.4");
        assert_eq!(fmt_tick(25.0, 5.0), "25");
        for step in [0.0005, 0.002, 0.005, 0.02, 0.05, 0.25, 0.5, 2.0, 50.0] {
            let labels: Vec<String> = (0..12)
                .map(|k| fmt_tick(0.9 + f64::from(k) * step, step))
                .collect();
            let mut unique = labels.clone();
            unique.dedup();
            assert_eq!(unique.len(), labels.len(), "{step}: {labels:?}");
        }
    }
    use super::*;

    /// A series far longer than the others (random-bounce's budget) no longer squeezes them
    /// into the first tenth of the axis: the axis ends at three times the median length, and
    /// the long series is cut there with its end written at the cut.
    #[test]
    fn an_outlier_series_is_cut_at_three_times_the_median_length() {
        let line = |end: f64| vec![[0.0, 0.0], [end, 1.0]];
        let series: Vec<(String, Vec<[f64; 2]>)> = [600.0, 650.0, 700.0, 6250.0]
            .iter()
            .enumerate()
            .map(|(k, &e)| (format!("p{k}"), line(e)))
            .collect();
        assert!((x_extent(&series, 6250.0) - 2100.0).abs() < 1e-9);
        let svg = line_chart("T", "distance (m)", "coverage", &series, Some(1.0)).to_svg();
        assert!(
            svg.contains("-&gt; 6250 m") || svg.contains("-> 6250 m"),
            "{svg}"
        );
        // Comparable lengths keep the whole axis.
        assert!((x_extent(&series[..3], 700.0) - 700.0).abs() < 1e-9);
        let near: Vec<(String, Vec<[f64; 2]>)> = [600.0, 650.0, 1500.0]
            .iter()
            .map(|&e| ("p".to_string(), line(e)))
            .collect();
        assert!((x_extent(&near, 1500.0) - 1500.0).abs() < 1e-9);
    }

    #[test]
    fn svg_and_png_agree_on_size_and_are_deterministic() {
        let series = vec![("a".to_string(), vec![[0.0, 0.0], [10.0, 0.5], [20.0, 0.9]])];
        let c = line_chart("T", "distance (m)", "coverage", &series, Some(1.0));
        let svg = c.to_svg();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains(r#"width="900""#));
        assert_eq!(
            svg,
            line_chart("T", "distance (m)", "coverage", &series, Some(1.0)).to_svg()
        );
        let png = c.to_png().unwrap();
        let img = Pixmap::decode_png(&png).unwrap();
        assert_eq!((img.width(), img.height()), (900, 520));
        assert_eq!(nice_step(100.0, 5), 20.0);
    }

    #[test]
    fn svg_snapshots() {
        let series = vec![
            (
                "ba-star".to_string(),
                vec![[0.0, 0.0], [50.0, 0.6], [100.0, 0.98]],
            ),
            (
                "random-bounce".to_string(),
                vec![[0.0, 0.0], [80.0, 0.4], [300.0, 0.85]],
            ),
        ];
        insta::assert_snapshot!(
            "line_chart",
            line_chart("Coverage", "distance (m)", "coverage", &series, Some(1.0)).to_svg()
        );
        let planners = vec!["a".to_string(), "b".to_string()];
        let metrics = vec![
            ("effective coverage".to_string(), vec![0.9, 0.7]),
            ("turns".to_string(), vec![120.0, 800.0]),
        ];
        insta::assert_snapshot!(
            "bar_panels",
            bar_panels("Summary", &planners, &metrics).to_svg()
        );
        insta::assert_snapshot!(
            "tradeoff_chart",
            tradeoff_chart(
                "Trade-off",
                &planners,
                &[Some([1.2, 0.9]), Some([1.5, 0.99])],
                &[vec![[1.1, 0.85], [9.0, 0.2]], vec![]],
            )
            .to_svg()
        );
    }

    /// The `(x, y)` of every `<text>` holding `label`, and of every circle, from the SVG.
    fn attr(line: &str, name: &str) -> f32 {
        let k = line.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
        line[k..].split('"').next().unwrap().parse().unwrap()
    }

    #[test]
    fn tradeoff_chart_draws_every_planner_once_with_readable_labels() {
        let planners: Vec<String> = ["ba-star", "bsa", "bcd", "random-bounce", "none"]
            .iter()
            .map(|s| (*s).to_string())
            .collect();
        // Three nearly coincident points, one far right (log axis), one missing.
        let points = [
            Some([1.0, 0.86]),
            Some([1.001, 0.8601]),
            Some([1.0, 0.8602]),
            Some([7.4, 0.5]),
            None,
        ];
        let c = tradeoff_chart("T", &planners, &points, &[]);
        let svg = c.to_svg();
        assert!(svg.contains(">better corner:</text>"));
        assert!(svg.contains("log scale"));
        // One disc or ring per drawn planner, in its colour; the missing one has none.
        for (k, p) in points.iter().enumerate() {
            let col = hex(SERIES[k]);
            let n = svg
                .lines()
                .filter(|l| l.starts_with("<circle") && l.contains(&col))
                .count();
            // The legend swatch is one more circle.
            assert_eq!(n, 1 + usize::from(p.is_some()), "{}", planners[k]);
        }
        // Coincident points: the later ones are rings (no fill), not hidden under a disc.
        let rings = svg
            .lines()
            .filter(|l| l.starts_with("<circle") && l.contains(r#"fill="none""#))
            .count();
        assert_eq!(rings, 2);
        // Labels inside the plot and not overlapping one another.
        let boxes: Vec<(f32, f32, f32)> = planners[..4]
            .iter()
            .map(|p| {
                let line = svg
                    .lines()
                    .rfind(|l| {
                        l.ends_with(&format!(">{p}</text>")) && l.contains(r#"font-size="13""#)
                    })
                    .unwrap_or_else(|| panic!("label {p}"));
                let w = font::text_width(p, 13.0);
                (attr(line, "x"), attr(line, "y"), w)
            })
            .collect();
        for (i, a) in boxes.iter().enumerate() {
            assert!(a.0 >= 80.0 && a.0 + a.2 <= 690.0, "{a:?}");
            for b in &boxes[i + 1..] {
                let ov = overlap((a.0, a.1, a.2, 16.0), (b.0, b.1, b.2, 16.0));
                assert_eq!(ov, 0.0, "{a:?} {b:?}");
            }
        }
        // Deterministic, and the PNG has the SVG's size.
        assert_eq!(svg, tradeoff_chart("T", &planners, &points, &[]).to_svg());
        let img = Pixmap::decode_png(&c.to_png().unwrap()).unwrap();
        assert_eq!((img.width(), img.height()), (900, 600));
    }

    #[test]
    fn tradeoff_summary_counts_faint_points_off_the_axes() {
        let planners = vec!["a".to_string(), "b".to_string()];
        let faint = vec![vec![[1.1, 0.9], [30.0, 0.1]], vec![[1.3, 0.95]]];
        let svg = tradeoff_chart(
            "S",
            &planners,
            &[Some([1.1, 0.9]), Some([1.3, 0.95])],
            &faint,
        )
        .to_svg();
        assert!(
            svg.contains(">1 per-map points beyond</text>")
                && svg.contains(">the axes: chevrons on the edge</text>"),
            "{svg}"
        );
        assert!(svg.contains(">mean over maps</text>") && svg.contains(">one map</text>"));
        // The point beyond the axes is a chevron in its planner's colour on the edge.
        let edge = hex(faded(SERIES[0], 0.3));
        assert_eq!(
            svg.matches(&format!("stroke=\"{edge}\"")).count(),
            1,
            "{svg}"
        );
        // Narrow range: a linear axis.
        assert!(!svg.contains("log scale"));
    }

    #[test]
    fn labels_avoid_discs_blocked_boxes_and_each_other() {
        let anchors = [
            (100.0, 100.0, 7.0),
            (104.0, 100.0, 10.5),
            (100.0, 104.0, 14.0),
            (300.0, 300.0, 7.0),
        ];
        let sizes = [(60.0, 16.0); 4];
        let blocked = [(110.0, 80.0, 100.0, 40.0)];
        let area = (0.0, 0.0, 400.0, 400.0);
        let out = place_labels(&anchors, &sizes, area, &blocked);
        for (i, (a, _)) in out.iter().enumerate() {
            assert!(a.0 >= 0.0 && a.1 >= 0.0 && a.0 + a.2 <= 400.0 && a.1 + a.3 <= 400.0);
            assert_eq!(overlap(*a, blocked[0]), 0.0, "{a:?}");
            for &(x, y, r) in &anchors {
                assert_eq!(overlap(*a, (x - r, y - r, 2.0 * r, 2.0 * r)), 0.0, "{a:?}");
            }
            for (b, _) in &out[i + 1..] {
                assert_eq!(overlap(*a, *b), 0.0, "{a:?} {b:?}");
            }
        }
        // The lone point keeps its label right beside it.
        assert_eq!(out[3], ((311.0, 292.0, 60.0, 16.0), false));
    }
}

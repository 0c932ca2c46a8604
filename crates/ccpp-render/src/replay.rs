//! The self-contained HTML replay (no network, no external file) and the animated GIF.

use std::fmt::Write as _;

use base64::Engine as _;
use ccpp_core::grid::Cell;
use ccpp_core::metrics::{coverage_curve_and_swept, Sweeper};
use ccpp_core::trace::{Entry, Event, Trace};
use ccpp_core::world::World;
use ccpp_core::Point;
use tiny_skia::{Color, Pixmap};

use crate::colours::{AREA_BORDER, KEEPOUT, KEEPOUT_HATCH, OUTSIDE_AREA};
use crate::{approach_end, crop_box, finished_record, unfinished, zone_class, RenderError};

/// Map class colours shared by the replay page and the GIF.
const C_OCC: [u8; 3] = [30, 30, 30];
const C_UNK: [u8; 3] = [170, 170, 170];
const C_FREE_OUT: [u8; 3] = [246, 246, 242];
const C_ACC: [u8; 3] = [250, 205, 190];
/// Swept floor (also the colour the browser test looks for).
pub const C_SWEPT: [u8; 3] = [120, 190, 245];
const C_PATH: [u8; 3] = [0, 70, 160];
/// The robot: the replay page's yellow disc (green means the start in every picture).
const C_ROBOT: [u8; 3] = [255, 212, 0];
/// The start: the replay page's green disc, as in the coverage picture.
const C_START: [u8; 3] = crate::colours::START;

/// Period of the keep-out hatching, in map pixels (the replay's background has one pixel per
/// map pixel; the coverage picture hatches in canvas pixels).
const HATCH_PERIOD: usize = 6;

/// Map class of pixel `i`, as in the coverage picture: obstacles and unknown pixels of the true
/// map, keep-out floor, floor outside the work area, then floor the tool can reach or not.
fn class_of(world: &World, i: usize) -> Class {
    match world.true_map().cells()[i] {
        Cell::Occupied => Class::Occupied,
        Cell::Unknown => Class::Unknown,
        Cell::Free => match zone_class(world, i) {
            1 => Class::Keepout,
            2 => Class::OutsideArea,
            _ if world.accessible().contains(i) => Class::Accessible,
            _ => Class::OutOfReach,
        },
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Class {
    Occupied,
    Unknown,
    OutOfReach,
    Accessible,
    Keepout,
    OutsideArea,
}

/// The keep-out hatching: a diagonal stripe at map pixel `(x, y)`.
fn hatched(x: usize, y: usize) -> bool {
    (x + y) % HATCH_PERIOD < 2
}

fn class_colour(world: &World, i: usize, x: usize, y: usize) -> [u8; 3] {
    match class_of(world, i) {
        Class::Occupied => C_OCC,
        Class::Unknown => C_UNK,
        Class::OutOfReach => C_FREE_OUT,
        Class::Accessible => C_ACC,
        Class::Keepout if hatched(x, y) => KEEPOUT_HATCH,
        Class::Keepout => KEEPOUT,
        Class::OutsideArea => OUTSIDE_AREA,
    }
}

/// The cropped map background, one canvas pixel per map pixel, as PNG.
fn background_png(
    world: &World,
    crop: (usize, usize, usize, usize),
) -> Result<Vec<u8>, RenderError> {
    let (c0, r0, w, h) = crop;
    let mut pm = Pixmap::new(w as u32, h as u32).ok_or(RenderError::Canvas(w as u32, h as u32))?;
    pm.fill(Color::WHITE);
    let f = *world.frame();
    let data = pm.data_mut();
    for y in 0..h {
        for x in 0..w {
            let c = class_colour(world, f.index(c0 + x, r0 + y), c0 + x, r0 + y);
            let o = (y * w + x) * 4;
            data[o..o + 4].copy_from_slice(&[c[0], c[1], c[2], 255]);
        }
    }
    pm.encode_png()
        .map_err(|e| RenderError::Encode(e.to_string()))
}

fn js_num(v: f64) -> String {
    if v.is_finite() {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s.is_empty() || s == "-" {
            "0".into()
        } else {
            s.to_string()
        }
    } else {
        "0".into()
    }
}

/// Largest display error of the decimated path, in map pixels.
const DECIMATE_TOL_PX: f64 = 0.25;
/// Quantisation of display coordinates: 1/`Q` map pixel.
const Q: f64 = 8.0;
/// Largest coordinate the path blob carries, in 1/[`Q`] pixel (2^40: far beyond any map).
const FAR_Q: i64 = 1 << 40;
/// Samples of the live coverage curve.
const COVERAGE_SAMPLES: usize = 2000;

/// A crop pixel coordinate in the blobs' units (1/[`Q`] px). A pose far off the map (a
/// corrupted trace) is drawn at a far edge: the deltas stay exact in JavaScript's numbers and
/// never overflow.
fn quantize(v: f64) -> i64 {
    ((v * Q).round() as i64).clamp(-FAR_Q, FAR_Q)
}

fn push_varint(out: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        out.push((v as u8 & 0x7f) | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

fn zigzag(v: i64) -> u64 {
    ((v << 1) ^ (v >> 63)) as u64
}

/// The poses kept for display: the first and last, every pose an event or a first tile visit
/// is anchored to, and enough others that the drawn polyline stays within
/// [`DECIMATE_TOL_PX`] of the executed one (Reumann-Witkam: a point is dropped while it stays
/// within the tolerance of the line through the last kept point and moves forward along it).
fn decimate(pts: &[[f64; 2]], forced: &[bool]) -> Vec<usize> {
    let n = pts.len();
    let mut kept = Vec::new();
    if n == 0 {
        return kept;
    }
    kept.push(0);
    let tol2 = DECIMATE_TOL_PX * DECIMATE_TOL_PX;
    let d2 = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2);
    let mut anchor = 0usize;
    let mut dir: Option<[f64; 2]> = None; // unit direction from the anchor
    let mut last_proj = 0.0f64;
    for j in 1..n {
        let p = pts[j];
        // Does `p` go on along the stretch from the anchor?
        let on_stretch = match dir {
            None => true,
            Some(u) => {
                let a = pts[anchor];
                let (vx, vy) = (p[0] - a[0], p[1] - a[1]);
                let proj = vx * u[0] + vy * u[1];
                let perp = (vx * u[1] - vy * u[0]).abs();
                let on = perp <= DECIMATE_TOL_PX && proj + DECIMATE_TOL_PX >= last_proj;
                if on {
                    last_proj = last_proj.max(proj);
                }
                on
            }
        };
        if !on_stretch {
            // Keep the previous pose and start a new stretch there. This comes first for a
            // pose that is kept anyway (an event's, the last): the corner before it was
            // dropped, and the drawn path cut across it.
            let prev = j - 1;
            if prev != anchor {
                kept.push(prev);
                anchor = prev;
            }
            dir = None;
            last_proj = 0.0;
        }
        if forced[j] || j == n - 1 {
            kept.push(j);
            anchor = j;
            dir = None;
            last_proj = 0.0;
            continue;
        }
        if dir.is_none() {
            let a = pts[anchor];
            let dd = d2(a, p);
            if dd > tol2 {
                let l = dd.sqrt();
                dir = Some([(p[0] - a[0]) / l, (p[1] - a[1]) / l]);
                last_proj = l;
            }
        }
    }
    kept
}

/// The replay data as a JS object literal (deterministic text). The path travels as one
/// base64 blob of varints: for each displayed pose the x and y deltas (zigzag, 1/8 map pixel,
/// canvas orientation), the step-counter delta, the travelled-distance delta (mm, of the
/// rounded running total, so no drift), then one heading byte per pose (on the image's axes).
/// Longest side of the page's canvas in device pixels (`4096` in the template's `layout`).
const CANVAS_MAX_PX: f64 = 4096.0;
/// Smallest tile the page outlines, device pixels (`tilesShown` in the template).
const TILE_MIN_DRAWN_PX: f64 = 6.0;

fn replay_data(
    world: &World,
    trace: &Trace,
    tile_side: Option<f64>,
    metrics_json: &str,
    crop: (usize, usize, usize, usize),
    warnings: &[String],
) -> String {
    let f = *world.frame();
    let (c0, r0, w, h) = crop;
    // Pass 1: poses in crop pixel coordinates (y down) and the ones tied to an event, for the
    // decimation; events and tile anchors. Only what the decimation needs is held per pose
    // (17 bytes): heading, step and distance are read again for the kept poses in pass 2
    // (held for every pose, with a vector's growth, they doubled the memory of a `--replay`
    // run under PID: 1073 MB where the run alone peaked at 519 MB).
    let n = trace.poses().count();
    let mut pts: Vec<[f64; 2]> = Vec::with_capacity(n);
    let mut forced: Vec<bool> = Vec::with_capacity(n);
    let mut raw_events: Vec<(usize, &Event)> = Vec::new();
    let mut tiles: Vec<usize> = Vec::new();
    let mut seen_tiles = std::collections::BTreeSet::new();
    // Tiles are on the lattice of the pose coverage starts from; the start marker is where the
    // robot was placed (before the approach, when the start is outside the area).
    let start = world.start();
    let placed = world.initial_pose();
    // The approach's last pose (kept for display, so that the page can tell it apart).
    let approach = approach_end(world, trace);
    // Under odometry noise a tile counts within half a tile of the true path, as in
    // `coverage_rate` (the page drew 4 tiles beside a tile coverage of 47.5 %).
    let noisy = ccpp_core::metrics::noisy_execution(trace);
    // Tile outlines only when the page can ever draw them: it draws them from
    // `TILE_MIN_DRAWN_PX` device pixels a tile, on a canvas of at most `CANVAS_MAX_PX` on its
    // longer side (ba-star on `cluttered_2000` at r = 0.025 m embedded 11.5 MB of 1-pixel
    // tiles, 84 % of a 13.6 MB page, that no screen showed).
    let tile_side = tile_side
        .filter(|t| t / f.resolution * CANVAS_MAX_PX / w.max(h).max(1) as f64 >= TILE_MIN_DRAWN_PX);
    let mut approach_pose: Option<usize> = None;
    let to_crop = |x: f64, y: f64| -> [f64; 2] {
        let g = f.world_to_grid(Point::new(x, y));
        [g.x - c0 as f64, f.height as f64 - g.y - r0 as f64]
    };
    for r in trace.entries() {
        match r {
            Entry::Pose { pose, .. } => {
                let ends_approach = approach.is_some_and(|(end, _)| end == pts.len());
                pts.push(to_crop(pose.x, pose.y));
                if ends_approach {
                    approach_pose = Some(pts.len() - 1);
                }
                forced.push(ends_approach);
                if let Some(t) = tile_side {
                    let fi = (pose.x - start.x) / t;
                    let fj = (pose.y - start.y) / t;
                    let (i2, j2) = (fi.round(), fj.round());
                    let near = if noisy {
                        (fi - i2).hypot(fj - j2) <= ccpp_core::metrics::NOISY_TILE_VISIT_TILES
                    } else {
                        (fi - i2).abs() < 1e-3 && (fj - j2).abs() < 1e-3
                    };
                    if near && seen_tiles.insert((i2 as i64, j2 as i64)) {
                        tiles.push(pts.len() - 1);
                    }
                }
            }
            Entry::Event { event, .. } => {
                let i = pts.len().saturating_sub(1);
                if let Some(x) = forced.get_mut(i) {
                    *x = true;
                }
                raw_events.push((i, event));
            }
        }
    }
    let kept = decimate(&pts, &forced);
    drop(forced);
    let display = |orig: usize| -> usize { kept.partition_point(|&k| k < orig) };
    // Pass 2: heading, step and distance travelled at the kept poses.
    let mut theta: Vec<f64> = Vec::with_capacity(kept.len());
    let mut steps: Vec<u64> = Vec::with_capacity(kept.len());
    let mut dist: Vec<f64> = Vec::with_capacity(kept.len());
    {
        let mut next = kept.iter().copied().peekable();
        let mut travelled = 0.0f64;
        let mut last_world: Option<Point> = None;
        let mut i = 0usize;
        for r in trace.entries() {
            let Entry::Pose { t, pose } = r else { continue };
            let wp = Point::new(pose.x, pose.y);
            if let Some(l) = last_world {
                travelled += l.dist(wp);
            }
            last_world = Some(wp);
            if next.peek() == Some(&i) {
                next.next();
                theta.push(pose.theta);
                steps.push(t);
                dist.push(travelled);
            }
            i += 1;
        }
    }
    // The blob.
    let mut blob = Vec::with_capacity(kept.len() * 6);
    for axis in 0..2 {
        let mut prev = 0i64;
        for &k in &kept {
            let q = quantize(pts[k][axis]);
            push_varint(&mut blob, zigzag(q - prev));
            prev = q;
        }
    }
    let mut prev_t = 0u64;
    for &st in &steps {
        push_varint(&mut blob, st.saturating_sub(prev_t));
        prev_t = prev_t.max(st);
    }
    let mut prev_mm = 0u64;
    for &d in &dist {
        let mm = (d * 1000.0).round() as u64;
        push_varint(&mut blob, mm.saturating_sub(prev_mm));
        prev_mm = prev_mm.max(mm);
    }
    for &th in &theta {
        // On the image's axes: an origin yaw turns the image against the world.
        let a = (th - f.origin.theta).rem_euclid(std::f64::consts::TAU);
        blob.push(((a / std::f64::consts::TAU * 256.0).round() as u32 % 256) as u8);
    }
    let blob = base64::engine::general_purpose::STANDARD.encode(&blob);
    // Events, in display indices and crop pixel coordinates.
    let to_px = |x: f64, y: f64| {
        let g = f.world_to_grid(Point::new(x, y));
        (
            js_num(g.x - c0 as f64),
            js_num(f.height as f64 - g.y - r0 as f64),
        )
    };
    let mut events = String::from("[");
    for (i, event) in raw_events {
        let i = display(i);
        let item = match event {
            Event::RegionStart { region } => Some(format!(r#"[{i},"region",{region}]"#)),
            Event::CriticalPoint { x, y } => {
                let (a, b) = to_px(*x, *y);
                Some(format!(r#"[{i},"critical",{a},{b}]"#))
            }
            Event::StartPoint { x, y } => {
                let (a, b) = to_px(*x, *y);
                Some(format!(r#"[{i},"restart",{a},{b}]"#))
            }
            Event::BacktrackStart => Some(format!(r#"[{i},"bt_start"]"#)),
            Event::BacktrackEnd => Some(format!(r#"[{i},"bt_end"]"#)),
            Event::Collision { x, y } => {
                let (a, b) = to_px(*x, *y);
                Some(format!(r#"[{i},"collision",{a},{b}]"#))
            }
            Event::BacktrackList { points } => {
                let mut pts = String::new();
                for (k, p) in points.iter().enumerate() {
                    let (a, b) = to_px(p[0], p[1]);
                    if k > 0 {
                        pts.push(',');
                    }
                    let _ = write!(pts, "{a},{b}");
                }
                Some(format!(r#"[{i},"list",[{pts}]]"#))
            }
            _ => None,
        };
        if let Some(item) = item {
            if events.len() > 1 {
                events.push(',');
            }
            events.push_str(&item);
        }
    }
    events.push(']');
    // First tile visits: display index (of the first displayed pose at or after the visit)
    // delta, then the visiting pose's x and y (zigzag deltas, 1/Q px), as varints.
    let mut tblob = Vec::with_capacity(tiles.len() * 4);
    let (mut pi, mut px, mut py) = (0u64, 0i64, 0i64);
    for &i in &tiles {
        let d = display(i) as u64;
        let (qx, qy) = (quantize(pts[i][0]), quantize(pts[i][1]));
        push_varint(&mut tblob, d - pi);
        push_varint(&mut tblob, zigzag(qx - px));
        push_varint(&mut tblob, zigzag(qy - py));
        (pi, px, py) = (d, qx, qy);
    }
    let tblob = base64::engine::general_purpose::STANDARD.encode(&tblob);
    // Live coverage: [distance m, coverage] samples.
    let (curve, swept) = coverage_curve_and_swept(world, trace, COVERAGE_SAMPLES);
    // The legend entry of swept floor the metrics do not count (as coverage.png's), or null.
    let swept_outside = {
        let (mut out_of_reach, mut outside_area) = (false, false);
        for i in swept.ones() {
            match class_of(world, i) {
                Class::OutOfReach => out_of_reach = true,
                Class::OutsideArea => outside_area = true,
                _ => {}
            }
        }
        match (out_of_reach, outside_area) {
            (false, false) => "null",
            (true, false) => "\"swept, outside reachable floor\"",
            (false, true) => "\"swept, outside the area\"",
            (true, true) => "\"swept, outside the area or reachable floor\"",
        }
    };
    let mut cov = String::from("[");
    for (k, c) in curve.iter().enumerate() {
        if k > 0 {
            cov.push(',');
        }
        let _ = write!(cov, "{},{}", js_num(c[0]), js_num(c[1]));
    }
    cov.push(']');
    let (sx, sy) = {
        let g = f.world_to_grid(placed.position());
        (g.x - c0 as f64, f.height as f64 - g.y - r0 as f64)
    };
    // Tile side in map pixels (first visits are drawn around the visiting pose).
    let tile = tile_side.map_or_else(|| "null".to_string(), |t| js_num(t / f.resolution));
    let yaw = f.origin.theta;
    let zones = zones_js(world, crop);
    let approach = approach_pose.map_or_else(|| "null".to_string(), |i| display(i).to_string());
    // The stop reason (a run the planner did not finish) and the step the run ended at, both
    // from the `finished` record: a run the simulator stopped for a stall holds a thousand
    // steps after its last move, and the page's step count ended at that move (64 / 64 for a
    // run stopped at step 1063).
    let finished = finished_record(trace);
    let stop = unfinished(finished).map_or_else(
        || "null".to_string(),
        |why| serde_json::Value::String(why.to_string()).to_string(),
    );
    let last = finished.map_or_else(|| "null".to_string(), |(t, _)| t.to_string());
    let classes = classes_js(world, crop);
    format!(
        r#"{{"w":{w},"h":{h},"res":{res},"yaw":{yaw},"r":{r},"rt":{rt},"swept_r":{swept_r},"tile":{tile},"start":[{sx},{sy},{st}],"n":{n},"m":{m},"q":{q},"blob":"{blob}","events":{events},"nt":{nt},"tblob":"{tblob}","cov":{cov},"palette":{palette},"zones":{zones},"approach":{approach},"stop":{stop},"last":{last},"classes":{classes},"swept_outside":{swept_outside},"warnings":{warnings},"metrics":{metrics}}}"#,
        res = js_num(f.resolution),
        yaw = js_num(yaw),
        r = js_num(world.robot().radius / f.resolution),
        rt = js_num(world.robot().tool_radius / f.resolution),
        // Pixel centres within this many map pixels of a pose are swept (as in the metrics).
        swept_r =
            js_num(world.robot().tool_radius / f.resolution + ccpp_core::metrics::SWEEP_EPS_PX),
        sx = js_num(sx),
        sy = js_num(sy),
        st = js_num(placed.theta),
        n = pts.len(),
        nt = tiles.len(),
        m = kept.len(),
        q = Q,
        palette = palette_js(),
        warnings = serde_json::to_string(warnings).unwrap_or_else(|_| "[]".to_string()),
        metrics = if metrics_json.trim().is_empty() {
            "{}"
        } else {
            metrics_json.trim()
        },
    )
}

/// Which map classes outside the zones the crop shows (the legend lists only those):
/// `{"occupied":..,"unknown":..,"out_of_reach":..,"accessible":..}`.
fn classes_js(world: &World, crop: (usize, usize, usize, usize)) -> String {
    let f = *world.frame();
    let (c0, r0, w, h) = crop;
    let mut seen = [false; 4];
    'rows: for y in r0..r0 + h {
        for x in c0..c0 + w {
            let k = match class_of(world, f.index(x, y)) {
                Class::Occupied => 0,
                Class::Unknown => 1,
                Class::OutOfReach => 2,
                Class::Accessible => 3,
                Class::Keepout | Class::OutsideArea => continue,
            };
            seen[k] = true;
            if seen.iter().all(|s| *s) {
                break 'rows;
            }
        }
    }
    format!(
        r#"{{"occupied":{},"unknown":{},"out_of_reach":{},"accessible":{}}}"#,
        seen[0], seen[1], seen[2], seen[3]
    )
}

/// The zones for the page (`null` without zones): the area and keep-out polygons in crop
/// pixel coordinates (flat `x, y` lists), whether the crop shows keep-out floor and floor
/// outside the area, and the colours (the coverage picture's).
fn zones_js(world: &World, crop: (usize, usize, usize, usize)) -> String {
    let Some(z) = world.zones() else {
        return "null".into();
    };
    let f = *world.frame();
    let (c0, r0, w, h) = crop;
    let polys = |ps: &[ccpp_core::zones::Polygon]| {
        let items: Vec<String> = ps
            .iter()
            .map(|p| {
                let pts: Vec<String> = p
                    .ring()
                    .iter()
                    .map(|q| {
                        let g = f.world_to_grid(*q);
                        format!(
                            "{},{}",
                            js_num(g.x - c0 as f64),
                            js_num(f.height as f64 - g.y - r0 as f64)
                        )
                    })
                    .collect();
                format!("[{}]", pts.join(","))
            })
            .collect();
        format!("[{}]", items.join(","))
    };
    let (mut keepout, mut outside) = (false, false);
    for y in r0..r0 + h {
        for x in c0..c0 + w {
            match class_of(world, f.index(x, y)) {
                Class::Keepout => keepout = true,
                Class::OutsideArea => outside = true,
                _ => {}
            }
        }
    }
    let rgb = |c: [u8; 3]| format!("[{},{},{}]", c[0], c[1], c[2]);
    format!(
        r#"{{"area":{},"keep":{},"has_keepout":{keepout},"has_outside":{outside},"ko":{},"koh":{},"oa":{},"ab":{}}}"#,
        polys(&z.area_polygons),
        polys(&z.keepout_polygons),
        rgb(KEEPOUT),
        rgb(KEEPOUT_HATCH),
        rgb(OUTSIDE_AREA),
        rgb(AREA_BORDER)
    )
}

fn palette_js() -> String {
    let items: Vec<String> = crate::PALETTE
        .iter()
        .map(|c| format!("\"rgb({},{},{})\"", c[0], c[1], c[2]))
        .collect();
    format!("[{}]", items.join(","))
}

/// Builds the self-contained `replay.html` of a run.
///
/// The page sizes its canvas to the window (the side panel stays visible from 1280x720 up and
/// moves under the map on narrow screens), ships the path decimated for display (every event
/// kept) as compact base64 varints, draws incrementally on offscreen layers, and shows the
/// travelled distance, step, live effective coverage and current region or backtracking at the
/// scrubber. Opened with `#selftest` it checks itself and writes the result (timings and the
/// side panel's bounding boxes) into the title and `#selftest`. The run's `warnings` (as
/// `ccpp run` prints them) are counted in an amber badge in the header and listed under the
/// metrics.
///
/// # Errors
/// When the background image cannot be drawn.
pub fn replay_html(
    world: &World,
    trace: &Trace,
    tile_side: Option<f64>,
    metrics_json: &str,
    title: &str,
    warnings: &[String],
) -> Result<String, RenderError> {
    let crop = crop_box(world, trace);
    let bg = base64::engine::general_purpose::STANDARD.encode(background_png(world, crop)?);
    // No `<` in the script's data at all: `</script>` in a map or planner name would end the
    // script early, and `<!--<script>` (escaping `</` alone let it through) puts the HTML
    // parser in a state where the real `</script>` no longer ends it: a blank, dead page. In
    // JSON a `<` can only stand in a string, where `\u003c` is the same character.
    let data =
        replay_data(world, trace, tile_side, metrics_json, crop, warnings).replace('<', "\\u003c");
    // Braces as character references too: the page's later placeholders are replaced over
    // the whole page, so a map named `x{{DATA}}` put the whole data into the title.
    let title = title
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('{', "&#123;")
        .replace('}', "&#125;");
    let mut html = String::with_capacity(data.len() + bg.len() + 16000);
    html.push_str(
        &TEMPLATE
            .replace("{{TITLE}}", &title)
            .replace(
                "{{SWEPT}}",
                &format!("rgb({},{},{})", C_SWEPT[0], C_SWEPT[1], C_SWEPT[2]),
            )
            .replace(
                "{{ACC}}",
                &format!("rgb({},{},{})", C_ACC[0], C_ACC[1], C_ACC[2]),
            )
            .replace(
                "{{OUT}}",
                &format!("rgb({},{},{})", C_FREE_OUT[0], C_FREE_OUT[1], C_FREE_OUT[2]),
            )
            .replace("{{SR}}", &C_SWEPT[0].to_string())
            .replace("{{SG}}", &C_SWEPT[1].to_string())
            .replace("{{SB}}", &C_SWEPT[2].to_string())
            .replace("{{XR}}", &crate::colours::SWEPT_OUTSIDE[0].to_string())
            .replace("{{XG}}", &crate::colours::SWEPT_OUTSIDE[1].to_string())
            .replace("{{XB}}", &crate::colours::SWEPT_OUTSIDE[2].to_string())
            .replace("{{OR}}", &C_FREE_OUT[0].to_string())
            .replace("{{OG}}", &C_FREE_OUT[1].to_string())
            .replace("{{OB}}", &C_FREE_OUT[2].to_string())
            .replace("{{AR}}", &C_ACC[0].to_string())
            .replace("{{AG}}", &C_ACC[1].to_string())
            .replace("{{AB}}", &C_ACC[2].to_string()),
    );
    html = html.replace("{{BG}}", &bg).replace("{{DATA}}", &data);
    Ok(html)
}

const TEMPLATE: &str = include_str!("replay_template.html");

/// Options of [`replay_gif`].
#[derive(Clone, Debug)]
pub struct GifOptions {
    /// Largest side in pixels.
    pub max_side: u32,
    /// Number of animation frames (the last one is held); at most [`MAX_GIF_FRAMES`], more
    /// are drawn as that many (`usize::MAX` ran for minutes and hundreds of MB).
    pub frames: usize,
    /// Delay per frame in hundredths of a second.
    pub delay_cs: u16,
}

/// The most frames [`replay_gif`] draws ([`GifOptions::frames`]): at the default size, about
/// two seconds and a few MB.
pub const MAX_GIF_FRAMES: usize = 10_000;

impl Default for GifOptions {
    fn default() -> Self {
        Self {
            max_side: 400,
            frames: 60,
            delay_cs: 8,
        }
    }
}

/// Builds an animated GIF of the run (swept area growing, path, robot), with the work area's
/// and keep-outs' borders as in the coverage picture.
///
/// # Errors
/// When encoding fails.
pub fn replay_gif(world: &World, trace: &Trace, opts: &GifOptions) -> Result<Vec<u8>, RenderError> {
    let f = *world.frame();
    let (c0, r0, cw, ch) = crop_box(world, trace);
    let (k, (mw, mh), (gw, gh)) = gif_layout(cw, ch, opts.max_side);
    // The map's offset on the canvas (white margins around a map thinner than the canvas).
    let (ox, oy) = ((gw - mw) / 2, (gh - mh) / 2);
    // Palette: 0 occ, 1 unk, 2 free-out, 3 accessible, 4 swept, 5 path, 6 robot, 7 white,
    // 8 keep-out, 9 keep-out hatching and border, 10 outside the area, 11 area border, 12 the
    // start, 13 swept floor the metrics do not count (then padding to 16).
    let palette: Vec<u8> = [
        C_OCC,
        C_UNK,
        C_FREE_OUT,
        C_ACC,
        C_SWEPT,
        C_PATH,
        C_ROBOT,
        [255, 255, 255],
        KEEPOUT,
        KEEPOUT_HATCH,
        OUTSIDE_AREA,
        AREA_BORDER,
        C_START,
        crate::colours::SWEPT_OUTSIDE,
        [255, 255, 255],
        [255, 255, 255],
    ]
    .iter()
    .flat_map(|c| c.iter().copied())
    .collect();
    // The map pixel under canvas pixel (gx, gy), `None` in the margins.
    let src = |gx: usize, gy: usize| -> Option<usize> {
        let (mx, my) = (gx.checked_sub(ox)?, gy.checked_sub(oy)?);
        if mx >= mw || my >= mh {
            return None;
        }
        let c = (c0 + ((mx as f64 + 0.5) / k) as usize).min(f.width - 1);
        let r = (r0 + ((my as f64 + 0.5) / k) as usize).min(f.height - 1);
        Some(f.index(c, r))
    };
    let base: Vec<u8> = (0..gw * gh)
        .map(|p| {
            let Some(i) = src(p % gw, p / gw) else {
                return 7;
            };
            match class_of(world, i) {
                Class::Occupied => 0,
                Class::Unknown => 1,
                Class::OutOfReach => 2,
                Class::Accessible => 3,
                Class::Keepout if hatched(p % gw, p / gw) => 9,
                Class::Keepout => 8,
                Class::OutsideArea => 10,
            }
        })
        .collect();
    let (poses, progress) = motion_progress(trace, world.robot().radius);
    let to_gif = |p: Point| {
        let g = f.world_to_grid(p);
        (
            (g.x - c0 as f64) * k + ox as f64,
            (f.height as f64 - g.y - r0 as f64) * k + oy as f64,
        )
    };
    // The zones' borders (palette index per GIF pixel, 0 = none), drawn over the swept floor
    // and under the path.
    let mut borders = vec![0u8; gw * gh];
    if let Some(z) = world.zones() {
        for (polys, v) in [(&z.area_polygons, 11u8), (&z.keepout_polygons, 9u8)] {
            for poly in polys {
                let ring = poly.ring();
                let mut layer = vec![false; gw * gh];
                for (k, &a) in ring.iter().enumerate() {
                    let b = ring[(k + 1) % ring.len()];
                    draw_line(&mut layer, gw, gh, to_gif(a), to_gif(b));
                }
                for (d, on) in borders.iter_mut().zip(layer) {
                    if on {
                        *d = v;
                    }
                }
            }
        }
    }
    let mut out = Vec::new();
    {
        let mut enc = gif::Encoder::new(&mut out, gw as u16, gh as u16, &palette)
            .map_err(|e| RenderError::Encode(e.to_string()))?;
        enc.set_repeat(gif::Repeat::Infinite)
            .map_err(|e| RenderError::Encode(e.to_string()))?;
        let mut sweeper = Sweeper::new(world);
        let mut path_layer = vec![false; gw * gh];
        let n = poses.len();
        let frames = opts.frames.clamp(1, MAX_GIF_FRAMES);
        let total = progress.last().copied().unwrap_or(0.0);
        let mut done = 0usize;
        if let Some(&p0) = poses.first() {
            sweeper.add(p0, p0);
        }
        for fr in 1..=frames {
            // Frames are evenly spaced in motion (see `motion_progress`), not in poses: a PID
            // run records each step of a turn in place but only the ends of a straight glide,
            // and an ideal run one pose per move, however long.
            let target = if fr == frames {
                f64::INFINITY
            } else {
                total * fr as f64 / frames as f64
            };
            while done + 1 < n && progress[done + 1] <= target {
                let (a, b) = (poses[done], poses[done + 1]);
                sweeper.add(a, b);
                let (pa, pb) = (to_gif(a), to_gif(b));
                draw_line(&mut path_layer, gw, gh, pa, pb);
                done += 1;
            }
            // The move under way, as far as the frame's share of the motion reaches.
            let mut robot = poses.get(done).copied();
            if done + 1 < n {
                let (m0, m1) = (progress[done], progress[done + 1]);
                let t = if m1 > m0 {
                    ((target - m0) / (m1 - m0)).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let (a, b) = (poses[done], poses[done + 1]);
                let q = Point::new(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t);
                if t > 0.0 && q != a {
                    sweeper.add(a, q);
                    draw_line(&mut path_layer, gw, gh, to_gif(a), to_gif(q));
                }
                robot = Some(q);
            }
            let swept = sweeper.swept();
            let mut buf = base.clone();
            for (p, v) in buf.iter_mut().enumerate() {
                // Keep-outs keep their colours, as in the coverage picture; floor outside the
                // area or out of reach that the tool swept (the approach to the area) shows in
                // the coverage picture's lighter swept colour.
                if matches!(*v, 2 | 3 | 10)
                    && src(p % gw, p / gw).is_some_and(|i| swept.contains(i))
                {
                    *v = if *v == 3 { 4 } else { 13 };
                }
                if borders[p] != 0 {
                    *v = borders[p];
                }
                if path_layer[p] {
                    *v = 5;
                }
            }
            let rr = (world.robot().radius / f.resolution * k).max(2.0);
            // The start, as on the page and in the coverage picture (hostile pass: the GIF had
            // none).
            if let Some(&p0) = poses.first() {
                let (x, y) = to_gif(p0);
                fill_disk(&mut buf, gw, gh, x, y, (rr * 0.6).max(2.0), 12);
            }
            if let Some(p) = robot {
                let (x, y) = to_gif(p);
                fill_disk(&mut buf, gw, gh, x, y, rr, 6);
            }
            let mut frame = gif::Frame::from_indexed_pixels(gw as u16, gh as u16, buf, None);
            frame.delay = if fr == frames { 250 } else { opts.delay_cs };
            enc.write_frame(&frame)
                .map_err(|e| RenderError::Encode(e.to_string()))?;
        }
    }
    Ok(out)
}

/// The trace's positions and the motion up to each, metres: the distance driven plus, for
/// each turn, the arc the robot's rim sweeps (`radius` times the angle), so that a turn in
/// place takes GIF time too.
fn motion_progress(trace: &Trace, radius: f64) -> (Vec<Point>, Vec<f64>) {
    let n = trace.pose_count();
    let (mut points, mut progress) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let mut m = 0.0f64;
    let mut last: Option<ccpp_core::Pose> = None;
    for p in trace.poses() {
        if let Some(a) = last {
            m += a.position().dist(p.position())
                + radius * ccpp_core::geometry::wrap_angle(p.theta - a.theta).abs();
        }
        points.push(p.position());
        progress.push(m);
        last = Some(p);
    }
    (points, progress)
}

/// Thinnest the map's strip is drawn in the GIF, pixels, where the canvas may grow longer for
/// it (up to four times `max_side`): a 4000 x 9 px corridor was a GIF of 400 x 1 px, in which
/// nothing of the run could be made out.
const MIN_GIF_STRIP: f64 = 16.0;

/// Shortest side of the GIF's canvas, pixels: a thinner map stands in the middle of white
/// margins, as in the coverage picture.
const MIN_GIF_SIDE: usize = 48;

/// The GIF's scale (GIF pixels per map pixel), the map's size on the canvas and the canvas's
/// size, for a crop of `cw` x `ch` map pixels: the long side `max_side` at most 4 GIF pixels a
/// map pixel; a map so elongated that its short side would be thinner than [`MIN_GIF_STRIP`]
/// scaled up to reach it, the long side then up to `4 max_side`; the canvas at least
/// [`MIN_GIF_SIDE`] each way.
fn gif_layout(cw: usize, ch: usize, max_side: u32) -> (f64, (usize, usize), (usize, usize)) {
    let (long, short) = (cw.max(ch).max(1) as f64, cw.min(ch).max(1) as f64);
    let max_side = f64::from(max_side);
    let mut k = (max_side / long).min(4.0);
    if short * k < MIN_GIF_STRIP {
        let longest = (4.0 * max_side).min(f64::from(u16::MAX));
        k = (MIN_GIF_STRIP / short).min(longest / long).min(4.0).max(k);
    }
    let (mw, mh) = (
        ((cw as f64 * k).round() as usize).max(1),
        ((ch as f64 * k).round() as usize).max(1),
    );
    (k, (mw, mh), (mw.max(MIN_GIF_SIDE), mh.max(MIN_GIF_SIDE)))
}

fn draw_line(layer: &mut [bool], w: usize, h: usize, a: (f64, f64), b: (f64, f64)) {
    // Walk only the part inside the layer (plus a pixel): a pose far outside the map, as in a
    // hand-edited trace, must not make the walk astronomically long.
    let Some((a, b)) = clip_segment(a, b, (-1.0, -1.0), (w as f64 + 1.0, h as f64 + 1.0)) else {
        return;
    };
    let steps = ((b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil() as usize).max(1);
    for s in 0..=steps {
        let t = s as f64 / steps as f64;
        let x = a.0 + t * (b.0 - a.0);
        let y = a.1 + t * (b.1 - a.1);
        if x >= 0.0 && y >= 0.0 && (x as usize) < w && (y as usize) < h {
            layer[y as usize * w + x as usize] = true;
        }
    }
}

/// The part of segment `a`-`b` inside the box `lo`-`hi` (Liang-Barsky), `None` when there is
/// none or a coordinate is not finite. Endpoints inside the box are returned unchanged.
pub(crate) fn clip_segment(
    a: (f64, f64),
    b: (f64, f64),
    lo: (f64, f64),
    hi: (f64, f64),
) -> Option<((f64, f64), (f64, f64))> {
    if ![a.0, a.1, b.0, b.1].iter().all(|v| v.is_finite()) {
        return None;
    }
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-dx, a.0 - lo.0),
        (dx, hi.0 - a.0),
        (-dy, a.1 - lo.1),
        (dy, hi.1 - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else if p < 0.0 {
            t0 = t0.max(q / p);
        } else {
            t1 = t1.min(q / p);
        }
    }
    if t0 > t1 {
        return None;
    }
    let at = |t: f64| (a.0 + t * dx, a.1 + t * dy);
    Some((
        if t0 > 0.0 { at(t0) } else { a },
        if t1 < 1.0 { at(t1) } else { b },
    ))
}

fn fill_disk(buf: &mut [u8], w: usize, h: usize, x: f64, y: f64, r: f64, v: u8) {
    let (x0, x1) = (
        (x - r).floor().max(0.0) as usize,
        ((x + r).ceil() as usize).min(w.saturating_sub(1)),
    );
    let (y0, y1) = (
        (y - r).floor().max(0.0) as usize,
        ((y + r).ceil() as usize).min(h.saturating_sub(1)),
    );
    for yy in y0..=y1 {
        for xx in x0..=x1 {
            let dx = xx as f64 + 0.5 - x;
            let dy = yy as f64 + 0.5 - y;
            if dx * dx + dy * dy <= r * r {
                buf[yy * w + xx] = v;
            }
        }
    }
}

/// Test access to the page data (for the coverage picture's tests, which build the runs).
#[cfg(test)]
pub(crate) mod tests_support {
    use super::{replay_data, Trace, World};

    /// The page data of a run (no tiles, no metrics).
    pub(crate) fn data(world: &World, trace: &Trace) -> String {
        replay_data(world, trace, None, "{}", crate::crop_box(world, trace), &[])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A room with a work area and a keep-out, a start inside the area and one lane.
    fn zoned() -> (World, Trace) {
        use ccpp_core::zones::{Polygon, ZoneMasks};
        let map =
            ccpp_core::grid::GridMap::from_ascii_scaled("######\n#....#\n#....#\n######", 20, 0.05)
                .unwrap();
        let area = [Polygon::rect([0.1, 0.1, 2.0, 2.9])];
        let keepout = [Polygon::rect([1.2, 1.8, 1.7, 2.3])];
        let zones = ZoneMasks::new(map.frame(), Some(&area), &keepout, &[]);
        let start = ccpp_core::Pose::new(1.3, 1.3, 0.0);
        let world = World::with_zones(
            map,
            ccpp_core::world::Robot::new(0.15),
            Some(start),
            Some(zones),
        )
        .unwrap();
        let mut trace = Trace::default();
        trace.push_pose(0, start);
        trace.push_pose(1, ccpp_core::Pose::new(1.8, 1.3, 0.0));
        (world, trace)
    }

    /// The GIF draws the area's and keep-outs' borders (README: "`coverage.png` and the replay
    /// (`replay.html`, `replay.gif`) ... draw the area and keep-out polygon borders").
    #[test]
    fn the_gif_draws_the_zone_borders() {
        let (world, trace) = zoned();
        let bytes = replay_gif(&world, &trace, &GifOptions::default()).unwrap();
        let mut opts = gif::DecodeOptions::new();
        opts.set_color_output(gif::ColorOutput::RGBA);
        let mut dec = opts.read_info(std::io::Cursor::new(bytes)).unwrap();
        let frame = dec.read_next_frame().unwrap().unwrap();
        let count = |c: [u8; 3]| {
            frame
                .buffer
                .chunks_exact(4)
                .filter(|p| p[..3] == c[..])
                .count()
        };
        assert!(count(AREA_BORDER) > 100, "area border pixels");
        // The keep-out's border: its hatching colour beyond the hatching inside it.
        assert!(count(KEEPOUT_HATCH) > 0);
        // The robot is the page's yellow disc, not the start's green (the tester read the
        // green dot at the end of an approach as the start).
        assert!(count(C_ROBOT) > 10, "robot pixels");
        assert_eq!(C_ROBOT, [255, 212, 0]);
        assert!(TEMPLATE.contains("rgba(255,212,0,"));
        // The start is marked once the robot has left it, in the page's green (the GIF had
        // no start: hostile pass).
        let mut last = frame.buffer.to_vec();
        while let Some(f) = dec.read_next_frame().unwrap() {
            last = f.buffer.to_vec();
        }
        let starts = last
            .chunks_exact(4)
            .filter(|p| p[..3] == C_START[..])
            .count();
        assert!(starts > 3, "start pixels: {starts}");
        assert!(TEMPLATE.contains("rgb(0,170,60)") && C_START == [0, 170, 60]);
    }

    /// The GIF's frames are spaced in motion, not in poses: one long move then a hundred
    /// short ones (a PID run records a glide by its ends and a turn step by step) put the
    /// robot halfway along the long move at the middle frame, not at its end.
    #[test]
    fn the_gif_paces_its_frames_by_motion() {
        let map = ccpp_core::grid::GridMap::from_ascii_scaled(
            "############\n#..........#\n#..........#\n############",
            10,
            0.05,
        )
        .unwrap();
        let start = ccpp_core::Pose::new(0.8, 1.0, 0.0);
        let world = World::new(map, ccpp_core::world::Robot::new(0.15), Some(start)).unwrap();
        let mut trace = Trace::default();
        trace.push_pose(0, start);
        trace.push_pose(1, ccpp_core::Pose::new(4.8, 1.0, 0.0));
        for k in 0..100 {
            let th = if k % 2 == 0 { 0.01 } else { 0.0 };
            trace.push_pose(2 + k, ccpp_core::Pose::new(4.8, 1.0, th));
        }
        let opts = GifOptions {
            frames: 10,
            ..GifOptions::default()
        };
        let bytes = replay_gif(&world, &trace, &opts).unwrap();
        let mut dec = gif::DecodeOptions::new();
        dec.set_color_output(gif::ColorOutput::RGBA);
        let mut dec = dec.read_info(std::io::Cursor::new(bytes)).unwrap();
        let w = usize::from(dec.width());
        // The robot's mean column in each frame, as a share of the canvas width.
        let mut xs = Vec::new();
        while let Some(frame) = dec.read_next_frame().unwrap() {
            let (mut sum, mut n) = (0usize, 0usize);
            for (i, p) in frame.buffer.chunks_exact(4).enumerate() {
                if p[..3] == C_ROBOT[..] {
                    sum += i % w;
                    n += 1;
                }
            }
            assert!(n > 0);
            xs.push(sum as f64 / n as f64 / w as f64);
        }
        assert_eq!(xs.len(), 10);
        // The motion is 4 m of driving and 100 heading changes of 0.01 rad (0.15 m of the
        // rim's arc): the fifth frame (of ten) shows the robot at x = 0.8 + 0.5 * 4.15 m of a
        // 6 m wide map, within a GIF pixel or two (pacing by poses put it at 4.8 m).
        let want = (0.8 + 0.5 * 4.15) / 6.0;
        assert!((xs[4] - want).abs() < 0.01, "{xs:?}");
        assert!(xs.windows(2).all(|p| p[1] >= p[0] - 1e-9), "{xs:?}");
    }

    /// `frames: usize::MAX` ran for minutes and hundreds of MB (hostile pass): the GIF has
    /// [`MAX_GIF_FRAMES`] frames.
    #[test]
    fn a_gif_has_at_most_the_frame_limit() {
        let map =
            ccpp_core::grid::GridMap::from_ascii_scaled("######\n#....#\n######", 4, 0.05).unwrap();
        let start = ccpp_core::Pose::new(0.3, 0.3, 0.0);
        let world = World::new(map, ccpp_core::world::Robot::new(0.05), Some(start)).unwrap();
        let mut trace = Trace::default();
        trace.push_pose(0, start);
        trace.push_pose(1, ccpp_core::Pose::new(0.9, 0.3, 0.0));
        let opts = GifOptions {
            frames: usize::MAX,
            max_side: 16,
            ..GifOptions::default()
        };
        let bytes = replay_gif(&world, &trace, &opts).unwrap();
        let mut dec = gif::DecodeOptions::new()
            .read_info(std::io::Cursor::new(bytes))
            .unwrap();
        let mut n = 0;
        while dec.read_next_frame().unwrap().is_some() {
            n += 1;
        }
        assert_eq!(n, MAX_GIF_FRAMES);
    }

    /// A corridor of 4000 x 9 px was a GIF of 400 x 1 px: the strip is now at least 16 px
    /// thick where a longer GIF (up to 1600 px) allows it, or as thick as that length allows,
    /// on a canvas of at least 48 px each way; ordinary maps keep their size.
    #[test]
    fn an_elongated_map_makes_a_gif_one_can_see() {
        // (crop w, crop h) -> (map on the canvas, canvas)
        for ((cw, ch), map, canvas) in [
            ((600, 400), (400, 267), (400, 267)),
            ((4000, 40), (1600, 16), (1600, 48)),
            ((400, 4000), (40, 400), (48, 400)),
            ((4000, 9), (1600, 4), (1600, 48)),
            ((9, 4000), (4, 1600), (48, 1600)),
            ((3, 3), (12, 12), (48, 48)),
            ((1000, 100), (400, 40), (400, 48)),
        ] {
            let (_, m, c) = gif_layout(cw, ch, 400);
            assert_eq!((m, c), (map, canvas), "{cw} x {ch}");
        }
        // The canvas fits a GIF's 16-bit sides whatever `max_side` asks.
        let (_, _, c) = gif_layout(1_000_000, 1, 60_000);
        assert!(u16::try_from(c.0).is_ok(), "{c:?}");
    }

    /// The margins of a thin map's GIF are white, and the run is drawn in the map's strip.
    #[test]
    fn a_thin_map_stands_in_white_margins() {
        let map = ccpp_core::grid::GridMap::from_ascii_scaled(
            &format!(
                "{}\n#{}#\n{}",
                "#".repeat(60),
                ".".repeat(58),
                "#".repeat(60)
            ),
            6,
            0.05,
        )
        .unwrap();
        let start = ccpp_core::Pose::new(0.5, 0.45, 0.0);
        let world = World::new(map, ccpp_core::world::Robot::new(0.1), Some(start)).unwrap();
        let mut trace = Trace::default();
        trace.push_pose(0, start);
        trace.push_pose(1, ccpp_core::Pose::new(17.5, 0.45, 0.0));
        let bytes = replay_gif(&world, &trace, &GifOptions::default()).unwrap();
        let mut opts = gif::DecodeOptions::new();
        opts.set_color_output(gif::ColorOutput::RGBA);
        let mut dec = opts.read_info(std::io::Cursor::new(bytes)).unwrap();
        let (w, h) = (usize::from(dec.width()), usize::from(dec.height()));
        assert_eq!((w, h), (400, 48));
        let frame = dec.read_next_frame().unwrap().unwrap();
        let px = |x: usize, y: usize| &frame.buffer[(y * w + x) * 4..][..3];
        // 360 x 18 map pixels at 400/360 GIF px each: 20 px tall, rows 14 to 33.
        for x in [0, w / 2, w - 1] {
            assert_eq!(px(x, 0), [255, 255, 255]);
            assert_eq!(px(x, h - 1), [255, 255, 255]);
        }
        assert!(
            (0..w).any(|x| px(x, h / 2) == C_PATH),
            "the path in the strip"
        );
    }

    /// The approach's dotted style is tested before backtracking's (both negative): the other
    /// way round a finished approach was drawn dashed, as backtracking, while the move under
    /// way was dotted.
    #[test]
    fn a_finished_approach_keeps_its_style() {
        let approach = TEMPLATE
            .find("if (style === -2) {")
            .expect("approach style");
        let backtrack = TEMPLATE
            .find("} else if (style < 0) {")
            .expect("backtrack style");
        assert!(approach < backtrack);
    }

    /// Tile outlines are embedded only when the page can draw them (from `TILE_MIN_DRAWN_PX`
    /// device pixels a tile on a canvas of at most `CANVAS_MAX_PX`, the template's own
    /// numbers): 1-pixel tiles on a 2000-pixel map were 84 % of a 13.6 MB page. The outlines
    /// turn with the map's yaw the way headings do (they turned the other way: on a map of yaw
    /// 0.5 the squares were the lanes' mirror image).
    #[test]
    fn tiles_are_embedded_when_the_page_can_draw_them() {
        let (world, trace) = zoned();
        let crop = crate::crop_box(&world, &trace);
        let shown = replay_data(&world, &trace, Some(0.3), "{}", crop, &[]);
        assert!(
            shown.contains(r#""tile":6,"#) && !shown.contains(r#""nt":0,"#),
            "{shown:.300}"
        );
        // 0.1 px tiles on a 120 px map: at most 3.4 device pixels a tile.
        let hidden = replay_data(&world, &trace, Some(0.005), "{}", crop, &[]);
        assert!(hidden.contains(r#""tile":null,"#) && hidden.contains(r#""nt":0,"#));
        assert!(TEMPLATE.contains("const k = Math.min(dpr, 4096 / Math.max(cssW, cssH));"));
        assert!(TEMPLATE.contains("D.tile * S >= 6;"));
        assert_eq!((CANVAS_MAX_PX, TILE_MIN_DRAWN_PX), (4096.0, 6.0));
        assert!(TEMPLATE.contains("paC.rotate(D.yaw); paC.strokeRect"));
        // Headings on the canvas: (cos h, -sin h) for an angle h on the image's axes, the
        // same turn as `rotate(+yaw)` on a y-down canvas.
        assert!(TEMPLATE.contains("cy - rr * Math.sin(h)"));
        // The run's warnings go into the page's data (a `<` in one escaped like the rest)
        // and the page counts and lists them.
        let warned = replay_data(
            &world,
            &trace,
            None,
            "{}",
            crop,
            &["a <b> warning".to_string()],
        );
        assert!(warned.contains(r#""warnings":["a <b> warning"]"#));
        assert!(TEMPLATE.contains(r#"b.textContent = D.warnings.length + (D.warnings.length === 1 ? " warning" : " warnings")"#));
        assert!(TEMPLATE.contains("li.textContent = w;"));
        // The legend's region count says how many of the run's regions are drawn (a region
        // with no move has no colour: it said 24 beside the metrics' 28).
        assert!(TEMPLATE.contains(r#"" drawn of " + D.metrics.regions"#));
    }

    /// The page lists only the map classes the map shows (`teb_maze` has no unknown pixel, the
    /// legend said "unknown") and names the wall time for what it is.
    #[test]
    fn the_page_knows_which_classes_the_map_shows() {
        let (world, trace) = zoned();
        let data = tests_support::data(&world, &trace);
        assert!(data.contains(r#""unknown":false"#), "{}", &data[..200]);
        assert!(data.contains(r#""occupied":true"#));
        assert!(TEMPLATE.contains("if (C.unknown) add("));
        assert!(TEMPLATE.contains(r#"["wall_time_s", "planning + simulation time", "s"]"#));
        assert!(data.contains(r#""stop":null"#));
    }

    fn seg_dist(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let l2 = dx * dx + dy * dy;
        let t = if l2 > 0.0 {
            (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
    }

    /// A trace's poses as the replay reads them: each move ends in a pose, and a turn in
    /// place repeats the position.
    fn poses(vertices: &[(f64, f64)]) -> Vec<[f64; 2]> {
        let mut out = Vec::new();
        for &(x, y) in vertices {
            out.push([x, y]);
            out.push([x, y]);
        }
        out
    }

    #[test]
    fn a_corner_before_an_event_pose_is_kept() {
        // t=8 turn and move to the corner, t=9 turn and move on, then an event: the corner
        // was dropped and the page drew (0,0) -> (20,10) straight.
        let pts = poses(&[(0.0, 0.0), (10.0, 0.0), (20.0, 10.0)]);
        let mut forced = vec![false; pts.len()];
        forced[0] = true;
        // The event follows the move's end pose (the turn after it is its own pose).
        forced[pts.len() - 2] = true;
        let kept = decimate(&pts, &forced);
        assert!(kept.iter().any(|&k| pts[k] == [10.0, 0.0]), "{kept:?}");
    }

    /// The page draws the heading on the image's axes: with the map's origin turned by pi/2,
    /// world east (theta 0) is a quarter turn clockwise there, heading byte 192 (it was 0,
    /// drawn pointing at world north).
    #[test]
    fn the_heading_byte_is_on_the_image_axes() {
        let byte = |yaw: f64| {
            let map = ccpp_core::grid::GridMap::from_ascii_scaled("#####\n#...#\n#####", 10, 0.05)
                .unwrap()
                .with_placement(0.05, ccpp_core::Pose::new(0.0, 0.0, yaw))
                .unwrap();
            let c = map.frame().grid_to_world(Point::new(25.0, 15.0));
            let start = ccpp_core::Pose::new(c.x, c.y, 0.0);
            let world = World::new(map, ccpp_core::world::Robot::new(0.1), Some(start)).unwrap();
            let mut trace = Trace::default();
            trace.push_pose(0, start);
            let data = replay_data(&world, &trace, None, "{}", crop_box(&world, &trace), &[]);
            let blob = data
                .split("\"blob\":\"")
                .nth(1)
                .unwrap()
                .split('"')
                .next()
                .unwrap();
            let bytes = base64::engine::general_purpose::STANDARD
                .decode(blob)
                .unwrap();
            *bytes.last().unwrap()
        };
        assert_eq!(byte(0.0), 0);
        assert_eq!(byte(std::f64::consts::FRAC_PI_2), 192);
    }

    proptest! {
        /// Every pose lies within twice the tolerance of the drawn polyline, between the kept
        /// poses around it (the line through the anchor bounds the dropped poses by the
        /// tolerance; the drawn segment to the next kept pose by as much again).
        #[test]
        fn the_drawn_path_follows_every_pose(
            vertices in prop::collection::vec((0.0f64..60.0, 0.0f64..60.0), 1..40),
            events in prop::collection::vec(any::<bool>(), 80),
        ) {
            let pts = poses(&vertices);
            let forced: Vec<bool> = (0..pts.len()).map(|i| events[i % events.len()] && i % 3 == 0).collect();
            let kept = decimate(&pts, &forced);
            prop_assert_eq!(kept[0], 0);
            prop_assert_eq!(*kept.last().unwrap(), pts.len() - 1);
            for (i, f) in forced.iter().enumerate() {
                prop_assert!(!f || kept.contains(&i));
            }
            for w in kept.windows(2) {
                prop_assert!(w[0] < w[1]);
                for p in &pts[w[0]..=w[1]] {
                    let d = seg_dist(*p, pts[w[0]], pts[w[1]]);
                    prop_assert!(d <= 2.0 * DECIMATE_TOL_PX + 1e-9, "{:?} is {} px off {:?}", p, d, w);
                }
            }
        }
    }
}

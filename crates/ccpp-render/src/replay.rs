//! The self-contained HTML replay (no network, no external file) and the animated GIF.

use std::fmt::Write as _;

use base64::Engine as _;
use ccpp_core::grid::Cell;
use ccpp_core::metrics::Sweeper;
use ccpp_core::trace::{Event, Record, Trace};
use ccpp_core::world::World;
use ccpp_core::Point;
use tiny_skia::{Color, Pixmap};

use crate::{crop_box, RenderError};

/// Map class colours shared by the replay page and the GIF.
const C_OCC: [u8; 3] = [30, 30, 30];
const C_UNK: [u8; 3] = [170, 170, 170];
const C_FREE_OUT: [u8; 3] = [246, 246, 242];
const C_ACC: [u8; 3] = [250, 205, 190];
/// Swept floor (also the colour the browser test looks for).
pub const C_SWEPT: [u8; 3] = [120, 190, 245];
const C_PATH: [u8; 3] = [0, 70, 160];
const C_ROBOT: [u8; 3] = [0, 160, 60];

fn class_colour(world: &World, i: usize) -> [u8; 3] {
    match world.map().cells()[i] {
        Cell::Occupied => C_OCC,
        Cell::Unknown => C_UNK,
        Cell::Free => {
            if world.accessible().contains(i) {
                C_ACC
            } else {
                C_FREE_OUT
            }
        }
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
            let c = class_colour(world, f.index(c0 + x, r0 + y));
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

/// The replay data as a JS object literal (deterministic text).
fn replay_data(
    world: &World,
    trace: &Trace,
    tile_side: Option<f64>,
    metrics_json: &str,
    crop: (usize, usize, usize, usize),
) -> String {
    let f = *world.frame();
    let mut poses = String::from("[");
    let mut events = String::from("[");
    let mut n = 0usize;
    for r in &trace.records {
        match r {
            Record::Pose { pose, .. } => {
                if n > 0 {
                    poses.push(',');
                }
                let _ = write!(
                    poses,
                    "[{},{},{}]",
                    js_num(pose[0]),
                    js_num(pose[1]),
                    js_num(pose[2])
                );
                n += 1;
            }
            Record::Event { event, .. } => {
                let i = n.saturating_sub(1);
                let item = match event {
                    Event::RegionStart { region } => {
                        Some(format!(r#"{{"i":{i},"k":"region","n":{region}}}"#))
                    }
                    Event::CriticalPoint { x, y } => Some(format!(
                        r#"{{"i":{i},"k":"critical","x":{},"y":{}}}"#,
                        js_num(*x),
                        js_num(*y)
                    )),
                    Event::StartPoint { x, y } => Some(format!(
                        r#"{{"i":{i},"k":"start","x":{},"y":{}}}"#,
                        js_num(*x),
                        js_num(*y)
                    )),
                    Event::BacktrackStart => Some(format!(r#"{{"i":{i},"k":"bt_start"}}"#)),
                    Event::BacktrackEnd => Some(format!(r#"{{"i":{i},"k":"bt_end"}}"#)),
                    Event::Collision { x, y } => Some(format!(
                        r#"{{"i":{i},"k":"collision","x":{},"y":{}}}"#,
                        js_num(*x),
                        js_num(*y)
                    )),
                    Event::BacktrackList { points } => {
                        let pts: Vec<String> = points
                            .iter()
                            .map(|p| format!("[{},{}]", js_num(p[0]), js_num(p[1])))
                            .collect();
                        Some(format!(r#"{{"i":{i},"k":"list","p":[{}]}}"#, pts.join(",")))
                    }
                    Event::BacktrackPoint { x, y } => Some(format!(
                        r#"{{"i":{i},"k":"bp","x":{},"y":{}}}"#,
                        js_num(*x),
                        js_num(*y)
                    )),
                    _ => None,
                };
                if let Some(item) = item {
                    if events.len() > 1 {
                        events.push(',');
                    }
                    events.push_str(&item);
                }
            }
        }
    }
    poses.push(']');
    events.push(']');
    let (c0, r0, w, h) = crop;
    let start = world.start();
    format!(
        r#"{{"res":{res},"ox":{ox},"oy":{oy},"yaw":{yaw},"height":{height},"c0":{c0},"r0":{r0},"w":{w},"h":{h},"r":{r},"rt":{rt},"tile":{tile},"start":[{sx},{sy}],"poses":{poses},"events":{events},"metrics":{metrics}}}"#,
        res = f.resolution,
        ox = f.origin.x,
        oy = f.origin.y,
        yaw = f.origin.theta,
        height = f.height,
        r = world.robot().radius,
        rt = world.robot().tool_radius,
        tile = tile_side.map_or_else(|| "null".into(), |t| t.to_string()),
        sx = js_num(start.x),
        sy = js_num(start.y),
        metrics = if metrics_json.trim().is_empty() {
            "{}"
        } else {
            metrics_json.trim()
        },
    )
}

/// Builds the self-contained `replay.html` of a run.
///
/// # Errors
/// When the background image cannot be drawn.
pub fn replay_html(
    world: &World,
    trace: &Trace,
    tile_side: Option<f64>,
    metrics_json: &str,
    title: &str,
) -> Result<String, RenderError> {
    let crop = crop_box(world, trace);
    let bg = base64::engine::general_purpose::STANDARD.encode(background_png(world, crop)?);
    let data = replay_data(world, trace, tile_side, metrics_json, crop);
    let title = title.replace('&', "&amp;").replace('<', "&lt;");
    let mut html = String::with_capacity(data.len() + bg.len() + 8000);
    html.push_str(
        &TEMPLATE
            .replace("{{TITLE}}", &title)
            .replace(
                "{{SWEPT}}",
                &format!("rgb({},{},{})", C_SWEPT[0], C_SWEPT[1], C_SWEPT[2]),
            )
            .replace("{{SR}}", &C_SWEPT[0].to_string())
            .replace("{{SG}}", &C_SWEPT[1].to_string())
            .replace("{{SB}}", &C_SWEPT[2].to_string()),
    );
    html = html.replace("{{BG}}", &bg).replace("{{DATA}}", &data);
    Ok(html)
}

const TEMPLATE: &str = r##"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{{TITLE}}</title>
<meta name="viewport" content="width=device-width, initial-scale=1">
<style>
body{margin:0;font:14px system-ui,sans-serif;background:#f4f4f4;color:#222}
header{padding:8px 12px;background:#fff;border-bottom:1px solid #ccc}
#controls{display:flex;gap:10px;align-items:center;padding:8px 12px;background:#fff;border-bottom:1px solid #ddd;flex-wrap:wrap}
#scrub{flex:1;min-width:200px}
#wrap{display:flex;gap:12px;padding:12px}
canvas{background:#fff;border:1px solid #bbb;image-rendering:pixelated;max-width:100%}
#side{min-width:230px;font-size:13px}
#side table{border-collapse:collapse}#side td{padding:1px 6px}
.key{display:inline-block;width:12px;height:12px;border:1px solid #888;vertical-align:middle;margin-right:4px}
</style></head><body>
<header><b>ccpp replay</b> — {{TITLE}}</header>
<div id="controls">
<button id="play" type="button">Play</button>
<label>Speed <select id="speed"><option value="1">1x</option><option value="4">4x</option><option value="16" selected>16x</option><option value="64">64x</option><option value="256">256x</option></select></label>
<input id="scrub" type="range" min="0" max="0" value="0" aria-label="frame">
<span id="label">0 / 0</span>
</div>
<div id="wrap"><canvas id="view"></canvas>
<div id="side"><div id="legend">
<div><span class="key" style="background:{{SWEPT}}"></span>swept floor</div>
<div><span class="key" style="background:rgb(250,205,190)"></span>floor not yet swept</div>
<div><span class="key" style="background:#1e1e1e"></span>obstacle <span class="key" style="background:#aaa"></span>unknown</div>
<div><span class="key" style="background:#ffa000"></span>critical point <span class="key" style="background:#8e24aa"></span>backtracking list</div>
<div><span class="key" style="background:#444"></span>backtracking path (dashed)</div>
</div><h4>Metrics</h4><table id="metrics"></table><pre id="selftest"></pre></div></div>
<img id="bg" alt="" style="display:none" src="data:image/png;base64,{{BG}}">
<script>
"use strict";
const D = {{DATA}};
const errors = [];
window.addEventListener("error", e => errors.push(String(e.message)));
const canvas = document.getElementById("view"), ctx = canvas.getContext("2d");
const scrub = document.getElementById("scrub"), label = document.getElementById("label");
const playBtn = document.getElementById("play"), speedSel = document.getElementById("speed");
const N = D.poses.length;
scrub.max = String(Math.max(0, N - 1));
const S = Math.max(1, Math.min(8, 1100 / Math.max(D.w, D.h / 0.8)));
canvas.width = Math.round(D.w * S); canvas.height = Math.round(D.h * S);
const swept = document.createElement("canvas"); swept.width = canvas.width; swept.height = canvas.height;
const sctx = swept.getContext("2d");
const cy = Math.cos(D.yaw), sy = Math.sin(D.yaw);
function toCanvas(x, y) {
  const dx = x - D.ox, dy = y - D.oy;
  const gx = (cy * dx + sy * dy) / D.res, gy = (-sy * dx + cy * dy) / D.res;
  return [(gx - D.c0) * S, (D.height - gy - D.r0) * S];
}
const P = D.poses.map(p => toCanvas(p[0], p[1]));
// Backtracking flags per segment end index.
const inBt = new Uint8Array(N);
{ let bt = false, k = 0; const ev = D.events;
  for (let i = 0; i < N; i++) { while (k < ev.length && ev[k].i < i) { if (ev[k].k === "bt_start") bt = true; if (ev[k].k === "bt_end") bt = false; k++; } inBt[i] = bt ? 1 : 0; } }
let drawnTo = 0;
function sweepTo(i) {
  if (i < drawnTo) { sctx.clearRect(0, 0, swept.width, swept.height); drawnTo = 0; }
  sctx.strokeStyle = "{{SWEPT}}"; sctx.fillStyle = "{{SWEPT}}"; sctx.lineCap = "round"; sctx.lineJoin = "round";
  sctx.lineWidth = 2 * D.rt / D.res * S;
  if (drawnTo === 0 && N > 0) { sctx.beginPath(); sctx.arc(P[0][0], P[0][1], D.rt / D.res * S, 0, 2 * Math.PI); sctx.fill(); }
  sctx.beginPath();
  for (let k = Math.max(1, drawnTo); k <= i; k++) { sctx.moveTo(P[k - 1][0], P[k - 1][1]); sctx.lineTo(P[k][0], P[k][1]); }
  sctx.stroke();
  drawnTo = Math.max(drawnTo, i);
}
const bg = document.getElementById("bg");
let frame = 0, playing = false;
const robotAt = [0, 0];
function draw(i) {
  frame = Math.max(0, Math.min(N - 1, i));
  ctx.imageSmoothingEnabled = false;
  ctx.drawImage(bg, 0, 0, canvas.width, canvas.height);
  sweepTo(frame);
  ctx.globalAlpha = 0.85; ctx.drawImage(swept, 0, 0); ctx.globalAlpha = 1;
  // Tiles covered so far (tile planners).
  if (D.tile) {
    const t = D.tile, half = t / 2, seen = new Set();
    ctx.strokeStyle = "rgba(0,60,140,0.25)"; ctx.lineWidth = 1;
    for (let k = 0; k <= frame; k++) {
      const p = D.poses[k], fi = (p[0] - D.start[0]) / t, fj = (p[1] - D.start[1]) / t;
      const i2 = Math.round(fi), j2 = Math.round(fj);
      if (Math.abs(fi - i2) < 1e-3 && Math.abs(fj - j2) < 1e-3) {
        const key = i2 + "," + j2; if (seen.has(key)) continue; seen.add(key);
        const a = toCanvas(D.start[0] + i2 * t - half, D.start[1] + j2 * t + half), b = toCanvas(D.start[0] + i2 * t + half, D.start[1] + j2 * t - half);
        ctx.strokeRect(Math.min(a[0], b[0]), Math.min(a[1], b[1]), Math.abs(b[0] - a[0]), Math.abs(b[1] - a[1]));
      }
    }
  }
  // Path: solid while covering, dashed while backtracking.
  ctx.lineWidth = Math.max(1, S * 0.6);
  for (const dashed of [false, true]) {
    ctx.setLineDash(dashed ? [6, 4] : []); ctx.strokeStyle = dashed ? "#444" : "rgb(0,70,160)";
    ctx.beginPath();
    for (let k = 1; k <= frame; k++) if ((inBt[k] === 1) === dashed) { ctx.moveTo(P[k - 1][0], P[k - 1][1]); ctx.lineTo(P[k][0], P[k][1]); }
    ctx.stroke();
  }
  ctx.setLineDash([]);
  let list = null;
  for (const e of D.events) {
    if (e.i > frame) break;
    if (e.k === "critical") { const c = toCanvas(e.x, e.y); ctx.fillStyle = "#ffa000"; ctx.fillRect(c[0] - 4, c[1] - 4, 8, 8); }
    else if (e.k === "collision") { const c = toCanvas(e.x, e.y); ctx.strokeStyle = "red"; ctx.lineWidth = 2; ctx.beginPath(); ctx.moveTo(c[0]-5,c[1]-5); ctx.lineTo(c[0]+5,c[1]+5); ctx.moveTo(c[0]-5,c[1]+5); ctx.lineTo(c[0]+5,c[1]-5); ctx.stroke(); }
    else if (e.k === "list") list = e.p;
  }
  if (list) { ctx.fillStyle = "#8e24aa"; for (const p of list) { const c = toCanvas(p[0], p[1]); ctx.beginPath(); ctx.arc(c[0], c[1], 3, 0, 2 * Math.PI); ctx.fill(); } }
  if (N > 0) {
    const p = D.poses[frame], c = P[frame], rr = D.r / D.res * S;
    ctx.fillStyle = "rgba(0,160,60,0.8)"; ctx.beginPath(); ctx.arc(c[0], c[1], Math.max(3, rr), 0, 2 * Math.PI); ctx.fill();
    ctx.strokeStyle = "#fff"; ctx.lineWidth = 2; ctx.beginPath(); ctx.moveTo(c[0], c[1]);
    ctx.lineTo(c[0] + Math.max(3, rr) * Math.cos(p[2]), c[1] - Math.max(3, rr) * Math.sin(p[2])); ctx.stroke();
    robotAt[0] = c[0]; robotAt[1] = c[1];
  }
  scrub.value = String(frame);
  label.textContent = frame + " / " + (N - 1);
}
function tick() {
  if (!playing) return;
  if (frame >= N - 1) { playing = false; playBtn.textContent = "Play"; return; }
  draw(frame + Number(speedSel.value));
  requestAnimationFrame(tick);
}
playBtn.addEventListener("click", () => { playing = !playing; playBtn.textContent = playing ? "Pause" : "Play"; if (playing) { if (frame >= N - 1) draw(0); requestAnimationFrame(tick); } });
scrub.addEventListener("input", () => { draw(Number(scrub.value)); });
const mt = document.getElementById("metrics");
for (const [k, v] of Object.entries(D.metrics)) { const tr = document.createElement("tr"); tr.innerHTML = "<td>" + k + "</td><td>" + (typeof v === "number" ? (Number.isInteger(v) ? v : v.toFixed(4)) : String(v)) + "</td>"; mt.appendChild(tr); }
function start() {
  const h = location.hash;
  draw(h.includes("frame=last") ? N - 1 : 0);
  if (h.includes("selftest")) {
    draw(0); const a = robotAt.slice();
    scrub.value = String(N - 1); scrub.dispatchEvent(new Event("input"));
    const b = robotAt.slice();
    const moved = N > 1 && (Math.abs(a[0] - b[0]) + Math.abs(a[1] - b[1])) > 0.5;
    const px = ctx.getImageData(0, 0, canvas.width, canvas.height).data;
    let sweptPx = 0; for (let k = 0; k < px.length; k += 4) if (Math.abs(px[k] - {{SR}}) < 24 && Math.abs(px[k+1] - {{SG}}) < 24 && Math.abs(px[k+2] - {{SB}}) < 24) sweptPx++;
    const ok = moved && sweptPx > 0 && errors.length === 0;
    const msg = "SELFTEST " + (ok ? "PASS" : "FAIL") + " moved=" + moved + " swept_px=" + sweptPx + " errors=" + errors.length + " frames=" + N;
    document.getElementById("selftest").textContent = msg; document.title = msg;
  }
}
if (bg.complete) start(); else bg.addEventListener("load", start);
</script></body></html>
"##;

/// Options of [`replay_gif`].
#[derive(Clone, Debug)]
pub struct GifOptions {
    /// Largest side in pixels.
    pub max_side: u32,
    /// Number of animation frames (the last one is held).
    pub frames: usize,
    /// Delay per frame in hundredths of a second.
    pub delay_cs: u16,
}

impl Default for GifOptions {
    fn default() -> Self {
        Self {
            max_side: 400,
            frames: 60,
            delay_cs: 8,
        }
    }
}

/// Builds an animated GIF of the run (swept area growing, path, robot).
///
/// # Errors
/// When encoding fails.
pub fn replay_gif(world: &World, trace: &Trace, opts: &GifOptions) -> Result<Vec<u8>, RenderError> {
    let f = *world.frame();
    let (c0, r0, cw, ch) = crop_box(world, trace);
    let k = (f64::from(opts.max_side) / cw.max(ch) as f64).min(4.0);
    let (gw, gh) = (
        ((cw as f64 * k).round() as usize).max(1),
        ((ch as f64 * k).round() as usize).max(1),
    );
    // Palette: 0 occ, 1 unk, 2 free-out, 3 accessible, 4 swept, 5 path, 6 robot, 7 white.
    let palette: Vec<u8> = [
        C_OCC,
        C_UNK,
        C_FREE_OUT,
        C_ACC,
        C_SWEPT,
        C_PATH,
        C_ROBOT,
        [255, 255, 255],
    ]
    .iter()
    .flat_map(|c| c.iter().copied())
    .collect();
    let src = |gx: usize, gy: usize| -> usize {
        let c = (c0 + ((gx as f64 + 0.5) / k) as usize).min(f.width - 1);
        let r = (r0 + ((gy as f64 + 0.5) / k) as usize).min(f.height - 1);
        f.index(c, r)
    };
    let base: Vec<u8> = (0..gw * gh)
        .map(|p| {
            let i = src(p % gw, p / gw);
            match world.map().cells()[i] {
                Cell::Occupied => 0,
                Cell::Unknown => 1,
                Cell::Free => {
                    if world.accessible().contains(i) {
                        3
                    } else {
                        2
                    }
                }
            }
        })
        .collect();
    let poses: Vec<Point> = trace.poses().map(|p| p.position()).collect();
    let to_gif = |p: Point| {
        let g = f.world_to_grid(p);
        (
            (g.x - c0 as f64) * k,
            (f.height as f64 - g.y - r0 as f64) * k,
        )
    };
    let mut out = Vec::new();
    {
        let mut enc = gif::Encoder::new(&mut out, gw as u16, gh as u16, &palette)
            .map_err(|e| RenderError::Encode(e.to_string()))?;
        enc.set_repeat(gif::Repeat::Infinite)
            .map_err(|e| RenderError::Encode(e.to_string()))?;
        let mut sweeper = Sweeper::new(world);
        let mut path_layer = vec![false; gw * gh];
        let n = poses.len();
        let frames = opts.frames.max(1);
        let mut done = 0usize;
        if let Some(&p0) = poses.first() {
            sweeper.add(p0, p0);
        }
        for fr in 1..=frames {
            let upto = if n == 0 {
                0
            } else {
                ((n - 1) * fr).div_ceil(frames)
            };
            while done < upto {
                let (a, b) = (poses[done], poses[done + 1]);
                sweeper.add(a, b);
                let (pa, pb) = (to_gif(a), to_gif(b));
                draw_line(&mut path_layer, gw, gh, pa, pb);
                done += 1;
            }
            let swept = sweeper.swept();
            let mut buf = base.clone();
            for (p, v) in buf.iter_mut().enumerate() {
                if *v >= 2 && swept.contains(src(p % gw, p / gw)) {
                    *v = 4;
                }
                if path_layer[p] {
                    *v = 5;
                }
            }
            if let Some(&p) = poses.get(done) {
                let (x, y) = to_gif(p);
                let rr = (world.robot().radius / f.resolution * k).max(2.0);
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
fn clip_segment(
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

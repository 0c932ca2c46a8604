//! Where does extended BSA miss floor? Runs `bsa-extended` on one map and writes a PNG of the
//! accessible surface (white swept, red missed, black blocked, blue path), then prints the
//! missed accessible pixels grouped into 8-connected components (largest first, with their
//! bounding boxes) and split by whether a missed pixel touches a blocked pixel (wall band).
//!
//! `cargo run --release -p ccpp-io --example bsa_debug -- MAP_YAML [OUT_PNG] [RADIUS_M]`

use std::path::PathBuf;

use ccpp_core::metrics::{compute, swept_pixels};
use ccpp_core::planners::bsa_extended::{BsaExtended, BsaExtendedOptions};
use ccpp_core::sim::{simulate, SimConfig};
use ccpp_core::world::{Robot, World};
use ccpp_io::{load_map, LoadOptions};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(map) = args.get(1).map(PathBuf::from) else {
        eprintln!("usage: bsa_debug MAP_YAML [OUT_PNG] [RADIUS_M]");
        std::process::exit(2);
    };
    let out = args
        .get(2)
        .map_or_else(|| PathBuf::from("bsa_debug.png"), PathBuf::from);
    let r: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(0.15);
    let loaded = load_map(&map, &LoadOptions::default()).expect("map loads");
    let world = World::new(loaded.grid, Robot::new(r), None).expect("world");
    let run = simulate(
        &world,
        &mut BsaExtended::new(BsaExtendedOptions::default()),
        &SimConfig::default(),
    );
    let m = compute(&world, &run, "debug");
    println!(
        "effective_coverage {:.4}  collisions {}  regions {}",
        m.effective_coverage, m.collisions, m.regions
    );
    let f = *world.frame();
    let swept = swept_pixels(&world, &run.trace);
    let acc = world.accessible();
    let missed: Vec<bool> = (0..f.len()).map(|i| acc[i] && !swept[i]).collect();
    let blocked = |c: i64, r: i64| {
        f.checked(c, r)
            .is_none_or(|(c, r)| !world.map().get(c, r).is_free())
    };

    let (mut wall, mut inner) = (0usize, 0usize);
    for (i, &mi) in missed.iter().enumerate() {
        if !mi {
            continue;
        }
        let (c, r) = f.col_row(i);
        let (c, r) = (c as i64, r as i64);
        let touches = (-1..=1).any(|dr| (-1..=1).any(|dc| blocked(c + dc, r + dr)));
        if touches {
            wall += 1;
        } else {
            inner += 1;
        }
    }
    // Which reachable centres could cover each missed pixel: any with clearance >= c (in S on
    // the true map) or only ones below it?
    let rt = world.robot().tool_radius / f.resolution + 1e-6;
    let c_px: f64 = std::env::var("CL")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0.05);
    let (mut by_s, mut only_low) = (0usize, 0usize);
    let reach = world.reachable();
    let w = rt.ceil() as i64;
    for (i, &mi) in missed.iter().enumerate() {
        if !mi {
            continue;
        }
        let (c, r) = f.col_row(i);
        let mut any_s = false;
        for dr in -w..=w {
            for dc in -w..=w {
                if ((dr * dr + dc * dc) as f64).sqrt() > rt {
                    continue;
                }
                if let Some((qc, qr)) = f.checked(c as i64 + dc, r as i64 + dr) {
                    let q = f.index(qc, qr);
                    if reach.contains(q)
                        && (world.pixel_clearance(qc, qr) - world.robot().radius) / f.resolution
                            >= c_px - 1e-9
                    {
                        any_s = true;
                    }
                }
            }
        }
        if any_s {
            by_s += 1;
        } else {
            only_low += 1;
        }
    }
    println!("missed coverable from a reachable centre with clearance >= {c_px} px: {by_s}; only from lower-clearance centres: {only_low}");
    let total = wall + inner;
    println!(
        "missed {total} of {} accessible px: {wall} touch a blocked pixel, {inner} do not",
        world.accessible_count()
    );

    // Components.
    let mut comp = vec![usize::MAX; f.len()];
    let mut comps: Vec<(usize, i64, i64, i64, i64, usize)> = Vec::new();
    for s in 0..f.len() {
        if !missed[s] || comp[s] != usize::MAX {
            continue;
        }
        let id = comps.len();
        let mut stack = vec![s];
        comp[s] = id;
        let (mut n, mut c0, mut c1, mut r0, mut r1, mut w) = (0, i64::MAX, 0, i64::MAX, 0, 0);
        while let Some(k) = stack.pop() {
            let (c, r) = f.col_row(k);
            let (c, r) = (c as i64, r as i64);
            n += 1;
            c0 = c0.min(c);
            c1 = c1.max(c);
            r0 = r0.min(r);
            r1 = r1.max(r);
            if (-1..=1).any(|dr| (-1..=1).any(|dc| blocked(c + dc, r + dr))) {
                w += 1;
            }
            for dr in -1..=1 {
                for dc in -1..=1 {
                    if let Some((qc, qr)) = f.checked(c + dc, r + dr) {
                        let q = f.index(qc, qr);
                        if missed[q] && comp[q] == usize::MAX {
                            comp[q] = id;
                            stack.push(q);
                        }
                    }
                }
            }
        }
        comps.push((n, c0, c1, r0, r1, w));
    }
    comps.sort_by_key(|c| std::cmp::Reverse(c.0));
    let mut hist = [0usize; 6];
    for c in &comps {
        let b = match c.0 {
            1 => 0,
            2..=4 => 1,
            5..=16 => 2,
            17..=64 => 3,
            65..=256 => 4,
            _ => 5,
        };
        hist[b] += c.0;
    }
    println!(
        "missed px by component size: 1: {}  2-4: {}  5-16: {}  17-64: {}  65-256: {}  >256: {}",
        hist[0], hist[1], hist[2], hist[3], hist[4], hist[5]
    );
    for c in comps.iter().take(25) {
        println!(
            "  comp {:5} px (wall {:5}) cols {}..{} rows {}..{}",
            c.0, c.5, c.1, c.2, c.3, c.4
        );
    }

    let mut img = image::RgbImage::new(f.width as u32, f.height as u32);
    for row in 0..f.height {
        for col in 0..f.width {
            let i = f.index(col, row);
            let px = if missed[i] {
                [230, 30, 30]
            } else if acc[i] {
                [255, 255, 255]
            } else if world.map().get(col, row).is_free() {
                [200, 200, 200]
            } else {
                [0, 0, 0]
            };
            img.put_pixel(col as u32, row as u32, image::Rgb(px));
        }
    }
    for p in run.trace.poses() {
        if let Some((c, r)) = f.pixel_of(p.position()) {
            let i = f.index(c, r);
            if !missed[i] {
                img.put_pixel(c as u32, r as u32, image::Rgb([60, 90, 255]));
            }
        }
    }
    img.save(&out).expect("png written");
    println!("wrote {}", out.display());

    // CROP=x,y,w,h,scale: a magnified crop with the executed path drawn as lines.
    let Ok(spec) = std::env::var("CROP") else {
        return;
    };
    let v: Vec<i64> = spec.split(',').filter_map(|t| t.parse().ok()).collect();
    let [x0, y0, cw, ch, sc] = v[..] else {
        eprintln!("CROP=x,y,w,h,scale");
        return;
    };
    let mut big = image::RgbImage::new((cw * sc) as u32, (ch * sc) as u32);
    for (x, y, p) in big.enumerate_pixels_mut() {
        let (c, r) = (x0 + i64::from(x) / sc, y0 + i64::from(y) / sc);
        *p = *img.get_pixel(
            c.clamp(0, f.width as i64 - 1) as u32,
            r.clamp(0, f.height as i64 - 1) as u32,
        );
        if matches!(&*p, image::Rgb([60, 90, 255])) {
            *p = image::Rgb([255, 255, 255]);
        }
    }
    let to_big = |q: ccpp_core::geometry::Point| {
        let g = f.world_to_grid(q);
        let (gx, gy) = (g.x, f.height as f64 - g.y);
        ((gx - x0 as f64) * sc as f64, (gy - y0 as f64) * sc as f64)
    };
    let mut prev: Option<(f64, f64)> = None;
    for p in run.trace.poses() {
        let b = to_big(p.position());
        if let Some(a) = prev {
            let n = ((b.0 - a.0).hypot(b.1 - a.1)).ceil().max(1.0) as usize;
            for k in 0..=n {
                let t = k as f64 / n as f64;
                let (x, y) = (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
                if x >= 0.0 && y >= 0.0 && (x as u32) < big.width() && (y as u32) < big.height() {
                    big.put_pixel(x as u32, y as u32, image::Rgb([40, 80, 255]));
                }
            }
        }
        if b.0 >= 0.0 && b.1 >= 0.0 && (b.0 as u32) < big.width() && (b.1 as u32) < big.height() {
            big.put_pixel(b.0 as u32, b.1 as u32, image::Rgb([0, 160, 0]));
        }
        prev = Some(b);
    }
    let crop_out = out.with_extension("crop.png");
    big.save(&crop_out).expect("crop written");
    println!("wrote {}", crop_out.display());
}

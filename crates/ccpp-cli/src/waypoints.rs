//! `ccpp waypoints`: the seed-001 lane plan as a plain list, for users who only want the plan.

use std::fmt::Write as _;

use anyhow::{bail, Context, Result};
use ccpp_core::planners::rect_boustrophedon::{plan, RectOptions};
use ccpp_core::world::World;

use crate::args::WaypointsArgs;
use crate::job::{prepare_map, robot_from};
use crate::staging::write_file;

/// Runs `ccpp waypoints`.
pub fn run(a: &WaypointsArgs) -> Result<()> {
    for (name, v) in [("--length", a.length), ("--width", a.width)] {
        if !v.is_finite() || v <= 0.0 {
            bail!("{name} must be a finite number > 0 m, got {v}");
        }
    }
    let format = a.format.to_ascii_lowercase();
    if format != "csv" && format != "json" {
        bail!("--format must be csv or json, got {:?}", a.format);
    }
    let (robot, start) = robot_from(&a.robot)?;
    let map = prepare_map(&a.map)?;
    let world = World::new(map.grid, robot, start)
        .with_context(|| format!("map {}", map.source.display()))?;
    let opts = RectOptions {
        length_m: a.length,
        width_m: a.width,
        area: a.area,
        ..RectOptions::default()
    };
    let p = plan(&world, &opts);
    let text = if format == "csv" {
        let mut s = String::from("x,y\n");
        for w in &p.waypoints {
            let _ = writeln!(s, "{},{}", w.x, w.y);
        }
        s
    } else {
        let pts: Vec<[f64; 2]> = p.waypoints.iter().map(|w| [w.x, w.y]).collect();
        let v = serde_json::json!({
            "map": map.name,
            "length_m": a.length,
            "width_m": a.width,
            "area": p.area,
            "waypoints": pts,
        });
        let mut s = serde_json::to_string_pretty(&v)?;
        s.push('\n');
        s
    };
    match &a.out {
        Some(path) => write_file(path, text.as_bytes())?,
        None => crate::print_stdout(&text)?,
    }
    Ok(())
}

//! `ccpp info`: what a map holds and how much of it a robot can reach.

use anyhow::{Context, Result};
use ccpp_core::grid::{Cell, GridMap};
use ccpp_core::world::World;
use serde::Serialize;

use crate::args::InfoArgs;
use crate::job::{prepare_map, robot_from};

/// The report.
#[derive(Serialize)]
struct Info {
    map: String,
    width_px: usize,
    height_px: usize,
    resolution_m: f64,
    origin: [f64; 3],
    width_m: f64,
    height_m: f64,
    free_px: usize,
    occupied_px: usize,
    unknown_px: usize,
    free_m2: f64,
    /// 4-connected components of free pixels.
    free_components: usize,
    /// Share of the free pixels in the largest component.
    largest_component_share: f64,
    robot_radius_m: f64,
    /// C-free pixel centres (the robot fits) on the whole map.
    cfree_px: usize,
    start: [f64; 3],
    /// C-free pixels reachable from the start.
    reachable_px: usize,
    /// Accessible surface from the start (m^2).
    accessible_m2: f64,
}

/// Counts 4-connected components of free pixels and the size of the largest.
fn free_components(g: &GridMap) -> (usize, usize) {
    let f = *g.frame();
    let cells = g.cells();
    let mut seen = vec![false; f.len()];
    let (mut n, mut largest) = (0usize, 0usize);
    let mut stack = Vec::new();
    for i in 0..f.len() {
        if cells[i] != Cell::Free || seen[i] {
            continue;
        }
        n += 1;
        let mut size = 0;
        seen[i] = true;
        stack.push(i);
        while let Some(k) = stack.pop() {
            size += 1;
            let (c, r) = f.col_row(k);
            let mut visit = |j: usize| {
                if cells[j] == Cell::Free && !seen[j] {
                    seen[j] = true;
                    stack.push(j);
                }
            };
            if c > 0 {
                visit(k - 1);
            }
            if c + 1 < f.width {
                visit(k + 1);
            }
            if r > 0 {
                visit(k - f.width);
            }
            if r + 1 < f.height {
                visit(k + f.width);
            }
        }
        largest = largest.max(size);
    }
    (n, largest)
}

/// Runs `ccpp info`.
pub fn run(a: &InfoArgs) -> Result<()> {
    let (robot, start) = robot_from(&a.robot)?;
    let map = prepare_map(&a.map)?;
    let g = &map.grid;
    let f = *g.frame();
    let (free, occ, unk) = g.counts();
    let (ncomp, largest) = free_components(g);
    let world = World::new(g.clone(), robot, start)
        .with_context(|| format!("map {}", map.source.display()))?;
    let s = world.start();
    let res2 = f.resolution * f.resolution;
    let info = Info {
        map: map.name.clone(),
        width_px: f.width,
        height_px: f.height,
        resolution_m: f.resolution,
        origin: [f.origin.x, f.origin.y, f.origin.theta],
        width_m: f.width_m(),
        height_m: f.height_m(),
        free_px: free,
        occupied_px: occ,
        unknown_px: unk,
        free_m2: free as f64 * res2,
        free_components: ncomp,
        largest_component_share: if free == 0 {
            0.0
        } else {
            largest as f64 / free as f64
        },
        robot_radius_m: robot.radius,
        cfree_px: world.cfree().count_ones(..),
        start: [s.x, s.y, s.theta],
        reachable_px: world.reachable().count_ones(..),
        accessible_m2: world.accessible_area_m2(),
    };
    if a.json {
        println!("{}", serde_json::to_string_pretty(&info)?);
        return Ok(());
    }
    let n = f.len() as f64 / 100.0;
    println!("map            {} ({})", info.map, map.source.display());
    println!(
        "size           {} x {} px, {} m/px = {:.2} x {:.2} m",
        f.width, f.height, f.resolution, info.width_m, info.height_m
    );
    println!(
        "origin         ({}, {}, {})",
        f.origin.x, f.origin.y, f.origin.theta
    );
    println!(
        "free           {free} px ({:.1} %), {:.1} m2",
        free as f64 / n,
        info.free_m2
    );
    println!("occupied       {occ} px ({:.1} %)", occ as f64 / n);
    println!("unknown        {unk} px ({:.1} %)", unk as f64 / n);
    println!(
        "components     {ncomp} (4-connected free), largest {:.1} % of free",
        100.0 * info.largest_component_share
    );
    println!(
        "robot radius   {} m: C-free {} px",
        robot.radius, info.cfree_px
    );
    println!("start          ({:.3}, {:.3}, {:.3})", s.x, s.y, s.theta);
    println!(
        "reachable      {} px of C-free from the start",
        info.reachable_px
    );
    println!(
        "accessible     {:.2} m2 (floor the tool can touch from the start)",
        info.accessible_m2
    );
    Ok(())
}

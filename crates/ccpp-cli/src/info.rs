//! `ccpp info`: what a map holds and how much of it a robot can reach.

use std::fmt::Write as _;

use anyhow::Result;
use ccpp_core::grid::Cell;
use ccpp_core::world::{World, WorldError};
use serde::Serialize;

use crate::args::InfoArgs;
use crate::components::{free_components, StartComponent};
use crate::job::{prepare_map, robot_from};
use crate::output::{fitted, num};

/// How the map's pixels were read.
#[derive(Serialize)]
struct Pixels {
    mode: &'static str,
    occupied_thresh: f64,
    free_thresh: f64,
    negate: bool,
}

/// The report. Robot-dependent fields are `null` when the robot does not fit on the map.
#[derive(Serialize)]
struct Info {
    map: String,
    width_px: usize,
    height_px: usize,
    resolution_m: f64,
    origin: [f64; 3],
    width_m: f64,
    height_m: f64,
    /// How the pixels were read: `map_server` mode, thresholds, negate.
    pixels: Pixels,
    /// How far `--inflate` grew the obstacles (m): every figure after it is on the grown map.
    #[serde(skip_serializing_if = "Option::is_none")]
    inflate_m: Option<f64>,
    free_px: usize,
    occupied_px: usize,
    unknown_px: usize,
    free_m2: f64,
    /// 4-connected components of free pixels.
    free_components: usize,
    /// Share of the free pixels in the largest component.
    largest_component_share: f64,
    robot_radius_m: f64,
    /// The tool radius `accessible_m2` is measured with (`--tool-radius`, default the robot's).
    tool_radius_m: f64,
    /// Whether the robot fits somewhere on the map (with the start given, there; with zones,
    /// inside the area and outside the keep-outs).
    robot_fits: bool,
    /// Why the robot does not fit, when it does not (naming the zones when they leave it no
    /// room).
    robot_error: Option<String>,
    /// C-free pixel centres (the robot fits) on the whole map.
    cfree_px: Option<usize>,
    start: Option<[f64; 3]>,
    /// Area of the 4-connected free component holding the start (m^2).
    start_component_m2: Option<f64>,
    /// Whether that component reaches the image border (the start may be outside a building).
    start_component_touches_border: Option<bool>,
    /// C-free pixels reachable from the start.
    reachable_px: Option<usize>,
    /// Accessible surface from the start (m^2); with zones, inside the area and outside the
    /// keep-outs.
    accessible_m2: Option<f64>,
    /// The zones given with `--area` / `--keepout`.
    #[serde(skip_serializing_if = "Option::is_none")]
    zones: Option<ZonesInfo>,
}

/// Sizes of the zones (`ccpp info --area/--keepout`).
#[derive(Serialize)]
#[allow(clippy::struct_field_names)] // the JSON keys carry their unit
struct ZonesInfo {
    /// Map area inside the work area (every pixel class), m^2; `None` without an area.
    area_m2: Option<f64>,
    /// Free floor inside the work area, m^2.
    area_free_m2: Option<f64>,
    /// Map area of the keep-out zones' pixels (every pixel a keep-out polygon overlaps), m^2.
    keepout_m2: f64,
    /// Free floor in the keep-out zones, m^2.
    keepout_free_m2: f64,
}

/// Metres (and square metres) as `info --json` prints them: rounded to a nanometre as the
/// path exports are (`0.9750000000000001` and `2.3400000000000003` were printed; hostile pass,
/// stop 70).
fn round_m(v: f64) -> f64 {
    ccpp_io::export::round_m(v)
}

/// Runs `ccpp info`.
pub fn run(a: &InfoArgs) -> Result<()> {
    let (robot, start) = robot_from(&a.robot)?;
    if a.robot.start.is_some_and(|s| s.heading_given) {
        // Nothing `info` reports depends on the heading: it was echoed and otherwise dropped.
        anyhow::bail!(
            "--start THETA does not apply to `ccpp info` (nothing it reports depends on the heading); give X,Y"
        );
    }
    let map = prepare_map(&a.map, a.limits.max_memory_mb())?;
    let g = &map.grid;
    let f = *g.frame();
    let (free, occ, unk) = g.counts();
    let (ncomp, largest) = free_components(g);
    let mut zs =
        ccpp_io::scenario::Scenario::new(map.recipe.clone(), ccpp_core::planners::PlannerKind::Bcd);
    zs.area.clone_from(&a.zones.area);
    zs.keepout.clone_from(&a.zones.keepout);
    zs.robot = robot;
    zs.validate()?;
    let zones = zs.zone_masks(&map)?;
    let res2 = f.resolution * f.resolution;
    let zones_info = zones.as_ref().map(|z| {
        let free_of = |i: usize| g.cells()[i] == Cell::Free;
        ZonesInfo {
            area_m2: z
                .area
                .as_ref()
                .map(|m| round_m(m.count_ones(..) as f64 * res2)),
            area_free_m2: z
                .area
                .as_ref()
                .map(|m| round_m(m.ones().filter(|&i| free_of(i)).count() as f64 * res2)),
            keepout_m2: round_m(z.keepout.count_ones(..) as f64 * res2),
            keepout_free_m2: round_m(
                z.keepout.ones().filter(|&i| free_of(i)).count() as f64 * res2,
            ),
        }
    });
    let (world, robot_error) = match World::with_zones(g.clone(), robot, start, zones) {
        Ok(w) => (Some(w), None),
        // A robot that fits nowhere is reported, not refused; with an inflation (the likely
        // cause) the report and a refused start name it, as `run` does.
        Err(e @ WorldError::RobotTooBig { .. }) => (
            None,
            Some(
                ccpp_io::scenario::inflated_world_error(&e, map.recipe.inflation())
                    .unwrap_or_else(|| e.to_string()),
            ),
        ),
        // Zones that leave no floor are reported too, naming the zone (as `run` refuses them):
        // `info` is where a user looks for why, and it printed nothing but an error that named
        // the map.
        Err(e @ WorldError::NoRoomInZones { .. }) => (
            None,
            Some(
                zs.zone_error(&e, &map.source)
                    .map_or_else(|| e.to_string(), |z| z.to_string()),
            ),
        ),
        // A start the user gave that does not work is a user error (naming the zone it is
        // about, as `run` does).
        Err(e) => {
            if let Some(zone) = zs.zone_error(&e, &map.source) {
                return Err(zone.into());
            }
            return Err(
                match ccpp_io::scenario::inflated_world_error(&e, map.recipe.inflation()) {
                    Some(m) => anyhow::anyhow!("map {}: {m}", map.source.display()),
                    None => anyhow::Error::new(e).context(format!("map {}", map.source.display())),
                },
            );
        }
    };
    // A start outside the area: where coverage would begin instead, as `run` and `plan` say
    // (the start printed below is that end; it was printed without a word).
    if let Some(note) = world.as_ref().and_then(crate::job::approach_note) {
        say!("{note}");
    }
    let s = world.as_ref().map(World::start);
    // On the map the planners see (zones as walls), as `run` reports it: on the plain map a
    // run inside a small area reported the start area of the whole floor.
    let comp = world
        .as_ref()
        .and_then(|w| s.map(|_| StartComponent::of_world(w)));
    let info = Info {
        map: map.name.clone(),
        width_px: f.width,
        height_px: f.height,
        resolution_m: f.resolution,
        origin: [f.origin.x, f.origin.y, f.origin.theta],
        width_m: round_m(f.width_m()),
        height_m: round_m(f.height_m()),
        pixels: Pixels {
            mode: map.thresholds.mode.name(),
            occupied_thresh: map.thresholds.occupied,
            free_thresh: map.thresholds.free,
            negate: map.thresholds.negate,
        },
        inflate_m: map.recipe.inflation(),
        free_px: free,
        occupied_px: occ,
        unknown_px: unk,
        free_m2: round_m(free as f64 * res2),
        free_components: ncomp,
        largest_component_share: if free == 0 {
            0.0
        } else {
            largest as f64 / free as f64
        },
        robot_radius_m: robot.radius,
        tool_radius_m: robot.tool_radius,
        robot_fits: world.is_some(),
        robot_error: robot_error.clone(),
        cfree_px: world.as_ref().map(|w| w.cfree().count_ones(..)),
        start: s.map(|s| [round_m(s.x), round_m(s.y), s.theta]),
        start_component_m2: comp.map(|c| round_m(c.area_m2)),
        start_component_touches_border: comp.map(|c| c.touches_border),
        reachable_px: world.as_ref().map(|w| w.reachable().count_ones(..)),
        accessible_m2: world.as_ref().map(|w| round_m(w.accessible_area_m2())),
        zones: zones_info,
    };
    let cut_off = world
        .as_ref()
        .and_then(ccpp_io::components::zone_cut_off_warning);
    for w in comp.and_then(|c| c.warning()).into_iter().chain(cut_off) {
        say!("warning: {w}");
    }
    if a.json {
        crate::print_stdout(&format!("{}\n", serde_json::to_string_pretty(&info)?))?;
        return Ok(());
    }
    let n = f.len() as f64 / 100.0;
    let mut t = String::new();
    // Each line with the characters a terminal acts on or hides written as `\u{..}`: a
    // right-to-left override in the map's folder name reversed the rest of its line.
    let mut line = |s: String| {
        t.push_str(&ccpp_io::message::visible(&s));
        t.push('\n');
    };
    line(format!(
        "map            {} ({})",
        info.map,
        map.source.display()
    ));
    line(format!(
        "size           {} x {} px, {} m/px = {} x {} m",
        f.width,
        f.height,
        fitted(f.resolution, 0.0),
        ccpp_core::display::fixed(info.width_m, 2),
        ccpp_core::display::fixed(info.height_m, 2)
    ));
    line(format!(
        "origin         ({}, {}, {})",
        fitted(f.origin.x, 1e-9),
        fitted(f.origin.y, 1e-9),
        fitted(f.origin.theta, 1e-12)
    ));
    line(format!(
        "pixels         {}: occupied above p = {}, free below {}{}",
        info.pixels.mode,
        num(info.pixels.occupied_thresh),
        num(info.pixels.free_thresh),
        if info.pixels.negate {
            ", negated (light is occupied)"
        } else {
            ""
        }
    ));
    if map.alpha_differs > 0 {
        line(format!(
            "note           {} px ({:.1} %) would read as another class under ROS map_server, which averages the alpha channel in with the colour in trinary mode (ccpp ignores alpha there, as the ROS docs describe the mode; see the README, Maps)",
            map.alpha_differs,
            map.alpha_differs as f64 / n
        ));
    }
    if let Some(m) = info.inflate_m {
        line(format!(
            "inflated       obstacles grown by {} m (--inflate): every figure below is on the grown map",
            num(m)
        ));
    }
    line(format!(
        "free           {free} px ({:.1} %), {} m2",
        free as f64 / n,
        ccpp_core::display::fixed(info.free_m2, 1)
    ));
    line(format!("occupied       {occ} px ({:.1} %)", occ as f64 / n));
    line(format!("unknown        {unk} px ({:.1} %)", unk as f64 / n));
    line(format!(
        "components     {ncomp} (4-connected free), largest {:.1} % of free",
        100.0 * info.largest_component_share
    ));
    match (&world, s, comp) {
        (Some(w), Some(s), Some(comp)) => {
            line(format!(
                "robot radius   {} m: C-free {} px",
                num(robot.radius),
                w.cfree().count_ones(..)
            ));
            // (no heading: `info` takes none, and nothing it reports depends on one)
            line(format!(
                "start          ({}, {})",
                ccpp_core::display::fixed(s.x, 3),
                ccpp_core::display::fixed(s.y, 3)
            ));
            line(format!("start area     {}", comp.line()));
            line(format!(
                "reachable      {} px of C-free from the start",
                w.reachable().count_ones(..)
            ));
            line(format!(
                "accessible     {} m2 (floor a tool of radius {} m can touch from the start{})",
                ccpp_core::display::fixed(w.accessible_area_m2(), 2),
                num(robot.tool_radius),
                match w.zones().map(|z| (z.area.is_some(), !z.keepout.is_clear())) {
                    Some((true, true)) => ", inside the area, outside the keep-outs",
                    Some((true, false)) => ", inside the area",
                    Some((false, true)) => ", outside the keep-outs",
                    _ => "",
                }
            ));
        }
        _ => line(format!(
            "robot          {}",
            robot_error.as_deref().unwrap_or("does not fit")
        )),
    }
    if let Some(z) = &info.zones {
        if let (Some(a), Some(af)) = (z.area_m2, z.area_free_m2) {
            let label = zs
                .area
                .as_ref()
                .map(ccpp_io::zones::ZoneSpec::label)
                .unwrap_or_default();
            let _ = writeln!(
                t,
                "area           {label}: {} m2, {} m2 of it free floor",
                ccpp_core::display::fixed(a, 2),
                ccpp_core::display::fixed(af, 2)
            );
        }
        if !zs.keepout.is_empty() {
            let labels: Vec<String> = zs
                .keepout
                .iter()
                .map(ccpp_io::zones::ZoneSpec::label)
                .collect();
            let _ = writeln!(
                t,
                "keep-out       {}: {} m2 of pixels kept out (each pixel a polygon overlaps, and a mask's occupied pixels), {} m2 of it free floor",
                labels.join(", "),
                ccpp_core::display::fixed(z.keepout_m2, 2),
                ccpp_core::display::fixed(z.keepout_free_m2, 2)
            );
        }
    }
    crate::print_stdout(&t)
}

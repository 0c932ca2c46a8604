//! The warnings of a finished run: what the command line prints on stderr and Python's
//! `RunResult.warnings` lists, from one place (the texts without the `warning: ` prefix).

use ccpp_core::grid::Cell;
use ccpp_core::metrics::Metrics;
use ccpp_core::trace::{Event, Trace};
use ccpp_core::world::World;
use fixedbitset::FixedBitSet;

use crate::components::StartComponent;
use crate::scenario::Scenario;

/// What an early stop (`Metrics::stop_reason`, or a plan's stop) means; `what` is the
/// incomplete result (`coverage` of a run, `path` of a plan).
pub fn stop_warning(why: &str, what: &str) -> String {
    match why {
        "stalled" => format!(
            "the run was stopped: the robot made no progress for {} motions in a row (its true position stayed within half a map pixel or half its radius, as when it keeps driving into a wall its drifted pose estimate does not show); the {what} is incomplete",
            ccpp_core::sim::STALL_STEPS
        ),
        "max_steps" => format!("the planner hit the simulator's step cap; the {what} is incomplete"),
        other => format!("the run ended early ({other}); the {what} is incomplete"),
    }
}

/// PID motions the per-motion cap cut short, said (`None` when none was), with the run's
/// bumper contacts when it has any: the moves after a cut start where the robot stopped, off
/// the plan, and may cross walls the plan went round (bsa-bfs on `teb_maze` at
/// `max_steps_per_motion: 120`: 3 cuts, then 48 contacts and 23 % swept, while the warning
/// read as if the run had recovered).
pub fn motions_cut_warning(trace: &Trace, metrics: &Metrics) -> Option<String> {
    ccpp_core::sim::motions_cut(trace).map(|n| {
        let after = if metrics.collisions > 0 {
            format!(
                ", so the moves after a cut started off the plan and may cross what it went round; the run has {} bumper contact(s)",
                metrics.collisions
            )
        } else {
            String::new()
        };
        format!(
            "{n} PID motion(s) stopped at max_steps_per_motion before reaching their goal (the run went on from where the robot was{after}): raise exec.pid.max_steps_per_motion or dt_s"
        )
    })
}

/// Bumper contacts and keep-out violations under odometry noise, explained (with the
/// landmark fixes, when there were some, that did not prevent them): the pose estimate
/// drifted from the truth, so the planner drove into walls it placed elsewhere (and an
/// offline planner's remaining moves started from a wrong position). The trace still ends
/// `done` (the planner finished its plan), so without this the run read as complete. Also
/// said without a contact when the true pose strayed from the planned path by more than the
/// robot's radius on average: bsa-bfs on `teb_maze` under `--odometry-noise 0.3,0.3,3`
/// strayed 1.69 m on average, touched nothing, swept 4.4 % and ended "done" without a word.
pub fn drift_warning(scenario: &Scenario, trace: &Trace, metrics: &Metrics) -> Option<String> {
    let (collisions, zones) = (metrics.collisions, metrics.keepout_violations);
    let strayed = metrics
        .tracking_error_mean_m
        .zip(metrics.tracking_error_max_m)
        .filter(|&(mean, _)| mean > scenario.robot.radius);
    if collisions == 0 && zones == 0 && strayed.is_none() {
        return None;
    }
    // The execution event comes first of all events (a run's first step).
    let noisy = trace
        .events()
        .take(4)
        .any(|(_, e)| matches!(e, Event::Execution { noisy: true, .. }));
    if !noisy {
        return None;
    }
    // Landmarks correct the estimate only when seen: given but never in range, the run is
    // the run without them (it got no warning). Seen somewhere, they still leave the estimate
    // to drift between fixes: one landmark by the start of `teb_corridor` gave 824 fixes
    // there, and the run beyond it made 22 contacts, strayed 0.54 m on average and swept 42 %
    // without a word (hostile pass; since the simulator lets a robot turn away from a wall
    // it touched, 702 fixes, 20 contacts, 0.84 m and 43 %).
    let given = scenario.sim.landmarks.landmarks.len();
    let fixes = trace
        .events()
        .filter(|(_, e)| matches!(e, Event::LandmarkFix { .. }))
        .count();
    let what = match (collisions, zones) {
        (c, 0) => format!("{c} bumper contact(s)"),
        (0, z) => format!("{z} keep-out violation(s)"),
        (c, z) => format!("{c} bumper contact(s) and {z} keep-out violation(s)"),
    };
    let range = ccpp_core::display::Compact(scenario.sim.landmarks.range_m);
    if fixes > 0 {
        let strayed = strayed.map_or_else(String::new, |(mean, max)| {
            format!(
                ", the true pose {mean:.2} m from the planned path on average (up to {max:.2} m)"
            )
        });
        let what = if collisions == 0 && zones == 0 {
            "under odometry noise".to_string()
        } else {
            format!("{what} under odometry noise")
        };
        return Some(format!(
            "{what}{strayed} although the robot saw landmarks ({fixes} fix(es)): between fixes the pose estimate drifts from the truth; place landmarks along the whole path, within {range} m of where it drives (the coverage is what was swept)"
        ));
    }
    let remedy = if given == 0 {
        // (a bench takes no landmarks: its runs under noise reach this through an options
        // file, and the advice named a flag `ccpp bench` does not have)
        "give --landmarks / landmarks= to `ccpp run` or Python's `run` to correct the estimate"
            .to_string()
    } else {
        format!(
            "the robot saw none of the {given} landmark(s) given (within {range} m of its path): place them where it drives"
        )
    };
    if collisions == 0 && zones == 0 {
        let (mean, max) = strayed.unwrap_or_default();
        return Some(format!(
            "the true pose strayed from the planned path by {mean:.2} m on average (up to {max:.2} m): under odometry noise without a landmark fix the pose estimate drifts from the truth, and the planner sweeps floor it believes is elsewhere; {remedy} (the coverage is what was swept)"
        ));
    }
    Some(format!(
        "{what}: under odometry noise without a landmark fix the pose estimate drifts from the truth, and the robot drives into walls and zones it believes are elsewhere; {remedy} (the coverage is what was swept)"
    ))
}

/// A run that drove nothing while floor was left, said (`None` otherwise). Options that are
/// legal but leave the planner nothing to do (a bsa-bfs `clearance_margin_m` no free cell
/// meets) ended "done" at 0 m without a word, as does a room too small for the planner's cells
/// at the robot's size.
pub fn no_motion_warning(metrics: &Metrics) -> Option<String> {
    (metrics.path_length_m == 0.0 && metrics.effective_coverage < 1.0).then(|| {
        format!(
            "the robot did not move (0 m driven, {:.1} % of the floor swept from the start): the planner found nowhere to go, as when its cells or lanes do not fit this floor at this robot size, or an option bounds its moves (a clearance margin, the sensor range)",
            100.0 * metrics.effective_coverage
        )
    })
}

/// A tool narrower than the map's pixels, said (`None` otherwise). Coverage is counted per
/// pixel: a pixel is swept when the tool passes within `r_tool` of its centre, so lanes one
/// pixel apart count every pixel swept whatever the tool's width (bcd at `--radius 0.01` on a
/// 0.05 m map reported 100 % at path ratio 0.40, where the tool touched about 40 % of the
/// floor).
pub fn narrow_tool_warning(world: &World) -> Option<String> {
    let res = world.frame().resolution;
    let rt = world.robot().tool_radius;
    (rt < 0.5 * res).then(|| {
        format!(
            "the tool radius {} m is below half the map's pixel ({} m): coverage is counted per pixel centre, so the coverage figures overstate what a tool this narrow sweeps (use a finer map)",
            ccpp_core::display::Compact(rt),
            ccpp_core::display::Compact(0.5 * res)
        )
    })
}

/// The radius below which a robot passes between two occupied pixels that meet only at a
/// corner, in pixels: the contact model counts an obstacle pixel as a disk of half a pixel
/// ([`ccpp_core::collide`]), and the corner lies `sqrt(0.5) - 0.5` from both disks.
pub const CORNER_GAP_PX: f64 = std::f64::consts::FRAC_1_SQRT_2 - 0.5;

/// A robot so small that it passes where the pixels of a one-pixel wall meet only at their
/// corners, said (`None` otherwise): such a wall, drawn diagonally, is closed on the map and
/// open to the robot, so it crosses it (bcd covered both halves of a room so divided, with no
/// collision and no word; hostile pass).
pub fn corner_gap_warning(world: &World) -> Option<String> {
    let res = world.frame().resolution;
    let r = world.robot().radius;
    (r < CORNER_GAP_PX * res).then(|| {
        format!(
            "the robot radius {} m is below {:.3} of the map's pixel ({} m): it passes between two occupied pixels that meet only at a corner, so a wall one pixel thick drawn diagonally does not stop it (use a finer map or a larger robot)",
            ccpp_core::display::Compact(r),
            CORNER_GAP_PX,
            ccpp_core::display::Compact((CORNER_GAP_PX * res * 1e6).round() / 1e6)
        )
    })
}

/// The planners whose lanes lie a tile apart and leave the floor between them to no one:
/// the tile planners without the coverage extension (which sweeps what the lanes leave).
fn tiles_only(scenario: &Scenario) -> bool {
    use ccpp_core::planners::PlannerKind as K;
    matches!(scenario.planner.kind(), K::BaStar | K::Bsa | K::BsaBfs)
}

/// The tile side and the tool's sweep (`2 r_tool`) of a tile-only planner whose tiles are
/// wider than that sweep, else `None`.
fn wide_tiles(scenario: &Scenario) -> Option<(f64, f64)> {
    if !tiles_only(scenario) {
        return None;
    }
    let side = scenario.tile_side()?;
    let sweep = 2.0 * scenario.robot.tool_radius;
    (side > sweep * (1.0 + 1e-9)).then_some((side, sweep))
}

/// Tiles wider than the tool sweeps, said (`None` otherwise): the planner's lanes lie a tile
/// apart, so they leave strips between them unswept, while `coverage_rate` counts the
/// planner's own tiles. ba-star at `--tile-side 0.9` with a 0.3 m tool reported
/// `coverage_rate` 1.0 beside an effective coverage of 0.34 without a word (bcd's lane
/// spacing and rect-boustrophedon's lane width are refused beyond the tool; the tile side is
/// the papers' parameter, and the default, the robot's diameter, is wider than a tool of a
/// smaller `--tool-radius`). Not for ba-star-extended and bsa-extended, whose extension
/// sweeps the strips.
pub fn wide_tiles_warning(scenario: &Scenario) -> Option<String> {
    wide_tiles(scenario).map(|(side, sweep)| {
        format!(
            "the tile side {} m is wider than the tool sweeps (2 x tool radius = {} m): lanes a tile apart leave strips unswept between them, and coverage_rate counts the planner's own tiles; effective_coverage is the share of the floor swept",
            ccpp_core::display::Compact(side),
            ccpp_core::display::Compact(sweep)
        )
    })
}

/// A planner that lays its tiles or lanes along the world axes, on a map whose origin has a
/// yaw that is not a multiple of a quarter turn, said (`None` otherwise): ba-star, bsa,
/// bsa-bfs, their extended forms and rect-boustrophedon then cross the grid's walls at that
/// angle (on `teb_maze` with a yaw of 0.3 rad, bsa made 483 turns instead of 133), while bcd
/// plans in the grid's frame. A rigid turn of the world changed their runs without a word.
pub fn world_axes_warning(scenario: &Scenario, world: &World) -> Option<String> {
    use ccpp_core::planners::PlannerConfig;
    let yaw = world.frame().origin.theta;
    let axes = match scenario.planner {
        PlannerConfig::RectBoustrophedon(_) => "lanes",
        _ if scenario
            .planner
            .settings()
            .tile_side(&world.robot())
            .is_some() =>
        {
            "tiles"
        }
        _ => return None,
    };
    ccpp_core::grid::off_the_axes(yaw).then(|| {
        format!(
            "the map's origin has a yaw of {} rad: {}'s {axes} run along the world axes, so they cross the map's walls at that angle (bcd plans in the map's own frame); --origin X,Y,0 (Python: origin=(x, y, 0)) lays them along the image's axes",
            ccpp_core::display::Compact((yaw * 1e4).round() / 1e4),
            scenario.planner.name()
        )
    })
}

/// A tile planner that visited (nearly) all its tiles reachable from the start but swept less
/// than half the floor the robot can reach, said (`None` otherwise): its tile lattice,
/// anchored at the start, does not lead out of where the robot started (a start in a closet
/// behind a doorway narrower than the lattice's fit). ba-star, bsa and bsa-bfs swept 6.2 %
/// and reported `coverage_rate` 1.0. With tiles wider than the tool ([`wide_tiles_warning`])
/// the lanes sweep at most `sweep / side` of the floor wherever the robot starts, so the bar
/// is half of that: at `--tile-side 0.9` with a 0.3 m tool, 34 % swept is the strips' doing
/// (not said), while tiles 0.7 % wider than the tool and 2.7 % swept is the start's (it was
/// suppressed whenever the tiles were wider at all, and the strips were blamed).
///
/// It also fires when the run's tiles were all visited while a part of the floor the robot can
/// reach was never approached ([`untouched_floor`]): a start in a room holding a little more
/// than half the floor left the other room, behind a doorway off the tile lattice, wholly
/// unswept beside `coverage_rate` 1.0, without a word (hostile pass: 50.7 % swept on its
/// map, 55.8 % on the test's). `untouched` is the run's [`untouched_floor`].
pub fn stranded_tiles_warning(
    scenario: &Scenario,
    metrics: &Metrics,
    untouched: Option<&Untouched>,
) -> Option<String> {
    let rate = metrics.coverage_rate?;
    if !tiles_only(scenario) || metrics.path_length_m == 0.0 || rate < 0.99 {
        return None;
    }
    let strips = wide_tiles(scenario).map_or(1.0, |(side, sweep)| sweep / side);
    // bsa's tiles are always the robot's diameter: only another start helps.
    let remedy = if scenario.planner.kind() == ccpp_core::planners::PlannerKind::Bsa {
        "try another --start"
    } else {
        "try another --start or a smaller --tile-side"
    };
    let low = metrics.effective_coverage < 0.5 * strips;
    let far = untouched.filter(|u| !low && u.is_large());
    (low || far.is_some()).then(|| {
        let far = far.map_or_else(String::new, |u| format!(" ({})", u.said()));
        format!(
            "the planner visited the tiles it could reach from the start ({:.0} %) but swept only {:.1} % of the floor the robot can reach{far}: its tiles (anchored at the start) do not lead out of there, as through a doorway too narrow for them; {remedy}",
            100.0 * rate,
            100.0 * metrics.effective_coverage
        )
    })
}

/// Floor a run never came near: accessible pixels farther than [`Untouched::distance_m`]
/// from every swept pixel (see [`untouched_floor`]).
#[derive(Clone, Copy, Debug)]
pub struct Untouched {
    /// The distance, in metres ([`untouched_distance_m`]).
    pub distance_m: f64,
    /// Accessible pixels farther than that from every swept pixel.
    pub pixels: usize,
    /// Accessible pixels.
    pub accessible: usize,
    /// Pixel side, in metres.
    pub resolution: f64,
}

/// The least distance from swept floor at which floor counts as never approached, in
/// metres ([`Untouched::distance_m`]).
pub const UNTOUCHED_M: f64 = 1.0;

/// The share of the accessible floor never approached from which a run is warned about it.
pub const UNTOUCHED_SHARE: f64 = 0.05;

impl Untouched {
    /// The share of the accessible floor never approached.
    pub fn share(&self) -> f64 {
        if self.accessible == 0 {
            0.0
        } else {
            self.pixels as f64 / self.accessible as f64
        }
    }

    /// Whether it is worth a warning: at least [`UNTOUCHED_SHARE`] of the floor. On the 14
    /// shared maps at r = 0.15 m, ba-star, bsa, bsa-bfs and rect-boustrophedon leave at most
    /// 1.1 % (`aws_small_warehouse_002`); a room behind a doorway they did not take, 34 %.
    pub fn is_large(&self) -> bool {
        self.share() >= UNTOUCHED_SHARE
    }

    /// The words for it: "34.4 % of it, 12.3 m2, lies more than 1 m from anything the tool
    /// swept".
    pub fn said(&self) -> String {
        let r2 = self.resolution * self.resolution;
        format!(
            "{:.1} % of it, {:.1} m2, lies more than {} m from anything the tool swept",
            100.0 * self.share(),
            self.pixels as f64 * r2,
            ccpp_core::display::Compact((self.distance_m * 1e3).round() / 1e3)
        )
    }
}

/// How far from swept floor floor counts as never approached, in metres: the larger of
/// [`UNTOUCHED_M`], three tool sweeps (`6 r_tool`) and, for tiles wider than the tool sweeps,
/// the unswept strip between two lanes (`side - 2 r_tool`), so that the rims a planner leaves
/// along walls and between lanes never count (ba-star at `--tile-side 4` in an open room was
/// told its tiles did not lead out through a doorway).
pub fn untouched_distance_m(scenario: &Scenario, world: &World) -> f64 {
    let strip = wide_tiles(scenario).map_or(0.0, |(side, sweep)| side - sweep);
    UNTOUCHED_M.max(6.0 * world.robot().tool_radius).max(strip)
}

/// The floor a run never approached ([`Untouched`]) at `distance_m` from its swept floor
/// ([`untouched_distance_m`]); `None` for a run that swept at least
/// `1 - UNTOUCHED_SHARE` of its floor or never moved (no need to look). `swept` are the run's
/// swept pixels ([`ccpp_core::metrics::swept_pixels`], found with its metrics).
///
/// Measured on blocks of pixels about a quarter of the distance wide: a block counts when its
/// centre lies farther than the distance plus a block's diagonal from the centre of every
/// block holding a swept pixel, so each of its unswept accessible pixels is surely farther
/// than the distance from every swept pixel (the share is a lower bound). Per pixel, the
/// distance transform of the whole map cost ba-star on the 16-million-pixel bench map
/// `office_4096` 0.8 s and 60 MB more than the run (2.1 s); on blocks, about 0.07 s and no
/// memory to speak of.
pub fn untouched_floor(
    world: &World,
    swept: &FixedBitSet,
    metrics: &Metrics,
    distance_m: f64,
) -> Option<Untouched> {
    if metrics.effective_coverage >= 1.0 - UNTOUCHED_SHARE || metrics.path_length_m == 0.0 {
        return None;
    }
    let frame = *world.frame();
    let d_px = distance_m / frame.resolution;
    // (at least one pixel; `d_px / 4` pixels is a whole number below 2^52 here)
    let b = ((d_px / 4.0).floor() as usize).max(1);
    let (bw, bh) = (frame.width.div_ceil(b), frame.height.div_ceil(b));
    let mut has_swept = vec![false; bw * bh];
    let mut open = vec![0u32; bw * bh];
    let block = |i: usize| (i / frame.width / b) * bw + (i % frame.width) / b;
    // The blocks holding a swept pixel, a word of the bit set at a time: of each run of set
    // bits inside one block's row, only the first is looked at.
    let bits = usize::BITS as usize;
    for (wi, &word) in swept.as_slice().iter().enumerate() {
        let mut w = word;
        while w != 0 {
            let bit = w.trailing_zeros() as usize;
            let i = wi * bits + bit;
            has_swept[block(i)] = true;
            // (the block's last column on this row, or the row's end, or the word's)
            let col = i % frame.width;
            let left = (((col / b) + 1) * b).min(frame.width) - col;
            let upto = (bit + left).min(bits);
            w &= if upto == bits {
                0
            } else {
                !((1usize << upto) - 1)
            };
        }
    }
    for i in world.accessible().difference(swept) {
        open[block(i)] += 1;
    }
    let dt = ccpp_core::dt::squared_edt_compact(bw, bh, |k| has_swept[k], false);
    // Block centres farther apart than this (in blocks): every pixel pair farther than d_px.
    let far = d_px / b as f64 + std::f64::consts::SQRT_2;
    let pixels = (0..bw * bh)
        .filter(|&k| f64::from(dt.get(k)) > far * far)
        .map(|k| open[k] as usize)
        .sum();
    Some(Untouched {
        distance_m,
        pixels,
        accessible: world.accessible_count(),
        resolution: frame.resolution,
    })
}

/// Floor swept outside the floor reachable from the start (outside the zones' keep-outs and
/// area, and more than a tool radius from the reachable floor), when it is at least [`OUTSIDE_REACH_MIN_M2`] and [`OUTSIDE_REACH_MIN_SHARE`] of
/// what the robot swept (`None` otherwise). The reachable floor is that of the pixel centres
/// clear of obstacles (world-and-metrics conventions), while the robot moves continuously: it
/// can pass a gap where no pixel centre is clear (a 1-px wall's gap a little wider than the
/// robot), and the floor beyond is not counted. random-bounce spent a whole run in a room
/// behind such a gap and reported 18 % coverage without a word (hostile pass).
pub fn outside_reach_warning(world: &World, swept: &FixedBitSet) -> Option<String> {
    let acc = world.accessible();
    let cells = world.map().cells();
    let in_zone = |i: usize| world.zones().is_some_and(|z| z.forbidden(i));
    let res = world.frame().resolution;
    let outside: Vec<usize> = swept
        .ones()
        .filter(|&i| !acc.contains(i) && cells[i] == Cell::Free && !in_zone(i))
        .collect();
    if outside.len() as f64 * res * res < OUTSIDE_REACH_MIN_M2 {
        return None;
    }
    // Only pixels more than a tool radius (and a pixel) from the reachable floor: the slivers
    // along walls that moves between pixel centres sweep (a lane end pushed to the wall) lie
    // beside it (bcd at r = 0.1 m on `rmf_office_scan`: 4.1 m2 in 750 pieces of at most 8
    // px, none a place the robot went to).
    let frame = world.frame();
    let k = (world.robot().tool_radius / res).ceil() as i64 + 1;
    let (w, h) = (frame.width as i64, frame.height as i64);
    let near = |i: usize| {
        let (c, r) = ((i % frame.width) as i64, (i / frame.width) as i64);
        (r - k..=r + k).any(|rr| {
            (0..h).contains(&rr)
                && (c - k..=c + k)
                    .any(|cc| (0..w).contains(&cc) && acc.contains((rr * w + cc) as usize))
        })
    };
    let outside = outside.into_iter().filter(|&i| !near(i)).count();
    let area = outside as f64 * res * res;
    let share = outside as f64 / swept.count_ones(..).max(1) as f64;
    if area < OUTSIDE_REACH_MIN_M2 || share < OUTSIDE_REACH_MIN_SHARE {
        return None;
    }
    Some(format!(
        "the robot swept {area:.1} m2 outside the floor reachable from its start ({:.0} % of what it swept): it passed where no pixel centre is clear of obstacles (a gap narrower than the map's pixels resolve), and the coverage does not count that floor; see coverage.png (\"swept, outside reachable floor\")",
        100.0 * share
    ))
}

/// Least area (m2) of [`outside_reach_warning`].
pub const OUTSIDE_REACH_MIN_M2: f64 = 0.5;
/// Least share of the swept floor of [`outside_reach_warning`].
pub const OUTSIDE_REACH_MIN_SHARE: f64 = 0.02;

/// A large part of the floor never approached, said for the runs no other warning explains
/// (`None` otherwise; see [`run_warnings`]): a rectangle's clearance disk that fits through
/// no doorway into the other room (53.5 % swept), a random bounce whose budget ran out before
/// it found two rooms (56.5 %), both without a word (hostile pass).
pub fn untouched_floor_warning(
    scenario: &Scenario,
    metrics: &Metrics,
    untouched: Option<&Untouched>,
) -> Option<String> {
    let u = untouched.filter(|u| u.is_large())?;
    let why = if scenario.planner.kind() == ccpp_core::planners::PlannerKind::RandomBounce {
        // (a random bounce ends when its distance budget is spent)
        "random-bounce spent its distance budget before it came there; a larger random_bounce.budget_m reaches more"
    } else {
        "the path never went there (as into a room behind a doorway it did not take)"
    };
    Some(format!(
        "the run swept {:.1} % of the floor the robot can reach, and {}: {why}; see coverage.png",
        100.0 * metrics.effective_coverage,
        u.said()
    ))
}

/// rect-boustrophedon's lanes keep the rectangle's clearance disk clear (its circumscribed
/// disk, wider than the robot's radius the metrics count the floor for): where that disk
/// reaches less than half the floor the robot's disk reaches from the start, the rectangle
/// is stranded there, said with the share (`None` otherwise). A 0.3 x 0.3 m robot (clearance
/// 0.212 m) in a closet behind a 0.35 m door swept 7 % of the floor a 0.15 m disk reaches,
/// without a word. Only looked at for a run that swept less than half its floor (the reach is
/// one more flood fill of the map).
pub fn rect_reach_warning(scenario: &Scenario, world: &World, metrics: &Metrics) -> Option<String> {
    let ccpp_core::planners::PlannerConfig::RectBoustrophedon(o) = &scenario.planner else {
        return None;
    };
    if metrics.effective_coverage >= 0.5 || metrics.path_length_m == 0.0 {
        return None;
    }
    let robot = world.robot();
    let rad = o.clearance_radius(&robot);
    if rad <= robot.radius {
        return None;
    }
    let disk = ccpp_core::world::Robot {
        radius: rad,
        tool_radius: robot.tool_radius,
    };
    let rect = World::new(world.map().clone(), disk, Some(world.start())).ok()?;
    // The floor a tool of the same radius touches from each disk's reachable centres.
    let (reach, all) = (rect.accessible_count(), world.accessible_count());
    (all > 0 && (reach as f64) < 0.5 * all as f64).then(|| {
        let share = 100.0 * reach as f64 / all as f64;
        let share = if share > 0.0 && share < 0.05 {
            "less than 0.1 %".to_string()
        } else {
            format!("{share:.1} %")
        };
        // The tool radius kept: the rectangle's sides default to twice it, and --tool-radius
        // defaults to --radius, so `--radius` alone would plan another rectangle.
        format!(
            "the rectangle's clearance disk (radius {:.3} m, the circle the {} x {} m robot turns in) reaches only {share} of the floor a robot of radius {} m reaches from the start, as through a doorway narrower than it: its lanes cover that part, and the metrics count the robot's floor; run with --radius {} --tool-radius {} to count the rectangle's own, or start elsewhere",
            rad,
            ccpp_core::display::Compact(o.length_for(&robot)),
            ccpp_core::display::Compact(o.width_for(&robot)),
            ccpp_core::display::Compact(robot.radius),
            ccpp_core::display::Compact((rad * 1e6).ceil() / 1e6),
            ccpp_core::display::Compact(robot.tool_radius),
        )
    })
}

/// rect-boustrophedon given both its own lane rectangle (`rect_boustrophedon.area`) and a work
/// area, said (`None` otherwise): both bound its lanes, so only their overlap is laned, while
/// the metrics measure the whole work area (a lane rectangle over a quarter of the area:
/// effective coverage 0.16, exit 0, no word). Both are honoured, as asked.
pub fn rect_lane_area_warning(scenario: &Scenario) -> Option<String> {
    let ccpp_core::planners::PlannerConfig::RectBoustrophedon(o) = &scenario.planner else {
        return None;
    };
    let lanes = o.area?;
    scenario.area.as_ref()?;
    Some(format!(
        "rect_boustrophedon.area [{}] and the work area (--area / area) both bound the lanes: only their overlap is laned, while the work area is what is to be covered (a run's metrics measure all of it); leave out rect_boustrophedon.area to lane the whole area",
        lanes
            .iter()
            .map(|v| ccpp_core::display::Compact(*v).to_string())
            .collect::<Vec<_>>()
            .join(", ")
    ))
}

/// A random-bounce run that ended boxed in, with budget left, said (its trace's
/// [`BOXED_IN_NOTE`](ccpp_core::planners::random_bounce::BOXED_IN_NOTE), `None` otherwise).
pub fn boxed_in_warning(trace: &Trace) -> Option<String> {
    note_warning(trace, ccpp_core::planners::random_bounce::BOXED_IN_NOTE)
}

/// Transfers of a bcd plan that could not keep its `margin_px`, said (the trace's
/// [`MARGIN_NOTE`](ccpp_core::planners::bcd::MARGIN_NOTE); `None` otherwise).
pub fn margin_warning(trace: &Trace) -> Option<String> {
    note_warning(trace, ccpp_core::planners::bcd::MARGIN_NOTE)
}

/// The warnings of a plan (`ccpp plan`, Python's `plan`), in the order `ccpp plan` prints
/// them: the start's free area reaching the map's border ([`StartComponent::warning`]), zones
/// cutting floor off from the start, a rect-boustrophedon lane rectangle that bounds the area
/// ([`rect_lane_area_warning`]), a path that does not move the
/// robot ([`still_plan_warning`]), bcd lanes farther apart than the tool sweeps
/// ([`narrow_lanes_warning`]), transfers that could not keep bcd's `margin_px`
/// ([`margin_warning`]). A run says the first two its own way ([`no_motion_warning`],
/// [`narrow_tool_warning`]); a plan, which has no coverage figures, said nothing.
pub fn plan_warnings(
    scenario: &Scenario,
    world: &World,
    trace: &Trace,
    route: &ccpp_core::route::Route,
) -> Vec<String> {
    // As for a run: a start whose free area reaches the map's border is probably outside.
    StartComponent::of_world(world)
        .warning()
        .into_iter()
        .chain(crate::components::zone_cut_off_warning(world))
        .chain(rect_lane_area_warning(scenario))
        .chain(corner_gap_warning(world))
        .chain(world_axes_warning(scenario, world))
        .chain(still_plan_warning(route))
        .chain(narrow_lanes_warning(scenario, world))
        .chain(margin_warning(trace))
        .collect()
}

/// A plan whose path does not move the robot (one waypoint, 0 m), said: `ccpp plan` wrote it
/// without a word where `ccpp run` warns that the robot did not move (rect-boustrophedon whose
/// rectangle fits nowhere else in the area a keep-out leaves it).
pub fn still_plan_warning(route: &ccpp_core::route::Route) -> Option<String> {
    (route.length_m() == 0.0).then(|| {
        "the path does not move the robot (one waypoint, 0 m): the planner found nowhere to go from the start, as when its lanes do not fit the floor, the area or what the keep-outs leave at this robot size".to_string()
    })
}

/// bcd lanes farther apart than the tool sweeps, said (`None` otherwise): its lanes lie at
/// least a map pixel apart, so a tool narrower than a pixel (`--tool-radius 0.02` on a 0.05 m
/// map) leaves strips between them that no pass sweeps. A plan wrote such lanes without a word
/// (an explicit `lane_spacing_m` that wide is refused).
pub fn narrow_lanes_warning(scenario: &Scenario, world: &World) -> Option<String> {
    let res = world.frame().resolution;
    let sweep = 2.0 * world.robot().tool_radius;
    (matches!(scenario.planner, ccpp_core::planners::PlannerConfig::Bcd(_)) && sweep < res).then(
        || {
            format!(
                "the tool sweeps {} m but bcd's lanes lie at least a map pixel ({} m) apart: strips between them stay unswept (use a finer map or a wider tool)",
                ccpp_core::display::Compact(sweep),
                ccpp_core::display::Compact(res)
            )
        },
    )
}

/// The trace's first note starting with `prefix`, as a warning (`None` when there is none).
fn note_warning(trace: &Trace, prefix: &str) -> Option<String> {
    trace.events().find_map(|(_, e)| match e {
        Event::Note { text } if text.starts_with(prefix) => Some(text.clone()),
        _ => None,
    })
}

/// The note that the start lies outside the work area and how far the robot drives on the
/// known map to reach it first (`None` when it starts inside), without `note: `: `ccpp run`,
/// `plan` and `info` print it, and Python's `RunResult.notes` and `PlanResult.notes` hold it.
pub fn approach_note(world: &World) -> Option<String> {
    if world.approach().is_empty() {
        return None;
    }
    let e = world.start();
    Some(format!(
        "the start is outside the area: the robot first drives {:.2} m on the known map to reach it at ({:.3}, {:.3})",
        world.approach_length_m(),
        e.x,
        e.y
    ))
}

/// Joins a run's warnings in one field (`ccpp bench`'s `results.csv`, `ccpp.sweep`'s
/// `warnings` column).
pub const SEPARATOR: &str = " | ";

/// The warnings `ccpp run` prints, in its order: the start's free area reaching the map's
/// border ([`StartComponent::warning`], from `start_area` when the caller found it while the
/// planner worked, else found here), then [`run_warnings`]. `ccpp run`, `ccpp replay DIR` and
/// Python's `run` list these (the bench's `warnings.txt` is [`run_warnings`] alone).
pub fn warnings_with_start(
    start_area: Option<StartComponent>,
    scenario: &Scenario,
    world: &World,
    trace: &Trace,
    metrics: &Metrics,
    swept: &FixedBitSet,
) -> Vec<String> {
    start_area
        .unwrap_or_else(|| StartComponent::of_world(world))
        .warning()
        .into_iter()
        .chain(crate::components::zone_cut_off_warning(world))
        .chain(run_warnings(scenario, world, trace, metrics, swept))
        .collect()
}

/// Every warning of a run of `scenario` in `world` with this trace and these metrics: an early
/// stop, PID motions cut short, contacts or a true pose far off the plan under drift, no
/// motion at all, a tool narrower than the pixels, tiles wider than the tool or stranded at
/// the start, a rectangle whose clearance disk reaches little of the floor or whose lane
/// rectangle bounds the work area, a random bounce boxed in, a large part of the floor never
/// approached, bcd transfers that could not keep its `margin_px`. `swept` are the run's swept pixels (found with its metrics).
pub fn run_warnings(
    scenario: &Scenario,
    world: &World,
    trace: &Trace,
    metrics: &Metrics,
    swept: &FixedBitSet,
) -> Vec<String> {
    let mut out = Vec::new();
    out.extend(corner_gap_warning(world));
    out.extend(narrow_tool_warning(world));
    out.extend(world_axes_warning(scenario, world));
    let no_motion = no_motion_warning(metrics);
    let moved = no_motion.is_none();
    out.extend(no_motion);
    out.extend(wide_tiles_warning(scenario));
    // (measured once, for the two warnings that read it)
    let untouched = untouched_floor(world, swept, metrics, untouched_distance_m(scenario, world));
    let stranded = stranded_tiles_warning(scenario, metrics, untouched.as_ref());
    let rect = rect_reach_warning(scenario, world, metrics);
    let boxed = boxed_in_warning(trace);
    let sparse = note_warning(
        trace,
        ccpp_core::planners::rect_boustrophedon::SPARSE_STOPS_NOTE,
    );
    // BA* under odometry noise ended with its frontier beyond moves its bumper stopped (it
    // was told as "the path never went there, as into a room behind a doorway": hostile pass).
    let unreachable = note_warning(trace, ccpp_core::planners::ba_star::UNREACHABLE_NOTE);
    // Contacts or a pose estimate far off under odometry noise stop a plan short of floor it
    // covers (bcd on `teb_maze` at noise 0.02, seed 1: 30 % swept, told first as "the path
    // never went there" and only then by the drift warning: hostile pass).
    let drift = drift_warning(scenario, trace, metrics);
    // (floor never approached is said once, by the warning that knows why when one does)
    let explained = stranded.is_some()
        || drift.is_some()
        || rect.is_some()
        || boxed.is_some()
        || sparse.is_some()
        || unreachable.is_some()
        || metrics.stop_reason.is_some()
        || !moved;
    out.extend(stranded);
    out.extend(rect);
    out.extend(rect_lane_area_warning(scenario));
    out.extend(boxed);
    out.extend(sparse);
    out.extend(unreachable);
    if !explained {
        out.extend(untouched_floor_warning(
            scenario,
            metrics,
            untouched.as_ref(),
        ));
    }
    out.extend(outside_reach_warning(world, swept));
    out.extend(margin_warning(trace));
    out.extend(drift);
    // (bcd and rect-boustrophedon under noise: waypoints their bumper reaction gave up; a run
    // that gave up most of its plan read as drift alone: hostile pass, stop 69)
    out.extend(note_warning(
        trace,
        ccpp_core::planners::replay::GAVE_UP_NOTE,
    ));
    out.extend(motions_cut_warning(trace, metrics));
    if let Some(why) = &metrics.stop_reason {
        out.push(stop_warning(why, "coverage"));
    }
    out
}

//! The ground truth: the map, the robot, C-free, the reachable component and the accessible
//! surface, plus exact collision checks. Only the simulator, the metrics and offline planners
//! look at a [`World`]; online planners never do.

use fixedbitset::FixedBitSet;
use serde::{Deserialize, Serialize};
use std::ops::{Add, Sub};

use crate::collide::{self, contact_radius_px};
use crate::display::Compact;
use crate::dt::{squared_edt, squared_edt_compact, CompactDt, INF};
use crate::geometry::{ceil_i64, floor_i64, Point, Pose};
use crate::grid::{Cell, GridMap, MapFrame};
use crate::search::{fill_runs, Connectivity};
use crate::zones::{MaskOccupancy, ZoneMasks};

/// The robot model: a disk of radius `radius` carrying a cleaning tool of radius `tool_radius`.
/// (Deserialized with unknown fields refused: a misspelt `tool_radus` ran with the tool as
/// wide as the robot, without a word.)
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Robot {
    /// Footprint radius `r` (collision), metres.
    pub radius: f64,
    /// Cleaning tool radius `r_tool <= r`, metres.
    pub tool_radius: f64,
}

impl Robot {
    /// A robot whose tool covers its whole footprint.
    pub fn new(radius: f64) -> Self {
        Self {
            radius,
            tool_radius: radius,
        }
    }

    /// Checks that both radii are finite, positive and `tool_radius <= radius`.
    ///
    /// # Errors
    /// [`WorldError::BadRadius`] or [`WorldError::BadToolRadius`].
    pub fn validate(&self) -> Result<(), WorldError> {
        if !(self.radius.is_finite() && self.radius > 0.0) {
            return Err(WorldError::BadRadius(self.radius));
        }
        if !(self.tool_radius.is_finite()
            && self.tool_radius > 0.0
            && self.tool_radius <= self.radius)
        {
            return Err(WorldError::BadToolRadius {
                tool: self.tool_radius,
                radius: self.radius,
            });
        }
        Ok(())
    }
}

/// [`WorldError::RobotTooBig`]'s message: a map with no free pixel says so (it said "the
/// widest free spot has clearance 0.000 m" of a map all occupied or unknown, whose cause is
/// most often its thresholds or `negate`).
fn too_big_text(radius: f64, max_clearance: f64) -> String {
    if max_clearance == 0.0 {
        format!(
            "robot of radius {} m does not fit anywhere on the map: the map has no free pixel \
             (every pixel is occupied or unknown; check its thresholds, negate and mode)",
            Compact(radius)
        )
    } else {
        format!(
            "robot of radius {} m does not fit anywhere on the map: the widest free spot has \
             clearance {} m",
            Compact(radius),
            crate::display::fixed(max_clearance, 3)
        )
    }
}

/// Errors building a world.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum WorldError {
    /// Robot radius not a finite number > 0.
    #[error(
        "robot radius must be a finite number > 0 m, got {}",
        Compact(*.0)
    )]
    BadRadius(f64),
    /// Tool radius invalid.
    #[error(
        "tool radius must be a finite number in (0, radius = {}] m, got {}",
        Compact(*.radius), Compact(*.tool)
    )]
    BadToolRadius {
        /// Tool radius given.
        tool: f64,
        /// Robot radius.
        radius: f64,
    },
    /// No centre position anywhere on the map keeps the robot clear of obstacles (with a
    /// `max_clearance` of 0: the map has no free pixel at all).
    #[error("{}", too_big_text(*.radius, *.max_clearance))]
    RobotTooBig {
        /// Robot radius.
        radius: f64,
        /// Largest clearance on the map, metres.
        max_clearance: f64,
    },
    /// Start pose not finite.
    #[error(
        "start pose must be finite, got ({}, {}, {})",
        Compact(*.0), Compact(*.1), Compact(*.2)
    )]
    BadStart(f64, f64, f64),
    /// Start outside the image.
    #[error(
        "start ({:.3}, {:.3}) is outside the map ({}x in [{:.3}, {:.3}], y in [{:.3}, {:.3}])",
        Compact(*.x), Compact(*.y), turned_text(*.yaw), Compact(*.x0), Compact(*.x1), Compact(*.y0), Compact(*.y1)
    )]
    StartOutside {
        /// Start x.
        x: f64,
        /// Start y.
        y: f64,
        /// Map bounds.
        x0: f64,
        /// Map bounds.
        x1: f64,
        /// Map bounds.
        y0: f64,
        /// Map bounds.
        y1: f64,
        /// The yaw of the map's origin: a map turned off the axes is a turned rectangle within
        /// the bounds, and a start inside them may be outside it.
        yaw: f64,
    },
    /// The map's frame lies where `f64` does not keep the precision the geometry needs
    /// ([`MapFrame::precision_problem`]).
    #[error("{0}")]
    Imprecise(crate::grid::FrameProblem),
    /// The start heading or the map origin's yaw is beyond
    /// [`crate::geometry::MAX_HEADING_RAD`] (a heading in degrees, or a typo).
    #[error("{what} {why}")]
    BadHeading {
        /// Which heading: `start heading` or `map origin yaw`.
        what: &'static str,
        /// Why it is refused ([`crate::geometry::heading_problem`]).
        why: String,
    },
    /// The robot's disk at the start overlaps an obstacle or unknown space.
    #[error(
        "start ({:.3}, {:.3}) is in an obstacle: a robot of radius {} m there overlaps \
         occupied or unknown pixels",
        Compact(*.x), Compact(*.y), Compact(*.radius)
    )]
    StartInObstacle {
        /// Start x.
        x: f64,
        /// Start y.
        y: f64,
        /// Robot radius.
        radius: f64,
    },
    /// The robot's disk at the start overlaps a keep-out zone.
    #[error(
        "start ({:.3}, {:.3}) is in a keep-out zone: a robot of radius {} m there \
         overlaps keep-out pixels",
        Compact(*.x), Compact(*.y), Compact(*.radius)
    )]
    StartInKeepout {
        /// Start x.
        x: f64,
        /// Start y.
        y: f64,
        /// Robot radius.
        radius: f64,
    },
    /// The robot fits at the start, but no pixel centre at or next to it is C-free (a start
    /// in a gap as wide as the robot, which it fits only between pixel centres): the reachable
    /// floor, flooded from C-free pixel centres, would be empty and every run measured 0.
    #[error(
        "start ({:.3}, {:.3}) fits a robot of radius {} m only between pixel centres: no pixel \
         centre at or next to it is clear for the robot, and the floor it can reach is measured \
         from those; move the start out of the gap",
        Compact(*.x), Compact(*.y), Compact(*.radius)
    )]
    StartBetweenCentres {
        /// Start x.
        x: f64,
        /// Start y.
        y: f64,
        /// Robot radius.
        radius: f64,
    },
    /// The robot's disk at the start reaches outside the work area (internal: such a start
    /// gets an approach, [`World::approach`], and this is never returned).
    #[error(
        "start ({:.3}, {:.3}) is outside the area: a robot of radius {} m there is not \
         wholly inside it",
        Compact(*.x), Compact(*.y), Compact(*.radius)
    )]
    StartOutsideArea {
        /// Start x.
        x: f64,
        /// Start y.
        y: f64,
        /// Robot radius.
        radius: f64,
    },
    /// No path leads from a start outside the area into it.
    #[error(
        "the area cannot be reached from the start ({:.3}, {:.3}): no path for a disk of \
         radius {} m (the robot, or the clearance disk a rectangular robot turns in) leads into \
         it without touching an obstacle or a keep-out zone",
        Compact(*.x), Compact(*.y), Compact((*.radius * 1e6).round() / 1e6)
    )]
    AreaUnreachable {
        /// Start x.
        x: f64,
        /// Start y.
        y: f64,
        /// Radius of the disk the approach was planned for.
        radius: f64,
    },
    /// The zones leave no spot where the robot fits.
    #[error(
        "{} no floor where a robot of radius {} m fits ({free_px} free pixels {})",
        zones.holds(),
        Compact((*.radius * 1e6).round() / 1e6),
        zones.pixels()
    )]
    NoRoomInZones {
        /// Robot radius.
        radius: f64,
        /// Free pixels of the true map that are inside the area and outside every keep-out.
        free_px: usize,
        /// The zones given.
        zones: ZonesGiven,
    },
}

/// Which zones a run has, for the words of [`WorldError::NoRoomInZones`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ZonesGiven {
    /// An area only.
    Area,
    /// Keep-out zones only.
    Keepout,
    /// An area and keep-out zones.
    Both,
}

impl ZonesGiven {
    /// The zones of `z`.
    #[must_use]
    pub fn of(z: &ZoneMasks) -> Self {
        match (z.area.is_some(), z.keepout.is_clear()) {
            (true, true) => Self::Area,
            (false, _) => Self::Keepout,
            (true, false) => Self::Both,
        }
    }

    fn holds(self) -> &'static str {
        match self {
            Self::Area => "the area holds",
            Self::Keepout => "the map outside the keep-out zones holds",
            Self::Both => "the area minus the keep-out zones holds",
        }
    }

    fn pixels(self) -> &'static str {
        match self {
            Self::Area => "inside the area",
            Self::Keepout => "outside the keep-outs",
            Self::Both => "inside the area and outside the keep-outs",
        }
    }
}

/// The ground truth for one robot on one map.
#[derive(Clone)]
pub struct World {
    /// The true map (collisions).
    map: GridMap,
    /// The true map with every forbidden zone pixel occupied (what planners plan on); `None`
    /// without zones.
    plan: Option<GridMap>,
    zones: Option<ZoneMasks>,
    robot: Robot,
    /// Where coverage starts (the end of the approach when the start is outside the area).
    start: Pose,
    /// Where the robot is placed: `start`, or a pose outside the area.
    initial: Pose,
    /// The approach from `initial` to `start` (waypoints after `initial`; empty when the
    /// robot starts inside the area).
    approach: Vec<Point>,
    /// Squared distance (px^2) from each pixel centre to the nearest non-free pixel centre of
    /// the planning map (virtual walls included), counting the outside as non-free; 2 bytes a
    /// pixel unless some pixel lies 256 pixels or more from every obstacle.
    obstacle_dt2: CompactDt,
    /// Non-free pixels of the true map (the simulator's collision checks skip free runs a
    /// word at a time).
    blocked: FixedBitSet,
    /// Non-free pixels of the planning map (with zones only).
    plan_blocked: Option<FixedBitSet>,
    cfree: FixedBitSet,
    /// The start's C-free component, found on first use ([`World::reachable`]).
    reachable: std::sync::OnceLock<FixedBitSet>,
    /// The accessible surface and its pixel count, computed on first use
    /// ([`World::accessible`]): only the metrics, the pictures and some offline planners read
    /// it, so a run can compute it on a second thread while the planner works.
    accessible: std::sync::OnceLock<(FixedBitSet, usize)>,
}

impl std::fmt::Debug for World {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("World")
            .field("frame", self.map.frame())
            .field("robot", &self.robot)
            .field("start", &self.start)
            .field("accessible_px", &self.accessible_count())
            .finish_non_exhaustive()
    }
}

/// [`World::digest`] of the world that `map` and `zones` make, computed before it is built
/// (so a changed map is named as such before anything else about the world is judged): the
/// true map's content hash and, with zones, that of the map with the zones as walls.
#[must_use]
pub fn map_digest(map: &GridMap, zones: Option<&ZoneMasks>) -> u64 {
    let mut h = crate::hash::Fnv::new();
    h.bytes(&map.content_hash().to_le_bytes());
    let n = map.frame().len();
    let zones = zones.filter(|z| {
        !z.is_empty() && z.keepout.len() == n && z.area.as_ref().is_none_or(|a| a.len() == n)
    });
    if let Some(z) = zones {
        h.bytes(
            &map.content_hash_mapped(|i, c| z.plan_cell(i, c))
                .to_le_bytes(),
        );
    }
    h.finish()
}

impl World {
    /// Prepares the truth for `robot` on `map`, starting at `start` (or, when `None`, at the
    /// default start: the C-free pixel centre with the largest clearance in the largest C-free
    /// component, ties by row-major order, heading east).
    ///
    /// The map's frame must lie where `f64` keeps the precision the geometry needs
    /// ([`MapFrame::precision_problem`]: a resolution of at least 1e-5 m/px, sides of at most
    /// 1e6 m, corners within 1e8 m of the world's origin), and the start heading and the
    /// origin's yaw within two turns: outside those bounds results would change without a word
    /// (at origin 1e15 m with a yaw of 0.5 rad, ba-star stalled at 10 % of the floor).
    ///
    /// # Errors
    /// Invalid radii, a frame beyond the precision bounds ([`WorldError::Imprecise`]), a
    /// heading beyond two turns ([`WorldError::BadHeading`]), a robot that fits nowhere, a start
    /// outside the map or in an obstacle.
    pub fn new(map: GridMap, robot: Robot, start: Option<Pose>) -> Result<Self, WorldError> {
        Self::with_zones(map, robot, start, None)
    }

    /// [`World::new`] with work zones ([`crate::zones`]): every pixel outside the area and every
    /// keep-out pixel becomes a virtual wall. C-free, the reachable component, the accessible
    /// surface, the default start and [`World::map`] (what planners plan on and the sensor
    /// reads) include the virtual walls; collisions ([`World::first_contact`]) are checked
    /// against the true map only ([`World::true_map`]). Empty zones are the same as `None`.
    ///
    /// # Errors
    /// As [`World::new`], plus a start in a keep-out zone, an area the start cannot reach
    /// (a start outside the area gets an approach, [`World::approach`]), and zones that leave
    /// no spot where the robot fits.
    ///
    /// # Panics
    /// When a zone mask is not the map's size.
    pub fn with_zones(
        map: GridMap,
        robot: Robot,
        start: Option<Pose>,
        zones: Option<ZoneMasks>,
    ) -> Result<Self, WorldError> {
        Self::with_zones_fitting(map, robot, start, zones, robot.radius)
    }

    /// [`World::with_zones`] for a planner that needs room for a disk of radius `fit` (a value
    /// below the robot's radius counts as the robot's): a start outside the area gets an
    /// approach planned for that disk, ending at the nearest pixel centre where it fits inside
    /// the area (rect-boustrophedon plans its lanes for the rectangle's clearance disk, which
    /// did not fit where the robot's disk first did, so every start outside an area was
    /// refused).
    ///
    /// # Errors
    /// As [`World::with_zones`].
    ///
    /// # Panics
    /// As [`World::with_zones`].
    pub fn with_zones_fitting(
        map: GridMap,
        robot: Robot,
        start: Option<Pose>,
        zones: Option<ZoneMasks>,
        fit: f64,
    ) -> Result<Self, WorldError> {
        Self::with_zones_room(map, robot, start, zones, fit, fit)
    }

    /// [`World::with_zones_fitting`] whose approach, once inside the area, goes on through the
    /// part of the area it reached to a pixel centre where a disk of radius `room` fits under
    /// every virtual wall, when the part has one (else it ends where it reached the part, as
    /// with `room` = `fit`): of the nearest 48 such centres, the one whose lattice of tiles of
    /// side `room - fit` anchored there reaches the most tiles (a tile counts where the disk
    /// of radius `fit` fits at its centre and halfway to its neighbour), ties to the nearest.
    /// For a tile planner, whose tiles are anchored at the start: an approach that ended at
    /// the first spot where the robot fitted (a strip beside a wall, at the end of the wall)
    /// left BA*'s tiles no way into the room beyond, and it swept 0.6 % of the area (hostile
    /// pass, on `teb_maze` with a yawed origin); one that ended at the nearest roomy spot left
    /// them in a pocket above an obstacle on `aws_small_house` (8.5 %; now 82 %).
    ///
    /// # Errors
    /// As [`World::with_zones`].
    ///
    /// # Panics
    /// As [`World::with_zones`].
    pub fn with_zones_room(
        map: GridMap,
        robot: Robot,
        start: Option<Pose>,
        zones: Option<ZoneMasks>,
        fit: f64,
        room: f64,
    ) -> Result<Self, WorldError> {
        robot.validate()?;
        let frame = *map.frame();
        if let Some(p) = frame.precision_problem() {
            return Err(WorldError::Imprecise(p));
        }
        // (a non-finite start is refused below as such: `BadStart`)
        let headings = [
            ("map origin yaw", Some(frame.origin.theta)),
            ("start heading", start.map(|s| s.theta)),
        ];
        for (what, theta) in headings {
            if let Some(why) = theta
                .filter(|t| t.is_finite())
                .and_then(crate::geometry::heading_problem)
            {
                return Err(WorldError::BadHeading { what, why });
            }
        }
        let zones = zones.filter(|z| !z.is_empty());
        let plan = zones.as_ref().map(|z| {
            assert!(
                z.keepout.len() == frame.len()
                    && z.area.as_ref().is_none_or(|a| a.len() == frame.len()),
                "zone masks must match the map"
            );
            let mut p = map.clone();
            for (i, c) in p.cells_mut().iter_mut().enumerate() {
                *c = z.plan_cell(i, *c);
            }
            p
        });
        let cells = plan.as_ref().unwrap_or(&map).cells();
        let (obstacle_dt2, cfree) = cfree_of(plan.as_ref().unwrap_or(&map), robot.radius);
        let rc = contact_radius_px(robot.radius / frame.resolution);
        let rc2 = rc * rc;
        if cfree.is_clear() && zones.is_some() {
            let free_px = cells.iter().filter(|c| c.is_free()).count();
            let fits_without = squared_edt(
                frame.width,
                frame.height,
                |i| !map.cells()[i].is_free(),
                true,
            )
            .iter()
            .any(|&d2| f64::from(d2) >= rc2);
            if let (true, Some(z)) = (fits_without, zones.as_ref()) {
                return Err(WorldError::NoRoomInZones {
                    radius: robot.radius,
                    free_px,
                    zones: ZonesGiven::of(z),
                });
            }
        }
        if cfree.is_clear() {
            // A start given off the map is refused as such first: the robot's size does not
            // matter to it (`ccpp info`, which reports a robot too big, took such a start).
            if let Some(s) = start {
                start_on_map(&frame, s)?;
            }
            let mut max_d2 = 0u32;
            obstacle_dt2.for_each(|_, d2| {
                if d2 != INF {
                    max_d2 = max_d2.max(d2);
                }
            });
            return Err(WorldError::RobotTooBig {
                radius: robot.radius,
                max_clearance: ((f64::from(max_d2)).sqrt() - 0.5).max(0.0) * frame.resolution,
            });
        }
        let start = match start {
            Some(s) => s,
            None => default_start(&frame, &cfree, &obstacle_dt2),
        };
        let blocked = {
            let cells = map.cells();
            bitset_where(frame.len(), |i| !cells[i].is_free())
        };
        let plan_blocked = plan.as_ref().map(|p| {
            let cells = p.cells();
            bitset_where(frame.len(), |i| !cells[i].is_free())
        });
        let mut world = Self {
            map,
            plan,
            plan_blocked,
            zones,
            robot,
            start,
            initial: start,
            approach: Vec::new(),
            obstacle_dt2,
            blocked,
            cfree,
            reachable: std::sync::OnceLock::new(),
            accessible: std::sync::OnceLock::new(),
        };
        match world.check_start() {
            Err(WorldError::StartOutsideArea { .. }) => world.plan_approach(fit, room)?,
            r => r?,
        }
        Ok(world)
    }

    fn check_start(&self) -> Result<(), WorldError> {
        let s = self.start;
        let frame = self.map.frame();
        start_on_map(frame, s)?;
        if self.true_disk_collides(s.position()) {
            return Err(WorldError::StartInObstacle {
                x: s.x,
                y: s.y,
                radius: self.robot.radius,
            });
        }
        if let Some(z) = &self.zones {
            let g = frame.world_to_grid(s.position());
            let r_px = self.r_px();
            let keepout = MaskOccupancy::new(frame, &z.keepout, false);
            if collide::disk_hits(&keepout, g, r_px) {
                return Err(WorldError::StartInKeepout {
                    x: s.x,
                    y: s.y,
                    radius: self.robot.radius,
                });
            }
            if let Some(area) = &z.area {
                if collide::disk_hits(&MaskOccupancy::new(frame, area, true), g, r_px) {
                    return Err(WorldError::StartOutsideArea {
                        x: s.x,
                        y: s.y,
                        radius: self.robot.radius,
                    });
                }
            }
        }
        if self.start_seed().is_none() {
            return Err(WorldError::StartBetweenCentres {
                x: s.x,
                y: s.y,
                radius: self.robot.radius,
            });
        }
        Ok(())
    }

    /// The pixel the reachable C-free set is flooded from: the start's own pixel when its
    /// centre is C-free, else the first C-free one of its 8 neighbours; `None` when none is
    /// (a start in a gap that the robot fits only between pixel centres).
    fn start_seed(&self) -> Option<usize> {
        let frame = *self.map.frame();
        let g = frame.world_to_grid(self.start.position());
        let (sc, sr) = frame.grid_to_pixel_signed(g);
        [
            (0, 0),
            (1, 0),
            (-1, 0),
            (0, 1),
            (0, -1),
            (1, 1),
            (-1, 1),
            (1, -1),
            (-1, -1),
        ]
        .into_iter()
        .filter_map(|(dc, dr)| frame.checked(sc + dc, sr + dr))
        .map(|(c, r)| frame.index(c, r))
        .find(|&i| self.cfree.contains(i))
    }

    /// The approach of a start outside the area: the shortest 8-connected chain of pixel
    /// centres where the robot stands clear of obstacles and keep-outs (the area's border does
    /// not count) from the start to the nearest centre that is C-free under every virtual wall
    /// in the largest part of the area it can reach (8-connected C-free centres; of equal parts
    /// the nearest; a start whose own pixel is in the area, its disk across the border, takes
    /// the nearest part),
    /// shortened to straight segments that are free of obstacles and keep-outs (exact swept-disk
    /// test). With `fit` above the robot's radius the whole approach is planned for a disk of
    /// that radius (a rectangular robot turns at every corner of it in its clearance disk), and
    /// it ends where that disk fits under every virtual wall. Sets `start` to its end (heading
    /// along its last segment).
    /// With `room` above `fit` the approach then goes on as [`World::with_zones_room`] says.
    fn plan_approach(&mut self, fit: f64, room: f64) -> Result<(), WorldError> {
        let s = self.start;
        let fit = fit.max(self.robot.radius);
        let unreachable = || WorldError::AreaUnreachable {
            x: s.x,
            y: s.y,
            radius: fit,
        };
        let Some(z) = self.zones.as_ref() else {
            return Err(unreachable());
        };
        let frame = *self.map.frame();
        let (w, h) = (frame.width, frame.height);
        let cells = self.map.cells();
        let dt = squared_edt(w, h, |i| !cells[i].is_free() || z.keepout.contains(i), true);
        let r_px = fit / frame.resolution;
        let rc = contact_radius_px(r_px);
        let occ = Approach {
            map: &self.map,
            keepout: &z.keepout,
        };
        let free_seg =
            |a: Point, b: Point| collide::segment_first_contact(&occ, a, b, r_px).is_none();
        let ok = |i: usize| f64::from(dt[i]) >= rc * rc;
        // Where coverage may start: room for the planner's disk under every virtual wall (for
        // the robot's own radius, C-free itself: the same test on the same distances).
        let fits = |i: usize| f64::from(self.obstacle_dt2.get(i)) >= rc * rc;
        // The parts of the area (8-connected pixels where the disk fits) and their sizes: the
        // approach goes to the largest part it reaches, not to the nearest (an area drawn
        // loosely around a room took in a strip of the corridor below it, and a start in the
        // corridor swept the 0.8 m2 strip, "effective coverage 1.0", not the 6.1 m2 room).
        // A start whose own pixel is inside the area (its disk across the border) moves
        // into the part it stands in, the nearest, as before: the largest-part rule is for a
        // start out of the area, and a few centimetres across a border must not send the
        // robot to another part.
        let inside = frame.pixel_of(s.position()).is_some_and(|(c, r)| {
            z.area
                .as_ref()
                .is_some_and(|a| a.contains(frame.index(c, r)))
        });
        // (not labelled for a start inside: every part then counts alike, the nearest wins)
        let parts = (!inside).then(|| parts_of(w, h, &fits));
        let size = |j: usize| {
            parts
                .as_ref()
                .map_or(1, |(part, sizes)| sizes[part[j] as usize])
        };
        let largest = parts
            .as_ref()
            .map_or(1, |(_, sizes)| sizes.iter().copied().max().unwrap_or(0));
        // Dijkstra with integer octile costs (70 straight, 99 diagonal).
        let mut dist = vec![u32::MAX; frame.len()];
        let mut parent = vec![u32::MAX; frame.len()];
        // (popped in the order of a binary heap of (cost, pixel), faster on a large map)
        let mut heap = crate::search::MonotoneQueue::new();
        let g0 = frame.world_to_grid(s.position());
        let (sc, sr) = frame.grid_to_pixel_signed(g0);
        for dr in -1..=1i64 {
            for dc in -1..=1i64 {
                if let Some((c, r)) = frame.checked(sc + dc, sr + dr) {
                    let i = frame.index(c, r);
                    if ok(i) && free_seg(g0, frame.pixel_center_grid(c, r)) {
                        let d = if dc == 0 && dr == 0 {
                            0
                        } else if dc == 0 || dr == 0 {
                            70
                        } else {
                            99
                        };
                        if d < dist[i] {
                            dist[i] = d;
                            heap.push(u64::from(d), i as u32);
                        }
                    }
                }
            }
        }
        // (the first pixel settled of a part is its nearest; of equal parts the nearer wins)
        let mut goal: Option<usize> = None;
        while let Some((d, i)) = heap.pop() {
            let (d, i) = (d as u32, i as usize);
            if d > dist[i] {
                continue;
            }
            if fits(i) {
                if goal.is_none_or(|g| size(i) > size(g)) {
                    goal = Some(i);
                }
                // No part is larger: the search can stop.
                if size(i) == largest {
                    break;
                }
            }
            relax_octile(&frame, i, d, &ok, &mut dist, &mut parent, &mut heap);
        }
        let Some(goal) = goal else {
            // No way in; or, for a disk larger than the robot, no spot inside to stand at all
            // (an area narrower than the disk): say which.
            if fit > self.robot.radius && !(0..frame.len()).any(fits) {
                let cells = self.plan.as_ref().unwrap_or(&self.map).cells();
                return Err(WorldError::NoRoomInZones {
                    radius: fit,
                    free_px: cells.iter().filter(|c| c.is_free()).count(),
                    zones: ZonesGiven::of(z),
                });
            }
            return Err(unreachable());
        };
        let mut chain = vec![goal];
        let mut k = goal;
        while parent[k] != u32::MAX {
            k = parent[k] as usize;
            chain.push(k);
        }
        chain.reverse();
        if room > fit {
            let rr = contact_radius_px(room / frame.resolution);
            let roomy = |i: usize| f64::from(self.obstacle_dt2.get(i)) >= rr * rr;
            // Of the nearest roomy spots, the one whose tile lattice (tiles of the extra
            // room's side, anchored there as the planner's are at its start) reaches the most
            // tiles; ties: the nearest. The nearest alone left BA*'s lattice in a pocket of
            // an area on `aws_small_house` (8.5 % swept where a start 5 cm away swept 90 %).
            let side_px = (room - fit) / frame.resolution;
            let reach = |i: usize| tiles_reached(&frame, i, side_px, &fits);
            chain.extend(best_roomy(&frame, goal, &fits, &roomy, &reach));
        }
        let pts: Vec<Point> = std::iter::once(g0)
            .chain(chain.iter().map(|&i| {
                let (c, r) = frame.col_row(i);
                frame.pixel_center_grid(c, r)
            }))
            .collect();
        // Greedy shortening: from each kept point, as far along the chain as a free segment
        // reaches.
        let mut kept = Vec::new();
        let mut anchor = pts[0];
        for j in 1..pts.len() {
            if !free_seg(anchor, pts[j]) {
                let prev = pts[j - 1];
                if prev == anchor || !free_seg(prev, pts[j]) {
                    return Err(unreachable());
                }
                kept.push(prev);
                anchor = prev;
            }
        }
        if let Some(&last) = pts.last() {
            if last != g0 {
                kept.push(last);
            }
        }
        let approach: Vec<Point> = kept.iter().map(|&g| frame.grid_to_world(g)).collect();
        let end = approach.last().copied().unwrap_or(s.position());
        let before = if approach.len() >= 2 {
            approach[approach.len() - 2]
        } else {
            s.position()
        };
        let theta = if end == before {
            s.theta
        } else {
            (end.y - before.y).atan2(end.x - before.x)
        };
        self.initial = s;
        self.start = Pose::new(end.x, end.y, theta);
        self.approach = approach;
        Ok(())
    }

    /// Where the robot is placed: the start, or, when the start given is outside the work
    /// area, that pose (the robot then drives [`World::approach`] to [`World::start`] first).
    pub fn initial_pose(&self) -> Pose {
        self.initial
    }

    /// The approach from [`World::initial_pose`] to [`World::start`] when the start given lies
    /// outside the work area: waypoints (world frame) after the initial position, driven
    /// before the planner starts; empty otherwise. It avoids obstacles and keep-outs.
    pub fn approach(&self) -> &[Point] {
        &self.approach
    }

    /// Length of [`World::approach`], metres.
    pub fn approach_length_m(&self) -> f64 {
        let mut last = self.initial.position();
        let mut len = 0.0;
        for p in &self.approach {
            len += last.dist(*p);
            last = *p;
        }
        len
    }

    /// 8-connected flood fill of C-free pixel centres from the start's pixel (or, if that centre
    /// is not C-free, from a C-free neighbour whose centre is within one pixel of the start).
    fn flood_reachable(&self) -> FixedBitSet {
        let frame = *self.map.frame();
        let mut seen = FixedBitSet::with_capacity(frame.len());
        if let Some(s) = self.start_seed() {
            fill_runs(
                frame.width,
                frame.height,
                |i| self.cfree.contains(i),
                s,
                Connectivity::Eight,
                &mut seen,
                |_, _, _| {},
            );
        }
        seen
    }

    /// The accessible surface and its pixel count, computed on the first call (a thread that
    /// calls it while another computes it waits for that result).
    fn accessible_and_count(&self) -> &(FixedBitSet, usize) {
        self.accessible.get_or_init(|| {
            let frame = *self.map.frame();
            let rt = self.robot.tool_radius / frame.resolution + 1e-6;
            let acc = accessible_pixels(self.map(), self.reachable(), rt);
            let count = acc.count_ones(..);
            (acc, count)
        })
    }

    /// The floor the zones cut off from the start, as `(allowed, apart)` pixel counts; `None`
    /// without zones or when the start is not C-free on the true map.
    ///
    /// `allowed`: the free pixels of [`World::map`] (inside the area, outside the keep-outs)
    /// that the tool sweeps from a position C-free under the zones that the robot reaches
    /// from the start on the *true* map (the zones not counted as walls on the way); `apart`:
    /// those of them that are not accessible ([`World::accessible`]: the zones counted). Both
    /// are judged by the robot's disk, so a gap between keep-outs too narrow for the robot
    /// cuts off what lies beyond it, as it does in the run (a 0.2 m gap for a 0.3 m robot, or
    /// 2000 one-pixel keep-outs, were taken for open by a pixel flood: hostile pass), and the
    /// rims along virtual walls, lost in both, do not count.
    pub fn zone_cut_off_px(&self) -> Option<(usize, usize)> {
        self.zones.as_ref()?;
        let frame = *self.map.frame();
        let seed = self.start_seed()?;
        let (_, cfree_plain) = cfree_of(&self.map, self.robot.radius);
        if !cfree_plain.contains(seed) {
            return None;
        }
        let mut near = FixedBitSet::with_capacity(frame.len());
        fill_runs(
            frame.width,
            frame.height,
            |i| cfree_plain.contains(i),
            seed,
            Connectivity::Eight,
            &mut near,
            |_, _, _| {},
        );
        near.intersect_with(&self.cfree);
        let rt = self.robot.tool_radius / frame.resolution + 1e-6;
        let allowed = accessible_pixels(self.map(), &near, rt);
        let n_allowed = allowed.count_ones(..);
        let apart = n_allowed - allowed.intersection_count(self.accessible());
        Some((n_allowed, apart))
    }

    /// The map planners plan on and the sensor reads: the true map, with every pixel outside
    /// the work area and every keep-out pixel occupied when the world has zones
    /// ([`World::with_zones`]); the true map otherwise.
    pub fn map(&self) -> &GridMap {
        self.plan.as_ref().unwrap_or(&self.map)
    }

    /// The true map (what collisions are checked against; pictures draw it).
    pub fn true_map(&self) -> &GridMap {
        &self.map
    }

    /// A digest of the maps the world was made of: the true map and, with zones, the planning
    /// map with the zones as walls ([`GridMap::content_hash`]). Two worlds with the same
    /// digest plan and measure on the same pixels; a map or zone file edited since a run gives
    /// another digest.
    #[must_use]
    pub fn digest(&self) -> u64 {
        map_digest(&self.map, self.zones.as_ref())
    }

    /// The work zones as pixel masks, if any.
    pub fn zones(&self) -> Option<&ZoneMasks> {
        self.zones.as_ref()
    }

    /// The map's geometry.
    pub fn frame(&self) -> &MapFrame {
        self.map.frame()
    }

    /// The robot.
    pub fn robot(&self) -> Robot {
        self.robot
    }

    /// The pose coverage starts from: the start, or the end of the approach when the start
    /// given lies outside the work area ([`World::initial_pose`]).
    pub fn start(&self) -> Pose {
        self.start
    }

    /// Non-free pixels of the planning map: the true map's, and with zones the pixels they
    /// forbid (virtual walls).
    pub fn plan_blocked(&self) -> &FixedBitSet {
        self.plan_blocked.as_ref().unwrap_or(&self.blocked)
    }

    /// Non-free pixels of the true map (obstacles and unknown; zones not included).
    pub fn true_blocked(&self) -> &FixedBitSet {
        &self.blocked
    }

    /// C-free pixel centres (whole map; virtual walls count as obstacles).
    pub fn cfree(&self) -> &FixedBitSet {
        &self.cfree
    }

    /// C-free pixel centres of the start's 8-connected component.
    ///
    /// Found on the first call (of any thread), then kept.
    pub fn reachable(&self) -> &FixedBitSet {
        self.reachable.get_or_init(|| self.flood_reachable())
    }

    /// The accessible surface `A`: free pixels whose centre lies within `r_tool` of a reachable
    /// C-free centre. With zones: free pixels of [`World::map`] (inside the area, outside every
    /// keep-out) within `r_tool` of a reachable centre of C-free under the virtual walls.
    ///
    /// Computed on the first call (of any thread), then kept.
    pub fn accessible(&self) -> &FixedBitSet {
        &self.accessible_and_count().0
    }

    /// Number of pixels in `A`.
    pub fn accessible_count(&self) -> usize {
        self.accessible_and_count().1
    }

    /// Area of `A` in square metres.
    pub fn accessible_area_m2(&self) -> f64 {
        let r = self.frame().resolution;
        self.accessible_count() as f64 * r * r
    }

    /// Clearance in metres at the centre of pixel `(col, row)`: distance to the nearest blocked
    /// pixel's inscribed disk (virtual walls included).
    pub fn pixel_clearance(&self, col: usize, row: usize) -> f64 {
        let d2 = self.obstacle_dt2.get(self.frame().index(col, row));
        (f64::from(d2).sqrt() - 0.5) * self.frame().resolution
    }

    fn r_px(&self) -> f64 {
        self.robot.radius / self.frame().resolution
    }

    /// Lower bound (pixels) on the distance from grid point `g` to the nearest blocked centre.
    #[inline]
    fn dist_lower_bound_px(&self, g: Point) -> f64 {
        let frame = self.frame();
        let (c, r) = frame.grid_to_pixel_signed(g);
        match frame.checked(c, r) {
            Some((c, r)) => {
                let d2 = self.obstacle_dt2.get(frame.index(c, r));
                (f64::from(d2).sqrt() - std::f64::consts::FRAC_1_SQRT_2).max(0.0)
            }
            None => 0.0,
        }
    }

    /// Does the robot's disk centred at world point `p` overlap a non-free pixel of the
    /// planning map [`World::map`] (exact; virtual walls included)? What offline planners
    /// check; the simulator uses [`World::true_disk_collides`].
    pub fn disk_collides(&self, p: Point) -> bool {
        self.disk_hits_on(p, self.map())
    }

    /// Does the robot's disk centred at world point `p` overlap a non-free pixel of the true
    /// map (exact; virtual walls ignored)?
    pub fn true_disk_collides(&self, p: Point) -> bool {
        self.disk_hits_on(p, &self.map)
    }

    /// [`World::disk_collides`] at the grid point `g` (pixels, y up): exact whatever the map's
    /// origin (a world point far from the world's origin carries rounding), so planners that
    /// plan in grid coordinates get the same answer for a map moved anywhere.
    pub fn disk_collides_grid(&self, g: Point) -> bool {
        self.disk_hits_grid(g, self.map())
    }

    fn disk_hits_on(&self, p: Point, map: &GridMap) -> bool {
        self.disk_hits_grid(self.frame().world_to_grid(p), map)
    }

    fn disk_hits_grid(&self, g: Point, map: &GridMap) -> bool {
        let r_px = self.r_px();
        if self.dist_lower_bound_px(g) > contact_radius_px(r_px) + 1e-9 {
            return false;
        }
        collide::disk_hits(map, g, r_px)
    }

    /// Exact first contact of the robot's disk moving straight from `a` to `b` (world frame)
    /// with the planning map [`World::map`] (virtual walls included): the parameter `t` in
    /// `[0, 1]` of the first overlap with a non-free pixel, or `None`. What offline planners
    /// check; the simulator uses [`World::true_first_contact`]. Sphere-traces the distance
    /// transform through open space and checks pixels exactly near obstacles, so long moves
    /// across open halls stay cheap.
    pub fn first_contact(&self, a: Point, b: Point) -> Option<f64> {
        let frame = self.frame();
        self.first_contact_grid(frame.world_to_grid(a), frame.world_to_grid(b))
    }

    /// [`World::first_contact`] between grid points `ga` and `gb` (pixels, y up): exact
    /// whatever the map's origin, see [`World::disk_collides_grid`].
    pub fn first_contact_grid(&self, ga: Point, gb: Point) -> Option<f64> {
        match (&self.plan, &self.plan_blocked) {
            (Some(map), Some(blocked)) => self.contact_on(ga, gb, map, blocked),
            _ => self.contact_on(ga, gb, &self.map, &self.blocked),
        }
    }

    /// [`World::first_contact`] against the true map (virtual walls do not stop the robot):
    /// the simulator's bumper.
    pub fn true_first_contact(&self, a: Point, b: Point) -> Option<f64> {
        let frame = self.frame();
        self.contact_on(
            frame.world_to_grid(a),
            frame.world_to_grid(b),
            &self.map,
            &self.blocked,
        )
    }

    /// First contact with `map` (whose non-free pixels are `blocked`) between grid points `ga`
    /// and `gb`. The distance transform is the planning map's: a lower bound of the distance to
    /// `map`'s obstacles either way.
    fn contact_on(
        &self,
        ga: Point,
        gb: Point,
        map: &GridMap,
        blocked: &FixedBitSet,
    ) -> Option<f64> {
        let frame = self.frame();
        let r_px = self.r_px();
        let rc = contact_radius_px(r_px);
        if box_clear(frame, ga, gb, rc, blocked) {
            return None;
        }
        let len = ga.dist(gb);
        if len == 0.0 {
            return if collide::disk_hits(map, ga, r_px) {
                Some(0.0)
            } else {
                None
            };
        }
        let u = gb.sub(ga).scale(1.0 / len);
        let mut s = 0.0;
        // The exact one-pixel steps go on to here since a stretch failed `capsule_clear`.
        let mut exact_to = 0.0;
        // The next stretch's length: doubled after a clear one, so a long free segment takes
        // a few capsule tests; back to the first after one that is not.
        let mut stretch = CLEAR_STRETCH_PX;
        while s < len {
            let p = ga.add(u.scale(s));
            let margin = self.dist_lower_bound_px(p) - rc;
            if margin > 0.5 {
                s += margin;
                continue;
            }
            if s >= exact_to {
                // Along a wall the distance transform skips nothing: ask a whole stretch at
                // once whether any blocked pixel lies within reach of it.
                let e = (s + stretch).min(len);
                if capsule_clear(frame, p, ga.add(u.scale(e)), rc, blocked) {
                    s = e;
                    stretch *= 2.0;
                    continue;
                }
                exact_to = e;
                stretch = CLEAR_STRETCH_PX;
            }
            let e = (s + 1.0).min(len);
            let q = ga.add(u.scale(e));
            let truth = Truth { map, blocked };
            if let Some(t) = collide::segment_first_contact(&truth, p, q, r_px) {
                return Some(((s + t * (e - s)) / len).clamp(0.0, 1.0));
            }
            s = e;
        }
        None
    }

    /// Is the straight motion of the robot from `a` to `b` free of contact with the planning
    /// map (virtual walls included)?
    pub fn segment_free(&self, a: Point, b: Point) -> bool {
        self.first_contact(a, b).is_none()
    }

    /// [`World::segment_free`] between grid points (pixels, y up), see
    /// [`World::first_contact_grid`].
    pub fn segment_free_grid(&self, ga: Point, gb: Point) -> bool {
        self.first_contact_grid(ga, gb).is_none()
    }
}

/// The pixels `[col0, col1, row0, row1]` (inclusive) whose centres lie within `r` of the box
/// of the segment from grid point `a` to `b` (so every pixel within `r` of the segment), taken
/// with a margin far below the contact tolerance and far above the rounding of grid
/// coordinates; `None` when that box is empty, reaches beyond the image or a value is not
/// finite (the exact tests then decide: they count every pixel beyond the image as blocked).
#[inline]
fn reach_box(frame: &MapFrame, a: Point, b: Point, r: f64) -> Option<[i64; 4]> {
    let eps = 1e-7;
    let h = frame.height as f64;
    if !(a.x.is_finite() && a.y.is_finite() && b.x.is_finite() && b.y.is_finite() && r.is_finite())
    {
        return None;
    }
    let cmin = ceil_i64(a.x.min(b.x) - r - 0.5 - eps);
    let cmax = floor_i64(a.x.max(b.x) + r - 0.5 + eps);
    let rmin = ceil_i64(h - a.y.max(b.y) - r - 0.5 - eps);
    let rmax = floor_i64(h - a.y.min(b.y) + r - 0.5 + eps);
    let (w, hh) = (frame.width as i64, frame.height as i64);
    (0 <= cmin && cmin <= cmax && cmax < w && 0 <= rmin && rmin <= rmax && rmax < hh)
        .then_some([cmin, cmax, rmin, rmax])
}

/// Is every pixel that can touch the disk of contact radius `rc` pixels moving from grid point
/// `a` to `b` inside the image and not in `blocked`? A pixel touches only when its centre lies
/// within `rc` of the segment ([`collide::segment_first_contact`], [`collide::disk_hits`]),
/// so within `rc` of the segment's bounding box in each coordinate; the box of those pixels is
/// taken with a margin far below the contact tolerance and far above the rounding of grid
/// coordinates. `true` means no contact (the exact tests would find none); `false` means
/// "ask them" (also for boxes of more than [`BOX_CLEAR_MAX_PX`] pixels and non-finite points).
#[inline]
fn box_clear(frame: &MapFrame, a: Point, b: Point, rc: f64, blocked: &FixedBitSet) -> bool {
    let Some([cmin, cmax, rmin, rmax]) = reach_box(frame, a, b, rc) else {
        return false;
    };
    if (cmax - cmin + 1) * (rmax - rmin + 1) > BOX_CLEAR_MAX_PX {
        return false;
    }
    let words = blocked.as_slice();
    (rmin..=rmax).all(|row| {
        let base = row as usize * frame.width;
        crate::bits::for_each_set(
            base + cmin as usize,
            base + cmax as usize + 1,
            |k| words[k],
            |_| false,
        )
    })
}

/// Is no pixel of the image that the disk of contact radius `rc` pixels moving from grid point
/// `a` to `b` can touch in `blocked`, and all of them inside the image? As [`box_clear`], for
/// a capsule instead of its box: the pixels whose centres lie within `rc` plus
/// [`CLEAR_EPS_PX`] of the segment ([`crate::raster::capsule_runs`], the predicate the exact
/// test rejects pixels with), a bitset word at a time. `true` means no contact (the exact
/// tests, on any cut of the segment into parts, would find none); `false` means "ask them".
/// Along a wall at clearance the distance transform gives no step longer than a pixel, and a
/// lane of a 2.5 km corridor (`bcd`, 0.05 m/px) took 50 000 exact steps per check.
fn capsule_clear(frame: &MapFrame, a: Point, b: Point, rc: f64, blocked: &FixedBitSet) -> bool {
    let r = rc + CLEAR_EPS_PX;
    if reach_box(frame, a, b, r).is_none() {
        return false;
    }
    let words = blocked.as_slice();
    let mut clear = true;
    crate::raster::capsule_runs(frame, a, b, r, |row, c_lo, c_hi| {
        if clear {
            let base = row * frame.width;
            clear =
                crate::bits::for_each_set(base + c_lo, base + c_hi + 1, |k| words[k], |_| false);
        }
    });
    clear
}

/// Margin (pixels) beyond the contact radius that [`capsule_clear`] keeps: far above the
/// rounding of the points on which the exact tests cut a segment, far below a pixel.
const CLEAR_EPS_PX: f64 = 1e-6;

/// Length (pixels) of the first stretch [`World::first_contact_grid`] asks [`capsule_clear`]
/// about where the distance transform gives no longer step (doubled after each clear one).
const CLEAR_STRETCH_PX: f64 = 32.0;

/// The largest pixel box [`box_clear`] looks at (larger ones go to the exact tests, which
/// skip open space by the distance transform).
const BOX_CLEAR_MAX_PX: i64 = 64;

/// The true map plus keep-out pixels (the approach's obstacles).
struct Approach<'a> {
    map: &'a GridMap,
    keepout: &'a FixedBitSet,
}

impl collide::Occupancy for Approach<'_> {
    fn frame(&self) -> &MapFrame {
        self.map.frame()
    }
    fn blocked(&self, col: i64, row: i64) -> bool {
        !self.map.get_signed(col, row).is_free()
            || self
                .map
                .frame()
                .checked(col, row)
                .is_some_and(|(c, r)| self.keepout.contains(self.map.frame().index(c, r)))
    }
}

/// The true map as an [`collide::Occupancy`] with its non-free pixels as a bitset.
struct Truth<'a> {
    map: &'a GridMap,
    blocked: &'a FixedBitSet,
}

impl collide::Occupancy for Truth<'_> {
    fn frame(&self) -> &MapFrame {
        self.map.frame()
    }
    #[inline]
    fn blocked(&self, col: i64, row: i64) -> bool {
        !self.map.get_signed(col, row).is_free()
    }
    fn for_each_blocked_in_row(
        &self,
        row: usize,
        lo: usize,
        hi: usize,
        f: &mut dyn FnMut(usize) -> bool,
    ) {
        let base = row * self.map.frame().width;
        let blocks = self.blocked.as_slice();
        crate::bits::for_each_set(base + lo, base + hi + 1, |k| blocks[k], |i| f(i - base));
    }
}

/// The set of `i < n` where `pred(i)` holds, built a word at a time.
/// The squared distance transform of `map`'s blocked (not free) pixels and the C-free pixel
/// centres for a robot of radius `radius` metres: those whose distance to every blocked
/// centre is at least the contact radius.
fn cfree_of(map: &GridMap, radius: f64) -> (CompactDt, FixedBitSet) {
    let frame = *map.frame();
    let cells = map.cells();
    let dt2 = squared_edt_compact(frame.width, frame.height, |i| !cells[i].is_free(), true);
    let rc = contact_radius_px(radius / frame.resolution);
    let rc2 = rc * rc;
    // `CompactDt::get` per pixel, with the storage matched once.
    let cfree = match &dt2 {
        CompactDt::U16(v) => bitset_where(frame.len(), |i| {
            let d = v[i];
            f64::from(if d == u16::MAX { INF } else { u32::from(d) }) >= rc2
        }),
        CompactDt::U32(v) => bitset_where(frame.len(), |i| f64::from(v[i]) >= rc2),
    };
    (dt2, cfree)
}

fn bitset_where(n: usize, pred: impl Fn(usize) -> bool) -> FixedBitSet {
    let mut set = FixedBitSet::with_capacity(n);
    let bits = usize::BITS as usize;
    for (k, block) in set.as_mut_slice().iter_mut().enumerate() {
        let base = k * bits;
        let mut word = 0usize;
        for i in base..(base + bits).min(n) {
            word |= usize::from(pred(i)) << (i - base);
        }
        *block = word;
    }
    set
}

/// The default start: the C-free pixel centre with the largest clearance in the largest C-free
/// 8-connected component; ties by row-major order; heading east.
///
/// Components are visited in the order of their first pixel (row-major); the first of the
/// largest wins, and within it the largest `dt2`, then the smallest index.
fn default_start(frame: &MapFrame, cfree: &FixedBitSet, dt2: &CompactDt) -> Pose {
    let (w, h) = (frame.width, frame.height);
    let mut visited = FixedBitSet::with_capacity(frame.len());
    // (size, best dt2, best index) of the chosen component.
    let mut best: Option<(usize, u32, usize)> = None;
    for i in cfree.ones() {
        if visited.contains(i) {
            continue;
        }
        let mut size = 0usize;
        let mut top = (0u32, usize::MAX);
        let inside = |j: usize| cfree.contains(j);
        fill_runs(
            w,
            h,
            inside,
            i,
            Connectivity::Eight,
            &mut visited,
            |row, lo, hi| {
                size += hi - lo + 1;
                let base = row * w;
                // The run's largest value at its first index, merged by the same rule as pixel
                // by pixel (largest, then smallest index).
                let (d, idx) = dt2.first_max(base + lo..base + hi + 1);
                if top.1 == usize::MAX || d > top.0 || (d == top.0 && idx < top.1) {
                    top = (d, idx);
                }
            },
        );
        if best.is_none_or(|b| size > b.0) {
            best = Some((size, top.0, top.1));
        }
    }
    let idx = best.map_or(usize::MAX, |b| b.2);
    let (c, r) = frame.col_row(idx);
    let p = frame.pixel_center(c, r);
    Pose::new(p.x, p.y, 0.0)
}

/// The accessible surface: free pixels whose centre lies within `rt` pixels of a `reachable`
/// centre (`d2 <= rt^2` on integer squared distances, exactly as a distance transform would
/// decide). Small tools test the few offsets of the disk around each free non-reachable pixel;
/// large ones use the distance transform.
fn accessible_pixels(map: &GridMap, reachable: &FixedBitSet, rt: f64) -> FixedBitSet {
    let frame = *map.frame();
    let (w, h) = (frame.width, frame.height);
    let cells = map.cells();
    let rt2 = rt * rt;
    let k = rt.floor().max(0.0) as i64 + 1;
    let mut offsets = Vec::new();
    if k <= 8 {
        for dy in -k..=k {
            for dx in -k..=k {
                let d2 = (dx * dx + dy * dy) as u32;
                if f64::from(d2) <= rt2 {
                    offsets.push((dx, dy, d2));
                }
            }
        }
        // Nearest first: most hits are adjacent.
        offsets.sort_by_key(|o| o.2);
    }
    let mut acc = FixedBitSet::with_capacity(frame.len());
    if k > 8 {
        let dt = squared_edt(w, h, |i| reachable.contains(i), false);
        for (i, &d2) in dt.iter().enumerate() {
            if cells[i] == Cell::Free && d2 != INF && f64::from(d2) <= rt2 {
                acc.insert(i);
            }
        }
        return acc;
    }
    acc.union_with(reachable);
    for i in 0..frame.len() {
        if cells[i] != Cell::Free || reachable.contains(i) {
            continue;
        }
        let (c, r) = ((i % w) as i64, (i / w) as i64);
        let hit = offsets.iter().any(|&(dx, dy, _)| {
            let (nc, nr) = (c + dx, r + dy);
            nc >= 0
                && nr >= 0
                && (nc as usize) < w
                && (nr as usize) < h
                && reachable.contains(nr as usize * w + nc as usize)
        });
        if hit {
            acc.insert(i);
        }
    }
    acc
}

/// Relaxes the 8 neighbours of pixel `i` (settled at cost `d`) where `open` holds, with
/// integer octile costs (70 straight, 99 diagonal) in a fixed order: the step of the
/// approach's searches.
fn relax_octile(
    frame: &MapFrame,
    i: usize,
    d: u32,
    open: &dyn Fn(usize) -> bool,
    dist: &mut [u32],
    parent: &mut [u32],
    heap: &mut crate::search::MonotoneQueue,
) {
    let (c, r) = ((i % frame.width) as i64, (i / frame.width) as i64);
    for (dc, dr, cost) in [
        (1, 0, 70),
        (-1, 0, 70),
        (0, 1, 70),
        (0, -1, 70),
        (1, 1, 99),
        (-1, 1, 99),
        (1, -1, 99),
        (-1, -1, 99),
    ] {
        if let Some((nc, nr)) = frame.checked(c + dc, r + dr) {
            let j = frame.index(nc, nr);
            let nd = d + cost;
            if open(j) && nd < dist[j] {
                dist[j] = nd;
                parent[j] = i as u32;
                heap.push(u64::from(nd), j as u32);
            }
        }
    }
}

/// Roomy spots [`best_roomy`] ranks: the nearest this many.
const ROOMY_CANDIDATES: usize = 48;

/// The way (pixels after `from`, through `through`) to the best of the [`ROOMY_CANDIDATES`]
/// pixels nearest to `from` where `goal` holds: the one with the largest `score`, ties to the
/// nearer (Dijkstra order); empty when `from` itself is one and scores at least as well, or
/// when none is reached.
fn best_roomy(
    frame: &MapFrame,
    from: usize,
    through: &dyn Fn(usize) -> bool,
    goal: &dyn Fn(usize) -> bool,
    score: &dyn Fn(usize) -> usize,
) -> Vec<usize> {
    let mut dist = vec![u32::MAX; frame.len()];
    let mut parent = vec![u32::MAX; frame.len()];
    let mut heap = crate::search::MonotoneQueue::new();
    dist[from] = 0;
    heap.push(0, from as u32);
    let mut best: Option<(usize, usize)> = None;
    let mut seen = 0;
    while let Some((d, i)) = heap.pop() {
        let (d, i) = (d as u32, i as usize);
        if d > dist[i] {
            continue;
        }
        if goal(i) {
            let s = score(i);
            if best.is_none_or(|b| s > b.0) {
                best = Some((s, i));
            }
            seen += 1;
            if seen == ROOMY_CANDIDATES {
                break;
            }
        }
        relax_octile(frame, i, d, through, &mut dist, &mut parent, &mut heap);
    }
    let Some((_, end)) = best else {
        return Vec::new();
    };
    let mut chain = Vec::new();
    let mut k = end;
    while k != from {
        chain.push(k);
        k = parent[k] as usize;
    }
    chain.reverse();
    chain
}

/// Most tiles [`tiles_reached`] counts (a bound on its work on a large map).
const TILES_COUNTED: usize = 1 << 20;

/// Tiles of side `side_px` on the lattice whose tile centres include pixel `at`'s centre,
/// reached from `at`'s tile through the four neighbours: a tile counts where `fits` holds at
/// the pixel of its centre and halfway to the tile it is reached from (the lattice a tile
/// planner starting at `at` has). At most [`TILES_COUNTED`].
fn tiles_reached(frame: &MapFrame, at: usize, side_px: f64, fits: &dyn Fn(usize) -> bool) -> usize {
    if !(side_px.is_finite() && side_px >= 1.0) {
        return 0;
    }
    let (c0, r0) = frame.col_row(at);
    // Whether `fits` holds at the pixel of lattice point `(u, v)` (in tile sides from `at`).
    let ok = |u: f64, v: f64| {
        let x = c0 as f64 + 0.5 + u * side_px;
        let y = r0 as f64 + 0.5 + v * side_px;
        frame
            .checked(x.floor() as i64, y.floor() as i64)
            .is_some_and(|(c, r)| fits(frame.index(c, r)))
    };
    // Lattice indices whose centres lie on the map, and a flag per tile.
    let span = |v0: usize, n: usize| {
        let lo = -((v0 as f64 + 0.5) / side_px).floor() as i64;
        let hi = ((n as f64 - v0 as f64 - 0.5) / side_px).floor() as i64;
        (lo, hi)
    };
    let ((i0, i1), (j0, j1)) = (span(c0, frame.width), span(r0, frame.height));
    let ni = (i1 - i0 + 1) as usize;
    let nj = (j1 - j0 + 1) as usize;
    let mut seen = vec![false; ni.saturating_mul(nj)];
    let slot = |i: i64, j: i64| {
        (i >= i0 && i <= i1 && j >= j0 && j <= j1)
            .then(|| (j - j0) as usize * ni + (i - i0) as usize)
    };
    let mut queue = std::collections::VecDeque::new();
    let Some(first) = slot(0, 0) else { return 0 };
    seen[first] = true;
    queue.push_back((0i64, 0i64));
    let mut count = 1;
    while let Some((i, j)) = queue.pop_front() {
        if count >= TILES_COUNTED {
            break;
        }
        for (di, dj) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
            let (a, b) = (i + di, j + dj);
            let Some(k) = slot(a, b) else { continue };
            let (mid_u, mid_v) = (i as f64 + 0.5 * di as f64, j as f64 + 0.5 * dj as f64);
            if !seen[k] && ok(a as f64, b as f64) && ok(mid_u, mid_v) {
                seen[k] = true;
                count += 1;
                queue.push_back((a, b));
            }
        }
    }
    count
}

/// 8-connected parts of the pixels of a `w` x `h` grid where `inside` holds: each pixel's part
/// (`u32::MAX` outside) and each part's pixel count, parts numbered in scan order (each filled
/// by [`crate::search::fill_runs`]).
fn parts_of(w: usize, h: usize, inside: &dyn Fn(usize) -> bool) -> (Vec<u32>, Vec<usize>) {
    use crate::search::{fill_runs, Connectivity};
    let mut part = vec![u32::MAX; w * h];
    let mut sizes = Vec::new();
    let mut seen = FixedBitSet::with_capacity(w * h);
    for i0 in 0..w * h {
        if seen.contains(i0) || !inside(i0) {
            continue;
        }
        let k = sizes.len() as u32;
        let mut n = 0;
        fill_runs(
            w,
            h,
            inside,
            i0,
            Connectivity::Eight,
            &mut seen,
            |row, lo, hi| {
                part[row * w + lo..=row * w + hi].fill(k);
                n += hi - lo + 1;
            },
        );
        sizes.push(n);
    }
    (part, sizes)
}

/// The checks of a start that do not depend on the robot: finite, and on the map.
fn start_on_map(frame: &MapFrame, s: Pose) -> Result<(), WorldError> {
    if !(s.x.is_finite() && s.y.is_finite() && s.theta.is_finite()) {
        return Err(WorldError::BadStart(s.x, s.y, s.theta));
    }
    if frame.pixel_of(s.position()).is_none() {
        let (lo, hi) = frame.world_bounds();
        return Err(WorldError::StartOutside {
            x: s.x,
            y: s.y,
            x0: lo.x,
            x1: hi.x,
            y0: lo.y,
            y1: hi.y,
            yaw: frame.origin.theta,
        });
    }
    Ok(())
}

/// How [`WorldError::StartOutside`] shows a map turned off the axes: the bounds it prints are
/// the turned rectangle's box, which a start may lie inside while off the map (a start
/// within both printed ranges was said to be outside them, with no word of the turn).
fn turned_text(yaw: f64) -> String {
    if crate::grid::off_the_axes(yaw) {
        format!(
            "a rectangle turned by {} rad, within ",
            Compact((yaw * 1e4).round() / 1e4)
        )
    } else {
        String::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn room(w: usize, h: usize, res: f64) -> GridMap {
        let mut s = String::new();
        for r in 0..h {
            for c in 0..w {
                s.push(if r == 0 || c == 0 || r == h - 1 || c == w - 1 {
                    '#'
                } else {
                    '.'
                });
            }
            s.push('\n');
        }
        GridMap::from_ascii_scaled(&s, 1, res).unwrap()
    }

    /// A world whose frame lies beyond the precision bounds is refused, naming the setting
    /// (the same room at origin 1e15 m with a yaw of 0.5 rad let ba-star stall at 10 % of the
    /// floor), and so is a heading beyond two turns; within the bounds the room is a world.
    #[test]
    fn frames_and_headings_beyond_the_precision_bounds_are_refused() {
        let placed = |res: f64, origin: Pose| {
            let m = room(12, 10, res);
            let mut frame = *m.frame();
            frame.origin = origin;
            GridMap::new(frame, m.cells().to_vec()).unwrap()
        };
        let robot = Robot::new(1.0);
        let ok =
            |res: f64, origin: Pose| World::new(placed(res, origin), Robot::new(res * 2.0), None);
        assert!(ok(1.0, Pose::new(1e7, -1e7, 0.5)).is_ok());
        assert!(ok(1e-5, Pose::new(0.0, 0.0, 0.0)).is_ok());
        let far = World::new(placed(1.0, Pose::new(1e15, 0.0, 0.5)), robot, None);
        match far {
            Err(WorldError::Imprecise(p)) => {
                assert_eq!(p.setting(), "origin");
                assert!(p.to_string().contains("farther than the 1e8 m"), "{p}");
            }
            other => panic!("{:?}", other.map(|_| ())),
        }
        let fine = World::new(
            placed(1e-6, Pose::new(0.0, 0.0, 0.0)),
            Robot::new(2e-6),
            None,
        );
        match fine {
            Err(WorldError::Imprecise(p)) => assert_eq!(p.setting(), "resolution"),
            other => panic!("{:?}", other.map(|_| ())),
        }
        let big = World::new(placed(2e5, Pose::new(0.0, 0.0, 0.0)), Robot::new(4e5), None);
        assert!(
            matches!(
                big,
                Err(WorldError::Imprecise(
                    crate::grid::FrameProblem::TooLarge { .. }
                ))
            ),
            "{:?}",
            big.map(|_| ())
        );
        // (a pose's fields are public: `Pose::new` wraps, a literal does not)
        let turned = Pose {
            x: 6.0,
            y: 5.0,
            theta: 90.0,
        };
        let e = World::new(placed(1.0, Pose::new(0.0, 0.0, 0.0)), robot, Some(turned));
        match e {
            Err(e @ WorldError::BadHeading { .. }) => {
                assert!(
                    e.to_string()
                        .starts_with("start heading 90 rad is more than two turns"),
                    "{e}"
                );
            }
            other => panic!("{:?}", other.map(|_| ())),
        }
        let yawed = Pose {
            x: 0.0,
            y: 0.0,
            theta: -20.0,
        };
        let e = World::new(placed(1.0, yawed), robot, None);
        assert!(
            matches!(
                e,
                Err(WorldError::BadHeading {
                    what: "map origin yaw",
                    ..
                })
            ),
            "{:?}",
            e.map(|_| ())
        );
        // A non-finite start is still refused as such.
        let nan = Pose {
            x: 6.0,
            y: 5.0,
            theta: f64::NAN,
        };
        let e = World::new(placed(1.0, Pose::new(0.0, 0.0, 0.0)), robot, Some(nan));
        assert!(
            matches!(e, Err(WorldError::BadStart(..))),
            "{:?}",
            e.map(|_| ())
        );
    }

    /// Whenever the free-box test clears a short motion, the exact tests find no contact:
    /// random clutter, motions between pixel centres and anywhere, several radii.
    #[test]
    fn free_box_agrees_with_the_exact_contact_tests() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let (w, h) = (40usize, 30usize);
        let mut art = String::new();
        for _ in 0..h {
            for _ in 0..w {
                art.push(if next() < 0.12 { '#' } else { '.' });
            }
            art.push('\n');
        }
        let map: GridMap = art.trim_end().parse().expect("map");
        let cells = map.cells();
        let blocked = bitset_where(map.frame().len(), |i| !cells[i].is_free());
        let truth = Truth {
            map: &map,
            blocked: &blocked,
        };
        let frame = *map.frame();
        let mut cleared = 0;
        for k in 0..40_000 {
            let centred = k % 2 == 0;
            let mut p = || {
                let (x, y) = (next() * w as f64, next() * h as f64);
                if centred {
                    Point::new(x.floor() + 0.5, y.floor() + 0.5)
                } else {
                    Point::new(x, y)
                }
            };
            let a = p();
            let b = match k % 3 {
                0 => a,
                1 => Point::new(a.x + (next() * 4.0 - 2.0).round(), a.y),
                _ => Point::new(a.x + next() * 3.0 - 1.5, a.y + next() * 3.0 - 1.5),
            };
            let r_px = [0.5, 1.0, 1.5, next() * 2.0][k % 4];
            if box_clear(&frame, a, b, contact_radius_px(r_px), &blocked) {
                cleared += 1;
                assert_eq!(collide::segment_first_contact(&truth, a, b, r_px), None);
                assert!(!collide::disk_hits(&map, a, r_px) && !collide::disk_hits(&map, b, r_px));
            }
        }
        assert!(cleared > 2000, "{cleared}");
    }

    /// Whenever the capsule test clears a long motion, the exact test finds no contact, and
    /// the contact search that uses it gives what one exact test of the whole motion gives:
    /// sparse clutter and corridors, motions along walls at and near clearance (where the
    /// capsule test sees a pixel just beyond reach), across the map and out of it.
    #[test]
    fn capsule_test_agrees_with_the_exact_contact_test() {
        let mut rng = crate::rng::SplitMix64::new(0x2545_f491_4f6c_dd1d);
        let mut next = move || rng.range(0.0, 1.0);
        let (w, h) = (300usize, 40usize);
        let mut art = String::new();
        for r in 0..h {
            for c in 0..w {
                let wall = r == 0 || r == h - 1 || r == 12 || c == 0 || c == w - 1;
                // Specks below the wall's corridor only (rows 13-38 from the top).
                art.push(if wall || (r > 20 && next() < 0.004) {
                    '#'
                } else {
                    '.'
                });
            }
            art.push('\n');
        }
        let map = GridMap::from_ascii_scaled(art.trim_end(), 1, 0.05).unwrap();
        let cells = map.cells();
        let blocked = bitset_where(map.frame().len(), |i| !cells[i].is_free());
        let truth = Truth {
            map: &map,
            blocked: &blocked,
        };
        let frame = *map.frame();
        let world = World::new(map.clone(), Robot::new(0.15), None).unwrap();
        let rc = contact_radius_px(world.r_px());
        let (mut cleared, mut hit, mut grazing) = (0, 0, 0);
        for k in 0..6_000 {
            // Row 12 (from the top) is a wall: its pixel centres lie at gy = 27.5; the corridor
            // below it (rows 13-20) is clear.
            let (a, b) = match k % 3 {
                // Along the wall, at the contact radius from its centres or a little off
                // (1e-7 and 5e-7 beyond it: free, but within the capsule test's margin).
                0 => {
                    let off = [0.0, 1e-7, 5e-7, 1e-3, -1e-3, 0.3][k / 3 % 6];
                    let y = 27.5 - rc - off;
                    let x0 = 5.0 + next() * 100.0;
                    (Point::new(x0, y), Point::new(x0 + next() * 185.0, y))
                }
                // Long motions anywhere in the image.
                1 => (
                    Point::new(next() * w as f64, next() * h as f64),
                    Point::new(next() * w as f64, next() * h as f64),
                ),
                // Out of the image.
                _ => (
                    Point::new(next() * w as f64, 20.0),
                    Point::new(next() * w as f64 * 1.2 - 20.0, -5.0 + next() * 10.0),
                ),
            };
            if capsule_clear(&frame, a, b, rc, &blocked) {
                cleared += 1;
                assert_eq!(
                    collide::segment_first_contact(&truth, a, b, world.r_px()),
                    None
                );
            }
            if collide::segment_first_contact(&truth, a, a, world.r_px()).is_some() {
                continue;
            }
            let exact = collide::segment_first_contact(&truth, a, b, world.r_px());
            let got = world.first_contact_grid(a, b);
            match (exact, got) {
                (None, None) => {
                    if k % 3 == 0 && !capsule_clear(&frame, a, b, rc, &blocked) {
                        grazing += 1;
                    }
                }
                (Some(x), Some(y)) => {
                    hit += 1;
                    assert!((x - y).abs() * a.dist(b) < 1e-6, "{a:?} {b:?}: {x} vs {y}");
                }
                _ => panic!("{a:?} -> {b:?}: exact {exact:?}, search {got:?}"),
            }
        }
        assert!(
            cleared > 500 && hit > 500 && grazing > 100,
            "{cleared} {hit} {grazing}"
        );
    }

    #[test]
    fn default_start_is_the_middle_and_errors_are_clear() {
        let w = World::new(room(11, 11, 0.1), Robot::new(0.2), None).unwrap();
        assert!((w.start().x - 0.55).abs() < 1e-9 && (w.start().y - 0.55).abs() < 1e-9);
        let e = World::new(room(5, 5, 0.1), Robot::new(0.2), None).unwrap_err();
        assert!(matches!(e, WorldError::RobotTooBig { .. }), "{e}");
        assert!(
            e.to_string().contains("widest free spot has clearance"),
            "{e}"
        );
        // A map with no free pixel says so (its thresholds or negate are the likely cause).
        for fill in [Cell::Occupied, Cell::Unknown] {
            let none = GridMap::filled(MapFrame::new(8, 8, 0.1), fill).unwrap();
            let e = World::new(none, Robot::new(0.1), None).unwrap_err();
            assert!(e.to_string().contains("the map has no free pixel"), "{e}");
        }
        let e = World::new(
            room(11, 11, 0.1),
            Robot::new(0.1),
            Some(Pose::new(0.12, 0.5, 0.0)),
        );
        assert!(matches!(e, Err(WorldError::StartInObstacle { .. })));
        let e = World::new(
            room(11, 11, 0.1),
            Robot::new(0.1),
            Some(Pose::new(5.0, 0.5, 0.0)),
        );
        assert!(matches!(e, Err(WorldError::StartOutside { .. })));
        let text = e.err().unwrap().to_string();
        assert!(text.contains("outside the map (x in ["), "{text}");
        // A map turned off the axes is a turned rectangle within the printed bounds: a start
        // inside both ranges but off the map was said to be outside them.
        let turned = room(11, 11, 0.1)
            .with_placement(0.1, Pose::new(0.0, 0.0, std::f64::consts::FRAC_PI_4))
            .unwrap();
        let e = World::new(turned, Robot::new(0.1), Some(Pose::new(0.7, 0.1, 0.0)));
        let text = e.err().unwrap().to_string();
        assert!(
            text.contains(
                "outside the map (a rectangle turned by 0.7854 rad, within x in [-0.778, 0.778]"
            ),
            "{text}"
        );
        // Off the map whatever the robot's size: a robot that fits nowhere does not hide it.
        let e = World::new(
            room(11, 11, 0.1),
            Robot::new(2.0),
            Some(Pose::new(5.0, 0.5, 0.0)),
        );
        assert!(matches!(e, Err(WorldError::StartOutside { .. })), "{e:?}");
        let e = World::new(
            room(11, 11, 0.1),
            Robot::new(2.0),
            Some(Pose::new(0.5, 0.5, 0.0)),
        );
        assert!(matches!(e, Err(WorldError::RobotTooBig { .. })), "{e:?}");
        let e = World::new(room(11, 11, 0.1), Robot::new(f64::NAN), None);
        assert!(matches!(e, Err(WorldError::BadRadius(_))));
        let e = World::new(
            room(11, 11, 0.1),
            Robot {
                radius: 0.1,
                tool_radius: 0.2,
            },
            None,
        );
        assert!(matches!(e, Err(WorldError::BadToolRadius { .. })));
    }

    /// Two rooms joined by a door exactly one robot diameter wide (6 px at 0.05 m/px, r = 0.15
    /// m): the robot fits in the doorway only between pixel centres. A start there was taken,
    /// its reachable floor was empty and every run measured 0 % after sweeping both rooms; it
    /// is refused. A start in a room beside the door is taken.
    #[test]
    fn a_start_that_fits_only_between_pixel_centres_is_refused() {
        let (w, h) = (120usize, 70usize);
        let mut art = String::new();
        for r in 0..h {
            for c in 0..w {
                let wall = c == 0 || c == w - 1 || r == 0 || r == h - 1;
                let door = c == 60 && !(30..36).contains(&r);
                art.push(if wall || door { '#' } else { '.' });
            }
            art.push('\n');
        }
        let map = GridMap::from_ascii_scaled(&art, 1, 0.05).unwrap();
        let e = World::new(
            map.clone(),
            Robot::new(0.15),
            Some(Pose::new(3.025, 1.85, 0.0)),
        );
        assert!(
            matches!(e, Err(WorldError::StartBetweenCentres { .. })),
            "{:?}",
            e.map(|w| w.accessible_count())
        );
        let w = World::new(map, Robot::new(0.15), Some(Pose::new(1.525, 2.15, 0.0))).unwrap();
        assert!(w.accessible_count() > 0);
    }

    #[test]
    fn contact_along_segment_is_exact() {
        // 1 m/px, 20 px wide room: wall centres at gx = 0.5 and 19.5. r = 2: contact at x = 17.
        let w = World::new(
            room(20, 9, 1.0),
            Robot::new(2.0),
            Some(Pose::new(5.0, 4.5, 0.0)),
        )
        .unwrap();
        let t = w.first_contact(Point::new(5.0, 4.5), Point::new(25.0, 4.5));
        let t = t.expect("hits the wall");
        assert!((5.0 + 20.0 * t - 17.0).abs() < 1e-4, "{t}");
        assert!(w.segment_free(Point::new(5.0, 4.5), Point::new(16.9, 4.5)));
        // Accessible: interior free pixels all reachable by a tool of radius 2 (pixel centres
        // within 2 of a reachable C-free centre).
        assert!(w.accessible_count() > 0);
    }
}

#[cfg(test)]
mod proptests {
    use super::*;
    use proptest::prelude::*;

    fn arb_map() -> impl Strategy<Value = GridMap> {
        (
            8usize..30,
            8usize..30,
            proptest::collection::vec(0u8..100, 900),
        )
            .prop_map(|(w, h, v)| {
                let cells = (0..w * h)
                    .map(|i| {
                        if v[i % v.len()] < 12 {
                            Cell::Occupied
                        } else {
                            Cell::Free
                        }
                    })
                    .collect();
                GridMap::new(MapFrame::new(w, h, 0.1), cells).unwrap()
            })
    }

    /// The previous `default_start` (a label per pixel), as the reference.
    fn default_start_reference(frame: &MapFrame, cfree: &FixedBitSet, dt2: &[u32]) -> Pose {
        let (w, h) = (frame.width, frame.height);
        let mut label = vec![u32::MAX; frame.len()];
        let mut best_comp = (0usize, 0u32);
        let mut next = 0u32;
        let mut stack = Vec::new();
        for i in cfree.ones() {
            if label[i] != u32::MAX {
                continue;
            }
            let mut size = 0usize;
            label[i] = next;
            stack.push(i);
            while let Some(k) = stack.pop() {
                size += 1;
                let (c, r) = ((k % w) as i64, (k / w) as i64);
                for dr in -1i64..=1 {
                    for dc in -1i64..=1 {
                        let (nc, nr) = (c + dc, r + dr);
                        if nc < 0 || nr < 0 || nc >= w as i64 || nr >= h as i64 {
                            continue;
                        }
                        let j = nr as usize * w + nc as usize;
                        if cfree.contains(j) && label[j] == u32::MAX {
                            label[j] = next;
                            stack.push(j);
                        }
                    }
                }
            }
            if size > best_comp.0 {
                best_comp = (size, next);
            }
            next += 1;
        }
        let mut best = (0u32, usize::MAX);
        for i in cfree.ones() {
            if label[i] == best_comp.1 && (best.1 == usize::MAX || dt2[i] > best.0) {
                best = (dt2[i], i);
            }
        }
        let (c, r) = frame.col_row(best.1);
        let p = frame.pixel_center(c, r);
        Pose::new(p.x, p.y, 0.0)
    }

    /// The previous pixel-by-pixel 8-connected flood fill, as the reference.
    fn flood_reference(cfree: &FixedBitSet, w: usize, h: usize, seed: usize) -> FixedBitSet {
        let mut seen = FixedBitSet::with_capacity(w * h);
        seen.insert(seed);
        let mut stack = vec![seed];
        while let Some(i) = stack.pop() {
            let (c, r) = ((i % w) as i64, (i / w) as i64);
            for dr in -1i64..=1 {
                for dc in -1i64..=1 {
                    let (nc, nr) = (c + dc, r + dr);
                    if nc < 0 || nr < 0 || nc >= w as i64 || nr >= h as i64 {
                        continue;
                    }
                    let j = nr as usize * w + nc as usize;
                    if cfree.contains(j) && !seen.contains(j) {
                        seen.insert(j);
                        stack.push(j);
                    }
                }
            }
        }
        seen
    }

    /// The previous accessible surface (a distance transform from the reachable set).
    fn accessible_reference(map: &GridMap, reach: &FixedBitSet, rt: f64) -> FixedBitSet {
        let f = *map.frame();
        let dt = squared_edt(f.width, f.height, |i| reach.contains(i), false);
        let mut acc = FixedBitSet::with_capacity(f.len());
        for (i, &d2) in dt.iter().enumerate() {
            if map.cells()[i] == Cell::Free && d2 != INF && f64::from(d2) <= rt * rt {
                acc.insert(i);
            }
        }
        acc
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 128, rng_seed: proptest::test_runner::RngSeed::Fixed(0x5eed_0101), ..ProptestConfig::default() })]
        /// The scanline fills and the offset dilation give exactly the previous start,
        /// reachable set and accessible surface.
        #[test]
        fn world_sets_match_reference(
            map in arb_map(),
            r in 0.05f64..0.25,
            tool in 0.2f64..1.0,
            big_tool in 0.0f64..1.2,
        ) {
            let f = *map.frame();
            let robot = Robot { radius: r, tool_radius: r * tool };
            let Ok(world) = World::new(map.clone(), robot, None) else { return Err(TestCaseError::reject("the robot fits nowhere")) };
            let plain = squared_edt(f.width, f.height, |i| !map.cells()[i].is_free(), true);
            for (i, &d2) in plain.iter().enumerate() {
                prop_assert_eq!(world.obstacle_dt2.get(i), d2);
            }
            let start = default_start_reference(&f, world.cfree(), &plain);
            prop_assert_eq!(world.start(), start);
            let (c, row) = f.grid_to_pixel_signed(f.world_to_grid(start.position()));
            let seed = f.index(c as usize, row as usize);
            prop_assert_eq!(world.reachable(), &flood_reference(world.cfree(), f.width, f.height, seed));
            for rt in [r * tool / f.resolution + 1e-6, big_tool * 12.0, 7.999, 8.0, 9.5] {
                prop_assert_eq!(
                    accessible_pixels(&map, world.reachable(), rt),
                    accessible_reference(&map, world.reachable(), rt),
                    "rt {}", rt
                );
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 96, rng_seed: proptest::test_runner::RngSeed::Fixed(0x5eed_0102), ..ProptestConfig::default() })]
        /// `first_contact` agrees with dense sampling of the exact disk test.
        #[test]
        fn first_contact_matches_sampling(
            map in arb_map(),
            r in 0.05f64..0.25,
            a in (0.0f64..1.0, 0.0f64..1.0),
            b in (0.0f64..1.0, 0.0f64..1.0),
        ) {
            let f = *map.frame();
            let pa = Point::new(a.0 * f.width_m(), a.1 * f.height_m());
            let pb = Point::new(b.0 * f.width_m(), b.1 * f.height_m());
            let robot = Robot::new(r);
            // Any valid start will do; skip maps where the robot fits nowhere.
            let Ok(world) = World::new(map, robot, None) else { return Err(TestCaseError::reject("the robot fits nowhere")) };
            if world.disk_collides(pa) {
                return Err(TestCaseError::reject("the segment starts in contact"));
            }
            let n = 400;
            let first_hit = (0..=n).map(|k| f64::from(k) / f64::from(n)).find(|&t| {
                world.disk_collides(Point::new(pa.x + t * (pb.x - pa.x), pa.y + t * (pb.y - pa.y)))
            });
            match world.first_contact(pa, pb) {
                None => prop_assert!(first_hit.is_none(), "sampling hits at {first_hit:?}"),
                Some(t) => {
                    // Just before t the disk is free; sampling finds no hit much earlier.
                    let before = (t - 1e-6).max(0.0);
                    prop_assert!(!world.disk_collides(Point::new(pa.x + before * (pb.x - pa.x), pa.y + before * (pb.y - pa.y))));
                    if let Some(h) = first_hit {
                        prop_assert!(h + 1.0 / f64::from(n) >= t - 1e-9, "sampled hit {h} before contact {t}");
                    }
                }
            }
        }
    }
}

//! The ground truth: the map, the robot, C-free, the reachable component and the accessible
//! surface, plus exact collision checks. Only the simulator, the metrics and offline planners
//! look at a [`World`]; online planners never do.

use std::ops::{Add, Sub};
use fixedbitset::FixedBitSet;
use serde::{Deserialize, Serialize};

use crate::collide::{self, contact_radius_px};
use crate::dt::{squared_edt, INF};
use crate::geometry::{Point, Pose};
use crate::grid::{Cell, GridMap, MapFrame};

/// The robot model: a disk of radius `radius` carrying a cleaning tool of radius `tool_radius`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
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

/// Errors building a world.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum WorldError {
    /// Robot radius not a finite number > 0.
    #[error("robot radius must be a finite number > 0 m, got {0}")]
    BadRadius(f64),
    /// Tool radius invalid.
    #[error("tool radius must be a finite number in (0, radius = {radius}] m, got {tool}")]
    BadToolRadius {
        /// Tool radius given.
        tool: f64,
        /// Robot radius.
        radius: f64,
    },
    /// No centre position anywhere on the map keeps the robot clear of obstacles.
    #[error(
        "robot of radius {radius} m does not fit anywhere on the map: the widest free spot has \
         clearance {max_clearance:.3} m"
    )]
    RobotTooBig {
        /// Robot radius.
        radius: f64,
        /// Largest clearance on the map, metres.
        max_clearance: f64,
    },
    /// Start pose not finite.
    #[error("start pose must be finite, got ({0}, {1}, {2})")]
    BadStart(f64, f64, f64),
    /// Start outside the image.
    #[error("start ({x:.3}, {y:.3}) is outside the map (x in [{x0:.3}, {x1:.3}], y in [{y0:.3}, {y1:.3}])")]
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
    },
    /// The robot's disk at the start overlaps an obstacle or unknown space.
    #[error(
        "start ({x:.3}, {y:.3}) is in an obstacle: a robot of radius {radius} m there overlaps \
         occupied or unknown pixels"
    )]
    StartInObstacle {
        /// Start x.
        x: f64,
        /// Start y.
        y: f64,
        /// Robot radius.
        radius: f64,
    },
}

/// The ground truth for one robot on one map.
#[derive(Clone)]
pub struct World {
    map: GridMap,
    robot: Robot,
    start: Pose,
    /// Squared distance (px^2) from each pixel centre to the nearest non-free pixel centre,
    /// counting the outside as non-free.
    obstacle_dt2: Vec<u32>,
    cfree: FixedBitSet,
    reachable: FixedBitSet,
    accessible: FixedBitSet,
    accessible_count: usize,
}

impl std::fmt::Debug for World {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("World")
            .field("frame", self.map.frame())
            .field("robot", &self.robot)
            .field("start", &self.start)
            .field("accessible_px", &self.accessible_count)
            .finish_non_exhaustive()
    }
}

impl World {
    /// Prepares the truth for `robot` on `map`, starting at `start` (or, when `None`, at the
    /// default start: the C-free pixel centre with the largest clearance in the largest C-free
    /// component, ties by row-major order, heading east).
    ///
    /// # Errors
    /// Invalid radii, a robot that fits nowhere, a start outside the map or in an obstacle.
    pub fn new(map: GridMap, robot: Robot, start: Option<Pose>) -> Result<Self, WorldError> {
        robot.validate()?;
        let frame = *map.frame();
        let cells = map.cells();
        let obstacle_dt2 = squared_edt(frame.width, frame.height, |i| !cells[i].is_free(), true);
        let r_px = robot.radius / frame.resolution;
        // C-free at a pixel centre: distance to every blocked centre >= contact radius.
        let rc = contact_radius_px(r_px);
        let rc2 = rc * rc;
        let mut cfree = FixedBitSet::with_capacity(frame.len());
        let mut max_d2 = 0u32;
        for (i, &d2) in obstacle_dt2.iter().enumerate() {
            if f64::from(d2) >= rc2 {
                cfree.insert(i);
            }
            if d2 != INF {
                max_d2 = max_d2.max(d2);
            }
        }
        if cfree.is_clear() {
            return Err(WorldError::RobotTooBig {
                radius: robot.radius,
                max_clearance: ((f64::from(max_d2)).sqrt() - 0.5).max(0.0) * frame.resolution,
            });
        }
        let start = match start {
            Some(s) => s,
            None => default_start(&frame, &cfree, &obstacle_dt2),
        };
        let mut world = Self {
            map,
            robot,
            start,
            obstacle_dt2,
            cfree,
            reachable: FixedBitSet::with_capacity(frame.len()),
            accessible: FixedBitSet::with_capacity(frame.len()),
            accessible_count: 0,
        };
        world.check_start()?;
        world.reachable = world.flood_reachable();
        world.compute_accessible();
        Ok(world)
    }

    fn check_start(&self) -> Result<(), WorldError> {
        let s = self.start;
        if !(s.x.is_finite() && s.y.is_finite() && s.theta.is_finite()) {
            return Err(WorldError::BadStart(s.x, s.y, s.theta));
        }
        let frame = self.map.frame();
        if frame.pixel_of(s.position()).is_none() {
            let corners = [
                frame.grid_to_world(Point::new(0.0, 0.0)),
                frame.grid_to_world(Point::new(frame.width as f64, 0.0)),
                frame.grid_to_world(Point::new(0.0, frame.height as f64)),
                frame.grid_to_world(Point::new(frame.width as f64, frame.height as f64)),
            ];
            let fold = |f: fn(f64, f64) -> f64, sel: fn(&Point) -> f64, init: f64| {
                corners.iter().map(sel).fold(init, f)
            };
            return Err(WorldError::StartOutside {
                x: s.x,
                y: s.y,
                x0: fold(f64::min, |p| p.x, f64::INFINITY),
                x1: fold(f64::max, |p| p.x, f64::NEG_INFINITY),
                y0: fold(f64::min, |p| p.y, f64::INFINITY),
                y1: fold(f64::max, |p| p.y, f64::NEG_INFINITY),
            });
        }
        if self.disk_collides(s.position()) {
            return Err(WorldError::StartInObstacle {
                x: s.x,
                y: s.y,
                radius: self.robot.radius,
            });
        }
        Ok(())
    }

    /// 8-connected flood fill of C-free pixel centres from the start's pixel (or, if that centre
    /// is not C-free, from a C-free neighbour whose centre is within one pixel of the start).
    fn flood_reachable(&self) -> FixedBitSet {
        let frame = *self.map.frame();
        let mut seen = FixedBitSet::with_capacity(frame.len());
        let g = frame.world_to_grid(self.start.position());
        let (sc, sr) = frame.grid_to_pixel_signed(g);
        let mut seeds = Vec::new();
        for (dc, dr) in [
            (0, 0),
            (1, 0),
            (-1, 0),
            (0, 1),
            (0, -1),
            (1, 1),
            (-1, 1),
            (1, -1),
            (-1, -1),
        ] {
            if let Some((c, r)) = frame.checked(sc + dc, sr + dr) {
                let i = frame.index(c, r);
                if self.cfree.contains(i) {
                    seeds.push(i);
                    if (dc, dr) == (0, 0) {
                        break;
                    }
                }
            }
        }
        let mut stack: Vec<usize> = Vec::new();
        if let Some(&s) = seeds.first() {
            seen.insert(s);
            stack.push(s);
        }
        let (w, h) = (frame.width, frame.height);
        while let Some(i) = stack.pop() {
            let (c, r) = (i % w, i / w);
            for dr in -1i64..=1 {
                for dc in -1i64..=1 {
                    if dc == 0 && dr == 0 {
                        continue;
                    }
                    let (nc, nr) = (c as i64 + dc, r as i64 + dr);
                    if nc < 0 || nr < 0 || nc >= w as i64 || nr >= h as i64 {
                        continue;
                    }
                    let j = nr as usize * w + nc as usize;
                    if self.cfree.contains(j) && !seen.contains(j) {
                        seen.insert(j);
                        stack.push(j);
                    }
                }
            }
        }
        seen
    }

    fn compute_accessible(&mut self) {
        let frame = *self.map.frame();
        let reach = &self.reachable;
        let dt = squared_edt(frame.width, frame.height, |i| reach.contains(i), false);
        let rt = self.robot.tool_radius / frame.resolution + 1e-6;
        let rt2 = rt * rt;
        let cells = self.map.cells();
        let mut acc = FixedBitSet::with_capacity(frame.len());
        for (i, &d2) in dt.iter().enumerate() {
            if cells[i] == Cell::Free && d2 != INF && f64::from(d2) <= rt2 {
                acc.insert(i);
            }
        }
        self.accessible_count = acc.count_ones(..);
        self.accessible = acc;
    }

    /// The true map.
    pub fn map(&self) -> &GridMap {
        &self.map
    }

    /// The map's geometry.
    pub fn frame(&self) -> &MapFrame {
        self.map.frame()
    }

    /// The robot.
    pub fn robot(&self) -> Robot {
        self.robot
    }

    /// The start pose.
    pub fn start(&self) -> Pose {
        self.start
    }

    /// C-free pixel centres (whole map).
    pub fn cfree(&self) -> &FixedBitSet {
        &self.cfree
    }

    /// C-free pixel centres of the start's 8-connected component.
    pub fn reachable(&self) -> &FixedBitSet {
        &self.reachable
    }

    /// The accessible surface `A`: free pixels whose centre lies within `r_tool` of a reachable
    /// C-free centre.
    pub fn accessible(&self) -> &FixedBitSet {
        &self.accessible
    }

    /// Number of pixels in `A`.
    pub fn accessible_count(&self) -> usize {
        self.accessible_count
    }

    /// Area of `A` in square metres.
    pub fn accessible_area_m2(&self) -> f64 {
        let r = self.frame().resolution;
        self.accessible_count as f64 * r * r
    }

    /// Clearance in metres at the centre of pixel `(col, row)`: distance to the nearest blocked
    /// pixel's inscribed disk.
    pub fn pixel_clearance(&self, col: usize, row: usize) -> f64 {
        let d2 = self.obstacle_dt2[self.frame().index(col, row)];
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
                let d2 = self.obstacle_dt2[frame.index(c, r)];
                (f64::from(d2).sqrt() - std::f64::consts::FRAC_1_SQRT_2).max(0.0)
            }
            None => 0.0,
        }
    }

    /// Does the robot's disk centred at world point `p` overlap a non-free pixel (exact)?
    pub fn disk_collides(&self, p: Point) -> bool {
        let g = self.frame().world_to_grid(p);
        let r_px = self.r_px();
        if self.dist_lower_bound_px(g) > contact_radius_px(r_px) + 1e-9 {
            return false;
        }
        collide::disk_hits(&self.map, g, r_px)
    }

    /// Exact first contact of the robot's disk moving straight from `a` to `b` (world frame):
    /// the parameter `t` in `[0, 1]` of the first overlap with a non-free pixel, or `None`.
    /// Sphere-traces the distance transform through open space and checks pixels exactly near
    /// obstacles, so long moves across open halls stay cheap.
    pub fn first_contact(&self, a: Point, b: Point) -> Option<f64> {
        let frame = self.frame();
        let ga = frame.world_to_grid(a);
        let gb = frame.world_to_grid(b);
        let len = ga.dist(gb);
        let r_px = self.r_px();
        let rc = contact_radius_px(r_px);
        if len == 0.0 {
            return if collide::disk_hits(&self.map, ga, r_px) {
                Some(0.0)
            } else {
                None
            };
        }
        let u = gb.sub(ga).scale(1.0 / len);
        let mut s = 0.0;
        while s < len {
            let p = ga.add(u.scale(s));
            let margin = self.dist_lower_bound_px(p) - rc;
            if margin > 0.5 {
                s += margin;
                continue;
            }
            let e = (s + 1.0).min(len);
            let q = ga.add(u.scale(e));
            if let Some(t) = collide::segment_first_contact(&self.map, p, q, r_px) {
                return Some(((s + t * (e - s)) / len).clamp(0.0, 1.0));
            }
            s = e;
        }
        None
    }

    /// Is the straight motion of the robot from `a` to `b` free of contact?
    pub fn segment_free(&self, a: Point, b: Point) -> bool {
        self.first_contact(a, b).is_none()
    }
}

/// The default start: the C-free pixel centre with the largest clearance in the largest C-free
/// 8-connected component; ties by row-major order; heading east.
fn default_start(frame: &MapFrame, cfree: &FixedBitSet, dt2: &[u32]) -> Pose {
    let (w, h) = (frame.width, frame.height);
    let mut label = vec![u32::MAX; frame.len()];
    let mut best_comp = (0usize, 0u32); // (size, label)
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

    #[test]
    fn default_start_is_the_middle_and_errors_are_clear() {
        let w = World::new(room(11, 11, 0.1), Robot::new(0.2), None).unwrap();
        assert!((w.start().x - 0.55).abs() < 1e-9 && (w.start().y - 0.55).abs() < 1e-9);
        let e = World::new(room(5, 5, 0.1), Robot::new(0.2), None).unwrap_err();
        assert!(matches!(e, WorldError::RobotTooBig { .. }), "{e}");
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

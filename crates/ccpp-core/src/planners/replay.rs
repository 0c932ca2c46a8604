//! The replay of an offline plan, with a bumper reaction.
//!
//! The offline planners (`bcd`, `rect-boustrophedon`) plan the whole path on the known map
//! and then hand out its steps one by one. Under ideal execution (and under PID execution
//! without odometry noise) no step meets an obstacle, and the replay is the plan. Under
//! odometry noise the pose estimate drifts from the truth: a motion may end on a bumper
//! contact, and the next `MoveTo`, a straight line from where the robot stopped, often points
//! into the same obstacle. A plain replay then bumped at one spot for every remaining
//! waypoint (rect-boustrophedon on `nav2_depot` at noise 0.005: 1071 contacts, 708 at one
//! point, stalled at 14 % swept: hostile pass).
//!
//! On a contact the replay does what a robot with a costmap does:
//!
//! 1. **Marks the obstacle** where the bumper met it, in its own copy of the known map: the
//!    pixels across the robot's front (as wide as the robot), just beyond its contact distance
//!    along its heading, in the frame of its pose estimate (that is where the obstacle is for
//!    everything it plans from then on).
//! 2. **Routes to its next waypoint around it**: A\* over the pixel centres where the robot's
//!    disk touches nothing of that map (8 neighbours, integer costs 10 and 14, the octile
//!    heuristic, [`DeeperFirst`] ties), shortened to the farthest waypoint each straight move
//!    reaches without contact. The route's moves go before the waypoint's.
//! 3. **Gives a waypoint up** after [`MAX_TRIES`] contacts on the way to it (its detours
//!    included), or when no route reaches it within [`MAX_EXPANSIONS`] pixels, and goes on
//!    with the next one (at most [`MAX_TARGETS`] given up per contact).
//!
//! Every contact counts towards giving up one of the plan's finitely many waypoints, so a
//! replay makes at most [`MAX_TRIES`] contacts per waypoint and ends. The marks and routes live in the estimate's frame, which drifts: landmarks
//! (`--landmarks`) keep it near the truth.
//!
//! ```text
//! plan:  A ---------> B          the move A -> B bumps at x (the true wall lies nearer
//!              x|                than the map says: drift); the replay marks | across the
//!               |                robot's front and drives round it to B:
//!        A ----x  .              A --> x, up, over, down to B (or gives B up after 3
//!               \_____> B        contacts on the way and goes on to the waypoint after it)
//! ```

use std::collections::VecDeque;

use fixedbitset::FixedBitSet;

use crate::collide::{contact_radius_px, disk_hits, segment_first_contact};
use crate::geometry::{Point, Pose};
use crate::grid::MapFrame;
use crate::planner::{Sensor, Step};
use crate::search::{DeeperFirst, SearchSpace};
use crate::world::World;
use crate::zones::MaskOccupancy;

/// Contacts on the way to one waypoint before it is given up.
pub const MAX_TRIES: u32 = 3;

/// Waypoints given up at most per contact (each costs one search).
pub const MAX_TARGETS: usize = 8;

/// Pixels a route search settles at most before its waypoint counts as out of reach.
pub const MAX_EXPANSIONS: usize = 250_000;

/// Orthogonal and diagonal step costs of the route search.
const ORTHO: u32 = 10;
const DIAG: u32 = 14;

/// A precomputed list of steps replayed with the bumper reaction of the module docs.
#[derive(Debug)]
pub struct Replay {
    steps: VecDeque<Step>,
    frame: MapFrame,
    /// The known map's non-free pixels (zones included: virtual walls), plus the marks.
    blocked: FixedBitSet,
    r_px: f64,
    /// The way round marked obstacles to the next waypoint of the plan, driven first.
    detour: VecDeque<Point>,
    /// The plan's waypoint the motion under way leads to (directly or by the detour).
    heading_for: Option<Point>,
    /// The plan's waypoint the last contacts were on the way to, and how many there were.
    target: Option<Point>,
    tries: u32,
    /// Route search state (made at the first contact).
    space: Option<SearchSpace<u32, DeeperFirst>>,
}

impl Replay {
    /// The replay of `steps`, planned on `world`'s known map (with its zones).
    pub fn new(world: &World, steps: VecDeque<Step>) -> Self {
        let frame = *world.frame();
        Self {
            steps,
            frame,
            blocked: world.plan_blocked().clone(),
            r_px: world.robot().radius / frame.resolution,
            detour: VecDeque::new(),
            heading_for: None,
            target: None,
            tries: 0,
            space: None,
        }
    }

    /// The steps left.
    pub fn steps(&self) -> &VecDeque<Step> {
        &self.steps
    }

    /// The next step: after a motion the bumper stopped, the reaction of the module docs
    /// first.
    pub fn next(&mut self, sensor: &dyn Sensor) -> Step {
        if sensor.bumped() {
            self.react(sensor.pose());
        }
        if let Some(p) = self.detour.pop_front() {
            return Step::MoveTo(p);
        }
        let step = self.steps.pop_front().unwrap_or(Step::Done);
        if let Step::MoveTo(p) = step {
            self.heading_for = Some(p);
        }
        step
    }

    /// The index in `steps` of the next `MoveTo` and its point.
    fn next_target(&self) -> Option<(usize, Point)> {
        self.steps.iter().enumerate().find_map(|(i, s)| match s {
            Step::MoveTo(p) => Some((i, *p)),
            _ => None,
        })
    }

    fn react(&mut self, pose: Pose) {
        // Contacts count towards the plan's waypoint, whatever detour led there.
        self.detour.clear();
        let at = self.frame.world_to_grid(pose.position());
        self.mark_front(at, pose.theta - self.frame.origin.theta);
        // The waypoint the stopped motion was on its way to (handed out already) first.
        let mut again = self.heading_for.take();
        for _ in 0..MAX_TARGETS {
            // (`in_list`: the waypoint's index in `steps`; `None` for one handed out already)
            let (w, in_list) = match again.take() {
                Some(w) => (w, None),
                None => match self.next_target() {
                    Some((i, w)) => (w, Some(i)),
                    None => return,
                },
            };
            if self.target == Some(w) {
                self.tries += 1;
            } else {
                self.target = Some(w);
                self.tries = 1;
            }
            let route = if self.tries > MAX_TRIES {
                Route::Unreachable
            } else {
                self.route(at, self.frame.world_to_grid(w))
            };
            match route {
                Route::Found(pts) => {
                    let f = self.frame;
                    self.detour
                        .extend(pts.into_iter().map(|g| f.grid_to_world(g)));
                    // (a waypoint handed out already is driven to again at the detour's end;
                    // one still in the list comes after the events before it)
                    if in_list.is_none() {
                        self.detour.push_back(w);
                    }
                    self.heading_for = Some(w);
                    return;
                }
                // The estimate lies where the map has no room for the robot: no route from
                // there; the waypoint is tried straight (and given up after more contacts).
                Route::NoStart => {
                    if in_list.is_none() {
                        self.detour.push_back(w);
                    }
                    self.heading_for = Some(w);
                    return;
                }
                Route::Unreachable => {
                    if let Some(i) = in_list {
                        self.steps.remove(i);
                    }
                    self.target = None;
                    self.tries = 0;
                }
            }
        }
    }

    /// Marks the pixels across the front of a robot at grid point `at` heading `theta` (grid
    /// frame): a row as wide as the robot, centred on its heading, just beyond its contact
    /// distance (far enough that the robot's own disk stays clear of them).
    fn mark_front(&mut self, at: Point, theta: f64) {
        let (s, c) = theta.sin_cos();
        let ahead = contact_radius_px(self.r_px) + 0.75;
        let centre = Point::new(at.x + ahead * c, at.y + ahead * s);
        let half = self.r_px.max(0.5);
        let n = (2.0 * half).ceil() as i64 * 2;
        for k in 0..=n {
            let t = -half + 2.0 * half * k as f64 / n as f64;
            let q = Point::new(centre.x - t * s, centre.y + t * c);
            if let Some((col, row)) = self.frame_checked(q) {
                self.blocked.insert(self.frame.index(col, row));
            }
        }
    }

    fn frame_checked(&self, g: Point) -> Option<(usize, usize)> {
        let (c, r) = self.frame.grid_to_pixel_signed(g);
        self.frame.checked(c, r)
    }

    /// Whether the robot's disk at grid point `g` is clear of the marked map.
    fn clear_at(&self, g: Point) -> bool {
        !disk_hits(&self.occupancy(), g, self.r_px)
    }

    /// Whether the straight move `a -> b` (grid) is clear of the marked map.
    fn free(&self, a: Point, b: Point) -> bool {
        segment_first_contact(&self.occupancy(), a, b, self.r_px).is_none()
    }

    fn occupancy(&self) -> MaskOccupancy<'_> {
        MaskOccupancy::new(&self.frame, &self.blocked, false)
    }

    /// A route (grid points, the waypoint `to` last) from grid point `from` to `to` on the
    /// marked map.
    fn route(&mut self, from: Point, to: Point) -> Route {
        let f = self.frame;
        let (w, h) = (f.width as i64, f.height as i64);
        // The pixel centres near a point joined to it by a clear straight move.
        let anchors = |me: &Self, p: Point| -> Vec<u32> {
            let (c0, r0) = f.grid_to_pixel_signed(p);
            let mut out = Vec::new();
            for dr in -1..=1 {
                for dc in -1..=1 {
                    let Some((c, r)) = f.checked(c0 + dc, r0 + dr) else {
                        continue;
                    };
                    let q = f.pixel_center_grid(c, r);
                    if me.clear_at(q) && me.free(p, q) {
                        out.push(f.index(c, r) as u32);
                    }
                }
            }
            out
        };
        let starts = anchors(self, from);
        if starts.is_empty() {
            return Route::NoStart;
        }
        let goals = anchors(self, to);
        if goals.is_empty() {
            return Route::Unreachable;
        }
        let centre = |v: u32| {
            let (c, r) = f.col_row(v as usize);
            f.pixel_center_grid(c, r)
        };
        let (gc, gr) = f.grid_to_pixel_signed(to);
        let h_of = |v: u32| -> u32 {
            let (c, r) = f.col_row(v as usize);
            let dx = (c as i64 - gc).unsigned_abs() as u32;
            let dy = (r as i64 - gr).unsigned_abs() as u32;
            ORTHO * dx.max(dy) + (DIAG - ORTHO) * dx.min(dy)
        };
        let mut space = self
            .space
            .take()
            .unwrap_or_else(|| SearchSpace::new(f.len()));
        let mut settled = 0usize;
        let mut gave_up = false;
        let found = {
            let me = &*self;
            space.astar(
                starts.iter().map(|&s| (s, 0)),
                |v, out| {
                    let (c, r) = f.col_row(v as usize);
                    let (c, r) = (c as i64, r as i64);
                    for (dc, dr) in crate::tiles::N8 {
                        let (dc, dr) = (i64::from(dc), i64::from(dr));
                        let (nc, nr) = (c + dc, r + dr);
                        if nc < 0 || nr < 0 || nc >= w || nr >= h {
                            continue;
                        }
                        let q = f.pixel_center_grid(nc as usize, nr as usize);
                        if !me.clear_at(q) {
                            continue;
                        }
                        // A diagonal step only where both side pixels are clear too.
                        if dc != 0 && dr != 0 {
                            let a = f.pixel_center_grid((c + dc) as usize, r as usize);
                            let b = f.pixel_center_grid(c as usize, (r + dr) as usize);
                            if !me.clear_at(a) || !me.clear_at(b) {
                                continue;
                            }
                        }
                        let step = if dc != 0 && dr != 0 { DIAG } else { ORTHO };
                        out.push((f.index(nc as usize, nr as usize) as u32, step));
                    }
                },
                h_of,
                |v, _| {
                    settled += 1;
                    if settled > MAX_EXPANSIONS {
                        gave_up = true;
                        return true;
                    }
                    goals.contains(&v)
                },
            )
        };
        let path = match found {
            Some(v) if !gave_up => space.path_to(v),
            _ => {
                self.space = Some(space);
                return Route::Unreachable;
            }
        };
        self.space = Some(space);
        let mut pts: Vec<Point> = std::iter::once(from)
            .chain(path.into_iter().map(centre))
            .chain(std::iter::once(to))
            .collect();
        pts.dedup();
        // Shortened: from each kept point, the farthest point a clear straight move reaches.
        let mut kept = Vec::new();
        let mut a = 0;
        while a + 1 < pts.len() {
            let mut b = a + 1;
            if !self.free(pts[a], pts[b]) {
                return Route::Unreachable;
            }
            while b + 1 < pts.len() && self.free(pts[a], pts[b + 1]) {
                b += 1;
            }
            kept.push(pts[b]);
            a = b;
        }
        // The waypoint itself is the plan's own step, already in the list.
        kept.pop();
        Route::Found(kept)
    }
}

/// What a route search found.
enum Route {
    /// The points to drive through before the waypoint (possibly none: a clear straight move).
    Found(Vec<Point>),
    /// No clear pixel centre next to the robot's estimated position.
    NoStart,
    /// The waypoint is out of reach (or beyond the search's bound).
    Unreachable,
}

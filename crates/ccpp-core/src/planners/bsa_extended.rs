//! `bsa-extended`: basic BSA ([`super::bsa`]) plus the generic coverage extension
//! ([`super::extension`]), so that the partially occupied cells BSA's `2 r` cells leave along
//! walls and furniture are swept too.
//!
//! Source: E. González, O. Álvarez, Y. Díaz, C. Parra, C. Bustacara, "BSA: a complete coverage
//! algorithm", ICRA 2005 (seed 002), sections III–V: the basic spiral filling runs unchanged,
//! and wall-following procedures are invoked for the obstacle boundaries the robot has
//! detected; gaps narrower than a cell are crossed inside a virtual pipe. The paper's own
//! remark that this extension is general is taken literally: the wall following, the pipes and
//! the transfers are the planner-independent component of [`super::extension`] (the same one
//! `ba-star-extended` drives), and this module is only the BSA-specific glue.
//!
//! # How BSA hosts the extension
//!
//! * **During a spiral** BSA decides alone. The extension records every executed motion as
//!   swept (the tool disk along it).
//! * **At the end of a spiral** (BSA's [`Event::RegionEnd`], its return path to the next
//!   backtracking point already chosen): cleaning passes over the rims within
//!   [`ExtensionOptions::reach_r`] robot radii of the robot (default 0 for BSA: none; a
//!   spiral ends in the middle of what it filled, and the trips to the rims from there and on
//!   to the next spiral cost more than one tour after BSA). A target is a known free pixel
//!   that is not swept and that BSA will not sweep anyway ([`Bsa::will_cover`]: its cell is
//!   neither visited nor known unstandable). Then the robot drives to the next spiral's first
//!   cell by the extension's known-free straight segments ([`Bsa::replace_transfer`]) when
//!   that way is shorter than BSA's cell path (or when the robot has moved away from the cell
//!   path's start); BSA's own transfer otherwise. What BSA's cell path would have swept on
//!   the way and the shorter way does not (specks at the spiral's turns) is owed to the final
//!   clean-up, so the extended planner never sweeps less than BSA.
//! * **At the end of BSA** (no backtracking point left): passes over every rim left,
//!   wherever it is, also behind gaps BSA's cells could not cross (the extension's positions
//!   fit through any gap the robot disk fits through: the virtual pipe of seed 002, III.D).
//!   At fine pixels the outer corners of the spiral's rings leave small triangles along its
//!   diagonals, reached only from positions off the obstacle contour; with
//!   [`BsaExtendedOptions::strip_walk`] a pass follows such a strip instead of fetching it one
//!   position (one pixel step, often a turn) at a time.
//!
//! The passes are marked `wall_follow_start` / `wall_follow_end` in the trace, trips of a
//! robot diameter or more between rims `backtrack_start` / `backtrack_end`. Everything is
//! planned from what the sensor has shown (BSA's [`KnownMap`](crate::planner::KnownMap)).
//!
//! # Example
//!
//! BSA's cells (`+` centres) do not line up with the walls; its spiral over them leaves rims
//! (`~`) along the walls and around the pillar. After BSA the extension drives the contour of
//! the rims in a few straight segments (`>`, `v`, `<`, `^`):
//!
//! ```text
//!   ############        ############
//!   #~~~~~~~~~~#        #>>>>>>>>>v#
//!   #~+ + + + ~#        #^+ + + + v#
//!   #~+ ~##~+ ~#   ->   #^+ >##v+ v#
//!   #~+ ~##~+ ~#        #^+ ^##<+ v#
//!   #~+ + + + ~#        #^+ + + + v#
//!   #~~~~~~~~~~#        #^<<<<<<<<<#
//!   ############        ############
//! ```
//!
//! ```
//! use ccpp_core::{GridMap, Pose};
//! use ccpp_core::world::{Robot, World};
//! use ccpp_core::planners::bsa::{Bsa, BsaOptions};
//! use ccpp_core::planners::bsa_extended::{BsaExtended, BsaExtendedOptions};
//! use ccpp_core::sim::{simulate, SimConfig};
//! use ccpp_core::metrics::compute;
//! // Characters of 0.2 m, robot of radius 0.08 m: cells of 0.16 m that do not line up with the
//! // obstacles, so basic BSA leaves bands near them.
//! let art = concat!(
//!     "#########\n",
//!     "#.......#\n",
//!     "#..#....#\n",
//!     "#.....#.#\n",
//!     "#.......#\n",
//!     "#########",
//! );
//! let map = GridMap::from_ascii_scaled(art, 5, 0.04).unwrap();
//! let start = Some(Pose::new(0.3, 0.3, 0.0));
//! let world = World::new(map, Robot::new(0.08), start).unwrap();
//! let basic = simulate(&world, &mut Bsa::new(BsaOptions::default()), &SimConfig::default());
//! let ext = simulate(
//!     &world,
//!     &mut BsaExtended::new(BsaExtendedOptions::default()),
//!     &SimConfig::default(),
//! );
//! let (mb, me) = (compute(&world, &basic, "m"), compute(&world, &ext, "m"));
//! assert_eq!(me.collisions, 0);
//! assert_eq!(me.coverage_rate, Some(1.0));
//! assert!(me.effective_coverage > mb.effective_coverage);
//! assert!(me.effective_coverage > 0.99);
//! ```

use serde::{Deserialize, Serialize};

use super::bsa::{Bsa, BsaOptions, Side};
use super::extension::{Chunk, Drive, Extension, ExtensionOptions, Mode};
use crate::geometry::polyline_length;
use crate::geometry::Point;
use crate::planner::{Planner, Sensor, Step};
use crate::trace::Event;

/// Options of [`BsaExtended`] (`--planner bsa-extended`, config section `bsa_extended`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BsaExtendedOptions {
    /// Reference lateral side of the spirals (`left` or `right`).
    pub side: Side,
    /// The extension (`lane_ends` is refused: BSA has no lanes). Its `reach_r` defaults to 0 here (one clean-up after BSA): a spiral ends
    /// in the middle of what it filled, far from the rims, and cleaning around spiral ends
    /// made the mean path ratio on the shared maps 1.436 instead of 1.373. An `extension`
    /// section that omits a field gets this planner's default for it, not the component's.
    /// Its wall passes may also drop vertices that lose up to two tool radii of pixels, within
    /// 0.5 % of the floor (`simplify_loss` 2, `simplify_fraction` 0.005; the component's are
    /// 1 and 0.0015): on the shared maps 5 % fewer turns for 0.16 % of the floor. Its final
    /// clean-up may leave 0.4 % of the floor in trips that do not pay (`leave_fraction`
    /// 0.004; the component's is 0.002): moving 0.1 % of the floor from the simplification
    /// budget to this one (0.006 / 0.003 before) makes the mean path ratio on the 14 shared
    /// maps 1.3165 instead of 1.3263 and the mean turns 1876 instead of 1877, every map still
    /// above 0.99 effective coverage (the lowest 0.9906). Its wall passes square a rounded
    /// corner where the way grows by at most 0.8 robot radii per turn saved (`corner_slack`
    /// 0.8; the component's is 0.1). With [`Self::strip_walk`] the mean turns on the 14 shared
    /// maps are 1876 instead of 1914 and the mean path ratio 1.3165 instead of 1.3221. (All
    /// measured again on the current code with `ccpp bench --planners bsa-extended` and a
    /// `--config` holding the other values; when each change was made, against the code of
    /// its day, `strip_walk` took the turns from 2006 to 1876 for a path ratio 0.007 higher.)
    #[serde(deserialize_with = "super::settings::bsa_extended_extension")]
    pub extension: ExtensionOptions,
    /// Let the final clean-up's wall pass follow a strip of rim away from the walls: a step
    /// off the obstacle contour onto a position that gains a single pixel is taken when that
    /// position lies on a strip (the rule by which such a position may start a pass), so the
    /// strip is one pass merged into straight segments (`false`: such a step must gain a tool
    /// radius of pixels, and the strip is fetched one position per chunk, one pixel step and
    /// often a turn each). On `aws_small_warehouse_002` (0.02 m pixels) 1 576 chunks of 1-3
    /// pixels became passes: 496 turns fewer (2 081 -> 1 585), the same floor swept.
    pub strip_walk: bool,
}

impl Default for BsaExtendedOptions {
    fn default() -> Self {
        Self {
            side: Side::default(),
            extension: ExtensionOptions {
                reach_r: 0.0,
                simplify_fraction: 0.005,
                simplify_loss: 2.0,
                leave_fraction: 0.004,
                corner_slack: 0.8,
                ..ExtensionOptions::default()
            },
            strip_walk: true,
        }
    }
}

/// Basic BSA plus the coverage extension (see the module docs).
pub struct BsaExtended {
    bsa: Bsa,
    opts: ExtensionOptions,
    ext: Option<Extension>,
    mode: Mode,
    /// Queued steps, trail and open wall pass.
    drive: Drive,
    /// [`BsaExtendedOptions::strip_walk`].
    strip_walk: bool,
}

impl BsaExtended {
    /// A planner with these options.
    pub fn new(opts: BsaExtendedOptions) -> Self {
        Self {
            bsa: Bsa::new(BsaOptions { side: opts.side }),
            opts: opts.extension,
            ext: None,
            mode: Mode::Host,
            drive: Drive::default(),
            strip_walk: opts.strip_walk,
        }
    }

    /// The BSA host (its known map and cells).
    pub fn host(&self) -> &Bsa {
        &self.bsa
    }

    /// One cleaning chunk, or the end of the cleaning (then the transfer to the next spiral).
    fn clean(&mut self, pos: Point, last: bool) {
        let (Some(ext), Some(known)) = (self.ext.as_mut(), self.bsa.known_map()) else {
            self.mode = Mode::Host;
            return;
        };
        let bounded = !last;
        let chunk = if bounded && ext.options().reach_r <= 0.0 {
            Chunk::default()
        } else {
            let bsa = &self.bsa;
            let wanted = |p: Point| !bsa.will_cover(p);
            ext.plan_pass(
                known,
                pos,
                bounded,
                (!last).then_some(&wanted as &dyn Fn(Point) -> bool),
            )
        };
        if self.drive.queue_chunk(pos, &chunk, ext.radius()) {
            return;
        }
        self.drive.end_pass();
        if last {
            self.mode = Mode::Done;
            return;
        }
        self.mode = Mode::Host;
        // The transfer to the next spiral: the extension's straight known-free way when it is
        // shorter than BSA's (or the robot left BSA's start), else BSA's cell path, retreating
        // the way the passes came first if needed.
        let Some(own) = self.bsa.transfer() else {
            return;
        };
        let goal = *own.last().expect("a transfer has moves");
        let moved = self.drive.trail.len() > 1;
        match ext.route(known, pos, goal) {
            Some(route)
                if route.last() == Some(&goal)
                    && (moved
                        || polyline_length(pos, &route) < polyline_length(pos, &own) - 1e-9) =>
            {
                // What BSA's cell path would have swept on the way and this one does not is
                // fetched by the final clean-up (a transfer over a spiral's turns sweeps the
                // specks they left).
                if !moved {
                    ext.owe_skipped(known, pos, &own, &route);
                }
                self.bsa.replace_transfer(pos, &route);
            }
            _ => {
                if moved {
                    for &p in self.drive.trail.iter().rev().skip(1) {
                        self.drive.queue.push_back(Step::MoveTo(p));
                    }
                }
            }
        }
    }
}

impl Planner for BsaExtended {
    fn name(&self) -> &'static str {
        "bsa-extended"
    }

    fn tile_side(&self) -> Option<f64> {
        self.bsa.tile_side()
    }

    fn next(&mut self, sensor: &dyn Sensor) -> Step {
        let strip_walk = self.strip_walk;
        let pos = self
            .drive
            .observe(&mut self.ext, &self.opts, sensor, |ext| {
                ext.set_strip_walk(strip_walk);
            });
        self.bsa.observe(sensor);
        // Stuck against a wall under odometry noise: the moves queued from a position the
        // robot is not at are dropped and the cleaning in progress is given up.
        self.drive.abandon_if_stuck(&mut self.mode);
        loop {
            if let Some(s) = self.drive.queue.pop_front() {
                return s;
            }
            match self.mode {
                Mode::Done => return Step::Done,
                Mode::Clean { last } => self.clean(pos, last),
                Mode::Host => match self.bsa.next(sensor) {
                    s @ Step::Mark(Event::RegionEnd { .. }) => {
                        if self.bsa.transfer().is_some() {
                            self.drive.trail = vec![pos];
                            self.mode = Mode::Clean { last: false };
                        }
                        return s;
                    }
                    Step::Done => {
                        self.drive.trail = vec![pos];
                        self.mode = Mode::Clean { last: true };
                    }
                    s => return s,
                },
            }
        }
    }
}

//! The trace: every executed pose and every event of a run, in order (under PID execution, the
//! poses the simulator records: see [`crate::sim`]). Metrics, pictures and the replay are pure
//! functions of (world, trace).
//!
//! # In memory
//!
//! A run of a tile planner is mostly straight moves of one tile per step, so the trace does not
//! keep one record per pose: [`Trace::push_pose`] merges a pose into the straight run before it
//! when it has the same heading, the next step number and the position that continues the run
//! exactly (bit for bit), so that expanding the runs gives back every pushed pose unchanged.
//! Two kinds of run exist:
//!
//! - a **lattice run**: positions `anchor + index * side` (each coordinate computed as
//!   `anchor.x + f64::from(i) * side`, the formula of [`crate::tiles::TileGrid::center`]) whose
//!   integer index advances by a fixed `(di, dj)`; the [`Lattice`] is fixed by the first pose
//!   (the anchor) and the first displacement (the side, rounded to 12 significant digits);
//! - a **step run**: each position is the previous one plus a fixed vector (`x + dx` in
//!   floating point), as a simulator that translates by a fixed distance produces.
//!
//! Every other pose is kept as it is. [`Trace::entries`], [`Trace::poses`], [`Trace::events`]
//! and [`Trace::records`] expand the runs; [`Trace::pieces`] shows them as stored (what the
//! `trace.jsonl` writer uses). A pose costs 40 bytes when it stands alone and nothing when it
//! extends a run (a run is 40 or 56 bytes); an event costs its [`Event`] plus 24 bytes.
//!
//! # On disk
//!
//! Serialized by `ccpp_io::trace` as JSON Lines: `{"t":3,"pose":[x,y,theta]}` for a pose,
//! `{"t":3,"event":"region_start","region":1}` for an event, and, for a straight run of `n`
//! poses at steps `t, t+1, ...`, `{"t":3,"poses":n,"from":[x,y],"to":[x,y],"theta":th}` (a
//! lattice run, after a `{"lattice":[x,y,side]}` line) or
//! `{"t":3,"poses":n,"from":[x,y],"step":[dx,dy],"theta":th}` (a step run). Files written
//! before runs existed (one line per pose) read the same.

use serde::{Deserialize, Serialize};

use crate::geometry::{round_i64, Point, Pose};

/// Something that happened during a run (a mark in the trace). Planners emit most of these;
/// the simulator emits [`Event::Collision`] and [`Event::Finished`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum Event {
    /// A coverage segment starts (boustrophedon region, spiral, BCD cell...). Counted by the
    /// `regions` metric.
    RegionStart {
        /// 1-based region number.
        region: u32,
    },
    /// A coverage segment ends.
    RegionEnd {
        /// 1-based region number.
        region: u32,
    },
    /// BA*: the robot is at a critical point (all four neighbours blocked).
    CriticalPoint {
        /// World x of the tile centre.
        x: f64,
        /// World y.
        y: f64,
    },
    /// A planner picked the next starting point (BA* `s_sp`, BSA backtracking point).
    StartPoint {
        /// World x.
        x: f64,
        /// World y.
        y: f64,
    },
    /// A transfer between regions starts: motion until [`Event::BacktrackEnd`] is backtracking.
    BacktrackStart,
    /// The transfer ends.
    BacktrackEnd,
    /// A planned path before smoothing (world points).
    PathRaw {
        /// Waypoints.
        points: Vec<[f64; 2]>,
    },
    /// A planned path after smoothing (world points).
    PathSmoothed {
        /// Waypoints.
        points: Vec<[f64; 2]>,
    },
    /// The current backtracking list (candidate start points), world tile centres.
    BacktrackList {
        /// Candidates.
        points: Vec<[f64; 2]>,
    },
    /// A candidate backtracking point was recorded (BSA).
    BacktrackPoint {
        /// World x.
        x: f64,
        /// World y.
        y: f64,
    },
    /// Wall following starts (extended BSA).
    WallFollowStart,
    /// Wall following ends.
    WallFollowEnd,
    /// The bumper touched an obstacle: the motion stopped at contact.
    Collision {
        /// World x of the robot centre at contact.
        x: f64,
        /// World y.
        y: f64,
    },
    /// The run ended.
    Finished {
        /// Why: `done`, `budget`, `max_steps`, ...
        reason: String,
    },
    /// Free-form note from a planner.
    Note {
        /// Text.
        text: String,
    },
    /// The simulator executes motions by PID tracking on a unicycle model (see
    /// [`crate::exec`]); written once at the start of such a run. Absent for ideal execution.
    Execution {
        /// `pid`.
        mode: String,
        /// Control period, seconds.
        dt_s: f64,
        /// Waypoint tolerance, metres: a waypoint counts as reached within this distance (the
        /// `coverage_rate` metric uses it as the tile-centre visit tolerance).
        tolerance_m: f64,
        /// Whether odometry noise perturbs the motion (written only when it does): the robot
        /// reaches its waypoints by its estimate, so `coverage_rate` counts a tile centre
        /// visited within half a tile of the true path.
        #[serde(default, skip_serializing_if = "std::ops::Not::not")]
        noisy: bool,
    },
    /// The straight segment the robot is asked to follow next (PID execution only). The pose
    /// records up to the next such event are measured against it (`tracking_error_*`).
    PlannedSegment {
        /// Start (planned position before the motion), world.
        from: [f64; 2],
        /// Goal, world.
        to: [f64; 2],
    },
    /// PID execution only: how far the true pose was from the planned segment in force (the
    /// last [`Event::PlannedSegment`]), over every control step after the first segment (and
    /// the pose of each contact), written once before [`Event::Finished`]: the
    /// `tracking_error_*` metrics. The trace's poses are a sample of those steps (one in
    /// `record_every`, and none inside a straight glide), so the figures come from here.
    Tracking {
        /// Mean distance, metres.
        mean_m: f64,
        /// Largest distance, metres.
        max_m: f64,
        /// Poses measured (control steps and contacts).
        steps: u64,
    },
    /// Rectangular-robot lane sweep (seed 001): lane spacing and robot length, for the
    /// `rect_guarantee` metric.
    RectLanes {
        /// Robot length `l` (waypoint spacing along a lane), metres.
        length_m: f64,
        /// Robot width `b` (lane spacing), metres.
        width_m: f64,
    },
    /// The pose estimate was reset from a landmark observation (see [`crate::landmarks`]).
    LandmarkFix {
        /// Observed (shared) landmark id.
        id: u32,
        /// Corrected estimate x.
        x: f64,
        /// Corrected estimate y.
        y: f64,
        /// Corrected estimate heading.
        theta: f64,
    },
}

/// One trace line of the one-record-per-pose form (and the unit of [`Trace::records`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Record {
    /// The robot's pose after a motion (or the start pose at `t = 0`).
    Pose {
        /// Step counter.
        t: u64,
        /// `[x, y, theta]`.
        pose: [f64; 3],
    },
    /// An event.
    Event {
        /// Step counter.
        t: u64,
        /// The event.
        #[serde(flatten)]
        event: Event,
    },
}

/// One entry of a trace, borrowed: a pose or an event, with its step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Entry<'a> {
    /// A pose.
    Pose {
        /// Step counter.
        t: u64,
        /// The pose.
        pose: Pose,
    },
    /// An event.
    Event {
        /// Step counter.
        t: u64,
        /// The event.
        event: &'a Event,
    },
}

/// The grid of a trace's lattice runs: point `(i, j)` is at
/// `(anchor[0] + f64::from(i) * side, anchor[1] + f64::from(j) * side)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lattice {
    /// World position of point `(0, 0)`.
    pub anchor: [f64; 2],
    /// Spacing, metres (finite, > 0).
    pub side: f64,
}

impl Lattice {
    /// The world coordinate of index `i` along an axis whose index 0 lies at `a`.
    #[inline]
    fn coord(a: f64, i: i32, side: f64) -> f64 {
        a + f64::from(i) * side
    }

    /// The world position of lattice point `(i, j)`.
    #[inline]
    pub fn point(&self, i: i32, j: i32) -> [f64; 2] {
        [
            Self::coord(self.anchor[0], i, self.side),
            Self::coord(self.anchor[1], j, self.side),
        ]
    }

    /// The lattice index of an axis coordinate `x` (anchor `a`) when `x` is exactly (bit for bit)
    /// a lattice coordinate, else `None`.
    #[inline]
    fn index_1d(a: f64, x: f64, side: f64) -> Option<i32> {
        let q = (x - a) / side;
        let i = if q.abs() <= f64::from(i32::MAX - 1) {
            // `q.round() as i32` without the call into libm: the rounded value lies in range.
            round_i64(q) as i32
        } else {
            // NaN, or out of range (up to rounding at the bound).
            let f = q.round();
            if f.is_nan() || f.abs() > f64::from(i32::MAX - 1) {
                return None;
            }
            f as i32
        };
        (Self::coord(a, i, side).to_bits() == x.to_bits()).then_some(i)
    }

    /// The lattice index of world position `p` when `p` is exactly a lattice point.
    #[inline]
    pub fn index(&self, p: [f64; 2]) -> Option<(i32, i32)> {
        Some((
            Self::index_1d(self.anchor[0], p[0], self.side)?,
            Self::index_1d(self.anchor[1], p[1], self.side)?,
        ))
    }

    /// `self.index(p) == Some((i, j))`, without the two divisions for a lattice of the kind
    /// [`Trace`] fixes (finite anchor and side below 1e15, side above 1e-9 of the anchor's
    /// larger coordinate or of 1, indices below 2^30 in magnitude): there the quotient
    /// `(x - a) / side` of a coordinate `x` equal to `coord(a, i, side)` lies within 1e-6 of
    /// `i` (rounding errors of a few ulps of `i` and of `a / side < 1e9`), so it rounds to `i`,
    /// and the index is `i` exactly when the coordinate is.
    #[inline]
    pub(crate) fn index_is(&self, p: [f64; 2], i: i32, j: i32) -> bool {
        let [a0, a1] = self.anchor;
        let scale = a0.abs().max(a1.abs()).max(1.0);
        let usual = a0.abs() < 1e15
            && a1.abs() < 1e15
            && self.side < 1e15
            && self.side > scale * 1e-9
            && i.unsigned_abs() < 1 << 30
            && j.unsigned_abs() < 1 << 30;
        if !usual {
            return self.index(p) == Some((i, j));
        }
        Self::coord(a0, i, self.side).to_bits() == p[0].to_bits()
            && Self::coord(a1, j, self.side).to_bits() == p[1].to_bits()
    }

    /// A lattice anchored at `anchor` whose side is `d` rounded to 12 significant digits, when
    /// that is a usable spacing.
    fn guess(anchor: [f64; 2], d: f64) -> Option<Self> {
        let side: f64 = format!("{d:.11e}").parse().ok()?;
        let scale = anchor[0].abs().max(anchor[1].abs()).max(1.0);
        (side.is_finite() && side > scale * 1e-9).then_some(Self { anchor, side })
    }
}

/// How the positions of a [`Run`] follow one another.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Advance {
    /// Lattice points: the first at index `(i, j)`, each next one `(di, dj)` further.
    Lattice {
        /// First index, east.
        i: i32,
        /// First index, north.
        j: i32,
        /// Index step, east.
        di: i32,
        /// Index step, north.
        dj: i32,
    },
    /// Each position is the previous one plus `d` (floating-point addition, per coordinate).
    Step {
        /// The step vector, metres.
        d: [f64; 2],
    },
}

/// A straight run of `n >= 2` poses with one heading, at steps `t, t + 1, ..., t + n - 1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Run {
    /// Step of the first pose.
    pub t: u64,
    /// Number of poses.
    pub n: u32,
    /// Heading of every pose.
    pub theta: f64,
    /// Position of the first pose.
    pub from: [f64; 2],
    /// How the next positions follow.
    pub advance: Advance,
}

impl Run {
    /// The poses of the run, in order (`lattice` is the trace's, needed by lattice runs).
    pub fn poses(self, lattice: Option<Lattice>) -> impl Iterator<Item = (u64, Pose)> {
        let mut pos = self.from;
        (0..self.n).map(move |k| {
            if k > 0 {
                pos = match (self.advance, lattice) {
                    (Advance::Lattice { i, j, di, dj }, Some(l)) => {
                        let k = k as i32;
                        l.point(i + k * di, j + k * dj)
                    }
                    (Advance::Step { d }, _) => [pos[0] + d[0], pos[1] + d[1]],
                    (Advance::Lattice { .. }, None) => pos,
                };
            }
            (self.t + u64::from(k), Pose::new(pos[0], pos[1], self.theta))
        })
    }

    /// The position of the last pose.
    pub fn to(self, lattice: Option<Lattice>) -> [f64; 2] {
        match (self.advance, lattice) {
            (Advance::Lattice { i, j, di, dj }, Some(l)) => {
                let k = self.n as i32 - 1;
                l.point(i + k * di, j + k * dj)
            }
            _ => self
                .poses(lattice)
                .last()
                .map_or(self.from, |(_, p)| [p.x, p.y]),
        }
    }
}

/// One stored piece of a trace: a lone pose, a straight run of poses, or an event.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Piece<'a> {
    /// A pose that extends no run.
    Pose {
        /// Step counter.
        t: u64,
        /// The pose.
        pose: Pose,
    },
    /// A straight run of poses.
    Run(Run),
    /// An event.
    Event {
        /// Step counter.
        t: u64,
        /// The event.
        event: &'a Event,
    },
}

/// Stored items (40 bytes, 56 for a step run).
#[derive(Clone, Debug, PartialEq)]
enum Item {
    Pose {
        t: u64,
        pose: [f64; 3],
    },
    Lattice {
        t: u64,
        theta: f64,
        i: i32,
        j: i32,
        di: i32,
        dj: i32,
        n: u32,
    },
    Step {
        t: u64,
        theta: f64,
        from: [f64; 2],
        d: [f64; 2],
        n: u32,
    },
    Event {
        t: u64,
        /// Index into `Trace::events`.
        k: u32,
    },
}

/// A position in a trace ([`Trace::end`], [`Trace::entries_from`]): entries before it were
/// seen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Cursor {
    item: usize,
    within: u32,
}

/// Consecutive pieces of a trace, copied out ([`Trace::chunk`]): the same pieces, in order,
/// with the trace's lattice (the events' point lists left empty).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Chunk(Trace);

impl Chunk {
    /// The pieces, in order.
    pub fn pieces(&self) -> impl Iterator<Item = Piece<'_>> + '_ {
        self.0.pieces()
    }

    /// The trace's lattice when the chunk was taken (fixed before its first lattice run).
    pub fn lattice(&self) -> Option<Lattice> {
        self.0.lattice
    }

    /// Number of pieces.
    pub fn len(&self) -> usize {
        self.0.items.len()
    }

    /// Whether it holds no piece.
    pub fn is_empty(&self) -> bool {
        self.0.items.is_empty()
    }

    /// The executed poses, in order (runs unrolled).
    pub fn poses(&self) -> impl Iterator<Item = Pose> + '_ {
        self.0.poses()
    }
}

/// A whole run's record.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trace {
    items: Vec<Item>,
    events: Vec<Event>,
    /// The lattice of lattice runs (fixed by the first pose and the first displacement).
    lattice: Option<Lattice>,
    /// First pose's position, until the lattice is fixed.
    anchor: Option<[f64; 2]>,
    /// Whether the lattice guess was made (right or wrong, it is made once).
    guessed: bool,
    /// The last pose pushed (step, x, y, theta).
    last: Option<(u64, [f64; 3])>,
    poses: usize,
}

impl Trace {
    /// Appends a pose.
    pub fn push_pose(&mut self, t: u64, p: Pose) {
        self.poses += 1;
        let xy = [p.x, p.y];
        if let Some((_, l)) = self.last {
            if !self.guessed && (l[0] != p.x || l[1] != p.y) {
                self.guessed = true;
                if let Some(a) = self.anchor {
                    let d = (p.x - l[0]).abs().max((p.y - l[1]).abs());
                    self.lattice = Lattice::guess(a, d);
                }
            }
        } else if self.anchor.is_none() {
            self.anchor = Some(xy);
        }
        if !self.try_extend(t, p) {
            self.items.push(Item::Pose {
                t,
                pose: [p.x, p.y, p.theta],
            });
        }
        self.last = Some((t, [p.x, p.y, p.theta]));
    }

    /// Merges pose `p` at step `t` into the last item when it continues it exactly.
    fn try_extend(&mut self, t: u64, p: Pose) -> bool {
        let Some((lt, l)) = self.last else {
            return false;
        };
        if t != lt.wrapping_add(1) || lt == u64::MAX || p.theta.to_bits() != l[2].to_bits() {
            return false;
        }
        let lattice = self.lattice;
        let same = |a: f64, b: f64| a.to_bits() == b.to_bits();
        let Some(last_item) = self.items.last_mut() else {
            return false;
        };
        match last_item {
            Item::Lattice {
                i, j, di, dj, n, ..
            } => {
                let Some(lat) = lattice else { return false };
                let k = *n as i32;
                let (Some(ni), Some(nj)) = (
                    di.checked_mul(k).and_then(|v| v.checked_add(*i)),
                    dj.checked_mul(k).and_then(|v| v.checked_add(*j)),
                ) else {
                    return false;
                };
                if lat.index_is([p.x, p.y], ni, nj) && *n < u32::MAX {
                    *n += 1;
                    return true;
                }
                false
            }
            Item::Step { d, n, .. } => {
                if same(l[0] + d[0], p.x) && same(l[1] + d[1], p.y) && *n < u32::MAX {
                    *n += 1;
                    return true;
                }
                false
            }
            Item::Pose { t: pt, pose } => {
                debug_assert_eq!(*pt, lt);
                let (pt, pose) = (*pt, *pose);
                if let Some(lat) = lattice {
                    if let (Some((i0, j0)), Some((i1, j1))) =
                        (lat.index([pose[0], pose[1]]), lat.index([p.x, p.y]))
                    {
                        if let (Some(di), Some(dj)) = (i1.checked_sub(i0), j1.checked_sub(j0)) {
                            *last_item = Item::Lattice {
                                t: pt,
                                theta: p.theta,
                                i: i0,
                                j: j0,
                                di,
                                dj,
                                n: 2,
                            };
                            return true;
                        }
                    }
                }
                let d = [p.x - pose[0], p.y - pose[1]];
                if same(pose[0] + d[0], p.x) && same(pose[1] + d[1], p.y) {
                    *last_item = Item::Step {
                        t: pt,
                        theta: p.theta,
                        from: [pose[0], pose[1]],
                        d,
                        n: 2,
                    };
                    return true;
                }
                false
            }
            Item::Event { .. } => false,
        }
    }

    /// Appends an event.
    pub fn push_event(&mut self, t: u64, event: Event) {
        let k = u32::try_from(self.events.len()).unwrap_or(u32::MAX);
        self.events.push(event);
        // An event ends any run: the next pose starts a new item.
        self.items.push(Item::Event { t, k });
    }

    /// Appends a record.
    pub fn push(&mut self, r: Record) {
        match r {
            Record::Pose { t, pose } => self.push_pose(t, Pose::new(pose[0], pose[1], pose[2])),
            Record::Event { t, event } => self.push_event(t, event),
        }
    }

    /// Appends a straight run (as [`Self::push_pose`] of each of its poses).
    pub fn push_run(&mut self, run: Run, lattice: Option<Lattice>) {
        for (t, p) in run.poses(lattice) {
            self.push_pose(t, p);
        }
    }

    /// The lattice of the lattice runs, if any was fixed.
    pub fn lattice(&self) -> Option<Lattice> {
        self.lattice
    }

    /// Number of poses.
    pub fn pose_count(&self) -> usize {
        self.poses
    }

    /// Number of events.
    pub fn event_count(&self) -> usize {
        self.events.len()
    }

    /// Number of entries (poses and events).
    pub fn len(&self) -> usize {
        self.poses + self.events.len()
    }

    /// Whether the trace holds nothing.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Number of stored pieces (lone poses, runs and events): what the trace costs.
    pub fn piece_count(&self) -> usize {
        self.items.len()
    }

    /// Number of stored pieces no later push can change: all but the last (a later pose may
    /// extend the last piece).
    pub fn sealed_count(&self) -> usize {
        self.items.len().saturating_sub(1)
    }

    /// An owned copy of the pieces `range` (piece indices, as [`Self::pieces`] yields them),
    /// with the trace's lattice: handed to another thread, it reads the trace as it grows
    /// (pieces below [`Self::sealed_count`] are final). The events' point lists
    /// ([`Event::BacktrackList`], [`Event::PathRaw`], [`Event::PathSmoothed`]) are copied
    /// empty: a chunk carries the motion and the events that mark it.
    ///
    /// # Panics
    /// When `range` is not within `0..piece_count()`.
    pub fn chunk(&self, range: std::ops::Range<usize>) -> Chunk {
        let mut events = Vec::new();
        let items = self.items[range]
            .iter()
            .map(|it| match *it {
                Item::Event { t, k } => {
                    let local = u32::try_from(events.len()).unwrap_or(u32::MAX);
                    // The point lists are left out: a chunk's readers count, sweep and merge
                    // the motion, and copying the backtracking lists would cost the run their
                    // size again.
                    events.push(match &self.events[k as usize] {
                        Event::BacktrackList { .. } => Event::BacktrackList { points: Vec::new() },
                        Event::PathRaw { .. } => Event::PathRaw { points: Vec::new() },
                        Event::PathSmoothed { .. } => Event::PathSmoothed { points: Vec::new() },
                        e => e.clone(),
                    });
                    Item::Event { t, k: local }
                }
                ref other => other.clone(),
            })
            .collect();
        Chunk(Self {
            items,
            events,
            lattice: self.lattice,
            ..Self::default()
        })
    }

    /// Bytes held by the trace's own vectors (not counting what events own on the heap).
    pub fn heap_bytes(&self) -> usize {
        self.items.capacity() * std::mem::size_of::<Item>()
            + self.events.capacity() * std::mem::size_of::<Event>()
    }

    fn piece(&self, item: &Item) -> Piece<'_> {
        match *item {
            Item::Pose { t, pose } => Piece::Pose {
                t,
                pose: Pose::new(pose[0], pose[1], pose[2]),
            },
            Item::Lattice {
                t,
                theta,
                i,
                j,
                di,
                dj,
                n,
            } => Piece::Run(Run {
                t,
                n,
                theta,
                from: self.lattice.map_or([0.0; 2], |l| l.point(i, j)),
                advance: Advance::Lattice { i, j, di, dj },
            }),
            Item::Step {
                t,
                theta,
                from,
                d,
                n,
            } => Piece::Run(Run {
                t,
                n,
                theta,
                from,
                advance: Advance::Step { d },
            }),
            Item::Event { t, k } => Piece::Event {
                t,
                event: &self.events[k as usize],
            },
        }
    }

    /// The stored pieces, in order.
    pub fn pieces(&self) -> impl Iterator<Item = Piece<'_>> + '_ {
        self.items.iter().map(|it| self.piece(it))
    }

    /// Every pose and event, in order.
    pub fn entries(&self) -> impl Iterator<Item = Entry<'_>> + '_ {
        self.entries_from(Cursor::default())
    }

    /// The position after the last entry (a later pose may extend the last item, so the
    /// cursor points into it).
    pub fn end(&self) -> Cursor {
        match self.items.last() {
            None => Cursor::default(),
            Some(Item::Lattice { n, .. } | Item::Step { n, .. }) => Cursor {
                item: self.items.len() - 1,
                within: *n,
            },
            Some(_) => Cursor {
                item: self.items.len() - 1,
                within: 1,
            },
        }
    }

    /// The entries from cursor `c` on (those pushed after [`Self::end`] returned `c`).
    pub fn entries_from(&self, c: Cursor) -> impl Iterator<Item = Entry<'_>> + '_ {
        let lattice = self.lattice;
        self.items
            .get(c.item..)
            .unwrap_or(&[])
            .iter()
            .enumerate()
            .flat_map(move |(k, it)| {
                let skip = if k == 0 { c.within as usize } else { 0 };
                let (one, run) = match self.piece(it) {
                    Piece::Pose { t, pose } => (Some(Entry::Pose { t, pose }), None),
                    Piece::Event { t, event } => (Some(Entry::Event { t, event }), None),
                    Piece::Run(r) => (None, Some(r)),
                };
                one.into_iter().skip(skip).chain(
                    run.into_iter()
                        .flat_map(move |r| r.poses(lattice))
                        .skip(skip)
                        .map(|(t, pose)| Entry::Pose { t, pose }),
                )
            })
    }

    /// The records (one per pose or event, events cloned), in order.
    pub fn records(&self) -> impl Iterator<Item = Record> + '_ {
        self.entries().map(|e| match e {
            Entry::Pose { t, pose } => Record::Pose {
                t,
                pose: [pose.x, pose.y, pose.theta],
            },
            Entry::Event { t, event } => Record::Event {
                t,
                event: event.clone(),
            },
        })
    }

    /// The position of the last executed pose, read from the last stored piece holding poses
    /// (without unrolling the runs before it); `None` for a trace without poses.
    pub fn last_position(&self) -> Option<Point> {
        self.items.iter().rev().find_map(|it| match self.piece(it) {
            Piece::Pose { pose, .. } => Some(pose.position()),
            Piece::Run(run) => {
                let [x, y] = run.to(self.lattice);
                Some(Point::new(x, y))
            }
            Piece::Event { .. } => None,
        })
    }

    /// The executed poses, in order.
    pub fn poses(&self) -> impl Iterator<Item = Pose> + '_ {
        self.entries().filter_map(|e| match e {
            Entry::Pose { pose, .. } => Some(pose),
            Entry::Event { .. } => None,
        })
    }

    /// The executed poses with their step, in order.
    pub fn timed_poses(&self) -> impl Iterator<Item = (u64, Pose)> + '_ {
        self.entries().filter_map(|e| match e {
            Entry::Pose { t, pose } => Some((t, pose)),
            Entry::Event { .. } => None,
        })
    }

    /// The events, in order, with their step.
    pub fn events(&self) -> impl Iterator<Item = (u64, &Event)> + '_ {
        self.items.iter().filter_map(|it| match *it {
            Item::Event { t, k } => Some((t, &self.events[k as usize])),
            _ => None,
        })
    }

    /// Keeps only the events for which `keep` is true (poses are all kept).
    pub fn retain_events(&mut self, mut keep: impl FnMut(&Event) -> bool) {
        let records: Vec<Record> = self.records().collect();
        *self = records
            .into_iter()
            .filter(|r| match r {
                Record::Event { event, .. } => keep(event),
                Record::Pose { .. } => true,
            })
            .collect();
    }
}

impl FromIterator<Record> for Trace {
    fn from_iter<I: IntoIterator<Item = Record>>(iter: I) -> Self {
        let mut t = Trace::default();
        t.extend(iter);
        t
    }
}

impl Extend<Record> for Trace {
    fn extend<I: IntoIterator<Item = Record>>(&mut self, iter: I) {
        for r in iter {
            self.push(r);
        }
    }
}

/// A record, borrowed (serialized exactly as [`Record`]).
#[derive(Serialize)]
#[serde(untagged)]
enum RecordRef<'a> {
    Pose {
        t: u64,
        pose: [f64; 3],
    },
    Event {
        t: u64,
        #[serde(flatten)]
        event: &'a Event,
    },
}

/// Serialized as `{"records": [record, ...]}`, one [`Record`] per pose or event (runs expanded).
impl Serialize for Trace {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct as _;
        struct Records<'a>(&'a Trace);
        impl Serialize for Records<'_> {
            fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
                serializer.collect_seq(self.0.entries().map(|e| match e {
                    Entry::Pose { t, pose } => RecordRef::Pose {
                        t,
                        pose: [pose.x, pose.y, pose.theta],
                    },
                    Entry::Event { t, event } => RecordRef::Event { t, event },
                }))
            }
        }
        let mut s = serializer.serialize_struct("Trace", 1)?;
        s.serialize_field("records", &Records(self))?;
        s.end()
    }
}

impl<'de> Deserialize<'de> for Trace {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        struct Records {
            records: Vec<Record>,
        }
        Ok(Records::deserialize(deserializer)?
            .records
            .into_iter()
            .collect())
    }
}

#[cfg(test)]
mod tests {

    /// `Lattice::index_is` says what `Lattice::index` says: lattice points and near misses by
    /// an ulp, anchors and sides of every magnitude (the fast path and the bounds around it),
    /// indices near 2^30 and the `i32` bound, non-finite coordinates.
    #[test]
    fn lattice_index_is_matches_index() {
        let mut seed: u64 = 0x853c_49e6_748f_ea9b;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let mut yes = 0;
        for k in 0..200_000u32 {
            let r = next();
            let mag = [1.0, 1e-3, 1e3, 1e9, 1e14, 1e16, 1e300][(r % 7) as usize];
            let a = [
                ((r >> 8) % 2001) as f64 * 0.0371 * mag - mag * 37.0,
                ((r >> 20) % 2001) as f64 * -0.0193 * mag,
            ];
            let side =
                [0.05, 0.1, 0.025, 1.0, 7.3e-4, 1e-9, 1e12, 1e16, 1e-12][(r >> 32) as usize % 9];
            let lat = Lattice { anchor: a, side };
            let big = [
                3,
                200_000,
                1 << 29,
                (1 << 30) - 1,
                1 << 30,
                i32::MAX - 2,
                i32::MAX,
            ];
            let pick = |v: u64| -> i32 {
                let m = big[(v % 7) as usize];
                let x = (v >> 8) as i64 % (i64::from(m) + 1);
                let x = if v >> 63 == 1 { -x } else { x };
                x.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32
            };
            let (i, j) = (pick(next()), pick(next()));
            let mut p = lat.point(i, j);
            match k % 5 {
                0 => p[0] = f64::from_bits(p[0].to_bits() ^ 1),
                1 => p[1] = f64::from_bits(p[1].to_bits().wrapping_add(1)),
                2 if k % 15 == 2 => {
                    p[(r >> 40) as usize % 2] = [f64::NAN, f64::INFINITY][(r >> 41) as usize % 2];
                }
                _ => {}
            }
            let (ti, tj) = match (r >> 44) % 4 {
                0 => (i, j + 1),
                1 => (i.wrapping_sub(1), j),
                _ => (i, j),
            };
            let want = lat.index(p) == Some((ti, tj));
            assert_eq!(lat.index_is(p, ti, tj), want, "{lat:?} {p:?} {ti} {tj}");
            yes += usize::from(want);
        }
        assert!(yes > 20_000, "{yes}");
    }

    /// `Lattice::index` without the libm `round` finds exactly the indices of the rounding
    /// definition: halves either way, negative indices, the range bound, NaN and infinities.
    #[test]
    fn lattice_index_matches_rounding_definition() {
        fn reference(a: f64, x: f64, side: f64) -> Option<i32> {
            let f = ((x - a) / side).round();
            if f.is_nan() || f.abs() > f64::from(i32::MAX - 1) {
                return None;
            }
            let i = f as i32;
            (Lattice::coord(a, i, side).to_bits() == x.to_bits()).then_some(i)
        }
        let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let mut hits = 0;
        for k in 0..200_000u32 {
            let r = next();
            let side = [0.05, 0.1, 0.03, 1.0, 0.3][(r % 5) as usize];
            let a = ((r >> 8) % 20_000) as f64 * 0.0137 - 100.0;
            let i = ((next() % 400_000) as i64 - 200_000) as f64;
            let x = match k % 6 {
                0 | 1 => a + i * side,
                2 => a + (i + 0.5) * side,
                3 => a + i * side + f64::from(k % 7) * 1e-13,
                4 => {
                    a + [
                        2_147_483_646.0,
                        2_147_483_646.5,
                        -2_147_483_646.4,
                        2_147_483_647.0,
                        3e9,
                    ][(r >> 20) as usize % 5]
                        * side
                }
                _ => [f64::NAN, f64::INFINITY, -f64::INFINITY, 1e300, -0.0][(r >> 30) as usize % 5],
            };
            let got = Lattice::index_1d(a, x, side);
            assert_eq!(got, reference(a, x, side), "a {a} x {x} side {side}");
            hits += usize::from(got.is_some());
        }
        assert!(hits > 50_000, "{hits}");
    }
    use super::*;

    #[test]
    fn last_position_is_the_last_poses_position() {
        let mut tr = Trace::default();
        assert_eq!(tr.last_position(), None);
        tr.push_event(0, Event::RegionStart { region: 1 });
        assert_eq!(tr.last_position(), None);
        // A lattice run, a turn in place, a run off the lattice, then events.
        let mut t = 0;
        for k in 0..6 {
            tr.push_pose(t, Pose::new(0.5 + 0.3 * f64::from(k), 1.0, 0.0));
            t += 1;
        }
        tr.push_pose(t, Pose::new(2.0, 1.0, 1.5));
        t += 1;
        for k in 1..5 {
            tr.push_pose(t, Pose::new(2.0, 1.0 + 0.07 * f64::from(k), 1.5));
            t += 1;
        }
        tr.push_event(t, Event::RegionEnd { region: 1 });
        let last = tr.poses().last().map(|p| p.position());
        assert_eq!(tr.last_position(), last);
        assert_eq!(last, Some(Point::new(2.0, 1.0 + 0.07 * 4.0)));
    }
}

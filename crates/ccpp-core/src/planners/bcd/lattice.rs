//! Shared geometry: the planning context [`Ctx`] (world, C-free set, pixel helpers) and the
//! [`Lattice`] the cells are decomposed on (the map's pixels or a turned lattice).

use std::borrow::Cow;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::geometry::Point;
use crate::grid::MapFrame;
use crate::world::World;

/// Shared geometry: the world, the C-free set and helpers in grid coordinates (pixels, y up).
pub(super) struct Ctx<'a> {
    pub(super) world: &'a World,
    pub(super) frame: MapFrame,
    /// Reachable C-free pixel centres.
    pub(super) ok: Vec<bool>,
    /// Transfer set: `ok` with the extra margin.
    pub(super) safe: Vec<bool>,
    /// With a margin ([`super::BcdOptions::margin_px`] > 0): the clearance in pixels that
    /// transfers keep from obstacles where they can (contact radius + margin); `None` without.
    pub(super) keep_px: Option<f64>,
    /// Tool radius in pixels.
    pub(super) rt: f64,
    /// The coarse grids of the hop costs, made once ([`super::hops::CoarseCache`]).
    pub(super) coarse: super::hops::CoarseCache,
    /// Set by another thread to give the planning up ([`super::Bcd::new_until`]).
    pub(super) stop: Option<&'a AtomicBool>,
}

/// The lattice the cells are decomposed on: points `(c, r)` one pixel apart (`c` to the right,
/// `r` down, as in the image), either the map's own pixel centres or the same lattice turned
/// by an angle about the map's centre (module docs, step 1).
pub(super) struct Lattice<'a> {
    /// Lattice points per row.
    pub(super) w: usize,
    /// Rows.
    pub(super) h: usize,
    /// `(cos, sin)` of the angle the lattice is turned by in the image; `None`: the pixels.
    rot: Option<(f64, f64)>,
    /// Map height in pixels (grid `y` of an image row).
    map_h: f64,
    /// The map's centre in image coordinates.
    centre: (f64, f64),
    /// Lattice points that are reachable and free for the robot's disk (the pixel lattice
    /// borrows the context's mask; a turned one owns its own).
    pub(super) ok: Cow<'a, [bool]>,
}

impl<'a> Lattice<'a> {
    /// The map's own pixel centres.
    pub(super) fn pixels(ctx: &'a Ctx<'_>) -> Self {
        let (w, h) = (ctx.frame.width, ctx.frame.height);
        Self {
            w,
            h,
            rot: None,
            map_h: h as f64,
            centre: (w as f64 / 2.0, h as f64 / 2.0),
            ok: Cow::Borrowed(&ctx.ok),
        }
    }

    /// The pixel lattice turned by `angle` (radians, in the image) about the map's centre,
    /// large enough to hold the whole map; a point is free where the pixel holding it is
    /// reachable C-free and the robot's disk centred on it touches no obstacle.
    pub(super) fn turned(ctx: &Ctx<'_>, angle: f64) -> Self {
        let (mw, mh) = (ctx.frame.width as f64, ctx.frame.height as f64);
        let (co, si) = (angle.cos(), angle.sin());
        let w = (mw * co.abs() + mh * si.abs()).ceil() as usize + 2;
        let h = (mw * si.abs() + mh * co.abs()).ceil() as usize + 2;
        let mut lat = Self {
            w,
            h,
            rot: Some((co, si)),
            map_h: mh,
            centre: (mw / 2.0, mh / 2.0),
            ok: Cow::Borrowed(&[]),
        };
        let mut ok = vec![false; w * h];
        for r in 0..h {
            for c in 0..w {
                let g = lat.grid(c as f64, r as f64);
                let (pc, pr) = ctx.frame.grid_to_pixel_signed(g);
                ok[r * w + c] = ctx.ok_at(pc, pr) && !ctx.world.disk_collides_grid(g);
            }
        }
        lat.ok = Cow::Owned(ok);
        lat
    }

    /// Grid point (pixels, y up) of the lattice position `(c, r)` (may be fractional).
    pub(super) fn grid(&self, c: f64, r: f64) -> Point {
        match self.rot {
            None => Point::new(c + 0.5, self.map_h - r - 0.5),
            Some((co, si)) => {
                let x = c + 0.5 - self.w as f64 / 2.0;
                let y = r + 0.5 - self.h as f64 / 2.0;
                Point::new(
                    self.centre.0 + co * x - si * y,
                    self.map_h - (self.centre.1 + si * x + co * y),
                )
            }
        }
    }

    /// The same lattice with the free points `ok` instead.
    pub(super) fn with_ok(&self, ok: Vec<bool>) -> Lattice<'static> {
        Lattice {
            w: self.w,
            h: self.h,
            rot: self.rot,
            map_h: self.map_h,
            centre: self.centre,
            ok: Cow::Owned(ok),
        }
    }

    pub(super) fn ok_at(&self, c: i64, r: i64) -> bool {
        c >= 0
            && r >= 0
            && (c as usize) < self.w
            && (r as usize) < self.h
            && self.ok[r as usize * self.w + c as usize]
    }
}

impl Ctx<'_> {
    /// The coarse grid of the hop costs over this C-free set, in blocks of about `sp` pixels
    /// ([`super::hops::Coarse::new`]; cached per plan in [`Ctx::coarse`]).
    pub(super) fn coarse_grid(&self, sp: f64) -> super::hops::Coarse {
        super::hops::Coarse::new(
            self.frame.width,
            self.frame.height,
            &self.ok,
            |i, j| self.pixel_move_free(i, j),
            sp,
            &|| self.stopped(),
        )
    }

    /// Has the caller given the planning up? Each step of a plan looks before it starts, and
    /// a plan given up ends with no plan.
    pub(super) fn stopped(&self) -> bool {
        self.stop.is_some_and(|s| s.load(Ordering::Relaxed))
    }

    pub(super) fn ok_at(&self, c: i64, r: i64) -> bool {
        self.frame
            .checked(c, r)
            .is_some_and(|(c, r)| self.ok[r * self.frame.width + c])
    }

    pub(super) fn centre(&self, c: usize, r: usize) -> Point {
        self.frame.pixel_center_grid(c, r)
    }

    /// Does the straight move from `a` to `b` keep the transfer margin ([`Ctx::keep_px`]): is
    /// every point of it in a `safe` pixel, apart from the points within the kept clearance of
    /// either end of the whole transfer, `ends` (an end may sit closer to a wall, at a lane
    /// end)? True without a margin.
    pub(super) fn keeps_margin(&self, a: Point, b: Point, ends: [Point; 2]) -> bool {
        let Some(keep) = self.keep_px else {
            return true;
        };
        let n = (a.dist(b) * 2.0).ceil() as usize;
        (1..n).all(|k| {
            let t = k as f64 / n as f64;
            let p = Point::new(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t);
            if ends.iter().any(|e| e.dist(p) <= keep) {
                return true;
            }
            let (c, r) = self.frame.grid_to_pixel_signed(p);
            self.frame
                .checked(c, r)
                .is_some_and(|(c, r)| self.safe[r * self.frame.width + c])
        })
    }

    /// Is the straight move between grid points `a` and `b` free on the true map?
    pub(super) fn free(&self, a: Point, b: Point) -> bool {
        self.world.segment_free_grid(a, b)
    }
}

//! Step 1 of a frame: every visible object's representations asked for their estimates,
//! side by side over chunks of objects, and what is kept between frames to ask fewer
//! (an object's front of undominated representations, [`super::Config::reask`]).

use super::REASK_MOVE;
use crate::core::{Frustum, Priced, Rect, RectProjector, Representation, Sight, Subject};
use engine::Sphere;
use glam::Vec3;

/// Objects per chunk of the predictions run side by side.
pub(super) const CHUNK: usize = 256;

/// What a chunk of objects' predictions found: the visible objects (index, pixels,
/// rectangle, bounds, horizon: [`super::Config::horizon`]) and their estimates
/// (representation-major within an object).
#[derive(Default)]
pub(super) struct Seen {
    pub(super) objects: Vec<(usize, f32, Rect, Sphere, f32)>,
    pub(super) estimates: Vec<Option<Priced>>,
    /// Predictions asked.
    pub(super) asked: usize,
}

/// What the planner keeps of an object's last prediction by every representation
/// ([`super::Config::reask`]).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Asked {
    /// The representations on the object's front then (bit `r`); 0: none known.
    pub(super) front: u32,
    /// The eye's offset from the object's centre then, and the object's version.
    pub(super) offset: Vec3,
    pub(super) version: u64,
}

impl Asked {
    /// Whether the front still stands for object `i` in frame `frame`, seen from `offset`
    /// (the eye less its centre), at `version`, asking all every `reask` frames.
    pub(super) fn stands(
        &self,
        i: usize,
        frame: u32,
        reask: u32,
        offset: Vec3,
        version: u64,
    ) -> bool {
        let due = (frame as usize)
            .wrapping_add(i)
            .is_multiple_of(reask.max(1) as usize);
        let moved = offset.distance(self.offset) > REASK_MOVE * self.offset.length();
        self.front != 0 && !due && !moved && version == self.version
    }
}

/// The representations a front is kept for ([`Asked::front`]'s bits): any past these is
/// asked every frame.
pub(super) const FRONT_REPS: usize = 32;

/// The representations (bit `r`) with an option on the front of `est`: none both cheaper
/// and more accurate (as it is, or rebuilt with its rebuild spread over `payback[r]`
/// frames, at most the object's `horizon`).
pub(super) fn front(est: &[Option<Priced>], payback: &[f32], horizon: f32) -> u32 {
    let mut options = [(0.0f32, 0.0f32, 0usize); 2 * FRONT_REPS];
    let mut n = 0;
    for (r, e) in est.iter().enumerate().take(FRONT_REPS) {
        let Some(e) = e else { continue };
        if e.error.is_finite() {
            options[n] = (e.ms, e.error, r);
            n += 1;
        }
        if e.rebuilds && e.rebuilt.is_finite() {
            let frames = payback.get(r).copied().unwrap_or(1.0).min(horizon);
            options[n] = (e.ms + e.rebuild_ms / frames.max(1.0), e.rebuilt, r);
            n += 1;
        }
    }
    let options = &options[..n];
    let mut mask = 0;
    for &(t, e, r) in options {
        let beaten = options
            .iter()
            .any(|&(u, f, _)| u <= t && f <= e && (u < t || f < e));
        if !beaten {
            mask |= 1 << r;
        }
    }
    mask
}

/// Visible object `v`'s estimates, one per representation of `nr` (found by `at`).
pub(super) fn estimates<'s>(
    seen: &'s [Seen],
    at: &[(u32, u32)],
    nr: usize,
    v: usize,
) -> &'s [Option<Priced>] {
    let (c, k) = at[v];
    &seen[c as usize].estimates[k as usize..k as usize + nr]
}

/// What every object's predictions in a frame share.
pub(super) struct Ask<'a, S> {
    pub(super) reps: &'a [Box<dyn Representation<S>>],
    pub(super) cost: &'a crate::core::CostModel,
    pub(super) base: Sight<'a>,
    /// Each object's representation in the previous frame.
    pub(super) before: &'a [Option<usize>],
    pub(super) project: &'a RectProjector,
    pub(super) frustum: &'a Frustum,
    /// Each representation's least time to draw anything (infinite: no bound known).
    pub(super) least_ms: &'a [f32],
    pub(super) payback: &'a [f32],
    pub(super) eye: Vec3,
    pub(super) frame: u32,
    pub(super) reask: u32,
    /// [`super::Config::horizon`].
    pub(super) floor: f32,
}

impl<S: Subject> Ask<'_, S> {
    /// Asks the visible objects of chunk `c` (`chunk`, its part of the kept fronts
    /// `asked` and of the frames in view `in_view`) into `seen`.
    pub(super) fn chunk(
        &self,
        c: usize,
        chunk: &[S],
        seen: &mut Seen,
        asked: &mut [Asked],
        in_view: &mut [u32],
    ) {
        seen.objects.clear();
        seen.estimates.clear();
        seen.asked = 0;
        for (k, s) in chunk.iter().enumerate() {
            let bounds = s.bounds();
            if !self.frustum.sees(bounds.center, bounds.radius) {
                in_view[k] = 0;
                continue;
            }
            let horizon = self.floor + in_view[k] as f32;
            in_view[k] = in_view[k].saturating_add(1);
            let i = c * CHUNK + k;
            let (offset, version) = (self.eye - bounds.center, s.version());
            let known = asked[k].stands(i, self.frame, self.reask, offset, version);
            let first = seen.estimates.len();
            // Corners once for every representation (geometry's box, a layer's warp).
            let sight = self.base.at(bounds).with_corners(s.corners());
            let pixels = sight.pixels;
            let rect = self.project.rect(bounds.center, bounds.radius);
            let rect = rect.unwrap_or_default();
            seen.objects.push((i, pixels, rect, bounds, horizon));
            // The least time of an exact option so far: a representation that cannot
            // draw for less is never chosen, so it is not asked (unless in use).
            let mut exact = f32::INFINITY;
            for (r, rep) in self.reps.iter().enumerate() {
                let dominated = self.least_ms[r].is_finite()
                    && self.before[i] != Some(r)
                    && self.least_ms[r] >= exact;
                let off_front = known
                    && r < FRONT_REPS
                    && asked[k].front & (1 << r) == 0
                    && self.before[i] != Some(r);
                let e = if dominated || off_front {
                    None
                } else {
                    seen.asked += 1;
                    let e = rep.estimate(i, s, &sight).filter(|e| !e.error.is_nan());
                    e.map(|e| Priced::new(&e, self.cost))
                };
                if let Some(e) = e.filter(|e| e.error <= 0.0) {
                    exact = exact.min(e.ms);
                }
                seen.estimates.push(e);
            }
            if !known {
                let front = front(&seen.estimates[first..], self.payback, horizon);
                asked[k] = Asked {
                    front,
                    offset,
                    version,
                };
            }
        }
    }
}

//! Seeing a cloud from inside: particles near the eye fade out with their distance (their
//! billboards would otherwise fill the view, each nearly opaque, a white wall), and the
//! opacity they took away comes back as a uniform fog over the view, in their colour.
//!
//! A particle of radius `r` at distance `d` from the eye keeps the share
//! [`near_fade`]`(d / r)` of its opacity: all of it from [`NEAR_FADE`] radii out, none
//! inside its own sphere. The rest, weighted by the share of directions it covers
//! ([`coverage`]: all inside the sphere, `(r / d)²` outside), is the fog's opacity:
//! `A = FOG_MAX s (1 - Π (1 - lost_i))` with `lost_i = (1 - fade_i) coverage_i density_i / 2`
//! (from inside, a ray crosses half a diameter on average), its colour the mean of those
//! particles' colours toward the eye. `s` ramps from 0 on the cloud's bounding sphere to 1
//! one mean particle radius inside, so the fog grows from nothing as the eye enters (an
//! impostor shows the cloud up to there, and is captured with the same fade). From
//! beyond [`NEAR_FADE`] radii of every particle a cloud draws as before.
//!
//! From inside, even faded, the particles a few radii away each cover a large part of the
//! view, and a cloud of a few hundred of them blends tens of screens of fragments (the
//! showcase's fly-through: 950 ms of raster work in one 1280 x 720 frame). So the fade is
//! also stretched, from inside the bounding sphere: by the smallest scale `s >= 1`
//! ([`fade_scale`]) for which the particles still drawn, those beyond `s` radii, fill at
//! most [`MAX_FILL`] screens (estimated from their quads' sizes in the view,
//! [`screen_share`]); the fade then runs from `s` to `s` [`NEAR_FADE`] radii, and the
//! opacity it takes goes into the fog as before. `s` eases in with the fog (from 1 on the
//! bounding sphere to all of it one mean particle radius inside), so entering does not pop,
//! and from outside (where an impostor may stand in) the cloud draws as before.

use crate::core::{push_quad, UvRect, View};
use engine::{Mesh, Rgba};
use glam::Vec3;

/// Most opacity of the fog: inside a dense cloud the faded particles add up to an opaque
/// white, which hides where the eye is going; the fog keeps this much sight through it (a
/// visibility floor, chosen for the look, not from the optical depth).
pub const FOG_MAX: f32 = 0.7;

/// Distance, in particle radii, from which a particle is drawn at full opacity.
pub const NEAR_FADE: f32 = 3.0;

/// Most screens of particle quads a cloud draws seen from close by or inside (module
/// docs): with the fog's own screen, about four blended layers over the whole view.
pub const MAX_FILL: f32 = 3.0;

/// The share of a view (`tan_half`: tangent of half its vertical field of view, `aspect`:
/// width over height) covered by a screen-facing quad of side `2 r` at view depth `z`
/// (along the view direction): its height and width over the view's, each at most 1; 1
/// when the eye is within `r` of its plane, 0 behind the eye beyond that.
pub fn screen_share(r: f32, z: f32, tan_half: f32, aspect: f32) -> f32 {
    if z <= -r {
        return 0.0;
    }
    if z <= r {
        return 1.0;
    }
    let h = (r / (z * tan_half)).min(1.0);
    let w = (r / (z * tan_half * aspect)).min(1.0);
    let share = h * w;
    if share.is_finite() {
        share.max(0.0)
    } else {
        1.0
    }
}

/// The fade's scale (module docs) for particles given as `(d, share)`: distance from the
/// eye in radii and [`screen_share`]. Sorts `near` by distance. The smallest `s >= 1`,
/// either 1 or one of the distances, such that the shares of the particles farther than
/// `s` radii sum to at most `max_fill` (those within 1 radius are never drawn).
pub fn fade_scale(near: &mut [(f32, f32)], max_fill: f32) -> f32 {
    near.sort_by(|a, b| a.0.total_cmp(&b.0));
    let drawn = |&(d, share): &(f32, f32)| if d > 1.0 { share } else { 0.0 };
    let mut fill: f32 = near.iter().map(drawn).sum();
    if fill <= max_fill {
        return 1.0;
    }
    // Drop the nearest first: each one dropped moves the scale out to its distance.
    for (k, p) in near.iter().enumerate() {
        fill -= drawn(p);
        // Equal distances go together: the fade drops every particle at the scale.
        let tied = near.get(k + 1).is_some_and(|q| q.0 == p.0);
        if fill <= max_fill && !tied {
            return p.0.max(1.0);
        }
    }
    near.last().map_or(1.0, |p| p.0.max(1.0))
}

/// Share of a particle's opacity kept at `d` radii from the eye: 0 up to 1 radius (the eye
/// inside its sphere), rising smoothly to 1 at [`NEAR_FADE`].
pub fn near_fade(d: f32) -> f32 {
    let t = ((d - 1.0) / (NEAR_FADE - 1.0)).clamp(0.0, 1.0);
    if t.is_finite() {
        t * t * (3.0 - 2.0 * t)
    } else {
        1.0
    }
}

/// The share of view directions a particle at `d` radii covers: 1 from inside its sphere,
/// falling as its solid angle, `1 / d²`, outside.
pub fn coverage(d: f32) -> f32 {
    if d <= 1.0 {
        1.0
    } else {
        (1.0 / (d * d)).min(1.0)
    }
}

/// The fog accumulated over the faded particles of one view.
#[derive(Clone, Copy, Debug)]
pub(super) struct Fog {
    transmit: f32,
    color: Vec3,
    weight: f32,
}

impl Default for Fog {
    fn default() -> Self {
        Fog {
            transmit: 1.0,
            color: Vec3::ZERO,
            weight: 0.0,
        }
    }
}

impl Fog {
    /// Adds a particle at `d` radii from the eye, of `density` and straight `color`,
    /// drawn with opacity share `fade`.
    pub(super) fn add(&mut self, d: f32, fade: f32, density: f32, color: Rgba) {
        let lost = ((1.0 - fade) * coverage(d) * density * 0.5).clamp(0.0, 1.0);
        if lost > 0.0 {
            self.transmit *= 1.0 - lost;
            self.color += Vec3::new(color.r, color.g, color.b) * lost;
            self.weight += lost;
        }
    }

    /// The fog's straight colour and opacity, its opacity scaled by `inside` in [0, 1].
    pub(super) fn color(&self, inside: f32) -> Rgba {
        let c = self.color / self.weight.max(1e-12);
        let a = FOG_MAX * (1.0 - self.transmit) * inside.clamp(0.0, 1.0);
        if c.is_finite() && a.is_finite() && a > 0.0 {
            Rgba::new(c.x, c.y, c.z, a)
        } else {
            Rgba::TRANSPARENT
        }
    }
}

/// Writes into `mesh` (cleared) one quad in front of the whole view, at `depth` along the
/// view direction and wide enough to cover any field of view under 160 degrees, in
/// `color`; nothing for a transparent or non-finite one.
pub(super) fn fog_quad(mesh: &mut Mesh, view: &View, depth: f32, color: Rgba) {
    mesh.clear();
    if !(color.a > 0.0 && depth > 0.0 && depth.is_finite()) {
        return;
    }
    let c = view.eye + view.forward * depth;
    let (r, u) = (view.right * (6.0 * depth), view.up * (6.0 * depth));
    let q = [c - r - u, c + r - u, c + r + u, c - r + u];
    if q.iter().all(|p| p.is_finite()) {
        push_quad(mesh, q, UvRect::FULL, color, 1.0);
    }
}

#[cfg(test)]
mod tests;

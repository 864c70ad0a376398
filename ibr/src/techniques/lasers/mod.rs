//! Dual-billboard lasers: a beam from A to B drawn as two quads that contain the beam axis,
//! turned about it to face the viewer, with glowing end caps, blended additively.
//!
//! The first quad's normal is the view vector projected onto the plane perpendicular to the
//! axis, so the beam shows its full width from any side; the second quad is at 90 degrees
//! to it. Seen end-on the projection vanishes: the quads then take a fixed direction from
//! the camera (still finite, full-size quads, seen edge-on), fade out within a few degrees
//! angle to the axis, and the end caps (screen-facing glows) carry the look.
//!
//! A cap is a glow around the beam's end (a muzzle flash at the emitter, an impact glow at
//! the far end): its sprite is drawn in front of everything within [`CAP_CLEARANCE`] cap
//! radii of the end, moved toward the viewer along the ray through the end point (so it
//! keeps its place and size on screen). The emitter's housing around the start (a turret
//! head) and the target the beam strikes then never hide the caps, and a beam seen end-on,
//! from either end, still shows.

mod technique;

use crate::core::sprites;
use crate::core::{push_quad, Billboard, BillboardBatch, Facing, UvRect, View};
use engine::{BlendMode, Draw, Material, Mesh, Rgba};
use glam::{Mat4, Vec2, Vec3};
use std::sync::Arc;

/// One beam.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Laser {
    /// One end of the beam, world space.
    pub a: Vec3,
    /// The other end of the beam, world space.
    pub b: Vec3,
    /// Full width of the glow across the beam, world units.
    pub width: f32,
    /// Straight linear colour.
    pub color: Rgba,
    /// Brightness multiplier of the colour (additive, so > 1 saturates toward white).
    pub intensity: f32,
}

/// Within this angle of the beam axis the beam quads fade out.
pub const END_ON_DEGREES: f32 = 4.0;

/// Cap glow diameter as a multiple of the beam width.
pub const CAP_SCALE: f32 = 3.0;

/// How far in front of its end a cap is drawn, in cap radii (`CAP_SCALE / 2` beam widths):
/// for the showcase's 0.35 wide beam, 1.31, clearing the turret head (radius 0.45) around
/// its emitter and the one its far end stops 0.6 short of (0.6 + 0.45 = 1.05).
pub const CAP_CLEARANCE: f32 = 2.5;

/// Where a cap glow at `end` is drawn for `view` so that it is in front of everything
/// within `clearance` of `end`, and the factor on its size: on the ray from the eye through
/// `end`, `clearance` nearer in view depth (in front of every point of that sphere; a
/// screen-facing quad is at one depth), scaled so its size on screen stays that of a glow
/// at `end`. An end within twice the clearance of the eye moves half its depth; an end at
/// or behind the eye stays. Orthographic views move along the view direction, at
/// unchanged size.
pub fn cap_placement(view: &View, end: Vec3, clearance: f32) -> (Vec3, f32) {
    let depth = view.depth(end);
    if !(clearance > 0.0 && clearance.is_finite() && depth.is_finite()) {
        return (end, 1.0);
    }
    // A perspective view has no pixel size at its own eye; an orthographic one has.
    if view.pixel_size_at(view.eye).is_some() {
        return (end - view.forward * clearance, 1.0);
    }
    if depth <= 0.0 {
        return (end, 1.0);
    }
    let s = (clearance / depth).min(0.5);
    (end + (view.eye - end) * s, 1.0 - s)
}

/// The beam's two quads for a viewer at `eye` (camera up `view_up` for the end-on case) and
/// the fade of the beam quads: 1 except within [`END_ON_DEGREES`] of the axis, where it
/// falls smoothly to 0 (there the quads are edge-on slivers and the caps carry the glow).
/// `None` for a zero-length or non-finite beam (its caps are still drawn).
pub fn beam_quads(
    l: &Laser,
    eye: Vec3,
    view_up: Vec3,
    view_right: Vec3,
) -> Option<([[Vec3; 4]; 2], f32)> {
    let axis = l.b - l.a;
    let len = axis.length();
    if !(len > 1e-6 && len.is_finite() && l.width.is_finite()) {
        return None;
    }
    let d = axis / len;
    // View vector from the closest point of the beam to the eye.
    let t = (eye - l.a).dot(d).clamp(0.0, len);
    let v = eye - (l.a + d * t);
    let perp = v - d * v.dot(d);
    let sin = if v.length() > 0.0 {
        (perp.length() / v.length()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let t = (sin / END_ON_DEGREES.to_radians().sin()).min(1.0);
    let fade = t * t * (3.0 - 2.0 * t);
    // Below a relative 1e-4 the projection is rounding noise, not a direction.
    let n1 = (perp.length() > 1e-4 * v.length())
        .then(|| perp.try_normalize())
        .flatten()
        .or_else(|| (view_up - d * view_up.dot(d)).try_normalize())
        .or_else(|| (view_right - d * view_right.dot(d)).try_normalize())
        .unwrap_or_else(|| d.any_orthonormal_vector());
    let across1 = d.cross(n1) * (0.5 * l.width);
    let across2 = n1 * (0.5 * l.width);
    let quad = |w: Vec3| [l.a - w, l.a + w, l.b + w, l.b - w];
    let q = [quad(across1), quad(across2)];
    q.iter()
        .flatten()
        .all(|p| p.is_finite())
        .then_some((q, fade))
}

/// A set of lasers: one additive draw for the beams, one for the end caps.
#[derive(Clone, Debug)]
pub struct LaserBatch {
    /// The beams drawn at the next build, in any order.
    pub lasers: Vec<Laser>,
    beams: Mesh,
    beam_material: Material,
    caps: BillboardBatch,
}

impl Default for LaserBatch {
    fn default() -> Self {
        Self::new()
    }
}

impl LaserBatch {
    /// A batch with generated beam and glow textures.
    pub fn new() -> Self {
        let material = |t: Arc<engine::Texture>| {
            let mut m = Material::unlit(Rgba::WHITE)
                .with_texture(t)
                .blended(BlendMode::Additive)
                .double_sided(true);
            m.name = "laser".into();
            m
        };
        LaserBatch {
            lasers: Vec::new(),
            beams: Mesh::default(),
            beam_material: material(Arc::new(sprites::beam(64))),
            caps: BillboardBatch::new(material(Arc::new(sprites::glow(64)))),
        }
    }

    /// Writes both meshes for `view`. Returns the number of beam quads.
    pub fn build(&mut self, view: &View) -> usize {
        let m = &mut self.beams;
        m.clear();
        self.caps.clear();
        for l in &self.lasers {
            let tint = Rgba::new(
                l.color.r * l.intensity,
                l.color.g * l.intensity,
                l.color.b * l.intensity,
                1.0,
            );
            if let Some((quads, fade)) = beam_quads(l, view.eye, view.up, view.right) {
                for q in quads {
                    push_quad(m, q, UvRect::FULL, tint, fade);
                }
            }
            let size = l.width * CAP_SCALE;
            for end in [l.a, l.b] {
                let (at, scale) = cap_placement(view, end, 0.5 * size * CAP_CLEARANCE);
                let mut cap = Billboard::new(at, Facing::Screen, Vec2::splat(size * scale));
                cap.tint = tint;
                self.caps.push(cap);
            }
        }
        self.caps.build(view);
        m.positions.len() / 4
    }

    /// The beam mesh of the last build (world space).
    pub fn beam_mesh(&self) -> &Mesh {
        &self.beams
    }

    /// The cap mesh of the last build (world space).
    pub fn cap_mesh(&self) -> &Mesh {
        self.caps.mesh()
    }

    /// The two draws (beams, caps).
    pub fn draws(&self) -> [Draw<'_>; 2] {
        [
            Draw {
                mesh: &self.beams,
                material: &self.beam_material,
                transform: Mat4::IDENTITY,
            },
            self.caps.draw(),
        ]
    }
}

#[cfg(test)]
mod tests;

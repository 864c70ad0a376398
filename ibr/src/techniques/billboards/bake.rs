//! A billboard's bake for the planner: the object's image from the side (an orthographic
//! capture along a horizontal direction), and what it measures of how the billboard will
//! err ([`Profile`]): the image's gradients and the billboard's own error against the
//! object from a grid of azimuths and elevations, each from small probe captures.
//!
//! The billboard turns about +Y through the object's centre to face the eye, so from an
//! azimuth `a` off the baked one and an elevation `e` it shows the baked image, squashed
//! vertically by `cos e` (its upright quad seen tilted), where the object shows itself from
//! `(a, e)`. A probe capture from `(a, e)` against the baked probe squashed so is that
//! error, seen orthographically: the object's asymmetry about its axis (a cylinder's is
//! nothing, a box's much) and the classic failure from above, both measured once.

use crate::core::axial_depth;
use crate::core::Capturer;
use crate::core::Subject;
use crate::core::BAKE_DISTANCE;
use engine::{Camera, Encoding, Lighting, Projection, Sphere, Target, Texture};
use glam::{Mat4, Vec3};

/// Probe azimuths, evenly spaced around the axis from the baked direction.
pub const AZIMUTHS: usize = 8;

/// Probe elevations, degrees (below the horizon too); the billboard is not drawn beyond
/// the last ([`Profile::view_error`] is infinite there).
pub const ELEVATIONS: [f32; 7] = [-75.0, -50.0, -25.0, 0.0, 25.0, 50.0, 75.0];

/// What a bake measures, in 8-bit levels (mean absolute difference over RGB of the stored
/// premultiplied sRGB values, a silhouette against the empty texels counting).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Profile {
    /// Neighbour difference of the baked image per texel, in levels.
    pub gradient: f32,
    /// Neighbour difference of the baked image per texel weighted by how far each surface
    /// lies from the quad's plane through the centre (radii, 0 to 1), in levels: times the
    /// shift in texels of a surface one radius off the plane, it is the parallax part of the
    /// predicted error.
    pub depth_gradient: f32,
    /// The billboard's orthographic error over its square from probe azimuth `k`
    /// (`k * 360 / AZIMUTHS` degrees, turning about +Y from the baked direction toward
    /// its right) and elevation `ELEVATIONS[j]`: `view[j][k]`. Made non-decreasing away
    /// from the horizon along each azimuth (the billboard only gets worse tilted).
    pub view: [[f32; AZIMUTHS]; ELEVATIONS.len()],
}

impl Profile {
    /// The same profile everywhere: `gradient`, its `depth_share`, and a view error of
    /// `level + tilt * sin |e|` (a prior before any bake).
    pub fn uniform(gradient: f32, depth_share: f32, level: f32, tilt: f32) -> Profile {
        let row = |e: f32| [level + tilt * e.to_radians().sin().abs(); AZIMUTHS];
        Profile {
            gradient,
            depth_gradient: gradient * depth_share,
            view: ELEVATIONS.map(row),
        }
    }

    /// The billboard's view error from `azimuth` radians off the baked direction (about
    /// +Y, toward the image's right) and `elevation` radians: the probes interpolated
    /// (periodic in azimuth, linear in elevation); infinite beyond the last elevation or
    /// for non-finite angles.
    pub fn view_error(&self, azimuth: f32, elevation: f32) -> f32 {
        let e = elevation.to_degrees();
        let (lo, hi) = (ELEVATIONS[0], ELEVATIONS[ELEVATIONS.len() - 1]);
        if !(e >= lo && e <= hi && azimuth.is_finite()) {
            return f32::INFINITY;
        }
        let step = (hi - lo) / (ELEVATIONS.len() - 1) as f32;
        let fe = (e - lo) / step;
        let j = (fe.floor() as usize).min(ELEVATIONS.len() - 2);
        let te = (fe - j as f32).clamp(0.0, 1.0);
        let fa = azimuth.rem_euclid(std::f32::consts::TAU) / std::f32::consts::TAU;
        let fa = fa * AZIMUTHS as f32;
        let k = (fa.floor() as usize).min(AZIMUTHS - 1);
        let ta = (fa - k as f32).clamp(0.0, 1.0);
        let at = |j: usize| {
            let row = &self.view[j];
            row[k] * (1.0 - ta) + row[(k + 1) % AZIMUTHS] * ta
        };
        at(j) * (1.0 - te) + at(j + 1) * te
    }

    /// The view error at every probe, as a flat slice (for priors: sums and means).
    pub fn cells(&self) -> impl Iterator<Item = &f32> {
        self.view.iter().flatten()
    }

    /// The view error at every probe, mutable, in the order of [`Profile::cells`].
    pub fn cells_mut(&mut self) -> impl Iterator<Item = &mut f32> {
        self.view.iter_mut().flatten()
    }
}

/// Unit direction toward the viewer from probe azimuth `azimuth` (radians, about +Y from
/// the horizontal `side`, toward its right `Y x side`) and elevation `elevation` radians.
pub(super) fn probe_direction(side: Vec3, azimuth: f32, elevation: f32) -> Vec3 {
    let right = Vec3::Y.cross(side);
    let h = side * azimuth.cos() + right * azimuth.sin();
    h * elevation.cos() + Vec3::Y * elevation.sin()
}

/// The orthographic camera looking at the sphere along `-d` (`d` toward the viewer, not
/// vertical), up as near +Y as it can be, framing exactly its `2r x 2r` square.
pub(super) fn bake_camera(bounds: Sphere, d: Vec3) -> Camera {
    let (c, r) = (bounds.center, bounds.radius);
    Camera {
        view: Mat4::look_at_rh(c + d * (BAKE_DISTANCE * r), c, Vec3::Y),
        projection: Projection::Orthographic {
            left: -r,
            right: r,
            bottom: -r,
            top: r,
            near: (BAKE_DISTANCE - 1.5) * r,
            far: (BAKE_DISTANCE + 1.5) * r,
        },
    }
}

/// The horizontal unit direction of `side` (+Z if it has none).
pub(super) fn horizontal(side: Vec3) -> Vec3 {
    Vec3::new(side.x, 0.0, side.z).normalize_or(Vec3::Z)
}

/// The bounds a bake frames: the subject's sphere, its radius at least 1e-3 and its
/// centre finite.
pub(super) fn bake_bounds(s: Sphere) -> Sphere {
    let center = Some(s.center).filter(|c| c.is_finite()).unwrap_or_default();
    let radius = if s.radius < f32::INFINITY {
        s.radius.max(1e-3)
    } else {
        1e-3
    };
    Sphere { center, radius }
}

/// A finished bake: the image (`px` square, premultiplied sRGB with mipmaps), what it
/// measured, and the captures it took.
#[derive(Clone, Debug)]
pub(super) struct Bake {
    pub image: Texture,
    pub profile: Profile,
    pub bounds: Sphere,
    pub version: u64,
    pub captures: u64,
    pub pixels: u64,
}

/// Captures `subject` seen from the horizontal direction `side` into a `px` square image,
/// and measures its [`Profile`] with `probe` pixel probes (see the module docs).
pub(super) fn bake(
    subject: &mut impl Subject,
    lighting: &Lighting,
    side: Vec3,
    px: u32,
    probe: u32,
) -> Bake {
    let (px, probe) = (px.max(4), probe.max(4));
    let bounds = bake_bounds(subject.bounds());
    let side = horizontal(side);
    let mut capturer = Capturer::new();
    let mut shoot = |d: Vec3, size: u32, out: &mut Vec<u32>, depth: Option<&mut Vec<f32>>| {
        let camera = bake_camera(bounds, d);
        subject.prepare(&camera, size);
        let mut draws = Vec::new();
        subject.draws(&mut draws);
        let t = capturer.render(draws, &camera, lighting, size, size, Encoding::Srgb);
        read(t, &camera, bounds, out, depth);
    };
    let (mut image, mut offsets) = (Vec::new(), Vec::new());
    shoot(side, px, &mut image, Some(&mut offsets));
    let (gradient, depth_gradient) = gradients(&image, &offsets, px as usize);
    let texture = Texture::from_packed(px, px, image, Encoding::Srgb, true)
        .expect("a square of at least 4 texels");
    // The probes: the baked view at the probe size, then every other view against it
    // squashed for its elevation.
    let (mut base, mut seen, mut squashed) = (Vec::new(), Vec::new(), Vec::new());
    shoot(side, probe, &mut base, None);
    let mut view = [[0.0; AZIMUTHS]; ELEVATIONS.len()];
    for (j, e) in ELEVATIONS.iter().map(|e| e.to_radians()).enumerate() {
        squash(&base, probe as usize, e.cos(), &mut squashed);
        for (k, cell) in view[j].iter_mut().enumerate() {
            let a = k as f32 * std::f32::consts::TAU / AZIMUTHS as f32;
            if k == 0 && e == 0.0 {
                continue;
            }
            shoot(probe_direction(side, a, e), probe, &mut seen, None);
            *cell = difference(&seen, &squashed);
        }
    }
    monotone(&mut view);
    let probes = (AZIMUTHS * ELEVATIONS.len()) as u64;
    Bake {
        image: texture,
        profile: Profile {
            gradient,
            depth_gradient,
            view,
        },
        bounds,
        version: subject.version(),
        captures: 1 + probes,
        pixels: u64::from(px * px) + probes * u64::from(probe * probe),
    }
}

/// The captures and pixels of a bake of `px` with `probe` probes (as [`bake`] counts them).
pub(super) fn bake_work(px: u32, probe: u32) -> (u64, u64) {
    let (px, probe) = (u64::from(px.max(4)), u64::from(probe.max(4)));
    let probes = (AZIMUTHS * ELEVATIONS.len()) as u64;
    (1 + probes, px * px + probes * probe * probe)
}

/// Reads a capture's packed colours row-major into `out`, and with `depth`, each texel's
/// distance from the plane through the centre facing the camera, in radii (0 to 1; 0
/// where nothing was drawn).
fn read(t: &Target, camera: &Camera, b: Sphere, out: &mut Vec<u32>, depth: Option<&mut Vec<f32>>) {
    let (mut row, mut z) = (Vec::new(), Vec::new());
    out.clear();
    let mut depth = depth;
    if let Some(d) = depth.as_deref_mut() {
        d.clear();
    }
    let plane = BAKE_DISTANCE * b.radius;
    for y in 0..t.height() {
        t.read_row(y, &mut row, &mut z);
        out.extend_from_slice(&row);
        if let Some(d) = depth.as_deref_mut() {
            d.extend(z.iter().map(|&r| {
                let a = axial_depth(camera, r);
                if a.is_finite() {
                    ((a - plane).abs() / b.radius).min(1.0)
                } else {
                    0.0
                }
            }));
        }
    }
}

/// Sum of the absolute RGB differences of two packed texels.
fn diff(p: u32, q: u32) -> u32 {
    let (p, q) = (p.to_le_bytes(), q.to_le_bytes());
    (0..3).map(|k| u32::from(p[k].abs_diff(q[k]))).sum()
}

/// The image's neighbour difference per texel and channel, and the same weighted by the
/// pair's larger distance from the centre plane ([`Profile::gradient`]).
fn gradients(image: &[u32], offsets: &[f32], side: usize) -> (f32, f32) {
    let (mut sum, mut weighted, mut n) = (0u64, 0f64, 0u64);
    for y in 0..side {
        for x in 0..side {
            let i = y * side + x;
            let mut pair = |j: usize| {
                let d = diff(image[i], image[j]);
                sum += u64::from(d);
                weighted += f64::from(d) * f64::from(offsets[i].max(offsets[j]));
                n += 3;
            };
            if x + 1 < side {
                pair(i + 1);
            }
            if y + 1 < side {
                pair(i + side);
            }
        }
    }
    let n = n.max(1);
    (sum as f32 / n as f32, (weighted / n as f64) as f32)
}

/// The mean absolute difference per texel and channel of two images of the same size.
fn difference(a: &[u32], b: &[u32]) -> f32 {
    let total: u64 = a.iter().zip(b).map(|(&p, &q)| u64::from(diff(p, q))).sum();
    total as f32 / (3 * a.len().max(1)) as f32
}

/// `image` (`side` square) squashed vertically about its centre row by `k` (0 to 1), as
/// its upright quad looks from an elevation `acos k`, into `out`: rows sampled linearly,
/// transparent beyond the squashed image.
fn squash(image: &[u32], side: usize, k: f32, out: &mut Vec<u32>) {
    out.clear();
    out.resize(side * side, 0);
    let h = side as f32 * 0.5;
    for y in 0..side {
        // Up from the centre in half-sides, then where that falls on the upright image.
        let up = 1.0 - (y as f32 + 0.5) / h;
        let src = up / k.max(1e-6);
        if src.abs() > 1.0 {
            continue;
        }
        let fy = (1.0 - src) * h - 0.5;
        let y0 = fy.floor().clamp(0.0, side as f32 - 1.0);
        let t = (fy - y0).clamp(0.0, 1.0);
        let (r0, r1) = (y0 as usize, (y0 as usize + 1).min(side - 1));
        for x in 0..side {
            let (p, q) = (
                image[r0 * side + x].to_le_bytes(),
                image[r1 * side + x].to_le_bytes(),
            );
            let mix: [u8; 4] = std::array::from_fn(|c| {
                (f32::from(p[c]) * (1.0 - t) + f32::from(q[c]) * t).round() as u8
            });
            out[y * side + x] = u32::from_le_bytes(mix);
        }
    }
}

/// Makes each azimuth's errors non-decreasing away from the horizon row, both ways.
fn monotone(view: &mut [[f32; AZIMUTHS]; ELEVATIONS.len()]) {
    let zero = ELEVATIONS.iter().position(|&e| e == 0.0).unwrap_or(0);
    for k in 0..AZIMUTHS {
        for j in zero + 1..ELEVATIONS.len() {
            view[j][k] = view[j][k].max(view[j - 1][k]);
        }
        for j in (0..zero).rev() {
            view[j][k] = view[j][k].max(view[j + 1][k]);
        }
    }
}

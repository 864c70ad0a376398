//! The cylindrical panorama (QuickTime VR's), a [`CubeMap`] unrolled around the vertical:
//! turn in place and look around, within its band of heights.

use super::CubeMap;
use crate::core::DepthImage;
use crate::stereo::rectify::pixel_ray;
use engine::{Camera, Premul};
use glam::Vec3;

/// A cylindrical panorama (QuickTime VR's): the view around a vertical axis, every
/// direction of azimuth over `width` columns and heights up to `tan(half_fov)` above and
/// below the horizon over `height` rows; viewed by turning in place. What lies above or
/// below its band is not in it.
#[derive(Clone, Debug)]
pub struct Cylinder {
    centre: Vec3,
    width: u32,
    height: u32,
    /// `tan` of the band's half height, as an angle above the horizon.
    tan_half: f32,
    /// Linear premultiplied colour, row-major, top row first; column 0 looks down -z.
    color: Vec<Premul>,
}

impl Cylinder {
    /// Unrolls `map` into a `width` x `height` cylinder reaching `half_fov` radians above
    /// and below the horizon.
    pub fn from_cube(map: &CubeMap, width: u32, height: u32, half_fov: f32) -> Cylinder {
        let tan_half = half_fov.clamp(0.01, 1.5).tan();
        let (w, h) = (width.max(1), height.max(1));
        let color = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                let theta = (x as f32 + 0.5) / w as f32 * std::f32::consts::TAU;
                let up = tan_half * (1.0 - 2.0 * (y as f32 + 0.5) / h as f32);
                let dir = Vec3::new(theta.sin(), up, -theta.cos());
                map.sample(dir).unwrap_or(Premul::TRANSPARENT)
            })
            .collect();
        Cylinder {
            centre: map.centre,
            width: w,
            height: h,
            tan_half,
            color,
        }
    }

    /// The view from `camera`'s orientation, turned in place at the centre, `w` x `h`:
    /// each ray's azimuth and height looked up (wrapping around), transparent above and
    /// below the band.
    pub fn view(&self, camera: &Camera, w: u32, h: u32) -> DepthImage {
        let mut out = DepthImage::new(w, h, *camera);
        let to_world = camera.gl_view_proj().inverse();
        let eye = camera.eye();
        let (cw, ch) = (self.width as f32, self.height as f32);
        for (i, c) in out.color.iter_mut().enumerate() {
            let dir = pixel_ray(&to_world, eye, (i as u32 % w, i as u32 / w), (w, h));
            let flat = (dir.x * dir.x + dir.z * dir.z).sqrt();
            if flat.is_nan() || flat <= 0.0 {
                continue;
            }
            let up = dir.y / flat;
            if up.abs() > self.tan_half {
                continue;
            }
            let theta = dir.x.atan2(-dir.z).rem_euclid(std::f32::consts::TAU);
            let u = theta / std::f32::consts::TAU * cw - 0.5;
            let v = (1.0 - up / self.tan_half) * 0.5 * ch - 0.5;
            *c = self.texel(u, v);
        }
        out
    }

    /// Bilinear at `(u, v)` (texel centres at integers), wrapping in `u`, clamped in `v`.
    fn texel(&self, u: f32, v: f32) -> Premul {
        let (w, h) = (self.width as i64, self.height as i64);
        let (u0, v0) = (u.floor(), v.floor());
        let (fu, fv) = (u - u0, v - v0);
        let at = |x: i64, y: i64| {
            let (x, y) = (x.rem_euclid(w), y.clamp(0, h - 1));
            self.color[(y * w + x) as usize]
        };
        let (x, y) = (u0 as i64, v0 as i64);
        let mix = |a: Premul, b: Premul, t: f32| Premul {
            r: a.r + (b.r - a.r) * t,
            g: a.g + (b.g - a.g) * t,
            b: a.b + (b.b - a.b) * t,
            a: a.a + (b.a - a.a) * t,
        };
        mix(
            mix(at(x, y), at(x + 1, y), fu),
            mix(at(x, y + 1), at(x + 1, y + 1), fu),
            fv,
        )
    }

    /// Where it was captured.
    pub fn centre(&self) -> Vec3 {
        self.centre
    }
}

//! Panoramas (Chen 95, QuickTime VR; environment maps): the far scene captured from one
//! point into a cube map, six 90-degree views, and drawn as the sky behind everything from
//! there: each pixel's ray direction looked up, whatever the eye's position. Right where
//! it was captured and in any direction; wrong, by parallax, as the eye moves away, which
//! is where the method fails. [`CubeMap::predicted_px`] says by how much before rendering
//! (the nearest point it holds, seen from the moved eye), and [`Sky`] re-captures when
//! that passes a tolerance.

use crate::capture::capture_batch;
use crate::images::DepthImage;
use crate::stereo::rectify::resample;
use engine::{Camera, Draw, Lighting};
use glam::{Mat3, Vec3};

/// The six faces' view directions and up vectors: +x, -x, +y, -y, +z, -z.
const FACES: [(Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::Y),
    (Vec3::NEG_X, Vec3::Y),
    (Vec3::Y, Vec3::NEG_Z),
    (Vec3::NEG_Y, Vec3::Z),
    (Vec3::Z, Vec3::Y),
    (Vec3::NEG_Z, Vec3::Y),
];

/// A cube map: six square views from one centre, with depth (for the error prediction).
#[derive(Clone, Debug)]
pub struct CubeMap {
    centre: Vec3,
    faces: Vec<DepthImage>,
}

impl CubeMap {
    /// Captures `draws` from `centre` into six `size` x `size` faces, seeing from `near`
    /// (what is nearer is left out: the near scene is drawn as geometry) to `far`.
    pub fn capture(
        draws: &[Draw<'_>],
        lighting: &Lighting,
        centre: Vec3,
        size: u32,
        near: f32,
        far: f32,
    ) -> CubeMap {
        let cameras: Vec<Camera> = FACES
            .iter()
            .map(|&(dir, up)| {
                Camera::look_at(centre, centre + dir, up, std::f32::consts::FRAC_PI_2, 1.0)
                    .with_depth_range(near.max(1e-4), far.max(near * 2.0))
            })
            .collect();
        CubeMap {
            centre,
            faces: capture_batch(draws, &cameras, lighting, size, size),
        }
    }

    /// Where it was captured.
    pub fn centre(&self) -> Vec3 {
        self.centre
    }

    /// The distance (along each face's axis) of the nearest point it holds; infinity when
    /// it holds only sky.
    pub fn nearest(&self) -> f32 {
        self.faces
            .iter()
            .flat_map(|f| f.depth.iter())
            .copied()
            .filter(|d| d.is_finite())
            .fold(f32::INFINITY, f32::min)
    }

    /// The view of the panorama from `camera`'s orientation (its position does not
    /// matter: the panorama is drawn as if infinitely far), `w` x `h`. Depth is empty
    /// everywhere: it is the sky, behind everything.
    pub fn view(&self, camera: &Camera, w: u32, h: u32) -> DepthImage {
        // The camera turned the same way, at the centre.
        let mut view = camera.view;
        let r = Mat3::from_mat4(view);
        view.w_axis = (-(r * self.centre)).extend(1.0);
        let at_centre = Camera {
            view,
            projection: camera.projection,
        };
        let mut out = DepthImage::new(w, h, *camera);
        for face in &self.faces {
            let seen = resample(face, &at_centre, w, h);
            for (o, s) in out.color.iter_mut().zip(&seen.color) {
                if o.a <= 0.0 && s.a > 0.0 {
                    *o = *s;
                }
            }
        }
        out
    }

    /// Fills the pixels of `frame` that show nothing with the panorama, as its sky.
    pub fn behind(&self, frame: &mut DepthImage) {
        let sky = self.view(&frame.camera, frame.width(), frame.height());
        for (c, s) in frame.color.iter_mut().zip(&sky.color) {
            if c.a <= 0.0 {
                *c = *s;
            }
        }
    }

    /// The predicted error of drawing this from `eye`: how far (in pixels, at `focal_px`
    /// pixels per unit of tangent) the nearest point it holds moves when seen from `eye`
    /// instead of the centre, at worst (moved across the line of sight). Zero at the
    /// centre; it grows with the distance moved and shrinks with the scene's distance.
    pub fn predicted_px(&self, eye: Vec3, focal_px: f32) -> f32 {
        let nearest = self.nearest();
        if !nearest.is_finite() {
            return 0.0;
        }
        focal_px * (eye - self.centre).length() / nearest
    }
}

/// A panorama sky with a re-capture policy: drawn from where it was captured until the
/// predicted error passes the tolerance, then captured again at the eye.
#[derive(Clone, Debug)]
pub struct Sky {
    pub map: CubeMap,
    /// Re-capture past this many pixels of predicted error.
    pub tolerance_px: f32,
    pub size: u32,
    pub near: f32,
    pub far: f32,
    /// Captures made (the first included).
    pub captures: u32,
}

impl Sky {
    /// Captures the first panorama at `eye`.
    pub fn new(
        draws: &[Draw<'_>],
        lighting: &Lighting,
        eye: Vec3,
        size: u32,
        (near, far): (f32, f32),
        tolerance_px: f32,
    ) -> Sky {
        Sky {
            map: CubeMap::capture(draws, lighting, eye, size, near, far),
            tolerance_px,
            size,
            near,
            far,
            captures: 1,
        }
    }

    /// Before drawing from `camera` (`focal_px` pixels per unit of tangent): re-captures at
    /// its eye when the predicted error there passes the tolerance. Returns whether it did.
    pub fn update(
        &mut self,
        draws: &[Draw<'_>],
        lighting: &Lighting,
        camera: &Camera,
        focal_px: f32,
    ) -> bool {
        let eye = camera.eye();
        if self.map.predicted_px(eye, focal_px) <= self.tolerance_px {
            return false;
        }
        self.map = CubeMap::capture(draws, lighting, eye, self.size, self.near, self.far);
        self.captures += 1;
        true
    }
}

#[cfg(test)]
mod tests;

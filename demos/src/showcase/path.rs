//! The headless camera path: a circle around the plaza, then a Catmull-Rom flight through
//! key poses over the forest, along the laser, toward the sun, over the city and through a cloud.

use super::Showcase;
use crate::showcase::impostors::CITY_CENTER;
use glam::Vec3;
use std::f32::consts::{PI, TAU};

/// Height of the eye above the highest ground within [`GROUND_RADIUS`] of it, at least.
pub const GROUND_CLEARANCE: f32 = 2.5;
/// Radius around the eye over which the ground clearance is kept.
pub const GROUND_RADIUS: f32 = 1.5;
/// Largest pitch of the flight's view up or down, radians (80 degrees).
pub const MAX_PITCH: f32 = 1.4;
/// Distance from the eye of the returned look-at target.
const LOOK_DISTANCE: f32 = 10.0;

impl Showcase {
    /// The headless camera path, `(eye, target)` at frame `i` of `n`. The first third
    /// circles the plaza once, bobbing up and down; the rest rises over the billboard
    /// forest (looking down on the trees, which show the views baked from above), comes back
    /// to look along the laser from just behind turret B, turns up toward the sun (lens
    /// flare), flies over the city district, climbs into a cloud and through it, and
    /// returns to the start. The eye stays [`GROUND_CLEARANCE`] above the ground around it,
    /// and the view never pitches past [`MAX_PITCH`].
    pub fn path(&self, i: usize, n: usize) -> (Vec3, Vec3) {
        const CIRCLE: f32 = 1.0 / 3.0;
        let f = (i % n.max(1)) as f32 / n.max(1) as f32;
        let (eye, dir) = if f < CIRCLE {
            let (eye, target) = self.circle(f / CIRCLE);
            (eye, (target - eye).normalize_or(Vec3::NEG_Z))
        } else {
            // The view turns by its yaw and pitch, not by a target point: between two
            // keys looking different ways a target sweeps past the eye, and the view
            // through it dives toward the ground (the old frame 43).
            let keys = self.flight_keys();
            let mut poses: Vec<(Vec3, Vec3)> = Vec::with_capacity(keys.len());
            for &(eye, target) in &keys {
                let (yaw, pitch) = yaw_pitch(target - eye);
                // Yaw unwrapped so that each turn goes the short way round.
                let yaw = poses
                    .last()
                    .map_or(yaw, |p| p.1.x + (yaw - p.1.x + PI).rem_euclid(TAU) - PI);
                poses.push((eye, Vec3::new(yaw, pitch, 0.0)));
            }
            let u = (f - CIRCLE) / (1.0 - CIRCLE) * (poses.len() - 1) as f32;
            let k = (u.floor() as usize).min(poses.len() - 2);
            let t = u - k as f32;
            let at = |j: isize| poses[j.clamp(0, poses.len() as isize - 1) as usize];
            let k = k as isize;
            let (p0, p1, p2, p3) = (at(k - 1), at(k), at(k + 1), at(k + 2));
            let angles = catmull_rom(p0.1, p1.1, p2.1, p3.1, t);
            let pitch = angles.y.clamp(-MAX_PITCH, MAX_PITCH);
            (
                catmull_rom(p0.0, p1.0, p2.0, p3.0, t),
                direction(angles.x, pitch),
            )
        };
        let eye = Vec3::new(eye.x, eye.y.max(self.clearance_floor(eye)), eye.z);
        (eye, eye + dir * LOOK_DISTANCE)
    }

    /// The lowest the eye may be at `eye`'s x, z: [`GROUND_CLEARANCE`] above the highest
    /// terrain within [`GROUND_RADIUS`] (so a slope beside the eye stays out of the near
    /// plane too).
    pub fn clearance_floor(&self, eye: Vec3) -> f32 {
        let ring = (0..8).map(|k| {
            let a = k as f32 * TAU / 8.0;
            let (s, c) = a.sin_cos();
            self.terrain
                .height_at(eye.x + GROUND_RADIUS * c, eye.z + GROUND_RADIUS * s)
        });
        ring.fold(self.terrain.height_at(eye.x, eye.z), f32::max) + GROUND_CLEARANCE
    }

    /// The plaza circle at fraction `f` of a turn.
    fn circle(&self, f: f32) -> (Vec3, Vec3) {
        let a = TAU * f + 0.6;
        let r = 17.0 + 1.5 * (2.0 * a).sin();
        let (x, z) = (r * a.cos(), r * a.sin());
        (
            Vec3::new(x, 4.8 + 1.4 * a.sin(), z),
            Vec3::new(0.0, 1.2, 0.0),
        )
    }

    /// Key poses of the flight: from the circle's end over the forest, along the laser,
    /// toward the sun, over the city, through a cloud and back to the circle's start.
    fn flight_keys(&self) -> Vec<(Vec3, Vec3)> {
        let [a, b] = self.ibr.turrets;
        let along = (b - a).normalize();
        let side = along.cross(Vec3::Y).normalize();
        let sun = self.scene.lighting.sun().map_or(Vec3::Y, |(d, _)| -d);
        let sun_eye = Vec3::new(-14.0, 9.0, -16.0);
        let start = self.circle(0.0);
        let city = Vec3::new(CITY_CENTER.x, 4.0, CITY_CENTER.y);
        // The cloud is entered from the south (over the city) at its centre's height and
        // left to the north: `2.2` radii out, so the approach starts outside the band in
        // which its impostor is refreshed every frame.
        let cloud = self.ibr.impostors.path_cloud();
        let (cc, reach) = (cloud.center, 2.2 * cloud.radius);
        vec![
            start,
            (Vec3::new(22.0, 13.0, 22.0), Vec3::new(34.0, 3.0, 32.0)),
            (Vec3::new(36.0, 24.0, 36.0), Vec3::new(41.0, 4.0, 40.0)),
            (Vec3::new(44.0, 22.0, 26.0), Vec3::new(48.0, 2.0, 20.0)),
            (Vec3::new(12.0, 14.0, 34.0), Vec3::new(-6.0, 4.0, 14.0)),
            // From behind turret B, down the beam toward A, where B's bolts explode.
            // (beside the turret's head, so the beam is seen nearly end-on).
            (b + along * 7.0 + side * 1.5 + Vec3::Y * 1.2, a),
            (b + along * 2.5 + side * 0.8 + Vec3::Y * 0.3, a + side * 0.3),
            // The sun about 20 degrees above the image centre, over the forest.
            (
                sun_eye,
                sun_eye + Vec3::new(sun.x, sun.y * 0.4, sun.z) * 10.0,
            ),
            // Over the city, looking down on its impostored buildings.
            (Vec3::new(-18.0, 12.0, -24.0), city),
            (
                city + Vec3::new(3.0, 15.0, -9.0),
                city + Vec3::new(-4.0, -2.0, 8.0),
            ),
            // Into the cloud and out of it.
            (cc - Vec3::Z * reach, cc),
            (cc, cc + Vec3::Z * reach),
            (
                cc + Vec3::new(0.0, 0.5, reach),
                cc + Vec3::new(6.0, -6.0, 2.0 * reach),
            ),
            (Vec3::new(-12.0, 14.0, 28.0), Vec3::new(0.0, 1.2, 0.0)),
            start,
        ]
    }
}

/// Yaw (radians about +Y, 0 looking down -Z) and pitch of direction `d`, packed as the
/// fly camera's angles.
fn yaw_pitch(d: Vec3) -> (f32, f32) {
    let d = d.normalize_or(Vec3::NEG_Z);
    ((-d.x).atan2(-d.z), d.y.clamp(-1.0, 1.0).asin())
}

/// Unit direction of `yaw` and `pitch` (the inverse of [`yaw_pitch`]).
fn direction(yaw: f32, pitch: f32) -> Vec3 {
    let (sy, cy) = yaw.sin_cos();
    let (sp, cp) = pitch.sin_cos();
    Vec3::new(-sy * cp, sp, -cy * cp)
}

/// Uniform Catmull-Rom interpolation between `p1` and `p2`.
fn catmull_rom(p0: Vec3, p1: Vec3, p2: Vec3, p3: Vec3, t: f32) -> Vec3 {
    let (t2, t3) = (t * t, t * t * t);
    0.5 * ((2.0 * p1)
        + (p2 - p0) * t
        + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2
        + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t3)
}

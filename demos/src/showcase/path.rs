//! The headless camera path: a circle around the plaza, then a Catmull-Rom flight through
//! key poses over the forest, along the laser, toward the sun, over the city and through a cloud.

use super::Showcase;
use crate::showcase_impostors::CITY_CENTER;
use glam::Vec3;

impl Showcase {
    /// The headless camera path, `(eye, target)` at frame `i` of `n`. The first third
    /// circles the plaza once, bobbing up and down; the rest rises over the billboard
    /// forest (looking down on the trees, past their fade to top-down sprites), comes back
    /// to look along the laser from just behind turret B, turns up toward the sun (lens
    /// flare), flies over the city district, climbs into a cloud and through it, and
    /// returns to the start. The eye stays 2.5 units above the ground.
    pub fn path(&self, i: usize, n: usize) -> (Vec3, Vec3) {
        const CIRCLE: f32 = 1.0 / 3.0;
        let f = (i % n.max(1)) as f32 / n.max(1) as f32;
        let (eye, target) = if f < CIRCLE {
            self.circle(f / CIRCLE)
        } else {
            let keys = self.flight_keys();
            let u = (f - CIRCLE) / (1.0 - CIRCLE) * (keys.len() - 1) as f32;
            let k = (u.floor() as usize).min(keys.len() - 2);
            let t = u - k as f32;
            let at = |j: isize| keys[j.clamp(0, keys.len() as isize - 1) as usize];
            let k = k as isize;
            let (p0, p1, p2, p3) = (at(k - 1), at(k), at(k + 1), at(k + 2));
            (
                catmull_rom(p0.0, p1.0, p2.0, p3.0, t),
                catmull_rom(p0.1, p1.1, p2.1, p3.1, t),
            )
        };
        let ground = self.terrain.height_at(eye.x, eye.z) + 2.5;
        (Vec3::new(eye.x, eye.y.max(ground), eye.z), target)
    }

    /// The plaza circle at fraction `f` of a turn.
    fn circle(&self, f: f32) -> (Vec3, Vec3) {
        let a = std::f32::consts::TAU * f + 0.6;
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

/// Uniform Catmull-Rom interpolation between `p1` and `p2`.
fn catmull_rom(p0: Vec3, p1: Vec3, p2: Vec3, p3: Vec3, t: f32) -> Vec3 {
    let (t2, t3) = (t * t, t * t * t);
    0.5 * ((2.0 * p1)
        + (p2 - p0) * t
        + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2
        + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t3)
}

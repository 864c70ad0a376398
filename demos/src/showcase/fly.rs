//! The interactive fly camera and the per-frame input it reads.

use super::camera;
use engine::Camera;
use glam::Vec3;

/// What the user asks the fly camera to do this frame (independent of the window library).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FlyInput {
    /// Move along the view direction (+1 forward, -1 back).
    pub forward: f32,
    /// Move sideways (+1 right).
    pub right: f32,
    /// Move along world +Y.
    pub up: f32,
    /// Turn, radians: yaw to the left, pitch up.
    pub yaw: f32,
    pub pitch: f32,
    /// Move faster.
    pub fast: bool,
}

/// A fly camera: a position and yaw / pitch angles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlyCamera {
    pub position: Vec3,
    /// Radians around +Y; 0 looks down -Z.
    pub yaw: f32,
    /// Radians; positive looks up.
    pub pitch: f32,
    /// World units per second.
    pub speed: f32,
}

impl Default for FlyCamera {
    fn default() -> Self {
        FlyCamera::looking_at(Vec3::new(10.0, 4.5, 13.0), Vec3::new(0.0, 1.2, 0.0))
    }
}

impl FlyCamera {
    pub fn looking_at(eye: Vec3, target: Vec3) -> Self {
        let d = (target - eye).normalize_or(Vec3::NEG_Z);
        FlyCamera {
            position: eye,
            yaw: (-d.x).atan2(-d.z),
            pitch: d.y.clamp(-1.0, 1.0).asin(),
            speed: 6.0,
        }
    }

    /// Unit view direction.
    pub fn forward(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        Vec3::new(-sy * cp, sp, -cy * cp)
    }

    /// Applies one frame of input over `dt` seconds.
    pub fn update(&mut self, input: &FlyInput, dt: f32) {
        self.yaw += input.yaw;
        self.pitch = (self.pitch + input.pitch).clamp(-1.5, 1.5);
        let f = self.forward();
        let right = f.cross(Vec3::Y).normalize_or(Vec3::X);
        let speed = self.speed * if input.fast { 4.0 } else { 1.0 } * dt;
        self.position += (f * input.forward + right * input.right + Vec3::Y * input.up) * speed;
    }

    pub fn camera(&self, width: u32, height: u32) -> Camera {
        camera(self.position, self.position + self.forward(), width, height)
    }
}

/// Counts taps of one key from the window's key events (press and release as they arrive,
/// not the key state sampled once a frame), so a tap shorter than a frame is still seen.
/// A held key's auto-repeated presses (down events while already down) count once.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TapCounter {
    down: bool,
    taps: u32,
}

impl TapCounter {
    /// Records one key event: `down` true for a press (or auto-repeat), false for a release.
    pub fn event(&mut self, down: bool) {
        if down && !self.down {
            self.taps = self.taps.saturating_add(1);
        }
        self.down = down;
    }

    /// The taps since the last call, resetting the count (the key's state is kept).
    pub fn take(&mut self) -> u32 {
        std::mem::take(&mut self.taps)
    }
}

/// A toggle after `taps` taps: each tap flips it.
pub fn toggled(on: bool, taps: u32) -> bool {
    on ^ (taps % 2 == 1)
}

//! Sprite sheets: a grid of animation frames in one texture, played from a particle's age.

use crate::core::UvRect;

/// A grid of animation frames in one texture, played at `fps` from a particle's age.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpriteSheet {
    /// Columns of the grid (frames across).
    pub cols: u32,
    /// Rows of the grid.
    pub rows: u32,
    /// Frames used, row-major from the top-left cell (at most `cols * rows`).
    pub frames: u32,
    /// Frames per second of particle age.
    pub fps: f32,
    /// Wrap to the first frame after the last; otherwise hold the last frame.
    pub looping: bool,
}

/// The layout of [`explosion_sheet`](super::explosion_sheet) as [`Effects`](super::Effects) generates it: 4 x 4 frames.
pub const EXPLOSION_SHEET: SpriteSheet = SpriteSheet {
    cols: 4,
    rows: 4,
    frames: 16,
    fps: 14.0,
    looping: false,
};

impl SpriteSheet {
    /// Columns and rows clamped to 1..=1024 and the frame count to 1..=cols*rows.
    fn grid(&self) -> (u32, u32, u32) {
        let (c, r) = (self.cols.clamp(1, 1024), self.rows.clamp(1, 1024));
        (c, r, self.frames.clamp(1, c * r))
    }

    /// Frame shown at `age` seconds (0 for negative or NaN ages and non-positive fps).
    pub fn frame(&self, age: f32) -> u32 {
        let (_, _, n) = self.grid();
        let f = (age * self.fps).floor();
        if f.is_nan() || f <= 0.0 {
            return 0;
        }
        if self.looping {
            // Infinity gives NaN here, which casts to 0.
            (f % n as f32) as u32 % n
        } else {
            f.min((n - 1) as f32) as u32
        }
    }

    /// The texture region of the frame shown at `age` seconds.
    pub fn region(&self, age: f32) -> UvRect {
        let (c, r, _) = self.grid();
        UvRect::cell(c, r, self.frame(age))
    }

    /// Seconds to play every frame once.
    pub fn duration(&self) -> f32 {
        self.grid().2 as f32 / self.fps
    }
}

//! A warped image written into the frame by a packed image pass, depth-tested against the
//! geometry there: what the depth-image, portal and light-field techniques composite with.

use super::{Warped, ENCODING};
use engine::{Encoding, PackedFragment, PackedPass, Projection};

/// Writes a warped image taken by the target's camera into the target: its packed colour
/// as it is, and its disparity turned into the target's reversed depth (a multiply-add;
/// at or beyond the far plane, sky too, the smallest positive depth, as
/// `Camera::reversed_from_view_depth` gives). Holes write nothing.
#[derive(Debug)]
pub struct ImagePass<'a> {
    image: &'a Warped,
    /// Reversed depth `scale * disparity - offset` (perspective cameras).
    scale: f32,
    offset: f32,
    /// Disparity of the far plane.
    far: f32,
}

impl<'a> ImagePass<'a> {
    /// A pass writing `image` (taken by the target's camera), its depth mapping computed
    /// from the image's camera.
    pub fn new(image: &'a Warped) -> Self {
        let (n, f) = image.camera.near_far();
        // reversed = n (f - z) / (z (f - n)) = (n f / (f - n)) / z - n / (f - n).
        let (scale, offset) = match image.camera.projection {
            Projection::Orthographic { .. } => (0.0, 0.0),
            _ => (n * f / (f - n), n / (f - n)),
        };
        ImagePass {
            image,
            scale,
            offset,
            far: 1.0 / f,
        }
    }
}

impl PackedPass for ImagePass<'_> {
    fn encoding(&self) -> Encoding {
        ENCODING
    }

    fn shade_span(&self, x0: u32, y: u32, out: &mut [Option<PackedFragment>]) {
        let w = self.image.width();
        if y >= self.image.height() || x0 >= w {
            return;
        }
        let start = (y * w + x0) as usize;
        let n = out.len().min((w - x0) as usize);
        let colors = &self.image.color[start..start + n];
        let disparities = &self.image.disparity[start..start + n];
        for ((o, &c), &d) in out.iter_mut().zip(colors).zip(disparities) {
            if d >= 0.0 {
                let depth = if d <= self.far {
                    f32::MIN_POSITIVE
                } else {
                    (self.scale * d - self.offset).max(f32::MIN_POSITIVE)
                };
                *o = Some(PackedFragment { color: c, depth });
            }
        }
    }
}

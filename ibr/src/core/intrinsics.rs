//! A pinhole camera's intrinsics in pixels, as capture files and the warp's equation
//! state them.

use engine::Projection;

/// A pinhole camera's intrinsics in pixels: focal lengths and principal point (`cy` from
/// the top row, y down), for a `w` x `h` image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Intrinsics {
    /// Focal length along x, pixels.
    pub fl_x: f32,
    /// Focal length along y, pixels.
    pub fl_y: f32,
    /// Principal point's x, pixels from the left edge.
    pub cx: f32,
    /// Principal point's y, pixels from the top edge (y down).
    pub cy: f32,
}

impl Intrinsics {
    /// A perspective camera's intrinsics for a `width` x `height` image; `None` for an
    /// orthographic one.
    pub fn of(projection: &Projection, width: u32, height: u32) -> Option<Self> {
        if !projection.is_perspective() {
            return None;
        }
        let [l, r, b, t] = projection.extents();
        let (n, _) = projection.near_far();
        let (w, h) = (width as f32, height as f32);
        Some(Intrinsics {
            fl_x: w * n / (r - l),
            fl_y: h * n / (t - b),
            cx: w * -l / (r - l),
            cy: h * t / (t - b),
        })
    }

    /// The projection with these intrinsics for a `width` x `height` image: symmetric
    /// ([`Projection::Perspective`]) when the principal point is the centre and pixels are
    /// square, else off-axis ([`Projection::Frustum`]).
    pub fn projection(&self, width: u32, height: u32, near: f32, far: f32) -> Projection {
        let (w, h) = (width as f32, height as f32);
        let centred = (self.cx - w / 2.0).abs() <= 1e-4 * w
            && (self.cy - h / 2.0).abs() <= 1e-4 * h
            && (self.fl_x - self.fl_y).abs() <= 1e-5 * self.fl_y;
        if centred {
            return Projection::Perspective {
                fov_y: 2.0 * (h / 2.0 / self.fl_y).atan(),
                aspect: w / h,
                near,
                far,
            };
        }
        Projection::Frustum {
            left: -self.cx * near / self.fl_x,
            right: (w - self.cx) * near / self.fl_x,
            bottom: -(h - self.cy) * near / self.fl_y,
            top: self.cy * near / self.fl_y,
            near,
            far,
        }
    }
}

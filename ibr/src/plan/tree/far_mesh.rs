//! The far field's image mesh: a captured depth image drawn as textured quads at its
//! pixels' depths, one quad per rectangle of pixels whose inverse depths one plane
//! reproduces (within [`DEPTH_TOLERANCE`]), the colours read from the image itself as a
//! texture (nearest texel, uncovered texels cut out). A planar face of a far building is
//! one quad whatever its windows; a row run of one colour per quad (the mesh before)
//! stopped at every window and took 2 triangles per pixel row of each object.
//! A rectangle stops at a depth that leaves the plane (a silhouette against a farther
//! object, a corner), so parallax stays a pixel's; coverage is the texture's alpha.

use crate::core::DepthImage;
use engine::color::Encoder;
use engine::{AlphaMode, Encoding, Filter, Material, Mesh, Rgba, Sampler, Texture, Wrap};
use glam::{Vec2, Vec4};
use std::sync::Arc;

/// Largest relative difference between a covered pixel's depth and its quad's plane there
/// (at 300 units, 0.6 units: a tenth of a pixel of parallax for the 18 units of eye motion
/// the world's field allows before its re-capture).
pub(super) const DEPTH_TOLERANCE: f32 = 0.002;

/// Largest slip of a texture coordinate from the image's point, pixels: a quad's uvs are
/// the image's at its corners, interpolated in perspective across it, which slips by about
/// a quarter of its side times its relative range of inverse depth (nearest texels, so
/// under half a pixel keeps every pixel's own).
pub(super) const TEXEL_SLIP: f32 = 0.125;

/// Largest side of a quad, pixels.
pub(super) const MAX_SIDE: u32 = 64;

/// Uncovered pixels a row of a quad may cross between covered ones (cut out when drawn).
pub(super) const MAX_GAP: u32 = 2;

/// Whether pixel `i` of `image` is drawn: at least half covered, at a finite depth.
fn covered(image: &DepthImage, i: usize) -> bool {
    image.color[i].a >= 0.5 && image.depth[i].is_finite() && image.depth[i] > 0.0
}

/// A least-squares plane of inverse depth over image points: `inv = a + b (x - mx) + c (y - my)`.
#[derive(Clone, Copy, Debug, Default)]
struct Plane {
    n: f64,
    sx: f64,
    sy: f64,
    sz: f64,
    sxx: f64,
    sxy: f64,
    syy: f64,
    sxz: f64,
    syz: f64,
}

impl Plane {
    fn add(&mut self, x: f64, y: f64, z: f64) {
        self.n += 1.0;
        self.sx += x;
        self.sy += y;
        self.sz += z;
        self.sxx += x * x;
        self.sxy += x * y;
        self.syy += y * y;
        self.sxz += x * z;
        self.syz += y * z;
    }

    /// The plane's inverse depth at `(x, y)`, as a closure.
    fn solve(&self) -> impl Fn(f64, f64) -> f64 {
        let n = self.n.max(1.0);
        let (mx, my, mz) = (self.sx / n, self.sy / n, self.sz / n);
        let xx = self.sxx / n - mx * mx;
        let xy = self.sxy / n - mx * my;
        let yy = self.syy / n - my * my;
        let xz = self.sxz / n - mx * mz;
        let yz = self.syz / n - my * mz;
        let det = xx * yy - xy * xy;
        let (b, c) = if det > 1e-9 * (xx + yy).max(1e-12).powi(2) {
            ((xz * yy - yz * xy) / det, (yz * xx - xz * xy) / det)
        } else if xx > 1e-12 {
            (xz / xx, 0.0)
        } else if yy > 1e-12 {
            (0.0, yz / yy)
        } else {
            (0.0, 0.0)
        };
        move |x, y| mz + b * (x - mx) + c * (y - my)
    }
}

/// A quad's pixel rectangle, first and last column and row (inclusive).
pub(super) type Rect = (u32, u32, u32, u32);

/// The quads of `image`: every covered pixel in exactly one rectangle, each rectangle's
/// covered pixels on one plane of inverse depth within [`DEPTH_TOLERANCE`], its first and
/// last columns and first row holding a covered pixel. Grown from the first pixel not yet
/// in one, row-major: right while the row fits (crossing at most [`MAX_GAP`] uncovered
/// pixels), then down a row at a time while the rectangle fits.
pub(super) fn rects(image: &DepthImage, taken: &mut Vec<bool>, out: &mut Vec<Rect>) {
    out.clear();
    let (w, h) = (image.width(), image.height());
    taken.clear();
    taken.resize((w * h) as usize, false);
    let at = |x: u32, y: u32| (y * w + x) as usize;
    let inv = |i: usize| 1.0 / f64::from(image.depth[i]);
    // Whether the rectangle's covered pixels lie on `plane`, and its texture coordinates,
    // interpolated in perspective, stay within [`TEXEL_SLIP`] of the image's.
    let fits = |plane: &Plane, (x0, x1, y0, y1): Rect| {
        let f = plane.solve();
        let (mut lo, mut hi) = (f64::MAX, 0.0f64);
        let on = (y0..=y1).all(|y| {
            (x0..=x1).all(|x| {
                let i = at(x, y);
                if !covered(image, i) {
                    return true;
                }
                let z = inv(i);
                (lo, hi) = (lo.min(z), hi.max(z));
                (f(f64::from(x), f64::from(y)) / z - 1.0).abs() <= f64::from(DEPTH_TOLERANCE)
            })
        });
        let side = f64::from((x1 - x0).max(y1 - y0) + 1);
        on && (hi / lo - 1.0) * side <= 4.0 * f64::from(TEXEL_SLIP)
    };
    for y in 0..h {
        for x in 0..w {
            let i = at(x, y);
            if taken[i] || !covered(image, i) {
                continue;
            }
            let mut plane = Plane::default();
            plane.add(f64::from(x), f64::from(y), inv(i));
            // Right along the row.
            let (mut x1, mut gap) = (x, 0);
            let mut nx = x + 1;
            while nx < w && nx - x < MAX_SIDE {
                let j = at(nx, y);
                if !covered(image, j) {
                    gap += 1;
                    if gap > MAX_GAP {
                        break;
                    }
                    nx += 1;
                    continue;
                }
                if taken[j] {
                    break;
                }
                let mut next = plane;
                next.add(f64::from(nx), f64::from(y), inv(j));
                if !fits(&next, (x, nx, y, y)) {
                    break;
                }
                plane = next;
                (x1, gap) = (nx, 0);
                nx += 1;
            }
            // Down, a row at a time.
            let mut y1 = y;
            while y1 + 1 < h && y1 + 1 - y < MAX_SIDE {
                let ny = y1 + 1;
                let mut next = plane;
                let mut any = false;
                let mut clash = false;
                for cx in x..=x1 {
                    let j = at(cx, ny);
                    if covered(image, j) {
                        clash |= taken[j];
                        any = true;
                        next.add(f64::from(cx), f64::from(ny), inv(j));
                    }
                }
                if !any || clash || !fits(&next, (x, x1, y, ny)) {
                    break;
                }
                plane = next;
                y1 = ny;
            }
            for ty in y..=y1 {
                for tx in x..=x1 {
                    let j = at(tx, ty);
                    if covered(image, j) {
                        taken[j] = true;
                    }
                }
            }
            out.push((x, x1, y, y1));
        }
    }
}

/// The material a far tile is drawn with: unlit, its image as a texture read at the
/// nearest texel (clamped at the tile's edges), texels under half covered cut out; both
/// sides (a quad is seen from nearby eyes only).
pub(super) fn tile_material(texture: Arc<Texture>) -> Material {
    Material {
        base_texture: Some(texture),
        sampler: Sampler {
            wrap_u: Wrap::Clamp,
            wrap_v: Wrap::Clamp,
            filter: Filter::Nearest,
        },
        vertex_colors: false,
        alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
        double_sided: true,
        ..Material::unlit(Rgba::WHITE)
    }
}

/// The texture of `image`: each covered pixel's colour, opaque; the others transparent
/// (cut out by [`tile_material`]). `None` for an empty image.
pub(super) fn image_texture(image: &DepthImage) -> Option<Texture> {
    let enc = Encoder::new(Encoding::Srgb);
    let texels = (0..image.color.len())
        .map(|i| {
            if covered(image, i) {
                let c = image.color[i].unpremultiply();
                enc.pack(c.r, c.g, c.b, 1.0)
            } else {
                0
            }
        })
        .collect();
    Texture::from_packed(image.width(), image.height(), texels, Encoding::Srgb, true)
}

/// Rebuilds `mesh` from `image` (a perspective capture): a quad per rectangle ([`rects`])
/// on its plane of inverse depth along the axis, textured with the image (uvs at the
/// image's points: [`image_texture`]), grown by `grow` pixels on every side so
/// neighbouring quads of one surface leave no cracks when seen from a nearby eye.
/// `scratch` holds the rectangles.
pub(super) fn span_mesh(
    image: &DepthImage,
    grow: f32,
    mesh: &mut Mesh,
    scratch: &mut (Vec<bool>, Vec<Rect>),
) {
    mesh.clear();
    let (w, h) = (image.width(), image.height());
    if w == 0 || h == 0 {
        return;
    }
    let camera = &image.camera;
    let inverse = camera.projection.reversed_z_matrix().inverse();
    let world = camera.view.inverse();
    // The view-space direction through a point of the image, at unit depth along -z: affine
    // in the image point for a perspective camera.
    let dir = |sx: f32, sy: f32| {
        let ndc = Vec4::new(
            2.0 * sx / w as f32 - 1.0,
            1.0 - 2.0 * sy / h as f32,
            0.0,
            1.0,
        );
        let p = inverse * ndc;
        let p = p.truncate() / p.w;
        p / -p.z
    };
    let o = dir(0.0, 0.0);
    let (dx, dy) = (dir(1.0, 0.0) - o, dir(0.0, 1.0) - o);
    let (taken, quads) = scratch;
    rects(image, taken, quads);
    let inv = |x: u32, y: u32| 1.0 / f64::from(image.depth[(y * w + x) as usize]);
    for &(x0, x1, y0, y1) in quads.iter() {
        let mut plane = Plane::default();
        let mut least = f64::MAX;
        for y in y0..=y1 {
            for x in x0..=x1 {
                if covered(image, (y * w + x) as usize) {
                    let z = inv(x, y);
                    least = least.min(z);
                    plane.add(f64::from(x), f64::from(y), z);
                }
            }
        }
        let f = plane.solve();
        let base = mesh.positions.len() as u32;
        let (left, right) = (x0 as f32 - grow, x1 as f32 + 1.0 + grow);
        let (top, bottom) = (y0 as f32 - grow, y1 as f32 + 1.0 + grow);
        for (sx, sy) in [(left, top), (right, top), (left, bottom), (right, bottom)] {
            // The plane is fitted at pixel indices (centres at index + 0.5).
            let at = f(f64::from(sx) - 0.5, f64::from(sy) - 0.5).max(least * 0.5);
            let z = (1.0 / at) as f32;
            let v = (o + dx * sx + dy * sy) * z;
            mesh.positions.push(world.transform_point3(v));
            mesh.uvs.push(Vec2::new(sx / w as f32, sy / h as f32));
        }
        mesh.indices
            .extend([base, base + 2, base + 1, base + 1, base + 2, base + 3]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use engine::{Camera, Draw, FrameOptions, Renderer, Target};
    use glam::{Mat4, Vec3};

    const W: u32 = 40;
    const H: u32 = 8;

    fn camera() -> Camera {
        Camera::look_at(Vec3::ZERO, -Vec3::Z, Vec3::Y, 1.0, W as f32 / H as f32)
            .with_depth_range(0.5, 1000.0)
    }

    fn image(f: impl Fn(u32, u32) -> Option<(Rgba, f32)>) -> DepthImage {
        let mut image = DepthImage::new(W, H, camera());
        for y in 0..H {
            for x in 0..W {
                if let Some((c, z)) = f(x, y) {
                    let i = (y * W + x) as usize;
                    image.color[i] = c.premultiply();
                    image.depth[i] = z;
                }
            }
        }
        image
    }

    fn rects_of(image: &DepthImage) -> Vec<Rect> {
        let (mut taken, mut out) = (Vec::new(), Vec::new());
        rects(image, &mut taken, &mut out);
        out
    }

    /// A colour that changes at every pixel (a far building's windows).
    fn windows(x: u32, y: u32) -> Rgba {
        Rgba::new(
            0.1 + 0.8 * ((x + y) % 2) as f32,
            0.3,
            0.1 * (y % 3) as f32,
            1.0,
        )
    }

    #[test]
    fn a_slanted_plane_of_any_colours_is_one_quad() {
        // Inverse depth affine in x and y (a plane), a new colour at every pixel: one quad,
        // 2 triangles, where the row runs of one colour took 2 a pixel (640).
        let img = image(|x, y| {
            Some((
                windows(x, y),
                1.0 / (0.004 - x as f32 * 4e-7 + y as f32 * 2e-7),
            ))
        });
        assert_eq!(rects_of(&img), vec![(0, W - 1, 0, H - 1)]);
        let mut mesh = Mesh::default();
        span_mesh(&img, 0.25, &mut mesh, &mut Default::default());
        assert_eq!(mesh.triangle_count(), 2);
        assert!(mesh.validate().is_ok());
    }

    #[test]
    fn rects_cover_each_covered_pixel_once_and_stop_at_depth_steps_and_gaps() {
        // Columns 0-9 at 300, 10-11 empty (a gap within MAX_GAP), 12-19 at 300, 20-24
        // empty, 25-31 at 300, 32-39 at 500 (a depth step); rows 6-7 at 900 (a farther
        // object below).
        let img = image(|x, y| {
            let z = match (x, y) {
                (_, 6..) => 900.0,
                (10..=11, _) | (20..=24, _) => return None,
                (32.., _) => 500.0,
                _ => 300.0,
            };
            Some((windows(x, y), z))
        });
        let got = rects_of(&img);
        assert_eq!(
            got,
            vec![(0, 19, 0, 5), (25, 31, 0, 5), (32, 39, 0, 5), (0, 39, 6, 7)]
        );
        let mut seen = vec![0; (W * H) as usize];
        for &(x0, x1, y0, y1) in &got {
            for y in y0..=y1 {
                for x in x0..=x1 {
                    if covered(&img, (y * W + x) as usize) {
                        seen[(y * W + x) as usize] += 1;
                    }
                }
            }
        }
        for (i, &n) in seen.iter().enumerate() {
            assert_eq!(n, usize::from(covered(&img, i)), "pixel {i}");
        }
    }

    #[test]
    fn the_mesh_drawn_from_its_eye_shows_the_image() {
        // Two planes at different depths, a gap, windows: drawn from the capture's eye
        // with the tile's texture, every covered pixel shows its colour (to the 8-bit
        // target), every uncovered one stays clear.
        let img = image(|x, y| match x {
            0..=14 => Some((windows(x, y), 1.0 / (0.004 - x as f32 * 3e-6))),
            15..=16 => None,
            _ => Some((windows(x + 1, y), 600.0 + y as f32)),
        });
        let mut mesh = Mesh::default();
        span_mesh(&img, 0.25, &mut mesh, &mut Default::default());
        assert!(mesh.triangle_count() <= 2 * 4, "{}", mesh.triangle_count());
        let material = tile_material(Arc::new(image_texture(&img).expect("a texture")));
        let mut target = Target::new(W, H);
        let opts = FrameOptions {
            clear: Some(Rgba::TRANSPARENT),
            ..Default::default()
        };
        let cam = camera();
        let draw = Draw {
            mesh: &mesh,
            material: &material,
            transform: Mat4::IDENTITY,
        };
        Renderer::new().render(
            [draw],
            &cam,
            &engine::Lighting::default(),
            &mut target,
            &opts,
        );
        let seen = DepthImage::from_target(&target, &cam);
        for i in 0..(W * H) as usize {
            let (want, got) = (img.color[i], seen.color[i]);
            if covered(&img, i) {
                let d = [
                    want.r - got.r,
                    want.g - got.g,
                    want.b - got.b,
                    want.a - got.a,
                ];
                assert!(
                    d.iter().all(|d| d.abs() < 0.01),
                    "pixel {i}: {want:?} {got:?}"
                );
            } else {
                assert!(got.a == 0.0, "pixel {i} drawn: {got:?}");
            }
        }
    }
}

//! The far field's image mesh: a captured depth image drawn as quads at its pixels'
//! depths with their colours, one quad per run of pixels along a row whose colours and
//! depths the quad's linear interpolation reproduces (within [`COLOR_TOLERANCE`] and
//! [`DEPTH_TOLERANCE`]), instead of one per pixel: the field's objects are a few pixels
//! wide, so a tile's triangles were mostly sub-pixel quads, each set up and binned alone.
//! A run stops at an uncovered pixel, a colour edge (a window, a silhouette against
//! another object) or a depth step, so coverage, edges and parallax stay a pixel's.

use crate::core::DepthImage;
use engine::{Mesh, Rgba};
use glam::{Vec3, Vec4};

/// Largest difference per channel (linear, 0 to 1) between a pixel's colour and the run's
/// interpolation there: about a quarter of an 8-bit level in the mid-tones.
pub(super) const COLOR_TOLERANCE: f32 = 1.0 / 1024.0;

/// Largest relative difference between a pixel's depth and the run's interpolation there
/// (at 300 units, 0.6 units: a tenth of a pixel of parallax for the 18 units of eye motion
/// the world's field allows before its re-capture).
pub(super) const DEPTH_TOLERANCE: f32 = 0.002;

/// Largest change of colour per channel and of relative depth from one pixel of a run to
/// the next: a run holds no edge (two pixels of different surfaces would otherwise make
/// one, a slanted quad between them seen from another eye).
pub(super) const STEP: (f32, f32) = (4.0 / 1024.0, 0.01);

/// Longest run, pixels.
pub(super) const MAX_RUN: u32 = 64;

/// Whether pixel `i` of `image` is drawn: at least half covered, at a finite depth.
fn covered(image: &DepthImage, i: usize) -> bool {
    image.color[i].a >= 0.5 && image.depth[i].is_finite() && image.depth[i] > 0.0
}

/// The runs of row `y` of `image` (first and last pixel, inclusive), left to right: every
/// covered pixel in exactly one run, no uncovered pixel in any.
pub(super) fn runs(image: &DepthImage, y: u32, out: &mut Vec<(u32, u32)>) {
    out.clear();
    let w = image.width();
    let row = (y * w) as usize;
    let px = |x: u32| row + x as usize;
    let mut x = 0;
    while x < w {
        if !covered(image, px(x)) {
            x += 1;
            continue;
        }
        let mut end = x;
        while end + 1 < w && end + 1 - x < MAX_RUN && covered(image, px(end + 1)) {
            if !fits(image, (px(x), px(end + 1))) {
                break;
            }
            end += 1;
        }
        out.push((x, end));
        x = end + 1;
    }
}

/// Whether a run from `a` to `b - 1` (indices in one row, `a < b`) takes in `b`: no edge
/// between `b - 1` and `b` ([`STEP`]), and every pixel between `a` and `b` within tolerance
/// of the interpolation between the two, colours linear across the row, inverse depths
/// linear (a straight segment in space between the two pixels' points).
fn fits(image: &DepthImage, (a, b): (usize, usize)) -> bool {
    let (ca, cb) = (
        rgb(image.color[a].unpremultiply()),
        rgb(image.color[b].unpremultiply()),
    );
    let (ia, ib) = (1.0 / image.depth[a], 1.0 / image.depth[b]);
    let n = (b - a) as f32;
    let (c0, c1) = (
        image.color[b - 1].unpremultiply(),
        image.color[b].unpremultiply(),
    );
    let step = (rgb(c1) - rgb(c0)).abs().max_element() <= STEP.0
        && (image.depth[b] / image.depth[b - 1] - 1.0).abs() <= STEP.1;
    step && (a + 1..b).all(|i| {
        let t = (i - a) as f32 / n;
        let c = rgb(image.color[i].unpremultiply());
        let colour = (c - ca.lerp(cb, t)).abs().max_element() <= COLOR_TOLERANCE;
        let depth = (image.depth[i] * (ia + (ib - ia) * t) - 1.0).abs() <= DEPTH_TOLERANCE;
        colour && depth
    })
}

fn rgb(c: Rgba) -> Vec3 {
    Vec3::new(c.r, c.g, c.b)
}

/// Rebuilds `mesh` from `image` (a perspective capture): a quad per run of each row
/// ([`runs`]) at the run's depths along the axis, with its colours, grown by `grow` pixels
/// on every side so neighbouring quads of one surface leave no cracks when seen from a
/// nearby eye. The values at the run's ends are those of its end pixels' centres, carried
/// linearly to the quad's edges.
pub(super) fn span_mesh(image: &DepthImage, grow: f32, mesh: &mut Mesh) {
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
    let mut row = Vec::new();
    for y in 0..h {
        runs(image, y, &mut row);
        for &(x0, x1) in &row {
            let (a, b) = ((y * w + x0) as usize, (y * w + x1) as usize);
            let (ca, cb) = (
                image.color[a].unpremultiply(),
                image.color[b].unpremultiply(),
            );
            let (ia, ib) = (1.0 / image.depth[a], 1.0 / image.depth[b]);
            let span = (x1 - x0).max(1) as f32;
            // Inverse depth and colour at image x, from the end pixels' centres.
            let at = |sx: f32| {
                let t = if x1 > x0 {
                    (sx - (x0 as f32 + 0.5)) / span
                } else {
                    0.0
                };
                let inv = (ia + (ib - ia) * t).max(ia.min(ib) * 0.5);
                let c = rgb(ca).lerp(rgb(cb), t).clamp(Vec3::ZERO, Vec3::ONE);
                (1.0 / inv, Rgba::new(c.x, c.y, c.z, 1.0))
            };
            let base = mesh.positions.len() as u32;
            let (left, right) = (x0 as f32 - grow, x1 as f32 + 1.0 + grow);
            let (top, bottom) = (y as f32 - grow, y as f32 + 1.0 + grow);
            for (sx, sy) in [(left, top), (right, top), (left, bottom), (right, bottom)] {
                let (z, color) = at(sx);
                let v = (o + dx * sx + dy * sy) * z;
                mesh.positions.push(world.transform_point3(v));
                mesh.colors.push(color);
            }
            mesh.indices
                .extend([base, base + 2, base + 1, base + 1, base + 2, base + 3]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use engine::Camera;

    const W: u32 = 40;

    fn image(f: impl Fn(u32) -> Option<(Rgba, f32)>) -> DepthImage {
        let camera = Camera::look_at(Vec3::ZERO, -Vec3::Z, Vec3::Y, 1.0, W as f32 / 2.0)
            .with_depth_range(0.5, 1000.0);
        let mut image = DepthImage::new(W, 2, camera);
        for y in 0..2 {
            for x in 0..W {
                if let Some((c, z)) = f(x) {
                    let i = (y * W + x) as usize;
                    image.color[i] = c.premultiply();
                    image.depth[i] = z;
                }
            }
        }
        image
    }

    fn runs_of(image: &DepthImage) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        runs(image, 1, &mut out);
        out
    }

    #[test]
    fn a_plane_of_one_colour_is_one_run_a_row() {
        // A plane slanting away (inverse depth linear across the row), one colour: a quad
        // a row, 2 triangles, where one per pixel is 80.
        let img = image(|x| {
            Some((
                Rgba::new(0.3, 0.5, 0.2, 1.0),
                1.0 / (0.01 - x as f32 * 2e-5),
            ))
        });
        assert_eq!(runs_of(&img), vec![(0, W - 1)]);
        let mut mesh = Mesh::default();
        span_mesh(&img, 0.25, &mut mesh);
        assert_eq!(mesh.triangle_count(), 2 * 2);
    }

    #[test]
    fn runs_cover_each_covered_pixel_once_and_stop_at_edges() {
        // Pixels 0-9 grey at 300, 10-14 empty, 15-24 alternating colours (a pixel each),
        // 25-39 grey with a depth step at 32 (300 -> 500).
        let grey = Rgba::new(0.4, 0.4, 0.4, 1.0);
        let img = image(|x| match x {
            0..=9 => Some((grey, 300.0)),
            10..=14 => None,
            15..=24 => Some((Rgba::new((x % 2) as f32, 0.0, 0.0, 1.0), 300.0)),
            25..=31 => Some((grey, 300.0)),
            _ => Some((grey, 500.0)),
        });
        let got = runs_of(&img);
        let mut expected = vec![(0, 9)];
        expected.extend((15..=24).map(|x| (x, x)));
        expected.extend([(25, 31), (32, 39)]);
        assert_eq!(got, expected);
        let mut mesh = Mesh::default();
        span_mesh(&img, 0.25, &mut mesh);
        assert_eq!(mesh.triangle_count(), 2 * 2 * expected.len());
    }

    #[test]
    fn a_gradient_within_tolerance_is_one_run_and_its_colours_are_kept() {
        // A linear ramp of colour: one run; the quad's end colours reproduce the ramp at
        // the pixel centres (carried half a pixel and the growth beyond them).
        let img = image(|x| Some((Rgba::new(0.2 + 0.002 * x as f32, 0.5, 0.5, 1.0), 400.0)));
        assert_eq!(runs_of(&img), vec![(0, W - 1)]);
        let mut mesh = Mesh::default();
        span_mesh(&img, 0.0, &mut mesh);
        // Row 0's quad: left edge x = 0 holds the colour half a pixel before pixel 0's.
        let left = mesh.colors[0].r;
        assert!((left - (0.2 - 0.001)).abs() < 1e-4, "{left}");
        let right = mesh.colors[1].r;
        assert!(
            (right - (0.2 + 0.002 * (W as f32 - 0.5))).abs() < 1e-4,
            "{right}"
        );
    }
}

//! Relief impostors (a nailboard after Schaufler 1997, as a mesh): an image drawn on a grid
//! whose nodes stand on the subject's captured surface instead of on a flat quad. Each node
//! lies on the capture ray through its texel position, at the view depth the capture
//! stored there, so from the capture eye the grid covers exactly the flat quad's pixels
//! with the same texels, and from any eye its depth is the subject's (to within a cell's
//! curvature): geometry and images in front of or behind one another occlude per pixel, as
//! their geometry would, instead of at one depth for the whole image.
//!
//! A node on a covered texel takes the nearest of the covered texels round its position;
//! a node outside the silhouette, the nearest covered texel within a cell of it (so a
//! cell on the outline is not stretched to the background); a node with none within a
//! cell borders only empty cells and stays on the quad's plane.
//!
//! For a subject that fills its box ([`Subject::corners`]: a building), the image is
//! instead projected onto that box ([`write_box`]; view-dependent texture mapping onto a
//! proxy after Debevec et al. 1996): each face split into cells, each vertex taking the
//! texel position it projects to from the capture eye. The outline and depth are then the
//! box's, exact from any eye, instead of a cutout of filtered coverage half a texel off;
//! the image's covered texels are spread two texels outward ([`dilate`]), so samples on
//! the outline read the wall's colour, not the transparent background's. A face the
//! capture eye saw edge-on or from behind has no texels across it: once it shows at an
//! angle ([`face_stretch`] over [`MAX_STRETCH`]) the image is invalid and taken again.
//!
//! [`Subject::corners`]: crate::core::Subject::corners

use super::Capture;
use crate::core::Rect;
use engine::{Camera, Mesh, Target};
use glam::{Vec2, Vec3};

/// Texels a side of one cell, about (8 texels: 4 screen pixels at the city's 2 texels a
/// pixel); no more than [`MAX_CELLS`] a side.
pub(super) const CELL_TEXELS: u32 = 8;
/// Most cells a side (a 512-texel capture's covered square: 32 x 32 cells).
pub(super) const MAX_CELLS: u32 = 32;

/// A relief's grid: its cells a side and its nodes' view depths (capture camera), row by
/// row from the top, `(cells.x + 1) * (cells.y + 1)` of them.
#[derive(Clone, Debug, Default)]
pub(super) struct Grid {
    pub(super) rect: Option<Rect>,
    pub(super) cells: (u32, u32),
    pub(super) depth: Vec<f32>,
}

/// Cells along a side of `texels` texels.
fn cells(texels: u32) -> u32 {
    texels.div_ceil(CELL_TEXELS).clamp(1, MAX_CELLS)
}

/// The node depths of the relief over `rect` (texels) of the capture `t` taken by `c`.
pub(super) fn grid(t: &Target, c: &Capture, rect: Rect, out: &mut Grid) {
    let camera = c.camera();
    let plane = c.eye.distance(c.center);
    let (nx, ny) = (cells(rect.width), cells(rect.height));
    out.rect = Some(rect);
    out.cells = (nx, ny);
    out.depth.clear();
    let (cw, ch) = (
        rect.width.div_ceil(nx) as i64,
        rect.height.div_ceil(ny) as i64,
    );
    for gy in 0..=ny {
        for gx in 0..=nx {
            let (tx, ty) = node_texel(rect, (nx, ny), gx, gy);
            let (x, y) = (tx.floor() as i64, ty.floor() as i64);
            // The texels touching the node's position, else within a cell of it.
            let d = nearest(t, &camera, (x - 1, y - 1), (x, y))
                .or_else(|| nearest(t, &camera, (x - cw, y - ch), (x + cw - 1, y + ch - 1)))
                .unwrap_or(plane);
            out.depth.push(d);
        }
    }
}

/// Node `(gx, gy)`'s position in texels (continuous: 0 at the image's left or top edge).
fn node_texel(rect: Rect, (nx, ny): (u32, u32), gx: u32, gy: u32) -> (f32, f32) {
    let f = |at: u32, len: u32, g: u32, n: u32| at as f32 + len as f32 * g as f32 / n as f32;
    (
        f(rect.x, rect.width, gx, nx),
        f(rect.y, rect.height, gy, ny),
    )
}

/// The smallest view depth of the covered texels in the inclusive box `lo`..=`hi`
/// (clipped to the image), if any.
fn nearest(t: &Target, camera: &Camera, lo: (i64, i64), hi: (i64, i64)) -> Option<f32> {
    let (w, h) = (t.width() as i64, t.height() as i64);
    let mut best: Option<f32> = None;
    for y in lo.1.max(0)..=hi.1.min(h - 1) {
        for x in lo.0.max(0)..=hi.0.min(w - 1) {
            let d = t.depth_reversed(x as u32, y as u32).unwrap_or(0.0);
            if d > 0.0 {
                let v = camera.view_depth_from_reversed(d);
                best = Some(best.map_or(v, |b| b.min(v)));
            }
        }
    }
    best
}

/// Writes the relief of `g` into `m` (cleared): positions on the capture's rays at the
/// nodes' depths, texture coordinates the nodes' texel positions, two triangles a cell
/// facing the capture eye. Returns the share of the capture's square it covers.
pub(super) fn write(c: &Capture, g: &Grid, m: &mut Mesh) -> f32 {
    m.clear();
    let Some(rect) = g.rect else {
        return 0.0;
    };
    let (nx, ny) = g.cells;
    let side = c.side as f32;
    let plane = c.eye.distance(c.center);
    let [bl, _, tr, tl] = c.corners;
    let (across, down) = (tr - tl, bl - tl);
    for gy in 0..=ny {
        for gx in 0..=nx {
            let (tx, ty) = node_texel(rect, (nx, ny), gx, gy);
            let uv = Vec2::new(tx, ty) / side;
            let flat = tl + across * uv.x + down * uv.y;
            let d = g.depth[(gy * (nx + 1) + gx) as usize];
            m.positions.push(c.eye + (flat - c.eye) * (d / plane));
            m.uvs.push(uv);
        }
    }
    crate::core::grid_triangles(nx, ny, 0, &mut m.indices);
    (rect.width as f32 / side) * (rect.height as f32 / side)
}

/// Cells a side of a box face at most; fewer when the face spans fewer texels
/// ([`BOX_CELL_TEXELS`] a cell). Texture coordinates interpolate linearly over a cell, while
/// the capture's projection of a receding face is not linear: small cells keep the
/// difference under a texel.
const BOX_MAX_CELLS: u32 = 8;
/// Texels a box cell spans along its longer edge, at most (unless [`BOX_MAX_CELLS`]).
const BOX_CELL_TEXELS: f32 = 24.0;

/// Where world point `p` lands in capture `c`'s image, in texels (continuous).
fn texel_of(c: &Capture, p: Vec3) -> Vec2 {
    let [bl, _, tr, tl] = c.corners;
    let axis = (c.center - c.eye).normalize_or_zero();
    let plane = c.eye.distance(c.center);
    let along = (p - c.eye).dot(axis).max(1e-6);
    let q = c.eye + (p - c.eye) * (plane / along);
    let (across, down) = (tr - tl, bl - tl);
    let uv = Vec2::new(
        (q - tl).dot(across) / across.length_squared().max(1e-12),
        (q - tl).dot(down) / down.length_squared().max(1e-12),
    );
    uv * c.side as f32
}

/// Writes the box `corners` (as [`crate::core::box_corners`] orders them) into `m`
/// (cleared), its six faces split into cells, each vertex's texture coordinates where the
/// capture `c` saw it. Returns the share of the capture's square the box covers in it
/// (its projected bounds, clipped).
pub(super) fn write_box(c: &Capture, corners: &[Vec3; 8], m: &mut Mesh) -> f32 {
    m.clear();
    let side = c.side as f32;
    let (mut lo, mut hi) = (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN));
    for face in 0..6 {
        let (axis, s) = (face / 2, face % 2);
        let (b, cc) = ((axis + 1) % 3, (axis + 2) % 3);
        let at = |kb: usize, kc: usize| corners[(s << axis) | (kb << b) | (kc << cc)];
        let quad = [at(0, 0), at(1, 0), at(1, 1), at(0, 1)];
        let t: Vec<Vec2> = quad.iter().map(|&p| texel_of(c, p)).collect();
        let longest = (0..4)
            .map(|k| t[k].distance(t[(k + 1) % 4]))
            .fold(0.0, f32::max);
        let n = ((longest / BOX_CELL_TEXELS).ceil() as u32).clamp(1, BOX_MAX_CELLS);
        let base = m.positions.len() as u32;
        for j in 0..=n {
            for i in 0..=n {
                let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
                let p = quad[0].lerp(quad[1], x).lerp(quad[3].lerp(quad[2], x), y);
                let texel = texel_of(c, p);
                (lo, hi) = (lo.min(texel), hi.max(texel));
                m.positions.push(p);
                m.uvs.push(texel / side);
            }
        }
        let at = |i: u32, j: u32| base + j * (n + 1) + i;
        for j in 0..n {
            for i in 0..n {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                m.indices.extend_from_slice(&[a, b, c, a, c, d]);
            }
        }
    }
    let (lo, hi) = (
        lo.clamp(Vec2::ZERO, Vec2::splat(side)),
        hi.clamp(Vec2::ZERO, Vec2::splat(side)),
    );
    let size = (hi - lo) / side;
    size.x * size.y
}

/// Screen pixels a capture texel spans across a box face, at most over the faces of the
/// box `corners` that face `eye` and are at least [`STRETCH_MIN_PX`] wide there:
/// `px_per_radian` on screen against the capture's texels per radian, times how much
/// nearer and less foreshortened the face is now than from the capture eye. A face seen
/// edge-on from the capture eye holds no texels across (the image has one column of it,
/// or none): seen at an angle now, that column is stretched over its width (infinite when
/// the capture eye saw the face's back). A fresh image, taken `density` texels a pixel,
/// gives `1 / density` on every face.
pub(super) fn face_stretch(c: &Capture, corners: &[Vec3; 8], eye: Vec3, px_per_radian: f32) -> f32 {
    let texels_per_radian = c.side as f32 / (2.0 * c.half_fov.tan()).max(1e-6);
    let middle = corners.iter().copied().sum::<Vec3>() / 8.0;
    let mut worst = 0.0f32;
    for face in 0..6 {
        let (axis, s) = (face / 2, face % 2);
        let (b, cc) = ((axis + 1) % 3, (axis + 2) % 3);
        let at = |kb: usize, kc: usize| corners[(s << axis) | (kb << b) | (kc << cc)];
        let (o, u, v) = (at(0, 0), at(1, 0) - at(0, 0), at(0, 1) - at(0, 0));
        let centre = o + 0.5 * (u + v);
        let normal = u.cross(v);
        let area = normal.length();
        let long = u.length().max(v.length());
        if !(area > 0.0 && long > 0.0) {
            continue;
        }
        let outward = (centre - middle).dot(normal).signum();
        let normal = normal / area * if outward == 0.0 { 1.0 } else { outward };
        // The face's width across (its area seen from `from` over its longer edge), radians.
        let across = |from: Vec3| {
            let to = from - centre;
            let d = to.length().max(1e-6);
            area * normal.dot(to / d) / (d * long)
        };
        let px = across(eye) * px_per_radian;
        if px < STRETCH_MIN_PX {
            continue;
        }
        let texels = across(c.eye) * texels_per_radian;
        let stretch = if texels > 1e-6 {
            px / texels
        } else {
            f32::INFINITY
        };
        worst = worst.max(stretch);
    }
    worst
}

/// Faces narrower than this on screen, pixels, are not judged by [`face_stretch`]: a
/// face seen edge-on from the eye too shows at most a stray pixel's column.
pub(super) const STRETCH_MIN_PX: f32 = 1.0;

/// The most screen pixels a capture texel may span across a box face before the image is
/// invalid ([`face_stretch`]): one texel a pixel, as the city's texel density goal.
pub(super) const MAX_STRETCH: f32 = 1.0;

/// Copies `t`'s image into `out` (row-major), each empty texel within two texels of the
/// covered ones (4-neighbours, one ring at a time) taking a covered neighbour's texel:
/// the first of left, right, above, below. Only `rect` grown by two is looked at.
pub(super) fn dilate(t: &Target, rect: Rect, out: &mut Vec<u32>, scratch: &mut Vec<u32>) {
    let (w, h) = (t.width(), t.height());
    out.clear();
    out.resize(w as usize * h as usize, 0);
    let mut depth = Vec::new();
    for y in 0..h {
        t.read_row(y, scratch, &mut depth);
        let at = y as usize * w as usize;
        out[at..at + w as usize].copy_from_slice(scratch);
    }
    let r = rect.grow(2, w, h);
    for _ in 0..2 {
        scratch.clone_from(out);
        for y in r.y..r.y + r.height {
            for x in r.x..r.x + r.width {
                let i = (y * w + x) as usize;
                if scratch[i] >> 24 != 0 {
                    continue;
                }
                let near = [
                    (x > 0).then_some(i.wrapping_sub(1)),
                    (x + 1 < w).then_some(i + 1),
                    (y > 0).then_some(i.wrapping_sub(w as usize)),
                    (y + 1 < h).then_some(i + w as usize),
                ];
                if let Some(k) = near.into_iter().flatten().find(|&k| scratch[k] >> 24 != 0) {
                    out[i] = scratch[k];
                }
            }
        }
    }
}

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

use super::Capture;
use crate::core::Rect;
use engine::{Camera, Mesh, Target};
use glam::Vec2;

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
    let at = |x: u32, y: u32| y * (nx + 1) + x;
    for gy in 0..ny {
        for gx in 0..nx {
            // Bottom-left, bottom-right, top-right, top-left as seen (v grows downward).
            let (a, b, c, d) = (
                at(gx, gy + 1),
                at(gx + 1, gy + 1),
                at(gx + 1, gy),
                at(gx, gy),
            );
            m.indices.extend_from_slice(&[a, b, c, a, c, d]);
        }
    }
    (rect.width as f32 / side) * (rect.height as f32 / side)
}

//! Setup stage: clip-space triangles -> screen-space [`Tri`]s with vertices snapped to
//! fixed point (`SUBPIXEL_BITS` sub-pixel bits), exact integer edge functions, a pixel
//! bounding box, and the planes the rasterizer interpolates.
//!
//! Screen space: x right, y down, pixel centres at `(x + 0.5, y + 0.5)`. After setup every
//! triangle winds so that its edge functions are positive inside; `FRONT` remembers whether
//! it was front-facing (counter-clockwise in NDC) before that. Triangles that are degenerate
//! (zero area) or cover no pixel centre's bounding box are dropped here.

use crate::space::{small_cover, ScreenVert, Viewport, ONE, SMALL};

/// [`Tri::flags`] bit: the triangle was front-facing.
pub const FRONT: u32 = 1;
/// [`Tri::flags`] bit: its varyings live in the chunk's clipped-vertex buffer.
pub const CLIPPED: u32 = 2;
/// [`Tri::flags`] bit: a small triangle, which carries its coverage mask instead of its
/// vertices.
const COVER: u32 = 4;
/// Where the flags sit in [`Tri`]'s draw word.
const FLAG_SHIFT: u32 = 29;

/// A linear function of screen position: `value = c + dx * (x - rx) + dy * (y - ry)`,
/// evaluated at pixel centres, where `(rx, ry)` is the triangle's bounding-box corner.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Plane {
    pub c: f32,
    pub dx: f32,
    pub dy: f32,
}

/// A set-up triangle, ready for binning and rasterization: 96 bytes, written once by the
/// front end and read by every tile it touches, so each field earns its place (at 1M
/// triangles a frame, 24 more bytes each cost about 2 ms of front end on two threads).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tri {
    /// Walked triangles: vertex positions in fixed point (pixels << SUBPIXEL_BITS),
    /// positive winding, `[x0, x1, x2, y0, y1, y2]`. Small ones: their coverage mask, low
    /// word first (see [`Tri::cover`]).
    shape: [i32; 6],
    /// Inclusive pixel bounding box, clamped to the target: `[x0, y0, x1, y1]`.
    pub bbox: [u16; 4],
    /// Reversed depth (interpolated linearly in screen space).
    pub z: Plane,
    /// 1 / w.
    pub iw: Plane,
    /// Barycentric weights of vertices 1 and 2, divided by w.
    pub l1: Plane,
    pub l2: Plane,
    /// Index into the frame's draw list, with the flags in the top bits.
    draw_flags: u32,
    /// Offsets (in floats) of the three vertices' varyings. Per-face shadings read no
    /// varyings: for them the first is the packed face colour ([`Tri::color`]).
    pub vary: [u32; 3],
}

const _: () = assert!(size_of::<Tri>() == 96);

impl Tri {
    /// Coverage of a small triangle: bit `SMALL * j + i` is pixel `(bbox[0] + i, bbox[1] +
    /// j)`, exactly as the edge walk would find it; 0 for the others, which are walked.
    #[inline]
    pub fn cover(&self) -> u64 {
        if self.flags() & COVER == 0 {
            return 0;
        }
        self.shape[0] as u32 as u64 | (self.shape[1] as u32 as u64) << 32
    }

    /// Vertex positions in fixed point, `(x, y)`; for walked triangles only (a small one
    /// keeps its mask in their place, and this returns `None`).
    #[inline]
    pub fn vertices(&self) -> Option<([i32; 3], [i32; 3])> {
        let s = &self.shape;
        (self.flags() & COVER == 0).then_some(([s[0], s[1], s[2]], [s[3], s[4], s[5]]))
    }

    /// Index into the frame's draw list.
    #[inline]
    pub fn draw(&self) -> u32 {
        self.draw_flags & ((1 << FLAG_SHIFT) - 1)
    }

    /// `FRONT` and `CLIPPED` bits.
    #[inline]
    pub fn flags(&self) -> u32 {
        self.draw_flags >> FLAG_SHIFT
    }

    /// Packed constant colour, for per-face shadings.
    #[inline]
    pub fn color(&self) -> u32 {
        self.vary[0]
    }

    /// Stamps the draw index (at most 2^29 draws a frame; higher bits are dropped) and
    /// adds `flags`.
    #[inline]
    pub(crate) fn stamp(&mut self, draw: u32, flags: u32) {
        self.draw_flags = (self.draw_flags & !((1 << FLAG_SHIFT) - 1))
            | draw & ((1 << FLAG_SHIFT) - 1)
            | flags << FLAG_SHIFT;
    }

    /// A triangle with only a box and an id (in `vary[0]`), for tests of the stages after setup.
    #[cfg(test)]
    pub(crate) fn with_box(bbox: [u16; 4], id: u32) -> Tri {
        Tri {
            shape: [0; 6],
            bbox,
            z: Plane::default(),
            iw: Plane::default(),
            l1: Plane::default(),
            l2: Plane::default(),
            draw_flags: 0,
            vary: [id, 0, 0],
        }
    }

    /// Sets the packed face colour of a per-face shading (which reads no varyings).
    #[inline]
    pub(crate) fn set_color(&mut self, color: u32) {
        self.vary = [color, 0, 0];
    }
}

/// Why setup dropped a triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dropped {
    Culled,
    Rejected,
}

/// Sets up one triangle. `vary` are the vertices' varying offsets, `cull_back` drops
/// back-facing triangles.
#[inline(always)]
pub fn setup(
    v: [ScreenVert; 3],
    vary: [u32; 3],
    cull_back: bool,
    vp: &Viewport,
) -> Result<Tri, Dropped> {
    let (x0, y0) = (v[0].x as i64, v[0].y as i64);
    let area =
        (v[1].x as i64 - x0) * (v[2].y as i64 - y0) - (v[2].x as i64 - x0) * (v[1].y as i64 - y0);
    if area == 0 {
        return Err(Dropped::Rejected);
    }
    // y points down on screen, so counter-clockwise in NDC has negative area here.
    let front = area < 0;
    if cull_back && !front {
        return Err(Dropped::Culled);
    }
    let (v, vary) = if area < 0 {
        ([v[0], v[2], v[1]], [vary[0], vary[2], vary[1]])
    } else {
        (v, vary)
    };
    // Pixel centres inside the bounding box: px * ONE + ONE/2 in [min, max].
    let (min_x, max_x) = (
        v.iter().map(|p| p.x).min().unwrap_or(0),
        v.iter().map(|p| p.x).max().unwrap_or(0),
    );
    let (min_y, max_y) = (
        v.iter().map(|p| p.y).min().unwrap_or(0),
        v.iter().map(|p| p.y).max().unwrap_or(0),
    );
    let first = |m: i32| (m as i64 - ONE / 2 + ONE - 1).div_euclid(ONE);
    let last = |m: i32| (m as i64 - ONE / 2).div_euclid(ONE);
    let bx0 = first(min_x).max(0);
    let by0 = first(min_y).max(0);
    let bx1 = last(max_x).min(vp.width as i64 - 1);
    let by1 = last(max_y).min(vp.height as i64 - 1);
    if bx0 > bx1 || by0 > by1 {
        return Err(Dropped::Rejected);
    }
    // Small triangles (at most `SMALL` x `SMALL` candidate pixel centres) get their exact
    // coverage now, as a bit mask the rasterizer reads instead of walking edges; those that
    // cover no pixel centre are dropped rather than binned (at 1M triangles and 1920x1080
    // about a third of them).
    let cover = if max_x - min_x < SMALL * ONE as i32 && max_y - min_y < SMALL * ONE as i32 {
        let xs = [v[0].x, v[1].x, v[2].x];
        let ys = [v[0].y, v[1].y, v[2].y];
        match small_cover(&xs, &ys, [bx0, by0, bx1, by1]) {
            0 => return Err(Dropped::Rejected),
            m => m,
        }
    } else {
        0
    };
    // Planes in f64, relative to v0, referenced at the bbox corner. They use the exact
    // (unsnapped) positions: snapping moves a vertex by up to 1/512 pixel, which tilts the
    // depth plane of long thin triangles (clipped fans) measurably. Snapped positions are
    // the fallback when the exact ones are degenerate.
    let inv = 1.0 / ONE as f64;
    let snapped = |k: usize| (v[k].x as f64 * inv, v[k].y as f64 * inv);
    let exact = |k: usize| (v[k].fx, v[k].fy);
    let geometry = |pos: &dyn Fn(usize) -> (f64, f64)| {
        let (p0, p1, p2) = (pos(0), pos(1), pos(2));
        let (dx1, dy1, dx2, dy2) = (p1.0 - p0.0, p1.1 - p0.1, p2.0 - p0.0, p2.1 - p0.1);
        (p0, dx1, dy1, dx2, dy2, dx1 * dy2 - dx2 * dy1)
    };
    let g = geometry(&exact);
    let (p0, dx1, dy1, dx2, dy2, det) = if g.5 > 0.0 && g.5.is_finite() {
        g
    } else {
        geometry(&snapped)
    };
    let inv_det = 1.0 / det;
    let (rx, ry) = (bx0 as f64 + 0.5 - p0.0, by0 as f64 + 0.5 - p0.1);
    // The four planes (depth, 1/w, l1, l2) side by side, so the compiler can use 4-wide f64.
    let iw = [v[0].iw, v[1].iw, v[2].iw];
    let f0 = [v[0].z, iw[0], 0.0, 0.0];
    let f1 = [v[1].z, iw[1], iw[1], 0.0];
    let f2 = [v[2].z, iw[2], 0.0, iw[2]];
    let mut planes = [Plane::default(); 4];
    for k in 0..4 {
        let (df1, df2) = (f1[k] - f0[k], f2[k] - f0[k]);
        let a = (df1 * dy2 - df2 * dy1) * inv_det;
        let b = (dx1 * df2 - dx2 * df1) * inv_det;
        planes[k] = Plane {
            c: (f0[k] + a * rx + b * ry) as f32,
            dx: a as f32,
            dy: b as f32,
        };
    }
    let mut flags = if front { FRONT } else { 0 };
    let shape = if cover != 0 {
        flags |= COVER;
        [cover as u32 as i32, (cover >> 32) as u32 as i32, 0, 0, 0, 0]
    } else {
        [v[0].x, v[1].x, v[2].x, v[0].y, v[1].y, v[2].y]
    };
    Ok(Tri {
        shape,
        bbox: [bx0 as u16, by0 as u16, bx1 as u16, by1 as u16],
        z: planes[0],
        iw: planes[1],
        l1: planes[2],
        l2: planes[3],
        draw_flags: flags << FLAG_SHIFT,
        vary,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;

    const VP: Viewport = Viewport {
        width: 100,
        height: 100,
    };

    fn sv(x: f32, y: f32) -> ScreenVert {
        ScreenVert {
            x: (x * ONE as f32) as i32,
            y: (y * ONE as f32) as i32,
            fx: x as f64,
            fy: y as f64,
            z: 0.5,
            iw: 1.0,
        }
    }

    #[test]
    fn winding_and_culling() {
        // clockwise on a y-down screen = counter-clockwise in NDC = front
        let front = [sv(10.0, 10.0), sv(10.0, 20.0), sv(20.0, 10.0)];
        let t = setup(front, [0, 1, 2], true, &VP).unwrap();
        assert_eq!(t.flags() & FRONT, FRONT);
        let back = [front[0], front[2], front[1]];
        assert_eq!(setup(back, [0, 1, 2], true, &VP), Err(Dropped::Culled));
        let t = setup(back, [0, 1, 2], false, &VP).unwrap();
        assert_eq!(t.flags() & FRONT, 0);
    }

    #[test]
    fn degenerate_and_pixelless_triangles_are_dropped() {
        let line = [sv(1.0, 1.0), sv(5.0, 5.0), sv(9.0, 9.0)];
        assert_eq!(setup(line, [0; 3], false, &VP), Err(Dropped::Rejected));
        // a sliver between pixel centres 10.5 and 11.5
        let tiny = [sv(10.6, 10.6), sv(10.9, 10.6), sv(10.6, 10.9)];
        assert_eq!(setup(tiny, [0; 3], false, &VP), Err(Dropped::Rejected));
        let off = [sv(-50.0, 10.0), sv(-40.0, 10.0), sv(-45.0, 20.0)];
        assert_eq!(setup(off, [0; 3], false, &VP), Err(Dropped::Rejected));
    }

    /// Independent reference: pixel centre `(px, py)` is covered when it is strictly inside
    /// every edge, or on an edge that is a top edge (horizontal, interior below) or a left
    /// edge (interior to its right), for a triangle wound positively on the y-down screen.
    fn covered(x: [i64; 3], y: [i64; 3], px: i64, py: i64) -> bool {
        let (cx, cy) = (px * ONE + ONE / 2, py * ONE + ONE / 2);
        (0..3).all(|i| {
            let (p, q) = ((i + 1) % 3, (i + 2) % 3);
            let (ex, ey) = (x[q] - x[p], y[q] - y[p]);
            let cross = ex * (cy - y[p]) - ey * (cx - x[p]);
            let top_left = ey < 0 || (ey == 0 && ex > 0);
            cross > 0 || (cross == 0 && top_left)
        })
    }

    proptest::proptest! {
        #[test]
        fn small_masks_follow_the_fill_rule(
            ox in 0i32..60, oy in 0i32..60,
            d in proptest::collection::vec(0i32..(SMALL * ONE as i32), 6),
            on_grid in proptest::bool::ANY,
        ) {
            // Vertices on the 1/256 grid, or on the half-pixel grid where centres sit on edges.
            let q = |v: i32| if on_grid { v / 128 * 128 } else { v };
            let vert = |k: usize| {
                let (x, y) = (ox * ONE as i32 + q(d[2 * k]), oy * ONE as i32 + q(d[2 * k + 1]));
                ScreenVert { x, y, fx: x as f64 / ONE as f64, fy: y as f64 / ONE as f64, z: 0.5, iw: 1.0 }
            };
            let vp = Viewport { width: 62, height: 61 };
            let v = [vert(0), vert(1), vert(2)];
            match setup(v, [0; 3], false, &vp) {
                Ok(t) => {
                    proptest::prop_assert!(t.cover() != 0);
                    // Setup may have swapped two vertices to make the winding positive; only
                    // that winding covers anything.
                    let (xs, ys) = (v.map(|p| p.x as i64), v.map(|p| p.y as i64));
                    let rev = ([xs[0], xs[2], xs[1]], [ys[0], ys[2], ys[1]]);
                    for j in 0..SMALL as i64 {
                        for i in 0..SMALL as i64 {
                            let (px, py) = (t.bbox[0] as i64 + i, t.bbox[1] as i64 + j);
                            let inside_target = px <= t.bbox[2] as i64 && py <= t.bbox[3] as i64;
                            let want = inside_target
                                && (covered(xs, ys, px, py) || covered(rev.0, rev.1, px, py));
                            let got = t.cover() >> (SMALL as i64 * j + i) & 1 != 0;
                            proptest::prop_assert_eq!(got, want, "pixel ({}, {})", px, py);
                        }
                    }
                }
                Err(_) => {
                    // Dropped: no pixel centre of the target is covered, whatever the winding.
                    let (xs, ys) = (v.map(|p| p.x as i64), v.map(|p| p.y as i64));
                    let rev = ([xs[0], xs[2], xs[1]], [ys[0], ys[2], ys[1]]);
                    for py in 0..vp.height as i64 {
                        for px in 0..vp.width as i64 {
                            proptest::prop_assert!(!covered(xs, ys, px, py) && !covered(rev.0, rev.1, px, py));
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn planes_reproduce_vertex_values() {
        let mut v = [sv(0.5, 0.5), sv(8.5, 0.5), sv(0.5, 4.5)];
        v[0].z = 0.2;
        v[1].z = 0.6;
        v[2].z = 1.0;
        let t = setup(v, [0; 3], false, &VP).unwrap();
        // reference corner is pixel (0, 0), whose centre is v0
        assert!((t.z.c - 0.2).abs() < 1e-6);
        assert!((t.z.c + 8.0 * t.z.dx - 0.6).abs() < 1e-6);
        assert!((t.z.c + 4.0 * t.z.dy - 1.0).abs() < 1e-6);
    }

    #[test]
    fn non_finite_positions_are_refused() {
        assert!(VP.to_screen(Vec4::new(f32::NAN, 0.0, 0.5, 1.0)).is_none());
        assert!(VP.to_screen(Vec4::new(0.0, 0.0, 0.5, 0.0)).is_none());
        let huge = VP.to_screen(Vec4::new(1e30, -1e30, 0.5, 1.0)).unwrap();
        assert!(
            huge.x > 0 && huge.y > 0,
            "y is flipped: NDC -y is screen +y"
        );
    }
}

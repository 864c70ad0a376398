//! The outline from geometry ([`super::LightFieldObject::proxy_outline`]): a light field
//! gives a surface's colour well between its cameras but its outline only to within a
//! sample (coverage blended between samples that are in or out, depth correction failing
//! where cameras disagree), and the outline is most of its error. With the object's
//! geometry kept, its coverage and depth are rasterised through the light-field image's
//! own camera (depth only, one unlit material, a few thousand triangles) and the image is
//! made to agree with them: what the geometry does not cover is a hole; what it covers is
//! opaque, at the geometry's depth, coloured by the light field (un-premultiplied) where
//! the light field found that surface there, else filled from the nearest pixel that did
//! on the same surface. The light field supplies the colour (lighting, view dependence),
//! the geometry the outline: Gortler et al.'s lumigraph with its proxy exact.
//!
//! The rules, in [`conform`]: a pixel keeps its light-field colour when its alpha is at
//! least [`MIN_ALPHA`] and its disparity is within [`SAME_SURFACE`] of the geometry's; the
//! others the geometry covers are filled in rounds, each taking, of its eight neighbours
//! filled before the round, the one whose geometry disparity is nearest its own (a pixel
//! no round reaches stays a hole). Sequential and in a fixed order: the same at any thread
//! count.

use crate::core::MeshGroup;
use crate::core::Subject;
use crate::warp::{Warped, ENCODING, HOLE};
use engine::color::{unpack, Encoder};
use engine::{Camera, Draw, FrameOptions, Lighting, Material, Renderer, Rgba, Target};

/// Relative disparity difference within which the light field's surface is taken to be the
/// geometry's.
pub(crate) const SAME_SURFACE: f32 = 0.05;

/// Coverage under which a light-field pixel's colour, un-premultiplied, is too coarse to
/// keep (8-bit colour divided by a small alpha): it is filled instead.
pub(crate) const MIN_ALPHA: u32 = 64;

/// Fill rounds: a pixel more than this many pixels from one the light field coloured
/// stays a hole.
const ROUNDS: usize = 16;

/// What the outline keeps from frame to frame: a renderer, its target and row buffers,
/// the geometry's disparity and each row's covered span.
#[derive(Debug)]
pub(crate) struct Outline {
    renderer: Renderer,
    target: Target,
    material: Material,
    proxy: Vec<f32>,
    /// Each row's pixels `x0..x1` from the first the geometry covers to the last (empty
    /// where it covers none), for [`super::render::render_within`].
    spans: Vec<(u32, u32)>,
    row: (Vec<u32>, Vec<f32>),
    fill: Fill,
}

impl Default for Outline {
    fn default() -> Self {
        Outline {
            renderer: Renderer::new(),
            target: Target::new(0, 0),
            material: Material::unlit(Rgba::WHITE),
            proxy: Vec::new(),
            spans: Vec::new(),
            row: (Vec::new(), Vec::new()),
            fill: Fill::default(),
        }
    }
}

impl Outline {
    /// Rasterises `geometry`'s coverage and disparity through `camera` into a `w` x `h`
    /// image, and each row's covered span ([`Outline::spans`]): [`conform`] keeps the
    /// light field's pixels only where the geometry covers, so a render need not look up
    /// the others' rays.
    pub(crate) fn cover(&mut self, geometry: &MeshGroup, camera: &Camera, w: u32, h: u32) {
        self.proxy.clear();
        self.spans.clear();
        if w == 0 || h == 0 {
            return;
        }
        if self.target.width() != w || self.target.height() != h {
            // Resized in place: the statue's rectangle changes size nearly every frame,
            // and a new target each time was a fresh allocation and its page faults in
            // the timed frame (session 19's fault profile, 85 samples at 720p).
            self.target.resize(w, h);
        }
        let mut draws: Vec<Draw<'_>> = Vec::new();
        geometry.draws(&mut draws);
        let material = &self.material;
        let draws = draws.into_iter().map(|d| Draw { material, ..d });
        let opts = FrameOptions {
            clear: Some(Rgba::TRANSPARENT),
            ..Default::default()
        };
        let lighting = Lighting::default();
        self.renderer
            .render(draws, camera, &lighting, &mut self.target, &opts);
        let (colors, depths) = &mut self.row;
        for y in 0..h {
            self.target.read_row(y, colors, depths);
            let first = depths.iter().position(|&d| d > 0.0);
            let last = depths.iter().rposition(|&d| d > 0.0);
            self.spans.push(match (first, last) {
                (Some(a), Some(b)) => (a as u32, b as u32 + 1),
                _ => (0, 0),
            });
            self.proxy.extend(depths.iter().map(|&d| {
                if d > 0.0 {
                    1.0 / camera.view_depth_from_reversed(d)
                } else {
                    HOLE
                }
            }));
        }
    }

    /// The last [`Outline::cover`]'s covered span of each row.
    pub(crate) fn spans(&self) -> &[(u32, u32)] {
        &self.spans
    }

    /// Makes `image` agree with the last [`Outline::cover`] ([`conform`]), which must
    /// have been of its size and camera; of another size, nothing is done.
    pub(crate) fn conform(&mut self, image: &mut Warped) {
        let w = image.width() as usize;
        if w == 0 || self.proxy.len() != w * image.height() as usize {
            return;
        }
        conform(
            &mut image.color,
            &mut image.disparity,
            &self.proxy,
            w,
            &mut self.fill,
        );
    }
}

/// The fill's lists, kept from frame to frame.
#[derive(Debug, Default)]
pub(crate) struct Fill {
    todo: Vec<usize>,
    next: Vec<usize>,
    done: Vec<(usize, u32)>,
}

/// Makes the image `color` / `disparity` (`w` wide, row-major) agree with the coverage and
/// disparity `proxy` of its geometry ([`HOLE`] where the geometry covers nothing): see the
/// module doc. Returns the pixels filled (not coloured by the light field).
pub(crate) fn conform(
    color: &mut [u32],
    disparity: &mut [f32],
    proxy: &[f32],
    w: usize,
    fill: &mut Fill,
) -> usize {
    let n = color.len().min(disparity.len()).min(proxy.len());
    if w == 0 {
        return 0;
    }
    let enc = Encoder::new(ENCODING);
    fill.todo.clear();
    for i in 0..n {
        let p = proxy[i];
        if p < 0.0 {
            color[i] = 0;
            disparity[i] = HOLE;
            continue;
        }
        let (c, d) = (color[i], disparity[i]);
        let a = c >> 24;
        let same = d >= 0.0 && (d - p).abs() <= SAME_SURFACE * p.max(d);
        if a >= MIN_ALPHA && same {
            if a < 255 {
                let q = unpack(ENCODING, c);
                color[i] = enc.pack(q.r / q.a, q.g / q.a, q.b / q.a, 1.0);
            }
        } else {
            color[i] = 0;
            fill.todo.push(i);
        }
        disparity[i] = p;
    }
    let filled = fill.todo.len();
    let h = n / w;
    for _ in 0..ROUNDS {
        if fill.todo.is_empty() {
            break;
        }
        fill.done.clear();
        fill.next.clear();
        for &i in &fill.todo {
            let (x, y) = (i % w, i / w);
            let mut best: Option<(f32, u32)> = None;
            for (dx, dy) in NEIGHBOURS {
                let (nx, ny) = (x as isize + dx, y as isize + dy);
                if nx < 0 || ny < 0 || nx as usize >= w || ny as usize >= h {
                    continue;
                }
                let j = ny as usize * w + nx as usize;
                if color[j] == 0 {
                    continue;
                }
                let off = (proxy[j] - proxy[i]).abs();
                if best.is_none_or(|(b, _)| off < b) {
                    best = Some((off, color[j]));
                }
            }
            match best {
                Some((_, c)) => fill.done.push((i, c)),
                None => fill.next.push(i),
            }
        }
        if fill.done.is_empty() {
            break;
        }
        for &(i, c) in &fill.done {
            color[i] = c;
        }
        std::mem::swap(&mut fill.todo, &mut fill.next);
    }
    for &i in &fill.todo {
        disparity[i] = HOLE;
    }
    filled - fill.todo.len()
}

/// The eight neighbours, the four sharing an edge first (ties go to the first).
const NEIGHBOURS: [(isize, isize); 8] = [
    (-1, 0),
    (1, 0),
    (0, -1),
    (0, 1),
    (-1, -1),
    (1, -1),
    (-1, 1),
    (1, 1),
];

#[cfg(test)]
mod tests {
    use super::*;

    const RED: u32 = 0xff00_00ff;
    const BLUE: u32 = 0xffff_0000;

    fn check(
        color: &[u32],
        disparity: &[f32],
        proxy: &[f32],
        w: usize,
    ) -> (Vec<u32>, Vec<f32>, usize) {
        let (mut c, mut d) = (color.to_vec(), disparity.to_vec());
        let n = conform(&mut c, &mut d, proxy, w, &mut Fill::default());
        (c, d, n)
    }

    /// What the geometry does not cover is a hole, what it covers is drawn at its depth.
    #[test]
    fn the_outline_and_depth_are_the_geometrys() {
        let (h, g) = (HOLE, 0.5);
        // A light field drawn one pixel too wide on the left, one short on the right.
        let color = [RED, RED, RED, 0, 0];
        let disparity = [g, g, g, h, h];
        let proxy = [h, 0.51, 0.49, 0.5, h];
        let (c, d, n) = check(&color, &disparity, &proxy, 5);
        assert_eq!(c, [0, RED, RED, RED, 0]);
        assert_eq!(d, proxy);
        assert_eq!(n, 1);
    }

    /// A pixel whose light field found another surface (a speck of the urn on the
    /// plinth) takes its colour from its neighbour on the geometry's surface, not from
    /// the nearer one on the other.
    #[test]
    fn a_pixel_of_the_wrong_surface_is_filled_from_the_right_one() {
        // Row 0: red on a far surface (0.2), the middle one blue at the near surface's
        // disparity 0.5; rows 1 and 2: blue on the near surface.
        let color = [RED, BLUE, RED, BLUE, BLUE, BLUE, BLUE, BLUE, BLUE];
        let disparity = [0.2, 0.5, 0.2, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5];
        let proxy = [0.2, 0.2, 0.2, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5];
        let (c, _, n) = check(&color, &disparity, &proxy, 3);
        assert_eq!(n, 1);
        assert_eq!(c[1], RED, "filled from its own surface");
        assert_eq!(&c[3..], &[BLUE; 6]);
    }

    /// Partly covered pixels the geometry covers are drawn opaque with their colour
    /// un-premultiplied; too faint ones are filled.
    #[test]
    fn partly_covered_pixels_become_opaque() {
        let enc = Encoder::new(ENCODING);
        let half = enc.pack(0.4, 0.2, 0.1, 0.5);
        let faint = enc.pack(0.1, 0.0, 0.0, 0.1);
        let (c, _, n) = check(&[half, faint], &[0.5, 0.5], &[0.5, 0.5], 2);
        let q = unpack(ENCODING, c[0]);
        assert_eq!(c[0] >> 24, 255);
        assert!(
            (q.r - 0.8).abs() < 0.02 && (q.g - 0.4).abs() < 0.02,
            "{q:?}"
        );
        assert_eq!((c[1], n), (c[0], 1));
    }

    /// Geometry the light field has no pixel near stays a hole, at any size.
    #[test]
    fn with_no_light_field_nothing_is_drawn() {
        let (c, d, n) = check(&[0; 4], &[HOLE; 4], &[0.5; 4], 2);
        assert_eq!((c, n), (vec![0; 4], 0));
        assert_eq!(d, [HOLE; 4]);
        let (c, _, _) = check(&[], &[], &[], 0);
        assert!(c.is_empty());
    }
}

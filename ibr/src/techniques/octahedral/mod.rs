//! Baked octahedral impostors (Ryan Brucks' octahedral impostors, Unreal's ImpostorBaker,
//! Amplify Impostors): a subject rendered once from `N x N` directions over the sphere (or
//! the upper hemisphere) into one atlas, then drawn as one view-facing quad whose image is
//! blended from the three baked views around the current one.
//!
//! **Mapping** ([`encode`], [`decode`]): an octahedron folded flat into `[-1, 1]^2`, +Y up.
//! - [`Layout::Full`]: `p = d / (|x| + |y| + |z|)`; upper half `uv = (p.x, p.z)`, lower half
//!   folded over the diamond's edges, `uv = ((1 - |p.z|) sgn p.x, (1 - |p.x|) sgn p.z)`.
//!   Decoding: `x = u, z = v, y = 1 - |u| - |v|`, unfolded the same way when `y < 0`.
//! - [`Layout::Hemi`] (objects on the ground): the upper diamond rotated 45 degrees to fill
//!   the square, `uv = (p.x + p.z, p.x - p.z)`; decoding `x = (u + v) / 2, z = (u - v) / 2,
//!   y = 1 - |x| - |z|`. Directions below the horizon are clamped to it.
//!
//! Frame `(i, j)` (index `j * N + i`, atlas column `i`, row `j`) is seen from the decoded
//! cell centre `((i + 0.5) / N, (j + 0.5) / N) * 2 - 1`.
//!
//! **Bake**: per frame, an orthographic capture ([`crate::core::Capturer`]) of
//! [`Subject::draws`] from `centre + d * 16r` ([`BAKE_DISTANCE`]), `2r x 2r` world units,
//! `frame_px` pixels square, transparent clear, colour and depth, into its cell of an
//! [`Atlas`] (image data, apart from the drawing below). Up is [`basis`]: +Y, or +Z
//! within 2.6 degrees of the poles (no tangent field on a sphere is continuous; the
//! reprojection below hides the switch).
//!
//! **Draw**: the view direction is encoded into the lattice of cell centres, each lattice
//! square split into two triangles along its `(1, 0)-(0, 1)` diagonal; the triangle holding
//! it gives three frames and barycentric weights ([`select`]). On the full octahedron,
//! lattice points past an edge are reflected back across it, so weights stay continuous
//! over the folds. The CPU composes the image: for each texel of a view-facing `2r x 2r`
//! quad through the centre, each frame is sampled (bilinear) where the view ray through the
//! texel meets that frame's plane through the centre (Brucks' per-frame projection, so
//! frames with other up vectors and directions line up), and the premultiplied linear
//! colours are summed by weight into a texture of its own ([`Texture::refill`]: no
//! allocation once warm). It is recomposed only when the frames, weights or view direction
//! (each to 1/4096) change. [`Blend::Nearest`] shows the heaviest frame alone.
//!
//! **Costs**: the bake renders `N^2` frames of `frame_px^2` pixels. The atlas holds
//! `N^2 frame_px^2` texels of 20 bytes (linear premultiplied colour and depth, as captured:
//! the blend reads them without decoding; [`OctahedralImpostor::bytes`]): `N = 8,
//! frame_px = 64` is 512 x 512, 5 MiB. Views are about `203 / N` degrees apart on the full octahedron and
//! `144 / N` on the hemi one, 1.4 times finer for the same memory when the underside is
//! never seen. Per frame: three bilinear taps per texel when the view changes, then one
//! two-triangle draw whatever the subject's triangle count. The tests measure the error
//! against the geometry at and between views, blended and nearest, for `N = 4` to `12`.

use crate::core::screen_rect;
use crate::core::Atlas;
use crate::core::Capturer;
use crate::core::DepthImage;
use crate::core::Subject;
use crate::core::BAKE_DISTANCE;
use crate::core::{push_quad, UvRect};
use engine::color::Encoder;
use engine::{
    BlendMode, Camera, Draw, Encoding, Lighting, Material, Mesh, Projection, Rgba, Sphere, Texture,
    Wrap,
};
use glam::{IVec2, Mat4, Vec2, Vec3};
use std::sync::Arc;

pub(crate) mod plan;
mod technique;
pub use plan::OctahedralSet;

/// Fewest views per side of the grid ([`OctahedralImpostor::bake`] clamps).
pub const MIN_GRID: u32 = 2;
/// Most views per side of the grid ([`OctahedralImpostor::bake`] clamps).
pub const MAX_GRID: u32 = 64;
/// Smallest frame side in pixels.
pub const MIN_FRAME_PX: u32 = 4;
/// Largest atlas side in pixels: `grid * frame_px` is clamped to it (frames shrink).
pub const MAX_ATLAS_SIDE: u32 = 4096;
/// `|d.y|` above which [`basis`] takes +Z instead of +Y as its up reference.
pub const POLE: f32 = 0.999;
/// Quantisation of the recomposition key (weights and view direction).
const KEY_STEPS: f32 = 4096.0;

/// Which directions are baked.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Layout {
    /// The whole sphere (objects seen from below too: floating, flying).
    #[default]
    Full,
    /// The upper hemisphere, +Y up (objects standing on the ground).
    Hemi,
}

/// How the frames are combined.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Blend {
    /// The three frames of the grid triangle holding the view, by barycentric weight.
    #[default]
    Three,
    /// The heaviest of those frames alone (pops from frame to frame).
    Nearest,
}

fn sign(x: f32) -> f32 {
    1f32.copysign(x)
}

/// `uv` clamped to the square, NaN read as the centre.
fn square(uv: Vec2) -> Vec2 {
    Vec2::select(uv.is_nan_mask(), Vec2::ZERO, uv).clamp(Vec2::NEG_ONE, Vec2::ONE)
}

/// A direction's octahedral coordinates in `[-1, 1]^2` (see the module docs). Zero and
/// non-finite directions give the centre (+Y); in [`Layout::Hemi`] directions below the
/// horizon are clamped to it (straight down to the horizon towards +Z).
pub fn encode(layout: Layout, d: Vec3) -> Vec2 {
    let hemi = layout == Layout::Hemi;
    let y = if hemi { d.y.max(0.0) } else { d.y };
    let l1 = d.x.abs() + y.abs() + d.z.abs();
    if !(l1 > 0.0 && l1.is_finite()) {
        // Zero or broken: the pole; straight down on the hemi layout: the horizon at +Z.
        return Vec2::new(1.0, -1.0) * f32::from(u8::from(hemi && d.y < 0.0));
    }
    let p = Vec3::new(d.x, y, d.z) / l1;
    let uv = match layout {
        Layout::Full if p.y < 0.0 => {
            Vec2::new((1.0 - p.z.abs()) * sign(p.x), (1.0 - p.x.abs()) * sign(p.z))
        }
        Layout::Full => Vec2::new(p.x, p.z),
        Layout::Hemi => Vec2::new(p.x + p.z, p.x - p.z),
    };
    uv.clamp(Vec2::NEG_ONE, Vec2::ONE)
}

/// The unit direction of octahedral coordinates (clamped to `[-1, 1]^2`; NaN reads as 0).
pub fn decode(layout: Layout, uv: Vec2) -> Vec3 {
    let Vec2 { x: u, y: v } = square(uv);
    let p = match layout {
        Layout::Full => {
            let y = 1.0 - u.abs() - v.abs();
            if y >= 0.0 {
                Vec3::new(u, y, v)
            } else {
                Vec3::new((1.0 - v.abs()) * sign(u), y, (1.0 - u.abs()) * sign(v))
            }
        }
        Layout::Hemi => {
            let (x, z) = ((u + v) * 0.5, (u - v) * 0.5);
            Vec3::new(x, (1.0 - x.abs() - z.abs()).max(0.0), z)
        }
    };
    // |x| + |y| + |z| = 1, so the length is at least 1 / sqrt(3).
    p.normalize()
}

/// Octahedral coordinates of the centre of cell `(i, j)` of an `n x n` grid.
pub fn cell_uv(n: u32, i: u32, j: u32) -> Vec2 {
    let n = n.max(1) as f32;
    Vec2::new(i as f32 + 0.5, j as f32 + 0.5) / n * 2.0 - 1.0
}

/// Unit `(right, up)` of the image seen from direction `d` (unit, pointing at the viewer):
/// `right = normalize(ref x d)`, `up = d x right`, `ref` = +Y, or +Z when `|d.y| > POLE`.
/// Bake cameras and drawn quads both use it.
pub fn basis(d: Vec3) -> (Vec3, Vec3) {
    let reference = if d.y.abs() > POLE { Vec3::Z } else { Vec3::Y };
    let right = reference.cross(d).normalize_or(Vec3::X);
    (right, d.cross(right).normalize_or(Vec3::Y))
}

/// Frame index of grid point `(i, j)` (`i, j` in `-1 ..= n`): on the full octahedron a
/// point past an edge is reflected across it (`(1 + e, v)` is `(1 - e, -v)`), on the hemi
/// one it is clamped to the horizon row or column.
fn wrap(layout: Layout, n: i32, mut i: i32, mut j: i32) -> u32 {
    if layout == Layout::Full {
        if i < 0 || i >= n {
            i = i.clamp(0, n - 1);
            j = n - 1 - j;
        }
        if j < 0 || j >= n {
            j = j.clamp(0, n - 1);
            i = n - 1 - i;
        }
    }
    (j.clamp(0, n - 1) * n + i.clamp(0, n - 1)) as u32
}

/// The three frames of an `n x n` grid around octahedral coordinates `uv` and their
/// barycentric weights (non-negative, summing to 1). See the module docs.
pub fn select(layout: Layout, n: u32, uv: Vec2) -> ([u32; 3], [f32; 3]) {
    let n = n.clamp(1, MAX_GRID) as i32;
    let nf = n as f32;
    let mut g = (square(uv) + 1.0) * 0.5 * nf - 0.5;
    let (lo, hi) = match layout {
        Layout::Full => (-1, n - 1),
        Layout::Hemi => {
            g = g.clamp(Vec2::ZERO, Vec2::splat(nf - 1.0));
            (0, (n - 2).max(0))
        }
    };
    // The lattice square holding `g` (its lower corner) and the position inside it.
    let lower = g
        .floor()
        .as_ivec2()
        .clamp(IVec2::splat(lo), IVec2::splat(hi));
    let f = (g - lower.as_vec2()).clamp(Vec2::ZERO, Vec2::ONE);
    let (i0, j0, fx, fy) = (lower.x, lower.y, f.x, f.y);
    let (gx, gy) = (1.0 - fx, 1.0 - fy);
    let (corners, w) = if fx + fy <= 1.0 {
        ([(0, 0), (1, 0), (0, 1)], [1.0 - fx - fy, fx, fy])
    } else {
        ([(1, 1), (0, 1), (1, 0)], [1.0 - gx - gy, gx, gy])
    };
    (corners.map(|(di, dj)| wrap(layout, n, i0 + di, j0 + dj)), w)
}

/// The orthographic camera of the frame seen from direction `d`.
fn frame_camera(centre: Vec3, r: f32, d: Vec3) -> Camera {
    let (_, up) = basis(d);
    Camera {
        view: Mat4::look_at_rh(centre + d * (BAKE_DISTANCE * r), centre, up),
        projection: Projection::Orthographic {
            left: -r,
            right: r,
            bottom: -r,
            top: r,
            near: (BAKE_DISTANCE - 1.5) * r,
            far: (BAKE_DISTANCE + 1.5) * r,
        },
    }
}

/// Direction from the subject to the viewer: towards a perspective eye, or against an
/// orthographic camera's view direction. `None` for an eye at the centre or a broken camera.
fn view_dir(camera: &Camera, centre: Vec3) -> Option<Vec3> {
    let d = match camera.projection {
        Projection::Orthographic { .. } => -camera.forward(),
        Projection::Perspective { .. } | Projection::Frustum { .. } => camera.eye() - centre,
    };
    d.try_normalize()
}

/// Memory of a texture: 4 bytes per packed texel plus the sampler's 8-byte linear copy,
/// over the whole mip chain.
fn texture_bytes(t: &Texture) -> usize {
    t.levels().iter().map(|l| l.texels.len() * 12).sum()
}

/// What a bake was made from and of.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BakeInfo {
    /// Which directions were baked.
    pub layout: Layout,
    /// Views per side (clamped to [`MIN_GRID`]..=[`MAX_GRID`]).
    pub grid: u32,
    /// Frame side in pixels (at least [`MIN_FRAME_PX`], at most [`MAX_ATLAS_SIDE`]` / grid`).
    pub frame_px: u32,
    /// The subject's bounding sphere (radius at least 1e-3): the quad is `2r` wide.
    pub bounds: Sphere,
    /// The subject's [`Subject::version`]: re-bake when it changes.
    pub version: u64,
}

type Key = (Blend, [u32; 3], [u16; 3], [i16; 3]);

/// A subject baked into an octahedral atlas, drawn as one blended view-facing quad.
#[derive(Clone, Debug)]
pub struct OctahedralImpostor {
    info: BakeInfo,
    /// The baked frames, linear premultiplied colour and depth, with their cameras.
    atlas: Atlas,
    /// Unit direction of every frame, by index.
    dirs: Vec<Vec3>,
    blend: Blend,
    frames: ([u32; 3], [f32; 3]),
    key: Option<Key>,
    /// The composed image lives in `material.base_texture`.
    material: Material,
    mesh: Mesh,
    /// What the last [`OctahedralImpostor::update_in_view`] found: on the image, recomposed.
    in_view: bool,
    recomposed: bool,
}

impl OctahedralImpostor {
    /// Renders `subject` from `grid x grid` directions of `layout` into an atlas of
    /// `frame_px`-pixel frames lit by `lighting` (sizes clamped as [`BakeInfo`] says).
    /// The image starts as the view from above (+Y).
    pub fn bake(
        subject: &mut impl Subject,
        lighting: &Lighting,
        grid: u32,
        frame_px: u32,
        layout: Layout,
    ) -> Self {
        let n = grid.clamp(MIN_GRID, MAX_GRID);
        let px = frame_px.max(MIN_FRAME_PX).min(MAX_ATLAS_SIDE / n);
        let s = subject.bounds();
        let center = Some(s.center).filter(|c| c.is_finite()).unwrap_or_default();
        let r = if s.radius < f32::INFINITY {
            s.radius.max(1e-3)
        } else {
            1e-3
        };
        let mut atlas = Atlas::new(n, n, px, px);
        let mut dirs = Vec::with_capacity((n * n) as usize);
        let mut capturer = Capturer::new();
        let mut cell = DepthImage::new(px, px, frame_camera(center, r, Vec3::Y));
        for k in 0..n * n {
            let (i, j) = (k % n, k / n);
            let d = decode(layout, cell_uv(n, i, j));
            dirs.push(d);
            let camera = frame_camera(center, r, d);
            // View-dependent subjects (clouds) face each bake camera in turn.
            subject.prepare(&camera, px);
            let mut draws = Vec::new();
            subject.draws(&mut draws);
            capturer.capture(draws.iter().copied(), &camera, lighting, px, px, &mut cell);
            atlas.write_cell(k, &cell);
        }
        let texture = |w: u32, t: Vec<u32>| {
            Texture::from_packed(w, w, t, Encoding::Srgb, true)
                .unwrap_or_else(|| Texture::solid(Rgba::TRANSPARENT))
        };
        let scratch = Arc::new(texture(px, vec![0; (px * px) as usize]));
        let mut material = Material::unlit(Rgba::WHITE)
            .with_texture(scratch)
            .blended(BlendMode::Alpha)
            .double_sided(true);
        (material.sampler.wrap_u, material.sampler.wrap_v) = (Wrap::Clamp, Wrap::Clamp);
        material.blend_depth = Some(crate::core::IMAGE_DEPTH_ALPHA);
        let bounds = Sphere { center, radius: r };
        let version = subject.version();
        let mut imp = OctahedralImpostor {
            info: BakeInfo {
                layout,
                grid: n,
                frame_px: px,
                bounds,
                version,
            },
            atlas,
            dirs,
            blend: Blend::Three,
            frames: ([0; 3], [1.0, 0.0, 0.0]),
            key: None,
            material,
            mesh: Mesh::default(),
            in_view: true,
            recomposed: false,
        };
        push_quad(&mut imp.mesh, [center; 4], UvRect::FULL, Rgba::WHITE, 1.0);
        imp.look_from(Vec3::Y);
        imp
    }

    /// Selects the frames for `camera`, recomposes the image if they changed and rebuilds
    /// the quad. Returns whether the image was recomposed. A camera at the centre or with
    /// non-finite matrices keeps the last image.
    pub fn update(&mut self, camera: &Camera) -> bool {
        view_dir(camera, self.info.bounds.center).is_some_and(|v| self.look_from(v))
    }

    /// Culls and updates for a `width` x `height` image from `camera`: an impostor whose
    /// bounding sphere is off the image ([`crate::core::screen_rect`]) is not updated;
    /// one on it is ([`OctahedralImpostor::update`]). See [`OctahedralImpostor::in_view`]
    /// and [`OctahedralImpostor::recomposed`].
    pub fn update_in_view(&mut self, camera: &Camera, width: u32, height: u32) {
        let s = self.info.bounds;
        self.in_view = screen_rect(camera, s.center, s.radius, width, height).is_some();
        self.recomposed = self.in_view && self.update(camera);
    }

    /// Whether the last [`OctahedralImpostor::update_in_view`] found it on the image (true
    /// until the first).
    pub fn in_view(&self) -> bool {
        self.in_view
    }

    /// Whether the last [`OctahedralImpostor::update_in_view`] recomposed the image.
    pub fn recomposed(&self) -> bool {
        self.recomposed
    }

    /// [`OctahedralImpostor::update`] for a unit direction `v` from the centre to the viewer.
    fn look_from(&mut self, v: Vec3) -> bool {
        let BakeInfo { layout, grid, .. } = self.info;
        let (mut idx, mut w) = select(layout, grid, encode(layout, v));
        if self.blend == Blend::Nearest {
            let k = (0..3).fold(0, |b, k| if w[k] > w[b] { k } else { b });
            (idx, w) = ([idx[k]; 3], [1.0, 0.0, 0.0]);
        }
        let q = |x: f32| (x * KEY_STEPS).round();
        let (wq, vq) = (w.map(|x| q(x) as u16), v.to_array().map(|x| q(x) as i16));
        let key = (self.blend, idx, wq, vq);
        if self.key == Some(key) {
            return false;
        }
        (self.key, self.frames) = (Some(key), (idx, w));
        let (right, up) = basis(v);
        self.compose(v, right, up);
        let (c, r) = (self.info.bounds.center, self.info.bounds.radius);
        let (x, y) = (right * r, up * r);
        // Only the corners move: the quad's uvs, colours and indices are written once.
        let corners = [c - x - y, c + x - y, c + x + y, c - x + y];
        self.mesh.positions.copy_from_slice(&corners);
        true
    }

    /// Writes the blend of the selected frames, as seen along `v` on the quad spanned by
    /// `right` and `up`, into the scratch texture.
    fn compose(&mut self, v: Vec3, right: Vec3, up: Vec3) {
        let (n, px) = (self.info.grid, self.info.frame_px);
        let (side, h, last) = ((n * px) as usize, px as f32 * 0.5, px as i32 - 1);
        // Per frame: weight, atlas offset, and the linear map from the quad's coordinates
        // (x right, y up, in [-1, 1]) to the frame's texel coordinates (less `h - 0.5`).
        let taps: [_; 3] = std::array::from_fn(|k| {
            let (f, w) = (self.frames.0[k], self.frames.1[k]);
            let d = self.dirs.get(f as usize).copied().unwrap_or(Vec3::Y);
            let (rk, uk) = basis(d);
            // A quad point P slides along v onto the frame's plane: P - v (P.d) / (v.d).
            let onto = |a: Vec3| (a - v * (a.dot(d) / v.dot(d).max(0.2))) * h;
            let (qr, qu) = (onto(right), onto(up));
            let origin = (f / n * px) as usize * side + (f % n * px) as usize;
            let m = [qr.dot(rk), qu.dot(rk), -qr.dot(uk), -qu.dot(uk)];
            (w, origin, m)
        });
        let atlas = &self.atlas.color;
        let texel = |origin: usize, x: i32, y: i32| {
            let inside = x >= 0 && y >= 0 && x <= last && y <= last;
            let at = inside.then(|| origin + y as usize * side + x as usize);
            let t = at.and_then(|i| atlas.get(i));
            t.map_or([0.0; 4], |t| t.to_array())
        };
        let enc = Encoder::new(Encoding::Srgb);
        let fill = |out: &mut [u32]| {
            for (i, out) in out.iter_mut().enumerate() {
                let x = ((i as u32 % px) as f32 + 0.5) / h - 1.0;
                let y = 1.0 - ((i as u32 / px) as f32 + 0.5) / h;
                let mut acc = [0.0f32; 4];
                for &(w, origin, m) in taps.iter().filter(|t| t.0 > 0.0) {
                    let fx = m[0] * x + m[1] * y + h - 0.5;
                    let fy = m[2] * x + m[3] * y + h - 0.5;
                    if !(fx > -1.0 && fy > -1.0 && fx < 2.0 * h && fy < 2.0 * h) {
                        continue;
                    }
                    let (x0, y0) = (fx.floor(), fy.floor());
                    let (tx, ty) = (fx - x0, fy - y0);
                    let (x0, y0) = (x0 as i32, y0 as i32);
                    for (dy, wy) in [(0, 1.0 - ty), (1, ty)] {
                        for (dx, wx) in [(0, 1.0 - tx), (1, tx)] {
                            let c = texel(origin, x0 + dx, y0 + dy);
                            (0..4).for_each(|ch| acc[ch] += c[ch] * wx * wy * w);
                        }
                    }
                }
                *out = enc.pack(acc[0], acc[1], acc[2], acc[3]);
            }
        };
        // Private and set at bake time; shared only if a caller cloned the material's Arc.
        if let Some(scratch) = self.material.base_texture.as_mut() {
            Arc::make_mut(scratch).refill(px, px, Encoding::Srgb, true, fill);
        }
    }

    /// The quad for the renderer (world space, identity transform), premultiplied
    /// alpha-blended and double-sided.
    pub fn draw(&self) -> Draw<'_> {
        Draw {
            mesh: &self.mesh,
            material: &self.material,
            transform: Mat4::IDENTITY,
        }
    }

    /// Multiplies the drawn image by `tint` (white: as baked), for the planner's debug view.
    pub fn set_tint(&mut self, tint: Rgba) {
        self.material.base_color = tint;
    }

    /// The frames of the current image and their weights (Nearest: `[k; 3]`, `[1, 0, 0]`).
    pub fn frames(&self) -> ([u32; 3], [f32; 3]) {
        self.frames
    }

    /// How the frames are combined ([`Blend::Three`] after a bake); takes effect, and
    /// recomposes, at the next update.
    pub fn set_blend(&mut self, blend: Blend) {
        self.blend = blend;
    }

    /// The baked atlas: frame `k` is the `frame_px` square cell at column `k % grid`, row
    /// `k / grid`, linear premultiplied colour and depth along its bake camera's axis.
    pub fn atlas(&self) -> &Atlas {
        &self.atlas
    }

    /// The composed image drawn on the quad.
    pub fn image(&self) -> Option<&Texture> {
        self.material.base_texture.as_deref()
    }

    /// Unit direction (towards the viewer) frame `k` was baked from.
    pub fn frame_direction(&self, k: u32) -> Option<Vec3> {
        self.dirs.get(k as usize).copied()
    }

    /// What the impostor was baked from and of.
    pub fn info(&self) -> &BakeInfo {
        &self.info
    }

    /// Frames rendered by the bake (`grid^2`).
    pub fn bake_renders(&self) -> u32 {
        self.info.grid * self.info.grid
    }

    /// Bytes held: the atlas (colour, depth and cameras), the composed texture (mips and
    /// linear copies included), frame directions and the quad.
    pub fn bytes(&self) -> usize {
        let scratch = self.image().map_or(0, texture_bytes);
        let vertex = size_of::<Vec3>() + size_of::<Vec2>() + size_of::<Rgba>();
        let quad = self.mesh.positions.len() * vertex + self.mesh.indices.len() * 4;
        let atlas = self.atlas.color.len() * size_of::<engine::Premul>()
            + self.atlas.depth.len() * 4
            + self.atlas.cameras.len() * size_of::<Option<Camera>>();
        atlas + scratch + self.dirs.len() * 12 + quad + size_of::<Self>()
    }
}

#[cfg(test)]
mod tests;

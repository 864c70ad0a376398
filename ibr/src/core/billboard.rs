//! Billboards: textured quads that turn to face the viewer, their three orientation modes,
//! and batches that turn thousands of them into one reusable mesh per frame.
//!
//! Orientation is a pure function of the billboard and a [`View`] ([`orient`]), so it can
//! be tested against the analytic answer without rasterizing. A [`BillboardBatch`] owns one
//! material (texture atlas, blend mode, depth test, soft edges) and a mesh it rewrites every
//! frame without reallocating once warm; blended batches sort their quads back to front.

use engine::{Camera, Draw, Material, Mesh, Projection, Rgba};
use glam::{Mat4, Vec2, Vec3};

/// How a billboard turns to face the viewer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Facing {
    /// Parallel to the image plane: normal = -view direction, up = the camera's up. Every
    /// billboard of a batch shares one orientation (particles, text, flares).
    Screen,
    /// Faces the eye position and keeps `up` (usually world +Y) as upright as possible
    /// (clouds, distant objects). Falls back to the camera's up when looking along `up`.
    World {
        /// World-space direction kept as upright as possible (need not be unit length).
        up: Vec3,
    },
    /// Rotates only about `axis` (unit, usually +Y) to face the eye: trees, lamp posts.
    /// Seen along the axis it cannot face the viewer; see [`AxialFallback`].
    Axial {
        /// World-space axis of rotation (normalised when used; zero falls back to +Y).
        axis: Vec3,
        /// The fade toward the axis and the optional top sprite.
        fallback: AxialFallback,
    },
}

/// What an axial billboard does when the view comes near its axis (from above or below).
///
/// Between `fade_start` and `fade_end` degrees of elevation (the angle between the view
/// direction and the plane perpendicular to the axis) the upright quad fades out; beyond
/// `fade_end` it is not drawn at all, so its orientation never has to be taken from a
/// degenerate cross product and cannot flip or jitter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxialFallback {
    /// Elevation in degrees at which the upright quad starts to fade (55 by default).
    pub fade_start: f32,
    /// Elevation in degrees at which the upright quad has faded out and is no longer drawn
    /// (75 by default); should be above `fade_start`.
    pub fade_end: f32,
    /// Also draw a quad lying across the axis (a top-down sprite, fixed in the world) with
    /// this texture region, fading in as the upright quad fades out. The two overlap
    /// rather than cross-fade (see [`fade_pair`]): one of them is always fully opaque, so
    /// a dithered or alpha-tested fade never opens holes onto the background where both
    /// are drawn.
    pub top: Option<UvRect>,
}

impl Default for AxialFallback {
    fn default() -> Self {
        AxialFallback {
            fade_start: 55.0,
            fade_end: 75.0,
            top: None,
        }
    }
}

impl Facing {
    /// Axial about +Y with the default fade.
    pub const UPRIGHT: Facing = Facing::Axial {
        axis: Vec3::Y,
        fallback: AxialFallback {
            fade_start: 55.0,
            fade_end: 75.0,
            top: None,
        },
    };
}

/// Billboard size: in world units, or in pixels (the same on screen at any distance).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Size {
    /// Width and height in world units.
    World(Vec2),
    /// Width and height in pixels of the target, the same at every distance (converted with
    /// [`View::pixel_size_at`] at the billboard's position).
    Pixels(Vec2),
}

/// A texture region in UV space (u right, v down), for sprite sheets and atlases.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvRect {
    /// Top-left corner (smallest u and v); (0, 0) is the texture's top-left.
    pub min: Vec2,
    /// Bottom-right corner (largest u and v); (1, 1) is the texture's bottom-right.
    pub max: Vec2,
}

impl UvRect {
    /// The whole texture, (0, 0) to (1, 1).
    pub const FULL: UvRect = UvRect {
        min: Vec2::ZERO,
        max: Vec2::ONE,
    };

    /// Cell `index` (row-major) of a `cols` x `rows` grid over the whole texture.
    pub fn cell(cols: u32, rows: u32, index: u32) -> UvRect {
        let (cols, rows) = (cols.max(1), rows.max(1));
        let index = index % (cols * rows);
        let size = Vec2::new(1.0 / cols as f32, 1.0 / rows as f32);
        let min = Vec2::new((index % cols) as f32, (index / cols) as f32) * size;
        UvRect {
            min,
            max: min + size,
        }
    }
}

/// One billboard.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Billboard {
    /// World-space position of the quad's [`Billboard::pivot`].
    pub position: Vec3,
    /// How the quad turns to face the viewer.
    pub facing: Facing,
    /// Width and height of the quad, in world units or pixels.
    pub size: Size,
    /// The point of the quad placed at `position`, in quad units: (0.5, 0.5) the centre,
    /// (0.5, 0) the bottom centre (trees standing on the ground).
    pub pivot: Vec2,
    /// Rotation about the quad's normal, radians, counter-clockwise as seen (particles).
    pub rotation: f32,
    /// Straight linear colour multiplied with the texture; alpha is the opacity.
    pub tint: Rgba,
    /// The texture region shown on the quad (u right, v down).
    pub region: UvRect,
}

impl Billboard {
    /// A white, centred, unrotated billboard of `size` world units showing the whole texture.
    pub fn new(position: Vec3, facing: Facing, size: Vec2) -> Self {
        Billboard {
            position,
            facing,
            size: Size::World(size),
            pivot: Vec2::splat(0.5),
            rotation: 0.0,
            tint: Rgba::WHITE,
            region: UvRect::FULL,
        }
    }
}

/// What billboards need to know about the camera and the image, computed once a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Eye position, world space.
    pub eye: Vec3,
    /// Unit camera axes in world space.
    pub right: Vec3,
    /// Unit camera up axis, world space.
    pub up: Vec3,
    /// Unit view direction (the camera's -Z), world space.
    pub forward: Vec3,
    /// World units per pixel at view distance 1 (perspective) or everywhere (orthographic).
    world_per_px: f32,
    perspective: bool,
}

impl View {
    /// The view of `camera` rendering into an image `height` pixels tall (the pixel size
    /// follows from the vertical field of view or extent).
    pub fn new(camera: &Camera, height: u32) -> Self {
        let world = camera.view.inverse();
        let h = height.max(1) as f32;
        let (world_per_px, perspective) = match camera.projection {
            Projection::Perspective { fov_y, .. } => (2.0 * (fov_y * 0.5).tan() / h, true),
            Projection::Orthographic { bottom, top, .. } => ((top - bottom).abs() / h, false),
            Projection::Frustum {
                bottom, top, near, ..
            } => ((top - bottom).abs() / (near * h), true),
        };
        View {
            eye: world.w_axis.truncate(),
            right: world.x_axis.truncate().normalize_or_zero(),
            up: world.y_axis.truncate().normalize_or_zero(),
            forward: -world.z_axis.truncate().normalize_or_zero(),
            world_per_px,
            perspective,
        }
    }

    /// Distance of `p` in front of the eye along the view direction.
    pub fn depth(&self, p: Vec3) -> f32 {
        (p - self.eye).dot(self.forward)
    }

    /// World size of one pixel at `p` (`None` at or behind the eye of a perspective view).
    pub fn pixel_size_at(&self, p: Vec3) -> Option<f32> {
        if !self.perspective {
            return Some(self.world_per_px);
        }
        let d = self.depth(p);
        (d > 0.0 && d.is_finite()).then_some(d * self.world_per_px)
    }
}

/// A billboard's orientation: unit `right` and `up` spanning the quad, `normal` toward the
/// viewer, and the opacity factor `fade` in [0, 1] from the axial fallback (1 elsewhere).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Basis {
    /// Unit horizontal axis of the quad, world space.
    pub right: Vec3,
    /// Unit vertical axis of the quad, world space.
    pub up: Vec3,
    /// Unit normal toward the viewer (`right x up`), world space.
    pub normal: Vec3,
    /// Opacity factor in [0, 1] from the axial fade (1 for screen and world billboards).
    pub fade: f32,
}

fn smoothstep(lo: f32, hi: f32, x: f32) -> f32 {
    let t = ((x - lo) / (hi - lo).max(1e-6)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The orientation of a billboard at `position` for `view`, before its own rotation.
pub fn orient(facing: Facing, view: &View, position: Vec3) -> Basis {
    let screen = Basis {
        right: view.right,
        up: view.up,
        normal: -view.forward,
        fade: 1.0,
    };
    let to_eye = (view.eye - position).normalize_or_zero();
    match facing {
        Facing::Screen => screen,
        Facing::World { up } => {
            if to_eye == Vec3::ZERO {
                return screen;
            }
            let normal = to_eye;
            let mut right = up.cross(normal);
            if right.length_squared() < 1e-8 {
                // Looking straight along `up`: use the camera's up instead.
                right = view.up.cross(normal);
            }
            let right = right.normalize_or(view.right);
            Basis {
                right,
                up: normal.cross(right),
                normal,
                fade: 1.0,
            }
        }
        Facing::Axial { axis, fallback } => {
            let axis = axis.normalize_or(Vec3::Y);
            let sin_elev = to_eye.dot(axis).abs();
            let elevation = sin_elev.clamp(0.0, 1.0).asin().to_degrees();
            let fade = 1.0 - smoothstep(fallback.fade_start, fallback.fade_end, elevation);
            // Within the fade the cross product is well away from zero; past it the quad
            // is invisible and any continuous fallback direction will do.
            let right = axis
                .cross(to_eye)
                .try_normalize()
                .or_else(|| axis.cross(-view.forward).try_normalize())
                .unwrap_or_else(|| axis.any_orthonormal_vector());
            Basis {
                right,
                up: axis,
                normal: right.cross(axis),
                fade,
            }
        }
    }
}

/// The share of an axial fade band over which each of the upright quad and the top sprite
/// fades (the upright quad at the band's far end, the top sprite at its near end); in
/// between both are drawn fully opaque, overlapping.
pub const HANDOVER: f32 = 0.25;

/// The opacities of an axial billboard's upright quad and of its top sprite at the
/// orientation fade `fade` (1 upright .. 0 over the top). Without a top sprite the upright
/// quad simply fades. With one, they overlap instead of cross-fading: the top sprite fades
/// in over the first [`HANDOVER`] of the band, the upright quad fades out over the last,
/// and both are opaque in between. A cross-fade `fade` / `1 - fade` with screen-door
/// (dithered) alpha leaves both quads out on the same pixels, since both compare against
/// one threshold pattern: a stipple of holes onto the background over the whole tree and
/// the whole band. Overlapped, only one quad is ever partly drawn, over the other, and
/// only over a quarter of the band each.
pub fn fade_pair(fade: f32, has_top: bool) -> (f32, f32) {
    let f = if fade.is_finite() {
        fade.clamp(0.0, 1.0)
    } else {
        1.0
    };
    if has_top {
        ((f / HANDOVER).min(1.0), ((1.0 - f) / HANDOVER).min(1.0))
    } else {
        (f, 0.0)
    }
}

/// Whether `facing` has a top sprite.
fn has_top(facing: Facing) -> bool {
    matches!(facing, Facing::Axial { fallback, .. } if fallback.top.is_some())
}

/// The four corners of a billboard (bottom-left, bottom-right, top-right, top-left as
/// seen) and its opacity factor ([`fade_pair`]), or `None` when it cannot be drawn (behind
/// a perspective eye with a pixel size, non-finite input, or fully faded).
pub fn corners(b: &Billboard, view: &View) -> Option<([Vec3; 4], f32)> {
    let basis = orient(b.facing, view, b.position);
    let opacity = fade_pair(basis.fade, has_top(b.facing)).0;
    if opacity <= 0.0 || !b.position.is_finite() {
        return None;
    }
    let size = match b.size {
        Size::World(s) => s,
        Size::Pixels(px) => px * view.pixel_size_at(b.position)?,
    };
    Some((quad(b.position, basis, size, b.pivot, b.rotation)?, opacity))
}

/// Corners of a quad of `size` placed with its `pivot` at `position`, spanned by the basis
/// rotated by `rotation` about its normal.
fn quad(position: Vec3, basis: Basis, size: Vec2, pivot: Vec2, rotation: f32) -> Option<[Vec3; 4]> {
    let (s, c) = rotation.sin_cos();
    let right = basis.right * c + basis.up * s;
    let up = basis.up * c - basis.right * s;
    let corner = |qx: f32, qy: f32| {
        position + right * ((qx - pivot.x) * size.x) + up * ((qy - pivot.y) * size.y)
    };
    let q = [
        corner(0.0, 0.0),
        corner(1.0, 0.0),
        corner(1.0, 1.0),
        corner(0.0, 1.0),
    ];
    q.iter().all(|p| p.is_finite()).then_some(q)
}

/// The top-down sprite of an axial billboard: a quad across the axis through the
/// billboard's centre, fixed in the world, with its opacity from [`fade_pair`].
fn top_sprite(b: &Billboard, view: &View) -> Option<([Vec3; 4], f32, UvRect)> {
    let Facing::Axial { axis, fallback } = b.facing else {
        return None;
    };
    let region = fallback.top?;
    let basis = orient(b.facing, view, b.position);
    let alpha = fade_pair(basis.fade, true).1;
    let Size::World(size) = b.size else {
        return None;
    };
    if alpha <= 0.0 {
        return None;
    }
    let axis = axis.normalize_or(Vec3::Y);
    // World-fixed: for +Y, right = +X and up = -Z, as `sprites::bake_upright` bakes it.
    let right = axis
        .cross(Vec3::Z)
        .try_normalize()
        .unwrap_or_else(|| axis.any_orthonormal_vector());
    let centre = b.position + axis * ((0.5 - b.pivot.y) * size.y);
    // right x (axis x right) = axis: the quad faces along the axis; seen from below, it is
    // wound the other way so it still faces the viewer.
    let up = if (view.eye - centre).dot(axis) >= 0.0 {
        axis.cross(right)
    } else {
        right.cross(axis)
    };
    let top = Basis {
        right,
        up,
        normal: right.cross(up),
        fade: alpha,
    };
    let width = Vec2::splat(size.x);
    Some((
        quad(centre, top, width, Vec2::splat(0.5), 0.0)?,
        alpha,
        region,
    ))
}

/// A set of billboards sharing one material, turned into one mesh per frame.
///
/// Call [`BillboardBatch::build`] after the camera is known, then hand
/// [`BillboardBatch::draw`] to the renderer with the rest of the frame's draws. When the
/// material is blended, quads are written back to front (by view depth, ties by index),
/// so the engine's in-order blending composites them correctly; between batches the engine
/// orders whole draws by their bounding boxes.
#[derive(Clone, Debug)]
pub struct BillboardBatch {
    /// Shared by every quad; made double-sided by [`BillboardBatch::new`].
    pub material: Material,
    /// The billboards drawn at the next [`BillboardBatch::build`], in any order.
    pub items: Vec<Billboard>,
    mesh: Mesh,
    order: Vec<(f32, u32)>,
}

impl BillboardBatch {
    /// An empty batch. Billboards are drawn double-sided, since they face the viewer by
    /// construction and a rotation must never cull them.
    pub fn new(material: Material) -> Self {
        BillboardBatch {
            material: material.double_sided(true),
            items: Vec::new(),
            mesh: Mesh::default(),
            order: Vec::new(),
        }
    }

    /// Empties the batch, keeping its memory.
    pub fn clear(&mut self) {
        self.items.clear();
    }

    /// Adds one billboard; it appears at the next [`BillboardBatch::build`].
    pub fn push(&mut self, b: Billboard) {
        self.items.push(b);
    }

    /// Writes the quads for `view` into the batch's mesh. Returns the number of quads.
    pub fn build(&mut self, view: &View) -> usize {
        let m = &mut self.mesh;
        m.clear();
        self.order.clear();
        self.order.extend(
            self.items
                .iter()
                .enumerate()
                .map(|(i, b)| (view.depth(b.position), i as u32)),
        );
        if self.material.is_blended() {
            // Far to near; NaN depths (non-finite positions) are dropped by `corners`.
            // Ties are broken by index, so the unstable sort (which, unlike the stable
            // one, needs no scratch memory) gives the one order.
            self.order
                .sort_unstable_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        }
        for &(_, i) in &self.order {
            let b = &self.items[i as usize];
            if let Some((q, fade)) = corners(b, view) {
                push_quad(m, q, b.region, b.tint, fade);
            }
            if let Some((q, alpha, region)) = top_sprite(b, view) {
                push_quad(m, q, region, b.tint, alpha);
            }
        }
        m.positions.len() / 4
    }

    /// The mesh written by the last [`BillboardBatch::build`] (world space).
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// The draw for the renderer (world-space mesh, identity transform).
    pub fn draw(&self) -> Draw<'_> {
        Draw {
            mesh: &self.mesh,
            material: &self.material,
            transform: Mat4::IDENTITY,
        }
    }
}

/// Appends one quad (two counter-clockwise triangles as seen) to a billboard mesh.
pub fn push_quad(m: &mut Mesh, q: [Vec3; 4], region: UvRect, tint: Rgba, fade: f32) {
    let base = m.positions.len() as u32;
    m.positions.extend_from_slice(&q);
    let (a, b) = (region.min, region.max);
    // Quad corners go bottom-left first; v grows downward in the texture.
    m.uvs.extend_from_slice(&[
        Vec2::new(a.x, b.y),
        Vec2::new(b.x, b.y),
        Vec2::new(b.x, a.y),
        Vec2::new(a.x, a.y),
    ]);
    let c = Rgba::new(tint.r, tint.g, tint.b, tint.a * fade);
    m.colors.extend_from_slice(&[c; 4]);
    m.indices
        .extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
}

mod area;
pub(crate) use area::screen_share;

#[cfg(test)]
mod fade_tests;
#[cfg(test)]
mod tests;

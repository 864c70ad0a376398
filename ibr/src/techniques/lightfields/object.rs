//! A light field standing in a rasterized scene, like an impostor: one or more slabs (up
//! to six on a cube, [`super::Slab::cube`]) around an object's bounding sphere. Each
//! frame the slab that sees the whole sphere from the eye, best aligned with the view of
//! it, is rendered into the screen rectangle its focal plane covers (a crop of the frame's
//! camera, so the cost follows the covered pixels), then composited by an image pass that
//! depth-tests against the geometry, blends its edges "over" and writes the depth of its
//! proxy. When no slab sees the whole object (the eye left the region its slabs cover, or
//! is inside the sphere) the object falls back to its geometry, if kept, and says so
//! ([`LightFieldObject::showing`], the `geometry` counter).

use super::outline::Outline;
use super::render::{render, render_within, LightFieldFrame, Lookup};
use super::{LightField, Slab};
use crate::core::{Counters, FrameView, Frustum, Technique};
use crate::core::{MeshGroup, Subject};
use crate::warp::ImagePass;
use crate::warp::{Warped, ENCODING, HOLE};
use engine::color::{unpack, Encoder};
use engine::{
    run_packed_pass, Camera, Draw, Encoding, FrameStats, PackedFragment, PackedPass, PassMode,
    PixelRect, Rgba, Sphere, Target,
};
use glam::{Vec2, Vec3};

/// What a light-field object showed in the last frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Showing {
    /// Slab `k` of [`LightFieldObject::slabs`].
    Slab(usize),
    /// Its geometry: no slab sees the whole object from the eye.
    Geometry,
    /// Nothing: no slab sees it and no geometry is kept (or it is off screen).
    #[default]
    Nothing,
}

/// A light field in a scene, and the geometry it stands for (the fallback, and the
/// reference for error measurement).
#[derive(Debug)]
pub struct LightFieldObject {
    /// The object's name, for reports and charts.
    pub name: String,
    /// The slabs, each a light field of the object from one side.
    pub slabs: Vec<LightField>,
    /// The object's bounding sphere: a slab is used only when every ray from the eye to
    /// it crosses both of the slab's rectangles.
    pub bounds: Sphere,
    /// How its renders look the slabs' rays up (interpolation, depth correction).
    pub lookup: Lookup,
    /// The geometry captured into the light field, if kept: drawn when no slab sees the
    /// object.
    pub reference: Option<MeshGroup>,
    /// Fills cracks: a hole between two drawn pixels (left and right, or above and below)
    /// takes the nearer one's colour and depth. Depth correction leaves rays it finds no
    /// surface for, where the cameras around disagree, undrawn; inside the object those
    /// are one-pixel cracks at its depth edges (a ring passing in front of another), not
    /// silhouette, which has a drawn pixel on one side only.
    pub fill_cracks: bool,
    /// Hard edges: a pixel whose blended coverage (alpha) is at least one half is drawn
    /// opaque (its colour un-premultiplied), the others are left holes. The blend's
    /// partly covered ring round the silhouette becomes a crisp edge where the
    /// interpolated coverage crosses one half, as rasterised geometry's edge falls where
    /// pixel centres leave its triangles.
    pub hard_edges: bool,
    /// When the bounding sphere's projected diameter is smaller than this many pixels and
    /// the geometry is kept, the geometry is drawn instead of a slab: far away the light
    /// field is minified many samples to a pixel and its outline, a pixel or two wide, is
    /// most of the object, while the geometry is a few pixels' worth of triangles. 0 (the
    /// default): a slab at any distance.
    pub min_px: f32,
    /// The outline from geometry ([`super::outline`]): with [`Self::reference`] kept, each
    /// image is made to agree with the geometry's coverage and depth seen through the
    /// same camera, the light field giving only the colour inside (`hard_edges` and
    /// `fill_cracks` then have nothing left to do).
    pub proxy_outline: bool,
    image: Composite,
    outline: Outline,
    showing: Showing,
}

impl LightFieldObject {
    /// One slab; the object's sphere is taken to be the one [`Slab::facing`] fits it
    /// around (centred in the focal plane, a quarter of its shorter edge; with the focal
    /// plane at infinity, an environment, there is no object: an empty sphere).
    pub fn new(name: impl Into<String>, field: LightField) -> Self {
        let st = field.slab.st;
        let bounds = if field.slab.infinite[1] {
            Sphere {
                center: field.slab.uv.at(0.5, 0.5),
                radius: 0.0,
            }
        } else {
            Sphere {
                center: st.at(0.5, 0.5),
                radius: 0.25 * st.edge_a.length().min(st.edge_b.length()),
            }
        };
        Self::with_slabs(name, vec![field], bounds)
    }

    /// Several slabs around the sphere `bounds`.
    pub fn with_slabs(name: impl Into<String>, slabs: Vec<LightField>, bounds: Sphere) -> Self {
        let camera = slabs.first().map_or_else(
            || Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 1.0, 1.0),
            |f| f.slab.camera(0, 0),
        );
        LightFieldObject {
            name: name.into(),
            slabs,
            bounds,
            lookup: Lookup::default(),
            reference: None,
            fill_cracks: false,
            hard_edges: false,
            min_px: 0.0,
            proxy_outline: false,
            image: Composite::new(camera),
            outline: Outline::default(),
            showing: Showing::Nothing,
        }
    }

    /// The last frame's work.
    pub fn last(&self) -> LightFieldFrame {
        self.image.last
    }

    /// What the last frame showed.
    pub fn showing(&self) -> Showing {
        self.showing
    }

    /// The pixels the last frame's light-field image covered (`None` when it drew none).
    pub fn rect(&self) -> Option<PixelRect> {
        self.image.rect
    }

    /// The bounding sphere's diameter on screen in `view`, pixels (infinite from inside
    /// it).
    pub fn projected_px(&self, view: &FrameView<'_>) -> f32 {
        let focal = view.camera.projection.gl_matrix().y_axis.y * 0.5 * view.height as f32;
        let distance = (self.bounds.center - view.camera.eye()).length();
        if distance <= self.bounds.radius {
            return f32::INFINITY;
        }
        2.0 * self.bounds.radius * focal.abs() / distance
    }

    /// Bytes of all slabs' samples in memory.
    pub fn bytes(&self) -> usize {
        self.slabs.iter().map(LightField::bytes).sum()
    }

    /// The slab that sees the whole object from `eye`, best aligned with the view of it.
    /// A slab with its `st` plane at infinity (an environment, not an object) is taken
    /// first when `eye` lies over its `uv` rectangle (along the slab's forward).
    pub fn choose(&self, eye: Vec3) -> Option<usize> {
        choose_slab(self.slabs.iter().map(|f| &f.slab), self.bounds, eye)
    }
}

/// Whether the line from `eye` along `d` is a ray of `slab`: it looks across the planes
/// from the `uv` side and crosses both rectangles.
fn sees(slab: &Slab, eye: Vec3, d: Vec3) -> bool {
    let inside = |c: Option<(f32, f32, f32)>| {
        c.is_some_and(|(_, a, b)| (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b))
    };
    d.dot(slab.forward()) > 0.0 && inside(slab.cross(0, eye, d)) && inside(slab.cross(1, eye, d))
}

/// An image pass over a crop of the frame: pixel `(x, y)` of the frame is pixel
/// `(x - x0, y - y0)` of the crop.
struct Cropped<'a> {
    pass: ImagePass<'a>,
    x0: u32,
    y0: u32,
}

impl PackedPass for Cropped<'_> {
    fn encoding(&self) -> Encoding {
        self.pass.encoding()
    }

    fn shade_span(&self, x0: u32, y: u32, out: &mut [Option<PackedFragment>]) {
        if x0 >= self.x0 && y >= self.y0 {
            self.pass.shade_span(x0 - self.x0, y - self.y0, out);
        }
    }
}

impl Technique for LightFieldObject {
    fn name(&self) -> &str {
        &self.name
    }

    fn prepare(&mut self, view: &FrameView<'_>) {
        let small = self.projected_px(view) < self.min_px;
        self.showing = match (self.choose(view.camera.eye()), &self.reference) {
            (Some(_), Some(_)) if small => Showing::Geometry,
            (Some(k), _) => Showing::Slab(k),
            (None, Some(_)) => Showing::Geometry,
            (None, None) => Showing::Nothing,
        };
        match self.showing {
            Showing::Slab(k) => {
                // With the outline from geometry, a pixel the geometry cannot cover is a
                // hole whatever the light field finds there: only the rays within the
                // geometry's sphere on screen are looked up (the focal plane's rectangle,
                // 4.4 radii across for a cube's slab, is several times its area), and none
                // when the sphere is out of view (the focal plane's rectangle is the whole
                // view when one of its corners is behind the eye: every row was searched
                // for rays that cross the slab, and none did).
                let clip = match (self.proxy_outline, &self.reference) {
                    (true, Some(g)) => {
                        let b = g.bounds();
                        if Frustum::new(view.camera.clip_from_world()).sees(b.center, b.radius) {
                            sphere_rect(b, view.camera, view.width, view.height)
                        } else {
                            Some(PixelRect {
                                x0: 0,
                                y0: 0,
                                x1: 0,
                                y1: 0,
                            })
                        }
                    }
                    _ => None,
                };
                // The geometry's outline first: the rays of pixels it does not cover are
                // not looked up, as the outline would make them holes.
                let outline = match (self.proxy_outline, &self.reference) {
                    (true, Some(g)) => Some((g, &mut self.outline)),
                    _ => None,
                };
                let outlined = outline.is_some();
                self.image
                    .render(&self.slabs[k], view, self.lookup, clip, outline);
                if outlined && self.image.rect.is_some() {
                    return;
                }
                if self.hard_edges {
                    self.image.harden();
                }
                if self.fill_cracks {
                    self.image.fill_cracks();
                }
            }
            _ => self.image.clear(),
        }
    }

    fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        if let (Showing::Geometry, Some(g)) = (self.showing, &self.reference) {
            g.draws(out);
        }
    }

    fn passes(&self, _view: &FrameView<'_>, target: &mut Target) -> FrameStats {
        self.image.pass(target)
    }

    fn counters(&self) -> Counters {
        Counters {
            images: self.image.rect.is_some() as u64,
            geometry: (self.showing == Showing::Geometry) as u64,
            pixels: self.image.last.pixels,
            samples: self.image.last.taps,
            ..Counters::default()
        }
    }

    fn reference<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        if let Some(g) = &self.reference {
            g.draws(out);
        }
    }
}

/// The slab of `slabs` that sees the whole sphere `bounds` from `eye`, best aligned with
/// the view of it (see [`LightFieldObject::choose`]); `None` from inside the sphere, from a
/// NaN eye, or where no slab sees all of it.
pub(crate) fn choose_slab<'s>(
    slabs: impl Iterator<Item = &'s Slab> + Clone,
    bounds: Sphere,
    eye: Vec3,
) -> Option<usize> {
    let environment = slabs.clone().position(|s| {
        s.infinite[1]
            && s.cross(0, eye, s.forward())
                .is_some_and(|(_, a, b)| (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b))
    });
    if environment.is_some() {
        return environment;
    }
    let to = bounds.center - eye;
    if to.length().is_nan() || to.length() <= bounds.radius {
        return None;
    }
    let dir = to.normalize();
    // Points all round the sphere (26 directions), a little outside it.
    let (c, r) = (bounds.center, bounds.radius * 1.05);
    let points = (0..27)
        .map(|k| {
            Vec3::new(
                (k % 3) as f32 - 1.0,
                (k / 3 % 3) as f32 - 1.0,
                (k / 9) as f32 - 1.0,
            )
        })
        .filter(|d| *d != Vec3::ZERO)
        .map(|d| c + d.normalize() * r);
    // The best aligned (ties: the first slab) of those that see every point: asked of
    // every object every frame by the planner, so the slabs are tried best aligned first
    // and the first that sees is taken (the best aligned usually does), sorted on the
    // stack: nothing is allocated. Past `ON_STACK` slabs, every better aligned one is
    // checked in turn.
    const ON_STACK: usize = 8;
    let mut order = [(usize::MAX, f32::NEG_INFINITY); ON_STACK];
    let mut n = 0;
    let mut best: Option<(usize, f32)> = None;
    let all = slabs.clone();
    for (k, s) in slabs.enumerate().filter(|(_, s)| !s.infinite[1]) {
        let align = s.forward().dot(dir);
        if n < ON_STACK {
            order[n] = (k, align);
            n += 1;
        } else if best.is_none_or(|(_, b)| align > b)
            && points.clone().all(|p| sees(s, eye, p - eye))
        {
            best = Some((k, align));
        }
    }
    let order = &mut order[..n];
    order.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    let on_stack = order.iter().find(|&&(k, _)| {
        let s = all.clone().nth(k);
        s.is_some_and(|s| points.clone().all(|p| sees(s, eye, p - eye)))
    });
    match (on_stack, best) {
        (Some(&(k, a)), Some((j, b))) => Some(if b > a { j } else { k }),
        (Some(&(k, _)), None) => Some(k),
        (None, b) => b.map(|(j, _)| j),
    }
}

/// The pixels of a `width` x `height` view `slab`'s focal plane can cover: the bounds of
/// its corners on screen, or the whole view when a corner is behind the eye; `None` when
/// off screen.
fn focal_rect(slab: &Slab, camera: &Camera, width: u32, height: u32) -> Option<PixelRect> {
    let m = camera.clip_from_world();
    let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::NEG_INFINITY);
    let st = &slab.st;
    // A plane at infinity's corners are directions: points at infinity.
    let w = if slab.infinite[1] { 0.0 } else { 1.0 };
    for p in st.corners() {
        let c = m * p.extend(w);
        if c.w.is_nan() || c.w <= 1e-6 {
            return Some(PixelRect::full(width, height));
        }
        let px = Vec2::new(
            (c.x / c.w + 1.0) * 0.5 * width as f32,
            (1.0 - c.y / c.w) * 0.5 * height as f32,
        );
        lo = lo.min(px);
        hi = hi.max(px);
    }
    let clamp = |v: f32, n: u32| v.clamp(0.0, n as f32);
    let (x0, y0) = (clamp(lo.x.floor(), width), clamp(lo.y.floor(), height));
    let (x1, y1) = (clamp(hi.x.ceil(), width), clamp(hi.y.ceil(), height));
    (x0 < x1 && y0 < y1).then_some(PixelRect {
        x0: x0 as u32,
        y0: y0 as u32,
        x1: x1 as u32,
        y1: y1 as u32,
    })
}

/// The pixels of a `width` x `height` view the sphere `s` can cover: the bounds on screen
/// of the corners of its box, a pixel wider on every side (empty when off screen);
/// `None` (no bound) when a corner is not in front of the eye or `s` is not finite.
pub(crate) fn sphere_rect(
    s: Sphere,
    camera: &Camera,
    width: u32,
    height: u32,
) -> Option<PixelRect> {
    if !(s.center.is_finite() && s.radius.is_finite()) {
        return None;
    }
    let m = camera.clip_from_world();
    let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::NEG_INFINITY);
    for k in 0..8 {
        let sign = |bit: u32| if k & bit == 0 { -1.0 } else { 1.0 };
        let corner = s.center + Vec3::new(sign(1), sign(2), sign(4)) * s.radius;
        let c = m * corner.extend(1.0);
        if c.w.is_nan() || c.w <= 1e-6 {
            return None;
        }
        let px = Vec2::new(
            (c.x / c.w + 1.0) * 0.5 * width as f32,
            (1.0 - c.y / c.w) * 0.5 * height as f32,
        );
        lo = lo.min(px);
        hi = hi.max(px);
    }
    let clamp = |v: f32, n: u32| v.clamp(0.0, n as f32) as u32;
    Some(PixelRect {
        x0: clamp(lo.x.floor() - 1.0, width),
        y0: clamp(lo.y.floor() - 1.0, height),
        x1: clamp(hi.x.ceil() + 1.0, width),
        y1: clamp(hi.y.ceil() + 1.0, height),
    })
}

/// The pixels a render of `slab` covers: its focal plane's ([`focal_rect`]), within `clip`
/// if given; `None` when empty.
pub(crate) fn drawn_rect(
    slab: &Slab,
    camera: &Camera,
    width: u32,
    height: u32,
    clip: Option<PixelRect>,
) -> Option<PixelRect> {
    let f = focal_rect(slab, camera, width, height)?;
    let Some(c) = clip else { return Some(f) };
    let (x0, y0) = (f.x0.max(c.x0), f.y0.max(c.y0));
    let (x1, y1) = (f.x1.min(c.x1), f.y1.min(c.y1));
    (x0 < x1 && y0 < y1).then_some(PixelRect { x0, y0, x1, y1 })
}

/// One frame's image of a light field and its composite, shared by [`LightFieldObject`]
/// and the planner's light fields ([`super::plan::LightFieldSet`]): a slab rendered
/// through a crop of the frame camera into the screen rectangle its focal plane covers
/// (its buffers kept frame to frame), then drawn over the frame by a depth-tested image
/// pass that blends its edges "over" and writes its proxy's depth.
#[derive(Debug)]
pub(crate) struct Composite {
    pub(crate) image: Warped,
    /// The pixels the image covers (`None`: nothing to draw).
    pub(crate) rect: Option<PixelRect>,
    /// The last render's work.
    pub(crate) last: LightFieldFrame,
    /// The image's colours and disparities before [`Composite::fill_cracks`], kept from
    /// frame to frame so the fill allocates nothing once warm.
    before: (Vec<u32>, Vec<f32>),
}

impl Composite {
    /// Nothing to draw; `camera` is a placeholder for the empty image's.
    pub(crate) fn new(camera: Camera) -> Self {
        Composite {
            image: Warped::new(0, 0, camera),
            rect: None,
            last: LightFieldFrame::default(),
            before: (Vec::new(), Vec::new()),
        }
    }

    /// Nothing to draw this frame (the buffers are kept).
    pub(crate) fn clear(&mut self) {
        self.rect = None;
        self.last = LightFieldFrame::default();
    }

    /// Renders `field` as `view` sees it into the pixels its focal plane covers, within
    /// `clip` if given (nothing when off screen or the view is empty). With an `outline`
    /// (the object's geometry and its [`Outline`]), the geometry's coverage is rasterised
    /// first, only the rays of the rows' covered spans are looked up, and the image is
    /// made to agree with the geometry ([`Outline::conform`]): the same pixels as
    /// looking every ray up before the outline, which makes the others holes.
    pub(crate) fn render(
        &mut self,
        field: &LightField,
        view: &FrameView<'_>,
        lookup: Lookup,
        clip: Option<PixelRect>,
        outline: Option<(&MeshGroup, &mut Outline)>,
    ) {
        self.clear();
        self.rect = drawn_rect(&field.slab, view.camera, view.width, view.height, clip);
        if let Some(r) = self.rect {
            let lo = Vec2::new(r.x0 as f32, r.y0 as f32);
            let hi = Vec2::new(r.x1 as f32, r.y1 as f32);
            let crop = view.camera.crop(lo, hi, view.width, view.height);
            let (w, h) = (r.x1 - r.x0, r.y1 - r.y0);
            let image = &mut self.image;
            self.last = match outline {
                Some((geometry, outline)) => {
                    outline.cover(geometry, &crop, w, h);
                    let spans = Some(outline.spans());
                    let last = render_within(field, &crop, w, h, lookup, spans, image);
                    outline.conform(image);
                    last
                }
                None => render(field, &crop, w, h, lookup, image),
            };
        }
    }

    /// Multiplies the rendered colours by `tint` (premultiplied linear, alpha kept).
    pub(crate) fn tint(&mut self, tint: Rgba) {
        let enc = Encoder::new(ENCODING);
        for c in self.image.color.iter_mut().filter(|c| **c != 0) {
            let p = unpack(ENCODING, *c);
            *c = enc.pack(p.r * tint.r, p.g * tint.g, p.b * tint.b, p.a);
        }
    }

    /// Hardens the image's edges ([`LightFieldObject::hard_edges`]): alpha of one half or
    /// more becomes opaque, less a hole.
    pub(crate) fn harden(&mut self) {
        let enc = Encoder::new(ENCODING);
        let image = &mut self.image;
        for (c, d) in image.color.iter_mut().zip(image.disparity.iter_mut()) {
            let a = *c >> 24;
            if a == 255 || *c == 0 {
                continue;
            }
            if a < 128 {
                *c = 0;
                *d = HOLE;
            } else {
                let p = unpack(ENCODING, *c);
                *c = enc.pack(p.r / p.a, p.g / p.a, p.b / p.a, 1.0);
            }
        }
    }

    /// Fills one-pixel cracks ([`LightFieldObject::fill_cracks`]), reading the image as
    /// it was before (a filled pixel fills nothing).
    pub(crate) fn fill_cracks(&mut self) {
        let Some(r) = self.rect else { return };
        let (w, h) = ((r.x1 - r.x0) as usize, (r.y1 - r.y0) as usize);
        let image = &mut self.image;
        if w < 3 || h < 3 || image.color.len() < w * h {
            return;
        }
        let (color, disparity) = &mut self.before;
        color.clone_from(&image.color);
        disparity.clone_from(&image.disparity);
        for y in 1..h - 1 {
            for x in 1..w - 1 {
                let i = y * w + x;
                if color[i] != 0 {
                    continue;
                }
                let mut best: Option<usize> = None;
                for (a, b) in [(i - 1, i + 1), (i - w, i + w)] {
                    if color[a] == 0 || color[b] == 0 {
                        continue;
                    }
                    // The nearer of the pair (larger disparity), the nearer of the pairs.
                    let near = if disparity[a] >= disparity[b] { a } else { b };
                    if best.is_none_or(|k| disparity[near] > disparity[k]) {
                        best = Some(near);
                    }
                }
                if let Some(k) = best {
                    image.color[i] = color[k];
                    image.disparity[i] = disparity[k];
                }
            }
        }
    }

    /// Composites the image over `target`, depth-tested; returns the pass's work.
    pub(crate) fn pass(&self, target: &mut Target) -> FrameStats {
        let Some(rect) = self.rect else {
            return FrameStats::default();
        };
        let pass = Cropped {
            pass: ImagePass::new(&self.image),
            x0: rect.x0,
            y0: rect.y0,
        };
        let mode = PassMode {
            blend: true,
            ..PassMode::default()
        };
        run_packed_pass(target, rect, &pass, mode)
    }
}

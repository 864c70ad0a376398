//! LDI portals (Popescu, Lastra, Aliaga and de Oliveira 98): what lies behind a door or
//! window is drawn from a layered depth image warped to the eye each frame, instead of
//! its geometry, so the frame's cost follows the pixels the opening covers, not the
//! triangles behind it.
//!
//! Per portal:
//! 1. **build** (when there is no image, the eye has left the region it was built for,
//!    or the predicted error of the move, [`PortalConfig::tolerance_px`], is too large):
//!    the geometry behind the opening is captured from the eye and from eyes spread
//!    around it (left, right, up, down by [`PortalConfig::reach`]), a few views a frame
//!    ([`PortalConfig::views_per_frame`] over all portals, so a rebuild is spread over
//!    frames instead of stalling one), and once all are in, merged into one LDI seen from
//!    the eye ([`LdiBuilder`]) and prepared for the warp. The old LDI is shown meanwhile
//!    (or the geometry, before the first);
//! 2. **warp**: the LDI is warped to the frame's camera and its holes filled;
//! 3. **clip**: only pixels inside the opening's outline on screen are kept
//!    ([`Opening::outline`]), gathered into one image for all portals;
//! 4. **composite**: an image pass writes them into the frame, depth-tested against the
//!    near room the rasterizer drew (warped samples carry depth, so a table in front of
//!    the door hides them).
//!
//! Portals can be made in code ([`Portal::new`]) or read from a loaded scene whose nodes
//! mark them ([`marked`]: `portal.<room>` and `room.<room>`).
//!
//! Walking up to the opening (within [`PortalConfig::through`] of its plane, over it) or
//! into the room behind it, the portal draws its geometry instead; the LDI built from an
//! eye at the opening sees what the geometry shows, so the switch does not pop. An eye past
//! the opening's plane is in its room if it came through the opening (or stands inside
//! the box around the room's geometry); otherwise, come in through another door, it sees
//! the opening from behind and the portal is culled.

mod ahead;
mod clip;
pub mod marked;
pub mod opening;
mod views;

use crate::core::Capturer;
use crate::core::{Counters, FrameView, Technique};
use crate::core::{DepthImage, LayeredDepthImage};
use crate::core::{MeshGroup, Subject};
use crate::warp::holes::{Fill, Filler};
use crate::warp::ldi::{LdiBuilder, LdiLanding};
use crate::warp::predict::{depth_range, parallax_px};
use crate::warp::ImagePass;
use crate::warp::{Prepared, WarpOptions, WarpStats, Warped, Warper};
use clip::{clip_into, holes_inside};
use engine::{run_packed_pass, Camera, Draw, FrameStats, Lighting, PassMode, PixelRect, Target};
use glam::{Vec2, Vec3};
pub use marked::{from_scene, MarkError, Marked};
pub use opening::{Opening, Outline};
use std::time::{Duration, Instant};
use views::{build_cameras, ldi_size, room_box};

/// What a portal's image holds (the three representations Rafferty et al. 98 compared).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PortalImage {
    /// A layered depth image merged from the eye's view and four side views.
    Ldi,
    /// One depth image, the eye's view: parallax, but what the eye did not see is a hole.
    DepthImage,
    /// The eye's view flat on the opening (every sample at the opening's plane): a
    /// textured portal, right only from where it was taken.
    Flat,
}

/// How portals are built and drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PortalConfig {
    /// Which image of the room a build makes.
    pub image: PortalImage,
    /// The LDI's largest side, pixels. A build makes it 1.5 times the opening's size on
    /// screen, up to this; an opening grown to twice what its LDI was built for is rebuilt.
    pub side: u32,
    /// How far (scene units) the eye may move from where an LDI was built before it is
    /// rebuilt, and how far the side views of a build are from its eye; at most 0.35
    /// of the eye's distance from the opening's plane (a region is narrower near the
    /// opening, where the parallax is larger).
    pub reach: f32,
    /// The predicted parallax (target pixels: how wide a disocclusion the eye's move from
    /// where the image was built can open, [`parallax_px`]) past which the image is
    /// rebuilt even inside its region.
    pub tolerance_px: f32,
    /// Relative depth within which samples of the build's views merge into one.
    pub tolerance: f32,
    /// Within this distance of the opening's plane (and over the opening) the portal
    /// draws its geometry.
    pub through: f32,
    /// The most views captured in one frame, over all portals (an LDI takes five, a depth
    /// or flat image one).
    pub views_per_frame: usize,
    /// How the holes left inside the openings after warping are filled.
    pub fill: Fill,
    /// How the images are warped into the openings.
    pub options: WarpOptions,
    /// Parts of the rooms with levels of detail
    /// ([`Part::with_lods`](crate::core::Part::with_lods)) are drawn as geometry and
    /// captured with the coarsest level whose deviation projects within this many pixels
    /// of the frame (of the build's view for captures); 0 draws the full meshes.
    pub lod_px: f32,
}

impl Default for PortalConfig {
    fn default() -> Self {
        PortalConfig {
            image: PortalImage::Ldi,
            side: 384,
            reach: 1.0,
            tolerance_px: 48.0,
            tolerance: 0.03,
            through: 1.0,
            views_per_frame: 1,
            fill: Fill::PullPush,
            options: WarpOptions::default(),
            lod_px: 0.5,
        }
    }
}

/// How a portal was drawn in the last frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PortalMode {
    /// Its opening is not on screen, or faces away (the eye is past its plane in another
    /// room): nothing drawn.
    Culled,
    /// Its LDI warped into the opening.
    Warped,
    /// Its geometry: the eye is at the opening or in the room behind it, or no LDI has
    /// been built yet.
    Geometry,
}

/// A door or window and what lies behind it.
#[derive(Debug)]
pub struct Portal {
    /// The doorway or window, world space.
    pub opening: Opening,
    /// The geometry seen through the opening (drawn only when the portal shows geometry).
    pub behind: MeshGroup,
    ldi: Option<LayeredDepthImage>,
    prepared: Prepared,
    /// The eye the LDI was built from, the reach of its region, and the on-screen size
    /// (pixels) it was built for.
    built_at: Option<(Vec3, f32, u32)>,
    /// A build under way.
    pending: Option<Pending>,
    /// The depth range of the LDI's front layer (for the predicted error).
    range: Option<(f32, f32)>,
    mode: PortalMode,
    rebuilds: u64,
    /// Whether the eye came into the room through this opening (it was over the opening,
    /// and has not since gone back out in front of it farther than `through`).
    entered: bool,
    /// The box `[min, max]` around `behind`'s vertices: an eye past the opening's plane is
    /// in the room if it came through the opening or stands inside this box.
    room: Option<[Vec3; 2]>,
    /// Which of `behind`'s parts are drawn when the portal shows its geometry: from an
    /// eye in front of the opening, only those it can see through it ([`Opening::sees`]).
    shown: Vec<bool>,
    /// The eye, pixels per radian and pixel tolerance the shown parts' levels of detail
    /// are chosen for ([`Part::mesh_seen`](crate::core::Part::mesh_seen)).
    seen: (Vec3, f32, f32),
    /// LDIs built at loading along a known path ([`Portals::prepare_path`]).
    ahead: Vec<ahead::Built>,
}

impl Portal {
    /// A portal through `opening` onto `behind`, culled and with no image until the first
    /// frame that sees it.
    pub fn new(opening: Opening, behind: MeshGroup) -> Self {
        let room = room_box(&behind);
        Portal {
            opening,
            behind,
            entered: false,
            room,
            ldi: None,
            prepared: Prepared::default(),
            built_at: None,
            pending: None,
            range: None,
            mode: PortalMode::Culled,
            rebuilds: 0,
            shown: Vec::new(),
            seen: (Vec3::ZERO, 0.0, 0.0),
            ahead: Vec::new(),
        }
    }

    /// How it was drawn in the last frame.
    pub fn mode(&self) -> PortalMode {
        self.mode
    }

    /// The LDI it warps, if built.
    pub fn ldi(&self) -> Option<&LayeredDepthImage> {
        self.ldi.as_ref()
    }

    /// LDIs built so far.
    pub fn rebuilds(&self) -> u64 {
        self.rebuilds
    }

    /// Forgets the LDI (after `behind` changed): the next frame rebuilds it.
    pub fn invalidate(&mut self) {
        self.ldi = None;
        self.built_at = None;
        self.pending = None;
        self.room = room_box(&self.behind);
    }

    /// Whether the eye is in the room behind the opening (past its plane, and come
    /// through it or inside the room's box), updating what the eye came through.
    fn eye_inside(&mut self, eye: Vec3, through: f32) -> bool {
        let side = self.opening.side(eye);
        if side > through {
            self.entered = false;
        } else if self.opening.over(eye) {
            self.entered = true;
        }
        let boxed = self
            .room
            .is_some_and(|[lo, hi]| eye.cmpge(lo).all() && eye.cmple(hi).all());
        side <= 0.0 && (self.entered || boxed)
    }

    /// Marks the parts of `behind` the portal draws as geometry from `eye`: those it can
    /// see through the opening (all of them from inside the room), each at its coarsest
    /// level of detail within `lod_px` at `px_per_radian`; returns their triangles and
    /// the parts left out.
    fn show_from(&mut self, eye: Vec3, px_per_radian: f32, lod_px: f32) -> (u64, u64) {
        let opening = self.opening;
        self.shown.clear();
        self.seen = (eye, px_per_radian, lod_px);
        let (mut triangles, mut hidden) = (0, 0);
        for part in &self.behind.parts {
            let s = part.bounds();
            let seen = opening.sees(eye, s.center, s.radius);
            self.shown.push(seen);
            if seen {
                let mesh = part.mesh_seen(eye, px_per_radian, lod_px);
                triangles += (mesh.indices.len() / 3) as u64;
            } else {
                hidden += 1;
            }
        }
        (triangles, hidden)
    }

    /// The reach of a region around `eye` ([`PortalConfig::reach`]).
    fn reach(&self, eye: Vec3, config: &PortalConfig) -> f32 {
        config.reach.min(0.35 * self.opening.side(eye).abs())
    }

    /// Starts a build from `eye` for an opening `screen` pixels across.
    fn start(&mut self, eye: Vec3, screen: u32, config: &PortalConfig) {
        let reach = self.reach(eye, config);
        let cameras = build_cameras(&self.opening, &self.behind, eye, reach);
        let side = (screen as f32 * 1.5).clamp(64.0, config.side.max(1) as f32) as u32;
        let views = match config.image {
            PortalImage::Ldi => cameras.len(),
            PortalImage::DepthImage | PortalImage::Flat => 1,
        };
        let (w, h) = ldi_size(&cameras[0], side);
        self.pending = Some(Pending {
            eye,
            reach,
            screen,
            size: (w, h),
            landing: LdiLanding::new(&cameras[0], w, h),
            cameras,
            views,
        });
    }

    /// Captures up to `budget` more views of the build under way; when the last is in,
    /// merges them into the new LDI. Returns the views captured and whether it finished.
    fn advance(
        &mut self,
        budget: usize,
        config: &PortalConfig,
        lighting: &Lighting,
        capturer: &mut Capturer,
        builder: &mut LdiBuilder,
        frame: &mut PortalFrame,
    ) -> (usize, bool) {
        let Some(b) = self.pending.as_mut() else {
            return (0, false);
        };
        let start = Instant::now();
        let mut captured = 0;
        let mut draws = Vec::new();
        // The eye's image plane is parallel to the opening: for a flat image the opening's
        // plane is at one depth along the axis for every pixel.
        let plane = self.opening.side(b.eye);
        while captured < budget && b.landing.images() < b.views {
            let camera = b.cameras[b.landing.images()];
            let mut image = DepthImage::new(0, 0, camera);
            let (w, h) = b.size;
            // Each view with the levels of detail its own eye and pixels need.
            draws.clear();
            let ppr = px_per_radian(&camera, h);
            let behind = &self.behind;
            behind.draws_seen(camera.eye(), ppr, config.lod_px, &mut draws);
            capturer.capture(draws.iter().copied(), &camera, lighting, w, h, &mut image);
            if config.image == PortalImage::Flat {
                for d in image.depth.iter_mut().filter(|d| d.is_finite()) {
                    *d = plane;
                }
            }
            // Landed now, so the frame that takes the last view only merges.
            b.landing.add(&image, config.tolerance);
            captured += 1;
        }
        let merge = Instant::now();
        frame.captures += merge - start;
        if b.landing.images() < b.views {
            return (captured, false);
        }
        let Some(mut b) = self.pending.take() else {
            return (captured, false);
        };
        let ldi = builder.merge(&mut b.landing, config.tolerance);
        self.prepared.prepare_ldi(&ldi, config.options.edge);
        self.range = depth_range(&ldi.layer(0));
        self.ldi = Some(ldi);
        self.built_at = Some((b.eye, b.reach, b.screen));
        self.rebuilds += 1;
        frame.merges += merge.elapsed();
        (captured, true)
    }
}

/// A portal's build under way: where from, for what, and the views captured so far.
#[derive(Debug)]
struct Pending {
    eye: Vec3,
    reach: f32,
    screen: u32,
    size: (u32, u32),
    cameras: [Camera; 5],
    /// Views the build takes (the first `views` cameras).
    views: usize,
    /// The views captured so far, landed in the LDI camera.
    landing: LdiLanding,
}

/// What the portals did in the last frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PortalFrame {
    /// Portals warped.
    pub warped: u64,
    /// Portals drawn as geometry (those of `gaping` included).
    pub geometry: u64,
    /// Triangles of the geometry drawn for those portals (parts that cannot be seen
    /// through the opening from the eye left out).
    pub triangles: u64,
    /// Parts of the rooms drawn as geometry left out: not seen through their opening.
    pub hidden_parts: u64,
    /// Portals drawn as geometry because their LDI's warp left more than 5% of the
    /// opening's pixels holes (the eye sees much the LDI does not hold).
    pub gaping: u64,
    /// Portals off the view, not drawn.
    pub culled: u64,
    /// LDIs finished this frame.
    pub rebuilds: u64,
    /// Views captured for builds this frame.
    pub views: u64,
    /// Portals shown with an image (or geometry) older than they want while their build is
    /// under way.
    pub stale: u64,
    /// The work of the frame's warps, summed over the warped portals.
    pub stats: WarpStats,
    /// The largest predicted parallax of the warped portals, target pixels.
    pub predicted_px: f32,
    /// Holes inside the openings before filling.
    pub holes: u64,
    /// Pixels the image pass offers the frame.
    pub pixels: u64,
    /// Portals that took an LDI built at loading ([`Portals::prepare_path`]) instead of
    /// starting a build.
    pub ahead: u64,
    /// Time capturing views for builds (wall clock).
    pub captures: Duration,
    /// Time merging the views into LDIs and preparing them for the warp.
    pub merges: Duration,
    /// Time clearing the composite, warping, filling and clipping into it.
    pub warps: Duration,
}

impl PortalFrame {
    /// Counts a portal's geometry: its triangles drawn and parts left out.
    fn show(&mut self, (triangles, hidden): (u64, u64)) {
        self.triangles += triangles;
        self.hidden_parts += hidden;
    }
}

/// A set of portals as one technique.
#[derive(Debug)]
pub struct Portals {
    /// The portals, each warped or drawn as geometry on its own.
    pub portals: Vec<Portal>,
    /// Settings; may be changed between frames.
    pub config: PortalConfig,
    /// Tints warped pixels green, to see where the image stands in for geometry.
    pub debug_tint: bool,
    warper: Warper,
    filler: Filler,
    builder: LdiBuilder,
    capturer: Capturer,
    /// The warped pixels inside the openings, at the frame's camera.
    composite: Warped,
    /// The rectangles of the frame the warped openings cover, one a portal.
    covered: Vec<[u32; 4]>,
    last: PortalFrame,
}

impl Portals {
    /// A technique drawing `portals` with `config`; nothing is built before the first frame.
    pub fn new(portals: Vec<Portal>, config: PortalConfig) -> Self {
        let camera = Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 1.0, 1.0);
        Portals {
            portals,
            config,
            debug_tint: false,
            warper: Warper::new(),
            filler: Filler::default(),
            builder: LdiBuilder::default(),
            capturer: Capturer::new(),
            composite: Warped::new(0, 0, camera),
            covered: Vec::new(),
            last: PortalFrame::default(),
        }
    }

    /// What the portals did in the last frame.
    pub fn last(&self) -> PortalFrame {
        self.last
    }

    /// The warped pixels of the last frame (holes elsewhere).
    pub fn image(&self) -> &Warped {
        &self.composite
    }

    /// Decides each portal's mode for `camera`, rebuilds LDIs within the budget, and warps
    /// and clips the warped portals into the composite image.
    pub fn update(&mut self, camera: &Camera, width: u32, height: u32, lighting: &Lighting) {
        let eye = camera.eye();
        let cfg = self.config;
        let mut frame = PortalFrame::default();
        let t0 = Instant::now();
        if (self.composite.width(), self.composite.height()) == (width, height) {
            // Only the last frame's openings hold samples.
            for &rect in &self.covered {
                self.composite.clear_rect(rect);
            }
            self.composite.camera = *camera;
        } else {
            self.composite.reset(camera, width, height);
        }
        self.covered.clear();
        frame.warps += t0.elapsed();
        let mut budget = cfg.views_per_frame;
        let ppr = px_per_radian(camera, height);
        for p in &mut self.portals {
            let side = p.opening.side(eye);
            if p.eye_inside(eye, cfg.through) || (side <= cfg.through && p.opening.over(eye)) {
                p.mode = PortalMode::Geometry;
                frame.geometry += 1;
                frame.show(p.show_from(eye, ppr, cfg.lod_px));
                continue;
            }
            // Past the plane but not in the room (come in through another door): the
            // opening faces away, its room cannot be seen through it.
            let outline = (side > 0.0)
                .then(|| p.opening.outline(camera, width, height))
                .flatten();
            let Some(outline) = outline else {
                p.mode = PortalMode::Culled;
                frame.culled += 1;
                continue;
            };
            let [x0, y0, x1, y1] = outline.bounds;
            let screen = (x1 - x0).max(y1 - y0);
            let predicted = match (&p.ldi, p.range) {
                (Some(ldi), Some(range)) => parallax_px(range, &ldi.camera, camera, width, height),
                _ => 0.0,
            };
            if !fresh(p.built_at, predicted, eye, screen, &cfg) {
                // A build under way is finished even if the eye has left its region (it is
                // still nearer than the old one, and restarting could starve a fast eye);
                // the next is started from wherever the eye is then.
                if p.pending.is_none() && p.take_ahead(camera, (width, height), screen, &cfg) {
                    frame.ahead += 1;
                } else {
                    if p.pending.is_none() {
                        p.start(eye, screen, &cfg);
                    }
                    let (views, done) = p.advance(
                        budget,
                        &cfg,
                        lighting,
                        &mut self.capturer,
                        &mut self.builder,
                        &mut frame,
                    );
                    budget -= views;
                    frame.views += views as u64;
                    frame.rebuilds += done as u64;
                    frame.stale += !done as u64;
                }
            }
            if p.ldi.is_none() {
                p.mode = PortalMode::Geometry;
                frame.geometry += 1;
                frame.show(p.show_from(eye, ppr, cfg.lod_px));
                continue;
            }
            // Warped into the outline's rectangle only (a crop of the frame's camera), so
            // the warp's image, its fill and the copy cost the opening's pixels.
            let (lo, hi) = (
                Vec2::new(x0 as f32, y0 as f32),
                Vec2::new(x1 as f32, y1 as f32),
            );
            let crop = camera.crop(lo, hi, width, height);
            let t0 = Instant::now();
            self.warper.begin(&crop, x1 - x0, y1 - y0);
            frame.stats += self.warper.add_prepared(&p.prepared, &cfg.options);
            let out = self.warper.output_mut();
            let (holes, inside) = holes_inside(out, &outline);
            if cfg.image == PortalImage::Ldi && holes as f64 > MAX_LDI_HOLES * inside as f64 {
                // The eye sees what the LDI does not hold (built from eyes that did not
                // see there): the geometry, not a hole-filled smear.
                p.mode = PortalMode::Geometry;
                frame.geometry += 1;
                frame.gaping += 1;
                frame.show(p.show_from(eye, ppr, cfg.lod_px));
                frame.warps += t0.elapsed();
                continue;
            }
            p.mode = PortalMode::Warped;
            frame.warped += 1;
            frame.predicted_px = frame.predicted_px.max(predicted);
            frame.holes += holes;
            self.filler.fill(out, cfg.fill, cfg.options.edge);
            frame.pixels += clip_into(&mut self.composite, out, &outline, self.debug_tint);
            self.covered.push(outline.bounds);
            frame.warps += t0.elapsed();
        }
        self.last = frame;
    }
}

/// Whether an LDI built at `built_at` (eye, reach, the opening's size on screen then)
/// still serves an eye at `eye` seeing the opening `screen` pixels across, the move's
/// predicted parallax `predicted` pixels.
fn fresh(
    built_at: Option<(Vec3, f32, u32)>,
    predicted: f32,
    eye: Vec3,
    screen: u32,
    cfg: &PortalConfig,
) -> bool {
    built_at
        .is_some_and(|(at, reach, built)| at.distance(eye) <= reach && screen <= 2 * built.max(32))
        && predicted <= cfg.tolerance_px
}

/// Pixels per unit of tangent at the centre of `camera`'s image, `height` pixels tall
/// (its focal length in pixels: a small length across the view at distance `d` covers
/// its length times this over `d` pixels there).
fn px_per_radian(camera: &Camera, height: u32) -> f32 {
    let [_, _, bottom, top] = camera.projection.extents();
    let near = camera.near_far().0;
    height as f32 * near / (top - bottom).max(1e-9)
}

/// The share of an opening's pixels an LDI's warp may leave as holes: past it, the eye
/// sees much the LDI does not hold and the portal draws its geometry that frame. A
/// current LDI leaves almost none (a crack's worth); a stale one seen from where its
/// eyes did not look leaves whole walls, which the fill smeared with the doorway's
/// edges (the grey and orange smudges of issue 39's `building_0033` to `_0037`).
pub(crate) const MAX_LDI_HOLES: f64 = 0.05;

impl Technique for Portals {
    fn name(&self) -> &str {
        "ldi portals"
    }

    fn prepare(&mut self, view: &FrameView<'_>) {
        self.update(view.camera, view.width, view.height, view.lighting);
    }

    fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        for p in &self.portals {
            if p.mode == PortalMode::Geometry {
                let (eye, ppr, lod_px) = p.seen;
                let parts = p.behind.parts.iter().zip(&p.shown);
                out.extend(parts.filter(|(_, &s)| s).map(|(part, _)| Draw {
                    mesh: part.mesh_seen(eye, ppr, lod_px),
                    material: &part.material,
                    transform: part.transform,
                }));
            }
        }
    }

    fn passes(&self, _view: &FrameView<'_>, target: &mut Target) -> FrameStats {
        // One pass a warped opening's rectangle, not over the rectangle around them all
        // (the wall between two doorways holds no sample).
        let pass = ImagePass::new(&self.composite);
        let mut stats = FrameStats::default();
        for &[x0, y0, x1, y1] in &self.covered {
            let rect = PixelRect { x0, y0, x1, y1 };
            stats += run_packed_pass(target, rect, &pass, PassMode::default());
        }
        stats
    }

    fn counters(&self) -> Counters {
        let f = self.last;
        Counters {
            images: f.warped,
            refreshes: f.rebuilds,
            geometry: f.geometry,
            pixels: f.pixels,
            samples: f.stats.samples,
            holes: f.holes,
            ..Counters::default()
        }
    }

    fn reference<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        for p in &self.portals {
            p.behind.draws(out);
        }
    }
}

#[cfg(test)]
mod tests;

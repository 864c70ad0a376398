//! Engine renders against the analytic ray-cast reference: which triangle each pixel shows
//! and the depth stored there.
//!
//! The engine snaps vertices to 1/256 pixel and computes in `f32`, the reference is exact
//! `f64` geometry, so a pixel whose centre lies within [`EDGE_EPS_PX`] of a boundary (a
//! triangle edge, the near-plane cut, an intersection line) may legitimately go either way.
//! Such pixels are found by casting 8 more rays on a circle of that radius around the
//! centre: if they disagree with the centre about which triangle is visible, the pixel is
//! *ambiguous* and skipped. Every other pixel must show exactly the reference's triangle
//! (or nothing), and its depth must match (see [`DEPTH_TOL_OF_MAX`]).

use crate::reference::{to_f64, Hit, RayCast};
use engine::{
    Camera, Cull, Encoding, FrameOptions, FrameStats, Material, Renderer, Rgba, Scene, Target,
};
use glam::{Mat4, Vec3};

/// Radius (pixels) of the "too close to a boundary to call" circle. Snapping moves a
/// vertex by at most 1/512 pixel per axis and `f32` projection adds far less, so an edge
/// drawn by the engine is within ~0.003 px of the exact one; 1/64 px leaves a 5x margin
/// and still checks all but a thin band along each boundary.
pub const EDGE_EPS_PX: f64 = 1.0 / 64.0;

/// Tolerance on stored reversed depth, as a fraction of the largest depth visible in the
/// scene, on top of the reference's own range over the ring of radius [`EDGE_EPS_PX`]
/// (which covers vertex snapping). The engine interpolates depth as an `f32` plane whose
/// terms are as large as the largest depth it reaches, so rounding is a few ulps of that
/// (2^-23 ~ 1.2e-7 relative); 1e-5 is ~80 ulps.
pub const DEPTH_TOL_OF_MAX: f64 = 1e-5;

/// Renders each triangle as its own draw in a colour that encodes its index (unorm bytes:
/// `index + 1` in R and G), on a black clear, so [`id_at`] can tell which one a pixel shows.
pub fn render_ids(
    tris: &[[Vec3; 3]],
    camera: &Camera,
    w: u32,
    h: u32,
    cull: Cull,
) -> (Target, FrameStats) {
    assert!(tris.len() < 65535);
    let mut scene = Scene::default();
    for (i, t) in tris.iter().enumerate() {
        let id = i as u32 + 1;
        let c = Rgba::new(
            (id & 0xff) as f32 / 255.0,
            (id >> 8) as f32 / 255.0,
            0.0,
            1.0,
        );
        scene.add(
            crate::scenes::soup(&[*t]),
            Material::unlit(c).double_sided(true),
            Mat4::IDENTITY,
        );
    }
    let mut target = Target::with_encoding(w, h, Encoding::Unorm);
    let opts = FrameOptions {
        clear: Some(Rgba::BLACK),
        cull,
    };
    let stats = Renderer::new().render_scene(&scene, camera, &mut target, &opts);
    (target, stats)
}

/// The triangle index a pixel of a [`render_ids`] target shows, or `None` for the clear
/// colour.
pub fn id_at(t: &Target, x: u32, y: u32) -> Option<usize> {
    let [r, g, _, _] = t.pixel(x, y).expect("inside").to_le_bytes();
    let id = r as usize | (g as usize) << 8;
    id.checked_sub(1)
}

/// What a comparison found.
#[derive(Clone, Debug, Default)]
pub struct Report {
    /// Pixels compared.
    pub checked: u64,
    /// Pixels skipped as within [`EDGE_EPS_PX`] of a boundary.
    pub ambiguous: u64,
    /// Pixels the reference says are covered (of the checked ones).
    pub covered: u64,
    /// (x, y, engine id, reference id) of pixels showing the wrong triangle.
    pub wrong_id: Vec<(u32, u32, Option<usize>, Option<usize>)>,
    /// (x, y, engine depth, reference range) of pixels with a wrong depth.
    pub wrong_depth: Vec<(u32, u32, f32, (f64, f64))>,
}

impl Report {
    /// Fails unless every checked pixel is right.
    ///
    /// # Panics
    /// On any wrong pixel.
    pub fn assert_ok(&self, what: &str) {
        assert!(
            self.wrong_id.is_empty() && self.wrong_depth.is_empty(),
            "{what}: {} pixels show the wrong triangle (x, y, engine, reference; first 10: {:?}); \
             {} have a wrong depth (x, y, engine, reference range; first 10: {:?}); \
             {} checked, {} skipped as ambiguous",
            self.wrong_id.len(),
            &self.wrong_id[..self.wrong_id.len().min(10)],
            self.wrong_depth.len(),
            &self.wrong_depth[..self.wrong_depth.len().min(10)],
            self.checked,
            self.ambiguous
        );
    }
}

/// Compares a [`render_ids`] target of `tris` with the ray-cast reference, pixel by pixel:
/// the visible triangle, the stored reversed depth (and the OpenGL depth derived from it).
/// Also checks that pixels showing nothing keep the cleared depth 0.
pub fn compare_ids(
    target: &Target,
    tris: &[[Vec3; 3]],
    camera: &Camera,
    cull_back: bool,
) -> Report {
    let (w, h) = (target.width(), target.height());
    let rc = RayCast::new(camera, w, h);
    let tris64 = to_f64(tris);
    let mut r = Report::default();
    // (x, y, engine depth, reference depth range) of the pixels to check for depth.
    let mut depths = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let centre = rc.cast_pixel(x, y, &tris64, cull_back);
            let ring = rc.ring(x, y, EDGE_EPS_PX, &tris64, cull_back);
            let id = |h: &Option<Hit>| h.map(|h| h.tri);
            if ring.iter().any(|s| id(s) != id(&centre)) {
                r.ambiguous += 1;
                continue;
            }
            r.checked += 1;
            let got = id_at(target, x, y);
            let depth = target.depth_reversed(x, y).expect("inside");
            let gl = target.depth_gl(x, y).expect("inside");
            if gl != 1.0 - depth {
                r.wrong_depth.push((x, y, depth, (f64::NAN, f64::NAN)));
            }
            if got != id(&centre) {
                r.wrong_id.push((x, y, got, id(&centre)));
                continue;
            }
            let range = match centre {
                None => (0.0, 0.0),
                Some(c) => {
                    r.covered += 1;
                    // Reversed depth falls as distance grows.
                    let (near, far) =
                        ring.iter().flatten().fold((c.dist, c.dist), |(lo, hi), s| {
                            (lo.min(s.dist), hi.max(s.dist))
                        });
                    (rc.reversed_depth(far), rc.reversed_depth(near))
                }
            };
            depths.push((x, y, depth, range));
        }
    }
    let zmax = depths.iter().map(|d| d.3 .1).fold(0.0, f64::max);
    let tol = DEPTH_TOL_OF_MAX * zmax;
    for (x, y, depth, (lo, hi)) in depths {
        let d = depth as f64;
        if !(d >= lo - tol && d <= hi + tol) {
            r.wrong_depth.push((x, y, depth, (lo, hi)));
        }
    }
    r
}

/// Renders `tris` with [`render_ids`] and compares with the ray-cast reference; fails on any
/// wrong pixel or when fewer than `min_checked` of the pixels could be checked.
pub fn check_raycast(
    what: &str,
    tris: &[[Vec3; 3]],
    camera: &Camera,
    w: u32,
    h: u32,
    cull: Cull,
) -> (Report, FrameStats) {
    let (target, stats) = render_ids(tris, camera, w, h, cull);
    let report = compare_ids(&target, tris, camera, cull == Cull::Back);
    report.assert_ok(what);
    let total = (w * h) as u64;
    assert!(
        report.checked * 10 >= total * 9,
        "{what}: only {} of {total} pixels were unambiguous",
        report.checked
    );
    (report, stats)
}

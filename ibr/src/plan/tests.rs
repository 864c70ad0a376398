//! The planner's promises: no object goes missing, the error budget holds where it can and
//! is reported where it cannot (a time budget, an exhausted rebuild budget, nothing able
//! to draw it), a zero budget is all geometry and an enormous one all images, teleports
//! and changing objects never show a stale image, hysteresis keeps choices still, the
//! same frames give the same pixels on any thread count, and the debug view colours each
//! object by its representation and leaves no trace when turned off.

use super::*;
use crate::core::screen_rect;
use crate::core::MeshGroup;
use crate::core::{CostModel, Estimate, Geometry, Representation, Sight, Work};
use crate::core::{FrameLoop, Technique};
use crate::metrics::{self, Options, Region};
use crate::techniques::impostors::{self as impostor, ImpostorSet};
use engine::{
    procedural, Camera, FrameOptions, Lighting, Material, Renderer, Rgba, Target, Texture,
};
use glam::{Mat4, Vec3};
use std::sync::Arc;

pub(crate) const W: u32 = 320;
pub(crate) const H: u32 = 192;

pub(crate) fn lighting() -> Lighting {
    Lighting::white_sun(0.3, Vec3::new(-0.3, -1.0, -0.4))
}

/// Sixteen lit tori (1024 triangles each) in a 4 x 4 grid two units apart, from z = 0 back
/// to z = -6: each costs far more drawn than as an image.
pub(crate) fn tori() -> Vec<MeshGroup> {
    let mesh = Arc::new(procedural::torus(0.4, 0.15, 32, 16));
    (0..16)
        .map(|k| {
            let at = Vec3::new((k % 4) as f32 * 2.0 - 3.0, 0.0, -((k / 4) as f32) * 2.0);
            let tint = Rgba::new(
                0.3 + 0.15 * (k % 4) as f32,
                0.5,
                0.9 - 0.2 * (k / 4) as f32,
                1.0,
            );
            MeshGroup::new().with(
                mesh.clone(),
                Arc::new(Material::lit(tint)),
                Mat4::from_translation(at) * Mat4::from_rotation_x(1.0 + 0.1 * k as f32),
            )
        })
        .collect()
}

pub(crate) fn camera(eye: Vec3, target: Vec3) -> Camera {
    Camera::look_at(eye, target, Vec3::Y, 0.9, W as f32 / H as f32).with_depth_range(0.05, 100.0)
}

/// The grid from in front and above, at `x` across.
pub(crate) fn view_at(x: f32) -> Camera {
    camera(Vec3::new(x, 2.0, 7.0), Vec3::new(0.0, 0.0, -3.0))
}

/// How the planner sees object `s` from `camera` (its pixels as the planner counts them).
pub(crate) fn sight<'a>(camera: &'a Camera, s: &impl Subject) -> Sight<'a> {
    Sight::new(camera, W, H, s.bounds())
}

/// Renders `draws` on a transparent target under the tests' light.
pub(crate) fn render(draws: Vec<Draw<'_>>, camera: &Camera, r: &mut Renderer) -> Target {
    let mut target = Target::new(W, H);
    let opts = FrameOptions {
        clear: Some(Rgba::TRANSPARENT),
        ..FrameOptions::default()
    };
    r.render(draws, camera, &lighting(), &mut target, &opts);
    target
}

/// The fit of a two-term error model `floor * a + slope * b` to calibration samples `(a,
/// b, measured)`: the pair with the least summed prediction that keeps a fraction `keep`
/// of the measurements at or below it, the slope in steps of 0.01 below `steps` / 100.
pub(crate) fn fit_bound(samples: &[(f32, f32, f32)], keep: f64, steps: u32) -> (f32, f32) {
    let mut best = (f32::INFINITY, 0.0, 0.0);
    let mut need: Vec<f32> = Vec::with_capacity(samples.len());
    for k in 0..steps {
        let k = k as f32 * 0.01;
        // Each sample's floor needed with this slope.
        need.clear();
        need.extend(samples.iter().map(|&(a, b, m)| (m - k * b) / a.max(1e-6)));
        need.sort_by(f32::total_cmp);
        let at = ((need.len() as f64 * keep).ceil() as usize).clamp(1, need.len()) - 1;
        let floor = need[at];
        let total: f32 = samples.iter().map(|&(a, b, _)| floor * a + k * b).sum();
        if total < best.0 {
            best = (total, floor, k);
        }
    }
    (best.1, best.2)
}

/// A perspective camera with a vertical field of view of `fov` radians at `distance`
/// radii from the subject's centre along `dir`, looking at it.
pub(crate) fn camera_at(s: &MeshGroup, dir: Vec3, distance: f32, fov: f32) -> Camera {
    let b = s.bounds();
    let eye = b.center + dir * distance * b.radius;
    Camera::look_at(eye, b.center, Vec3::Y, fov, W as f32 / H as f32)
        .with_depth_range(0.05, distance * b.radius * 2.0 + 10.0)
}

/// The planner tests' field of view.
pub(crate) const FOV: f32 = 0.9;

/// Mean absolute error over the object's screen rectangle, as the planner's unit is.
pub(crate) fn measured(s: &impl Subject, camera: &Camera, got: &Target, want: &Target) -> f64 {
    let b = s.bounds();
    let rect = screen_rect(camera, b.center, b.radius, W, H).unwrap_or_default();
    let opts = Options {
        region: Region::Rect(rect),
        ..Options::default()
    };
    metrics::compare(want, got, &opts)
        .expect("same size")
        .mean_abs
}

/// A tilted lit torus, a lit box, a double-sided checkered card and a torus through a box:
/// silhouettes, flat faces, texture detail and depth spread over the sphere.
pub(crate) fn subjects() -> Vec<MeshGroup> {
    let lit = |c: Rgba| Arc::new(Material::lit(c));
    let torus = Arc::new(procedural::torus(0.8, 0.3, 32, 12));
    let cube = Arc::new(procedural::cuboid(Vec3::new(1.0, 1.3, 0.7)));
    let card = Arc::new(procedural::quad(1.6, 1.6));
    let checker = Arc::new(Texture::checker(
        64,
        8,
        Rgba::new(0.9, 0.8, 0.2, 1.0),
        Rgba::new(0.1, 0.2, 0.6, 1.0),
    ));
    let tilt = Mat4::from_rotation_x(0.6) * Mat4::from_rotation_z(0.3);
    let checkered = Material::unlit(Rgba::WHITE)
        .with_texture(checker)
        .double_sided(true);
    vec![
        MeshGroup::new().with(torus.clone(), lit(Rgba::new(0.3, 0.6, 0.9, 1.0)), tilt),
        MeshGroup::new().with(
            cube.clone(),
            lit(Rgba::new(0.9, 0.5, 0.2, 1.0)),
            Mat4::from_rotation_y(0.4) * Mat4::from_rotation_x(0.2),
        ),
        MeshGroup::new().with(card, Arc::new(checkered), tilt),
        MeshGroup::new()
            .with(torus, lit(Rgba::new(0.8, 0.8, 0.8, 1.0)), tilt)
            .with(
                Arc::new(procedural::cuboid(Vec3::new(0.5, 1.4, 0.3))),
                lit(Rgba::new(0.9, 0.5, 0.1, 1.0)),
                Mat4::from_translation(Vec3::new(0.3, 0.1, 0.0)),
            ),
    ]
}

/// The cost model with the tori's triangles priced as a detailed model's (a hundred times
/// the calibrated cost each): what makes a representation drawn by image passes, tens of
/// microseconds each, cheaper than an object's geometry, for tests of the planner with
/// them among its choices.
pub(crate) fn dear_geometry() -> CostModel {
    let cost = CostModel::default();
    CostModel {
        ns_per_triangle: cost.ns_per_triangle * 100.0,
        ..cost
    }
}

/// A planner over `objects` choosing between geometry and `rep`, with an error budget per
/// object, `rebuilds` a frame and the cost model `cost`. The objects are expected to stay
/// in view ([`Config::horizon`] infinite): a bake is weighed over its whole payback from
/// the first frame.
pub(crate) fn beside_geometry(
    objects: Vec<MeshGroup>,
    rep: Box<dyn Representation<MeshGroup>>,
    error: f32,
    rebuilds: usize,
    cost: CostModel,
) -> Planner<MeshGroup> {
    let config = Config {
        budgets: Budgets {
            error,
            rebuilds,
            ..Budgets::default()
        },
        cost,
        horizon: f32::INFINITY,
        ..Config::default()
    };
    Planner::new(config, objects, vec![Box::new(Geometry), rep])
}

/// A baked representation's promises about a changed subject, for object `i` of
/// `subjects` seen from `cam`, whose bake (already made) errs `fresh` from there: a new
/// version makes its error infinite and a rebuild's the same as before, the rebuild
/// restores it, a move without a new version makes it infinite again (a rebuild finite),
/// and an object past the set's range has no estimate.
pub(crate) fn assert_changes_invalidate(
    set: &mut dyn Representation<MeshGroup>,
    subjects: &mut [MeshGroup],
    i: usize,
    cam: &Camera,
    fresh: Estimate,
) {
    let light = lighting();
    let view = FrameView::still(cam, W, H, &light);
    let seen = sight(cam, &subjects[i]);
    // Animated: the bake no longer shows it; a rebuild would.
    subjects[i].version += 1;
    let stale = set.estimate(i, &subjects[i], &seen).expect("seen");
    assert!(stale.error.is_infinite(), "{stale:?}");
    assert_eq!(stale.rebuilt, fresh.rebuilt);
    set.rebuild(&[i], subjects, &view);
    let again = set.estimate(i, &subjects[i], &seen).expect("seen");
    assert_eq!(again.error, fresh.error);
    // Moved without a new version: the bake sits where the subject was.
    subjects[i].parts[0].transform *= Mat4::from_translation(Vec3::X * 0.1);
    let seen = sight(cam, &subjects[i]);
    let moved = set.estimate(i, &subjects[i], &seen).expect("seen");
    assert!(
        moved.error.is_infinite() && moved.rebuilt.is_finite(),
        "{moved:?}"
    );
    // An object out of the set's range: nothing to say.
    assert!(set
        .estimate(subjects.len().max(1) * 1000, &subjects[i], &seen)
        .is_none());
}

/// Each frame's pixels and choices, and the objects each representation drew in the last.
pub(crate) type Flown = (Vec<(Vec<u8>, Vec<Choice>)>, Vec<usize>);

/// The planner `make` gives, flown through `cams` in order on a pool of `threads`.
pub(crate) fn fly_on_threads(
    threads: usize,
    make: impl FnOnce() -> Planner<MeshGroup> + Send,
    cams: &[Camera],
) -> Flown {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let (mut p, mut r) = (make(), Renderer::new());
        let frames = cams.iter().map(|cam| {
            let t = frame(&mut p, cam, &mut r);
            (t.to_rgba8(), p.choices().to_vec())
        });
        let frames = frames.collect();
        (frames, p.report.counts.clone())
    })
}

/// Planner `p` flown for `frames` frames at `cam` (releasing what is unused after 3)
/// holds images, all of them its representation `rep`'s; looking away, it keeps them two
/// frames and then frees them all. Returns the bytes it held.
pub(crate) fn assert_holds_then_releases_when_away(
    p: &mut Planner<MeshGroup>,
    rep: usize,
    cam: &Camera,
    frames: usize,
    r: &mut Renderer,
) -> usize {
    p.config.release_after = 3;
    for _ in 0..frames {
        frame(p, cam, r);
    }
    let held = p.report.memory;
    let set = p.representation(rep).expect("the representation");
    assert!(held > 0 && set.memory() == held, "{:?}", p.report);
    let away = camera(Vec3::new(0.0, 2.0, 7.0), Vec3::new(0.0, 2.0, 20.0));
    for k in 0..6 {
        frame(p, &away, r);
        assert_eq!(p.report.culled, p.objects.len());
        if k < 2 {
            assert_eq!(p.report.memory, held, "frame {k}");
        }
    }
    assert_eq!(p.report.memory, 0, "{:?}", p.report);
    held
}

/// Object `i` of `set` seen alone from `camera`: its estimate, then its image drawn on an
/// empty frame (prepared, then by its draws and its passes), and the object's geometry
/// drawn alone. `None` where `set` gives no estimate.
pub(crate) fn drawn_alone(
    set: &mut dyn Representation<MeshGroup>,
    subjects: &[MeshGroup],
    i: usize,
    camera: &Camera,
    r: &mut Renderer,
) -> Option<(Estimate, Target, Target)> {
    let s = &subjects[i];
    let e = set.estimate(i, s, &sight(camera, s))?;
    let light = lighting();
    let view = FrameView::still(camera, W, H, &light);
    set.prepare(&[i], subjects, &view);
    let mut draws = Vec::new();
    set.draw(i, s, camera.eye(), &mut draws);
    let mut got = render(draws, camera, r);
    set.passes(&view, &mut got);
    let mut draws = Vec::new();
    s.draws(&mut draws);
    Some((e, got, render(draws, camera, r)))
}

/// One object's view in a calibration run of a baked representation: its image's
/// gradients (levels per texel, and depth-weighted), the view's texels per screen pixel
/// and parallax shift (texels), and the error predicted and measured.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Sample {
    pub gradient: f32,
    pub depth_gradient: f32,
    pub texels_per_px: f32,
    pub shift: f32,
    pub predicted: f32,
    pub measured: f64,
}

impl Sample {
    /// The prediction's two terms without their constants: resampling (texel density)
    /// and parallax (ghosting).
    pub(crate) fn terms(&self) -> (f32, f32) {
        (
            self.gradient * self.texels_per_px.max(1.0),
            self.depth_gradient * self.shift,
        )
    }
}

/// `s` (object 0 of `set`) seen by a NaN eye, by an eye at its centre and from `cam` on an
/// empty target: no estimate.
pub(crate) fn assert_no_estimate_from_odd_views(
    set: &dyn Representation<MeshGroup>,
    s: &MeshGroup,
    cam: &Camera,
) {
    let nan = camera(Vec3::NAN, Vec3::ZERO);
    let c = s.bounds().center;
    let inside = camera(c, c + Vec3::Z);
    let empty = Sight {
        width: 0,
        height: 0,
        ..sight(cam, s)
    };
    for seen in [sight(&nan, s), sight(&inside, s), empty] {
        assert!(set.estimate(0, s, &seen).is_none(), "{seen:?}");
    }
}

/// Object 1 released, then indices past `set`'s objects: ignored by `release`, by
/// `rebuild` (no work) and by `prepare` (with object 1, now holding nothing).
pub(crate) fn release_one_and_ignore_out_of_range(
    set: &mut dyn Representation<MeshGroup>,
    subjects: &mut [MeshGroup],
    view: &FrameView<'_>,
) {
    set.release(1);
    set.release(99);
    assert_eq!(set.rebuild(&[99], subjects, view), Work::default());
    set.prepare(&[1, 99], subjects, view);
}

pub(crate) fn planner(budgets: Budgets) -> Planner<MeshGroup> {
    let objects = tori();
    let n = objects.len();
    let reps: Vec<Box<dyn Representation<MeshGroup>>> = vec![
        Box::new(Geometry),
        Box::new(ImpostorSet::new(impostor::Config::default(), n)),
    ];
    let config = Config {
        budgets,
        ..Config::default()
    };
    Planner::new(config, objects, reps)
}

pub(crate) fn budgets(error: f32, rebuilds: usize) -> Budgets {
    Budgets {
        error,
        rebuilds,
        ..Budgets::default()
    }
}

/// Renders one frame through the frame loop; returns the target.
pub(crate) fn frame<S: Subject + Send + Sync>(
    p: &mut Planner<S>,
    cam: &Camera,
    r: &mut Renderer,
) -> Target {
    let light = lighting();
    let view = FrameView::still(cam, W, H, &light);
    let mut target = Target::new(W, H);
    let mut techniques: [&mut dyn Technique; 1] = [p];
    FrameLoop::new().render(
        r,
        std::iter::empty(),
        &mut techniques,
        &view,
        &mut target,
        &FrameOptions::default(),
    );
    target
}

/// Every object's geometry from `cam`.
pub(crate) fn truth<S: Subject + Send + Sync>(
    p: &Planner<S>,
    cam: &Camera,
    r: &mut Renderer,
) -> Target {
    let mut draws = Vec::new();
    p.reference(&mut draws);
    let mut target = Target::new(W, H);
    r.render(
        draws,
        cam,
        &lighting(),
        &mut target,
        &FrameOptions::default(),
    );
    target
}

pub(crate) const GEOMETRY: usize = 0;
pub(crate) const IMAGES: usize = 1;

/// Every object the frustum keeps has a representation that draws something.
pub(crate) fn assert_none_missing(p: &Planner<MeshGroup>) {
    let visible = p.choices().iter().filter(|c| c.rep.is_some()).count();
    assert_eq!(visible + p.report.culled, p.objects.len());
    for (i, c) in p.choices().iter().enumerate() {
        if let Some(r) = c.rep {
            let mut out = Vec::new();
            p.representation(r)
                .unwrap()
                .draw(i, &p.objects[i], p.eye, &mut out);
            assert!(!out.is_empty(), "object {i} chose {r} but draws nothing");
        }
    }
}

#[test]
fn a_zero_error_budget_draws_only_geometry_and_matches_it_exactly() {
    let mut p = planner(budgets(0.0, 16));
    let mut r = Renderer::new();
    for x in [0.0, 0.5, 1.0] {
        let cam = view_at(x);
        let got = frame(&mut p, &cam, &mut r);
        assert_eq!(p.report.counts[IMAGES], 0, "{:?}", p.report);
        assert_eq!(p.report.counts[GEOMETRY], 16 - p.report.culled);
        assert_eq!((p.report.rebuilds, p.report.over_budget), (0, 0));
        assert_none_missing(&p);
        let want = truth(&p, &cam, &mut r);
        assert_eq!(got.to_rgba8(), want.to_rgba8());
    }
}

#[test]
fn an_enormous_budget_turns_everything_into_images_within_the_rebuild_budget() {
    let mut p = planner(budgets(1e9, 5));
    let mut r = Renderer::new();
    let cam = view_at(0.0);
    let mut images = Vec::new();
    for _ in 0..5 {
        frame(&mut p, &cam, &mut r);
        assert!(p.report.rebuilds <= 5, "{:?}", p.report);
        assert_none_missing(&p);
        images.push(p.report.counts[IMAGES]);
    }
    let visible = 16 - p.report.culled;
    assert!(visible >= 12, "{:?}", p.report);
    // Five a frame until all are images; then nothing more to rebuild.
    assert_eq!(images[0], 5);
    assert_eq!(images[1], 10);
    assert_eq!(*images.last().unwrap(), visible, "{images:?}");
    assert_eq!(p.report.rebuilds, 0);
    assert!(p.report.memory > 0);
}

#[test]
fn a_memory_budget_caps_what_the_images_hold() {
    // An enormous error budget, plenty of rebuilds, and memory for about four images of
    // the first frame's sizes: images stop at the memory, the rest stay geometry and are
    // counted as deferred; nothing is missing.
    let mut probe = planner(budgets(1e9, 16));
    let mut r = Renderer::new();
    let cam = view_at(0.0);
    frame(&mut probe, &cam, &mut r);
    let per_image = probe.report.memory / probe.report.counts[IMAGES].max(1);
    assert!(per_image > 0, "{:?}", probe.report);
    let cap = per_image * 4 + per_image / 2;
    for scope in [Scope::Object, Scope::Frame] {
        let mut p = planner(Budgets {
            memory: Some(cap),
            scope,
            ..budgets(1e9, 16)
        });
        for _ in 0..3 {
            frame(&mut p, &cam, &mut r);
            assert_none_missing(&p);
            assert!(p.report.memory <= cap, "{scope:?} {:?}", p.report);
        }
        let images = p.report.counts[IMAGES];
        assert!((1..=6).contains(&images), "{scope:?} {:?}", p.report);
        assert!(p.report.deferred > 0, "{scope:?} {:?}", p.report);
    }
}

#[test]
fn an_exhausted_rebuild_budget_leaves_geometry_and_says_so() {
    // No rebuilds at all: no image ever exists, so everything stays geometry, within the
    // error budget, and the wanted rebuilds are counted as deferred.
    let mut p = planner(budgets(4.0, 0));
    let mut r = Renderer::new();
    frame(&mut p, &view_at(0.0), &mut r);
    assert_eq!(p.report.counts[IMAGES], 0);
    assert_eq!(p.report.over_budget, 0);
    assert!(p.report.deferred > 0, "{:?}", p.report);
    assert_none_missing(&p);
}

#[test]
fn without_geometry_an_object_nothing_can_draw_is_reported_not_hidden_in_the_mean() {
    let objects = tori();
    let n = objects.len();
    let reps: Vec<Box<dyn Representation<MeshGroup>>> =
        vec![Box::new(ImpostorSet::new(impostor::Config::default(), n))];
    let config = Config {
        budgets: budgets(4.0, 3),
        ..Config::default()
    };
    let mut p = Planner::new(config, objects, reps);
    let mut r = Renderer::new();
    frame(&mut p, &view_at(0.0), &mut r);
    let visible = n - p.report.culled;
    assert_eq!(p.report.rebuilds, 3);
    // Three images; the rest had nothing and are said to be over for want of rebuilds.
    assert_eq!(p.report.counts[0], visible);
    assert_eq!(p.report.over_rebuilds, visible - 3, "{:?}", p.report);
    assert_eq!(p.report.over_budget, visible - 3);
    assert!(p.report.max_error.is_infinite());
}

#[test]
fn a_teleport_never_shows_a_stale_image() {
    let mut p = planner(budgets(6.0, 2));
    let mut r = Renderer::new();
    for _ in 0..10 {
        frame(&mut p, &view_at(0.0), &mut r);
    }
    assert!(p.report.counts[IMAGES] >= 8, "{:?}", p.report);
    // To the other side of the grid, looking back: every image is far from its capture.
    let behind = camera(Vec3::new(4.0, 3.0, -12.0), Vec3::new(0.0, 0.0, -3.0));
    frame(&mut p, &behind, &mut r);
    let rep = &p.report;
    assert!(rep.switches > 0, "{rep:?}");
    assert_eq!(rep.over_budget, 0, "{rep:?}");
    assert!(rep.max_error <= 6.0, "{rep:?}");
    assert_none_missing(&p);
    for c in p.choices().iter().filter(|c| c.rep == Some(IMAGES)) {
        assert!(c.rebuilt, "a stale image was kept: {c:?}");
    }
}

#[test]
fn a_changed_object_is_not_drawn_from_its_old_image() {
    let mut p = planner(budgets(6.0, 16));
    let mut r = Renderer::new();
    let cam = view_at(0.0);
    frame(&mut p, &cam, &mut r);
    frame(&mut p, &cam, &mut r);
    assert_eq!(p.choices()[5].rep, Some(IMAGES));
    // Animate it: its image is invalid, so it is rebuilt (or drawn as geometry).
    p.objects[5].version += 1;
    p.config.budgets.rebuilds = 0;
    frame(&mut p, &cam, &mut r);
    assert_eq!(p.choices()[5].rep, Some(GEOMETRY), "{:?}", p.choices()[5]);
    p.config.budgets.rebuilds = 16;
    frame(&mut p, &cam, &mut r);
    let c = p.choices()[5];
    assert_eq!((c.rep, c.rebuilt), (Some(IMAGES), true), "{c:?}");
}

#[test]
fn hysteresis_keeps_choices_still_under_small_oscillations() {
    let mut p = planner(budgets(5.0, 4));
    let mut r = Renderer::new();
    let mut switches = 0;
    for k in 0..40 {
        // Back and forth by 2 cm: no object's error crosses its band every frame.
        let x = if k % 2 == 0 { 0.0 } else { 0.02 };
        frame(&mut p, &view_at(x), &mut r);
        if k >= 10 {
            switches += p.report.switches;
            assert!(p.report.counts[IMAGES] >= 8, "{:?}", p.report);
        }
    }
    assert!(switches <= 2, "{switches} switches");
}

//! Images the planner takes denser than a texel a pixel ([`ImpostorSet::density`]): an
//! image just taken must pass its own estimate from the same eye, or a still camera
//! rebuilds it every frame; and a rebuild judged after its life
//! ([`ImpostorSet::rebuild_life`]) while the eye moves.

use super::shape::block;
use super::*;
use crate::core::{Estimate, FrameView, Representation, Sight};

/// A box impostor set taking its images `density` texels a pixel, at most `max_side`.
fn dense(density: f32, max_side: u32) -> ImpostorSet {
    let mut imps = set(1, 1);
    imps.config.max_side = max_side;
    imps.shape = Shape::Box;
    imps.density = density;
    imps
}

/// The box every test here looks at: turned, so the eye sees two of its sides at a slant.
fn subject() -> [MeshGroup; 1] {
    let color = Rgba::new(0.8, 0.5, 0.2, 1.0);
    [block(Vec3::new(1.0, 1.6, 0.8), Vec3::ZERO, 0.6, color)]
}

/// `imps`' estimate of `subjects[0]` from `cam` right after the planner rebuilt its image
/// from there, and the image's side.
fn fresh(imps: &mut ImpostorSet, subjects: &mut [MeshGroup], cam: &Camera) -> (Estimate, u32) {
    let light = lighting();
    imps.rebuild(&[0], subjects, &FrameView::still(cam, W, H, &light));
    let side = imps.impostors[0].capture().expect("taken").side;
    let seen = Sight::new(cam, W, H, subjects[0].bounds());
    (imps.estimate(0, &subjects[0], &seen).expect("seen"), side)
}

#[test]
fn an_image_taken_denser_errs_as_much_as_its_rebuild_from_its_own_eye() {
    // The box's disc about 30 pixels: a texel a pixel needs 32 texels; at 2.5 and 3 texels
    // a pixel the power of two is 128, four times that, more than the density. The
    // estimate's rebuild was then priced as an image of density times 32 texels, below
    // the held image's error, and a still camera rebuilt it every frame.
    let mut subjects = subject();
    let b = subjects[0].bounds();
    let ppr = pixels_per_radian(&camera(Vec3::Z, Vec3::ZERO), H);
    let dist = 2.0 * ppr * b.radius / 30.0;
    let cam = camera(Vec3::new(0.3, 0.4, 1.0).normalize() * dist, Vec3::ZERO);
    let needed = needed_side(b.radius, dist, ppr, 16, 512);
    assert_eq!(needed, 32);
    for (density, side) in [(1.0, 32), (2.0, 64), (2.5, 128), (3.0, 128)] {
        let mut imps = dense(density, 512);
        let (e, taken) = fresh(&mut imps, &mut subjects, &cam);
        assert_eq!(taken, side, "density {density}");
        assert!(e.error.is_finite(), "density {density}: {e:?}");
        assert!(
            (e.error - e.rebuilt).abs() <= 1e-3 * e.rebuilt,
            "density {density}: a rebuild from the capture eye would gain {e:?}"
        );
    }
}

#[test]
fn an_image_at_the_largest_side_passes_its_own_face_check_near_the_eye() {
    // 1.27 radii away the disc is about 136 pixels; the largest side, 144, gives a box face
    // seen at a slant about 1.3 pixels a texel (the capture's half angle is 52 degrees),
    // over the texel a pixel the face check asks for. A rebuild cannot do better: the
    // image just taken is valid from its own eye.
    let mut subjects = subject();
    let b = subjects[0].bounds();
    let cam = camera(
        Vec3::new(0.3, 0.4, 1.0).normalize() * 1.27 * b.radius,
        Vec3::ZERO,
    );
    let mut imps = dense(3.0, 144);
    let (e, side) = fresh(&mut imps, &mut subjects, &cam);
    assert_eq!(side, 144);
    let c = *imps.impostors[0].capture().expect("taken");
    let ppr = pixels_per_radian(&cam, H);
    let stretch = relief::face_stretch(&c, &subjects[0].corners(), cam.eye(), ppr);
    assert!(stretch > relief::MAX_STRETCH, "stretch {stretch}");
    assert!(
        e.error.is_finite() && (e.error - e.rebuilt).abs() <= 1e-3 * e.rebuilt,
        "{e:?}"
    );
}

/// With a rebuild life, a rebuild is judged by the parallax it would show after that many
/// more steps of the eye's last one: from a still eye as without, from a moving eye worse
/// than without (the image the planner does not draw would soon be left), and an image
/// the planner draws is judged as taken (its refreshes are not held back).
#[test]
fn a_rebuild_is_judged_after_its_life_while_the_eye_moves() {
    let light = lighting();
    let mut subjects = subject();
    let b = subjects[0].bounds();
    let ppr = pixels_per_radian(&camera(Vec3::Z, Vec3::ZERO), H);
    let dist = 2.0 * ppr * b.radius / 30.0;
    let from = Vec3::new(0.3, 0.4, 1.0).normalize() * dist;
    let still = camera(from, Vec3::ZERO);
    // A step sideways of a hundredth of the distance: the same side needed.
    let step = Vec3::new(1.0, 0.0, -0.3).normalize() * dist * 0.01;
    let moved = camera(from + step, Vec3::ZERO);
    let estimate = |life: Option<f32>, drawn: &[usize], subjects: &mut [MeshGroup]| {
        let mut imps = dense(3.0, 512);
        imps.rebuild_life = life;
        let view = FrameView::still(&still, W, H, &light);
        imps.rebuild(&[0], subjects, &view);
        Representation::<MeshGroup>::prepare(&mut imps, drawn, subjects, &view);
        let at = |cam: &Camera| {
            let seen = Sight::new(cam, W, H, subjects[0].bounds());
            imps.estimate(0, &subjects[0], &seen).expect("seen")
        };
        (at(&still), at(&moved))
    };
    let (still0, moved0) = estimate(None, &[], &mut subjects);
    let (still4, moved4) = estimate(Some(4.0), &[], &mut subjects);
    let (_, drawn4) = estimate(Some(4.0), &[0], &mut subjects);
    assert!(still0.rebuilt.is_finite() && moved0.rebuilt.is_finite());
    assert_eq!(still4.rebuilt, still0.rebuilt, "a still eye: {still4:?}");
    assert_eq!(moved4.error, moved0.error, "the held image as before");
    assert!(
        moved4.rebuilt > moved0.rebuilt * 1.5,
        "four more steps on: {moved4:?} against {moved0:?}"
    );
    assert_eq!(drawn4.rebuilt, moved0.rebuilt, "drawn: judged as taken");
}

//! Billboards end to end through the engine: an axial-billboard forest flown over the top
//! (both fallbacks) against the same forest as meshes, sorted alpha blending against the
//! analytic "over" result, thread-count determinism of a full billboard frame (forest,
//! lasers, effects, lens flare), laser glow end-on and from the side, a batch of thousands
//! of particles (triangle counters, no buffer growth), and lens-flare occlusion.

use engine::procedural::{self, TreeKind};
use engine::{
    AlphaMode, BlendMode, Camera, Draw, Encoding, FrameOptions, FrameStats, Lighting, Material,
    Mesh, Premul, Renderer, Rgba, Target,
};
use glam::{Mat4, Vec2, Vec3};
use ibr::effects::Effects;
use ibr::flare::{FlareSource, LensFlare};
use ibr::laser::{Laser, LaserBatch};
use ibr::sprites::{self, BakedSprite};
use ibr::technique::{Flare, FrameLoop, FrameView, Technique};
use ibr::{AxialFallback, Billboard, BillboardBatch, Facing, Size, View};
use tests::scenes::Rng;

const W: u32 = 160;
const H: u32 = 120;
const FOV: f32 = 0.8;

/// Every pixel's premultiplied linear colour, row-major.
fn pixels(t: &Target) -> Vec<Premul> {
    (0..t.height())
        .flat_map(|y| (0..t.width()).map(move |x| (x, y)))
        .map(|(x, y)| t.color_linear(x, y).expect("inside"))
        .collect()
}

/// Panics unless every pixel is a finite, valid premultiplied colour (alpha in [0, 1],
/// colour channels in [0, alpha]) and every depth is finite in [0, 1].
fn assert_valid(what: &str, t: &Target) {
    for y in 0..t.height() {
        for x in 0..t.width() {
            let c = t.color_linear(x, y).expect("inside");
            let ok = [c.r, c.g, c.b, c.a].iter().all(|v| v.is_finite())
                && (0.0..=1.0).contains(&c.a)
                && [c.r, c.g, c.b].iter().all(|&v| v >= 0.0 && v <= c.a + 1e-6);
            assert!(ok, "{what}: pixel ({x}, {y}) is {c:?}");
            let d = t.depth_reversed(x, y).expect("inside");
            assert!(
                d.is_finite() && (0.0..=1.0).contains(&d),
                "{what}: depth {d} at ({x}, {y})"
            );
        }
    }
}

/// Mean absolute difference per pixel of the linear RGB (averaged over the 3 channels).
fn mean_abs_diff(a: &[Premul], b: &[Premul]) -> f32 {
    let sum: f64 = a
        .iter()
        .zip(b)
        .map(|(p, q)| ((p.r - q.r).abs() + (p.g - q.g).abs() + (p.b - q.b).abs()) as f64 / 3.0)
        .sum();
    (sum / a.len() as f64) as f32
}

fn assert_mesh_finite(what: &str, m: &Mesh) {
    assert!(
        m.positions.iter().all(|p| p.is_finite())
            && m.uvs.iter().all(|p| p.is_finite())
            && m.colors
                .iter()
                .all(|c| [c.r, c.g, c.b, c.a].iter().all(|v| v.is_finite())),
        "{what}: non-finite vertex data"
    );
    assert_eq!(m.indices.len() % 6, 0, "{what}: whole quads");
}

// ---------------------------------------------------------------------------------------
// The forest
// ---------------------------------------------------------------------------------------

/// Unlit ground colour: purple, far from every bark and leaf colour, so a pixel that is
/// not this colour shows a tree.
const GROUND: Rgba = Rgba::new(0.45, 0.2, 0.6, 1.0);
const SKY: Rgba = Rgba::new(0.3, 0.5, 0.8, 1.0);

/// A tree of the forest: where it stands, its kind (index into the baked sprites) and
/// height.
#[derive(Clone, Copy, Debug)]
struct Tree {
    at: Vec3,
    kind: usize,
    height: f32,
}

const KINDS: [(TreeKind, u64); 2] = [(TreeKind::Pine, 1), (TreeKind::Broadleaf, 3)];

/// Fourteen trees in a disc of radius 3.2 around the origin, on the ground (y = 0).
fn forest_layout() -> Vec<Tree> {
    let mut rng = Rng(0xf0_2e57);
    (0..14)
        .map(|k| {
            let a = rng.range(0.0, std::f64::consts::TAU) as f32;
            let r = 3.2 * (rng.unit() as f32).sqrt();
            Tree {
                at: Vec3::new(r * a.cos(), 0.0, r * a.sin()),
                kind: k % 2,
                height: rng.range(2.0, 3.0) as f32,
            }
        })
        .collect()
}

fn tree_mesh(kind: usize) -> Mesh {
    procedural::tree(KINDS[kind].0, 1.0, KINDS[kind].1)
}

/// The sprites of both kinds, baked under the default lighting, as the showcase does.
fn bake_sprites() -> Vec<BakedSprite> {
    (0..KINDS.len())
        .map(|kind| {
            sprites::bake_upright(
                &tree_mesh(kind),
                &Material::lit(Rgba::WHITE),
                &Lighting::default(),
                Vec3::new(1.0, 0.0, 0.6),
                64,
            )
        })
        .collect()
}

/// How the billboard trees fall back over the top: the fade's elevations (degrees) and
/// whether a top-down sprite takes over.
#[derive(Clone, Copy, Debug)]
struct Fallback {
    fade: (f32, f32),
    top: bool,
}

/// The library's default fade (55 to 75 degrees), without and with the top sprite.
const FADE_ONLY: Fallback = Fallback {
    fade: (55.0, 75.0),
    top: false,
};
const WITH_TOP: Fallback = Fallback {
    fade: (55.0, 75.0),
    top: true,
};

/// One alpha-tested axial batch per kind.
fn billboard_forest(
    sprites: &[BakedSprite],
    trees: &[Tree],
    fallback: Fallback,
) -> Vec<BillboardBatch> {
    sprites
        .iter()
        .enumerate()
        .map(|(kind, sprite)| {
            let material = Material {
                alpha_mode: AlphaMode::Mask { cutoff: 0.45 },
                vertex_colors: true,
                ..Material::unlit(Rgba::WHITE).with_texture(sprite.texture.clone())
            };
            let facing = Facing::Axial {
                axis: Vec3::Y,
                fallback: AxialFallback {
                    fade_start: fallback.fade.0,
                    fade_end: fallback.fade.1,
                    top: fallback.top.then_some(sprite.top),
                },
            };
            let mut batch = BillboardBatch::new(material);
            for t in trees.iter().filter(|t| t.kind == kind) {
                batch.push(Billboard {
                    pivot: sprite.pivot,
                    region: sprite.side,
                    ..Billboard::new(
                        t.at,
                        facing,
                        Vec2::new(sprite.size.x / sprite.size.y, 1.0) * t.height,
                    )
                });
            }
            batch
        })
        .collect()
}

/// The reference: the same trees as meshes, scaled so a tree and its billboard have the
/// same height and stand on the same point.
fn mesh_forest(sprites: &[BakedSprite], trees: &[Tree]) -> Vec<(Mesh, Mat4)> {
    trees
        .iter()
        .map(|t| {
            let s = t.height / sprites[t.kind].size.y;
            (
                tree_mesh(t.kind),
                Mat4::from_translation(t.at) * Mat4::from_scale(Vec3::splat(s)),
            )
        })
        .collect()
}

fn ground() -> (Mesh, Material) {
    (procedural::plane(80.0, 80.0, 1, 1), Material::unlit(GROUND))
}

/// Where the flight looks: the middle of the forest, a metre up, from 12 units away. From
/// straight above (13 units up) every tree is seen at more than 75 degrees of elevation,
/// past the default `fade_end` of 75.
const CENTRE: Vec3 = Vec3::new(0.0, 1.0, 0.0);
const DIST: f32 = 12.0;
/// Frames of the flight: elevation 0, 3.75, ..., 180 degrees (frame 24 is straight above).
const FRAMES: u32 = 49;

/// The camera at `elevation_deg` of a loop over the forest in the x-y plane, a little off
/// it in z. Its up vector is the loop's tangent, so the image does not roll: with a fixed
/// +Y up a look-at camera turns the picture half over in the frame or two around the top,
/// a jump larger than anything billboards could cause, which would hide theirs.
fn loop_camera(elevation_deg: f32) -> Camera {
    let (s, c) = elevation_deg.to_radians().sin_cos();
    let eye = CENTRE + Vec3::new(c, s, 0.0) * DIST + Vec3::new(0.0, 0.0, 0.2);
    Camera::look_at(eye, CENTRE, Vec3::new(-s, c, 0.0), FOV, W as f32 / H as f32)
        .with_depth_range(0.1, 200.0)
}

fn flight_elevation(k: u32) -> f32 {
    180.0 * k as f32 / (FRAMES - 1) as f32
}

fn sky_opts() -> FrameOptions {
    FrameOptions {
        clear: Some(SKY),
        ..Default::default()
    }
}

/// The flight clears to the ground colour: the horizon sweeping through the picture would
/// otherwise be most of every frame-to-frame change and hide the trees' part in it.
fn ground_opts() -> FrameOptions {
    FrameOptions {
        clear: Some(GROUND),
        ..Default::default()
    }
}

/// Renders the flight with the trees as meshes (`None`) or as billboards; returns each
/// frame's pixels and the number of quads built at each frame.
fn fly(
    sprites: &[BakedSprite],
    trees: &[Tree],
    billboards: Option<Fallback>,
) -> Vec<(Vec<Premul>, usize)> {
    let (ground_mesh, ground_mat) = ground();
    let meshes = mesh_forest(sprites, trees);
    let tree_mat = Material::lit(Rgba::WHITE);
    let mut batches = billboards.map(|f| billboard_forest(sprites, trees, f));
    let mut renderer = Renderer::new();
    let mut target = Target::new(W, H);
    let lighting = Lighting::default();
    (0..FRAMES)
        .map(|k| {
            let cam = loop_camera(flight_elevation(k));
            let view = View::new(&cam, H);
            let mut draws = vec![Draw {
                mesh: &ground_mesh,
                material: &ground_mat,
                transform: Mat4::IDENTITY,
            }];
            let mut quads = 0;
            match &mut batches {
                Some(batches) => {
                    for b in batches.iter_mut() {
                        quads += b.build(&view);
                        assert_mesh_finite("forest batch", b.mesh());
                    }
                    draws.extend(batches.iter().map(BillboardBatch::draw));
                }
                None => draws.extend(meshes.iter().map(|(mesh, transform)| Draw {
                    mesh,
                    material: &tree_mat,
                    transform: *transform,
                })),
            }
            renderer.render(draws, &cam, &lighting, &mut target, &ground_opts());
            assert_valid(&format!("frame {k} ({billboards:?})"), &target);
            (pixels(&target), quads)
        })
        .collect()
}

/// Fraction of pixels that are not the ground colour.
fn tree_coverage(frame: &[Premul]) -> f32 {
    let off = |c: &Premul| {
        (c.r - GROUND.r).abs() > 0.02
            || (c.g - GROUND.g).abs() > 0.02
            || (c.b - GROUND.b).abs() > 0.02
    };
    frame.iter().filter(|c| off(c)).count() as f32 / frame.len() as f32
}

/// Mean absolute change between consecutive frames.
fn steps(frames: &[(Vec<Premul>, usize)]) -> Vec<f32> {
    frames
        .windows(2)
        .map(|w| mean_abs_diff(&w[0].0, &w[1].0))
        .collect()
}

/// The largest step and the frame it starts at.
fn max_step(steps: &[f32]) -> (f32, usize) {
    steps
        .iter()
        .copied()
        .enumerate()
        .fold((0.0, 0), |a, (k, s)| if s > a.0 { (s, k) } else { a })
}

/// Frame-to-frame change allowed along the flight: twice the mesh forest's largest step
/// plus 0.004 (a mean linear change of 0.4% of full scale per pixel). The mesh forest's
/// steps come from the camera turning (about 0.005 to 0.006 here). Alpha testing turns each
/// tree's fade into a switch at the elevation where its faded alpha crosses the cutoff, so
/// the billboard forests change more than the meshes while trees swap between side and
/// top sprites (measured: up to 1.9 x the mesh's largest step); a forest popping in or out
/// at once, or quads blowing up at the top, would be several times more.
const STEP_FACTOR: f32 = 2.0;
const STEP_SLACK: f32 = 0.004;

#[test]
fn axial_forest_over_the_top_is_finite_smooth_and_keeps_its_documented_fallbacks() {
    let sprites = bake_sprites();
    let trees = forest_layout();
    let mesh = fly(&sprites, &trees, None);
    let fade = fly(&sprites, &trees, Some(FADE_ONLY));
    let top = fly(&sprites, &trees, Some(WITH_TOP));
    let above = (FRAMES / 2) as usize;
    assert_eq!(flight_elevation(above as u32), 90.0);

    // The reference is not trivial: the mesh forest changes the picture as it turns.
    let mesh_steps = steps(&mesh);
    let (mesh_step, mesh_at) = max_step(&mesh_steps);
    assert!(mesh_step > 0.002, "mesh flight barely changes: {mesh_step}");
    let bound = STEP_FACTOR * mesh_step + STEP_SLACK;
    for (name, frames) in [("fade only", &fade), ("top sprite", &top)] {
        let s = steps(frames);
        let (step, at) = max_step(&s);
        assert!(
            step <= bound,
            "{name}: largest frame-to-frame change {step} (frames {at}-{}) exceeds \
             {STEP_FACTOR} x mesh {mesh_step} (frames {mesh_at}-{}) + {STEP_SLACK}",
            at + 1,
            mesh_at + 1
        );
        // From 78.75 to 101.25 degrees only top sprites (or nothing) are drawn:
        // they are fixed in the world, so they must not jitter or flip as the camera
        // passes over; they change the picture no more than the meshes do.
        for k in above - 3..above + 3 {
            assert!(
                s[k] <= mesh_steps[k] + 0.001,
                "{name}: step {k}-{} near the top changes {} (mesh {})",
                k + 1,
                s[k],
                mesh_steps[k]
            );
        }
    }

    // From the side, both billboard forests cover about what the mesh forest does.
    let mesh_side = tree_coverage(&mesh[0].0);
    assert!(mesh_side > 0.04, "mesh forest from the side: {mesh_side}");
    for (name, frames) in [("fade only", &fade), ("top sprite", &top)] {
        let side = tree_coverage(&frames[0].0);
        assert_eq!(frames[0].1, trees.len(), "{name}: one quad per tree");
        assert!(
            (side - mesh_side).abs() <= 0.25 * mesh_side,
            "{name}: side coverage {side} vs mesh {mesh_side}"
        );
    }

    // Straight above: the mesh forest is seen from the top.
    let mesh_above = tree_coverage(&mesh[above].0);
    assert!(mesh_above > 0.05, "mesh forest from above: {mesh_above}");
    // Fade only: every tree is past `fade_end` from up there, so none is drawn at all.
    let fade_above = tree_coverage(&fade[above].0);
    assert_eq!(fade[above].1, 0, "fade only: quads built from above");
    assert!(
        fade_above <= 0.001,
        "fade only: coverage from above {fade_above}"
    );
    // Top sprite: one flat sprite per tree stands in for it, covering about as much.
    let top_above = tree_coverage(&top[above].0);
    assert_eq!(top[above].1, trees.len(), "top sprite: one quad per tree");
    assert!(
        (top_above - mesh_above).abs() <= 0.25 * mesh_above,
        "top sprite: coverage from above {top_above} vs mesh {mesh_above}"
    );
}

// ---------------------------------------------------------------------------------------
// Sorted blending
// ---------------------------------------------------------------------------------------

const CLEAR: Rgba = Rgba::new(0.1, 0.15, 0.2, 1.0);

/// Twelve screen billboards straight ahead at distinct depths, each covering the image
/// centre, in distinct colours at alpha 0.5. Listed near to far.
fn stacked_billboards() -> Vec<Billboard> {
    let mut rng = Rng(12);
    (0..12)
        .map(|k| {
            let z = 3.0 + k as f32;
            let hue = k as f32 / 12.0 * std::f32::consts::TAU;
            let color = Rgba::new(
                0.5 + 0.5 * hue.cos(),
                0.5 + 0.5 * (hue + 2.1).cos(),
                0.5 + 0.5 * (hue + 4.2).cos(),
                0.5,
            );
            let jitter = Vec2::new(rng.range(-0.1, 0.1) as f32, rng.range(-0.1, 0.1) as f32) * z;
            Billboard {
                tint: color,
                ..Billboard::new(
                    Vec3::new(jitter.x, jitter.y, -z),
                    Facing::Screen,
                    Vec2::splat(0.8 * z),
                )
            }
        })
        .collect()
}

fn shuffle<T>(v: &mut [T], rng: &mut Rng) {
    for i in (1..v.len()).rev() {
        v.swap(i, rng.below(i as u64 + 1) as usize);
    }
}

/// Premultiplied "over" of straight colours `layers` (drawn in that order) on `clear`.
fn over(clear: Rgba, layers: impl Iterator<Item = Rgba>) -> [f64; 3] {
    let mut dst = [clear.r as f64, clear.g as f64, clear.b as f64];
    for c in layers {
        let a = c.a as f64;
        let src = [c.r as f64, c.g as f64, c.b as f64];
        dst = [0, 1, 2].map(|i| src[i] * a + dst[i] * (1.0 - a));
    }
    dst
}

fn render_stack(items: &[Billboard]) -> Target {
    let cam = Camera::look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 1.0, 1.0);
    let mut batch = BillboardBatch::new(Material::unlit(Rgba::WHITE).blended(BlendMode::Alpha));
    for b in items {
        batch.push(*b);
    }
    assert_eq!(batch.build(&View::new(&cam, 64)), items.len());
    let mut target = Target::with_encoding(64, 64, Encoding::Unorm);
    let opts = FrameOptions {
        clear: Some(CLEAR),
        ..Default::default()
    };
    Renderer::new().render(
        [batch.draw()],
        &cam,
        &Lighting::default(),
        &mut target,
        &opts,
    );
    target
}

#[test]
fn blended_batch_composites_back_to_front_whatever_the_push_order() {
    let near_to_far = stacked_billboards();
    let want = over(CLEAR, near_to_far.iter().rev().map(|b| b.tint));
    // The test can tell the orders apart: near-to-far compositing is visibly different.
    let wrong = over(CLEAR, near_to_far.iter().map(|b| b.tint));
    assert!(
        (0..3).any(|i| (want[i] - wrong[i]).abs() > 0.05),
        "{want:?} vs {wrong:?}"
    );

    let mut rng = Rng(7);
    let mut orders = vec![near_to_far.clone()];
    for _ in 0..2 {
        let mut v = near_to_far.clone();
        shuffle(&mut v, &mut rng);
        orders.push(v);
    }
    let mut first: Option<Vec<u8>> = None;
    for (k, items) in orders.iter().enumerate() {
        let target = render_stack(items);
        let c = target.color_linear(32, 32).expect("inside");
        let got = [c.r as f64, c.g as f64, c.b as f64];
        // Unorm bytes: the engine blends in f32 and rounds once, so half a step apart at
        // most; one step of tolerance.
        let tol = 1.0 / 255.0;
        assert!(
            (0..3).all(|i| (got[i] - want[i]).abs() <= tol) && (c.a - 1.0).abs() <= tol as f32,
            "order {k}: centre {c:?}, want {want:?} (front to back would be {wrong:?})"
        );
        let bytes = target.to_rgba8();
        match &first {
            None => first = Some(bytes),
            Some(f) => assert!(*f == bytes, "order {k}: image differs from order 0"),
        }
    }
}

// ---------------------------------------------------------------------------------------
// A full billboard frame at several thread counts
// ---------------------------------------------------------------------------------------

/// Toward the sun of the default lighting.
fn sun() -> Vec3 {
    let Some(engine::Light::Directional { direction, .. }) =
        Lighting::default().lights.first().copied()
    else {
        panic!("default lighting has a directional light first");
    };
    -direction
}

/// Frames of 1/30 s through the frame loop until an explosion is 0.4 s old: ground,
/// billboard forest (with top sprites), a beam and a bolt, the explosion next to continuous
/// smoke, and the sun's lens flare measured in the finished frame and drawn over it. The
/// last frame's pixels and counters, its quads and the flare's visibility. Everything
/// (baking included) runs on the current rayon pool.
fn full_frame() -> (Vec<u8>, FrameStats, u64, f32) {
    let sprites = bake_sprites();
    let trees = forest_layout();
    let mut forest = billboard_forest(&sprites, &trees, WITH_TOP);
    let mut lasers = LaserBatch::new();
    lasers.lasers.push(Laser {
        a: Vec3::new(-3.0, 2.0, -4.0),
        b: Vec3::new(3.0, 2.5, -1.0),
        width: 0.3,
        color: Rgba::new(1.0, 0.25, 0.15, 1.0),
        intensity: 1.4,
    });
    lasers.lasers.push(Laser {
        a: Vec3::new(2.0, 1.0, -6.0),
        b: Vec3::new(-1.0, 3.0, 1.0),
        width: 0.2,
        color: Rgba::new(0.2, 1.0, 0.35, 1.0),
        intensity: 2.0,
    });
    let mut effects = Effects::new(31);
    effects.add_smoke(Vec3::new(-1.5, 0.5, -2.0));
    for _ in 0..3 {
        effects.update(1.0 / 30.0);
    }
    effects.spawn_explosion(Vec3::new(1.0, 1.5, -3.0));
    let mut flare = Flare {
        lens: LensFlare::default(),
        source: FlareSource::Directional(sun()),
    };
    let (ground_mesh, ground_mat) = ground();
    let ground = Draw {
        mesh: &ground_mesh,
        material: &ground_mat,
        transform: Mat4::IDENTITY,
    };
    let cam = Camera::look_at(
        Vec3::new(0.0, 1.5, -10.0),
        Vec3::new(0.0, 1.5, -10.0) + Vec3::new(0.25, 0.35, 1.0),
        Vec3::Y,
        1.1,
        W as f32 / H as f32,
    )
    .with_depth_range(0.1, 200.0);
    let lighting = Lighting::default();
    let mut renderer = Renderer::new();
    let mut frame_loop = FrameLoop::new();
    let mut target = Target::new(W, H);
    let mut stats = FrameStats::default();
    for f in 1..=12 {
        let view = FrameView {
            camera: &cam,
            width: W,
            height: H,
            lighting: &lighting,
            time: f as f32 / 30.0,
            dt: 1.0 / 30.0,
        };
        let mut techniques: [&mut dyn Technique; 4] =
            [&mut forest, &mut lasers, &mut effects, &mut flare];
        stats = frame_loop.render(
            &mut renderer,
            [ground],
            &mut techniques,
            &view,
            &mut target,
            &sky_opts(),
        );
    }
    let quads = frame_loop.counters.iter().map(|c| c.quads).sum::<u64>();
    // The flare's own quads are not scene quads.
    let quads = quads - frame_loop.counters[3].quads;
    assert_valid("full frame", &target);
    (target.to_rgba8(), stats, quads, flare.lens.visibility())
}

#[test]
fn full_billboard_frame_is_identical_at_1_2_and_8_threads() {
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(full_frame)
    };
    let (bytes1, stats1, quads1, vis1) = run(1);
    // Every part is in the picture: trees, beams, caps and particles, and the flare.
    assert!(quads1 > 14 + 4 + 4 + 20, "only {quads1} quads");
    assert!(vis1 > 0.5, "the sun should be in view: visibility {vis1}");
    assert!(stats1.draws >= 8, "{stats1:?}");
    for threads in [2, 8] {
        let (bytes, stats, quads, vis) = run(threads);
        let bad = bytes.iter().zip(&bytes1).filter(|(a, b)| a != b).count();
        assert!(
            bad == 0,
            "{threads} threads: {bad} bytes differ from 1 thread"
        );
        assert_eq!(stats, stats1, "{threads} threads: stats differ");
        assert_eq!((quads, vis), (quads1, vis1), "{threads} threads");
    }
}

// ---------------------------------------------------------------------------------------
// Lasers
// ---------------------------------------------------------------------------------------

/// A dark background: ground, and a wall far down the beam.
fn dark_background() -> Vec<(Mesh, Material, Mat4)> {
    vec![
        (
            procedural::plane(200.0, 200.0, 1, 1),
            Material::unlit(Rgba::new(0.04, 0.05, 0.04, 1.0)),
            Mat4::IDENTITY,
        ),
        (
            procedural::quad(200.0, 200.0),
            Material::unlit(Rgba::new(0.03, 0.03, 0.05, 1.0)).double_sided(true),
            Mat4::from_translation(Vec3::new(0.0, 0.0, -60.0)),
        ),
    ]
}

const BEAM: Laser = Laser {
    a: Vec3::new(0.0, 1.0, -3.0),
    b: Vec3::new(0.0, 1.0, -20.0),
    width: 0.4,
    color: Rgba::new(0.5, 0.12, 0.06, 1.0),
    intensity: 1.0,
};

/// The background alone, and with the beam drawn in the same frame.
fn render_beam(cam: &Camera, size: u32) -> (Target, Target) {
    let background = dark_background();
    let mut lasers = LaserBatch::new();
    lasers.lasers.push(BEAM);
    lasers.build(&View::new(cam, size));
    assert_mesh_finite("beams", lasers.beam_mesh());
    assert_mesh_finite("caps", lasers.cap_mesh());
    let draws = || {
        background.iter().map(|(mesh, material, transform)| Draw {
            mesh,
            material,
            transform: *transform,
        })
    };
    let opts = FrameOptions::default();
    let mut renderer = Renderer::new();
    let mut bg = Target::new(size, size);
    renderer.render(draws(), cam, &Lighting::default(), &mut bg, &opts);
    let mut lit = Target::new(size, size);
    renderer.render(
        draws().chain(lasers.draws()),
        cam,
        &Lighting::default(),
        &mut lit,
        &opts,
    );
    assert_valid("laser", &lit);
    (bg, lit)
}

fn camera(eye: Vec3, at: Vec3) -> Camera {
    Camera::look_at(eye, at, Vec3::Y, 1.0, 1.0).with_depth_range(0.1, 200.0)
}

#[test]
fn laser_glows_end_on_draws_a_line_from_the_side_and_never_darkens() {
    const S: u32 = 64;
    // End-on: the eye on the beam's axis behind `a`, looking down it.
    let end_on = camera(Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 1.0, -1.0));
    let (bg, lit) = render_beam(&end_on, S);
    let (c, b) = (
        lit.color_linear(S / 2, S / 2).expect("inside"),
        bg.color_linear(S / 2, S / 2).expect("inside"),
    );
    let added = Vec3::new(c.r - b.r, c.g - b.g, c.b - b.b);
    let colour = Vec3::new(BEAM.color.r, BEAM.color.g, BEAM.color.b);
    assert!(added.x > 0.3, "end-on centre barely lit: {c:?} over {b:?}");
    assert!(
        added.normalize().dot(colour.normalize()) > 0.995,
        "end-on centre glows {added:?}, not in the beam colour {colour:?}"
    );
    // The glow is local: the image corner is untouched.
    assert_eq!(lit.pixel(1, 1), bg.pixel(1, 1), "end-on corner");

    // From the side: a horizontal line through the middle row, nothing far above it.
    let side = camera(Vec3::new(6.0, 1.0, -11.5), Vec3::new(0.0, 1.0, -11.5));
    let (bg, lit) = render_beam(&side, S);
    let row_gain = |y: u32| {
        (0..S)
            .filter(|&x| {
                let (c, b) = (
                    lit.color_linear(x, y).unwrap(),
                    bg.color_linear(x, y).unwrap(),
                );
                c.r - b.r > 0.1
            })
            .count()
    };
    assert!(
        row_gain(S / 2) as u32 >= S - 2,
        "side: beam row lit at {} of {S} pixels",
        row_gain(S / 2)
    );
    // The beam quads are about 4 pixels wide here: rows well away are untouched.
    for y in [4, 12, S / 2 - 8, S / 2 + 8, S - 12, S - 4] {
        for x in 0..S {
            assert_eq!(lit.pixel(x, y), bg.pixel(x, y), "side: ({x}, {y}) changed");
        }
    }

    // Additive over the background never darkens a pixel, from any side: along the axis,
    // a few degrees off it (inside and past the end-on fade), obliquely, from the side,
    // from behind `b`, and from above.
    let views = [
        end_on,
        side,
        camera(Vec3::new(0.2, 1.0, 0.0), Vec3::new(0.0, 1.0, -11.0)),
        camera(Vec3::new(0.8, 1.3, 0.0), Vec3::new(0.0, 1.0, -11.0)),
        camera(Vec3::new(4.0, 3.0, 2.0), Vec3::new(0.0, 1.0, -11.0)),
        camera(Vec3::new(0.0, 1.0, -30.0), Vec3::new(0.0, 1.0, 0.0)),
        camera(Vec3::new(0.3, 12.0, -11.0), Vec3::new(0.0, 1.0, -11.0)),
    ];
    for (k, cam) in views.iter().enumerate() {
        let (bg, lit) = render_beam(cam, S);
        let (bg, lit) = (bg.to_rgba8_premultiplied(), lit.to_rgba8_premultiplied());
        let darker = lit.iter().zip(&bg).filter(|(l, b)| l < b).count();
        assert_eq!(
            darker, 0,
            "view {k}: {darker} channel bytes darker than the background"
        );
        assert!(lit != bg, "view {k}: the beam is not visible at all");
    }
}

// ---------------------------------------------------------------------------------------
// Thousands of particles
// ---------------------------------------------------------------------------------------

const PARTICLES: usize = 5000;
const BEHIND: usize = 200;

/// 5000 world-sized screen particles in front of the eye, and 200 pixel-sized ones
/// behind it (which have no size there and are skipped).
fn particle_batch() -> BillboardBatch {
    let material = Material::unlit(Rgba::WHITE)
        .with_texture(std::sync::Arc::new(sprites::puff(32)))
        .blended(BlendMode::Alpha);
    let mut batch = BillboardBatch::new(material);
    let mut rng = Rng(5000);
    let mut r = |lo: f64, hi: f64| rng.range(lo, hi) as f32;
    for _ in 0..PARTICLES {
        let p = Vec3::new(r(-6.0, 6.0), r(-4.0, 4.0), r(-25.0, -5.0));
        batch.push(Billboard {
            rotation: r(0.0, 6.3),
            tint: Rgba::new(r(0.2, 1.0), r(0.2, 1.0), r(0.2, 1.0), r(0.3, 0.9)),
            ..Billboard::new(p, Facing::Screen, Vec2::splat(r(0.2, 0.7)))
        });
    }
    for _ in 0..BEHIND {
        let p = Vec3::new(r(-3.0, 3.0), r(-3.0, 3.0), r(2.0, 6.0));
        batch.push(Billboard {
            size: Size::Pixels(Vec2::splat(8.0)),
            ..Billboard::new(p, Facing::Screen, Vec2::ONE)
        });
    }
    batch
}

fn capacities(m: &Mesh) -> [usize; 5] {
    [
        m.positions.capacity(),
        m.uvs.capacity(),
        m.colors.capacity(),
        m.indices.capacity(),
        m.normals.capacity(),
    ]
}

#[test]
fn thousands_of_particles_count_two_triangles_per_quad_and_reuse_their_buffers() {
    let mut batch = particle_batch();
    let mut renderer = Renderer::new();
    let mut target = Target::new(W, H);
    let lighting = Lighting::default();
    let mut warm = None;
    for frame in 0..21 {
        // The eye wanders on a small circle, always looking down -Z: every particle in
        // front stays in front, every one behind stays behind.
        let a = frame as f32 * 0.3;
        let eye = Vec3::new(a.cos(), 0.5 * a.sin(), 0.0);
        let cam = Camera::look_at(
            eye,
            eye + Vec3::new(0.05 * a.sin(), 0.0, -1.0),
            Vec3::Y,
            1.0,
            W as f32 / H as f32,
        );
        let quads = batch.build(&View::new(&cam, H));
        assert_eq!(quads, PARTICLES, "frame {frame}: quads built");
        let m = batch.mesh();
        assert_eq!(m.indices.len(), 6 * quads, "frame {frame}");
        assert_mesh_finite("particles", m);
        let stats = renderer.render([batch.draw()], &cam, &lighting, &mut target, &sky_opts());
        assert_eq!(stats.draws, 1, "frame {frame}");
        assert_eq!(
            stats.triangles_in,
            2 * quads as u64,
            "frame {frame}: triangles submitted for {quads} quads ({stats:?})"
        );
        assert!(
            stats.fragments_written > (W * H) as u64,
            "frame {frame}: {stats:?}"
        );
        if frame == 0 {
            assert_valid("particles", &target);
        }
        // Frame 0 warms the buffers; the next 20 rebuilds must not grow them.
        match warm {
            None => warm = Some(capacities(m)),
            Some(c) => assert_eq!(capacities(m), c, "frame {frame}: buffer capacities changed"),
        }
    }
}

// ---------------------------------------------------------------------------------------
// Lens flare
// ---------------------------------------------------------------------------------------

/// The scene (ground and a wall `wall_x` to the side of the sun's line) in one render,
/// then the flare pass over it. Returns the scene alone, the composite, and the flare.
fn flare_frame(wall_x: f32) -> (Target, Target, LensFlare) {
    let eye = Vec3::new(0.0, 1.5, 0.0);
    let sun = sun();
    // Look a little below and beside the sun so it is in view, off centre.
    let look = (sun + Vec3::new(0.15, -0.2, 0.0)).normalize();
    let cam = camera(eye, eye + look);
    // An opaque wall 8 units toward the sun, facing the eye, 3 x 3, shifted sideways
    // (perpendicular to the sun direction) by `wall_x`.
    let side = sun.cross(Vec3::Y).normalize();
    let centre = eye + sun * 8.0 + side * wall_x;
    let wall = procedural::quad(3.0, 3.0);
    // The quad faces +Z; this turns +Z toward the eye (-sun) and puts it at `centre`.
    let wall_transform = Mat4::look_to_rh(centre, sun, Vec3::Y).inverse();
    let (ground_mesh, ground_mat) = ground();
    let wall_mat = Material::lit(Rgba::new(0.5, 0.5, 0.5, 1.0)).double_sided(true);
    let lighting = Lighting::default();
    let mut renderer = Renderer::new();
    let mut target = Target::new(W, H);
    let draws = [
        Draw {
            mesh: &ground_mesh,
            material: &ground_mat,
            transform: Mat4::IDENTITY,
        },
        Draw {
            mesh: &wall,
            material: &wall_mat,
            transform: wall_transform,
        },
    ];
    renderer.render(draws, &cam, &lighting, &mut target, &sky_opts());
    let scene = target.clone();
    let mut flare = LensFlare::default();
    flare.update(&cam, &target, FlareSource::Directional(sun), 1.0);
    let over = FrameOptions {
        clear: None,
        ..Default::default()
    };
    renderer.render([flare.draw()], &cam, &lighting, &mut target, &over);
    assert_valid("flare", &target);
    (scene, target, flare)
}

#[test]
fn lens_flare_is_hidden_by_an_opaque_wall_and_brightens_around_a_visible_sun() {
    // Hidden: the wall stands on the sun's line.
    let (scene, lit, flare) = flare_frame(0.0);
    let sun_px = flare.state.light.expect("the sun projects").pixel;
    assert!(
        sun_px.x > 8.0 && sun_px.x < W as f32 - 8.0 && sun_px.y > 8.0 && sun_px.y < H as f32 - 8.0,
        "sun at {sun_px}"
    );
    assert!(
        scene
            .depth_reversed(sun_px.x as u32, sun_px.y as u32)
            .unwrap()
            > 0.0,
        "the wall covers the sun"
    );
    assert_eq!(flare.measured(), 0.0);
    assert_eq!(flare.quad_count(), 0);
    assert!(
        scene.to_rgba8_premultiplied() == lit.to_rgba8_premultiplied(),
        "a hidden sun's flare pass changed pixels"
    );

    // Visible: the wall moved aside, still in the picture.
    let (scene, lit, flare) = flare_frame(4.0);
    let sun_px = flare.state.light.expect("the sun projects").pixel;
    assert_eq!(flare.measured(), 1.0);
    assert!(flare.quad_count() > 0);
    let wall_pixels = (0..H)
        .flat_map(|y| (0..W).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let c = scene.color_linear(x, y).unwrap();
            (c.r - SKY.r).abs() > 0.02 && (c.r - GROUND.r).abs() > 0.02
        })
        .count();
    assert!(
        wall_pixels > 50,
        "the wall is in the picture ({wall_pixels} pixels)"
    );
    let lum = |t: &Target, x: u32, y: u32| {
        let c = t.color_linear(x, y).unwrap();
        c.r + c.g + c.b
    };
    let mut brightened = 0;
    let mut near = 0;
    for dy in -4i32..=4 {
        for dx in -4i32..=4 {
            let (x, y) = ((sun_px.x as i32 + dx) as u32, (sun_px.y as i32 + dy) as u32);
            near += 1;
            if lum(&lit, x, y) > lum(&scene, x, y) + 0.1 {
                brightened += 1;
            }
        }
    }
    assert_eq!(brightened, near, "pixels around the sun brightened");
    // Additive: nothing anywhere darkens.
    let (s, l) = (scene.to_rgba8_premultiplied(), lit.to_rgba8_premultiplied());
    assert_eq!(s.iter().zip(&l).filter(|(s, l)| l < s).count(), 0);
}

//! Criterion benchmarks of the pipeline, through the public API only.
//!
//! Stages are isolated by choosing scenes one stage dominates, not by calling stage
//! internals (which change as the pipeline is tuned):
//! - `stage/vertex_reject`: a 1M-triangle torus wholly behind the camera (vertex transform
//!   and trivial frustum rejection, nothing reaches setup);
//! - `stage/clip_near`: a torus the near plane cuts through (clipping);
//! - `stage/setup_bin_tiny`: a 1M-triangle wavy grid filling the screen with ~0.3 px
//!   triangles, unlit constant colour (setup and binning);
//! - `stage/raster_fill`: 16 huge overlapping triangles, unlit constant colour at 1080p
//!   (edge walking, depth test, writes);
//! - `stage/shade_lit_textured`: the same triangles lit and textured (add the shading cost);
//! - `stage/blend`: the same triangles alpha-blended (second pass, read-modify-write);
//! - `stage/texture_sample`: 64k trilinear samples straight from a texture;
//! - `torus/N/WxH`: the peers' torus, lit and vertex-coloured, at two sizes and two loads;
//! - `full_frame`: the showcase's built-in scene at 1280x720.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use demos::bench::raster::peer_camera;
use demos::showcase::{self, Showcase};
use engine::procedural::{self, XorShift};
use engine::{
    BlendMode, Camera, FrameOptions, Material, Mesh, Renderer, Rgba, Sampler, Scene, Target,
    Texture,
};
use glam::{Mat4, Vec3};
use std::hint::black_box;
use std::sync::Arc;
use std::time::Duration;

fn one(mesh: Mesh, material: Material, transform: Mat4) -> Scene {
    let mut s = Scene::default();
    s.add(mesh, material, transform);
    s
}

fn tilted_torus(n: u32) -> Scene {
    let tilt =
        Mat4::from_rotation_y(20f32.to_radians()) * Mat4::from_rotation_x(-55f32.to_radians());
    one(
        procedural::torus_with_triangles(n),
        Material::lit(Rgba::WHITE),
        tilt,
    )
}

/// Renders `scene` once per iteration into a kept target with a kept renderer.
fn bench_frame(
    c: &mut Criterion,
    group: &str,
    (function, param): (&str, &str),
    scene: &Scene,
    camera: Camera,
    size: (u32, u32),
) {
    let mut g = c.benchmark_group(group);
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    g.throughput(Throughput::Elements(scene.triangle_count() as u64));
    let mut renderer = Renderer::new();
    let mut target = Target::new(size.0, size.1);
    let opts = FrameOptions::default();
    // One untimed frame, to say what the scene exercises.
    let st = renderer.render_scene(scene, &camera, &mut target, &opts);
    eprintln!(
        "{group}/{function}/{param}: {} triangles in, {} clipped, {} culled, {} rejected, {} set up, {} shaded",
        st.triangles_in,
        st.triangles_clipped,
        st.triangles_culled,
        st.triangles_rejected,
        st.triangles_set_up,
        st.fragments_shaded
    );
    g.bench_function(BenchmarkId::new(function, param), |b| {
        b.iter(|| black_box(renderer.render_scene(scene, &camera, &mut target, &opts)))
    });
    g.finish();
}

fn torus(c: &mut Criterion) {
    for n in [10_000, 100_000] {
        let scene = tilted_torus(n);
        for (w, h) in [(640, 480), (1920, 1080)] {
            let (f, p) = (format!("{}k", n / 1000), format!("{w}x{h}"));
            bench_frame(c, "torus", (&f, &p), &scene, peer_camera(w, h), (w, h));
        }
    }
}

/// The pipeline's stages one by one: vertex and rejection, clipping, set-up and binning
/// ([`geometry_stages`]), fill, shading and blending ([`fill_stages`]), and texture
/// sampling alone.
fn stages(c: &mut Criterion) {
    geometry_stages(c);
    let tex = fill_stages(c);
    texture_sample(c, &tex);
}

/// Vertex and rejection, clipping, set-up and binning.
fn geometry_stages(c: &mut Criterion) {
    let (w, h) = (1920, 1080);
    // Vertex + rejection: the torus sits behind the eye.
    let behind = one(
        procedural::torus_with_triangles(1_000_000),
        Material::unlit(Rgba::WHITE),
        Mat4::from_translation(Vec3::new(0.0, 0.0, 8.0)),
    );
    bench_frame(
        c,
        "stage",
        ("vertex_reject", "1M"),
        &behind,
        peer_camera(w, h),
        (w, h),
    );

    // Clipping: the eye sits inside the tube of a big torus, so the near plane cuts it.
    let around = one(
        procedural::torus(3.0, 0.6, 400, 125),
        Material::lit(Rgba::WHITE),
        Mat4::from_translation(Vec3::new(-3.0, 0.0, 3.0)),
    );
    let inside = Camera::look_at(
        Vec3::new(0.0, 0.0, 3.0),
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::Y,
        1.0,
        1.0,
    )
    .with_aspect(w, h)
    .with_depth_range(0.05, 100.0);
    bench_frame(c, "stage", ("clip_near", "100k"), &around, inside, (w, h));

    // Setup and binning: a million sub-pixel triangles.
    let grid = one(
        procedural::wave_grid(1_000_000, 3.1, 1.8, 0.15),
        Material {
            vertex_colors: false,
            ..Material::unlit(Rgba::new(0.4, 0.7, 0.3, 1.0))
        },
        Mat4::IDENTITY,
    );
    bench_frame(
        c,
        "stage",
        ("setup_bin_tiny", "1M"),
        &grid,
        peer_camera(1280, 720),
        (1280, 720),
    );
}

/// Fill, lit and textured shading, blending; the checker texture it used.
fn fill_stages(c: &mut Criterion) -> Arc<Texture> {
    let (w, h) = (1920, 1080);
    // Fill: 16 huge triangles, constant colour, then lit + textured, then blended.
    let huge = procedural::huge_triangles(16, 2);
    let fill = one(
        huge.clone(),
        Material {
            vertex_colors: false,
            double_sided: true,
            ..Material::unlit(Rgba::new(0.8, 0.5, 0.2, 1.0))
        },
        Mat4::IDENTITY,
    );
    bench_frame(
        c,
        "stage",
        ("raster_fill", "huge16"),
        &fill,
        peer_camera(w, h),
        (w, h),
    );
    let tex = Arc::new(Texture::checker(
        256,
        8,
        Rgba::WHITE,
        Rgba::new(0.2, 0.3, 0.8, 1.0),
    ));
    let lit = one(
        huge.clone(),
        Material::lit(Rgba::WHITE)
            .with_texture(tex.clone())
            .double_sided(true),
        Mat4::IDENTITY,
    );
    bench_frame(
        c,
        "stage",
        ("shade_lit_textured", "huge16"),
        &lit,
        peer_camera(w, h),
        (w, h),
    );
    let blend = one(
        huge,
        Material::unlit(Rgba::new(0.3, 0.6, 0.9, 0.4))
            .blended(BlendMode::Alpha)
            .double_sided(true),
        Mat4::IDENTITY,
    );
    bench_frame(
        c,
        "stage",
        ("blend", "huge16"),
        &blend,
        peer_camera(w, h),
        (w, h),
    );
    tex
}

/// Texture sampling on its own.
fn texture_sample(c: &mut Criterion, tex: &Texture) {
    let mut g = c.benchmark_group("stage");
    g.sample_size(20);
    let sampler = Sampler::default();
    let mut rng = XorShift::new(9);
    let uvs: Vec<(f32, f32, f32)> = (0..65_536)
        .map(|_| {
            (
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
                rng.range(0.0, 6.0),
            )
        })
        .collect();
    g.throughput(Throughput::Elements(uvs.len() as u64));
    g.bench_function(BenchmarkId::new("texture_sample", "trilinear64k"), |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &(u, v, lod) in &uvs {
                acc += tex.sample(&sampler, u, v, lod).r;
            }
            black_box(acc)
        })
    });
    g.finish();
}

/// The showcase's scene (the built-in default scene), seen from the first frame of its
/// headless camera path.
fn game_scene() -> (Scene, Camera) {
    let show = Showcase::new();
    let (eye, target) = show.path(0, 60);
    (show.scene, showcase::camera(eye, target, 1280, 720))
}

fn full_frame(c: &mut Criterion) {
    let (scene, camera) = game_scene();
    bench_frame(
        c,
        "full_frame",
        ("game_scene", "1280x720"),
        &scene,
        camera,
        (1280, 720),
    );
}

criterion_group!(benches, stages, torus, full_frame);
criterion_main!(benches);

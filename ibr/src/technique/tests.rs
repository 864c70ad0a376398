use super::*;
use engine::{Material, Mesh, Rgba};
use glam::{Mat4, Vec3};
use std::cell::RefCell;

/// Records the calls it gets, in order, in a shared log.
#[derive(Debug)]
struct Probe<'l> {
    name: &'static str,
    log: &'l RefCell<Vec<String>>,
    mesh: Mesh,
    material: Material,
    seen: Option<f32>,
}

impl<'l> Probe<'l> {
    fn new(name: &'static str, log: &'l RefCell<Vec<String>>) -> Self {
        Probe {
            name,
            log,
            mesh: engine::procedural::quad(1.0, 1.0),
            material: Material::unlit(Rgba::WHITE).double_sided(true),
            seen: None,
        }
    }
    fn note(&self, what: &str) {
        self.log.borrow_mut().push(format!("{} {what}", self.name));
    }
}

impl Technique for Probe<'_> {
    fn name(&self) -> &str {
        self.name
    }
    fn prepare(&mut self, view: &FrameView<'_>) {
        self.note(&format!("prepare {}", view.time));
    }
    fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        self.note("draws");
        out.push(Draw {
            mesh: &self.mesh,
            material: &self.material,
            transform: Mat4::IDENTITY,
        });
    }
    fn passes(&self, _view: &FrameView<'_>, _target: &mut Target) -> FrameStats {
        self.note("passes");
        FrameStats::default()
    }
    fn observe(&self, seen: &mut Observed<'_, '_>) -> Option<f32> {
        self.note(&format!("observe {} draws", seen.draws.len()));
        // The centre pixel's alpha: the quads were drawn before it looks.
        let (w, h) = (seen.target.width(), seen.target.height());
        seen.target.color_linear(w / 2, h / 2).map(|c| c.a)
    }
    fn resolve(&mut self, _view: &FrameView<'_>, observed: Option<f32>) {
        self.note("resolve");
        self.seen = observed;
    }
    fn overlay<'a>(&'a self, _out: &mut Vec<Draw<'a>>) {
        self.note("overlay");
    }
    fn counters(&self) -> Counters {
        Counters {
            quads: 1,
            ..Counters::default()
        }
    }
}

fn camera() -> Camera {
    Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 1.0, 1.0)
}

#[test]
fn the_loop_calls_every_step_in_order_and_adds_the_scene() {
    let log = RefCell::new(Vec::new());
    let (mut a, mut b) = (Probe::new("a", &log), Probe::new("b", &log));
    let cam = camera();
    let lighting = Lighting::default();
    let mut target = Target::new(32, 32);
    let view = FrameView {
        camera: &cam,
        width: 32,
        height: 32,
        lighting: &lighting,
        time: 1.5,
        dt: 0.1,
    };
    let scene_mesh = engine::procedural::quad(0.1, 0.1);
    let scene_mat = Material::unlit(Rgba::WHITE);
    let scene = [Draw {
        mesh: &scene_mesh,
        material: &scene_mat,
        transform: Mat4::from_translation(Vec3::new(0.0, 0.0, -5.0)),
    }];
    let mut frame = FrameLoop::new();
    let mut list: [&mut dyn Technique; 2] = [&mut a, &mut b];
    let stats = frame.render(
        &mut Renderer::new(),
        scene,
        &mut list,
        &view,
        &mut target,
        &FrameOptions::default(),
    );
    assert_eq!(
        stats.draws, 3,
        "the scene's draw and one from each technique"
    );
    let want = [
        "a prepare 1.5",
        "b prepare 1.5",
        "a draws",
        "b draws",
        "a passes",
        "b passes",
        "a observe 3 draws",
        "b observe 3 draws",
        "a resolve",
        "b resolve",
        "a overlay",
        "b overlay",
    ];
    assert_eq!(*log.borrow(), want);
    assert_eq!(
        frame.counters,
        vec![
            Counters {
                quads: 1,
                ..Default::default()
            };
            2
        ]
    );
    assert_eq!(a.seen, Some(1.0), "observed the finished frame");
    // Times are measured (what they are is the benchmarks' business), prepare within total.
    assert!(
        frame.times.prepare <= frame.times.total,
        "{:?}",
        frame.times
    );
    // A list of techniques of one kind is one technique.
    log.borrow_mut().clear();
    let mut both = vec![Probe::new("x", &log), Probe::new("y", &log)];
    both.prepare(&view);
    assert_eq!(both.counters().quads, 2);
    let mut out = Vec::new();
    both.draws(&mut out);
    assert_eq!(out.len(), 2);
    assert_eq!(
        *log.borrow(),
        ["x prepare 1.5", "y prepare 1.5", "x draws", "y draws"]
    );
}

#[test]
fn a_flare_in_the_loop_measures_as_update_with_blended_does() {
    // A half-opaque blended sheet in front of the sun.
    let sheet = Mesh {
        positions: vec![
            Vec3::new(-50.0, -50.0, -5.0),
            Vec3::new(50.0, -50.0, -5.0),
            Vec3::new(50.0, 50.0, -5.0),
            Vec3::new(-50.0, 50.0, -5.0),
        ],
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Default::default()
    };
    let glass = Material::unlit(Rgba::new(1.0, 1.0, 1.0, 0.4))
        .blended(engine::BlendMode::Alpha)
        .double_sided(true);
    let draws = [Draw {
        mesh: &sheet,
        material: &glass,
        transform: Mat4::IDENTITY,
    }];
    let cam = camera();
    let lighting = Lighting::default();
    let source = FlareSource::Directional(Vec3::new(0.2, 0.1, -1.0));
    let (w, h) = (64, 48);
    let view = FrameView {
        camera: &cam,
        width: w,
        height: h,
        lighting: &lighting,
        time: 0.0,
        dt: 1e6, // no fade
    };
    let mut flare = Flare {
        lens: LensFlare::default(),
        source,
    };
    let mut target = Target::new(w, h);
    let mut renderer = Renderer::new();
    let mut frame = FrameLoop::new();
    let mut list: [&mut dyn Technique; 1] = [&mut flare];
    frame.render(
        &mut renderer,
        draws,
        &mut list,
        &view,
        &mut target,
        &FrameOptions::default(),
    );
    let in_loop = flare.lens.measured();
    assert!((in_loop - 0.6).abs() < 0.01, "{in_loop}");
    assert!(
        flare.lens.quad_count() > 0,
        "its sprites were drawn over the frame"
    );
    let mut alone = LensFlare::default();
    let mut plain = Target::new(w, h);
    renderer.render(draws, &cam, &lighting, &mut plain, &FrameOptions::default());
    alone.update_with_blended(&cam, &plain, source, 1e6, &lighting, draws);
    assert_eq!(alone.measured(), in_loop);
}

#[test]
fn an_octahedral_impostor_off_the_image_is_neither_updated_nor_drawn() {
    let mut subject = crate::subject::MeshGroup::new().with(
        std::sync::Arc::new(engine::procedural::uv_sphere(1.0, 8, 12)),
        std::sync::Arc::new(Material::lit(Rgba::new(0.8, 0.3, 0.2, 1.0))),
        Mat4::IDENTITY,
    );
    let lighting = Lighting::default();
    let mut imp = OctahedralImpostor::bake(
        &mut subject,
        &lighting,
        4,
        16,
        crate::octahedral::Layout::Full,
    );
    let mut frame = FrameLoop::new();
    let mut target = Target::new(32, 32);
    let mut run = |imp: &mut OctahedralImpostor, eye: Vec3, at: Vec3| {
        let cam = Camera::look_at(eye, at, Vec3::Y, 1.0, 1.0);
        let view = FrameView {
            camera: &cam,
            width: 32,
            height: 32,
            lighting: &lighting,
            time: 0.0,
            dt: 0.0,
        };
        let stats = frame.render(
            &mut Renderer::new(),
            [],
            &mut [imp],
            &view,
            &mut target,
            &FrameOptions::default(),
        );
        (stats.draws, frame.counters[0])
    };
    // Seen from the side (the bake starts from above): recomposed and drawn.
    let (draws, c) = run(&mut imp, Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO);
    assert_eq!((draws, c.images, c.quads, c.refreshes), (1, 1, 1, 1));
    let frames = imp.frames();
    // Looking away from another side: culled, and the image keeps its frames.
    let (draws, c) = run(&mut imp, Vec3::new(4.0, 0.0, 0.0), Vec3::new(8.0, 0.0, 0.0));
    assert_eq!((draws, c.images, c.quads, c.refreshes), (0, 0, 0, 0));
    assert!(!imp.in_view());
    assert_eq!(imp.frames(), frames, "not updated while culled");
    // Back in view from that side: recomposed for it.
    let (draws, c) = run(&mut imp, Vec3::new(4.0, 0.0, 0.0), Vec3::ZERO);
    assert_eq!((draws, c.images, c.refreshes), (1, 1, 1));
    assert_ne!(imp.frames(), frames);
}

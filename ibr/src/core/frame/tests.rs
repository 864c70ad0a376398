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
    // The stages split the frame: their times add up to the total, one prepare per technique.
    let t = frame.times;
    assert_eq!(
        t.prepare + t.render + t.passes + t.observe + t.overlay,
        t.total
    );
    assert_eq!(frame.prepares.len(), 2);
    assert!(frame.prepares.iter().sum::<Duration>() <= t.prepare);
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

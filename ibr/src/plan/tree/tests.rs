//! The hierarchy's properties: bounds, refits, the cut's cover, and planning that follows
//! the nodes opened (counters, not time).

use super::*;
use crate::core::{CostModel, Estimate, Representation, Sight, Work};
use engine::{Camera, Lighting, Material, Mesh, Sphere, Texture};
use glam::{Mat4, Vec3};
use std::sync::Arc;

/// A ball of radius `r` at `c`, of 500 triangles, drawing nothing (the cut is what is tested).
#[derive(Clone, Debug)]
pub(super) struct Ball(pub Vec3, pub f32);

impl Subject for Ball {
    fn bounds(&self) -> Sphere {
        Sphere {
            center: self.0,
            radius: self.1,
        }
    }
    fn draws<'s>(&'s self, _out: &mut Vec<Draw<'s>>) {}
    fn triangle_count(&self) -> usize {
        500
    }
}

/// An image per node, from the eye it was taken at: its error grows with the angle the eye
/// moved as seen from the node (100 levels per radian), infinite once the node changed;
/// none for a node wider than 64 pixels on screen. A held image is drawn as one quad of a
/// 1 x 1 texture.
pub(super) struct Snapshots {
    held: Vec<Option<(Vec3, u64)>>,
    rebuilt: Vec<usize>,
    quad: Mesh,
    material: Material,
}

impl Representation<Cluster<Ball>> for Snapshots {
    fn name(&self) -> &str {
        "snapshots"
    }
    fn estimate(&self, i: usize, s: &Cluster<Ball>, sight: &Sight<'_>) -> Option<Estimate> {
        let b = sight.bounds;
        let disc = 2.0 * (b.radius / sight.distance).min(1.0).asin() * sight.px_per_radian;
        if sight.within(1.5) || disc > 64.0 {
            return None;
        }
        let error = match self.held[i] {
            Some((eye, v)) if v == s.version() => {
                let (a, c) = (
                    (eye - b.center).normalize(),
                    (sight.eye - b.center).normalize(),
                );
                a.angle_between(c) * 100.0
            }
            _ => f32::INFINITY,
        };
        let mut e = Estimate::image(error, 0.5, sight.pixels, s.triangle_count(), (32, 32));
        e.rebuild = Work {
            triangles: s.triangle_count() as u64,
            ..Work::default()
        };
        Some(e)
    }
    fn rebuild(
        &mut self,
        nodes: &[usize],
        subjects: &mut [Cluster<Ball>],
        view: &FrameView<'_>,
    ) -> Work {
        for &k in nodes {
            self.held[k] = Some((view.camera.eye(), subjects[k].version()));
            self.rebuilt.push(k);
        }
        Work::default()
    }
    fn draw<'a>(&'a self, i: usize, _: &'a Cluster<Ball>, _: Vec3, out: &mut Vec<Draw<'a>>) {
        if self.held[i].is_some() {
            out.push(Draw {
                mesh: &self.quad,
                material: &self.material,
                transform: Mat4::IDENTITY,
            });
        }
    }
    fn release(&mut self, i: usize) {
        self.held[i] = None;
    }
    /// A byte per image rebuilt so far: the tests read the representation's own count of
    /// rebuilds through [`TreeReport::memory`].
    fn memory(&self) -> usize {
        self.rebuilt.len()
    }
}

/// `side` x `side` balls a unit apart on the ground, centred on the origin.
pub(super) fn field(side: usize) -> Vec<Ball> {
    let h = side as f32 * 0.5;
    (0..side * side)
        .map(|k| {
            Ball(
                Vec3::new((k % side) as f32 - h, 0.3, (k / side) as f32 - h),
                0.3,
            )
        })
        .collect()
}

pub(super) fn hierarchy(side: usize, config: TreeConfig) -> Hierarchy<Ball> {
    Hierarchy::new(config, field(side), |n| {
        let mut quad = Mesh::default();
        let corners = [Vec3::ZERO, Vec3::X, Vec3::X + Vec3::Y, Vec3::Y];
        let uv = crate::core::UvRect {
            min: glam::Vec2::ZERO,
            max: glam::Vec2::ONE,
        };
        crate::core::push_quad(&mut quad, corners, uv, engine::Rgba::WHITE, 1.0);
        let snaps = Snapshots {
            held: vec![None; n],
            rebuilt: Vec::new(),
            quad,
            material: Material {
                base_texture: Some(Arc::new(Texture::solid(engine::Rgba::WHITE))),
                ..Material::default()
            },
        };
        vec![Box::new(snaps) as Box<dyn Representation<Cluster<Ball>>>]
    })
}

/// Looking over the field from `eye`, 16:9.
pub(super) fn camera(eye: Vec3, side: usize) -> Camera {
    Camera::look_at(
        eye,
        Vec3::new(0.0, 0.0, -(side as f32) * 0.25),
        Vec3::Y,
        1.0,
        16.0 / 9.0,
    )
    .with_depth_range(0.1, side as f32 * 4.0)
}

pub(super) fn plan(h: &mut Hierarchy<Ball>, camera: &Camera) -> TreeReport {
    let lighting = Lighting::default();
    *h.plan(&FrameView::still(camera, 320, 180, &lighting))
}

/// Per object, how many times the last cut draws it (as geometry or under an image).
pub(super) fn drawn(h: &Hierarchy<Ball>) -> Vec<usize> {
    let mut times = vec![0; h.objects().len()];
    for &i in h.geometry() {
        times[i as usize] += 1;
    }
    for &(k, _, _) in h.images() {
        for &i in h.tree().objects_of(k as usize) {
            times[i as usize] += 1;
        }
    }
    times
}

#[test]
fn every_node_contains_its_children_and_its_objects() {
    let balls = field(37);
    let h = hierarchy(37, TreeConfig::default());
    let nodes = h.tree().nodes();
    let inside = |lo: Vec3, hi: Vec3, n: &Node| lo.cmpge(n.lo).all() && hi.cmple(n.hi).all();
    for (k, n) in nodes.iter().enumerate() {
        assert!(n.count as usize <= TreeConfig::default().leaf || !n.is_leaf());
        for &i in h.tree().objects_of(k) {
            let b = balls[i as usize].bounds();
            assert!(
                inside(b.center - b.radius, b.center + b.radius, n),
                "{k} {i}"
            );
        }
        if !n.is_leaf() {
            let [a, b] = n.children.map(|c| nodes[c as usize]);
            assert!(inside(a.lo, a.hi, n) && inside(b.lo, b.hi, n));
            assert_eq!(a.count + b.count, n.count);
            assert_eq!(a.parent as usize, k);
        }
    }
    // Every object in exactly one leaf.
    let mut seen = vec![0; balls.len()];
    nodes
        .iter()
        .enumerate()
        .filter(|(_, n)| n.is_leaf())
        .for_each(|(k, _)| {
            h.tree()
                .objects_of(k)
                .iter()
                .for_each(|&i| seen[i as usize] += 1)
        });
    assert!(seen.iter().all(|&s| s == 1));
}

#[test]
fn a_refit_touches_only_the_moved_objects_ancestors() {
    let mut h = hierarchy(64, TreeConfig::default());
    let before: Vec<Node> = h.tree().nodes().to_vec();
    // 300 of 4,096 objects lifted by one unit.
    let moved: Vec<usize> = (0..300).map(|k| (k * 4093) % 4096).collect();
    let refitted = h.update(&moved, |_, b| b.0.y += 1.0);
    // The ancestors, found independently: every node whose range holds a moved object.
    let mut want = Vec::new();
    for (k, _) in before.iter().enumerate() {
        if h.tree()
            .objects_of(k)
            .iter()
            .any(|i| moved.contains(&(*i as usize)))
        {
            want.push(k);
        }
    }
    assert_eq!(refitted, want.len());
    assert!(
        refitted < before.len() / 2,
        "{refitted} of {}",
        before.len()
    );
    for (k, (a, b)) in before.iter().zip(h.tree().nodes()).enumerate() {
        let touched = want.contains(&k);
        assert_eq!(b.version, a.version + u64::from(touched), "{k}");
        if touched {
            assert!(
                b.hi.y >= a.hi.y + 0.99 || !b.is_leaf() || b.hi.y > 1.2,
                "{k}"
            );
        } else {
            assert_eq!((a.lo, a.hi), (b.lo, b.hi), "{k}");
        }
    }
    // Images of untouched nodes stay; only touched ones are rebuilt.
    let cam = camera(Vec3::new(0.0, 20.0, 60.0), 64);
    let mut h = hierarchy(
        64,
        TreeConfig {
            rebuilds: 100_000,
            rebuild_ms: 1e9,
            ..TreeConfig::default()
        },
    );
    plan(&mut h, &cam);
    let first: Vec<u32> = h.images().iter().map(|x| x.0).collect();
    assert!(!first.is_empty());
    let refitted = h.update(&moved, |_, b| b.0.y += 1.0);
    let r = plan(&mut h, &cam);
    assert!(r.rebuilds <= refitted, "{} > {refitted}", r.rebuilds);
    let versions = h.tree().nodes();
    for &(k, _, _) in h.images() {
        let stays = first.contains(&k) && versions[k as usize].version == 0;
        assert!(stays || r.rebuilds > 0);
    }
}

#[test]
fn the_cut_draws_every_object_in_view_exactly_once() {
    let mut h = hierarchy(
        96,
        TreeConfig {
            rebuilds: 40,
            ..TreeConfig::default()
        },
    );
    let mut total = TreeReport::default();
    for f in 0..12 {
        let cam = camera(Vec3::new(f as f32 * 1.5 - 8.0, 12.0, 50.0), 96);
        let r = plan(&mut h, &cam);
        total.images += r.images;
        total.geometry += r.geometry;
        total.over += r.over;
        let frustum = crate::core::Frustum::new(cam.clip_from_world());
        for (i, &n) in drawn(&h).iter().enumerate() {
            let b = h.objects()[i].bounds();
            if frustum.sees(b.center, b.radius) {
                assert_eq!(n, 1, "object {i} at frame {f}");
            } else {
                assert!(n <= 1, "object {i} at frame {f}");
            }
        }
    }
    // Both kinds drawn: images for the far field, geometry near.
    assert!(total.images > 0 && total.geometry > 0, "{total:?}");
}

#[test]
fn planning_visits_the_nodes_opened_not_the_objects() {
    // The same view of fields of 4 and 64 times as many objects: the far field is a few
    // images, so the nodes visited grow by far less than the objects.
    let config = TreeConfig {
        rebuilds: 100_000,
        rebuild_ms: 1e9,
        ..TreeConfig::default()
    };
    let mut visits = Vec::new();
    for side in [64, 128, 512] {
        let mut h = hierarchy(side, config);
        let cam = camera(Vec3::new(0.0, 10.0, side as f32 * 0.5 + 20.0), side);
        plan(&mut h, &cam);
        let r = plan(&mut h, &cam);
        // A binary tree: the root and two children per node opened, nothing else.
        assert_eq!(r.visited, 1 + 2 * r.opened, "{r:?}");
        assert!(r.estimates <= r.visited - r.culled, "{r:?}");
        assert_eq!(r.rebuilds, 0, "a still view keeps its images: {r:?}");
        visits.push((side * side, r.visited));
    }
    let (small, large) = (visits[0], visits[2]);
    assert!(large.0 == 64 * small.0);
    assert!(large.1 < 4 * small.1, "{visits:?}");
    assert!(large.1 * 20 < large.0, "{visits:?}");
}

#[test]
fn the_same_frames_make_the_same_cut() {
    let run = || {
        let mut h = hierarchy(48, TreeConfig::default());
        (0..5)
            .map(|f| {
                plan(&mut h, &camera(Vec3::new(f as f32, 8.0, 30.0), 48));
                (h.images().to_vec(), h.geometry().to_vec())
            })
            .collect::<Vec<_>>()
    };
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    assert_eq!(one.install(run), two.install(run));
}

#[test]
fn odd_boxes_and_no_objects_do_not_panic() {
    let mut h = Hierarchy::new(TreeConfig::default(), Vec::<Ball>::new(), |_| Vec::new());
    assert_eq!(plan(&mut h, &camera(Vec3::Z, 4)).visited, 0);
    let odd = vec![
        Ball(Vec3::NAN, 1.0),
        Ball(Vec3::ZERO, f32::INFINITY),
        Ball(Vec3::X, 0.5),
    ];
    let mut h = Hierarchy::new(TreeConfig::default(), odd, |_| Vec::new());
    plan(&mut h, &camera(Vec3::new(0.0, 2.0, 10.0), 4));
    assert_eq!(
        h.update(&[0, 7], |_, b| b.0 = Vec3::ONE),
        1.max(h.report.refitted)
    );
}

#[test]
fn the_rebuild_budget_holds_every_frame() {
    // A moving eye stales images every frame. Each frame's rebuilds are the ones the
    // representation was asked for, within the count and the predicted milliseconds
    // (the loading frames' larger allowance first), and a frame whose budget is spent
    // draws the rest stale or opens them: every object in view still drawn once.
    let cost = CostModel::default();
    let one = cost.ms(Work {
        triangles: 500,
        ..Work::default()
    });
    let config = TreeConfig {
        rebuilds: 6,
        // Room for about 40 objects' captures a frame, 200 while loading.
        rebuild_ms: 40.0 * one,
        loading: (2, 200.0 * one),
        ..TreeConfig::default()
    };
    let mut h = hierarchy(64, config);
    let mut asked = 0;
    for f in 0..10 {
        let cam = camera(Vec3::new(f as f32 * 2.0 - 10.0, 10.0, 40.0), 64);
        let r = plan(&mut h, &cam);
        let cap = if f < 2 { 200.0 } else { 40.0 } * one;
        assert!(r.rebuilds <= 6, "frame {f}: {r:?}");
        assert!(r.rebuild_ms <= cap * 1.0001, "frame {f}: {r:?} over {cap}");
        // The cut's rebuilds are exactly the representation's.
        let total = rebuilt(&h);
        assert_eq!(total - asked, r.rebuilds, "frame {f}");
        asked = total;
        let frustum = crate::core::Frustum::new(cam.clip_from_world());
        for (i, &n) in drawn(&h).iter().enumerate() {
            let b = h.objects()[i].bounds();
            assert!(
                n <= 1 && (n == 1 || !frustum.sees(b.center, b.radius)),
                "{i} {f}"
            );
        }
    }
    assert!(asked > 0);
}

#[test]
fn a_capture_cost_caps_the_rebuilds_a_frame() {
    // The same moving eye as above, the count not binding: uncharged, frames after
    // loading rebuild two node images (each within ten objects' triangles of the model);
    // charged a measured cost per capture besides the model's (`TreeConfig::capture_ms`,
    // twenty objects' triangles), the 40 objects' budget holds one a frame. Counters
    // only: the budget is predicted milliseconds, not a clock.
    let one = CostModel::default().ms(Work {
        triangles: 500,
        ..Work::default()
    });
    let run = |capture_ms: f32| {
        let config = TreeConfig {
            rebuilds: 1_000,
            rebuild_ms: 40.0 * one,
            loading: (2, 200.0 * one),
            capture_ms,
            ..TreeConfig::default()
        };
        let mut h = hierarchy(64, config);
        let mut most = 0;
        for f in 0..10 {
            let cam = camera(Vec3::new(f as f32 * 2.0 - 10.0, 10.0, 40.0), 64);
            let r = plan(&mut h, &cam);
            if f >= 2 {
                assert!(r.rebuild_ms <= 40.0 * one * 1.0001, "frame {f}: {r:?}");
                most = most.max(r.rebuilds);
            }
        }
        most
    };
    let (charged, free) = (run(20.0 * one), run(0.0));
    assert_eq!(charged, 1, "at most one a frame, and one taken");
    assert!(free >= 2, "uncharged {free}");
}

/// How many node images the test representation has rebuilt so far.
fn rebuilt(h: &Hierarchy<Ball>) -> usize {
    h.report.memory
}

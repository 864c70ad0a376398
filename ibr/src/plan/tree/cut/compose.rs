//! A node's image composed of its children's images (Shade et al. 96's hierarchical image
//! cache, [`super::TreeConfig::compose`]): which children's images will do, what the
//! composed rebuild is priced at and errs by, and the parts its capture draws.

use super::{Hierarchy, TreeReport};
use crate::core::{Sight, Subject, Work};
use crate::plan::tree::cluster::Part;
use glam::Vec3;

/// One way of drawing a node this frame: its representation, predicted error, and
/// predicted milliseconds to draw and to rebuild; for a rebuild composed of its children's
/// images, what it takes from them.
#[derive(Clone, Copy, Debug)]
pub(super) struct Choice {
    pub(super) rep: usize,
    pub(super) error: f32,
    pub(super) ms: f32,
    pub(super) rebuild: f32,
    pub(super) composed: Option<Composed>,
}

/// A rebuild composed of a node's children's images: the largest error of those images,
/// and which children are drawn as their image (the others as their objects).
#[derive(Clone, Copy, Debug)]
pub(super) struct Composed {
    pub(super) error: f32,
    pub(super) images: [bool; 2],
}

impl<S: Subject + Send + Sync> Hierarchy<S> {
    /// Gives each of the frame's composed rebuilds its parts: the chosen children's images
    /// as drawn from `eye` (a child whose image is gone by now: its objects), the other
    /// children's objects.
    pub(super) fn compose_batch(&mut self, eye: Vec3, report: &mut TreeReport) {
        for i in 0..self.composing.len() {
            let (k, r, images) = self.composing[i];
            let node = self.tree.nodes()[k as usize];
            let mut parts = Vec::with_capacity(2);
            for (j, &child) in node.children.iter().enumerate() {
                let c = child as usize;
                let mut draws = Vec::new();
                if images[j] {
                    self.reps[usize::from(r)].draw(c, &self.clusters[c], eye, &mut draws);
                }
                if draws.is_empty() {
                    let n = self.tree.nodes()[c];
                    parts.push(Part::Objects(n.first, n.count));
                } else {
                    parts.extend(draws.iter().map(Part::image));
                }
            }
            report.composed += 1;
            report.composed_texels += parts.iter().map(Part::texels).sum::<u64>();
            self.clusters[k as usize].compose(parts);
        }
        self.composing.clear();
    }

    /// Node `k`'s options seen as `sight` (`base` at the eye), each the cheapest to draw of
    /// the representations': as it is within the budget, rebuilt this frame within the
    /// budget and paying back within [`TreeConfig::payback`] frames of its geometry's
    /// `geometry_ms` (composed of its children's images when that is cheaper, still within
    /// the budget), and as it is within [`TreeConfig::stale`] times the budget.
    pub(super) fn options(
        &self,
        k: usize,
        base: &Sight<'_>,
        sight: &Sight<'_>,
        geometry_ms: f32,
        estimates: &mut usize,
    ) -> [Option<Choice>; 3] {
        let cfg = &self.config;
        let cluster = &self.clusters[k];
        let (mut as_is, mut fresh, mut stale) = (None, None, None);
        for (r, rep) in self.reps.iter().enumerate() {
            let Some(e) = rep.estimate(k, cluster, sight) else {
                continue;
            };
            *estimates += 1;
            let error = e.error + self.inherited[k];
            let ms = cfg.cost.ms(e.draw);
            // A rebuild draws its objects at the capture's levels of detail, not their
            // full meshes.
            let capture = Work {
                triangles: cluster.capture_triangles() as u64,
                ..e.rebuild
            };
            let rb = cfg.cost.ms(capture);
            let cheaper = |o: &Option<Choice>| o.is_none_or(|b| ms < b.ms);
            let now = Choice {
                rep: r,
                error,
                ms,
                rebuild: rb,
                composed: None,
            };
            if error <= cfg.budget && cheaper(&as_is) {
                as_is = Some(now);
            }
            if error <= cfg.budget * cfg.stale && cheaper(&stale) {
                stale = Some(now);
            }
            let mut rebuilt = Choice {
                error: e.rebuilt,
                ..now
            };
            if error > cfg.budget {
                if let Some((c, triangles)) = self.composition(k, r, base, estimates) {
                    let composed_rb = cfg.cost.ms(Work {
                        triangles,
                        ..e.rebuild
                    });
                    if e.rebuilt + c.error <= cfg.budget && composed_rb < rb {
                        rebuilt = Choice {
                            error: e.rebuilt + c.error,
                            rebuild: composed_rb,
                            composed: Some(c),
                            ..now
                        };
                    }
                }
            }
            let pays = rebuilt.rebuild <= geometry_ms * cfg.payback;
            if rebuilt.error <= cfg.budget
                && pays
                && fresh.is_none_or(|b: Choice| rebuilt.rebuild < b.rebuild)
            {
                fresh = Some(rebuilt);
            }
        }
        [as_is, fresh, stale]
    }

    /// Node `k`'s rebuild by representation `r` composed of its children's images: which
    /// children hold an image erring within [`TreeConfig::compose`] of the budget (as seen
    /// from `base`'s eye), the largest of their errors, and the triangles the capture
    /// draws (two a child image, the other child's objects); `None` for a leaf, with
    /// composing off, or when no child's image will do.
    fn composition(
        &self,
        k: usize,
        r: usize,
        base: &Sight<'_>,
        estimates: &mut usize,
    ) -> Option<(Composed, u64)> {
        let cfg = &self.config;
        let node = self.tree.nodes()[k];
        if cfg.compose <= 0.0 || node.is_leaf() {
            return None;
        }
        let mut composed = Composed {
            error: 0.0,
            images: [false; 2],
        };
        let mut triangles = 0u64;
        for (j, &child) in node.children.iter().enumerate() {
            let c = child as usize;
            let cluster = &self.clusters[c];
            let sight = base
                .at(self.tree.nodes()[c].sphere())
                .with_corners(cluster.corners());
            let e = self.reps[r].estimate(c, cluster, &sight);
            *estimates += usize::from(e.is_some());
            let error = e.map_or(f32::INFINITY, |e| e.error + self.inherited[c]);
            if error <= cfg.compose * cfg.budget {
                composed.images[j] = true;
                composed.error = composed.error.max(error);
                triangles += 2;
            } else {
                triangles += cluster.capture_triangles() as u64;
            }
        }
        composed
            .images
            .contains(&true)
            .then_some((composed, triangles))
    }
}

impl<S: Subject + Send + Sync> Hierarchy<S> {
    /// Whether node `k` is better opened than rebuilt: every child holds an image (of some
    /// representation) within the budget as it is, seen from `base`'s eye, so opening it
    /// draws two images at no rebuild, where rebuilding spends the frame's rebuild budget
    /// on what is already shown within the budget.
    pub(super) fn children_will_do(
        &self,
        k: usize,
        base: &Sight<'_>,
        estimates: &mut usize,
    ) -> bool {
        let node = self.tree.nodes()[k];
        if node.is_leaf() {
            return false;
        }
        node.children.iter().all(|&child| {
            let c = child as usize;
            let cluster = &self.clusters[c];
            let sight = base
                .at(self.tree.nodes()[c].sphere())
                .with_corners(cluster.corners());
            self.reps.iter().any(|rep| {
                let e = rep.estimate(c, cluster, &sight);
                *estimates += usize::from(e.is_some());
                e.is_some_and(|e| e.error + self.inherited[c] <= self.config.budget)
            })
        })
    }
}

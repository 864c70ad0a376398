//! `bench budget --objects`: each image representation's predicted error against the error
//! measured on the objects it draws, by their size on screen. Per scene and
//! representation, a planner choosing between geometry and that representation alone,
//! with an error budget no object reaches (so each takes its image wherever it can draw
//! one), flies the scene's frames; every object it draws as an image is measured over its
//! screen rectangle against all the geometry, and binned by the rectangle's side. Where
//! rectangles overlap, an object's measured error includes its neighbours' (their images'
//! errors and the occlusion between images): `overlap` says how much, the mean count of
//! other rectangles over each of its pixels. In dense scenes no rectangle is alone, so
//! this is the error a frame of images shows around each object, not the object's own.

use super::{fly_with, planner_of, scenes, Settings, REPRESENTATIONS};
use crate::bench::sweep::{self, CsvRow};
use ibr::metrics::{Rect, RectCover};

/// Rectangle sides (pixels, the square root of its area) the bins start at.
pub const BINS: [f64; 6] = [0.0, 4.0, 8.0, 16.0, 32.0, 64.0];

/// One bin: the object-frames of one representation in one scene whose rectangles' sides
/// are in `[side, next bin)`.
#[derive(Clone, Debug)]
pub struct ObjectRow {
    pub scene: &'static str,
    pub representation: &'static str,
    pub side: f64,
    pub count: usize,
    pub predicted_mean: f64,
    pub measured_mean: f64,
    /// The 95th percentile of the measured error.
    pub measured_p95: f64,
    /// The fraction whose measured error is at or under the prediction.
    pub within: f64,
    /// Mean over the object-frames of how many other rectangles cover each pixel of theirs.
    pub overlap: f64,
}

impl CsvRow for ObjectRow {
    const HEADER: &'static str =
        "scene,representation,side_px,count,predicted_mean,measured_mean,measured_p95,within,overlap";

    fn csv(&self) -> String {
        format!(
            "{},{},{},{},{:.4},{:.4},{:.4},{:.4},{:.3}",
            self.scene,
            self.representation,
            self.side,
            self.count,
            self.predicted_mean,
            self.measured_mean,
            self.measured_p95,
            self.within,
            self.overlap
        )
    }
}

/// The budget that lets every object take its image: far above any prediction.
const UNREACHED: f32 = 1e6;

/// Runs the sweep: every scene, every image representation.
pub fn objects(
    settings: &Settings,
    progress: &mut dyn FnMut(usize, usize, &str),
) -> Vec<ObjectRow> {
    let scenes = scenes(settings);
    let reps = REPRESENTATIONS.len() - 1;
    let mut tick = sweep::ticker(scenes.len() * reps, progress);
    let mut rows = Vec::new();
    for scene in &scenes {
        for k in 1..=reps {
            tick(format!("{} {}", scene.name, REPRESENTATIONS[k]));
            // Per bin: (predicted, measured, overlap) of every object-frame.
            let mut bins: Vec<Vec<(f64, f64, f64)>> = vec![Vec::new(); BINS.len()];
            let mut cover = Coverage::default();
            let mut p = planner_of(scene, settings, UNREACHED, &[k]);
            fly_with(scene, settings, UNREACHED, &mut p, &mut |p, seen| {
                cover.count(settings.size, seen.iter().map(|s| s.2));
                for &(i, measured, r) in seen {
                    let c = p.choices()[i];
                    if c.rep != Some(1) || !c.error.is_finite() {
                        continue;
                    }
                    let side = f64::from(r.width * r.height).sqrt();
                    let b = BINS.iter().rposition(|&lo| side >= lo).unwrap_or(0);
                    bins[b].push((f64::from(c.error), measured, cover.others(r)));
                }
            });
            for (b, mut v) in bins.into_iter().enumerate() {
                if v.is_empty() {
                    continue;
                }
                let n = v.len() as f64;
                let within = v.iter().filter(|(p, m, _)| m <= p).count() as f64 / n;
                let overlap = v.iter().map(|x| x.2).sum::<f64>() / n;
                let predicted_mean = v.iter().map(|x| x.0).sum::<f64>() / n;
                let measured_mean = v.iter().map(|x| x.1).sum::<f64>() / n;
                v.sort_by(|a, b| a.1.total_cmp(&b.1));
                let p95 = v[((n * 0.95).ceil() as usize).clamp(1, v.len()) - 1].1;
                rows.push(ObjectRow {
                    scene: scene.name,
                    representation: REPRESENTATIONS[k],
                    side: BINS[b],
                    count: v.len(),
                    predicted_mean,
                    measured_mean,
                    measured_p95: p95,
                    within,
                    overlap,
                });
            }
        }
    }
    rows
}

/// How many rectangles cover each pixel of a frame.
#[derive(Default)]
struct Coverage(RectCover);

impl Coverage {
    /// Counts `rects` over a frame of `size`.
    fn count(&mut self, size: (u32, u32), rects: impl Iterator<Item = Rect>) {
        self.0.count(size.0, size.1, rects);
        self.0.summed();
    }

    /// How many other rectangles cover each pixel of `r`, on average.
    fn others(&self, r: Rect) -> f64 {
        let area = u64::from(r.width) * u64::from(r.height);
        (self.0.sum(r) as f64 - area as f64) / area.max(1) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coverage_counts_the_other_rectangles_over_each_one() {
        let rects = [
            Rect::new(0, 0, 4, 4),
            Rect::new(3, 3, 4, 4),
            Rect::new(10, 0, 2, 5),
            Rect::new(0, 8, 16, 2),
        ];
        let mut c = Coverage::default();
        c.count((16, 10), rects.iter().copied());
        let others: Vec<f64> = rects.iter().map(|&r| c.others(r)).collect();
        assert_eq!(others, [1.0 / 16.0, 1.0 / 16.0, 0.0, 0.0]);
        c.count(
            (16, 10),
            rects.iter().copied().chain([Rect::new(0, 0, 16, 10)]),
        );
        let others: Vec<f64> = rects.iter().map(|&r| c.others(r)).collect();
        assert_eq!(others, [1.0 + 1.0 / 16.0, 1.0 + 1.0 / 16.0, 1.0, 1.0]);
    }
}

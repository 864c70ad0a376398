//! The error budget over the whole frame: the pixel-weighted mean of the visible objects'
//! predicted errors kept within the budget at the least predicted time, by a Lagrange
//! multiplier. Each object takes the option least in `ms + lambda * error * pixels`; the
//! mean error falls as `lambda` grows, and `lambda` is the least (found by bisection) whose
//! choices bring it within the budget. Small objects may then err more than the budget
//! where that buys most time, as long as the frame as a whole does not.

use super::cost::{CostModel, Work};
use super::represent::Estimate;

/// One visible object's options this frame, as the multiplier weighs them.
pub(super) struct Object<'e> {
    /// Per representation (`None`: cannot draw it).
    pub est: &'e [Option<Estimate>],
    pub pixels: f32,
    /// The representation in use, whose time is discounted by the hysteresis.
    pub current: Option<usize>,
}

/// What an object may do this frame: draw one representation as it is, or rebuild it
/// first (its time then includes the rebuild spread over the payback frames).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Pick {
    pub rep: usize,
    pub rebuild: bool,
    pub error: f32,
    /// Drawing it, milliseconds (the rebuild left out).
    pub ms: f32,
    /// What the multiplier weighs: `time + lambda * weighted`, where `time` is `ms` less
    /// the hysteresis discount, plus the spread rebuild, and `weighted` is error times
    /// pixels.
    time: f64,
    weighted: f64,
}

impl Pick {
    pub(super) fn score(&self, lambda: f64) -> f64 {
        self.time + lambda * self.weighted
    }
}

/// How options are weighed besides the multiplier.
pub(super) struct Weights<'c> {
    pub cost: &'c CostModel,
    /// The hysteresis discount on the representation in use, a fraction of its time.
    pub stick: f32,
    /// Frames a rebuild's time is spread over.
    pub payback: f32,
}

/// Every visible object's options with a finite error, flattened once per frame so that
/// the bisection only does arithmetic.
pub(super) struct Options {
    picks: Vec<Pick>,
    /// Each object's range of `picks`, and its pixels.
    ranges: Vec<(usize, usize)>,
    pixels: Vec<f64>,
}

impl Options {
    pub(super) fn new(objects: &[Object<'_>], w: &Weights<'_>) -> Options {
        let mut out = Options {
            picks: Vec::new(),
            ranges: Vec::with_capacity(objects.len()),
            pixels: Vec::with_capacity(objects.len()),
        };
        for o in objects {
            let first = out.picks.len();
            let px = f64::from(o.pixels);
            for (r, e) in o.est.iter().enumerate() {
                let Some(e) = e else { continue };
                let ms = w.cost.ms(e.draw);
                let held = if Some(r) == o.current {
                    ms * (1.0 - w.stick)
                } else {
                    ms
                };
                if e.error.is_finite() {
                    out.picks.push(Pick {
                        rep: r,
                        rebuild: false,
                        error: e.error,
                        ms,
                        time: f64::from(held),
                        weighted: f64::from(e.error) * px,
                    });
                }
                if e.rebuild != Work::default() && e.rebuilt.is_finite() {
                    let spread = w.cost.ms(e.rebuild) / w.payback.max(1.0);
                    out.picks.push(Pick {
                        rep: r,
                        rebuild: true,
                        error: e.rebuilt,
                        ms,
                        time: f64::from(ms + spread),
                        weighted: f64::from(e.rebuilt) * px,
                    });
                }
            }
            out.ranges.push((first, out.picks.len()));
            out.pixels.push(px);
        }
        out
    }

    /// Object `k`'s options at multiplier `lambda`: the best as it is, and the best of
    /// all (rebuilds included), least `time + lambda * error * pixels` (ties: the first).
    pub(super) fn pick(&self, k: usize, lambda: f64) -> (Option<Pick>, Option<Pick>) {
        let (a, b) = self.ranges[k];
        let (mut as_is, mut best): (Option<Pick>, Option<Pick>) = (None, None);
        for p in &self.picks[a..b] {
            let score = p.score(lambda);
            if !p.rebuild && as_is.is_none_or(|q| score < q.score(lambda)) {
                as_is = Some(*p);
            }
            if best.is_none_or(|q| score < q.score(lambda)) {
                best = Some(*p);
            }
        }
        (as_is, best)
    }

    /// The pixel-weighted mean error of the objects' best options at `lambda`.
    fn mean_error(&self, lambda: f64) -> f64 {
        let (mut sum, mut weight) = (0.0, 0.0);
        for (k, &(a, b)) in self.ranges.iter().enumerate() {
            let best = self.picks[a..b]
                .iter()
                .min_by(|p, q| p.score(lambda).total_cmp(&q.score(lambda)));
            if let Some(p) = best {
                sum += p.weighted;
                weight += self.pixels[k];
            }
        }
        if weight > 0.0 {
            sum / weight
        } else {
            0.0
        }
    }
}

/// The least multiplier whose choices keep the mean error within `budget` (the largest
/// tried, 1e9 ms per level-pixel, when none does: the frame is then as accurate as its
/// options allow).
pub(super) fn multiplier(options: &Options, budget: f32) -> f64 {
    let budget = f64::from(budget.max(0.0));
    if options.mean_error(0.0) <= budget {
        return 0.0;
    }
    let (mut lo, mut hi) = (0.0f64, 1e-12f64);
    while options.mean_error(hi) > budget {
        lo = hi;
        hi *= 4.0;
        if hi > 1e9 {
            return 1e9;
        }
    }
    // Geometric bisection between lo (over) and hi (within).
    for _ in 0..40 {
        let mid = if lo > 0.0 { (lo * hi).sqrt() } else { hi * 0.5 };
        if options.mean_error(mid) > budget {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= hi * 1e-4 {
            break;
        }
    }
    hi
}

#[cfg(test)]
mod tests {
    use super::*;

    fn est(error: f32, triangles: u64) -> Option<Estimate> {
        Some(Estimate {
            error,
            rebuilt: error,
            draw: Work {
                triangles,
                ..Work::default()
            },
            rebuild: Work::default(),
            memory: 0,
        })
    }

    #[test]
    fn the_multiplier_spends_error_where_it_buys_most_time() {
        // Two objects, each geometry (exact, costly) or an image (cheap, erring), saving
        // the same time: the big one's image costs 1000 level-pixels, the small one's 80.
        let cost = CostModel::default();
        let w = Weights {
            cost: &cost,
            stick: 0.0,
            payback: 30.0,
        };
        let big = [est(0.0, 10_000), est(1.0, 2)];
        let small = [est(0.0, 10_000), est(8.0, 2)];
        let object = |est, pixels| Object {
            est,
            pixels,
            current: None,
        };
        let objects = [object(&big[..], 1000.0), object(&small[..], 10.0)];
        let options = Options::new(&objects, &w);
        let pick = |l: f64| [0, 1].map(|k| options.pick(k, l).1.unwrap().rep);
        // Within 0.5 only one image fits, the small one's (80 / 1010): the big one, whose
        // image would cost more error for the same time, is drawn as geometry.
        let l = multiplier(&options, 0.5);
        assert_eq!(pick(l), [0, 1]);
        assert!(options.mean_error(l) <= 0.5);
        // A generous budget takes both images; a zero one both geometries.
        assert_eq!(multiplier(&options, 2.0), 0.0);
        assert_eq!(pick(0.0), [1, 1]);
        assert_eq!(pick(multiplier(&options, 0.0)), [0, 0]);
    }
}

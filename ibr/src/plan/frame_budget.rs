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
    /// What the multiplier weighs: `ms` (less the hysteresis discount, plus the spread
    /// rebuild) and `lambda * error * pixels`.
    pub score: f64,
}

/// The options of `o` at multiplier `lambda`: the best as it is, and the best of all
/// (rebuilds included), by `ms + lambda * error * pixels`, the representation in use
/// discounted by `stick` (a fraction of its time) and a rebuild's time spread over
/// `payback` frames. Options with an infinite error are never taken.
pub(super) fn options(
    o: &Object<'_>,
    lambda: f64,
    cost: &CostModel,
    stick: f32,
    payback: f32,
) -> (Option<Pick>, Option<Pick>) {
    let (mut as_is, mut best): (Option<Pick>, Option<Pick>) = (None, None);
    for (r, e) in o.est.iter().enumerate() {
        let Some(e) = e else { continue };
        let ms = cost.ms(e.draw);
        let held = if Some(r) == o.current {
            ms * (1.0 - stick)
        } else {
            ms
        };
        let spread = cost.ms(e.rebuild) / payback.max(1.0);
        let weigh = |err: f32, t: f32| f64::from(t) + lambda * f64::from(err) * f64::from(o.pixels);
        let mut consider = |pick: Pick, only_best: bool| {
            if !pick.error.is_finite() {
                return;
            }
            if !only_best && as_is.is_none_or(|b| pick.score < b.score) {
                as_is = Some(pick);
            }
            if best.is_none_or(|b| pick.score < b.score) {
                best = Some(pick);
            }
        };
        consider(
            Pick {
                rep: r,
                rebuild: false,
                error: e.error,
                ms,
                score: weigh(e.error, held),
            },
            false,
        );
        if e.rebuild != Work::default() {
            let pick = Pick {
                rep: r,
                rebuild: true,
                error: e.rebuilt,
                ms,
                score: weigh(e.rebuilt, ms + spread),
            };
            consider(pick, true);
        }
    }
    (as_is, best)
}

/// How options are weighed besides the multiplier.
pub(super) struct Weights<'c> {
    pub cost: &'c CostModel,
    /// The hysteresis discount on the representation in use, a fraction of its time.
    pub stick: f32,
    /// Frames a rebuild's time is spread over.
    pub payback: f32,
}

/// The pixel-weighted mean error of the objects' best options at `lambda`.
fn mean_error(objects: &[Object<'_>], lambda: f64, w: &Weights) -> f64 {
    let (mut sum, mut weight) = (0.0, 0.0);
    for o in objects {
        if let (_, Some(p)) = options(o, lambda, w.cost, w.stick, w.payback) {
            sum += f64::from(p.error) * f64::from(o.pixels);
            weight += f64::from(o.pixels);
        }
    }
    if weight > 0.0 {
        sum / weight
    } else {
        0.0
    }
}

/// The least multiplier whose choices keep the mean error within `budget` (the largest
/// tried, 1e9 ms per level-pixel, when none does: the frame is then as accurate as its
/// options allow).
pub(super) fn multiplier(objects: &[Object<'_>], budget: f32, w: &Weights) -> f64 {
    let budget = f64::from(budget.max(0.0));
    if mean_error(objects, 0.0, w) <= budget {
        return 0.0;
    }
    let (mut lo, mut hi) = (0.0f64, 1e-12f64);
    while mean_error(objects, hi, w) > budget {
        lo = hi;
        hi *= 4.0;
        if hi > 1e9 {
            return 1e9;
        }
    }
    // Geometric bisection between lo (over) and hi (within).
    for _ in 0..40 {
        let mid = if lo > 0.0 { (lo * hi).sqrt() } else { hi * 0.5 };
        if mean_error(objects, mid, w) > budget {
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
        let pick = |l: f64| {
            objects
                .each_ref()
                .map(|o| options(o, l, &cost, 0.0, 30.0).1.unwrap().rep)
        };
        // Within 0.5 only one image fits, the small one's (80 / 1010): the big one, whose
        // image would cost more error for the same time, is drawn as geometry.
        let l = multiplier(&objects, 0.5, &w);
        assert_eq!(pick(l), [0, 1]);
        assert!(mean_error(&objects, l, &w) <= 0.5);
        // A generous budget takes both images; a zero one both geometries.
        assert_eq!(multiplier(&objects, 2.0, &w), 0.0);
        assert_eq!(pick(0.0), [1, 1]);
        assert_eq!(pick(multiplier(&objects, 0.0, &w)), [0, 0]);
    }
}

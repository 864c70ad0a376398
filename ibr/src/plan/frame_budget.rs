//! The error budget over the whole frame: a bound on the frame's mean error over the pixels
//! its visible objects cover kept within the budget at the least predicted time, by a
//! Lagrange multiplier. Small objects may then err more than the budget where that buys
//! most time, as long as the frame as a whole does not.
//!
//! **The frame's error.** The mean error over the `A` pixels the visible objects' screen
//! rectangles cover, each pixel once however many rectangles cover it. Each object's
//! predicted error `e` is a mean over its own rectangle, so it adds `w e` to the frame's
//! total, `w` its rectangle's area times the share of it that the last frame says shows
//! ([`super::occlusion`]: an object behind others adds nothing), and the frame's
//! error is `sum(w e) / A`. Where two objects' errors fall on one pixel they are added,
//! which errs high.
//!
//! **The bound.** An object's measured error scatters about its prediction `e`; take its
//! spread as `s * e` ([`super::Config::spread`]), independently per object. With weights
//! `w` the frame's error is about `sum(w e) / A` give or take
//! `s * sqrt(sum((w e)^2)) / A`, and the bound is the mean plus [`Z99`] of those: the
//! frame stays within it on 99% of frames. Where many objects share the error (a world of
//! thousands) the second term vanishes and the bound is the mean; where one image fills
//! the frame it is that image's error times `1 + 2.3 s`, so the budget then holds for the
//! frame as it would for that one object.
//!
//! **The multiplier.** Each object takes the option least in
//! `ms + lambda * (w e + kappa * (w e)^2)`, and `lambda` is the least (found by bisection)
//! whose choices keep the bound within the budget. `kappa` is the bound's slope in
//! `(w e)^2` against its slope in `w e` (`Z99 * s / (2 sqrt(sum((w e)^2)))`), taken at the
//! choices of a first bisection with `kappa = 0`: one large error then costs more than
//! many small ones adding up to it, as it does in the bound.

use crate::core::Priced;
use rayon::prelude::*;

/// The standard normal's 99th percentile: the bound holds on 99% of frames.
pub const Z99: f64 = 2.326;

/// One visible object's options this frame, as the multiplier weighs them.
#[derive(Clone, Copy)]
pub(super) struct Object<'e> {
    /// Per representation (`None`: cannot draw it).
    pub est: &'e [Option<Priced>],
    /// Its weight: its screen rectangle's area times the share of it that shows, pixels.
    pub weight: f32,
    /// The representation in use, whose time is discounted by the hysteresis.
    pub current: Option<usize>,
    /// The most frames a rebuild of it may be spread over, whatever its representation's
    /// payback ([`super::Config::horizon`]).
    pub horizon: f32,
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
    /// What the multiplier weighs ([`Price::score`]): `time` is `ms` less the hysteresis
    /// discount, plus the spread rebuild, and `weighted` is error times pixels.
    time: f64,
    weighted: f64,
}

/// What error costs in time: the multiplier and the weight of large errors (module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Price {
    pub lambda: f64,
    pub kappa: f64,
}

impl Price {
    pub(super) fn score(&self, p: &Pick) -> f64 {
        self.score_of(p.time, p.weighted)
    }

    fn score_of(&self, time: f64, weighted: f64) -> f64 {
        time + self.lambda * (weighted + self.kappa * weighted * weighted)
    }
}

/// How options are weighed besides the multiplier.
pub(super) struct Weights<'c> {
    /// The hysteresis discount on the representation in use, a fraction of its time.
    pub stick: f32,
    /// Frames a rebuild's time is spread over, per representation.
    pub payback: &'c [f32],
    /// An object's relative error spread ([`super::Config::spread`]).
    pub spread: f32,
}

/// Every visible object's options with a finite error, flattened once per frame so that
/// the bisection only does arithmetic: in parts of [`FILL_CHUNK`] objects, filled and
/// read side by side (object `k` in part `k / FILL_CHUNK`).
#[derive(Default)]
pub(super) struct Options {
    /// The parts in use, and their memory kept beyond them.
    parts: Vec<Part>,
    used: usize,
    /// The pixels the objects' rectangles cover.
    area: f64,
    /// `Z99` times the objects' relative spread.
    margin: f64,
}

/// The options of [`FILL_CHUNK`] objects (fewer in the last part).
#[derive(Default)]
struct Part {
    picks: Vec<Pick>,
    /// Each object's range of `picks`.
    ranges: Vec<(usize, usize)>,
    /// Each object's options no other beats in both time and weighted error (`[time,
    /// weighted]`, by time), and its range of them: the best at any price is one of these,
    /// so the bisection looks at these alone.
    front: Vec<[f64; 2]>,
    front_ranges: Vec<(usize, usize)>,
}

/// Objects per chunk of [`Options::fill`].
const FILL_CHUNK: usize = 1024;

impl Options {
    /// The options of `objects`, whose rectangles cover `area` pixels.
    #[cfg(test)]
    pub(super) fn new(objects: &[Object<'_>], area: f64, w: &Weights<'_>) -> Options {
        let mut out = Options::default();
        out.fill(objects.len(), |k| objects[k], area, w);
        out
    }

    /// The options of `n` objects, object `k` being `object(k)`, whose rectangles cover
    /// `area` pixels, in place of what it held (its memory reused). Side by side over
    /// chunks of objects, joined in order.
    pub(super) fn fill<'e>(
        &mut self,
        n: usize,
        object: impl Fn(usize) -> Object<'e> + Sync,
        area: f64,
        w: &Weights<'_>,
    ) {
        self.area = area.max(1.0);
        self.margin = Z99 * f64::from(w.spread.max(0.0));
        let chunks = n.div_ceil(FILL_CHUNK);
        if self.parts.len() < chunks {
            self.parts.resize_with(chunks, Part::default);
        }
        self.used = chunks;
        self.parts[..chunks]
            .par_iter_mut()
            .enumerate()
            .for_each(|(c, part)| {
                let objects = c * FILL_CHUNK..((c + 1) * FILL_CHUNK).min(n);
                part.fill(objects.map(&object), w);
            });
    }

    /// Object `k`'s options.
    fn of(&self, k: usize) -> &[Pick] {
        let part = &self.parts[k / FILL_CHUNK];
        let (a, b) = part.ranges[k % FILL_CHUNK];
        &part.picks[a..b]
    }
}

impl Part {
    /// The options of `objects` into this part, from its start.
    fn fill<'e>(&mut self, objects: impl Iterator<Item = Object<'e>>, w: &Weights<'_>) {
        self.picks.clear();
        self.ranges.clear();
        self.front.clear();
        self.front_ranges.clear();
        let out = self;
        for o in objects {
            let first = out.picks.len();
            let px = f64::from(o.weight);
            for (r, e) in o.est.iter().enumerate() {
                let Some(e) = e else { continue };
                let ms = e.ms;
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
                if e.rebuilds && e.rebuilt.is_finite() {
                    let frames = w.payback.get(r).copied().unwrap_or(1.0).min(o.horizon);
                    let spread = e.rebuild_ms / frames.max(1.0);
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
            // The front: by time (then weighted error), each less in error than all before.
            let start = out.front.len();
            let picks = &out.picks[first..];
            out.front.extend(picks.iter().map(|p| [p.time, p.weighted]));
            let mine = &mut out.front[start..];
            mine.sort_unstable_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
            let mut kept = start;
            let mut least = f64::INFINITY;
            for j in start..out.front.len() {
                let f = out.front[j];
                if f[1] < least {
                    least = f[1];
                    out.front[kept] = f;
                    kept += 1;
                }
            }
            out.front.truncate(kept);
            out.front_ranges.push((start, kept));
        }
    }
}

impl Options {
    /// Object `k`'s rebuild options (at most one per representation).
    pub(super) fn rebuilds(&self, k: usize) -> impl Iterator<Item = &Pick> {
        self.of(k).iter().filter(|p| p.rebuild)
    }

    /// Object `k`'s options at `price`: the best as it is, and the best of all (rebuilds
    /// included), least in [`Price::score`] (ties: the first).
    pub(super) fn pick(&self, k: usize, price: Price) -> (Option<Pick>, Option<Pick>) {
        let (mut as_is, mut best): (Option<Pick>, Option<Pick>) = (None, None);
        for p in self.of(k) {
            let score = price.score(p);
            if !p.rebuild && as_is.is_none_or(|q| score < price.score(&q)) {
                as_is = Some(*p);
            }
            if best.is_none_or(|q| score < price.score(&q)) {
                best = Some(*p);
            }
        }
        (as_is, best)
    }

    /// Of the objects' best options at `price`: the sum of weighted errors and of their
    /// squares. Summed side by side over the parts, their sums added in order (the same
    /// at any thread count).
    fn sums(&self, price: Price) -> (f64, f64) {
        let score = |f: &[f64; 2]| price.score_of(f[0], f[1]);
        let chunk = |part: &Part| {
            let (mut sum, mut squares) = (0.0, 0.0);
            for &(a, b) in &part.front_ranges {
                let best = part.front[a..b]
                    .iter()
                    .min_by(|p, q| score(p).total_cmp(&score(q)));
                if let Some(&[_, weighted]) = best {
                    sum += weighted;
                    squares += weighted * weighted;
                }
            }
            (sum, squares)
        };
        let parts = &self.parts[..self.used];
        let sums: Vec<(f64, f64)> = parts.par_iter().map(chunk).collect();
        sums.iter()
            .fold((0.0, 0.0), |(s, q), &(a, b)| (s + a, q + b))
    }

    /// The bound on the frame's mean error of the objects' best options at `price`
    /// (module docs).
    pub(super) fn bound(&self, price: Price) -> f64 {
        let (sum, squares) = self.sums(price);
        bound(sum, squares, self.area, self.margin)
    }

    /// The least multiplier at `kappa` whose choices keep the bound within `budget` (the
    /// largest tried, 1e9 ms per level-pixel, when none does), to 0.1%, bracketed from
    /// `start` (the last frame's: a few steps when the view changed little).
    fn lambda(&self, kappa: f64, budget: f64, start: f64) -> f64 {
        let over = |lambda| self.bound(Price { lambda, kappa }) > budget;
        if !over(0.0) {
            return 0.0;
        }
        let start = if start.is_finite() && start > 0.0 {
            start.clamp(1e-12, 1e9)
        } else {
            1e-6
        };
        // lo over (or 0), hi within.
        let (mut lo, mut hi) = (start, start);
        if over(start) {
            while over(hi) {
                lo = hi;
                hi *= 4.0;
                if hi > 1e9 {
                    return 1e9;
                }
            }
        } else {
            while !over(lo) {
                hi = lo;
                lo *= 0.25;
                if lo < 1e-12 {
                    lo = 0.0;
                    break;
                }
            }
        }
        for _ in 0..60 {
            if hi - lo <= hi * 1e-3 {
                break;
            }
            let mid = if lo > 0.0 { (lo * hi).sqrt() } else { hi * 0.5 };
            if over(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    }
}

/// The least price whose choices keep the bound on the frame's error within `budget`
/// (module docs); at the largest multiplier tried when none does (the frame is then as
/// accurate as its options allow). `warm` holds the last frame's two multipliers (without
/// and with `kappa`), each bisection's starting point, and is updated.
pub(super) fn price(options: &Options, budget: f32, warm: &mut [f64; 2]) -> Price {
    let budget = f64::from(budget.max(0.0));
    let first = Price {
        lambda: options.lambda(0.0, budget, warm[0]),
        kappa: 0.0,
    };
    if first.lambda > 0.0 {
        warm[0] = first.lambda;
    }
    if first.lambda == 0.0 || options.margin == 0.0 {
        return first;
    }
    // The spread's term matters only where few objects carry the error: when it adds
    // under 5% to the mean at the first choices, they stand.
    let (sum, squares) = options.sums(first);
    if squares <= 0.0 || options.margin * squares.sqrt() < 0.05 * sum {
        return first;
    }
    let kappa = options.margin / (2.0 * squares.sqrt());
    let second = Price {
        lambda: options.lambda(kappa, budget, warm[1]),
        kappa,
    };
    // The second bisection's choices are within the bound or as accurate as they can be;
    // keep the first's when the second found nothing within.
    if second.lambda >= 1e9 {
        first
    } else {
        if second.lambda > 0.0 {
            warm[1] = second.lambda;
        }
        second
    }
}

/// The bound on the frame's error from the sum of the objects' weighted errors and of their
/// squares, the pixels their rectangles cover, and `Z99` times the relative spread.
pub(super) fn bound(sum: f64, squares: f64, area: f64, margin: f64) -> f64 {
    (sum + margin * squares.sqrt()) / area.max(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::core::{CostModel, Estimate, Work};

    fn est(error: f32, triangles: u64) -> Option<Priced> {
        let e = Estimate {
            error,
            rebuilt: error,
            draw: Work {
                triangles,
                ..Work::default()
            },
            rebuild: Work::default(),
            memory: 0,
        };
        Some(Priced::new(&e, &CostModel::default()))
    }

    fn weights(spread: f32) -> Weights<'static> {
        Weights {
            stick: 0.0,
            payback: &[30.0, 30.0],
            spread,
        }
    }

    fn object(est: &[Option<Priced>], area: f32) -> Object<'_> {
        Object {
            est,
            weight: area,
            current: None,
            horizon: f32::INFINITY,
        }
    }

    /// Options of objects whose rectangles do not overlap.
    fn apart(objects: &[Object<'_>], w: &Weights<'_>) -> Options {
        Options::new(
            objects,
            objects.iter().map(|o| f64::from(o.weight)).sum(),
            w,
        )
    }

    #[test]
    fn the_bound_over_undominated_options_is_the_bound_over_all() {
        // Objects of eight options each, many dominated (slower and no more accurate than
        // another), some tied: at every price the bound from the fronts alone is the bound
        // from every option, its best option per object found by brute force.
        let w = weights(0.5);
        let ests: Vec<[Option<Priced>; 8]> = (0..50u64)
            .map(|k| {
                std::array::from_fn(|r| {
                    let r = r as u64;
                    let error = ((k * 7 + r * 13) % 11) as f32 * 0.5;
                    (r != 3 || k % 2 == 0)
                        .then(|| est(error, 100 + (k * 31 + r * 17) % 900).unwrap())
                })
            })
            .collect();
        let objects: Vec<Object<'_>> = ests
            .iter()
            .enumerate()
            .map(|(k, e)| object(e, 10.0 + k as f32 * 3.0))
            .collect();
        let options = apart(&objects, &w);
        let part = &options.parts[0];
        assert!(
            part.front.len() < part.picks.len() / 2,
            "{}",
            part.front.len()
        );
        for lambda in [0.0, 1e-6, 1e-4, 1e-2, 1.0] {
            for kappa in [0.0, 1e-3] {
                let price = Price { lambda, kappa };
                let (mut sum, mut squares) = (0.0, 0.0);
                for k in 0..objects.len() {
                    let best = options
                        .of(k)
                        .iter()
                        .map(|p| (price.score(p), p.weighted))
                        .min_by(|x, y| x.0.total_cmp(&y.0))
                        .unwrap();
                    (sum, squares) = (sum + best.1, squares + best.1 * best.1);
                }
                let want = bound(sum, squares, options.area, options.margin);
                let got = options.bound(price);
                assert!((got - want).abs() <= 1e-9 * want.max(1.0), "{got} {want}");
            }
        }
    }

    #[test]
    fn the_multiplier_spends_error_where_it_buys_most_time() {
        // Two objects, each geometry (exact, costly) or an image (cheap, erring), saving
        // the same time: the big one's image costs 1000 level-pixels, the small one's 80.
        // The mean alone (no spread).
        let w = weights(0.0);
        let big = [est(0.0, 10_000), est(1.0, 2)];
        let small = [est(0.0, 10_000), est(8.0, 2)];
        let objects = [object(&big, 1000.0), object(&small, 10.0)];
        let options = apart(&objects, &w);
        let pick = |p: Price| [0, 1].map(|k| options.pick(k, p).1.unwrap().rep);
        // Within 0.5 only one image fits, the small one's (80 / 1010): the big one, whose
        // image would cost more error for the same time, is drawn as geometry.
        let p = price(&options, 0.5, &mut [0.0; 2]);
        assert_eq!(pick(p), [0, 1]);
        assert!(options.bound(p) <= 0.5);
        // A generous budget takes both images; a zero one both geometries.
        assert_eq!(price(&options, 2.0, &mut [0.0; 2]), Price::default());
        assert_eq!(pick(Price::default()), [1, 1]);
        assert_eq!(pick(price(&options, 0.0, &mut [0.0; 2])), [0, 0]);
    }

    #[test]
    fn the_bound_is_the_mean_over_many_objects_and_one_objects_bound_alone() {
        // An image of error 1 in place of each object's geometry, half the spread.
        let w = weights(0.5);
        let options = [est(0.0, 10_000), est(1.0, 2)];
        let margin = Z99 * 0.5;
        // Alone, the image's error scatters as the frame's does: 1 + 1.16, over 1.5.
        let one = [object(&options, 1000.0)];
        let one = apart(&one, &w);
        let p = price(&one, 1.5, &mut [0.0; 2]);
        assert_eq!(one.pick(0, p).1.unwrap().rep, 0);
        assert!((one.bound(Price::default()) - (1.0 + margin)).abs() < 1e-9);
        assert_eq!(
            one.pick(0, price(&one, 2.2, &mut [0.0; 2])).1.unwrap().rep,
            1
        );
        // A hundred such images of a tenth the size: their errors average out, 1 + 0.116.
        let many: Vec<Object<'_>> = (0..100).map(|_| object(&options, 10.0)).collect();
        let many = apart(&many, &w);
        let p = price(&many, 1.5, &mut [0.0; 2]);
        assert_eq!(p, Price::default());
        assert!((many.bound(p) - (1.0 + margin / 10.0)).abs() < 1e-9);
        assert!((0..100).all(|k| many.pick(k, p).1.unwrap().rep == 1));
    }

    #[test]
    fn large_errors_weigh_more_than_many_small_ones() {
        // One large object and ten small ones of the same total pixels, whose images save
        // time in proportion to their pixels: the mean alone is indifferent between them.
        // The budget (1.1) fits either the large image (bound 1.08) or the ten small ones
        // (0.68), not both (1.61). The mean alone takes the large one, by a hair; the bound
        // takes the small ones, at the same time saved and a lower bound.
        let w = weights(0.5);
        let large = [est(0.0, 100_000), est(1.0, 2)];
        let small = [est(0.0, 10_000), est(1.0, 2)];
        let mut objects = vec![object(&large, 1000.0)];
        objects.extend((0..10).map(|_| object(&small, 100.0)));
        let all = apart(&objects, &w);
        let reps = |p: Price| {
            (0..11)
                .map(|k| all.pick(k, p).1.unwrap().rep)
                .collect::<Vec<_>>()
        };
        let linear = Price {
            lambda: all.lambda(0.0, 1.1, 0.0),
            kappa: 0.0,
        };
        assert_eq!(reps(linear), [&[1][..], &[0; 10]].concat());
        let p = price(&all, 1.1, &mut [0.0; 2]);
        assert_eq!(reps(p), [&[0][..], &[1; 10]].concat());
        assert!(all.bound(p) < all.bound(linear) && all.bound(linear) <= 1.1);
    }
}

//! The impostors' readout: what one frame's updates did ([`Readout`], the city's part
//! [`CityReport`]) and totals over a run of frames ([`RunStats`]), for the showcase's
//! on-screen lines and its headless statistics.

use super::{GEOMETRY, IMPOSTORS, LAYERS};
use ibr::impostor::Report;
use ibr::plan::Planner;
use ibr::subject::MeshGroup;

/// What one frame's city plan did (the planner's [`ibr::plan::Report`], as the readout needs it).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CityReport {
    /// Buildings drawn by each representation ([`super::CITY_REPRESENTATIONS`]).
    pub counts: [usize; 3],
    pub culled: usize,
    pub rebuilds: usize,
    /// Rebuilds wanted but left for a later frame.
    pub deferred: usize,
    pub switches: usize,
    /// Buildings drawn over the error budget.
    pub over_budget: usize,
    /// Largest predicted error, the mean over the buildings drawn as images, and the
    /// budget (levels).
    pub max_error: f32,
    pub mean_image_error: f32,
    pub budget: f32,
}

impl CityReport {
    /// The planner's last frame.
    pub fn of(city: &Planner<MeshGroup>) -> Self {
        let r = &city.report;
        let mut counts = [0; 3];
        for (c, &n) in counts.iter_mut().zip(&r.counts) {
            *c = n;
        }
        let images = city
            .choices()
            .iter()
            .filter(|c| c.rep.is_some_and(|k| k != GEOMETRY));
        let (sum, n) = images.fold((0.0, 0), |(s, n), c| (s + c.error, n + 1));
        CityReport {
            counts,
            culled: r.culled,
            rebuilds: r.rebuilds,
            deferred: r.deferred,
            switches: r.switches,
            over_budget: r.over_budget,
            max_error: r.max_error,
            mean_image_error: if n == 0 { 0.0 } else { sum / n as f32 },
            budget: city.config.budgets.error,
        }
    }

    /// Buildings drawn as images (impostors and layers).
    pub fn images(&self) -> usize {
        self.counts[IMPOSTORS] + self.counts[LAYERS]
    }

    /// Largest predicted error over the budget (1 is the budget).
    pub fn max_ratio(&self) -> f32 {
        self.max_error / self.budget.max(1e-6)
    }

    /// The on-screen line (upper case, for the bitmap font).
    pub fn line(&self) -> String {
        let [g, i, l] = self.counts;
        format!(
            "CITY geometry {g} impostors {i} layers {l} | rebuilds {} switches {} | err {:.2}/{:.1}",
            self.rebuilds, self.switches, self.max_error, self.budget
        )
        .to_uppercase()
    }
}

/// What one frame's updates did: the clouds' impostors and the city's plan. The totals add
/// the city's buildings to the clouds' counts: an image is a cloud's or a building's
/// (impostor or layer), a refresh a cloud's or a rebuild of either kind.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Readout {
    pub clouds: Report,
    pub city: CityReport,
}

impl Readout {
    pub fn refreshes(&self) -> usize {
        self.clouds.refreshes + self.city.rebuilds
    }
    pub fn images(&self) -> usize {
        self.clouds.images + self.city.images()
    }
    pub fn geometry(&self) -> usize {
        self.clouds.geometry + self.city.counts[GEOMETRY]
    }
    pub fn culled(&self) -> usize {
        self.clouds.culled + self.city.culled
    }
    /// Images wanted but not made this frame: invalid cloud impostors left stale, and the
    /// city's deferred rebuilds.
    pub fn stale(&self) -> usize {
        self.clouds.stale + self.city.deferred
    }
    /// Images drawn with a predicted error over their tolerance (the city's: objects over
    /// its error budget).
    pub fn over_tolerance(&self) -> usize {
        self.clouds.over_tolerance + self.city.over_budget
    }
    /// Clouds drawn as geometry because their image was too stale to show.
    pub fn stale_fallbacks(&self) -> usize {
        self.clouds.stale_fallbacks
    }
    /// Refreshes of clouds about to come into view.
    pub fn prewarmed(&self) -> usize {
        self.clouds.prewarmed
    }
    /// Largest predicted error ratio over the drawn images (1 is the tolerance; the
    /// city's error over its budget).
    pub fn max_ratio(&self) -> f32 {
        self.clouds.max_ratio.max(self.city.max_ratio())
    }
    /// Mean predicted error ratio over the drawn images.
    pub fn mean_ratio(&self) -> f32 {
        let (a, b) = (&self.clouds, &self.city);
        let n = a.images + b.images();
        let city = b.mean_image_error / b.budget.max(1e-6);
        if n == 0 {
            0.0
        } else {
            (a.mean_ratio * a.images as f32 + city * b.images() as f32) / n as f32
        }
    }

    /// The clouds' on-screen line (upper case, for the bitmap font); the city's is
    /// [`CityReport::line`].
    pub fn line(&self) -> String {
        let c = &self.clouds;
        format!(
            "CLOUDS {}  IMG {}  GEO {}  REFRESH {}  STALE {}  ERR MAX {:.2} MEAN {:.2}",
            c.images + c.geometry,
            c.images,
            c.geometry,
            c.refreshes,
            c.stale,
            c.max_ratio,
            c.mean_ratio
        )
        .to_uppercase()
    }
}

/// Frames whose per-frame figures [`RunStats::per_frame`] keeps (the first ones).
pub const HISTORY: usize = 1 << 14;

/// Statistics over a run of frames: the clouds' and the city's together (as [`Readout`]'s
/// totals), then the city's plan.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunStats {
    pub frames: usize,
    /// The city's rebuilds, switches, and building-frames drawn by each representation
    /// ([`super::CITY_REPRESENTATIONS`]) and over the error budget; its largest predicted error
    /// (levels).
    pub city_rebuilds: usize,
    pub city_switches: usize,
    pub city_frames: [usize; 3],
    pub city_over_budget: usize,
    pub city_max_error: f32,
    pub refreshes: usize,
    /// Most refreshes in one frame.
    pub peak_refreshes: usize,
    /// Invalid impostors left stale, summed over the frames.
    pub stale: usize,
    /// Largest predicted error ratio of a drawn image over the run.
    pub max_ratio: f32,
    /// Frames that showed an image over its tolerance, and over twice it.
    pub frames_over: usize,
    pub frames_over_twice: usize,
    /// Stale cloud images replaced by geometry, summed over the frames; pre-warming
    /// refreshes.
    pub stale_fallbacks: usize,
    pub prewarmed: usize,
    /// Per frame (the first [`HISTORY`]): the largest predicted error ratio shown, and the
    /// refreshes.
    pub per_frame: Vec<(f32, usize)>,
    /// Sum over the frames of the mean predicted ratio, and the frames with images.
    ratio_sum: f64,
    ratio_frames: usize,
}

impl RunStats {
    pub(super) fn add(&mut self, r: &Readout) {
        self.frames += 1;
        let city = &r.city;
        self.city_rebuilds += city.rebuilds;
        self.city_switches += city.switches;
        for (t, n) in self.city_frames.iter_mut().zip(city.counts) {
            *t += n;
        }
        self.city_over_budget += city.over_budget;
        self.city_max_error = self.city_max_error.max(city.max_error);
        self.refreshes += r.refreshes();
        self.peak_refreshes = self.peak_refreshes.max(r.refreshes());
        self.stale += r.stale();
        self.max_ratio = self.max_ratio.max(r.max_ratio());
        self.frames_over += (r.max_ratio() > 1.0) as usize;
        self.frames_over_twice += (r.max_ratio() > 2.0) as usize;
        self.stale_fallbacks += r.stale_fallbacks();
        self.prewarmed += r.prewarmed();
        if self.per_frame.len() < HISTORY {
            // Reserved once, so recording never reallocates mid-run.
            self.per_frame.reserve_exact(HISTORY - self.per_frame.len());
            self.per_frame.push((r.max_ratio(), r.refreshes()));
        }
        if r.images() > 0 {
            self.ratio_sum += r.mean_ratio() as f64;
            self.ratio_frames += 1;
        }
    }

    pub fn mean_refreshes(&self) -> f64 {
        self.refreshes as f64 / self.frames.max(1) as f64
    }

    /// The mean over the frames (with images) of the mean predicted error ratio.
    pub fn mean_ratio(&self) -> f64 {
        self.ratio_sum / self.ratio_frames.max(1) as f64
    }
}

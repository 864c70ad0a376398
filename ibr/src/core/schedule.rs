//! The refresh scheduler every image cache shares (runtime impostors, image layers): which
//! stale images a frame re-renders within its budget. Candidates are ranked visible first,
//! then largest error first, ties by index (so the schedule is deterministic); the budget is
//! a count, and optionally a time that the measured cost of recent refreshes is fitted to.

use crate::core::recycle;
use crate::core::Capturer;
use crate::core::Subject;
use engine::{Camera, Draw, Encoding, FrameStats, Lighting, Rgba, Target, Texture};
use rayon::prelude::*;
use std::time::Duration;

/// How much re-rendering a frame may do.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    /// Most images re-rendered per frame.
    pub refreshes: usize,
    /// Time the frame's refreshes may take: at most as many refreshes as the measured cost
    /// of recent ones fits in, and at least one (interactive use; makes the refresh schedule
    /// depend on the machine, so tests and benchmarks leave it `None`).
    pub time: Option<Duration>,
}

impl Budget {
    /// At most `refreshes` per frame, no time limit.
    pub fn count(refreshes: usize) -> Budget {
        Budget {
            refreshes,
            time: None,
        }
    }
}

/// One image that wants re-rendering this frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    /// In view now (else only near it: refreshed ahead of coming into view, after every
    /// visible one).
    pub visible: bool,
    /// Larger first: the predicted error over the tolerance, or `f32::MAX` for must-do.
    pub priority: f32,
    /// Which image, in its owner's numbering.
    pub index: usize,
}

/// A frame's candidates, ranked, and the running cost of a refresh.
#[derive(Clone, Debug)]
pub struct Scheduler {
    candidates: Vec<Candidate>,
    /// Measured milliseconds per refresh, a running mean (for a time budget).
    refresh_ms: f32,
}

impl Default for Scheduler {
    fn default() -> Self {
        Scheduler {
            candidates: Vec::new(),
            refresh_ms: 1.0,
        }
    }
}

impl Scheduler {
    /// Starts a frame: no candidates.
    pub fn clear(&mut self) {
        self.candidates.clear();
    }

    /// Adds a candidate for this frame: image `index` of the owner, in view or not, with
    /// `priority` (larger first; see [`Candidate`]).
    pub fn push(&mut self, visible: bool, priority: f32, index: usize) {
        self.candidates.push(Candidate {
            visible,
            priority,
            index,
        });
    }

    /// Puts the frame's candidates in refresh order ([`Scheduler::ranked`]) and returns how
    /// many refreshes `budget` allows. The caller takes them in order until it has started
    /// that many (a candidate it cannot refresh, say for want of a texture, does not use up
    /// the budget).
    pub fn rank(&mut self, budget: &Budget) -> usize {
        self.candidates.sort_by(|a, b| {
            b.visible
                .cmp(&a.visible)
                .then(b.priority.total_cmp(&a.priority))
                .then(a.index.cmp(&b.index))
        });
        let mut allowed = budget.refreshes;
        if let Some(t) = budget.time {
            let fits = (t.as_secs_f32() * 1e3 / self.refresh_ms.max(1e-3)).floor() as usize;
            allowed = allowed.min(fits.max(1));
        }
        allowed
    }

    /// The candidates, in refresh order after [`Scheduler::rank`].
    pub fn ranked(&self) -> &[Candidate] {
        &self.candidates
    }

    /// Records that `refreshes` re-renders took `elapsed` together.
    pub fn measured(&mut self, refreshes: usize, elapsed: Duration) {
        if refreshes > 0 {
            let ms = elapsed.as_secs_f32() * 1e3 / refreshes as f32;
            self.refresh_ms = 0.8 * self.refresh_ms + 0.2 * ms;
        }
    }

    /// The running mean cost of one refresh, milliseconds.
    pub fn refresh_ms(&self) -> f32 {
        self.refresh_ms
    }
}

/// The items at `indices` (ascending), mutably and in that order, to hand a frame's
/// refreshes their subjects side by side; indices out of order or out of range are skipped.
pub fn pick_mut<T>(items: &mut [T], indices: impl IntoIterator<Item = usize>) -> Vec<&mut T> {
    let mut wanted = indices.into_iter().peekable();
    let mut out = Vec::with_capacity(wanted.size_hint().0);
    for (i, item) in items.iter_mut().enumerate() {
        while wanted.peek().is_some_and(|&w| w < i) {
            wanted.next();
        }
        if wanted.peek() == Some(&i) {
            wanted.next();
            out.push(item);
        }
    }
    out
}

/// Runs a frame's refreshes side by side on the thread pool: `jobs` (each refreshing a
/// distinct subject, `subject_of`) each get their subject and a worker of their own
/// (`workers` grows to fit), so every job writes only its own worker's memory and the
/// results do not depend on the thread count. Jobs whose subject is out of range are
/// dropped. The jobs are left ordered largest subject first (by triangles, then subject),
/// so worker `k` always takes the frame's `k`-th largest capture: a worker's buffers grow
/// to the largest capture it is handed, and with the largest always going to the same
/// workers, fewer of them grow into fresh memory (page faults and zeroing were a third of
/// a large world's capture time while every worker in turn met its largest).
pub fn refresh_side_by_side<J, S, W>(
    jobs: &mut Vec<J>,
    subject_of: impl Fn(&J) -> usize,
    subjects: &mut [S],
    workers: &mut Vec<W>,
    refresh: impl Fn(&J, &mut S, &mut W) + Sync,
) where
    J: Sync,
    S: Subject + Send,
    W: Send + Default,
{
    jobs.sort_by_key(&subject_of);
    let chosen = pick_mut(subjects, jobs.iter().map(&subject_of));
    // The jobs past the picked subjects (out of range, so sorted last) are dropped here.
    let mut pairs: Vec<(J, &mut S)> = jobs.drain(..).zip(chosen).collect();
    // A stable sort: equal sizes keep the subjects' order.
    pairs.sort_by_cached_key(|(_, s)| std::cmp::Reverse(s.triangle_count()));
    let mut chosen = Vec::with_capacity(pairs.len());
    for (job, subject) in pairs {
        jobs.push(job);
        chosen.push(subject);
    }
    if workers.len() < jobs.len() {
        workers.resize_with(jobs.len(), W::default);
    }
    jobs.par_iter()
        .zip(chosen.par_iter_mut())
        .zip(workers.par_iter_mut())
        .with_max_len(1)
        .for_each(|((job, subject), w)| refresh(job, subject, w));
}

/// What one refresh renders with: a capturer, a draw list, and the texture its image is
/// copied into (traded for the image's own afterwards), all reused frame to frame.
#[derive(Debug, Default)]
pub struct Refresher {
    capturer: Capturer,
    draws: Vec<Draw<'static>>,
    /// The last image, as a texture (with mipmaps).
    pub texture: Option<Texture>,
}

impl Refresher {
    /// Renders `subject` (prepared for `camera` first) into a `width` x `height` image and
    /// copies it into [`Refresher::texture`]; the renderer's counters.
    pub fn render<S: Subject>(
        &mut self,
        subject: &mut S,
        camera: &Camera,
        lighting: &Lighting,
        size: (u32, u32),
    ) -> FrameStats {
        let stats = self.capture(subject, camera, lighting, size);
        self.keep();
        stats
    }

    /// Copies the last image ([`Refresher::target`]) into [`Refresher::texture`], with
    /// its mip chain.
    pub fn keep(&mut self) {
        let texture = self
            .texture
            .get_or_insert_with(|| Texture::solid(Rgba::TRANSPARENT));
        self.capturer.target().copy_to_texture(texture);
    }

    /// As [`Refresher::render`] without the copy: the image stays in
    /// [`Refresher::target`], for a caller that fills [`Refresher::texture`] itself (each
    /// copy rebuilds the texture's mip chain).
    pub fn capture<S: Subject>(
        &mut self,
        subject: &mut S,
        camera: &Camera,
        lighting: &Lighting,
        (width, height): (u32, u32),
    ) -> FrameStats {
        subject.prepare(camera, height);
        let mut draws = recycle(std::mem::take(&mut self.draws));
        subject.draws(&mut draws);
        let (drawn, enc) = (draws.iter().copied(), Encoding::Srgb);
        self.capturer
            .render(drawn, camera, lighting, width, height, enc);
        self.draws = recycle(draws);
        self.capturer.last_stats()
    }

    /// The last image as rendered.
    pub fn target(&self) -> &Target {
        self.capturer.target()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn visible_first_then_largest_error_then_index() {
        let mut s = Scheduler::default();
        s.push(false, 9.0, 0);
        s.push(true, 1.5, 3);
        s.push(true, f32::MAX, 7);
        s.push(true, 1.5, 1);
        let allowed = s.rank(&Budget::count(2));
        let idx: Vec<usize> = s.ranked().iter().map(|c| c.index).collect();
        assert_eq!(idx, [7, 1, 3, 0]);
        assert_eq!(allowed, 2);
    }

    #[test]
    fn a_time_budget_fits_the_measured_cost_and_allows_at_least_one() {
        let mut s = Scheduler::default();
        for _ in 0..40 {
            s.measured(2, Duration::from_millis(8));
        }
        assert!((s.refresh_ms() - 4.0).abs() < 0.01, "{}", s.refresh_ms());
        let budget = Budget {
            refreshes: 100,
            time: Some(Duration::from_millis(10)),
        };
        assert_eq!(s.rank(&budget), 2);
        let tight = Budget {
            time: Some(Duration::from_micros(1)),
            ..budget
        };
        assert_eq!(s.rank(&tight), 1);
        s.measured(0, Duration::from_secs(1));
        assert!((s.refresh_ms() - 4.0).abs() < 0.01, "no refresh, no change");
    }

    /// Each job meets its own subject and worker; the jobs come back largest subject
    /// first (ties by subject), worker `k` having run job `k`; a job whose subject is out
    /// of range is dropped.
    #[test]
    fn refreshes_meet_their_subjects_largest_first() {
        use crate::core::subject::MeshGroup;
        use engine::procedural::torus;
        use engine::Material;
        use glam::Mat4;
        use std::sync::Arc;
        let group = |u: u32| {
            MeshGroup::new().with(
                Arc::new(torus(1.0, 0.3, u, 4)),
                Arc::new(Material::default()),
                Mat4::IDENTITY,
            )
        };
        let mut subjects = vec![group(3), group(8), group(5), group(8)];
        let triangles: Vec<usize> = subjects.iter().map(Subject::triangle_count).collect();
        let mut jobs = vec![2usize, 0, 9, 3, 1];
        let mut workers: Vec<Vec<(usize, usize)>> = Vec::new();
        refresh_side_by_side(
            &mut jobs,
            |&j| j,
            &mut subjects,
            &mut workers,
            |&j, s, w| w.push((j, s.triangle_count())),
        );
        assert_eq!(jobs, [1, 3, 2, 0], "{triangles:?}");
        assert_eq!(workers.len(), 4);
        for (k, &j) in jobs.iter().enumerate() {
            assert_eq!(workers[k], [(j, triangles[j])], "worker {k}");
        }
    }

    #[test]
    fn picks_the_wanted_items_in_order() {
        let mut v = [10, 11, 12, 13, 14];
        let picked: Vec<i32> = pick_mut(&mut v, [1, 3, 9])
            .into_iter()
            .map(|x| *x)
            .collect();
        assert_eq!(picked, [11, 13]);
    }
}

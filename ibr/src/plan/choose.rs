//! Steps 2 to 5 of a frame: each object's choice as things are, the frame budget's weights,
//! rebuilds within the rebuild budget, the time budget, and the frame finished (see the
//! planner's module docs).

use super::*;

impl<S: Subject + Send + Sync> Planner<S> {
    /// Step 2: each visible object's cheapest representation within the budget as things
    /// are, with hysteresis; rebuild candidates for step 3.
    pub(super) fn choose_as_is(&mut self, previous: &[Option<usize>]) {
        let cfg = self.config;
        let budget = cfg.budgets.error.max(0.0);
        let nr = self.reps.len();
        self.rebuilds.clear();
        if cfg.budgets.scope == Scope::Frame {
            self.choose_for_frame(previous);
            return;
        }
        let mut rebuilds = std::mem::take(&mut self.rebuilds);
        for (v, &i) in self.visible.iter().enumerate() {
            let est = estimates(&self.seen, &self.at, nr, v);
            let current = previous[i];
            let ms = |e: &Priced| e.ms;
            let limit = |r: usize| {
                if Some(r) == current {
                    budget
                } else {
                    budget * cfg.hysteresis
                }
            };
            // Cheapest within its limit (ties: earlier representation).
            let mut best: Option<(usize, f32)> = None;
            for (r, e) in est.iter().enumerate() {
                let Some(e) = e else { continue };
                let fits = e.error.is_finite() && e.error <= limit(r);
                if fits && best.is_none_or(|(_, b)| ms(e) < b) {
                    best = Some((r, ms(e)));
                }
            }
            // Keep the one in use unless the other saves enough.
            if let (Some((b, b_ms)), Some(c)) = (best, current) {
                if let Some(Some(e)) = est.get(c) {
                    if b != c && e.error <= budget && b_ms > ms(e) * (1.0 - cfg.min_saving) {
                        best = Some((c, ms(e)));
                    }
                }
            }
            let within = best.is_some();
            // None within: the least error (ties: cheaper).
            let best = best.or_else(|| {
                let mut least: Option<(usize, f32, f32)> = None;
                for (r, e) in est.iter().enumerate() {
                    let Some(e) = e else { continue };
                    let better = least
                        .is_none_or(|(_, err, m)| e.error < err || (e.error == err && ms(e) < m));
                    if better {
                        least = Some((r, e.error, ms(e)));
                    }
                }
                least.map(|(r, _, m)| (r, m))
            });
            let Some((r0, ms0)) = best else {
                self.choices[i] = Choice {
                    over: Some(Over::Nothing),
                    error: f32::INFINITY,
                    ..Choice::default()
                };
                continue;
            };
            let err0 = est[r0].map_or(f32::INFINITY, |e| e.error);
            self.choices[i] = Choice {
                rep: Some(r0),
                error: err0,
                ms: ms0,
                rebuilt: false,
                over: (!within).then_some(Over::Nothing),
            };
            self.rebuild_candidates(v, i, r0, err0, ms0, budget, current, &mut rebuilds);
        }
        self.rebuilds = rebuilds;
    }

    /// Step 2 with the budget over the frame ([`Scope::Frame`]): each object's option at
    /// the frame's multiplier, and the rebuilds worth more than they cost at it (by the
    /// time and weighted error they save, net of the rebuild spread over
    /// [`Config::payback_frames`]).
    pub(super) fn choose_for_frame(&mut self, previous: &[Option<usize>]) {
        let cfg = self.config;
        let nr = self.reps.len();
        let (seen, at, visible) = (&self.seen, &self.at, &self.visible);
        let (weights, horizons) = (&self.weights, &self.horizons);
        let object = |v: usize| frame_budget::Object {
            est: estimates(seen, at, nr, v),
            weight: weights[v],
            current: previous[visible[v]],
            horizon: horizons[v],
        };
        let w = frame_budget::Weights {
            stick: cfg.min_saving,
            payback: &self.payback,
            spread: cfg.spread,
        };
        let mut options = std::mem::take(&mut self.options);
        options.fill(self.visible.len(), object, self.area, &w);
        let price = frame_budget::price(&options, cfg.budgets.error, &mut self.warm);
        let mut rebuilds = std::mem::take(&mut self.rebuilds);
        // Each object's best as it is, side by side (each alone: the same at any count).
        let mut picks = std::mem::take(&mut self.picks);
        (0..self.visible.len())
            .into_par_iter()
            .map(|k| options.pick(k, price).0)
            .collect_into_vec(&mut picks);
        for (k, &i) in self.visible.iter().enumerate() {
            let as_is = picks[k];
            // Drawn as it is unless a rebuild happens (the rebuild budget decides): every
            // rebuild that scores better is a candidate, the best taken first.
            for b in options.rebuilds(k) {
                let value = as_is.map_or(f64::MAX, |n| price.score(&n) - price.score(b));
                if value > 0.0 {
                    rebuilds.push(Rebuild {
                        tier: if as_is.is_none() { 0 } else { 2 },
                        key: value.min(f64::from(f32::MAX)) as f32,
                        object: i,
                        rep: b.rep,
                    });
                }
            }
            self.choices[i] = match as_is {
                Some(p) => Choice {
                    rep: Some(p.rep),
                    error: p.error,
                    ms: p.ms,
                    rebuilt: false,
                    over: None,
                },
                None => Choice {
                    over: Some(Over::Nothing),
                    error: f32::INFINITY,
                    ..Choice::default()
                },
            };
        }
        self.options = options;
        self.rebuilds = rebuilds;
        self.picks = picks;
    }

    /// The rebuilds of visible object `v` (object `i`), now drawn by `r0` with `err0` in
    /// `ms0`, one per representation that qualifies, appended to `out`: see the tiers in
    /// the module docs. Step 3 takes at most one per object, the best that fits.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn rebuild_candidates(
        &self,
        v: usize,
        i: usize,
        r0: usize,
        err0: f32,
        ms0: f32,
        budget: f32,
        current: Option<usize>,
        out: &mut Vec<Rebuild>,
    ) {
        let cfg = self.config;
        let nr = self.reps.len();
        let est = estimates(&self.seen, &self.at, nr, v);
        let pixels = self.pixels_of(v);
        let horizon = self.horizons[v];
        for (r, e) in est.iter().enumerate() {
            let Some(e) = e else { continue };
            let within = e.rebuilt <= budget * cfg.hysteresis;
            if !e.rebuilds || !within {
                continue;
            }
            let (ms, rb) = (e.ms, e.rebuild_ms);
            let frames = self.payback[r].min(horizon);
            let cand = if err0 > budget {
                Some((0, (err0 - e.rebuilt).min(1e6) * pixels - ms))
            } else if r == r0 && Some(r) == current && e.error > budget * cfg.hysteresis {
                Some((1, e.error / budget.max(1e-6)))
            } else if ms < ms0 * (1.0 - cfg.min_saving) && (ms0 - ms) * frames >= rb {
                Some((2, ms0 - ms - rb / frames.max(1.0)))
            } else {
                None
            };
            if let Some((tier, key)) = cand {
                out.push(Rebuild {
                    tier,
                    key,
                    object: i,
                    rep: r,
                });
            }
        }
    }

    /// The screen pixels of visible object `v` ([`Sight::pixels`], at least 1).
    pub(super) fn pixels_of(&self, v: usize) -> f32 {
        self.pixels[v].max(1.0)
    }

    /// Each visible object's weight in the frame's error (its rectangle's pixels times the
    /// share of it that showed in the last frame: [`occlusion`]), and the pixels the rectangles cover on a `width` x `height` target
    /// (each once, at least 1): see [`frame_budget`].
    pub(super) fn weigh(&mut self, camera: &Camera, width: u32, height: u32) {
        let hidden = self
            .occlusion
            .get_mut()
            .unwrap_or_else(PoisonError::into_inner);
        let (then, visible, rects) = (&self.then, &self.visible, &self.rects);
        hidden.weigh(
            visible.len(),
            |k| then.get(visible[k]).copied().flatten(),
            |k| rects[k].width as f32 * rects[k].height as f32,
            camera,
            (width, height),
            &mut self.weights,
        );
        // This frame's bounds, for the next frame's lookups (none for what is not drawn).
        self.then.clear();
        self.then.resize(self.objects.len(), None);
        for seen in &self.seen[..self.objects.len().div_ceil(CHUNK)] {
            for &(i, _, _, bounds, _) in &seen.objects {
                self.then[i] = Some(bounds);
            }
        }
        let covered = self.cover.area(width, height, self.rects.iter().copied());
        self.covered = covered;
        self.area = (covered as f64).max(1.0);
    }

    /// Takes what the finished frame `target`, seen from `camera`, hides for the next
    /// frame's weights ([`occlusion`]).
    pub fn observe_frame(&self, target: &Target, camera: &Camera) {
        let mut hidden = self
            .occlusion
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        hidden.observe(target, camera);
    }

    /// Step 3: the ranked rebuilds within the budget, each representation's in one call.
    pub(super) fn rebuild(&mut self, view: &FrameView<'_>) {
        let cfg = self.config;
        let nr = self.reps.len();
        if cfg.budgets.rebuild_ms.is_some() {
            // Under a time budget, what a rebuild is worth per millisecond it takes: one
            // long bake must not take the place of many short rebuilds worth more in all.
            for c in &mut self.rebuilds {
                let Ok(v) = self.visible.binary_search(&c.object) else {
                    continue;
                };
                if let Some(e) = estimates(&self.seen, &self.at, nr, v)[c.rep] {
                    c.key /= e.rebuild_ms.max(1e-3);
                }
            }
        }
        self.rebuilds.sort_by(|a, b| {
            a.tier
                .cmp(&b.tier)
                .then(b.key.total_cmp(&a.key))
                .then(a.object.cmp(&b.object))
        });
        let slot = |planner: &Self, i: usize| planner.visible.binary_search(&i).ok();
        let mut taken = 0;
        let mut spent = 0.0;
        // Bytes held now, and what the rebuilds taken will hold (counted in full: an image
        // replaced is freed only after).
        let mut held: usize = match cfg.budgets.memory {
            Some(_) => self.held.iter().sum(),
            None => 0,
        };
        // Per object: 1 once a rebuild is taken, 2 while one is deferred.
        self.state.clear();
        self.state.resize(self.objects.len(), 0);
        let mut chosen = Vec::new();
        for c in &self.rebuilds {
            if self.state[c.object] == 1 {
                continue;
            }
            let Some(v) = slot(self, c.object) else {
                continue;
            };
            let Some(e) = estimates(&self.seen, &self.at, nr, v)[c.rep] else {
                continue;
            };
            let ms = e.rebuild_ms;
            let over_ms = cfg
                .budgets
                .rebuild_ms
                .is_some_and(|t| taken > 0 && spent + ms > t);
            let over_memory = cfg.budgets.memory.is_some_and(|m| held + e.memory > m);
            if taken >= cfg.budgets.rebuilds || over_ms || over_memory {
                self.state[c.object] = 2;
                if c.tier == 0 {
                    self.choices[c.object].over = Some(Over::Rebuilds);
                }
                continue;
            }
            self.state[c.object] = 1;
            taken += 1;
            spent += ms;
            held += e.memory;
            chosen.push((c.rep, c.object, e));
        }
        self.report.deferred = self.state.iter().filter(|&&s| s == 2).count();
        self.report.rebuild_ms = spent;
        self.report.rebuilds = taken;
        for r in 0..nr {
            self.batch.clear();
            self.batch
                .extend(chosen.iter().filter(|c| c.0 == r).map(|c| c.1));
            if self.batch.is_empty() {
                continue;
            }
            self.batch.sort_unstable();
            self.reps[r].rebuild(&self.batch, &mut self.objects, view);
            self.held[r] = self.reps[r].memory();
        }
        for (r, i, e) in chosen {
            self.idle[i * nr + r] = 0;
            self.choices[i] = Choice {
                rep: Some(r),
                error: e.rebuilt,
                ms: e.ms,
                rebuilt: true,
                over: None,
            };
        }
    }

    /// Step 4: cheaper representations, least added error per millisecond saved first,
    /// until the predicted frame fits the time budget.
    pub(super) fn fit_time(&mut self) {
        let cfg = self.config;
        let nr = self.reps.len();
        let draw: f32 = self.choices.iter().map(|c| c.ms).sum();
        let mut total = draw + self.report.rebuild_ms;
        let Some(limit) = cfg.budgets.time_ms else {
            return;
        };
        if total <= limit {
            return;
        }
        // (added error x pixels per ms saved, object, representation, saving)
        let mut moves: Vec<(f32, usize, usize, f32)> = Vec::new();
        for (v, &i) in self.visible.iter().enumerate() {
            let c = self.choices[i];
            let Some(r0) = c.rep else { continue };
            let pixels = self.pixels_of(v);
            let mut best: Option<(f32, usize, f32)> = None;
            for r in 0..nr {
                let Some(e) = estimates(&self.seen, &self.at, nr, v)[r] else {
                    continue;
                };
                // A representation rebuilt this frame is drawn at its rebuilt error.
                let err = if r == r0 { c.error } else { e.error };
                let ms = e.ms;
                if r == r0 || ms >= c.ms || !err.is_finite() {
                    continue;
                }
                let ratio = (err - c.error).max(0.0) * pixels / (c.ms - ms);
                if best.is_none_or(|b| ratio < b.0) {
                    best = Some((ratio, r, c.ms - ms));
                }
            }
            if let Some((ratio, r, saving)) = best {
                moves.push((ratio, i, r, saving));
            }
        }
        moves.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        for (_, i, r, saving) in moves {
            if total <= limit {
                break;
            }
            let v = self.visible.binary_search(&i).unwrap_or(0);
            let Some(e) = estimates(&self.seen, &self.at, nr, v)[r] else {
                continue;
            };
            let over = e.error > cfg.budgets.error;
            self.choices[i] = Choice {
                rep: Some(r),
                error: e.error,
                ms: e.ms,
                rebuilt: false,
                over: over.then_some(Over::Time),
            };
            total -= saving;
        }
    }

    /// The report, idle counts and releases, and prepares objects and representations for
    /// their draws.
    pub(super) fn finish(&mut self, view: &FrameView<'_>, previous: &[Option<usize>]) {
        let cfg = self.config;
        let nr = self.reps.len();
        let budget = cfg.budgets.error.max(0.0);
        let r = &mut self.report;
        r.counts.clear();
        r.counts.resize(nr, 0);
        (r.culled, r.switches, r.over_budget) = (0, 0, 0);
        (r.over_time, r.over_rebuilds, r.over_nothing) = (0, 0, 0);
        (r.draw_ms, r.max_error) = (0.0, 0.0);
        // The frame's mean and bound over what is drawn (what nothing draws is reported
        // apart); over the frame, objects are over only when the bound is.
        let (mut sum, mut squares) = (0.0f64, 0.0f64);
        for (v, &i) in self.visible.iter().enumerate() {
            let c = &self.choices[i];
            if c.rep.is_some() {
                let e = f64::from(c.error) * f64::from(self.weights[v]);
                (sum, squares) = (sum + e, squares + e * e);
            }
        }
        let margin = Z99 * f64::from(cfg.spread.max(0.0));
        let r = &mut self.report;
        r.mean_error = frame_budget::bound(sum, squares, self.area, 0.0) as f32;
        r.scatter = frame_budget::bound(0.0, squares, self.area, 1.0) as f32;
        r.bound = frame_budget::bound(sum, squares, self.area, margin) as f32;
        r.covered = self.covered;
        let frame_over = cfg.budgets.scope == Scope::Frame
            && !self.visible.is_empty()
            && (r.bound > budget || r.bound.is_nan());
        let allowed = match cfg.budgets.scope {
            Scope::Object => budget,
            Scope::Frame if frame_over => budget,
            Scope::Frame => f32::INFINITY,
        };
        for &i in &self.visible {
            let c = &mut self.choices[i];
            if c.error <= allowed && c.rep.is_some() {
                c.over = None;
            } else if c.over.is_none() {
                c.over = Some(Over::Nothing);
            }
            let Some(rep) = c.rep else {
                r.over_budget += 1;
                r.over_nothing += 1;
                continue;
            };
            r.counts[rep] += 1;
            self.idle[i * nr + rep] = 0;
            r.switches += usize::from(previous[i].is_some_and(|p| p != rep));
            r.draw_ms += c.ms;
            r.max_error = r.max_error.max(c.error);
            match c.over {
                Some(Over::Time) => r.over_time += 1,
                Some(Over::Rebuilds) => r.over_rebuilds += 1,
                Some(Over::Nothing) => r.over_nothing += 1,
                None => {}
            }
            r.over_budget += usize::from(c.over.is_some());
            if self.reps[rep].draws_subject() {
                self.objects[i].prepare(view.camera, view.height);
            }
        }
        r.culled = self.objects.len() - self.visible.len();
        for i in 0..self.objects.len() {
            for k in 0..nr {
                if self.idle[i * nr + k] == cfg.release_after.saturating_add(1) {
                    self.reps[k].release(i);
                    self.touched[k] = true;
                }
            }
        }
        for (k, rep) in self.reps.iter_mut().enumerate() {
            self.batch.clear();
            let drawn = self.choices.iter().enumerate();
            self.batch
                .extend(drawn.filter(|(_, c)| c.rep == Some(k)).map(|(i, _)| i));
            rep.prepare(&self.batch, &self.objects, view);
        }
        for (k, rep) in self.reps.iter().enumerate() {
            if std::mem::take(&mut self.touched[k]) {
                self.held[k] = rep.memory();
            }
        }
        self.report.memory = self.held.iter().sum();
    }
}

//! Image layers as a technique of the frame loop: a set and the subjects it stands in for.

use super::{Config, LayerSet, Report};
use crate::core::Subject;
use crate::core::{Counters, FrameView, Technique};
use engine::Draw;

/// Subjects drawn as [`LayerSet`] image layers (one each), as one [`Technique`].
#[derive(Debug)]
pub struct Layered<S> {
    /// The image layers, one per subject.
    pub set: LayerSet,
    /// The subjects, in the layers' order.
    pub subjects: Vec<S>,
    /// What the last `prepare` did.
    pub report: Report,
    name: String,
}

impl<S: Subject> Layered<S> {
    /// `subjects` as layers configured by `config`, named `name` in readouts.
    pub fn new(name: impl Into<String>, config: Config, subjects: Vec<S>) -> Self {
        Layered {
            set: LayerSet::new(config, subjects.len()),
            subjects,
            report: Report::default(),
            name: name.into(),
        }
    }
}

impl<S: Subject + Send> Technique for Layered<S> {
    fn name(&self) -> &str {
        &self.name
    }
    fn prepare(&mut self, view: &FrameView<'_>) {
        let size = (view.width, view.height);
        self.report = self
            .set
            .update(&mut self.subjects, view.camera, size, view.lighting);
    }
    fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        self.set.draws(&self.subjects, out);
    }
    fn counters(&self) -> Counters {
        let r = &self.report;
        Counters {
            quads: r.images as u64,
            images: r.images as u64,
            refreshes: r.refreshes as u64,
            geometry: r.geometry as u64,
            ..Counters::default()
        }
    }
    fn reference<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        self.subjects.iter().for_each(|s| s.draws(out));
    }
}

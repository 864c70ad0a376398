//! Impostors as a technique of the frame loop: a set and the subjects it stands in for.

use super::{Config, ImpostorSet, Report};
use crate::core::Subject;
use crate::core::{Counters, FrameView, Technique};
use engine::Draw;

/// Subjects drawn through an [`ImpostorSet`] (one impostor each), as one
/// [`Technique`]: `prepare` predicts, refreshes within the budget and decides what is drawn;
/// `draws` gives images and fallback geometry; `reference` the subjects' geometry.
#[derive(Debug)]
pub struct Impostored<S> {
    /// The impostors, one per subject.
    pub set: ImpostorSet,
    /// The subjects, in the impostors' order.
    pub subjects: Vec<S>,
    /// What the last `prepare` did.
    pub report: Report,
    /// Draw images pulled to their subjects' nearest corners ([`ImpostorSet::draws_near`]).
    pub near: bool,
    eye: glam::Vec3,
    name: String,
}

impl<S: Subject> Impostored<S> {
    /// `subjects` behind impostors configured by `config`, named `name` in readouts.
    pub fn new(name: impl Into<String>, config: Config, subjects: Vec<S>) -> Self {
        Impostored {
            set: ImpostorSet::new(config, subjects.len()),
            subjects,
            report: Report::default(),
            near: false,
            eye: glam::Vec3::ZERO,
            name: name.into(),
        }
    }
}

impl<S: Subject + Send> Technique for Impostored<S> {
    fn name(&self) -> &str {
        &self.name
    }
    fn prepare(&mut self, view: &FrameView<'_>) {
        self.eye = view.camera.eye();
        self.report = self
            .set
            .update(&mut self.subjects, view.camera, view.height, view.lighting);
    }
    fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        if self.near {
            self.set.draws_near(&self.subjects, self.eye, out);
        } else {
            self.set.draws(&self.subjects, out);
        }
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

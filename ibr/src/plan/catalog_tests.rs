//! The contract every technique in the catalogue keeps, checked once for all of them
//! (adding a catalogue line adds the technique to every test here): each entry has a face
//! (or a sweep or attraction that shows it), a unique name and its folder, and every
//! technique folder has an entry; each planner representation gives no estimate from odd
//! views, is chosen and holds memory under a loose budget and frees it when looked away
//! from, and gives the same pixels and choices on one and two threads; each frame
//! technique renders through the frame loop with the same pixels and counters on one and
//! two threads.

use super::tests::*;
use super::*;
use crate::core::{Counters, FrameLoop, MeshGroup, Technique};
use crate::techniques::{catalog, Entry, MakeRepresentation, MakeTechnique};
use engine::{FrameOptions, Renderer};

/// The catalogue's representations, with their entries.
fn representations() -> impl Iterator<Item = (&'static Entry, MakeRepresentation)> {
    catalog()
        .iter()
        .filter_map(|e| e.representation.map(|make| (e, make)))
}

/// The tori beside geometry and `make`'s representation, under a loose error budget.
fn loose(make: MakeRepresentation) -> Planner<MeshGroup> {
    let objects = tori();
    let set = make(objects.len());
    beside_geometry(objects, set, 1e9, 16, dear_geometry())
}

#[test]
fn every_entry_has_a_face_a_unique_name_and_its_folder() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/src/techniques/");
    for (k, e) in catalog().iter().enumerate() {
        let faces = [
            e.representation.is_some(),
            e.technique.is_some(),
            e.sweep.is_some(),
            e.attraction.is_some(),
        ];
        assert!(
            faces.contains(&true),
            "{}: no face, sweep or attraction",
            e.name
        );
        assert!(!e.name.is_empty() && catalog()[..k].iter().all(|o| o.name != e.name));
        let folder = std::path::Path::new(dir).join(e.folder);
        assert!(folder.join("mod.rs").is_file(), "{}: no {folder:?}", e.name);
    }
}

#[test]
fn every_technique_folder_has_a_catalogue_entry() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/src/techniques/");
    let mut folders: Vec<String> = std::fs::read_dir(dir)
        .expect("the techniques folder")
        .map(|f| f.expect("a folder entry").path())
        .filter(|p| p.is_dir())
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    folders.sort();
    assert!(!folders.is_empty());
    for f in &folders {
        assert!(
            catalog().iter().any(|e| e.folder == *f),
            "ibr/src/techniques/{f}/ has no line in the catalogue"
        );
    }
}

#[test]
fn no_representation_estimates_from_odd_views() {
    let subjects = tori();
    for (e, make) in representations() {
        let set = make(subjects.len());
        eprintln!("{}", e.name);
        assert_no_estimate_from_odd_views(&*set, &subjects[0], &view_at(0.0));
    }
}

#[test]
fn every_representation_holds_images_in_view_and_frees_them_away() {
    let mut r = Renderer::new();
    for (e, make) in representations() {
        eprintln!("{}", e.name);
        let mut p = loose(make);
        let held = assert_holds_then_releases_when_away(&mut p, IMAGES, &view_at(0.0), 2, &mut r);
        assert!(held > 0, "{}", e.name);
    }
}

#[test]
fn every_representation_gives_the_same_frames_on_one_and_two_threads() {
    let cams: Vec<Camera> = (0..3).map(|k| view_at(0.2 * k as f32)).collect();
    for (e, make) in representations() {
        let run = |threads| fly_on_threads(threads, || loose(make), &cams);
        let one = run(1);
        let chosen = one
            .0
            .iter()
            .any(|f| f.1.iter().any(|c| c.rep == Some(IMAGES)));
        assert!(chosen, "{}: never chosen", e.name);
        assert!(one == run(2), "{}: differs on two threads", e.name);
    }
}

/// Two frames of the technique `make` makes over the tori, on `threads` threads: the
/// frames' bytes and counters.
fn frames(make: MakeTechnique, threads: usize) -> Vec<(Vec<u8>, Counters)> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut t = make(tori());
        let (mut frame, mut r) = (FrameLoop::new(), Renderer::new());
        let light = lighting();
        (0..2)
            .map(|k| {
                let cam = view_at(0.2 * k as f32);
                let view = FrameView {
                    time: k as f32 / 30.0,
                    dt: 1.0 / 30.0,
                    ..FrameView::still(&cam, W, H, &light)
                };
                let mut target = Target::new(W, H);
                let mut techniques: [&mut dyn Technique; 1] = [&mut *t];
                let opts = FrameOptions::default();
                frame.render(
                    &mut r,
                    std::iter::empty(),
                    &mut techniques,
                    &view,
                    &mut target,
                    &opts,
                );
                (target.to_rgba8(), t.counters())
            })
            .collect()
    })
}

#[test]
fn every_frame_technique_renders_the_same_on_one_and_two_threads() {
    for e in catalog() {
        let Some(make) = e.technique else { continue };
        assert!(!make(Vec::new()).name().is_empty(), "{}", e.name);
        let one = frames(make, 1);
        assert!(one == frames(make, 2), "{}: differs on two threads", e.name);
    }
}

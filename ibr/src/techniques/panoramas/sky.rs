//! The panorama sky's re-capture policy: a [`CubeMap`] drawn from where it was captured
//! until its predicted parallax passes a tolerance, and captured again where the eye will
//! be, a few faces a frame, started ahead of the tolerance so that the new panorama is
//! complete, and swapped in whole, when the old one's parallax passes it. Only when the
//! eye outruns the spread (its parallax past the tolerance with faces still to capture)
//! are the faces left captured at once. A panorama is never drawn with faces from two
//! centres.

use super::{capture_faces, face_bands, face_cameras, CubeMap};
use crate::core::{Capturer, DepthImage};
use engine::{Draw, Lighting};
use glam::Vec3;
use std::ops::Range;

/// Faces in a cube map.
const FACES: usize = 6;

/// What one [`Sky::update`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SkyStep {
    /// Faces rendered in this update (0 to 6; faces that can show nothing are left empty
    /// and not counted).
    pub faces: usize,
    /// Pixels of those faces rendered: only the rows of each that can show something.
    pub pixels: u64,
    /// Whether a re-capture was completed in this update and is drawn from now on.
    pub swapped: bool,
}

/// A re-capture under way: where from, the rows of each face that can show something
/// from there (none for a face that can show nothing), and the faces captured so far (in
/// face order).
#[derive(Clone, Debug)]
struct Pending {
    centre: Vec3,
    bands: [Range<u32>; FACES],
    faces: Vec<DepthImage>,
}

/// A panorama sky with a re-capture policy (module docs).
#[derive(Clone, Debug)]
pub struct Sky {
    /// The cube map drawn, captured at its [`CubeMap::centre`].
    pub map: CubeMap,
    /// Re-capture past this many pixels of predicted error.
    pub tolerance_px: f32,
    /// Side of each cube face of a capture, pixels.
    pub size: u32,
    /// Near distance of a capture, world units.
    pub near: f32,
    /// Far distance of a capture, world units.
    pub far: f32,
    /// Captures completed (the first included).
    pub captures: u32,
    /// Faces a re-capture takes an update while it is spread (1 to 6; 6 is all at once).
    faces_per_update: usize,
    pending: Option<Pending>,
    /// The faces of the cube maps swapped out with the rows they may hold, the storage of
    /// the next re-capture's faces (at 1280x720 a face is 31 MB: allocating two a frame
    /// was a third of a re-capture frame's time, in page faults).
    pub(super) spare: Vec<(DepthImage, Range<u32>)>,
    /// A renderer and target per face rendered in an update, and the image its band is
    /// read into, kept between re-captures.
    capturers: Vec<(Capturer, DepthImage)>,
}

impl Sky {
    /// Captures the first panorama at `eye`; re-captures take all six faces at once until
    /// [`Sky::spread`] says otherwise.
    pub fn new(
        draws: &[Draw<'_>],
        lighting: &Lighting,
        eye: Vec3,
        size: u32,
        (near, far): (f32, f32),
        tolerance_px: f32,
    ) -> Sky {
        Sky {
            map: CubeMap::capture(draws, lighting, eye, size, near, far),
            tolerance_px,
            size,
            near,
            far,
            captures: 1,
            faces_per_update: FACES,
            pending: None,
            spare: Vec::new(),
            capturers: Vec::new(),
        }
    }

    /// Makes the storage of a re-capture's six faces now (empty faces, as spares), so that
    /// no update allocates one: at 1280x720 a face is 31 MB, and two fresh ones an update
    /// were page faults worth more than their render (issue 39, session 13). Done at
    /// loading, as the first capture is.
    pub fn reserve(&mut self) {
        let cameras = face_cameras(self.map.centre(), self.near, self.far);
        while self.spare.len() < FACES {
            let camera = cameras[self.spare.len()];
            let face = DepthImage::new(self.size, self.size, camera);
            self.spare.push((face, 0..0));
        }
    }

    /// Spreads re-captures over updates, `faces` faces each (clamped to 1 to 6).
    pub fn spread(mut self, faces: usize) -> Sky {
        self.faces_per_update = faces.clamp(1, FACES);
        self
    }

    /// Updates a re-capture started now takes after this one to complete: how far ahead
    /// the `ahead` eye of [`Sky::update`] should be. Faces that can show nothing are not
    /// rendered ([`CubeMap::faces_rendered`]): the held panorama's count of rendered faces
    /// stands for the next's.
    pub fn lead(&self) -> usize {
        let rendered = self.map.faces_rendered().max(1);
        rendered.div_ceil(self.faces_per_update) - 1
    }

    /// Faces of the re-capture under way captured so far; `None` when there is none.
    pub fn pending_faces(&self) -> Option<usize> {
        self.pending.as_ref().map(|p| p.faces.len())
    }

    /// Before drawing from `eye` (`focal_px` pixels per unit of tangent), with the eye
    /// expected at `ahead` [`Sky::lead`] updates later. Starts a re-capture at `ahead` when
    /// the held panorama's predicted parallax there passes the tolerance (at `eye` when it
    /// already does there), captures the next faces of one under way, all that are left
    /// when the parallax at `eye` passes the tolerance, and swaps the new panorama in when
    /// its six faces are there.
    pub fn update(
        &mut self,
        draws: &[Draw<'_>],
        lighting: &Lighting,
        eye: Vec3,
        ahead: Vec3,
        focal_px: f32,
    ) -> SkyStep {
        let tolerance = self.tolerance_px;
        let over = self.map.predicted_px(eye, focal_px) > tolerance;
        // A re-capture under way from where the eye no longer is (it turned back) would be
        // as wrong as the held one: started again at the eye.
        let stale = self.pending.as_ref().is_some_and(|p| {
            let nearest = self.map.nearest();
            over && nearest.is_finite()
                && focal_px * (eye - p.centre).length() / nearest > tolerance
        });
        if stale {
            self.pending = None;
        }
        if self.pending.is_none() {
            let centre = if over {
                eye
            } else if self.map.predicted_px(ahead, focal_px) > tolerance {
                ahead
            } else {
                return SkyStep::default();
            };
            self.pending = Some(Pending {
                centre,
                bands: face_bands(draws, centre, self.near, self.far, self.size),
                faces: Vec::with_capacity(FACES),
            });
        }
        let Some(pending) = self.pending.as_mut() else {
            return SkyStep::default();
        };
        // The next faces to render (all that are left when the eye is past the
        // tolerance), and the empty ones among and after them, which cost no render.
        let budget = if over { FACES } else { self.faces_per_update };
        let from = pending.faces.len();
        let (mut to, mut rendered) = (from, 0);
        let shown = |f: usize| !pending.bands[f].is_empty();
        while to < FACES && (rendered < budget || !shown(to)) {
            rendered += shown(to) as usize;
            to += 1;
        }
        let cameras = face_cameras(pending.centre, self.near, self.far);
        let bands = &pending.bands[from..to];
        let (size, spare, capturers) = (self.size, &mut self.spare, &mut self.capturers);
        let cameras = &cameras[from..to];
        let (faces, pixels) =
            capture_faces(draws, cameras, bands, lighting, size, spare, capturers);
        pending.faces.extend(faces);
        let step = SkyStep {
            faces: rendered,
            pixels,
            swapped: false,
        };
        if pending.faces.len() < FACES {
            return step;
        }
        let Some(Pending {
            centre,
            faces,
            bands,
        }) = self.pending.take()
        else {
            return step;
        };
        if faces.len() != FACES {
            return step;
        }
        let old = std::mem::replace(&mut self.map, CubeMap::assemble(centre, faces, bands));
        self.spare.extend(old.faces.into_iter().zip(old.bands));
        self.captures += 1;
        SkyStep {
            swapped: true,
            ..step
        }
    }
}

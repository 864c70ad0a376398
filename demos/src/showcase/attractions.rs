//! Each image-based attraction of the showcase measured against its geometry from the same
//! eye, on every frame where it is drawn from images: one row of [`ATTRACTIONS`] per
//! attraction, one [`Track`] of figures per row, filled by a [`Meter`].
//!
//! How an attraction is measured (a [`Probe`] in its row):
//! - **Draws** (statue, city impostors, cloud impostors, billboard forest, LDI portals): the
//!   attraction's own
//!   draws and image passes, as the frame just showed them, and its geometry (the
//!   technique's `reference`; the forest's tree meshes where its billboards stand) are
//!   each rendered alone, from the frame's camera at the
//!   frame's size, into a transparent target. Its *screen mask* is the pixels either covers
//!   (alpha > 0). An attraction seen through something (the portals, through the hall's
//!   doorways) has that occluder drawn first into both and into a third target alone; its
//!   mask is then the pixels where either differs from the occluder alone. The city's
//!   occluder is its buildings the planner drew as geometry: the mask is the image-drawn
//!   buildings' pixels (it was every building's, the geometry ones identical in both, and
//!   a frame whose images were all hidden or off screen counted 99 dB). Nothing is
//!   prepared again, so measuring changes nothing the tour shows; the renders happen after
//!   the frame's clock stopped and are never in a frame time. A subject whose geometry
//!   depends on the eye (a cloud's particles face it and fade near it) is measured
//!   through a copy prepared for the frame's eye (the [`Stand`]): the frame prepares only
//!   the clouds it draws as particles, so the others' particles still face the eye of
//!   their last capture, and measuring those (as before) compared the image with a
//!   stale reference.
//! - **Views** (image layers, panorama, view morph): the views moment measures each frame
//!   against the geometry itself; its figure is taken as it is, and its flicker from the
//!   frame it showed and its geometry ([`ViewsTour::renders`], over the pixels its part
//!   measures: the panorama's far scene, the whole frame for the others) when the
//!   previous frame showed the same part.
//! - **Unmeasured**: a row that gives no geometry to compare with stays at zero frames
//!   and says why (none at present).
//!
//! The figures, over the frames an attraction was measured in:
//! - **PSNR** of the image against the geometry over the mask
//!   ([`ibr::metrics::compare`] with a [`Region::Mask`]), capped at [`PSNR_CAP`] dB; `mean` over frames and
//!   `worst` (the lowest).
//! - **Flicker**: for each pair of consecutive frames both measured, over the union `M` of
//!   the two frames' masks, `I` = the sum over `M` of the mean absolute change of the
//!   image's R, G, B (8-bit premultiplied levels) from one frame to the next, and `G` the
//!   same for the geometry. Flicker = `(ΣI / ΣM + ε) / (ΣG / ΣM + ε)` summed over all
//!   pairs, with `ε` = [`FLICKER_EPS`] levels guarding a still geometry (both still gives
//!   1). 1 means the image changes as much as its geometry does; above, it flickers.
//!   `None` before two consecutive frames were measured.

use crate::showcase::building::BuildingTour;
use crate::showcase::views::{Shown, ViewsTour};
use crate::showcase::Showcase;
use engine::{Camera, Draw, FrameOptions, Lighting, Renderer, Rgba, Target};
use ibr::cloud::Cloud;
use ibr::metrics::{self, Image, ImageError, Options, Region};
use ibr::portal::PortalMode;
use ibr::subject::Subject;
use ibr::technique::{FrameView, Technique};

mod renders;

use renders::{change, px, Reader, Renders};

/// PSNR figures are capped here (an image identical to its geometry has an infinite one).
pub const PSNR_CAP: f64 = 99.0;
/// Levels added to both mean changes of the flicker ratio (module docs).
pub const FLICKER_EPS: f64 = 0.5;

/// Copies of eye-dependent subjects prepared for the frame's eye (module docs), reused
/// frame to frame.
#[derive(Debug, Default)]
pub struct Stand {
    clouds: Vec<Cloud>,
}

/// What the image draws and the geometry draws of one attraction are, in a frame of its
/// part; `None` from a probe: not drawn from images this frame.
pub struct Drawn<'a> {
    pub image: Vec<Draw<'a>>,
    /// Whose image passes run over the image render (after its draws).
    pub passes: Option<&'a dyn Technique>,
    pub truth: Vec<Draw<'a>>,
    /// Drawn first under both (module docs); empty for most.
    pub occluder: Vec<Draw<'a>>,
    pub lighting: &'a Lighting,
}

/// How an attraction is measured (module docs).
#[derive(Clone, Copy)]
pub enum Probe {
    /// Given the frame's camera and height, and the [`Stand`] for copies prepared for it.
    Tour(for<'a> fn(&'a Showcase, &'a mut Stand, &Camera, u32) -> Option<Drawn<'a>>),
    Building(fn(&BuildingTour) -> Option<Drawn<'_>>),
    Views(fn(&Shown) -> Option<ImageError>),
    Unmeasured(&'static str),
}

/// One attraction: its name, its technique in plain words, the part of the tour it is in.
#[derive(Clone, Copy)]
pub struct Attraction {
    pub name: &'static str,
    pub technique: &'static str,
    pub part: &'static str,
    pub probe: Probe,
}

/// The eight attractions, in the order the summary lists them.
pub const ATTRACTIONS: [Attraction; 8] = [
    Attraction {
        name: "statue",
        technique: "light field",
        part: "tour",
        probe: Probe::Tour(statue),
    },
    Attraction {
        name: "portals",
        technique: "LDI portals",
        part: "building",
        probe: Probe::Building(portals),
    },
    Attraction {
        name: "background",
        technique: "image layers",
        part: "views",
        probe: Probe::Views(layers),
    },
    Attraction {
        name: "sky",
        technique: "panorama",
        part: "views",
        probe: Probe::Views(sky),
    },
    Attraction {
        name: "morph",
        technique: "view morph",
        part: "views",
        probe: Probe::Views(morph),
    },
    Attraction {
        name: "city",
        technique: "impostors",
        part: "tour",
        probe: Probe::Tour(city),
    },
    Attraction {
        name: "forest",
        technique: "billboards",
        part: "tour",
        probe: Probe::Tour(forest),
    },
    Attraction {
        name: "clouds",
        technique: "cloud impostors",
        part: "tour",
        probe: Probe::Tour(clouds),
    },
];

fn layers(shown: &Shown) -> Option<ImageError> {
    match shown {
        Shown::Layers(f) => f.error,
        _ => None,
    }
}

fn sky(shown: &Shown) -> Option<ImageError> {
    match shown {
        Shown::Sky(f) => f.error,
        _ => None,
    }
}

fn morph(shown: &Shown) -> Option<ImageError> {
    match shown {
        Shown::Morph(f) => f.error.map(|(e, _)| e),
        _ => None,
    }
}

fn statue<'a>(show: &'a Showcase, _: &'a mut Stand, _: &Camera, _: u32) -> Option<Drawn<'a>> {
    let s = &show.ibr.statue;
    s.object.rect()?;
    let mut drawn = Drawn::new(&s.lighting);
    s.object.draws(&mut drawn.image);
    drawn.passes = Some(&s.object);
    s.object.reference(&mut drawn.truth);
    Some(drawn)
}

/// The buildings drawn from images (impostors, layers), against their geometry; the
/// buildings the planner drew as geometry are the occluder under both (module docs), so
/// the mask is the image-drawn buildings' pixels alone, not diluted by geometry drawn
/// identically in both.
fn city<'a>(show: &'a Showcase, _: &'a mut Stand, cam: &Camera, _: u32) -> Option<Drawn<'a>> {
    let plan = &show.ibr.impostors.city;
    let mut drawn = Drawn::new(&show.scene.lighting);
    let eye = cam.eye();
    for (i, c) in plan.choices().iter().enumerate() {
        let Some(rep) = c.rep.and_then(|r| plan.representation(r)) else {
            continue;
        };
        let object = &plan.objects[i];
        if rep.draws_subject() {
            rep.draw(i, object, eye, &mut drawn.occluder);
        } else {
            rep.draw(i, object, eye, &mut drawn.image);
            object.draws(&mut drawn.truth);
        }
    }
    (!drawn.image.is_empty()).then_some(drawn)
}

/// The clouds drawn from images, against their particles prepared for this eye.
fn clouds<'a>(
    show: &'a Showcase,
    stand: &'a mut Stand,
    camera: &Camera,
    height: u32,
) -> Option<Drawn<'a>> {
    let imp = &show.ibr.impostors;
    if imp.readout().clouds.images == 0 {
        return None;
    }
    let mut drawn = Drawn::new(&show.scene.lighting);
    imp.cloud_set.draws(&imp.clouds.clouds, &mut drawn.image);
    stand.clouds.clone_from(&imp.clouds.clouds);
    for c in &mut stand.clouds {
        c.prepare(camera, height);
    }
    for c in &stand.clouds {
        c.draws(&mut drawn.truth);
    }
    Some(drawn)
}

/// The billboard trees as the frame drew them, against the tree meshes they were baked
/// from, standing where the billboards do; the trees the frame drew as meshes (near the
/// eye) are the occluder under both, so the mask is the billboards' pixels alone (it was
/// the near meshes' too, identical in both).
fn forest<'a>(show: &'a Showcase, _: &'a mut Stand, cam: &Camera, _: u32) -> Option<Drawn<'a>> {
    let layer = &show.ibr;
    let mut drawn = Drawn::new(&show.scene.lighting);
    layer.forest_sprites(&mut drawn.image);
    layer.forest_near(&mut drawn.occluder);
    layer.forest_geometry(cam, true, &mut drawn.truth);
    Some(drawn)
}

/// The rooms drawn from their LDIs, against their geometry, seen through the hall's
/// doorways; the hall and the rooms drawn as geometry this frame are the occluder (they
/// were in the mask, identical in both).
fn portals(tour: &BuildingTour) -> Option<Drawn<'_>> {
    if tour.last().warped == 0 {
        return None;
    }
    let mut drawn = Drawn::new(&tour.building.lighting);
    tour.building.hall.draws(&mut drawn.occluder);
    drawn.passes = Some(&tour.portals);
    for p in &tour.portals.portals {
        match p.mode() {
            PortalMode::Warped => p.behind.draws(&mut drawn.truth),
            PortalMode::Geometry => p.behind.draws(&mut drawn.occluder),
            _ => {}
        }
    }
    Some(drawn)
}

impl<'a> Drawn<'a> {
    fn new(lighting: &'a Lighting) -> Self {
        Drawn {
            image: Vec::new(),
            passes: None,
            truth: Vec::new(),
            occluder: Vec::new(),
            lighting,
        }
    }
}

/// One attraction's figures so far (module docs).
#[derive(Clone, Debug, Default)]
pub struct Track {
    /// Frames measured (drawn from images).
    pub frames: usize,
    /// Each measured frame's PSNR, capped.
    pub psnr: Vec<f64>,
    /// Sums over consecutive measured pairs: image change, geometry change (levels summed
    /// over the mask) and mask pixels.
    image_change: f64,
    truth_change: f64,
    mask: f64,
    /// The last measured frame's image and geometry (premultiplied RGBA8); `paired`: it
    /// is the frame before this one's. Kept when not paired, its storage reused.
    prev: Renders,
    paired: bool,
}

/// One attraction's result, as the summary gives it.
#[derive(Clone, Debug, PartialEq)]
pub struct Figures {
    pub name: &'static str,
    pub technique: &'static str,
    pub part: &'static str,
    pub frames: usize,
    /// Mean and worst PSNR (dB); `None` with no frame measured.
    pub psnr_mean: Option<f64>,
    pub psnr_worst: Option<f64>,
    pub flicker: Option<f64>,
}

impl Track {
    /// Adds a frame's error (PSNR only).
    pub fn add(&mut self, e: ImageError) {
        self.frames += 1;
        self.psnr.push(e.psnr_capped(PSNR_CAP));
    }

    /// A frame not drawn from images: the next measured frame starts a new flicker pair.
    pub fn skip(&mut self) {
        self.paired = false;
    }

    /// Adds a frame's renders (`w` x `h`): its PSNR over its mask and its change since the
    /// last. Paired, the renders are kept as the last frame's and `r` is given the storage
    /// of the one before.
    fn add_renders(&mut self, r: &mut Renders, (w, h): (u32, u32)) -> Option<ImageError> {
        let opts = Options {
            region: Region::Mask(&r.mask),
            ..Options::default()
        };
        let e = Image::new(w, h, &r.image)
            .and_then(|a| metrics::compare_rgba8(a, Image::new(w, h, &r.truth)?, &opts));
        let e = match e {
            Ok(e) if r.mask.contains(&true) => e,
            _ => {
                self.paired = false;
                return None;
            }
        };
        self.add(e);
        self.pair(r);
        Some(e)
    }

    /// Adds a measured frame's renders to the flicker: its change since the last measured
    /// frame, if that was the frame before. `r` is kept as the last frame's, traded for
    /// the storage of the one before.
    fn pair(&mut self, r: &mut Renders) {
        if self.paired {
            let (di, dt, m) = change(&self.prev, r);
            self.image_change += di;
            self.truth_change += dt;
            self.mask += m;
        }
        std::mem::swap(&mut self.prev, r);
        self.paired = true;
    }

    /// The flicker ratio so far (module docs); `None` before a measured pair.
    pub fn flicker(&self) -> Option<f64> {
        (self.mask > 0.0).then(|| {
            (self.image_change / self.mask + FLICKER_EPS)
                / (self.truth_change / self.mask + FLICKER_EPS)
        })
    }

    fn figures(&self, a: &Attraction) -> Figures {
        let n = self.psnr.len();
        Figures {
            name: a.name,
            technique: a.technique,
            part: a.part,
            frames: self.frames,
            psnr_mean: (n > 0).then(|| self.psnr.iter().sum::<f64>() / n as f64),
            psnr_worst: (n > 0).then(|| self.psnr.iter().copied().fold(f64::INFINITY, f64::min)),
            flicker: self.flicker(),
        }
    }
}

/// `occluder`'s draws, then `d`'s.
fn under<'a>(occluder: &[Draw<'a>], d: Vec<Draw<'a>>) -> Vec<Draw<'a>> {
    occluder.iter().copied().chain(d).collect()
}

/// Environment variable naming a folder: when set, every measured frame of every
/// attraction is written there as one PNG, image | geometry | difference (x4) over the
/// mask, named by attraction, frame and PSNR, for looking at what the measure sees (the
/// panorama sky's frames too, named by their place along its walk, in thousandths).
pub const DUMP: &str = "PARALLAX_ATTRACTIONS_DUMP";

/// Writes frame `n` of attraction `name`, its image and geometry (RGBA8, `w` x `h`) and
/// their difference over `mask`, side by side into `dir` ([`DUMP`]); a failed write is
/// reported, not fatal.
pub(crate) fn dump(
    dir: &std::path::Path,
    name: &str,
    n: usize,
    e: ImageError,
    [image, truth]: [&[u8]; 2],
    mask: &[bool],
    (w, h): (u32, u32),
) {
    let (w, h) = (w as usize, h as usize);
    let mut out = vec![0u8; 3 * w * h * 4];
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let (a, b) = (px(image, i), px(truth, i));
            let d: Vec<u8> = (0..3)
                .map(|c| (a[c].abs_diff(b[c]) as u32 * 4).min(255) as u8)
                .collect();
            let m = if mask[i] { 255 } else { 0 };
            for (k, p) in [
                [a[0], a[1], a[2], 255],
                [b[0], b[1], b[2], 255],
                [d[0], d[1], d[2], m],
            ]
            .iter()
            .enumerate()
            {
                let o = 4 * (y * 3 * w + k * w + x);
                out[o..o + 4].copy_from_slice(p);
            }
        }
    }
    let _ = std::fs::create_dir_all(dir);
    let path = dir.join(format!(
        "{name}_{n:04}_{:.1}db.png",
        e.psnr_capped(PSNR_CAP)
    ));
    if let Err(err) = engine::load::write_png_rgba8(&path, 3 * w as u32, h as u32, &out) {
        eprintln!("{}: {err}", path.display());
    }
}

/// Measures the attractions frame by frame; one [`Track`] per row of [`ATTRACTIONS`].
#[derive(Debug)]
pub struct Meter {
    pub tracks: Vec<Track>,
    /// The last error measured per attraction (for the readout), `None` if not drawn
    /// from images in its part's last frame.
    pub last: Vec<Option<ImageError>>,
    renderer: Renderer,
    image: Target,
    truth: Target,
    base: Target,
    stand: Stand,
    /// The frame being measured's renders (traded with the tracks' last ones) and the
    /// rows its targets are read through: kept frame to frame.
    scratch: Renders,
    reader: Reader,
    /// The showcase's reduced resolution for soft draws, as the tour's frame used it.
    low_res_scale: u32,
}

impl Default for Meter {
    fn default() -> Self {
        Meter {
            tracks: vec![Track::default(); ATTRACTIONS.len()],
            last: vec![None; ATTRACTIONS.len()],
            renderer: Renderer::new(),
            image: Target::new(1, 1),
            truth: Target::new(1, 1),
            base: Target::new(1, 1),
            stand: Stand::default(),
            scratch: Renders::default(),
            reader: Reader::default(),
            low_res_scale: 1,
        }
    }
}

impl Meter {
    pub fn new() -> Self {
        Self::default()
    }

    /// [`Meter::views`] of the moment's last frame, and that frame's renders for the
    /// flicker of the attraction it showed.
    pub fn views_tour(&mut self, tour: &ViewsTour) {
        let shown = tour.last();
        self.views(&shown);
        let Some((image, truth, mask)) = tour.renders() else {
            return;
        };
        let shown_k = ATTRACTIONS.iter().enumerate().position(|(k, a)| {
            matches!(a.probe, Probe::Views(p) if p(&shown).is_some()) && self.last[k].is_some()
        });
        if let Some(k) = shown_k {
            self.tracks[k].pair(&mut Renders { image, truth, mask });
        }
    }

    /// Measures the tour's attractions in the frame `show` just rendered with `camera`
    /// at `width` x `height`.
    pub fn tour(&mut self, show: &Showcase, camera: &Camera, width: u32, height: u32) {
        let mut stand = std::mem::take(&mut self.stand);
        for (k, a) in ATTRACTIONS.iter().enumerate() {
            if let Probe::Tour(probe) = a.probe {
                let drawn = probe(show, &mut stand, camera, height);
                self.low_res_scale = show.low_res_scale;
                self.measure(k, drawn, camera, width, height);
            }
        }
        self.stand = stand;
    }

    /// The same for the building's frame.
    pub fn building(&mut self, tour: &BuildingTour, camera: &Camera, width: u32, height: u32) {
        for (k, a) in ATTRACTIONS.iter().enumerate() {
            if let Probe::Building(probe) = a.probe {
                let drawn = probe(tour);
                self.measure(k, drawn, camera, width, height);
            }
        }
    }

    /// Takes the views moment's own measures of its last frame.
    pub fn views(&mut self, shown: &Shown) {
        for (k, a) in ATTRACTIONS.iter().enumerate() {
            if let Probe::Views(probe) = a.probe {
                self.last[k] = probe(shown);
                match self.last[k] {
                    Some(e) => self.tracks[k].add(e),
                    None => self.tracks[k].skip(),
                }
            }
        }
    }

    fn measure(&mut self, k: usize, drawn: Option<Drawn<'_>>, cam: &Camera, w: u32, h: u32) {
        let Some(drawn) = drawn else {
            self.tracks[k].skip();
            self.last[k] = None;
            return;
        };
        for t in [&mut self.image, &mut self.truth, &mut self.base] {
            if t.width() != w || t.height() != h {
                *t = Target::new(w, h);
            }
        }
        let opts = FrameOptions {
            clear: Some(Rgba::TRANSPARENT),
            ..Default::default()
        };
        let view = FrameView::still(cam, w, h, drawn.lighting);
        let (r, l) = (&mut self.renderer, drawn.lighting);
        let occluded = !drawn.occluder.is_empty();
        let under = |d| under(&drawn.occluder, d);
        // The images as the frame drew them (soft ones at its reduced resolution), the
        // geometry at full resolution.
        r.set_low_res_scale(self.low_res_scale);
        r.render(under(drawn.image), cam, l, &mut self.image, &opts);
        r.set_low_res_scale(1);
        if let Some(t) = drawn.passes {
            t.passes(&view, &mut self.image);
        }
        r.render(under(drawn.truth), cam, l, &mut self.truth, &opts);
        if occluded {
            r.render(under(Vec::new()), cam, l, &mut self.base, &opts);
        }
        let mut r = std::mem::take(&mut self.scratch);
        let base = occluded.then_some(&self.base);
        r.fill(&self.image, &self.truth, base, &mut self.reader);
        self.last[k] = self.tracks[k].add_renders(&mut r, (w, h));
        self.scratch = r;
        if let (Some(dir), Some(e)) = (std::env::var_os(DUMP), self.last[k]) {
            // Measured, so paired: the frame's renders are its track's last.
            let n = self.tracks[k].frames - 1;
            let name = ATTRACTIONS[k].name;
            let r = &self.tracks[k].prev;
            dump(
                dir.as_ref(),
                name,
                n,
                e,
                [&r.image, &r.truth],
                &r.mask,
                (w, h),
            );
        }
    }

    /// Bytes the meter's per-frame buffers hold (their capacities: the tracks' last
    /// renders, the scratch, the rows read), for the tests that check they are kept.
    pub fn held(&self) -> usize {
        let tracks: usize = self.tracks.iter().map(|t| t.prev.held()).sum();
        tracks + self.scratch.held() + self.reader.held()
    }

    /// The last error measured of the attraction named `name` (`None`: not drawn from
    /// images in its part's last measured frame, or no such attraction).
    pub fn last_of(&self, name: &str) -> Option<ImageError> {
        let k = ATTRACTIONS.iter().position(|a| a.name == name)?;
        self.last[k]
    }

    /// Every attraction's figures, in table order.
    pub fn figures(&self) -> Vec<Figures> {
        ATTRACTIONS
            .iter()
            .zip(&self.tracks)
            .map(|(a, t)| t.figures(a))
            .collect()
    }

    /// One upper-case line per attraction (the bitmap font's), for the window and console:
    /// name, technique, frames, PSNR mean / worst, flicker, or why it is not measured.
    pub fn lines(&self) -> Vec<String> {
        self.lines_of(|_| true)
    }

    /// [`Meter::lines`] of the attractions in `part` alone.
    pub fn part_lines(&self, part: &str) -> Vec<String> {
        self.lines_of(|a| a.part == part)
    }

    fn lines_of(&self, keep: impl Fn(&Attraction) -> bool) -> Vec<String> {
        let f = |v: Option<f64>, d: usize| v.map_or("-".to_string(), |v| format!("{v:.d$}"));
        ATTRACTIONS
            .iter()
            .zip(self.figures())
            .filter(|(a, _)| keep(a))
            .map(|(a, g)| match a.probe {
                Probe::Unmeasured(why) => {
                    format!("{} ({}): NOT MEASURED, {why}", g.name, g.technique)
                }
                _ => format!(
                    "{} ({}): {} frames  PSNR mean {} dB worst {} dB  flicker {}",
                    g.name,
                    g.technique,
                    g.frames,
                    f(g.psnr_mean, 1),
                    f(g.psnr_worst, 1),
                    f(g.flicker, 2)
                ),
            })
            .map(|s| s.to_uppercase())
            .collect()
    }
}

impl std::fmt::Debug for Probe {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Probe::Tour(_) => write!(f, "Tour"),
            Probe::Building(_) => write!(f, "Building"),
            Probe::Views(_) => write!(f, "Views"),
            Probe::Unmeasured(why) => write!(f, "Unmeasured({why})"),
        }
    }
}

impl std::fmt::Debug for Drawn<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (i, t) = (self.image.len(), self.truth.len());
        write!(f, "Drawn {{ image: {i} draws, truth: {t} draws }}")
    }
}

impl std::fmt::Debug for Attraction {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} ({})", self.name, self.technique)
    }
}

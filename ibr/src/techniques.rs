//! The techniques, one folder each. A technique imports `crate::core`, `engine` and the
//! image operations (`crate::warp`, `crate::stereo`, `crate::metrics`, `crate::transforms`),
//! never a sibling technique.

pub(crate) mod billboards;
pub(crate) mod clouds;
pub(crate) mod depth_images;
pub(crate) mod effects;
pub(crate) mod flare;
pub(crate) mod impostors;
pub(crate) mod lasers;
pub(crate) mod layers;
pub(crate) mod lightfields;
pub(crate) mod morph;
pub(crate) mod octahedral;
pub(crate) mod panoramas;
pub(crate) mod portals;

use crate::core::{BillboardBatch, MeshGroup, Representation, Technique};
use engine::{Lighting, Material, Rgba};
use glam::Vec3;

/// A constructor of a planner representation for `objects` objects.
pub type MakeRepresentation = fn(objects: usize) -> Box<dyn Representation<MeshGroup>>;

/// A constructor of a frame technique over `subjects`.
pub type MakeTechnique = fn(subjects: Vec<MeshGroup>) -> Box<dyn Technique>;

/// One technique in the catalogue: its name, the constructors of its faces and where the
/// demos show and measure it. A face it does not have is `None`; every technique has at
/// least one of the four (clouds, panoramas and view morphing are drawn by their owners,
/// outside both seams: the showcase and the bench name them here).
#[derive(Clone, Copy)]
pub struct Entry {
    /// The technique's name in plain words, as sweeps' CSV rows and charts print it.
    pub name: &'static str,
    /// Its folder under `ibr/src/techniques/`.
    pub folder: &'static str,
    /// Its planner representation for `objects` objects with the catalogue's settings (the
    /// ones `bench budget` measures with).
    pub representation: Option<MakeRepresentation>,
    /// It drawn through the frame seam over `subjects` with the catalogue's settings
    /// (techniques that stand in for no subject ignore them).
    pub technique: Option<MakeTechnique>,
    /// The `bench` sweep that measures it on its own, by its subcommand's name.
    pub sweep: Option<&'static str>,
    /// The showcase attraction that shows it, by the attraction's name.
    pub attraction: Option<&'static str>,
}

impl std::fmt::Debug for Entry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Entry")
            .field("name", &self.name)
            .field("folder", &self.folder)
            .field("representation", &self.representation.is_some())
            .field("technique", &self.technique.is_some())
            .field("sweep", &self.sweep)
            .field("attraction", &self.attraction)
            .finish()
    }
}

/// Layers an LDI peels per reference in the catalogue's settings.
pub const LDI_LAYERS: usize = 3;

/// Every technique, in the order the sweeps list them: the planner's representations
/// first (in `bench budget`'s order), then the techniques drawn only through the frame
/// seam, then those outside both seams. Every folder under `ibr/src/techniques/` has at
/// least one line. Adding a technique is its folder and one line here.
pub fn catalog() -> &'static [Entry] {
    &CATALOG
}

/// The representation named `name` in the catalogue, for `objects` objects.
pub fn represent(name: &str, objects: usize) -> Option<Box<dyn Representation<MeshGroup>>> {
    let entry = CATALOG.iter().find(|e| e.name == name)?;
    entry.representation.map(|make| make(objects))
}

#[rustfmt::skip]
static CATALOG: [Entry; 14] = [
    Entry { name: "impostors", folder: "impostors", representation: Some(|n| Box::new(impostors::ImpostorSet::new(impostors::Config::default(), n))), technique: Some(|s| Box::new(impostors::Impostored::new("impostors", impostors::Config::default(), s))), sweep: Some("impostors"), attraction: Some("city") },
    Entry { name: "layers", folder: "layers", representation: Some(|n| Box::new(layers::LayerSet::new(layers::Config::default(), n))), technique: Some(|s| Box::new(layers::Layered::new("layers", layers::Config::default(), s))), sweep: Some("layers"), attraction: Some("background") },
    Entry { name: "octahedral", folder: "octahedral", representation: Some(|n| Box::new(octahedral::OctahedralSet::new(n, 8, 32, octahedral::Layout::Hemi))), technique: Some(octahedral_baked), sweep: Some("impostors"), attraction: None },
    Entry { name: "depth images", folder: "depth_images", representation: Some(|n| Box::new(depth_images::DepthImageSet::new(depth_images::Config::default(), n))), technique: None, sweep: Some("warp"), attraction: None },
    Entry { name: "LDIs", folder: "depth_images", representation: Some(|n| Box::new(depth_images::DepthImageSet::new(depth_images::Config { layers: LDI_LAYERS, ..depth_images::Config::default() }, n))), technique: None, sweep: Some("portals"), attraction: None },
    Entry { name: "billboards", folder: "billboards", representation: Some(|n| Box::new(billboards::BillboardSet::new(n, 64))), technique: Some(|_| Box::new(BillboardBatch::new(Material::unlit(Rgba::WHITE)))), sweep: Some("billboards"), attraction: Some("forest") },
    Entry { name: "light fields", folder: "lightfields", representation: Some(|n| Box::new(lightfields::LightFieldSet::new(n, 8, 32))), technique: None, sweep: Some("lightfield"), attraction: Some("statue") },
    Entry { name: "lasers", folder: "lasers", representation: None, technique: Some(|_| Box::new(lasers::LaserBatch::new())), sweep: None, attraction: None },
    Entry { name: "lens flare", folder: "flare", representation: None, technique: Some(|_| Box::new(flare::Flare { lens: flare::LensFlare::default(), source: flare::FlareSource::Directional(Vec3::new(0.2, 0.3, -1.0)) })), sweep: None, attraction: None },
    Entry { name: "effects", folder: "effects", representation: None, technique: Some(|_| Box::new(effects::Effects::default())), sweep: None, attraction: None },
    Entry { name: "portals", folder: "portals", representation: None, technique: Some(|_| Box::new(portals::Portals::new(Vec::new(), portals::PortalConfig::default()))), sweep: Some("portals"), attraction: Some("portals") },
    Entry { name: "clouds", folder: "clouds", representation: None, technique: None, sweep: None, attraction: Some("clouds") },
    Entry { name: "panoramas", folder: "panoramas", representation: None, technique: None, sweep: Some("panorama"), attraction: Some("sky") },
    Entry { name: "view morphing", folder: "morph", representation: None, technique: None, sweep: Some("morph"), attraction: Some("morph") },
];

/// Octahedral impostors of `subjects`, baked with the catalogue's settings.
fn octahedral_baked(mut subjects: Vec<MeshGroup>) -> Box<dyn Technique> {
    let lighting = Lighting::default();
    let baked: Vec<_> = subjects
        .iter_mut()
        .map(|s| {
            octahedral::OctahedralImpostor::bake(s, &lighting, 4, 16, octahedral::Layout::Full)
        })
        .collect();
    Box::new(baked)
}

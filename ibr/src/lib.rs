//! Image-based rendering for Parallax: techniques that replace geometry with images where
//! that is cheaper (billboards, lasers, lens flare, effects, runtime and octahedral
//! impostors, clouds), and the image data later techniques build on: images with depth and
//! their camera, layered depth images, atlases, and one capture service; and the 3D warp
//! of depth images to new views.
//!
//! Rules: `ibr` builds on `engine` and never the reverse. IBR *data* (an impostor atlas, a
//! depth image) is kept apart from the code that bakes or draws it through the engine, so
//! the data can be built and tested without the rasterizer. Every technique turns into
//! ordinary [`engine::Draw`]s, or into per-pixel image passes ([`engine::pass`]) that write
//! colour and depth into the target: the renderer knows nothing of billboards.
//!
//! - [`images`]: images with depth and their camera, layered depth images, atlases (data
//!   only, no drawing).
//! - [`capture`]: the one offscreen capture path: any draws from any camera into colour,
//!   depth, triangle ids or depth-peeled layers; batches over both cores.
//! - [`billboard`]: screen, world and axial billboards, batched into one mesh per frame.
//! - [`impostor`]: runtime impostors refreshed when their predicted error is too large.
//! - [`layers`]: image layers (Lengyel and Snyder): each subject's image warped by the affine
//!   map fitted to its characteristic points, re-rendered when that errs too far.
//! - [`plan`]: each object's representation chosen per frame under an error, a time and a
//!   rebuild budget, among every representation that predicts its error and cost.
//! - [`schedule`]: the refresh scheduler impostors and image layers share (budgeted,
//!   largest error first).
//! - [`cloud`]: cumulus particle clouds lit by a precomputed light pass (Harris and Lastra).
//! - [`laser`]: dual-billboard beams with glowing end caps.
//! - [`flare`]: lens flare with depth-buffer occlusion and a temporal fade.
//! - [`effects`]: animated sprite sheets and particle emitters (explosions, smoke, sparks).
//! - [`octahedral`]: baked octahedral impostors (N x N views in one atlas, three-frame blend).
//! - [`metrics`]: image error against a ground-truth render (PSNR, mean and max error).
//! - [`technique`]: the technique interface every technique implements, and the one frame
//!   loop ([`technique::FrameLoop`]) that drives them beside a scene's geometry.
//! - [`warp`]: the 3D warp of depth images to new cameras (McMillan's equation and
//!   occlusion-compatible order, points or splats, hole counting and filling).
//! - [`subject`]: what an image can stand in for (mesh groups, particle clouds).
//! - [`sprites`]: textures generated at start-up (glows, puffs, beam profiles, baked
//!   sprites of meshes).

#![warn(missing_docs)]
#![warn(unreachable_pub)]

// Every module is private: the public API is the curated list below. The layers, each
// importing only those before it: `core` (engine only) <- image operations (`warp`,
// `stereo`, `metrics`, `transforms`) <- `techniques` (one folder each, no sibling imports)
// <- the catalogue and the planner (`plan`).
mod core;
mod techniques;

// Image operations and the planner: public modules whose own items are their API.
pub mod metrics;
pub mod plan;
pub mod stereo;
pub mod transforms;
pub mod warp;

// The catalogue: every technique by name, with its constructors.
pub use techniques::{catalog, represent, Entry, MakeRepresentation, MakeTechnique, LDI_LAYERS};

// The most used billboard types at the root, as before.
pub use crate::core::{
    AxialFallback, Basis, Billboard, BillboardBatch, Facing, Size, UvRect, View,
};

// The core: the frame seam, what images stand in for, images with depth, capture.

/// The frame seam: the [`Technique`](technique::Technique) interface and the one frame loop that drives techniques beside a scene's geometry.
pub mod technique {
    pub use crate::core::{
        quads, recycle, Counters, FrameLoop, FrameTimes, FrameView, Observed, Technique,
    };
    pub use crate::techniques::flare::Flare;
}

/// What an image can stand in for (mesh groups, particle clouds).
pub mod subject {
    pub use crate::core::{box_corners, enclose, MeshGroup, Part, Subject};
}

/// The refresh budget impostors and image layers share.
pub mod schedule {
    pub use crate::core::{
        pick_mut, refresh_side_by_side, Budget, Candidate, Refresher, Scheduler,
    };
}

/// The one offscreen capture path: any draws from any camera into colour, depth, triangle ids or depth-peeled layers.
pub mod capture {
    pub use crate::core::{capture_batch, cube_cameras, Capturer};
}

/// Images with depth and their camera, layered depth images, atlases (data only, no drawing).
pub mod images {
    pub use crate::core::{
        axial_depth, srgb8, unproject, DepthImage, LayeredDepthImage, LdiSample, EMPTY,
    };
    pub use crate::transforms;
}

/// Textures generated at start-up (glows, puffs, beam profiles, baked sprites of meshes).
pub mod sprites {
    pub use crate::core::sprites::{
        bake_upright, beam, glow, glow_profile, puff, radial, BakedSprite,
    };
}

// Techniques, one namespace each (their folders are under `src/techniques/`).

/// Screen, world and axial billboards batched into one mesh per frame; axial billboards baked per object for the planner.
pub mod billboard {
    pub use crate::core::{
        corners, fade_pair, orient, push_quad, AxialFallback, Basis, Billboard, BillboardBatch,
        Facing, Size, UvRect, View, HANDOVER,
    };
    pub use crate::techniques::billboards::{
        BillboardSet, Profile, Trim, ViewAtlas, AZIMUTHS, ELEVATIONS, MAX_ELEVATION,
    };
}

/// Dual-billboard beams with glowing end caps.
pub mod laser {
    pub use crate::techniques::lasers::{
        beam_quads, cap_placement, Laser, LaserBatch, CAP_CLEARANCE, CAP_SCALE, END_ON_DEGREES,
    };
}

/// Lens flare with depth-buffer occlusion and a temporal fade.
pub mod flare {
    pub use crate::techniques::flare::{
        approach, atlas, measure, occlusion, occlusion_through, probe, project, region,
        sun_elements, AtlasAlpha, Flare, FlareElement, FlareShape, FlareSource, FlareState,
        LensFlare, Placed, Projected, Reach, Seen, ATLAS_COLS, ATLAS_ROWS, CELL_PX, GUTTER,
        MIN_VISIBILITY,
    };
}

/// Animated sprite sheets and particle emitters (explosions, smoke, sparks).
pub mod effects {
    pub use crate::techniques::effects::{
        explosion_sheet, smoke_puff, spark, Effect, EffectId, Effects, Emitter, EmitterConfig,
        Layer, Particle, SpriteSheet, EXPLOSION_SHEET, MAX_PARTICLES, MAX_STEP,
    };
}

/// Cumulus particle clouds lit by a precomputed light pass (Harris and Lastra).
pub mod cloud {
    pub use crate::techniques::clouds::{
        coverage, cumulus, fade_scale, near_fade, puff_profile, puff_texture, screen_share, Cloud,
        CloudField, CloudParticle, CloudShading, Phase, FOG_MAX, LIGHT_RES, MAX_FILL,
        MAX_PARTICLES, NEAR_FADE,
    };
}

/// Runtime impostors refreshed when their predicted error is too large.
pub mod impostor {
    pub use crate::core::{image_material, screen_rect, Budget, Frustum, Pool};
    pub use crate::techniques::impostors::{
        error_color, Config, Fallback, Impostor, ImpostorSet, Impostored, Mode, Predicted, Report,
        Shape, Tolerance,
    };
}

/// Baked octahedral impostors (N x N views in one atlas, three-frame blend).
pub mod octahedral {
    pub use crate::techniques::octahedral::{
        basis, cell_uv, decode, encode, select, BakeInfo, Blend, Layout, OctahedralImpostor,
        OctahedralSet, MAX_ATLAS_SIDE, MAX_GRID, MIN_FRAME_PX, MIN_GRID, POLE,
    };
}

/// Image layers (Lengyel and Snyder): each subject's image warped by the map fitted to its box, re-rendered when that errs too far.
pub mod layers {
    pub use crate::techniques::layers::{
        project, split_by_depth, unproject, Affine, Config, Homography, Layer, LayerSet, Layered,
        Mode, Predicted, Projector, Report, Unprojector, Why,
    };
}

/// Light slabs: capture, vector quantisation, rendering, sparse rebinning, files, and light fields as a technique and a planner representation.
pub mod lightfield {
    pub use crate::techniques::lightfields::{
        file, rebin, render, vq, Interpolation, LightField, LightFieldFrame, LightFieldObject,
        LightFieldSet, Lookup, Quantised, RawRays, Rays, Rebinned, Rect3, Showing, Slab, SlabError,
        TileShape, VqError, VqReport, VqSettings,
    };
}

/// Depth images and LDIs: references warped to each frame, and each object's own depth image or LDI as a planner representation.
pub mod depth_images {
    pub use crate::techniques::depth_images::{Config, DepthImageSet, WarpFrame, WarpedView};
}

/// LDI portals: openings warped, drawn as geometry or culled per frame.
pub mod portal {
    pub use crate::techniques::portals::{
        from_scene, marked, opening, MarkError, Marked, Opening, Outline, Portal, PortalConfig,
        PortalFrame, PortalImage, PortalMode, Portals,
    };
}

/// Panoramas: cube maps and cylinders as the far scene's sky.
pub mod panorama {
    pub use crate::techniques::panoramas::{
        trim_beyond, Behind, BehindRow, CubeMap, Cylinder, Sky, SkyStep,
    };
}

/// View morphing (Seitz and Dyer), calibrated or from point pairs.
pub mod morph {
    pub use crate::techniques::morph::{
        between, fundamental, plain_morph, uncalibrated, Correspondence, Labels, MorphError,
        MorphScratch, MorphStats, ViewMorph,
    };
}

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

pub mod core;
pub mod metrics;
pub mod plan;
pub mod stereo;
pub mod techniques;
pub mod transforms;
pub mod warp;

//! Parallax's engine: a tile-binned CPU rasterizer with render targets, meshes, materials,
//! textures, cameras and loaders.
//!
//! Data flow for one frame: [`Scene`] (or any [`Draw`]s) + [`Camera`] -> `vertex` ->
//! `clip` -> `setup` -> `bin` -> `raster` + `shade` per tile -> [`Target`]. Per-pixel
//! techniques write colour and depth into a target after it through [`pass`]
//! ([`run_pass`]), and [`Renderer::render_behind`] peels depth layers. Rendering cannot
//! fail; only loading can (see `load`). Conventions (right-handed, +Y up, reversed depth
//! inside, OpenGL depth outside, counter-clockwise front faces, linear colour inside) are in
//! `ARCHITECTURE.md`.
//!
//! ```
//! use engine::{Camera, Material, Mesh, Renderer, Rgba, Scene, Target, FrameOptions};
//! use glam::{Mat4, Vec3};
//!
//! let mut scene = Scene::default();
//! let tri = Mesh {
//!     positions: vec![Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)],
//!     indices: vec![0, 1, 2],
//!     ..Default::default()
//! };
//! scene.add(tri, Material::unlit(Rgba::new(1.0, 0.0, 0.0, 1.0)), Mat4::IDENTITY);
//! let camera = Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 1.0, 1.0);
//! let mut target = Target::new(32, 32);
//! let stats = Renderer::new().render_scene(&scene, &camera, &mut target, &FrameOptions::default());
//! assert_eq!(stats.triangles_set_up, 1);
//! // the centre is red, a corner is the black clear colour
//! assert_eq!(target.pixel(16, 16), Some(0xff00_00ff));
//! assert_eq!(target.pixel(0, 0), Some(0xff00_0000));
//! ```

#![warn(missing_docs)]

// The pipeline's stages, in order, each building only on the ones before it and on the
// shared modules (`space`, `state`, `simd`); internal to the engine but for `simd`, which
// the `ibr` crate's warp shares.
mod bin;
mod clip;
mod front;
mod raster;
mod setup;
mod shade;
mod space;
mod state;
mod tile;
mod vertex;

// Unit tests' shared support.
#[cfg(test)]
mod testing;

// What users see.
pub mod camera;
pub mod color;
pub mod light;
pub mod load;
pub mod material;
pub mod mesh;
pub mod pass;
pub mod procedural;
pub mod renderer;
pub mod scene;
pub mod simd;
pub mod stats;
pub mod target;
pub mod texture;

pub use camera::{Camera, Projection};
pub use color::{Encoding, Premul, Rgba};
pub use light::{Light, Lighting};
pub use load::{LoadError, Loaded};
pub use material::{AlphaMode, BlendMode, DepthOffset, Material, Shading};
pub use mesh::{Mesh, Sphere};
pub use pass::{
    run_packed_pass, run_pass, Fragment, PackedFragment, PackedPass, PassMode, PixelPass, PixelRect,
};
pub use renderer::{Cull, FrameOptions, Renderer, StageTimes};
pub use scene::{Draw, Instance, Scene};
pub use stats::{DrawCost, FrameStats};
pub use target::Target;
pub use texture::{Filter, Sampler, Texture, Wrap};

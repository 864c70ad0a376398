//! Loaders: OBJ + MTL (via `tobj`), glTF 2.0 / GLB (via `gltf`) and images (via `image`),
//! each turning a file into engine data ([`Scene`], [`Texture`]).
//!
//! Loading is the only part of the engine that can fail, and every failure is one
//! [`LoadError`] whose message names the file. Loaders never panic on bad input: counts,
//! offsets and indices read from a file are checked against the bytes actually present
//! before anything is allocated from them, and sizes are capped ([`MAX_FILE_BYTES`],
//! [`MAX_BUFFER_BYTES`], [`MAX_IMAGE_ALLOC`], [`crate::texture::MAX_TEXTURE_SIZE`]). Every
//! mesh returned has passed [`Mesh::validate`].
//!
//! **Missing textures are not errors.** A texture file that is missing or cannot be
//! decoded (OBJ `map_Kd`, glTF base-colour image) is replaced by a magenta-and-black checker
//! ([`placeholder_texture`]) and a warning is pushed to [`Loaded::warnings`], so that a
//! model with one broken texture still shows up, visibly marked. Anything unsafe (a glTF
//! URI outside the file's folder) or structurally wrong (an index out of range) is an error.
//!
//! ```no_run
//! let loaded = engine::load::model(std::path::Path::new("duck.glb"))?;
//! for w in &loaded.warnings {
//!     eprintln!("warning: {w}");
//! }
//! println!("{} triangles", loaded.scene.triangle_count());
//! # Ok::<(), engine::load::LoadError>(())
//! ```

mod accessor;
mod error;
mod files;
mod float;
pub mod fuzz;
mod gltf;
mod image;
mod obj;
mod patch;
mod uri;

pub use self::error::{FileName, LoadError};
pub use self::files::{inside_path, Disk, Files, Memory};
pub use self::float::{
    float_image, float_image_from, parse_pfm, parse_png16, pfm_bytes, write_float_image, FloatImage,
};
pub use self::gltf::GLTF_EXTENSIONS;
pub use self::image::{rgba8_from_bytes, write_png_rgba8, MAX_IMAGE_ALLOC};
pub use self::uri::MAX_BUFFER_BYTES;

use crate::color::{Encoding, Rgba};
use crate::mesh::Mesh;
use crate::scene::Scene;
use crate::texture::Texture;
use std::path::Path;
use std::sync::Arc;

/// The largest main file (OBJ, MTL, glTF JSON, GLB) the loaders read.
pub const MAX_FILE_BYTES: u64 = 1 << 30;

/// What a model loader returns: the scene and what it had to work around.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Loaded {
    /// The model: meshes, materials, instances (object -> world transforms from the file's
    /// node hierarchy; identity for OBJ) and the default [`Lighting`](crate::Lighting).
    pub scene: Scene,
    /// Human-readable notes on what was skipped or replaced (e.g. a missing texture).
    pub warnings: Vec<String>,
    /// Where each instance of `scene` came from, one per instance: for glTF the names of
    /// the nodes from the scene's root down to the instance's node, joined by `/` (a node
    /// without a name is `node<index>`); for OBJ the object or group's name. Techniques
    /// read markers from them (an LDI portal's opening and room, `ibr::portal`).
    pub names: Vec<String>,
}

/// Loads a Wavefront OBJ file with its MTL materials and `map_Kd` textures.
///
/// One mesh, material and instance per OBJ model (object / group / material change), in
/// file order, with identity transforms; faces are fan-triangulated in file order, so
/// triangle `t` of the scene is the file's `t`-th triangle. Vertex colours written as
/// `v x y z r g b` are kept as linear values, exactly as written. Without an MTL
/// material a model gets `Material::lit(white)` (vertex colours on).
pub fn obj(path: &Path) -> Result<Loaded, LoadError> {
    obj::load(path, &Disk)
}

/// [`obj`], reading the OBJ, its MTL libraries and textures from `files`.
pub fn obj_from(path: &Path, files: &dyn Files) -> Result<Loaded, LoadError> {
    obj::load(path, files)
}

/// Loads a glTF 2.0 file (`.gltf` with external or `data:` buffers, or `.glb`).
///
/// The default scene (or scene 0, or every root node) is walked with composed node
/// transforms; each node-primitive becomes one instance, and meshes and materials used
/// several times are shared. A glTF may only read files inside its own folder: absolute
/// paths, `..` components and URI schemes other than `data:` are refused before anything
/// is read.
pub fn gltf(path: &Path) -> Result<Loaded, LoadError> {
    gltf::load(path, &Disk)
}

/// [`gltf`], reading the file, its buffers and images from `files`.
pub fn gltf_from(path: &Path, files: &dyn Files) -> Result<Loaded, LoadError> {
    gltf::load(path, files)
}

/// Loads an image file (PNG or JPEG) as a texture whose bytes are in `encoding`
/// (`Srgb` for colour images, `Unorm` for data).
pub fn image(path: &Path, encoding: Encoding) -> Result<Texture, LoadError> {
    image_from(path, encoding, &Disk)
}

/// [`image`], reading the file from `files`.
pub fn image_from(
    path: &Path,
    encoding: Encoding,
    files: &dyn Files,
) -> Result<Texture, LoadError> {
    let bytes = files.read(path, MAX_FILE_BYTES)?;
    image::texture_from_bytes(&bytes, None, encoding).map_err(|e| e.into_load_error(path))
}

/// Loads a model, choosing the loader from the extension (`.obj`, `.gltf`, `.glb`; any
/// case).
pub fn model(path: &Path) -> Result<Loaded, LoadError> {
    model_from(path, &Disk)
}

/// [`model`], reading from `files`.
///
/// A model held in memory, with its material library beside it (a tiny OBJ: one red
/// quad, fan-triangulated into two triangles):
///
/// ```rust
/// use engine::load::{self, Memory};
/// use std::path::Path;
///
/// let obj = "mtllib quad.mtl\n\
///            v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n\
///            vn 0 0 1\n\
///            o quad\nusemtl red\nf 1//1 2//1 3//1 4//1\n";
/// let mtl = "newmtl red\nKd 1 0 0\n";
/// let files = Memory::default().with("quad.obj", obj).with("quad.mtl", mtl);
/// let loaded = load::model_from(Path::new("quad.obj"), &files)?;
/// assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
/// assert_eq!(loaded.scene.triangle_count(), 2);
/// assert_eq!(loaded.names, ["quad"]);
/// let material = &loaded.scene.materials[loaded.scene.instances[0].material];
/// assert_eq!((material.name.as_str(), material.base_color.r), ("red", 1.0));
///
/// // A missing file is an error that names it, not a panic.
/// let err = load::model_from(Path::new("missing.obj"), &files).unwrap_err();
/// assert!(err.to_string().starts_with("missing.obj"));
/// # Ok::<(), engine::LoadError>(())
/// ```
pub fn model_from(path: &Path, files: &dyn Files) -> Result<Loaded, LoadError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("obj") => obj::load(path, files),
        Some("gltf") | Some("glb") => gltf::load(path, files),
        _ => Err(LoadError::Unsupported { file: path.into() }),
    }
}

/// The stand-in for a texture that is missing or cannot be decoded: an 8 x 8-cell magenta
/// and black checker, impossible to mistake for real content.
pub fn placeholder_texture() -> Arc<Texture> {
    Arc::new(Texture::checker(
        64,
        8,
        Rgba::new(1.0, 0.0, 1.0, 1.0),
        Rgba::BLACK,
    ))
}

/// Runs [`Mesh::validate`], turning a failure into an error naming the mesh.
pub(crate) fn check_mesh(path: &Path, what: &str, mesh: &Mesh) -> Result<(), LoadError> {
    mesh.validate()
        .map_err(|e| LoadError::invalid(path, format!("{what}: {e}")))
}

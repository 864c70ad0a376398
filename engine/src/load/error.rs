//! The one error type of the loaders: every variant names the file and says what is wrong.

use std::fmt;
use std::path::{Path, PathBuf};

/// A file name for messages: the path as given, lossily converted.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FileName(pub PathBuf);

impl fmt::Display for FileName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0.display())
    }
}

impl From<&Path> for FileName {
    fn from(p: &Path) -> Self {
        FileName(p.to_path_buf())
    }
}

/// Why a file could not be loaded. `Display` is one line that starts with the file's path.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LoadError {
    /// The file (or a file it references) could not be opened or read.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// The file that could not be read (or, for the writers, written), as given.
        file: FileName,
        /// What the operating system said.
        #[source]
        source: std::io::Error,
    },
    /// `tobj` rejected an OBJ or MTL file.
    #[error("{file}: bad OBJ: {source}")]
    Obj {
        /// The OBJ file being loaded.
        file: FileName,
        /// What `tobj` said.
        #[source]
        source: tobj::LoadError,
    },
    /// The `gltf` crate rejected the file (JSON syntax, GLB framing or validation).
    #[error("{file}: bad glTF: {source}")]
    Gltf {
        /// The `.gltf` or `.glb` file being loaded.
        file: FileName,
        /// What the `gltf` crate said.
        #[source]
        source: ::gltf::Error,
    },
    /// The `image` crate could not decode an image (or it exceeds the limits).
    #[error("{file}: bad image: {source}")]
    Image {
        /// The image file, read or written.
        file: FileName,
        /// What the `image` crate said.
        #[source]
        source: ::image::ImageError,
    },
    /// The file parsed but its content is invalid or unsafe (out-of-range index, a path
    /// outside the file's folder, a size over a cap, ...).
    #[error("{file}: {reason}")]
    Invalid {
        /// The file whose content is wrong.
        file: FileName,
        /// What is wrong, one line, naming the offending element (mesh, accessor, URI...).
        reason: String,
    },
    /// The extension is not one the loaders know.
    #[error("{file}: unsupported file type (expected .obj, .gltf or .glb)")]
    Unsupported {
        /// The file whose extension is unknown.
        file: FileName,
    },
}

impl LoadError {
    /// The file could not be opened or read.
    pub fn io(file: &Path, source: std::io::Error) -> Self {
        LoadError::Io {
            file: file.into(),
            source,
        }
    }

    /// The file was read but its content is wrong, for `reason`.
    pub fn invalid(file: &Path, reason: impl Into<String>) -> Self {
        LoadError::Invalid {
            file: file.into(),
            reason: reason.into(),
        }
    }

    /// The file the error is about.
    pub fn file(&self) -> &Path {
        match self {
            LoadError::Io { file, .. }
            | LoadError::Obj { file, .. }
            | LoadError::Gltf { file, .. }
            | LoadError::Image { file, .. }
            | LoadError::Invalid { file, .. }
            | LoadError::Unsupported { file } => &file.0,
        }
    }
}

//! Where a loader's files come from: the disk ([`Disk`]), or memory ([`Memory`]: assets
//! packed into a game, tests, fuzzing). Every read is capped before it is made, and a file a
//! model refers to is read only from inside the model's folder.

use super::LoadError;
use std::collections::HashMap;
use std::io::Read;
use std::path::{Path, PathBuf};

/// A source of files for the loaders.
pub trait Files {
    /// The whole of `path`, refusing a file over `cap` bytes before reading it.
    fn read(&self, path: &Path, cap: u64) -> Result<Vec<u8>, LoadError>;

    /// `rel` (already checked to be a plain relative path) inside `dir`: its first `need`
    /// bytes when given (refusing a shorter file before reading), else all of it up to
    /// `cap` bytes. Refuses a file that resolves outside `dir`. Errors name the file.
    fn read_inside(
        &self,
        dir: &Path,
        rel: &Path,
        need: Option<u64>,
        cap: u64,
    ) -> Result<Vec<u8>, String>;
}

/// A path written in a file (a capture's frame, a material's texture) as a plain path
/// relative to that file's folder: refuses empty, absolute and drive paths, `..`, URL
/// schemes and NUL bytes, so what a file names stays inside its folder. Backslashes are
/// read as separators.
pub fn inside_path(written: &str) -> Result<PathBuf, String> {
    let short: String = written.chars().take(80).collect();
    if written.is_empty() {
        return Err("empty path".into());
    }
    if written.contains('\0') {
        return Err(format!("path '{short}' contains a NUL byte"));
    }
    if written.contains(':') || written.starts_with(['/', '\\']) {
        return Err(format!(
            "path '{short}' is absolute or has a scheme; only paths inside the file's folder are allowed"
        ));
    }
    let mut path = PathBuf::new();
    for c in Path::new(&written.replace('\\', "/")).components() {
        match c {
            std::path::Component::Normal(part) => path.push(part),
            std::path::Component::CurDir => {}
            _ => {
                return Err(format!(
                    "path '{short}' leaves the file's folder; only paths inside it are allowed"
                ))
            }
        }
    }
    if path.as_os_str().is_empty() {
        return Err(format!(
            "path '{short}' names the folder itself, not a file"
        ));
    }
    Ok(path)
}

/// The file system.
#[derive(Clone, Copy, Debug, Default)]
pub struct Disk;

impl Files for Disk {
    fn read(&self, path: &Path, cap: u64) -> Result<Vec<u8>, LoadError> {
        let file = std::fs::File::open(path).map_err(|e| LoadError::io(path, e))?;
        let meta = file.metadata().map_err(|e| LoadError::io(path, e))?;
        if meta.is_dir() {
            return Err(LoadError::invalid(path, "is a directory, not a file"));
        }
        check_cap(path, meta.len(), cap)?;
        let mut out = Vec::with_capacity(meta.len() as usize);
        file.take(cap + 1)
            .read_to_end(&mut out)
            .map_err(|e| LoadError::io(path, e))?;
        if out.len() as u64 > cap {
            return Err(LoadError::invalid(path, "file grew over the size limit"));
        }
        Ok(out)
    }

    fn read_inside(
        &self,
        dir: &Path,
        rel: &Path,
        need: Option<u64>,
        cap: u64,
    ) -> Result<Vec<u8>, String> {
        let full = dir.join(rel);
        let shown = full.display().to_string();
        let canon_dir = dir
            .canonicalize()
            .map_err(|e| format!("{}: {e}", dir.display()))?;
        // Through links too: what the path resolves to must stay inside the folder.
        let canon = full.canonicalize().map_err(|e| format!("{shown}: {e}"))?;
        if !canon.starts_with(&canon_dir) {
            return Err(format!("{shown} resolves outside the model's folder"));
        }
        let file = std::fs::File::open(&canon).map_err(|e| format!("{shown}: {e}"))?;
        let meta = file.metadata().map_err(|e| format!("{shown}: {e}"))?;
        if !meta.is_file() {
            return Err(format!("{shown} is not a regular file"));
        }
        let want = wanted(&shown, meta.len(), need, cap)?;
        let mut out = Vec::with_capacity(want as usize);
        file.take(want)
            .read_to_end(&mut out)
            .map_err(|e| format!("{shown}: {e}"))?;
        if (out.len() as u64) < want {
            return Err(format!("{shown}: file shorter than expected"));
        }
        Ok(out)
    }
}

/// Files held in memory, by path (`Memory::default().with("ship.obj", bytes)`). Paths are
/// compared as given: a model at `ship.obj` finds `ship.mtl`, one at `models/ship.gltf`
/// finds `models/ship.bin`.
#[derive(Clone, Debug, Default)]
pub struct Memory {
    files: HashMap<PathBuf, Vec<u8>>,
}

impl Memory {
    /// Adds (or replaces) a file.
    pub fn with(mut self, path: impl Into<PathBuf>, bytes: impl Into<Vec<u8>>) -> Self {
        self.files.insert(key(&path.into()), bytes.into());
        self
    }

    fn get(&self, path: &Path) -> Option<&[u8]> {
        self.files.get(&key(path)).map(Vec::as_slice)
    }
}

impl Files for Memory {
    fn read(&self, path: &Path, cap: u64) -> Result<Vec<u8>, LoadError> {
        let bytes = self.get(path).ok_or_else(|| not_found(path))?;
        check_cap(path, bytes.len() as u64, cap)?;
        Ok(bytes.to_vec())
    }

    fn read_inside(
        &self,
        dir: &Path,
        rel: &Path,
        need: Option<u64>,
        cap: u64,
    ) -> Result<Vec<u8>, String> {
        let full = dir.join(rel);
        let shown = full.display().to_string();
        let bytes = self
            .get(&full)
            .ok_or_else(|| format!("{shown}: no such file"))?;
        let want = wanted(&shown, bytes.len() as u64, need, cap)?;
        Ok(bytes[..want as usize].to_vec())
    }
}

/// A path without its `.` components (`./a.bin` and `a.bin` are one file).
fn key(path: &Path) -> PathBuf {
    path.components()
        .filter(|c| !matches!(c, std::path::Component::CurDir))
        .collect()
}

fn not_found(path: &Path) -> LoadError {
    LoadError::io(path, std::io::ErrorKind::NotFound.into())
}

fn check_cap(path: &Path, len: u64, cap: u64) -> Result<(), LoadError> {
    if len > cap {
        return Err(LoadError::invalid(
            path,
            format!("file is {len} bytes, over the {cap}-byte limit"),
        ));
    }
    Ok(())
}

/// How many bytes to read of a `len`-byte file: `need` (which it must have), or all of it
/// within `cap`.
fn wanted(shown: &str, len: u64, need: Option<u64>, cap: u64) -> Result<u64, String> {
    match need {
        Some(n) if n > len => Err(format!(
            "{shown}: byteLength {n} exceeds the file's {len} bytes"
        )),
        Some(n) => Ok(n),
        None if len > cap => Err(format!("{shown}: {len} bytes, over the {cap}-byte limit")),
        None => Ok(len),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_reads_capped_and_only_what_it_holds() {
        let m = Memory::default()
            .with("a/model.obj", b"v 0 0 0".to_vec())
            .with("a/tex/t.png", vec![7u8; 10]);
        assert_eq!(m.read(Path::new("a/model.obj"), 100).unwrap(), b"v 0 0 0");
        let e = m.read(Path::new("a/model.obj"), 3).unwrap_err().to_string();
        assert!(e.contains("over the 3-byte limit"), "{e}");
        assert!(m.read(Path::new("b.obj"), 100).is_err());
        assert!(m.read(Path::new("./a/model.obj"), 100).is_ok());
        let dir = Path::new("a");
        let rel = Path::new("tex/t.png");
        assert_eq!(m.read_inside(dir, rel, Some(4), 100).unwrap(), vec![7; 4]);
        assert_eq!(m.read_inside(dir, rel, None, 100).unwrap().len(), 10);
        assert!(m.read_inside(dir, rel, Some(11), 100).is_err());
        assert!(m.read_inside(dir, rel, None, 9).is_err());
        assert!(m.read_inside(dir, Path::new("x.bin"), None, 9).is_err());
    }

    #[test]
    fn inside_paths_stay_inside() {
        assert_eq!(inside_path("./img/a.png").unwrap(), Path::new("img/a.png"));
        assert_eq!(inside_path("img\\a.png").unwrap(), Path::new("img/a.png"));
        for (bad, why) in [
            ("", "empty"),
            ("../a.png", "leaves"),
            ("img/../../a.png", "leaves"),
            ("/etc/passwd", "absolute"),
            ("\\\\server\\a.png", "absolute"),
            ("C:/a.png", "absolute"),
            ("file:a.png", "scheme"),
            ("a\0.png", "NUL"),
            ("./.", "folder itself"),
        ] {
            let e = inside_path(bad).unwrap_err();
            assert!(e.contains(why), "{bad:?}: {e}");
        }
    }
}

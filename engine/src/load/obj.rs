//! The OBJ + MTL loader: a checking pre-scan of the text, then `tobj` (fan triangulation,
//! single index), then one engine mesh + material + instance per OBJ model.
//!
//! The pre-scan exists because `tobj` trusts its input in a few places (a face index like
//! `1/-9223372036854775807` overflows its arithmetic; `Kd 1 2` in an MTL panics): every face
//! index is checked against the vertex counts first, so what reaches `tobj` is sound, and
//! errors can name the offending line.

use super::{check_mesh, placeholder_texture, Files, LoadError, Loaded, MAX_FILE_BYTES};
use crate::color::{Encoding, Rgba};
use crate::material::{AlphaMode, Material, Shading};
use crate::mesh::Mesh;
use crate::texture::Texture;
use glam::{Mat4, Vec2, Vec3};
use std::cell::RefCell;
use std::collections::HashMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// What the pre-scan learned.
#[derive(Debug, Default)]
struct Scan {
    /// `f` lines with at least three vertices.
    faces: usize,
    /// `v` lines with and without the `r g b` extension.
    colored: usize,
    plain: usize,
    /// `l` (polyline) lines: `tobj` would turn those with 3+ points into triangles.
    lines: usize,
    /// Lines that are OBJ statements, and lines that are neither statements, comments nor
    /// blank (a file of only those is not an OBJ).
    statements: usize,
    unknown: usize,
    /// Face texcoord and normal indices that name nothing (the file has no `vt` / `vn`
    /// lines, or the index is 0): read as absent.
    ignored: [usize; 2],
}

/// The OBJ statements (geometry, grouping, display and curve keywords of the format).
const STATEMENTS: [&str; 30] = [
    "v", "vt", "vn", "vp", "f", "l", "p", "o", "g", "s", "mg", "usemtl", "mtllib", "usemap",
    "maplib", "cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm", "trim", "hole",
    "scrv", "sp", "end", "con", "lod",
];

fn text_of<'a>(path: &Path, bytes: &'a [u8]) -> Result<&'a str, LoadError> {
    std::str::from_utf8(bytes).map_err(|e| {
        LoadError::invalid(
            path,
            format!("not UTF-8 text (bad byte at offset {})", e.valid_up_to()),
        )
    })
}

/// Checks every face index (1-based, or negative = relative to the vertices read so far)
/// against the vertex, texcoord and normal counts. Positive indices may refer forward
/// (to any vertex in the file), as the peers' loader allows.
fn scan(text: &str) -> Result<Scan, String> {
    let mut totals = [0i64; 3];
    for line in text.lines() {
        match line.split_whitespace().next() {
            Some("v") => totals[0] += 1,
            Some("vt") => totals[1] += 1,
            Some("vn") => totals[2] += 1,
            _ => {}
        }
    }
    let mut seen = [0i64; 3];
    let mut s = Scan::default();
    for (no, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let first = words.clone().next();
        match first {
            Some(w) if STATEMENTS.contains(&w) => s.statements += 1,
            Some(w) if !w.starts_with('#') => s.unknown += 1,
            _ => {}
        }
        match words.next() {
            Some(kind @ ("v" | "vt" | "vn")) => {
                let k = ["v", "vt", "vn"]
                    .iter()
                    .position(|x| *x == kind)
                    .unwrap_or(0);
                seen[k] += 1;
                let nums: Vec<&str> = words.collect();
                let need = if k == 1 { 2 } else { 3 };
                if nums.len() < need || nums[..need].iter().any(|t| t.parse::<f32>().is_err()) {
                    return Err(format!(
                        "line {}: bad `{kind}` line '{}'",
                        no + 1,
                        line.trim()
                    ));
                }
                if k == 0 {
                    if nums.len() >= 6 {
                        s.colored += 1;
                    } else {
                        s.plain += 1;
                    }
                }
            }
            Some("l") => s.lines += 1,
            Some("f") => {
                let mut n = 0;
                for tok in words {
                    n += 1;
                    let parts: Vec<&str> = tok.split('/').collect();
                    if parts.len() > 3 {
                        return Err(format!("line {}: bad face vertex '{tok}'", no + 1));
                    }
                    for (k, part) in parts.iter().enumerate() {
                        if part.is_empty() && k > 0 {
                            continue;
                        }
                        let i: i64 = part
                            .parse()
                            .map_err(|_| format!("line {}: bad face vertex '{tok}'", no + 1))?;
                        let (what, many) = [
                            ("vertex", "vertices"),
                            ("texcoord", "texcoords"),
                            ("normal", "normals"),
                        ][k];
                        // A texcoord or normal index in a file with none of them, or 0,
                        // means "none here" (as `tobj` reads it): ignored, with a warning.
                        if k > 0 && (totals[k] == 0 || i == 0) {
                            s.ignored[k - 1] += 1;
                            continue;
                        }
                        let ok = if i > 0 {
                            i <= totals[k]
                        } else {
                            i < 0 && i >= -seen[k]
                        };
                        if !ok {
                            return Err(format!(
                                "line {}: face {what} index {i} out of range ({} {many}{})",
                                no + 1,
                                if i > 0 { totals[k] } else { seen[k] },
                                if i == 0 {
                                    "; OBJ indices start at 1"
                                } else {
                                    ""
                                },
                            ));
                        }
                    }
                }
                if n >= 3 {
                    s.faces += 1;
                }
            }
            _ => {}
        }
    }
    Ok(s)
}

/// Removes what `tobj` should not see: `l` lines (replaced by blank lines so line numbers
/// stay), and, when only some vertices carry colours, the colours.
fn filter(text: &str, drop_colors: bool) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("l") => {}
            Some("v") if drop_colors => {
                let w: Vec<&str> = words.collect();
                if w.len() >= 6 {
                    out.push_str(&format!("v {} {} {}", w[0], w[1], w[2]));
                } else {
                    out.push_str(line);
                }
            }
            _ => out.push_str(line),
        }
        out.push('\n');
    }
    out
}

/// Reads and parses one MTL file. `Kd`-style lines need three numbers (`tobj` would panic
/// on fewer).
fn load_mtl(path: &Path, files: &dyn Files) -> Result<tobj::MTLLoadResult, String> {
    let bytes = files
        .read(path, MAX_FILE_BYTES)
        .map_err(|e| e.to_string())?;
    let text = text_of(path, &bytes).map_err(|e| e.to_string())?;
    for (no, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if let Some("Ka" | "Kd" | "Ks" | "Ke") = words.next() {
            if words.count() < 3 {
                return Err(format!(
                    "{}: line {}: expected three numbers",
                    path.display(),
                    no + 1
                ));
            }
        }
    }
    Ok(tobj::load_mtl_buf(&mut Cursor::new(text.as_bytes())))
}

/// The file name in a `map_Kd` value: options such as `-s 1 1 1` come first, so take the
/// last word when there are options; Windows separators become `/`.
fn texture_name(value: &str) -> String {
    let name = if value.starts_with('-') {
        value.split_whitespace().last().unwrap_or(value)
    } else {
        value
    };
    name.replace('\\', "/")
}

/// Loads textures once per file; failures become the placeholder plus a warning.
struct Textures<'f> {
    files: &'f dyn Files,
    cache: HashMap<PathBuf, Arc<Texture>>,
}

impl Textures<'_> {
    fn get(&mut self, path: PathBuf, warnings: &mut Vec<String>) -> Arc<Texture> {
        if let Some(t) = self.cache.get(&path) {
            return t.clone();
        }
        let t = match super::image_from(&path, Encoding::Srgb, self.files) {
            Ok(t) => Arc::new(t),
            Err(e) => {
                warnings.push(format!("texture replaced by a placeholder: {e}"));
                placeholder_texture()
            }
        };
        self.cache.insert(path, t.clone());
        t
    }
}

fn material(
    mt: &tobj::Material,
    mtl_dir: &Path,
    textures: &mut Textures<'_>,
    warnings: &mut Vec<String>,
) -> Material {
    let kd = mt.diffuse.unwrap_or([1.0; 3]);
    let alpha = match (mt.dissolve, mt.unknown_param.get("Tr")) {
        (Some(d), _) => d,
        (None, Some(tr)) => tr
            .split_whitespace()
            .next()
            .and_then(|t| t.parse::<f32>().ok())
            .map_or(1.0, |tr| 1.0 - tr),
        (None, None) => 1.0,
    };
    let alpha = if alpha.is_finite() {
        alpha.clamp(0.0, 1.0)
    } else {
        1.0
    };
    let mut m = Material::lit(Rgba::new(kd[0], kd[1], kd[2], alpha));
    m.name = mt.name.clone();
    if let Shading::Lit {
        specular,
        shininess,
    } = &mut m.shading
    {
        if let Some(ks) = mt.specular {
            *specular = (ks[0] + ks[1] + ks[2]) / 3.0;
        }
        if let Some(ns) = mt.shininess.filter(|n| n.is_finite()) {
            *shininess = ns.max(1.0);
        }
    }
    if alpha < 1.0 {
        m.alpha_mode = AlphaMode::Blend;
    }
    if let Some(ke) = mt.emissive {
        m.emissive = Rgba::new(ke[0], ke[1], ke[2], 0.0);
    }
    if let Some(tex) = &mt.diffuse_texture {
        let file = mtl_dir.join(texture_name(tex));
        m.base_texture = Some(textures.get(file, warnings));
    }
    m
}

fn mesh(m: &tobj::Mesh, label: &str, warnings: &mut Vec<String>) -> Mesh {
    let n = m.positions.len() / 3;
    let positions = m
        .positions
        .chunks_exact(3)
        .map(|p| Vec3::new(p[0], p[1], p[2]))
        .collect();
    let mut out = Mesh {
        positions,
        indices: m.indices.clone(),
        ..Default::default()
    };
    if m.normals.len() == 3 * n {
        out.normals = m
            .normals
            .chunks_exact(3)
            .map(|v| Vec3::new(v[0], v[1], v[2]).normalize_or(Vec3::Y))
            .collect();
    } else if !m.normals.is_empty() {
        warnings.push(format!(
            "{label}: only some face vertices have normals; normals ignored"
        ));
    }
    if m.texcoords.len() == 2 * n {
        // OBJ's v points up; the engine's (like glTF's) points down.
        out.uvs = m
            .texcoords
            .chunks_exact(2)
            .map(|t| Vec2::new(t[0], 1.0 - t[1]))
            .collect();
    } else if !m.texcoords.is_empty() {
        warnings.push(format!(
            "{label}: only some face vertices have texture coordinates; ignored"
        ));
    }
    if m.vertex_color.len() == 3 * n {
        out.colors = m
            .vertex_color
            .chunks_exact(3)
            .map(|c| Rgba::new(c[0], c[1], c[2], 1.0))
            .collect();
    }
    out
}

pub(crate) fn load(path: &Path, files: &dyn Files) -> Result<Loaded, LoadError> {
    let bytes = files.read(path, MAX_FILE_BYTES)?;
    let text = text_of(path, &bytes)?;
    let s = scan(text).map_err(|r| LoadError::invalid(path, r))?;
    if s.statements == 0 && s.unknown > 0 {
        return Err(LoadError::invalid(
            path,
            "no OBJ statements: not an OBJ file",
        ));
    }
    let mut warnings = Vec::new();
    for (n, what) in s.ignored.iter().zip(["texcoord", "normal"]) {
        if *n > 0 {
            warnings.push(format!(
                "{}: {n} face {what} indices name no {what} (the file has none, or the \
                 index is 0); read as absent",
                path.display()
            ));
        }
    }
    if s.faces == 0 {
        // Valid (points, lines, or nothing at all), but nothing the renderer draws.
        warnings.push(format!(
            "{}: no faces (`f` lines with 3 or more vertices): the scene is empty",
            path.display()
        ));
        return Ok(Loaded {
            scene: crate::scene::Scene::default(),
            warnings,
            names: Vec::new(),
        });
    }
    let mixed = s.colored > 0 && s.plain > 0;
    if mixed {
        warnings.push(format!(
            "{}: {} of {} vertices have colours; vertex colours ignored",
            path.display(),
            s.colored,
            s.colored + s.plain
        ));
    }
    let filtered;
    let text = if mixed || s.lines > 0 {
        filtered = filter(text, mixed);
        &filtered
    } else {
        text
    };

    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let (models, materials, mat_dirs) = parse(path, text, &dir, files, &mut warnings)?;

    let mut scene = crate::scene::Scene::default();
    let mut names = Vec::new();
    let mut textures = Textures {
        files,
        cache: HashMap::new(),
    };
    for (i, model) in models.iter().enumerate() {
        let label = format!("model {i} '{}'", model.name);
        if model.mesh.indices.is_empty() {
            continue; // an `o` / `g` with no faces
        }
        let mesh = mesh(&model.mesh, &label, &mut warnings);
        check_mesh(path, &label, &mesh)?;
        let mat = match model.mesh.material_id.and_then(|id| materials.get(id)) {
            Some(mt) => {
                let id = model.mesh.material_id.unwrap_or(0);
                let mtl_dir = mat_dirs.get(id).unwrap_or(&dir);
                material(mt, mtl_dir, &mut textures, &mut warnings)
            }
            None => Material {
                name: "default".into(),
                ..Material::lit(Rgba::WHITE)
            },
        };
        scene.add(mesh, mat, Mat4::IDENTITY);
        names.push(model.name.clone());
    }
    Ok(Loaded {
        scene,
        warnings,
        names,
    })
}

/// What [`parse`] reads: models, materials, and each material's library folder.
type Parsed = (Vec<tobj::Model>, Vec<tobj::Material>, Vec<PathBuf>);

/// Parses the (filtered) OBJ text with tobj, loading the MTL libraries it names through
/// `files`: the models, the materials, and the folder each material's library lies in (for
/// its texture paths). Unreadable or bad libraries become warnings.
fn parse(
    path: &Path,
    text: &str,
    dir: &Path,
    files: &dyn Files,
    warnings: &mut Vec<String>,
) -> Result<Parsed, LoadError> {
    // (folder of the MTL file, number of materials it brought), in load order.
    let libs: RefCell<Vec<(PathBuf, usize)>> = RefCell::default();
    let lib_warnings: RefCell<Vec<String>> = RefCell::default();
    #[allow(clippy::needless_update)] // reason: tobj's `merging`/`reordering` features add fields
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let (models, materials) = tobj::load_obj_buf(&mut Cursor::new(text.as_bytes()), &opts, |lib| {
        let file = dir.join(lib);
        match load_mtl(&file, files) {
            Ok(Ok(r)) => {
                let lib_dir = file.parent().unwrap_or(Path::new("")).to_path_buf();
                libs.borrow_mut().push((lib_dir, r.0.len()));
                Ok(r)
            }
            Ok(Err(e)) => {
                lib_warnings.borrow_mut().push(format!(
                    "{}: bad MTL: {e}; its materials ignored",
                    file.display()
                ));
                Err(e)
            }
            Err(e) => {
                lib_warnings
                    .borrow_mut()
                    .push(format!("{e}; its materials ignored"));
                Err(tobj::LoadError::OpenFileFailed)
            }
        }
    })
    .map_err(|source| LoadError::Obj {
        file: path.into(),
        source,
    })?;
    warnings.extend(lib_warnings.into_inner());
    let materials = materials.unwrap_or_default();
    let mut mat_dirs = Vec::with_capacity(materials.len());
    for (lib_dir, n) in libs.into_inner() {
        mat_dirs.extend(std::iter::repeat_n(lib_dir, n));
    }
    Ok((models, materials, mat_dirs))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scan_checks_indices() {
        assert!(scan("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").is_ok());
        assert!(scan("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n").is_ok());
        let e = scan("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n").unwrap_err();
        assert!(e.contains("line 4") && e.contains("out of range"), "{e}");
        assert!(scan("v 0 0 0\nvt 0 0\nf 1/-9223372036854775807 1 1\n").is_err());
        assert!(scan("v 0 0 0\nf 0 1 1\n").is_err());
        assert!(scan("v 0 0 0\nf -9223372036854775808 1 1\n").is_err());
        assert!(scan("v 0 0 0\nf 1/1/1/1 1 1\n").is_err());
        assert!(scan("v 0 0 0\nvn 0 0 1\nf 1//2 1 1\n").is_err());
        assert!(scan("v 0 0 0\nvt 0 0\nf 1/2 1 1\n").is_err());
        // Texcoord and normal indices with nothing to name are absent, not errors.
        let s = scan("v 0 0 0\nf 1//1 1/1 1/0/0\n").unwrap();
        assert_eq!(s.ignored, [2, 2]);
        assert!(scan("v 0 0 0\nvn 0 0 1\nf 0//1 1//1 1//1\n").is_err());
        assert_eq!(
            scan("v 0 0 0\nvn 0 0 1\nf 1//1 1//1 1//1\n").unwrap().faces,
            1
        );
    }

    #[test]
    fn texture_names() {
        assert_eq!(texture_name("a b.png"), "a b.png");
        assert_eq!(texture_name("-s 1 1 1 tex\\a.png"), "tex/a.png");
    }
}

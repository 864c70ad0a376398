//! The glTF 2.0 loader: `.gltf` (external or `data:` buffers) and `.glb`, parsed and validated
//! by the `gltf` crate, with buffers, images and accessors read here under our own checks.
//!
//! Order of work: parse the JSON (or GLB framing, whose header is checked first); check
//! every buffer and image URI ([`super::uri::classify`]) and every declared `byteLength`
//! against [`super::MAX_BUFFER_BYTES`] before reading anything; read the buffers (a declared
//! length longer than the data is refused); walk the scene's nodes, building each
//! (mesh, primitive) and each material once and one [`crate::scene::Instance`] per
//! node-primitive. Images are decoded lazily, only for base-colour textures; a missing or
//! undecodable one becomes the placeholder checker plus a warning. The `gltf` crate's own
//! readers are not used (see `accessor`), and the few inputs on which its parsing or
//! accessors panic are refused beforehand ([`precheck`]).
//!
//! Materials: base-colour factor times base-colour texture (sRGB) with its sampler (wrap
//! modes; `Nearest` when the magnification filter is NEAREST, else `Trilinear`), with
//! KHR_texture_transform baked into the UVs; `alphaMode` / `alphaCutoff`; `doubleSided`;
//! KHR_materials_unlit -> `Shading::Unlit`, otherwise `Shading::Lit` with
//! [`Material::lit`]'s highlight (metallic-roughness is not modelled); the emissive factor
//! times KHR_materials_emissive_strength -> `emissive`, unless an emissive texture goes
//! with it (the engine has no emission maps, so emission is then dropped with a warning).
//! Only `TEXCOORD_0` and `COLOR_0` are read. Other extensions are ignored with a warning, or refused when required
//! ([`GLTF_EXTENSIONS`]).
//!
//! Every optional part of the specification may be absent: no `scenes` (every root node
//! is drawn), a scene without `nodes`, no `meshes` or `materials` (an empty scene loads,
//! with a warning, and renders as an empty frame); sparse accessors are read.

use super::accessor::{read_f32, read_indices, view_bytes};
use super::image::{format_from_mime, texture_from_bytes};
use super::uri::{classify, data_bytes, load_buffers, Uri};
use super::{
    check_mesh, patch, placeholder_texture, Files, LoadError, Loaded, MAX_BUFFER_BYTES,
    MAX_FILE_BYTES,
};
use crate::color::{Encoding, Rgba};
use crate::material::{AlphaMode, Material};
use crate::mesh::Mesh;
use crate::scene::{Instance, Scene};
use crate::texture::{Filter, Sampler, Texture, Wrap};
use ::gltf::mesh::Mode;
use ::gltf::texture::{MagFilter, MinFilter, WrappingMode};
use ::gltf::{Document, Node, Semantic};
use glam::{Mat4, Vec2, Vec3};
use std::borrow::Cow;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Refuses a GLB whose header is too short or claims more bytes than the file has (the
/// `gltf` crate would underflow on a length below 12).
fn check_glb_header(path: &Path, bytes: &[u8]) -> Result<(), LoadError> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    if bytes.len() < 20 {
        return Err(LoadError::invalid(
            path,
            format!("truncated GLB: only {} bytes", bytes.len()),
        ));
    }
    let len = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize;
    if len < 20 || len > bytes.len() {
        return Err(LoadError::invalid(
            path,
            format!(
                "truncated GLB: header says {len} bytes, file has {}",
                bytes.len()
            ),
        ));
    }
    Ok(())
}

/// Refuses what the `gltf` crates (1.4.1) would panic on rather than report: attribute
/// accessor indices that do not exist (validation indexes the POSITION accessor before
/// checking it), and images without a `uri` or with a `bufferView` but no `mimeType`.
fn precheck(path: &Path, doc: &Document) -> Result<(), LoadError> {
    let root = doc.as_json();
    for (i, img) in root.images.iter().enumerate() {
        let ok = match img.buffer_view {
            Some(_) => img.mime_type.is_some(),
            None => img.uri.is_some(),
        };
        if !ok {
            return Err(LoadError::invalid(
                path,
                format!("image {i}: needs a uri, or a bufferView and a mimeType"),
            ));
        }
    }
    for (mi, m) in root.meshes.iter().enumerate() {
        for (pi, p) in m.primitives.iter().enumerate() {
            for a in p.attributes.values() {
                if a.value() >= root.accessors.len() {
                    return Err(LoadError::invalid(
                        path,
                        format!(
                            "mesh {mi} primitive {pi}: attribute accessor {} does not exist \
                             ({} accessors)",
                            a.value(),
                            root.accessors.len()
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// The extensions this loader reads: everything else in `extensionsUsed` is ignored with
/// a warning, and a file that lists anything else in `extensionsRequired` is refused (the
/// specification says a loader must not render what it cannot read correctly).
pub const GLTF_EXTENSIONS: [&str; 3] = [
    "KHR_materials_emissive_strength",
    "KHR_materials_unlit",
    "KHR_texture_transform",
];

/// Refuses required extensions the loader does not read; warns of used ones it ignores.
fn extensions(path: &Path, doc: &Document, warnings: &mut Vec<String>) -> Result<(), LoadError> {
    let root = doc.as_json();
    if let Some(ext) = root
        .extensions_required
        .iter()
        .find(|e| !GLTF_EXTENSIONS.contains(&e.as_str()))
    {
        return Err(LoadError::invalid(
            path,
            format!(
                "requires extension {ext}, which this loader does not read (it reads {})",
                GLTF_EXTENSIONS.join(", ")
            ),
        ));
    }
    for ext in &root.extensions_used {
        if !GLTF_EXTENSIONS.contains(&ext.as_str()) {
            warnings.push(format!(
                "{}: extension {ext} is not supported; ignored",
                path.display()
            ));
        }
    }
    Ok(())
}

/// Everything the scene walk shares.
struct Ctx<'a> {
    path: &'a Path,
    files: &'a dyn Files,
    dir: PathBuf,
    buffers: Vec<Cow<'a, [u8]>>,
    scene: Scene,
    warnings: Vec<String>,
    /// Each instance's node path ([`Loaded::names`]).
    names: Vec<String>,
    /// (mesh, primitive) -> scene mesh (`None`: skipped primitive).
    meshes: HashMap<(usize, usize), Option<usize>>,
    /// glTF material index (`None` = the default material) -> scene material.
    materials: HashMap<Option<usize>, usize>,
    images: HashMap<usize, Arc<Texture>>,
}

impl Ctx<'_> {
    fn image(&mut self, img: ::gltf::Image) -> Arc<Texture> {
        if let Some(t) = self.images.get(&img.index()) {
            return t.clone();
        }
        let (label, result) = match img.source() {
            ::gltf::image::Source::View { view, mime_type } => (
                format!("image {} (bufferView {})", img.index(), view.index()),
                view_bytes(&view, &self.buffers).and_then(|b| {
                    texture_from_bytes(b, format_from_mime(mime_type), Encoding::Srgb)
                        .map_err(|e| e.to_string())
                }),
            ),
            ::gltf::image::Source::Uri { uri, mime_type } => {
                let hint = mime_type.and_then(format_from_mime);
                let bytes = match classify(uri) {
                    Ok(Uri::Data {
                        base64,
                        payload,
                        mime,
                    }) => data_bytes(base64, payload)
                        .map(|b| (b, hint.or_else(|| mime.and_then(format_from_mime)))),
                    Ok(Uri::Relative(rel)) => self
                        .files
                        .read_inside(&self.dir, &rel, None, MAX_BUFFER_BYTES)
                        .map(|b| (b, hint)),
                    Err(e) => Err(e),
                };
                let label = if uri.starts_with("data:") {
                    format!("image {} (data: URI)", img.index())
                } else {
                    format!("image {} ('{uri}')", img.index())
                };
                let result = bytes.and_then(|(b, hint)| {
                    texture_from_bytes(&b, hint, Encoding::Srgb).map_err(|e| e.to_string())
                });
                (label, result)
            }
        };
        let tex = match result {
            Ok(t) => Arc::new(t),
            Err(e) => {
                self.warnings.push(format!(
                    "{}: {label}: {e}; using a placeholder texture",
                    self.path.display()
                ));
                placeholder_texture()
            }
        };
        self.images.insert(img.index(), tex.clone());
        tex
    }

    fn material(&mut self, m: ::gltf::Material) -> usize {
        if let Some(&i) = self.materials.get(&m.index()) {
            return i;
        }
        let pbr = m.pbr_metallic_roughness();
        let mut out = if m.unlit() {
            Material::unlit(Rgba::from_array(pbr.base_color_factor()))
        } else {
            Material::lit(Rgba::from_array(pbr.base_color_factor()))
        };
        out.name = m.name().unwrap_or_default().to_string();
        out.double_sided = m.double_sided();
        out.alpha_mode = match m.alpha_mode() {
            ::gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            ::gltf::material::AlphaMode::Mask => AlphaMode::Mask {
                cutoff: m.alpha_cutoff().unwrap_or(0.5),
            },
            ::gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        };
        // The engine's emission is one constant colour. With an emissive texture the
        // factor only scales the texture (usually mostly black), so applying it alone
        // would light the whole surface: emission is dropped instead, with a warning.
        // KHR_materials_emissive_strength scales the factor past 1 (HDR emission).
        let strength = m.emissive_strength().filter(|s| s.is_finite() && *s >= 0.0);
        let e = m.emissive_factor().map(|c| c * strength.unwrap_or(1.0));
        if m.emissive_texture().is_none() {
            out.emissive = Rgba::new(e[0], e[1], e[2], 0.0);
        } else if e != [0.0; 3] {
            self.warnings.push(format!(
                "{}: material {:?}: emissive textures are not supported; emission ignored",
                self.path.display(),
                out.name
            ));
        }
        if let Some(info) = pbr.base_color_texture() {
            let tex = info.texture();
            let set = info
                .texture_transform()
                .and_then(|t| t.tex_coord())
                .unwrap_or(info.tex_coord());
            if set != 0 {
                self.warnings.push(format!(
                    "{}: material {:?} samples TEXCOORD_{set}; only TEXCOORD_0 is loaded",
                    self.path.display(),
                    out.name
                ));
            }
            out.base_texture = Some(self.image(tex.source()));
            let s = tex.sampler();
            let wrap = |w| match w {
                WrappingMode::ClampToEdge => Wrap::Clamp,
                WrappingMode::MirroredRepeat => Wrap::Mirror,
                WrappingMode::Repeat => Wrap::Repeat,
            };
            let nearest = matches!(
                (s.mag_filter(), s.min_filter()),
                (Some(MagFilter::Nearest), _)
                    | (
                        None,
                        Some(MinFilter::Nearest | MinFilter::NearestMipmapNearest)
                    )
            );
            out.sampler = Sampler {
                wrap_u: wrap(s.wrap_s()),
                wrap_v: wrap(s.wrap_t()),
                filter: if nearest {
                    Filter::Nearest
                } else {
                    Filter::Trilinear
                },
            };
        }
        self.scene.materials.push(out);
        let i = self.scene.materials.len() - 1;
        self.materials.insert(m.index(), i);
        i
    }

    /// The scene mesh of a primitive, built on first use.
    fn primitive(
        &mut self,
        mesh: &::gltf::Mesh,
        prim: &::gltf::Primitive,
    ) -> Result<Option<usize>, LoadError> {
        let key = (mesh.index(), prim.index());
        if let Some(&m) = self.meshes.get(&key) {
            return Ok(m);
        }
        let label = format!(
            "mesh {} ('{}') primitive {}",
            mesh.index(),
            mesh.name().unwrap_or(""),
            prim.index()
        );
        let built = match prim.mode() {
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan => {
                let m = build_mesh(prim, &self.buffers, &mut self.warnings, &label)
                    .map_err(|r| LoadError::invalid(self.path, format!("{label}: {r}")))?;
                check_mesh(self.path, &label, &m)?;
                self.scene.meshes.push(m);
                Some(self.scene.meshes.len() - 1)
            }
            mode => {
                self.warnings.push(format!(
                    "{}: {label}: mode {mode:?} is not triangles; skipped",
                    self.path.display()
                ));
                None
            }
        };
        self.meshes.insert(key, built);
        Ok(built)
    }

    fn node(&mut self, node: &Node, world: Mat4, name: &str) -> Result<(), LoadError> {
        let Some(mesh) = node.mesh() else {
            return Ok(());
        };
        for prim in mesh.primitives() {
            if let Some(mi) = self.primitive(&mesh, &prim)? {
                let material = self.material(prim.material());
                self.scene.instances.push(Instance {
                    mesh: mi,
                    material,
                    transform: world,
                });
                self.names.push(name.to_string());
            }
        }
        Ok(())
    }
}

/// `uv' = offset + R(rotation) * (scale * uv)`, KHR_texture_transform's matrix.
fn transform_uv(t: &::gltf::texture::TextureTransform, uv: Vec2) -> Vec2 {
    let ([ox, oy], [sx, sy], r) = (t.offset(), t.scale(), t.rotation());
    let (s, c) = r.sin_cos();
    let (u, v) = (uv.x * sx, uv.y * sy);
    Vec2::new(ox + c * u + s * v, oy - s * u + c * v)
}

fn build_mesh(
    prim: &::gltf::Primitive,
    buffers: &[Cow<[u8]>],
    warnings: &mut Vec<String>,
    label: &str,
) -> Result<Mesh, String> {
    let pos = prim
        .get(&Semantic::Positions)
        .ok_or("no POSITION attribute")?;
    let (p, _) = read_f32(&pos, buffers, &[3])?;
    let n = p.len() / 3;
    let mut mesh = Mesh {
        positions: p.chunks_exact(3).map(Vec3::from_slice).collect(),
        ..Default::default()
    };
    let count_ok = |what: &str, got: usize| {
        if got == n {
            Ok(())
        } else {
            Err(format!("{what} has {got} entries for {n} positions"))
        }
    };
    if let Some(a) = prim.get(&Semantic::Normals) {
        let (v, _) = read_f32(&a, buffers, &[3])?;
        count_ok("NORMAL", v.len() / 3)?;
        mesh.normals = v
            .chunks_exact(3)
            .map(|c| Vec3::from_slice(c).normalize_or(Vec3::Y))
            .collect();
    }
    if let Some(a) = prim.get(&Semantic::TexCoords(0)) {
        let (v, _) = read_f32(&a, buffers, &[2])?;
        count_ok("TEXCOORD_0", v.len() / 2)?;
        let tt = prim
            .material()
            .pbr_metallic_roughness()
            .base_color_texture()
            .and_then(|i| i.texture_transform());
        mesh.uvs = v
            .chunks_exact(2)
            .map(|c| {
                let uv = Vec2::new(c[0], c[1]);
                tt.as_ref().map_or(uv, |t| transform_uv(t, uv))
            })
            .collect();
    }
    if let Some(a) = prim.get(&Semantic::Colors(0)) {
        let (v, k) = read_f32(&a, buffers, &[3, 4])?;
        count_ok("COLOR_0", v.len() / k)?;
        mesh.colors = v
            .chunks_exact(k)
            .map(|c| Rgba::new(c[0], c[1], c[2], if k == 4 { c[3] } else { 1.0 }))
            .collect();
    }
    let list: Vec<u32> = match prim.indices() {
        Some(a) => {
            let idx = read_indices(&a, buffers)?;
            if let Some(&bad) = idx.iter().find(|&&i| i as usize >= n) {
                return Err(format!("index {bad} out of range for {n} vertices"));
            }
            idx
        }
        None => (0..n as u32).collect(),
    };
    mesh.indices = match prim.mode() {
        Mode::TriangleStrip => (0..list.len().saturating_sub(2))
            .flat_map(|i| {
                let (a, b) = if i % 2 == 0 { (1, 2) } else { (2, 1) };
                [list[i], list[i + a], list[i + b]]
            })
            .collect(),
        Mode::TriangleFan => (0..list.len().saturating_sub(2))
            .flat_map(|i| [list[i + 1], list[i + 2], list[0]])
            .collect(),
        _ => {
            let mut l = list;
            let extra = l.len() % 3;
            if extra != 0 {
                warnings.push(format!(
                    "{label}: {} indices is not a multiple of 3; the last {extra} dropped",
                    l.len()
                ));
                l.truncate(l.len() - extra);
            }
            l
        }
    };
    Ok(mesh)
}

pub(crate) fn load(path: &Path, files: &dyn Files) -> Result<Loaded, LoadError> {
    let bytes = files.read(path, MAX_FILE_BYTES)?;
    check_glb_header(path, &bytes)?;
    let bytes = patch::optional_fields(&bytes);
    let gltf_error = |source| LoadError::Gltf {
        file: path.into(),
        source,
    };
    // Parse, pre-check what gltf-json's validation would index without checking, then
    // validate.
    let ::gltf::Gltf { document, blob } =
        ::gltf::Gltf::from_slice_without_validation(&bytes).map_err(gltf_error)?;
    precheck(path, &document)?;
    let mut warnings = Vec::new();
    extensions(path, &document, &mut warnings)?;
    let document = Document::from_json(document.into_json()).map_err(gltf_error)?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let buffers = load_buffers(path, &dir, &document, blob.as_deref(), files)?;
    let mut ctx = Ctx {
        path,
        files,
        dir,
        buffers,
        scene: Scene::default(),
        warnings,
        names: Vec::new(),
        meshes: HashMap::new(),
        materials: HashMap::new(),
        images: HashMap::new(),
    };
    let roots: Vec<Node> = match document
        .default_scene()
        .or_else(|| document.scenes().next())
    {
        Some(s) => s.nodes().collect(),
        None => {
            let mut is_child = vec![false; document.nodes().len()];
            for n in document.nodes() {
                for c in n.children() {
                    is_child[c.index()] = true;
                }
            }
            document.nodes().filter(|n| !is_child[n.index()]).collect()
        }
    };
    // Depth-first, children in order; each node once (a node reached again would mean a
    // cycle or a shared child, which glTF forbids).
    let mut visited = vec![false; document.nodes().len()];
    let mut stack: Vec<(Node, Mat4, String)> = roots
        .into_iter()
        .rev()
        .map(|n| (n, Mat4::IDENTITY, String::new()))
        .collect();
    while let Some((node, parent, parent_name)) = stack.pop() {
        if std::mem::replace(&mut visited[node.index()], true) {
            ctx.warnings.push(format!(
                "{}: node {} is reached twice (cycle or shared child); skipped",
                path.display(),
                node.index()
            ));
            continue;
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        let own = node
            .name()
            .map_or_else(|| format!("node{}", node.index()), str::to_string);
        let name = if parent_name.is_empty() {
            own
        } else {
            format!("{parent_name}/{own}")
        };
        ctx.node(&node, world, &name)?;
        let children: Vec<Node> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world, name.clone())));
    }
    if ctx.scene.instances.is_empty() {
        ctx.warnings.push(format!(
            "{}: no node of the scene has a mesh to draw: the scene is empty",
            path.display()
        ));
    }
    Ok(Loaded {
        scene: ctx.scene,
        warnings: ctx.warnings,
        names: ctx.names,
    })
}

//! Loader tests: every model of the shared assets' manifest loads with its listed triangle
//! count, and broken files written here (truncated GLB, bad indices, URIs leaving the
//! folder, huge sizes, missing textures, garbage OBJ, ...) give errors naming the file,
//! never panics.

use engine::load::fuzz::glb_container;
use engine::load::{self, LoadError, Loaded};
use engine::{AlphaMode, Encoding, Shading, Wrap};
use std::path::{Path, PathBuf};
use tests::assets;

/// A scratch folder under the system temp dir, removed on drop. Models go in `models/`,
/// so `../secret.bin` from a model is a real file that must still not be read.
struct Tmp(PathBuf);

impl Tmp {
    fn new(name: &str) -> Tmp {
        let d =
            std::env::temp_dir().join(format!("parallax-loaders-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(d.join("models")).unwrap();
        std::fs::write(d.join("secret.bin"), [7u8; 64]).unwrap();
        Tmp(d)
    }

    /// Writes `models/<name>` and returns its path.
    fn write(&self, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
        let p = self.0.join("models").join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    }
}

impl Drop for Tmp {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The message of an expected error, checked to name the file.
fn err_naming(r: Result<Loaded, LoadError>, file: &Path) -> String {
    let e = match r {
        Ok(l) => panic!(
            "{} loaded ({} triangles) but should fail",
            file.display(),
            l.scene.triangle_count()
        ),
        Err(e) => e,
    };
    let msg = e.to_string();
    let name = file.file_name().unwrap().to_string_lossy();
    assert!(msg.contains(&*name), "message does not name {name}: {msg}");
    assert!(!msg.contains('\n'), "message is not one line: {msg}");
    assert_eq!(e.file(), file);
    println!("ok: {msg}");
    msg
}

// ---------------------------------------------------------------------------------------
// glTF builders: one triangle, positions (36 bytes) then u16 indices (6 + 2 padding).

fn tri_bin(indices: [u16; 3]) -> Vec<u8> {
    let mut b = Vec::new();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for i in indices {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b.extend_from_slice(&[0, 0]);
    b
}

/// A one-triangle glTF. `buffer` is the buffer object's JSON, `prim` extra primitive
/// members, `extra` extra top-level members (both starting with a comma when non-empty).
fn tri_gltf(buffer: &str, prim: &str, extra: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
"nodes":[{{"mesh":0}}],
"meshes":[{{"name":"tri","primitives":[{{"attributes":{{"POSITION":0}},"indices":1{prim}}}]}}],
"buffers":[{buffer}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
{{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}]{extra}}}"#
    )
}

fn tri_glb(indices: [u16; 3]) -> Vec<u8> {
    glb_container(&tri_gltf(r#"{"byteLength":44}"#, "", ""), &tri_bin(indices))
}

// ---------------------------------------------------------------------------------------
// The shared assets.

#[test]
fn every_manifest_model_loads_with_its_triangle_count() {
    let Some(dir) = assets::require("every_manifest_model_loads_with_its_triangle_count") else {
        return;
    };
    let models = assets::manifest_models(&dir);
    assert!(models.len() >= 10, "manifest table not parsed: {models:?}");
    for m in &models {
        let path = dir.join(&m.file);
        let loaded = load::model(&path).unwrap_or_else(|e| panic!("{e}"));
        let scene = &loaded.scene;
        // Distinct meshes: instancing is not multiplied.
        let tris: usize = scene.meshes.iter().map(|x| x.triangle_count()).sum();
        assert_eq!(tris, m.triangles, "{}", m.file);
        for (i, mesh) in scene.meshes.iter().enumerate() {
            mesh.validate()
                .unwrap_or_else(|e| panic!("{} mesh {i}: {e}", m.file));
        }
        assert!(!scene.instances.is_empty(), "{}", m.file);
        println!(
            "{}: {tris} triangles, {} meshes, {} instances, {} warnings",
            m.file,
            scene.meshes.len(),
            scene.instances.len(),
            loaded.warnings.len()
        );
        for w in &loaded.warnings {
            println!("  warning: {w}");
        }
        // Every texture present loads for real (no placeholders).
        assert!(
            loaded.warnings.iter().all(|w| !w.contains("placeholder")),
            "{}: {:?}",
            m.file,
            loaded.warnings
        );
    }
}

#[test]
fn gltf_variants_of_one_model_agree() {
    let Some(dir) = assets::require("gltf_variants_of_one_model_agree") else {
        return;
    };
    let a = load::model(&dir.join("gltf/Box/glTF/Box.gltf")).unwrap();
    let b = load::model(&dir.join("gltf/Box/glTF-Binary/Box.glb")).unwrap();
    let c = load::model(&dir.join("gltf/Box/glTF-Embedded/Box.gltf")).unwrap();
    assert_eq!(a.scene, b.scene);
    assert_eq!(a.scene, c.scene);
    let t = load::model(&dir.join("gltf/BoxTextured/glTF/BoxTextured.gltf")).unwrap();
    let tb = load::model(&dir.join("gltf/BoxTextured/glTF-Binary/BoxTextured.glb")).unwrap();
    assert_eq!(t.scene, tb.scene);
    let tex = t.scene.materials[0]
        .base_texture
        .as_ref()
        .expect("textured");
    assert!(tex.width() > 8 && tex.encoding() == Encoding::Srgb);
    assert!(!t.scene.meshes[0].uvs.is_empty());
}

#[test]
fn gltf_materials_and_hierarchy_are_read() {
    let Some(dir) = assets::require("gltf_materials_and_hierarchy_are_read") else {
        return;
    };
    let alpha =
        load::model(&dir.join("gltf/AlphaBlendModeTest/glTF-Binary/AlphaBlendModeTest.glb"))
            .unwrap()
            .scene;
    let modes: Vec<AlphaMode> = alpha.materials.iter().map(|m| m.alpha_mode).collect();
    assert!(modes.contains(&AlphaMode::Blend), "{modes:?}");
    assert!(modes.contains(&AlphaMode::Opaque), "{modes:?}");
    assert!(
        modes.iter().any(|m| matches!(m, AlphaMode::Mask { .. })),
        "{modes:?}"
    );
    // The Duck's mesh hangs under transformed nodes.
    let duck = load::model(&dir.join("gltf/Duck/glTF/Duck.gltf"))
        .unwrap()
        .scene;
    assert!(duck
        .instances
        .iter()
        .any(|i| i.transform != glam::Mat4::IDENTITY));
    assert!(matches!(duck.materials[0].shading, Shading::Lit { .. }));
    let helmet = load::model(&dir.join("gltf/DamagedHelmet/glTF-Binary/DamagedHelmet.glb"))
        .unwrap()
        .scene;
    // Its emission comes from a texture, which the engine cannot apply: dropped.
    assert_eq!(helmet.materials[0].emissive.r, 0.0);
}

#[test]
fn obj_assets_keep_file_order_and_attributes() {
    let Some(dir) = assets::require("obj_assets_keep_file_order_and_attributes") else {
        return;
    };
    let suz = load::obj(&dir.join("obj/suzanne/suzanne.obj"))
        .unwrap()
        .scene;
    assert_eq!(suz.meshes.len(), 1);
    assert!(!suz.meshes[0].normals.is_empty());
    let m = &suz.materials[0];
    assert!(matches!(m.shading, Shading::Lit { .. }) && m.vertex_colors);
    let spot = load::obj(&dir.join("obj/spot/spot_triangulated.obj"))
        .unwrap()
        .scene;
    assert!(!spot.meshes[0].uvs.is_empty());
    let tex = load::image(
        &dir.join("textures/kenney_simplespace_ship_C.png"),
        Encoding::Srgb,
    )
    .unwrap();
    assert_eq!((tex.width(), tex.height()), (64, 64));
}

// ---------------------------------------------------------------------------------------
// Files written here.

#[test]
fn small_gltf_and_glb_load() {
    let t = Tmp::new("ok");
    let bin = tri_bin([0, 1, 2]);
    t.write("tri.bin", &bin);
    let p = t.write(
        "tri.gltf",
        tri_gltf(r#"{"uri":"tri.bin","byteLength":44}"#, "", ""),
    );
    let a = load::gltf(&p).unwrap();
    assert_eq!(a.scene.triangle_count(), 1);
    assert_eq!(a.scene.meshes[0].indices, [0, 1, 2]);
    let b = load::gltf(&t.write("tri.glb", tri_glb([0, 1, 2]))).unwrap();
    assert_eq!(a.scene, b.scene);
    // Base64 data: URI, and a percent-encoded file name.
    let uri = format!("data:application/octet-stream;base64,{}", base64(&bin));
    let c = load::gltf(&t.write(
        "embedded.gltf",
        tri_gltf(&format!(r#"{{"uri":"{uri}","byteLength":44}}"#), "", ""),
    ))
    .unwrap();
    assert_eq!(a.scene, c.scene);
    t.write("my tri.bin", &bin);
    let d = t.write(
        "pct.gltf",
        tri_gltf(r#"{"uri":"my%20tri.bin","byteLength":44}"#, "", ""),
    );
    assert_eq!(load::gltf(&d).unwrap().scene, a.scene);
}

fn base64(b: &[u8]) -> String {
    const A: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in b.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

#[test]
fn strips_and_fans_become_triangles() {
    let t = Tmp::new("modes");
    // 5 vertices on a zig-zag; non-indexed.
    let mut bin = Vec::new();
    for v in [
        0.0f32, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 2.0, 0.0, 0.0,
    ] {
        bin.extend_from_slice(&v.to_le_bytes());
    }
    for (mode, want) in [
        (5, vec![0, 1, 2, 1, 3, 2, 2, 3, 4]),
        (6, vec![1, 2, 0, 2, 3, 0, 3, 4, 0]),
    ] {
        let json = format!(
            r#"{{"asset":{{"version":"2.0"}},"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"mode":{mode}}},{{"attributes":{{"POSITION":0}},"mode":1}}]}}],
"buffers":[{{"byteLength":60}}],"bufferViews":[{{"buffer":0,"byteLength":60}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":5,"type":"VEC3","min":[0,0,0],"max":[2,1,0]}}]}}"#
        );
        let p = t.write(&format!("mode{mode}.glb"), glb_container(&json, &bin));
        let l = load::gltf(&p).unwrap();
        assert_eq!(l.scene.meshes.len(), 1, "lines primitive skipped");
        assert_eq!(l.scene.meshes[0].indices, want, "mode {mode}");
        assert!(
            l.warnings.iter().any(|w| w.contains("skipped")),
            "{:?}",
            l.warnings
        );
    }
}

#[test]
fn broken_gltf_files_give_errors_naming_the_file() {
    let t = Tmp::new("broken");
    t.write("tri.bin", tri_bin([0, 1, 2]));

    // Truncated GLB, at every length (none may panic), and a header length below 12.
    let whole = tri_glb([0, 1, 2]);
    for n in 0..whole.len() {
        let p = t.write("truncated.glb", &whole[..n]);
        err_naming(load::gltf(&p), &p);
    }
    let mut short = whole.clone();
    short[8..12].copy_from_slice(&4u32.to_le_bytes());
    let p = t.write("short.glb", &short);
    err_naming(load::gltf(&p), &p);

    // Index out of range: the message names the mesh and primitive.
    let p = t.write("badindex.glb", tri_glb([0, 1, 7]));
    let msg = err_naming(load::gltf(&p), &p);
    assert!(
        msg.contains("out of range") && msg.contains("mesh 0") && msg.contains("primitive 0"),
        "{msg}"
    );

    // URIs that leave the folder, whatever they point at.
    let abs = t.0.join("secret.bin");
    for (name, uri) in [
        ("parent.gltf", "../secret.bin".to_string()),
        ("pct-parent.gltf", "%2e%2e/secret.bin".to_string()),
        ("absolute.gltf", abs.display().to_string()),
        ("http.gltf", "http://example.com/tri.bin".to_string()),
        ("file.gltf", format!("file://{}", abs.display())),
    ] {
        let p = t.write(
            name,
            tri_gltf(&format!(r#"{{"uri":"{uri}","byteLength":44}}"#), "", ""),
        );
        let msg = err_naming(load::gltf(&p), &p);
        assert!(msg.contains("buffer 0"), "{msg}");
    }
    // The same for an image URI (refused before any buffer is read).
    let p = t.write(
        "image-parent.gltf",
        tri_gltf(
            r#"{"uri":"tri.bin","byteLength":44}"#,
            r#","material":0"#,
            r#","materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],
"textures":[{"source":0}],"images":[{"uri":"../secret.png"}]"#,
        ),
    );
    err_naming(load::gltf(&p), &p);

    // Sizes: a huge byteLength, a byteLength longer than the file, an accessor count
    // longer than its view.
    let p = t.write(
        "huge.gltf",
        tri_gltf(r#"{"uri":"tri.bin","byteLength":1000000000000}"#, "", ""),
    );
    let msg = err_naming(load::gltf(&p), &p);
    assert!(msg.contains("byteLength"), "{msg}");
    let p = t.write(
        "long.gltf",
        tri_gltf(r#"{"uri":"tri.bin","byteLength":4400}"#, "", ""),
    );
    err_naming(load::gltf(&p), &p);
    let json = tri_gltf(r#"{"byteLength":44}"#, "", "").replace(
        r#""count":3,"type":"VEC3""#,
        r#""count":4000000000,"type":"VEC3""#,
    );
    let p = t.write("count.glb", glb_container(&json, &tri_bin([0, 1, 2])));
    err_naming(load::gltf(&p), &p);
    let json = tri_gltf(r#"{"byteLength":44}"#, "", "").replace(
        r#""byteOffset":36,"byteLength":6"#,
        r#""byteOffset":36,"byteLength":600"#,
    );
    let p = t.write("view.glb", glb_container(&json, &tri_bin([0, 1, 2])));
    err_naming(load::gltf(&p), &p);

    // Not glTF at all, and a file that does not exist.
    let p = t.write("garbage.gltf", "this is not json");
    err_naming(load::gltf(&p), &p);
    let p = t.0.join("models").join("nonexistent.gltf");
    err_naming(load::gltf(&p), &p);
    err_naming(load::model(&p), &p);
    let p = t.write("model.fbx", "x");
    err_naming(load::model(&p), &p);
}

#[test]
fn missing_texture_loads_with_a_placeholder_and_a_warning() {
    let t = Tmp::new("texture");
    t.write("tri.bin", tri_bin([0, 1, 2]));
    let materials = r#","materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],
"textures":[{"source":0,"sampler":0}],"samplers":[{"magFilter":9728,"wrapS":33071}],
"images":[{"uri":"missing.png"}]"#;
    let p = t.write(
        "missing-tex.gltf",
        tri_gltf(
            r#"{"uri":"tri.bin","byteLength":44}"#,
            r#","material":0"#,
            materials,
        ),
    );
    let l = load::gltf(&p).unwrap();
    assert!(
        l.warnings
            .iter()
            .any(|w| w.contains("missing.png") && w.contains("placeholder")),
        "{:?}",
        l.warnings
    );
    let m = &l.scene.materials[0];
    assert_eq!(
        m.base_texture.as_deref(),
        Some(&*load::placeholder_texture())
    );
    assert_eq!(m.sampler.filter, engine::Filter::Nearest);
    assert_eq!(
        (m.sampler.wrap_u, m.sampler.wrap_v),
        (Wrap::Clamp, Wrap::Repeat)
    );
    // An undecodable one too.
    t.write("missing.png", "not a png");
    let l = load::gltf(&p).unwrap();
    assert!(
        l.warnings.iter().any(|w| w.contains("placeholder")),
        "{:?}",
        l.warnings
    );
}

// ---------------------------------------------------------------------------------------
// OBJ.

#[test]
fn obj_with_mtl_texture_and_vertex_colours() {
    let t = Tmp::new("obj");
    std::fs::create_dir_all(t.0.join("models/mat/tex")).unwrap();
    let img = image::RgbaImage::from_pixel(4, 2, image::Rgba([255, 0, 0, 255]));
    img.save(t.0.join("models/mat/tex/red.png")).unwrap();
    t.write(
        "mat/quad.mtl",
        "newmtl glass\nKd 0.5 0.25 1\nKs 0.5 0.5 0.5\nNs 64\nd 0.5\nmap_Kd tex/red.png\n",
    );
    let p = t.write(
        "quad.obj",
        "mtllib mat/quad.mtl\n\
         v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 1 1 1\n\
         vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
         o first\nusemtl glass\nf 1/1 2/2 3/3 4/4\n\
         o second\nf 1/1 3/3 4/4\n",
    );
    let l = load::obj(&p).unwrap();
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    let s = &l.scene;
    assert_eq!(s.meshes.len(), 2);
    assert_eq!(s.instances.len(), 2);
    let q = &s.meshes[0];
    assert_eq!(q.triangle_count(), 2);
    // Fan order: (1 2 3) (1 3 4), as positions.
    let tri = |k: usize| [0, 1, 2].map(|j| q.positions[q.indices[3 * k + j] as usize]);
    assert_eq!(tri(1)[2], glam::Vec3::new(0.0, 1.0, 0.0));
    assert_eq!(
        q.colors[q.indices[2] as usize],
        engine::Rgba::new(0.0, 0.0, 1.0, 1.0)
    );
    // v flipped: OBJ vt (1, 1) -> (1, 0).
    assert_eq!(q.uvs[q.indices[2] as usize], glam::Vec2::new(1.0, 0.0));
    let m = &s.materials[0];
    assert_eq!(m.base_color, engine::Rgba::new(0.5, 0.25, 1.0, 0.5));
    assert_eq!(m.alpha_mode, AlphaMode::Blend);
    assert_eq!(
        m.shading,
        Shading::Lit {
            specular: 0.5,
            shininess: 64.0
        }
    );
    assert_eq!(m.base_texture.as_ref().unwrap().width(), 4);
    // `usemtl` stays in force across `o`.
    assert_eq!(s.materials[1].name, "glass");
    // Without an MTL: the default lit white, vertex colours on.
    let p2 = t.write("plain.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let plain = load::obj(&p2).unwrap().scene;
    assert_eq!(plain.materials[0].base_color, engine::Rgba::WHITE);
    assert!(plain.materials[0].vertex_colors);
    assert!(matches!(plain.materials[0].shading, Shading::Lit { .. }));
    assert!(plain.meshes[0].colors.is_empty());

    // A missing texture is a warning, not an error.
    std::fs::remove_file(t.0.join("models/mat/tex/red.png")).unwrap();
    let l = load::obj(&p).unwrap();
    assert!(
        l.warnings.iter().any(|w| w.contains("red.png")),
        "{:?}",
        l.warnings
    );
}

#[test]
fn broken_obj_files_give_errors_naming_the_file() {
    let t = Tmp::new("badobj");
    for (name, text) in [
        ("garbage.obj", "hello world\nthis is not an obj file\n"),
        ("binary.obj", "\u{0}\u{1}\u{2}"),
        ("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"),
        ("negative.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n"),
        ("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
        (
            "overflow.obj",
            "v 0 0 0\nvt 0 0\nf 1/-9223372036854775807 1/1 1/1\n",
        ),
        ("badnum.obj", "v 0 zero 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
    ] {
        let p = t.write(name, text);
        let msg = err_naming(load::obj(&p), &p);
        if name == "range.obj" {
            assert!(
                msg.contains("out of range") && msg.contains("line 4"),
                "{msg}"
            );
        }
    }
    let p = t.write("notutf8.obj", [b'v', b' ', 0xff, 0xfe]);
    err_naming(load::obj(&p), &p);
    let p = t.0.join("models/nonexistent.obj");
    err_naming(load::obj(&p), &p);
    // A broken MTL (tobj would panic on `Kd 1 2`) only costs the materials.
    t.write("bad.mtl", "newmtl m\nKd 1 2\n");
    let p = t.write(
        "badmtl.obj",
        "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n",
    );
    let l = load::obj(&p).unwrap();
    assert!(
        l.warnings.iter().any(|w| w.contains("bad.mtl")),
        "{:?}",
        l.warnings
    );
}

#[test]
fn image_loader_reports_bad_files() {
    let t = Tmp::new("image");
    let p = t.write("bad.png", "not an image");
    let e = load::image(&p, Encoding::Srgb).unwrap_err().to_string();
    assert!(e.contains("bad.png"), "{e}");
    let p = t.0.join("models/none.png");
    let e = load::image(&p, Encoding::Unorm).unwrap_err().to_string();
    assert!(e.contains("none.png"), "{e}");
}

/// A richer one-triangle GLB: normals, uvs, colours (u8 normalised), a texture embedded
/// through a bufferView, a node hierarchy and a sparse accessor.
fn rich_glb() -> (String, Vec<u8>) {
    let mut bin = tri_bin([0, 1, 2]); // 0..36 positions, 36..42 indices (+2)
    for _ in 0..3 {
        bin.extend_from_slice(&[0; 8]);
        bin.extend_from_slice(&1.0f32.to_le_bytes()); // normal (0, 0, 1)
    } // 44..80 normals (12 bytes each)
    for v in [0.0f32, 0.0, 1.0, 0.0, 0.0, 1.0] {
        bin.extend_from_slice(&v.to_le_bytes());
    } // 80..104 uvs
    bin.extend_from_slice(&[255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255]); // 104..116
    bin.extend_from_slice(&[1, 0, 0, 0]); // 116..120 sparse index (u8) + pad
    bin.extend_from_slice(&0.5f32.to_le_bytes()); // 120..124: sparse value... padded below
    bin.extend_from_slice(&[0; 8]); // 124..132: completes a VEC3 value
    let mut png = Vec::new();
    image::RgbaImage::from_pixel(2, 2, image::Rgba([10, 20, 30, 255]))
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap();
    let png_at = bin.len();
    bin.extend_from_slice(&png);
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
"nodes":[{{"children":[1],"translation":[1,2,3]}},{{"mesh":0,"scale":[2,2,2]}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"NORMAL":2,"TEXCOORD_0":3,"COLOR_0":4}},"indices":1,"material":0,"mode":4}}]}}],
"materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0}}}},"alphaMode":"MASK","alphaCutoff":0.25,"doubleSided":true,
"emissiveFactor":[0.25,0.5,0.75]}}],
"textures":[{{"source":0,"sampler":0}}],"samplers":[{{"wrapS":33648}}],
"images":[{{"bufferView":5,"mimeType":"image/png"}}],
"buffers":[{{"byteLength":{len}}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}},
{{"buffer":0,"byteOffset":44,"byteLength":36}},{{"buffer":0,"byteOffset":80,"byteLength":24}},
{{"buffer":0,"byteOffset":104,"byteLength":12}},{{"buffer":0,"byteOffset":{png_at},"byteLength":{png_len}}},
{{"buffer":0,"byteOffset":116,"byteLength":4}},{{"buffer":0,"byteOffset":120,"byteLength":12}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0],
"sparse":{{"count":1,"indices":{{"bufferView":6,"componentType":5121}},"values":{{"bufferView":7}}}}}},
{{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}},
{{"bufferView":2,"componentType":5126,"count":3,"type":"VEC3"}},
{{"bufferView":3,"componentType":5126,"count":3,"type":"VEC2"}},
{{"bufferView":4,"componentType":5121,"normalized":true,"count":3,"type":"VEC4"}}]}}"#,
        len = bin.len(),
        png_len = png.len()
    );
    (json, bin)
}

#[test]
fn rich_glb_attributes_are_read() {
    let t = Tmp::new("rich");
    let (json, bin) = rich_glb();
    let l = load::gltf(&t.write("rich.glb", glb_container(&json, &bin))).unwrap();
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    let s = &l.scene;
    let m = &s.meshes[0];
    // The sparse accessor moved vertex 1 to (0.5, 0, 0).
    assert_eq!(m.positions[1], glam::Vec3::new(0.5, 0.0, 0.0));
    assert_eq!(m.normals[2], glam::Vec3::Z);
    assert_eq!(m.uvs[1], glam::Vec2::new(1.0, 0.0));
    assert_eq!(m.colors[1], engine::Rgba::new(0.0, 1.0, 0.0, 1.0));
    let mat = &s.materials[0];
    assert_eq!(mat.alpha_mode, AlphaMode::Mask { cutoff: 0.25 });
    assert!(mat.double_sided);
    assert_eq!(mat.emissive, engine::Rgba::new(0.25, 0.5, 0.75, 0.0));
    assert_eq!(mat.sampler.wrap_u, Wrap::Mirror);
    assert_eq!(mat.base_texture.as_ref().unwrap().width(), 2);
    let want = glam::Mat4::from_translation(glam::Vec3::new(1.0, 2.0, 3.0))
        * glam::Mat4::from_scale(glam::Vec3::splat(2.0));
    assert_eq!(s.instances[0].transform, want);
}

/// A deterministic xorshift generator for the mutation tests: `rand(n)` is in `0..n`.
fn fuzz_rng(mut seed: u64) -> impl FnMut(usize) -> usize {
    move |n: usize| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed % n as u64) as usize
    }
}

/// Mutation rounds: `default`, or `PARALLAX_FUZZ_ROUNDS=n` for more.
fn fuzz_rounds(default: usize) -> usize {
    std::env::var("PARALLAX_FUZZ_ROUNDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Counts a mutated file's outcome: a loaded scene must be valid, an error must name the file.
fn tally(r: Result<Loaded, LoadError>, file: &str, ok: &mut u32, err: &mut u32) {
    match r {
        Ok(l) => {
            *ok += 1;
            for m in &l.scene.meshes {
                m.validate().unwrap();
            }
        }
        Err(e) => {
            *err += 1;
            assert!(e.to_string().contains(file), "{e}");
        }
    }
}

/// Thousands of deterministic mutations of a valid GLB (numbers in the JSON replaced by
/// awkward values, bytes of the binary chunk flipped): the loader may succeed or fail but
/// must never panic, and what it returns must be valid. `PARALLAX_FUZZ_ROUNDS=n` runs more.
#[test]
fn mutated_glb_files_never_panic() {
    let t = Tmp::new("mutate");
    let (json, bin) = rich_glb();
    let mut rand = fuzz_rng(0x9e37_79b9_7f4a_7c15);
    let numbers: Vec<(usize, usize)> = {
        let b = json.as_bytes();
        let mut v = Vec::new();
        let mut i = 0;
        while i < b.len() {
            if b[i].is_ascii_digit() {
                let s = i;
                while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
                    i += 1;
                }
                v.push((s, i));
            } else {
                i += 1;
            }
        }
        v
    };
    let awkward = [
        "0",
        "1",
        "2",
        "3",
        "4",
        "5",
        "6",
        "7",
        "12",
        "36",
        "44",
        "255",
        "256",
        "5121",
        "5123",
        "5125",
        "5126",
        "65535",
        "4294967295",
        "4294967296",
        "18446744073709551615",
        "-1",
        "1e30",
        "0.5",
    ];
    let (mut ok, mut err) = (0, 0);
    let rounds = fuzz_rounds(3000);
    for round in 0..rounds {
        let mut j = json.clone();
        let mut b = bin.clone();
        for _ in 0..1 + rand(3) {
            if round % 4 == 3 && !b.is_empty() {
                let k = rand(b.len());
                b[k] ^= 1 << rand(8);
            } else {
                // Replace one number (ranges stay valid: replace from the end of the list).
                let (s, e) = numbers[rand(numbers.len())];
                if e <= j.len() {
                    j.replace_range(s..e, awkward[rand(awkward.len())]);
                }
            }
        }
        let p = t.write("m.glb", glb_container(&j, &b));
        tally(load::gltf(&p), "m.glb", &mut ok, &mut err);
    }
    println!("{ok} loaded, {err} refused");
    assert!(ok > 0 && err > 0);
}

/// Deterministic token mutations of an OBJ + MTL pair: errors or valid scenes, no panics.
#[test]
fn mutated_obj_files_never_panic() {
    let t = Tmp::new("mutate-obj");
    let obj = "mtllib m.mtl\nv 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 1 1 1\n\
               vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nusemtl a\nf 1/1/1 2/2/1 3/3/1 4/1/1\n\
               g second\nf -4//1 -3//1 -2//1\nl 1 2 3\nf 1 2\n";
    let mtl = "newmtl a\nKd 1 0.5 0\nKs 0.2 0.2 0.2\nNs 10\nd 0.5\nTr 0.2\nmap_Kd t.png\n";
    let awkward = [
        "0",
        "1",
        "-1",
        "-5",
        "4",
        "5",
        "1/1",
        "1//1",
        "/",
        "1/2/3/4",
        "x",
        "1e40",
        "nan",
        "-9223372036854775808",
        "9999999999999999999999",
        "f",
        "v",
        "l",
        "#",
        "Kd",
        "map_Kd",
        "usemtl",
        "mtllib",
        "newmtl",
        "",
    ];
    let mut rand = fuzz_rng(0x2545_f491_4f6c_dd1d);
    let mutate = |text: &str, rand: &mut dyn FnMut(usize) -> usize| {
        let mut lines: Vec<Vec<String>> = text
            .lines()
            .map(|l| l.split(' ').map(String::from).collect())
            .collect();
        for _ in 0..1 + rand(3) {
            let li = rand(lines.len());
            match rand(4) {
                0 => {
                    let l = lines[li].clone();
                    lines.insert(rand(lines.len()), l);
                }
                1 if lines.len() > 1 => {
                    lines.remove(li);
                }
                _ => {
                    let ti = rand(lines[li].len());
                    lines[li][ti] = awkward[rand(awkward.len())].to_string();
                }
            }
        }
        lines.iter().map(|l| l.join(" ") + "\n").collect::<String>()
    };
    let (mut ok, mut err) = (0, 0);
    let rounds = fuzz_rounds(2000);
    for _ in 0..rounds {
        t.write("m.mtl", mutate(mtl, &mut rand));
        let p = t.write("m.obj", mutate(obj, &mut rand));
        tally(load::obj(&p), "m.obj", &mut ok, &mut err);
    }
    println!("{ok} loaded, {err} refused");
    assert!(ok > 0 && err > 0);
}

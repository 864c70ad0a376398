//! Valid files with the optional parts of their formats left out must load: glTF 2.0
//! without `scenes`, a scene without `nodes`, no `meshes` or `materials`, sparse
//! accessors, extensions the loader reads or ignores; OBJ with per-face normals and OBJ
//! without faces. Every file is written here, by hand, from the specifications; loaded
//! from memory ([`load::Memory`]) and from disk alike.

use engine::load::fuzz::glb_container;
use engine::load::{self, Loaded, Memory};
use engine::Rgba;
use glam::Vec3;
use std::path::Path;

/// Loads `name` (its loader chosen by extension) from memory holding `files`, and from a
/// scratch folder holding the same files; both must agree. Returns the loaded model.
fn load_both(name: &str, files: &[(&str, &[u8])]) -> Loaded {
    let mut memory = Memory::default();
    for (n, b) in files {
        memory = memory.with(*n, *b);
    }
    let from_memory = load::model_from(Path::new(name), &memory)
        .unwrap_or_else(|e| panic!("{name} from memory: {e}"));
    let dir = std::env::temp_dir().join(format!(
        "parallax-valid-{}-{}",
        std::process::id(),
        name.replace('.', "-")
    ));
    std::fs::create_dir_all(&dir).unwrap();
    for (n, b) in files {
        std::fs::write(dir.join(n), b).unwrap();
    }
    let from_disk = load::model(&dir.join(name));
    let _ = std::fs::remove_dir_all(&dir);
    let from_disk = from_disk.unwrap_or_else(|e| panic!("{name} from disk: {e}"));
    assert_eq!(
        from_disk.scene, from_memory.scene,
        "{name}: disk and memory differ"
    );
    assert_eq!(
        from_disk.warnings.len(),
        from_memory.warnings.len(),
        "{name}"
    );
    from_memory
}

fn warned(l: &Loaded, what: &str) -> bool {
    l.warnings.iter().any(|w| w.contains(what))
}

fn f32s(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// One triangle (0,0,0) (1,0,0) (0,1,0), non-indexed, in `tri.bin`; `extra` goes into the
/// root object (starting with a comma), `node` is the node list's JSON.
fn triangle(scenes: &str, nodes: &str, material: &str, extra: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}}{scenes},"nodes":{nodes},
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}{material}}}]}}],
"buffers":[{{"uri":"tri.bin","byteLength":36}}],
"bufferViews":[{{"buffer":0,"byteLength":36}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
"min":[0,0,0],"max":[1,1,0]}}]{extra}}}"#
    )
}

fn tri_bin() -> Vec<u8> {
    f32s(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0])
}

#[test]
fn a_scene_without_nodes_loads_as_an_empty_scene_with_a_notice() {
    let json = r#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"name":"empty"}]}"#;
    for (name, bytes) in [
        ("empty.gltf", json.as_bytes().to_vec()),
        ("empty.glb", glb_container(json, &[])),
    ] {
        let l = load_both(name, &[(name, &bytes)]);
        assert!(l.scene.instances.is_empty(), "{name}");
        assert!(warned(&l, "the scene is empty"), "{name}: {:?}", l.warnings);
    }
    // A scene without nodes beside a node that has a mesh: the scene is what is drawn.
    let bin = tri_bin();
    let json = triangle(r#","scene":0,"scenes":[{}]"#, r#"[{"mesh":0}]"#, "", "");
    let l = load_both("t.gltf", &[("t.gltf", json.as_bytes()), ("tri.bin", &bin)]);
    assert!(l.scene.instances.is_empty());
}

#[test]
fn without_scenes_every_root_node_is_drawn() {
    let bin = tri_bin();
    let json = triangle(
        "",
        r#"[{"mesh":0,"translation":[5,0,0]},{"children":[2]},{"mesh":0}]"#,
        "",
        "",
    );
    let l = load_both("t.gltf", &[("t.gltf", json.as_bytes()), ("tri.bin", &bin)]);
    assert_eq!(
        l.scene.instances.len(),
        2,
        "root 0, and node 2 under root 1"
    );
    assert_eq!(l.scene.triangle_count(), 2);
    // No material: the default one (lit white, per the specification's default material).
    assert_eq!(l.scene.materials.len(), 1);
    assert_eq!(l.scene.materials[0].base_color, Rgba::WHITE);
}

#[test]
fn no_meshes_no_materials_no_nodes_load_empty() {
    for json in [
        r#"{"asset":{"version":"2.0"}}"#,
        r#"{"asset":{"version":"2.0"},"nodes":[{"name":"lonely"}]}"#,
        r#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{}]}"#,
    ] {
        let l = load_both("m.gltf", &[("m.gltf", json.as_bytes())]);
        assert!(l.scene.instances.is_empty(), "{json}");
        assert!(l.scene.meshes.is_empty() && l.scene.materials.is_empty());
        assert!(warned(&l, "the scene is empty"), "{json}: {:?}", l.warnings);
    }
}

#[test]
fn sparse_accessors_replace_the_listed_elements() {
    // Accessor 0: no bufferView (zeros) with three sparse positions, so the triangle
    // exists only through the sparse values. Accessor 1: dense positions with vertex 1
    // moved by a sparse value.
    let mut bin = Vec::new();
    bin.extend_from_slice(&[0u16, 1, 2].map(u16::to_le_bytes).concat()); // 0..6
    bin.extend_from_slice(&[0, 0]); // 6..8
    bin.extend(f32s(&[2.0, 0.0, 0.0, 0.0, 3.0, 0.0, 1.0, 1.0, 1.0])); // 8..44
    bin.extend_from_slice(&[1u8, 0, 0, 0]); // 44..48: one u8 index, padded
    bin.extend(f32s(&[4.0, 0.0, 0.0])); // 48..60
    bin.extend(tri_bin()); // 60..96
    let json = r#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[0,1]}],
"nodes":[{"mesh":0},{"mesh":1}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]},
          {"primitives":[{"attributes":{"POSITION":1}}]}],
"buffers":[{"byteLength":96}],
"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":6},
               {"buffer":0,"byteOffset":8,"byteLength":36},
               {"buffer":0,"byteOffset":44,"byteLength":1},
               {"buffer":0,"byteOffset":48,"byteLength":12},
               {"buffer":0,"byteOffset":60,"byteLength":36}],
"accessors":[
 {"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[2,3,1],
  "sparse":{"count":3,"indices":{"bufferView":0,"componentType":5123},
            "values":{"bufferView":1}}},
 {"bufferView":4,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[4,1,0],
  "sparse":{"count":1,"indices":{"bufferView":2,"componentType":5121},
            "values":{"bufferView":3}}}]}"#;
    let file = glb_container(json, &bin);
    let l = load_both("s.glb", &[("s.glb", &file)]);
    let positions: Vec<&[Vec3]> = l
        .scene
        .meshes
        .iter()
        .map(|m| m.positions.as_slice())
        .collect();
    assert_eq!(
        positions,
        [
            &[
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(0.0, 3.0, 0.0),
                Vec3::ONE
            ][..],
            &[Vec3::ZERO, Vec3::new(4.0, 0.0, 0.0), Vec3::Y][..],
        ]
    );
}

#[test]
fn extensions_are_read_ignored_with_a_warning_or_refused_when_required() {
    let bin = tri_bin();
    let material = r#","material":0"#;
    let extra = r#","extensionsUsed":["KHR_materials_emissive_strength","KHR_texture_transform",
"KHR_materials_clearcoat"],
"extensionsRequired":["KHR_materials_emissive_strength","KHR_texture_transform"],
"materials":[{"emissiveFactor":[1,0.5,0],
"extensions":{"KHR_materials_emissive_strength":{"emissiveStrength":4},
"KHR_materials_clearcoat":{"clearcoatFactor":1}}}]"#;
    let json = triangle(
        r#","scenes":[{"nodes":[0]}]"#,
        r#"[{"mesh":0}]"#,
        material,
        extra,
    );
    let l = load_both("x.gltf", &[("x.gltf", json.as_bytes()), ("tri.bin", &bin)]);
    assert_eq!(l.scene.triangle_count(), 1);
    assert_eq!(l.scene.materials[0].emissive, Rgba::new(4.0, 2.0, 0.0, 0.0));
    assert!(
        warned(&l, "KHR_materials_clearcoat is not supported; ignored"),
        "{:?}",
        l.warnings
    );
    assert!(!warned(&l, "KHR_texture_transform"), "{:?}", l.warnings);
    // Required but not read: refused, naming the file and the extension.
    let extra = r#","extensionsUsed":["KHR_draco_mesh_compression"],
"extensionsRequired":["KHR_draco_mesh_compression"]"#;
    let json = triangle(r#","scenes":[{"nodes":[0]}]"#, r#"[{"mesh":0}]"#, "", extra);
    let memory = Memory::default()
        .with("d.gltf", json.as_bytes())
        .with("tri.bin", bin);
    let e = load::gltf_from(Path::new("d.gltf"), &memory)
        .expect_err("a required extension it cannot read")
        .to_string();
    assert!(
        e.contains("d.gltf") && e.contains("requires extension KHR_draco_mesh_compression"),
        "{e}"
    );
}

#[test]
fn obj_with_per_face_normals_loads_them() {
    // One normal per face, shared by the face's corners (flat shading, as exporters write
    // it): a quad facing +Z and a triangle facing +X, with relative indices too.
    let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 0 -1\nv 2 1 0\n\
               vn 0 0 1\nvn 1 0 0\n\
               f 1//1 2//1 3//1 4//1\n\
               f -3//-1 -2//-1 -1//-1\n";
    let l = load_both("flat.obj", &[("flat.obj", obj.as_bytes())]);
    let mesh = &l.scene.meshes[0];
    assert_eq!(mesh.triangle_count(), 3);
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    for tri in mesh.indices.chunks_exact(3) {
        let n: Vec<Vec3> = tri.iter().map(|&i| mesh.normals[i as usize]).collect();
        let p: Vec<Vec3> = tri.iter().map(|&i| mesh.positions[i as usize]).collect();
        let face = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
        assert!(n.iter().all(|&v| v == n[0]), "one normal per face: {n:?}");
        assert!(
            n[0].dot(face) > 0.999,
            "the face's own normal: {n:?} {face}"
        );
    }
}

#[test]
fn obj_normal_and_texcoord_indices_naming_nothing_are_read_as_absent() {
    // Indices into normals and texcoords a file does not have, and index 0 ("none"), as
    // `tobj` reads them: the triangle loads without them, with a warning.
    for (name, text) in [
        ("no_vn.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 3//1\n"),
        (
            "no_vt.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1\n",
        ),
        (
            "zero.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//0 2//0 3//0\n",
        ),
    ] {
        let l = load_both(name, &[(name, text.as_bytes())]);
        assert_eq!(l.scene.triangle_count(), 1, "{name}");
        assert!(warned(&l, "read as absent"), "{name}: {:?}", l.warnings);
        if name == "no_vt.obj" {
            assert_eq!(l.scene.meshes[0].normals, [Vec3::Z; 3], "{name}");
        }
    }
}

#[test]
fn obj_without_faces_loads_as_an_empty_scene_with_a_notice() {
    for (name, text) in [
        ("nothing.obj", ""),
        ("comments.obj", "# exported by hand\n\n"),
        ("points.obj", "v 0 0 0\nv 1 0 0\np 1 2\n"),
    ] {
        let l = load_both(name, &[(name, text.as_bytes())]);
        assert!(l.scene.instances.is_empty(), "{name}");
        assert!(warned(&l, "the scene is empty"), "{name}: {:?}", l.warnings);
    }
    // Text that is not OBJ at all is still an error.
    let memory = Memory::default().with("prose.obj", "hello world\nnot an obj\n");
    let e = load::obj_from(Path::new("prose.obj"), &memory).expect_err("prose");
    assert!(e.to_string().contains("not an OBJ file"), "{e}");
}

#[test]
fn every_instance_is_named_after_its_object_or_node_path() {
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\no first\nf 1 2 3\no second\nf 1 3 2\n";
    let l = load_both("named.obj", &[("named.obj", obj)]);
    assert_eq!(l.names, ["first", "second"]);
    // glTF: root-to-node paths, unnamed nodes by index.
    let json = triangle(
        r#","scene":0,"scenes":[{"nodes":[0]}]"#,
        r#"[{"name":"a","children":[1,2],"mesh":0},{"mesh":0},{"name":"c","mesh":0}]"#,
        "",
        "",
    );
    let l = load_both(
        "named.gltf",
        &[("named.gltf", json.as_bytes()), ("tri.bin", &tri_bin())],
    );
    assert_eq!(l.names, ["a", "a/node1", "a/c"]);
    assert_eq!(l.names.len(), l.scene.instances.len());
}

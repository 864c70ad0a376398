//! LDI portals read from a glTF file whose node names mark them (`portal.<room>` for the
//! opening, `room.<room>` for what lies behind it): the file is written here by hand, loaded
//! with the engine's loader, and its portals drawn against the same scene as geometry.

use engine::load::{self, Memory};
use engine::{Camera, Draw, FrameOptions, Lighting, Renderer, Rgba, Target};
use glam::Vec3;
use ibr::portal::{from_scene, MarkError, PortalConfig, PortalMode, Portals};
use ibr::technique::{FrameLoop, FrameView, Technique};
use std::path::Path;

/// A unit-ish quad (x in [-0.6, 0.6], y in [0, 2], z = 0, facing +z: counter-clockwise
/// seen from +z) as mesh 0, and a big quad (x, y in [-4, 4]) as mesh 1; `nodes` and the
/// scene's root list are the caller's.
fn gltf(nodes: &str, roots: &str) -> (String, Vec<u8>) {
    let pos: [[f32; 3]; 8] = [
        [-0.6, 0.0, 0.0],
        [0.6, 0.0, 0.0],
        [0.6, 2.0, 0.0],
        [-0.6, 2.0, 0.0],
        [-4.0, -4.0, 0.0],
        [4.0, -4.0, 0.0],
        [4.0, 4.0, 0.0],
        [-4.0, 4.0, 0.0],
    ];
    let mut bin: Vec<u8> = pos.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
    for i in [0u16, 1, 2, 0, 2, 3] {
        bin.extend(i.to_le_bytes());
    }
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":{roots}}}],
"nodes":{nodes},
"materials":[{{"pbrMetallicRoughness":{{"baseColorFactor":[0.8,0.3,0.2,1]}},"doubleSided":true}},
 {{"pbrMetallicRoughness":{{"baseColorFactor":[0.2,0.5,0.8,1]}},"doubleSided":true}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":2,"material":0}}]}},
 {{"primitives":[{{"attributes":{{"POSITION":1}},"indices":2,"material":1}}]}}],
"buffers":[{{"uri":"scene.bin","byteLength":{len}}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":48}},
 {{"buffer":0,"byteOffset":96,"byteLength":12}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[-0.6,0,0],"max":[0.6,2,0]}},
 {{"bufferView":1,"componentType":5126,"count":4,"type":"VEC3","min":[-4,-4,0],"max":[4,4,0]}},
 {{"bufferView":2,"componentType":5123,"count":6,"type":"SCALAR"}}]}}"#,
        len = bin.len()
    );
    (json, bin)
}

fn load(nodes: &str, roots: &str) -> load::Loaded {
    let (json, bin) = gltf(nodes, roots);
    let files = Memory::default()
        .with("scene.gltf", json.as_bytes())
        .with("scene.bin", &bin[..]);
    load::model_from(Path::new("scene.gltf"), &files).expect("a valid file")
}

/// A wall of the hall (mesh 1 far to the side, as near geometry), the doorway marker, and
/// the room: a back wall and a panel, below a `room.kitchen` node.
const NODES: &str = r#"[
 {"name":"hall","mesh":1,"translation":[0,0,3],"scale":[0.1,0.1,1]},
 {"name":"portal.kitchen","mesh":0},
 {"name":"room.kitchen","children":[3,4]},
 {"name":"back","mesh":1,"translation":[0,0,-5]},
 {"name":"panel","mesh":0,"translation":[0.2,0.1,-2]}
]"#;

#[test]
fn node_names_mark_the_opening_and_the_room_behind_it() {
    let loaded = load(NODES, "[0,1,2]");
    assert_eq!(
        loaded.names,
        [
            "hall",
            "portal.kitchen",
            "room.kitchen/back",
            "room.kitchen/panel"
        ]
    );
    let marked = from_scene(&loaded.scene, &loaded.names).expect("marked");
    assert_eq!(marked.near, [0]);
    assert_eq!(marked.portals.len(), 1);
    let p = &marked.portals[0];
    assert_eq!(p.behind.parts.len(), 2);
    assert!(
        p.opening.normal().z > 0.999,
        "faces +z: {}",
        p.opening.normal()
    );
    assert!((p.opening.center() - Vec3::new(0.0, 1.0, 0.0)).length() < 1e-5);

    // Drawn through the portal from the near side, the doorway shows the room as the
    // geometry does.
    let (w, h) = (96, 72);
    let cam = Camera::look_at(
        Vec3::new(0.2, 1.2, 3.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::Y,
        1.0,
        4.0 / 3.0,
    )
    .with_depth_range(0.05, 50.0);
    let lighting = Lighting {
        ambient: Rgba::WHITE,
        lights: Vec::new(),
    };
    let config = PortalConfig {
        views_per_frame: 5,
        ..PortalConfig::default()
    };
    let mut portals = Portals::new(marked.portals, config);
    let scene = &loaded.scene;
    let near: Vec<Draw> = marked
        .near
        .iter()
        .map(|&i| {
            let inst = &scene.instances[i];
            Draw {
                mesh: &scene.meshes[inst.mesh],
                material: &scene.materials[inst.material],
                transform: inst.transform,
            }
        })
        .collect();
    let view = FrameView {
        camera: &cam,
        width: w,
        height: h,
        lighting: &lighting,
        time: 0.0,
        dt: 0.0,
    };
    let mut frame = Target::new(w, h);
    let mut list: [&mut dyn Technique; 1] = [&mut portals];
    FrameLoop::new().render(
        &mut Renderer::new(),
        near.iter().copied(),
        &mut list,
        &view,
        &mut frame,
        &FrameOptions::default(),
    );
    assert_eq!(portals.portals[0].mode(), PortalMode::Warped);
    let mut truth = Target::new(w, h);
    let mut all = near.clone();
    portals.reference(&mut all);
    Renderer::new().render(all, &cam, &lighting, &mut truth, &FrameOptions::default());
    let outline = portals.portals[0]
        .opening
        .outline(&cam, w, h)
        .expect("on screen");
    let [x0, y0, x1, y1] = outline.bounds;
    let (mut n, mut off) = (0, 0);
    for y in y0..y1 {
        for x in x0..x1 {
            if outline.contains(x, y) {
                n += 1;
                let (a, b) = (frame.pixel(x, y).unwrap(), truth.pixel(x, y).unwrap());
                let (a, b) = (a.to_le_bytes(), b.to_le_bytes());
                off += (0..3).any(|k| a[k].abs_diff(b[k]) > 24) as u32;
            }
        }
    }
    assert!(n > 300 && off * 10 < n, "{off} of {n} doorway pixels off");
}

#[test]
fn bad_markers_are_errors_naming_the_node() {
    // A room with no opening.
    let l = load(NODES, "[0,2]");
    let e = from_scene(&l.scene, &l.names).unwrap_err();
    assert!(
        matches!(e, MarkError::NoPortal { ref room, .. } if room == "kitchen"),
        "{e}"
    );
    assert!(e.to_string().contains("room.kitchen"), "{e}");
    // An opening with nothing behind it.
    let l = load(NODES, "[0,1]");
    let e = from_scene(&l.scene, &l.names).unwrap_err();
    assert!(matches!(e, MarkError::NoRoom { .. }), "{e}");
    // A names list of the wrong length.
    let l = load(NODES, "[0,1,2]");
    assert!(matches!(
        from_scene(&l.scene, &l.names[..1]),
        Err(MarkError::Names { .. })
    ));
    // Two openings for one room.
    let l2 = load(
        &NODES.replace(
            r#"{"name":"hall","mesh":1,"translation":[0,0,3],"scale":[0.1,0.1,1]}"#,
            r#"{"name":"portal.kitchen","mesh":0,"translation":[2,0,0]}"#,
        ),
        "[0,1,2]",
    );
    let e = from_scene(&l2.scene, &l2.names).unwrap_err();
    assert!(matches!(e, MarkError::TwoPortals { .. }), "{e}");
    // An opening flattened to a line: not a quad.
    let tri = load(
        &NODES.replace(
            r#"{"name":"portal.kitchen","mesh":0}"#,
            r#"{"name":"portal.kitchen","mesh":0,"scale":[1,0,1]}"#,
        ),
        "[0,1,2]",
    );
    let e = from_scene(&tri.scene, &tri.names).unwrap_err();
    assert!(
        matches!(e, MarkError::NotAQuad { ref node, .. } if node == "portal.kitchen"),
        "{e}"
    );
}

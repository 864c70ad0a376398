//! The sample model the project ships (`assets/models/`, written by
//! `demos/examples/make_sample.rs`): both files load without warnings and agree, every file
//! they name is in their folder, and `render`'s default view (no camera flags) shows it
//! whole, where the model's own vertices project.

use engine::load::{self, Disk, Files, LoadError};
use glam::Vec3;
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::Tmp;

fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/models")
}

/// The bounds of every mesh vertex, placed by its instance.
fn bounds(scene: &engine::Scene) -> (Vec3, Vec3) {
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for inst in &scene.instances {
        for p in &scene.meshes[inst.mesh].positions {
            let p = inst.transform.transform_point3(*p);
            (lo, hi) = (lo.min(p), hi.max(p));
        }
    }
    (lo, hi)
}

#[test]
fn gltf_and_obj_load_without_warnings_and_agree() {
    let gltf = load::model(&models().join("sample.gltf")).expect("sample.gltf loads");
    let obj = load::model(&models().join("sample.obj")).expect("sample.obj loads");
    for (name, l) in [("gltf", &gltf), ("obj", &obj)] {
        assert!(l.warnings.is_empty(), "{name}: {:?}", l.warnings);
        let tris = l.scene.triangle_count();
        assert!((500..=5000).contains(&tris), "{name}: {tris} triangles");
        // Four materials; the stone's texture is the 64 x 64 image, not the placeholder.
        assert_eq!(l.scene.materials.len(), 4, "{name}");
        let textured: Vec<_> = l
            .scene
            .materials
            .iter()
            .filter_map(|m| m.base_texture.as_ref())
            .collect();
        assert_eq!(textured.len(), 1, "{name}");
        assert_eq!(
            (textured[0].width(), textured[0].height()),
            (64, 64),
            "{name}"
        );
        for m in &l.scene.meshes {
            let n = m.positions.len();
            assert!(
                m.normals.len() == n && m.uvs.len() == n && m.colors.len() == n,
                "{name}"
            );
            assert!(
                m.normals.iter().all(|v| (v.length() - 1.0).abs() < 1e-3),
                "{name}"
            );
        }
        // About 2 units tall, standing centred on the origin: render's default view.
        let (lo, hi) = bounds(&l.scene);
        assert!(
            (lo.y + 1.0).abs() < 1e-4 && (hi.y - 1.0).abs() < 1e-4,
            "{name}: {lo} {hi}"
        );
        assert!(
            lo.x.max(lo.z) < -0.8 && hi.x.min(hi.z) > 0.8,
            "{name}: {lo} {hi}"
        );
        assert!(
            lo.x.min(lo.z) > -1.0 && hi.x.max(hi.z) < 1.0,
            "{name}: {lo} {hi}"
        );
    }
    // The twins: the same triangles (OBJ text rounds positions to 1e-5).
    assert_eq!(gltf.scene.triangle_count(), obj.scene.triangle_count());
    let (a, b) = (bounds(&gltf.scene), bounds(&obj.scene));
    assert!(
        a.0.abs_diff_eq(b.0, 1e-4) && a.1.abs_diff_eq(b.1, 1e-4),
        "{a:?} {b:?}"
    );
    let area = |s: &engine::Scene| -> f32 {
        let tri = |m: &engine::Mesh, t: &[u32]| {
            let [p, q, r] = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
            (q - p).cross(r - p).length() / 2.0
        };
        s.meshes
            .iter()
            .map(|m| m.indices.chunks(3).map(|t| tri(m, t)).sum::<f32>())
            .sum()
    };
    assert!((area(&gltf.scene) - area(&obj.scene)).abs() < 1e-3 * area(&gltf.scene));
}

/// Records every file a loader reads, reading it from the disk.
#[derive(Default)]
struct Recorder(RefCell<Vec<PathBuf>>);

impl Files for Recorder {
    fn read(&self, path: &Path, cap: u64) -> Result<Vec<u8>, LoadError> {
        self.0.borrow_mut().push(path.to_path_buf());
        Disk.read(path, cap)
    }
    fn read_inside(
        &self,
        dir: &Path,
        rel: &Path,
        need: Option<u64>,
        cap: u64,
    ) -> Result<Vec<u8>, String> {
        self.0.borrow_mut().push(dir.join(rel));
        Disk.read_inside(dir, rel, need, cap)
    }
}

/// The values of `"key":"..."` in a JSON text (the generator writes no spaces there).
fn strings<'a>(json: &'a str, key: &str) -> Vec<&'a str> {
    let pat = format!("\"{key}\":\"");
    json.match_indices(&pat)
        .map(|(i, _)| {
            let rest = &json[i + pat.len()..];
            &rest[..rest.find('"').expect("closing quote")]
        })
        .collect()
}

#[test]
fn every_file_named_is_in_the_folder() {
    let dir = models();
    let json = std::fs::read_to_string(dir.join("sample.gltf")).unwrap();
    // Read as the glTF specification has it: each URI a plain relative file name.
    let uris = strings(&json, "uri");
    assert_eq!(uris, ["sample_stone.png", "sample.bin"]);
    for uri in &uris {
        assert!(
            !uri.contains(['/', '\\', ':']) && !uri.starts_with('.'),
            "{uri}"
        );
        assert!(dir.join(uri).is_file(), "{uri} missing");
    }
    let bin = std::fs::metadata(dir.join("sample.bin")).unwrap().len();
    let declared = json.split("\"byteLength\":").nth(1).unwrap();
    let declared: u64 = declared[..declared.find('}').unwrap()].parse().unwrap();
    // The buffer is the first `byteLength` in the file, and matches the file's size.
    assert!(json.find("\"buffers\"").unwrap() < json.find("\"byteLength\":").unwrap());
    assert_eq!(declared, bin);
    // The OBJ's material library and texture, by the MTL format: plain names beside it.
    let obj = std::fs::read_to_string(dir.join("sample.obj")).unwrap();
    let mtl = std::fs::read_to_string(dir.join("sample.mtl")).unwrap();
    assert!(obj.lines().any(|l| l == "mtllib sample.mtl"));
    assert_eq!(
        mtl.lines()
            .filter(|l| l.starts_with("map_Kd"))
            .collect::<Vec<_>>(),
        ["map_Kd sample_stone.png"]
    );
    // And the loaders read exactly those files, all in the folder.
    for (model, expected) in [
        (
            "sample.gltf",
            ["sample.gltf", "sample.bin", "sample_stone.png"],
        ),
        (
            "sample.obj",
            ["sample.obj", "sample.mtl", "sample_stone.png"],
        ),
    ] {
        let files = Recorder::default();
        let loaded = load::model_from(&dir.join(model), &files).unwrap();
        assert!(loaded.warnings.is_empty());
        let mut read: Vec<PathBuf> = files.0.into_inner();
        read.sort();
        read.dedup();
        let mut want: Vec<PathBuf> = expected.iter().map(|f| dir.join(f)).collect();
        want.sort();
        assert_eq!(read, want, "{model}");
    }
    // Nothing else in the folder: every shipped file is used.
    let mut all: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    all.sort();
    assert_eq!(
        all,
        [
            "sample.bin",
            "sample.gltf",
            "sample.mtl",
            "sample.obj",
            "sample_stone.png"
        ]
    );
}

#[test]
fn render_default_view_shows_it_whole() {
    let tmp = Tmp::new("sample", "render");
    let (png, depth) = (tmp.path("out.png"), tmp.path("out.depth"));
    let model = models().join("sample.gltf");
    let out = Command::new(env!("CARGO_BIN_EXE_render"))
        .arg("--gltf")
        .arg(&model)
        .arg("--png")
        .arg(&png)
        .arg("--depth")
        .arg(&depth)
        .output()
        .expect("run render");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && !err.contains("warning"), "{err}");
    assert!(image::open(&png).is_ok());
    let (w, h) = (640usize, 480usize); // render's defaults
    let bytes = std::fs::read(&depth).unwrap();
    assert_eq!(bytes.len(), w * h * 4);
    let covered: Vec<bool> = bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]) < 1.0)
        .collect();
    let share = covered.iter().filter(|&&c| c).count() as f64 / (w * h) as f64;
    assert!(
        (0.08..0.5).contains(&share),
        "the model covers {:.1}% of the frame",
        share * 100.0
    );
    // The covered box against the vertices projected by hand with render's documented
    // camera (eye 0,0,3 looking at the origin, 60 degrees vertical, pixel centres at +0.5).
    let (mut cols, mut rows) = ((w, 0), (h, 0));
    for (i, _) in covered.iter().enumerate().filter(|(_, &c)| c) {
        let (x, y) = (i % w, i / w);
        (cols, rows) = (
            (cols.0.min(x), cols.1.max(x)),
            (rows.0.min(y), rows.1.max(y)),
        );
    }
    let scene = load::model(&model).unwrap().scene;
    let f = 1.0 / 30f32.to_radians().tan();
    let (mut xs, mut ys) = ((f32::MAX, f32::MIN), (f32::MAX, f32::MIN));
    for inst in &scene.instances {
        for p in &scene.meshes[inst.mesh].positions {
            let p = inst.transform.transform_point3(*p);
            let d = 3.0 - p.z; // distance along the view axis
            let x = (1.0 + f * p.x / d * h as f32 / w as f32) * w as f32 / 2.0;
            let y = (1.0 - f * p.y / d) * h as f32 / 2.0;
            (xs, ys) = ((xs.0.min(x), xs.1.max(x)), (ys.0.min(y), ys.1.max(y)));
        }
    }
    assert!(
        xs.0 > 0.0 && ys.0 > 0.0 && xs.1 < w as f32 && ys.1 < h as f32,
        "{xs:?} {ys:?}"
    );
    for (got, want) in [
        (cols.0, xs.0),
        (cols.1, xs.1),
        (rows.0, ys.0),
        (rows.1, ys.1),
    ] {
        assert!(
            (got as f32 + 0.5 - want).abs() < 2.0,
            "covered {cols:?} x {rows:?}, projected {xs:?} x {ys:?}"
        );
    }
}

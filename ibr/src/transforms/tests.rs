use super::*;
use engine::load::{fuzz::TEXTURE_PNG, pfm_bytes, FloatImage, Memory};
use engine::Projection;
use glam::{Mat4, Vec2, Vec3};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("parallax-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A 6 x 4 image with distinct colours (some translucent), depths (one pixel empty).
fn sample(camera: Camera) -> DepthImage {
    let (w, h) = (6, 4);
    let color = (0..w * h)
        .map(|i| {
            let a = if i % 5 == 0 { 0.5 } else { 1.0 };
            through_8_bits(Rgba::new(i as f32 / 24.0, 0.3, 1.0 - i as f32 / 24.0, a).premultiply())
        })
        .collect();
    let mut depth: Vec<f32> = (0..w * h).map(|i| 2.0 + i as f32 * 0.25).collect();
    depth[7] = EMPTY;
    DepthImage::from_planes(w, h, color, depth, camera).unwrap()
}

fn close(a: Mat4, b: Mat4, tol: f32) -> bool {
    a.to_cols_array()
        .iter()
        .zip(b.to_cols_array())
        .all(|(x, y)| (x - y).abs() <= tol * (1.0 + y.abs()))
}

#[test]
fn a_capture_round_trips_through_files() {
    let eye = Camera::look_at(Vec3::new(1.0, 2.0, 5.0), Vec3::ZERO, Vec3::Y, 0.9, 1.5)
        .with_depth_range(0.5, 40.0);
    // An off-axis crop of it too: its principal point is off centre.
    let crop = eye.crop(Vec2::new(1.0, -0.5), Vec2::new(5.0, 3.0), 6, 4);
    let images = [sample(eye), sample(crop)];
    let dir = temp_dir("transforms");
    write_transforms(&dir, &images).unwrap();
    let back = read_transforms(&dir.join("transforms.json")).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(back.len(), 2);
    for (a, b) in images.iter().zip(&back) {
        assert_eq!((a.width(), a.height()), (b.width(), b.height()));
        assert_eq!(a.depth, b.depth, "depth is stored exactly");
        assert_eq!(
            a.color, b.color,
            "colour survives 8 bits once through_8_bits"
        );
        assert!(close(a.camera.view, b.camera.view, 1e-5));
        assert!(
            close(a.camera.clip_from_world(), b.camera.clip_from_world(), 1e-4),
            "{:?} vs {:?}",
            a.camera.projection,
            b.camera.projection
        );
    }
    assert!(matches!(
        back[0].camera.projection,
        Projection::Perspective { .. }
    ));
    assert!(matches!(
        back[1].camera.projection,
        Projection::Frustum { .. }
    ));
}

#[test]
fn intrinsics_put_points_where_the_pinhole_model_does() {
    // A point at view-space (x, y, -z) lands at pixel (cx + fl_x x / z, cy - fl_y y / z).
    let k = Intrinsics {
        fl_x: 500.0,
        fl_y: 480.0,
        cx: 300.0,
        cy: 190.0,
    };
    let (w, h) = (640, 400);
    let camera = Camera {
        view: Mat4::IDENTITY,
        projection: k.projection(w, h, 0.1, 100.0),
    };
    let p = Vec3::new(0.7, -0.4, -3.0);
    let clip = camera.clip_from_world() * p.extend(1.0);
    let ndc = clip.truncate() / clip.w;
    let px = (ndc.x + 1.0) * 0.5 * w as f32;
    let py = (1.0 - ndc.y) * 0.5 * h as f32;
    assert!((px - (300.0 + 500.0 * 0.7 / 3.0)).abs() < 1e-3, "{px}");
    assert!((py - (190.0 + 480.0 * 0.4 / 3.0)).abs() < 1e-3, "{py}");
    let back = Intrinsics::of(&camera.projection, w, h).unwrap();
    for (a, b) in [
        (back.fl_x, 500.0),
        (back.fl_y, 480.0),
        (back.cx, 300.0),
        (back.cy, 190.0),
    ] {
        assert!((a - b).abs() < 1e-3, "{back:?}");
    }
}

/// A capture in memory: `c/transforms.json` with `json`, a 2 x 2 `a.png`, and depth maps.
fn memory(json: &str, depth: &[f32], depth_size: (u32, u32)) -> Memory {
    Memory::default()
        .with("c/transforms.json", json)
        .with("c/a.png", TEXTURE_PNG)
        .with(
            "c/a.pfm",
            pfm_bytes(&FloatImage::new(depth_size.0, depth_size.1, depth.to_vec()).unwrap()),
        )
}

const POSE: &str = "[[1,0,0,0],[0,1,0,0],[0,0,1,3],[0,0,0,1]]";

fn frame_json(extra: &str) -> String {
    format!(
        r#"{{"camera_angle_x": 1.0, "frames": [{{"file_path": "./a", "depth_file_path": "a.pfm", "transform_matrix": {POSE}{extra}}}]}}"#
    )
}

fn read(files: &Memory) -> Result<Vec<DepthImage>, LoadError> {
    read_transforms_from(Path::new("c/transforms.json"), files)
}

#[test]
fn a_nerf_style_file_reads() {
    // `./a` gets `.png`; camera_angle_x gives square pixels, centred.
    let images = read(&memory(
        &frame_json(""),
        &[1.0, 2.0, f32::INFINITY, 4.0],
        (2, 2),
    ))
    .unwrap();
    let image = &images[0];
    assert_eq!(image.depth, vec![1.0, 2.0, EMPTY, 4.0]);
    assert!((image.camera.eye() - Vec3::new(0.0, 0.0, 3.0)).length() < 1e-6);
    let Projection::Perspective { fov_y, aspect, .. } = image.camera.projection else {
        panic!("{:?}", image.camera.projection)
    };
    assert!((fov_y - 1.0).abs() < 1e-6 && aspect == 1.0);
}

#[test]
fn depth_zero_reads_as_nothing_measured() {
    // Before issue 40, a 0 was refused; instant-ngp and RGB-D datasets write it for "no
    // measurement".
    let images = read(&memory(&frame_json(""), &[0.0, 2.0, 0.0, 4.0], (2, 2))).unwrap();
    assert_eq!(images[0].depth, vec![EMPTY, 2.0, EMPTY, 4.0]);
}

#[test]
fn photographs_read_with_or_without_depth_maps() {
    let json = frame_json("").replace(", \"depth_file_path\": \"a.pfm\"", "");
    let files = memory(&json, &[1.0; 4], (2, 2));
    let path = Path::new("c/transforms.json");
    let images = read_photos_from(path, &files).unwrap();
    // No depth: every pixel empty; the colour and the camera as with one.
    assert_eq!(images[0].depth, vec![EMPTY; 4]);
    assert!(images[0].color.iter().any(|c| c.a > 0.0));
    assert!((images[0].camera.eye() - Vec3::new(0.0, 0.0, 3.0)).length() < 1e-6);
    // A depth map given is read as by read_transforms; read_transforms needs one.
    let with = memory(&frame_json(""), &[1.0, 2.0, 3.0, 4.0], (2, 2));
    assert_eq!(read_photos_from(path, &with).unwrap(), read(&with).unwrap());
    assert!(read(&files).is_err());
}

#[test]
fn bad_captures_are_refused_naming_the_file() {
    let ok_depth = [1.0, 2.0, 3.0, 4.0];
    let cases: Vec<(Memory, &str, &str)> = vec![
        (
            memory("{}", &ok_depth, (2, 2)),
            "c/transforms.json",
            "frames",
        ),
        (
            memory(r#"{"frames": []}"#, &ok_depth, (2, 2)),
            "c/transforms.json",
            "empty",
        ),
        (
            memory("[1", &ok_depth, (2, 2)),
            "c/transforms.json",
            "bad JSON",
        ),
        (memory(&frame_json(""), &[1.0], (1, 1)), "c/a.pfm", "1 x 1"),
        (
            memory(&frame_json(""), &[1.0, f32::NAN, 3.0, 4.0], (2, 2)),
            "c/a.pfm",
            "NaN",
        ),
        (
            memory(&frame_json(""), &[1.0, -2.0, 3.0, 4.0], (2, 2)),
            "c/a.pfm",
            "(1, 0)",
        ),
        (
            memory(&frame_json(r#", "w": 3"#), &ok_depth, (2, 2)),
            "c/a.png",
            "\"w\": 3",
        ),
        (
            memory(
                &frame_json("").replace("\"./a\"", "\"../a.png\""),
                &ok_depth,
                (2, 2),
            ),
            "c/transforms.json",
            "folder",
        ),
        (
            memory(
                &frame_json("").replace("a.pfm", "/etc/passwd"),
                &ok_depth,
                (2, 2),
            ),
            "c/transforms.json",
            "absolute",
        ),
        (
            memory(
                &frame_json("").replace("a.pfm", "missing.pfm"),
                &ok_depth,
                (2, 2),
            ),
            "c/missing.pfm",
            "no such file",
        ),
        (
            memory(
                &frame_json("").replace("\"camera_angle_x\": 1.0,", ""),
                &ok_depth,
                (2, 2),
            ),
            "c/transforms.json",
            "intrinsics",
        ),
        (
            memory(
                &frame_json("").replace("[0,0,1,3]", "[0,0,0,3]"),
                &ok_depth,
                (2, 2),
            ),
            "c/transforms.json",
            "singular",
        ),
        (
            memory(
                &frame_json("").replace(", \"depth_file_path\": \"a.pfm\"", ""),
                &ok_depth,
                (2, 2),
            ),
            "c/transforms.json",
            "depth_file_path",
        ),
    ];
    for (files, file, want) in cases {
        let e = read(&files).unwrap_err().to_string();
        assert!(e.starts_with(file), "{e:?} should start with {file:?}");
        assert!(e.contains(want), "{e:?} should mention {want:?}");
    }
}

#[test]
fn the_fuzz_entry_point_takes_garbage_and_valid_files() {
    fuzz(b"");
    fuzz(b"{\"frames\": [{}]}");
    fuzz(frame_json("").as_bytes());
    fuzz(frame_json(r#", "near": -1"#).as_bytes());
}

//! Writes the sample model the project ships, `assets/models/`: a lighthouse with its
//! keeper's cottage on a rock, 2 units tall and centred on the origin (so `render`'s default
//! view, eye `0,0,3` looking at the origin, shows it whole), as glTF (`sample.gltf` +
//! `sample.bin`) and its OBJ twin (`sample.obj` + `sample.mtl`), sharing one base-colour
//! texture (`sample_stone.png`, stone blocks, generated here too).
//! `cargo run -p demos --example make_sample [-- OUT_DIR]`.
//!
//! Parts carry their colours as vertex colours (glTF `COLOR_0`, OBJ `v x y z r g b`), so
//! every shading mode shows them; the four materials are white apart from the stone's
//! texture, the glass's emission and their highlights. Each part is flat-banded (its own
//! vertices per band, smooth around) with outward normals and counter-clockwise fronts.

use engine::load::write_png_rgba8;
use glam::{Vec2, Vec3};
use std::f32::consts::TAU;
use std::fmt::Write as _;
use std::path::PathBuf;

/// A vertex: position, normal, uv (v down, as glTF), linear colour.
type Vert = (Vec3, Vec3, Vec2, [f32; 3]);

/// One material's triangles.
#[derive(Default)]
struct Part {
    verts: Vec<Vert>,
    tris: Vec<[u16; 3]>,
}

impl Part {
    /// A convex polygon (corners in order), turned to face `n`.
    fn poly(&mut self, ps: &[Vec3], uvs: &[Vec2], n: Vec3, c: [f32; 3]) {
        let b = self.verts.len() as u16;
        self.verts
            .extend(ps.iter().zip(uvs).map(|(&p, &uv)| (p, n, uv, c)));
        for i in 1..ps.len() - 1 {
            let front = (ps[i] - ps[0]).cross(ps[i + 1] - ps[0]).dot(n) >= 0.0;
            let (j, k) = if front { (i, i + 1) } else { (i + 1, i) };
            self.tris.push([b, b + j as u16, b + k as u16]);
        }
    }

    /// A solid of revolution about the vertical line through `at`: bands between profile
    /// points `(radius, y)`, bottom to top, each with its colour; flat caps where asked.
    fn lathe(&mut self, at: Vec3, prof: &[(f32, f32)], cols: &[[f32; 3]], caps: (bool, bool)) {
        let seg = 32;
        let ring = |r: f32, y: f32, i: u32| {
            let t = TAU * i as f32 / seg as f32;
            at + Vec3::new(r * t.sin(), y, r * t.cos())
        };
        for (k, w) in prof.windows(2).enumerate() {
            let ((r0, y0), (r1, y1)) = (w[0], w[1]);
            let slope = Vec2::new(y1 - y0, r0 - r1).normalize();
            let b = self.verts.len() as u16;
            for i in 0..=seg {
                let t = TAU * i as f32 / seg as f32;
                let n = Vec3::new(slope.x * t.sin(), slope.y, slope.x * t.cos());
                let u = 4.0 * i as f32 / seg as f32;
                self.verts
                    .push((ring(r0, y0, i), n, Vec2::new(u, 0.5 - y0), cols[k]));
                self.verts
                    .push((ring(r1, y1, i), n, Vec2::new(u, 0.5 - y1), cols[k]));
            }
            for i in 0..seg as u16 {
                let (a, c) = (b + 2 * i, b + 2 * i + 2);
                self.tris.push([a, c, c + 1]);
                if r1 > 0.0 {
                    self.tris.push([a, c + 1, a + 1]);
                }
            }
        }
        let ends = [(prof[0], -1.0, caps.0), (prof[prof.len() - 1], 1.0, caps.1)];
        let colors = [cols[0], cols[cols.len() - 1]];
        for (((r, y), ny, on), c) in ends.into_iter().zip(colors) {
            if on {
                let ps: Vec<Vec3> = (0..seg).map(|i| ring(r, y, i)).collect();
                let uvs: Vec<Vec2> = ps.iter().map(|p| Vec2::new(p.x, p.z) * 0.8).collect();
                self.poly(&ps, &uvs, Vec3::Y * ny, c);
            }
        }
    }

    /// An axis-aligned box from `lo` to `hi` (six faces; the bottom left out).
    fn cuboid(&mut self, lo: Vec3, hi: Vec3, c: [f32; 3]) {
        let uv = [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y];
        for (axis, sign) in [(0, -1.0), (0, 1.0), (1, 1.0), (2, -1.0), (2, 1.0)] {
            let n = Vec3::from_array(std::array::from_fn(|k| if k == axis { sign } else { 0.0 }));
            let pick = |u: bool, v: bool| {
                let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
                let mut p = if sign > 0.0 { hi } else { lo };
                p[a] = if u { hi[a] } else { lo[a] };
                p[b] = if v { hi[b] } else { lo[b] };
                p
            };
            let ps = [
                pick(false, false),
                pick(true, false),
                pick(true, true),
                pick(false, true),
            ];
            self.poly(&ps, &uv, n, c);
        }
    }
}

const STONE: [f32; 3] = [0.80, 0.76, 0.70];
const RED: [f32; 3] = [0.62, 0.05, 0.04];
const WHITE: [f32; 3] = [0.90, 0.88, 0.84];
const DARK: [f32; 3] = [0.06, 0.06, 0.07];
const ROOF: [f32; 3] = [0.30, 0.07, 0.05];
const GLASS: [f32; 3] = [1.0, 0.85, 0.45];

/// The model: (material name, its part), in the files' order.
fn model() -> Vec<(&'static str, Part)> {
    let mut parts: [Part; 4] = Default::default();
    let [s, p, r, g] = &mut parts;
    // The rock: a low drum, its rim bevelled.
    let rock = [(0.92, -1.0), (0.95, -0.9), (0.9, -0.8)];
    s.lathe(Vec3::ZERO, &rock, &[STONE, STONE], (true, true));
    // The tower: six painted bands, narrowing upward, then the gallery and the lantern.
    let t = Vec3::new(-0.25, 0.0, 0.0);
    let bands: Vec<(f32, f32)> = (0..=6)
        .map(|i| (0.34 - 0.1 * i as f32 / 6.0, -0.8 + 1.2 * i as f32 / 6.0))
        .collect();
    let cols = [RED, WHITE, RED, WHITE, RED, WHITE];
    p.lathe(t, &bands, &cols, (false, false));
    r.lathe(t, &[(0.34, 0.4), (0.34, 0.46)], &[DARK], (true, true));
    g.lathe(t, &[(0.17, 0.46), (0.17, 0.72)], &[GLASS], (false, false));
    r.lathe(t, &[(0.25, 0.72), (0.0, 1.0)], &[ROOF], (true, false));
    // The cottage: walls, a door and two windows on the front, a gabled roof along x.
    let (lo, hi) = (Vec3::new(0.12, -0.8, -0.28), Vec3::new(0.76, -0.45, 0.28));
    p.cuboid(lo, hi, WHITE);
    let front = |x0: f32, x1: f32, y0: f32, y1: f32| {
        let z = hi.z + 0.004;
        [
            Vec3::new(x0, y0, z),
            Vec3::new(x1, y0, z),
            Vec3::new(x1, y1, z),
            Vec3::new(x0, y1, z),
        ]
    };
    let uv = [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y];
    for (x0, x1, y0, y1) in [
        (0.40, 0.50, -0.8, -0.58),
        (0.2, 0.32, -0.68, -0.56),
        (0.58, 0.7, -0.68, -0.56),
    ] {
        p.poly(&front(x0, x1, y0, y1), &uv, Vec3::Z, DARK);
    }
    let (y0, y1, ox, oz) = (hi.y, -0.25, 0.04, 0.06);
    let eave = |x: f32, z: f32| Vec3::new(x, y0, z);
    let ridge = |x: f32| Vec3::new(x, y1, 0.0);
    let (xa, xb, za, zb) = (lo.x - ox, hi.x + ox, lo.z - oz, hi.z + oz);
    let slope = |z: f32| Vec3::new(0.0, zb, (y1 - y0) * z.signum()).normalize();
    r.poly(
        &[eave(xa, zb), eave(xb, zb), ridge(xb), ridge(xa)],
        &uv,
        slope(1.0),
        ROOF,
    );
    r.poly(
        &[eave(xb, za), eave(xa, za), ridge(xa), ridge(xb)],
        &uv,
        slope(-1.0),
        ROOF,
    );
    r.poly(
        &[eave(xa, zb), eave(xb, zb), eave(xb, za), eave(xa, za)],
        &uv,
        -Vec3::Y,
        ROOF,
    );
    for x in [lo.x, hi.x] {
        let gable = [
            Vec3::new(x, y0, hi.z),
            Vec3::new(x, y0, lo.z),
            Vec3::new(x, y1, 0.0),
        ];
        p.poly(&gable, &uv, Vec3::X * (x - 0.44).signum(), WHITE);
    }
    ["stone", "paint", "roof", "glass"]
        .into_iter()
        .zip(parts)
        .collect()
}

/// The stone texture: 64 x 64 sRGB, courses of blocks of varying shade between mortar.
fn stone_texture() -> Vec<u8> {
    let mut out = Vec::with_capacity(64 * 64 * 4);
    for y in 0..64u32 {
        for x in 0..64u32 {
            let (course, shift) = (y / 16, if (y / 16) % 2 == 0 { 0 } else { 12 });
            let block = (x + shift) / 24 + course * 7;
            let mortar = y % 16 == 0 || (x + shift) % 24 == 0;
            let hash = (block.wrapping_mul(2_654_435_761) >> 13) % 48;
            let grain = ((x * 7 + y * 13) ^ (x * y)) % 11;
            let v: u8 = if mortar {
                220
            } else {
                (150 + hash + grain) as u8
            };
            out.extend([v, v - 8, v.saturating_sub(20), 255]);
        }
    }
    out
}

/// Appends `data` to `bin` (4-byte aligned) as a buffer view; returns its index.
fn view(bin: &mut Vec<u8>, views: &mut Vec<String>, data: &[u8], target: u32) -> usize {
    bin.resize(bin.len().next_multiple_of(4), 0);
    let (off, len) = (bin.len(), data.len());
    bin.extend_from_slice(data);
    views.push(format!(
        r#"{{"buffer":0,"byteOffset":{off},"byteLength":{len},"target":{target}}}"#
    ));
    views.len() - 1
}

fn floats(vals: impl Iterator<Item = f32>) -> Vec<u8> {
    vals.flat_map(f32::to_le_bytes).collect()
}

/// `sample.gltf` and `sample.bin`: one node, one mesh, a primitive per material.
fn write_gltf(dir: &std::path::Path, parts: &[(&str, Part)]) -> std::io::Result<()> {
    let mut bin = Vec::new();
    let (mut views, mut accs, mut prims, mut mats) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (m, (name, part)) in parts.iter().enumerate() {
        let n = part.verts.len();
        let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        part.verts
            .iter()
            .for_each(|v| (lo, hi) = (lo.min(v.0), hi.max(v.0)));
        let attrs: [(&str, &str, Vec<u8>); 4] = [
            (
                "POSITION",
                "VEC3",
                floats(part.verts.iter().flat_map(|v| v.0.to_array())),
            ),
            (
                "NORMAL",
                "VEC3",
                floats(part.verts.iter().flat_map(|v| v.1.to_array())),
            ),
            (
                "TEXCOORD_0",
                "VEC2",
                floats(part.verts.iter().flat_map(|v| v.2.to_array())),
            ),
            (
                "COLOR_0",
                "VEC3",
                floats(part.verts.iter().flat_map(|v| v.3)),
            ),
        ];
        let mut fields = Vec::new();
        for (attr, ty, data) in attrs {
            let v = view(&mut bin, &mut views, &data, 34962);
            let bounds = if attr == "POSITION" {
                format!(r#","min":{:?},"max":{:?}"#, lo.to_array(), hi.to_array())
            } else {
                String::new()
            };
            accs.push(format!(
                r#"{{"bufferView":{v},"componentType":5126,"count":{n},"type":"{ty}"{bounds}}}"#
            ));
            fields.push(format!(r#""{attr}":{}"#, accs.len() - 1));
        }
        let idx: Vec<u8> = part
            .tris
            .iter()
            .flatten()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let v = view(&mut bin, &mut views, &idx, 34963);
        let count = part.tris.len() * 3;
        accs.push(format!(
            r#"{{"bufferView":{v},"componentType":5123,"count":{count},"type":"SCALAR"}}"#
        ));
        prims.push(format!(
            r#"{{"attributes":{{{}}},"indices":{},"material":{m}}}"#,
            fields.join(","),
            accs.len() - 1
        ));
        let extra = match *name {
            "stone" => r#","baseColorTexture":{"index":0}"#,
            _ => "",
        };
        let emissive = if *name == "glass" {
            r#","emissiveFactor":[1.0,0.8,0.35]"#
        } else {
            ""
        };
        let rough = if *name == "stone" { 0.9 } else { 0.5 };
        mats.push(format!(r#"{{"name":"{name}","pbrMetallicRoughness":{{"baseColorFactor":[1,1,1,1],"metallicFactor":0,"roughnessFactor":{rough}{extra}}}{emissive}}}"#));
    }
    let mut json = String::new();
    let _ = write!(
        json,
        r#"{{"asset":{{"version":"2.0","generator":"Parallax demos/examples/make_sample.rs","copyright":"Parallax contributors, MIT OR Apache-2.0"}},
"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"name":"lighthouse","mesh":0}}],
"meshes":[{{"name":"lighthouse","primitives":[
{}]}}],
"materials":[
{}],
"textures":[{{"sampler":0,"source":0}}],"samplers":[{{"magFilter":9729,"minFilter":9987,"wrapS":10497,"wrapT":10497}}],
"images":[{{"uri":"sample_stone.png"}}],
"buffers":[{{"uri":"sample.bin","byteLength":{}}}],
"bufferViews":[
{}],
"accessors":[
{}]}}
"#,
        prims.join(",\n"),
        mats.join(",\n"),
        bin.len(),
        views.join(",\n"),
        accs.join(",\n")
    );
    std::fs::write(dir.join("sample.bin"), &bin)?;
    std::fs::write(dir.join("sample.gltf"), json)
}

/// `sample.obj` and `sample.mtl`: an object per material, the same vertices and triangles.
fn write_obj(dir: &std::path::Path, parts: &[(&str, Part)]) -> std::io::Result<()> {
    let mut obj = String::from("# Parallax sample model (demos/examples/make_sample.rs), MIT OR Apache-2.0\nmtllib sample.mtl\n");
    let mut base = 1;
    for (name, part) in parts {
        let _ = writeln!(obj, "o {name}\nusemtl {name}");
        for (p, _, _, c) in &part.verts {
            let _ = writeln!(
                obj,
                "v {:.5} {:.5} {:.5} {:.4} {:.4} {:.4}",
                p.x, p.y, p.z, c[0], c[1], c[2]
            );
        }
        for (_, _, uv, _) in &part.verts {
            let _ = writeln!(obj, "vt {:.5} {:.5}", uv.x, 1.0 - uv.y);
        }
        for (_, n, _, _) in &part.verts {
            let _ = writeln!(obj, "vn {:.5} {:.5} {:.5}", n.x, n.y, n.z);
        }
        for t in &part.tris {
            let [a, b, c] = t.map(|i| i as usize + base);
            let _ = writeln!(obj, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}");
        }
        base += part.verts.len();
    }
    let mtl = "# Parallax sample model's materials, MIT OR Apache-2.0\n\
        newmtl stone\nKd 1 1 1\nKs 0.05 0.05 0.05\nNs 8\nmap_Kd sample_stone.png\n\n\
        newmtl paint\nKd 1 1 1\nKs 0.3 0.3 0.3\nNs 32\n\n\
        newmtl roof\nKd 1 1 1\nKs 0.3 0.3 0.3\nNs 32\n\n\
        newmtl glass\nKd 1 1 1\nKs 0.3 0.3 0.3\nNs 32\nKe 1 0.8 0.35\n";
    std::fs::write(dir.join("sample.mtl"), mtl)?;
    std::fs::write(dir.join("sample.obj"), obj)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args_os().nth(1).map_or_else(
        || PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../assets/models")),
        PathBuf::from,
    );
    std::fs::create_dir_all(&dir)?;
    let parts = model();
    write_gltf(&dir, &parts)?;
    write_obj(&dir, &parts)?;
    write_png_rgba8(&dir.join("sample_stone.png"), 64, 64, &stone_texture())?;
    let tris: usize = parts.iter().map(|(_, p)| p.tris.len()).sum();
    println!(
        "wrote the sample model ({tris} triangles) to {}",
        dir.display()
    );
    Ok(())
}

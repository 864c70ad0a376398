//! The light-field sweep's series, in the order it runs them: sampling (geometry, `uv`
//! density, `st` resolution), compression, the outline from geometry, sparse capture, frame
//! time against resolution and against triangles.

use super::{capture, file_size, slab, wander, Bench, Object, Row, Setting, Settings, EYES};
use crate::bench::sweep::ticker;
use engine::{Camera, Renderer};
use ibr::lightfield::{LightField, LightFieldObject, Lookup, TileShape, VqSettings};
use ibr::subject::MeshGroup;
use ibr::technique::FrameLoop;
use std::sync::Arc;
use std::time::Instant;

/// Runs the sweep at these settings; `progress(step, total, what)` before each point.
pub fn run(settings: &Settings, progress: &mut dyn FnMut(usize, usize, &str)) -> Vec<Row> {
    let total = settings.uv.len()
        + settings.st.len()
        + settings.codewords.len()
        + settings.tiles.len()
        + settings.resolutions.len()
        + settings.triangles.len()
        + settings.photographs.len()
        + 4;
    let mut tick = ticker(total, progress);
    let mut bench = Bench {
        settings,
        renderer: Renderer::new(),
        frames: FrameLoop::new(),
    };
    let mut rows = Vec::new();
    let object = Object::torus(settings.object_triangles);
    sampling(&mut bench, &object, &mut tick, &mut rows);
    let (lf, raw) = compression(&mut bench, &object, &mut tick, &mut rows);
    outline(&mut bench, &object, &lf, &raw, &mut tick, &mut rows);
    sparse(&mut bench, &object, &mut tick, &mut rows);
    resolution(&mut bench, &object, lf, &raw, &mut tick, &mut rows);
    triangles(&mut bench, &mut tick, &mut rows);
    rows
}

/// The geometry from every eye, then the lookups over `uv` density and `st` resolution.
fn sampling(bench: &mut Bench, object: &Object, tick: &mut dyn FnMut(String), rows: &mut Vec<Row>) {
    let settings = bench.settings;
    let (base_uv, base_st) = settings.base;
    tick("geometry".into());
    for k in 0..EYES.len() {
        let setting = Setting {
            triangles: settings.object_triangles,
            ..Setting::default()
        };
        rows.push(bench.point("geometry", object, None, k, settings.size, &setting));
    }
    for (series, values) in [("density", &settings.uv), ("st", &settings.st)] {
        for &n in values {
            let (uv, st) = if series == "density" {
                (n, base_st)
            } else {
                (base_uv, n)
            };
            tick(format!("{series} {uv}x{uv}x{st}x{st}"));
            let (lf, capture_s) = capture(object, slab(uv, st));
            let setting = Setting {
                uv,
                st,
                triangles: settings.object_triangles,
                raw_bytes: lf.bytes() as u64,
                capture_s,
                ..Setting::default()
            };
            rows.extend(bench.lookups(series, object, lf, &setting));
        }
    }
}

/// The base slab captured, then quantised at each codebook size and tile shape; the raw
/// slab and its setting.
fn compression(
    bench: &mut Bench,
    object: &Object,
    tick: &mut dyn FnMut(String),
    rows: &mut Vec<Row>,
) -> (LightField, Setting) {
    let settings = bench.settings;
    let (base_uv, base_st) = settings.base;
    tick("capture the base slab".into());
    let (lf, capture_s) = capture(object, slab(base_uv, base_st));
    let raw = Setting {
        uv: base_uv,
        st: base_st,
        triangles: settings.object_triangles,
        raw_bytes: lf.bytes() as u64,
        raw_file_bytes: file_size(&lf, "raw.plf"),
        capture_s,
        ..Setting::default()
    };
    let quantised = settings
        .codewords
        .iter()
        .map(|&k| ("codebook", k, [2, 2, 2, 2]))
        .chain(
            settings
                .tiles
                .iter()
                .map(|&t| ("tile", settings.tile_codewords, t)),
        );
    for (series, codewords, dims) in quantised {
        let tile = TileShape::new(dims).expect("a valid tile");
        tick(format!("{series} {codewords} codewords, {tile} tiles"));
        let vq = VqSettings {
            tile,
            codewords,
            training_tiles: settings.training_tiles,
            ..VqSettings::default()
        };
        let start = Instant::now();
        let (q, report) = lf.quantise(&vq).expect("valid settings");
        let setting = Setting {
            codewords: report.codewords,
            tile: tile.to_string(),
            quantise_s: start.elapsed().as_secs_f64(),
            file_bytes: file_size(&q, "vq.plf"),
            ..raw.clone()
        };
        rows.extend(bench.every_eye(series, object, q, &setting));
    }
    (lf, raw)
}

/// The raw base slab at every eye, depth-corrected, without and with the outline from
/// geometry ([`LightFieldObject::proxy_outline`]: the torus kept as its reference; methods
/// [`NO_OUTLINE`] and [`OUTLINE`]), on the same frames as the geometry's points.
fn outline(
    bench: &mut Bench,
    object: &Object,
    lf: &LightField,
    raw: &Setting,
    tick: &mut dyn FnMut(String),
    rows: &mut Vec<Row>,
) {
    tick("outline from geometry".into());
    let reference = MeshGroup::new().with(
        Arc::new(object.mesh.clone()),
        Arc::new(object.material.clone()),
        object.draw().transform,
    );
    for (method, on) in [(NO_OUTLINE, false), (OUTLINE, true)] {
        let mut o = LightFieldObject::new("torus", lf.clone());
        o.lookup = Lookup::default();
        o.reference = Some(reference.clone());
        o.proxy_outline = on;
        for k in 0..EYES.len() {
            let size = bench.settings.size;
            rows.push(bench.point("outline", object, Some((method, &mut o)), k, size, raw));
        }
    }
}

/// The `outline` series' methods: the depth-corrected lookup alone, and with the outline
/// from geometry.
pub const NO_OUTLINE: &str = "quadrilinear-dc";
pub const OUTLINE: &str = "dc+outline";

/// Sparse against dense capture of one slab.
fn sparse(bench: &mut Bench, object: &Object, tick: &mut dyn FnMut(String), rows: &mut Vec<Row>) {
    let settings = bench.settings;
    let (uv, st) = settings.sparse_slab;
    tick(format!("sparse: dense {uv}x{uv}x{st}x{st}"));
    let (dense, capture_s) = capture(object, slab(uv, st));
    let mut setting = Setting {
        uv,
        st,
        triangles: settings.object_triangles,
        raw_bytes: dense.bytes() as u64,
        capture_s,
        ..Setting::default()
    };
    rows.extend(bench.every_eye("sparse", object, dense, &setting));
    for &n in &settings.photographs {
        tick(format!("sparse: {n} photographs"));
        let start = Instant::now();
        let cameras: Vec<Camera> = (0..n).map(|k| wander(k, n)).collect();
        let images = ibr::capture::capture_batch(
            &[object.draw()],
            &cameras,
            &object.lighting,
            settings.photo_size,
            settings.photo_size,
        );
        let r = ibr::lightfield::rebin(slab(uv, st), &images);
        setting.capture_s = start.elapsed().as_secs_f64();
        setting.photographs = n;
        setting.invented = r.invented();
        rows.extend(bench.every_eye("sparse", object, r.field, &setting));
    }
}

/// Frame time against resolution: the base slab and the geometry.
fn resolution(
    bench: &mut Bench,
    object: &Object,
    lf: LightField,
    raw: &Setting,
    tick: &mut dyn FnMut(String),
    rows: &mut Vec<Row>,
) {
    let settings = bench.settings;
    let mut o = LightFieldObject::new("torus", lf);
    o.lookup = Lookup::default();
    for &size in &settings.resolutions {
        tick(format!("resolution {}x{}", size.0, size.1));
        rows.push(bench.point(
            "resolution",
            object,
            Some(("quadrilinear-dc", &mut o)),
            0,
            size,
            raw,
        ));
        rows.push(bench.point("resolution", object, None, 0, size, raw));
    }
}

/// Frame time against the object's triangles: a slab of each torus and its geometry.
fn triangles(bench: &mut Bench, tick: &mut dyn FnMut(String), rows: &mut Vec<Row>) {
    let settings = bench.settings;
    let (base_uv, base_st) = settings.base;
    for &n in &settings.triangles {
        tick(format!("triangles {n}"));
        let object = Object::torus(n);
        let (lf, capture_s) = capture(&object, slab(base_uv.min(16), base_st));
        let setting = Setting {
            uv: lf.slab.nu,
            st: lf.slab.ns,
            triangles: object.mesh.triangle_count() as u32,
            raw_bytes: lf.bytes() as u64,
            capture_s,
            ..Setting::default()
        };
        let mut o = LightFieldObject::new("torus", lf);
        o.lookup = Lookup::default();
        rows.push(bench.point(
            "triangles",
            &object,
            Some(("quadrilinear-dc", &mut o)),
            0,
            settings.size,
            &setting,
        ));
        rows.push(bench.point("triangles", &object, None, 0, settings.size, &setting));
    }
}

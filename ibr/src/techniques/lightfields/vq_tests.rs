//! Vector quantisation against its definition: the search is exact, the codes are
//! lossless where the codebook has room for every distinct tile and close where it has
//! not, rendering reads the codes as it reads raw samples, and files round-trip.

use super::file::FileError;
use super::vq::Search;
use super::*;
use crate::warp::Warped;

/// A small deterministic generator (xorshift).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 32) as u32
    }
}

fn slab(counts: [u32; 4]) -> Slab {
    let square = |z: f32| Rect3::centered(Vec3::new(0.0, 0.0, z), Vec3::X * 2.0, Vec3::NEG_Y * 2.0);
    Slab::new(square(4.0), square(0.0), counts, 0.5, 20.0).expect("a valid slab")
}

/// A light field whose samples (premultiplied: colour bytes at most alpha) and depths
/// depend only on which of `kinds` patterns their tile (2x2x2x2) was given.
fn patterned(counts: [u32; 4], kinds: u32, seed: u64) -> LightField {
    let slab = slab(counts);
    let mut rng = Rng(seed);
    let patterns: Vec<Vec<(u32, f32)>> = (0..kinds)
        .map(|_| {
            (0..16)
                .map(|_| {
                    let a = 128 + rng.next() % 128;
                    let c = |r: &mut Rng| r.next() % (a + 1);
                    let (r, g, b) = (c(&mut rng), c(&mut rng), c(&mut rng));
                    let z = if rng.next().is_multiple_of(5) {
                        f32::INFINITY
                    } else {
                        3.0 + (rng.next() % 100) as f32 * 0.01
                    };
                    (u32::from_le_bytes([r as u8, g as u8, b as u8, a as u8]), z)
                })
                .collect()
        })
        .collect();
    let choice: Vec<u32> = (0..TileShape::LEVOY.tiles(counts).iter().product::<u32>())
        .map(|_| rng.next() % kinds)
        .collect();
    let [nu, nv, ns, nt] = counts;
    let [tu, _, ts, tt] = TileShape::LEVOY.tiles(counts);
    let (mut samples, mut depth) = (Vec::new(), Vec::new());
    for v in 0..nv {
        for u in 0..nu {
            for t in 0..nt {
                for s in 0..ns {
                    let tile = (((v / 2) * tu + u / 2) * tt + t / 2) * ts + s / 2;
                    let within = (((v % 2) * 2 + u % 2) * 2 + t % 2) * 2 + s % 2;
                    let (c, z) = patterns[choice[tile as usize] as usize][within as usize];
                    samples.push(c);
                    depth.push(z);
                }
            }
        }
    }
    LightField {
        slab,
        rays: Rays::Raw(RawRays::new(samples, depth)),
    }
}

fn settings(codewords: u32) -> VqSettings {
    VqSettings {
        codewords,
        training_tiles: 1 << 12,
        ..VqSettings::default()
    }
}

#[test]
fn the_fast_search_finds_the_nearest_codeword_as_brute_force_does() {
    let mut rng = Rng(7);
    for (dim, k) in [(4, 1), (16, 50), (80, 300), (20, 2)] {
        // Clustered codewords (as trained codebooks are), some duplicated.
        let mut book: Vec<f32> = (0..k * dim)
            .map(|i| ((i / dim) % 7) as f32 * 30.0 + (rng.next() % 40) as f32)
            .collect();
        if k > 2 {
            let first = book[..dim].to_vec();
            book[dim..2 * dim].copy_from_slice(&first);
        }
        let search = Search::new(&book, dim);
        for _ in 0..200 {
            let x: Vec<f32> = (0..dim).map(|_| (rng.next() % 260) as f32).collect();
            let brute = book
                .chunks_exact(dim)
                .map(|w| x.iter().zip(w).map(|(a, b)| (a - b) * (a - b)).sum::<f32>())
                .enumerate()
                .fold(
                    (0, f32::INFINITY),
                    |best, (i, d)| {
                        if d < best.1 {
                            (i, d)
                        } else {
                            best
                        }
                    },
                );
            let (i, d, work) = search.nearest(&x);
            assert!(
                (d - brute.1).abs() <= 1e-3 * brute.1.max(1.0),
                "dim {dim}, k {k}: {d} against {}",
                brute.1
            );
            assert_eq!(i, brute.0, "ties go to the lower index");
            assert!(work as usize <= k);
        }
    }
}

#[test]
fn with_room_for_every_tile_quantisation_is_lossless() {
    // Counts that are not multiples of the tile: edge tiles repeat their last samples.
    // Six patterns, and their clipped copies at the edges: at most 24 distinct tiles.
    let lf = patterned([5, 4, 13, 10], 6, 3);
    let (q, report) = lf.quantise(&settings(64)).expect("quantised");
    assert!(report.codewords <= 64);
    assert_eq!(report.mse, 0.0, "{report:?}");
    let sl = lf.slab;
    for v in 0..sl.nv {
        for u in 0..sl.nu {
            for t in 0..sl.nt {
                for s in 0..sl.ns {
                    assert_eq!(q.sample(u, v, s, t), lf.sample(u, v, s, t));
                    let (a, b) = (q.depth_at(u, v, s, t), lf.depth_at(u, v, s, t));
                    assert!(a == b || (a - b).abs() <= 1e-5 * b, "{a} against {b}");
                }
            }
        }
    }
    // Rendering from codes gives the raw field's pixels and work.
    let camera = Camera::look_at(Vec3::new(0.3, -0.2, 6.0), Vec3::ZERO, Vec3::Y, 0.6, 1.0)
        .with_depth_range(0.1, 30.0);
    for interpolation in [
        Interpolation::Nearest,
        Interpolation::BilinearUv,
        Interpolation::Quadrilinear,
    ] {
        let lookup = Lookup {
            interpolation,
            depth_correction: true,
        };
        let (mut a, mut b) = (Warped::new(0, 0, camera), Warped::new(0, 0, camera));
        let fa = render(&lf, &camera, 40, 40, lookup, &mut a);
        let fb = render(&q, &camera, 40, 40, lookup, &mut b);
        assert_eq!(fa, fb);
        assert!(fa.pixels > 300, "{fa:?}");
        assert_eq!(a.color, b.color);
    }
}

#[test]
fn a_codebook_smaller_than_the_distinct_tiles_is_close_and_never_invalid() {
    let lf = patterned([6, 6, 16, 16], 40, 11);
    let mut last = f64::INFINITY;
    for k in [1, 4, 16] {
        let (q, report) = lf.quantise(&settings(k)).expect("quantised");
        assert!(report.codewords as usize <= k as usize);
        assert!(report.mse.is_finite() && report.mse > 0.0, "{report:?}");
        assert!(report.mse < last, "more codewords, less error: {report:?}");
        last = report.mse;
        let Rays::Quantised(codes) = &q.rays else {
            panic!("quantised");
        };
        // Premultiplied colour stays premultiplied; depths are positive or infinite.
        for c in &codes.colors {
            let [r, g, b, a] = c.to_le_bytes();
            assert!(r <= a && g <= a && b <= a, "{c:08x}");
        }
        assert!(codes.depths.iter().all(|z| *z > 0.0 && !z.is_nan()));
        // A view renders without NaN.
        let camera = Camera::look_at(Vec3::new(0.0, 0.0, 6.0), Vec3::ZERO, Vec3::Y, 0.6, 1.0)
            .with_depth_range(0.1, 30.0);
        let mut out = Warped::new(0, 0, camera);
        let frame = render(&q, &camera, 32, 32, Lookup::default(), &mut out);
        assert!(frame.rays > 0);
        assert!(out
            .disparity
            .iter()
            .all(|&d| d == crate::warp::HOLE || (d.is_finite() && d >= 0.0)));
    }
}

#[test]
fn bad_tiles_and_codebook_sizes_are_refused() {
    let lf = patterned([4, 4, 4, 4], 2, 1);
    for k in [0, 70_000] {
        assert_eq!(
            lf.quantise(&settings(k)).unwrap_err(),
            VqError::Codewords(k)
        );
    }
    for dims in [[3, 2, 2, 2], [32, 1, 1, 1], [16, 16, 2, 1], [0, 1, 1, 1]] {
        assert_eq!(TileShape::new(dims).unwrap_err(), VqError::Tile(dims));
    }
    let tile = TileShape::new([1, 1, 4, 4]).expect("a tile");
    assert_eq!(tile.len(), 16);
    assert_eq!(tile.tiles([5, 4, 13, 10]), [5, 4, 4, 3]);
    // Parts that disagree.
    let colors = vec![0u32; 32];
    assert!(Quantised::new(tile, [1, 1, 1, 2], colors.clone(), vec![], vec![0, 2]).is_err());
    assert!(Quantised::new(tile, [1, 1, 1, 2], colors.clone(), vec![1.0; 3], vec![0, 1]).is_err());
    assert!(Quantised::new(tile, [1, 1, 1, 2], colors.clone(), vec![], vec![0]).is_err());
    assert!(Quantised::new(tile, [1, 1, 1, 2], colors, vec![], vec![0, 1]).is_ok());
}

#[test]
fn a_quantised_light_field_saves_compressed_and_loads_back() {
    let lf = patterned([8, 8, 32, 32], 12, 5);
    let (q, _) = lf.quantise(&settings(32)).expect("quantised");
    let dir = std::env::temp_dir().join(format!("parallax-vq-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let (raw_path, path) = (dir.join("raw.plf"), dir.join("vq.plf"));
    lf.save(&raw_path).expect("saved raw");
    q.save(&path).expect("saved quantised");
    let back = LightField::load(&path).expect("loaded");
    let (Rays::Quantised(a), Rays::Quantised(b)) = (&back.rays, &q.rays) else {
        panic!("quantised light fields load quantised");
    };
    assert_eq!(a, b);
    let (raw, small) = (
        std::fs::metadata(&raw_path).unwrap().len(),
        std::fs::metadata(&path).unwrap().len(),
    );
    // 12 distinct tiles of 16 samples: the indices are most of it, and zstd packs them.
    assert!(raw > 20 * small, "{raw} bytes raw, {small} quantised");

    let bytes = std::fs::read(&path).unwrap();
    let write = |name: &str, b: &[u8]| {
        let p = dir.join(name);
        std::fs::write(&p, b).unwrap();
        p
    };
    let refused = |p: &std::path::Path| {
        let e = LightField::load(p).unwrap_err();
        assert!(e.to_string().contains(&p.display().to_string()), "{e}");
        e
    };
    // Truncated, corrupt in the compressed frame, a bad tile, a huge codebook.
    let p = write("cut.plf", &bytes[..bytes.len() - 3]);
    assert!(matches!(
        refused(&p),
        FileError::Length { .. } | FileError::Corrupt { .. }
    ));
    let mut flipped = bytes.clone();
    let n = flipped.len();
    for b in &mut flipped[n - 40..n - 20] {
        *b ^= 0x5a;
    }
    let p = write("flipped.plf", &flipped);
    assert!(matches!(
        refused(&p),
        FileError::Corrupt { .. } | FileError::Quantised { .. }
    ));
    let tile_at = 124;
    let mut tile = bytes.clone();
    tile[tile_at..tile_at + 4].copy_from_slice(&3u32.to_le_bytes());
    let p = write("tile.plf", &tile);
    assert!(matches!(refused(&p), FileError::Quantised { .. }));
    let mut huge = bytes.clone();
    huge[tile_at + 16..tile_at + 20].copy_from_slice(&u32::MAX.to_le_bytes());
    let p = write("huge.plf", &huge);
    assert!(matches!(refused(&p), FileError::Quantised { .. }));
    // Indices past the codebook: the header says fewer codewords than there are.
    let mut fewer = bytes.clone();
    fewer[tile_at + 16..tile_at + 20].copy_from_slice(&2u32.to_le_bytes());
    let p = write("fewer.plf", &fewer);
    assert!(matches!(refused(&p), FileError::Corrupt { .. }));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn training_tiles_are_scattered_not_strided() {
    // Patterns that vary only along s: a stride through the tile index that is a multiple
    // of the tiles per image row would train on one column and find one codeword.
    let counts = [4, 4, 64, 8];
    let slab = slab(counts);
    let samples: Vec<u32> = (0..slab.len())
        .map(|i| {
            let s = (i % 64) as u32;
            u32::from_le_bytes([(s * 3) as u8, 0, 0, 255])
        })
        .collect();
    let lf = LightField {
        slab,
        rays: Rays::Raw(RawRays::new(samples.clone(), vec![3.0; samples.len()])),
    };
    let (_, report) = lf
        .quantise(&VqSettings {
            codewords: 32,
            training_tiles: 64,
            ..VqSettings::default()
        })
        .expect("quantised");
    assert!(report.codewords >= 16, "{report:?}");
}

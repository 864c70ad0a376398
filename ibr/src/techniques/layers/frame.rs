//! What a layer's image costs this frame and how it is drawn: its predicted error under the
//! fitted warp, the screen rectangle a refresh renders, taking a refresh's image, and the
//! quad that draws the warped image; with the screen-rectangle arithmetic they share.

use super::Unprojector;
use super::{Affine, Config, Homography, Image, Job, Layer, Mode, Predicted, Worker};
use crate::core::{push_quad, UvRect};
use engine::Rgba;
use glam::Vec2;
use std::sync::{Arc, PoisonError};

/// The error of `layer`'s image warped to this frame's projections (`layer.screen`), and
/// this frame's warp; `on_screen` is the part of the layer's rectangle inside the view.
pub(super) fn predict(
    layer: &mut Layer,
    version: u64,
    on_screen: (Vec2, Vec2),
    cfg: &Config,
) -> Predicted {
    let Some(image) = layer.image else {
        return Predicted {
            ratio: f32::INFINITY,
            ..Predicted::default()
        };
    };
    let fitted = layer
        .fitted
        .get_mut()
        .unwrap_or_else(PoisonError::into_inner);
    let of = FitOf {
        image,
        screen: layer.screen,
        version,
        on_screen,
        cfg: *cfg,
    };
    let (predicted, warp) = fit_once(fitted, of);
    layer.warp = warp;
    predicted
}

/// What a fit is made from: an image, its characteristic points' projections this frame,
/// the subject's version, the part of the layer's rectangle inside the view, the settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct FitOf {
    pub image: Image,
    pub screen: [Vec2; 8],
    pub version: u64,
    pub on_screen: (Vec2, Vec2),
    pub cfg: Config,
}

/// [`fit`] of `of`, or the fit `last` holds when it was of the same (the same result: the
/// fit depends on nothing else); `last` then holds this one. The planner asks for a
/// layer's error (a fit) and then, for the layer it chose, fits the same warp to draw it.
pub(super) fn fit_once(
    last: &mut Option<(FitOf, (Predicted, Homography))>,
    of: FitOf,
) -> (Predicted, Homography) {
    if let Some((_, out)) = last.as_ref().filter(|(kept, _)| *kept == of) {
        return *out;
    }
    let out = fit(&of.image, &of.screen, of.version, of.on_screen, &of.cfg);
    *last = Some((of, out));
    out
}

/// The error of `image` warped to `screen` (its characteristic points' projections this
/// frame), and the warp; `on_screen` is the part of the layer's rectangle inside the view.
pub(super) fn fit(
    image: &Image,
    screen: &[Vec2; 8],
    version: u64,
    on_screen: (Vec2, Vec2),
    cfg: &Config,
) -> (Predicted, Homography) {
    let (from, to) = (&image.texels, screen);
    let affine = Homography::from(Affine::fit(from, to, image.scale));
    let mut pixels = affine.max_error(from, to);
    let mut warp = affine;
    if cfg.perspective {
        if let Some(h) = Homography::fit(from, to) {
            let e = h.max_error(from, to);
            if e < pixels {
                (warp, pixels) = (h, e);
            }
        }
    }
    let (w, h) = (image.width as f32, image.height as f32);
    let centre = Vec2::new(w, h) * 0.5;
    let (hi, lo) = Affine {
        m: warp.jacobian(centre),
        t: Vec2::ZERO,
    }
    .stretch();
    let scale = image.scale.max(1e-12);
    let octaves = (hi / scale).log2().abs().max((lo / scale).log2().abs());
    // The on-screen part, taken back into the image, must lie within it on every side
    // where the image was cut (a texel of slack); past the layer's own edges the warp's
    // error is the geometric error's to measure.
    // The image's corners must stay in front of the warp's horizon, to be drawn.
    let [left, top, right, bottom] = image.cut;
    let drawable = image_corners(w, h).iter().all(|&c| warp.map(c).is_some());
    let covered = drawable
        && warp.inverse().is_some_and(|back| {
            let (a, b) = on_screen;
            [a, Vec2::new(b.x, a.y), b, Vec2::new(a.x, b.y)]
                .iter()
                .all(|&p| match back.map(p) {
                    Some((t, _)) => {
                        !(left && t.x < -1.0
                            || top && t.y < -1.0
                            || right && t.x > w + 1.0
                            || bottom && t.y > h + 1.0)
                    }
                    None => false,
                })
        });
    let ratio = if version != image.version || !covered {
        f32::INFINITY
    } else {
        (pixels / cfg.tolerance_px.max(1e-6)).max(octaves / cfg.octaves.max(1e-6))
    };
    let predicted = Predicted {
        pixels,
        octaves,
        covered,
        ratio: if ratio.is_nan() { f32::INFINITY } else { ratio },
    };
    (predicted, warp)
}

/// The refresh of layer `i`, its characteristic points at `screen`: its screen rectangle
/// within `grown`, widened to whole pixels, at [`Config::resolution`] (shrunk to
/// [`Config::max_side`]); `None` when nothing of it is left.
pub(super) fn job(i: usize, screen: &[Vec2; 8], grown: (Vec2, Vec2), cfg: &Config) -> Option<Job> {
    let whole = bounds(screen);
    let (min, max) = clip(whole, grown);
    let cut = [
        whole.0.x < min.x,
        whole.0.y < min.y,
        whole.1.x > max.x,
        whole.1.y > max.y,
    ];
    let (min, max) = (min.floor(), max.ceil());
    let size = max - min;
    if !(size.x >= 1.0 && size.y >= 1.0) {
        return None;
    }
    let texels_per_px = cfg
        .resolution
        .min(cfg.max_side.max(1) as f32 / size.max_element())
        .max(1e-6);
    let n = |len: f32| ((len * texels_per_px).round() as u32).clamp(1, cfg.max_side.max(1));
    Some(Job {
        i,
        min,
        max,
        width: n(size.x),
        height: n(size.y),
        cut,
    })
}

/// Takes worker `w`'s image for `job`'s layer: the texture, where the characteristic
/// points lie in it, and a warp that puts it back where it was rendered.
pub(super) fn finish(layer: &mut Layer, w: &mut Worker, job: &Job, version: u64) {
    if let (Some(tex), Some(held)) = (
        w.refresher.texture.as_mut(),
        layer.material.base_texture.as_mut().and_then(Arc::get_mut),
    ) {
        std::mem::swap(held, tex);
    }
    let size = job.max - job.min;
    let scale = size.x / job.width as f32;
    let per_texel = Vec2::new(job.width as f32, job.height as f32) / size;
    layer.image = Some(Image {
        texels: layer.screen.map(|p| (p - job.min) * per_texel),
        width: job.width,
        height: job.height,
        scale,
        version,
        cut: job.cut,
        gradient: w.gradient,
    });
    layer.warp = Affine {
        m: glam::Mat2::from_diagonal(size / Vec2::new(job.width as f32, job.height as f32)),
        t: job.min,
    }
    .into();
    layer.predicted = Predicted {
        covered: true,
        ..Predicted::default()
    };
    if layer.mode != Mode::Culled {
        layer.mode = Mode::Image;
    }
    layer.refreshes += 1;
}

/// The quad that draws `layer`'s image: its corners where the warp puts them, the nearest
/// at the layer's nearest depth and the others as much farther as their homogeneous
/// weights are larger (all at one depth for an affine warp), so the renderer's
/// perspective-correct interpolation across the quad is the warp. `unprojector` is the
/// camera's, `near` its near plane.
pub(super) fn build_quad(layer: &mut Layer, unprojector: &Unprojector, near: f32) {
    let Some(image) = layer.image else {
        return;
    };
    let z = layer.nearest.max(near * 1.001);
    // Bottom-left first, as `push_quad` takes them.
    let [tl, tr, br, bl] = image_corners(image.width as f32, image.height as f32);
    let mapped = [bl, br, tr, tl].map(|c| layer.warp.map(c));
    let Some(least) = mapped
        .iter()
        .map(|m| m.map(|(_, w)| w))
        .try_fold(f32::MAX, |a, w| Some(a.min(w?)))
    else {
        return;
    };
    let quad = mapped.map(|m| {
        let (px, w) = m.unwrap_or((Vec2::ZERO, least));
        unprojector.unproject(px, z * w / least)
    });
    let full = UvRect {
        min: Vec2::ZERO,
        max: Vec2::ONE,
    };
    layer.quad.clear();
    push_quad(&mut layer.quad, quad, full, Rgba::WHITE, 1.0);
    layer.quad.colors.clear();
}

/// The corners of a `w` x `h` image: top-left, top-right, bottom-right, bottom-left.
pub(super) fn image_corners(w: f32, h: f32) -> [Vec2; 4] {
    [
        Vec2::ZERO,
        Vec2::new(w, 0.0),
        Vec2::new(w, h),
        Vec2::new(0.0, h),
    ]
}

/// The rectangle around `points`.
pub(crate) fn bounds(points: &[Vec2]) -> (Vec2, Vec2) {
    let lo = points.iter().fold(Vec2::splat(f32::MAX), |a, &p| a.min(p));
    let hi = points.iter().fold(Vec2::splat(f32::MIN), |a, &p| a.max(p));
    (lo, hi)
}

pub(super) fn overlaps(a: (Vec2, Vec2), b: (Vec2, Vec2)) -> bool {
    a.0.x < b.1.x && a.0.y < b.1.y && b.0.x < a.1.x && b.0.y < a.1.y
}

pub(crate) fn clip(a: (Vec2, Vec2), to: (Vec2, Vec2)) -> (Vec2, Vec2) {
    (a.0.max(to.0), a.1.min(to.1))
}

/// `r` grown by `f` of its size on every side.
pub(super) fn grow(r: (Vec2, Vec2), f: f32) -> (Vec2, Vec2) {
    let d = (r.1 - r.0) * f.max(0.0);
    (r.0 - d, r.1 + d)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 40 x 20 image of a box whose corners lie at `texels`.
    fn image(version: u64) -> Image {
        let texels = [(2.0, 2.0), (38.0, 2.0), (38.0, 18.0), (2.0, 18.0)];
        let texels: [Vec2; 8] = std::array::from_fn(|k| {
            let (x, y) = texels[k % 4];
            Vec2::new(x, y) + Vec2::splat(0.5 * (k / 4) as f32)
        });
        Image {
            texels,
            width: 40,
            height: 20,
            scale: 1.0,
            version,
            cut: [false; 4],
            gradient: 10.0,
        }
    }

    #[test]
    fn a_fit_is_kept_for_the_same_inputs_and_made_again_for_others() {
        let cfg = Config {
            perspective: true,
            ..Config::default()
        };
        let on_screen = (Vec2::ZERO, Vec2::new(100.0, 100.0));
        let moved = |dx: f32| image(1).texels.map(|t| t * 1.1 + Vec2::new(dx, 3.0));
        let mut last = None;
        let bits = |(p, h): (Predicted, Homography)| format!("{p:?} {h:?}");
        let of = |image, screen, version, on_screen, cfg| FitOf {
            image,
            screen,
            version,
            on_screen,
            cfg,
        };
        let first = fit_once(&mut last, of(image(1), moved(5.0), 1, on_screen, cfg));
        assert_eq!(
            bits(first),
            bits(fit(&image(1), &moved(5.0), 1, on_screen, &cfg))
        );
        // The same inputs again: the kept fit.
        let again = fit_once(&mut last, of(image(1), moved(5.0), 1, on_screen, cfg));
        assert_eq!(bits(again), bits(first));
        // Anything changed (the points, the image, the subject's version, the rectangle,
        // the settings): fitted again, as `fit` would.
        let cases = [
            (image(1), moved(9.0), 1, on_screen, cfg),
            (image(2), moved(9.0), 1, on_screen, cfg),
            (image(2), moved(9.0), 2, on_screen, cfg),
            (
                image(2),
                moved(9.0),
                2,
                (Vec2::ZERO, Vec2::splat(50.0)),
                cfg,
            ),
            (image(2), moved(9.0), 2, on_screen, Config::default()),
        ];
        for (im, screen, version, rect, c) in cases {
            let got = fit_once(&mut last, of(im, screen, version, rect, c));
            assert_eq!(bits(got), bits(fit(&im, &screen, version, rect, &c)));
        }
        // A changed version makes the kept image's fit invalid, as `fit` says.
        let stale = fit_once(&mut last, of(image(2), moved(9.0), 3, on_screen, cfg));
        assert!(stale.0.ratio.is_infinite());
    }
}

//! The one gradient prior every image representation starts from, and the one bake
//! distance: defined here once so the runtime impostors, layers, depth images, octahedral
//! and light-field sets and baked billboards agree on what an image never taken is
//! expected to look like.

/// The neighbour difference assumed for an object never captured or baked (8-bit levels
/// per texel), until a set's first image measures one.
pub(crate) const PRIOR_GRADIENT: f32 = 8.0;

/// The depth-weighted gradient assumed for an object never baked, as a fraction of its
/// gradient, until a set's first bake measures one (the calibration run's subjects measure
/// 0.30 to 0.43).
pub(crate) const PRIOR_DEPTH_SHARE: f32 = 0.5;

/// Bake cameras sit this many radii from the centre: orthographic images do not depend on
/// it, but view-dependent shading (specular) does, and baked images are seen from afar.
pub(crate) const BAKE_DISTANCE: f32 = 16.0;

/// The gradient and depth-weighted gradient expected of a bake never made, from a set's
/// running sums `(gradients, depth gradients, bakes)`: their mean, or the shared prior
/// ([`PRIOR_GRADIENT`], [`PRIOR_DEPTH_SHARE`]) before any bake.
pub(crate) fn prior((gradients, depth_gradients, bakes): (f64, f64, u32)) -> (f32, f32) {
    if bakes == 0 {
        return (PRIOR_GRADIENT, PRIOR_GRADIENT * PRIOR_DEPTH_SHARE);
    }
    let n = f64::from(bakes);
    ((gradients / n) as f32, (depth_gradients / n) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_prior_is_the_shared_constant_before_any_bake_then_the_mean() {
        assert_eq!(prior((0.0, 0.0, 0)), (8.0, 4.0));
        assert_eq!(prior((6.0, 3.0, 2)), (3.0, 1.5));
    }
}

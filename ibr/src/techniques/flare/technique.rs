//! The lens flare through the frame seam: visibility observed in the finished frame, sprites blended into it.

use super::{FlareSource, LensFlare, Seen};
use crate::core::{Counters, FrameView, Observed, Technique};
use engine::{Draw, FrameStats, Target};

/// A lens flare following one light: its visibility is measured in the finished frame
/// (depth taps dimmed by the blended draws in front of the light) and its sprites drawn
/// over it.
#[derive(Clone, Debug)]
pub struct Flare {
    /// The flare: its elements, occlusion and fade settings.
    pub lens: LensFlare,
    /// The light it follows.
    pub source: FlareSource,
}

impl Technique for Flare {
    fn name(&self) -> &str {
        "lens flare"
    }
    fn prepare(&mut self, _view: &FrameView<'_>) {}
    fn draws<'a>(&'a self, _out: &mut Vec<Draw<'a>>) {}
    fn observe(&self, seen: &mut Observed<'_, '_>) -> Option<f32> {
        let (w, h) = (seen.target.width(), seen.target.height());
        let light = super::project(seen.camera, self.source, w, h)?;
        let frame = Seen {
            target: seen.target,
            camera: seen.camera,
            lighting: seen.lighting,
        };
        let (samples, radius) = (self.lens.samples, self.lens.radius_px);
        let draws = seen.draws.iter().copied();
        Some(super::measure(
            seen.capturer,
            &frame,
            draws,
            &light,
            samples,
            radius,
        ))
    }
    /// Fades toward the observed visibility (at least a 60th of a second per frame).
    fn resolve(&mut self, view: &FrameView<'_>, observed: Option<f32>) {
        let dt = view.dt.max(1.0 / 60.0);
        self.lens.set_measured(
            view.camera,
            self.source,
            observed,
            dt,
            view.width,
            view.height,
        );
    }
    /// The sprites blended into the finished frame over their reach only
    /// ([`LensFlare::blend`]), not a second render pass.
    fn overlay_pass(&self, _view: &FrameView<'_>, target: &mut Target) -> FrameStats {
        self.lens.blend(target)
    }
    fn counters(&self) -> Counters {
        Counters {
            quads: self.lens.quad_count() as u64,
            ..Counters::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::FrameLoop;
    use engine::{Camera, FrameOptions, Lighting, Material, Mesh, Renderer, Rgba, Target};
    use glam::{Mat4, Vec3};

    fn camera() -> Camera {
        Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 1.0, 1.0)
    }

    #[test]
    fn a_flare_in_the_loop_measures_as_update_with_blended_does() {
        // A half-opaque blended sheet in front of the sun.
        let sheet = Mesh {
            positions: vec![
                Vec3::new(-50.0, -50.0, -5.0),
                Vec3::new(50.0, -50.0, -5.0),
                Vec3::new(50.0, 50.0, -5.0),
                Vec3::new(-50.0, 50.0, -5.0),
            ],
            indices: vec![0, 1, 2, 0, 2, 3],
            ..Default::default()
        };
        let glass = Material::unlit(Rgba::new(1.0, 1.0, 1.0, 0.4))
            .blended(engine::BlendMode::Alpha)
            .double_sided(true);
        let draws = [Draw {
            mesh: &sheet,
            material: &glass,
            transform: Mat4::IDENTITY,
        }];
        let cam = camera();
        let lighting = Lighting::default();
        let source = FlareSource::Directional(Vec3::new(0.2, 0.1, -1.0));
        let (w, h) = (64, 48);
        let view = FrameView {
            camera: &cam,
            width: w,
            height: h,
            lighting: &lighting,
            time: 0.0,
            dt: 1e6, // no fade
        };
        let mut flare = Flare {
            lens: LensFlare::default(),
            source,
        };
        let mut target = Target::new(w, h);
        let mut renderer = Renderer::new();
        let mut frame = FrameLoop::new();
        let mut list: [&mut dyn Technique; 1] = [&mut flare];
        frame.render(
            &mut renderer,
            draws,
            &mut list,
            &view,
            &mut target,
            &FrameOptions::default(),
        );
        let in_loop = flare.lens.measured();
        assert!((in_loop - 0.6).abs() < 0.01, "{in_loop}");
        assert!(
            flare.lens.quad_count() > 0,
            "its sprites were drawn over the frame"
        );
        let mut alone = LensFlare::default();
        let mut plain = Target::new(w, h);
        renderer.render(draws, &cam, &lighting, &mut plain, &FrameOptions::default());
        alone.update_with_blended(&cam, &plain, source, 1e6, &lighting, draws);
        assert_eq!(alone.measured(), in_loop);
    }
}

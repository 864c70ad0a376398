//! Octahedral impostors through the frame seam: culled off the image, recomposed when the view moves.

use super::OctahedralImpostor;
use crate::core::{Counters, FrameView, Technique};
use engine::Draw;

/// Culled while its bounding sphere is off the image: then neither updated nor drawn.
impl Technique for OctahedralImpostor {
    fn name(&self) -> &str {
        "octahedral impostor"
    }
    fn prepare(&mut self, view: &FrameView<'_>) {
        self.update_in_view(view.camera, view.width, view.height);
    }
    fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        if self.in_view() {
            out.push(self.draw());
        }
    }
    fn counters(&self) -> Counters {
        let shown = u64::from(self.in_view());
        Counters {
            quads: shown,
            images: shown,
            refreshes: u64::from(self.recomposed()),
            ..Counters::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::FrameLoop;
    use engine::{Camera, FrameOptions, Lighting, Material, Renderer, Rgba, Target};
    use glam::{Mat4, Vec3};

    #[test]
    fn an_octahedral_impostor_off_the_image_is_neither_updated_nor_drawn() {
        let mut subject = crate::core::MeshGroup::new().with(
            std::sync::Arc::new(engine::procedural::uv_sphere(1.0, 8, 12)),
            std::sync::Arc::new(Material::lit(Rgba::new(0.8, 0.3, 0.2, 1.0))),
            Mat4::IDENTITY,
        );
        let lighting = Lighting::default();
        let mut imp = OctahedralImpostor::bake(
            &mut subject,
            &lighting,
            4,
            16,
            crate::techniques::octahedral::Layout::Full,
        );
        let mut frame = FrameLoop::new();
        let mut target = Target::new(32, 32);
        let mut run = |imp: &mut OctahedralImpostor, eye: Vec3, at: Vec3| {
            let cam = Camera::look_at(eye, at, Vec3::Y, 1.0, 1.0);
            let view = FrameView {
                camera: &cam,
                width: 32,
                height: 32,
                lighting: &lighting,
                time: 0.0,
                dt: 0.0,
            };
            let stats = frame.render(
                &mut Renderer::new(),
                [],
                &mut [imp],
                &view,
                &mut target,
                &FrameOptions::default(),
            );
            (stats.draws, frame.counters[0])
        };
        // Seen from the side (the bake starts from above): recomposed and drawn.
        let (draws, c) = run(&mut imp, Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO);
        assert_eq!((draws, c.images, c.quads, c.refreshes), (1, 1, 1, 1));
        let frames = imp.frames();
        // Looking away from another side: culled, and the image keeps its frames.
        let (draws, c) = run(&mut imp, Vec3::new(4.0, 0.0, 0.0), Vec3::new(8.0, 0.0, 0.0));
        assert_eq!((draws, c.images, c.quads, c.refreshes), (0, 0, 0, 0));
        assert!(!imp.in_view());
        assert_eq!(imp.frames(), frames, "not updated while culled");
        // Back in view from that side: recomposed for it.
        let (draws, c) = run(&mut imp, Vec3::new(4.0, 0.0, 0.0), Vec3::ZERO);
        assert_eq!((draws, c.images, c.refreshes), (1, 1, 1));
        assert_ne!(imp.frames(), frames);
    }
}

//! The showcase's building tour (`showcase --building`): the procedural building's hall
//! drawn as geometry, its three furnished rooms seen through LDI portals as the camera
//! walks along the hall and through the middle door, with a readout of the portals' work
//! and a debug view that tints warped pixels green.

use super::moment::MomentFrame;
use crate::building::Building;
use engine::{Camera, FrameStats, Renderer, Rgba, Target};
use ibr::portal::{PortalConfig, PortalFrame, Portals};
use ibr::subject::Subject;
use ibr::technique::FrameView;

/// Furniture triangles per room.
pub const ROOM_TRIANGLES: u32 = 200_000;
/// The tour's vertical field of view, radians.
pub const FOV_Y: f32 = 1.05;
/// The clear colour (nothing should show it: the building is closed).
pub const CLEAR: Rgba = Rgba::new(0.05, 0.05, 0.06, 1.0);

/// The building, its portals and the frame loop's memory.
#[derive(Debug)]
pub struct BuildingTour {
    pub building: Building,
    pub portals: Portals,
    frame: MomentFrame,
}

impl BuildingTour {
    pub fn new() -> Self {
        Self::with_triangles(ROOM_TRIANGLES)
    }

    /// The tour with `triangles` of furniture per room.
    pub fn with_triangles(triangles: u32) -> Self {
        let building = Building::new(triangles, 5);
        let portals = Portals::new(building.portals(), PortalConfig::default());
        BuildingTour {
            building,
            portals,
            frame: MomentFrame::default(),
        }
    }

    /// The camera at frame `i` of `n` along the walkthrough, for a `width` x `height`
    /// image.
    pub fn camera(i: usize, n: usize, width: u32, height: u32) -> Camera {
        let t = i as f32 / (n.max(2) - 1) as f32;
        let (eye, at) = Building::path(t);
        Camera::look_at(eye, at, glam::Vec3::Y, FOV_Y, 1.0)
            .with_aspect(width, height)
            .with_depth_range(0.05, 60.0)
    }

    /// Renders the hall and the portals (rooms as geometry where the portals say so).
    pub fn render(
        &mut self,
        renderer: &mut Renderer,
        camera: &Camera,
        target: &mut Target,
    ) -> FrameStats {
        let view = FrameView {
            camera,
            width: target.width(),
            height: target.height(),
            lighting: &self.building.lighting,
            time: 0.0,
            dt: 0.0,
        };
        self.frame.render(
            renderer,
            |d| self.building.hall.draws(d),
            &mut self.portals,
            &view,
            target,
            CLEAR,
        )
    }

    /// What the portals did in the last frame.
    pub fn last(&self) -> PortalFrame {
        self.portals.last()
    }

    /// One line for the window and the console: the portals' work in the last frame.
    pub fn readout(&self) -> String {
        let f = self.last();
        format!(
            "PORTALS {} WARPED {} GEOMETRY ({} TRIS)  {} SAMPLES  {} HOLES  {} PX  {} REBUILDS  PREDICTED {:.1} PX{}",
            f.warped,
            f.geometry,
            f.triangles,
            f.stats.samples,
            f.holes,
            f.pixels,
            f.rebuilds,
            f.predicted_px,
            if self.portals.debug_tint {
                "  TINT"
            } else {
                ""
            }
        )
    }
}

impl Default for BuildingTour {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tour_warps_rooms_in_the_hall_and_draws_geometry_inside_one() {
        let mut tour = BuildingTour::with_triangles(2_000);
        // Whole LDIs a frame, so the ten frames' big steps are not all spent building.
        tour.portals.config.views_per_frame = 5;
        let mut renderer = Renderer::new();
        let (w, h, n) = (160, 90, 10);
        let mut target = Target::new(w, h);
        let (mut warped, mut inside) = (0, 0);
        for i in 0..n {
            let cam = BuildingTour::camera(i, n, w, h);
            tour.render(&mut renderer, &cam, &mut target);
            let f = tour.last();
            warped += f.warped;
            if i == n - 1 {
                inside = f.geometry;
            }
            assert!(tour.readout().starts_with("PORTALS"));
        }
        assert!(warped >= 5, "{warped} portal frames warped along the hall");
        assert!(inside >= 1, "the middle room is geometry from inside it");
    }

    /// The first frame at `camera` of the full tour with no LDI built (so the rooms in view
    /// are geometry), its rings' levels of detail within `lod_px`: the frame and the
    /// room triangles drawn.
    fn rooms_as_geometry(camera: &Camera, w: u32, h: u32, lod_px: f32) -> (Target, u64) {
        let mut tour = BuildingTour::new();
        tour.portals.config.views_per_frame = 0;
        tour.portals.config.lod_px = lod_px;
        let mut target = Target::new(w, h);
        tour.render(&mut Renderer::new(), camera, &mut target);
        assert_eq!(tour.last().warped, 0);
        (target, tour.last().triangles)
    }

    #[test]
    fn rooms_seen_from_the_hall_draw_coarse_rings_within_half_a_pixel() {
        let (w, h) = (320, 180);
        // Along the hall, the left and middle rooms' statues in view through the doors.
        let cam = BuildingTour::camera(12, 60, w, h);
        let (full, full_tris) = rooms_as_geometry(&cam, w, h, 0.0);
        let (coarse, tris) = rooms_as_geometry(&cam, w, h, 0.5);
        // The rings seen (67k triangles each at full detail) are far: a few hundred
        // triangles each.
        assert!(full_tris > 100_000, "{full_tris} full");
        assert!(
            tris * 20 < full_tris,
            "{tris} with levels of detail, {full_tris} full"
        );
        assert!(tris <= 4_000, "{tris} room triangles set up");
        // Each pixel's colour is found within one pixel in the full-detail frame, and the
        // other way round: the surfaces moved by at most half a pixel (the shading of the
        // coarser normals may differ by a few levels). A half-pixel move flips pixels on
        // silhouettes, a few of which (a ring's thin edge) have no like neighbour: at most
        // 1 in 2,000 (measured: 10 of 113,288 pixel pairs, 18 differing at all, 52.8 dB).
        let gap = |a: u32, b: u32| {
            let (a, b) = (a.to_le_bytes(), b.to_le_bytes());
            (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap()
        };
        let (mut differ, mut sq, mut worst, mut missed) = (0u32, 0f64, 0u8, 0u32);
        for (one, other) in [(&coarse, &full), (&full, &coarse)] {
            for y in 1..h - 1 {
                for x in 1..w - 1 {
                    let c = one.pixel(x, y).unwrap();
                    let gap = (0..9)
                        .map(|k| gap(c, other.pixel(x + k % 3 - 1, y + k / 3 - 1).unwrap()))
                        .min()
                        .unwrap();
                    worst = worst.max(gap);
                    missed += (gap > 6) as u32;
                    let d = other.pixel(x, y).unwrap();
                    differ += (c != d) as u32;
                    let (c, d) = (c.to_le_bytes(), d.to_le_bytes());
                    sq += (0..3)
                        .map(|i| (c[i] as f64 - d[i] as f64).powi(2))
                        .sum::<f64>();
                }
            }
        }
        let mse = sq / (2.0 * 3.0 * (w - 2) as f64 * (h - 2) as f64);
        let psnr = 10.0 * (255.0f64 * 255.0 / mse.max(1e-12)).log10();
        eprintln!("room triangles {tris} (full {full_tris}); {psnr:.1} dB, {differ} differ");
        eprintln!("{missed} not within a pixel (worst {worst})");
        let pairs = 2 * (w - 2) * (h - 2);
        assert!(
            missed * 2_000 <= pairs,
            "{missed} of {pairs} not within a pixel"
        );
        assert!(
            differ * 1_000 <= pairs,
            "{differ} of {pairs} pixel pairs differ"
        );
        assert!(psnr > 45.0, "{psnr:.1} dB, {differ} pixel pairs differ");
    }

    #[test]
    fn the_debug_tint_changes_warped_pixels_only() {
        let (w, h) = (160, 90);
        let cam = BuildingTour::camera(3, 10, w, h);
        let run = |tint: bool| {
            let mut tour = BuildingTour::with_triangles(2_000);
            tour.portals.debug_tint = tint;
            let mut target = Target::new(w, h);
            // The portals' LDIs are captured a few views a frame: render until built.
            for _ in 0..10 {
                tour.render(&mut Renderer::new(), &cam, &mut target);
            }
            (target, tour.portals.image().clone())
        };
        let ((plain, image), (tinted, _)) = (run(false), run(true));
        let mut changed = 0;
        for y in 0..h {
            for x in 0..w {
                let warped = image.is_filled((y * w + x) as usize);
                let same = plain.pixel(x, y) == tinted.pixel(x, y);
                assert!(warped || same, "({x}, {y}) is not warped but changed");
                changed += !same as u32;
            }
        }
        assert!(changed > 100, "{changed} pixels tinted");
    }
}

//! LDIs built at loading along a known camera path: a walk whose eyes are known ahead
//! (a guided tour) captures and merges every LDI it will want before its first frame,
//! and each frame that would start a build takes the one built for its eye instead.

use super::{fresh, Portal, PortalConfig, Portals};
use crate::core::LayeredDepthImage;
use crate::warp::predict::parallax_px;
use crate::warp::Prepared;
use engine::{Camera, Lighting};
use glam::Vec3;

/// An LDI built ahead, with what the portal keeps of a build.
#[derive(Clone, Debug)]
pub(super) struct Built {
    ldi: LayeredDepthImage,
    prepared: Prepared,
    range: Option<(f32, f32)>,
    built_at: (Vec3, f32, u32),
}

impl Portal {
    /// LDIs built ahead for this portal.
    pub fn built_ahead(&self) -> usize {
        self.ahead.len()
    }

    /// The LDI built ahead that the frame's `camera` (`width` x `height`, the opening
    /// `screen` pixels across) may warp, the one with the least predicted parallax, made
    /// current; whether there was one.
    pub(super) fn take_ahead(
        &mut self,
        camera: &Camera,
        (width, height): (u32, u32),
        screen: u32,
        config: &PortalConfig,
    ) -> bool {
        let eye = camera.eye();
        let best = self
            .ahead
            .iter()
            .enumerate()
            .filter_map(|(k, b)| {
                let predicted = b.range.map_or(0.0, |r| {
                    parallax_px(r, &b.ldi.camera, camera, width, height)
                });
                fresh(Some(b.built_at), predicted, eye, screen, config).then_some((k, predicted))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let Some((k, _)) = best else {
            return false;
        };
        let b = &self.ahead[k];
        self.ldi = Some(b.ldi.clone());
        self.prepared.clone_from(&b.prepared);
        self.range = b.range;
        self.built_at = Some(b.built_at);
        true
    }

    /// What the portal's last build left, as an LDI built ahead.
    fn current(&self) -> Option<Built> {
        Some(Built {
            ldi: self.ldi.clone()?,
            prepared: self.prepared.clone(),
            range: self.range,
            built_at: self.built_at?,
        })
    }

    /// Forgets the walk's state (its image, build, mode and rebuild count), keeping the
    /// LDIs built ahead.
    fn restart(&mut self) {
        let ahead = std::mem::take(&mut self.ahead);
        *self = Portal::new(self.opening, std::mem::take(&mut self.behind));
        self.ahead = ahead;
    }
}

impl Portals {
    /// Builds ahead the LDIs a walk through `cameras` (each `width` x `height`) will want:
    /// the frames are run through the portals' decisions with every build finished in the
    /// frame it starts, each LDI built is kept, and the portals start over with them. A
    /// frame of the walk then takes the LDI built for its eye (the least predicted parallax
    /// among those its region and tolerance accept) instead of capturing; off the path, it
    /// builds as before. Returns the LDIs built.
    pub fn prepare_path(
        &mut self,
        cameras: impl IntoIterator<Item = Camera>,
        width: u32,
        height: u32,
        lighting: &Lighting,
    ) -> usize {
        let saved = self.config.views_per_frame;
        self.config.views_per_frame = 5 * self.portals.len();
        for camera in cameras {
            let before: Vec<u64> = self.portals.iter().map(Portal::rebuilds).collect();
            self.update(&camera, width, height, lighting);
            for (p, was) in self.portals.iter_mut().zip(before) {
                if p.rebuilds() > was {
                    if let Some(b) = p.current() {
                        p.ahead.push(b);
                    }
                }
            }
        }
        self.config.views_per_frame = saved;
        self.portals.iter_mut().for_each(Portal::restart);
        self.last = Default::default();
        self.portals.iter().map(Portal::built_ahead).sum()
    }
}

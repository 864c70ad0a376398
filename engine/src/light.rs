//! Lights for the `Lit` shading model. Directions and positions are in world space;
//! colours are linear and may exceed 1 (intensity).

use crate::color::Rgba;
use glam::Vec3;

/// A light source.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Light arriving along `direction` (pointing from the light into the scene).
    Directional {
        /// The direction the light travels, world space; any length (normalised when
        /// shading; zero lights nothing).
        direction: Vec3,
        /// Linear RGB intensity, unattenuated; alpha is ignored.
        color: Rgba,
    },
    /// A point light whose intensity falls off smoothly to zero at `range`.
    Point {
        /// Position, world space.
        position: Vec3,
        /// Linear RGB intensity; at distance `d` it is scaled by
        /// `(1 - min(d / range, 1)^2)^2 / (d^2 + 1)`. Alpha is ignored.
        color: Rgba,
        /// Distance, world units, at and beyond which the light contributes nothing; > 0.
        range: f32,
    },
}

/// Lighting shared by every lit material in a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Lighting {
    /// Linear RGB light reaching every point from all around, added to the diffuse factor
    /// (so it multiplies the surface's base colour); alpha is ignored.
    pub ambient: Rgba,
    /// The lights, summed: Lambert diffuse plus Blinn-Phong specular per light.
    pub lights: Vec<Light>,
}

impl Default for Lighting {
    fn default() -> Self {
        Lighting {
            ambient: Rgba::new(0.15, 0.15, 0.17, 1.0),
            lights: vec![Light::Directional {
                direction: Vec3::new(-0.35, -0.6, -0.72).normalize(),
                color: Rgba::new(1.0, 0.97, 0.92, 1.0),
            }],
        }
    }
}

impl Lighting {
    /// One white sun whose light travels along `direction` (normalised here) over a grey
    /// ambient term of `ambient`.
    pub fn white_sun(ambient: f32, direction: Vec3) -> Lighting {
        Lighting {
            ambient: Rgba::new(ambient, ambient, ambient, 1.0),
            lights: vec![Light::Directional {
                direction: direction.normalize_or(Vec3::NEG_Y),
                color: Rgba::WHITE,
            }],
        }
    }

    /// The first directional light (the sun): the direction its light travels, and its
    /// colour.
    pub fn sun(&self) -> Option<(Vec3, Rgba)> {
        self.lights.iter().find_map(|l| match *l {
            Light::Directional { direction, color } => Some((direction, color)),
            Light::Point { .. } => None,
        })
    }
}

//! The one shading model of the workspace: ambient + Lambert + Blinn-Phong under directional
//! lights, in linear RGB.
//!
//! The rasteriser, every sphere method and the reference ray tracer call [`Lighting::shade`], so a
//! difference between a method's image and the reference is the method's own error, not a
//! lighting mismatch (ARCHITECTURE.md, "Shared conventions").
//!
//! Lights are directional ("at infinity", as Seed 002 assumes) and given in world space.
//! A method that works in eye space converts them once per frame with [`Lighting::to_eye`].
//!
//! ```
//! use texmap_core::shade::{Lighting, Material};
//! use texmap_core::glam::Vec3;
//! let lighting = Lighting::new(Vec3::splat(0.1), &[(Vec3::Z, Vec3::ONE)]).unwrap();
//! let m = Material::matte(Vec3::new(1.0, 0.0, 0.0));
//! // A surface facing the light head-on: ambient + full diffuse.
//! let c = lighting.shade(&m, Vec3::Z, Vec3::Z);
//! assert!((c.x - 1.1).abs() < 1e-6 && c.y.abs() < 1e-6);
//! ```

use glam::Vec3;

use crate::camera::Camera;

/// The most directional lights one [`Lighting`] holds; a fixed array keeps shading free of
/// allocation and indirection.
pub const MAX_LIGHTS: usize = 4;

/// A light at infinity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    /// Unit vector from the surface TOWARD the light.
    pub to_light: Vec3,
    /// Linear RGB radiance scale.
    pub color: Vec3,
}

/// A surface's reflectance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Linear RGB diffuse (and ambient) reflectance.
    pub base_color: Vec3,
    /// Specular reflectance (grey).
    pub specular: f32,
    /// Blinn-Phong exponent.
    pub shininess: f32,
}

impl Material {
    /// A plastic-like material: the base colour with a white highlight (specular 0.35, exponent 40),
    /// the default look of the molecule renderers.
    pub fn plastic(base_color: Vec3) -> Material {
        Material {
            base_color,
            specular: 0.35,
            shininess: 40.0,
        }
    }

    /// Diffuse only.
    pub fn matte(base_color: Vec3) -> Material {
        Material {
            base_color,
            specular: 0.0,
            shininess: 1.0,
        }
    }
}

/// Why a lighting set-up was refused.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum LightingError {
    TooManyLights {
        count: usize,
    },
    /// A light direction is zero or not finite, or a colour is not finite.
    BadLight {
        index: usize,
    },
    BadAmbient,
}

impl std::fmt::Display for LightingError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LightingError::TooManyLights { count } => {
                write!(f, "{count} lights given, at most {MAX_LIGHTS} supported")
            }
            LightingError::BadLight { index } => write!(
                f,
                "light {index}: direction must be finite and non-zero, colour finite"
            ),
            LightingError::BadAmbient => write!(f, "ambient colour must be finite"),
        }
    }
}

impl std::error::Error for LightingError {}

/// Ambient light plus up to [`MAX_LIGHTS`] directional lights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lighting {
    pub ambient: Vec3,
    lights: [DirectionalLight; MAX_LIGHTS],
    count: usize,
}

impl Lighting {
    /// Lighting from an ambient colour and `(direction toward the light, colour)` pairs; the
    /// directions are normalised here.
    pub fn new(ambient: Vec3, lights: &[(Vec3, Vec3)]) -> Result<Lighting, LightingError> {
        if lights.len() > MAX_LIGHTS {
            return Err(LightingError::TooManyLights {
                count: lights.len(),
            });
        }
        if !ambient.is_finite() {
            return Err(LightingError::BadAmbient);
        }
        let mut out = [DirectionalLight {
            to_light: Vec3::Z,
            color: Vec3::ZERO,
        }; MAX_LIGHTS];
        for (i, &(d, c)) in lights.iter().enumerate() {
            let len = d.length();
            if !(len.is_finite() && len > 0.0 && c.is_finite()) {
                return Err(LightingError::BadLight { index: i });
            }
            out[i] = DirectionalLight {
                to_light: d / len,
                color: c,
            };
        }
        Ok(Lighting {
            ambient,
            lights: out,
            count: lights.len(),
        })
    }

    /// The default molecule lighting for a camera: a key light from the upper left behind the
    /// viewer and a weak fill light, fixed to the camera (given in world space for this camera).
    pub fn default_for(camera: &Camera) -> Lighting {
        let key = camera.dir_to_world(Vec3::new(-0.4, 0.55, 1.0));
        let fill = camera.dir_to_world(Vec3::new(0.6, -0.2, 0.8));
        Lighting::new(
            Vec3::splat(0.12),
            &[(key, Vec3::splat(0.85)), (fill, Vec3::splat(0.2))],
        )
        .expect("constant lights are valid")
    }

    /// The lights.
    #[inline]
    pub fn lights(&self) -> &[DirectionalLight] {
        &self.lights[..self.count]
    }

    /// The same lighting with directions expressed in the camera's eye space.
    pub fn to_eye(&self, camera: &Camera) -> Lighting {
        let mut l = *self;
        for light in &mut l.lights[..l.count] {
            light.to_light = camera.dir_to_eye(light.to_light);
        }
        l
    }

    /// Outgoing linear radiance at a surface with unit normal `n`, unit vector toward the viewer
    /// `v`, and material `m`:
    /// `ambient·base + Σ colour·(base·max(n·l, 0) + specular·max(n·h, 0)^shininess)` with
    /// `h = normalize(l + v)`; the specular term is present only where `n·l > 0`.
    /// All vectors in the same frame as the lights.
    #[inline]
    pub fn shade(&self, m: &Material, n: Vec3, v: Vec3) -> Vec3 {
        // Scaling by exactly 1 and keeping every light changes no bit.
        self.shade_with(m, n, v, 1.0, u32::MAX)
    }

    /// [`Lighting::shade`] with the ambient term scaled by `ambient_scale` (ambient occlusion:
    /// the unoccluded fraction in [0, 1]) and light `i` present only where bit `i` of
    /// `lights_visible` is set (hard shadows). `shade(m, n, v)` is
    /// `shade_with(m, n, v, 1.0, u32::MAX)`.
    #[inline]
    pub fn shade_with(
        &self,
        m: &Material,
        n: Vec3,
        v: Vec3,
        ambient_scale: f32,
        lights_visible: u32,
    ) -> Vec3 {
        let mut c = self.ambient * m.base_color * ambient_scale;
        for (i, light) in self.lights[..self.count].iter().enumerate() {
            if lights_visible & (1 << i) == 0 {
                continue;
            }
            let ndl = n.dot(light.to_light);
            if ndl > 0.0 {
                let mut term = m.base_color * ndl;
                if m.specular > 0.0 {
                    let h = (light.to_light + v).normalize_or_zero();
                    let ndh = n.dot(h).max(0.0);
                    term += Vec3::splat(m.specular * ndh.powf(m.shininess));
                }
                c += light.color * term;
            }
        }
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blinn_phong_peak_and_falloff_match_hand_values() {
        let l = Lighting::new(Vec3::ZERO, &[(Vec3::Z, Vec3::ONE)]).unwrap();
        let m = Material {
            base_color: Vec3::splat(0.5),
            specular: 1.0,
            shininess: 2.0,
        };
        // Normal, light and view aligned: diffuse 0.5 + specular 1.
        let c = l.shade(&m, Vec3::Z, Vec3::Z);
        assert!((c.x - 1.5).abs() < 1e-6, "{c}");
        // Normal at 60° from light and view: n·l = 0.5, h = z, n·h = 0.5 -> 0.25 + 0.25.
        let n = Vec3::new(3f32.sqrt() / 2.0, 0.0, 0.5);
        let c = l.shade(&m, n, Vec3::Z);
        assert!((c.x - 0.5).abs() < 1e-5, "{c}");
        // Facing away: nothing.
        assert_eq!(l.shade(&m, -Vec3::Z, Vec3::Z), Vec3::ZERO);
    }

    #[test]
    fn shade_with_all_on_is_shade_and_masks_lights() {
        let l = Lighting::new(
            Vec3::splat(0.2),
            &[(Vec3::Z, Vec3::splat(0.7)), (Vec3::X, Vec3::splat(0.3))],
        )
        .unwrap();
        let m = Material::plastic(Vec3::new(0.3, 0.5, 0.9));
        let n = Vec3::new(0.4, 0.1, 0.9).normalize();
        let v = Vec3::new(0.0, 0.2, 1.0).normalize();
        assert_eq!(l.shade_with(&m, n, v, 1.0, u32::MAX), l.shade(&m, n, v));
        // No light and no ambient: black. Ambient alone: ambient * base * scale.
        assert_eq!(l.shade_with(&m, n, v, 0.0, 0), Vec3::ZERO);
        let a = l.shade_with(&m, n, v, 0.5, 0);
        assert!((a - Vec3::splat(0.1) * m.base_color).length() < 1e-7);
        // The two lights add up to the whole.
        let k = l.shade_with(&m, n, v, 0.0, 1);
        let f = l.shade_with(&m, n, v, 0.0, 2);
        assert!((a * 2.0 + k + f - l.shade(&m, n, v)).length() < 1e-6);
    }

    #[test]
    fn bad_lights_are_refused() {
        assert_eq!(
            Lighting::new(Vec3::ZERO, &[(Vec3::ZERO, Vec3::ONE)]),
            Err(LightingError::BadLight { index: 0 })
        );
        assert!(Lighting::new(Vec3::NAN, &[]).is_err());
        assert!(Lighting::new(Vec3::ZERO, &[(Vec3::Z, Vec3::ONE); 5]).is_err());
    }

    #[test]
    fn to_eye_keeps_shading_invariant() {
        let cam = Camera::perspective_look_at(
            Vec3::new(3.0, 1.0, 4.0),
            Vec3::ZERO,
            Vec3::Y,
            40.0,
            10,
            10,
        )
        .unwrap();
        let lw = Lighting::default_for(&cam);
        let le = lw.to_eye(&cam);
        let m = Material::plastic(Vec3::new(0.2, 0.4, 0.9));
        let n = Vec3::new(0.3, 0.8, 0.2).normalize();
        let v = Vec3::new(-0.1, 0.3, 0.9).normalize();
        let a = lw.shade(&m, n, v);
        let b = le.shade(&m, cam.dir_to_eye(n), cam.dir_to_eye(v));
        assert!((a - b).length() < 1e-5, "{a} vs {b}");
    }
}

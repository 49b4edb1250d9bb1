//! The background environment: radiance arriving from infinity along each direction.
//!
//! Either a latitude-longitude image (linear RGB, `width = 2 · height`, the layout of HDR
//! panoramas; the caller decodes PNG, EXR or Radiance HDR and hands the texels over, so this crate opens no
//! file) or a built-in analytic sky. The same [`Environment::radiance`] function feeds the static
//! maps and the reference ray tracer's escaped rays, so a difference between a method and the
//! reference is the method's sampling, never a different background.
//!
//! Lat-long layout (world frame, y up): column `u = ½ + atan2(d_x, −d_z)/(2π)` (the −z direction
//! is the image centre), row `v = acos(d_y)/π` (row 0 is straight up). Lookups are bilinear,
//! wrapping in `u` and clamping in `v`.

use glam::Vec3;

use crate::error::EnvMapError;

/// The environment seen along directions that hit nothing.
#[derive(Clone, Debug, PartialEq)]
pub enum Environment {
    /// The built-in sky: a blue gradient with a sun above the horizon, and below it a checkered
    /// ground plane one unit down (sharp edges that show where a map's sampling is coarse),
    /// fading to its mean colour towards the horizon.
    Sky,
    /// A latitude-longitude image (see the module docs).
    LatLong(LatLong),
}

/// A validated latitude-longitude image of linear RGB texels.
#[derive(Clone, Debug, PartialEq)]
pub struct LatLong {
    width: u32,
    height: u32,
    texels: Vec<Vec3>,
}

impl LatLong {
    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.height
    }
}

/// Sun direction of the built-in sky.
const SUN: Vec3 = Vec3::new(0.48, 0.6, -0.64);

impl Environment {
    /// A latitude-longitude environment from linear RGB texels (row 0 = straight up). Errors: the
    /// image is not 2:1 or empty, the buffer length differs from `width · height`, or a texel is
    /// negative or not finite.
    pub fn lat_long(
        width: u32,
        height: u32,
        texels: Vec<Vec3>,
    ) -> Result<Environment, EnvMapError> {
        if height == 0 || width != height.saturating_mul(2) {
            return Err(EnvMapError::EnvironmentShape { width, height });
        }
        let expected = width as usize * height as usize;
        if texels.len() != expected {
            return Err(EnvMapError::EnvironmentLength {
                expected,
                actual: texels.len(),
            });
        }
        if let Some(i) = texels
            .iter()
            .position(|t| !(t.is_finite() && t.cmpge(Vec3::ZERO).all()))
        {
            return Err(EnvMapError::EnvironmentTexel {
                x: (i % width as usize) as u32,
                y: (i / width as usize) as u32,
            });
        }
        Ok(Environment::LatLong(LatLong {
            width,
            height,
            texels,
        }))
    }

    /// Linear RGB radiance arriving along unit direction `d` (world frame). Finite for any input.
    #[inline]
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        let d = d.normalize_or(Vec3::Y);
        match self {
            Environment::Sky => sky(d),
            Environment::LatLong(img) => img.bilinear(d),
        }
    }
}

/// The built-in sky (see [`Environment::Sky`]).
#[inline]
fn sky(d: Vec3) -> Vec3 {
    if d.y >= 0.0 {
        let zenith = Vec3::new(0.10, 0.25, 0.65);
        let horizon = Vec3::new(0.75, 0.80, 0.90);
        let t = d.y.sqrt();
        let base = horizon + (zenith - horizon) * t;
        let s = d.dot(SUN.normalize());
        if s > 0.995 {
            Vec3::new(6.0, 5.5, 4.5)
        } else {
            base
        }
    } else {
        // A checkered ground plane one unit below the viewer, squares of one unit: the point
        // seen is d · (1/−d_y); no trigonometry.
        let k = 1.0 / (-d.y).max(1e-6);
        let (x, z) = ((d.x * k).floor(), (d.z * k).floor());
        // Parity of the square (clamped: far squares are faded to the mean anyway).
        let lim = 1e6;
        let odd = ((x.clamp(-lim, lim) as i64 + z.clamp(-lim, lim) as i64) & 1) == 1;
        // Fade to the mean towards the horizon, where the squares shrink below any pixel.
        let mean = Vec3::new(0.275, 0.215, 0.125);
        let sq = if odd {
            Vec3::new(0.10, 0.08, 0.05)
        } else {
            Vec3::new(0.45, 0.35, 0.20)
        };
        let f = (-d.y * 8.0).min(1.0);
        mean + (sq - mean) * f
    }
}

impl LatLong {
    #[inline]
    fn texel(&self, x: i64, y: i64) -> Vec3 {
        let w = self.width as i64;
        let h = self.height as i64;
        let x = x.rem_euclid(w);
        let y = y.clamp(0, h - 1);
        self.texels[(y * w + x) as usize]
    }

    #[inline]
    fn bilinear(&self, d: Vec3) -> Vec3 {
        let u = 0.5 + d.x.atan2(-d.z) / std::f32::consts::TAU;
        let v = d.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
        let x = u * self.width as f32 - 0.5;
        let y = v * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let a = self.texel(x0, y0) * (1.0 - fx) + self.texel(x0 + 1, y0) * fx;
        let b = self.texel(x0, y0 + 1) * (1.0 - fx) + self.texel(x0 + 1, y0 + 1) * fx;
        a * (1.0 - fy) + b * fy
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrong_shapes_and_bad_texels_are_refused() {
        assert!(matches!(
            Environment::lat_long(4, 4, vec![Vec3::ONE; 16]),
            Err(EnvMapError::EnvironmentShape { .. })
        ));
        assert!(matches!(
            Environment::lat_long(0, 0, vec![]),
            Err(EnvMapError::EnvironmentShape { .. })
        ));
        assert!(matches!(
            Environment::lat_long(4, 2, vec![Vec3::ONE; 7]),
            Err(EnvMapError::EnvironmentLength {
                expected: 8,
                actual: 7
            })
        ));
        let mut t = vec![Vec3::ONE; 8];
        t[5] = Vec3::NAN;
        assert!(matches!(
            Environment::lat_long(4, 2, t),
            Err(EnvMapError::EnvironmentTexel { x: 1, y: 1 })
        ));
    }

    #[test]
    fn lat_long_rows_and_columns_follow_the_layout() {
        // 8x4 image: texel value encodes (column, row).
        let texels = (0..32)
            .map(|i| Vec3::new((i % 8) as f32, (i / 8) as f32, 0.0))
            .collect();
        let env = Environment::lat_long(8, 4, texels).unwrap();
        // Straight up is the top row (clamped: exactly row 0).
        assert!((env.radiance(Vec3::Y).y - 0.0).abs() < 1e-5);
        assert!((env.radiance(Vec3::NEG_Y).y - 3.0).abs() < 1e-5);
        // −z on the horizon is u = ½, v = ½: between columns 3 and 4, rows 1 and 2.
        let c = env.radiance(Vec3::NEG_Z);
        assert!((c - Vec3::new(3.5, 1.5, 0.0)).length() < 1e-4, "{c}");
        // +x is u = ¾: between columns 5 and 6.
        let c = env.radiance(Vec3::X);
        assert!((c.x - 5.5).abs() < 1e-4, "{c}");
    }

    #[test]
    fn the_sky_is_finite_everywhere() {
        for d in [
            Vec3::ZERO,
            Vec3::NAN,
            Vec3::Y,
            Vec3::NEG_Y,
            SUN,
            Vec3::new(1.0, -1e-9, 0.0),
        ] {
            assert!(Environment::Sky.radiance(d).is_finite());
        }
    }
}

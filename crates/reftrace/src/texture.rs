//! Textures for the reference and its footprint-integrating filter.
//!
//! A [`Texture`] is a linear-light RGBA f32 image. Texel `(x, y)` covers the uv square
//! `[x/w, (x+1)/w] × [y/h, (y+1)/h]`: u grows to the right, v grows DOWN the rows (row 0 at
//! v = 0, as in glTF). Addressing wraps (repeat) in both directions.
//!
//! The reference filter is deliberately independent of `texmap-core`'s mip pyramids and samplers:
//! it is the box integral of the level-0 texels (nearest-texel reconstruction) over the exact
//! screen footprint, computed by the midpoint rule on a grid fine enough to put at least two
//! points per texel along each axis of the footprint (see [`crate::render`]).

use glam::{Vec2, Vec4};

use crate::error::TextureError;

/// A linear RGBA f32 texture, row-major, row 0 at v = 0.
///
/// # Guarantees
/// `width, height >= 1`, `texels.len() == width * height`, every texel finite.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    width: u32,
    height: u32,
    texels: Vec<Vec4>,
}

impl Texture {
    /// A texture from linear RGBA texels (row-major).
    pub fn new(width: u32, height: u32, texels: Vec<[f32; 4]>) -> Result<Texture, TextureError> {
        if width == 0 || height == 0 {
            return Err(TextureError::Empty { width, height });
        }
        if texels.len() as u64 != width as u64 * height as u64 {
            return Err(TextureError::SizeMismatch {
                width,
                height,
                texels: texels.len(),
            });
        }
        if let Some(i) = texels.iter().position(|t| !t.iter().all(|c| c.is_finite())) {
            return Err(TextureError::NonFinite {
                x: (i % width as usize) as u32,
                y: (i / width as usize) as u32,
            });
        }
        Ok(Texture {
            width,
            height,
            texels: texels.into_iter().map(Vec4::from_array).collect(),
        })
    }

    #[inline]
    pub fn width(&self) -> u32 {
        self.width
    }
    #[inline]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The texel containing `uv` (nearest reconstruction, repeat wrap). Non-finite uv gives
    /// texel (0, 0).
    #[inline]
    pub fn nearest(&self, uv: Vec2) -> Vec4 {
        let fx = uv.x * self.width as f32;
        let fy = uv.y * self.height as f32;
        // `as i64` saturates and maps NaN to 0; rem_euclid wraps negatives.
        let x = (fx.floor() as i64).rem_euclid(self.width as i64) as usize;
        let y = (fy.floor() as i64).rem_euclid(self.height as i64) as usize;
        self.texels[y * self.width as usize + x]
    }

    /// The texel at integer coordinates (wrapped).
    #[inline]
    pub fn texel(&self, x: i64, y: i64) -> Vec4 {
        let x = x.rem_euclid(self.width as i64) as usize;
        let y = y.rem_euclid(self.height as i64) as usize;
        self.texels[y * self.width as usize + x]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn addressing_wraps_and_rows_grow_with_v() {
        let t = Texture::new(
            2,
            2,
            vec![
                [1.0, 0.0, 0.0, 1.0],
                [0.0, 1.0, 0.0, 1.0],
                [0.0, 0.0, 1.0, 1.0],
                [1.0, 1.0, 1.0, 1.0],
            ],
        )
        .unwrap();
        assert_eq!(t.nearest(Vec2::new(0.25, 0.25)).x, 1.0);
        assert_eq!(t.nearest(Vec2::new(0.75, 0.25)).y, 1.0);
        assert_eq!(t.nearest(Vec2::new(0.25, 0.75)).z, 1.0);
        assert_eq!(t.nearest(Vec2::new(-0.25, 0.25)).y, 1.0);
        assert_eq!(t.nearest(Vec2::new(1.25, 1.75)).z, 1.0);
        assert_eq!(t.nearest(Vec2::NAN).x, 1.0);
        assert_eq!(t.texel(-1, -1), Vec4::ONE);
    }

    #[test]
    fn bad_textures_are_refused() {
        assert!(Texture::new(0, 1, vec![]).is_err());
        assert!(Texture::new(2, 1, vec![[0.0; 4]]).is_err());
        assert_eq!(
            Texture::new(2, 1, vec![[0.0; 4], [f32::NAN, 0.0, 0.0, 0.0]]),
            Err(TextureError::NonFinite { x: 1, y: 0 })
        );
    }
}

//! Materials of a scene: one per distinct colour, and a distinct colour per atom type.
//!
//! Colours are quantised to 8-bit sRGB; each new colour gets the next material index until
//! [`MAX_MATERIALS`] exist, after which a colour takes the nearest existing one (squared 8-bit
//! distance, lowest index on ties). Indices are stable for the palette's life, so per-material
//! tables of the sphere methods survive from frame to frame.

use std::collections::HashMap;

use glam::Vec3;
use texmap_core::color::{hsv_to_rgb, srgb_to_linear};
use texmap_core::shade::Material;

/// Most materials a scene gets: every method handles this many cheaply (the LUT and template
/// methods build tables per material). Colours past the first `MAX_MATERIALS` distinct ones
/// (after 8-bit quantisation) are drawn with the nearest of those.
pub const MAX_MATERIALS: usize = 256;

/// A distinct, evenly spaced hue per type index (golden-angle hues), sRGB in [0, 1].
pub fn type_color(i: usize) -> [f32; 3] {
    let c = hsv_to_rgb(Vec3::new((i as f32 * 137.507_77) % 360.0, 0.65, 0.95));
    [c.x, c.y, c.z]
}

/// Colour -> material index, capped at [`MAX_MATERIALS`] (see the module docs).
#[derive(Clone, Debug, Default)]
pub struct Palette {
    colors: Vec<[u8; 3]>,
    /// 8-bit colour -> material (exact, or the nearest entry once the palette is full).
    kinds: HashMap<[u8; 3], u16>,
    /// Distinct colours drawn with a nearest entry.
    merged: usize,
}

impl Palette {
    /// An empty palette.
    pub fn new() -> Palette {
        Palette::default()
    }

    /// The material of an sRGB colour in [0, 1] (clamped, then quantised to 8 bits per
    /// channel): its own new one while fewer than [`MAX_MATERIALS`] exist, else the nearest.
    pub fn kind_of(&mut self, srgb: [f32; 3]) -> u16 {
        let key = srgb.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
        if let Some(k) = self.kinds.get(&key) {
            return *k;
        }
        let k = if self.colors.len() < MAX_MATERIALS {
            self.colors.push(key);
            (self.colors.len() - 1) as u16
        } else {
            self.merged += 1;
            let d2 =
                |p: &[u8; 3]| -> i32 { (0..3).map(|c| (p[c] as i32 - key[c] as i32).pow(2)).sum() };
            let mut best = 0;
            for (i, p) in self.colors.iter().enumerate() {
                if d2(p) < d2(&self.colors[best]) {
                    best = i;
                }
            }
            best as u16
        };
        self.kinds.insert(key, k);
        k
    }

    /// The 8-bit sRGB colour of every material, in index order.
    pub fn colors(&self) -> &[[u8; 3]] {
        &self.colors
    }

    /// Distinct colours so far drawn with the nearest of the first [`MAX_MATERIALS`].
    pub fn merged_colors(&self) -> usize {
        self.merged
    }

    /// One plastic material per palette colour (linear RGB), in index order.
    pub fn materials(&self) -> Vec<Material> {
        self.colors
            .iter()
            .map(|c| {
                Material::plastic(Vec3::new(
                    srgb_to_linear(c[0] as f32 / 255.0),
                    srgb_to_linear(c[1] as f32 / 255.0),
                    srgb_to_linear(c[2] as f32 / 255.0),
                ))
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn palette_is_capped_and_overflow_colours_take_the_nearest() {
        let mut b = Palette::new();
        // MAX_MATERIALS distinct greys 0..=255 fill the palette exactly.
        for g in 0..MAX_MATERIALS {
            let v = g as f32 / 255.0;
            assert_eq!(b.kind_of([v, v, v]) as usize, g);
        }
        assert_eq!(b.merged_colors(), 0);
        // Pure red is nearest (squared 8-bit distance, computed here by brute force) to the grey
        // g minimising (255 − g)² + 2g²: g = 85.
        let best = (0..256i32)
            .min_by_key(|g| (255 - g).pow(2) + 2 * g * g)
            .unwrap();
        assert_eq!(best, 85);
        assert_eq!(b.kind_of([1.0, 0.0, 0.0]) as usize, best as usize);
        assert_eq!(b.merged_colors(), 1);
        // Asked again: same material, counted once.
        assert_eq!(b.kind_of([1.0, 0.0, 0.0]) as usize, best as usize);
        assert_eq!(b.merged_colors(), 1);
        // The palette never grows past the cap, so u16 kinds cannot wrap.
        for i in 0..5000u32 {
            let c = [(i % 97) as f32 / 96.0, (i % 89) as f32 / 88.0, 0.5];
            assert!((b.kind_of(c) as usize) < MAX_MATERIALS);
        }
        assert_eq!(b.colors().len(), MAX_MATERIALS);
        assert_eq!(b.materials().len(), MAX_MATERIALS);
    }

    #[test]
    fn materials_are_the_colours_in_linear_light() {
        let mut p = Palette::new();
        // Out-of-range values clamp; 0.5 quantises to 128.
        assert_eq!(p.kind_of([2.0, -1.0, 0.5]), 0);
        assert_eq!(p.colors(), [[255, 0, 128]]);
        let m = p.materials()[0];
        // sRGB 128/255 in linear light, by the sRGB formula ((c + 0.055) / 1.055)^2.4.
        let want = ((128.0f32 / 255.0 + 0.055) / 1.055).powf(2.4);
        let lin = m.base_color;
        assert!((lin.x - 1.0).abs() < 1e-6 && lin.y == 0.0 && (lin.z - want).abs() < 1e-5);
    }

    #[test]
    fn type_colours_are_distinct_and_in_range() {
        let cs: Vec<[u8; 3]> = (0..64)
            .map(|i| type_color(i).map(|c| (c * 255.0).round() as u8))
            .collect();
        for (i, a) in cs.iter().enumerate() {
            for b in &cs[..i] {
                assert_ne!(a, b);
            }
        }
        assert!(
            (0..64)
                .flat_map(type_color)
                .all(|c| (0.0..=1.0).contains(&c))
        );
    }
}

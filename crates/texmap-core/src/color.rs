//! Colour conversions: sRGB transfer functions (IEC 61966-2-1) and HSV.
//!
//! Inside the renderers colours are linear f32; they become sRGB 8-bit only at the edges
//! ([`linear_to_srgb8`]). The fast encoder uses a 4096-entry table indexed by the linear value and
//! is checked against the exact formula in a test (at most one code value off).

use glam::Vec3;
use std::sync::OnceLock;

/// sRGB-encoded value (0..1) to linear light.
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear light (0..1) to the sRGB-encoded value.
#[inline]
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Exact encode of one linear channel to an 8-bit sRGB code, clamping to [0, 1]; NaN maps to 0.
#[inline]
pub fn linear_to_srgb8_exact(c: f32) -> u8 {
    let c = if c.is_nan() { 0.0 } else { c.clamp(0.0, 1.0) };
    (linear_to_srgb(c) * 255.0 + 0.5) as u8
}

const ENC_BITS: usize = 12;
const ENC_N: usize = 1 << ENC_BITS;

/// Bins of the table behind [`linear_to_srgb8_fast`] ([`srgb_encode_table`]).
pub const SRGB_ENCODE_BINS: usize = ENC_N;

/// The table behind [`linear_to_srgb8_fast`]: entry `i` is the code of the linear values in
/// `[i/4096, (i+1)/4096)` (the exact code at the bin centre; 0 and 255 at the ends). The lane
/// encoder ([`crate::lanes::srgb_rgba_lanes`]) reads it widened to `u32`.
pub fn srgb_encode_table() -> &'static [u8; SRGB_ENCODE_BINS] {
    enc_table()
}

fn enc_table() -> &'static [u8; ENC_N] {
    static T: OnceLock<[u8; ENC_N]> = OnceLock::new();
    T.get_or_init(|| {
        let mut t = [0u8; ENC_N];
        for (i, v) in t.iter_mut().enumerate() {
            // Table entry i stands for the linear value at the centre of bin i.
            let lin = (i as f32 + 0.5) / ENC_N as f32;
            *v = linear_to_srgb8_exact(lin);
        }
        t[0] = 0;
        t[ENC_N - 1] = 255;
        t
    })
}

/// Fast table encode of one linear channel to an 8-bit sRGB code (clamped; NaN maps to 0).
/// At most one code value from [`linear_to_srgb8_exact`] for values ≥ 1/4096; exact at 0 and 1.
#[inline]
pub fn linear_to_srgb8_fast(c: f32) -> u8 {
    let t = enc_table();
    // `as usize` saturates and maps NaN to 0.
    let i = ((c * ENC_N as f32) as usize).min(ENC_N - 1);
    t[i]
}

/// 256-entry decode table: sRGB code -> linear value.
pub fn srgb8_to_linear_table() -> &'static [f32; 256] {
    static T: OnceLock<[f32; 256]> = OnceLock::new();
    T.get_or_init(|| {
        let mut t = [0f32; 256];
        for (i, v) in t.iter_mut().enumerate() {
            *v = srgb_to_linear(i as f32 / 255.0);
        }
        t
    })
}

/// sRGB code to linear light.
#[inline]
pub fn srgb8_to_linear(c: u8) -> f32 {
    srgb8_to_linear_table()[c as usize]
}

/// A linear RGB colour to RGBA8 sRGB with the given alpha (fast table encoder).
#[inline]
pub fn linear_to_srgb8(c: Vec3, alpha: u8) -> [u8; 4] {
    [
        linear_to_srgb8_fast(c.x),
        linear_to_srgb8_fast(c.y),
        linear_to_srgb8_fast(c.z),
        alpha,
    ]
}

/// RGBA8 sRGB to linear RGB (alpha dropped).
#[inline]
pub fn srgb8_to_linear_rgb(c: [u8; 4]) -> Vec3 {
    Vec3::new(
        srgb8_to_linear(c[0]),
        srgb8_to_linear(c[1]),
        srgb8_to_linear(c[2]),
    )
}

/// RGB (any 0..1 space) to HSV: hue in degrees [0, 360), saturation and value in [0, 1].
pub fn rgb_to_hsv(c: Vec3) -> Vec3 {
    let max = c.max_element();
    let min = c.min_element();
    let d = max - min;
    let h = if d <= 0.0 {
        0.0
    } else if max == c.x {
        60.0 * ((c.y - c.z) / d).rem_euclid(6.0)
    } else if max == c.y {
        60.0 * ((c.z - c.x) / d + 2.0)
    } else {
        60.0 * ((c.x - c.y) / d + 4.0)
    };
    let s = if max <= 0.0 { 0.0 } else { d / max };
    Vec3::new(h.rem_euclid(360.0), s, max)
}

/// HSV (hue in degrees, any value wraps; saturation and value 0..1) to RGB.
pub fn hsv_to_rgb(hsv: Vec3) -> Vec3 {
    let h = hsv.x.rem_euclid(360.0) / 60.0;
    let s = hsv.y.clamp(0.0, 1.0);
    let v = hsv.z;
    let c = v * s;
    let x = c * (1.0 - ((h % 2.0) - 1.0).abs());
    let m = v - c;
    let (r, g, b) = match h as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    Vec3::new(r + m, g + m, b + m)
}

/// Replace the hue of `c` (Seed 004's "one template recoloured by HSV hue"), keeping saturation
/// and value.
pub fn with_hue(c: Vec3, hue_deg: f32) -> Vec3 {
    let mut hsv = rgb_to_hsv(c);
    hsv.x = hue_deg;
    hsv_to_rgb(hsv)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trip_and_known_points() {
        // 50% sRGB grey is 21.4% linear light (IEC 61966-2-1).
        assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-5);
        for i in 0..=255u8 {
            let lin = srgb8_to_linear(i);
            assert_eq!(linear_to_srgb8_exact(lin), i);
        }
    }

    #[test]
    fn fast_encoder_is_within_one_code_of_exact() {
        let mut worst = 0i32;
        for i in 0..=100_000 {
            let x = i as f32 / 100_000.0;
            let d = linear_to_srgb8_fast(x) as i32 - linear_to_srgb8_exact(x) as i32;
            if x >= 1.0 / 4096.0 {
                worst = worst.max(d.abs());
            }
        }
        assert!(worst <= 1, "worst difference {worst}");
        assert_eq!(linear_to_srgb8_fast(0.0), 0);
        assert_eq!(linear_to_srgb8_fast(1.0), 255);
        assert_eq!(linear_to_srgb8_fast(7.0), 255);
        assert_eq!(linear_to_srgb8_fast(-1.0), 0);
        assert_eq!(linear_to_srgb8_fast(f32::NAN), 0);
    }

    #[test]
    fn hsv_matches_hand_values_and_round_trips() {
        let hsv = rgb_to_hsv(Vec3::new(1.0, 0.5, 0.0));
        assert!((hsv - Vec3::new(30.0, 1.0, 1.0)).length() < 1e-5, "{hsv}");
        assert!(
            (hsv_to_rgb(Vec3::new(240.0, 1.0, 0.5)) - Vec3::new(0.0, 0.0, 0.5)).length() < 1e-6
        );
        let mut state = 12345u32;
        for _ in 0..1000 {
            let mut r = || {
                state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (state >> 8) as f32 / (1u32 << 24) as f32
            };
            let c = Vec3::new(r(), r(), r());
            let back = hsv_to_rgb(rgb_to_hsv(c));
            assert!((back - c).length() < 1e-5, "{c} -> {back}");
        }
        let red_as_green = with_hue(Vec3::new(0.8, 0.2, 0.2), 120.0);
        assert!((red_as_green - Vec3::new(0.2, 0.8, 0.2)).length() < 1e-5);
    }
}

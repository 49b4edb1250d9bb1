//! Mip pyramids: level sizes (power-of-two and not), the mean carried to the 1x1 top level,
//! gamma-correct versus naive box reduction on a checkerboard, wrap modes and input validation.

use texmap_core::color::srgb_to_linear;
use texmap_core::glam::Vec4;
use texmap_core::mip::{MipError, MipTexture, Reduction, Wrap};

fn sizes(t: &MipTexture) -> Vec<(u32, u32)> {
    t.levels().iter().map(|l| (l.width, l.height)).collect()
}

fn random_linear(w: u32, h: u32, seed: u32) -> Vec<Vec4> {
    let mut s = seed;
    let mut r = move || {
        s ^= s << 13;
        s ^= s >> 17;
        s ^= s << 5;
        (s >> 8) as f32 / (1u32 << 24) as f32
    };
    (0..w * h).map(|_| Vec4::new(r(), r(), r(), r())).collect()
}

#[test]
fn level_sizes_halve_down_to_one() {
    let t = MipTexture::from_linear(8, 8, &random_linear(8, 8, 1), Reduction::Box, Wrap::Repeat)
        .unwrap();
    assert_eq!(sizes(&t), vec![(8, 8), (4, 4), (2, 2), (1, 1)]);
    assert!(t.is_pow2());
    let t = MipTexture::from_linear(
        13,
        5,
        &random_linear(13, 5, 2),
        Reduction::Box,
        Wrap::Repeat,
    )
    .unwrap();
    assert_eq!(sizes(&t), vec![(13, 5), (6, 2), (3, 1), (1, 1)]);
    assert!(!t.is_pow2());
    let t = MipTexture::from_linear(1, 9, &random_linear(1, 9, 3), Reduction::Box, Wrap::Clamp)
        .unwrap();
    assert_eq!(sizes(&t), vec![(1, 9), (1, 4), (1, 2), (1, 1)]);
    let total: usize = t
        .levels()
        .iter()
        .map(|l| (l.width * l.height) as usize)
        .sum();
    assert_eq!(t.texels().len(), total);
}

#[test]
fn the_top_level_is_the_mean_of_the_image() {
    // Exact-box NPOT reduction preserves the mean at every level; compare with an f64 mean.
    for (w, h) in [(64, 64), (37, 23), (100, 3), (5, 5)] {
        let data = random_linear(w, h, w * 31 + h);
        let mut expect = [0f64; 4];
        for t in &data {
            for (e, v) in expect.iter_mut().zip(t.to_array()) {
                *e += v as f64 / (w * h) as f64;
            }
        }
        let t =
            MipTexture::from_linear(w, h, &data, Reduction::GammaCorrect, Wrap::Repeat).unwrap();
        for li in 0..t.level_count() {
            let got = t.level_mean(li).unwrap();
            for c in 0..4 {
                // f32 accumulation over ≤ 7 levels of 2–3-tap averages: a few ulps of 1.
                assert!(
                    (got[c] - expect[c]).abs() < 2e-6,
                    "{w}x{h} level {li} channel {c}: expected {}, got {}, tol 2e-6",
                    expect[c],
                    got[c]
                );
            }
        }
    }
}

#[test]
fn gamma_correct_checkerboard_is_188_and_naive_box_is_128() {
    // 16x16 one-texel black/white checkerboard in sRGB8.
    let n = 16u32;
    let mut px = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let v = if (x + y) % 2 == 0 { 0 } else { 255 };
            px.extend_from_slice(&[v, v, v, 255]);
        }
    }
    let g = MipTexture::from_srgb8(n, n, &px, Reduction::GammaCorrect, Wrap::Repeat).unwrap();
    let b = MipTexture::from_srgb8(n, n, &px, Reduction::Box, Wrap::Repeat).unwrap();
    for li in 1..g.level_count() {
        // Linear-light average of black and white: 0.5 linear = sRGB 0.7354 -> code 188.
        assert_eq!(
            g.texel_srgb8(li, 0, 0),
            [188, 188, 188, 255],
            "gamma-correct level {li}"
        );
        // Averaging the codes: 127.5 -> 128, which is only 21.6% linear light (too dark).
        assert_eq!(
            b.texel_srgb8(li, 1, 0),
            [128, 128, 128, 255],
            "box level {li}"
        );
        let lin = b.texel(li, 0, 0).unwrap().x;
        let expect = srgb_to_linear(0.5);
        assert!(
            (lin - expect).abs() < 1e-6,
            "expected {expect}, got {lin}, tol 1e-6"
        );
    }
    // Level 0 is the input either way.
    assert_eq!(g.texel_srgb8(0, 1, 0), [255, 255, 255, 255]);
    assert_eq!(b.texel_srgb8(0, 0, 0), [0, 0, 0, 255]);
}

#[test]
fn wrap_modes_fold_addresses() {
    let data: Vec<Vec4> = (0..12).map(|i| Vec4::splat(i as f32)).collect();
    let r = MipTexture::from_linear(4, 3, &data, Reduction::Box, Wrap::Repeat).unwrap();
    assert_eq!(r.texel(0, -1, 0).unwrap().x, 3.0);
    assert_eq!(r.texel(0, 4, -1).unwrap().x, 8.0);
    let c = r.clone().with_wrap(Wrap::Clamp);
    assert_eq!(c.texel(0, -5, 7).unwrap().x, 8.0);
    assert_eq!(c.texel(0, 9, 1).unwrap().x, 7.0);
    assert!(c.texel(9, 0, 0).is_none());
}

#[test]
fn bad_input_is_an_error() {
    let d = random_linear(2, 2, 9);
    assert_eq!(
        MipTexture::from_linear(0, 2, &d, Reduction::Box, Wrap::Repeat),
        Err(MipError::BadSize {
            width: 0,
            height: 2
        })
    );
    assert!(matches!(
        MipTexture::from_linear(2, 3, &d, Reduction::Box, Wrap::Repeat),
        Err(MipError::DataLength {
            expected: 6,
            actual: 4
        })
    ));
    let mut bad = d.clone();
    bad[3].y = f32::NAN;
    assert_eq!(
        MipTexture::from_linear(2, 2, &bad, Reduction::Box, Wrap::Repeat),
        Err(MipError::NonFinite { x: 1, y: 1 })
    );
    assert!(matches!(
        MipTexture::from_srgb8(2, 2, &[0u8; 15], Reduction::Box, Wrap::Repeat),
        Err(MipError::DataLength { .. })
    ));
    assert!(matches!(
        MipTexture::from_srgb8(20000, 1, &[], Reduction::Box, Wrap::Repeat),
        Err(MipError::BadSize { .. })
    ));
}

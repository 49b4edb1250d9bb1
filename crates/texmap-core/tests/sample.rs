//! Samplers against an independent f64 recomputation from the texels (`MipTexture::texel`), and
//! the quad API's conventions.

use texmap_core::glam::{DVec4, Vec2, Vec4};
use texmap_core::mip::{MipTexture, Reduction, Wrap};
use texmap_core::sample::{Banks, Sampler};

struct Rng(u32);
impl Rng {
    fn f(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 17;
        self.0 ^= self.0 << 5;
        (self.0 >> 8) as f32 / (1u32 << 24) as f32
    }
}

fn tex(w: u32, h: u32, wrap: Wrap, r: &mut Rng) -> MipTexture {
    let d: Vec<Vec4> = (0..w * h)
        .map(|_| Vec4::new(r.f(), r.f(), r.f(), 1.0))
        .collect();
    MipTexture::from_linear(w, h, &d, Reduction::GammaCorrect, wrap).unwrap()
}

/// Bilinear in f64 from `texel()`, texel centres at (i + ½)/w.
fn bilinear_f64(t: &MipTexture, level: usize, uv: Vec2) -> DVec4 {
    let l = t.level(level).unwrap();
    let x = uv.x as f64 * l.width as f64 - 0.5;
    let y = uv.y as f64 * l.height as f64 - 0.5;
    let (fx, fy) = (x.floor(), y.floor());
    let (ax, ay) = (x - fx, y - fy);
    let g = |dx: i64, dy: i64| {
        t.texel(level, fx as i64 + dx, fy as i64 + dy)
            .unwrap()
            .as_dvec4()
    };
    (g(0, 0) * (1.0 - ax) + g(1, 0) * ax) * (1.0 - ay) + (g(0, 1) * (1.0 - ax) + g(1, 1) * ax) * ay
}

/// Eq. (2)'s level in f64 (max component, exact log2) and Eq. (4)'s blend of the two levels
/// around it, each level filtered by `level_f64`; level 0 under magnification, the last beyond it.
fn blend_levels_f64(
    t: &MipTexture,
    uv: Vec2,
    dx: Vec2,
    dy: Vec2,
    level_f64: fn(&MipTexture, usize, Vec2) -> DVec4,
) -> DVec4 {
    let (w, h) = (t.width() as f64, t.height() as f64);
    let m = (dx.x as f64 * w)
        .abs()
        .max((dx.y as f64 * h).abs())
        .max((dy.x as f64 * w).abs())
        .max((dy.y as f64 * h).abs());
    let last = t.level_count() - 1;
    let lam = m.log2();
    if lam.is_nan() || lam <= 0.0 {
        return level_f64(t, 0, uv);
    }
    if lam >= last as f64 {
        return level_f64(t, last, uv);
    }
    let i = lam.floor() as usize;
    let f = lam - i as f64;
    level_f64(t, i, uv) * (1.0 - f) + level_f64(t, i + 1, uv) * f
}

/// Seed 000 Eq. (4) in f64: bilinear levels blended.
fn trilinear_f64(t: &MipTexture, uv: Vec2, dx: Vec2, dy: Vec2) -> DVec4 {
    blend_levels_f64(t, uv, dx, dy, bilinear_f64)
}

/// The quadratic 3x3 of one level in f64 from `texel()`: the texel coordinate `u·w − ½` as the
/// sampler forms it in f32 (the nearest texel is a discontinuity, so it must round the same
/// value), its nearest texel by `round`, Lagrange weights and sums in f64, clamped to [0, 1].
fn quadratic_level_f64(t: &MipTexture, level: usize, uv: Vec2) -> DVec4 {
    let l = t.level(level).unwrap();
    let x = (uv.x * l.width as f32 - 0.5) as f64;
    let y = (uv.y * l.height as f32 - 0.5) as f64;
    let (cx, cy) = (x.round(), y.round());
    let w = |d: f64| [0.5 * d * (d - 1.0), 1.0 - d * d, 0.5 * d * (d + 1.0)];
    let (wx, wy) = (w(x - cx), w(y - cy));
    let mut s = DVec4::ZERO;
    for (j, wyj) in wy.iter().enumerate() {
        for (i, wxi) in wx.iter().enumerate() {
            let texel = t
                .texel(level, cx as i64 + i as i64 - 1, cy as i64 + j as i64 - 1)
                .unwrap();
            s += texel.as_dvec4() * wxi * wyj;
        }
    }
    s.clamp(DVec4::ZERO, DVec4::ONE)
}

/// [`Sampler::Quadratic3`] in f64: trilinear's levels and blend (Eq. 2, exact log2) over
/// [`quadratic_level_f64`].
fn quadratic_f64(t: &MipTexture, uv: Vec2, dx: Vec2, dy: Vec2) -> DVec4 {
    blend_levels_f64(t, uv, dx, dy, quadratic_level_f64)
}

/// Four textures of random texels (both wraps, power-of-two and not), each looked up at 20,000
/// random points (uv over three periods, footprints from 10^−3.5 to 10^0.5 of the map):
/// `check` asserts on one lookup and returns its difference to the reference; the worst per
/// texture is printed under `name`.
fn random_lookups(
    seed: u32,
    name: &str,
    mut check: impl FnMut(&MipTexture, Vec2, Vec2, Vec2) -> f64,
) {
    let mut r = Rng(seed);
    for (w, h, wrap) in [
        (64, 64, Wrap::Repeat),
        (64, 64, Wrap::Clamp),
        (40, 24, Wrap::Repeat),
        (17, 9, Wrap::Clamp),
    ] {
        let t = tex(w, h, wrap, &mut r);
        let mut worst = 0f64;
        for _ in 0..20_000 {
            let uv = Vec2::new(r.f() * 3.0 - 1.0, r.f() * 3.0 - 1.0);
            let s = 10f32.powf(r.f() * 4.0 - 3.5);
            let dx = Vec2::new(r.f() - 0.5, r.f() - 0.5) * s;
            let dy = Vec2::new(r.f() - 0.5, r.f() - 0.5) * s;
            worst = worst.max(check(&t, uv, dx, dy));
        }
        eprintln!("{w}x{h} {wrap:?}: worst {name} difference {worst:e}");
    }
}

#[test]
fn quadratic3_matches_an_f64_recomputation() {
    // Random uv and derivatives, both wrap modes, power-of-two and NPOT pyramids, single pixels
    // and quads (the quad kernel in lanes).
    random_lookups(0xF00D, "quadratic3", |t, uv, dx, dy| {
        let got = Sampler::Quadratic3.sample(t, uv, dx, dy).as_dvec4();
        let e = quadratic_f64(t, uv, dx, dy);
        // As trilinear: the log2's error (≤ 1.2e-4) moves the blend weight, times the
        // difference of two clamped level values (≤ 1).
        let d = (got - e).abs().max_element();
        assert!(
            d < 2e-4,
            "quadratic3 {uv} {dx} {dy}: expected {e}, got {got}, tol 2e-4"
        );
        let quad = [uv, uv + dx, uv + dy, uv + dx + dy];
        let got = Sampler::Quadratic3.sample_quad(t, quad);
        for j in 0..4 {
            let e = quadratic_f64(t, quad[j], quad[1] - quad[0], quad[2] - quad[0]);
            let d = (got[j].as_dvec4() - e).abs().max_element();
            assert!(
                d < 2e-4,
                "quadratic3 quad {quad:?} pixel {j}: expected {e}, got {}",
                got[j]
            );
        }
        d
    });
}

#[test]
fn bilinear_and_trilinear_match_an_f64_recomputation() {
    random_lookups(0xBEEF, "trilinear", |t, uv, dx, dy| {
        let b = Sampler::Bilinear.sample(t, uv, dx, dy).as_dvec4();
        let e = bilinear_f64(t, 0, uv);
        assert!(
            (b - e).abs().max_element() < 1e-5,
            "bilinear {uv}: expected {e}, got {b}, tol 1e-5"
        );
        let got = Sampler::Trilinear.sample(t, uv, dx, dy).as_dvec4();
        let e = trilinear_f64(t, uv, dx, dy);
        // The sampler's log2 has |error| ≤ 1.2e-4 (tested in the crate): the blend weight
        // moves at most that much times the difference of two texel values (≤ 1).
        let d = (got - e).abs().max_element();
        assert!(
            d < 2e-4,
            "trilinear {uv} {dx} {dy}: expected {e}, got {got}, tol 2e-4"
        );
        d
    });
}

#[test]
fn a_constant_texture_samples_to_the_constant_everywhere() {
    let c = Vec4::new(0.25, 0.5, 0.75, 1.0);
    let t = MipTexture::from_linear(32, 16, &vec![c; 512], Reduction::GammaCorrect, Wrap::Repeat)
        .unwrap();
    let mut r = Rng(5);
    for s in [
        Sampler::Nearest,
        Sampler::Bilinear,
        Sampler::Trilinear,
        Sampler::Span(Banks::K3),
        Sampler::Span(Banks::K4),
        Sampler::Quadratic3,
        Sampler::Anisotropic { max_taps: 16 },
    ] {
        for _ in 0..2000 {
            let uv = Vec2::new(r.f() * 10.0 - 5.0, r.f() * 10.0 - 5.0);
            let d = Vec2::new(r.f(), r.f()) * 0.3;
            let got = s.sample(&t, uv, d, d.perp());
            assert!(
                (got - c).abs().max_element() < 1e-6,
                "{s:?}: expected {c}, got {got}, tol 1e-6"
            );
        }
    }
}

#[test]
fn quad_api_uses_coarse_derivatives_and_pixel_order() {
    let mut r = Rng(77);
    let t = tex(128, 128, Wrap::Repeat, &mut r);
    let p = Vec2::new(0.3, 0.6);
    let (dx, dy) = (Vec2::new(0.013, 0.002), Vec2::new(-0.001, 0.02));
    let quad = [p, p + dx, p + dy, p + dx + dy];
    let got = Sampler::Trilinear.sample_quad(&t, quad);
    let (qdx, qdy) = (quad[1] - quad[0], quad[2] - quad[0]);
    for j in 0..4 {
        let e = Sampler::Trilinear.sample(&t, quad[j], qdx, qdy);
        assert_eq!(got[j], e, "pixel {j}");
    }
    let got = Sampler::Trilinear.sample_quad_with_derivatives(&t, quad, [dx; 4], [dy; 4]);
    assert_eq!(got[3], Sampler::Trilinear.sample(&t, quad[3], dx, dy));
    // Bulk calls equal single calls, and refuse mismatched slices.
    let uv = vec![p; 3];
    let mut out = vec![Vec4::ZERO; 3];
    Sampler::Trilinear
        .sample_pixels(&t, &uv, &[dx; 3], &[dy; 3], &mut out)
        .unwrap();
    assert_eq!(out[1], Sampler::Trilinear.sample(&t, p, dx, dy));
    assert!(
        Sampler::Trilinear
            .sample_pixels(&t, &uv, &[dx; 2], &[dy; 3], &mut out)
            .is_err()
    );
    let mut qout = vec![[Vec4::ZERO; 4]; 2];
    Sampler::Span(Banks::K4)
        .sample_quads(&t, &[quad, quad], &mut qout)
        .unwrap();
    assert_eq!(qout[1], Sampler::Span(Banks::K4).sample_quad(&t, quad));
    assert!(
        Sampler::Span(Banks::K4)
            .sample_quads(&t, &[quad], &mut qout)
            .is_err()
    );
}

#[test]
fn span_k4_equals_trilinear_at_the_span_level() {
    // For an axis-aligned span (u along x only, v along y only) Eq. (9)'s extent is the per-pixel
    // footprint, so the K = 4 span sampler is trilinear with λ from that footprint.
    let mut r = Rng(123);
    let t = tex(256, 256, Wrap::Repeat, &mut r);
    for _ in 0..5000 {
        let p = Vec2::new(r.f(), r.f());
        let d = 10f32.powf(r.f() * 3.0 - 3.5);
        let (dx, dy) = (Vec2::new(d, 0.0), Vec2::new(0.0, d));
        let quad = [p, p + dx, p + dy, p + dx + dy];
        let span = Sampler::Span(Banks::K4).sample_quad(&t, quad);
        for j in 0..4 {
            let e = trilinear_f64(&t, quad[j], dx, dy);
            let dd = (span[j].as_dvec4() - e).abs().max_element();
            assert!(
                dd < 2e-4,
                "pixel {j} of span at {p}, d={d}: expected {e}, got {}, tol 2e-4",
                span[j]
            );
        }
    }
}

//! [`Lighting::shade`] without library calls, one pixel ([`shade`]) or 8 lanes at a time
//! ([`shade_lanes`], [`shade_chunks`]): the same ambient + Lambert + Blinn-Phong sum, only
//! `x^e` becomes `exp2(e·log2 x)` with the polynomials of [`super::math`] (or, for integer
//! shininess, repeated squaring). A test bounds the difference from [`Lighting::shade`]
//! (≤ 2e-5 absolute on random inputs, far under half an 8-bit sRGB step).
//!
//! Shading is a third of the sphere ray-cast time with `powf` from libm (measured on S2, one
//! thread: `Lighting::shade` 17% + `powf` 14%), hence the polynomials.
//!
//! The lane forms are written once over [`Lanes8`]; every backend performs the same IEEE
//! operations in the same order, so all give the same bits.

// Comparisons written `!(a > b)` are deliberate: they also reject NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Lane loops index several fixed-width arrays with one lane counter (the vectorised form).
#![allow(clippy::needless_range_loop)]

use glam::Vec3;

use super::math::{SpecPow, pow_int_lanes, pow01, pow01_lanes, spec_pow};
use super::{F32x8, Lanes8};
use crate::shade::{Lighting, MAX_LIGHTS, Material};

/// [`Lighting::shade`] with [`pow01`]: same inputs, same formula.
#[inline]
pub fn shade(l: &Lighting, m: &Material, n: Vec3, v: Vec3) -> Vec3 {
    let mut c = l.ambient * m.base_color;
    for light in l.lights() {
        let ndl = n.dot(light.to_light);
        if ndl > 0.0 {
            let mut term = m.base_color * ndl;
            if m.specular > 0.0 {
                let h = light.to_light + v;
                let hh = h.length_squared();
                if hh > 0.0 {
                    let ndh = (n.dot(h) / hh.sqrt()).clamp(0.0, 1.0);
                    term += Vec3::splat(m.specular * pow01(ndh, m.shininess));
                }
            }
            c += light.color * term;
        }
    }
    c
}

/// Surface and material of 8 pixels, structure-of-arrays.
#[derive(Clone, Copy, Debug, Default)]
pub struct Surf8 {
    pub n: [[f32; 8]; 3],
    pub v: [[f32; 8]; 3],
    pub base: [[f32; 8]; 3],
    pub spec: [f32; 8],
    pub shin: [f32; 8],
}

/// [`shade`] over 8 lanes: the same formula, masks instead of branches, on [`F32x8`] lanes.
#[inline(always)]
pub fn shade8(l: &Lighting, s: &Surf8) -> [[f32; 8]; 3] {
    let ld = |a: &[[f32; 8]; 3]| [F32x8::load(&a[0]), F32x8::load(&a[1]), F32x8::load(&a[2])];
    let c = shade_lanes(
        l,
        ld(&s.n),
        ld(&s.v),
        ld(&s.base),
        F32x8::load(&s.spec),
        F32x8::load(&s.shin),
        spec_pow(&s.shin),
    );
    [c[0].store(), c[1].store(), c[2].store()]
}

/// [`shade`] over 8 lanes of any [`Lanes8`] backend: the same formula, masks instead of
/// branches. `pw` is [`super::math::spec_pow_of`]`(shin)` (the caller may know it for the
/// whole frame): integer exponents are taken by squaring (exact to a few ulp, and cheaper),
/// others by exp2(e·log2 x). Every backend performs the same IEEE operations in the same
/// order, so all give the same bits.
#[inline(always)]
pub fn shade_lanes<V: Lanes8>(
    l: &Lighting,
    n: [V; 3],
    v: [V; 3],
    base: [V; 3],
    spec_k: V,
    shin: V,
    pw: SpecPow,
) -> [V; 3] {
    let a = (n, v, base, spec_k, shin, pw);
    // The build for this light count (the same operations as one generic loop).
    macro_rules! with {
        ($n:literal) => {
            shade_lanes_n(
                &LanesLighting::<V, $n>::new(l),
                a.0,
                a.1,
                a.2,
                a.3,
                a.4,
                a.5,
            )
        };
    }
    const { assert!(MAX_LIGHTS == 4) };
    match l.lights().len() {
        0 => with!(0),
        1 => with!(1),
        2 => with!(2),
        3 => with!(3),
        _ => with!(4),
    }
}

/// A [`Lighting`] with exactly `N` lights, its constants splat into lanes once (per tile) for
/// [`shade_lanes_n`].
#[derive(Clone, Copy)]
pub struct LanesLighting<V, const N: usize> {
    ambient: [V; 3],
    dir: [[V; 3]; N],
    color: [[V; 3]; N],
}

impl<V: Lanes8, const N: usize> LanesLighting<V, N> {
    /// `l`'s constants as lanes (`l` must have `N` lights).
    #[inline(always)]
    pub fn new(l: &Lighting) -> Self {
        debug_assert_eq!(l.lights().len(), N);
        let v3 = |a: Vec3| [V::splat(a.x), V::splat(a.y), V::splat(a.z)];
        LanesLighting {
            ambient: v3(l.ambient),
            dir: std::array::from_fn(|i| v3(l.lights()[i].to_light)),
            color: std::array::from_fn(|i| v3(l.lights()[i].color)),
        }
    }
}

/// The body of [`shade_lanes`] for a lighting of `N` lights known at compile time: the light
/// loops unroll, and a caller that shades many chunks (the ray-cast resolve) makes `l` once per
/// tile, so the lights' constants stay in registers instead of being splat per chunk. Lights
/// are taken two at a time (their specular powers share one squaring loop, see `pow_int_lanes`) and
/// their terms added in the lights' order.
#[inline(always)]
pub fn shade_lanes_n<V: Lanes8, const N: usize>(
    l: &LanesLighting<V, N>,
    n: [V; 3],
    v: [V; 3],
    base: [V; 3],
    spec_k: V,
    shin: V,
    pw: SpecPow,
) -> [V; 3] {
    let s = LaneSurf {
        n,
        v,
        base,
        spec: spec_k,
        shin,
    };
    shade_chunks(l, [s], pw)[0]
}

/// The shading inputs of one 8-lane chunk for [`shade_chunks`].
#[derive(Clone, Copy)]
pub struct LaneSurf<V> {
    /// Unit normal.
    pub n: [V; 3],
    /// Unit vector toward the eye.
    pub v: [V; 3],
    /// Base colour.
    pub base: [V; 3],
    /// Specular coefficient.
    pub spec: V,
    /// Shininess (read only when `pw` is [`SpecPow::Poly`]).
    pub shin: V,
}

/// [`shade_lanes_n`] for `C` chunks at once (`C` ≤ 2) that share one [`SpecPow`]: every lane
/// sees exactly the operations it would alone, but the chunks' dependency chains (square
/// roots, divisions, the squarings of one shared loop) are interleaved in one straight-line
/// body, so the CPU overlaps them instead of waiting out one chunk's latency at a time.
#[inline(always)]
pub fn shade_chunks<V: Lanes8, const N: usize, const C: usize>(
    l: &LanesLighting<V, N>,
    s: [LaneSurf<V>; C],
    pw: SpecPow,
) -> [[V; 3]; C] {
    const { assert!(C == 1 || C == 2) };
    // `Ints` holds exponents per lane: one chunk's.
    debug_assert!(C == 1 || !matches!(pw, SpecPow::Ints { .. }));
    let mut c: [[V; 3]; C] = std::array::from_fn(|j| {
        let b = s[j].base;
        [
            b[0] * l.ambient[0],
            b[1] * l.ambient[1],
            b[2] * l.ambient[2],
        ]
    });
    let zero = V::splat(0.0);
    let tiny = V::splat(1e-30);
    let mut p = 0;
    while p < N {
        let m = (N - p).min(2);
        let mut ndl = [[zero; 2]; C];
        let mut ndh = [[zero; 2]; C];
        let mut pos = [[zero.lt(zero); 2]; C];
        for i in 0..m {
            let [ax, ay, az] = l.dir[p + i];
            for j in 0..C {
                let (n, v) = (s[j].n, s[j].v);
                ndl[j][i] = n[0] * ax + n[1] * ay + n[2] * az;
                let hx = ax + v[0];
                let hy = ay + v[1];
                let hz = az + v[2];
                let hh = hx * hx + hy * hy + hz * hz;
                let nh = n[0] * hx + n[1] * hy + n[2] * hz;
                let q = nh / hh.sqrt();
                pos[j][i] = q.gt(tiny);
                ndh[j][i] = V::select(pos[j][i], q.min(V::splat(1.0)), tiny);
            }
        }
        // The powers of all chunks and lights in one squaring loop.
        let mut pw2 = [[zero; 2]; C];
        match pw {
            SpecPow::Poly => {
                for j in 0..C {
                    for i in 0..m {
                        pw2[j][i] = pow01_lanes(ndh[j][i], s[j].shin);
                    }
                }
            }
            _ => match (C, m) {
                (1, 1) => pw2[0][0] = pow_int_lanes([ndh[0][0]], &pw)[0],
                (1, _) => pw2[0] = pow_int_lanes(ndh[0], &pw),
                (_, 1) => {
                    let r = pow_int_lanes([ndh[0][0], ndh[C - 1][0]], &pw);
                    (pw2[0][0], pw2[C - 1][0]) = (r[0], r[1]);
                }
                _ => {
                    let r =
                        pow_int_lanes([ndh[0][0], ndh[0][1], ndh[C - 1][0], ndh[C - 1][1]], &pw);
                    (pw2[0], pw2[C - 1]) = ([r[0], r[1]], [r[2], r[3]]);
                }
            },
        }
        for i in 0..m {
            for j in 0..C {
                let spec = V::select(pos[j][i], s[j].spec * pw2[j][i], zero);
                let lit = ndl[j][i].gt(zero);
                for k in 0..3 {
                    let term = s[j].base[k] * ndl[j][i] + spec;
                    c[j][k] = c[j][k] + V::select(lit, l.color[p + i][k] * term, zero);
                }
            }
        }
        p += 2;
    }
    c
}

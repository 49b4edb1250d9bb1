//! The workspace's shading model over lanes: 8 pixels (or chunks of 8) at a time, with the
//! polynomial `pow` of the parent module.

use super::*;

/// Surface and material of 8 pixels, structure-of-arrays.
#[derive(Clone, Copy, Debug, Default)]
#[cfg_attr(not(test), allow(dead_code))] // the SoA form of the tests (and of the bond pass)
pub(crate) struct Surf8 {
    pub n: [F8; 3],
    pub v: [F8; 3],
    pub base: [F8; 3],
    pub spec: F8,
    pub shin: F8,
}

/// [`shade`] over 8 lanes: the same formula, masks instead of branches, on [`V8`] lanes.
#[inline(always)]
#[cfg_attr(not(test), allow(dead_code))] // as `Surf8`
pub(crate) fn shade8(l: &Lighting, s: &Surf8) -> [F8; 3] {
    let ld = |a: &[F8; 3]| [V8::load(&a[0]), V8::load(&a[1]), V8::load(&a[2])];
    let c = shade_lanes(
        l,
        ld(&s.n),
        ld(&s.v),
        ld(&s.base),
        V8::load(&s.spec),
        V8::load(&s.shin),
        spec_pow(&s.shin),
    );
    [c[0].store(), c[1].store(), c[2].store()]
}

/// [`shade`] over 8 lanes of any [`Simd8`] backend: the same formula, masks instead of
/// branches. `pw` is [`spec_pow_of`]`(shin)` (the caller may know it for the whole frame):
/// integer exponents are taken by squaring (exact to a few ulp, and cheaper), others by
/// exp2(e·log2 x). Every backend performs the same IEEE operations in the same
/// order, so all give the same bits.
#[inline(always)]
pub(crate) fn shade_lanes<V: Simd8>(
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
pub(crate) struct LanesLighting<V, const N: usize> {
    ambient: [V; 3],
    dir: [[V; 3]; N],
    color: [[V; 3]; N],
}

impl<V: Simd8, const N: usize> LanesLighting<V, N> {
    /// `l`'s constants as lanes (`l` must have `N` lights).
    #[inline(always)]
    pub(crate) fn new(l: &Lighting) -> Self {
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
/// are taken two at a time (their specular powers share one squaring loop, see `pow_int8`) and
/// their terms added in the lights' order.
#[inline(always)]
pub(crate) fn shade_lanes_n<V: Simd8, const N: usize>(
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
pub(crate) struct LaneSurf<V> {
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
pub(crate) fn shade_chunks<V: Simd8, const N: usize, const C: usize>(
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
                        pw2[j][i] = pow_poly8(ndh[j][i], s[j].shin);
                    }
                }
            }
            _ => match (C, m) {
                (1, 1) => pw2[0][0] = pow_int8([ndh[0][0]], &pw)[0],
                (1, _) => pw2[0] = pow_int8(ndh[0], &pw),
                (_, 1) => {
                    let r = pow_int8([ndh[0][0], ndh[C - 1][0]], &pw);
                    (pw2[0][0], pw2[C - 1][0]) = (r[0], r[1]);
                }
                _ => {
                    let r = pow_int8([ndh[0][0], ndh[0][1], ndh[C - 1][0], ndh[C - 1][1]], &pw);
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

/// `x^e = exp2(e·log2 x)` over 8 lanes with the polynomials (`x ∈ (0, 1]`, any `e ≥ 0`).
#[inline(always)]
pub(super) fn pow_poly8<V: Simd8>(x: V, shin: V) -> V {
    let mut a = [0f32; W];
    x.store_to(&mut a);
    let lg = V::load_from(&log2_8(&a));
    let z = (shin * lg).min(V::splat(0.0));
    z.store_to(&mut a);
    V::load_from(&exp2_neg8(&a))
}

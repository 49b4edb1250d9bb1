//! The span sampler's level policy makes bank conflicts impossible (Seed 000 §3, Eq. 8–10):
//! a property test over random planes, eyes, map scales and spans, for K = 3 and K = 4, power-of-two
//! and other sizes, repeat and clamp. It also checks the converse — one level finer than the
//! policy (the conventional pair for K = 3) DOES conflict — and that the fast path reads the same
//! bits as the bank emulator.

use texmap_core::camera::Camera;
use texmap_core::glam::{Vec3, Vec4};
use texmap_core::mip::{MipTexture, Reduction, Wrap};
use texmap_core::sample::{BankStats, BankedTexture, Banks, Sampler};
use texmap_core::transform::TexturedFace;

/// xorshift64*: a small seeded generator.
struct Rng(u64);
impl Rng {
    fn f(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 40) as f32 / (1u64 << 24) as f32
    }
    fn range(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.f()
    }
    fn vec(&mut self, s: f32) -> Vec3 {
        Vec3::new(self.range(-s, s), self.range(-s, s), self.range(-s, s))
    }
}

fn texture(w: u32, h: u32, wrap: Wrap, r: &mut Rng) -> MipTexture {
    let data: Vec<Vec4> = (0..w * h)
        .map(|_| Vec4::new(r.f(), r.f(), r.f(), 1.0))
        .collect();
    MipTexture::from_linear(w, h, &data, Reduction::GammaCorrect, wrap).unwrap()
}

/// Random scenes; calls `f` with each span's four map images.
fn for_random_spans(
    seed: u64,
    scenes: usize,
    spans: usize,
    mut f: impl FnMut([texmap_core::glam::Vec2; 4]),
) -> usize {
    let mut r = Rng(seed);
    let mut n = 0;
    for _ in 0..scenes {
        let eye = r.vec(10.0);
        let Ok(cam) = Camera::perspective_look_at(
            eye,
            r.vec(2.0),
            Vec3::Y,
            r.range(10.0, 150.0),
            r.range(32.0, 512.0) as u32,
            r.range(32.0, 512.0) as u32,
        ) else {
            continue;
        };
        // Map widths from 1/50 to 50 world units: heavy magnification to heavy minification.
        let map_width = 10f32.powf(r.range(-1.7, 1.7));
        let Ok(face) = TexturedFace::new(r.vec(3.0), r.vec(1.0), r.vec(1.0), map_width, &cam)
        else {
            continue;
        };
        for _ in 0..spans {
            let x = r.range(1.0, cam.width() as f32 - 1.0);
            let y = r.range(1.0, cam.height() as f32 - 1.0);
            if let Some(q) = face.map_span(x, y) {
                f(q);
                n += 1;
            }
        }
    }
    n
}

#[test]
fn the_level_policy_makes_bank_conflicts_impossible() {
    let mut tr = Rng(7);
    let mut total = 0;
    for (w, h) in [(64, 64), (256, 256), (48, 20), (7, 33), (1, 1)] {
        for wrap in [Wrap::Repeat, Wrap::Clamp] {
            let tex = texture(w, h, wrap, &mut tr);
            for banks in [Banks::K3, Banks::K4] {
                let bt = BankedTexture::new(&tex, banks);
                let mut st = BankStats::default();
                let (mut one_level, mut two_levels) = (0, 0);
                let n = for_random_spans(0xC0FFEE ^ w as u64 ^ ((h as u64) << 20), 150, 60, |q| {
                    let before = st.window_reads;
                    let got = bt.sample_quad(&tex, q, &mut st);
                    match st.window_reads - before {
                        1 => one_level += 1,
                        2 => two_levels += 1,
                        k => panic!("{k} window reads for one span"),
                    }
                    // The fast path reads the same texels: bit-identical.
                    let fast = Sampler::Span(banks).sample_quad(&tex, q);
                    for j in 0..4 {
                        assert_eq!(
                            got[j].to_array().map(f32::to_bits),
                            fast[j].to_array().map(f32::to_bits),
                            "{w}x{h} {wrap:?} {banks:?} pixel {j}: emulator {} vs fast {}",
                            got[j],
                            fast[j]
                        );
                        assert!(got[j].is_finite());
                    }
                });
                assert_eq!(
                    st.conflicts, 0,
                    "{w}x{h} {wrap:?} {banks:?}: {st:?} over {n} spans"
                );
                assert_eq!(
                    st.bank_reads,
                    st.window_reads * (banks.k() * banks.k()) as u64
                );
                assert!(n > 4000, "only {n} spans");
                // The random spans reached both the blended and the single-level cases, and (for
                // textures bigger than a window) windows that cross the edge into the apron.
                if w * h > 1 {
                    assert!(
                        one_level > 0 && two_levels > 0,
                        "{one_level} / {two_levels}"
                    );
                }
                if w > 8 && h > 8 {
                    assert!(st.edge_windows > 0, "no edge windows: {st:?}");
                }
                total += n;
            }
        }
    }
    eprintln!("{total} spans, no conflicts");
}

#[test]
fn one_level_finer_than_the_policy_conflicts() {
    // K = 3 with the conventional pair (⌊l⌋, ⌊l⌋+1), and K = 4 one level finer still: the span
    // extent at the finer level can reach 2 (K = 3) or 4 (K = 4) texels, beyond the window.
    let mut tr = Rng(11);
    let tex = texture(256, 256, Wrap::Repeat, &mut tr);
    for banks in [Banks::K3, Banks::K4] {
        let bt = BankedTexture::new(&tex, banks).with_level_bias(-1);
        let mut st = BankStats::default();
        for_random_spans(99, 100, 60, |q| {
            let got = bt.sample_quad(&tex, q, &mut st);
            assert!(got.iter().all(|c| c.is_finite()));
        });
        assert!(
            st.conflicts > 100,
            "{banks:?} one level finer than the policy should conflict: {st:?}"
        );
        eprintln!("{banks:?} with level bias -1: {st:?}");
    }
}

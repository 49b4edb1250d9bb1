//! The bank emulator (Seed 000 §3): a level's texels dealt into K x K memory banks by
//! `(x mod K, y mod K)`, every span window read bank by bank, and every read and conflict
//! counted, so the conflict-free claim is checked rather than assumed.

use super::*;

/// Counters of the bank emulator.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BankStats {
    /// Spans sampled.
    pub spans: u64,
    /// Parallel window reads (one per level per span).
    pub window_reads: u64,
    /// Individual bank reads (K² per window read; each bank read once per window).
    pub bank_reads: u64,
    /// Texel accesses that fell outside the fetched window (would need another memory cycle).
    pub conflicts: u64,
    /// Window reads that crossed the right or bottom edge of their level (served by the apron).
    pub edge_windows: u64,
}

/// One level stored as K x K banks of the padded level (apron of K − 1 texels, see module doc).
#[derive(Clone, Debug)]
pub(super) struct BankedLevel {
    /// Addresses per bank row (bank width).
    pub(super) bank_w: usize,
    /// `banks[j * K + i]` holds texels with `X mod K = i`, `Y mod K = j`.
    pub(super) banks: Vec<Vec<Vec4>>,
}

/// A [`MipTexture`] re-laid out as K x K memory banks per level (Seed 000 Eq. 10), for emulating
/// the span sampler's parallel reads and counting bank conflicts. Slow by design: it is the
/// model the fast path is checked against, not a renderer.
#[derive(Clone, Debug)]
pub struct BankedTexture {
    banks: Banks,
    levels: Vec<BankedLevel>,
    bias: i32,
}

impl BankedTexture {
    /// Split every level of `tex` into `banks.k()`² banks (with the wrap apron).
    pub fn new(tex: &MipTexture, banks: Banks) -> BankedTexture {
        let k = banks.k();
        let levels = (0..tex.level_count())
            .map(|li| {
                let l = tex.levels()[li];
                let (pw, ph) = (l.width as usize + k - 1, l.height as usize + k - 1);
                let (bw, bh) = (pw.div_ceil(k), ph.div_ceil(k));
                let mut bk = vec![vec![Vec4::ZERO; bw * bh]; k * k];
                for py in 0..ph {
                    for px in 0..pw {
                        // Padded texel (px, py) holds the wrapped (Repeat) or edge (Clamp) texel.
                        let t = tex.texel(li, px as i64, py as i64).unwrap_or(Vec4::ZERO);
                        bk[(py % k) * k + px % k][(py / k) * bw + px / k] = t;
                    }
                }
                BankedLevel {
                    bank_w: bw,
                    banks: bk,
                }
            })
            .collect();
        BankedTexture {
            banks,
            levels,
            bias: 0,
        }
    }

    /// For experiments: add `bias` to the policy's finer level index (negative = finer). Any
    /// negative bias breaks the no-conflict guarantee — e.g. K = 3 with bias −1 is the
    /// conventional trilinear pair — and the conflicts show up in [`BankStats::conflicts`].
    pub fn with_level_bias(mut self, bias: i32) -> BankedTexture {
        self.bias = bias.clamp(-64, 64);
        self
    }

    /// K, banks per side.
    pub fn banks(&self) -> Banks {
        self.banks
    }

    /// The span sampler through the banks: same output as [`Sampler::Span`] (bit-identical),
    /// counting reads and conflicts in `stats`. `tex` must be the texture this was built from.
    pub fn sample_quad(&self, tex: &MipTexture, uv: [Vec2; 4], stats: &mut BankStats) -> [Vec4; 4] {
        stats.spans += 1;
        let mut src = BankSource { bt: self, stats };
        with_addr!(tex, A, {
            match self.banks {
                Banks::K3 => span_quad::<A, _, 3>(tex, uv, self.bias, &mut src),
                Banks::K4 => span_quad::<A, _, 4>(tex, uv, self.bias, &mut src),
            }
        })
    }
}

pub(super) struct BankSource<'a> {
    pub(super) bt: &'a BankedTexture,
    pub(super) stats: &'a mut BankStats,
}

impl WindowSource for BankSource<'_> {
    type Win = [[Vec4; 4]; 4];
    fn window<A: Addr, const K: usize>(
        &mut self,
        tex: &MipTexture,
        level: usize,
        x0: i32,
        y0: i32,
    ) -> Self::Win {
        let l = &tex.levels()[level];
        let bl = &self.bt.levels[level];
        // Reduce the corner into the level (the window never wraps in the padded bank space).
        let (x0, y0) = if A::REPEAT {
            (
                x0.rem_euclid(l.width as i32) as usize,
                y0.rem_euclid(l.height as i32) as usize,
            )
        } else {
            (
                x0.clamp(0, l.width as i32 - 1) as usize,
                y0.clamp(0, l.height as i32 - 1) as usize,
            )
        };
        self.stats.window_reads += 1;
        if x0 + K > l.width as usize || y0 + K > l.height as usize {
            self.stats.edge_windows += 1;
        }
        let mut win = [[Vec4::ZERO; 4]; 4];
        for j in 0..K {
            // Seed 000 Eq. (10): a_j = ⌊Y0/K⌋ + δ(j, Y0), δ = 1 if j < Y0 mod K.
            let ay = y0 / K + usize::from(j < y0 % K);
            let oy = ay * K + j - y0;
            for i in 0..K {
                let ax = x0 / K + usize::from(i < x0 % K);
                let ox = ax * K + i - x0;
                debug_assert!(ox < K && oy < K);
                win[oy][ox] = bl.banks[j * K + i][ay * bl.bank_w + ax];
                self.stats.bank_reads += 1;
            }
        }
        win
    }
    fn quad(_tex: &MipTexture, win: &Self::Win, ox: usize, oy: usize) -> [Vec4; 4] {
        [
            win[oy][ox],
            win[oy][ox + 1],
            win[oy + 1][ox],
            win[oy + 1][ox + 1],
        ]
    }
    fn conflict(&mut self) {
        self.stats.conflicts += 1;
    }
}

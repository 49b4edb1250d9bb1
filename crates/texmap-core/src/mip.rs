//! Mip pyramids: the texel storage every sampler of [`crate::sample`] reads.
//!
//! A [`MipTexture`] holds all levels of one image as linear-light RGBA `f32` texels ([`Vec4`],
//! 16 bytes, SIMD-aligned) in ONE contiguous buffer, level 0 (finest) first, each level row-major
//! with row 0 at map `v = 0` (followed, on power-of-two pyramids, by small copies of the levels'
//! seams for the AVX-512 span kernel: see [`MipTexture`]). Per level it keeps the offset, size
//! and the reciprocal-free `f32` sizes the samplers need, so the hot path does no division and
//! (after validation here) no bounds checks.
//!
//! # Level sizes and the non-power-of-two (NPOT) reduction
//! Level `i + 1` has `max(1, ⌊w_i / 2⌋) x max(1, ⌊h_i / 2⌋)` texels, down to 1x1. Each axis is
//! reduced separably with an exact box over the destination texel's footprint:
//! - even size `2m`: destination `x` averages sources `2x, 2x+1` (weights ½, ½);
//! - odd size `2m+1` (m ≥ 1): destination `x` covers `(2m+1)/m` source texels, so it takes
//!   sources `2x, 2x+1, 2x+2` with weights `(m−x)/(2m+1), m/(2m+1), (x+1)/(2m+1)`;
//! - size 1: copied.
//!
//! Every source texel then carries the same total weight `m/(2m+1)`, so the mean of a level equals
//! the mean of the level above it exactly (up to float rounding), and the 1x1 top level is the mean
//! of the whole image. Rounding up to a power of two was rejected: it resamples level 0 and so
//! changes the image the user gave.
//!
//! # Box versus gamma-correct reduction
//! [`Reduction::GammaCorrect`] averages LINEAR light (sRGB input is decoded first, the stored
//! texels stay linear): a black/white checkerboard reduces to 0.5 linear = sRGB code 188.
//! [`Reduction::Box`] averages the values in the input's own encoding — for sRGB input, the
//! encoded values, as naive mip generators do (the same checkerboard gives code 128, too dark);
//! for linear input the two reductions coincide. Alpha is straight (not premultiplied) and always
//! averaged linearly.
//!
//! # Wrap modes
//! [`Wrap::Repeat`] tiles the map (`u = 1` is `u = 0`); [`Wrap::Clamp`] repeats the edge texels.
//! A texture whose level 0 is a power of two on both axes wraps with bit masks; others with a
//! Euclidean remainder ([`MipTexture::is_pow2`]).
//!
//! Texel centres: texel `(x, y)` of a `w x h` level is centred at map coordinates
//! `((x + ½)/w, (y + ½)/h)` (map widths), so box-filtered levels stay registered. Seed 000 Eq. (3)
//! writes `a_c = ⌊2^L r_m⌋` without the half-texel offset; [`crate::sample`] applies Eq. (3) to
//! `2^L r_m − ½`.
//!
//! ```
//! use texmap_core::mip::{MipTexture, Reduction, Wrap};
//! // A 2x2 black/white checkerboard in sRGB8.
//! let px = [[0u8, 0, 0, 255], [255, 255, 255, 255], [255, 255, 255, 255], [0, 0, 0, 255]];
//! let tex = MipTexture::from_srgb8(2, 2, px.as_flattened(), Reduction::GammaCorrect, Wrap::Repeat)
//!     .unwrap();
//! assert_eq!(tex.level_count(), 2);
//! // The 1x1 level is 50% linear light: sRGB code 188, not the naive 128.
//! assert_eq!(tex.texel_srgb8(1, 0, 0)[0], 188);
//! ```

use glam::Vec4;

use crate::color::{linear_to_srgb, linear_to_srgb8_exact, srgb_to_linear, srgb8_to_linear};

/// The largest level-0 side accepted (the same bound as camera images).
pub const MAX_TEXTURE_SIDE: u32 = 16384;

/// How texel addresses outside a level are folded back into it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Wrap {
    /// Tile the map: texel `x` is texel `x mod w`.
    Repeat,
    /// Clamp to the edge texel.
    Clamp,
}

/// How one level is averaged into the next.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Reduction {
    /// Average the values in the input's own encoding (naive for sRGB input).
    Box,
    /// Average linear light (decode sRGB, average, keep linear).
    GammaCorrect,
}

/// Why a texture could not be built.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum MipError {
    /// A side is zero or larger than [`MAX_TEXTURE_SIDE`].
    BadSize { width: u32, height: u32 },
    /// The pixel buffer does not hold `width * height` pixels.
    DataLength { expected: usize, actual: usize },
    /// A linear input texel holds NaN or an infinity.
    NonFinite { x: u32, y: u32 },
}

impl std::fmt::Display for MipError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MipError::BadSize { width, height } => write!(
                f,
                "texture size {width}x{height} is not allowed (each side must be 1..={MAX_TEXTURE_SIDE})"
            ),
            MipError::DataLength { expected, actual } => {
                write!(f, "texture data holds {actual} values, expected {expected}")
            }
            MipError::NonFinite { x, y } => {
                write!(f, "texel ({x}, {y}) is not finite")
            }
        }
    }
}

impl std::error::Error for MipError {}

/// Where one level lives in the texel buffer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LevelInfo {
    /// Index of texel (0, 0) in [`MipTexture::texels`].
    pub offset: usize,
    pub width: u32,
    pub height: u32,
    /// `width as f32`, `height as f32`: map widths -> texels.
    pub width_f: f32,
    pub height_f: f32,
    /// `width / width_0`, `height / height_0`: level-0 texel coordinates -> this level's
    /// (exactly `2^-i` for power-of-two textures).
    pub scale_x: f32,
    pub scale_y: f32,
    /// `1 / width_f`, `1 / height_f`.
    pub inv_width_f: f32,
    pub inv_height_f: f32,
}

/// A validated mip pyramid of linear RGBA `f32` texels.
///
/// # Guarantees
/// At least one level; level 0 is the input size; each next level follows the module's size rule
/// down to 1x1; every texel is finite; [`MipTexture::texels`]`.len()` is the sum of the level
/// areas.
///
/// # Seam strips
/// On a power-of-two pyramid, each `w x h` level also has two Repeat *seam strips* after the
/// levels in the same buffer (not part of [`MipTexture::texels`]), so that every 3x3 window
/// whose corner `(x0, y0)` is wrapped into `[0, w) x [0, h)` is contiguous somewhere:
/// - windows with `x0 + 3 > w` (crossing the right edge) in the *column strip*: level columns
///   `w − 2 .. w + 2` (mod `w`) of rows `0 .. h + 2` (mod `h`), row stride 4;
/// - other windows with `y0 + 3 > h` in the *row strip*: level rows `h − 2 .. h + 2` (mod `h`),
///   all `w` columns, row stride `w`;
/// - all others are inside the level itself.
///
/// That is `4·(h + 2) + 4·w` texels per level, about `8·(w + h)` texels per pyramid (`w x h`
/// level 0): 1 MiB for 4096² (0.3% of the pyramid), 65 KiB for 256² (5%). The AVX-512 span kernel reads such windows as interior ones
/// instead of taking the per-span edge path.
#[derive(Clone, Debug, PartialEq)]
pub struct MipTexture {
    /// The levels' texels, then the seam strips'.
    texels: Vec<Vec4>,
    /// Number of level texels (the sum of the level areas): `texels[..level_texels]`.
    level_texels: usize,
    /// Per level `min(i, last)`, the strips' origins ([`MipTexture::seam_offsets16`]); all 0
    /// without strips (NPOT pyramids).
    col_strip16: [i32; 16],
    row_strip16: [i32; 16],
    levels: Vec<LevelInfo>,
    wrap: Wrap,
    reduction: Reduction,
    pow2: bool,
    /// Texel index of level `min(i, last)`'s texel (0, 0), as `i32` (the sum of all level areas is
    /// at most 4/3 · 16384² < 2^31): a 16-entry table the AVX2 sampling kernels look levels up in
    /// with two register permutes instead of per-pixel loads.
    offsets16: [i32; 16],
}

/// The input's encoding, which decides the averaging space of [`Reduction::Box`].
#[derive(Clone, Copy, PartialEq)]
enum Encoding {
    Srgb,
    Linear,
}

/// Buffers a pyramid is built into (empty, or taken from a pyramid no longer needed).
#[derive(Default)]
struct Storage {
    texels: Vec<Vec4>,
    levels: Vec<LevelInfo>,
}

fn check_size(width: u32, height: u32) -> Result<(), MipError> {
    if width == 0 || height == 0 || width > MAX_TEXTURE_SIDE || height > MAX_TEXTURE_SIDE {
        return Err(MipError::BadSize { width, height });
    }
    Ok(())
}

impl MipTexture {
    /// A pyramid from RGBA8 pixels whose RGB is sRGB-encoded and alpha linear (the usual PNG).
    /// `data` holds `4 * width * height` bytes, row 0 first.
    pub fn from_srgb8(
        width: u32,
        height: u32,
        data: &[u8],
        reduction: Reduction,
        wrap: Wrap,
    ) -> Result<MipTexture, MipError> {
        check_size(width, height)?;
        let n = width as usize * height as usize;
        if data.len() != 4 * n {
            return Err(MipError::DataLength {
                expected: 4 * n,
                actual: data.len(),
            });
        }
        // Decode to the averaging space: linear light, or (Box) the encoded values in 0..1.
        let work: Vec<Vec4> = data
            .chunks_exact(4)
            .map(|p| match reduction {
                Reduction::GammaCorrect => Vec4::new(
                    srgb8_to_linear(p[0]),
                    srgb8_to_linear(p[1]),
                    srgb8_to_linear(p[2]),
                    p[3] as f32 / 255.0,
                ),
                Reduction::Box => Vec4::new(
                    p[0] as f32 / 255.0,
                    p[1] as f32 / 255.0,
                    p[2] as f32 / 255.0,
                    p[3] as f32 / 255.0,
                ),
            })
            .collect();
        Ok(Self::build(
            width,
            height,
            &work,
            Encoding::Srgb,
            reduction,
            wrap,
            Storage::default(),
        ))
    }

    /// A pyramid from linear-light RGBA `f32` texels (row 0 first). Every value must be finite.
    pub fn from_linear(
        width: u32,
        height: u32,
        data: &[Vec4],
        reduction: Reduction,
        wrap: Wrap,
    ) -> Result<MipTexture, MipError> {
        Self::linear(width, height, data, reduction, wrap, Storage::default())
    }

    /// [`MipTexture::from_linear`] built into the buffers of `old`, a pyramid no longer needed:
    /// when they are large enough (a pyramid of the same size rebuilt every frame), nothing is
    /// allocated. The result equals [`MipTexture::from_linear`]'s; on an error `old` is dropped.
    pub fn from_linear_reusing(
        old: MipTexture,
        width: u32,
        height: u32,
        data: &[Vec4],
        reduction: Reduction,
        wrap: Wrap,
    ) -> Result<MipTexture, MipError> {
        let storage = Storage {
            texels: old.texels,
            levels: old.levels,
        };
        Self::linear(width, height, data, reduction, wrap, storage)
    }

    fn linear(
        width: u32,
        height: u32,
        data: &[Vec4],
        reduction: Reduction,
        wrap: Wrap,
        storage: Storage,
    ) -> Result<MipTexture, MipError> {
        check_size(width, height)?;
        let n = width as usize * height as usize;
        if data.len() != n {
            return Err(MipError::DataLength {
                expected: n,
                actual: data.len(),
            });
        }
        if let Some(i) = data.iter().position(|t| !t.is_finite()) {
            return Err(MipError::NonFinite {
                x: (i % width as usize) as u32,
                y: (i / width as usize) as u32,
            });
        }
        Ok(Self::build(
            width,
            height,
            data,
            Encoding::Linear,
            reduction,
            wrap,
            storage,
        ))
    }

    /// Reduce level by level in the averaging space (`level0` is level 0 in it); store every
    /// level as linear light, in `storage`'s buffers.
    fn build(
        width: u32,
        height: u32,
        level0: &[Vec4],
        encoding: Encoding,
        reduction: Reduction,
        wrap: Wrap,
        storage: Storage,
    ) -> MipTexture {
        let encoded = encoding == Encoding::Srgb && reduction == Reduction::Box;
        let pow2 = width.is_power_of_two() && height.is_power_of_two();
        let Storage {
            mut texels,
            mut levels,
        } = storage;
        levels.clear();
        let (mut w, mut h) = (width, height);
        let mut level_texels = 0usize;
        let mut strip_texels = 0usize;
        loop {
            levels.push(LevelInfo {
                offset: level_texels,
                width: w,
                height: h,
                width_f: w as f32,
                height_f: h as f32,
                scale_x: w as f32 / width as f32,
                scale_y: h as f32 / height as f32,
                inv_width_f: 1.0 / w as f32,
                inv_height_f: 1.0 / h as f32,
            });
            level_texels += w as usize * h as usize;
            if pow2 {
                strip_texels += 4 * (h as usize + 2) + 4 * w as usize;
            }
            if w == 1 && h == 1 {
                break;
            }
            (w, h) = ((w / 2).max(1), (h / 2).max(1));
        }
        // Every level and seam strip in one buffer, sized once (a reused buffer keeps its pages).
        texels.clear();
        texels.resize(level_texels + strip_texels, Vec4::ZERO);
        // The levels are reduced in place in the averaging space: the texel buffer itself, or a
        // separate one for Box-filtered sRGB input (reduced encoded, stored linear).
        let mut encoded_levels = Vec::new();
        let avg: &mut [Vec4] = if encoded {
            encoded_levels.resize(level_texels, Vec4::ZERO);
            &mut encoded_levels
        } else {
            &mut texels[..level_texels]
        };
        avg[..level0.len()].copy_from_slice(level0);
        let mut rows = vec![Vec4::ZERO; 3 * (width as usize / 2).max(1)];
        for pair in levels.windows(2) {
            let (src, dst) = avg.split_at_mut(pair[1].offset);
            reduce_level(&src[pair[0].offset..], &pair[0], dst, &pair[1], &mut rows);
        }
        if encoded {
            for (t, e) in texels.iter_mut().zip(&encoded_levels) {
                *t = Vec4::new(
                    srgb_to_linear(e.x),
                    srgb_to_linear(e.y),
                    srgb_to_linear(e.z),
                    e.w,
                );
            }
        }
        // Linear-light storage of sRGB Box levels can only drift by float rounding: keep it finite.
        debug_assert!(texels.iter().all(|t| t.is_finite()));
        let last = levels.len() - 1;
        let offsets16 = std::array::from_fn(|i| levels[i.min(last)].offset as i32);
        // Repeat seam strips of every level (power-of-two pyramids only: the kernel that reads
        // them is the power-of-two one). Origins are stored shifted so that strip texel (x, y)
        // sits at origin + y·stride + x in level coordinates (x = w − 2.. in the column strip,
        // y = h − 2.. in the row strip); they stay positive (each strip follows all levels).
        let (mut col_strip16, mut row_strip16) = ([0i32; 16], [0i32; 16]);
        if pow2 {
            let mut end = level_texels;
            for (i, l) in levels.iter().enumerate() {
                let (w, h) = (l.width as usize, l.height as usize);
                let at = |x: usize, y: usize| l.offset + (y % h) * w + x % w;
                col_strip16[i] = (end + 2) as i32 - w as i32;
                for y in 0..h + 2 {
                    for x in w + w - 2..w + w + 2 {
                        texels[end] = texels[at(x, y)];
                        end += 1;
                    }
                }
                row_strip16[i] = end as i32 - (h as i32 - 2) * w as i32;
                for y in h + h - 2..h + h + 2 {
                    for x in 0..w {
                        texels[end] = texels[at(x, y)];
                        end += 1;
                    }
                }
            }
            debug_assert_eq!(end, texels.len(), "strip storage sized exactly");
            let top = (col_strip16[last], row_strip16[last]);
            let strips = col_strip16.iter_mut().zip(row_strip16.iter_mut());
            for (c, r) in strips.skip(levels.len()) {
                (*c, *r) = top;
            }
        }
        MipTexture {
            texels,
            level_texels,
            col_strip16,
            row_strip16,
            levels,
            wrap,
            reduction,
            pow2,
            offsets16,
        }
    }

    /// The same texels with another wrap mode.
    pub fn with_wrap(mut self, wrap: Wrap) -> MipTexture {
        self.wrap = wrap;
        self
    }

    #[inline]
    pub fn wrap(&self) -> Wrap {
        self.wrap
    }
    #[inline]
    pub fn reduction(&self) -> Reduction {
        self.reduction
    }
    /// Whether level 0 is a power of two on both axes (then every level is, and Repeat uses masks).
    #[inline]
    pub fn is_pow2(&self) -> bool {
        self.pow2
    }
    #[inline]
    pub fn width(&self) -> u32 {
        self.levels[0].width
    }
    #[inline]
    pub fn height(&self) -> u32 {
        self.levels[0].height
    }
    /// Number of levels, level 0 (the input) to the 1x1 top.
    #[inline]
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }
    /// Size and offset of level `i`, or `None` past the top.
    #[inline]
    pub fn level(&self, i: usize) -> Option<&LevelInfo> {
        self.levels.get(i)
    }
    /// All levels, finest first.
    #[inline]
    pub fn levels(&self) -> &[LevelInfo] {
        &self.levels
    }
    /// Texel index of each level's texel (0, 0) for levels `0..16`, entries past the top level
    /// repeating the top level's (for the sampling kernels' table look-ups).
    #[inline]
    pub(crate) fn level_offsets16(&self) -> &[i32; 16] {
        &self.offsets16
    }
    /// All texels of all levels (linear RGBA), level 0 first, row-major.
    #[inline]
    pub fn texels(&self) -> &[Vec4] {
        &self.texels[..self.level_texels]
    }
    /// The whole texel buffer: [`MipTexture::texels`], then the Repeat seam strips (see the
    /// type's doc); the level offsets and [`MipTexture::seam_offsets16`] index it.
    #[inline]
    pub(crate) fn texel_buffer(&self) -> &[Vec4] {
        &self.texels
    }
    /// The seam strips' origins in [`MipTexture::texel_buffer`] for levels `0..16` (entries past
    /// the top repeating the top level's), `(column strip, row strip)`: the copy of level texel
    /// `(x mod w, y mod h)` is at `col + 4·y + x` for `x ∈ [w − 2, w + 2)`, `y ∈ [0, h + 2)`, and
    /// at `row + w·y + x` for `x ∈ [0, w)`, `y ∈ [h − 2, h + 2)`. `None` on NPOT pyramids (no
    /// strips).
    #[inline]
    pub(crate) fn seam_offsets16(&self) -> Option<(&[i32; 16], &[i32; 16])> {
        self.pow2.then_some((&self.col_strip16, &self.row_strip16))
    }
    /// `log2` of the larger level-0 side: the `n` of a `2^n`-texel map (fractional for NPOT).
    pub fn size_log2(&self) -> f32 {
        (self.width().max(self.height()) as f32).log2()
    }

    /// Texel `(x, y)` of level `level` with the texture's wrap mode applied to any integer address;
    /// `None` if the level does not exist.
    pub fn texel(&self, level: usize, x: i64, y: i64) -> Option<Vec4> {
        let l = self.levels.get(level)?;
        let (xi, yi) = match self.wrap {
            Wrap::Repeat => (x.rem_euclid(l.width as i64), y.rem_euclid(l.height as i64)),
            Wrap::Clamp => (
                x.clamp(0, l.width as i64 - 1),
                y.clamp(0, l.height as i64 - 1),
            ),
        };
        Some(self.texels[l.offset + yi as usize * l.width as usize + xi as usize])
    }

    /// Texel `(x, y)` of `level` encoded as RGBA8 sRGB (exact encoder); `[0; 4]` if the level does
    /// not exist.
    pub fn texel_srgb8(&self, level: usize, x: i64, y: i64) -> [u8; 4] {
        match self.texel(level, x, y) {
            Some(t) => [
                linear_to_srgb8_exact(t.x),
                linear_to_srgb8_exact(t.y),
                linear_to_srgb8_exact(t.z),
                (t.w.clamp(0.0, 1.0) * 255.0 + 0.5) as u8,
            ],
            None => [0; 4],
        }
    }

    /// Mean linear value of a level (f64 accumulation), for checks and tests.
    pub fn level_mean(&self, level: usize) -> Option<[f64; 4]> {
        let l = self.levels.get(level)?;
        let n = l.width as usize * l.height as usize;
        let mut s = [0f64; 4];
        for t in &self.texels[l.offset..l.offset + n] {
            for (c, v) in s.iter_mut().zip(t.to_array()) {
                *c += v as f64;
            }
        }
        Some(s.map(|v| v / n as f64))
    }
}

/// Reduce one line of `src.len()` texels (stride `ss`) into `dst` (stride `ds`) with the module's
/// exact box weights.
fn reduce_line(src: &[Vec4], ss: usize, dst: &mut [Vec4], ds: usize) {
    let n = src.len().div_ceil(ss);
    let get = |i: usize| src[i * ss];
    let m = dst.len().div_ceil(ds);
    if n == 1 {
        dst[0] = get(0);
    } else if n.is_multiple_of(2) {
        // Even: pairs with weights ½, ½.
        for x in 0..m {
            dst[x * ds] = (get(2 * x) + get(2 * x + 1)) * 0.5;
        }
    } else {
        // Odd 2m+1: three taps (m−x, m, x+1)/(2m+1).
        let inv = 1.0 / n as f32;
        let mf = m as f32;
        for x in 0..m {
            let xf = x as f32;
            dst[x * ds] = get(2 * x) * ((mf - xf) * inv)
                + get(2 * x + 1) * (mf * inv)
                + get(2 * x + 2) * ((xf + 1.0) * inv);
        }
    }
}

/// Reduce level `src` (`a`) into level `dst` (`b`, the next one) with the module's exact box
/// weights, separably: each destination row combines the x-reduced source rows under it (into
/// `rows`, three rows of `b.width` at least), with [`reduce_line`]'s weights and arithmetic along
/// y, so every texel is the same expression as reducing all rows first and then each column.
fn reduce_level(src: &[Vec4], a: &LevelInfo, dst: &mut [Vec4], b: &LevelInfo, rows: &mut [Vec4]) {
    let (w, h) = (a.width as usize, a.height as usize);
    let nw = b.width as usize;
    let row = |y: usize, out: &mut [Vec4]| reduce_line(&src[y * w..(y + 1) * w], 1, out, 1);
    let (r0, rest) = rows.split_at_mut(nw);
    let (r1, rest) = rest.split_at_mut(nw);
    let r2 = &mut rest[..nw];
    let m = b.height as usize;
    let inv = 1.0 / h as f32;
    let mf = m as f32;
    for (y, out) in dst.chunks_exact_mut(nw).take(m).enumerate() {
        if h == 1 {
            row(0, out);
        } else if h.is_multiple_of(2) {
            row(2 * y, r0);
            row(2 * y + 1, r1);
            for ((o, &p), &q) in out.iter_mut().zip(&*r0).zip(&*r1) {
                *o = (p + q) * 0.5;
            }
        } else {
            row(2 * y, r0);
            row(2 * y + 1, r1);
            row(2 * y + 2, r2);
            let yf = y as f32;
            let (w0, w1, w2) = ((mf - yf) * inv, mf * inv, (yf + 1.0) * inv);
            for (((o, &p), &q), &r) in out.iter_mut().zip(&*r0).zip(&*r1).zip(&*r2) {
                *o = p * w0 + q * w1 + r * w2;
            }
        }
    }
}

/// Encode a linear value to sRGB in 0..1 (helper for callers building Box-encoded references).
#[inline]
pub fn encode_srgb(c: f32) -> f32 {
    linear_to_srgb(c.clamp(0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn level_offset_table_matches_the_levels() {
        // The largest level count (a 16384-wide side: 15 levels) and small pyramids; entries
        // past the top repeat the top level's offset, and offsets are the running sums of the
        // level areas (recomputed here).
        for (w, h) in [(1, 1), (64, 16), (48, 20), (MAX_TEXTURE_SIDE, 2)] {
            let data = vec![Vec4::ONE; (w * h) as usize];
            let t = MipTexture::from_linear(w, h, &data, Reduction::Box, Wrap::Repeat).unwrap();
            let (mut sum, mut lw, mut lh) = (0usize, w as usize, h as usize);
            let mut expect = Vec::new();
            for _ in 0..t.level_count() {
                expect.push(sum as i32);
                sum += lw * lh;
                (lw, lh) = ((lw / 2).max(1), (lh / 2).max(1));
            }
            for (i, &got) in t.level_offsets16().iter().enumerate() {
                let e = expect[i.min(expect.len() - 1)];
                assert_eq!(got, e, "{w}x{h} level {i}: expected offset {e}, got {got}");
            }
        }
    }

    #[test]
    fn seam_strips_hold_the_wrapped_texels() {
        // Every strip texel is the level texel at its wrapped address (see `seam_offsets16`);
        // NPOT pyramids have none.
        for (w, h) in [(1, 1), (256, 64), (8, 128), (2, 1), (48, 20)] {
            let data: Vec<Vec4> = (0..w * h).map(|i| Vec4::splat(i as f32)).collect();
            let t = MipTexture::from_linear(w, h, &data, Reduction::Box, Wrap::Repeat).unwrap();
            let buf = t.texel_buffer();
            assert_eq!(t.texels(), &buf[..t.texels().len()]);
            let Some((col, row)) = t.seam_offsets16() else {
                assert!(!t.is_pow2());
                assert_eq!(buf.len(), t.texels().len());
                continue;
            };
            let mut strips = 0;
            for (i, l) in t.levels().iter().enumerate() {
                let (lw, lh) = (l.width as i64, l.height as i64);
                let want = |x: i64, y: i64| t.texel(i, x, y).unwrap();
                for y in 0..lh + 2 {
                    for x in lw - 2..lw + 2 {
                        let got = buf[(col[i] as i64 + 4 * y + x) as usize];
                        assert_eq!(got, want(x, y), "{w}x{h} level {i} column strip ({x}, {y})");
                    }
                }
                for y in lh - 2..lh + 2 {
                    for x in 0..lw {
                        let got = buf[(row[i] as i64 + lw * y + x) as usize];
                        assert_eq!(got, want(x, y), "{w}x{h} level {i} row strip ({x}, {y})");
                    }
                }
                strips += 4 * (lh + 2) + 4 * lw;
            }
            assert_eq!(buf.len() - t.texels().len(), strips as usize, "{w}x{h}");
            let last = t.level_count() - 1;
            assert!(col[last + 1..].iter().all(|&o| o == col[last]));
            assert!(row[last + 1..].iter().all(|&o| o == row[last]));
        }
    }

    #[test]
    fn odd_weights_sum_to_one_and_preserve_the_mean() {
        // A ramp of 7 values: the reduced 3 values must have the same mean (f64 check).
        let src: Vec<Vec4> = (0..7).map(|i| Vec4::splat(i as f32 * i as f32)).collect();
        let mut dst = vec![Vec4::ZERO; 3];
        reduce_line(&src, 1, &mut dst, 1);
        let ms: f64 = src.iter().map(|v| v.x as f64).sum::<f64>() / 7.0;
        let md: f64 = dst.iter().map(|v| v.x as f64).sum::<f64>() / 3.0;
        assert!((ms - md).abs() < 1e-5, "expected {ms}, got {md}, tol 1e-5");
    }

    /// Texels from a small deterministic hash (values in 0..1).
    fn noise(w: u32, h: u32, seed: u32) -> Vec<Vec4> {
        (0..w * h)
            .map(|i| {
                let v = |k: u32| {
                    let x = (i ^ seed.wrapping_mul(0x9e37_79b9)).wrapping_add(k) as u64;
                    ((x.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) & 0xffff) as f32 / 65535.0
                };
                Vec4::new(v(1), v(2), v(3), v(4))
            })
            .collect()
    }

    #[test]
    fn levels_are_the_separable_box_of_the_level_below() {
        // Each level against an f64 evaluation of the module's weights (the tap lists written
        // out again here), for odd, even and unit sides.
        let taps = |n: usize, m: usize, x: usize| -> Vec<(usize, f64)> {
            if n == 1 {
                vec![(0, 1.0)]
            } else if n.is_multiple_of(2) {
                vec![(2 * x, 0.5), (2 * x + 1, 0.5)]
            } else {
                let (nf, mf, xf) = (n as f64, m as f64, x as f64);
                vec![
                    (2 * x, (mf - xf) / nf),
                    (2 * x + 1, mf / nf),
                    (2 * x + 2, (xf + 1.0) / nf),
                ]
            }
        };
        for (w, h) in [(7, 5), (6, 9), (1, 7), (10, 1), (258, 258), (33, 64)] {
            let t = MipTexture::from_linear(w, h, &noise(w, h, w * h), Reduction::Box, Wrap::Clamp)
                .unwrap();
            for i in 1..t.level_count() {
                let (a, b) = (t.levels()[i - 1], t.levels()[i]);
                let (aw, ah) = (a.width as usize, a.height as usize);
                let (bw, bh) = (b.width as usize, b.height as usize);
                for y in 0..bh {
                    for x in 0..bw {
                        let mut want = [0f64; 4];
                        for (sy, wy) in taps(ah, bh, y) {
                            for (sx, wx) in taps(aw, bw, x) {
                                let v = t.texels()[a.offset + sy * aw + sx].to_array();
                                for c in 0..4 {
                                    want[c] += wx * wy * v[c] as f64;
                                }
                            }
                        }
                        let got = t.texels()[b.offset + y * bw + x].to_array();
                        for c in 0..4 {
                            assert!(
                                (got[c] as f64 - want[c]).abs() < 1e-5,
                                "{w}x{h} level {i} ({x}, {y}) channel {c}: {} vs {}",
                                got[c],
                                want[c]
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn rebuilding_into_old_storage_gives_the_same_pyramid() {
        // Power-of-two (seam strips) and NPOT pyramids, rebuilt into a smaller, a larger and an
        // equal old buffer: the same texture as a fresh build, strips included.
        let sizes = [(64, 64), (48, 20), (258, 258), (258, 258), (16, 128)];
        let mut old =
            MipTexture::from_linear(1, 1, &[Vec4::ONE], Reduction::Box, Wrap::Repeat).unwrap();
        for (k, (w, h)) in sizes.into_iter().enumerate() {
            let data = noise(w, h, k as u32);
            let fresh = MipTexture::from_linear(w, h, &data, Reduction::Box, Wrap::Repeat).unwrap();
            let rebuilt =
                MipTexture::from_linear_reusing(old, w, h, &data, Reduction::Box, Wrap::Repeat)
                    .unwrap();
            assert_eq!(rebuilt, fresh, "{w}x{h}");
            old = rebuilt;
        }
        let bad = vec![Vec4::NAN; 4];
        let err = MipTexture::from_linear_reusing(old, 2, 2, &bad, Reduction::Box, Wrap::Clamp);
        assert!(matches!(err, Err(MipError::NonFinite { x: 0, y: 0 })));
    }
}

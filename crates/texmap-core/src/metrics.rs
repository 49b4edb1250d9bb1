//! Image metrics that say how far a method's [`Frame`] is from the reference.
//!
//! - [`psnr`]: peak signal-to-noise ratio of the 8-bit sRGB colour (RGB channels, peak 255), in dB.
//! - [`ssim`]: structural similarity (Wang et al. 2004) of the 8-bit sRGB luma
//!   (Rec. 601 weights), 8x8 windows with stride 4, constants K1 = 0.01, K2 = 0.03, L = 255.
//! - [`depth_error`]: mean and maximum absolute depth difference over the pixels both frames cover.
//! - [`silhouette_error`]: pixels whose coverage differs, and that count divided by the length of
//!   the reference silhouette (counted in pixel edges between covered and uncovered pixels):
//!   the mean displacement of the outline in pixels. Pixel-edge length overestimates the length of
//!   a diagonal outline by up to 4/π, so this mean displacement errs small by at most that factor.
//!
//! All metrics are computed on the 8-bit sRGB output (ARCHITECTURE.md); none allocates per pixel.

use crate::frame::Frame;

/// Why two frames could not be compared.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum MetricError {
    SizeMismatch { a: (u32, u32), b: (u32, u32) },
}

impl std::fmt::Display for MetricError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MetricError::SizeMismatch { a, b } => write!(
                f,
                "frames differ in size: {}x{} vs {}x{}",
                a.0, a.1, b.0, b.1
            ),
        }
    }
}

impl std::error::Error for MetricError {}

fn same_size(a: &Frame, b: &Frame) -> Result<(), MetricError> {
    if a.width() != b.width() || a.height() != b.height() {
        return Err(MetricError::SizeMismatch {
            a: (a.width(), a.height()),
            b: (b.width(), b.height()),
        });
    }
    Ok(())
}

/// PSNR of the RGB channels in dB; `f64::INFINITY` for identical images.
pub fn psnr(a: &Frame, b: &Frame) -> Result<f64, MetricError> {
    same_size(a, b)?;
    let mut sse = 0u64;
    for (p, q) in a.color.iter().zip(&b.color) {
        for c in 0..3 {
            let d = p[c] as i64 - q[c] as i64;
            sse += (d * d) as u64;
        }
    }
    let n = (a.len() * 3) as f64;
    if sse == 0 || n == 0.0 {
        return Ok(f64::INFINITY);
    }
    let mse = sse as f64 / n;
    Ok(10.0 * (255.0f64 * 255.0 / mse).log10())
}

#[inline]
fn luma(c: [u8; 4]) -> f64 {
    0.299 * c[0] as f64 + 0.587 * c[1] as f64 + 0.114 * c[2] as f64
}

/// Mean SSIM of the luma over 8x8 windows at stride 4 (1.0 for identical images). Images smaller
/// than 8 pixels in a side use one window of their full size.
pub fn ssim(a: &Frame, b: &Frame) -> Result<f64, MetricError> {
    same_size(a, b)?;
    const C1: f64 = (0.01 * 255.0) * (0.01 * 255.0);
    const C2: f64 = (0.03 * 255.0) * (0.03 * 255.0);
    let (w, h) = (a.width() as usize, a.height() as usize);
    if w == 0 || h == 0 {
        return Ok(1.0);
    }
    let win_w = w.min(8);
    let win_h = h.min(8);
    let mut total = 0.0;
    let mut count = 0usize;
    let mut y0 = 0;
    loop {
        let mut x0 = 0;
        loop {
            let (mut sa, mut sb, mut saa, mut sbb, mut sab) = (0.0, 0.0, 0.0, 0.0, 0.0);
            for y in y0..y0 + win_h {
                for x in x0..x0 + win_w {
                    let i = y * w + x;
                    let pa = luma(a.color[i]);
                    let pb = luma(b.color[i]);
                    sa += pa;
                    sb += pb;
                    saa += pa * pa;
                    sbb += pb * pb;
                    sab += pa * pb;
                }
            }
            let n = (win_w * win_h) as f64;
            let ma = sa / n;
            let mb = sb / n;
            let va = (saa / n - ma * ma).max(0.0);
            let vb = (sbb / n - mb * mb).max(0.0);
            let cov = sab / n - ma * mb;
            total += ((2.0 * ma * mb + C1) * (2.0 * cov + C2))
                / ((ma * ma + mb * mb + C1) * (va + vb + C2));
            count += 1;
            if x0 + win_w >= w {
                break;
            }
            x0 = (x0 + 4).min(w - win_w);
        }
        if y0 + win_h >= h {
            break;
        }
        y0 = (y0 + 4).min(h - win_h);
    }
    Ok(total / count as f64)
}

/// Depth error over the pixels both frames cover.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthError {
    pub mean_abs: f64,
    pub max_abs: f64,
    /// Pixels covered in both frames (the pixels the statistics are over).
    pub pixels: usize,
}

/// Mean and maximum absolute depth difference over pixels covered in both frames (zero when no
/// pixel is covered in both).
pub fn depth_error(a: &Frame, reference: &Frame) -> Result<DepthError, MetricError> {
    same_size(a, reference)?;
    let mut sum = 0.0f64;
    let mut max = 0.0f64;
    let mut n = 0usize;
    for (&da, &db) in a.depth.iter().zip(&reference.depth) {
        if da.is_finite() && db.is_finite() {
            let d = (da as f64 - db as f64).abs();
            sum += d;
            max = max.max(d);
            n += 1;
        }
    }
    Ok(DepthError {
        mean_abs: if n > 0 { sum / n as f64 } else { 0.0 },
        max_abs: max,
        pixels: n,
    })
}

/// Coverage disagreement between a frame and the reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SilhouetteError {
    /// Pixels covered in exactly one of the two frames.
    pub mismatched_pixels: usize,
    /// Length of the reference outline in pixel edges (covered next to uncovered, image border
    /// not counted).
    pub outline_edges: usize,
    /// `mismatched_pixels / outline_edges`: mean outline displacement in pixels (0 if the
    /// reference has no outline and nothing mismatches; `mismatched_pixels` if it has no outline).
    pub mean_displacement_px: f64,
}

/// Compare coverage (`depth.is_finite()`) of a frame with the reference.
pub fn silhouette_error(a: &Frame, reference: &Frame) -> Result<SilhouetteError, MetricError> {
    same_size(a, reference)?;
    let (w, h) = (reference.width() as usize, reference.height() as usize);
    let mut mismatched = 0usize;
    let mut edges = 0usize;
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let cr = reference.depth[i].is_finite();
            if a.depth[i].is_finite() != cr {
                mismatched += 1;
            }
            if x + 1 < w && reference.depth[i + 1].is_finite() != cr {
                edges += 1;
            }
            if y + 1 < h && reference.depth[i + w].is_finite() != cr {
                edges += 1;
            }
        }
    }
    let mean = if edges > 0 {
        mismatched as f64 / edges as f64
    } else {
        mismatched as f64
    };
    Ok(SilhouetteError {
        mismatched_pixels: mismatched,
        outline_edges: edges,
        mean_displacement_px: mean,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn disc(w: u32, h: u32, cx: f64, cy: f64, r: f64) -> Frame {
        let mut f = Frame::new(w, h, [0, 0, 0, 255]);
        for y in 0..h {
            for x in 0..w {
                let dx = x as f64 + 0.5 - cx;
                let dy = y as f64 + 0.5 - cy;
                if dx * dx + dy * dy <= r * r {
                    let i = f.index(x, y);
                    f.depth[i] = 1.0;
                    f.color[i] = [200, 100, 50, 255];
                }
            }
        }
        f
    }

    #[test]
    fn psnr_of_uniform_error_is_analytic() {
        let a = Frame::new(10, 10, [100, 100, 100, 255]);
        let b = Frame::new(10, 10, [110, 100, 100, 255]);
        // MSE = 100/3 over RGB -> PSNR = 10 log10(255² · 3 / 100).
        let expect = 10.0 * (255.0f64 * 255.0 * 3.0 / 100.0).log10();
        let got = psnr(&a, &b).unwrap();
        assert!((got - expect).abs() < 1e-9, "expected {expect}, got {got}");
        assert_eq!(psnr(&a, &a).unwrap(), f64::INFINITY);
        assert!(psnr(&a, &Frame::new(9, 10, [0; 4])).is_err());
    }

    #[test]
    fn ssim_is_one_for_identical_and_drops_for_noise() {
        let a = disc(64, 48, 30.0, 20.0, 15.0);
        assert!((ssim(&a, &a).unwrap() - 1.0).abs() < 1e-12);
        let mut b = a.clone();
        for (i, c) in b.color.iter_mut().enumerate() {
            c[0] = c[0].wrapping_add(((i * 7919) % 61) as u8);
        }
        let s = ssim(&a, &b).unwrap();
        assert!(s < 0.95 && s > 0.0, "{s}");
        // A constant offset hurts SSIM far less than noise of the same size.
        let c = Frame::new(64, 48, [30, 30, 30, 255]);
        let d = Frame::new(64, 48, [40, 40, 40, 255]);
        assert!(ssim(&c, &d).unwrap() > 0.9);
    }

    #[test]
    fn silhouette_displacement_of_grown_disc_is_its_growth() {
        // A disc of radius 40.5 against one of radius 40: the annulus of area π(40.5² − 40²) over
        // the outline 2π·40 (times the pixel-edge factor up to 4/π) is ≈ 0.5 px · (π/4 .. 1).
        let r = disc(200, 200, 100.0, 100.0, 40.0);
        let a = disc(200, 200, 100.0, 100.0, 40.5);
        let e = silhouette_error(&a, &r).unwrap();
        let m = e.mean_displacement_px;
        assert!(
            m > 0.5 * std::f64::consts::PI / 4.0 * 0.9 && m < 0.5 * 1.1,
            "{e:?}"
        );
        let z = silhouette_error(&r, &r).unwrap();
        assert_eq!(z.mismatched_pixels, 0);
        assert_eq!(z.mean_displacement_px, 0.0);
    }

    #[test]
    fn depth_error_only_counts_pixels_covered_in_both() {
        let r = disc(50, 50, 25.0, 25.0, 10.0);
        let mut a = disc(50, 50, 25.0, 25.0, 12.0);
        for d in a.depth.iter_mut().filter(|d| d.is_finite()) {
            *d += 0.25;
        }
        let e = depth_error(&a, &r).unwrap();
        assert!((e.mean_abs - 0.25).abs() < 1e-9 && (e.max_abs - 0.25).abs() < 1e-9);
        assert_eq!(e.pixels, r.coverage_count());
    }
}

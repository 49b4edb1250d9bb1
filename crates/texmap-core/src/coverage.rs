//! Seed 000 Eq. (5)–(7): which mip level a ground point needs, the bound over every altitude and
//! pitch, the active area each level must cover and the number of geospecific (GST) maps.
//!
//! Geometry (Seed 000 Fig. 1): the eye at altitude `h` looks with pitch `θ` — the angle of the
//! view axis from the nadir — at the ground point `A = (x_a, 0, 0)` in the vertical plane of the
//! view axis; `ε = atan(x_a / h)` is the angle of A from the nadir and `|θ − ε| ≤ ψ/2` keeps A on
//! the screen (ψ the horizontal FOV, which the paper also uses for the vertical direction here).
//! Lengths are in map widths, so a level `l` means `2^l` texels per map width (larger = finer,
//! Seed 000's convention; see [`crate::transform`] for `λ`).
//!
//! - Eq. (5): `r_s = k z⁻¹ r_e`, `r_e = (cosθ x_a − sinθ h, 0, sinθ x_a + cosθ h)ᵗ`.
//! - Eq. (6): `l(x_a, h, θ) = log2( k h / ((x_a² + h²) cos²(θ − ε)) )` — the level from the
//!   ground-range derivative `|∂x_m/∂x_s|` along the pitch direction ([`level_at`]).
//! - Eq. (7): its maximum over `h > 0` and `|θ − ε| ≤ ψ/2` is reached at `h = x_a`,
//!   `|θ − ε| = ψ/2`: `l_max = log2( n_pxl / (2 sin ψ · x_a) )` ([`level_max`]); with
//!   `k = n_pxl / (2 tan(ψ/2))` that is `log2(k / (2 x_a cos²(ψ/2)))`.
//!
//! A GST level `L` holds maps of `T x T` texels (`T` = texels per map) each `2^−L` level-0 map
//! widths wide, i.e. `T·2^L` texels per level-0 map width. Level `L` is the finest one needed
//! wherever `l_max(x_a) ≥ log2(T·2^L)`, so it must cover the active radius
//! `|x_a| ≤ n_pxl / (2 sin ψ · T · 2^L)` level-0 map widths = `n_pxl / (2 sin ψ · T)` of its own maps
//! ([`ActiveArea`]); a square of `2⌈that⌉` maps per side covers it.
//!
//! Worked example (Seed 000 §2): ψ = 45°, 1024 pixels per scanline, 256 x 256 texels per map ->
//! level L covers `|x_a| ≤ 2.83·2^−L`, and levels 0..=8 need `(2·3)²·9 = 324` maps.
//!
//! ```
//! use texmap_core::coverage::ActiveArea;
//! let a = ActiveArea::new(45.0, 1024, 256).unwrap();
//! assert!((a.radius_in_own_maps() - 2.83).abs() < 0.005);
//! assert_eq!(a.map_count(0..=8), 324);
//! ```
//!
//! # References
//! Seed 000 (Kajihara) Eq. (5)–(7) and the worked example of §2; /work/shared/SEEDS.md.

use std::ops::RangeInclusive;

/// Why an active area could not be set up.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum CoverageError {
    /// The field of view is not finite or not strictly between 0° and 180°.
    BadFov { hfov_deg: f64 },
    /// Zero pixels per scanline.
    NoPixels,
    /// Zero texels per map.
    NoTexels,
}

impl std::fmt::Display for CoverageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CoverageError::BadFov { hfov_deg } => write!(
                f,
                "field of view {hfov_deg}° must be strictly between 0° and 180°"
            ),
            CoverageError::NoPixels => write!(f, "pixels per scanline must be positive"),
            CoverageError::NoTexels => write!(f, "texels per map must be positive"),
        }
    }
}

impl std::error::Error for CoverageError {}

/// Seed 000 Eq. (5): the eye-frame vector `r_e` of ground point A (x along the pitch direction,
/// z along the view axis).
pub fn eye_vector(x_a: f64, h: f64, theta: f64) -> [f64; 3] {
    let (s, c) = theta.sin_cos();
    [c * x_a - s * h, 0.0, s * x_a + c * h]
}

/// Seed 000 Eq. (6): the level at ground point `x_a` seen from altitude `h` with pitch `theta`
/// (radians from the nadir) and focal length `k` pixels. `x_a`, `h` in map widths. Returns
/// `+∞` for `h = 0` or `x_a = h = 0` degenerate views and `NaN` never (non-finite input gives
/// `−∞`).
pub fn level_at(x_a: f64, h: f64, theta: f64, k: f64) -> f64 {
    let eps = (x_a / h).atan();
    let c = (theta - eps).cos();
    let l = (k * h / ((x_a * x_a + h * h) * c * c)).log2();
    if l.is_nan() { f64::NEG_INFINITY } else { l }
}

/// Seed 000 Eq. (7): the largest level ground point `x_a` (map widths, > 0) can need over every
/// altitude and pitch, `log2(n_pxl / (2 sin ψ · x_a))`, ψ the horizontal FOV in radians.
pub fn level_max(x_a: f64, n_pxl: u32, hfov_rad: f64) -> f64 {
    (n_pxl as f64 / (2.0 * hfov_rad.sin() * x_a.abs())).log2()
}

/// A display and GST layout: field of view, pixels per scanline, texels per map side.
///
/// # Guarantees
/// `0 < ψ < 180°`, `n_pxl > 0`, `texels_per_map > 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ActiveArea {
    hfov_rad: f64,
    n_pxl: u32,
    texels_per_map: u32,
}

impl ActiveArea {
    /// Validate the layout.
    pub fn new(
        hfov_deg: f64,
        n_pxl: u32,
        texels_per_map: u32,
    ) -> Result<ActiveArea, CoverageError> {
        if !(hfov_deg.is_finite() && hfov_deg > 0.0 && hfov_deg < 180.0) {
            return Err(CoverageError::BadFov { hfov_deg });
        }
        if n_pxl == 0 {
            return Err(CoverageError::NoPixels);
        }
        if texels_per_map == 0 {
            return Err(CoverageError::NoTexels);
        }
        Ok(ActiveArea {
            hfov_rad: hfov_deg.to_radians(),
            n_pxl,
            texels_per_map,
        })
    }

    /// Focal length `k = n_pxl / (2 tan(ψ/2))` in pixels (Seed 000 Eq. 1).
    pub fn k(&self) -> f64 {
        self.n_pxl as f64 / (2.0 * (self.hfov_rad * 0.5).tan())
    }

    /// Eq. (7) at `x_a` (level-0 map widths).
    pub fn level_max(&self, x_a: f64) -> f64 {
        level_max(x_a, self.n_pxl, self.hfov_rad)
    }

    /// The radius level `L` must cover, in its OWN map widths: `n_pxl / (2 sin ψ · T)` (the same
    /// for every level; 2.83 in the worked example).
    pub fn radius_in_own_maps(&self) -> f64 {
        self.n_pxl as f64 / (2.0 * self.hfov_rad.sin() * self.texels_per_map as f64)
    }

    /// The radius level `L` must cover in level-0 map widths: `radius_in_own_maps · 2^−L`, where
    /// Eq. (7) equals `log2(T·2^L)`.
    pub fn radius(&self, level: u32) -> f64 {
        self.radius_in_own_maps() * (-(level as f64)).exp2()
    }

    /// Maps of one level covering the active square `|x|, |y| ≤ radius`:
    /// `(2 ⌈radius_in_own_maps⌉)²` (maps aligned to the level's grid around the eye).
    pub fn maps_per_level(&self) -> u64 {
        let per_side = 2.0 * self.radius_in_own_maps().ceil();
        let per_side = if per_side.is_finite() {
            per_side.min(u32::MAX as f64) as u64
        } else {
            u32::MAX as u64
        };
        per_side.saturating_mul(per_side)
    }

    /// Maps over a range of levels (Seed 000: levels 0..=8 -> 324).
    pub fn map_count(&self, levels: RangeInclusive<u32>) -> u64 {
        let n = (*levels.end() as u64 + 1).saturating_sub(*levels.start() as u64);
        self.maps_per_level().saturating_mul(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eq5_depth_component_is_the_view_axis_distance() {
        // θ = ε: A is on the view axis, so r_e = (0, 0, sqrt(x² + h²)).
        let (x, h) = (3.0, 4.0);
        let r = eye_vector(x, h, (x / h).atan());
        assert!(r[0].abs() < 1e-12 && (r[2] - 5.0).abs() < 1e-12, "{r:?}");
    }

    #[test]
    fn errors_on_bad_layouts() {
        for f in [0.0, 180.0, -3.0, f64::NAN] {
            assert!(matches!(
                ActiveArea::new(f, 10, 10),
                Err(CoverageError::BadFov { .. })
            ));
        }
        assert_eq!(ActiveArea::new(45.0, 0, 10), Err(CoverageError::NoPixels));
        assert_eq!(ActiveArea::new(45.0, 10, 0), Err(CoverageError::NoTexels));
    }
}

//! Seed 000 Eq. (1)–(3): the screen -> map transform of a textured planar face seen from an eye,
//! its analytic screen derivatives, the mip level and the texel addresses.
//!
//! # Frames and conventions
//! The workspace camera ([`crate::camera`]) has x right, y DOWN on the screen, pixel centres at
//! `i + ½` and focal length `k = n_pxl / (2 tan(ψ/2))` (horizontal FOV ψ). Seed 000's screen vector
//! is `r_s = (x_s, y_s, k)ᵗ` with `(x_s, y_s) = (x − w/2, y − h/2)` in pixels; its eye frame e has
//! x right, y down, z forward, so `r_s / k` is the eye-frame direction through the pixel.
//!
//! A [`TexturedFace`] is a plane through `origin` spanned by the world vectors `u_axis`, `v_axis`
//! (any two non-parallel vectors, not necessarily orthogonal or unit), with `map_width` world
//! units per map width: the world point `origin + map_width·(x_m·u_axis + y_m·v_axis)` has map
//! coordinates `r_m = (x_m, y_m)` in map widths — Seed 000's unit. `T_me` (eye -> map, Eq. 1) is
//! `B⁻¹ R_ew / map_width` with `B = [u_axis v_axis n]`, `n = (u_axis × v_axis)/|…|`.
//!
//! # Where this departs from the paper
//! - Inverse depth: we use the true `z⁻¹ = 1/depth` (depth along the view axis), so
//!   Eq. (1) reads `r_m = T_me r_s / (k z⁻¹) + r_meye` and
//!   `z⁻¹ = (T_eb n)ᵗ r_s / (k · n·(origin − r_eye))`; the paper folds `k` and the sign of the
//!   normal (`d_b = −n·origin`, its denominator is `−k·n·(origin − r_eye)`) into its symbols.
//!   The derivatives keep the paper's form: `∂r_m/∂x_s = T_me e1/(k z⁻¹) − T_me r_s (∂z⁻¹/∂x_s)/(k z⁻²)`
//!   and `∂z⁻¹/∂x_s = (T_eb n)_x z⁻¹ / ((T_eb n)ᵗ r_s)`.
//! - Screen y grows downward (the workspace convention), so `∂r_m/∂y_s` is per pixel step down.
//! - Only perspective cameras: Seed 000 is a perspective method; an orthographic camera is refused
//!   with [`TransformError::Orthographic`].
//!
//! # Level: paper `l` and the usual `λ`
//! Eq. (2): `l = −log2(max{|∂x_m/∂x_s|, |∂x_m/∂y_s|, |∂y_m/∂x_s|, |∂y_m/∂y_s|})`, LARGER = FINER:
//! level `L` has `2^L` texels per map width. For a texture of `2^n x 2^n` texels the usual
//! `λ = log2(max |∂(texel coordinate)/∂(screen)|)` (larger = coarser) is exactly
//! `λ = n − l`, because texel coordinates are `2^n r_m` so every derivative is multiplied by `2^n`;
//! paper level `L` is pyramid index `i = n − L` (level 0 = finest, `2^n` texels), and Eq. (4)'s
//! weight `γ = l − ⌊l⌋` of the finer level equals `1 − frac(λ)`. [`MapSample::level`] gives `l`,
//! [`MapSample::lambda`] gives `λ` for a given `n` (fractional for non-power-of-two sides:
//! `n = log2(side)`).
//!
//! ```
//! use texmap_core::camera::Camera;
//! use texmap_core::glam::Vec3;
//! use texmap_core::transform::TexturedFace;
//! // Looking straight down at the ground plane y = 0 from 10 units up, 90° FOV, 100 px wide.
//! let cam = Camera::perspective_look_at(Vec3::new(0.0, 10.0, 0.0), Vec3::ZERO, Vec3::NEG_Z, 90.0, 100, 100)
//!     .unwrap();
//! let face = TexturedFace::new(Vec3::ZERO, Vec3::X, Vec3::Z, 1.0, &cam).unwrap();
//! let s = face.map(50.0, 50.0).unwrap(); // the image centre sees the origin
//! assert!(s.uv.length() < 1e-5);
//! // 20 world units span 100 pixels: 0.2 map widths per pixel, so l = −log2(0.2).
//! assert!((s.duv_dx.x - 0.2).abs() < 1e-5);
//! assert!((s.level() + 0.2f32.log2()).abs() < 1e-4);
//! ```
//!
//! # References
//! Seed 000 (Kajihara) Eq. (1)–(4); /work/shared/SEEDS.md.

use glam::{DMat3, I64Vec2, Mat3, Vec2, Vec3};

use crate::camera::{Camera, Projection};

/// The level returned when the derivatives are degenerate or infinite: `l` is clamped to
/// `[-LEVEL_LIMIT, LEVEL_LIMIT]` so it stays finite.
pub const LEVEL_LIMIT: f32 = 64.0;

/// Why a face could not be set up.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum TransformError {
    /// Origin, axes or map width are not finite.
    NonFinite,
    /// An axis is zero or the two axes are (nearly) parallel: no plane.
    DegenerateAxes,
    /// The map width is not positive.
    BadMapWidth { map_width: f32 },
    /// The eye lies in the face's plane: every pixel sees the face edge-on.
    EdgeOn { eye_distance: f32 },
    /// The camera is orthographic; Seed 000's transform is perspective.
    Orthographic,
}

impl std::fmt::Display for TransformError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TransformError::NonFinite => {
                write!(f, "face origin, axes and map width must be finite")
            }
            TransformError::DegenerateAxes => {
                write!(f, "face axes are zero or parallel: they span no plane")
            }
            TransformError::BadMapWidth { map_width } => {
                write!(f, "map width {map_width} must be positive")
            }
            TransformError::EdgeOn { eye_distance } => write!(
                f,
                "the eye is {eye_distance} from the face plane: the face is seen edge-on"
            ),
            TransformError::Orthographic => {
                write!(f, "the Seed 000 transform needs a perspective camera")
            }
        }
    }
}

impl std::error::Error for TransformError {}

/// The map image of one screen point (Eq. 1) with its screen derivatives (Eq. 2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapSample {
    /// `r_m = (x_m, y_m)` in map widths.
    pub uv: Vec2,
    /// `∂r_m/∂x_s` per pixel to the right.
    pub duv_dx: Vec2,
    /// `∂r_m/∂y_s` per pixel down.
    pub duv_dy: Vec2,
    /// `z⁻¹ = 1/depth`, depth along the view axis.
    pub inv_depth: f32,
}

/// Seed 000 Eq. (3) texel addresses and Eq. (4) weights for one sample at level `l`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexelAddress {
    /// `L = ⌊l⌋` (paper convention, `2^L` texels per map width).
    pub level: i32,
    /// `a_c = ⌊2^L r_m⌋`.
    pub a_c: I64Vec2,
    /// `a_f = ⌊2^(L+1) r_m⌋`.
    pub a_f: I64Vec2,
    /// `(α_c, β_c) = frac(2^L r_m)`.
    pub w_c: Vec2,
    /// `(α_f, β_f) = frac(2^(L+1) r_m)`.
    pub w_f: Vec2,
    /// `γ = l − ⌊l⌋`, the weight of the finer level.
    pub gamma: f32,
}

impl MapSample {
    /// Seed 000 Eq. (2): `l = −log2(max |∂r_m/∂(x_s, y_s)|)`, larger = finer, clamped to
    /// `±LEVEL_LIMIT` (finite for any input).
    pub fn level(&self) -> f32 {
        let m = self.duv_dx.abs().max(self.duv_dy.abs()).max_element();
        if m > 0.0 {
            (-m.log2()).clamp(-LEVEL_LIMIT, LEVEL_LIMIT)
        } else {
            LEVEL_LIMIT
        }
    }

    /// The usual `λ = size_log2 − l` (larger = coarser) for a map with `2^size_log2` texels per
    /// side (see the module doc).
    pub fn lambda(&self, size_log2: f32) -> f32 {
        size_log2 - self.level()
    }

    /// Seed 000 Eq. (3): texel addresses at levels `⌊l⌋` and `⌊l⌋ + 1`, as the paper writes them
    /// (no half-texel offset; [`crate::sample`] applies them to `2^L r_m − ½`). Computed in f64.
    pub fn texel_address(&self) -> TexelAddress {
        let l = self.level();
        let big_l = l.floor();
        let c = (big_l as f64).exp2();
        let f = 2.0 * c;
        let (xc, yc) = (self.uv.x as f64 * c, self.uv.y as f64 * c);
        let (xf, yf) = (self.uv.x as f64 * f, self.uv.y as f64 * f);
        TexelAddress {
            level: big_l as i32,
            a_c: I64Vec2::new(xc.floor() as i64, yc.floor() as i64),
            a_f: I64Vec2::new(xf.floor() as i64, yf.floor() as i64),
            w_c: Vec2::new((xc - xc.floor()) as f32, (yc - yc.floor()) as f32),
            w_f: Vec2::new((xf - xf.floor()) as f32, (yf - yf.floor()) as f32),
            gamma: l - big_l,
        }
    }
}

/// A textured planar face seen by a perspective camera: Seed 000 Eq. (1)–(3) precomputed.
///
/// A NaN eye or a field of view of 0° or 180° cannot reach this type: [`Camera`] refuses them
/// (`CameraError::NonFinite`, `CameraError::BadFov`). A face seen edge-on (eye in its plane) is
/// [`TransformError::EdgeOn`]; a face seen at a grazing angle is accepted and its pixels near the
/// horizon return `None` from [`TexturedFace::map`].
///
/// # Guarantees
/// Built only from finite data with non-parallel axes, a positive map width, a perspective camera
/// and an eye off the plane; every stored coefficient is finite. [`TexturedFace::map`] returns
/// `None` (never NaN) where the pixel's ray misses the face (behind the eye or past the horizon).
#[derive(Clone, Debug, PartialEq)]
pub struct TexturedFace {
    /// `T_me / k`, rows 0 and 1 (the map's x and y), as a 3x3 whose third row is the normal part.
    m: Mat3,
    /// `r_meye`: the eye in map coordinates (map widths; z is the height above the plane).
    eye_map: Vec3,
    /// `T_eb n`: the face normal in the paper's eye frame (x right, y down, z forward).
    n_eye: Vec3,
    /// `k · n·(origin − r_eye)`.
    kc: f32,
    k: f32,
    cx: f32,
    cy: f32,
}

impl TexturedFace {
    /// The face through `origin` spanned by `u_axis`, `v_axis` (world), `map_width` world units per
    /// map width, seen by `camera`.
    // `!(a > b)` on purpose: NaN must take the fallback branch.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    pub fn new(
        origin: Vec3,
        u_axis: Vec3,
        v_axis: Vec3,
        map_width: f32,
        camera: &Camera,
    ) -> Result<TexturedFace, TransformError> {
        if !(origin.is_finite()
            && u_axis.is_finite()
            && v_axis.is_finite()
            && map_width.is_finite())
        {
            return Err(TransformError::NonFinite);
        }
        if map_width <= 0.0 {
            return Err(TransformError::BadMapWidth { map_width });
        }
        if let Projection::Orthographic { .. } = camera.projection() {
            return Err(TransformError::Orthographic);
        }
        // Build in f64: B = [u v n], n the unit normal.
        let (u, v) = (u_axis.as_dvec3(), v_axis.as_dvec3());
        let cross = u.cross(v);
        let cl = cross.length();
        if !(cl > 1e-6 * u.length() * v.length()) {
            return Err(TransformError::DegenerateAxes);
        }
        let n = cross / cl;
        let b = DMat3::from_cols(u, v, n);
        let b_inv = b.inverse() / map_width as f64;
        // R_ew: paper eye frame (x right, y down, z forward) -> world.
        let r_ew = DMat3::from_cols(
            camera.right().as_dvec3(),
            -camera.up().as_dvec3(),
            camera.forward().as_dvec3(),
        );
        let k = camera.scale() as f64;
        let eye = camera.eye().as_dvec3();
        let o = origin.as_dvec3();
        // Seed 000 Eq. (1): T_me = T_mb T_bw T_ew⁻¹ (here B⁻¹ R_ew / map_width) and r_meye.
        let t_me = b_inv * r_ew;
        let eye_map = b_inv * (eye - o);
        // Signed distance of the plane from the eye along n.
        let c = n.dot(o - eye);
        let eye_distance = c.abs() as f32;
        if !(c.abs() > 1e-9 * (1.0 + o.length().max(eye.length()))) || eye_distance == 0.0 {
            return Err(TransformError::EdgeOn { eye_distance });
        }
        let n_eye = r_ew.transpose() * n;
        let m = (t_me / k).as_mat3();
        let face = TexturedFace {
            m,
            eye_map: eye_map.as_vec3(),
            n_eye: n_eye.as_vec3(),
            kc: (k * c) as f32,
            k: k as f32,
            cx: camera.width() as f32 * 0.5,
            cy: camera.height() as f32 * 0.5,
        };
        let ok = face.m.is_finite()
            && face.eye_map.is_finite()
            && face.n_eye.is_finite()
            && face.kc.is_finite()
            && face.kc != 0.0;
        if !ok {
            return Err(TransformError::NonFinite);
        }
        Ok(face)
    }

    /// `r_meye`, the eye in map coordinates (map widths); z is its height above the plane along the
    /// unit normal, in map widths.
    pub fn eye_in_map(&self) -> Vec3 {
        self.eye_map
    }

    /// Seed 000's `z⁻¹` at screen point `(x, y)` (pixels): `(T_eb n)ᵗ r_s / (k c)`; positive where
    /// the ray meets the face in front of the eye.
    #[inline]
    pub fn inv_depth(&self, x: f32, y: f32) -> f32 {
        let rs = Vec3::new(x - self.cx, y - self.cy, self.k);
        self.n_eye.dot(rs) / self.kc
    }

    /// Seed 000 Eq. (1) and (2) at screen point `(x, y)` in pixels (use `i + 0.5` for pixel
    /// centres): the map point, its screen derivatives and `z⁻¹`. `None` where the ray misses the
    /// face (`z⁻¹ ≤ 0`) or the result is not finite (at the horizon).
    #[inline]
    // `!(a > b)` on purpose: NaN must take the fallback branch.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    pub fn map(&self, x: f32, y: f32) -> Option<MapSample> {
        let rs = Vec3::new(x - self.cx, y - self.cy, self.k);
        // z⁻¹ = (T_eb n)ᵗ r_s / (k c).
        let zi = self.n_eye.dot(rs) / self.kc;
        if !(zi > 0.0) {
            return None;
        }
        // (T_me/k) r_s: the map-space direction of the pixel ray.
        let a = self.m * rs;
        let inv = 1.0 / zi;
        // Eq. (1): r_m = T_me r_s / (k z⁻¹) + r_meye.
        let uv = Vec2::new(a.x * inv + self.eye_map.x, a.y * inv + self.eye_map.y);
        // Eq. (2): ∂z⁻¹/∂(x_s, y_s) = (T_eb n)_(x,y) / (k c).
        let dzx = self.n_eye.x / self.kc;
        let dzy = self.n_eye.y / self.kc;
        // ∂r_m/∂x_s = T_me e1/(k z⁻¹) − T_me r_s (∂z⁻¹/∂x_s)/(k z⁻²), same for y with e2.
        let inv2 = inv * inv;
        let duv_dx = Vec2::new(
            self.m.x_axis.x * inv - a.x * dzx * inv2,
            self.m.x_axis.y * inv - a.y * dzx * inv2,
        );
        let duv_dy = Vec2::new(
            self.m.y_axis.x * inv - a.x * dzy * inv2,
            self.m.y_axis.y * inv - a.y * dzy * inv2,
        );
        let s = MapSample {
            uv,
            duv_dx,
            duv_dy,
            inv_depth: zi,
        };
        (s.uv.is_finite() && s.duv_dx.is_finite() && s.duv_dy.is_finite()).then_some(s)
    }

    /// Seed 000 Eq. (8): the four pixel images of the 2x2 span centred at `(x, y)` (pixels at
    /// `(x ± ½, y ± ½)`), in the quad order `[(−,−), (+,−), (−,+), (+,+)]` that
    /// [`crate::sample::Sampler::sample_quad`] takes. `z⁻¹` is affine in the screen, so
    /// `z⁻¹(u, v) = z⁻¹_spn + ∂z⁻¹/∂x_s·u + ∂z⁻¹/∂y_s·v` exactly. `None` if any pixel misses the face.
    pub fn map_span(&self, x: f32, y: f32) -> Option<[Vec2; 4]> {
        let p = |dx: f32, dy: f32| self.map(x + dx, y + dy).map(|s| s.uv);
        Some([p(-0.5, -0.5)?, p(0.5, -0.5)?, p(-0.5, 0.5)?, p(0.5, 0.5)?])
    }
}

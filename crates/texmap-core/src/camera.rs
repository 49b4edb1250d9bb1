//! Cameras shared by every renderer of the workspace.
//!
//! Conventions (ARCHITECTURE.md, "Shared conventions"):
//! - right-handed world; in eye space the camera sits at the origin and looks down −z, +y is up,
//!   +x is right;
//! - the field of view is the HORIZONTAL angle ψ, as in Seed 000: the focal length in pixels is
//!   `k = width / (2 tan(ψ/2))` (Seed 000 Eq. 1), pixels are square;
//! - pixel (i, j) has its centre at (i + 0.5, j + 0.5); row 0 is the top of the image, so screen y
//!   grows downward;
//! - depth is the eye-space distance along the view axis, `−z_eye` (positive in front).
//!
//! An orthographic camera is described by the width of its view in world units; its "focal
//! length" is then a fixed scale in pixels per world unit.

use glam::{Mat3, Vec2, Vec3};

/// The largest image side accepted, in pixels: big enough for any poster, small enough that a
/// colour + depth frame (8 bytes a pixel) stays under 2 GiB.
pub const MAX_IMAGE_SIDE: u32 = 16384;

/// How the camera projects eye space onto the image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Pinhole perspective with a horizontal field of view in degrees, in the open interval (0, 180).
    Perspective { hfov_deg: f32 },
    /// Parallel projection; `view_width` world units span the image horizontally.
    Orthographic { view_width: f32 },
}

/// Why a camera could not be built.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum CameraError {
    /// Width or height is zero or larger than [`MAX_IMAGE_SIDE`].
    BadSize { width: u32, height: u32 },
    /// The horizontal field of view is not finite or not strictly between 0° and 180°.
    BadFov { hfov_deg: f32 },
    /// The orthographic view width is not finite and positive.
    BadViewWidth { view_width: f32 },
    /// Eye, target or up vector is not finite.
    NonFinite,
    /// The eye and the target coincide, so there is no view direction.
    EyeAtTarget,
    /// The up vector is zero or parallel to the view direction.
    DegenerateUp,
    /// The near plane is not finite and positive, or not in front of the far plane.
    BadClip { near: f32, far: f32 },
}

impl std::fmt::Display for CameraError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CameraError::BadSize { width, height } => write!(
                f,
                "image size {width}x{height} is not allowed (each side must be 1..={MAX_IMAGE_SIDE})"
            ),
            CameraError::BadFov { hfov_deg } => write!(
                f,
                "horizontal field of view {hfov_deg}° must be strictly between 0° and 180°"
            ),
            CameraError::BadViewWidth { view_width } => write!(
                f,
                "orthographic view width {view_width} must be finite and positive"
            ),
            CameraError::NonFinite => write!(f, "eye, target and up must be finite"),
            CameraError::EyeAtTarget => write!(f, "eye and target coincide: no view direction"),
            CameraError::DegenerateUp => {
                write!(f, "up vector is zero or parallel to the view direction")
            }
            CameraError::BadClip { near, far } => {
                write!(f, "clip planes near={near}, far={far}: need 0 < near < far")
            }
        }
    }
}

impl std::error::Error for CameraError {}

fn check_size(width: u32, height: u32) -> Result<(), CameraError> {
    if width == 0 || height == 0 || width > MAX_IMAGE_SIDE || height > MAX_IMAGE_SIDE {
        return Err(CameraError::BadSize { width, height });
    }
    Ok(())
}

/// A world-space ray: `origin + t·dir`, `dir` of unit length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
}

impl Ray {
    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// A camera: pose, projection and image size. Build it with [`Camera::perspective_look_at`] or
/// [`Camera::orthographic_look_at`].
///
/// # Guarantees
/// The basis is orthonormal and right-handed, every field is finite, width and height are in
/// `1..=MAX_IMAGE_SIDE`, and `0 < near < far`.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    eye: Vec3,
    /// Rows are the eye-space axes expressed in world space: right (x), up (y), back (z = −forward).
    right: Vec3,
    up: Vec3,
    back: Vec3,
    projection: Projection,
    width: u32,
    height: u32,
    /// Perspective: focal length k in pixels. Orthographic: pixels per world unit.
    scale: f32,
    near: f32,
    far: f32,
}

impl Camera {
    /// A perspective camera at `eye` looking at `target`, `up` giving the image's up direction,
    /// with horizontal field of view `hfov_deg` degrees and an image of `width` x `height` pixels.
    ///
    /// The near plane defaults to 1e-4 of the eye–target distance and the far plane to infinity;
    /// change them with [`Camera::with_clip`].
    pub fn perspective_look_at(
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        hfov_deg: f32,
        width: u32,
        height: u32,
    ) -> Result<Camera, CameraError> {
        check_size(width, height)?;
        if !(hfov_deg.is_finite() && hfov_deg > 0.0 && hfov_deg < 180.0) {
            return Err(CameraError::BadFov { hfov_deg });
        }
        // Seed 000 Eq. (1): k = n_pxl / (2 tan(ψ_FOV / 2)).
        let k = width as f32 / (2.0 * (hfov_deg.to_radians() * 0.5).tan());
        if !(k.is_finite() && k > 0.0) {
            return Err(CameraError::BadFov { hfov_deg });
        }
        Self::build(
            eye,
            target,
            up,
            Projection::Perspective { hfov_deg },
            width,
            height,
            k,
        )
    }

    /// An orthographic camera at `eye` looking at `target`; `view_width` world units span the
    /// image width. The eye position still matters: depth is measured from it, and the near plane
    /// (default 1e-4 of the eye–target distance) clips what lies behind it.
    pub fn orthographic_look_at(
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        view_width: f32,
        width: u32,
        height: u32,
    ) -> Result<Camera, CameraError> {
        check_size(width, height)?;
        if !(view_width.is_finite() && view_width > 0.0) {
            return Err(CameraError::BadViewWidth { view_width });
        }
        let s = width as f32 / view_width;
        if !(s.is_finite() && s > 0.0) {
            return Err(CameraError::BadViewWidth { view_width });
        }
        Self::build(
            eye,
            target,
            up,
            Projection::Orthographic { view_width },
            width,
            height,
            s,
        )
    }

    fn build(
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        projection: Projection,
        width: u32,
        height: u32,
        scale: f32,
    ) -> Result<Camera, CameraError> {
        if !(eye.is_finite() && target.is_finite() && up.is_finite()) {
            return Err(CameraError::NonFinite);
        }
        let to_target = target - eye;
        let dist = to_target.length();
        if !(dist > 0.0 && dist.is_finite()) {
            return Err(CameraError::EyeAtTarget);
        }
        let forward = to_target / dist;
        let right = forward.cross(up);
        let rl = right.length();
        // Reject an up vector within ~0.06° of the view axis: the basis would be noise. The
        // negated comparison is deliberate: it also rejects NaN.
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(rl > 1e-6 * up.length()) || rl == 0.0 {
            return Err(CameraError::DegenerateUp);
        }
        let right = right / rl;
        let up = right.cross(forward);
        Ok(Camera {
            eye,
            right,
            up,
            back: -forward,
            projection,
            width,
            height,
            scale,
            near: (dist * 1e-4).max(f32::MIN_POSITIVE),
            far: f32::INFINITY,
        })
    }

    /// A camera that frames a bounding sphere (`center`, `radius`) seen along `view_dir`:
    /// perspective with horizontal field of view `hfov_deg`, or orthographic when `hfov_deg` is
    /// `None`. The sphere fills the smaller image side up to `margin` (1.0 = touching; 1.1 leaves
    /// 10 % space). Used by the command line's automatic camera.
    #[allow(clippy::too_many_arguments)]
    pub fn fit_sphere(
        center: Vec3,
        radius: f32,
        view_dir: Vec3,
        up: Vec3,
        hfov_deg: Option<f32>,
        width: u32,
        height: u32,
        margin: f32,
    ) -> Result<Camera, CameraError> {
        check_size(width, height)?;
        if !(center.is_finite() && view_dir.is_finite() && radius.is_finite() && margin.is_finite())
        {
            return Err(CameraError::NonFinite);
        }
        let radius = radius.max(1e-6) * margin.max(1e-3);
        let dir = view_dir.normalize_or_zero();
        if dir == Vec3::ZERO {
            return Err(CameraError::EyeAtTarget);
        }
        let aspect = height as f32 / width as f32;
        match hfov_deg {
            Some(hfov) => {
                if !(hfov.is_finite() && hfov > 0.0 && hfov < 180.0) {
                    return Err(CameraError::BadFov { hfov_deg: hfov });
                }
                // Half-angle of the narrower image side; the sphere's tangent cone must fit in it.
                let half_h = (hfov.to_radians() * 0.5).tan();
                let half = half_h.min(half_h * aspect).atan();
                let dist = radius / half.sin();
                Camera::perspective_look_at(center - dir * dist, center, up, hfov, width, height)
            }
            None => {
                let view_width = 2.0 * radius * (1.0f32).max(1.0 / aspect);
                let cam = Camera::orthographic_look_at(
                    center - dir * (2.0 * radius),
                    center,
                    up,
                    view_width,
                    width,
                    height,
                )?;
                let near = radius * 1e-3;
                cam.with_clip(near, f32::INFINITY)
            }
        }
    }

    /// The same camera with other clip distances (eye-space depths). `far` may be infinite.
    pub fn with_clip(mut self, near: f32, far: f32) -> Result<Camera, CameraError> {
        if !(near.is_finite() && near > 0.0 && far > near) {
            return Err(CameraError::BadClip { near, far });
        }
        self.near = near;
        self.far = far;
        Ok(self)
    }

    /// The same camera with another image size, keeping the horizontal field of view (or view
    /// width) and the pose.
    pub fn with_size(&self, width: u32, height: u32) -> Result<Camera, CameraError> {
        let mut c = match self.projection {
            Projection::Perspective { hfov_deg } => Camera::perspective_look_at(
                self.eye,
                self.eye - self.back,
                self.up,
                hfov_deg,
                width,
                height,
            )?,
            Projection::Orthographic { view_width } => Camera::orthographic_look_at(
                self.eye,
                self.eye - self.back,
                self.up,
                view_width,
                width,
                height,
            )?,
        };
        c.near = self.near;
        c.far = self.far;
        Ok(c)
    }

    #[inline]
    pub fn width(&self) -> u32 {
        self.width
    }
    #[inline]
    pub fn height(&self) -> u32 {
        self.height
    }
    #[inline]
    pub fn eye(&self) -> Vec3 {
        self.eye
    }
    /// Unit view direction in world space.
    #[inline]
    pub fn forward(&self) -> Vec3 {
        -self.back
    }
    /// Unit image-right direction in world space.
    #[inline]
    pub fn right(&self) -> Vec3 {
        self.right
    }
    /// Unit image-up direction in world space.
    #[inline]
    pub fn up(&self) -> Vec3 {
        self.up
    }
    #[inline]
    pub fn projection(&self) -> Projection {
        self.projection
    }
    #[inline]
    pub fn is_orthographic(&self) -> bool {
        matches!(self.projection, Projection::Orthographic { .. })
    }
    /// Perspective: the focal length k in pixels (Seed 000 Eq. 1). Orthographic: pixels per world
    /// unit.
    #[inline]
    pub fn scale(&self) -> f32 {
        self.scale
    }
    #[inline]
    pub fn near(&self) -> f32 {
        self.near
    }
    #[inline]
    pub fn far(&self) -> f32 {
        self.far
    }

    /// The rotation from world to eye space (its rows are right, up, back).
    #[inline]
    pub fn world_to_eye_rotation(&self) -> Mat3 {
        Mat3::from_cols(self.right, self.up, self.back).transpose()
    }

    /// A world point in eye space (camera at the origin looking down −z).
    #[inline]
    pub fn world_to_eye(&self, p: Vec3) -> Vec3 {
        let d = p - self.eye;
        Vec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.back))
    }

    /// A world direction in eye space.
    #[inline]
    pub fn dir_to_eye(&self, d: Vec3) -> Vec3 {
        Vec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.back))
    }

    /// An eye-space direction in world space.
    #[inline]
    pub fn dir_to_world(&self, d: Vec3) -> Vec3 {
        self.right * d.x + self.up * d.y + self.back * d.z
    }

    /// An eye-space point on the screen, in pixels (x right, y down, pixel centres at +0.5).
    /// Returns `None` for a perspective point not strictly in front of the eye.
    #[inline]
    pub fn eye_to_screen(&self, pe: Vec3) -> Option<Vec2> {
        let cx = self.width as f32 * 0.5;
        let cy = self.height as f32 * 0.5;
        match self.projection {
            Projection::Perspective { .. } => {
                let depth = -pe.z;
                if depth > 0.0 {
                    let s = self.scale / depth;
                    Some(Vec2::new(cx + pe.x * s, cy - pe.y * s))
                } else {
                    None
                }
            }
            Projection::Orthographic { .. } => {
                Some(Vec2::new(cx + pe.x * self.scale, cy - pe.y * self.scale))
            }
        }
    }

    /// A world point's screen position (pixels) and depth (eye-space distance along the view
    /// axis). `None` when a perspective point is not in front of the eye.
    #[inline]
    pub fn project(&self, p: Vec3) -> Option<(Vec2, f32)> {
        let pe = self.world_to_eye(p);
        self.eye_to_screen(pe).map(|s| (s, -pe.z))
    }

    /// Whether the sphere of `radius` around world point `center` lies wholly outside the view:
    /// behind the eye's plane, or beyond one side of the image (perspective: the pyramid's side
    /// planes through the eye; orthographic: the box's sides). Culling may skip such a sphere.
    /// One only beyond the near or far plane is not reported: the clip planes remove it.
    pub fn sphere_outside_view(&self, center: Vec3, radius: f32) -> bool {
        let pe = self.world_to_eye(center);
        if pe.z > radius {
            return true;
        }
        let (w, h) = (self.width as f32 * 0.5, self.height as f32 * 0.5);
        match self.projection {
            Projection::Perspective { .. } => {
                let k = self.scale;
                // Outward normals of the right, left, top and bottom planes through the eye.
                [
                    Vec3::new(k, 0.0, w),
                    Vec3::new(-k, 0.0, w),
                    Vec3::new(0.0, k, h),
                    Vec3::new(0.0, -k, h),
                ]
                .iter()
                .any(|n| n.dot(pe) > radius * n.length())
            }
            Projection::Orthographic { .. } => {
                let (hx, hy) = (w / self.scale, h / self.scale);
                pe.x - radius > hx
                    || -pe.x - radius > hx
                    || pe.y - radius > hy
                    || -pe.y - radius > hy
            }
        }
    }

    /// The world ray through screen position `(x, y)` in pixels (use `i + 0.5, j + 0.5` for the
    /// centre of pixel (i, j)). Perspective rays start at the eye; orthographic rays start on the
    /// plane through the eye perpendicular to the view direction. The ray parameter `t` equals
    /// the depth for orthographic rays; for perspective rays depth = `t · (dir · forward)`.
    #[inline]
    pub fn ray(&self, x: f32, y: f32) -> Ray {
        let dx = x - self.width as f32 * 0.5;
        let dy = self.height as f32 * 0.5 - y;
        match self.projection {
            Projection::Perspective { .. } => {
                let d = self.right * dx + self.up * dy - self.back * self.scale;
                Ray {
                    origin: self.eye,
                    dir: d.normalize(),
                }
            }
            Projection::Orthographic { .. } => Ray {
                origin: self.eye + (self.right * dx + self.up * dy) / self.scale,
                dir: -self.back,
            },
        }
    }

    /// The eye-space ray direction (not normalised, z = −1 for perspective) through screen
    /// position `(x, y)`: `((x − w/2)/k, (h/2 − y)/k, −1)`. For orthographic cameras it is
    /// `(0, 0, −1)`.
    #[inline]
    pub fn eye_ray_dir(&self, x: f32, y: f32) -> Vec3 {
        match self.projection {
            Projection::Perspective { .. } => Vec3::new(
                (x - self.width as f32 * 0.5) / self.scale,
                (self.height as f32 * 0.5 - y) / self.scale,
                -1.0,
            ),
            Projection::Orthographic { .. } => Vec3::NEG_Z,
        }
    }

    /// The unit vector from a world point toward the eye (for orthographic cameras, the constant
    /// direction opposite to the view).
    #[inline]
    pub fn to_eye_dir(&self, p: Vec3) -> Vec3 {
        if self.is_orthographic() {
            self.back
        } else {
            (self.eye - p).normalize_or(self.back)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spheres_outside_the_view_are_told() {
        // 90° across 200 px: the side planes are x = ±depth (and y = ±depth/2 for 100 px).
        let cam =
            Camera::perspective_look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 90.0, 200, 100).unwrap();
        let out = |x: f32, y: f32, z: f32, r: f32| cam.sphere_outside_view(Vec3::new(x, y, z), r);
        assert!(!out(0.0, 0.0, -10.0, 1.0));
        // Beside the right edge: 1.5 from the plane x = 10 (distance 1.5 / √2 ≈ 1.06).
        assert!(out(11.5, 0.0, -10.0, 1.0));
        assert!(!out(11.5, 0.0, -10.0, 1.1));
        assert!(out(0.0, -6.5, -10.0, 1.0) && !out(0.0, -5.5, -10.0, 1.0));
        // Behind the eye; reaching across its plane.
        assert!(out(0.0, 0.0, 2.0, 1.0) && !out(0.0, 0.0, 0.5, 1.0));
        let ortho =
            Camera::orthographic_look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 20.0, 200, 100).unwrap();
        let out = |x: f32, r: f32| ortho.sphere_outside_view(Vec3::new(x, 0.0, -5.0), r);
        assert!(out(11.5, 1.0) && !out(10.5, 1.0) && !out(-10.5, 1.0) && out(-11.5, 1.0));
    }

    fn cam() -> Camera {
        Camera::perspective_look_at(
            Vec3::new(1.0, 2.0, 10.0),
            Vec3::new(0.5, -1.0, 0.0),
            Vec3::Y,
            50.0,
            800,
            600,
        )
        .unwrap()
    }

    #[test]
    fn focal_length_matches_seed000_eq1() {
        // k = n / (2 tan(ψ/2)); for ψ = 90° and n = 1000, k = 500 exactly (tan 45° = 1).
        let c = Camera::perspective_look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 90.0, 1000, 10).unwrap();
        assert!((c.scale() - 500.0).abs() < 1e-3, "k = {}", c.scale());
        // A point at 45° to the right lands on the right image edge.
        let (s, d) = c.project(Vec3::new(1.0, 0.0, 0.0)).unwrap();
        assert!(
            (s.x - 1000.0).abs() < 1e-3 && (d - 1.0).abs() < 1e-6,
            "{s:?} {d}"
        );
    }

    #[test]
    fn ray_through_projection_round_trips() {
        let c = cam();
        for &(x, y) in &[(0.5, 0.5), (400.0, 300.0), (799.5, 10.25), (123.0, 599.5)] {
            let r = c.ray(x, y);
            let p = r.at(7.5);
            let (s, depth) = c.project(p).unwrap();
            assert!(
                (s.x - x).abs() < 2e-3 && (s.y - y).abs() < 2e-3,
                "({x},{y}) -> {s:?}"
            );
            let expect_depth = 7.5 * r.dir.dot(c.forward());
            assert!((depth - expect_depth).abs() < 1e-4);
        }
    }

    #[test]
    fn orthographic_rays_are_parallel_and_t_is_depth() {
        let c = Camera::orthographic_look_at(
            Vec3::new(0.0, 0.0, 5.0),
            Vec3::ZERO,
            Vec3::Y,
            4.0,
            400,
            200,
        )
        .unwrap();
        assert!((c.scale() - 100.0).abs() < 1e-4);
        let r = c.ray(0.0, 0.0);
        assert!((r.origin - Vec3::new(-2.0, 1.0, 5.0)).length() < 1e-5);
        assert_eq!(r.dir, Vec3::NEG_Z);
        let (s, d) = c.project(r.at(3.0)).unwrap();
        assert!(s.length() < 1e-4 && (d - 3.0).abs() < 1e-6);
    }

    #[test]
    fn basis_is_orthonormal_and_right_handed() {
        let c = cam();
        let (r, u, b) = (c.right(), c.up(), -c.forward());
        assert!((r.cross(u) - b).length() < 1e-6);
        assert!(r.dot(u).abs() < 1e-6 && (r.length() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn fitted_sphere_touches_the_narrow_side() {
        // A unit sphere framed in a 200x100 image at 90° horizontal FOV with margin 1: its
        // tangent cone must touch the top and bottom edges (the narrower side).
        let c = Camera::fit_sphere(
            Vec3::ZERO,
            1.0,
            -Vec3::Z,
            Vec3::Y,
            Some(90.0),
            200,
            100,
            1.0,
        )
        .unwrap();
        let half_v = (0.5f64).atan(); // tan(half_v) = (h/2)/k = 50/100
        let dist = 1.0 / half_v.sin();
        assert!((c.eye().z as f64 - dist).abs() < 1e-4, "eye {}", c.eye());
        let o = Camera::fit_sphere(Vec3::ONE, 2.0, Vec3::X, Vec3::Y, None, 100, 200, 1.0).unwrap();
        assert!(o.is_orthographic());
        // Orthographic: the narrower side (width, 100 px) spans exactly the diameter 4.
        assert!((o.scale() - 25.0).abs() < 1e-4, "{}", o.scale());
    }

    #[test]
    fn bad_parameters_are_errors_not_panics() {
        let e = Vec3::Z;
        let t = Vec3::ZERO;
        for fov in [0.0, 180.0, -5.0, f32::NAN, f32::INFINITY] {
            assert!(matches!(
                Camera::perspective_look_at(e, t, Vec3::Y, fov, 10, 10),
                Err(CameraError::BadFov { .. })
            ));
        }
        assert_eq!(
            Camera::perspective_look_at(e, e, Vec3::Y, 60.0, 10, 10),
            Err(CameraError::EyeAtTarget)
        );
        assert_eq!(
            Camera::perspective_look_at(e, t, Vec3::Z, 60.0, 10, 10),
            Err(CameraError::DegenerateUp)
        );
        assert_eq!(
            Camera::perspective_look_at(Vec3::NAN, t, Vec3::Y, 60.0, 10, 10),
            Err(CameraError::NonFinite)
        );
        assert!(matches!(
            Camera::perspective_look_at(e, t, Vec3::Y, 60.0, 0, 10),
            Err(CameraError::BadSize { .. })
        ));
        assert!(matches!(
            Camera::orthographic_look_at(e, t, Vec3::Y, 0.0, 10, 10),
            Err(CameraError::BadViewWidth { .. })
        ));
        let c = Camera::perspective_look_at(e, t, Vec3::Y, 60.0, 10, 10).unwrap();
        assert!(c.clone().with_clip(0.0, 1.0).is_err());
        assert!(c.with_clip(1.0, 0.5).is_err());
    }
}

//! Camera paths for movies: a pose that orbits its target, and keyframes interpolated smoothly.
//!
//! A [`Pose`] is where a camera stands (`eye`), what it looks at (`target`), which way is up
//! and, for a perspective camera, its horizontal field of view. [`Pose::camera`] turns it into a
//! [`Camera`] with the projection, image size and (orthographic) clip distances of a template
//! camera, so a path changes only the pose of the camera a render was set up with.
//!
//! - **Orbit.** [`Pose::orbit`] turns the eye about the axis through the target along `up`
//!   (right-handed: positive degrees turn counter-clockwise seen from above). The distance to the
//!   target and the elevation stay; frame `k` of a movie orbiting at `d` degrees per frame is
//!   `pose.orbit(k as f32 * d)`, which never accumulates rounding from frame to frame.
//! - **Keyframes.** [`Keyframes`] holds poses at frame numbers (strictly increasing, not
//!   necessarily integers or evenly spaced) and interpolates eye, target, up and field of view by
//!   cubic Hermite segments whose tangents are the finite differences of the neighbouring keys
//!   (a Catmull–Rom spline for non-uniform key times): the path passes through every key, its
//!   velocity is continuous at the keys, and keys on a straight line at even speed give exactly
//!   that line. Before the first key the path holds the first pose, after the last the last.
//!   `up` is renormalised after interpolation.
//!
//! The text form read by [`Keyframes::parse`] has one key per line: `FRAME EX EY EZ TX TY TZ`,
//! then optionally `UX UY UZ`, then optionally `FOV` (degrees), separated by spaces, tabs or
//! commas. `#` starts a comment; blank lines are skipped, and a first line that is not numeric
//! (a CSV header) is skipped too. A missing up or field of view takes the default given to
//! `parse`. Errors name the line and the column of the offending field.
//!
//! ```
//! use texmap_core::camera_path::{Keyframes, Pose};
//! use texmap_core::glam::Vec3;
//!
//! let start = Pose::new(Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO, Vec3::Y, Some(40.0));
//! let keys = Keyframes::parse("0  0 0 10  0 0 0\n10  0 0 20  0 0 0  0 1 0  30\n", &start).unwrap();
//! let mid = keys.at(5.0);
//! assert!((mid.eye.z - 15.0).abs() < 1e-4);
//! let quarter = start.orbit(90.0);
//! assert!((quarter.eye - Vec3::new(10.0, 0.0, 0.0)).length() < 1e-4);
//! ```

use glam::{Quat, Vec3};

use crate::camera::{Camera, CameraError, Projection};

/// Where a camera stands and what it looks at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Horizontal field of view in degrees; `None` keeps the template camera's.
    pub hfov_deg: Option<f32>,
}

impl Pose {
    pub fn new(eye: Vec3, target: Vec3, up: Vec3, hfov_deg: Option<f32>) -> Pose {
        Pose {
            eye,
            target,
            up,
            hfov_deg,
        }
    }

    /// The pose of `camera` looking at `target` (a camera does not remember its target).
    pub fn of_camera(camera: &Camera, target: Vec3) -> Pose {
        let hfov_deg = match camera.projection() {
            Projection::Perspective { hfov_deg } => Some(hfov_deg),
            Projection::Orthographic { .. } => None,
        };
        Pose::new(camera.eye(), target, camera.up(), hfov_deg)
    }

    /// The pose turned by `degrees` about the axis through the target along `up`: the eye moves
    /// on a circle about that axis and `up` turns with it.
    pub fn orbit(&self, degrees: f32) -> Pose {
        let axis = self.up.normalize_or_zero();
        if axis == Vec3::ZERO || !degrees.is_finite() {
            return *self;
        }
        // Reduce first so that large frame counts keep full precision in the angle.
        let r = Quat::from_axis_angle(axis, (degrees % 360.0).to_radians());
        Pose {
            eye: self.target + r * (self.eye - self.target),
            up: r * self.up,
            ..*self
        }
    }

    /// The pose moved by `d` (eye and target together).
    pub fn translated(&self, d: Vec3) -> Pose {
        Pose {
            eye: self.eye + d,
            target: self.target + d,
            ..*self
        }
    }

    /// A camera at this pose with the projection, size and clip distances of `template`.
    ///
    /// Perspective: this pose's field of view (or the template's); the near plane is the
    /// default for the new eye–target distance and the far plane the template's. Orthographic:
    /// the template's view width and clip distances.
    pub fn camera(&self, template: &Camera) -> Result<Camera, CameraError> {
        let (w, h) = (template.width(), template.height());
        match template.projection() {
            Projection::Perspective { hfov_deg } => {
                let fov = self.hfov_deg.unwrap_or(hfov_deg);
                let cam = Camera::perspective_look_at(self.eye, self.target, self.up, fov, w, h)?;
                if template.far().is_finite() {
                    let near = cam.near();
                    cam.with_clip(near, template.far().max(near * 2.0))
                } else {
                    Ok(cam)
                }
            }
            Projection::Orthographic { view_width } => {
                Camera::orthographic_look_at(self.eye, self.target, self.up, view_width, w, h)?
                    .with_clip(template.near(), template.far())
            }
        }
    }
}

/// A keyframe file or list that cannot be used: the line (1-based; 0 for a list given in code),
/// the column (1-based, 0 when the whole line is meant) and what was expected.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyframeError {
    pub line: usize,
    pub column: usize,
    pub message: String,
}

impl std::fmt::Display for KeyframeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (self.line, self.column) {
            (0, _) => f.write_str(&self.message),
            (l, 0) => write!(f, "line {l}: {}", self.message),
            (l, c) => write!(f, "line {l}, column {c}: {}", self.message),
        }
    }
}

impl std::error::Error for KeyframeError {}

/// Poses at frame numbers, interpolated smoothly (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Keyframes {
    frames: Vec<f32>,
    poses: Vec<Pose>,
}

/// Most keys a path may hold (a keyframe file is written by hand or by a short script).
pub const MAX_KEYS: usize = 100_000;

fn key_error(line: usize, column: usize, message: impl Into<String>) -> KeyframeError {
    KeyframeError {
        line,
        column,
        message: message.into(),
    }
}

/// Why a pose cannot be a key, if it cannot.
fn pose_problem(p: &Pose) -> Option<&'static str> {
    if !(p.eye.is_finite() && p.target.is_finite() && p.up.is_finite()) {
        return Some("eye, target and up must be finite");
    }
    if (p.target - p.eye).length() <= 0.0 {
        return Some("the eye is at the target");
    }
    if p.up.length() <= 0.0 || (p.target - p.eye).cross(p.up).length() <= 1e-6 * p.up.length() {
        return Some("up is zero or along the view direction");
    }
    if let Some(f) = p.hfov_deg
        && !(f.is_finite() && f > 0.0 && f < 180.0)
    {
        return Some("the field of view must be strictly between 0 and 180 degrees");
    }
    None
}

impl Keyframes {
    /// Keys from `(frame, pose)` pairs with strictly increasing frames (at least one key).
    pub fn new(keys: Vec<(f32, Pose)>) -> Result<Keyframes, KeyframeError> {
        if keys.is_empty() {
            return Err(key_error(0, 0, "a camera path needs at least one key"));
        }
        if keys.len() > MAX_KEYS {
            return Err(key_error(
                0,
                0,
                format!("{} keys: at most {MAX_KEYS}", keys.len()),
            ));
        }
        for (i, (f, p)) in keys.iter().enumerate() {
            if !f.is_finite() {
                return Err(key_error(0, 0, format!("key {i}: frame {f} is not finite")));
            }
            if i > 0 && *f <= keys[i - 1].0 {
                return Err(key_error(
                    0,
                    0,
                    format!(
                        "key {i}: frame {f} does not come after {} (frames must increase)",
                        keys[i - 1].0
                    ),
                ));
            }
            if let Some(why) = pose_problem(p) {
                return Err(key_error(0, 0, format!("key {i}: {why}")));
            }
        }
        let (frames, poses) = keys.into_iter().unzip();
        Ok(Keyframes { frames, poses })
    }

    /// Reads the text form (see the module docs); a key without up or field of view takes
    /// `defaults.up` / `defaults.hfov_deg`.
    pub fn parse(text: &str, defaults: &Pose) -> Result<Keyframes, KeyframeError> {
        let mut keys: Vec<(f32, Pose)> = Vec::new();
        let mut seen_data = false;
        for (i, raw) in text.lines().enumerate() {
            let line = i + 1;
            let content = raw.split('#').next().unwrap_or("");
            // Fields with their 1-based columns.
            let mut fields: Vec<(usize, &str)> = Vec::new();
            let mut start = None;
            for (c, ch) in content.char_indices().chain([(content.len(), ' ')]) {
                let sep = ch == ',' || ch.is_whitespace();
                match (sep, start) {
                    (false, None) => start = Some(c),
                    (true, Some(s)) => {
                        fields.push((s + 1, &content[s..c]));
                        start = None;
                    }
                    _ => {}
                }
            }
            if fields.is_empty() {
                continue;
            }
            let numeric = fields[0].1.parse::<f32>().is_ok();
            if !seen_data && !numeric && keys.is_empty() {
                // A header line such as "frame,eye_x,...".
                seen_data = true;
                continue;
            }
            seen_data = true;
            if !matches!(fields.len(), 7 | 10 | 11) {
                return Err(key_error(
                    line,
                    0,
                    format!(
                        "{} fields: expected FRAME EX EY EZ TX TY TZ [UX UY UZ [FOV]] (7, 10 or 11 numbers)",
                        fields.len()
                    ),
                ));
            }
            let mut v = [0f32; 11];
            for (k, (col, s)) in fields.iter().enumerate() {
                v[k] = match s.parse::<f32>() {
                    Ok(x) if x.is_finite() => x,
                    _ => {
                        return Err(key_error(
                            line,
                            *col,
                            format!("{s:?} is not a finite number"),
                        ));
                    }
                };
            }
            if keys.len() >= MAX_KEYS {
                return Err(key_error(line, 0, format!("more than {MAX_KEYS} keys")));
            }
            let pose = Pose {
                eye: Vec3::new(v[1], v[2], v[3]),
                target: Vec3::new(v[4], v[5], v[6]),
                up: if fields.len() >= 10 {
                    Vec3::new(v[7], v[8], v[9])
                } else {
                    defaults.up
                },
                hfov_deg: if fields.len() == 11 {
                    Some(v[10])
                } else {
                    defaults.hfov_deg
                },
            };
            if let Some(&(last, _)) = keys.last()
                && v[0] <= last
            {
                return Err(key_error(
                    line,
                    fields[0].0,
                    format!(
                        "frame {} does not come after {last} (frames must increase)",
                        v[0]
                    ),
                ));
            }
            if let Some(why) = pose_problem(&pose) {
                return Err(key_error(line, 0, why));
            }
            keys.push((v[0], pose));
        }
        if keys.is_empty() {
            return Err(key_error(0, 0, "no key: the path holds no numeric line"));
        }
        Keyframes::new(keys)
    }

    /// Number of keys.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// Always false: a path has at least one key.
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// The frame number of the last key.
    pub fn last_frame(&self) -> f32 {
        *self.frames.last().expect("at least one key")
    }

    /// The pose at `frame` (see the module docs for the interpolation).
    pub fn at(&self, frame: f32) -> Pose {
        let n = self.frames.len();
        if n == 1 || frame.is_nan() || frame <= self.frames[0] {
            return self.poses[0];
        }
        if frame >= self.frames[n - 1] {
            return self.poses[n - 1];
        }
        // The segment [i, i+1] holding `frame`.
        let i = self.frames.partition_point(|&f| f <= frame) - 1;
        let (t0, t1) = (self.frames[i], self.frames[i + 1]);
        let h = t1 - t0;
        let s = (frame - t0) / h;
        // Hermite basis.
        let (s2, s3) = (s * s, s * s * s);
        let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
        let h10 = s3 - 2.0 * s2 + s;
        let h01 = -2.0 * s3 + 3.0 * s2;
        let h11 = s3 - s2;
        // Tangent (per frame) at key k: the central difference over its neighbours, one-sided
        // at the ends.
        let tangent = |get: &dyn Fn(&Pose) -> Vec3, k: usize| -> Vec3 {
            let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
            (get(&self.poses[b]) - get(&self.poses[a])) / (self.frames[b] - self.frames[a])
        };
        let interp = |get: &dyn Fn(&Pose) -> Vec3| -> Vec3 {
            get(&self.poses[i]) * h00
                + tangent(get, i) * (h10 * h)
                + get(&self.poses[i + 1]) * h01
                + tangent(get, i + 1) * (h11 * h)
        };
        let eye = interp(&|p| p.eye);
        let target = interp(&|p| p.target);
        let up = interp(&|p| p.up).normalize_or(self.poses[i].up);
        let hfov_deg = match (self.poses[i].hfov_deg, self.poses[i + 1].hfov_deg) {
            (Some(_), Some(_)) => {
                let f = interp(&|p| Vec3::splat(p.hfov_deg.unwrap_or(0.0))).x;
                Some(f.clamp(0.01, 179.99))
            }
            (a, b) => {
                if s < 0.5 {
                    a
                } else {
                    b
                }
            }
        };
        Pose {
            eye,
            target,
            up,
            hfov_deg,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose(eye: [f32; 3], target: [f32; 3]) -> Pose {
        Pose::new(Vec3::from(eye), Vec3::from(target), Vec3::Y, Some(40.0))
    }

    #[test]
    fn orbit_keeps_distance_and_height_and_turns_counter_clockwise() {
        let p = pose([0.0, 3.0, 10.0], [1.0, 0.0, 0.0]);
        for k in 0..40 {
            let q = p.orbit(k as f32 * 9.0);
            assert!(((q.eye - q.target).length() - (p.eye - p.target).length()).abs() < 1e-4);
            assert!((q.eye.y - 3.0).abs() < 1e-5);
        }
        // +90° about +y takes +z to +x (right-handed).
        let q = p.orbit(90.0);
        assert!((q.eye - Vec3::new(11.0, 3.0, 1.0)).length() < 1e-4, "{q:?}");
        // A full turn after many frames comes back to the start.
        let r = p.orbit(360.0 * 1000.0);
        assert!((r.eye - p.eye).length() < 1e-4);
    }

    #[test]
    fn keys_are_passed_through_and_even_lines_stay_lines() {
        let keys = Keyframes::new(vec![
            (0.0, pose([0.0, 0.0, 10.0], [0.0, 0.0, 0.0])),
            (4.0, pose([4.0, 0.0, 10.0], [0.0, 0.0, 0.0])),
            (8.0, pose([8.0, 0.0, 10.0], [0.0, 0.0, 0.0])),
            (12.0, pose([12.0, 0.0, 10.0], [0.0, 0.0, 0.0])),
        ])
        .unwrap();
        for f in 0..=12 {
            let p = keys.at(f as f32);
            assert!((p.eye.x - f as f32).abs() < 1e-5, "frame {f}: {}", p.eye.x);
        }
        assert_eq!(keys.at(-3.0), keys.at(0.0));
        assert_eq!(keys.at(99.0).eye.x, 12.0);
    }

    #[test]
    fn velocity_is_continuous_at_interior_keys() {
        let keys = Keyframes::new(vec![
            (0.0, pose([0.0, 0.0, 10.0], [0.0, 0.0, 0.0])),
            (3.0, pose([5.0, 2.0, 10.0], [0.0, 0.0, 0.0])),
            (10.0, pose([1.0, 7.0, 12.0], [0.0, 0.0, 0.0])),
            (11.0, pose([0.0, 9.0, 12.0], [0.0, 0.0, 0.0])),
        ])
        .unwrap();
        let e = 1e-2;
        for &k in &[3.0f32, 10.0] {
            let left = (keys.at(k).eye - keys.at(k - e).eye) / e;
            let right = (keys.at(k + e).eye - keys.at(k).eye) / e;
            assert!(
                (left - right).length() < 0.05 * left.length().max(1.0),
                "{k}: {left} vs {right}"
            );
            // And the path passes through the key itself.
            let key = keys.poses[keys.frames.iter().position(|&f| f == k).unwrap()];
            assert!((keys.at(k).eye - key.eye).length() < 1e-5);
        }
    }

    #[test]
    fn parse_reads_defaults_headers_and_comments_and_locates_errors() {
        let d = Pose::new(Vec3::ZERO, Vec3::Z, Vec3::Y, Some(40.0));
        let k = Keyframes::parse(
            "frame,ex,ey,ez,tx,ty,tz\n# a comment\n\n0, 0,0,10, 0,0,0\n5 1 0 10 0 0 0 0 0 1 25 # z up\n",
            &d,
        )
        .unwrap();
        assert_eq!(k.len(), 2);
        assert_eq!(k.at(0.0).hfov_deg, Some(40.0));
        assert_eq!(k.at(5.0).up, Vec3::Z);
        assert_eq!(k.at(5.0).hfov_deg, Some(25.0));

        let e = Keyframes::parse("0 0 0 10 0 0 0\n1 0 0 x 0 0 0\n", &d).unwrap_err();
        assert_eq!((e.line, e.column), (2, 7), "{e}");
        let e = Keyframes::parse("0 0 0 10 0 0 0\n0 1 0 10 0 0 0\n", &d).unwrap_err();
        assert_eq!(e.line, 2, "{e}");
        assert!(e.message.contains("must increase"), "{e}");
        let e = Keyframes::parse("0 0 0 10 0 0 0 1 2\n", &d).unwrap_err();
        assert!(e.message.contains("9 fields"), "{e}");
        let e = Keyframes::parse("0 0 0 0 0 0 0\n", &d).unwrap_err();
        assert!(e.message.contains("eye is at the target"), "{e}");
        let e = Keyframes::parse("0 0 0 10 0 0 0 0 0 1 0 200\n", &d).unwrap_err();
        assert!(e.message.contains("12 fields"), "{e}");
        let e = Keyframes::parse("0 0 0 10 0 0 0 0 1 0 200\n", &d).unwrap_err();
        assert!(e.message.contains("field of view"), "{e}");
        assert!(Keyframes::parse("# nothing\n", &d).is_err());
    }

    #[test]
    fn camera_keeps_the_template_projection() {
        let t = Camera::orthographic_look_at(Vec3::Z * 10.0, Vec3::ZERO, Vec3::Y, 7.0, 64, 32)
            .unwrap()
            .with_clip(0.5, 100.0)
            .unwrap();
        let c = Pose::of_camera(&t, Vec3::ZERO)
            .orbit(45.0)
            .camera(&t)
            .unwrap();
        assert_eq!(c.projection(), t.projection());
        assert_eq!(
            (c.width(), c.height(), c.near(), c.far()),
            (64, 32, 0.5, 100.0)
        );
        let p =
            Camera::perspective_look_at(Vec3::Z * 10.0, Vec3::ZERO, Vec3::Y, 40.0, 64, 32).unwrap();
        let c = Pose::of_camera(&p, Vec3::ZERO).camera(&p).unwrap();
        assert_eq!(c, p);
    }
}

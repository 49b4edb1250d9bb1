//! Map addressing: unit direction ⇄ map coordinates for the three environment-map layouts.
//!
//! All functions work in the *map frame* (see [`MapFrame`]): a right-handed orthonormal basis in
//! which the layout is defined. Map coordinates `(u, v)` are in map widths, `[0, 1]²`, `v` along
//! the texture's rows (row 0 at `v = 0`, as [`texmap_core::mip::MipTexture`] stores them).
//!
//! - **Sphere map** (Seed 003, the OpenGL convention): the image of a mirror ball at infinity seen
//!   along −z. For a reflection `r`, `m = 2·sqrt(r_x² + r_y² + (r_z + 1)²)`, `u = r_x/m + ½`,
//!   `v = r_y/m + ½`. The whole sphere of directions lands in the disc inscribed in `[0,1]²`; the
//!   single direction `r = (0, 0, −1)` (straight away from the viewer) is smeared over the whole
//!   rim circle, where `m = 0`. [`sphere_uv`] returns a rim point there instead of a NaN.
//! - **Cube map**: six faces `+X, −X, +Y, −Y, +Z, −Z` ([`Face`]), each the image of a 90° camera at
//!   the centre. The face is the direction's major axis (ties go to x, then y, then z, so every
//!   direction has exactly one face); `(u, v)` follow the face camera's image (u right, v down).
//! - **Dual paraboloid** (Heidrich and Seidel 1998): two hemispheres, `z ≥ 0` (front) and `z < 0`
//!   (back), each the image of a paraboloid mirror: `p = (x, y) / (1 + |z|)`, `(u, v) = p/2 + ½`.
//!   The hemisphere's boundary `z = 0` is the circle `|p| = 1`. Unlike the sphere map, the
//!   formula stays regular a little past the boundary (`|p| > 1` is the other hemisphere, up to
//!   `z → ∓1`), which is what lets the renderer give each map an overlap band for seamless
//!   filtering.
//!
//! # References
//! - Seed 003 (sphere-map formula; the rim singularity noted as a gotcha).
//! - W. Heidrich, H.-P. Seidel, "View-independent environment maps", Graphics Hardware 1998
//!   (dual paraboloid parameterisation).

use glam::{Mat3, Vec2, Vec3};

/// An orthonormal right-handed basis that a map's layout is defined in. `to_map` rotates world
/// directions into it; its transpose rotates back.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MapFrame {
    /// Rows are the map's x, y, z axes expressed in world coordinates.
    to_map: Mat3,
}

impl MapFrame {
    /// The world frame itself.
    pub const WORLD: MapFrame = MapFrame {
        to_map: Mat3::IDENTITY,
    };

    /// A frame from its three axes (world coordinates). `None` unless they are finite, unit
    /// length and orthogonal within 1e-4, and right-handed.
    pub fn from_axes(x: Vec3, y: Vec3, z: Vec3) -> Option<MapFrame> {
        let ok_len = |a: Vec3| a.is_finite() && (a.length() - 1.0).abs() < 1e-4;
        if !(ok_len(x) && ok_len(y) && ok_len(z)) {
            return None;
        }
        if x.dot(y).abs() > 1e-4 || y.dot(z).abs() > 1e-4 || x.dot(z).abs() > 1e-4 {
            return None;
        }
        if x.cross(y).dot(z) < 0.0 {
            return None;
        }
        Some(MapFrame {
            to_map: Mat3::from_cols(x, y, z).transpose(),
        })
    }

    /// The eye frame of a camera: x right, y up, z toward the viewer (backwards). A sphere map in
    /// this frame is the view-dependent map of Seed 003: its singular direction points straight
    /// away from the viewer, and it turns with the camera (roll included).
    pub fn of_camera(cam: &texmap_core::camera::Camera) -> MapFrame {
        MapFrame {
            to_map: cam.world_to_eye_rotation(),
        }
    }

    /// World direction → map frame.
    #[inline]
    pub fn to_map(&self, d: Vec3) -> Vec3 {
        self.to_map * d
    }

    /// Map frame → world direction.
    #[inline]
    pub fn to_world(&self, d: Vec3) -> Vec3 {
        self.to_map.transpose() * d
    }

    /// The map's z axis in world coordinates.
    pub fn z_axis(&self) -> Vec3 {
        self.to_map.row(2)
    }
}

/// Below this `m²` the direction is taken as the sphere map's singular direction `(0, 0, −1)`.
const SPHERE_SINGULAR_M2: f32 = 1e-12;

/// Seed 003: sphere-map coordinates of a direction `r` (map frame; any length, normalised here).
///
/// `m = 2·sqrt(r_x² + r_y² + (r_z + 1)²)`, `u = r_x/m + ½`, `v = r_y/m + ½`. The singular
/// direction `r = (0, 0, −1)`, and any direction within `1e-6` of it, maps to the rim point
/// `(1, ½)`; a zero or non-finite `r` does too. The result is always finite and in the disc.
#[inline]
pub fn sphere_uv(r: Vec3) -> Vec2 {
    let r = r.normalize_or(Vec3::NEG_Z);
    let m2 = r.x * r.x + r.y * r.y + (r.z + 1.0) * (r.z + 1.0);
    if m2.is_nan() || m2 <= SPHERE_SINGULAR_M2 {
        return Vec2::new(1.0, 0.5);
    }
    let inv_m = 0.5 / m2.sqrt();
    Vec2::new(r.x * inv_m + 0.5, r.y * inv_m + 0.5)
}

/// Inverse of [`sphere_uv`]: the unit direction a sphere-map point shows, or `None` outside the
/// disc. The ball's normal at disc point `p = 2(u, v) − 1` is `n = (p, sqrt(1 − |p|²))`, and the
/// shown direction is the view ray `(0, 0, −1)` mirrored about it:
/// `r = (2 n_z p_x, 2 n_z p_y, 2 n_z² − 1)`.
#[inline]
pub fn sphere_dir(uv: Vec2) -> Option<Vec3> {
    let p = uv * 2.0 - Vec2::ONE;
    let s2 = p.length_squared();
    if s2.is_nan() || s2 > 1.0 {
        return None;
    }
    let nz = (1.0 - s2).sqrt();
    Some(Vec3::new(2.0 * nz * p.x, 2.0 * nz * p.y, 2.0 * nz * nz - 1.0).normalize_or(Vec3::NEG_Z))
}

/// A cube-map face.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Face {
    PosX,
    NegX,
    PosY,
    NegY,
    PosZ,
    NegZ,
}

impl Face {
    /// All six faces in storage order.
    pub const ALL: [Face; 6] = [
        Face::PosX,
        Face::NegX,
        Face::PosY,
        Face::NegY,
        Face::PosZ,
        Face::NegZ,
    ];

    /// Storage index 0..6.
    #[inline]
    pub fn index(self) -> usize {
        self as usize
    }

    /// The face camera's basis `(forward, right, up)` in the map frame; `right = forward × up`,
    /// as [`texmap_core::camera::Camera::perspective_look_at`] builds it from the up hint.
    #[inline]
    pub fn basis(self) -> (Vec3, Vec3, Vec3) {
        let (f, up) = match self {
            Face::PosX => (Vec3::X, Vec3::Y),
            Face::NegX => (Vec3::NEG_X, Vec3::Y),
            Face::PosY => (Vec3::Y, Vec3::NEG_Z),
            Face::NegY => (Vec3::NEG_Y, Vec3::Z),
            Face::PosZ => (Vec3::Z, Vec3::Y),
            Face::NegZ => (Vec3::NEG_Z, Vec3::Y),
        };
        (f, f.cross(up), up)
    }
}

/// The face a direction falls on and its `(u, v)` on that face (`[0, 1]²`, u right, v down in the
/// face camera's image). A zero or non-finite direction gives the centre of `+Z`.
#[inline]
pub fn cube_uv(d: Vec3) -> (Face, Vec2) {
    if !(d.is_finite() && d != Vec3::ZERO) {
        return (Face::PosZ, Vec2::splat(0.5));
    }
    let a = d.abs();
    let face = if a.x >= a.y && a.x >= a.z {
        if d.x >= 0.0 { Face::PosX } else { Face::NegX }
    } else if a.y >= a.z {
        if d.y >= 0.0 { Face::PosY } else { Face::NegY }
    } else if d.z >= 0.0 {
        Face::PosZ
    } else {
        Face::NegZ
    };
    (face, cube_face_uv(face, d).unwrap_or(Vec2::splat(0.5)))
}

/// `(u, v)` of direction `d` projected onto `face`'s image plane (beyond `[0, 1]` when `d` lies
/// outside the face's 90° frustum), or `None` when `d` points away from the face.
#[inline]
pub fn cube_face_uv(face: Face, d: Vec3) -> Option<Vec2> {
    let (f, r, up) = face.basis();
    let z = d.dot(f);
    if z.is_nan() || z <= 0.0 {
        return None;
    }
    let sc = d.dot(r) / z;
    let tc = d.dot(up) / z;
    Some(Vec2::new(0.5 * (sc + 1.0), 0.5 * (1.0 - tc)))
}

/// The unit direction through `(u, v)` of `face` (any `(u, v)`: outside `[0, 1]²` it continues
/// the face's image plane).
#[inline]
pub fn cube_dir(face: Face, uv: Vec2) -> Vec3 {
    let (f, r, up) = face.basis();
    (f + r * (2.0 * uv.x - 1.0) + up * (1.0 - 2.0 * uv.y)).normalize()
}

/// A dual-paraboloid hemisphere: `Front` holds `z ≥ 0`, `Back` `z < 0` (map frame).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Hemisphere {
    Front,
    Back,
}

impl Hemisphere {
    /// Storage index 0 (front) or 1 (back).
    #[inline]
    pub fn index(self) -> usize {
        self as usize
    }
}

/// The paraboloid point `p = (x, y)/(1 + s·z)` of direction `d` on `hemi`'s map (`s = +1` front,
/// `−1` back), in the unit disc for the hemisphere's own directions and beyond it for the other's.
/// `None` at the map's own singular direction (`z = −1` front, `z = +1` back) or for a zero or
/// non-finite `d`.
#[inline]
pub fn paraboloid_point(hemi: Hemisphere, d: Vec3) -> Option<Vec2> {
    let d = d.try_normalize()?;
    let s = match hemi {
        Hemisphere::Front => 1.0,
        Hemisphere::Back => -1.0,
    };
    let den = 1.0 + s * d.z;
    if den.is_nan() || den <= 1e-6 {
        return None;
    }
    Some(Vec2::new(d.x, d.y) / den)
}

/// The hemisphere a direction belongs to and its `(u, v) = p/2 + ½` there (always in the disc).
/// A zero or non-finite direction gives the centre of the front map.
#[inline]
pub fn paraboloid_uv(d: Vec3) -> (Hemisphere, Vec2) {
    let hemi = if d.z >= 0.0 {
        Hemisphere::Front
    } else {
        Hemisphere::Back
    };
    match paraboloid_point(hemi, d) {
        Some(p) => (hemi, p * 0.5 + Vec2::splat(0.5)),
        None => (Hemisphere::Front, Vec2::splat(0.5)),
    }
}

/// The unit direction shown at paraboloid point `p` of `hemi` (any `p`; `|p| > 1` continues into
/// the other hemisphere): `z = s·(1 − |p|²)/(1 + |p|²)`, `(x, y) = p·(1 + s·z)`.
#[inline]
pub fn paraboloid_dir(hemi: Hemisphere, p: Vec2) -> Vec3 {
    let s = match hemi {
        Hemisphere::Front => 1.0,
        Hemisphere::Back => -1.0,
    };
    let s2 = p.length_squared();
    let z = s * (1.0 - s2) / (1.0 + s2);
    let k = 1.0 + s * z;
    Vec3::new(p.x * k, p.y * k, z).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic directions spread over the sphere (a Fibonacci lattice) plus the axes.
    fn directions(n: usize) -> Vec<Vec3> {
        let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
        let mut v: Vec<Vec3> = (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
                let r = (1.0 - z * z).sqrt();
                let phi = golden * i as f32;
                Vec3::new(r * phi.cos(), r * phi.sin(), z)
            })
            .collect();
        v.extend([Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z]);
        v
    }

    #[test]
    fn sphere_map_matches_the_seed_formula_at_hand_points() {
        // r = +z (toward the viewer): the disc centre.
        assert!((sphere_uv(Vec3::Z) - Vec2::splat(0.5)).length() < 1e-7);
        // r = +x: m = 2·sqrt(1 + 1) = 2√2, u = 1/(2√2) + ½.
        let uv = sphere_uv(Vec3::X);
        let want = Vec2::new(0.5 + 1.0 / (2.0 * 2f32.sqrt()), 0.5);
        assert!((uv - want).length() < 1e-6, "expected {want}, got {uv}");
        // r = −y: v = −1/(2√2) + ½.
        let uv = sphere_uv(Vec3::NEG_Y);
        let want = Vec2::new(0.5, 0.5 - 1.0 / (2.0 * 2f32.sqrt()));
        assert!((uv - want).length() < 1e-6, "expected {want}, got {uv}");
    }

    #[test]
    fn sphere_map_round_trips_away_from_the_singular_direction() {
        for d in directions(2000) {
            if d.z < -0.999 {
                continue;
            }
            let uv = sphere_uv(d);
            assert!(
                (uv - Vec2::splat(0.5)).length() <= 0.5 + 1e-6,
                "{d} -> {uv}"
            );
            let back = sphere_dir(uv).expect("inside the disc");
            // Near the rim one f32 ulp of uv is a large angle: the tolerance grows as 1/(1 + z).
            let tol = 2e-6 / (1.0 + d.z).max(1e-3).sqrt() + 1e-6;
            assert!(
                (back - d).length() < tol,
                "{d} -> {uv} -> {back}, tol {tol}"
            );
        }
    }

    #[test]
    fn the_singular_direction_gives_no_nan() {
        for r in [
            Vec3::NEG_Z,
            Vec3::new(0.0, 0.0, -5.0),
            Vec3::new(1e-8, -1e-8, -1.0),
            Vec3::ZERO,
            Vec3::NAN,
            Vec3::new(f32::INFINITY, 0.0, 0.0),
        ] {
            let uv = sphere_uv(r);
            assert!(uv.is_finite(), "{r} -> {uv}");
            assert!(
                (uv - Vec2::splat(0.5)).length() <= 0.5 + 1e-6,
                "{r} -> {uv}"
            );
        }
        // The rim circle shows the singular direction.
        let d = sphere_dir(Vec2::new(1.0, 0.5)).unwrap();
        assert!((d - Vec3::NEG_Z).length() < 1e-6, "{d}");
        assert_eq!(sphere_dir(Vec2::new(1.0, 1.0)), None);
    }

    #[test]
    fn cube_map_round_trips_and_picks_the_major_axis() {
        for d in directions(2000) {
            let (face, uv) = cube_uv(d);
            assert!(
                uv.cmpge(Vec2::ZERO).all() && uv.cmple(Vec2::ONE).all(),
                "{d} -> {uv}"
            );
            let (f, _, _) = face.basis();
            assert!(d.dot(f) >= d.abs().max_element() - 1e-6, "{d} on {face:?}");
            let back = cube_dir(face, uv);
            assert!((back - d).length() < 1e-5, "{d} -> {face:?} {uv} -> {back}");
        }
    }

    #[test]
    fn cube_faces_agree_with_the_face_cameras() {
        // The face's (u, v) must be the face camera's image coordinates: pixel centre
        // (i + ½, j + ½) of an n x n, 90° camera looks along cube_dir(face, (i + ½, j + ½)/n).
        let n = 8u32;
        for face in Face::ALL {
            let (f, _, up) = face.basis();
            let cam =
                texmap_core::camera::Camera::perspective_look_at(Vec3::ZERO, f, up, 90.0, n, n)
                    .unwrap();
            for (i, j) in [(0, 0), (7, 0), (3, 5), (7, 7)] {
                let (x, y) = (i as f32 + 0.5, j as f32 + 0.5);
                let ray = cam.ray(x, y).dir;
                let d = cube_dir(face, Vec2::new(x, y) / n as f32);
                assert!(
                    (ray - d).length() < 1e-5,
                    "{face:?} ({i},{j}): camera {ray}, map {d}"
                );
            }
        }
    }

    #[test]
    fn cube_edges_are_continuous() {
        // Directions just either side of an edge map to neighbouring texels of two faces whose
        // back-projections are equally close.
        let e = 1e-4;
        for d in [
            Vec3::new(1.0, 1.0 - e, 0.3),
            Vec3::new(1.0 - e, 1.0, 0.3),
            Vec3::new(-0.2, 1.0, -1.0 + e),
            Vec3::new(-0.2, 1.0 - e, -1.0),
        ] {
            let (face, uv) = cube_uv(d);
            assert!((cube_dir(face, uv) - d.normalize()).length() < 1e-5);
            // On the edge, one of u, v is 0 or 1.
            let m = uv.x.min(1.0 - uv.x).min(uv.y).min(1.0 - uv.y);
            assert!(m < 1e-3, "{d} -> {face:?} {uv}");
        }
    }

    #[test]
    fn paraboloid_round_trips_and_splits_at_the_equator() {
        for d in directions(2000) {
            let (h, uv) = paraboloid_uv(d);
            assert!(
                (uv - Vec2::splat(0.5)).length() <= 0.5 + 1e-6,
                "{d} -> {uv}"
            );
            let back = paraboloid_dir(h, uv * 2.0 - Vec2::ONE);
            assert!((back - d).length() < 1e-5, "{d} -> {h:?} {uv} -> {back}");
        }
        // The equator is the unit circle on both maps.
        let p = paraboloid_point(Hemisphere::Back, Vec3::X).unwrap();
        assert!((p.length() - 1.0).abs() < 1e-6);
        // Past the equator the formula continues: a back direction on the front map, |p| > 1.
        let d = Vec3::new(1.0, 0.0, -0.2).normalize();
        let p = paraboloid_point(Hemisphere::Front, d).unwrap();
        assert!(p.length() > 1.0);
        assert!((paraboloid_dir(Hemisphere::Front, p) - d).length() < 1e-5);
        assert_eq!(paraboloid_point(Hemisphere::Front, Vec3::NEG_Z), None);
    }

    #[test]
    fn frames_validate_and_rotate() {
        assert!(MapFrame::from_axes(Vec3::X, Vec3::Y, Vec3::NEG_Z).is_none());
        assert!(MapFrame::from_axes(Vec3::X, Vec3::X, Vec3::Z).is_none());
        let f = MapFrame::from_axes(Vec3::Y, Vec3::Z, Vec3::X).unwrap();
        assert!((f.to_map(Vec3::Y) - Vec3::X).length() < 1e-7);
        assert!((f.to_world(Vec3::X) - Vec3::Y).length() < 1e-7);
        assert_eq!(f.z_axis(), Vec3::X);
    }
}

//! Ellipsoids for aspherical particles, as OVITO draws its "Aspherical Shape" and
//! "Orientation" properties ([`crate::DrawStyle::Ellipsoids`]): liquid crystals (Gay–Berne),
//! colloids, coarse-grained molecules of LAMMPS `atom_style ellipsoid` and HOOMD-blue.
//!
//! Each selected atom is an ellipsoid at its centre with semi-axes `(a, b, c)` along the axes of
//! its rotation `q`: the surface is `x = centre + q · (a u_x, b u_y, c u_z)` for unit vectors `u`.
//!
//! Where the shape and orientation come from ([`EllipsoidOptions`]):
//! - the shape ([`SHAPE_SOURCES`], the first the frame has): the per-atom properties `shapex
//!   shapey shapez` (LAMMPS's `compute property/atom`: the three *diameters*, halved here, as
//!   OVITO halves them), or `c_shape[1] c_shape[2] c_shape[3]` (the semi-axes, as OVITO exports
//!   its "Aspherical Shape" to a LAMMPS dump; md-io gives a HOOMD-blue GSD file's ellipsoid
//!   `type_shapes` as `shapex..` too); or one shape for every atom
//!   ([`EllipsoidOptions::shape`], semi-axes in Å). An atom whose three shape values are 0 is a
//!   sphere in LAMMPS and is drawn as a sphere of its radius, as OVITO does; one with some but
//!   not all of them 0, or a negative or non-finite one, is an error naming the atom.
//! - the orientation ([`ORIENTATION_SOURCES`]): the quaternion `quatw quati quatj quatk`
//!   (LAMMPS, w first), else `c_orient[1..4]` (x, y, z, w: OVITO's export), else none (the
//!   ellipsoid's axes along x, y, z). A quaternion of another length is normalised; a zero or
//!   non-finite one is an error naming the atom.
//!
//! # Drawing: exact impostors
//! [`draw`] draws each ellipsoid as a ray-cast impostor, as the sphere methods draw atoms: a
//! screen rectangle (the projection of the ellipsoid's exact eye-space bounding box) binned
//! into tiles by the rasteriser's sprites, each pixel's eye ray intersected with the quadric in
//! the frame where it is the unit sphere, the nearest hit's depth and exact normal written and
//! lit, with early depth rejection from the box's nearest depth. Exact silhouettes and depths at
//! any size, at a cost per covered pixel rather than per triangle.
//!
//! # Tessellation, no finer than the view needs
//! For the reference ray tracer (`--method reference`, `--quality`) and for export the
//! ellipsoids are meshes, each an icosphere ([`MAX_LEVEL`] + 1 levels, 20 · 4^level triangles) mapped onto the ellipsoid. The
//! flat triangles of a unit icosphere of level `l` lie within `sag(l)` of the sphere, so the
//! mapped mesh lies within `sag / (1 − sag) · a_max` of the ellipsoid (`a_max` its longest
//! semi-axis). [`tessellate`] picks for each ellipsoid the coarsest level that keeps this gap
//! within a tolerance in pixels at the ellipsoid's nearest depth, and leaves out the ellipsoids
//! wholly outside the view: thousands of particles a few pixels across cost 20–80 triangles
//! each, one that fills the view 20,480. Vertices lie exactly on the ellipsoid and carry its
//! exact normal (`q · (u_x / a, u_y / b, u_z / c)`, normalised), so shading is smooth at any
//! level and only the silhouette is polygonal, within the tolerance.
//!
//! ```
//! use glam::{Quat, Vec3};
//! use texmap_core::camera::Camera;
//! use texmap_md_scene::ellipsoids::{Ellipsoid, tessellate};
//!
//! let e = Ellipsoid {
//!     center: Vec3::ZERO,
//!     semi_axes: Vec3::new(2.0, 1.0, 0.5),
//!     rotation: Quat::from_rotation_z(0.3),
//!     kind: 0,
//! };
//! let camera = Camera::perspective_look_at(
//!     Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO, Vec3::Y, 45.0, 640, 480,
//! ).unwrap();
//! let mesh = tessellate(&[e], Some(&camera), 0.25);
//! // Every vertex on the ellipsoid.
//! for p in &mesh.positions {
//!     let u = e.rotation.inverse() * (*p - e.center) / e.semi_axes;
//!     assert!((u.length() - 1.0).abs() < 1e-4);
//! }
//! ```

use std::fmt;
use std::sync::OnceLock;

use glam::Mat3;
use glam::{Quat, Vec3};
use texmap_core::camera::Camera;
use texmap_core::frame::Frame as Image;
use texmap_core::shade::{Lighting, Material};
use texmap_impostor::Tess;
use texmap_md_io::Frame;
use texmap_raster::{DrawState, Framebuffer, QuadOut, RasterError, Sprite, SpriteQuad};

use crate::surface::MolMesh;

/// The finest icosphere level (20,480 triangles).
pub const MAX_LEVEL: usize = texmap_impostor::ICOSPHERE_LEVELS - 1;
/// The default silhouette tolerance of [`tessellate`], pixels.
pub const TOLERANCE_PX: f32 = 0.25;
/// The per-atom properties a shape is read from, in order of preference, each with the factor
/// that makes its values semi-axes: LAMMPS's diameters, OVITO's exported semi-axes.
pub const SHAPE_SOURCES: [([&str; 3], f32); 2] = [
    (["shapex", "shapey", "shapez"], 0.5),
    (["c_shape[1]", "c_shape[2]", "c_shape[3]"], 1.0),
];
/// The per-atom properties an orientation quaternion is read from, in order of preference,
/// each listed as its w, x, y, z components: LAMMPS's (w first in the file), OVITO's exported
/// `c_orient` (w last in the file).
pub const ORIENTATION_SOURCES: [[&str; 4]; 2] = [
    ["quatw", "quati", "quatj", "quatk"],
    ["c_orient[4]", "c_orient[1]", "c_orient[2]", "c_orient[3]"],
];

/// The indices in `frame.properties` of the first orientation source the frame has, as w, x,
/// y, z; `None` when it has none complete (every property one value per atom).
pub fn orientation_properties(frame: &Frame) -> Option<[usize; 4]> {
    let n = frame.n_atoms();
    ORIENTATION_SOURCES.iter().find_map(|names| {
        let at = names.map(|name| {
            frame
                .properties
                .iter()
                .position(|p| p.name == name && p.values.len() == n)
        });
        match at {
            [Some(w), Some(x), Some(y), Some(z)] => Some([w, x, y, z]),
            _ => None,
        }
    })
}

/// One ellipsoid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ellipsoid {
    pub center: Vec3,
    /// Semi-axes (Å) along the rotated x, y, z axes.
    pub semi_axes: Vec3,
    /// A unit quaternion: the ellipsoid's axes in the world.
    pub rotation: Quat,
    /// The material index.
    pub kind: u16,
}

impl Ellipsoid {
    /// The longest semi-axis: the radius of the sphere around the ellipsoid.
    pub fn bounding_radius(&self) -> f32 {
        self.semi_axes.max_element()
    }
}

/// Where the ellipsoids' shapes come from; see the module docs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EllipsoidOptions {
    /// One shape for every atom, semi-axes in Å; `None` reads [`SHAPE_PROPERTIES`].
    pub shape: Option<[f32; 3]>,
}

impl EllipsoidOptions {
    /// Checks the options: a given shape has three finite semi-axes > 0.
    pub fn check(&self) -> Result<(), EllipsoidError> {
        match self.shape {
            Some(s) if !s.iter().all(|v| v.is_finite() && *v > 0.0) => {
                Err(EllipsoidError::BadOption { shape: s })
            }
            _ => Ok(()),
        }
    }
}

/// Why a frame's ellipsoids could not be had.
#[derive(Clone, Debug, PartialEq)]
pub enum EllipsoidError {
    /// No shape option and the frame has none of [`SHAPE_SOURCES`]; the frame's property
    /// names.
    NoShape { have: Vec<String> },
    /// An atom's shape is not three diameters ≥ 0, all zero (a sphere) or all positive.
    BadShape { atom: usize, diameters: [f32; 3] },
    /// An atom's orientation quaternion is zero or not finite.
    BadOrientation { atom: usize, quaternion: [f32; 4] },
    /// The shape given for every atom is not three finite semi-axes > 0.
    BadOption { shape: [f32; 3] },
}

impl fmt::Display for EllipsoidError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EllipsoidError::NoShape { have } => {
                let have = if have.is_empty() {
                    "none".to_string()
                } else {
                    have.join(", ")
                };
                write!(
                    f,
                    "no shape: the frame has neither shapex shapey shapez (LAMMPS) nor c_shape[1..3] (OVITO) properties (it has: {have}); give every atom one shape instead"
                )
            }
            EllipsoidError::BadShape { atom, diameters } => write!(
                f,
                "atom {atom} has the shape {diameters:?}: expected three diameters > 0 (an ellipsoid) or three zeros (a sphere)"
            ),
            EllipsoidError::BadOrientation { atom, quaternion } => write!(
                f,
                "atom {atom} has the orientation {quaternion:?} (w, i, j, k): expected a non-zero finite quaternion"
            ),
            EllipsoidError::BadOption { shape } => write!(
                f,
                "the shape {shape:?}: expected three finite semi-axes > 0 (Å)"
            ),
        }
    }
}

impl std::error::Error for EllipsoidError {}

/// Each atom's semi-axes (zero for an atom LAMMPS treats as a sphere) and rotation, from the
/// frame's properties or the options (see the module docs).
pub fn shapes(
    frame: &Frame,
    options: &EllipsoidOptions,
) -> Result<Vec<(Vec3, Quat)>, EllipsoidError> {
    let n = frame.n_atoms();
    let column = |name: &str| frame.property(name).filter(|v| v.len() == n);
    let diameters: Option<([&[f32]; 3], f32)> = match options.shape {
        Some(_) => None,
        None => {
            let found = SHAPE_SOURCES
                .iter()
                .find_map(|(names, factor)| match names.map(column) {
                    [Some(x), Some(y), Some(z)] => Some(([x, y, z], *factor)),
                    _ => None,
                });
            match found {
                Some(f) => Some(f),
                None => {
                    return Err(EllipsoidError::NoShape {
                        have: frame.properties.iter().map(|p| p.name.clone()).collect(),
                    });
                }
            }
        }
    };
    let quats =
        orientation_properties(frame).map(|at| at.map(|k| frame.properties[k].values.as_slice()));
    let mut out = Vec::with_capacity(n);
    for atom in 0..n {
        let semi = match (options.shape, diameters) {
            (Some(s), _) => Vec3::from(s),
            (None, Some((d, factor))) => {
                let d = [d[0][atom], d[1][atom], d[2][atom]];
                let all_zero = d.iter().all(|v| *v == 0.0);
                let all_positive = d.iter().all(|v| v.is_finite() && *v > 0.0);
                if !(all_zero || all_positive) {
                    return Err(EllipsoidError::BadShape { atom, diameters: d });
                }
                Vec3::from(d) * factor
            }
            (None, None) => unreachable!("a shape or the shape properties"),
        };
        let rotation = match quats {
            Some(q) => {
                let q = [q[0][atom], q[1][atom], q[2][atom], q[3][atom]];
                let n2: f32 = q.iter().map(|v| v * v).sum();
                if !(n2.is_finite() && n2 > 0.0) {
                    return Err(EllipsoidError::BadOrientation {
                        atom,
                        quaternion: q,
                    });
                }
                Quat::from_xyzw(q[1], q[2], q[3], q[0]).normalize()
            }
            None => Quat::IDENTITY,
        };
        out.push((semi, rotation));
    }
    Ok(out)
}

/// The icospheres of levels 0..=[`MAX_LEVEL`] (the polygon method's), built once.
fn unit_spheres() -> &'static [Tess] {
    static SPHERES: OnceLock<Vec<Tess>> = OnceLock::new();
    SPHERES.get_or_init(texmap_impostor::icospheres)
}

/// The farthest the flat triangles of an icosphere of `level` lie from the unit sphere.
pub fn sag(level: usize) -> f32 {
    unit_spheres()[level.min(MAX_LEVEL)].sag
}

/// The coarsest level whose mesh of an ellipsoid `radius_px` pixels across its longest
/// semi-axis lies within `tolerance_px` of it ([`MAX_LEVEL`] at most).
pub fn level_for(radius_px: f32, tolerance_px: f32) -> usize {
    (0..MAX_LEVEL)
        .find(|&l| {
            let s = sag(l);
            s / (1.0 - s) * radius_px <= tolerance_px
        })
        .unwrap_or(MAX_LEVEL)
}

/// Appends the mesh of ellipsoid `e` at icosphere `level` (counter-clockwise seen from
/// outside whatever the rotation: the map is a rotation times positive scales).
pub fn append_ellipsoid(mesh: &mut MolMesh, e: &Ellipsoid, level: usize) {
    let unit = &unit_spheres()[level.min(MAX_LEVEL)];
    let base = mesh.positions.len() as u32;
    let inv = e.semi_axes.recip();
    for u in &unit.verts {
        mesh.positions
            .push(e.center + e.rotation * (*u * e.semi_axes));
        mesh.normals.push((e.rotation * (*u * inv)).normalize());
    }
    for t in &unit.tris {
        mesh.triangles.push(t.map(|i| base + i));
        mesh.kinds.push(e.kind);
    }
}

/// The pixels per Å at eye-space depth `depth` (perspective) or everywhere (orthographic).
fn pixels_per_unit(camera: &Camera, depth: f32) -> f32 {
    if camera.is_orthographic() {
        camera.scale()
    } else {
        camera.scale() / depth.max(camera.near()).max(1e-6)
    }
}

/// The meshes of `ellipsoids`. With a camera (a picture), each at the coarsest level that
/// keeps its silhouette within `tolerance_px` pixels, and those wholly outside the view left
/// out; without one (a model to export), every ellipsoid at the level that keeps its mesh
/// within 1 % of its longest semi-axis, and `tolerance_px` unused.
pub fn tessellate(ellipsoids: &[Ellipsoid], camera: Option<&Camera>, tolerance_px: f32) -> MolMesh {
    let mut mesh = MolMesh::default();
    for e in ellipsoids {
        let radius = e.bounding_radius();
        if !(e.center.is_finite() && radius.is_finite() && radius > 0.0) {
            continue;
        }
        let level = match camera {
            Some(cam) => {
                if cam.sphere_outside_view(e.center, radius) {
                    continue;
                }
                let depth = -cam.world_to_eye(e.center).z - radius;
                level_for(radius * pixels_per_unit(cam, depth), tolerance_px)
            }
            None => level_for(100.0, 1.0),
        };
        append_ellipsoid(&mut mesh, e, level);
    }
    mesh
}

/// One ellipsoid in eye space, for the impostor shader.
struct EyeEllipsoid {
    center: Vec3,
    /// Eye space to the frame where the ellipsoid is the unit sphere (centre subtracted first).
    to_unit: Mat3,
    /// The ellipsoid's axes in eye space, and the reciprocal semi-axes: the normal at unit
    /// point `u` is `axes · (u / semi)`.
    axes: Mat3,
    inv_semi: Vec3,
    material: Material,
}

/// Draws `ellipsoids` as `camera` sees them over `frame` where they are nearer, as exact
/// ray-cast impostors (see the module docs), lit as the sphere methods light atoms
/// (`materials` indexed by kind; a kind past them is grey). Returns how many were drawn (not
/// culled). A `frame` of another size than the camera's is replaced by a cleared one.
pub fn draw(
    ellipsoids: &[Ellipsoid],
    materials: &[Material],
    camera: &Camera,
    lighting: &Lighting,
    frame: &mut Image,
) -> Result<usize, RasterError> {
    let (w, h) = (camera.width() as f32, camera.height() as f32);
    let (k, near) = (camera.scale(), camera.near());
    let ortho = camera.is_orthographic();
    let to_eye = camera.world_to_eye_rotation();
    let mut eyes = Vec::with_capacity(ellipsoids.len());
    let mut sprites = Vec::with_capacity(ellipsoids.len());
    for e in ellipsoids {
        let semi = e.semi_axes;
        if !(e.center.is_finite() && semi.is_finite() && semi.min_element() > 0.0) {
            continue;
        }
        let axes = to_eye * Mat3::from_quat(e.rotation.normalize());
        let m = axes * Mat3::from_diagonal(semi);
        let c = camera.world_to_eye(e.center);
        // The exact eye-space box: half-extent along axis i is the length of row i of m.
        let rows = m.transpose();
        let half = Vec3::new(
            rows.x_axis.length(),
            rows.y_axis.length(),
            rows.z_axis.length(),
        );
        let (nearest, farthest) = (-(c.z + half.z), -(c.z - half.z));
        if farthest <= near || nearest >= camera.far() {
            continue;
        }
        let (lo, hi) = if ortho {
            let centre = glam::Vec2::new(w * 0.5 + c.x * k, h * 0.5 - c.y * k);
            let r = glam::Vec2::new(half.x, half.y) * k;
            (centre - r, centre + r)
        } else if nearest > near {
            // The exact bounds of the projected ellipse: the planes through the eye tangent to
            // the ellipsoid. With the dual quadric A = M Mᵀ − c cᵀ, the plane x + s z = 0
            // (screen x = w/2 + k s) touches it where A₀₀ + 2 s A₀₂ + s² A₂₂ = 0; y likewise.
            // A₂₂ < 0: the ellipsoid lies wholly in front of the eye's plane.
            let a = m * m.transpose() - Mat3::from_cols(c * c.x, c * c.y, c * c.z);
            let roots = |aii: f32, ai2: f32| {
                let a22 = a.z_axis.z;
                let disc = (ai2 * ai2 - aii * a22).max(0.0).sqrt();
                let (s0, s1) = ((-ai2 + disc) / a22, (-ai2 - disc) / a22);
                (s0.min(s1), s0.max(s1))
            };
            let (x0, x1) = roots(a.x_axis.x, a.z_axis.x);
            let (y0, y1) = roots(a.y_axis.y, a.z_axis.y);
            // One pixel of margin for the roots' rounding.
            (
                glam::Vec2::new(w * 0.5 + k * x0 - 1.0, h * 0.5 - k * y1 - 1.0),
                glam::Vec2::new(w * 0.5 + k * x1 + 1.0, h * 0.5 - k * y0 + 1.0),
            )
        } else {
            // Reaching the near plane: every pixel may see it.
            (glam::Vec2::ZERO, glam::Vec2::new(w, h))
        };
        let lo = lo.floor().max(glam::Vec2::ZERO);
        let hi = hi.ceil().min(glam::Vec2::new(w, h));
        if !(lo.x < hi.x && lo.y < hi.y) {
            continue;
        }
        sprites.push(Sprite {
            min: lo,
            max: hi,
            depth_min: nearest.max(near),
            id: eyes.len() as u32,
        });
        eyes.push(EyeEllipsoid {
            center: c,
            to_unit: Mat3::from_diagonal(semi.recip()) * axes.transpose(),
            axes,
            inv_semi: semi.recip(),
            material: materials
                .get(e.kind as usize)
                .copied()
                .unwrap_or(Material::plastic(Vec3::splat(0.6))),
        });
    }
    if frame.width() != camera.width() || frame.height() != camera.height() {
        *frame = Image::new(camera.width(), camera.height(), [0, 0, 0, 255]);
    }
    if sprites.is_empty() {
        return Ok(0);
    }
    // Front to back, so that early depth rejection spares what is hidden.
    sprites.sort_by(|a, b| a.depth_min.total_cmp(&b.depth_min).then(a.id.cmp(&b.id)));
    let light = lighting.to_eye(camera);
    let shader = |id: u32, q: &SpriteQuad| -> QuadOut {
        let e = &eyes[id as usize];
        let mut out = QuadOut {
            color: [Vec3::ZERO; 4],
            depth: [f32::NAN; 4],
            mask: 0,
        };
        for lane in 0..4 {
            if q.mask & (1 << lane) == 0 {
                continue;
            }
            let (x, y) = (q.x[lane], q.y[lane]);
            let (origin, dir) = if ortho {
                let o = Vec3::new((x - w * 0.5) / k, (h * 0.5 - y) / k, 0.0);
                (o, Vec3::NEG_Z)
            } else {
                (Vec3::ZERO, camera.eye_ray_dir(x, y))
            };
            let o = e.to_unit * (origin - e.center);
            let d = e.to_unit * dir;
            // From the ray's point nearest the centre (`t0`), whose distance from it is taken
            // as a vector, not as b² − ac: far from the camera's origin those two are large and
            // nearly equal, and their difference loses the digits the silhouette needs.
            let a = d.dot(d);
            let t0 = -o.dot(d) / a;
            let closest = o + d * t0;
            let gap = 1.0 - closest.dot(closest);
            if gap.is_nan() || gap < 0.0 {
                continue;
            }
            let t = t0 - (gap / a).sqrt();
            let p = origin + dir * t;
            let depth = -p.z;
            if !(t > 0.0 && depth > near) {
                continue;
            }
            let u = o + d * t;
            let n = (e.axes * (u * e.inv_semi)).normalize();
            let v = if ortho { Vec3::Z } else { -p.normalize() };
            out.color[lane] = light.shade(&e.material, n, v);
            out.depth[lane] = depth;
            out.mask |= 1 << lane;
        }
        out
    };
    let mut fb = Framebuffer::new(camera.width(), camera.height())?;
    fb.clear([0, 0, 0, 0]);
    fb.draw_sprites(&sprites, &shader, &DrawState::default())?;
    crate::surface::composite(frame, &fb.to_frame(), 1.0);
    Ok(sprites.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn volume(mesh: &MolMesh) -> f64 {
        mesh.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| mesh.positions[i as usize].as_dvec3());
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn mesh_lies_on_the_ellipsoid_with_its_exact_normals_and_volume() {
        let e = Ellipsoid {
            center: Vec3::new(1.0, -2.0, 3.0),
            semi_axes: Vec3::new(3.0, 1.5, 0.75),
            rotation: Quat::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.7),
            kind: 3,
        };
        for level in 0..=MAX_LEVEL {
            let mut mesh = MolMesh::default();
            append_ellipsoid(&mut mesh, &e, level);
            assert!(mesh.kinds.iter().all(|k| *k == 3));
            for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
                let local = e.rotation.inverse() * (*p - e.center);
                let u = local / e.semi_axes;
                assert!((u.length() - 1.0).abs() < 1e-5);
                // The gradient of (x/a)² + (y/b)² + (z/c)².
                let g = e.rotation * (local / (e.semi_axes * e.semi_axes));
                assert!(n.dot(g.normalize()) > 1.0 - 1e-5);
            }
            // Inside the ellipsoid, by at most the sag's share of its volume.
            let exact = 4.0 / 3.0 * std::f64::consts::PI * 3.0 * 1.5 * 0.75;
            let mut centred = mesh.clone();
            centred.positions.iter_mut().for_each(|p| *p -= e.center);
            let v = volume(&centred);
            let s = sag(level) as f64;
            assert!(v > 0.0, "outward winding");
            assert!(
                v <= exact && v >= exact * (1.0 - s).powi(3),
                "level {level}: {v} vs {exact}"
            );
        }
    }

    #[test]
    fn the_level_keeps_the_silhouette_within_the_tolerance() {
        for radius_px in [0.5f32, 3.0, 10.0, 40.0, 200.0, 800.0] {
            let l = level_for(radius_px, 0.25);
            let s = sag(l);
            if l < MAX_LEVEL {
                assert!(s / (1.0 - s) * radius_px <= 0.25);
            }
            if l > 0 {
                let c = sag(l - 1);
                assert!(
                    c / (1.0 - c) * radius_px > 0.25,
                    "level {l} is not the coarsest"
                );
            }
        }
        assert_eq!(level_for(0.5, 0.25), 0);
        assert_eq!(level_for(1e6, 0.25), MAX_LEVEL);
    }

    #[test]
    fn shapes_from_lammps_properties() {
        let mut frame = Frame::new();
        frame.positions = vec![[0.0; 3]; 3];
        let props = [
            ("shapex", [2.0, 0.0, 1.0]),
            ("shapey", [1.0, 0.0, 1.0]),
            ("shapez", [4.0, 0.0, 1.0]),
            ("quatw", [1.0, 0.0, 2.0]),
            ("quati", [0.0, 0.0, 0.0]),
            ("quatj", [0.0, 0.0, 0.0]),
            ("quatk", [0.0, 1.0, 0.0]),
        ];
        for (name, values) in props {
            frame.properties.push(texmap_md_io::Property {
                name: name.into(),
                values: values.to_vec(),
            });
        }
        let s = shapes(&frame, &EllipsoidOptions::default()).unwrap();
        assert_eq!(s[0].0, Vec3::new(1.0, 0.5, 2.0));
        assert_eq!(s[1].0, Vec3::ZERO, "a LAMMPS sphere");
        // w = 0, k = 1: a half turn about z; a quaternion of length 2 is normalised.
        assert!((s[1].1 * Vec3::X + Vec3::X).length() < 1e-6);
        assert_eq!(s[2].1, Quat::IDENTITY);
        frame.properties[1].values[1] = 1.0;
        assert_eq!(
            shapes(&frame, &EllipsoidOptions::default()),
            Err(EllipsoidError::BadShape {
                atom: 1,
                diameters: [0.0, 1.0, 0.0]
            })
        );
        frame.properties[1].values[1] = 0.0;
        frame.properties[6].values[1] = 0.0;
        assert!(matches!(
            shapes(&frame, &EllipsoidOptions::default()),
            Err(EllipsoidError::BadOrientation { atom: 1, .. })
        ));
        frame.properties.truncate(1);
        assert!(matches!(
            shapes(&frame, &EllipsoidOptions::default()),
            Err(EllipsoidError::NoShape { .. })
        ));
        let uniform = EllipsoidOptions {
            shape: Some([1.0, 2.0, 3.0]),
        };
        let s = shapes(&frame, &uniform).unwrap();
        assert!(
            s.iter()
                .all(|(a, q)| *a == Vec3::new(1.0, 2.0, 3.0) && *q == Quat::IDENTITY)
        );
        assert!(
            EllipsoidOptions {
                shape: Some([1.0, 0.0, 1.0])
            }
            .check()
            .is_err()
        );
    }

    #[test]
    fn ellipsoids_outside_the_view_are_left_out() {
        let cam = Camera::perspective_look_at(
            Vec3::new(0.0, 0.0, 20.0),
            Vec3::ZERO,
            Vec3::Y,
            40.0,
            400,
            300,
        )
        .unwrap();
        let e = |x: f32, z: f32| Ellipsoid {
            center: Vec3::new(x, 0.0, z),
            semi_axes: Vec3::splat(1.0),
            rotation: Quat::IDENTITY,
            kind: 0,
        };
        let seen = tessellate(&[e(0.0, 0.0)], Some(&cam), TOLERANCE_PX);
        assert!(!seen.triangles.is_empty());
        // Beside the view, behind the eye.
        assert!(
            tessellate(&[e(40.0, 0.0), e(0.0, 30.0)], Some(&cam), TOLERANCE_PX)
                .triangles
                .is_empty()
        );
        // Just touching the view's edge still counts: half-width at depth 20 is 20 tan 20°.
        let edge = 20.0 * (20f32.to_radians()).tan();
        assert!(
            !tessellate(&[e(edge + 0.9, 0.0)], Some(&cam), TOLERANCE_PX)
                .triangles
                .is_empty()
        );
        // Nearer is finer.
        let near = tessellate(&[e(0.0, 15.0)], Some(&cam), TOLERANCE_PX);
        assert!(near.triangles.len() > seen.triangles.len());
    }
}

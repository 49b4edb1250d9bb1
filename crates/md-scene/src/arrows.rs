//! Arrows for a vector per atom, as OVITO's vector display draws velocities, forces and
//! displacements ([`crate::DrawStyle::Arrows`]).
//!
//! Each selected atom gets an arrow from its centre along its vector times
//! [`ArrowOptions::scale`]: a shaft of [`ArrowOptions::radius`] and a cone head of
//! [`HEAD_WIDTH`] times that radius, [`HEAD_LENGTH`] radii long (half the arrow when the arrow
//! is shorter than two heads), closed by flat discs, with [`ARROW_SEGMENTS`] sides, in the
//! atom's colour (or the representation's). The tip lies exactly at the centre plus the scaled
//! vector. A zero or non-finite vector draws nothing.
//!
//! The vectors ([`ArrowSource`]):
//! - the velocities the file holds (Å/ps: GRO, TRR, NetCDF, LAMMPS dump `vx vy vz`, extended
//!   XYZ `velo`, a CONTCAR's);
//! - the displacement from the first frame built (OVITO's Displacements modifier with frame 0
//!   as the reference), taken to the nearest periodic image when the frame has a cell, so an
//!   atom wrapped across the box moves by its true step;
//! - three per-atom properties named by a stem (a LAMMPS dump's forces `fx fy fz` by `f`, a
//!   compute's `c_disp[1] c_disp[2] c_disp[3]` by `c_disp`): `{stem}x`, `{stem}y`, `{stem}z`,
//!   else `{stem}[1]`, `{stem}[2]`, `{stem}[3]`, else `{stem}_x`, `{stem}_y`, `{stem}_z`.

use std::fmt;

use glam::Vec3;
use texmap_md_io::Frame;

use crate::surface::MolMesh;

/// Sides of an arrow's shaft and head.
pub const ARROW_SEGMENTS: usize = 12;
/// The head's radius over the shaft's.
pub const HEAD_WIDTH: f32 = 2.5;
/// The head's length in shaft radii (at most half the arrow).
pub const HEAD_LENGTH: f32 = 6.0;

/// Where an atom's vector comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum ArrowSource {
    /// The file's velocities (Å/ps).
    Velocity,
    /// The displacement from the first frame built (Å), to the nearest periodic image.
    Displacement,
    /// Three per-atom properties named by a stem (see the module docs).
    Property(String),
}

/// How arrows are drawn.
#[derive(Clone, Debug, PartialEq)]
pub struct ArrowOptions {
    pub source: ArrowSource,
    /// Arrow length per unit of the vector (Å per Å/ps for velocities, 1 for displacements).
    pub scale: f32,
    /// Shaft radius, Å.
    pub radius: f32,
}

impl Default for ArrowOptions {
    fn default() -> ArrowOptions {
        ArrowOptions {
            source: ArrowSource::Velocity,
            scale: 1.0,
            radius: 0.1,
        }
    }
}

/// Why a frame's vectors could not be had.
#[derive(Clone, Debug, PartialEq)]
pub enum ArrowError {
    /// The frame holds no velocities.
    NoVelocities,
    /// No triple of properties answers to the stem; the frame's property names are listed.
    NoProperty { stem: String, have: Vec<String> },
    /// The frame has another number of atoms than the displacement's reference frame.
    AtomCount { reference: usize, frame: usize },
    /// The scale or the radius is not a finite number > 0.
    BadOption { what: &'static str, value: f32 },
}

impl fmt::Display for ArrowError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ArrowError::NoVelocities => write!(
                f,
                "the frame holds no velocities (GRO, TRR, NetCDF, LAMMPS dump vx vy vz, extended XYZ velo and a CONTCAR's have them)"
            ),
            ArrowError::NoProperty { stem, have } => write!(
                f,
                "no per-atom properties {stem}x {stem}y {stem}z, {stem}[1] {stem}[2] {stem}[3] or {stem}_x {stem}_y {stem}_z in the frame (it has: {})",
                if have.is_empty() {
                    "none".to_string()
                } else {
                    have.join(", ")
                }
            ),
            ArrowError::AtomCount { reference, frame } => write!(
                f,
                "displacements need the same atoms in every frame: the first frame had {reference}, this one {frame}"
            ),
            ArrowError::BadOption { what, value } => {
                write!(
                    f,
                    "the arrows' {what} must be a finite number > 0, got {value}"
                )
            }
        }
    }
}

impl std::error::Error for ArrowError {}

impl ArrowOptions {
    /// Checks the scale and radius.
    pub fn check(&self) -> Result<(), ArrowError> {
        for (what, value) in [("scale", self.scale), ("radius", self.radius)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(ArrowError::BadOption { what, value });
            }
        }
        Ok(())
    }
}

/// The vector of every atom of `frame` from `source`; `reference` is the first frame's
/// positions for [`ArrowSource::Displacement`] (none: zero displacements, the first frame).
pub fn vectors(
    frame: &Frame,
    source: &ArrowSource,
    reference: Option<&[[f32; 3]]>,
) -> Result<Vec<Vec3>, ArrowError> {
    let n = frame.n_atoms();
    match source {
        ArrowSource::Velocity => {
            if frame.velocities.len() != n || n == 0 {
                return Err(ArrowError::NoVelocities);
            }
            Ok(frame.velocities.iter().map(|v| Vec3::from(*v)).collect())
        }
        ArrowSource::Displacement => {
            let Some(reference) = reference else {
                return Ok(vec![Vec3::ZERO; n]);
            };
            if reference.len() != n {
                return Err(ArrowError::AtomCount {
                    reference: reference.len(),
                    frame: n,
                });
            }
            Ok(frame
                .positions
                .iter()
                .zip(reference)
                .map(|(p, r)| {
                    let mut d: [f64; 3] = std::array::from_fn(|k| p[k] as f64 - r[k] as f64);
                    if let Some(cell) = &frame.cell {
                        d = texmap_md_io::pbc::minimum_image(cell, d);
                    }
                    glam::DVec3::from_array(d).as_vec3()
                })
                .collect())
        }
        ArrowSource::Property(stem) => {
            let find = |name: String| frame.properties.iter().find(|p| p.name == name);
            let forms = [
                ["x", "y", "z"].map(|c| format!("{stem}{c}")),
                ["[1]", "[2]", "[3]"].map(|c| format!("{stem}{c}")),
                ["_x", "_y", "_z"].map(|c| format!("{stem}{c}")),
            ];
            for names in forms {
                let [Some(x), Some(y), Some(z)] = names.map(find) else {
                    continue;
                };
                return Ok((0..n)
                    .map(|i| Vec3::new(x.values[i], y.values[i], z.values[i]))
                    .collect());
            }
            Err(ArrowError::NoProperty {
                stem: stem.clone(),
                have: frame.properties.iter().map(|p| p.name.clone()).collect(),
            })
        }
    }
}

/// Appends the arrow from `from` along `v` (already scaled, Å) with shaft radius `radius` to
/// `mesh`, its triangles of material `kind`; false (nothing appended) for a zero or non-finite
/// vector.
pub fn append_arrow(mesh: &mut MolMesh, from: Vec3, v: Vec3, radius: f32, kind: u16) -> bool {
    let length = v.length();
    if !(length.is_finite() && length > 0.0 && from.is_finite()) {
        return false;
    }
    let dir = v / length;
    let head = (HEAD_LENGTH * radius).min(0.5 * length);
    let neck = from + dir * (length - head);
    let tip = from + v;
    let wide = HEAD_WIDTH * radius;
    // (u, w, dir) right-handed: angles grow counter-clockwise seen from the tip.
    let u = dir.any_orthonormal_vector();
    let w = dir.cross(u);
    let ring = |k: usize| {
        let t = std::f32::consts::TAU * k as f32 / ARROW_SEGMENTS as f32;
        u * t.cos() + w * t.sin()
    };
    let mut push = |p: Vec3, n: Vec3| {
        mesh.positions.push(p);
        mesh.normals.push(n);
        mesh.positions.len() as u32 - 1
    };
    let mut tris = Vec::with_capacity(6 * ARROW_SEGMENTS);
    // The base disc, facing back.
    let c = push(from, -dir);
    let base: Vec<u32> = (0..ARROW_SEGMENTS)
        .map(|k| push(from + ring(k) * radius, -dir))
        .collect();
    // The shaft's side, normals radial.
    let low: Vec<u32> = (0..ARROW_SEGMENTS)
        .map(|k| push(from + ring(k) * radius, ring(k)))
        .collect();
    let high: Vec<u32> = (0..ARROW_SEGMENTS)
        .map(|k| push(neck + ring(k) * radius, ring(k)))
        .collect();
    // The head's back, an annulus facing back.
    let inner: Vec<u32> = (0..ARROW_SEGMENTS)
        .map(|k| push(neck + ring(k) * radius, -dir))
        .collect();
    let outer: Vec<u32> = (0..ARROW_SEGMENTS)
        .map(|k| push(neck + ring(k) * wide, -dir))
        .collect();
    // The cone, normals across its side; one tip vertex per side, with that side's normal.
    let slope = wide / head;
    let cone_normal = |k: usize| (ring(k) + dir * slope).normalize();
    let rim: Vec<u32> = (0..ARROW_SEGMENTS)
        .map(|k| push(neck + ring(k) * wide, cone_normal(k)))
        .collect();
    let tips: Vec<u32> = (0..ARROW_SEGMENTS)
        .map(|k| {
            let mid = (ring(k) + ring(k + 1)).normalize() + dir * slope;
            push(tip, mid.normalize())
        })
        .collect();
    for k in 0..ARROW_SEGMENTS {
        let j = (k + 1) % ARROW_SEGMENTS;
        // Counter-clockwise seen from outside: the base disc seen from behind.
        tris.push([c, base[j], base[k]]);
        tris.push([low[k], low[j], high[j]]);
        tris.push([low[k], high[j], high[k]]);
        tris.push([inner[k], inner[j], outer[j]]);
        tris.push([inner[k], outer[j], outer[k]]);
        tris.push([rim[k], rim[j], tips[k]]);
    }
    for t in tris {
        mesh.triangles.push(t);
        mesh.kinds.push(kind);
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use texmap_md_io::{Property, UnitCell};

    fn area_ngon(r: f64) -> f64 {
        let n = ARROW_SEGMENTS as f64;
        0.5 * n * r * r * (std::f64::consts::TAU / n).sin()
    }

    #[test]
    fn an_arrow_is_a_closed_solid_of_the_analytic_volume_ending_at_the_tip() {
        let from = Vec3::new(1.0, -2.0, 0.5);
        let v = Vec3::new(3.0, 4.0, -12.0); // 13 Å
        let r = 0.2;
        let mut mesh = MolMesh::default();
        assert!(append_arrow(&mut mesh, from, v, r, 7));
        assert!(mesh.kinds.iter().all(|k| *k == 7));
        // The tip is the farthest point along the vector, exactly at from + v.
        let dir = v.normalize();
        let far = mesh
            .positions
            .iter()
            .map(|p| (*p - from).dot(dir))
            .fold(f32::MIN, f32::max);
        assert!((far - 13.0).abs() < 1e-4, "{far}");
        // Volume: an n-gon prism and an n-gon pyramid (the divergence theorem over the
        // triangles needs them closed and wound outwards).
        let head = (HEAD_LENGTH * r) as f64;
        let want =
            area_ngon(r as f64) * (13.0 - head) + area_ngon((HEAD_WIDTH * r) as f64) * head / 3.0;
        let got = mesh.volume();
        assert!((got - want).abs() < 1e-4 * want, "{got} vs {want}");
        // Every vertex within the head's radius of the axis.
        for p in &mesh.positions {
            let d = *p - from;
            let radial = (d - dir * d.dot(dir)).length();
            assert!(radial <= HEAD_WIDTH * r + 1e-5);
        }
        // A short arrow: the head takes half of it.
        let mut short = MolMesh::default();
        append_arrow(&mut short, Vec3::ZERO, Vec3::X * 0.5, r, 0);
        let want = area_ngon(r as f64) * 0.25 + area_ngon((HEAD_WIDTH * r) as f64) * 0.25 / 3.0;
        assert!((short.volume() - want).abs() < 1e-4 * want);
        // Nothing for a zero or non-finite vector.
        assert!(!append_arrow(&mut short, Vec3::ZERO, Vec3::ZERO, r, 0));
        assert!(!append_arrow(&mut short, Vec3::ZERO, Vec3::NAN, r, 0));
    }

    #[test]
    fn vectors_from_velocities_properties_and_displacements() {
        let mut f = Frame::new();
        f.positions = vec![[0.0, 0.0, 0.0], [9.5, 1.0, 1.0]];
        assert_eq!(
            vectors(&f, &ArrowSource::Velocity, None),
            Err(ArrowError::NoVelocities)
        );
        f.velocities = vec![[1.0, 2.0, 3.0], [0.0, 0.0, -1.0]];
        let v = vectors(&f, &ArrowSource::Velocity, None).unwrap();
        assert_eq!(v[1], Vec3::new(0.0, 0.0, -1.0));
        for (names, stem) in [
            (["fx", "fy", "fz"], "f"),
            (["c_d[1]", "c_d[2]", "c_d[3]"], "c_d"),
            (["force_x", "force_y", "force_z"], "force"),
        ] {
            let mut g = f.clone();
            for (k, n) in names.iter().enumerate() {
                g.properties.push(Property {
                    name: n.to_string(),
                    values: vec![k as f32, 10.0 + k as f32],
                });
            }
            let v = vectors(&g, &ArrowSource::Property(stem.into()), None).unwrap();
            assert_eq!(v, [Vec3::new(0.0, 1.0, 2.0), Vec3::new(10.0, 11.0, 12.0)]);
            let e = vectors(&g, &ArrowSource::Property("q".into()), None).unwrap_err();
            assert!(e.to_string().contains(names[0]), "{e}");
        }
        // Displacements through a 10 Å box: the second atom moved from 0.5 to 9.5 along x,
        // which is 1 Å backwards through the face.
        let reference = [[0.0, 0.0, 0.0], [0.5, 1.0, 1.0]];
        f.cell = Some(UnitCell::orthorhombic(10.0, 10.0, 10.0).unwrap());
        let d = vectors(&f, &ArrowSource::Displacement, Some(&reference)).unwrap();
        assert!(
            (d[1] - Vec3::new(-1.0, 0.0, 0.0)).length() < 1e-6,
            "{:?}",
            d[1]
        );
        f.cell = None;
        let d = vectors(&f, &ArrowSource::Displacement, Some(&reference)).unwrap();
        assert!((d[1] - Vec3::new(9.0, 0.0, 0.0)).length() < 1e-6);
        let e = vectors(&f, &ArrowSource::Displacement, Some(&reference[..1])).unwrap_err();
        assert!(matches!(
            e,
            ArrowError::AtomCount {
                reference: 1,
                frame: 2
            }
        ));
    }
}

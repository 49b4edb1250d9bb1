//! Built-in shapes as [`TriMesh`]es: the scene objects and tessellated targets the crate needs
//! without a file. Every mesh is closed where the shape is, wound counter-clockwise seen from
//! outside (the tunnel: seen from inside) and carries unit vertex normals.

use glam::{Quat, Vec3};
use texmap_mesh::TriMesh;

/// Build a mesh from parts whose indices are in range by construction.
fn mesh(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>, normals: Vec<Vec3>) -> TriMesh {
    TriMesh {
        positions,
        triangles,
        uvs: None,
        normals: Some(normals),
    }
}

/// A latitude-longitude sphere: `segments` around (≥ 3), `rings` from pole to pole (≥ 2).
pub fn uv_sphere(centre: Vec3, radius: f32, segments: u32, rings: u32) -> TriMesh {
    let (segments, rings) = (segments.max(3), rings.max(2));
    let mut pos = Vec::new();
    let mut nrm = Vec::new();
    for j in 0..=rings {
        let th = std::f32::consts::PI * j as f32 / rings as f32;
        for i in 0..=segments {
            let ph = std::f32::consts::TAU * i as f32 / segments as f32;
            let n = Vec3::new(th.sin() * ph.cos(), th.cos(), -th.sin() * ph.sin());
            pos.push(centre + n * radius);
            nrm.push(n);
        }
    }
    let row = segments + 1;
    let mut tris = Vec::new();
    for j in 0..rings {
        for i in 0..segments {
            let a = j * row + i;
            let b = a + row;
            if j != 0 {
                tris.push([a, b, a + 1]);
            }
            if j != rings - 1 {
                tris.push([a + 1, b, b + 1]);
            }
        }
    }
    mesh(pos, tris, nrm)
}

/// An axis-aligned box between `lo` and `hi`, rotated by `rot` about its centre (flat faces:
/// four vertices per face).
pub fn cuboid(lo: Vec3, hi: Vec3, rot: Quat) -> TriMesh {
    let c = (lo + hi) * 0.5;
    let h = (hi - lo) * 0.5;
    let mut pos = Vec::new();
    let mut nrm = Vec::new();
    let mut tris = Vec::new();
    for axis in 0..3 {
        for s in [-1.0f32, 1.0] {
            let mut n = Vec3::ZERO;
            n[axis] = s;
            let u = Vec3::from_array(std::array::from_fn(|k| {
                if k == (axis + 1) % 3 { 1.0 } else { 0.0 }
            }));
            let v = n.cross(u);
            let base = pos.len() as u32;
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                let p = n * h + u * (a * h) + v * (b * h);
                pos.push(c + rot * p);
                nrm.push(rot * n);
            }
            tris.push([base, base + 1, base + 2]);
            tris.push([base, base + 2, base + 3]);
        }
    }
    mesh(pos, tris, nrm)
}

/// A torus around `axis` (unit) through `centre`: tube radius `r` at distance `big_r`,
/// `segments` around the axis and `sides` around the tube.
pub fn torus(centre: Vec3, axis: Vec3, big_r: f32, r: f32, segments: u32, sides: u32) -> TriMesh {
    let (segments, sides) = (segments.max(3), sides.max(3));
    let rot = Quat::from_rotation_arc(Vec3::Y, axis.normalize_or(Vec3::Y));
    let mut pos = Vec::new();
    let mut nrm = Vec::new();
    for i in 0..segments {
        let ph = std::f32::consts::TAU * i as f32 / segments as f32;
        let radial = Vec3::new(ph.cos(), 0.0, -ph.sin());
        for j in 0..sides {
            let th = std::f32::consts::TAU * j as f32 / sides as f32;
            let n = radial * th.cos() + Vec3::Y * th.sin();
            pos.push(centre + rot * (radial * big_r + n * r));
            nrm.push(rot * n);
        }
    }
    let mut tris = Vec::new();
    for i in 0..segments {
        for j in 0..sides {
            let a = i * sides + j;
            let b = ((i + 1) % segments) * sides + j;
            let a1 = i * sides + (j + 1) % sides;
            let b1 = ((i + 1) % segments) * sides + (j + 1) % sides;
            tris.push([a, b, b1]);
            tris.push([a, b1, a1]);
        }
    }
    mesh(pos, tris, nrm)
}

/// The wall of a tunnel along z: a cylinder of `radius` from `z0` to `z1`, `segments` around and
/// `rings` along, split into `stripes` meshes of alternating rings (so that two materials draw a
/// striped tunnel), normals pointing inward.
pub fn tunnel(
    radius: f32,
    z0: f32,
    z1: f32,
    segments: u32,
    rings: u32,
    stripes: u32,
) -> Vec<TriMesh> {
    let (segments, rings, stripes) = (segments.max(3), rings.max(1), stripes.max(1));
    let mut out = vec![TriMesh::default(); stripes as usize];
    for k in 0..rings {
        let m = &mut out[(k % stripes) as usize];
        let za = z0 + (z1 - z0) * k as f32 / rings as f32;
        let zb = z0 + (z1 - z0) * (k + 1) as f32 / rings as f32;
        let base = m.positions.len() as u32;
        let normals = m.normals.get_or_insert_with(Vec::new);
        for i in 0..=segments {
            let ph = std::f32::consts::TAU * i as f32 / segments as f32;
            let n = Vec3::new(-ph.cos(), -ph.sin(), 0.0);
            for z in [za, zb] {
                m.positions
                    .push(Vec3::new(ph.cos() * radius, ph.sin() * radius, z));
                normals.push(n);
            }
        }
        for i in 0..segments {
            let a = base + 2 * i;
            // Seen from the axis (inside), counter-clockwise.
            m.triangles.push([a, a + 1, a + 2]);
            m.triangles.push([a + 1, a + 3, a + 2]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(m: &TriMesh) {
        m.validate("test", 0).unwrap();
        let n = m.normals.as_ref().unwrap();
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            let face = (b - a).cross(c - a);
            if face.length() < 1e-9 {
                continue;
            }
            // The winding agrees with the stated normal (outside, or inside for the tunnel).
            let vn = n[t[0] as usize] + n[t[1] as usize] + n[t[2] as usize];
            assert!(
                face.dot(vn) > 0.0,
                "triangle {t:?} wound against its normals"
            );
        }
    }

    #[test]
    fn shapes_are_valid_and_wound_with_their_normals() {
        check(&uv_sphere(Vec3::ONE, 2.0, 16, 8));
        check(&cuboid(Vec3::ZERO, Vec3::ONE, Quat::from_rotation_y(0.3)));
        check(&torus(Vec3::ZERO, Vec3::X, 2.0, 0.5, 12, 8));
        for m in tunnel(4.0, -10.0, 10.0, 16, 6, 2) {
            check(&m);
        }
        // Sphere vertices lie on the sphere.
        let s = uv_sphere(Vec3::ONE, 2.0, 16, 8);
        assert!(
            s.positions
                .iter()
                .all(|p| ((*p - Vec3::ONE).length() - 2.0).abs() < 1e-5)
        );
    }
}

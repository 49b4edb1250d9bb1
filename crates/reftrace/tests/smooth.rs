//! Smooth shading of meshes (interpolated vertex normals) against an analytic surface: a finely
//! tessellated sphere, whose true normal at any point is the radial direction.

use texmap_core::camera::{Camera, Ray};
use texmap_core::shade::{Lighting, Material};
use texmap_reftrace::glam::Vec3;
use texmap_reftrace::{MeshShading, RenderOptions, SceneBuilder, SceneError, SurfaceMaterial};

/// Deterministic LCG for ray generation.
struct Lcg(u64);
impl Lcg {
    fn f(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32) / (1u64 << 24) as f32
    }
    fn vec(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.f(), self.f(), self.f()) * (hi - lo) + Vec3::splat(lo)
    }
}

const CENTER: Vec3 = Vec3::new(0.3, -0.2, 0.1);
const RADIUS: f32 = 1.5;

/// A UV sphere with shared vertices (one vertex per pole, the seam closed by index), `lon`
/// segments around and `lat` from pole to pole: positions, indices and the exact normals.
fn uv_sphere(lon: u32, lat: u32) -> (Vec<Vec3>, Vec<u32>, Vec<Vec3>) {
    let mut dirs = vec![Vec3::Y];
    for j in 1..lat {
        let th = std::f64::consts::PI * j as f64 / lat as f64;
        for i in 0..lon {
            let ph = std::f64::consts::TAU * i as f64 / lon as f64;
            dirs.push(Vec3::new(
                (th.sin() * ph.cos()) as f32,
                th.cos() as f32,
                (th.sin() * ph.sin()) as f32,
            ));
        }
    }
    dirs.push(Vec3::NEG_Y);
    let south = dirs.len() as u32 - 1;
    let ring = |j: u32, i: u32| 1 + (j - 1) * lon + (i % lon);
    let mut idx = Vec::new();
    for i in 0..lon {
        idx.extend([0, ring(1, i + 1), ring(1, i)]);
        idx.extend([south, ring(lat - 1, i), ring(lat - 1, i + 1)]);
    }
    for j in 1..lat - 1 {
        for i in 0..lon {
            let (a, b, c, d) = (
                ring(j, i),
                ring(j, i + 1),
                ring(j + 1, i),
                ring(j + 1, i + 1),
            );
            idx.extend([a, b, c, b, d, c]);
        }
    }
    let pos = dirs.iter().map(|d| CENTER + *d * RADIUS).collect();
    (pos, idx, dirs)
}

/// Largest and mean angle (radians) between the hit's shading normal and the radial direction
/// of the hit point, over rays aimed at the sphere from outside.
fn normal_error(shading: MeshShading, with_normals: bool) -> (f32, f32, usize) {
    let (pos, idx, nrm) = uv_sphere(96, 48);
    let mut b = SceneBuilder::new();
    let normals = with_normals.then_some(&nrm[..]);
    b.add_mesh_shaded(&pos, &idx, None, normals, shading, 0)
        .unwrap();
    let scene = b.build();
    let mut rng = Lcg(5);
    let (mut max, mut sum, mut hits) = (0.0f32, 0.0f64, 0usize);
    for _ in 0..20_000 {
        let origin = CENTER + rng.vec(-1.0, 1.0).normalize_or(Vec3::X) * 6.0;
        let target = CENTER + rng.vec(-1.0, 1.0) * RADIUS * 0.9;
        let ray = Ray {
            origin,
            dir: (target - origin).normalize(),
        };
        let Some(h) = scene.intersect(&ray) else {
            continue;
        };
        hits += 1;
        assert!(
            (h.shading_normal.length() - 1.0).abs() < 1e-5,
            "shading normal not unit: {}",
            h.shading_normal
        );
        let truth = (h.point - CENTER).normalize();
        // atan2(|a × b|, a · b): accurate for small angles, where acos(a · b) is not.
        let n = h.shading_normal;
        let angle = n.cross(truth).length().atan2(n.dot(truth));
        max = max.max(angle);
        sum += angle as f64;
    }
    (max, (sum / hits as f64) as f32, hits)
}

#[test]
fn interpolated_normals_follow_the_analytic_sphere_and_flat_ones_do_not() {
    // With the exact vertex normals n_i = (v_i − c)/r, the interpolated Σ b_i n_i equals
    // (p − c)/r for the hit point p = Σ b_i v_i: the radial direction of p, to rounding.
    let (smooth_max, smooth_mean, hits) = normal_error(MeshShading::VertexNormals, true);
    assert!(hits > 15_000, "only {hits} hits");
    let tol = 1e-4; // f32 rounding of normals, barycentrics and the point: ~1e-6 rad.
    assert!(
        smooth_max < tol,
        "given normals: expected angle < {tol} rad, got max {smooth_max} (mean {smooth_mean})"
    );
    // Averaged face normals: not exact at the vertices, but within a small angle. The UV
    // sphere's angular step is 3.75° (0.065 rad); the bound 0.01 rad (0.57°) is a sixth of it.
    let (avg_max, avg_mean, _) = normal_error(MeshShading::VertexNormalsOrAveraged, false);
    let tol = 0.01;
    assert!(
        avg_max < tol,
        "averaged normals: expected angle < {tol} rad, got max {avg_max} (mean {avg_mean})"
    );
    // Flat shading: up to about half a facet's angular size off, so the test discriminates.
    let (flat_max, flat_mean, _) = normal_error(MeshShading::Flat, true);
    assert!(
        flat_max > 0.02 && flat_mean > 10.0 * avg_mean,
        "flat shading should deviate: max {flat_max}, mean {flat_mean} (averaged mean {avg_mean})"
    );
    eprintln!(
        "angle to the true normal (rad): given max {smooth_max:.2e} mean {smooth_mean:.2e}; averaged max {avg_max:.2e} mean {avg_mean:.2e}; flat max {flat_max:.2e} mean {flat_mean:.2e}"
    );
    // VertexNormals without normals is flat shading.
    let (none_max, _, _) = normal_error(MeshShading::VertexNormals, false);
    assert_eq!(
        none_max, flat_max,
        "VertexNormals without normals must be flat"
    );
}

/// Mean and max absolute difference (8-bit codes, over channels of pixels where both images
/// hit) between a render of the mesh and one of the analytic sphere.
fn image_error(shading: MeshShading) -> (f64, u8) {
    let (pos, idx, nrm) = uv_sphere(96, 48);
    let cam = Camera::perspective_look_at(
        CENTER + Vec3::new(1.0, 0.8, 3.0).normalize() * 6.0,
        CENTER,
        Vec3::Y,
        40.0,
        160,
        120,
    )
    .unwrap();
    let mats = [SurfaceMaterial::opaque(Material::plastic(Vec3::new(
        0.7, 0.5, 0.3,
    )))];
    let opts = RenderOptions::new(Lighting::default_for(&cam), &mats);
    let mut m = SceneBuilder::new();
    m.add_mesh_shaded(&pos, &idx, None, Some(&nrm), shading, 0)
        .unwrap();
    let mesh = m.build().render(&cam, &opts).unwrap();
    let mut s = SceneBuilder::new();
    s.add_sphere(CENTER, RADIUS, 0);
    let sphere = s.build().render(&cam, &opts).unwrap();
    let (mut sum, mut n, mut max) = (0u64, 0u64, 0u8);
    for k in 0..mesh.color.len() {
        if mesh.depth[k].is_finite() && sphere.depth[k].is_finite() {
            for c in 0..3 {
                let d = mesh.color[k][c].abs_diff(sphere.color[k][c]);
                sum += d as u64;
                n += 1;
                max = max.max(d);
            }
        }
    }
    assert!(n > 3 * 5000, "too few common pixels: {}", n / 3);
    (sum as f64 / n as f64, max)
}

#[test]
fn smooth_mesh_renders_like_the_analytic_sphere() {
    let (smooth_mean, smooth_max) = image_error(MeshShading::VertexNormals);
    let (flat_mean, flat_max) = image_error(MeshShading::Flat);
    eprintln!(
        "smooth mean {smooth_mean:.3} max {smooth_max}; flat mean {flat_mean:.3} max {flat_max}"
    );
    // Shading depends only on the normal and the ray: the mesh's hit lies on a chord up to
    // r·(1 − cos 1.9°) ≈ 5e-4 r inside the sphere, so the radial directions of the two hits
    // differ little except near the silhouette, where a ray meets chord and sphere up to
    // √(2·5e-4) ≈ 0.03 rad apart.
    assert!(
        smooth_mean < 0.25 && smooth_max <= 6,
        "smooth: expected mean < 0.25 and max ≤ 6 codes, got mean {smooth_mean:.3}, max {smooth_max}"
    );
    assert!(
        flat_mean > 4.0 * smooth_mean && flat_max > smooth_max,
        "flat should be visibly worse: flat mean {flat_mean:.3} max {flat_max}, smooth mean {smooth_mean:.3} max {smooth_max}"
    );
}

#[test]
fn bad_or_unusable_normals_are_refused_or_fall_back_never_nan() {
    let (pos, idx, mut nrm) = uv_sphere(16, 8);
    let mut b = SceneBuilder::new();
    assert_eq!(
        b.add_mesh_shaded(
            &pos,
            &idx,
            None,
            Some(&nrm[1..]),
            MeshShading::VertexNormals,
            0
        ),
        Err(SceneError::NormalCountMismatch {
            normals: nrm.len() - 1,
            vertices: pos.len()
        })
    );
    // Zero, NaN and infinite normals: the shading normal falls back to the geometric one
    // where needed and is always a finite unit vector.
    for (k, n) in nrm.iter_mut().enumerate() {
        match k % 4 {
            0 => *n = Vec3::ZERO,
            1 => *n = Vec3::NAN,
            2 => *n = Vec3::splat(f32::INFINITY),
            _ => *n *= 7.0,
        }
    }
    b.add_mesh_shaded(&pos, &idx, None, Some(&nrm), MeshShading::VertexNormals, 0)
        .unwrap();
    let scene = b.build();
    let mut rng = Lcg(8);
    let mut hits = 0;
    for _ in 0..5000 {
        let origin = CENTER + rng.vec(-1.0, 1.0).normalize_or(Vec3::X) * 6.0;
        let dir = (CENTER + rng.vec(-1.0, 1.0) - origin).normalize();
        if let Some(h) = scene.intersect(&Ray { origin, dir }) {
            hits += 1;
            let n = h.shading_normal;
            assert!(
                n.is_finite() && (n.length() - 1.0).abs() < 1e-5,
                "bad shading normal {n}"
            );
            assert!(n.dot(h.normal) >= 0.0, "shading normal on the other side");
        }
    }
    assert!(hits > 1000);
}

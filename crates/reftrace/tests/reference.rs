//! End-to-end checks of the reference ray tracer through its public API only: BVH against brute
//! force, analytic silhouettes and depths, watertightness, degenerate input, determinism, optics
//! and the texture reference.

use texmap_core::camera::{Camera, Ray};
use texmap_core::color::linear_to_srgb8_fast;
use texmap_core::shade::{Lighting, Material};
use texmap_reftrace::glam::{DVec3, Vec2, Vec3};
use texmap_reftrace::{
    BvhKind, CylinderPart, HitKind, RenderError, RenderOptions, Scene, SceneBuilder,
    SurfaceMaterial, Texture,
};

/// Deterministic LCG for scene generation.
struct Lcg(u64);
impl Lcg {
    fn f(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32) / (1u64 << 24) as f32
    }
    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.f()
    }
    fn vec(&mut self, lo: f32, hi: f32) -> Vec3 {
        Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
    }
}

fn random_scene(seed: u64, kind: BvhKind) -> Scene {
    let mut rng = Lcg(seed);
    let mut b = SceneBuilder::new().bvh(kind);
    for k in 0..2000 {
        b.add_sphere(rng.vec(-10.0, 10.0), rng.range(0.05, 0.6), k % 3);
    }
    for k in 0..300 {
        let a = rng.vec(-10.0, 10.0);
        b.add_cylinder(a, a + rng.vec(-1.5, 1.5), rng.range(0.05, 0.3), k % 3);
    }
    let mut pos = Vec::new();
    let mut idx = Vec::new();
    for t in 0..1500u32 {
        let c = rng.vec(-10.0, 10.0);
        pos.extend([c, c + rng.vec(-1.0, 1.0), c + rng.vec(-1.0, 1.0)]);
        idx.extend([3 * t, 3 * t + 1, 3 * t + 2]);
    }
    b.add_mesh(&pos, &idx, None, 2).unwrap();
    b.build()
}

fn unlit_lighting() -> Lighting {
    // Ambient 1, no lights: a matte surface shows exactly its (textured) base colour.
    Lighting::new(Vec3::ONE, &[]).unwrap()
}

#[test]
fn bvh_traversal_equals_brute_force_on_random_scenes() {
    for kind in [BvhKind::Bvh2, BvhKind::CwBvh, BvhKind::Wide4] {
        let scene = random_scene(42, kind);
        let mut rng = Lcg(9);
        let (mut hits, mut kinds) = (0, [0usize; 3]);
        for _ in 0..20_000 {
            let origin = rng.vec(-14.0, 14.0);
            let dir = rng.vec(-1.0, 1.0).normalize_or(Vec3::X);
            let ray = Ray { origin, dir };
            let a = scene.intersect(&ray);
            let b = scene.intersect_brute_force(&ray);
            assert_eq!(
                a.map(|h| (h.t, h.prim_id, h.kind)),
                b.map(|h| (h.t, h.prim_id, h.kind)),
                "{kind:?}: BVH and brute force disagree for {ray:?}"
            );
            if let Some(h) = a {
                hits += 1;
                kinds[match h.kind {
                    HitKind::Sphere => 0,
                    HitKind::Cylinder { .. } => 1,
                    HitKind::Triangle { .. } => 2,
                }] += 1;
            }
        }
        assert!(
            hits > 5000 && kinds.iter().all(|&k| k > 300),
            "{kind:?}: too few hits to be a test: {hits}, per kind {kinds:?}"
        );
    }
}

#[test]
fn sphere_only_scenes_match_brute_force_in_every_layout() {
    // Sphere-only scenes take the sphere kernel of the 4-wide traversal; sizes 1..=3000 cover a
    // root that is a single leaf, a root with empty lanes and a deep tree. Rays: random, and
    // axis-parallel rays (two zero direction components) through sphere centres and along
    // sphere tangent planes, where the slab test meets 0·∞.
    for count in [1usize, 2, 5, 37, 3000] {
        for kind in [BvhKind::Bvh2, BvhKind::CwBvh, BvhKind::Wide4] {
            let mut rng = Lcg(100 + count as u64);
            let mut b = SceneBuilder::new().bvh(kind);
            let mut spheres = Vec::new();
            for _ in 0..count {
                let (c, r) = (rng.vec(-10.0, 10.0), rng.range(0.05, 1.0));
                b.add_sphere(c, r, 0);
                spheres.push((c, r));
            }
            let scene = b.build();
            let mut rays = Vec::new();
            for _ in 0..4000 {
                let origin = rng.vec(-14.0, 14.0);
                rays.push(Ray {
                    origin,
                    dir: rng.vec(-1.0, 1.0).normalize_or(Vec3::X),
                });
            }
            for &(c, r) in spheres.iter().take(300) {
                for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
                    let side = if axis == Vec3::X { Vec3::Y } else { Vec3::X };
                    for off in [Vec3::ZERO, side * r, side * (r * 0.999)] {
                        rays.push(Ray {
                            origin: c + off - axis * 20.0,
                            dir: axis,
                        });
                        rays.push(Ray {
                            origin: c + off + axis * 20.0,
                            dir: -axis,
                        });
                    }
                }
            }
            let (mut hits, mut wrong) = (0, Vec::new());
            for ray in &rays {
                let a = scene.intersect(ray).map(|h| (h.t, h.prim_id));
                let b = scene.intersect_brute_force(ray).map(|h| (h.t, h.prim_id));
                if a != b {
                    wrong.push((ray, a, b));
                }
                hits += a.is_some() as usize;
            }
            eprintln!(
                "{kind:?}, {count} spheres: {} of {} disagree",
                wrong.len(),
                rays.len()
            );
            if kind != BvhKind::CwBvh {
                assert!(
                    wrong.is_empty(),
                    "{kind:?}, {count} spheres: BVH and brute force disagree for {} rays, first {:?}",
                    wrong.len(),
                    wrong.first()
                );
            }
            assert!(hits > 0, "{kind:?}, {count} spheres: no ray hit");
        }
    }
}

#[test]
fn sphere_silhouette_is_the_exact_perspective_ellipse_and_depth_is_analytic() {
    // An off-axis sphere: its image is an ellipse; a pixel centre is covered iff its ray's angle to
    // the centre direction is below asin(r / |c - eye|) (the analytic cone test, in f64).
    let eye = Vec3::new(0.3, -0.2, 9.0);
    let centre = Vec3::new(2.1, 1.3, -0.5);
    let r = 1.7f32;
    let cam = Camera::perspective_look_at(eye, Vec3::ZERO, Vec3::Y, 55.0, 320, 240).unwrap();
    let mut b = SceneBuilder::new();
    b.add_sphere(centre, r, 0);
    let scene = b.build();
    let mats = [SurfaceMaterial::opaque(Material::matte(Vec3::ONE))];
    let frame = scene
        .render(&cam, &RenderOptions::new(unlit_lighting(), &mats))
        .unwrap();
    let (ce, rd) = ((centre - eye).as_dvec3(), r as f64);
    let cos_cone = (1.0 - (rd / ce.length()).powi(2)).sqrt();
    let (mut covered, mut ambiguous) = (0, 0);
    for j in 0..240 {
        for i in 0..320 {
            let ray = cam.ray(i as f32 + 0.5, j as f32 + 0.5);
            let cosang = ray.dir.as_dvec3().normalize().dot(ce.normalize());
            let inside = cosang > cos_cone;
            let got = frame.depth[frame.index(i, j)].is_finite();
            // Pixel centres within 1e-6 rad of the cone are numerically ambiguous.
            if (cosang - cos_cone).abs() < 1e-6 {
                ambiguous += 1;
                continue;
            }
            assert_eq!(
                got, inside,
                "pixel ({i}, {j}): cone test says {inside}, reference says {got}"
            );
            covered += inside as usize;
        }
    }
    assert!(covered > 2000 && ambiguous < 10, "{covered} {ambiguous}");
    // Depth along the axis through the centre: |c − eye| − r, for an on-axis sphere.
    let cam2 = Camera::perspective_look_at(eye, centre, Vec3::Y, 40.0, 101, 101).unwrap();
    let f2 = scene
        .render(&cam2, &RenderOptions::new(unlit_lighting(), &mats))
        .unwrap();
    let want = ce.length() - rd;
    let got = f2.depth[f2.index(50, 50)] as f64;
    assert!(
        (got - want).abs() < 1e-5 * want,
        "centre depth: expected {want}, got {got}, tolerance {}",
        1e-5 * want
    );
    // Every covered pixel's depth equals the analytic first hit (f64) times cos to the axis.
    let fwd = cam2.forward().as_dvec3();
    for j in 0..101 {
        for i in 0..101 {
            let d = f2.depth[f2.index(i, j)];
            if !d.is_finite() {
                continue;
            }
            let ray = cam2.ray(i as f32 + 0.5, j as f32 + 0.5);
            let dir = ray.dir.as_dvec3();
            let f = eye.as_dvec3() - centre.as_dvec3();
            let bq = dir.dot(f);
            let disc = bq * bq - dir.dot(dir) * (f.dot(f) - rd * rd);
            let t = (-bq - disc.max(0.0).sqrt()) / dir.dot(dir);
            let want = t * dir.dot(fwd);
            assert!(
                (d as f64 - want).abs() < 2e-5 * want,
                "pixel ({i},{j}): expected depth {want}, got {d}, tolerance {}",
                2e-5 * want
            );
        }
    }
}

#[test]
fn capped_cylinder_seen_side_on_covers_its_rectangle_and_caps_face_the_axis() {
    // Orthographic view perpendicular to a cylinder along x: coverage is the rectangle
    // |x| <= L/2, |y| <= r exactly, and depth is the distance to the front of the side.
    let (half_len, r) = (3.0f32, 1.25f32);
    let mut b = SceneBuilder::new();
    b.add_cylinder(
        Vec3::new(-half_len, 0.0, 0.0),
        Vec3::new(half_len, 0.0, 0.0),
        r,
        0,
    );
    let scene = b.build();
    let cam =
        Camera::orthographic_look_at(Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO, Vec3::Y, 8.0, 160, 80)
            .unwrap();
    let mats = [SurfaceMaterial::opaque(Material::matte(Vec3::ONE))];
    let f = scene
        .render(&cam, &RenderOptions::new(unlit_lighting(), &mats))
        .unwrap();
    let px = 8.0 / 160.0;
    for j in 0..80 {
        for i in 0..160 {
            let x = (i as f32 + 0.5 - 80.0) * px;
            let y = (40.0 - (j as f32 + 0.5)) * px;
            let inside = x.abs() < half_len && y.abs() < r;
            let got = f.depth[f.index(i, j)];
            assert_eq!(got.is_finite(), inside, "pixel ({i},{j}) at ({x},{y})");
            if inside {
                let want = 10.0 - (r * r - y * y).sqrt();
                assert!(
                    (got - want).abs() < 1e-5 * 10.0,
                    "({i},{j}): expected {want}, got {got}"
                );
            }
        }
    }
    // A ray along the axis hits cap A first, with normal −axis.
    let h = scene
        .intersect(&Ray {
            origin: Vec3::new(-10.0, 0.3, 0.2),
            dir: Vec3::X,
        })
        .unwrap();
    assert_eq!(
        h.kind,
        HitKind::Cylinder {
            part: CylinderPart::CapA
        }
    );
    assert!(
        (h.t - 7.0).abs() < 1e-5 && (h.normal - Vec3::NEG_X).length() < 1e-6,
        "{h:?}"
    );
}

/// The analytic height the heightfield samples.
fn height(x: f32, z: f32) -> f32 {
    0.05 * (x * 17.0).sin() * (z * 13.0).cos() + 0.02 * ((x + z) * 41.0).sin()
}

/// A heightfield of `n x n` vertices over [0, 1]², two triangles per cell sharing exact vertices.
fn heightfield(n: u32) -> (Vec<Vec3>, Vec<u32>) {
    let mut pos = Vec::with_capacity((n * n) as usize);
    for j in 0..n {
        for i in 0..n {
            let (x, z) = (i as f32 / (n - 1) as f32, j as f32 / (n - 1) as f32);
            pos.push(Vec3::new(x, height(x, z), z));
        }
    }
    let mut idx = Vec::with_capacity(((n - 1) * (n - 1) * 6) as usize);
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = j * n + i;
            let (b, c, d) = (a + 1, a + n, a + n + 1);
            idx.extend([a, c, b, b, c, d]);
        }
    }
    (pos, idx)
}

#[test]
fn heightfield_has_no_pinholes_at_grazing_and_steep_angles() {
    let n = 256;
    let (pos, idx) = heightfield(n);
    for kind in [BvhKind::Bvh2, BvhKind::CwBvh, BvhKind::Wide4] {
        let mut b = SceneBuilder::new().bvh(kind);
        b.add_mesh(&pos, &idx, None, 0).unwrap();
        let scene = b.build();
        assert_eq!(scene.stats().triangles, 2 * 255 * 255);
        let mut misses = 0;
        let mut rays = 0;
        // Rays aimed EXACTLY at every vertex and the midpoints of the grid edges (the shared edges
        // where non-watertight tests leak), from a steep and a grazing direction.
        let dirs = [
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(0.13, -1.0, 0.07).normalize(),
            Vec3::new(0.9, -0.12, 0.41).normalize(),
            Vec3::new(-0.3, -0.08, -0.95).normalize(),
        ];
        for (di, &dir) in dirs.iter().enumerate() {
            for j in 1..n - 1 {
                for i in 1..n - 1 {
                    // Skip most vertices for the slow grazing runs: every 3rd row and column.
                    if di >= 2 && (i % 3 != 0 || j % 3 != 0) {
                        continue;
                    }
                    let k = (j * n + i) as usize;
                    let targets = [
                        pos[k],
                        (pos[k] + pos[k + 1]) * 0.5,
                        (pos[k] + pos[k + n as usize]) * 0.5,
                        (pos[k] + pos[k + n as usize + 1]) * 0.5,
                    ];
                    for target in targets {
                        // The ray must CROSS the surface at the target (above it just before,
                        // below it just after); a ray that only touches a convex crest is a
                        // tangent, not a pinhole. The margin 1e-4 exceeds the mesh's deviation
                        // from the analytic height at this resolution (about 3e-5).
                        let (before, after) = (target - dir * 0.01, target + dir * 0.01);
                        if before.y < height(before.x, before.z) + 1e-4
                            || after.y > height(after.x, after.z) - 1e-4
                        {
                            continue;
                        }
                        let origin = target - dir * 0.01;
                        rays += 1;
                        if scene.intersect(&Ray { origin, dir }).is_none() {
                            misses += 1;
                        }
                    }
                }
            }
        }
        // Straight down, exactly on the grid lines (x = i/(n-1)): rays through edges and vertices.
        for j in 1..(n - 1) * 2 {
            for i in 1..(n - 1) * 2 {
                let x = i as f32 / (2 * (n - 1)) as f32;
                let z = j as f32 / (2 * (n - 1)) as f32;
                rays += 1;
                let ray = Ray {
                    origin: Vec3::new(x, 1.0, z),
                    dir: Vec3::NEG_Y,
                };
                if scene.intersect(&ray).is_none() {
                    misses += 1;
                }
            }
        }
        assert_eq!(misses, 0, "{kind:?}: {misses} pinholes out of {rays} rays");
        assert!(rays > 400_000, "{kind:?}: only {rays} rays tested");
    }
}

#[test]
fn degenerate_input_is_skipped_and_counted_never_nan() {
    let mut b = SceneBuilder::new();
    b.add_sphere(Vec3::ZERO, 1.0, 0);
    b.add_sphere(Vec3::ONE, 0.0, 0);
    b.add_sphere(Vec3::ONE, -1.0, 0);
    b.add_sphere(Vec3::ONE, f32::NAN, 0);
    b.add_sphere(Vec3::NAN, 1.0, 0);
    b.add_sphere(Vec3::splat(f32::INFINITY), 1.0, 0);
    b.add_cylinder(Vec3::ZERO, Vec3::ZERO, 1.0, 0);
    b.add_cylinder(Vec3::ZERO, Vec3::X, f32::NAN, 0);
    let pos = [Vec3::ZERO, Vec3::X, Vec3::X * 2.0, Vec3::NAN, Vec3::Y];
    // Collinear (zero area), repeated vertex, NaN vertex, and one good triangle.
    b.add_mesh(&pos, &[0, 1, 2, 0, 0, 1, 0, 3, 4, 0, 1, 4], None, 0)
        .unwrap();
    assert!(b.add_mesh(&pos, &[0, 1, 9], None, 0).is_err());
    assert!(b.add_mesh(&pos, &[0, 1], None, 0).is_err());
    assert!(
        b.add_mesh(&pos, &[0, 1, 2], Some(&[Vec2::ZERO]), 0)
            .is_err()
    );
    let scene = b.build();
    let s = scene.stats();
    assert_eq!((s.spheres, s.skipped_spheres), (1, 5), "{s:?}");
    assert_eq!((s.cylinders, s.skipped_cylinders), (0, 2), "{s:?}");
    assert_eq!((s.triangles, s.skipped_triangles), (1, 3), "{s:?}");
    let cam =
        Camera::perspective_look_at(Vec3::new(0.5, 0.5, 6.0), Vec3::ZERO, Vec3::Y, 60.0, 64, 64)
            .unwrap();
    let mats = [SurfaceMaterial::opaque(Material::plastic(Vec3::ONE))];
    let f = scene
        .render(
            &cam,
            &RenderOptions::new(Lighting::default_for(&cam), &mats),
        )
        .unwrap();
    assert!(f.depth.iter().all(|d| !d.is_nan()));
    assert!(f.coverage_count() > 100);
    // Bad rays miss instead of panicking.
    for ray in [
        Ray {
            origin: Vec3::NAN,
            dir: Vec3::X,
        },
        Ray {
            origin: Vec3::ZERO,
            dir: Vec3::ZERO,
        },
        Ray {
            origin: Vec3::ZERO,
            dir: Vec3::splat(f32::INFINITY),
        },
    ] {
        assert!(scene.intersect(&ray).is_none());
    }
    // The empty scene renders the background.
    let empty = SceneBuilder::new().build();
    let f = empty
        .render(&cam, &RenderOptions::new(Lighting::default_for(&cam), &[]))
        .unwrap();
    assert_eq!(f.coverage_count(), 0);
    assert!(
        empty
            .intersect(&Ray {
                origin: Vec3::ZERO,
                dir: Vec3::X
            })
            .is_none()
    );
    // Bad options are errors.
    let mut o = RenderOptions::new(Lighting::default_for(&cam), &mats);
    o.samples_per_axis = 0;
    assert!(matches!(
        scene.render(&cam, &o),
        Err(RenderError::BadSamples { .. })
    ));
    let o = RenderOptions::new(Lighting::default_for(&cam), &[]);
    assert!(matches!(
        scene.render(&cam, &o),
        Err(RenderError::MissingMaterial { .. })
    ));
    let bad = [SurfaceMaterial::mirror(Material::matte(Vec3::ONE), 1.5)];
    let o = RenderOptions::new(Lighting::default_for(&cam), &bad);
    assert!(matches!(
        scene.render(&cam, &o),
        Err(RenderError::BadMaterial { .. })
    ));
}

fn busy_scene() -> (Scene, Camera, Vec<SurfaceMaterial>) {
    let mut rng = Lcg(5);
    let mut b = SceneBuilder::new();
    for k in 0..3000 {
        b.add_sphere(rng.vec(-5.0, 5.0), rng.range(0.1, 0.5), k % 4);
    }
    let (pos, idx) = heightfield(64);
    let pos: Vec<Vec3> = pos
        .iter()
        .map(|p| *p * 12.0 - Vec3::new(6.0, 7.0, 6.0))
        .collect();
    b.add_mesh(&pos, &idx, None, 1).unwrap();
    let cam =
        Camera::perspective_look_at(Vec3::new(4.0, 6.0, 14.0), Vec3::ZERO, Vec3::Y, 50.0, 96, 72)
            .unwrap();
    let mats = vec![
        SurfaceMaterial::opaque(Material::plastic(Vec3::new(0.8, 0.3, 0.2))),
        SurfaceMaterial::mirror(Material::plastic(Vec3::new(0.2, 0.3, 0.8)), 0.5),
        SurfaceMaterial::refractive(1.5),
        SurfaceMaterial::opaque(Material::matte(Vec3::new(0.3, 0.9, 0.3))),
    ];
    (b.build(), cam, mats)
}

#[test]
fn depth_image_is_the_render_depth_buffer() {
    let (scene, cam, mats) = busy_scene();
    let mut opts = RenderOptions::new(Lighting::default_for(&cam), &mats);
    for n in [1, 2] {
        opts.samples_per_axis = n;
        let frame = scene.render(&cam, &opts).unwrap();
        let depth = scene.depth_image(&cam);
        assert_eq!(depth.len(), frame.depth.len());
        let same = depth
            .iter()
            .zip(&frame.depth)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(
            same,
            "depth_image differs from the render's depth ({n}x{n} samples)"
        );
        assert!(depth.iter().any(|d| d.is_finite()) && depth.iter().any(|d| d.is_infinite()));
    }
}

#[test]
fn render_is_byte_identical_for_one_and_two_threads() {
    let (scene, cam, mats) = busy_scene();
    let mut opts = RenderOptions::new(Lighting::default_for(&cam), &mats);
    opts.samples_per_axis = 2;
    let env = |d: Vec3| Vec3::new(0.5 + 0.5 * d.x, 0.5 + 0.5 * d.y, 0.3);
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| scene.render_with_environment(&cam, &opts, &env).unwrap())
    };
    let a = run(1);
    let b = run(2);
    assert!(a.coverage_count() > 1000);
    assert_eq!(a.color, b.color);
    assert_eq!(
        a.depth.iter().map(|d| d.to_bits()).collect::<Vec<_>>(),
        b.depth.iter().map(|d| d.to_bits()).collect::<Vec<_>>()
    );
    // A sphere-only scene (the sphere kernel of the 4-wide traversal) and the trace-only path.
    let mut rng = Lcg(77);
    let mut sb = SceneBuilder::new();
    for k in 0..5000 {
        sb.add_sphere(rng.vec(-5.0, 5.0), rng.range(0.05, 0.3), k % 4);
    }
    let spheres = sb.build();
    let pool = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
    };
    let (f1, d1) = pool(1).install(|| {
        (
            spheres.render(&cam, &opts).unwrap(),
            spheres.depth_image(&cam),
        )
    });
    let (f2, d2) = pool(2).install(|| {
        (
            spheres.render(&cam, &opts).unwrap(),
            spheres.depth_image(&cam),
        )
    });
    assert!(f1.coverage_count() > 1000);
    assert_eq!(f1.color, f2.color);
    let bits = |v: &[f32]| v.iter().map(|d| d.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&f1.depth), bits(&f2.depth));
    assert_eq!(bits(&d1), bits(&d2));
}

#[test]
fn mirror_sphere_shows_the_environment_in_the_reflected_direction() {
    // max_depth 0: every reflected ray takes env(r) with r = d − 2(d·n)n computed here in f64.
    let mut b = SceneBuilder::new();
    b.add_sphere(Vec3::ZERO, 1.0, 0);
    let scene = b.build();
    let cam =
        Camera::perspective_look_at(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, 40.0, 64, 64)
            .unwrap();
    let mats = [SurfaceMaterial::mirror(Material::matte(Vec3::ONE), 1.0)];
    let mut o = RenderOptions::new(unlit_lighting(), &mats);
    o.max_depth = 0;
    let env = |d: Vec3| (d + Vec3::ONE) * 0.5;
    let f = scene.render_with_environment(&cam, &o, &env).unwrap();
    let mut checked = 0;
    for j in 0..64 {
        for i in 0..64 {
            let k = f.index(i, j);
            if !f.depth[k].is_finite() {
                continue;
            }
            let ray = cam.ray(i as f32 + 0.5, j as f32 + 0.5);
            let (o64, d64) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
            let bq = d64.dot(o64);
            let t = -bq - (bq * bq - (o64.dot(o64) - 1.0)).max(0.0).sqrt();
            let n = (o64 + d64 * t).normalize();
            let r = d64 - n * (2.0 * d64.dot(n));
            // Skip the rim, where the reflected direction turns fast.
            if n.dot(-d64) < 0.2 {
                continue;
            }
            let want = (r + DVec3::ONE) * 0.5;
            for c in 0..3 {
                let w = linear_to_srgb8_fast(want[c] as f32) as i32;
                let g = f.color[k][c] as i32;
                assert!(
                    (w - g).abs() <= 1,
                    "pixel ({i},{j}) channel {c}: expected {w}, got {g}, tolerance 1"
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 500, "{checked}");
}

#[test]
fn index_one_glass_is_invisible_and_glass_bends_light() {
    // A refractive sphere of index 1 without Fresnel passes every ray straight through: the image
    // is the environment in the primary direction. With index 1.5 it is not.
    let mut b = SceneBuilder::new();
    b.add_sphere(Vec3::ZERO, 1.0, 0);
    let scene = b.build();
    let cam =
        Camera::perspective_look_at(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, 40.0, 48, 48)
            .unwrap();
    let env = |d: Vec3| (d + Vec3::ONE) * 0.5;
    let render = |ior| {
        let mats = [SurfaceMaterial {
            optics: texmap_reftrace::Optics::Refractive {
                ior,
                fresnel: false,
            },
            ..SurfaceMaterial::refractive(ior)
        }];
        let mut o = RenderOptions::new(unlit_lighting(), &mats);
        o.environment_on_primary_miss = true;
        scene.render_with_environment(&cam, &o, &env).unwrap()
    };
    let clear = render(1.0);
    let mut empty_opts = RenderOptions::new(unlit_lighting(), &[]);
    empty_opts.environment_on_primary_miss = true;
    let nothing = SceneBuilder::new()
        .build()
        .render_with_environment(&cam, &empty_opts, &env)
        .unwrap();
    assert!(clear.coverage_count() > 300);
    for (k, (a, b)) in clear.color.iter().zip(&nothing.color).enumerate() {
        for c in 0..3 {
            assert!(
                (a[c] as i32 - b[c] as i32).abs() <= 1,
                "pixel {k}: {a:?} vs {b:?}"
            );
        }
    }
    let glass = render(1.5);
    let differ = glass
        .color
        .iter()
        .zip(&nothing.color)
        .filter(|(a, b)| a != b)
        .count();
    assert!(
        differ > 200,
        "glass of index 1.5 changed only {differ} pixels"
    );
}

#[test]
fn texture_reference_integrates_the_footprint() {
    // A quad facing an orthographic camera, 64 px across, with a 128x128 checkerboard: each pixel
    // covers exactly 2x2 texels, two black and two white, so the box integral is 0.5 everywhere.
    // A 32x32 checkerboard (2 px per texel) is constant over each pixel: 0 or 1.
    let quad = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
    ];
    // v grows down the rows: the top of the quad (y = +1) is v = 0.
    let uvs = [
        Vec2::new(0.0, 1.0),
        Vec2::new(1.0, 1.0),
        Vec2::new(1.0, 0.0),
        Vec2::new(0.0, 0.0),
    ];
    let mut b = SceneBuilder::new();
    b.add_mesh(&quad, &[0, 1, 2, 0, 2, 3], Some(&uvs), 0)
        .unwrap();
    let scene = b.build();
    let cam =
        Camera::orthographic_look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 2.0, 64, 64)
            .unwrap();
    let checker = |n: u32| {
        let t: Vec<[f32; 4]> = (0..n * n)
            .map(|k| {
                let v = ((k % n + k / n) % 2) as f32;
                [v, v, v, 1.0]
            })
            .collect();
        Texture::new(n, n, t).unwrap()
    };
    let textures = [checker(128), checker(32)];
    let mats = [
        SurfaceMaterial::opaque(Material::matte(Vec3::ONE)).with_texture(0),
        SurfaceMaterial::opaque(Material::matte(Vec3::ONE)).with_texture(1),
    ];
    let mut o = RenderOptions::new(unlit_lighting(), &mats[..1]);
    o.textures = &textures;
    let fine = scene.render(&cam, &o).unwrap();
    let half = linear_to_srgb8_fast(0.5);
    assert_eq!(fine.coverage_count(), 64 * 64);
    for (k, c) in fine.color.iter().enumerate() {
        assert!(
            (c[0] as i32 - half as i32).abs() <= 1,
            "pixel {k}: expected {half}, got {}",
            c[0]
        );
    }
    // Coarse texture: pixel (i, j) shows texel (i/2, j/2) exactly.
    let mut b = SceneBuilder::new();
    b.add_mesh(&quad, &[0, 1, 2, 0, 2, 3], Some(&uvs), 1)
        .unwrap();
    let scene = b.build();
    let mut o = RenderOptions::new(unlit_lighting(), &mats);
    o.textures = &textures;
    o.samples_per_axis = 3;
    let coarse = scene.render(&cam, &o).unwrap();
    for j in 0..64u32 {
        for i in 0..64u32 {
            let want = if (i / 2 + j / 2) % 2 == 1 { 255 } else { 0 };
            let got = coarse.color[coarse.index(i, j)][0];
            assert_eq!(got, want, "pixel ({i},{j})");
        }
    }
}

#[test]
fn supersampling_averages_coverage_and_keeps_centre_depth() {
    // A sphere edge: 4x4 supersampled colours lie between background and surface; depth and
    // coverage equal the 1-sample render's.
    let mut b = SceneBuilder::new();
    b.add_sphere(Vec3::ZERO, 1.0, 0);
    let scene = b.build();
    let cam =
        Camera::perspective_look_at(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, 40.0, 40, 40)
            .unwrap();
    let mats = [SurfaceMaterial::opaque(Material::matte(Vec3::ONE))];
    let o1 = RenderOptions::new(unlit_lighting(), &mats);
    let one = scene.render(&cam, &o1).unwrap();
    for n in [2, 3, 4] {
        let mut o = RenderOptions::new(unlit_lighting(), &mats);
        o.samples_per_axis = n;
        let ss = scene.render(&cam, &o).unwrap();
        assert_eq!(
            one.depth.iter().map(|d| d.to_bits()).collect::<Vec<_>>(),
            ss.depth.iter().map(|d| d.to_bits()).collect::<Vec<_>>(),
            "n = {n}"
        );
        let partial = ss.color.iter().filter(|c| c[0] > 0 && c[0] < 255).count();
        assert!(partial > 20, "n = {n}: only {partial} edge pixels blended");
    }
}

#[test]
fn a_tree_too_deep_for_the_wide_stack_falls_back_to_the_binary_bvh() {
    // Spheres whose spacing grows geometrically along a line: every sphere's nearest neighbour is
    // the cluster of all smaller ones, so the binary tree is a chain ~one level per sphere, deeper
    // than the 4-wide traversal's fixed stack allows. Asking for Wide4 must then give the binary
    // layout (not an overflow), and it must still agree with brute force.
    let mut b = SceneBuilder::new().bvh(BvhKind::Wide4);
    let mut spheres = Vec::new();
    let mut x = 1.0f32;
    // (×1.2 per sphere and 190 spheres keep every quadratic far from f32 overflow: r < 2e14.)
    for _ in 0..190 {
        b.add_sphere(Vec3::new(x, 0.0, 0.0), 0.15 * x, 0);
        spheres.push((x, 0.15 * x));
        x *= 1.2;
    }
    let scene = b.build();
    assert_eq!(
        scene.bvh_kind(),
        Some(BvhKind::Bvh2),
        "a chain of 190 geometrically spaced spheres should be too deep for Wide4"
    );
    // Rays across the line through every sphere (hits) and just outside it (misses), plus a ray
    // along the line, which meets sphere 0 first.
    let mut rng = Lcg(77);
    let (mut hits, mut rays) = (0, 0);
    for &(cx, r) in &spheres {
        for dy in [0.0, 0.5 * r, 0.99 * r, 1.01 * r] {
            let origin = Vec3::new(cx + rng.range(-0.1, 0.1) * r, dy, -10.0 * r);
            let ray = Ray {
                origin,
                dir: Vec3::Z,
            };
            let a = scene.intersect(&ray).map(|h| (h.t, h.prim_id));
            let e = scene.intersect_brute_force(&ray).map(|h| (h.t, h.prim_id));
            assert_eq!(a, e, "BVH and brute force disagree for {ray:?}");
            hits += a.is_some() as usize;
            rays += 1;
        }
    }
    let along = Ray {
        origin: Vec3::new(-5.0, 0.0, 0.0),
        dir: Vec3::X,
    };
    let a = scene.intersect(&along).map(|h| (h.t, h.prim_id));
    assert_eq!(
        a,
        scene
            .intersect_brute_force(&along)
            .map(|h| (h.t, h.prim_id))
    );
    assert_eq!(
        a.map(|(_, id)| id),
        Some(0),
        "the ray along the line meets sphere 0 first"
    );
    assert!(
        hits >= 3 * spheres.len() && hits < rays,
        "too few hits ({hits} of {rays}) or no miss: not a test"
    );
}

//! The breaking points and guarantees of the methods, each pinned by a test against something
//! independent: the exact footprint of a triangle computed by ray casting, or the camera's own
//! geometry. The comparisons with the reference ray tracer are the study crate's
//! (`crates/study/tests/envmap_reference.rs`).

use texmap_core::camera::Camera;
use texmap_core::shade::{Lighting, Material};
use texmap_envmap::address::{MapFrame, sphere_dir};
use texmap_envmap::glam::{Vec2, Vec3};
use texmap_envmap::maps::{MapScratch, UpdateParams, update_sphere};
use texmap_envmap::scene::{TunnelParams, tunnel_camera, tunnel_lighting, tunnel_scene};
use texmap_envmap::{
    EnvMap, EnvScene, Environment, Filter, MapKind, Method, Object, Options, Renderer, RimPolicy,
    Surface, Target, TargetShape,
};
use texmap_mesh::TriMesh;

fn black_env() -> Environment {
    Environment::lat_long(2, 1, vec![Vec3::ZERO; 2]).unwrap()
}

/// Ray from the origin along `d` against triangle `t` (Möller–Trumbore, f64).
fn hits(d: Vec3, t: [Vec3; 3]) -> bool {
    let d = d.as_dvec3();
    let [a, b, c] = t.map(|v| v.as_dvec3());
    let e1 = b - a;
    let e2 = c - a;
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return false;
    }
    let s = -a / det;
    let u = s.dot(p);
    let q = s.cross(e1);
    let v = d.dot(q);
    let t = e2.dot(q);
    u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0
}

#[test]
fn a_triangle_straddling_the_rim_changes_no_texel_outside_its_footprint() {
    let n = 128u32;
    let lighting = Lighting::new(Vec3::ONE, &[]).unwrap();
    // Both behind the probe (the map's −z is its singular direction): one contains it, one
    // passes just above it.
    let tris = [
        [
            Vec3::new(-4.0, -1.0, -3.0),
            Vec3::new(4.0, -1.0, -3.0),
            Vec3::new(0.0, 4.0, -3.0),
        ],
        [
            Vec3::new(-4.0, 0.3, -3.0),
            Vec3::new(4.0, 0.3, -3.0),
            Vec3::new(0.0, 4.0, -3.0),
        ],
    ];
    for tri in tris {
        let obj = Object {
            mesh: TriMesh::new(tri.to_vec(), vec![[0, 1, 2]]).unwrap(),
            material: Material::matte(Vec3::ONE),
        };
        let env = black_env();
        let objects = [obj];
        let mut p = UpdateParams {
            objects: &objects,
            lighting: &lighting,
            environment: &env,
            centre: Vec3::ZERO,
            frame: MapFrame::WORLD,
            size: n,
            min_distance: 0.0,
            rim: RimPolicy::Split,
        };
        let inside = |x: u32, y: u32, margin: f32| {
            let q = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) / n as f32 - Vec2::splat(0.5);
            q.length() < 0.5 - margin / n as f32
        };
        let footprint: Vec<bool> = (0..n * n)
            .map(|i| {
                let uv = Vec2::new((i % n) as f32 + 0.5, (i / n) as f32 + 0.5) / n as f32;
                sphere_dir(uv).is_some_and(|d| hits(d, tri))
            })
            .collect();
        let near_footprint = |x: u32, y: u32| {
            let (x, y) = (x as i64, y as i64);
            (-1..=1).any(|dy| {
                (-1..=1).any(|dx| {
                    let (a, b) = (x + dx, y + dy);
                    (0..n as i64).contains(&a)
                        && (0..n as i64).contains(&b)
                        && footprint[(b * n as i64 + a) as usize]
                })
            })
        };
        let mut outside_split = 0;
        let mut outside_naive = 0;
        for rim in [RimPolicy::Split, RimPolicy::Naive] {
            p.rim = rim;
            let map = update_sphere(&p, &mut MapScratch::default()).unwrap();
            let tex = &map.faces()[0];
            let (mut drawn, mut missed, mut outside) = (0, 0, 0);
            for y in 0..n {
                for x in 0..n {
                    if !inside(x, y, 1.0) {
                        continue;
                    }
                    let lit = tex.texel(0, x as i64, y as i64).unwrap().x > 0.5;
                    if lit && !near_footprint(x, y) {
                        outside += 1;
                    }
                    // Interior texels (the whole 3x3 neighbourhood in the footprint) must be
                    // drawn; at the boundary the straight edges may be half a texel off.
                    let interior = (x > 0 && y > 0 && x + 1 < n && y + 1 < n)
                        && (-1i64..=1).all(|dy| {
                            (-1i64..=1).all(|dx| {
                                footprint[((y as i64 + dy) * n as i64 + x as i64 + dx) as usize]
                            })
                        });
                    if interior && inside(x, y, 3.0) {
                        if lit { drawn += 1 } else { missed += 1 }
                    }
                }
            }
            match rim {
                RimPolicy::Split => {
                    outside_split = outside;
                    // Not vacuous: the triangle is drawn where it truly is.
                    assert!(
                        drawn > 100 && missed * 100 <= drawn,
                        "drawn {drawn}, missed {missed}"
                    );
                }
                RimPolicy::Naive => outside_naive = outside,
            }
        }
        assert_eq!(
            outside_split, 0,
            "split: {outside_split} texels outside the footprint"
        );
        // The 1998 method smears across the disc: the test can tell.
        assert!(
            outside_naive > 100,
            "naive smear only {outside_naive} texels"
        );
    }
}

#[test]
fn the_singular_direction_gives_finite_lookups() {
    let cam =
        Camera::perspective_look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 60.0, 64, 64)
            .unwrap();
    let frame = MapFrame::of_camera(&cam);
    let m = EnvMap::from_environment(MapKind::Sphere, &Environment::Sky, frame, Vec3::ZERO, 64)
        .unwrap();
    // The singular direction of a sphere map in the eye frame points away from the viewer.
    let away = cam.forward();
    let e = 1e-7;
    let dirs = [
        away,
        away + Vec3::X * e,
        away - Vec3::Y * e,
        away + Vec3::new(e, e, 0.0),
    ];
    for filter in [Filter::Bilinear, Filter::Trilinear] {
        let c = m.lookup_quad(&dirs, 0b1111, filter);
        assert!(c.iter().all(|c| c.is_finite()), "{c:?}");
    }
    assert!(m.lookup(away).is_finite());
    // A full render of a sphere filling the view reaches the rim at its silhouette.
    let scene = EnvScene::new(
        vec![],
        Target {
            shape: TargetShape::Sphere {
                centre: Vec3::ZERO,
                radius: 1.0,
            },
            surface: Surface::Mirror,
        },
        Environment::Sky,
        tunnel_lighting(),
    )
    .unwrap();
    for method in Method::ALL {
        let out = Renderer::new()
            .render(&scene, &cam, &Options::new(method))
            .unwrap();
        assert!(out.frame.depth.iter().all(|d| !d.is_nan()));
    }
}

#[test]
fn frames_are_identical_for_one_and_two_threads() {
    let scene = tunnel_scene(TunnelParams {
        time: 0.7,
        ..Default::default()
    })
    .unwrap();
    let cam = tunnel_camera(160, 120).unwrap();
    for method in Method::ALL {
        let run = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                Renderer::new()
                    .render(&scene, &cam, &Options::new(method))
                    .unwrap()
                    .frame
            })
        };
        let (f1, f2) = (run(1), run(2));
        assert!(
            f1.color == f2.color
                && f1
                    .depth
                    .iter()
                    .zip(&f2.depth)
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
            "{}",
            method.name()
        );
    }
}

//! Interpolation, clipping, depth, sprites and determinism against independent f64 truth.

use glam::{DVec3, Vec2, Vec3, Vec4};
use texmap_core::camera::Camera;
use texmap_core::shade::{Lighting, Material};
use texmap_raster::{
    Cull, DepthTest, DrawState, Framebuffer, Mesh, QuadOut, Shading, Sprite, SpriteQuad, TexQuad,
};

/// The f64 eye-space-free ray through pixel centre (x, y): origin and a direction whose
/// component along the view axis is exactly 1 (so the ray parameter is the depth).
fn ray64(cam: &Camera, x: f64, y: f64) -> (DVec3, DVec3) {
    let k = cam.scale() as f64;
    let dx = (x - cam.width() as f64 * 0.5) / k;
    let dy = (cam.height() as f64 * 0.5 - y) / k;
    let d = cam.right().as_dvec3() * dx + cam.up().as_dvec3() * dy + cam.forward().as_dvec3();
    (cam.eye().as_dvec3(), d)
}

/// Uv-as-colour sampler: lane colour = (u, v, 0), so the framebuffer stores the interpolated uv.
fn uv_probe(q: &TexQuad) -> [Vec3; 4] {
    q.uv.map(|p| Vec3::new(p.x, p.y, 0.0))
}

#[test]
fn perspective_correct_uv_and_depth_match_f64_ray_plane() {
    let cam = Camera::perspective_look_at(
        Vec3::new(0.3, 2.0, 5.0),
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::Y,
        60.0,
        160,
        120,
    )
    .unwrap();
    // A tilted plane 0.2x − y − 0.1z = 0 with uv = (x, z).
    let plane_y = |x: f32, z: f32| 0.2 * x - 0.1 * z;
    let corners = [(-4.0, -6.0), (4.0, -6.0), (4.0, 3.0), (-4.0, 3.0)];
    let pos: Vec<Vec3> = corners
        .iter()
        .map(|&(x, z)| Vec3::new(x, plane_y(x, z), z))
        .collect();
    let uv: Vec<Vec2> = corners.iter().map(|&(x, z)| Vec2::new(x, z)).collect();
    let idx = [[0, 3, 2], [0, 2, 1]];
    let mesh = Mesh::new(&pos, &idx).unwrap().with_uvs(&uv).unwrap();
    let mut fb = Framebuffer::new(160, 120).unwrap();
    fb.clear([0, 0, 0, 255]);
    let st = DrawState {
        cull: Cull::None,
        ..DrawState::default()
    };
    fb.draw_textured(&cam, &mesh, &uv_probe, &st).unwrap();
    let n = DVec3::new(0.2, -1.0, -0.1);
    // Exact uv and depth of the plane under screen point (x, y).
    let exact = |x: f64, y: f64| {
        let (o, d) = ray64(&cam, x, y);
        let t = -n.dot(o) / n.dot(d);
        let p = o + d * t;
        (p.x, p.z, t)
    };
    let (mut checked, mut worst_uv, mut worst_depth) = (0, 0.0f64, 0.0f64);
    for y in 0..120u32 {
        for x in 0..160u32 {
            let (o, d) = ray64(&cam, x as f64 + 0.5, y as f64 + 0.5);
            let t = -n.dot(o) / n.dot(d);
            let p = o + d * t;
            let inside = t > 0.0 && p.x.abs() < 3.99 && p.z > -5.99 && p.z < 2.99;
            let depth = fb.depth_at(x, y).unwrap();
            if !inside {
                continue;
            }
            assert!(
                depth.is_finite(),
                "pixel ({x},{y}) inside the plane not drawn"
            );
            let c = fb.color_at(x, y).unwrap();
            // Tolerances: vertices are snapped to 1/256 pixel, which moves the whole triangle by
            // up to 1/362 pixel (√2/512), so a value with screen gradient g may be off by g/362;
            // plus f32 rounding of the plane equations (~1e-5 relative).
            let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
            let (u1, v1, t1) = exact(cx + 1.0, cy);
            let (u2, v2, t2) = exact(cx, cy + 1.0);
            let g_uv = (u1 - p.x)
                .abs()
                .max((v1 - p.z).abs())
                .max((u2 - p.x).abs())
                .max((v2 - p.z).abs());
            let g_t = (t1 - t).abs().max((t2 - t).abs());
            let tol_uv = 1e-5 * (1.0 + p.x.abs().max(p.z.abs())) + 2.0 * g_uv / 362.0;
            let eu = (c.x as f64 - p.x).abs().max((c.y as f64 - p.z).abs());
            assert!(
                eu <= tol_uv,
                "uv at ({x},{y}): expected ({:.6},{:.6}) got ({},{}) tol {tol_uv:e}",
                p.x,
                p.z,
                c.x,
                c.y
            );
            // Depth = t (the ray's view-axis component is 1).
            let tol_d = 1e-5 * t + 2.0 * g_t / 362.0;
            let ed = (depth as f64 - t).abs();
            assert!(
                ed <= tol_d,
                "depth at ({x},{y}): expected {t} got {depth} tol {tol_d:e}"
            );
            let ed = ed / t;
            worst_uv = worst_uv.max(eu);
            worst_depth = worst_depth.max(ed);
            checked += 1;
        }
    }
    assert!(checked > 5000, "only {checked} pixels checked");
    eprintln!(
        "perspective: {checked} px, worst uv error {worst_uv:e}, worst rel depth {worst_depth:e}"
    );
}

/// Möller–Trumbore in f64: (t, distance to the nearest edge, negative outside) of the ray's hit with the triangle's plane.
fn hit64(o: DVec3, d: DVec3, p: [DVec3; 3]) -> Option<(f64, f64)> {
    let e1 = p[1] - p[0];
    let e2 = p[2] - p[0];
    let h = d.cross(e2);
    let a = e1.dot(h);
    if a.abs() < 1e-300 {
        return None;
    }
    let s = o - p[0];
    let u = s.dot(h) / a;
    let q = s.cross(e1);
    let v = d.dot(q) / a;
    let t = e2.dot(q) / a;
    // Margin as a distance (world units) to the nearest edge line: barycentric × height.
    let twice_area = e1.cross(e2).length();
    let h = |opp: DVec3| twice_area / opp.length();
    let m = (u * h(p[2] - p[0]))
        .min(v * h(p[1] - p[0]))
        .min((1.0 - u - v) * h(p[2] - p[1]));
    Some((t, m))
}

#[test]
fn near_plane_and_guard_band_clipping_match_per_pixel_ray_tests() {
    let cam = Camera::perspective_look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 70.0, 120, 90)
        .unwrap()
        .with_clip(0.5, 1e6)
        .unwrap();
    let tris: [[Vec3; 3]; 4] = [
        // A floor triangle reaching behind the eye (crosses the near plane and the eye plane).
        [
            Vec3::new(-3.0, -1.0, -4.0),
            Vec3::new(3.0, -1.0, -4.0),
            Vec3::new(0.2, -1.0, 3.0),
        ],
        // A wall whose vertex lies far outside the guard band to the right.
        [
            Vec3::new(-1.0, 0.5, -3.0),
            Vec3::new(1e6, 0.7, -3.5),
            Vec3::new(-0.5, 1.5, -3.2),
        ],
        // A triangle slicing through the near plane at a steep angle.
        [
            Vec3::new(-0.3, -0.2, -0.2),
            Vec3::new(0.4, 0.1, -2.0),
            Vec3::new(-0.1, 0.4, -1.0),
        ],
        // Entirely behind the near plane: draws nothing.
        [
            Vec3::new(-1.0, 0.0, -0.3),
            Vec3::new(1.0, 0.0, -0.3),
            Vec3::new(0.0, 1.0, -0.2),
        ],
    ];
    for (ti, tri) in tris.iter().enumerate() {
        let mesh_idx = [[0u32, 1, 2]];
        let mesh = Mesh::new(tri, &mesh_idx).unwrap();
        let mut fb = Framebuffer::new(120, 90).unwrap();
        fb.clear([0, 0, 0, 255]);
        let st = DrawState {
            cull: Cull::None,
            ..DrawState::default()
        };
        let stats = fb
            .draw_mesh(&cam, &mesh, &Shading::Flat(Vec3::ONE), &st)
            .unwrap();
        if ti < 3 {
            assert_eq!(
                stats.clipped, 1,
                "triangle {ti} should take the clipping path"
            );
        }
        let p = tri.map(|v| v.as_dvec3());
        let (mut sure, mut mismatches) = (0, 0);
        for y in 0..90u32 {
            for x in 0..120u32 {
                let (o, d) = ray64(&cam, x as f64 + 0.5, y as f64 + 0.5);
                let got = fb.depth_at(x, y).unwrap();
                let Some((t, margin)) = hit64(o, d, p) else {
                    assert!(got.is_infinite());
                    continue;
                };
                // t is the depth (view-axis component of d is 1).
                let inside = margin > 1e-5 && t > 0.5 * (1.0 + 1e-5);
                let outside = margin < -1e-5 || t < 0.5 * (1.0 - 1e-5);
                if inside {
                    sure += 1;
                    if !got.is_finite() {
                        mismatches += 1;
                        eprintln!(
                            "tri {ti}: ({x},{y}) should be covered (t {t}, margin {margin:e})"
                        );
                    } else {
                        let rel = (got as f64 - t).abs() / t;
                        assert!(
                            rel < 1e-4,
                            "tri {ti} ({x},{y}) depth expected {t} got {got} rel tol 1e-4"
                        );
                    }
                } else if outside && got.is_finite() {
                    mismatches += 1;
                    eprintln!("tri {ti}: ({x},{y}) should be empty (t {t}, margin {margin:e})");
                }
            }
        }
        assert_eq!(mismatches, 0, "triangle {ti}");
        if ti < 3 {
            assert!(sure > 50, "triangle {ti}: only {sure} pixels inside");
        } else {
            assert_eq!(fb.to_frame().coverage_count(), 0);
        }
    }
}

#[test]
fn smooth_lighting_matches_the_shared_model_per_pixel() {
    let cam =
        Camera::perspective_look_at(Vec3::new(0.0, 1.0, 4.0), Vec3::ZERO, Vec3::Y, 50.0, 64, 48)
            .unwrap();
    let lighting = Lighting::default_for(&cam);
    let material = Material::plastic(Vec3::new(0.8, 0.3, 0.1));
    let pos = [
        Vec3::new(-3.0, 0.0, -3.0),
        Vec3::new(3.0, 0.0, -3.0),
        Vec3::new(0.0, 0.0, 3.0),
    ];
    // Per-vertex normals differ: the interpolated normal is affine in world position.
    let nrm = [
        Vec3::new(-0.3, 1.0, 0.0),
        Vec3::new(0.3, 1.0, 0.1),
        Vec3::new(0.0, 1.0, 0.4),
    ];
    let idx = [[0u32, 2, 1]];
    let mesh = Mesh::new(&pos, &idx).unwrap().with_normals(&nrm).unwrap();
    let mut fb = Framebuffer::new(64, 48).unwrap();
    fb.clear([0, 0, 0, 255]);
    fb.draw_mesh(
        &cam,
        &mesh,
        &Shading::LitSmooth { lighting, material },
        &DrawState::default(),
    )
    .unwrap();
    let p = pos.map(|v| v.as_dvec3());
    let mut checked = 0;
    for y in 0..48u32 {
        for x in 0..64u32 {
            let (o, d) = ray64(&cam, x as f64 + 0.5, y as f64 + 0.5);
            let Some((t, margin)) = hit64(o, d, p) else {
                continue;
            };
            if margin < 1e-2 || t <= 0.0 {
                continue;
            }
            // Barycentric interpolation of the normal in world space (f64), then the shared model.
            let h = o + d * t;
            let area = (p[1] - p[0]).cross(p[2] - p[0]);
            let b1 = (h - p[0]).cross(p[2] - p[0]).dot(area) / area.length_squared();
            let b2 = (p[1] - p[0]).cross(h - p[0]).dot(area) / area.length_squared();
            let b0 = 1.0 - b1 - b2;
            let n = (nrm[0].as_dvec3() * b0 + nrm[1].as_dvec3() * b1 + nrm[2].as_dvec3() * b2)
                .normalize();
            let v = (-d).normalize();
            let expect = lighting.shade(&material, n.as_vec3(), v.as_vec3());
            let got = fb.color_at(x, y).unwrap();
            let err = (got - expect).abs().max_element();
            assert!(
                err < 2e-4,
                "({x},{y}): expected {expect} got {got} tol 2e-4"
            );
            checked += 1;
        }
    }
    assert!(checked > 300, "{checked}");
}

#[test]
fn depth_test_keeps_the_nearest_surface_in_any_order() {
    let cam =
        Camera::perspective_look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 60.0, 48, 48)
            .unwrap();
    // Two interpenetrating triangles: red tilted, blue flat.
    let pos = [
        Vec3::new(-2.0, -2.0, -1.0),
        Vec3::new(2.0, -2.0, 1.0),
        Vec3::new(0.0, 2.0, 0.0),
        Vec3::new(-2.0, -1.5, 0.0),
        Vec3::new(2.0, -1.5, 0.0),
        Vec3::new(0.0, 2.5, 0.0),
    ];
    let cols = [Vec3::X, Vec3::X, Vec3::X, Vec3::Z, Vec3::Z, Vec3::Z];
    let render = |order: [[u32; 3]; 2], test| {
        let mesh = Mesh::new(&pos, &order).unwrap().with_colors(&cols).unwrap();
        let mut fb = Framebuffer::new(48, 48).unwrap();
        fb.clear([0, 0, 0, 255]);
        let st = DrawState {
            depth_test: test,
            ..DrawState::default()
        };
        fb.draw_mesh(&cam, &mesh, &Shading::VertexColor, &st)
            .unwrap();
        fb.to_frame()
    };
    let a = render([[0, 1, 2], [3, 4, 5]], DepthTest::Less);
    let b = render([[3, 4, 5], [0, 1, 2]], DepthTest::Less);
    assert_eq!(a, b);
    let reds = a.color.iter().filter(|c| c[0] == 255).count();
    let blues = a.color.iter().filter(|c| c[2] == 255).count();
    assert!(
        reds > 50 && blues > 50,
        "both surfaces visible: {reds} {blues}"
    );
    // With Always, the later triangle wins everywhere it covers.
    let c = render([[0, 1, 2], [3, 4, 5]], DepthTest::Always);
    assert!(c.color.iter().filter(|c| c[0] == 255).count() < reds);
}

/// Depth units per pixel of sprite radius in the sphere shader.
const DEPTH_PER_PX: f32 = 0.05;

/// A sphere impostor shader: unit-radius sphere seen head-on under an orthographic-like sprite,
/// depth = centre depth − sqrt(1 − s² − t²)·r, discard outside the disc.
fn disc_shader(centres: &[(Vec2, f32, f32)]) -> impl Fn(u32, &SpriteQuad) -> QuadOut + Sync + '_ {
    move |id, q| {
        let (_, zc, r) = centres[id as usize];
        let mut out = QuadOut {
            color: [Vec3::ZERO; 4],
            depth: [0.0; 4],
            mask: 0,
        };
        for l in 0..4 {
            let u = q.s[l] * 2.0 - 1.0;
            let v = q.t[l] * 2.0 - 1.0;
            let rr = u * u + v * v;
            if rr < 1.0 {
                out.mask |= 1 << l;
                out.depth[l] = zc - (1.0 - rr).sqrt() * r * DEPTH_PER_PX;
                out.color[l] = Vec3::new(id as f32 + 1.0, 0.0, 0.0);
            }
        }
        out
    }
}

#[test]
fn sprites_cover_analytic_discs_with_per_fragment_depth() {
    let (w, h) = (100u32, 80u32);
    // (centre, centre depth, radius in pixels)
    let spheres = [
        (Vec2::new(20.3, 30.7), 10.0, 12.5),
        (Vec2::new(70.0, 40.0), 12.0, 20.0),
        (Vec2::new(99.0, 2.0), 8.0, 6.0), // clipped by the image corner
    ];
    let sprites: Vec<Sprite> = spheres
        .iter()
        .enumerate()
        .map(|(i, &(c, z, r))| Sprite {
            min: c - r,
            max: c + r,
            depth_min: z - r * DEPTH_PER_PX,
            id: i as u32,
        })
        .collect();
    let mut fb = Framebuffer::new(w, h).unwrap();
    fb.clear([0, 0, 0, 255]);
    let stats = fb
        .draw_sprites(&sprites, &disc_shader(&spheres), &DrawState::default())
        .unwrap();
    assert_eq!(stats.binned, 3);
    for y in 0..h {
        for x in 0..w {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5).as_dvec2();
            let mut best: Option<(f64, usize)> = None;
            for (i, &(c, z, r)) in spheres.iter().enumerate() {
                let d2 = (p - c.as_dvec2()).length_squared() / (r as f64 * r as f64);
                if d2 < 1.0 - 1e-4 {
                    let depth = z as f64 - (1.0 - d2).sqrt() * (r * DEPTH_PER_PX) as f64;
                    if best.is_none_or(|b| depth < b.0) {
                        best = Some((depth, i));
                    }
                } else if d2 < 1.0 + 1e-4 {
                    best = None; // on a rim: either answer is fine
                    break;
                }
            }
            let got = fb.depth_at(x, y).unwrap();
            match best {
                Some((depth, i)) => {
                    assert!(
                        (got as f64 - depth).abs() < 1e-3 * depth,
                        "({x},{y}) depth expected {depth} got {got} tol 1e-3 rel"
                    );
                    assert_eq!(fb.color_at(x, y).unwrap().x, i as f32 + 1.0, "({x},{y})");
                }
                None => {
                    let any_disc = spheres
                        .iter()
                        .any(|&(c, _, r)| (p - c.as_dvec2()).length() <= r as f64 * (1.0 + 1e-4));
                    if !any_disc {
                        assert!(got.is_infinite(), "({x},{y}) outside every disc drawn");
                    }
                }
            }
        }
    }
}

#[test]
fn early_depth_rejection_does_not_change_the_image() {
    let (w, h) = (128u32, 96u32);
    let mut spheres = Vec::new();
    let mut s = 3u64;
    let mut rnd = || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1);
        (s >> 40) as f32 / (1u64 << 24) as f32
    };
    for _ in 0..400 {
        spheres.push((
            Vec2::new(rnd() * 140.0 - 6.0, rnd() * 110.0 - 7.0),
            5.0 + rnd() * 50.0,
            2.0 + rnd() * 15.0,
        ));
    }
    let render = |tight: bool| {
        let sprites: Vec<Sprite> = spheres
            .iter()
            .enumerate()
            .map(|(i, &(c, z, r))| Sprite {
                min: c - r,
                max: c + r,
                depth_min: if tight { z - r * DEPTH_PER_PX } else { 0.0 },
                id: i as u32,
            })
            .collect();
        let mut fb = Framebuffer::new(w, h).unwrap();
        fb.clear([0, 0, 0, 255]);
        fb.draw_sprites(&sprites, &disc_shader(&spheres), &DrawState::default())
            .unwrap();
        fb.to_frame()
    };
    let a = render(true);
    assert_eq!(a, render(false));
    assert!(a.coverage_count() > 5000);
}

/// A mixed scene: lit triangles of every size (some clipped), textured triangles, sprites.
fn busy_scene(fb: &mut Framebuffer) {
    let cam = Camera::perspective_look_at(
        Vec3::new(0.5, 3.0, 9.0),
        Vec3::ZERO,
        Vec3::Y,
        65.0,
        fb.width(),
        fb.height(),
    )
    .unwrap()
    .with_clip(0.3, 100.0)
    .unwrap();
    let mut s = 99u64;
    let mut rnd = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut pos = Vec::new();
    let mut nrm = Vec::new();
    let mut uv = Vec::new();
    let mut idx = Vec::new();
    for t in 0..20_000u32 {
        let c = Vec3::new(rnd() * 16.0 - 8.0, rnd() * 8.0 - 4.0, rnd() * 18.0 - 12.0);
        let size = if t % 100 == 0 {
            6.0
        } else {
            0.05 + rnd() * 0.3
        };
        for _ in 0..3 {
            pos.push(c + Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * size);
            nrm.push(Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5));
            uv.push(Vec2::new(rnd() * 4.0, rnd() * 4.0));
        }
        idx.push([3 * t, 3 * t + 1, 3 * t + 2]);
    }
    fb.clear([20, 30, 40, 255]);
    let mesh = Mesh::new(&pos, &idx)
        .unwrap()
        .with_normals(&nrm)
        .unwrap()
        .with_uvs(&uv)
        .unwrap();
    let st = DrawState {
        cull: Cull::None,
        ..DrawState::default()
    };
    let lighting = Lighting::default_for(&cam);
    let half = idx.len() / 2;
    let m1 = Mesh::new(&pos, &idx[..half])
        .unwrap()
        .with_normals(&nrm)
        .unwrap();
    fb.draw_mesh(
        &cam,
        &m1,
        &Shading::LitSmooth {
            lighting,
            material: Material::plastic(Vec3::new(0.2, 0.6, 0.9)),
        },
        &st,
    )
    .unwrap();
    let m2 = Mesh::new(&pos, &idx[half..])
        .unwrap()
        .with_uvs(&uv)
        .unwrap();
    let checker = |q: &TexQuad| {
        let (dx, _) = q.derivatives();
        q.uv.map(|p| {
            let c = ((p.x.floor() + p.y.floor()) as i32 & 1) as f32;
            Vec3::new(c, 0.5, dx.length().min(1.0))
        })
    };
    fb.draw_textured(&cam, &m2, &checker, &st).unwrap();
    let _ = mesh;
    let spheres: Vec<(Vec2, f32, f32)> = (0..3000)
        .map(|_| {
            (
                Vec2::new(rnd() * 700.0, rnd() * 500.0),
                2.0 + rnd() * 20.0,
                1.0 + rnd() * 6.0,
            )
        })
        .collect();
    let sprites: Vec<Sprite> = spheres
        .iter()
        .enumerate()
        .map(|(i, &(c, z, r))| Sprite {
            min: c - r,
            max: c + r,
            depth_min: z - r * DEPTH_PER_PX,
            id: i as u32,
        })
        .collect();
    fb.draw_sprites(&sprites, &disc_shader(&spheres), &DrawState::default())
        .unwrap();
}

#[test]
fn output_is_byte_identical_for_one_and_two_threads() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut fb = Framebuffer::new(640, 480).unwrap();
            busy_scene(&mut fb);
            fb.to_frame()
        })
    };
    let a = run(1);
    let b = run(2);
    assert_eq!(a.color, b.color);
    let bits =
        |f: &texmap_core::frame::Frame| f.depth.iter().map(|d| d.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&a), bits(&b));
    assert!(
        a.coverage_count() > 20_000,
        "scene too empty: {}",
        a.coverage_count()
    );
    assert!(a.depth.iter().all(|d| !d.is_nan()));
}

#[test]
fn degenerate_input_is_skipped_without_panic_or_nan() {
    let cam =
        Camera::perspective_look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 60.0, 33, 17)
            .unwrap();
    let n = f32::NAN;
    let inf = f32::INFINITY;
    let pos = [
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(n, 0.0, 0.0),
        Vec3::new(0.0, inf, 0.0),
        Vec3::new(0.0, 3.0, 0.0),
        Vec3::new(1e30, 1e30, -1e30),
        Vec3::new(f32::MAX, -f32::MAX, f32::MAX),
        Vec3::new(0.0, -1.0, 0.0),
    ];
    let idx = [
        [0, 1, 3], // NaN vertex
        [0, 4, 1], // infinite vertex
        [0, 0, 1], // repeated vertex: zero area
        [2, 5, 8], // collinear on the view axis's plane x = 0: zero area on screen
        [0, 6, 7], // huge but finite: clipped, whatever remains is drawn
        [0, 1, 2], // a good one
    ];
    let mesh = Mesh::new(&pos, &idx).unwrap();
    let mut fb = Framebuffer::new(33, 17).unwrap();
    fb.clear([0, 0, 0, 255]);
    let st = DrawState {
        cull: Cull::None,
        ..DrawState::default()
    };
    let s = fb
        .draw_mesh(&cam, &mesh, &Shading::Flat(Vec3::ONE), &st)
        .unwrap();
    assert_eq!(s.submitted, 6);
    assert_eq!(s.skipped_invalid, 2, "{s:?}");
    assert_eq!(s.degenerate, 2, "{s:?}");
    let f = fb.to_frame();
    assert!(f.coverage_count() > 0);
    assert!(f.depth.iter().all(|d| !d.is_nan()));
    // Empty inputs.
    let empty = Mesh::new(&[], &[]).unwrap();
    assert_eq!(
        fb.draw_mesh(&cam, &empty, &Shading::Flat(Vec3::ONE), &st)
            .unwrap()
            .submitted,
        0
    );
    assert_eq!(
        fb.draw_sprites(&[], &disc_shader(&[]), &st)
            .unwrap()
            .submitted,
        0
    );
    // Bad sprites and a shader returning NaN depth or colour.
    let bad = [
        Sprite {
            min: Vec2::new(n, 0.0),
            max: Vec2::ONE,
            depth_min: 0.0,
            id: 0,
        },
        Sprite {
            min: Vec2::new(5.0, 5.0),
            max: Vec2::new(4.0, 9.0),
            depth_min: 0.0,
            id: 0,
        },
        Sprite {
            min: Vec2::ZERO,
            max: Vec2::splat(8.0),
            depth_min: n,
            id: 0,
        },
        Sprite {
            min: Vec2::ZERO,
            max: Vec2::splat(8.0),
            depth_min: 0.0,
            id: 0,
        },
    ];
    let nan_shader = |_: u32, _: &SpriteQuad| QuadOut {
        color: [Vec3::NAN; 4],
        depth: [n, 1.0, n, 2.0],
        mask: 0b1111,
    };
    let all = DrawState {
        depth_test: DepthTest::Always,
        ..DrawState::default()
    };
    let s = fb.draw_sprites(&bad, &nan_shader, &all).unwrap();
    assert_eq!(s.skipped_invalid, 3);
    let f = fb.to_frame();
    assert!(f.depth.iter().all(|d| !d.is_nan()));
    // Mismatched sizes and missing attributes are errors.
    let small = Camera::perspective_look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 60.0, 8, 8).unwrap();
    assert!(
        fb.draw_mesh(&small, &mesh, &Shading::Flat(Vec3::ONE), &st)
            .is_err()
    );
    assert!(
        fb.draw_mesh(&cam, &mesh, &Shading::VertexColor, &st)
            .is_err()
    );
    assert!(fb.draw_textured(&cam, &mesh, &uv_probe, &st).is_err());
    let _ = Vec4::ZERO;
}

/// One world unit per pixel on a 64x48 image, and the corners of a 20 x 10 rectangle centred on
/// it, counter-clockwise from (−10, −5).
fn rectangle_64x48() -> (Camera, [Vec3; 4]) {
    let cam =
        Camera::orthographic_look_at(Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO, Vec3::Y, 64.0, 64, 48)
            .unwrap();
    let pos = [
        Vec3::new(-10.0, -5.0, 0.0),
        Vec3::new(10.0, -5.0, 0.0),
        Vec3::new(10.0, 5.0, 0.0),
        Vec3::new(-10.0, 5.0, 0.0),
    ];
    (cam, pos)
}

#[test]
fn textured_quads_name_their_source_triangle() {
    // One world unit per pixel; a 20 x 10 rectangle cut by its diagonal from (−10, −5) to
    // (10, 5): triangle 0 below it, triangle 1 above. The sampler colours by `quad.triangle`.
    let (cam, pos) = rectangle_64x48();
    let uv = [Vec2::ZERO; 4];
    let mesh = Mesh::new(&pos, &[[0, 1, 2], [0, 2, 3]])
        .unwrap()
        .with_uvs(&uv)
        .unwrap();
    let by_triangle = |q: &TexQuad| {
        [match q.triangle {
            0 => Vec3::X,
            1 => Vec3::Y,
            _ => Vec3::Z,
        }; 4]
    };
    let mut fb = Framebuffer::new(64, 48).unwrap();
    fb.clear([0, 0, 0, 255]);
    fb.draw_textured(&cam, &mesh, &by_triangle, &DrawState::default())
        .unwrap();
    let frame = fb.to_frame();
    let (mut below, mut above) = (0, 0);
    for j in 0..48 {
        for i in 0..64 {
            let c = frame.color[frame.index(i, j)];
            let (x, y) = (i as f64 + 0.5 - 32.0, 24.0 - (j as f64 + 0.5));
            if x.abs() > 10.0 || y.abs() > 5.0 {
                assert_eq!(c, [0, 0, 0, 255], "({i}, {j}) outside");
            } else if y < x / 2.0 {
                assert_eq!(c, [255, 0, 0, 255], "({i}, {j}) in triangle 0");
                below += 1;
            } else {
                assert_eq!(c, [0, 255, 0, 255], "({i}, {j}) in triangle 1");
                above += 1;
            }
        }
    }
    assert_eq!(below + above, 200);
    assert_eq!(below, above);
}

#[test]
fn first_vertex_colour_fills_each_triangle_with_its_first_vertex() {
    // The same rectangle and diagonal; vertex colours differ everywhere, and the two triangles
    // start at different vertices: every covered pixel holds exactly its triangle's first
    // vertex colour (linear, read back unencoded), nothing interpolated.
    let (cam, pos) = rectangle_64x48();
    let colors = [
        Vec3::new(0.9, 0.1, 0.2),
        Vec3::new(0.1, 0.8, 0.3),
        Vec3::new(0.3, 0.2, 0.7),
        Vec3::new(0.5, 0.5, 0.05),
    ];
    let mesh = Mesh::new(&pos, &[[1, 2, 0], [3, 0, 2]])
        .unwrap()
        .with_colors(&colors)
        .unwrap();
    let mut fb = Framebuffer::new(64, 48).unwrap();
    fb.clear([0, 0, 0, 255]);
    fb.draw_mesh(
        &cam,
        &mesh,
        &Shading::FirstVertexColor,
        &DrawState::default(),
    )
    .unwrap();
    let (mut below, mut above) = (0, 0);
    for j in 0..48 {
        for i in 0..64 {
            let (x, y) = (i as f64 + 0.5 - 32.0, 24.0 - (j as f64 + 0.5));
            let got = fb.color_at(i, j).unwrap();
            if x.abs() > 10.0 || y.abs() > 5.0 {
                assert!(
                    fb.depth_at(i, j).unwrap().is_infinite(),
                    "({i}, {j}) outside"
                );
            } else if y < x / 2.0 {
                assert_eq!(got, colors[1], "({i}, {j}) in triangle 0");
                below += 1;
            } else {
                assert_eq!(got, colors[3], "({i}, {j}) in triangle 1");
                above += 1;
            }
        }
    }
    assert_eq!((below, above), (100, 100));
    // Without colours the draw is refused, as for Gouraud colours.
    let bare = Mesh::new(&pos, &[[0, 1, 2]]).unwrap();
    assert!(
        fb.draw_mesh(
            &cam,
            &bare,
            &Shading::FirstVertexColor,
            &DrawState::default()
        )
        .is_err()
    );
}

//! Coverage tests against independent truth: analytic pixel-centre counts, brute-force f64
//! point-in-triangle tests, and exact-once coverage of shared edges (fan and grid).

use glam::{Vec2, Vec3};
use texmap_core::camera::Camera;
use texmap_raster::{Cull, DrawState, Framebuffer, Mesh, Shading};

/// An orthographic camera mapping world (x, y, 0) to screen (w/2 + x, h/2 − y): one world unit per
/// pixel, exactly.
fn ortho(w: u32, h: u32) -> Camera {
    Camera::orthographic_look_at(
        Vec3::new(0.0, 0.0, 10.0),
        Vec3::ZERO,
        Vec3::Y,
        w as f32,
        w,
        h,
    )
    .unwrap()
}

/// The world point that lands on screen position (sx, sy) under [`ortho`].
fn world(cam: &Camera, sx: f64, sy: f64) -> Vec3 {
    Vec3::new(
        (sx - cam.width() as f64 * 0.5) as f32,
        (cam.height() as f64 * 0.5 - sy) as f32,
        0.0,
    )
}

/// Draw triangles given in screen coordinates additively with colour 1 (no culling, no depth
/// test) and return the per-pixel write counts.
fn counts(w: u32, h: u32, screen: &[[f64; 2]], tris: &[[u32; 3]]) -> Vec<u32> {
    let cam = ortho(w, h);
    let pos: Vec<Vec3> = screen.iter().map(|p| world(&cam, p[0], p[1])).collect();
    let mesh = Mesh::new(&pos, tris).unwrap();
    let mut fb = Framebuffer::new(w, h).unwrap();
    fb.clear([0, 0, 0, 255]);
    fb.draw_mesh(
        &cam,
        &mesh,
        &Shading::Flat(Vec3::ONE),
        &DrawState::additive_overlay(),
    )
    .unwrap();
    let mut out = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let c = fb.color_at(x, y).unwrap().x;
            assert_eq!(c, c.round(), "pixel ({x},{y}) count {c} not an integer");
            out.push(c as u32);
        }
    }
    out
}

/// Seeded LCG in [0, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Snap to the 1/256 grid so the test's f64 geometry equals the rasteriser's fixed point.
fn snap(v: f64) -> f64 {
    (v * 256.0).round() / 256.0
}

#[test]
fn rectangle_pixel_count_equals_analytic_count() {
    // Rectangles with corners on the 1/8 grid, some exactly on pixel centres.
    let (w, h) = (97, 61);
    let cases = [
        (3.0, 4.0, 40.0, 30.0),
        (2.5, 3.5, 20.5, 9.5),
        (0.125, 7.875, 96.875, 60.5),
        (-10.0, -3.25, 12.375, 5.625),
        (50.5, 20.5, 51.5, 21.5),
        (10.25, 10.25, 10.75, 10.75),
    ];
    for (x0, y0, x1, y1) in cases {
        let pts = [[x0, y0], [x1, y0], [x1, y1], [x0, y1]];
        let c = counts(w, h, &pts, &[[0, 1, 2], [0, 2, 3]]);
        // Top-left rule on a rectangle: x0 <= centre < x1 and y0 <= centre < y1.
        let inside = |lo: f64, hi: f64, n: u32| {
            (0..n)
                .filter(|&i| lo <= i as f64 + 0.5 && (i as f64 + 0.5) < hi)
                .count()
        };
        let expect = inside(x0, x1, w) * inside(y0, y1, h);
        let got: u32 = c.iter().sum();
        assert_eq!(got as usize, expect, "rectangle ({x0},{y0})-({x1},{y1})");
        assert!(c.iter().all(|&n| n <= 1), "a pixel was drawn twice");
    }
}

#[test]
fn random_triangle_pixel_count_matches_f64_brute_force() {
    let (w, h) = (128, 96);
    let mut rng = Rng(7);
    let mut tested = 0;
    while tested < 300 {
        let p: Vec<[f64; 2]> = (0..3)
            .map(|_| {
                [
                    snap(rng.next() * 150.0 - 11.0),
                    snap(rng.next() * 120.0 - 12.0),
                ]
            })
            .collect();
        // Brute force in f64: strictly inside, and reject the sample if a centre is on an edge.
        let edge = |a: [f64; 2], b: [f64; 2], x: f64, y: f64| {
            (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])
        };
        let area = edge(p[0], p[1], p[2][0], p[2][1]);
        if area == 0.0 {
            continue;
        }
        let mut expect = 0usize;
        let mut on_edge = false;
        for j in 0..h {
            for i in 0..w {
                let (x, y) = (i as f64 + 0.5, j as f64 + 0.5);
                let e = [
                    edge(p[1], p[2], x, y),
                    edge(p[2], p[0], x, y),
                    edge(p[0], p[1], x, y),
                ];
                if e.contains(&0.0) {
                    on_edge = true;
                }
                if e.iter().all(|&v| v * area > 0.0) {
                    expect += 1;
                }
            }
        }
        if on_edge {
            continue;
        }
        let got: u32 = counts(w, h, &p, &[[0, 1, 2]]).iter().sum();
        assert_eq!(got as usize, expect, "triangle {p:?}");
        tested += 1;
    }
}

#[test]
fn fan_covers_interior_exactly_once() {
    // A fan of 37 triangles around an off-grid centre, rim vertices at random radii.
    let (w, h) = (160, 120);
    let mut rng = Rng(11);
    let c = [snap(80.3), snap(61.7)];
    let n = 37;
    let mut pts = vec![c];
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        let r = 40.0 + 30.0 * rng.next();
        pts.push([snap(c[0] + r * a.cos()), snap(c[1] + r * a.sin())]);
    }
    let tris: Vec<[u32; 3]> = (0..n).map(|k| [0, 1 + k, 1 + (k + 1) % n]).collect();
    let cnt = counts(w, h, &pts, &tris);
    assert!(cnt.iter().all(|&k| k <= 1), "double-drawn pixel in the fan");
    // Every pixel centre strictly inside one of the fan triangles (f64) is drawn; total equals
    // the number of pixel centres inside the star polygon.
    let mut inside = 0;
    for j in 0..h {
        for i in 0..w {
            let (x, y) = (i as f64 + 0.5, j as f64 + 0.5);
            let hit = tris.iter().any(|t| {
                let [a, b, cc] = t.map(|k| pts[k as usize]);
                let e = |a: [f64; 2], b: [f64; 2]| {
                    (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])
                };
                let (e0, e1, e2) = (e(b, cc), e(cc, a), e(a, b));
                (e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0) || (e0 <= 0.0 && e1 <= 0.0 && e2 <= 0.0)
            });
            if hit {
                inside += 1;
                let strictly = tris.iter().any(|t| {
                    let [a, b, cc] = t.map(|k| pts[k as usize]);
                    let e = |a: [f64; 2], b: [f64; 2]| {
                        (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])
                    };
                    let (e0, e1, e2) = (e(b, cc), e(cc, a), e(a, b));
                    (e0 > 0.0 && e1 > 0.0 && e2 > 0.0) || (e0 < 0.0 && e1 < 0.0 && e2 < 0.0)
                });
                if strictly {
                    assert_eq!(
                        cnt[(j * w + i) as usize],
                        1,
                        "pixel ({i},{j}) inside the fan not drawn"
                    );
                }
            }
        }
    }
    let total: u32 = cnt.iter().sum();
    // Pixels on the outer rim may go either way; the interior shared edges must not lose any.
    assert!(
        total as usize <= inside && total as usize + 2 * n as usize * 2 >= inside,
        "total {total}, closed-inside {inside}"
    );
}

fn grid_mesh(
    w: u32,
    h: u32,
    nx: usize,
    ny: usize,
    jitter: f64,
    seed: u64,
) -> (Vec<[f64; 2]>, Vec<[u32; 3]>) {
    let mut rng = Rng(seed);
    let mut pts = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            // The outer ring lies beyond the image so every pixel is inside the grid.
            let mut x = -3.0 + (w as f64 + 6.0) * i as f64 / nx as f64;
            let mut y = -3.0 + (h as f64 + 6.0) * j as f64 / ny as f64;
            if i > 0 && i < nx && j > 0 && j < ny {
                x += jitter * (rng.next() - 0.5);
                y += jitter * (rng.next() - 0.5);
            }
            pts.push([snap(x), snap(y)]);
        }
    }
    let mut tris = Vec::new();
    let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    for j in 0..ny {
        for i in 0..nx {
            // Alternate the diagonal so edges of every direction occur.
            if (i + j) % 2 == 0 {
                tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            } else {
                tris.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
                tris.push([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
    }
    (pts, tris)
}

#[test]
fn jittered_grid_covers_every_pixel_exactly_once() {
    let (w, h) = (203, 131); // odd sizes: partial tiles and partial quads
    for (nx, ny, jitter, seed) in [(17, 11, 7.0, 1), (60, 40, 2.0, 2), (150, 100, 0.9, 3)] {
        let (pts, tris) = grid_mesh(w, h, nx, ny, jitter, seed);
        let cnt = counts(w, h, &pts, &tris);
        for (i, &k) in cnt.iter().enumerate() {
            assert_eq!(
                k,
                1,
                "grid {nx}x{ny}: pixel ({},{}) written {k} times",
                i as u32 % w,
                i as u32 / w
            );
        }
    }
}

#[test]
fn grid_through_pixel_centres_covers_every_pixel_exactly_once() {
    // Vertices exactly on pixel centres: horizontal, vertical and diagonal edges through centres
    // exercise every tie of the fill rule.
    let (w, h) = (64 + 37, 64 + 5);
    let mut pts = Vec::new();
    let (nx, ny) = (w as usize / 2 + 2, h as usize / 2 + 2);
    for j in 0..=ny {
        for i in 0..=nx {
            pts.push([-1.5 + 2.0 * i as f64, -1.5 + 2.0 * j as f64]);
        }
    }
    let (_, tris) = grid_mesh(w, h, nx, ny, 0.0, 0);
    let cnt = counts(w, h, &pts, &tris);
    for (i, &k) in cnt.iter().enumerate() {
        assert_eq!(
            k,
            1,
            "pixel ({},{}) written {k} times",
            i as u32 % w,
            i as u32 / w
        );
    }
}

#[test]
fn back_face_culling_follows_counter_clockwise_front() {
    let cam = ortho(32, 32);
    // Counter-clockwise as seen from the camera (world y up): front-facing.
    let pos = [
        Vec3::new(-8.0, -8.0, 0.0),
        Vec3::new(8.0, -8.0, 0.0),
        Vec3::new(0.0, 8.0, 0.0),
    ];
    let mesh = Mesh::new(&pos, &[[0, 1, 2]]).unwrap();
    let mut fb = Framebuffer::new(32, 32).unwrap();
    let draw = |fb: &mut Framebuffer, cull| {
        fb.clear([0, 0, 0, 255]);
        let st = DrawState {
            cull,
            ..DrawState::default()
        };
        fb.draw_mesh(&cam, &mesh, &Shading::Flat(Vec3::ONE), &st)
            .unwrap();
        fb.to_frame().coverage_count()
    };
    let all = draw(&mut fb, Cull::None);
    assert!(all > 100);
    assert_eq!(draw(&mut fb, Cull::Back), all);
    assert_eq!(draw(&mut fb, Cull::Front), 0);
    let _ = Vec2::ZERO;
}

/// Clearing is deferred per tile: after a second clear to another colour, every pixel no later
/// draw reaches reads (and resolves to) the new colour with infinite depth, and a draw into one
/// tile sees the new clear values there, whatever the first frame left in that tile.
#[test]
fn a_second_clear_holds_for_drawn_and_untouched_tiles() {
    let (w, h) = (200u32, 150u32);
    let cam = ortho(w, h);
    let big = [[0.0, 0.0], [400.0, 0.0], [0.0, 300.0]];
    let pos: Vec<Vec3> = big.iter().map(|p| world(&cam, p[0], p[1])).collect();
    let mut fb = Framebuffer::new(w, h).unwrap();
    fb.clear([0, 0, 0, 255]);
    let state = DrawState {
        cull: Cull::None,
        ..DrawState::default()
    };
    let mesh = Mesh::new(&pos, &[[0, 1, 2]]).unwrap();
    fb.draw_mesh(&cam, &mesh, &Shading::Flat(Vec3::ONE), &state)
        .unwrap();
    assert_eq!(fb.color_at(150, 100), Some(Vec3::ONE));
    // Second frame: another background, one small triangle inside the first tile only.
    fb.clear([0, 255, 0, 255]);
    let small = [[4.0, 4.0], [20.0, 4.0], [4.0, 20.0]];
    let pos: Vec<Vec3> = small.iter().map(|p| world(&cam, p[0], p[1])).collect();
    let mesh = Mesh::new(&pos, &[[0, 1, 2]]).unwrap();
    fb.draw_mesh(&cam, &mesh, &Shading::Flat(Vec3::X), &state)
        .unwrap();
    let f = fb.to_frame();
    for y in 0..h {
        for x in 0..w {
            let inside = x >= 4 && y >= 4 && x + y < 23;
            let (c, d) = (f.color[f.index(x, y)], f.depth[f.index(x, y)]);
            if inside {
                assert_eq!(c, [255, 0, 0, 255], "({x},{y})");
                assert!(d.is_finite());
            } else if x + y > 25 || x < 3 || y < 3 {
                assert_eq!(c, [0, 255, 0, 255], "({x},{y})");
                assert_eq!(d, f32::INFINITY);
                assert_eq!(fb.depth_at(x, y), Some(f32::INFINITY));
                assert_eq!(fb.color_at(x, y), Some(Vec3::Y));
            }
        }
    }
}

#[test]
fn composite_takes_drawn_pixels_and_the_underlay_elsewhere() {
    // A 131x70 image (odd width, partial tiles) with a triangle across tile borders and one
    // tile row never drawn: every texel is checked against the per-pixel accessors, with a
    // distinct underlay value per texel.
    let (w, h) = (131u32, 70u32);
    let cam = ortho(w, h);
    let screen = [[3.5, 2.0], [120.25, 30.0], [40.0, 60.5]];
    let pos: Vec<Vec3> = screen.iter().map(|p| world(&cam, p[0], p[1])).collect();
    let mesh = Mesh::new(&pos, &[[0, 1, 2]]).unwrap();
    let mut fb = Framebuffer::new(w, h).unwrap();
    fb.clear([0, 0, 0, 255]);
    let state = DrawState {
        cull: Cull::None,
        ..DrawState::default()
    };
    fb.draw_mesh(
        &cam,
        &mesh,
        &Shading::Flat(Vec3::new(0.25, 0.5, 0.75)),
        &state,
    )
    .unwrap();
    let under: Vec<glam::Vec4> = (0..w * h)
        .map(|i| glam::Vec4::new(i as f32, -(i as f32), 2.0, 0.5))
        .collect();
    let mut out = vec![glam::Vec4::NAN; (w * h) as usize];
    fb.composite_linear_into(&under, &mut out);
    let mut drawn = 0;
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let want = if fb.depth_at(x, y).unwrap().is_finite() {
                drawn += 1;
                fb.color_at(x, y).unwrap().extend(1.0)
            } else {
                under[i]
            };
            assert_eq!(out[i], want, "texel ({x}, {y})");
        }
    }
    // About half the triangle's bounding box: the triangle was drawn, not skipped.
    assert!(drawn > 2000, "{drawn} pixels drawn");
}

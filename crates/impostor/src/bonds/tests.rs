use super::*;

/// Tiny deterministic RNG (LCG).
struct Lcg(u64);
impl Lcg {
    fn f(&mut self, lo: f32, hi: f32) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        lo + (hi - lo) * ((self.0 >> 40) as f32 / (1u64 << 24) as f32)
    }
}

#[test]
fn row_span_contains_every_point_of_the_hull_and_is_tight() {
    let mut rng = Lcg(3);
    let mut hits = 0;
    for _ in 0..2000 {
        let mut ends = [[0f32; 4]; 2];
        for e in &mut ends {
            let (x, y) = (rng.f(0.0, 100.0), rng.f(0.0, 100.0));
            let (w, h) = (rng.f(0.0, 20.0), rng.f(0.0, 20.0));
            *e = [x, x + w, y, y + h];
        }
        // Points of the hull: (1 − λ)·p + λ·q with p in A and q in B.
        for _ in 0..50 {
            let l = rng.f(0.0, 1.0);
            let (pa, pb) = (rng.f(0.0, 1.0), rng.f(0.0, 1.0));
            let (qa, qb) = (rng.f(0.0, 1.0), rng.f(0.0, 1.0));
            let [a, b] = ends;
            let px = a[0] + (a[1] - a[0]) * pa;
            let py = a[2] + (a[3] - a[2]) * pb;
            let qx = b[0] + (b[1] - b[0]) * qa;
            let qy = b[2] + (b[3] - b[2]) * qb;
            let (x, y) = (px + (qx - px) * l, py + (qy - py) * l);
            let (s0, s1) = row_span(&ends, y).expect("a hull point's row meets the hull");
            assert!(
                x >= s0 - 1e-3 && x <= s1 + 1e-3,
                "x {x} outside span [{s0}, {s1}] at y {y} for {ends:?}"
            );
            hits += 1;
        }
        // Tight: the span's ends are hull points (x of an interpolated corner), so a row
        // beyond both rectangles' y-ranges misses.
        let top = ends[0][2].min(ends[1][2]) - 1.0;
        assert!(row_span(&ends, top).is_none(), "{ends:?}");
    }
    assert_eq!(hits, 100_000);
}

// The previous scalar kernel (one lane at a time, validated against reftrace), kept as the
// reference of the lane kernel: the same IEEE operations in the same order.
/// Per-lane ray data of 8 pixels in one row, in the generic form of the intersection.
struct Lanes {
    /// `A = |d × u|²`.
    a: [f32; LANES],
    /// `g·(d × u)` (up to sign): `√A` times the ray–axis distance.
    dn: [f32; LANES],
    /// Closest approach `s = num / A`.
    num: [f32; LANES],
    /// `h(o)`: axial coordinate of the ray origin.
    h0: [f32; LANES],
    /// `d·u`.
    du: [f32; LANES],
    /// For rays parallel to the axis: whether the ray runs inside the infinite cylinder.
    par_in: [bool; LANES],
}

/// Intersect 8 rays with one bond: depths (`INFINITY` for a miss or a clipped hit) and flags.
///
/// Entry and exit of the solid capped cylinder are `max`/`min` of the infinite-cylinder interval
/// and the cap slab (module docs); entry nearer than the near plane takes the exit instead.
#[inline(always)]
fn solve8_scalar(
    rec: &BondRec,
    l: &Lanes,
    valid: usize,
    near: f32,
    far: f32,
) -> ([f32; LANES], [u32; LANES]) {
    let mut t = [f32::INFINITY; LANES];
    let mut flag = [0u32; LANES];
    for k in 0..LANES {
        let a = l.a[k];
        let par = !(a > PARALLEL_A);
        // Infinite cylinder: s ∓ √(r²A − dn²)/A.
        let ia = 1.0 / if par { 1.0 } else { a };
        let disc = rec.r2 * a - l.dn[k] * l.dn[k];
        let hc = (if disc > 0.0 { disc } else { 0.0 }).sqrt() * ia;
        let s = l.num[k] * ia;
        let side_hit = if par { l.par_in[k] } else { disc >= 0.0 };
        let t0 = if par { f32::NEG_INFINITY } else { s - hc };
        let t1 = if par { f32::INFINITY } else { s + hc };
        // Cap slab: 0 ≤ h0 + t·du ≤ len.
        let du = l.du[k];
        let du = if du.abs() > MIN_DU { du } else { MIN_DU };
        let inv = 1.0 / du;
        let ta = -l.h0[k] * inv;
        let tb = (rec.len - l.h0[k]) * inv;
        let (s0, s1) = if ta < tb { (ta, tb) } else { (tb, ta) };
        // Entry and exit of the solid.
        let en = if t0 > s0 { t0 } else { s0 };
        let ex = if t1 < s1 { t1 } else { s1 };
        let front = en >= near;
        let th = if front { en } else { ex };
        let cap = if front { s0 > t0 } else { s1 < t1 };
        let ok = side_hit && en <= ex && th >= near && th <= far && k < valid;
        t[k] = if ok { th } else { f32::INFINITY };
        flag[k] = (if front { 0 } else { FLAG_INSIDE }) | (if cap { FLAG_CAP } else { 0 });
    }
    (t, flag)
}

/// Fill the lanes of a perspective camera: `o = 0`, `d = (dx, dy, −1)`.
#[inline(always)]
fn lanes_persp(rec: &BondRec, dx: &[f32], dy: f32, qq: f32) -> Lanes {
    let [ux, uy, uz] = rec.u;
    let [nx, ny, nz] = rec.n;
    let [qx, qy, qz] = rec.q;
    let mut l = Lanes {
        a: [0.0; LANES],
        dn: [0.0; LANES],
        num: [0.0; LANES],
        h0: [-rec.au; LANES],
        du: [0.0; LANES],
        par_in: [qq <= rec.r2; LANES],
    };
    for k in 0..LANES {
        let x = dx[k];
        // d × u, component by component (z of d is −1).
        let c1 = dy * uz + uy;
        let c2 = -ux - x * uz;
        let c3 = x * uy - dy * ux;
        l.a[k] = c1 * c1 + c2 * c2 + c3 * c3;
        l.dn[k] = x * nx + dy * ny - nz;
        l.num[k] = x * qx + dy * qy - qz;
        l.du[k] = x * ux + dy * uy - uz;
    }
    l
}

/// Fill the lanes of an orthographic camera: `o = (ox, oy, 0)`, `d = (0, 0, −1)`.
#[inline(always)]
fn lanes_ortho(rec: &BondRec, ox: &[f32], oy: f32, a_eye: Vec3) -> Lanes {
    let [ux, uy, uz] = rec.u;
    let a = ux * ux + uy * uy;
    let mut l = Lanes {
        a: [a; LANES],
        dn: [0.0; LANES],
        num: [0.0; LANES],
        h0: [0.0; LANES],
        du: [-uz; LANES],
        par_in: [false; LANES],
    };
    for k in 0..LANES {
        let x = ox[k];
        // g = o − a; d × u = (uy, −ux, 0).
        let (gx, gy, gz) = (x - a_eye.x, oy - a_eye.y, -a_eye.z);
        let gu = gx * ux + gy * uy + gz * uz;
        l.dn[k] = gx * uy - gy * ux;
        // s = −(g·w)/A with w = d − (d·u)u = (uz·ux, uz·uy, −A) (as |u| = 1): written so,
        // not as `gz − uz·(g·u)`, which cancels two terms of the size of the depth when the
        // bond is seen nearly end-on.
        l.num[k] = gz * a - uz * (gx * ux + gy * uy);
        l.h0[k] = gu;
        l.par_in[k] = gx * gx + gy * gy + gz * gz - gu * gu <= rec.r2;
    }
    l
}

/// The lane kernel (`rays_*` + `solve8`) against the scalar reference on random bonds, views
/// and pixels, including bonds seen exactly end-on (rays parallel to the axis) and bonds
/// crossing the near plane: the same depths (bit for bit, up to the sign of zero) and the
/// same flags wherever a lane hits.
#[test]
fn lane_kernel_matches_the_scalar_reference() {
    use texmap_core::camera::Camera;
    let mut rng = Lcg(11);
    let (mut hits, mut compared, mut par_lanes) = (0usize, 0usize, 0usize);
    for trial in 0..600 {
        let ortho = trial % 3 == 2;
        let eye = if trial % 5 == 0 {
            Vec3::new(0.0, 0.0, 8.0)
        } else {
            Vec3::new(rng.f(-9.0, 9.0), rng.f(-9.0, 9.0), rng.f(4.0, 12.0))
        };
        let cam = if ortho {
            Camera::orthographic_look_at(eye, Vec3::ZERO, Vec3::Y, rng.f(3.0, 9.0), 96, 80)
        } else {
            Camera::perspective_look_at(eye, Vec3::ZERO, Vec3::Y, rng.f(10.0, 150.0), 96, 80)
        }
        .unwrap();
        let view = View::new(&cam);
        // Bond: random, or exactly along the view axis of the axis-aligned eye.
        let (pa, pb) = if trial % 5 == 0 {
            let p = Vec3::new(rng.f(-1.0, 1.0), rng.f(-1.0, 1.0), rng.f(-2.0, 2.0));
            (p, p - Vec3::Z * rng.f(0.5, 2.0))
        } else {
            let p = Vec3::new(rng.f(-3.0, 3.0), rng.f(-3.0, 3.0), rng.f(-3.0, 3.0));
            let q = Vec3::new(rng.f(-1.5, 1.5), rng.f(-1.5, 1.5), rng.f(-1.5, 1.5));
            (p, p + q)
        };
        let r = rng.f(0.05, 0.8);
        let a = eye_space_f64(&view, pa);
        let b = eye_space_f64(&view, pb);
        let Some(rec) = project(&view, a, b, r, [0, 1]) else {
            continue;
        };
        let bv = BondV::new(&rec, 5);
        let qq = Vec3::from(rec.q).length_squared();
        let (near, far) = (F32x8::splat(view.near), F32x8::splat(view.far));
        let [x0, y0, x1, y1] = rec.bbox.map(|v| v as u32);
        for y in y0.saturating_sub(2)..(y1 + 2).min(view.height) {
            let ys = (view.cy - (y as f32 + 0.5)) * view.inv_k;
            let mut xs = [0f32; LANES];
            let mut i = x0.saturating_sub(3);
            while i < (x1 + 3).min(view.width) {
                for (k, x) in xs.iter_mut().enumerate() {
                    *x = ((i + k as u32) as f32 + 0.5 - view.cx) * view.inv_k;
                }
                let lanes_ref = if view.ortho {
                    lanes_ortho(&rec, &xs, ys, rec.a())
                } else {
                    lanes_persp(&rec, &xs, ys, qq)
                };
                let (t_ref, f_ref) = solve8_scalar(&rec, &lanes_ref, LANES, view.near, view.far);
                let (x, yv) = (F32x8::load(&xs), F32x8::splat(ys));
                let rays = if view.ortho {
                    Ortho::rays(&bv, &Ortho::row(&bv, yv), x)
                } else {
                    Persp::rays(&bv, &Persp::row(&bv, yv), x)
                };
                let (t, word) = solve8(&bv, &rays, lanes::Mask8::first(LANES), near, far);
                let (t, word) = (t.store(), word.store());
                for k in 0..LANES {
                    par_lanes += !(lanes_ref.a[k] > PARALLEL_A) as usize;
                    compared += 1;
                    assert!(
                        t[k] == t_ref[k] || (t[k].is_infinite() && t_ref[k].is_infinite()),
                        "trial {trial} pixel ({}, {y}): lane t {} vs scalar {}",
                        i + k as u32,
                        t[k],
                        t_ref[k]
                    );
                    if t[k].is_finite() {
                        hits += 1;
                        assert_eq!(
                            word[k].to_bits(),
                            5 | f_ref[k],
                            "trial {trial} pixel ({}, {y}): flags",
                            i + k as u32
                        );
                    }
                }
                i += LANES as u32;
            }
        }
    }
    eprintln!("{hits} hits, {par_lanes} parallel lanes of {compared} lanes compared");
    assert!(
        hits > 20_000 && par_lanes > 10,
        "{hits} hits, {par_lanes} parallel lanes"
    );
}

/// The 8-lane rectangles of two end spheres against the scalar [`sphere_rect`]: bit-equal,
/// including spheres that reach or cross the eye plane (no finite bound: `None`).
#[test]
fn lane_sphere_rects_match_the_scalar_ones() {
    use texmap_core::camera::Camera;
    let mut rng = Lcg(7);
    let mut nones = 0;
    for trial in 0..20_000 {
        let fov = rng.f(5.0, 160.0);
        let cam =
            Camera::perspective_look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, fov, 64, 48)
                .unwrap();
        let view = View::new(&cam);
        let mut p = || Vec3::new(rng.f(-6.0, 6.0), rng.f(-6.0, 6.0), rng.f(-12.0, 1.0));
        let (a, b) = (p(), p());
        let r = rng.f(0.01, 2.0);
        let lanes = sphere_rects_persp(&view, a, b, r);
        let scalar = [sphere_rect(&view, a, r), sphere_rect(&view, b, r)];
        nones += lanes.iter().flatten().filter(|o| o.is_none()).count();
        let bits = |v: [[Option<(f32, f32)>; 2]; 2]| {
            v.map(|e| e.map(|o| o.map(|(lo, hi)| (lo.to_bits(), hi.to_bits()))))
        };
        assert_eq!(
            bits(lanes),
            bits(scalar),
            "trial {trial}: {a} {b} r {r} fov {fov}"
        );
    }
    assert!(
        nones > 100,
        "only {nones} unbounded axes: the eye-plane cases are not tested"
    );
}

/// The AVX2 depth and shading passes against the SSE2 ones on every tile of random
/// ball-and-stick scenes (perspective and orthographic): the same depths and winners, bit for
/// bit, then the same colours and depths. Skipped (with a note) on a CPU without AVX2.
#[test]
#[cfg(target_arch = "x86_64")]
fn avx2_and_sse_depth_passes_are_bit_identical() {
    use texmap_core::camera::Camera;
    use texmap_core::shade::Material;
    if !F32x8Avx2::available() {
        eprintln!("no AVX2 on this CPU: nothing to compare");
        return;
    }
    let mut rng = Lcg(23);
    let mut compared = 0usize;
    for trial in 0..12 {
        let mats = vec![Material::plastic(Vec3::ONE); 2];
        let mut scene = SphereScene::new(mats);
        scene.bond_radius = rng.f(0.05, 0.5);
        for i in 0..300u32 {
            let c = Vec3::new(rng.f(-4.0, 4.0), rng.f(-4.0, 4.0), rng.f(-4.0, 4.0));
            scene.push(c, rng.f(0.1, 0.5), (i % 2) as u16);
            if i > 0 {
                scene.bonds.push([i - 1, i]);
            }
        }
        let eye = Vec3::new(rng.f(-3.0, 3.0), rng.f(-3.0, 3.0), rng.f(2.0, 12.0));
        let cam = if trial % 3 == 2 {
            Camera::orthographic_look_at(eye, Vec3::ZERO, Vec3::Y, 9.0, 150, 110)
        } else {
            Camera::perspective_look_at(eye, Vec3::ZERO, Vec3::Y, rng.f(20.0, 120.0), 150, 110)
        }
        .unwrap();
        let view = View::new(&cam);
        let mut bins = BondBins::default();
        bins.build(&scene, &view);
        let k = Kernel {
            view,
            avx2: false,
            spec_pow: None,
            lighting: Lighting::default_for(&cam),
            materials: &scene.materials,
        };
        for ty in 0..view.tiles_y {
            for tx in 0..view.tiles_x {
                let t = (ty * view.tiles_x + tx) as usize;
                let recs = bins.tile(t);
                let (x0, y0) = (tx * TILE, ty * TILE);
                let (w, h) = ((view.width - x0).min(TILE), (view.height - y0).min(TILE));
                // A sphere-pass depth to test against: a slanted plane through the scene.
                let mut a = TileBuf {
                    depth: [f32::INFINITY; TILE_BUF],
                    win: [NONE; TILE_BUF],
                };
                for (i, d) in a.depth[..TILE_PX].iter_mut().enumerate() {
                    let (x, y) = ((x0 as usize + i % 32) as f32, (y0 as usize + i / 32) as f32);
                    let z = eye.length() + 0.02 * x - 0.03 * y;
                    *d = if (i / 7) % 3 == 0 { f32::INFINITY } else { z };
                }
                let mut b = TileBuf {
                    depth: a.depth,
                    win: a.win,
                };
                raster_sse(&k, recs, x0, y0, w, h, &mut a);
                // SAFETY: AVX2 checked above.
                unsafe { raster_avx2(&k, recs, x0, y0, w, h, &mut b) };
                let bits = |d: &[f32; TILE_BUF]| d.map(f32::to_bits);
                assert!(
                    bits(&a.depth) == bits(&b.depth),
                    "trial {trial} tile {tx},{ty}"
                );
                assert!(a.win == b.win, "trial {trial} tile {tx},{ty}: winners");
                compared += a.win.iter().filter(|&&w| w != NONE).count();
                // Shading: the same colours and depths from both backends.
                let mut out = [([[0u8; 4]; TILE_PX], [0f32; TILE_PX]); 2];
                let [(ca, da), (cb, db)] = &mut out;
                resolve_sse(&k, recs, x0, y0, w, h, &a, ca, da, TILE as usize);
                // SAFETY: AVX2 checked above.
                unsafe { resolve_avx2(&k, recs, x0, y0, w, h, &a, cb, db, TILE as usize) };
                assert!(ca == cb, "trial {trial} tile {tx},{ty}: colours");
                assert!(
                    da.map(f32::to_bits) == db.map(f32::to_bits),
                    "trial {trial}: depths"
                );
            }
        }
    }
    eprintln!("{compared} bond pixels compared");
    assert!(compared > 5_000, "only {compared} bond pixels");
}

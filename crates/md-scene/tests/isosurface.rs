//! Isosurfaces of volumetric data against analytic surfaces: a Gaussian's sphere on a skewed
//! grid, a p orbital's two lobes, a periodic slab's planes, a region cut by the grid's border.

use std::collections::HashMap;
use std::f64::consts::PI;

use glam::{DVec3, Vec3};
use texmap_md_io::volume::Volume;
use texmap_md_scene::isosurface::{IsoError, Side, isosurface};
use texmap_md_scene::surface::MolMesh;

/// A volume sampling `f` (Å in, value out) at `origin + i·s0 + j·s1 + k·s2`.
fn sample(
    origin: DVec3,
    steps: [DVec3; 3],
    dims: [usize; 3],
    periodic: bool,
    f: impl Fn(DVec3) -> f64,
) -> Volume {
    let mut data = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let p = origin + steps[0] * i as f64 + steps[1] * j as f64 + steps[2] * k as f64;
                data.push(f(p) as f32);
            }
        }
    }
    Volume::new(
        origin.to_array(),
        steps.map(|s| s.to_array()),
        dims,
        data,
        periodic,
        "test",
    )
    .unwrap()
}

/// Every edge of the mesh is shared by exactly two triangles, running opposite ways.
fn assert_closed(m: &MolMesh) {
    let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
    for t in &m.triangles {
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            *edges.entry((a, b)).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &edges {
        assert_eq!(n, 1, "edge {a}-{b} used {n} times the same way");
        assert_eq!(edges.get(&(b, a)), Some(&1), "edge {a}-{b} has no twin");
    }
}

#[test]
fn a_gaussian_on_a_skewed_grid_gives_its_sphere() {
    // exp(−|p − c|² / 2σ²) at level exp(−R²/2σ²): the sphere of radius R around c.
    let (c, sigma, r) = (DVec3::new(0.3, -0.2, 0.1), 0.8f64, 1.2f64);
    let level = (-(r * r) / (2.0 * sigma * sigma)).exp() as f32;
    // Skewed steps (monoclinic-like), 0.12 Å: the grid covers the sphere with margin.
    let steps = [
        DVec3::new(0.12, 0.0, 0.0),
        DVec3::new(0.04, 0.11, 0.0),
        DVec3::new(-0.03, 0.02, 0.12),
    ];
    let origin = DVec3::new(-2.0, -2.4, -2.2);
    let vol = sample(origin, steps, [42, 42, 40], false, |p| {
        (-(p - c).length_squared() / (2.0 * sigma * sigma)).exp()
    });
    let m = isosurface(&vol, level, Side::Above, 3).unwrap();
    assert!(m.triangles.len() > 2000, "{} triangles", m.triangles.len());
    assert!(m.kinds.iter().all(|&k| k == 3));
    assert_closed(&m);
    let cf = c.as_vec3();
    let mut worst = 0.0f32;
    for (p, n) in m.positions.iter().zip(&m.normals) {
        let d = *p - cf;
        worst = worst.max((d.length() - r as f32).abs());
        // Outward and radial: within 2° of the exact normal.
        assert!(n.dot(d.normalize()) > 2f32.to_radians().cos(), "{n} at {d}");
    }
    // Linear crossings on a Gaussian's flank and their mean within a cell: O(h²) inside.
    assert!(worst < 0.02, "worst radius error {worst} Å");
    let sphere = 4.0 / 3.0 * PI * r.powi(3);
    let rel = m.volume() / sphere - 1.0;
    assert!(rel.abs() < 0.02, "volume {} vs {sphere}", m.volume());
    let area = 4.0 * PI * r * r;
    assert!((m.area() / area - 1.0).abs() < 0.03, "area {}", m.area());
}

#[test]
fn a_p_orbital_has_two_mirror_lobes_each_lit_outside() {
    // x·exp(−r²/2): positive for x > 0, negative for x < 0, antisymmetric in x.
    let h = 0.15;
    let n = 61;
    let o = -4.5;
    let steps = [DVec3::X * h, DVec3::Y * h, DVec3::Z * h];
    let vol = sample(DVec3::splat(o), steps, [n, n, n], false, |p| {
        p.x * (-p.length_squared() / 2.0).exp()
    });
    let pos = isosurface(&vol, 0.1, Side::Above, 0).unwrap();
    let neg = isosurface(&vol, -0.1, Side::Below, 1).unwrap();
    assert_closed(&pos);
    assert_closed(&neg);
    assert!(pos.triangles.len() > 1000);
    // Mirror images: the same volume and area; centroids at ±x.
    assert!((pos.volume() / neg.volume() - 1.0).abs() < 1e-3);
    assert!((pos.area() / neg.area() - 1.0).abs() < 1e-3);
    let centroid =
        |m: &MolMesh| m.positions.iter().copied().sum::<Vec3>() / m.positions.len() as f32;
    let (cp, cn) = (centroid(&pos), centroid(&neg));
    assert!(cp.x > 0.8 && cn.x < -0.8, "{cp} {cn}");
    assert!((cp.x + cn.x).abs() < 1e-3);
    // Every vertex lies on its level within the grid's interpolation error, on its side.
    let f = |p: Vec3| p.x as f64 * (-(p.length_squared() as f64) / 2.0).exp();
    for p in &pos.positions {
        assert!((f(*p) - 0.1).abs() < 4e-3 && p.x > 0.0, "{p}: {}", f(*p));
    }
    for p in &neg.positions {
        assert!((f(*p) + 0.1).abs() < 4e-3 && p.x < 0.0, "{p}: {}", f(*p));
    }
    // Both lit on their outside: the normal points where the value moves away from the
    // enclosed side (down for the positive lobe, up for the negative one).
    let grad = |p: Vec3| {
        let e = 1e-3;
        Vec3::new(
            (f(p + Vec3::X * e) - f(p - Vec3::X * e)) as f32,
            (f(p + Vec3::Y * e) - f(p - Vec3::Y * e)) as f32,
            (f(p + Vec3::Z * e) - f(p - Vec3::Z * e)) as f32,
        )
    };
    for (p, n) in pos.positions.iter().zip(&pos.normals) {
        assert!(n.dot(grad(*p)) < 0.0);
    }
    for (p, n) in neg.positions.iter().zip(&neg.normals) {
        assert!(n.dot(grad(*p)) > 0.0);
    }
    // Exactly the enclosed volume of the positive lobe: x·exp(−r²/2) > 0.1, by quadrature.
    let mut inside = 0usize;
    let q = 0.03;
    let m = (4.0 / q) as i64;
    for i in 0..m {
        for j in -m..m {
            for k in -m..m {
                let p = DVec3::new(
                    (i as f64 + 0.5) * q,
                    (j as f64 + 0.5) * q,
                    (k as f64 + 0.5) * q,
                );
                if p.x * (-p.length_squared() / 2.0).exp() > 0.1 {
                    inside += 1;
                }
            }
        }
    }
    let exact = inside as f64 * q * q * q;
    assert!(
        (pos.volume() / exact - 1.0).abs() < 0.02,
        "{} vs {exact}",
        pos.volume()
    );
}

#[test]
fn a_periodic_grid_runs_on_across_the_cell_and_a_bounded_one_is_capped() {
    // cos(2π u) over a skewed cell (u the first fractional coordinate) at level 1/2: the
    // region |u| < 1/6 (mod 1), bounded by the planes u = 1/6 and u = 5/6 (≡ −1/6).
    let cell = [
        DVec3::new(6.0, 0.0, 0.0),
        DVec3::new(2.0, 5.0, 0.0),
        DVec3::new(0.5, 1.0, 4.0),
    ];
    let dims = [30, 25, 20];
    let steps = std::array::from_fn(|a| cell[a] / dims[a] as f64);
    let inv = glam::DMat3::from_cols(cell[0], cell[1], cell[2]).inverse();
    let frac = move |p: DVec3| inv * p;
    let field = move |p: DVec3| (2.0 * PI * frac(p).x).cos();
    let periodic = sample(DVec3::ZERO, steps, dims, true, field);
    let m = isosurface(&periodic, 0.5, Side::Above, 0).unwrap();
    // Every vertex lies on one of the two planes (or its image one period over): no cap.
    for p in &m.positions {
        let u = frac(p.as_dvec3()).x;
        let near = [-1.0 / 6.0, 1.0 / 6.0, 5.0 / 6.0, 7.0 / 6.0]
            .iter()
            .any(|&w| (u - w).abs() < 0.01);
        assert!(near, "vertex at u = {u}");
    }
    // Two planes, each spanning the cell's b x c face: area 2·|b x c|, within the half-cell
    // margins the surface runs past the faces.
    let face = cell[1].cross(cell[2]).length();
    let a = m.area();
    assert!(
        a > 2.0 * face && a < 2.0 * face * 1.25,
        "area {a} vs 2 x {face}"
    );

    // The same grid not periodic: the region at u ∈ [0, 1/6) and (5/6, 1) is cut by the
    // grid's border, so caps close it (vertices at u ≈ 0 and at the last grid plane).
    let bounded = Volume {
        periodic: false,
        ..periodic.clone()
    };
    let m = isosurface(&bounded, 0.5, Side::Above, 0).unwrap();
    assert_closed(&m);
    let last = (dims[0] - 1) as f64 / dims[0] as f64;
    let us: Vec<f64> = m.positions.iter().map(|p| frac(p.as_dvec3()).x).collect();
    assert!(us.iter().any(|u| u.abs() < 1e-4));
    assert!(us.iter().any(|u| (u - last).abs() < 1e-4));
    assert!(us.iter().all(|u| *u > -1e-4 && *u < last + 1e-4));
    // The enclosed volume: the slabs u ∈ [0, 1/6] and [5/6, last] of the cell.
    let vcell = cell[0].dot(cell[1].cross(cell[2]));
    let exact = vcell * (1.0 / 6.0 + (last - 5.0 / 6.0));
    // The grid's cross-section is one cell short along b and c (points 0..n−1).
    let exact =
        exact * ((dims[1] - 1) as f64 / dims[1] as f64) * ((dims[2] - 1) as f64 / dims[2] as f64);
    assert!(
        (m.volume() / exact - 1.0).abs() < 0.01,
        "{} vs {exact}",
        m.volume()
    );
}

#[test]
fn a_mirrored_grid_is_still_wound_outward_and_nothing_crosses_is_empty() {
    // Steps of negative determinant (the third axis reversed).
    let steps = [DVec3::X * 0.1, DVec3::Y * 0.1, DVec3::NEG_Z * 0.1];
    let vol = sample(
        DVec3::new(-2.0, -2.0, 2.0),
        steps,
        [41, 41, 41],
        false,
        |p| (-p.length_squared()).exp(),
    );
    let m = isosurface(&vol, 0.5, Side::Above, 0).unwrap();
    assert_closed(&m);
    assert!(m.volume() > 0.0);
    let r = (2f64.ln()).sqrt();
    let rel = m.volume() / (4.0 / 3.0 * PI * r.powi(3)) - 1.0;
    assert!(rel.abs() < 0.02, "{rel}");
    assert!(
        isosurface(&vol, 2.0, Side::Above, 0)
            .unwrap()
            .triangles
            .is_empty()
    );
    assert!(matches!(
        isosurface(&vol, f32::NAN, Side::Above, 0),
        Err(IsoError::BadLevel(l)) if l.is_nan()
    ));
}

#[test]
fn colour_bands_cut_the_surface_along_the_values_and_keep_it_closed() {
    use texmap_md_scene::isosurface::bands;
    let steps = [DVec3::X * 0.1, DVec3::Y * 0.1, DVec3::Z * 0.1];
    let vol = sample(DVec3::splat(-2.0), steps, [41, 41, 41], false, |p| {
        (-p.length_squared()).exp()
    });
    let m = isosurface(&vol, 0.3, Side::Above, 0).unwrap();
    // Colour by x over [-1, 1] in 16 bands, reversed too; one vertex with no value.
    let mut values: Vec<f64> = m.positions.iter().map(|p| p.x as f64).collect();
    values[7] = f64::NAN;
    for range in [(-1.0, 1.0), (1.0, -1.0)] {
        let b = bands(&m, &values, range, 16, 5, 99);
        assert_closed(&b);
        assert!(
            (b.area() / m.area() - 1.0).abs() < 1e-4,
            "{} vs {}",
            b.area(),
            m.area()
        );
        assert!((b.volume() / m.volume() - 1.0).abs() < 1e-4);
        assert!(b.triangles.len() > m.triangles.len());
        let (lo, hi) = range;
        // The triangles around the vertex with no value keep their area, in kind 99.
        let tri_area = |m: &MolMesh, t: &[u32; 3]| {
            let [a, c, d] = t.map(|i| m.positions[i as usize]);
            (c - a).cross(d - a).length() as f64 / 2.0
        };
        let around: f64 = m
            .triangles
            .iter()
            .filter(|t| t.contains(&7))
            .map(|t| tri_area(&m, t))
            .sum();
        let off: f64 = b
            .triangles
            .iter()
            .zip(&b.kinds)
            .filter(|(_, k)| **k == 99)
            .map(|(t, _)| tri_area(&b, t))
            .sum();
        assert!(
            around > 0.0 && (off / around - 1.0).abs() < 1e-4,
            "{off} vs {around}"
        );
        for (t, &k) in b.triangles.iter().zip(&b.kinds) {
            if k == 99 {
                continue;
            }
            assert!((5..21).contains(&k), "kind {k}");
            // Every corner of a piece lies in its band (ends open to the clamped values).
            let band = (k - 5) as f64;
            for &i in t {
                let u = (b.positions[i as usize].x as f64 - lo) / (hi - lo) * 16.0;
                let u = u.clamp(0.0, 16.0);
                assert!(
                    u >= band - 1e-3 && u <= band + 1.0 + 1e-3,
                    "u {u} in band {band}"
                );
            }
        }
    }
}

/// A slice through a skewed grid: a plane at the fraction asked along its axis, the value at
/// every vertex (a linear field's, exactly), both sides wound towards their normals; a periodic
/// grid's plane covers the whole cell.
#[test]
fn a_slice_is_a_plane_of_the_grids_values_seen_from_both_sides() {
    use texmap_md_scene::isosurface::{SliceError, slice};
    let steps = [
        DVec3::new(0.5, 0.0, 0.0),
        DVec3::new(0.1, 0.4, 0.0),
        DVec3::new(0.0, -0.1, 0.3),
    ];
    let f = |p: DVec3| 1.0 + p.x - 2.0 * p.y + 3.0 * p.z;
    let vol = sample(DVec3::new(1.0, 2.0, 3.0), steps, [6, 5, 7], false, f);
    let (m, values) = slice(&vol, 2, 0.25, 4).unwrap();
    // 6 x 5 points per side, 5 x 4 quads, two triangles each, two sides.
    assert_eq!(m.positions.len(), 60);
    assert_eq!(m.triangles.len(), 80);
    assert!(m.kinds.iter().all(|&k| k == 4));
    let inv = glam::DMat3::from_cols(steps[0], steps[1], steps[2]).inverse();
    for (p, v) in m.positions.iter().zip(&values) {
        let q = inv * (p.as_dvec3() - DVec3::new(1.0, 2.0, 3.0));
        assert!((q.z - 1.5).abs() < 1e-5, "{q}");
        assert!(
            (v - f(p.as_dvec3())).abs() < 1e-4,
            "{v} vs {}",
            f(p.as_dvec3())
        );
    }
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        let n = m.normals[t[0] as usize];
        assert!((b - a).cross(c - a).normalize().dot(n) > 0.999);
    }
    // Periodic: the plane spans the cell, one more row and column.
    let periodic = Volume {
        periodic: true,
        ..vol.clone()
    };
    let (m, values) = slice(&periodic, 0, 1.0, 0).unwrap();
    assert_eq!(m.positions.len(), 2 * 6 * 8);
    assert!(values.iter().all(|v| v.is_finite()));
    let far = m
        .positions
        .iter()
        .map(|p| (inv * (p.as_dvec3() - DVec3::new(1.0, 2.0, 3.0))).z)
        .fold(0.0f64, f64::max);
    assert!((far - 7.0).abs() < 1e-4, "{far}");
    assert_eq!(slice(&vol, 3, 0.5, 0).unwrap_err(), SliceError::BadAxis(3));
    assert_eq!(
        slice(&vol, 0, 1.5, 0).unwrap_err(),
        SliceError::BadFraction(1.5)
    );
}

/// The same surface, vertex for vertex, whatever the number of threads.
#[test]
fn an_isosurface_is_the_same_on_any_thread_count() {
    let steps = [
        DVec3::X * 0.13,
        DVec3::new(0.02, 0.12, 0.0),
        DVec3::Z * 0.11,
    ];
    let vol = sample(DVec3::splat(-2.5), steps, [40, 41, 45], false, |p| {
        (p.x * 1.3).sin() * (p.y * 0.9).cos() + 0.3 * p.z
    });
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| isosurface(&vol, 0.2, Side::Above, 0).unwrap())
    };
    let one = run(1);
    assert!(one.triangles.len() > 1000);
    for threads in [2, 3] {
        assert_eq!(run(threads), one, "{threads} threads");
    }
}

//! The RTIN's error bound, checked against every grid sample with an independent f64 barycentric
//! evaluation of the triangle each sample lies in; analytic grids with known triangle counts.

use texmap_terrain::dem::{Georef, Grid};
use texmap_terrain::greedy::greedy;
use texmap_terrain::rtin::{ErrorMap, GridMesh, extract};

/// A seeded rough surface: a sum of incommensurate sines plus a hashed-noise term (relief ~300 m).
fn rough(n: u32) -> Vec<f32> {
    (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f64, (i / n) as f64);
            let mut hsh = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            hsh ^= hsh >> 29;
            let noise = (hsh % 1000) as f64 / 1000.0 - 0.5;
            (150.0 * (x * 0.05).sin() * (y * 0.031).cos()
                + 80.0 * (x * 0.13 + y * 0.07).sin()
                + 4.0 * noise) as f32
        })
        .collect()
}

/// Max over all samples of |h − triangle interpolation| (f64), and the number of samples covered.
fn measured_error(mesh: &GridMesh, h: &[f32], n: u32) -> (f64, usize) {
    let mut covered = vec![false; (n * n) as usize];
    let mut worst = 0.0f64;
    for t in &mesh.triangles {
        let p = t
            .map(|v| mesh.vertices[v as usize])
            .map(|[x, y]| (x as f64, y as f64, h[(y * n + x) as usize] as f64));
        let (x0, x1) = (
            p.iter().map(|q| q.0).fold(f64::MAX, f64::min),
            p.iter().map(|q| q.0).fold(f64::MIN, f64::max),
        );
        let (y0, y1) = (
            p.iter().map(|q| q.1).fold(f64::MAX, f64::min),
            p.iter().map(|q| q.1).fold(f64::MIN, f64::max),
        );
        let det = (p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[2].0 - p[0].0) * (p[1].1 - p[0].1);
        for y in y0 as u32..=y1 as u32 {
            for x in x0 as u32..=x1 as u32 {
                let (fx, fy) = (x as f64, y as f64);
                let l1 =
                    ((fx - p[0].0) * (p[2].1 - p[0].1) - (p[2].0 - p[0].0) * (fy - p[0].1)) / det;
                let l2 =
                    ((p[1].0 - p[0].0) * (fy - p[0].1) - (fx - p[0].0) * (p[1].1 - p[0].1)) / det;
                let l0 = 1.0 - l1 - l2;
                if l0 < -1e-9 || l1 < -1e-9 || l2 < -1e-9 {
                    continue;
                }
                let z = l0 * p[0].2 + l1 * p[1].2 + l2 * p[2].2;
                let hs = h[(y * n + x) as usize] as f64;
                if !hs.is_nan() {
                    worst = worst.max((hs - z).abs());
                }
                covered[(y * n + x) as usize] = true;
            }
        }
    }
    (worst, covered.iter().filter(|&&c| c).count())
}

#[test]
fn bound_holds_at_every_sample() {
    let n = 129;
    let h = rough(n);
    let map = ErrorMap::new(&h, n);
    let mut last = usize::MAX;
    for e in [0.5f32, 2.0, 5.0, 10.0, 30.0, 100.0] {
        let mesh = extract(&map, &h, 0, 0, n - 1, e, 1);
        let (worst, covered) = measured_error(&mesh, &h, n);
        // f32 plane evaluation in the map vs f64 here: 1e-3 m of rounding at ~300 m heights.
        assert!(worst <= e as f64 + 1e-3, "error {e}: measured {worst}");
        assert!(mesh.max_bound <= e, "error {e}: bound {}", mesh.max_bound);
        assert_eq!(
            covered,
            (n * n) as usize,
            "error {e}: every sample under a triangle"
        );
        assert!(
            mesh.triangles.len() < last,
            "fewer triangles at a larger error"
        );
        last = mesh.triangles.len();
        // Conforming: every interior edge is shared by exactly two triangles (no T-junction).
        let mut edges = std::collections::HashMap::new();
        for t in &mesh.triangles {
            for k in 0..3 {
                let (a, b) = (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]));
                *edges.entry((a, b)).or_insert(0) += 1;
            }
        }
        let boundary = edges.values().filter(|&&c| c == 1).count();
        assert!(edges.values().all(|&c| c <= 2));
        // Boundary edges only on the tile border: their count equals the border vertex count.
        let border = mesh
            .vertices
            .iter()
            .filter(|[x, y]| *x == 0 || *y == 0 || *x == n - 1 || *y == n - 1)
            .count();
        assert_eq!(boundary, border, "error {e}");
    }
}

#[test]
fn cone_bound_and_symmetry() {
    // A cone's apex is a crease: the error must be measured, not predicted, and stay bounded.
    let n = 65;
    let h: Vec<f32> = (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f64 - 32.0, (i / n) as f64 - 32.0);
            (100.0 - 3.0 * (x * x + y * y).sqrt()) as f32
        })
        .collect();
    let map = ErrorMap::new(&h, n);
    for e in [0.1f32, 1.0, 8.0] {
        let mesh = extract(&map, &h, 0, 0, n - 1, e, 1);
        let (worst, _) = measured_error(&mesh, &h, n);
        assert!(worst <= e as f64 + 1e-4, "cone at {e}: {worst}");
    }
}

#[test]
fn holes_are_dropped_and_the_rest_is_bounded() {
    let n = 65;
    let mut h = rough(n);
    for y in 20..30 {
        for x in 10..25 {
            h[(y * n + x) as usize] = f32::NAN;
        }
    }
    let map = ErrorMap::new(&h, n);
    let mesh = extract(&map, &h, 0, 0, n - 1, 20.0, 1);
    for t in &mesh.triangles {
        for &v in t {
            let [x, y] = mesh.vertices[v as usize];
            assert!(!h[(y * n + x) as usize].is_nan());
        }
    }
    let (worst, covered) = measured_error(&mesh, &h, n);
    assert!(worst <= 20.0 + 1e-3);
    // Every valid sample is a vertex or under a triangle; the 10 x 15 hole is not covered except
    // at most by triangles touching it — none do, since they would need a no-data vertex.
    assert_eq!(covered, (n * n - 150) as usize);
}

#[test]
fn greedy_bound_holds_with_fewer_triangles_than_rtin() {
    let n = 129;
    let h = rough(n);
    let map = ErrorMap::new(&h, n);
    let grid = Grid::new("rough", n, n, h.clone(), Georef::local(1.0)).unwrap();
    for e in [2.0f32, 10.0, 30.0] {
        let g = greedy(&grid, e).unwrap();
        let (worst, covered) = measured_error(&g, &h, n);
        assert!(worst <= e as f64 + 1e-6, "greedy at {e}: {worst}");
        assert_eq!(covered, (n * n) as usize);
        let r = extract(&map, &h, 0, 0, n - 1, e, 1);
        assert!(
            g.triangles.len() < r.triangles.len(),
            "{e} m: greedy {} vs RTIN {}",
            g.triangles.len(),
            r.triangles.len()
        );
        // Same winding as the RTIN (counter-clockwise seen from above with rows going south).
        for t in &g.triangles {
            let [a, b, c] = t
                .map(|v| g.vertices[v as usize])
                .map(|[x, y]| (x as i64, y as i64));
            assert!((b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0) < 0);
        }
    }
    // A non-square, non-2^k+1 grid works as is.
    let odd = Grid::new(
        "odd",
        50,
        37,
        (0..50 * 37)
            .map(|i| ((i % 50) as f32 * 0.3).sin() * 20.0)
            .collect(),
        Georef::local(1.0),
    )
    .unwrap();
    let g = greedy(&odd, 1.0).unwrap();
    assert!(g.max_bound <= 1.0);
}

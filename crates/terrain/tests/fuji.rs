//! Mapbox's Fuji tile (a Terrain-RGB PNG written by Mapbox, the fixture of mapbox/martini): our
//! Terrain-RGB decoding and RTIN mesh on real data. The grid is made 513² as martini's test does
//! (the last row and column repeat the 512th); the mesh at each error bound is checked against
//! every grid sample by brute force (the true vertical error of the triangulated surface), and
//! its triangle count is printed beside martini's (19,086 at 30 m, from ../shared/peers).

use std::path::PathBuf;

use texmap_terrain::dem::png::terrain_rgb_height;
use texmap_terrain::rtin::{ErrorMap, extract};

fn fuji() -> (Vec<f32>, u32) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuji.png");
    let img = image::open(&path).unwrap().to_rgba8();
    let (w, h) = img.dimensions();
    assert_eq!((w, h), (512, 512));
    let n = w + 1;
    let mut g = vec![0f32; (n * n) as usize];
    for y in 0..n {
        for x in 0..n {
            let p = img.get_pixel(x.min(w - 1), y.min(h - 1));
            g[(y * n + x) as usize] = terrain_rgb_height(p[0], p[1], p[2]) as f32;
        }
    }
    (g, n)
}

/// The largest |surface − sample| over every grid sample, the surface being the mesh's
/// triangles (each sample measured in the triangles that contain it).
fn true_error(g: &[f32], n: u32, verts: &[[u32; 2]], tris: &[[u32; 3]]) -> f32 {
    let mut worst = 0f32;
    let mut covered = vec![false; (n * n) as usize];
    for t in tris {
        let p = t.map(|i| verts[i as usize]);
        let h = p.map(|q| g[(q[1] * n + q[0]) as usize] as f64);
        let (x0, y0) = (p[0][0] as f64, p[0][1] as f64);
        let (e1, e2) = (
            [p[1][0] as f64 - x0, p[1][1] as f64 - y0],
            [p[2][0] as f64 - x0, p[2][1] as f64 - y0],
        );
        let det = e1[0] * e2[1] - e1[1] * e2[0];
        assert!(det != 0.0, "degenerate triangle {t:?}");
        let xs = p.map(|q| q[0]);
        let ys = p.map(|q| q[1]);
        for y in *ys.iter().min().unwrap()..=*ys.iter().max().unwrap() {
            for x in *xs.iter().min().unwrap()..=*xs.iter().max().unwrap() {
                let (dx, dy) = (x as f64 - x0, y as f64 - y0);
                let u = (dx * e2[1] - dy * e2[0]) / det;
                let v = (e1[0] * dy - e1[1] * dx) / det;
                if u < -1e-9 || v < -1e-9 || u + v > 1.0 + 1e-9 {
                    continue;
                }
                let z = h[0] + u * (h[1] - h[0]) + v * (h[2] - h[0]);
                let k = (y * n + x) as usize;
                worst = worst.max((z - g[k] as f64).abs() as f32);
                covered[k] = true;
            }
        }
    }
    assert!(
        covered.iter().all(|c| *c),
        "the mesh leaves grid samples uncovered"
    );
    worst
}

#[test]
fn fuji_meshes_stay_within_their_error_bound_on_every_sample() {
    let (g, n) = fuji();
    let (lo, hi) = g
        .iter()
        .fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    // Mount Fuji: 3,776 m at the summit; the tile reaches it.
    assert!(hi > 3_700.0 && hi < 3_800.0 && lo > 0.0, "{lo}..{hi}");
    let map = ErrorMap::new(&g, n);
    let mut last = usize::MAX;
    for max_error in [1.0f32, 5.0, 10.0, 30.0, 100.0, 500.0] {
        let mesh = extract(&map, &g, 0, 0, n - 1, max_error, 1);
        let e = true_error(&g, n, &mesh.vertices, &mesh.triangles);
        assert!(
            e <= max_error + 1e-3,
            "{max_error} m: true error {e} m with {} triangles",
            mesh.triangles.len()
        );
        assert!(
            mesh.triangles.len() < last,
            "coarser bounds give fewer triangles"
        );
        last = mesh.triangles.len();
        eprintln!(
            "fuji 513², max error {max_error} m: {} triangles, {} vertices, true error {e:.2} m{}",
            mesh.triangles.len(),
            mesh.vertices.len(),
            if max_error == 30.0 {
                " (martini: 19,086 triangles)"
            } else {
                ""
            }
        );
    }
}

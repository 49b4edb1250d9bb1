//! Mapbox's Fuji tile (a Terrain-RGB PNG written by Mapbox, the fixture of mapbox/martini): our
//! Terrain-RGB decoding and RTIN mesh on real data. The grid is made 513² as martini's test does
//! (the last row and column repeat the 512th); the mesh at each error bound is checked against
//! every grid sample by brute force (the true vertical error of the triangulated surface), and
//! its triangle count is printed beside martini's (19,086 at 30 m, from ../shared/peers).

use std::path::PathBuf;

use texmap_terrain::dem::png::terrain_rgb_height;
use texmap_terrain::rtin::{ErrorMap, extract};

use crate::common;
use common::true_error;

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
        let e = true_error(&g, n, (n, n), &mesh.vertices, &mesh.triangles);
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

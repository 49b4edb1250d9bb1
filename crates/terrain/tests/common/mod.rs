//! Shared by the real-data mesh tests: the true vertical error of a grid mesh, by brute force.

/// The largest |surface − sample| over the finite samples of the `w x h` grid stored with row
/// `stride` in `g`, the surface being the mesh's triangles (each sample measured in every triangle
/// that contains it). Triangles with a no-data (NaN) corner are holes; every finite sample of the
/// grid must be covered by some triangle.
pub fn true_error(
    g: &[f32],
    stride: u32,
    (w, h): (u32, u32),
    verts: &[[u32; 2]],
    tris: &[[u32; 3]],
) -> f32 {
    let at = |x: u32, y: u32| g[(y * stride + x) as usize];
    let mut worst = 0f32;
    let mut covered = vec![false; (w * h) as usize];
    for t in tris {
        let p = t.map(|i| verts[i as usize]);
        let h3 = p.map(|q| at(q[0], q[1]) as f64);
        assert!(
            h3.iter().all(|z| z.is_finite()),
            "a triangle on no-data {t:?}"
        );
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
                let s = at(x, y) as f64;
                if x >= w || y >= h || !s.is_finite() {
                    continue;
                }
                let z = h3[0] + u * (h3[1] - h3[0]) + v * (h3[2] - h3[0]);
                worst = worst.max((z - s).abs() as f32);
                covered[(y * w + x) as usize] = true;
            }
        }
    }
    let uncovered = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| at(x, y).is_finite() && !covered[(y * w + x) as usize])
        .count();
    assert_eq!(
        uncovered, 0,
        "the mesh leaves finite grid samples uncovered"
    );
    worst
}

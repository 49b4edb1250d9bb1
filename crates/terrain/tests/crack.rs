//! Crack test: neighbouring chunks at mixed depths, rasterised with texmap-raster, must show no
//! background pixel where the full-resolution terrain covers the image; without their skirts the
//! same selection must show some (so the test can fail).

use texmap_core::camera::Camera;
use texmap_core::glam::Vec3;
use texmap_raster::{Cull, DrawState, Framebuffer, Mesh, Shading};
use texmap_terrain::chunks::{self, Chunk};
use texmap_terrain::dem::{Georef, Grid};

fn rough(n: u32) -> Vec<f32> {
    (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f64, (i / n) as f64);
            let mut hsh = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
            hsh ^= hsh >> 29;
            let noise = (hsh % 1000) as f64 / 1000.0 - 0.5;
            (150.0 * (x * 0.05).sin() * (y * 0.031).cos()
                + 80.0 * (x * 0.13 + y * 0.07).sin()
                + 20.0 * noise) as f32
        })
        .collect()
}

fn coverage(cam: &Camera, meshes: &[(Vec<Vec3>, Vec<[u32; 3]>)]) -> Vec<bool> {
    let mut fb = Framebuffer::new(cam.width(), cam.height()).unwrap();
    fb.clear([0, 0, 0, 255]);
    let state = DrawState {
        cull: Cull::None,
        ..DrawState::default()
    };
    for (p, t) in meshes {
        let mesh = Mesh::new(p, t).unwrap();
        fb.draw_mesh(cam, &mesh, &Shading::Flat(Vec3::ONE), &state)
            .unwrap();
    }
    fb.to_frame().depth.iter().map(|d| d.is_finite()).collect()
}

fn holes(cam: &Camera, reference: &[bool], chunks: &[&Chunk], skirts: bool) -> usize {
    let meshes: Vec<_> = chunks
        .iter()
        .map(|c| {
            let n = if skirts {
                c.mesh.triangles.len()
            } else {
                c.surface_triangles as usize
            };
            (c.mesh.positions.clone(), c.mesh.triangles[..n].to_vec())
        })
        .collect();
    let got = coverage(cam, &meshes);
    let (w, h) = (cam.width() as i64, cam.height() as i64);
    // Pixels whose 5x5 neighbourhood is all terrain in the reference (away from silhouettes, where
    // a coarser surface may legitimately cover less).
    let inside = |x: i64, y: i64| {
        (-2..=2).all(|dy| {
            (-2..=2).all(|dx| {
                let (u, v) = (x + dx, y + dy);
                u >= 0 && v >= 0 && u < w && v < h && reference[(v * w + u) as usize]
            })
        })
    };
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| inside(x, y) && !got[(y * w + x) as usize])
        .count()
}

#[test]
fn mixed_depths_show_no_background_through_the_terrain() {
    let n = 257;
    let grid = Grid::new("rough", n, n, rough(n), Georef::local(10.0)).unwrap();
    let tree = chunks::build(&grid, 4.0, 65).unwrap();
    assert_eq!(tree.max_depth, 2);
    // Top-left quadrant at depth 1, the other three quadrants as depth-2 chunks.
    let mut sel: Vec<&Chunk> = vec![tree.get(1, 0, 0).unwrap()];
    for iy in 0..4 {
        for ix in 0..4 {
            if !(ix < 2 && iy < 2) {
                sel.push(tree.get(2, ix, iy).unwrap());
            }
        }
    }
    assert!(sel[0].geometric_error > sel[1].geometric_error);
    // The selection is the depth-1 chunk plus the children of the other three depth-1 cells.
    let kids = tree.children(tree.get(1, 1, 1).unwrap()).unwrap();
    assert_eq!(kids, [(2, 2), (3, 2), (2, 3), (3, 3)]);
    let full = texmap_terrain::rtin::extract(
        &texmap_terrain::rtin::ErrorMap::new(grid.heights(), n),
        grid.heights(),
        0,
        0,
        n - 1,
        0.0,
        1,
    );
    let fp: Vec<Vec3> = full
        .vertices
        .iter()
        .map(|&[x, y]| chunks::vertex(&grid, x, y, grid.at(x, y)).0)
        .collect();
    let mut any_gap_without = 0;
    for (eye, target) in [
        (
            Vec3::new(1280.0, 1800.0, 3600.0),
            Vec3::new(1280.0, 0.0, 1280.0),
        ),
        (
            Vec3::new(-900.0, 1200.0, -700.0),
            Vec3::new(1100.0, 0.0, 1300.0),
        ),
        (
            Vec3::new(1280.0, 2600.0, 1300.0),
            Vec3::new(1280.0, 0.0, 1280.0),
        ),
    ] {
        let cam = Camera::perspective_look_at(eye, target, Vec3::Y, 60.0, 320, 240).unwrap();
        let reference = coverage(&cam, &[(fp.clone(), full.triangles.clone())]);
        assert!(
            reference.iter().filter(|&&c| c).count() > 10_000,
            "the terrain fills the view"
        );
        assert_eq!(
            holes(&cam, &reference, &sel, true),
            0,
            "eye {eye}: background through the skirted chunks"
        );
        any_gap_without += holes(&cam, &reference, &sel, false);
    }
    assert!(
        any_gap_without > 0,
        "without skirts the mixed depths must crack (else the test proves nothing)"
    );
}

#[test]
fn chunk_errors_bound_and_double_per_level() {
    let n = 257;
    let grid = Grid::new("rough", n, n, rough(n), Georef::local(10.0)).unwrap();
    let tree = chunks::build(&grid, 2.0, 65).unwrap();
    assert_eq!(
        tree.levels.iter().map(|l| l.len()).collect::<Vec<_>>(),
        vec![1, 4, 16]
    );
    for level in &tree.levels {
        for c in level {
            assert_eq!(c.target_error, 2.0 * (1 << (2 - c.depth)) as f32);
            // Capped at (chunk − 1)² cells: at most 2·64² surface triangles.
            assert!(c.surface_triangles <= 2 * 64 * 64);
            assert!(c.skirt >= 5.0 * c.geometric_error);
            assert!(c.mesh.positions.iter().all(|p| p.is_finite()));
        }
    }
    // Determinism across thread counts.
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| chunks::build(&grid, 2.0, 65).unwrap());
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap()
        .install(|| chunks::build(&grid, 2.0, 65).unwrap());
    assert_eq!(one.levels, two.levels);
}

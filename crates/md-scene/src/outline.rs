//! The periodic box outline as spheres: every sphere method draws spheres and none draws lines,
//! so each of the cell's twelve edges becomes a row of small grey spheres spaced at one radius,
//! close enough to read as a line.

use glam::Vec3;
use texmap_core::shade::Material;
use texmap_impostor::SphereScene;
use texmap_md_io::UnitCell;

/// Most spheres on one edge, whatever the box (an edge of `n` spheres is `n + 1` points).
pub const MAX_SPHERES_PER_EDGE: usize = 2000;

/// The outline's sphere radius as a fraction of the cell's shortest edge length.
pub const OUTLINE_RADIUS_FRACTION: f64 = 0.004;

/// The 8 corners of a periodic cell: corner `c` at the fractional coordinates given by its bits
/// (bit 0: along the first cell vector, bit 1: the second, bit 2: the third).
pub fn cell_corners(cell: &UnitCell) -> [Vec3; 8] {
    std::array::from_fn(|c| {
        let p = cell.to_cartesian([(c & 1) as f64, ((c >> 1) & 1) as f64, ((c >> 2) & 1) as f64]);
        Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32)
    })
}

/// Append the outline of `cell` to `scene`: one new matte grey material, and along each edge
/// evenly spaced spheres (both ends included) at most one radius apart, the radius
/// [`OUTLINE_RADIUS_FRACTION`] of the shortest edge (at least 1e-3).
pub fn add_box_outline(cell: &UnitCell, scene: &mut SphereScene) {
    let grey = scene.materials.len() as u16;
    scene.materials.push(Material::matte(Vec3::splat(0.6)));
    let l = cell.lengths();
    let r = ((l[0].min(l[1]).min(l[2]) * OUTLINE_RADIUS_FRACTION) as f32).max(1e-3);
    let corners = cell_corners(cell);
    for a in 0..8u32 {
        for bit in [1u32, 2, 4] {
            if a & bit == 0 {
                let (p, q) = (corners[a as usize], corners[(a | bit) as usize]);
                let n = ((p.distance(q) / r).ceil() as usize).clamp(1, MAX_SPHERES_PER_EDGE);
                for k in 0..=n {
                    scene.push(p.lerp(q, k as f32 / n as f32), r, grey);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance from `p` to the segment `a`–`b`.
    fn to_segment(p: Vec3, a: Vec3, b: Vec3) -> f32 {
        let ab = b - a;
        let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
        (a + ab * t).distance(p)
    }

    #[test]
    fn outline_spheres_lie_on_the_cell_edges_and_cover_them() {
        // A triclinic cell, its edges computed here from lengths and angles by hand.
        let (a, b, c) = (12.0f64, 9.0f64, 15.0f64);
        let gamma = 70f64.to_radians();
        let cell = UnitCell::from_lengths_angles([a, b, c], [90.0, 90.0, 70.0]).unwrap();
        let va = Vec3::new(a as f32, 0.0, 0.0);
        let vb = Vec3::new((b * gamma.cos()) as f32, (b * gamma.sin()) as f32, 0.0);
        let vc = Vec3::new(0.0, 0.0, c as f32);
        let corners = cell_corners(&cell);
        for (k, p) in corners.iter().enumerate() {
            let want = va * (k & 1) as f32 + vb * ((k >> 1) & 1) as f32 + vc * (k >> 2) as f32;
            assert!(p.distance(want) < 1e-4, "corner {k}: {p} vs {want}");
        }
        let edges: Vec<(Vec3, Vec3)> = (0..8)
            .flat_map(|i| [1, 2, 4].map(|bit| (i, i | bit)))
            .filter(|(i, j)| i != j)
            .map(|(i, j)| (corners[i], corners[j]))
            .collect();
        assert_eq!(edges.len(), 12);

        let mut scene = SphereScene::default();
        scene.push(Vec3::ONE, 1.0, 0);
        scene.materials.push(Material::plastic(Vec3::X));
        add_box_outline(&cell, &mut scene);
        assert_eq!(scene.materials.len(), 2);
        let r = (9.0 * OUTLINE_RADIUS_FRACTION) as f32;
        // Every outline sphere sits on an edge, with the grey material and the radius.
        for i in 1..scene.len() {
            let d = edges
                .iter()
                .map(|&(a, b)| to_segment(scene.centers[i], a, b))
                .fold(f32::INFINITY, f32::min);
            assert!(d < 1e-4, "sphere {i} is {d} from every edge");
            assert_eq!(scene.kinds[i], 1);
            assert!((scene.radii[i] - r).abs() < 1e-6);
        }
        // Every point of every edge is within one radius of a sphere centre (no gaps).
        for &(a, b) in &edges {
            for k in 0..=500 {
                let p = a.lerp(b, k as f32 / 500.0);
                let near = scene.centers[1..]
                    .iter()
                    .map(|c| c.distance(p))
                    .fold(f32::INFINITY, f32::min);
                assert!(near <= r * 0.5 + 1e-4, "gap of {near} on an edge");
            }
        }
    }

    #[test]
    fn huge_boxes_keep_a_bounded_sphere_count() {
        let cell = UnitCell::orthorhombic(1.0, 1.0, 1.0e6).unwrap();
        let mut scene = SphereScene::default();
        add_box_outline(&cell, &mut scene);
        // Four long edges hit the cap; the eight unit edges take 1 / (0.004) = 250 steps.
        assert_eq!(scene.len(), 4 * (MAX_SPHERES_PER_EDGE + 1) + 8 * 251);
    }
}

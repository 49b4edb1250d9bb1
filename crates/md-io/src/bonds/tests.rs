//! The grid against all-pairs references: exact (f32, the rule of the module doc) where the
//! arithmetic of a periodic shift is exact (open boxes; power-of-two orthorhombic boxes with
//! dyadic coordinates), and against an f64 minimum image within rounding of the thresholds for a
//! triclinic box.

use super::*;
use crate::pbc::minimum_image;

struct Lcg(u64);
impl Lcg {
    fn next_u32(&mut self) -> u32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 32) as u32
    }
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 / (1u32 << 24) as f32
    }
    /// A multiple of 2^-12 in [lo, lo + span), exactly representable.
    fn dyadic(&mut self, lo: i32, span: u32) -> f32 {
        lo as f32 + (self.next_u32() % (span * 4096)) as f32 / 4096.0
    }
    /// A radius: mostly covalent radii of common elements, some that bond nothing.
    fn radius(&mut self) -> f32 {
        const R: [f32; 10] = [0.31, 0.31, 0.66, 0.66, 0.76, 0.71, 1.05, 1.02, 0.0, -1.0];
        match self.next_u32() % 64 {
            0 => f32::NAN,
            k => R[k as usize % R.len()],
        }
    }
}

/// The bond rule of the module doc for displacement `v` of atoms with radii `ri`, `rj`.
fn bonded(v: [f32; 3], ri: f32, rj: f32) -> bool {
    let d2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    let lim = ri + rj + BOND_TOLERANCE;
    ri > 0.0 && rj > 0.0 && d2 < lim * lim && d2 > MIN_BOND_LENGTH * MIN_BOND_LENGTH
}

/// All pairs, plain displacements.
fn all_pairs_open(pos: &[[f32; 3]], r: &[f32]) -> Vec<[u32; 2]> {
    let mut out = Vec::new();
    for i in 0..pos.len() {
        for j in i + 1..pos.len() {
            let v = std::array::from_fn(|k| pos[j][k] - pos[i][k]);
            if bonded(v, r[i], r[j]) {
                out.push([i as u32, j as u32]);
            }
        }
    }
    out
}

/// All pairs in the cubic box [o, o + l)³ by wrapping each coordinate and taking the nearest
/// image per axis: exact f32 arithmetic when `l` is a power of two and coordinates are dyadic
/// with few enough bits (multiples of 2^-12 near 0, of 2^-7 near 2^16).
fn all_pairs_cube(pos: &[[f32; 3]], r: &[f32], o: f32, l: f32) -> Vec<[u32; 2]> {
    let w: Vec<[f32; 3]> = pos
        .iter()
        .map(|p| p.map(|x| (x - o) - l * ((x - o) / l).floor()))
        .collect();
    let mut out = Vec::new();
    for i in 0..pos.len() {
        for j in i + 1..pos.len() {
            let v = std::array::from_fn(|k| {
                let d = w[j][k] - w[i][k];
                d - l * (d / l).round()
            });
            if bonded(v, r[i], r[j]) {
                out.push([i as u32, j as u32]);
            }
        }
    }
    out
}

/// A radius `ra` such that `ra + rb + BOND_TOLERANCE` is exactly `lim` in f32.
fn radius_for_limit(lim: f32, rb: f32) -> f32 {
    let mut s = lim - BOND_TOLERANCE;
    for _ in 0..16 {
        s = f32::from_bits(s.to_bits() - 1);
    }
    for _ in 0..32 {
        let ra = s - rb;
        if ra + rb == s && s + BOND_TOLERANCE == lim {
            return ra;
        }
        s = f32::from_bits(s.to_bits() + 1);
    }
    panic!("no radius gives the limit {lim}");
}

/// Pairs placed exactly at the thresholds, each `[atom, partner, bonded]`: at the limit (not
/// bonded, the test is strict), 2^-16 Å inside it (bonded), at 0.4 Å (not bonded) and just above.
/// `at(k, v)` gives the two positions of pair `k` with displacement `v`.
fn threshold_pairs(
    pos: &mut Vec<[f32; 3]>,
    r: &mut Vec<f32>,
    mut at: impl FnMut(usize, [f32; 3]) -> ([f32; 3], [f32; 3]),
) -> Vec<(u32, u32, bool)> {
    let lim = 1.5f32;
    let rb = 0.25f32;
    let ra = radius_for_limit(lim, rb);
    let inside = lim - 1.0 / 65536.0;
    let cases: [([f32; 3], f32, f32, bool); 8] = [
        ([lim, 0.0, 0.0], ra, rb, false),
        ([inside, 0.0, 0.0], ra, rb, true),
        ([0.0, -lim, 0.0], rb, ra, false),
        ([0.0, 0.0, -inside], rb, ra, true),
        // |(1, 1, 0.5)| = 1.5 exactly.
        ([-1.0, 1.0, -0.5], ra, rb, false),
        ([1.0, -1.0, 0.5 - 1.0 / 4096.0], ra, rb, true),
        ([MIN_BOND_LENGTH, 0.0, 0.0], 0.66, 0.66, false),
        ([0.0, 0.40625, 0.0], 0.66, 0.66, true),
    ];
    let mut out = Vec::new();
    for (k, (v, ri, rj, want)) in cases.into_iter().enumerate() {
        let (p, q) = at(k, v);
        let i = pos.len() as u32;
        pos.extend([p, q]);
        r.extend([ri, rj]);
        out.push((i, i + 1, want));
    }
    out
}

fn check_thresholds(found: &[[u32; 2]], cases: &[(u32, u32, bool)]) {
    for &(i, j, want) in cases {
        assert_eq!(found.contains(&[i, j]), want, "pair {i}-{j}");
    }
}

#[test]
fn inverse_times_matrix_is_identity() {
    let m = UnitCell::from_lengths_angles([10.0, 12.0, 15.0], [70.0, 80.0, 100.0])
        .unwrap()
        .matrix();
    let inv = invert(m).unwrap();
    for (r, row) in m.iter().enumerate() {
        for c in 0..3 {
            let v: f64 = row.iter().zip(&inv).map(|(a, b)| a * b[c]).sum();
            assert!((v - if r == c { 1.0 } else { 0.0 }).abs() < 1e-12);
        }
    }
}

#[test]
fn water_across_the_box_bonds_by_minimum_image_only() {
    // O at x = 0.2, H at x = 9.4 in a 10 Å box: 0.8 Å apart through the face, 9.2 Å
    // directly; a second H in the middle, 4.8 Å from the O.
    let pos = [[0.2, 5.0, 5.0], [9.4, 5.0, 5.0], [5.0, 5.0, 5.0]];
    let r = [0.66, 0.31, 0.31];
    let cell = UnitCell::orthorhombic(10.0, 10.0, 10.0).unwrap();
    assert_eq!(bonds_with_radii(&pos, &r, Some(cell)).pairs, vec![[0, 1]]);
    assert!(bonds_with_radii(&pos, &r, None).pairs.is_empty());
}

#[test]
fn open_box_matches_all_pairs_exactly() {
    let mut rng = Lcg(7);
    let mut pos = Vec::new();
    let mut r = Vec::new();
    // Water density in a 32 Å cube, a few overlapping clumps and a far outlier.
    for _ in 0..3200 {
        pos.push([0; 3].map(|_| 32.0 * rng.unit()));
        r.push(rng.radius());
    }
    for k in 0..40 {
        let c = pos[k * 50];
        for _ in 0..4 {
            pos.push(std::array::from_fn(|a| c[a] + 0.6 * (rng.unit() - 0.5)));
            r.push(rng.radius());
        }
    }
    pos.push([500.0, -300.0, 90.0]);
    r.push(0.76);
    let cases = threshold_pairs(&mut pos, &mut r, |k, v| {
        // x = 0 keeps `p + v` exact; the pairs are 4 Å apart in y, away from the others.
        let p = [0.0, 40.0 + 4.0 * k as f32, 40.0];
        (p, std::array::from_fn(|a| p[a] + v[a]))
    });
    let want = all_pairs_open(&pos, &r);
    check_thresholds(&want, &cases);
    assert!(want.len() > 1000, "{} bonds", want.len());
    let got = bonds_with_radii(&pos, &r, None);
    assert!(!got.periodic);
    assert_eq!(got.pairs, want);
}

#[test]
fn periodic_cube_matches_all_pairs_exactly_inside_and_outside_the_box() {
    let l = 32.0f32;
    let mut rng = Lcg(11);
    let mut pos = Vec::new();
    let mut r = Vec::new();
    // Dyadic coordinates from a box before to a box after the cell.
    for _ in 0..3300 {
        pos.push([0; 3].map(|_| rng.dyadic(-32, 96)));
        r.push(rng.radius());
    }
    // Threshold pairs split by the faces, edges and corner at 0, some of them one box away;
    // the two at 0.4 Å inside the box, where `p - v` is exact.
    let cases = threshold_pairs(&mut pos, &mut r, |k, v| {
        let p = match k {
            6 => [MIN_BOND_LENGTH, 8.0, 8.0],
            7 => [8.0, 8.5, 8.0],
            _ => [0.25, 0.5, 0.75].map(|x| x + if k % 2 == 0 { 0.0 } else { l }),
        };
        (p, std::array::from_fn(|a| p[a] - v[a]))
    });
    let want = all_pairs_cube(&pos, &r, 0.0, l);
    check_thresholds(&want, &cases);
    assert!(want.len() > 1000, "{} bonds", want.len());
    let cell = UnitCell::orthorhombic(l as f64, l as f64, l as f64).unwrap();
    let got = bonds_with_radii(&pos, &r, Some(cell));
    assert!(got.periodic);
    assert_eq!(got.pairs, want);
}

#[test]
fn far_from_the_origin_matches_all_pairs_exactly() {
    // At 2^16 Å an f32 step is 2^-7 Å: the margin of the reach must cover it.
    let (o, l) = (65536.0f32, 32.0f32);
    let mut rng = Lcg(13);
    let mut pos = Vec::new();
    let mut r = Vec::new();
    for _ in 0..3300 {
        pos.push([0; 3].map(|_| o - 32.0 + (rng.next_u32() % (96 * 128)) as f32 / 128.0));
        r.push(rng.radius());
    }
    let cell = UnitCell::orthorhombic(l as f64, l as f64, l as f64)
        .unwrap()
        .with_origin([o as f64; 3]);
    let want = all_pairs_cube(&pos, &r, o, l);
    assert!(want.len() > 1000, "{} bonds", want.len());
    assert_eq!(bonds_with_radii(&pos, &r, Some(cell)).pairs, want);
    assert_eq!(
        bonds_with_radii(&pos, &r, None).pairs,
        all_pairs_open(&pos, &r)
    );
}

#[test]
fn triclinic_box_matches_the_f64_minimum_image_up_to_rounding() {
    let cell = UnitCell::from_lengths_angles([30.0, 33.0, 36.0], [80.0, 95.0, 105.0])
        .unwrap()
        .with_origin([-3.0, 2.0, 1.5]);
    let m = cell.matrix();
    let mut rng = Lcg(23);
    let n = 3500;
    let mut pos = Vec::with_capacity(n);
    let mut r = Vec::with_capacity(n);
    for _ in 0..n {
        // Fractional coordinates in [-0.5, 1.5): a quarter of the atoms outside the cell.
        let f = [0; 3].map(|_| 2.0 * rng.unit() as f64 - 0.5);
        pos.push(std::array::from_fn(|k| {
            (cell.origin()[k] + f[0] * m[0][k] + f[1] * m[1][k] + f[2] * m[2][k]) as f32
        }));
        r.push(rng.radius());
    }
    let got = bonds_with_radii(&pos, &r, Some(cell));
    assert!(got.periodic);
    assert!(got.pairs.windows(2).all(|w| w[0] < w[1]), "sorted, once");
    // Within 1e-4 Å of a threshold, f32 rounding of the wrapped positions may decide either way.
    let tol = 1e-4;
    let (mut want, mut near) = (Vec::new(), Vec::new());
    for i in 0..n {
        for j in i + 1..n {
            if !(r[i] > 0.0 && r[j] > 0.0) {
                continue;
            }
            let v = minimum_image(
                &cell,
                std::array::from_fn(|k| (pos[j][k] - pos[i][k]) as f64),
            );
            let d = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let lim = (r[i] + r[j] + BOND_TOLERANCE) as f64;
            let lo = MIN_BOND_LENGTH as f64;
            if (d - lim).abs() < tol || (d - lo).abs() < tol {
                near.push([i as u32, j as u32]);
            } else if d < lim && d > lo {
                want.push([i as u32, j as u32]);
            }
        }
    }
    assert!(want.len() > 1000, "{} bonds", want.len());
    assert!(
        near.len() < 5,
        "{} pairs within {tol} Å of a threshold",
        near.len()
    );
    let decided: Vec<[u32; 2]> = got
        .pairs
        .iter()
        .filter(|p| !near.contains(p))
        .copied()
        .collect();
    assert_eq!(decided, want);
}

#[test]
fn a_box_narrower_than_three_cutoffs_falls_back_to_open() {
    let mut rng = Lcg(5);
    let pos: Vec<[f32; 3]> = (0..400)
        .map(|_| [40.0 * rng.unit(), 5.0 * rng.unit(), 40.0 * rng.unit()])
        .collect();
    let r: Vec<f32> = (0..400).map(|_| rng.radius()).collect();
    let cell = UnitCell::orthorhombic(40.0, 5.0, 40.0).unwrap();
    let got = bonds_with_radii(&pos, &r, Some(cell));
    assert!(!got.periodic);
    assert_eq!(got.pairs, all_pairs_open(&pos, &r));
}

#[test]
fn the_same_bonds_for_one_and_two_threads() {
    // Enough atoms for several sorting chunks and many slabs.
    let mut rng = Lcg(3);
    let n = 150_000;
    let side = (n as f32 / 0.1).cbrt();
    let pos: Vec<[f32; 3]> = (0..n).map(|_| [0; 3].map(|_| side * rng.unit())).collect();
    let r: Vec<f32> = (0..n).map(|_| rng.radius()).collect();
    let cell = UnitCell::orthorhombic(side as f64, side as f64, side as f64).unwrap();
    let run = |t: usize, cell: Option<UnitCell>| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .unwrap()
            .install(|| bonds_with_radii(&pos, &r, cell))
    };
    for cell in [Some(cell), None] {
        let one = run(1, cell);
        assert!(one.pairs.len() > n / 2, "{} bonds", one.pairs.len());
        assert_eq!(one, run(2, cell));
        assert_eq!(one, run(3, cell));
    }
}

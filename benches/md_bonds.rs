//! Bonds by distance (texmap-md-io `bonds::bonds_with_radii`, covalent radii + 0.45 Å through a
//! cell grid) for 1,000,000 atoms: water-like triples (an O on a 3.1 Å lattice, two H at 0.96 Å
//! in seeded directions) in a periodic cubic box (minimum image) and the same atoms open.
//! Target: ≤ 100 ms on 2 cores.
//!
//! Hydrogen bonds (`md_io::hbonds`, MDAnalysis's 3.0 Å / 150° criterion) on a real system:
//! frame 0 of MDAnalysis's adenylate kinase in water (md-io's tests/data/hbonds: 47,681 atoms,
//! triclinic box, 13.5k hydrogen bonds), the search alone (donor-hydrogen pairs given) and a
//! frame's whole cost when the bonds come by distance (bonds, pairs, search), as the hbonds
//! representation pays it.
//!
//! `cargo bench --bench md_bonds -- --warm-up-time 1 --measurement-time 5`
//! (test mode, `cargo test --bench md_bonds`, uses 30,000 atoms.)

use criterion::{Criterion, criterion_group};
use texmap::md_io::UnitCell;
use texmap::md_io::bonds::{bonds_by_distance, bonds_with_radii};
use texmap::md_io::hbonds::{Criteria, donor_hydrogens, hydrogen_bonds};

mod common;

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
    fn dir(&mut self) -> [f32; 3] {
        loop {
            let v = [
                2.0 * self.next() - 1.0,
                2.0 * self.next() - 1.0,
                2.0 * self.next() - 1.0,
            ];
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if l > 0.1 && l <= 1.0 {
                return v.map(|x| x / l);
            }
        }
    }
}

/// `n_atoms` (a multiple of 3) water-like atoms and the cubic box holding their lattice.
fn waters(n_atoms: usize) -> (Vec<[f32; 3]>, Vec<f32>, UnitCell) {
    let n_mol = n_atoms / 3;
    let side = (n_mol as f64).cbrt().ceil() as usize;
    let a = 3.1f32;
    let mut rng = Lcg(42);
    let mut pos = Vec::with_capacity(n_atoms);
    let mut radii = Vec::with_capacity(n_atoms);
    for m in 0..n_mol {
        let o = [
            (m % side) as f32 * a,
            ((m / side) % side) as f32 * a,
            (m / (side * side)) as f32 * a,
        ];
        pos.push(o);
        radii.push(0.66);
        for _ in 0..2 {
            let d = rng.dir();
            pos.push([o[0] + 0.96 * d[0], o[1] + 0.96 * d[1], o[2] + 0.96 * d[2]]);
            radii.push(0.31);
        }
    }
    let l = side as f64 * a as f64;
    (pos, radii, UnitCell::orthorhombic(l, l, l).unwrap())
}

fn bench(c: &mut Criterion) {
    // `cargo bench` passes --bench; `cargo test --benches` runs the small sizes.
    let test_mode = !std::env::args().any(|a| a == "--bench");
    let n = if test_mode { 30_000 } else { 1_000_000 };
    let (pos, radii, cell) = waters(n - n % 3);
    let mut g = c.benchmark_group("md_bonds");
    g.sample_size(10);
    g.bench_function(format!("periodic_{n}"), |b| {
        b.iter(|| bonds_with_radii(&pos, &radii, Some(cell)).pairs.len())
    });
    g.bench_function(format!("open_{n}"), |b| {
        b.iter(|| bonds_with_radii(&pos, &radii, None).pairs.len())
    });
    g.finish();
    // Each molecule has its two O-H bonds (H-H at 1.57 Å > 2·0.31 + 0.45 = 1.07 Å).
    let found = bonds_with_radii(&pos, &radii, Some(cell)).pairs.len();
    assert!(found >= 2 * (n / 3), "{found} bonds");
}

fn bench_hbonds(c: &mut Criterion) {
    let frame = common::adk_frame();
    let dh = donor_hydrogens(&frame, &bonds_by_distance(&frame, true).pairs);
    let found = hydrogen_bonds(&frame, &dh, None, Criteria::default()).unwrap();
    assert!(found.len() > 13_000, "{}", found.len());
    let mut g = c.benchmark_group("md_hbonds");
    g.sample_size(20);
    g.bench_function("adk_47681_search", |b| {
        b.iter(|| {
            hydrogen_bonds(&frame, &dh, None, Criteria::default())
                .unwrap()
                .len()
        })
    });
    g.bench_function("adk_47681_bonds_and_search", |b| {
        b.iter(|| {
            let dh = donor_hydrogens(&frame, &bonds_by_distance(&frame, true).pairs);
            hydrogen_bonds(&frame, &dh, None, Criteria::default())
                .unwrap()
                .len()
        })
    });
    g.finish();
}

criterion_group!(benches, bench, bench_hbonds);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}

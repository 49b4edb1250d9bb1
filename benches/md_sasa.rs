//! Solvent-accessible surface areas (texmap-md-io `sasa::sasa`, what `--sasa` computes every
//! frame: Shrake–Rupley, 960 points, probe 1.4 Å) on frame 0 of MDAnalysis's adenylate kinase in
//! water (md-io's tests/data/hbonds: 47,681 atoms, triclinic box), 2 threads: the protein alone
//! (3,341 atoms, `--sasa protein`) and every atom (the solvated system, under the minimum
//! image; TIP4P's 11,084 virtual sites have no element and no surface).
//!
//! The peer, `benches/peers/mdtraj_sasa.py`, times MDTraj 1.11's `shrake_rupley` (C++ with
//! OpenMP) on the same atoms: run it in the same minutes.
//!
//! `cargo bench --bench md_sasa -- --warm-up-time 1 --measurement-time 5`

use criterion::{Criterion, criterion_group};
use texmap::md_io::sasa::{PROBE, sasa};
use texmap::md_io::select::Selection;

mod common;

fn bench(c: &mut Criterion) {
    let frame = common::adk_frame();
    let protein = Selection::parse("protein")
        .unwrap()
        .evaluate(&frame)
        .unwrap();
    assert_eq!(protein.iter().filter(|&&p| p).count(), 3341);
    let area = sasa(&frame, Some(&protein), PROBE).unwrap();
    let total: f64 = area
        .iter()
        .filter(|a| a.is_finite())
        .map(|a| *a as f64)
        .sum();
    // The protein is cut by the box in this frame: without the cell (as MDTraj measures it,
    // ignoring the box) its pieces' cut faces count, 13,456.5 Å² here against MDTraj's 13,456.0
    // (the peer prints it); under the minimum image it is whole, 12,055.6 Å².
    let mut open = frame.clone();
    open.cell = None;
    let cut: f64 = sasa(&open, Some(&protein), PROBE)
        .unwrap()
        .iter()
        .filter(|a| a.is_finite())
        .map(|a| *a as f64)
        .sum();
    assert!((cut - 13_456.0).abs() < 2.0, "{cut} Å² without the cell");
    assert!((total - 12_055.6).abs() < 1.0, "{total} Å²");

    let mut g = c.benchmark_group("md_sasa");
    g.sample_size(10);
    g.bench_function("adk_protein_3341", |b| {
        b.iter(|| sasa(&frame, Some(&protein), PROBE).unwrap().len())
    });
    g.bench_function("adk_solvated_47681", |b| {
        b.iter(|| sasa(&frame, None, PROBE).unwrap().len())
    });
    g.finish();
}

criterion_group!(benches, bench);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}

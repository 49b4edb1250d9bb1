//! The per-atom analyses materials users colour by (texmap-md-io `cna`, `centrosymmetry`,
//! `strain`, `coordination`) on a periodic FCC copper crystal of 32³ unit cells (131,072 atoms,
//! a = 3.615 Å, seeded thermal noise of 0.05 Å) and the same atoms sheared by 3 % with new
//! noise (the strain's current frame), 2 threads:
//! - adaptive CNA (`cna::classify`);
//! - centrosymmetry from 12 neighbours, conventional and minimum-weight matching;
//! - atomic strain at a 3.0 Å cutoff (neighbour pairs, F, shear, volumetric, D²min);
//! - Voronoi cells (volume, faces, index);
//! - coordination at 3.0 Å;
//! - the radial distribution function to 8 Å in 200 bins (OVITO: the Coordination analysis
//!   modifier at that cutoff, whose table it is);
//! - on a polycrystal of the same size (aluminium, 16 Voronoi grains in random orientations
//!   from `texmap_study::materials::polycrystal`,
//!   thermal noise 0.05 Å; `target/md_analysis_poly.xyz`): lattice orientations (a-CNA and the
//!   template fit, as OVITO's PTM gives structure and orientation in one pass) and grains
//!   (the orientations, then the segmentation, as OVITO's PTM followed by Grain segmentation);
//!   and the export `texmap convert --select 'not cna fcc' --columns cna -o F.lammpstrj` does
//!   per frame (a-CNA, the non-FCC atoms kept, written as a LAMMPS dump with their structure
//!   type to `target/md_analysis_export.lammpstrj`), as OVITO's CNA, Expression selection,
//!   Delete selected and export_file.
//!
//! Both configurations are written to `target/md_analysis_{ref,cur}.xyz` (extended XYZ) for
//! the peer, `benches/peers/ovito_analysis.py`, which times OVITO's modifiers on the same atoms
//! with the same parameters: run it in the same minutes.
//!
//! `cargo bench --bench md_analysis -- --warm-up-time 1 --measurement-time 5`
//! (test mode, `cargo test --bench md_analysis`, uses 8³ cells.)

use std::io::Write;

use criterion::{Criterion, criterion_group};
use texmap::md_io::centrosymmetry::{CspMode, centrosymmetry};
use texmap::md_io::{
    Format, Frame, Property, UnitCell, Writer, cna, coordination, grains, orientation, rdf, strain,
    voronoi,
};

mod common;
use common::Lcg;

/// The reference crystal of `n`³ cells and its sheared copy.
fn crystals(n: usize) -> (Frame, Frame) {
    let a = 3.615;
    let l = n as f64 * a;
    let mut rng = Lcg(2026);
    let base = [
        [0.0, 0.0, 0.0],
        [0.5, 0.5, 0.0],
        [0.5, 0.0, 0.5],
        [0.0, 0.5, 0.5],
    ];
    let mut reference = Frame::new();
    let mut current = Frame::new();
    for i in 0..n * n * n {
        let cell = [i % n, i / n % n, i / (n * n)];
        for b in base {
            let p: [f64; 3] =
                [0, 1, 2].map(|k| (cell[k] as f64 + b[k] + 0.25) * a + 0.05 * rng.normal());
            reference.positions.push(p.map(|x| x as f32));
            let mut q = [0, 1, 2].map(|k| p[k] + 0.05 * rng.normal());
            q[0] += 0.03 * q[1];
            current.positions.push(q.map(|x| x as f32));
        }
    }
    reference.cell = Some(UnitCell::orthorhombic(l, l, l).unwrap());
    current.cell =
        Some(UnitCell::from_matrix([[l, 0.0, 0.0], [0.03 * l, l, 0.0], [0.0, 0.0, l]]).unwrap());
    for f in [&mut reference, &mut current] {
        f.names = vec![texmap::md_io::Label::new("Cu").unwrap(); f.positions.len()];
    }
    (reference, current)
}

/// `frame` as extended XYZ (the peer's input).
fn write_xyz(frame: &Frame, path: &str) {
    let m = frame.cell.unwrap().matrix();
    let mut out = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    writeln!(out, "{}", frame.positions.len()).unwrap();
    let lattice: Vec<String> = m.iter().flatten().map(|v| format!("{v:.6}")).collect();
    writeln!(
        out,
        "Lattice=\"{}\" Properties=species:S:1:pos:R:3 pbc=\"T T T\"",
        lattice.join(" ")
    )
    .unwrap();
    for p in &frame.positions {
        writeln!(
            out,
            "{} {:.6} {:.6} {:.6}",
            frame.names[0].as_str(),
            p[0],
            p[1],
            p[2]
        )
        .unwrap();
    }
}

fn bench(c: &mut Criterion) {
    // `cargo bench` passes --bench; `cargo test --benches` runs the small sizes.
    let test_mode = !std::env::args().any(|a| a == "--bench");
    let n = if test_mode { 8 } else { 32 };
    let (reference, current) = crystals(n);
    let atoms = reference.positions.len();
    let wanted = if test_mode { 3 } else { 16 };
    let poly_size = if test_mode { 8_000 } else { atoms };
    let (poly, _) = texmap::study::materials::polycrystal(poly_size, wanted, 0.05, 7);
    if !test_mode {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/target");
        write_xyz(&reference, &format!("{dir}/md_analysis_ref.xyz"));
        write_xyz(&current, &format!("{dir}/md_analysis_cur.xyz"));
        write_xyz(&poly, &format!("{dir}/md_analysis_poly.xyz"));
    }
    // The polycrystal's grains are found.
    let poly_types = cna::classify(&poly);
    let fits = orientation::orientations(&poly, &poly_types);
    let found = grains::segment(&poly, &poly_types, &fits, &grains::GrainOptions::default());
    assert_eq!(
        found.grains.len(),
        wanted,
        "{:?}",
        found.grains.iter().map(|g| g.size).collect::<Vec<_>>()
    );
    let poly_atoms = poly.positions.len();
    // The analyses see what they should: a thermal FCC crystal, sheared by 3 %.
    let types = cna::classify(&reference);
    assert!(
        types
            .iter()
            .filter(|t| **t == cna::StructureType::Fcc)
            .count()
            > atoms * 9 / 10
    );
    let s = strain::atomic_strain(&reference, &current, 3.0).unwrap();
    let mean = s.shear.iter().map(|v| *v as f64).sum::<f64>() / atoms as f64;
    assert!((mean - 0.015).abs() < 0.01, "mean shear strain {mean}");
    let cells = voronoi::voronoi(&reference).unwrap();
    let total: f64 = cells.volume.iter().map(|v| *v as f64).sum();
    let box_volume = reference.cell.unwrap().volume();
    assert!(
        (total - box_volume).abs() < 1e-4 * box_volume,
        "{total} of {box_volume}"
    );

    let mut g = c.benchmark_group("md_analysis");
    g.sample_size(10);
    g.bench_function(format!("cna_{atoms}"), |b| {
        b.iter(|| cna::classify(&reference).len())
    });
    g.bench_function(format!("centrosymmetry_conventional_{atoms}"), |b| {
        b.iter(|| {
            centrosymmetry(&reference, 12, CspMode::Conventional)
                .unwrap()
                .len()
        })
    });
    g.bench_function(format!("centrosymmetry_matching_{atoms}"), |b| {
        b.iter(|| {
            centrosymmetry(&reference, 12, CspMode::Matching)
                .unwrap()
                .len()
        })
    });
    g.bench_function(format!("strain_{atoms}"), |b| {
        b.iter(|| {
            strain::atomic_strain(&reference, &current, 3.0)
                .unwrap()
                .shear
                .len()
        })
    });
    g.bench_function(format!("voronoi_{atoms}"), |b| {
        b.iter(|| voronoi::voronoi(&reference).unwrap().volume.len())
    });
    g.bench_function(format!("rdf_8A_200_bins_{atoms}"), |b| {
        b.iter(|| rdf::rdf(&reference, 8.0, 200, false).unwrap().total.len())
    });
    g.bench_function(format!("coordination_{atoms}"), |b| {
        b.iter(|| coordination::coordination(&reference, 3.0).unwrap().len())
    });
    g.bench_function(format!("orientations_poly_{poly_atoms}"), |b| {
        b.iter(|| {
            let types = cna::classify(&poly);
            orientation::orientations(&poly, &types).len()
        })
    });
    g.bench_function(format!("grains_poly_{poly_atoms}"), |b| {
        b.iter(|| {
            let types = cna::classify(&poly);
            let fits = orientation::orientations(&poly, &types);
            grains::segment(&poly, &types, &fits, &grains::GrainOptions::default())
                .grains
                .len()
        })
    });
    let export = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/target/md_analysis_export.lammpstrj"
    );
    g.bench_function(format!("export_defects_poly_{poly_atoms}"), |b| {
        b.iter(|| {
            let mut frame = poly.clone();
            let types = cna::classify(&frame);
            frame.properties.push(Property {
                name: "cna".into(),
                values: types.iter().map(|&t| t as u8 as f32).collect(),
            });
            let keep: Vec<bool> = types
                .iter()
                .map(|&t| t != cna::StructureType::Fcc)
                .collect();
            frame.ids = (1..=frame.n_atoms() as i64).collect();
            frame.retain_atoms(&keep);
            let mut w = Writer::create(export, Format::LammpsDump).unwrap();
            w.write_frame(&frame).unwrap();
            w.finish().unwrap();
            frame.n_atoms()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}

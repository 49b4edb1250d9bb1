//! Principal component analysis (texmap-md-io `pca::Pca`, what `texmap convert --pca-table`
//! computes) of adenylate kinase's CA atoms (214: 642 coordinates, the covariance matrix) and
//! backbone atoms (855: 2,565 coordinates, the 1,000 x 1,000 matrix of the frames' products)
//! over 1,000 frames, each frame the crystal positions moved along five seeded collective modes
//! plus 0.3 Å of noise: the frames kept, then the variances, five components and every frame's
//! projections. 2 threads (the covariance products are shared, the eigensolver is one thread).
//!
//! Then the pairwise RMSD after superposition (`rmsd::rmsd_matrix`, what `--rmsd-matrix`
//! computes) of the CA atoms over the first 500 frames, 2 threads.
//!
//! Then the clustering of those CA frames (`conformations::cluster`, what `--rmsd-clusters`
//! computes once the matrix is there) over all 1,000 frames at 1.5 Å, gromos and single
//! linkage, one thread.
//!
//! Then one frame of the residue–residue distance and contact map (`distance_map`, what
//! `--distance-map` and `--contact-map` add per frame) of adenylate kinase's 214 residues
//! (3,341 protein atoms) in its truncated octahedron, 2 threads.
//!
//! Then one frame of lipid tail order parameters (`order`, what `--order-table` adds per
//! frame) of md-io's model bilayer (tests/data/order) replicated 4 x 4 in the membrane plane:
//! 512 lipids, 44,544 atoms, S_CH of 14,336 carbons from 29,696 C–H bonds, and the
//! united-atom construction of 12,288 carbons; one thread.
//!
//! The peer, `benches/peers/mdanalysis_pca.py`, times MDAnalysis's `analysis.pca.PCA` plus
//! `transform` on frames of the same sizes held in memory, and `DistanceMatrix` with a
//! superposing `rms.rmsd` on 500 frames of 214 atoms: run it in the same minutes.
//! `benches/peers/gmx_cluster.py` times `gmx cluster` against `texmap convert --rmsd-clusters`
//! end to end on one XTC file (both read it, fit every pair, cluster, write the clusters);
//! `benches/peers/gmx_mdmat.py` times `gmx mdmat` against `texmap convert --distance-map`.
//!
//! `cargo bench --bench md_pca -- --warm-up-time 1 --measurement-time 10`
//! (test mode, `cargo test --bench md_pca`, uses 100 frames.)

use criterion::{Criterion, criterion_group};
use texmap::md_io::conformations::{Method, cluster};
use texmap::md_io::distance_map::DistanceMap;
use texmap::md_io::order::{Method as OrderMethod, OrderParameters};
use texmap::md_io::pca::Pca;
use texmap::md_io::select::Selection;

mod common;
use common::{Lcg, adk_frame};

fn bench(c: &mut Criterion) {
    let test_mode = !std::env::args().any(|a| a == "--bench");
    let frames = if test_mode { 100 } else { 1000 };
    let adk = adk_frame();
    let mut g = c.benchmark_group("md_pca");
    g.sample_size(10);
    for sel in ["name CA", "backbone"] {
        let pick = Selection::parse(sel).unwrap().indices(&adk).unwrap();
        let base: Vec<[f64; 3]> = pick
            .iter()
            .map(|&i| adk.positions[i].map(f64::from))
            .collect();
        let mut rng = Lcg(61207);
        let modes: Vec<Vec<[f64; 3]>> = (0..5)
            .map(|_| {
                base.iter()
                    .map(|_| std::array::from_fn(|_| rng.normal()))
                    .collect()
            })
            .collect();
        let walk: Vec<Vec<[f32; 3]>> = (0..frames)
            .map(|t| {
                let phase = std::f64::consts::TAU * t as f64 / frames as f64;
                let amp: Vec<f64> = (0..5)
                    .map(|m| (phase * (m + 1) as f64).sin() / (m + 1) as f64)
                    .collect();
                base.iter()
                    .enumerate()
                    .map(|(i, b)| {
                        std::array::from_fn(|a| {
                            let moved: f64 = (0..5).map(|m| amp[m] * modes[m][i][a]).sum();
                            (b[a] + moved + 0.3 * rng.normal()) as f32
                        })
                    })
                    .collect()
            })
            .collect();
        let run = || {
            let mut pca = Pca::new(usize::MAX);
            for f in &walk {
                pca.add(f).unwrap();
            }
            pca.solve(5).unwrap()
        };
        let name = format!(
            "{}_{}_atoms_{frames}_frames",
            sel.replace(' ', "_"),
            base.len()
        );
        g.bench_function(name, |b| b.iter(run));
        // The five modes carry most of the motion: the components find them.
        let c = run();
        assert!(c.cumulated(4) > 0.5, "{sel}: {}", c.cumulated(4));
        if sel == "name CA" {
            let first = &walk[..frames / 2];
            let name = format!("rmsd_matrix_{}_atoms_{}_frames", base.len(), first.len());
            g.bench_function(name, |b| {
                b.iter(|| texmap::md_io::rmsd::rmsd_matrix(first, usize::MAX).unwrap())
            });
            let m = texmap::md_io::rmsd::rmsd_matrix(&walk, usize::MAX).unwrap();
            for method in [Method::Gromos, Method::Linkage] {
                // The walk is one slow drift: gromos cuts it into pieces, linkage chains it.
                let found = cluster(&m, frames, 1.5, method).unwrap();
                assert_eq!(found.clusters.len() > 1, method == Method::Gromos);
                let name = format!("{}_{}_atoms_{frames}_frames", method.name(), base.len());
                g.bench_function(name, |b| {
                    b.iter(|| cluster(&m, frames, 1.5, method).unwrap())
                });
            }
        }
    }
    // The residue map of adk's protein atoms, one frame.
    let protein = Selection::parse("protein").unwrap().evaluate(&adk).unwrap();
    let groups: Vec<Vec<usize>> = texmap::md_io::secondary::residue_ranges(&adk)
        .into_iter()
        .map(|r| r.filter(|&i| protein[i]).collect::<Vec<usize>>())
        .filter(|g| !g.is_empty())
        .collect();
    assert_eq!(groups.len(), 214);
    g.bench_function("distance_map_214_residues_1_frame", |b| {
        b.iter(|| {
            let mut map = DistanceMap::new(groups.clone(), 4.5).unwrap();
            map.add(&adk.positions, adk.cell.as_ref()).unwrap();
            map
        })
    });
    // Lipid order parameters of a 512-lipid bilayer, one frame.
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/crates/md-io/tests/data/order");
    let mut bilayer = texmap::md_io::Frame::new();
    texmap::md_io::Trajectory::open(format!("{dir}/bilayer.gro"))
        .unwrap()
        .read_frame(0, &mut bilayer)
        .unwrap();
    let mut bonds = texmap::md_io::bonds::bonds_by_distance(&bilayer, true).pairs;
    texmap::md_io::replicate::replicate(&mut bilayer, &mut bonds, [4, 4, 1]).unwrap();
    let tails = Selection::parse("name C2* C3*")
        .unwrap()
        .evaluate(&bilayer)
        .unwrap();
    for (name, method) in [
        ("order_hydrogens_512_lipids_1_frame", OrderMethod::Hydrogens),
        (
            "order_united_atom_512_lipids_1_frame",
            OrderMethod::UnitedAtom,
        ),
    ] {
        let mut order = OrderParameters::new(&bilayer, &tails, &bonds, method, 2).unwrap();
        g.bench_function(name, |b| {
            b.iter(|| {
                order
                    .add(&bilayer.positions, bilayer.cell.as_ref())
                    .unwrap()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}

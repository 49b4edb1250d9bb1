//! The mean squared displacement over every time origin (texmap-md-io `msd::AllOrigins`, what
//! `--msd-lags` computes) of 10,000 atoms on seeded Gaussian random walks (0.2 Å per axis per
//! frame) over 1,000 frames, 2 threads: the frames kept, then the average per lag for all atoms
//! and two kinds. Then the velocity autocorrelation (`vacf::Velocities`, what `--vacf-table`
//! computes) and the vibrational density of states (`--vdos-table`) of 10,000 atoms'
//! Ornstein–Uhlenbeck velocities over 1,000 frames, for all atoms and two kinds. And the 3-D
//! density map of the random walk's 10,000 atoms over its 1,000 frames (`density::DensityMap`,
//! what `--density-map` computes: 1 Å cells, 2 Å around the first frame's atoms), one thread.
//!
//! The peer, `benches/peers/mdanalysis_msd.py`, times MDAnalysis's `EinsteinMSD` (fft=True,
//! through tidynamics) on a walk of the same size held in memory: run it in the same minutes;
//! `benches/peers/mdanalysis_density.py` times MDAnalysis's `DensityAnalysis` on the walk.
//!
//! `cargo bench --bench md_msd -- --warm-up-time 1 --measurement-time 5`
//! (test mode, `cargo test --bench md_msd`, uses 500 atoms and 100 frames.)

use criterion::{Criterion, criterion_group};
use texmap::md_io::density::DensityMap;
use texmap::md_io::msd::AllOrigins;
use texmap::md_io::vacf::Velocities;

mod common;
use common::Lcg;

fn bench(c: &mut Criterion) {
    let test_mode = !std::env::args().any(|a| a == "--bench");
    let (atoms, frames) = if test_mode {
        (500, 100)
    } else {
        (10_000, 1000)
    };
    let mut rng = Lcg(61206);
    let mut p: Vec<[f64; 3]> = (0..atoms)
        .map(|_| std::array::from_fn(|_| 50.0 * rng.next()))
        .collect();
    let mut all = AllOrigins::new(usize::MAX);
    let mut walk: Vec<Vec<[f32; 3]>> = Vec::with_capacity(frames);
    for _ in 0..frames {
        all.push(&p).unwrap();
        walk.push(p.iter().map(|q| q.map(|x| x as f32)).collect());
        for q in &mut p {
            for x in q.iter_mut() {
                *x += 0.2 * rng.normal();
            }
        }
    }
    let kind: Vec<usize> = (0..atoms).map(|i| usize::from(i % 3 == 0)).collect();
    // The walk's own slope: 3 · 0.2² Å² per frame.
    let lags = all.mean(&kind, 2).unwrap();
    let slope = lags.total[frames / 10] / (frames / 10) as f64;
    assert!(
        (slope - 0.12).abs() < 0.02,
        "MSD slope {slope} Å² per frame"
    );

    let mut g = c.benchmark_group("md_msd");
    g.sample_size(10);
    g.bench_function(format!("msd_lags_{atoms}_atoms_{frames}_frames"), |b| {
        b.iter(|| all.mean(&kind, 2).unwrap().total[1])
    });
    g.bench_function(format!("keep_{atoms}_atoms_{frames}_frames"), |b| {
        b.iter(|| {
            let mut kept = AllOrigins::new(usize::MAX);
            for _ in 0..frames {
                kept.push(&p).unwrap();
            }
            kept.frames()
        })
    });

    // Velocities relaxing with a correlation time of 1 / (1 − 0.9) = 10 frames.
    let mut v = vec![[0.0f32; 3]; atoms];
    let mut velocities = Velocities::new(usize::MAX);
    for _ in 0..frames {
        for w in &mut v {
            for x in w.iter_mut() {
                *x = 0.9 * *x + rng.normal() as f32;
            }
        }
        velocities.push(&v).unwrap();
    }
    let c = velocities.autocorrelation(&kind, 2).unwrap();
    // Ornstein–Uhlenbeck: C(m) / C(0) = 0.9^m.
    let ratio = c.total[5] / c.total[0];
    assert!((ratio - 0.9f64.powi(5)).abs() < 0.03, "C(5)/C(0) = {ratio}");
    let mass: Vec<f64> = kind.iter().map(|k| [12.0, 1.0][*k]).collect();
    g.bench_function(format!("vacf_{atoms}_atoms_{frames}_frames"), |b| {
        b.iter(|| velocities.autocorrelation(&kind, 2).unwrap().total[1])
    });
    g.bench_function(format!("vdos_{atoms}_atoms_{frames}_frames"), |b| {
        b.iter(|| {
            velocities
                .density_of_states(&kind, 2, &mass, 0.01)
                .unwrap()
                .total[1]
        })
    });
    g.bench_function(format!("density_map_{atoms}_atoms_{frames}_frames"), |b| {
        b.iter(|| {
            let mut map = DensityMap::around(&walk[0], 1.0, 2.0).unwrap();
            for frame in &walk {
                map.add(frame.iter().copied());
            }
            map.outside()
        })
    });
    // Every position is counted once, inside the grid or outside it.
    let mut map = DensityMap::around(&walk[0], 1.0, 2.0).unwrap();
    for frame in &walk {
        map.add(frame.iter().copied());
    }
    let v = map.to_volume("walk");
    let inside = v.integral() * frames as f64;
    let total = (atoms * frames) as f64;
    assert!((inside + map.outside() as f64 - total).abs() < 1e-6 * total);
    g.finish();
}

criterion_group!(benches, bench);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}

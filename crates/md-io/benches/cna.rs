//! Adaptive common neighbour analysis speed: `cargo bench -p texmap-md-io --bench cna`.
//!
//! A periodic FCC crystal of 40x40x40 conventional cells (256,000 atoms, a = 3.615 Å) jiggled
//! by seeded noise of 0.05 Å, classified on one core.

use criterion::{Criterion, criterion_group, criterion_main};
use texmap_md_io::{Frame, UnitCell};

fn crystal(n: usize) -> Frame {
    let a = 3.615f32;
    let mut state = 0x2545_f491u64;
    let mut noise = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((state >> 40) as f32 / (1u64 << 24) as f32 - 0.5) * 0.17
    };
    let mut f = Frame::new();
    for (i, j, k) in (0..n * n * n).map(|m| (m % n, m / n % n, m / (n * n))) {
        for b in [
            [0.0, 0.0, 0.0],
            [0.5, 0.5, 0.0],
            [0.5, 0.0, 0.5],
            [0.0, 0.5, 0.5],
        ] {
            f.positions.push([
                (i as f32 + b[0]) * a + noise(),
                (j as f32 + b[1]) * a + noise(),
                (k as f32 + b[2]) * a + noise(),
            ]);
        }
    }
    let l = (n as f32 * a) as f64;
    f.cell = Some(UnitCell::orthorhombic(l, l, l).unwrap());
    f
}

fn bench(c: &mut Criterion) {
    let frame = crystal(40);
    let mut g = c.benchmark_group("cna");
    g.sample_size(10);
    g.bench_function("fcc_256k_atoms", |b| {
        b.iter(|| texmap_md_io::cna::classify(&frame))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);

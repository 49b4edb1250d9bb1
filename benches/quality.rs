//! Speed of the quality pass (`texmap-quality`) at the `good` preset — 4 anti-aliasing samples
//! on edges, 8 ambient-occlusion rays, hard shadows from the key light — on the named scenes of
//! `texmap-study`: S1 (1,115 particles) at 500x500 (target ≤ 100 ms), S2 (100,000 spheres) at
//! 1920x1080 (target ≤ 1.5 s) and S3 (1,000,000 spheres) at 1920x1080. Each iteration draws a
//! whole frame: the ray-cast impostor, the grid build, recovery, shading and the edge samples;
//! 10 samples per scene. With `--bench` S1 is also timed with the `publication` preset and with
//! `good` plus soft shadows (16 rays, a 4° light).
//!
//! `CARGO_TARGET_DIR=/work/target-a cargo bench --bench quality -- --warm-up-time 1 --measurement-time 3`
//! (test mode, `cargo test --bench quality`, draws each scene once at 160x120.)

use criterion::{Criterion, criterion_group};
use texmap::quality::{DEFAULT_LIGHT_SIZE_DEG, QualityOptions, QualityRenderer, SoftShadows};
use texmap::study::scenes::{SceneId, build};

fn bench(c: &mut Criterion) {
    let test_mode = std::env::args().any(|a| a == "--test");
    let full = std::env::args().any(|a| a == "--bench");
    let opts = QualityOptions::good();
    for id in [SceneId::S1, SceneId::S2, SceneId::S3] {
        let mut s = build(id);
        if test_mode {
            s = s.with_size(160, 120).unwrap();
        }
        let mut g = c.benchmark_group(format!("quality/{}", s.name()));
        g.sample_size(10);
        let mut r = QualityRenderer::new();
        g.bench_function("aa4_ao8_shadows", |b| {
            b.iter(|| r.render(&s.spheres, &s.camera, &s.lighting, &opts).unwrap())
        });
        if full && id == SceneId::S1 {
            let p = QualityOptions::publication();
            g.bench_function("publication", |b| {
                b.iter(|| r.render(&s.spheres, &s.camera, &s.lighting, &p).unwrap())
            });
            let soft = QualityOptions {
                soft_shadows: Some(SoftShadows {
                    samples: 16,
                    light_size_deg: DEFAULT_LIGHT_SIZE_DEG,
                }),
                ..opts
            };
            g.bench_function("good_soft16", |b| {
                b.iter(|| r.render(&s.spheres, &s.camera, &s.lighting, &soft).unwrap())
            });
        }
        g.finish();
    }
}

criterion_group!(benches, bench);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}

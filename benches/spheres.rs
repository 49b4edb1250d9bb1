//! Speed of every sphere method on the named scenes S1, S2, S3 of `texmap-study`
//! (PERFORMANCE-NOTES.md): S1 = Seed 004's 1,115-particle system at 500x500, S2 = 100,000
//! spheres r 0.5 in a 100³ box at 1920x1080, S3 = 1,000,000 spheres r 0.3 in a 200³ box at
//! 1920x1080; perspective cameras at 2.4 box lengths from the box centre.
//!
//! Each method draws with a [`Renderer`] and a frame reused across iterations (tables built in
//! the first frame, as in an animation). S3 runs only with `--bench` so that
//! `cargo test --bench spheres` stays quick.
//!
//! `CARGO_TARGET_DIR=/work/target-impostor cargo bench --bench spheres -- --warm-up-time 1 --measurement-time 3`

use criterion::{Criterion, criterion_group};
use texmap::core::frame::Frame;
use texmap::impostor::{Method, Options, Renderer};
use texmap::study::scenes::{SceneId, build};

fn bench(c: &mut Criterion) {
    let full = std::env::args().any(|a| a == "--bench");
    let mut ids = vec![SceneId::S1, SceneId::S2];
    if full {
        ids.push(SceneId::S3);
    }
    for id in ids {
        let s = build(id);
        let mut g = c.benchmark_group(format!("spheres/{}", s.name()));
        g.sample_size(10);
        for m in Method::ALL {
            // The polygon baseline is seconds per frame on S3: measured on S1 and S2 only.
            if m == Method::Polygon && id == SceneId::S3 {
                continue;
            }
            let opts = Options::new(m, s.lighting);
            let mut r = Renderer::new();
            let mut frame = Frame::new(s.camera.width(), s.camera.height(), opts.background);
            g.bench_function(m.name(), |b| {
                b.iter(|| r.render_into(&s.spheres, &s.camera, &opts, &mut frame))
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

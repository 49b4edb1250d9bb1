//! Speed of the bond pass (exact ray-cast cylinder impostors drawn after the spheres), as the
//! difference between spheres only and spheres + bonds on two scenes:
//! - `molecule-bs`: texmap-study's ball-and-stick α-helix (300 atoms, 299 bonds) at 500x500;
//! - `chains-100k`: 1,000 random-walk chains of 100 atoms (100,000 atoms r 0.4, 99,000 bonds
//!   r 0.2, step 1.5) in a 100³ box at 1920x1080, seen by the study's box camera (as S2).
//!
//! Each case draws with a [`Renderer`] and a frame reused across iterations.
//!
//! `CARGO_TARGET_DIR=/work/target-bonds cargo bench --bench bonds -- --warm-up-time 1 --measurement-time 3`

use criterion::{Criterion, criterion_group};
use texmap::core::frame::Frame;
use texmap::impostor::{Method, Options, Renderer};
use texmap::study::scenes::{SceneId, build, chains_100k};

fn bench(c: &mut Criterion) {
    for s in [build(SceneId::MoleculeBallStick), chains_100k()] {
        let mut g = c.benchmark_group(format!("bonds/{}", s.name()));
        g.sample_size(10);
        for (m, bonds) in [
            (Method::Raycast, false),
            (Method::Raycast, true),
            (Method::Lut, true),
        ] {
            let mut opts = Options::new(m, s.lighting);
            opts.draw_bonds = bonds;
            let mut r = Renderer::new();
            let mut frame = Frame::new(s.camera.width(), s.camera.height(), opts.background);
            let name = format!("{}{}", m.name(), if bonds { "+bonds" } else { "" });
            g.bench_function(name, |b| {
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

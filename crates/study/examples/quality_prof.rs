//! Profiling aid for the quality pass: times `texmap-quality` settings on a named scene and
//! prints its statistics (edge pixels, recovery walks).
//!
//! ```text
//! cargo run --release -p texmap-study --example quality_prof -- [s1|s2] [RUNS] [SETTING] | [s1|s2] --dump FILE
//! ```

use std::time::Instant;

use texmap_quality::{QualityOptions, QualityRenderer};
use texmap_study::scenes::{SceneId, build};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let id = args
        .first()
        .and_then(|s| SceneId::from_name(s))
        .unwrap_or(SceneId::S1);
    let runs: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(5);
    let s = build(id);
    // `--dump FILE`: the scene as extended XYZ (position, radius, sRGB colour) and its camera,
    // for running another renderer on the same atoms.
    if let Some(k) = args.iter().position(|a| a == "--dump") {
        use std::fmt::Write as _;
        let mut out = String::new();
        let sp = &s.spheres;
        let _ = writeln!(out, "{}", sp.len());
        let eye = s.camera.eye();
        let f = s.camera.forward();
        let _ = writeln!(
            out,
            "Properties=species:S:1:pos:R:3:radius:R:1:color:R:3 eye=\"{} {} {}\" dir=\"{} {} {}\"",
            eye.x, eye.y, eye.z, f.x, f.y, f.z
        );
        for i in 0..sp.len() {
            let c = sp.centers[i];
            let m = sp.materials[sp.kinds[i] as usize].base_color;
            let e = |v: f32| texmap_core::color::linear_to_srgb(v);
            let _ = writeln!(
                out,
                "X {} {} {} {} {} {} {}",
                c.x,
                c.y,
                c.z,
                sp.radii[i],
                e(m.x),
                e(m.y),
                e(m.z)
            );
        }
        std::fs::write(&args[k + 1], out).expect("write the dump");
        println!("{:?}", s.camera.projection());
        return;
    }
    let mut r = QualityRenderer::new();
    let draft = QualityOptions::draft();
    let settings = [
        ("draft", draft),
        ("aa4", QualityOptions { aa: 4, ..draft }),
        (
            "shadows",
            QualityOptions {
                shadows: true,
                ..draft
            },
        ),
        (
            "ao8",
            QualityOptions {
                ao_samples: 8,
                ..draft
            },
        ),
        ("aa4-ao8-shadows", QualityOptions::good()),
    ];
    let only = args.get(2).cloned();
    for (name, o) in settings {
        if only.as_deref().is_some_and(|x| x != name) {
            continue;
        }
        let mut times = Vec::new();
        let mut stats = None;
        for _ in 0..runs {
            let t = Instant::now();
            let out = r.render(&s.spheres, &s.camera, &s.lighting, &o).unwrap();
            times.push(t.elapsed().as_secs_f64() * 1e3);
            stats = Some(out.stats);
        }
        times.sort_by(f64::total_cmp);
        let st = stats.unwrap();
        println!(
            "{:<18} median {:8.2} ms  min {:8.2} ms  edges {:7}  walks {:6}  misses {:4}",
            name,
            times[times.len() / 2],
            times[0],
            st.edge_pixels,
            st.recovery_walks,
            st.recovery_misses
        );
    }
}

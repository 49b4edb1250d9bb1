//! Quick wall-clock timing of BVH build and primary rays on S2/S3-like sphere scenes, for
//! profiling (`cargo run --release -p texmap-reftrace --example timing -- [count] [side] [r] [w] [h] [reps] [bvh2|cwbvh|wide4] [trace|shade] [study]`).
//! The criterion bench `benches/reftrace.rs` is the measurement of record.

use std::time::Instant;
use texmap_core::camera::Camera;
use texmap_core::shade::{Lighting, Material};
use texmap_reftrace::glam::Vec3;
use texmap_reftrace::{BvhKind, RenderOptions, SceneBuilder, SurfaceMaterial};

/// Process CPU time (user + system) in seconds, from /proc/self/stat (Linux; 0 elsewhere).
/// On a shared machine CPU time is a steadier measure of work than wall time.
fn cpu_seconds() -> f64 {
    let Ok(s) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    let Some(rest) = s.rsplit(')').next() else {
        return 0.0;
    };
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11).and_then(|x| x.parse().ok()).unwrap_or(0.0)
        + f.get(12).and_then(|x| x.parse().ok()).unwrap_or(0.0);
    ticks / 100.0
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let count: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(100_000);
    let side: f32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(100.0);
    let r: f32 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(0.5);
    let w: u32 = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(1920);
    let h: u32 = args.get(5).and_then(|s| s.parse().ok()).unwrap_or(1080);
    let reps: usize = args.get(6).and_then(|s| s.parse().ok()).unwrap_or(3);
    let mut state = 2024u64;
    let mut rnd = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 40) as f32) / (1u64 << 24) as f32
    };
    let pts: Vec<Vec3> = (0..count)
        .map(|_| (Vec3::new(rnd(), rnd(), rnd()) - 0.5) * side)
        .collect();
    // "study": texmap-study's S2 view (direction (0.45, 0.35, 1), FOV framing the box: 69°).
    let study = args.get(9).is_some_and(|a| a == "study");
    let (dir, hfov) = if study {
        (Vec3::new(0.45, 0.35, 1.0), 69.0)
    } else {
        (Vec3::new(0.3, 0.4, 1.0), 40.0)
    };
    let cam = Camera::perspective_look_at(
        dir.normalize() * side * 2.4,
        Vec3::ZERO,
        Vec3::Y,
        hfov,
        w,
        h,
    )
    .unwrap();
    let mats = [SurfaceMaterial::opaque(Material::plastic(Vec3::new(
        0.8, 0.3, 0.2,
    )))];
    let opts = RenderOptions::new(Lighting::default_for(&cam), &mats);
    let only = args.get(7).cloned().unwrap_or_default();
    // "trace": primary visibility only (Scene::depth_image), no shading.
    let trace_only = args.get(8).is_some_and(|a| a == "trace");
    for kind in [BvhKind::Bvh2, BvhKind::CwBvh, BvhKind::Wide4] {
        if !only.is_empty() && !format!("{kind:?}").eq_ignore_ascii_case(&only) {
            continue;
        }
        let mut b = SceneBuilder::with_sphere_capacity(count).bvh(kind);
        for p in &pts {
            b.add_sphere(*p, r, 0);
        }
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let scene = b.build();
        let (build, build_cpu) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
        let mut best = f64::INFINITY;
        let mut best_cpu = f64::INFINITY;
        let mut covered = 0;
        for _ in 0..reps {
            let (t0, c0) = (Instant::now(), cpu_seconds());
            covered = if trace_only {
                let d = scene.depth_image(&cam);
                d.iter().filter(|d| d.is_finite()).count()
            } else {
                scene.render(&cam, &opts).unwrap().coverage_count()
            };
            best = best.min(t0.elapsed().as_secs_f64());
            best_cpu = best_cpu.min(cpu_seconds() - c0);
        }
        let rays = w as f64 * h as f64;
        println!(
            "{kind:?}: {count} spheres, build {:.1} ms wall / {:.2} s CPU, render {w}x{h} {:.1} ms wall ({:.2} M rays/s) / {:.2} s CPU ({:.2} M rays per CPU-second), {:.1}% covered, {} threads",
            build * 1e3,
            build_cpu,
            best * 1e3,
            rays / best / 1e6,
            best_cpu,
            rays / best_cpu / 1e6,
            100.0 * covered as f64 / rays,
            rayon::current_num_threads()
        );
    }
}

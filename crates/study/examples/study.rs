//! The study end to end: scenes, harness, sweeps, charts, and the MD demo.
//!
//! ```text
//! cargo run --release -p texmap-study --example study -- OUTDIR [--big] [--sweep-size N]
//! ```
//! writes into OUTDIR: results.json / results.csv (every method on S1 and the molecule, plus S2
//! and S3 with `--big`), sweeps.csv, the charts (SVG + PNG), and per scene the reference, each
//! method's frame and its error image (PNG). Prints a summary table.

use std::error::Error;
use std::path::{Path, PathBuf};

use texmap_core::frame::Frame;
use texmap_study::chart;
use texmap_study::harness::{self, HarnessOptions};
use texmap_study::md::{MdParams, MdSystem};
use texmap_study::scenes::{self, SCENE_SEED, SceneId, Seed004System};
use texmap_study::sweeps::{self, SweepKind};

fn save_png(path: &Path, f: &Frame) -> Result<(), Box<dyn Error>> {
    image::save_buffer(
        path,
        f.color_bytes(),
        f.width(),
        f.height(),
        image::ColorType::Rgba8,
    )?;
    Ok(())
}

fn main() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = PathBuf::from(
        args.first()
            .ok_or("usage: study OUTDIR [--big] [--sweep-size N]")?,
    );
    let big = args.iter().any(|a| a == "--big");
    let sweep_size: u32 = args
        .iter()
        .position(|a| a == "--sweep-size")
        .and_then(|i| args.get(i + 1))
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(256);
    std::fs::create_dir_all(&out)?;

    // 1. Every method on the named scenes.
    let mut ids = vec![SceneId::S1, SceneId::Molecule, SceneId::MoleculeBallStick];
    if big {
        ids.extend([SceneId::S2, SceneId::S3]);
    }
    let mut records = Vec::new();
    for id in ids {
        let t = std::time::Instant::now();
        let scene = scenes::build(id);
        let large = matches!(id, SceneId::S2 | SceneId::S3);
        let opts = HarnessOptions {
            warmup: if large { 1 } else { 2 },
            runs: if large { 3 } else { 9 },
            supersample: Some(if large { 2 } else { 4 }),
            ..HarnessOptions::default()
        };
        let rep = harness::run_scene(&scene, &opts)?;
        eprintln!(
            "{}: {} spheres, done in {:.1} s",
            id.name(),
            scene.spheres.len(),
            t.elapsed().as_secs_f64()
        );
        save_png(
            &out.join(format!("{}_reference.png", id.name())),
            &rep.reference,
        )?;
        if let Some(ss) = &rep.reference_ss {
            save_png(&out.join(format!("{}_reference_ss.png", id.name())), ss)?;
        }
        for run in &rep.runs {
            let m = run.method.name();
            save_png(&out.join(format!("{}_{m}.png", id.name())), &run.frame)?;
            let err = harness::error_image(&run.frame, &rep.reference, 8.0)?;
            save_png(&out.join(format!("{}_{m}_error.png", id.name())), &err)?;
        }
        records.extend(rep.records);
    }
    harness::write_results(&out, &records)?;

    // 2. Stability sweeps.
    let series = sweeps::run_all_sweeps(sweep_size)?;
    std::fs::write(out.join("sweeps.csv"), sweeps::series_to_csv(&series))?;

    // 3. Charts.
    let written = chart::write_charts(&out, &records, &series)?;

    // 4. The MD demo: Seed 004's 801 frames' worth of steps, energy bookkeeping.
    let sys = Seed004System::generate(SCENE_SEED);
    let mut md = MdSystem::new(&sys, MdParams::default())?;
    let e0 = md.kinetic_energy() + md.potential_energy();
    let t = std::time::Instant::now();
    let frames = md.run(800, 100);
    let md_ms = t.elapsed().as_secs_f64() * 1e3;
    let e1 = md.kinetic_energy() + md.potential_energy();

    // Summary.
    println!(
        "scene     method    reference       ms/frame   PSNR dB   SSIM    depth mean   depth max    sil px  mismatched"
    );
    for r in &records {
        println!(
            "{:<9} {:<9} {:<14} {:>9.3} {:>9.2} {:>7.4} {:>12.3e} {:>12.3e} {:>8.3} {:>10}",
            r.scene,
            r.method,
            r.reference,
            r.ms_per_frame,
            r.psnr_db,
            r.ssim,
            r.depth_err_mean,
            r.depth_err_max,
            r.silhouette_px,
            r.silhouette_mismatched
        );
    }
    println!();
    println!("sweeps at {sweep_size}x{sweep_size}:");
    for s in &series {
        let worst_sil = s
            .points
            .iter()
            .filter(|p| !(s.kind == SweepKind::EyeDistance && p.x < 1.0))
            .map(|p| p.metrics.silhouette_px)
            .fold(0.0, f64::max);
        let min_psnr = s
            .points
            .iter()
            .filter(|p| !(s.kind == SweepKind::EyeDistance && p.x < 1.0))
            .map(|p| p.metrics.psnr_db)
            .fold(f64::INFINITY, f64::min);
        let first_bad = s.breaking_point(|m| m.silhouette_px > 0.5);
        println!(
            "  {:<13} {:<9} worst silhouette {:>7.3} px, min PSNR {:>6.2} dB, first x with silhouette > 0.5 px: {:?}",
            s.kind.name(),
            s.method.name(),
            worst_sil,
            min_psnr,
            first_bad
        );
    }
    println!();
    println!(
        "MD: {} particles, 800 steps (dt = {} τ) in {:.0} ms, {} frames kept, energy {:.3} -> {:.3} ε (drift {:.2e} of |E0|)",
        md.len(),
        MdParams::default().dt,
        md_ms,
        frames.len(),
        e0,
        e1,
        ((e1 - e0) / e0).abs()
    );
    println!(
        "wrote {} chart files and results into {}",
        written.len(),
        out.display()
    );
    Ok(())
}

//! The quality axis of the study (module `texmap_study::quality`) on S1 and, with `--s2`, on S2
//! at a reduced size.
//!
//! ```text
//! cargo run --release -p texmap-study --example quality -- OUTDIR [--s2 WxH] [--ref N] [--ref-ao M]
//! ```
//! writes into OUTDIR: quality.json / quality.csv (one record per setting and scene), the chart
//! quality.svg (ms per frame against PSNR), and per scene the references and each setting's
//! frame as PNG. Prints a table. Defaults: an 8x8 reference with 2x2 AO rays per sample
//! (256 AO rays per pixel).

use std::error::Error;
use std::path::Path;

use texmap_core::frame::Frame;
use texmap_study::quality::{QualityStudyOptions, run_quality, write_quality};
use texmap_study::scenes::{SceneId, build, build_sized};

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
    let out = Path::new(
        args.first()
            .ok_or("usage: quality OUTDIR [--s2 WxH] [--ref N] [--ref-ao M]")?,
    );
    std::fs::create_dir_all(out)?;
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let mut opts = QualityStudyOptions::default();
    if let Some(n) = value("--ref") {
        opts.ref_samples_per_axis = n.parse()?;
    }
    if let Some(m) = value("--ref-ao") {
        opts.ref_ao_samples_per_axis = m.parse()?;
    }
    let mut scenes = vec![build(SceneId::S1)];
    if let Some(size) = value("--s2") {
        let (w, h) = size.split_once('x').ok_or("--s2 takes WxH")?;
        scenes.push(build_sized(SceneId::S2, w.parse()?, h.parse()?)?);
    }
    let mut records = Vec::new();
    println!(
        "{:<6} {:<20} {:<30} {:>10} {:>8} {:>7}",
        "scene", "setting", "reference", "ms/frame", "PSNR dB", "SSIM"
    );
    for s in &scenes {
        let rep = run_quality(s, &opts)?;
        for (name, f) in &rep.references {
            save_png(&out.join(format!("{}_{name}.png", s.name())), f)?;
        }
        for r in &rep.runs {
            let rec = &r.record;
            println!(
                "{:<6} {:<20} {:<30} {:>10.2} {:>8.2} {:>7.4}",
                rec.scene, rec.method, rec.reference, rec.ms_per_frame, rec.psnr_db, rec.ssim
            );
            save_png(
                &out.join(format!("{}_{}.png", s.name(), rec.method)),
                &r.frame,
            )?;
            records.push(rec.clone());
        }
    }
    for p in write_quality(out, &records)? {
        println!("wrote {}", p.display());
    }
    Ok(())
}

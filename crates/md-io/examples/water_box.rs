//! Writes a water-like test system of any size: a PDB topology and an XTC trajectory (the pair
//! a GROMACS user has), for end-to-end timings such as
//! `texmap render run.xtc --topology top.pdb --size 1920x1080 -o movie.mp4`.
//!
//! `cargo run --release -p texmap-md-io --example water_box -- OUT_DIR MOLECULES FRAMES`
//! (three atoms a molecule: an O on a 3.1 Å lattice and two H at 0.96 Å, residue SOL; each
//! frame moves every molecule by a small deterministic wobble).

use texmap_md_io::{Format, Frame, Label, UnitCell, Writer};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 {
        return Err("usage: water_box OUT_DIR MOLECULES FRAMES".into());
    }
    let dir = std::path::Path::new(&args[1]);
    let n_mol: usize = args[2].parse()?;
    let frames: usize = args[3].parse()?;
    if n_mol == 0 || frames == 0 {
        return Err("MOLECULES and FRAMES must be at least 1".into());
    }
    std::fs::create_dir_all(dir)?;
    let side = (n_mol as f64).cbrt().ceil() as usize;
    let (o, h1, h2, sol) = (
        Label::new("OW").ok_or("label")?,
        Label::new("HW1").ok_or("label")?,
        Label::new("HW2").ok_or("label")?,
        Label::new("SOL").ok_or("label")?,
    );
    let frame = |k: usize, named: bool| -> Result<Frame, Box<dyn std::error::Error>> {
        let mut f = Frame::new();
        for m in 0..n_mol {
            let phase = (m as f32 * 0.618_034 + k as f32 * 0.15) * std::f32::consts::TAU;
            let c = [
                (m % side) as f32 * 3.1 + 0.4 * phase.sin(),
                ((m / side) % side) as f32 * 3.1 + 0.4 * (1.3 * phase).cos(),
                (m / (side * side)) as f32 * 3.1,
            ];
            f.positions.push(c);
            f.positions.push([c[0] + 0.96, c[1], c[2]]);
            f.positions.push([c[0] - 0.24, c[1] + 0.93, c[2]]);
            if named {
                f.names.extend([o, h1, h2]);
                f.res_names.extend([sol; 3]);
                f.res_ids.extend([m as i64 % 9999 + 1; 3]);
            }
        }
        let l = side as f64 * 3.1;
        f.cell = Some(UnitCell::orthorhombic(l, l, l)?);
        Ok(f)
    };
    let mut top = Writer::create(dir.join("top.pdb"), Format::Pdb)?;
    top.write_frame(&frame(0, true)?)?;
    top.finish()?;
    let mut xtc = Writer::create(dir.join("run.xtc"), Format::Xtc)?;
    for k in 0..frames {
        xtc.write_frame(&frame(k, false)?)?;
    }
    xtc.finish()?;
    println!(
        "wrote {} and {} ({} atoms, {frames} frames)",
        dir.join("top.pdb").display(),
        dir.join("run.xtc").display(),
        3 * n_mol
    );
    Ok(())
}

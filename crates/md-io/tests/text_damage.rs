//! Damaged text files built from the good ones in tests/data: cut at every byte (so at every
//! line boundary and inside every line) and with bytes replaced at every position. Nothing may
//! panic; every frame that ends before the damage reads back unchanged; an error names the file,
//! the frame and the line and byte.
//!
//! Frame boundaries are found here independently of the readers, from each format's markers.

use std::io::Cursor;
use std::path::PathBuf;
use texmap_md_io::{Error, Format, Frame, Trajectory};

const FILES: &[(&str, Format)] = &[
    ("ase_ext.xyz", Format::Xyz),
    ("ase_plain.xyz", Format::Xyz),
    ("mda_multi.pdb", Format::Pdb),
    ("gemmi_multi.cif", Format::Mmcif),
    ("mda_vel.gro", Format::Gro),
    ("py_prec5.gro", Format::Gro),
    ("lmp_tri.lammpstrj", Format::LammpsDump),
    ("lmp_scaled.lammpstrj", Format::LammpsDump),
    ("molecules/library.sdf", Format::Sdf),
    ("molecules/caffeine_v3000.mol", Format::Sdf),
    ("molecules/library.mol2", Format::Mol2),
    ("vasp/XDATCAR_pmg", Format::Vasp),
    ("vasp/XDATCAR_ase", Format::Vasp),
    ("vasp/POSCAR_pmg_vel", Format::Vasp),
    ("volume/CHGCAR_small", Format::Vasp),
    ("volume/ase_small.cube", Format::Cube),
    ("crystal/two_blocks.cif", Format::CrystalCif),
    ("crystal/cod_9001665.cif", Format::CrystalCif),
    ("lammps_data/ase_full.data", Format::LammpsData),
    ("lammps_data/mda_full_tri.data", Format::LammpsData),
    ("amber_ascii/box.mdcrd", Format::AmberTrj),
    ("amber_ascii/vel_box.rst7", Format::AmberRestart),
    ("amber_ascii/odd.inpcrd", Format::AmberRestart),
    ("mda_two.crd", Format::CharmmCrd),
    ("parmed_models.pqr", Format::Pqr),
    ("pdbqt/poses.pdbqt", Format::Pdbqt),
    ("tinker/water_box.arc", Format::Tinker),
    ("tinker/caffeine.txyz", Format::Tinker),
    ("dlpoly/HISTORY", Format::DlPoly),
    ("dlpoly/CONFIG", Format::DlPoly),
    ("xsf/ase_anim_fixed.axsf", Format::Xsf),
    ("xsf/ase_anim_cell.axsf", Format::Xsf),
    ("xsf/ase_anim_molecule.axsf", Format::Xsf),
    ("xsf/ase_grid_small.xsf", Format::Xsf),
    ("xsf/pmg_grids.xsf", Format::Xsf),
    ("espresso/si_md.pwo", Format::EspressoOut),
    ("espresso/ibrav4_hex.pwi", Format::EspressoIn),
];

/// The options a fixture is read with: an AMBER trajectory needs its topology's atom count
/// (box.mdcrd: 66).
fn options(format: Format) -> texmap_md_io::ReadOptions {
    let o = texmap_md_io::ReadOptions::new();
    if format == Format::AmberTrj {
        o.atoms(66)
    } else {
        o
    }
}

fn data(name: &str) -> Vec<u8> {
    std::fs::read(
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name),
    )
    .unwrap()
}

/// Byte offsets where each frame's text ends, from the format's markers.
fn frame_ends(bytes: &[u8], format: Format) -> Vec<usize> {
    let text = std::str::from_utf8(bytes).unwrap();
    let mut line_starts = vec![0];
    for (i, b) in bytes.iter().enumerate() {
        if *b == b'\n' {
            line_starts.push(i + 1);
        }
    }
    let lines: Vec<&str> = text.split_inclusive('\n').collect();
    let mut ends = Vec::new();
    match format {
        Format::Xyz | Format::Gro => {
            // XYZ: count line, comment, n atoms. GRO: title, count, n atoms, box.
            let mut l = 0;
            while l < lines.len() {
                let (count_line, extra) = if format == Format::Xyz {
                    (l, 2)
                } else {
                    (l + 1, 3)
                };
                let n: usize = lines[count_line].trim().parse().unwrap();
                l += n + extra;
                ends.push(line_starts[l]);
            }
        }
        Format::Pdb | Format::Pdbqt => {
            for (k, l) in lines.iter().enumerate() {
                if l.starts_with("ENDMDL") {
                    ends.push(line_starts[k + 1]);
                }
            }
        }
        Format::Mmcif => {
            // A model ends where the next one's first _atom_site row shows (the row's line is
            // part of what ends it: a damaged model number there is the earlier model's
            // damage); the last ends with the loop, here at the end of the file. The rows are
            // gemmi's one-line ATOM records, the model number their last field.
            let model = |l: &str| l.split_whitespace().last().unwrap().to_string();
            let rows: Vec<usize> = (0..lines.len())
                .filter(|&k| lines[k].starts_with("ATOM") || lines[k].starts_with("HETATM"))
                .collect();
            for w in rows.windows(2) {
                if model(lines[w[0]]) != model(lines[w[1]]) {
                    ends.push(line_starts[w[1] + 1]);
                }
            }
            ends.push(bytes.len());
        }
        Format::LammpsDump => {
            let mut starts: Vec<usize> = lines
                .iter()
                .enumerate()
                .filter(|(_, l)| l.starts_with("ITEM: TIMESTEP"))
                .map(|(k, _)| line_starts[k])
                .collect();
            starts.remove(0);
            starts.push(bytes.len());
            ends = starts;
        }
        Format::Sdf => {
            // A record ends with its '$$$$' line; a molfile (no '$$$$') with the file.
            for (k, l) in lines.iter().enumerate() {
                if l.trim_end() == "$$$$" {
                    ends.push(line_starts[k + 1]);
                }
            }
            if ends.last() != Some(&bytes.len()) {
                ends.push(bytes.len());
            }
        }
        Format::Mol2 => {
            // A molecule ends where the next one's header line shows (that line is part of
            // what ends it: its damage is the earlier molecule's), the last with the file.
            for (k, l) in lines.iter().enumerate().skip(1) {
                if l.starts_with("@<TRIPOS>MOLECULE") {
                    ends.push(line_starts[k + 1]);
                }
            }
            ends.push(bytes.len());
        }
        Format::Vasp => {
            // An XDATCAR frame ends after the atom lines of its configuration line; the atom
            // count is the sum on the header's counts line (the 7th). A POSCAR is one frame.
            let n: usize = lines[6]
                .split_whitespace()
                .map(|c| c.parse::<usize>().unwrap())
                .sum();
            for (k, l) in lines.iter().enumerate() {
                if l.contains("configuration=") {
                    ends.push(line_starts[k + 1 + n]);
                }
            }
            if ends.is_empty() {
                ends.push(bytes.len());
            }
        }
        Format::CrystalCif => {
            // A data block ends where the next one's `data_` line shows (that line is part of
            // what ends it: its damage is the earlier block's), the last with the file. (Every
            // block of these files holds atom sites.)
            let blocks = (0..lines.len()).filter(|&k| lines[k].starts_with("data_"));
            for k in blocks.skip(1) {
                ends.push(line_starts[k + 1]);
            }
            ends.push(bytes.len());
        }
        Format::DlPoly if lines[2].starts_with("timestep") => {
            // The title and header, then per frame a timestep line, 3 cell lines and 4 lines
            // per atom (name, position, velocity, force: levcfg 2).
            let n: usize = lines[1].split_whitespace().nth(2).unwrap().parse().unwrap();
            let mut l = 2 + 4 + 4 * n;
            while l <= lines.len() {
                ends.push(line_starts[l]);
                l += 4 + 4 * n;
            }
        }
        Format::DlPoly => ends.push(bytes.len()),
        Format::Tinker => {
            // A count line, a box line when the next starts with a real number, the atoms.
            let mut l = 0;
            while l < lines.len() {
                let n: usize = lines[l].split_whitespace().next().unwrap().parse().unwrap();
                let boxed = lines[l + 1]
                    .split_whitespace()
                    .next()
                    .is_some_and(|f| f.contains('.'));
                l += 1 + usize::from(boxed) + n;
                ends.push(line_starts[l]);
            }
        }
        Format::AmberTrj => {
            // The title, then per frame 20 coordinate lines (198 numbers) and a box line.
            let mut l = 1 + 21;
            while l <= lines.len() {
                ends.push(line_starts[l]);
                l += 21;
            }
        }
        Format::CharmmCrd => {
            // Title lines starting with '*', the count line (its first number), the atoms.
            let mut l = 0;
            while l < lines.len() {
                while lines[l].starts_with('*') {
                    l += 1;
                }
                let n: usize = lines[l].split_whitespace().next().unwrap().parse().unwrap();
                l += 1 + n;
                ends.push(line_starts[l]);
            }
        }
        Format::Pqr => {
            // ENDMDL ends a model; a file without models is one frame.
            for (k, l) in lines.iter().enumerate() {
                if l.starts_with("ENDMDL") {
                    ends.push(line_starts[k + 1]);
                }
            }
            if ends.is_empty() {
                ends.push(bytes.len());
            }
        }
        Format::Xsf => {
            // A step ends where the next one's first keyword line shows (`ATOMS k`, `PRIMVEC
            // k` or `PRIMCOORD k`, k ≥ 2: that line is part of what ends it, its damage the
            // earlier step's); the last, with its data grids, with the file.
            let mut seen = std::collections::BTreeSet::new();
            for (k, l) in lines.iter().enumerate() {
                let mut w = l.split_whitespace();
                let key = w.next().unwrap_or("").to_ascii_uppercase();
                let step: usize = w.next().and_then(|t| t.parse().ok()).unwrap_or(0);
                if ["ATOMS", "PRIMVEC", "PRIMCOORD"].contains(&key.as_str())
                    && step >= 2
                    && seen.insert(step)
                {
                    ends.push(line_starts[k + 1]);
                }
            }
            ends.push(bytes.len());
        }
        Format::EspressoOut => {
            // A step ends where the next one's configuration starts: in molecular dynamics its
            // `Entering Dynamics` line (the positions after the last step, which have no
            // results, follow the last such line: no frame of their own); an scf run is one
            // frame, the whole file.
            for (k, l) in lines.iter().enumerate() {
                if l.trim_start().starts_with("Entering Dynamics") {
                    ends.push(line_starts[k]);
                }
            }
            if ends.is_empty() {
                ends.push(bytes.len());
            }
        }
        Format::LammpsData | Format::Cube | Format::AmberRestart | Format::EspressoIn => {
            // One frame: the whole file (a LAMMPS data file's sections may come in any order;
            // a cube's frame is its molecule, its grid values walked to the end).
            ends.push(bytes.len());
        }
        _ => unreachable!(),
    }
    ends
}

/// Reads until the end or the first error; returns the frames and the error.
fn read_all(bytes: &[u8], format: Format) -> (Vec<Frame>, Option<Error>) {
    let mut t = Trajectory::from_reader_with(
        Cursor::new(bytes.to_vec()),
        format,
        "damaged",
        options(format),
    )
    .unwrap();
    let mut out = Vec::new();
    let mut f = Frame::new();
    loop {
        match t.read_next(&mut f) {
            Ok(true) => out.push(f.clone()),
            Ok(false) => return (out, None),
            Err(e) => return (out, Some(e)),
        }
        assert!(out.len() < 100, "reader does not stop");
    }
}

fn check_error_names_the_place(e: &Error, frames_before: usize) {
    let msg = e.to_string();
    assert!(msg.starts_with("damaged: frame "), "{msg}");
    let loc = e
        .location()
        .unwrap_or_else(|| panic!("no location in {msg}"));
    assert_eq!(loc.frame, Some(frames_before), "{msg}");
    assert!(loc.line.is_some() && loc.byte.is_some(), "{msg}");
    assert!(msg.contains("line ") && msg.contains("byte "), "{msg}");
}

#[test]
fn cut_at_every_byte_keeps_the_frames_before_the_cut() {
    for &(name, format) in FILES {
        let good = data(name);
        let (all, err) = read_all(&good, format);
        assert!(err.is_none(), "{name}: {err:?}");
        let ends = frame_ends(&good, format);
        assert_eq!(ends.len(), all.len(), "{name}: frame count");
        for cut in 0..good.len() {
            let (got, err) = read_all(&good[..cut], format);
            let complete = ends.iter().filter(|e| **e <= cut).count();
            assert!(
                got.len() >= complete,
                "{name} cut at {cut}: {} frames, {complete} complete",
                got.len()
            );
            // Every frame complete before the cut is unchanged.
            for k in 0..complete {
                assert_eq!(got[k], all[k], "{name} cut at {cut}: frame {k}");
            }
            if let Some(e) = err {
                check_error_names_the_place(&e, got.len());
            }
        }
    }
}

#[test]
fn replaced_bytes_never_panic_and_keep_earlier_frames() {
    for &(name, format) in FILES {
        let good = data(name);
        let (all, _) = read_all(&good, format);
        let ends = frame_ends(&good, format);
        for at in 0..good.len() {
            // A letter, a line break, a space and a non-UTF-8 byte (the last two at every third
            // byte, to keep the test quick).
            let all_junk: &[u8] = if at % 3 == 0 { b"x\n \xff" } else { b"x\n" };
            for &junk in all_junk {
                let mut bad = good.clone();
                bad[at] = junk;
                let (got, err) = read_all(&bad, format);
                // Frames that end before the damaged byte read back unchanged.
                let before = ends.iter().filter(|e| **e <= at).count();
                assert!(
                    got.len() >= before,
                    "{name} byte {at} -> {junk}: {} < {before}",
                    got.len()
                );
                for k in 0..before {
                    assert_eq!(got[k], all[k], "{name} byte {at} -> {junk}: frame {k}");
                }
                if let Some(e) = err {
                    check_error_names_the_place(&e, got.len());
                }
            }
        }
    }
}

#[test]
fn error_after_good_frames_then_random_access_still_reaches_them() {
    // Cut the 3-frame PDB inside the last model: frames 0 and 1 stay reachable by index.
    let good = data("mda_multi.pdb");
    let ends = frame_ends(&good, Format::Pdb);
    let cut = &good[..ends[1] + 100];
    let mut t = Trajectory::from_reader(Cursor::new(cut.to_vec()), Format::Pdb, "cut.pdb").unwrap();
    let e = t.n_frames().unwrap_err();
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    assert!(e.to_string().starts_with("cut.pdb: frame 2, line "), "{e}");
    let (all, _) = read_all(&good, Format::Pdb);
    let mut f = Frame::new();
    // The failed count left the stream where it was: frame 0 comes next.
    assert!(t.read_next(&mut f).unwrap());
    assert_eq!(f, all[0]);
    t.read_frame(1, &mut f).unwrap();
    assert_eq!(f, all[1]);
    t.read_frame(0, &mut f).unwrap();
    assert_eq!(f, all[0]);
    assert!(t.read_frame(2, &mut f).is_err());
}

/// Under `allow_truncated`, a file cut at any byte streams its complete frames and stops at
/// the cut with a warning: a partial last line is the cut, not damage. Frames complete before
/// the cut read back unchanged, and the frame count agrees with what streaming gave. (A cut
/// before the first atom's data leaves no frame to keep, and may be an error.) One more
/// frame than the complete ones may be read where nothing in the file tells that it is cut: a
/// model of a format without atom counts (mmCIF) cut between rows, or a partial last line that
/// still parses (a number cut to a shorter number, no end of line after it), which the readers
/// cannot tell from a file written without a final newline.
#[test]
fn allow_truncated_streams_every_cut_to_its_complete_frames() {
    for &(name, format) in FILES {
        let lenient = options(format).allow_truncated(true);
        let good = data(name);
        let (all, _) = read_all(&good, format);
        let ends = frame_ends(&good, format);
        let mut errors = Vec::new();
        for cut in 1..good.len() {
            let src = Cursor::new(good[..cut].to_vec());
            let mut t = Trajectory::from_reader_with(src, format, "cut", lenient.clone()).unwrap();
            let complete = ends.iter().filter(|e| **e <= cut).count();
            let mut f = Frame::new();
            let mut got = 0;
            let streamed = loop {
                match t.read_next(&mut f) {
                    Ok(true) => {
                        if got < complete {
                            assert_eq!(f, all[got], "{name} cut at {cut}: frame {got}");
                        }
                        got += 1;
                    }
                    Ok(false) => break Ok(got),
                    Err(e) => break Err(e),
                }
            };
            match streamed {
                Ok(k) => {
                    // (mmCIF: `frame_ends` counts a model complete only after the next
                    // model's first row line, where the reader already has it.)
                    assert!(
                        k >= complete && (format == Format::Mmcif || k <= complete + 1),
                        "{name} cut at {cut}: {k} frames, {complete} complete"
                    );
                    assert_eq!(t.n_frames().unwrap(), k, "{name} cut at {cut}");
                }
                Err(e) => errors.push((cut, e.to_string())),
            }
        }
        // Only a cut before the first atom's data may fail: an mmCIF header without its
        // complete _atom_site loop is a file that holds no frame, not a cut frame.
        let first_row = match format {
            Format::Mmcif => std::str::from_utf8(&good).unwrap().find("\nATOM").unwrap(),
            // A crystallographic CIF's first block without its atom-site loop holds no frame.
            Format::CrystalCif => (std::str::from_utf8(&good).unwrap())
                .find("\n_atom_site_label")
                .unwrap(),
            _ => 0,
        };
        let late: Vec<_> = errors.iter().filter(|(cut, _)| *cut > first_row).collect();
        assert!(
            late.is_empty(),
            "{name}: {} cuts failed: {:?}",
            late.len(),
            &late[..late.len().min(5)]
        );
    }
}

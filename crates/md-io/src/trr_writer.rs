//! GROMACS TRR trajectories written as `gmx mdrun` and `gmx trjconv` write them, in single
//! precision: per frame the box, positions, velocities and forces that the frame has.
//!
//! # What is written
//! Each frame is one XDR (big-endian) record, laid out as src/trr.rs describes: the magic 1993,
//! the version string `GMX_trn_file`, the block sizes, the atom count, the step, `nre` 0, the
//! time and λ as f32, then the blocks:
//! - **box**: the cell's rows in nm, as the cell gives them (GROMACS's own boxes are lower
//!   triangular; a cell from another program keeps its orientation, as the XTC writer keeps it);
//!   absent when the frame has no cell;
//! - **x**: positions, Å → nm;
//! - **v**: velocities, Å/ps → nm/ps, when the frame has them;
//! - **f**: the properties `fx fy fz` as forces in kJ/(mol·Å) → kJ/(mol·nm), when the frame has
//!   all three. They are the unit our TRR reader gives (and MDAnalysis's): a TRR read and written
//!   back keeps its forces. Forces read from other programs' files are in those programs' units
//!   (eV/Å from ASE, the dump's units from LAMMPS) and are written unconverted.
//!
//! The virial and pressure blocks are never written (`gmx trjconv` drops them too). Each block
//! is chosen per frame, as mdrun chooses them by `nstxout`, `nstvout` and `nstfout`: a frame
//! without velocities has a zero `v_size`. The step is the frame's (else its index in the file),
//! the time the frame's in ps (else 0, as the XTC writer writes it), λ 0.
//!
//! Conversion: every length is divided by 10 in f32 (a correctly rounded quotient), so a TRR
//! read and written back gives each nm value back within one unit in the last place (f32 has no
//! exact tenth); forces are multiplied by 10.
//!
//! # Refused, before any byte of the frame is written
//! A frame whose atom count differs from the first frame's (GROMACS's tools and MDAnalysis take
//! one count per file), a step outside the header's 32-bit integer, an atom count whose blocks
//! would not fit the header's 32-bit sizes, and non-finite forces (our reader, like GROMACS,
//! refuses them).

use std::io::{self, Write};

use crate::frame::Frame;
use crate::trr::MAGIC;

/// Writes GROMACS TRR frames in single precision.
#[derive(Debug)]
pub struct TrrWriter<W> {
    pub(crate) out: W,
    n_atoms: Option<usize>,
    n_written: usize,
    buf: Vec<u8>,
}

/// The forces of `frame` (`fx fy fz`, all three), if it has them.
fn forces(frame: &Frame) -> Option<[&[f32]; 3]> {
    Some([
        frame.property("fx")?,
        frame.property("fy")?,
        frame.property("fz")?,
    ])
}

impl<W: Write> TrrWriter<W> {
    /// A TRR writer on `out`.
    pub fn new(out: W) -> Self {
        TrrWriter {
            out,
            n_atoms: None,
            n_written: 0,
            buf: Vec::new(),
        }
    }

    /// Whether the format can hold `frame` after the frames written (`Err`: what it cannot).
    pub fn check(&self, frame: &Frame) -> Result<(), String> {
        let n = frame.n_atoms();
        if let Some(first) = self.n_atoms
            && first != n
        {
            return Err(format!(
                "{n} atoms, where the first frame had {first} (a TRR file holds one atom count)"
            ));
        }
        if n == 0 {
            return Err("no atoms".into());
        }
        if n > i32::MAX as usize / 12 {
            return Err(format!(
                "{n} atoms: a TRR block of 3 x {n} f32 exceeds the header's 32-bit size"
            ));
        }
        let step = frame.step.unwrap_or(self.n_written as i64);
        if i32::try_from(step).is_err() {
            return Err(format!(
                "step {step}: TRR's header holds a 32-bit step (-2147483648 to 2147483647)"
            ));
        }
        if let Some(f) = forces(frame)
            && let Some((d, i)) = f
                .iter()
                .enumerate()
                .find_map(|(d, col)| col.iter().position(|v| !v.is_finite()).map(|i| (d, i)))
        {
            return Err(format!(
                "atom {i}'s force {} is {}: TRR forces must be finite",
                ["fx", "fy", "fz"][d],
                f[d][i]
            ));
        }
        Ok(())
    }

    /// Appends a [`Frame`] (the `Writer` contract, which has called [`TrrWriter::check`]).
    pub fn write_frame(&mut self, frame: &Frame) -> io::Result<()> {
        let n = frame.n_atoms();
        let block = (3 * 4 * n) as i32;
        let cell = frame.cell.map(|c| c.matrix());
        let has_v = !frame.velocities.is_empty();
        let f = forces(frame);
        let step = frame.step.unwrap_or(self.n_written as i64) as i32;
        let b = &mut self.buf;
        b.clear();
        let int = |b: &mut Vec<u8>, v: i32| b.extend_from_slice(&v.to_be_bytes());
        let real = |b: &mut Vec<u8>, v: f32| b.extend_from_slice(&v.to_be_bytes());
        int(b, MAGIC);
        int(b, 13);
        int(b, 12);
        b.extend_from_slice(b"GMX_trn_file");
        // ir, e, box, vir, pres, top, sym, x, v, f.
        let sizes = [
            0,
            0,
            if cell.is_some() { 36 } else { 0 },
            0,
            0,
            0,
            0,
            block,
            if has_v { block } else { 0 },
            if f.is_some() { block } else { 0 },
        ];
        for s in sizes {
            int(b, s);
        }
        int(b, n as i32);
        int(b, step);
        int(b, 0);
        real(b, frame.time.unwrap_or(0.0) as f32);
        real(b, 0.0);
        if let Some(m) = cell {
            for v in m.as_flattened() {
                real(b, (*v / 10.0) as f32);
            }
        }
        for p in frame.positions.iter().chain(if has_v {
            frame.velocities.iter()
        } else {
            [].iter()
        }) {
            for c in p {
                real(b, c / 10.0);
            }
        }
        if let Some([fx, fy, fz]) = f {
            for ((x, y), z) in fx.iter().zip(fy).zip(fz) {
                for c in [x, y, z] {
                    real(b, c * 10.0);
                }
            }
        }
        self.out.write_all(b)?;
        self.n_atoms = Some(n);
        self.n_written += 1;
        Ok(())
    }

    /// Ends the file (the `Writer` contract): TRR has no trailer.
    pub fn finish(&mut self) -> io::Result<()> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{Property, UnitCell};
    use crate::trr::TrrReader;
    use std::io::Cursor;

    fn frame(n: usize, seed: f32) -> Frame {
        let mut f = Frame::new();
        f.positions = (0..n)
            .map(|i| [i as f32 * 1.25 + seed, 3.5 - seed, 0.1 * i as f32])
            .collect();
        f.cell = Some(
            UnitCell::from_matrix([[30.0, 0.0, 0.0], [5.0, 28.0, 0.0], [-2.5, 3.0, 25.5]]).unwrap(),
        );
        f.time = Some(f64::from(seed) * 2.0);
        f.step = Some((seed * 1000.0) as i64);
        f
    }

    #[test]
    fn our_reader_reads_back_every_block_of_every_frame() {
        let n = 5;
        let mut frames = vec![frame(n, 1.0), frame(n, 2.0), frame(n, 3.0)];
        frames[0].velocities = (0..n).map(|i| [i as f32, -0.5, 2.0]).collect();
        for (d, name) in ["fx", "fy", "fz"].into_iter().enumerate() {
            frames[0].properties.push(Property {
                name: name.into(),
                values: (0..n).map(|i| i as f32 * 0.3 - d as f32).collect(),
            });
        }
        frames[1].cell = None;
        frames[2].step = None;
        let mut w = TrrWriter::new(Vec::new());
        for f in &frames {
            w.check(f).unwrap();
            w.write_frame(f).unwrap();
        }
        let bytes = w.out;
        let mut r = TrrReader::new(Cursor::new(bytes), "w.trr".into()).unwrap();
        assert_eq!(r.n_frames().unwrap(), 3);
        let mut got = Frame::new();
        for (k, want) in frames.iter().enumerate() {
            assert!(r.read_next(&mut got).unwrap());
            assert_eq!(got.n_atoms(), n);
            for (a, b) in got.positions.iter().zip(&want.positions) {
                for d in 0..3 {
                    // One rounding each way: within an f32 unit of the value.
                    assert!((a[d] - b[d]).abs() <= b[d].abs() * 2.5e-7, "{a:?} vs {b:?}");
                }
            }
            assert_eq!(got.velocities.len(), want.velocities.len());
            assert_eq!(got.properties.len(), want.properties.len());
            for (p, q) in got.properties.iter().zip(&want.properties) {
                assert_eq!(p.name, q.name);
                for (a, b) in p.values.iter().zip(&q.values) {
                    assert!((a - b).abs() <= b.abs() * 2.5e-7);
                }
            }
            assert_eq!(got.step, Some(want.step.unwrap_or(k as i64)));
            assert_eq!(got.time, Some(f64::from(want.time.unwrap() as f32)));
            assert_eq!(got.cell.is_some(), want.cell.is_some());
            if let (Some(a), Some(b)) = (got.cell, want.cell) {
                for (x, y) in a
                    .matrix()
                    .as_flattened()
                    .iter()
                    .zip(b.matrix().as_flattened())
                {
                    assert!((x - y).abs() < 1e-5, "{x} vs {y}");
                }
            }
        }
        assert!(!r.read_next(&mut got).unwrap());
    }

    #[test]
    fn frames_it_cannot_hold_are_refused() {
        let mut w = TrrWriter::new(Vec::new());
        let f = frame(4, 1.0);
        w.write_frame(&f).unwrap();
        let e = w.check(&frame(5, 1.0)).unwrap_err();
        assert!(e.contains("5 atoms, where the first frame had 4"), "{e}");
        let mut big = frame(4, 1.0);
        big.step = Some(1 << 40);
        assert!(w.check(&big).unwrap_err().contains("32-bit step"));
        let mut nan = frame(4, 1.0);
        for name in ["fx", "fy", "fz"] {
            nan.properties.push(Property {
                name: name.into(),
                values: vec![1.0, 2.0, f32::NAN, 0.0],
            });
        }
        let e = w.check(&nan).unwrap_err();
        assert!(e.contains("atom 2's force fx is NaN"), "{e}");
    }
}

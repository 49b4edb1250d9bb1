//! HOOMD-blue GSD trajectories written as `gsd.hoomd` writes them: GSD file format 2.0, the
//! `hoomd` schema 1.4, for HOOMD-blue (`Simulation.create_state_from_gsd`), `gsd.hoomd`, OVITO,
//! freud and our reader.
//!
//! # The file
//! A 256-byte header, the data chunks of every frame in order, then the namelist and the index
//! (src/gsd.rs describes the layer). The chunks are appended as frames come; the index (32 bytes
//! a chunk, kept in memory) and the namelist are written by [`GsdWriter::finish`], which then
//! writes the header pointing at them: memory is one frame plus the index. Index entries are
//! sorted by frame, then name id, as GSD 2.x requires.
//!
//! # What each frame holds (the hoomd schema)
//! | chunk | from | written |
//! |---|---|---|
//! | `configuration/step` (u64) | [`Frame::step`], else the frame's index | every frame |
//! | `configuration/dimensions` (u8) | 2 for a planar frame 0 (below), else 3 | frame 0 |
//! | `configuration/box` (6 f32) | the cell (below) | every frame |
//! | `particles/N` (u32) | the atom count | every frame |
//! | `particles/types`, `particles/typeid` | [`Frame::types`], else element symbols, else names, else `A`; numbered in order of first appearance | frame 0, and a later frame whose values differ |
//! | `particles/position` (N×3 f32) | positions in the box (below) | every frame |
//! | `particles/image` (N×3 i32) | the periodic images the wrapping moved each atom by, plus the frame's `ix iy iz` | every frame |
//! | `particles/velocity` (N×3 f32) | [`Frame::velocities`], turned with the box | every frame that has them |
//! | `particles/diameter`, `mass`, `charge` (f32) | twice [`Frame::radii`]; the properties `mass`, `charge` | frame 0, and a later frame whose values differ |
//! | `particles/orientation` (N×4 f32) | the properties `quatw quati quatj quatk` | every frame that has them |
//! | `particles/body` (i32) | the property `body` | as `mass` |
//! | `bonds/N`, `bonds/types`, `bonds/typeid`, `bonds/group` | [`Frame::bonds`], one bond type per unordered pair of particle types (`A-B`) | as `mass` |
//!
//! A chunk left out of a later frame takes frame 0's values, as the schema says and as
//! `gsd.hoomd` writes: types, diameters, masses and bonds are stored once. Values are written as
//! they are: HOOMD has no fixed units, so Å stay Å (the reader reads them back unchanged).
//!
//! **The box.** HOOMD's box is centred on the origin with edges a1 = (Lx, 0, 0),
//! a2 = (xy·Ly, Ly, 0), a3 = (xz·Lz, yz·Lz, Lz): LAMMPS's restricted triclinic form. A cell in
//! another orientation is rotated into it with its atoms, and tilts beyond half an edge are
//! reduced, as the LAMMPS data writer does (src/lammps_data_writer.rs); the positions are then
//! shifted by the box's centre and wrapped into it, since HOOMD requires every particle inside
//! its box: the periodic images moved are added to `particles/image`, so unwrapping gives the
//! positions back. A frame without a cell gets its atoms' bounding box grown by 1 Å each side.
//!
//! **2-D.** A file is 2-D, as HOOMD's 2-D simulations and `gsd.hoomd` write it (`dimensions` 2,
//! every box's Lz, xz, yz 0), when frame 0 is planar: its cell is open along its third edge
//! ([`crate::UnitCell::periodic`], as our reader gives a 2-D box), that edge is perpendicular
//! to the other two and every atom lies in the box's mid-plane (z = 0 once centred). Positions
//! are then not wrapped along z, so a GSD read and written back keeps its dimensionality.
//!
//! # Refused
//! A label with a NUL byte (the type list is NUL-separated), more than 2³² − 1 atoms, bonds or
//! types (the schema's u32 counts), and a step below zero.

use std::collections::HashMap;
use std::io::{self, Seek, SeekFrom, Write};

use crate::frame::{Frame, Label};
use crate::gsd::MAGIC;
use crate::lammps_data_writer::{DataBox, bounding_box, data_box};

/// GSD data types (the file layer's codes).
const U8: u8 = 1;
const U32: u8 = 3;
const U64: u8 = 4;
const I8: u8 = 5;
const I32: u8 = 7;
const F32: u8 = 9;

/// One index entry: frame, rows N, location, columns M, name id, type.
struct Entry {
    frame: u64,
    rows: u64,
    location: u64,
    cols: u32,
    id: u16,
    ty: u8,
}

/// Writes HOOMD-blue GSD files.
pub struct GsdWriter<W> {
    pub(crate) out: W,
    /// Where the next chunk goes (the header takes the first 256 bytes).
    at: u64,
    names: Vec<&'static str>,
    entries: Vec<Entry>,
    frames: u64,
    /// Frame 0's bytes of the chunks stored once (types, diameters, bonds, ...), by name.
    first: HashMap<&'static str, Vec<u8>>,
    buf: Vec<u8>,
    /// Frame 0 was planar: the file is 2-D.
    two_d: bool,
}

/// Names of a frame's particle types, and each atom's type id.
fn particle_types(frame: &Frame) -> (Vec<String>, Vec<u32>) {
    let n = frame.n_atoms();
    let label = |i: usize| -> String {
        let pick = |l: &[Label]| {
            l.get(i)
                .filter(|l| !l.is_empty())
                .map(|l| l.as_str().to_string())
        };
        pick(&frame.types)
            .or_else(|| {
                frame
                    .elements
                    .get(i)
                    .filter(|e| !e.is_unknown())
                    .map(|e| e.symbol().to_string())
            })
            .or_else(|| pick(&frame.names))
            .unwrap_or_else(|| "A".to_string())
    };
    let mut names: Vec<String> = Vec::new();
    let mut ids: HashMap<String, u32> = HashMap::new();
    let typeid = (0..n)
        .map(|i| {
            let l = label(i);
            *ids.entry(l.clone()).or_insert_with(|| {
                names.push(l);
                names.len() as u32 - 1
            })
        })
        .collect();
    (names, typeid)
}

/// Type names as the schema stores them: N × M chars, each name NUL-padded to M (the longest
/// name plus its NUL).
fn char_table(names: &[String]) -> (Vec<u8>, u64, u32) {
    let m = names.iter().map(|s| s.len()).max().unwrap_or(0) + 1;
    let mut b = Vec::with_capacity(names.len() * m);
    for s in names {
        b.extend_from_slice(s.as_bytes());
        b.resize(b.len() + m - s.len(), 0);
    }
    (b, names.len() as u64, m as u32)
}

/// HOOMD's box `Lx Ly Lz xy xz yz`, the map of a position into it (rotation, then the shift to
/// the centred box), and the box matrix (rows a1, a2, a3).
struct HoomdBox {
    params: [f32; 6],
    data_box: DataBox,
    centre: [f64; 3],
    m: [[f64; 3]; 3],
}

fn hoomd_box(frame: &Frame) -> HoomdBox {
    let data_box = match &frame.cell {
        Some(c) => data_box(c),
        None => bounding_box(&frame.positions),
    };
    let l: [f64; 3] = std::array::from_fn(|k| data_box.hi[k] - data_box.lo[k]);
    let [txy, txz, tyz] = data_box.tilt;
    let m = [[l[0], 0.0, 0.0], [txy, l[1], 0.0], [txz, tyz, l[2]]];
    let centre = std::array::from_fn(|k| data_box.lo[k] + 0.5 * (m[0][k] + m[1][k] + m[2][k]));
    let params = [l[0], l[1], l[2], txy / l[1], txz / l[2], tyz / l[2]].map(|v| v as f32);
    HoomdBox {
        params,
        data_box,
        centre,
        m,
    }
}

/// Whether `frame` is planar (a 2-D file): a cell open along its third edge, that edge
/// perpendicular to the other two (no xz, yz tilt) and every atom in the box's mid-plane.
fn planar(frame: &Frame, hb: &HoomdBox) -> bool {
    let open_c = frame.cell.is_some_and(|c| !c.periodic()[2]);
    let upright = hb.data_box.tilt[1] == 0.0 && hb.data_box.tilt[2] == 0.0;
    open_c
        && upright
        && frame.positions.iter().all(|p| {
            let p = hb.data_box.rotate.as_ref().map_or(*p, |r| r.apply(*p));
            (p[2] as f64 - hb.centre[2]) as f32 == 0.0
        })
}

impl<W: Write + Seek> GsdWriter<W> {
    /// A GSD writer on `out` (positioned at its start).
    pub fn new(out: W) -> Self {
        GsdWriter {
            out,
            at: 256,
            names: Vec::new(),
            entries: Vec::new(),
            frames: 0,
            first: HashMap::new(),
            buf: Vec::new(),
            two_d: false,
        }
    }

    /// Whether the schema can hold `frame` (`Err`: what it cannot).
    pub fn check(&self, frame: &Frame) -> Result<(), String> {
        let n = frame.n_atoms();
        if n > u32::MAX as usize || frame.bonds.len() > u32::MAX as usize {
            return Err(format!(
                "{n} atoms and {} bonds: GSD's hoomd schema counts them in 32 bits",
                frame.bonds.len()
            ));
        }
        if let Some(step) = frame.step
            && step < 0
        {
            return Err(format!("step {step}: GSD's steps are unsigned"));
        }
        let (names, _) = particle_types(frame);
        if let Some(bad) = names.iter().find(|s| s.contains('\0')) {
            return Err(format!(
                "type {bad:?} holds a NUL byte, which ends a name in GSD's type list"
            ));
        }
        Ok(())
    }

    /// Appends one chunk of `rows` × `cols` values of type `ty` (`bytes`, little-endian).
    fn chunk(
        &mut self,
        name: &'static str,
        ty: u8,
        rows: u64,
        cols: u32,
        bytes: &[u8],
    ) -> io::Result<()> {
        let id = match self.names.iter().position(|n| *n == name) {
            Some(i) => i,
            None => {
                self.names.push(name);
                self.names.len() - 1
            }
        };
        if self.at == 256 && self.entries.is_empty() {
            // Room for the header, written by `finish`.
            self.out.write_all(&[0u8; 256])?;
        }
        self.out.write_all(bytes)?;
        self.entries.push(Entry {
            frame: self.frames,
            rows,
            location: self.at,
            cols,
            id: id as u16,
            ty,
        });
        self.at += bytes.len() as u64;
        Ok(())
    }

    /// A chunk stored once: written in frame 0, and in a later frame only when its bytes (or
    /// shape) differ from frame 0's.
    fn once(
        &mut self,
        name: &'static str,
        ty: u8,
        rows: u64,
        cols: u32,
        bytes: Vec<u8>,
    ) -> io::Result<()> {
        let mut key = bytes;
        key.extend_from_slice(&rows.to_le_bytes());
        key.extend_from_slice(&cols.to_le_bytes());
        let len = key.len() - 12;
        match self.first.get(name) {
            Some(f) if *f == key => Ok(()),
            _ => {
                self.chunk(name, ty, rows, cols, &key[..len])?;
                if self.frames == 0 {
                    self.first.insert(name, key);
                }
                Ok(())
            }
        }
    }

    /// Appends a [`Frame`] (the `Writer` contract, which has called [`GsdWriter::check`]).
    pub fn write_frame(&mut self, frame: &Frame) -> io::Result<()> {
        let n = frame.n_atoms();
        let step = frame.step.unwrap_or(self.frames as i64) as u64;
        self.chunk("configuration/step", U64, 1, 1, &step.to_le_bytes())?;
        let mut hb = hoomd_box(frame);
        if self.frames == 0 {
            self.two_d = planar(frame, &hb);
            let dims = if self.two_d { 2 } else { 3 };
            self.chunk("configuration/dimensions", U8, 1, 1, &[dims])?;
        }
        if self.two_d {
            // HOOMD's 2-D box: Lz, xz, yz are 0.
            for k in [2, 4, 5] {
                hb.params[k] = 0.0;
            }
        }
        let mut b = std::mem::take(&mut self.buf);
        b.clear();
        for v in hb.params {
            b.extend_from_slice(&v.to_le_bytes());
        }
        self.chunk("configuration/box", F32, 6, 1, &b)?;
        self.chunk("particles/N", U32, 1, 1, &(n as u32).to_le_bytes())?;

        // Positions in the centred box, wrapped, and the images they moved by.
        let flags = ["ix", "iy", "iz"].map(|k| frame.property(k));
        let mut pos = Vec::with_capacity(12 * n);
        let mut img = Vec::with_capacity(12 * n);
        for (i, p) in frame.positions.iter().enumerate() {
            let p = hb.data_box.rotate.as_ref().map_or(*p, |r| r.apply(*p));
            // Fractions of the box measured from its corner (lo).
            let d: [f64; 3] = std::array::from_fn(|k| p[k] as f64 - hb.data_box.lo[k]);
            let f = crate::pbc::to_frac(&hb.m, d);
            let mut shift = f.map(|x| if x.is_finite() { x.floor() } else { 0.0 });
            if self.two_d {
                shift[2] = 0.0;
            }
            for k in 0..3 {
                let q = p[k] as f64
                    - hb.centre[k]
                    - (shift[0] * hb.m[0][k] + shift[1] * hb.m[1][k] + shift[2] * hb.m[2][k]);
                pos.extend_from_slice(&(q as f32).to_le_bytes());
                let given = flags[k].map_or(0, |v| v[i] as i32);
                img.extend_from_slice(&(given.wrapping_add(shift[k] as i32)).to_le_bytes());
            }
        }
        self.chunk("particles/position", F32, n as u64, 3, &pos)?;
        self.chunk("particles/image", I32, n as u64, 3, &img)?;
        if !frame.velocities.is_empty() {
            b.clear();
            for &v in &frame.velocities {
                // Turned with the box, as the positions are.
                let v = hb
                    .data_box
                    .rotate
                    .as_ref()
                    .map_or(v, |r| r.apply_vector(v.map(f64::from)).map(|x| x as f32));
                for c in v {
                    b.extend_from_slice(&c.to_le_bytes());
                }
            }
            self.chunk("particles/velocity", F32, n as u64, 3, &b)?;
        }
        if let [Some(w), Some(x), Some(y), Some(z)] =
            ["quatw", "quati", "quatj", "quatk"].map(|k| frame.property(k))
        {
            b.clear();
            for i in 0..n {
                for q in [w[i], x[i], y[i], z[i]] {
                    b.extend_from_slice(&q.to_le_bytes());
                }
            }
            self.chunk("particles/orientation", F32, n as u64, 4, &b)?;
        }
        self.buf = b;

        // What is stored once.
        let (types, typeid) = particle_types(frame);
        let (table, rows, cols) = char_table(&types);
        self.once("particles/types", I8, rows, cols, table)?;
        let le = |v: &[u32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
        self.once("particles/typeid", U32, n as u64, 1, le(&typeid))?;
        if !frame.radii.is_empty() {
            let d = frame
                .radii
                .iter()
                .flat_map(|r| (2.0 * r).to_le_bytes())
                .collect();
            self.once("particles/diameter", F32, n as u64, 1, d)?;
        }
        for (prop, name) in [("mass", "particles/mass"), ("charge", "particles/charge")] {
            if let Some(v) = frame.property(prop) {
                let bytes = v.iter().flat_map(|x| x.to_le_bytes()).collect();
                self.once(name, F32, n as u64, 1, bytes)?;
            }
        }
        if let Some(v) = frame.property("body") {
            let bytes = v.iter().flat_map(|x| (*x as i32).to_le_bytes()).collect();
            self.once("particles/body", I32, n as u64, 1, bytes)?;
        }
        if !frame.bonds.is_empty() || self.first.contains_key("bonds/N") {
            let nb = frame.bonds.len();
            self.once("bonds/N", U32, 1, 1, (nb as u32).to_le_bytes().to_vec())?;
        }
        if !frame.bonds.is_empty() {
            let nb = frame.bonds.len();
            let mut pair_names: Vec<String> = Vec::new();
            let mut pair_ids: HashMap<(u32, u32), u32> = HashMap::new();
            let mut ids = Vec::with_capacity(nb);
            for &[a, c] in &frame.bonds {
                let (ta, tc) = (typeid[a as usize], typeid[c as usize]);
                let key = (ta.min(tc), ta.max(tc));
                let id = *pair_ids.entry(key).or_insert_with(|| {
                    pair_names.push(format!(
                        "{}-{}",
                        types[key.0 as usize], types[key.1 as usize]
                    ));
                    pair_names.len() as u32 - 1
                });
                ids.push(id);
            }
            let (table, rows, cols) = char_table(&pair_names);
            self.once("bonds/types", I8, rows, cols, table)?;
            self.once("bonds/typeid", U32, nb as u64, 1, le(&ids))?;
            self.once(
                "bonds/group",
                U32,
                nb as u64,
                2,
                le(frame.bonds.as_flattened()),
            )?;
        }
        self.frames += 1;
        Ok(())
    }

    /// Writes the namelist, the index and the header (the `Writer` contract).
    pub fn finish(&mut self) -> io::Result<()> {
        if self.entries.is_empty() {
            self.out.write_all(&[0u8; 256])?;
        }
        // The namelist: NUL-terminated names in id order, padded to 64-byte segments with at
        // least one NUL after the last name (an empty name ends the list).
        let mut names = Vec::new();
        for n in &self.names {
            names.extend_from_slice(n.as_bytes());
            names.push(0);
        }
        names.push(0);
        names.resize(names.len().div_ceil(64) * 64, 0);
        let names_at = self.at;
        self.out.write_all(&names)?;
        // The index, sorted by frame then name id (chunks were appended frame by frame).
        self.entries.sort_by_key(|e| (e.frame, e.id));
        let index_at = names_at + names.len() as u64;
        let slots = self.entries.len().max(1);
        let mut index = Vec::with_capacity(32 * slots);
        for e in &self.entries {
            index.extend_from_slice(&e.frame.to_le_bytes());
            index.extend_from_slice(&e.rows.to_le_bytes());
            index.extend_from_slice(&e.location.to_le_bytes());
            index.extend_from_slice(&e.cols.to_le_bytes());
            index.extend_from_slice(&e.id.to_le_bytes());
            index.extend_from_slice(&[e.ty, 0]);
        }
        index.resize(32 * slots, 0);
        self.out.write_all(&index)?;
        // The header.
        let mut h = [0u8; 256];
        h[0..8].copy_from_slice(&MAGIC.to_le_bytes());
        h[8..16].copy_from_slice(&index_at.to_le_bytes());
        h[16..24].copy_from_slice(&(slots as u64).to_le_bytes());
        h[24..32].copy_from_slice(&names_at.to_le_bytes());
        h[32..40].copy_from_slice(&(names.len() as u64 / 64).to_le_bytes());
        h[40..44].copy_from_slice(&((1u32 << 16) | 4).to_le_bytes());
        h[44..48].copy_from_slice(&(2u32 << 16).to_le_bytes());
        let app = format!("texmap {}", env!("CARGO_PKG_VERSION"));
        h[48..48 + app.len()].copy_from_slice(app.as_bytes());
        h[112..117].copy_from_slice(b"hoomd");
        self.out.seek(SeekFrom::Start(0))?;
        self.out.write_all(&h)?;
        self.out.seek(SeekFrom::End(0))?;
        Ok(())
    }
}

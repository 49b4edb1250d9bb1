//! ASE trajectories (`.traj`: ASE's ULM binary format, what `ase.io.Trajectory`, ASE's MD
//! drivers and optimisers, GPAW and the machine-learned potentials run through ASE write).
//!
//! # The file
//! `- of Ulm` (8 bytes), a 16-byte tag (`ASE-Trajectory`), then three little-endian int64s:
//! the format version, the number of items N and the position of the offsets table, which holds
//! N int64 positions, one per item. An item is an int64 length and that many bytes of JSON: a
//! dictionary whose keys ending in `.` refer to arrays stored raw elsewhere in the file
//! (`{"ndarray": [shape, dtype, offset]}`, in the byte order the item's `_little_endian` says,
//! little by default) or to a child dictionary (`calculator.`). Each item is one frame.
//!
//! # What becomes of it
//! - `numbers` (atomic numbers) give [`Frame::elements`] and [`Frame::names`] (the symbols);
//!   `positions` (Å) the positions; `cell` (three edge vectors, Å; all zero: none) and `pbc`
//!   the [`crate::UnitCell`] and its periodic edges. An item without `numbers` uses the first
//!   item's numbers, `pbc` and `masses`, as ASE's reader does (ASE writes them only when they
//!   change).
//! - `momenta` become [`Frame::velocities`] in Å/ps: divided by the masses (`masses`, else each
//!   element's standard weight) and converted from ASE's time unit (1 fs = 0.09822694788464063
//!   of it, ASE's CODATA 2014 constants), as `get_velocities() * 1000 * units.fs`.
//! - Per-atom properties: `masses` → `mass`, `tags` → `tag`, `charges` (initial charges) →
//!   `charge`, `magmoms` → `magmom`; the calculator's `forces` → `fx fy fz` (eV/Å, the names a
//!   LAMMPS dump's force columns have: `--arrows f` draws them), `energies` → `energies` (eV),
//!   its `charges` and `magmoms` where the atoms have none.
//! - The calculator's `energy`, `free_energy` and `stress` go into the frame's comment as
//!   extended XYZ writes them (`energy=-0.214 free_energy=-0.214 stress="…"`), so `--label
//!   '{title}'` shows them.
//! - Not kept: constraints, `info`, the calculator's name and parameters.
//!
//! # Damage
//! Nothing is sized from the file before it is checked against the file's length: the item
//! count against the offsets table, each item's length and each array's extent (its shape's
//! product times its element size) against the bytes after it. Errors name the file, the
//! frame (item) and the byte: a wrong magic or tag, an offset or array past the end, JSON that
//! does not parse, an array of another shape than the atoms need, a dtype we cannot read,
//! non-finite positions. ASE's pre-2016 formats (`AFFormat` files, pickle trajectories) are
//! refused by name.
//!
//! # References
//! - ASE `ase/io/ulm.py` (the file layout) and `ase/io/trajectory.py` (the keys), read for the
//!   layout only; the tests compare with ASE 3.29's own reading.

use std::io::{Read, Seek, SeekFrom};
use std::sync::Arc;

use serde_json::Value;

use crate::cursor::{IN_BOUNDS, all_in_bounds, first_out_of_bounds};
use crate::elements::Element;
use crate::error::{Error, Location};
use crate::frame::{Frame, Label, Property, UnitCell};

/// An array's shape and its values, flattened.
type Shaped = (Vec<usize>, Vec<f64>);

/// ASE's femtosecond in its own time unit (Å·sqrt(amu/eV)), CODATA 2014 as ASE's defaults.
const ASE_FS: f64 = 0.098_226_947_884_640_63;

/// Longest JSON item read (bytes): an item describes one frame; its arrays are stored apart.
const MAX_ITEM: u64 = 1 << 28;

/// The atoms an item without `numbers` borrows from the first item.
#[derive(Clone, Default)]
struct Header {
    numbers: Vec<i64>,
    pbc: [bool; 3],
    masses: Option<Vec<f64>>,
}

/// Streaming reader of an ASE trajectory (one frame per item).
pub(crate) struct AseTrajReader<R> {
    src: R,
    file: Arc<str>,
    len: u64,
    offsets: Vec<u64>,
    header: Option<Header>,
    next: usize,
}

impl<R: Read + Seek> AseTrajReader<R> {
    /// Reads the header and the offsets table.
    pub fn new(mut src: R, file: Arc<str>) -> Result<Self, Error> {
        let len = src.seek(SeekFrom::End(0)).map_err(|source| Error::Io {
            at: Location::file(&file),
            source,
        })?;
        let mut r = AseTrajReader {
            src,
            file,
            len,
            offsets: Vec::new(),
            header: None,
            next: 0,
        };
        let head = r.bytes(0, 48, 0, "the 48-byte ULM header")?;
        if &head[..8] != b"- of Ulm" {
            let found = if head.starts_with(b"AFFormat") || head.starts_with(b"PickleTrajectory") {
                "an ASE trajectory from before ASE 3.12 (convert it with `ase convert`)".to_string()
            } else {
                Error::found(&head[..8])
            };
            return Err(Error::Parse {
                at: Location::binary(&r.file, 0, 0),
                expected: "the ULM magic '- of Ulm' of an ASE trajectory",
                found,
            });
        }
        let tag = String::from_utf8_lossy(&head[8..24]).trim_end().to_string();
        if tag != "ASE-Trajectory" {
            return Err(Error::Parse {
                at: Location::binary(&r.file, 0, 8),
                expected: "the tag 'ASE-Trajectory' (another program's ULM file?)",
                found: tag,
            });
        }
        let int = |k: usize| i64::from_le_bytes(head[24 + 8 * k..32 + 8 * k].try_into().unwrap());
        let (n, pos0) = (int(1), int(2));
        let table_fits = n >= 0
            && pos0 >= 48
            && (n as u64)
                .checked_mul(8)
                .and_then(|b| b.checked_add(pos0 as u64))
                .is_some_and(|end| end <= len);
        if !table_fits {
            return Err(Error::Parse {
                at: Location::binary(&r.file, 0, 32),
                expected: "an item count whose offsets table lies inside the file",
                found: format!("{n} items, table at byte {pos0}, a file of {len} bytes"),
            });
        }
        let table = r.bytes(pos0 as u64, 8 * n as u64, 0, "the offsets table")?;
        r.offsets = table
            .chunks_exact(8)
            .map(|c| i64::from_le_bytes(c.try_into().unwrap()).max(-1) as u64)
            .collect();
        Ok(r)
    }

    /// `n` bytes at `at`, or an error naming frame `frame` and what was wanted.
    fn bytes(&mut self, at: u64, n: u64, frame: usize, what: &str) -> Result<Vec<u8>, Error> {
        if at.checked_add(n).is_none_or(|end| end > self.len) {
            return Err(Error::Truncated {
                at: Location::binary(&self.file, frame, at),
                expected: format!(
                    "{what}: {n} bytes at byte {at}, past the file's {} bytes",
                    self.len
                ),
            });
        }
        let mut buf = vec![0u8; n as usize];
        self.src
            .seek(SeekFrom::Start(at))
            .and_then(|_| self.src.read_exact(&mut buf))
            .map_err(|source| Error::Io {
                at: Location::binary(&self.file, frame, at),
                source,
            })?;
        Ok(buf)
    }

    /// Item `i`'s JSON dictionary.
    fn item(&mut self, i: usize) -> Result<serde_json::Map<String, Value>, Error> {
        let at = self.offsets[i];
        let size = self.bytes(at, 8, i, "an item's length")?;
        let size = i64::from_le_bytes(size.try_into().unwrap());
        if size < 0 || size as u64 > MAX_ITEM {
            return Err(Error::Parse {
                at: Location::binary(&self.file, i, at),
                expected: "an item length of 0 to 256 MiB",
                found: size.to_string(),
            });
        }
        let text = self.bytes(at + 8, size as u64, i, "an item's JSON")?;
        match serde_json::from_slice::<Value>(&text) {
            Ok(Value::Object(map)) => Ok(map),
            Ok(_) => Err(Error::Parse {
                at: Location::binary(&self.file, i, at + 8),
                expected: "a JSON object (an item of an ASE trajectory)",
                found: Error::found(&text),
            }),
            Err(e) => Err(Error::Parse {
                at: Location::binary(&self.file, i, at + 8 + e.column() as u64),
                expected: "an item's JSON (an ASE trajectory)",
                found: e.to_string(),
            }),
        }
    }

    /// The values of array `key` of `map` (an `ndarray` reference, a `__ndarray__` literal or
    /// a nested list), flattened, with its shape; `None` when absent.
    fn array(
        &mut self,
        map: &serde_json::Map<String, Value>,
        key: &str,
        little: bool,
        frame: usize,
    ) -> Result<Option<Shaped>, Error> {
        let bad = |what: String| Error::Parse {
            at: Location::binary(&self.file, frame, self.offsets[frame]),
            expected: "an array reference {\"ndarray\": [shape, dtype, offset]} or a list",
            found: what,
        };
        let value = match (map.get(&format!("{key}.")), map.get(key)) {
            (Some(v), _) => v,
            (None, Some(v)) => {
                return literal(v)
                    .map(Some)
                    .ok_or_else(|| bad(format!("{key}: {v}")));
            }
            (None, None) => return Ok(None),
        };
        let Some([shape, dtype, offset]) = value
            .get("ndarray")
            .and_then(Value::as_array)
            .and_then(|a| <&[Value; 3]>::try_from(a.as_slice()).ok())
        else {
            return Err(bad(format!("{key}.: {value}")));
        };
        let shape: Option<Vec<usize>> = shape
            .as_array()
            .and_then(|s| s.iter().map(|d| d.as_u64().map(|d| d as usize)).collect());
        let (Some(shape), Some(dtype), Some(offset)) = (shape, dtype.as_str(), offset.as_u64())
        else {
            return Err(bad(format!("{key}.: {value}")));
        };
        let size = match dtype {
            "float64" | "int64" | "uint64" => 8,
            "float32" | "int32" | "uint32" => 4,
            "int16" | "uint16" => 2,
            "int8" | "uint8" | "bool" => 1,
            _ => return Err(bad(format!("{key}.: dtype {dtype}"))),
        };
        let count = shape
            .iter()
            .try_fold(1u64, |a, &d| a.checked_mul(d as u64))
            .ok_or_else(|| bad(format!("{key}.: shape {shape:?}")))?;
        // The arrays of an item precede its JSON, which ends inside the file: an array past
        // the end is damage, not a cut.
        let bytes = count.saturating_mul(size);
        if offset.checked_add(bytes).is_none_or(|end| end > self.len) {
            return Err(Error::Parse {
                at: Location::binary(&self.file, frame, self.offsets[frame]),
                expected: "arrays inside the file",
                found: format!(
                    "'{key}' of shape {shape:?} ({bytes} bytes) at byte {offset}, a file of {} bytes",
                    self.len
                ),
            });
        }
        let raw = self.bytes(offset, bytes, frame, &format!("the array '{key}'"))?;
        let values = raw
            .chunks_exact(size as usize)
            .map(|c| number(c, dtype, little))
            .collect();
        Ok(Some((shape, values)))
    }

    /// Reads the next frame (the `Trajectory` contract).
    pub fn read_next(&mut self, frame: &mut Frame) -> Result<bool, Error> {
        frame.clear();
        if self.next >= self.offsets.len() {
            return Ok(false);
        }
        let i = self.next;
        if self.header.is_none() {
            let first = self.item(0)?;
            let little = first
                .get("_little_endian")
                .and_then(Value::as_bool)
                .unwrap_or(true);
            self.header = Some(self.header_of(&first, little, 0)?.unwrap_or_default());
        }
        let map = self.item(i)?;
        let little = map
            .get("_little_endian")
            .and_then(Value::as_bool)
            .unwrap_or(true);
        let header = match self.header_of(&map, little, i)? {
            Some(h) => h,
            None => self.header.clone().unwrap_or_default(),
        };
        if let Err(e) = self.fill(frame, &map, &header, little, i) {
            frame.clear();
            return Err(e);
        }
        self.next += 1;
        Ok(true)
    }

    /// The numbers, pbc and masses an item states, if it states numbers.
    fn header_of(
        &mut self,
        map: &serde_json::Map<String, Value>,
        little: bool,
        i: usize,
    ) -> Result<Option<Header>, Error> {
        let Some((_, numbers)) = self.array(map, "numbers", little, i)? else {
            return Ok(None);
        };
        let pbc = match map.get("pbc").and_then(literal) {
            Some((_, p)) if p.len() == 3 => [p[0] != 0.0, p[1] != 0.0, p[2] != 0.0],
            _ => [false; 3],
        };
        let masses = self.array(map, "masses", little, i)?.map(|(_, m)| m);
        Ok(Some(Header {
            numbers: numbers.iter().map(|&z| z as i64).collect(),
            pbc,
            masses,
        }))
    }

    fn fill(
        &mut self,
        frame: &mut Frame,
        map: &serde_json::Map<String, Value>,
        header: &Header,
        little: bool,
        i: usize,
    ) -> Result<(), Error> {
        let n = header.numbers.len();
        let at = Location::binary(&self.file, i, self.offsets[i]);
        let shaped = |what: &str, shape: &[usize], want: &[usize]| -> Result<(), Error> {
            if shape == want {
                Ok(())
            } else {
                Err(Error::Parse {
                    at: at.clone(),
                    expected: "arrays of one row per atom (as many as 'numbers')",
                    found: format!("'{what}' of shape {shape:?} for {n} atoms"),
                })
            }
        };
        let Some((shape, pos)) = self.array(map, "positions", little, i)? else {
            return Err(Error::Parse {
                at,
                expected: "'positions' in every item",
                found: "none".into(),
            });
        };
        shaped("positions", &shape, &[n, 3])?;
        frame.positions = pos
            .chunks_exact(3)
            .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32])
            .collect();
        if !all_in_bounds(&frame.positions) {
            let bad = first_out_of_bounds(&frame.positions).unwrap_or(0);
            return Err(Error::Parse {
                at,
                expected: IN_BOUNDS,
                found: format!("atom {bad}: {:?}", frame.positions[bad]),
            });
        }
        for &z in &header.numbers {
            let e = u8::try_from(z)
                .ok()
                .and_then(Element::from_z)
                .unwrap_or(Element::UNKNOWN);
            frame.elements.push(e);
            frame.names.push(
                Label::new(if e.is_unknown() { "X" } else { e.symbol() }).unwrap_or_default(),
            );
        }
        if let Some((shape, c)) = self.array(map, "cell", little, i)? {
            shaped("cell", &shape, &[3, 3])?;
            if c.iter().any(|&v| v != 0.0) {
                let m = [[c[0], c[1], c[2]], [c[3], c[4], c[5]], [c[6], c[7], c[8]]];
                let cell = UnitCell::from_matrix(m).map_err(|e| Error::Parse {
                    at: at.clone(),
                    expected: "a cell of three right-handed edges with volume",
                    found: e.to_string(),
                })?;
                frame.cell = Some(cell.with_periodic(header.pbc));
            }
        }
        let masses = match &header.masses {
            Some(m) => {
                shaped("masses", &[m.len()], &[n])?;
                frame.properties.push(Property {
                    name: "mass".into(),
                    values: m.iter().map(|&v| v as f32).collect(),
                });
                m.clone()
            }
            None => frame.elements.iter().map(|e| e.mass()).collect(),
        };
        if let Some((shape, p)) = self.array(map, "momenta", little, i)? {
            shaped("momenta", &shape, &[n, 3])?;
            frame.velocities = p
                .chunks_exact(3)
                .zip(&masses)
                .map(|(p, &m)| {
                    let k = if m > 0.0 { 1000.0 * ASE_FS / m } else { 0.0 };
                    [(p[0] * k) as f32, (p[1] * k) as f32, (p[2] * k) as f32]
                })
                .collect();
            if let Some(bad) = frame
                .velocities
                .iter()
                .position(|v| v.iter().any(|x| !x.is_finite()))
            {
                return Err(Error::Parse {
                    at,
                    expected: "finite momenta",
                    found: format!("atom {bad}: velocity {:?} Å/ps", frame.velocities[bad]),
                });
            }
        }
        let mut per_atom = |name: &str, values: Vec<f64>| {
            if !frame.properties.iter().any(|p| p.name == name) {
                frame.properties.push(Property {
                    name: name.into(),
                    values: values.iter().map(|&v| v as f32).collect(),
                });
            }
        };
        for (key, name) in [
            ("tags", "tag"),
            ("charges", "charge"),
            ("magmoms", "magmom"),
        ] {
            if let Some((shape, v)) = self.array(map, key, little, i)? {
                shaped(key, &shape, &[n])?;
                per_atom(name, v);
            }
        }
        if let Some(Value::Object(calc)) = map.get("calculator.") {
            let mut comment = Vec::new();
            for key in ["energy", "free_energy"] {
                if let Some(e) = calc.get(key).and_then(Value::as_f64) {
                    comment.push(format!("{key}={e}"));
                }
            }
            if let Some((_, s)) = calc.get("stress").and_then(literal) {
                let s: Vec<String> = s.iter().map(f64::to_string).collect();
                comment.push(format!("stress=\"{}\"", s.join(" ")));
            }
            frame.comment = comment.join(" ");
            if let Some((shape, f)) = self.array(calc, "forces", little, i)? {
                shaped("forces", &shape, &[n, 3])?;
                for (k, name) in ["fx", "fy", "fz"].into_iter().enumerate() {
                    per_atom(name, f.iter().skip(k).step_by(3).copied().collect());
                }
            }
            for (key, name) in [
                ("energies", "energies"),
                ("charges", "charge"),
                ("magmoms", "magmom"),
            ] {
                if let Some((shape, v)) = self.array(calc, key, little, i)? {
                    shaped(key, &shape, &[n])?;
                    per_atom(name, v);
                }
            }
        }
        Ok(())
    }

    /// Makes `read_next` read frame `n`; false past the last.
    pub fn seek_frame(&mut self, n: usize) -> Result<bool, Error> {
        if n < self.offsets.len() {
            self.next = n;
            Ok(true)
        } else {
            Ok(false)
        }
    }

    /// The number of items, each checked to end inside the file (an item's arrays come before
    /// its JSON, so a whole JSON means a whole item): a cut file is [`Error::Truncated`] at the
    /// first item it cuts.
    pub fn n_frames(&mut self) -> Result<usize, Error> {
        for i in 0..self.offsets.len() {
            let at = self.offsets[i];
            let size = self.bytes(at, 8, i, "an item's length")?;
            let size = i64::from_le_bytes(size.try_into().unwrap_or_default()).max(0) as u64;
            if (at + 8).checked_add(size).is_none_or(|end| end > self.len) {
                return Err(Error::Truncated {
                    at: Location::binary(&self.file, i, at + 8),
                    expected: format!("item {i}'s {size} bytes of JSON"),
                });
            }
        }
        Ok(self.offsets.len())
    }
}

/// One element of a raw array as f64.
fn number(c: &[u8], dtype: &str, little: bool) -> f64 {
    macro_rules! read {
        ($t:ty) => {{
            let b = c.try_into().unwrap_or_default();
            if little {
                <$t>::from_le_bytes(b) as f64
            } else {
                <$t>::from_be_bytes(b) as f64
            }
        }};
    }
    match dtype {
        "float64" => read!(f64),
        "float32" => read!(f32),
        "int64" => read!(i64),
        "uint64" => read!(u64),
        "int32" => read!(i32),
        "uint32" => read!(u32),
        "int16" => read!(i16),
        "uint16" => read!(u16),
        "int8" => c[0] as i8 as f64,
        _ => c[0] as f64,
    }
}

/// A JSON array (nested lists of numbers or booleans), or ASE's `{"__ndarray__": [shape,
/// dtype, values]}`, flattened, with its shape.
fn literal(v: &Value) -> Option<Shaped> {
    if let Some(Value::Array(a)) = v.get("__ndarray__") {
        let [shape, _, values] = <&[Value; 3]>::try_from(a.as_slice()).ok()?;
        let shape: Vec<usize> = shape
            .as_array()?
            .iter()
            .map(|d| d.as_u64().map(|d| d as usize))
            .collect::<Option<_>>()?;
        let (_, flat) = literal(values)?;
        return (shape.iter().product::<usize>() == flat.len()).then_some((shape, flat));
    }
    match v {
        Value::Number(x) => Some((Vec::new(), vec![x.as_f64()?])),
        Value::Bool(b) => Some((Vec::new(), vec![f64::from(u8::from(*b))])),
        Value::Array(items) => {
            let mut flat = Vec::new();
            let mut inner: Option<Vec<usize>> = None;
            for item in items {
                let (s, f) = literal(item)?;
                if inner.as_ref().is_some_and(|i| *i != s) {
                    return None;
                }
                inner = Some(s);
                flat.extend(f);
            }
            let mut shape = vec![items.len()];
            shape.extend(inner.unwrap_or_default());
            Some((shape, flat))
        }
        _ => None,
    }
}

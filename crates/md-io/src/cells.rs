//! Cells given from outside a trajectory file ([`CellOverride`]), for the files that hold
//! positions only: a fixed box for every frame (VMD's `pbc set {a b c}`), or the per-step cells
//! of a CP2K `.cell` file ([`CellTable`]), matched to the frames by their step numbers.
//!
//! CP2K writes an MD run's positions to `PROJECT-pos-1.xyz` (no cell: the comment line is
//! `i = STEP, time = FS, E = HARTREE`, which the XYZ reader reads as the frame's step and time)
//! and, in a variable-cell run (NPT, cell optimisation) or whenever `&MOTION/&PRINT/&CELL` asks,
//! the cell of every printed step to `PROJECT-1.cell`:
//!
//! ```text
//! #   Step   Time [fs]       Ax [Angstrom]  ...  Cz [Angstrom]      Volume [Angstrom^3]
//!        0       0.000       15.7800000000  ...  15.7800000000          3929.3525520000
//! ```
//!
//! Each data line is the step, the time (fs), the edge vectors A, B, C as rows (Å) and the
//! volume (Å³). The volume is checked against the vectors' determinant (a relative 1e-6, well
//! above CP2K's printed digits), which catches a file of other columns. A step printed twice
//! (a restarted run appends from its restart point) takes the later line's cell.
//!
//! Applied to a frame ([`CellOverride::apply`]), a table looks the frame's step up; a frame
//! without a step number, or with a step the file does not hold, is an error naming the frame,
//! and a frame whose time differs from the table's time at that step by more than CP2K's
//! printed precision (0.001 fs) is an error too: the cell file belongs to another run.
//!
//! ```
//! use texmap_md_io::cells::{CellOverride, CellTable};
//! use texmap_md_io::Frame;
//! let text = "#   Step   Time [fs]  Ax Ay Az Bx By Bz Cx Cy Cz  Volume\n\
//!             0  0.000  10 0 0  0 11 0  0 0 12  1320\n\
//!             5  2.500  10 0 0  0 11 0  1 0 12  1320\n";
//! let table = CellTable::parse(text.as_bytes(), "run-1.cell")?;
//! let mut frame = Frame::new();
//! frame.step = Some(5);
//! CellOverride::Steps(table.into()).apply(&mut frame, 0, "run-pos-1.xyz")?;
//! assert_eq!(frame.cell.unwrap().matrix()[2], [1.0, 0.0, 12.0]);
//! # Ok::<(), texmap_md_io::Error>(())
//! ```

use std::collections::BTreeMap;
use std::io::BufRead;
use std::path::Path;
use std::sync::Arc;

use crate::error::{Error, Location};
use crate::frame::{Frame, UnitCell};

/// The cells of a CP2K `.cell` file by step number; see the module docs.
#[derive(Clone, Debug)]
pub struct CellTable {
    name: Arc<str>,
    /// Step → (time in fs, cell).
    rows: BTreeMap<i64, (f64, UnitCell)>,
}

/// CP2K prints times with 3 decimals of a femtosecond.
const TIME_TOLERANCE_FS: f64 = 0.0011;

impl CellTable {
    /// Reads a CP2K `.cell` file. Errors name the file and the line.
    pub fn read(path: impl AsRef<Path>) -> Result<CellTable, Error> {
        let path = path.as_ref();
        let name = path.display().to_string();
        let file = std::fs::File::open(path).map_err(|source| Error::Io {
            at: Location::file(&name.as_str().into()),
            source,
        })?;
        CellTable::parse(std::io::BufReader::new(file), &name)
    }

    /// Parses a `.cell` file's text from `src`; `name` names it in errors.
    pub fn parse(mut src: impl BufRead, name: &str) -> Result<CellTable, Error> {
        let name: Arc<str> = name.into();
        let mut rows = BTreeMap::new();
        let mut line = Vec::new();
        let (mut number, mut byte) = (0u64, 0u64);
        loop {
            line.clear();
            let n = src
                .read_until(b'\n', &mut line)
                .map_err(|source| Error::Io {
                    at: Location {
                        file: name.clone(),
                        frame: None,
                        line: Some(number + 1),
                        byte: Some(byte),
                    },
                    source,
                })?;
            if n == 0 {
                break;
            }
            number += 1;
            let at = Location {
                file: name.clone(),
                frame: None,
                line: Some(number),
                byte: Some(byte),
            };
            byte += n as u64;
            let text = String::from_utf8_lossy(&line);
            let text = text.trim();
            if text.is_empty() || text.starts_with('#') {
                continue;
            }
            let parse_error = |found: String| Error::Parse {
                at: at.clone(),
                expected: "a CP2K cell line: step, time (fs), Ax Ay Az Bx By Bz Cx Cy Cz (Å), volume (Å³)",
                found,
            };
            let fields: Vec<&str> = text.split_ascii_whitespace().collect();
            if fields.len() != 12 {
                return Err(parse_error(format!("{} fields: {text:.80}", fields.len())));
            }
            let step: i64 = fields[0]
                .parse()
                .map_err(|_| parse_error(format!("step {:.40}", fields[0])))?;
            let mut v = [0.0f64; 11];
            for (k, f) in fields[1..].iter().enumerate() {
                v[k] = f
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| parse_error(format!("{f:.40}")))?;
            }
            let matrix = [[v[1], v[2], v[3]], [v[4], v[5], v[6]], [v[7], v[8], v[9]]];
            let cell = UnitCell::from_matrix(matrix)
                .map_err(|e| parse_error(format!("step {step}: {}", e.to_string().trim_end())))?;
            let det = cell.volume();
            if (det - v[10]).abs() > 1e-6 * det.abs().max(v[10].abs()) {
                return Err(parse_error(format!(
                    "step {step}: volume {} where the vectors' determinant is {det:.6}",
                    v[10]
                )));
            }
            rows.insert(step, (v[0], cell));
        }
        if rows.is_empty() {
            return Err(Error::Parse {
                at: Location::file(&name),
                expected: "at least one cell line after the header",
                found: "none".into(),
            });
        }
        Ok(CellTable { name, rows })
    }

    /// The file's name, as errors give it.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The number of steps the file holds.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether the table holds no step (never true of a table read from a file).
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The time (fs) and cell at `step`.
    pub fn at_step(&self, step: i64) -> Option<(f64, &UnitCell)> {
        self.rows.get(&step).map(|(t, c)| (*t, c))
    }

    /// The first and last steps.
    pub fn steps(&self) -> (i64, i64) {
        let first = self.rows.keys().next().copied().unwrap_or(0);
        let last = self.rows.keys().next_back().copied().unwrap_or(0);
        (first, last)
    }
}

/// A cell to give every frame read: see the module docs.
#[derive(Clone, Debug)]
pub enum CellOverride {
    /// The same cell for every frame (replacing the file's, if it has one).
    Fixed(UnitCell),
    /// Each frame's cell looked up by its step number.
    Steps(Arc<CellTable>),
}

impl CellOverride {
    /// Sets `frame`'s cell; `index` and `file` name the frame in errors.
    pub fn apply(&self, frame: &mut Frame, index: usize, file: &str) -> Result<(), Error> {
        let table = match self {
            CellOverride::Fixed(cell) => {
                frame.cell = Some(*cell);
                return Ok(());
            }
            CellOverride::Steps(table) => table,
        };
        let invalid = |what: String| Error::InvalidValue {
            what: format!("{file}: frame {index}: {what}"),
        };
        let Some(step) = frame.step else {
            return Err(invalid(format!(
                "the frame has no step number to find its cell in {} by",
                table.name
            )));
        };
        let Some((time_fs, cell)) = table.at_step(step) else {
            let (first, last) = table.steps();
            return Err(invalid(format!(
                "step {step} is not in {} ({} steps, {first} to {last})",
                table.name,
                table.len()
            )));
        };
        if let Some(t) = frame.time
            && (t * 1000.0 - time_fs).abs() > TIME_TOLERANCE_FS
        {
            return Err(invalid(format!(
                "step {step} is at {:.3} fs, but at {time_fs:.3} fs in {}: the cell file is of another run",
                t * 1000.0,
                table.name
            )));
        }
        frame.cell = Some(*cell);
        Ok(())
    }
}

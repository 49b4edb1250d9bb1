//! Per-atom numbers from a text file ([`AtomValues`]): an analysis result (RMSF, a
//! conservation score, a charge set, a per-frame order parameter) given to the frames as a
//! property, for colouring and selections, as VMD's `user` field loaded from a file, PyMOL's
//! `alter b=...` or OVITO's per-particle file columns.
//!
//! # The file
//! Text; `#` starts a comment, blank lines are skipped, numbers are separated by spaces, tabs
//! or commas (what `numpy.savetxt`, a spreadsheet's CSV, `gmx` `.xvg` rows after their `@`/`#`
//! header, or `print` write; `@` lines are skipped too). `nan` is a number (an atom with no
//! value, drawn in the colour maps' no-value grey).
//! - **One column** (every line a single number): one value per atom, the same for every frame.
//! - **Rows of several numbers**: one row per frame, one value per atom: frame `f` of the
//!   trajectory takes row `f`.
//!
//! Errors name the file and line: a token that is no number, rows of different lengths, and
//! (from [`AtomValues::for_frame`]) a count that is not the frame's atom count or a frame past
//! the rows. Memory is the file's numbers (a file is read whole, four bytes a value).
//!
//! ```
//! use texmap_md_io::values::AtomValues;
//! let v = AtomValues::parse("# rmsf\n0.5\n1.25\nnan\n", "rmsf.txt")?;
//! assert_eq!(v.for_frame(7, 3)?[1], 1.25);
//! assert!(v.for_frame(0, 4).is_err()); // 3 values, 4 atoms
//! # Ok::<(), texmap_md_io::Error>(())
//! ```

use std::path::Path;
use std::sync::Arc;

use crate::error::{Error, Location};

/// Per-atom values read from a file; see the module docs.
#[derive(Clone, Debug, PartialEq)]
pub struct AtomValues {
    file: Arc<str>,
    /// One row (every frame) or one row per frame.
    rows: Vec<Vec<f32>>,
    /// Each row's line in the file (1-based).
    lines: Vec<usize>,
    /// The file was one column: its one row applies to every frame.
    every_frame: bool,
}

impl AtomValues {
    /// Reads `path` (see the module docs).
    pub fn open(path: impl AsRef<Path>) -> Result<AtomValues, Error> {
        let path = path.as_ref();
        let name: Arc<str> = path.display().to_string().into();
        let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
            at: Location::file(&name),
            source,
        })?;
        AtomValues::parse(&text, &name)
    }

    /// Parses `text`, named `name` in errors (see the module docs).
    pub fn parse(text: &str, name: &str) -> Result<AtomValues, Error> {
        let file: Arc<str> = name.into();
        let mut rows: Vec<Vec<f32>> = Vec::new();
        let mut lines = Vec::new();
        let mut byte = 0usize;
        for (k, line) in text.split('\n').enumerate() {
            let start = byte;
            byte += line.len() + 1;
            let body = line.split('#').next().unwrap_or("").trim();
            if body.is_empty() || body.starts_with('@') {
                continue;
            }
            let mut row = Vec::new();
            for token in body.split([' ', '\t', ',', '\r']).filter(|t| !t.is_empty()) {
                match token.parse::<f32>() {
                    Ok(v) if !v.is_infinite() => row.push(v),
                    _ => {
                        return Err(Error::Parse {
                            at: Location {
                                line: Some(k as u64 + 1),
                                byte: Some(start as u64),
                                ..Location::file(&file)
                            },
                            expected: "numbers (one per atom), separated by spaces or commas",
                            found: token.to_string(),
                        });
                    }
                }
            }
            if row.is_empty() {
                continue;
            }
            rows.push(row);
            lines.push(k + 1);
        }
        if rows.is_empty() {
            return Err(Error::Parse {
                at: Location::file(&file),
                expected: "per-atom numbers",
                found: "no number".into(),
            });
        }
        let every_frame = rows.iter().all(|r| r.len() == 1) && rows.len() > 1;
        if every_frame {
            let column = rows.iter().map(|r| r[0]).collect();
            return Ok(AtomValues {
                file,
                rows: vec![column],
                lines: vec![lines[0]],
                every_frame: true,
            });
        }
        let n = rows[0].len();
        if let Some(k) = rows.iter().position(|r| r.len() != n) {
            return Err(Error::Parse {
                at: Location {
                    line: Some(lines[k] as u64),
                    ..Location::file(&file)
                },
                expected: "as many values in every row (one row per frame)",
                found: format!("{} values after rows of {n}", rows[k].len()),
            });
        }
        Ok(AtomValues {
            file,
            rows,
            lines,
            every_frame: false,
        })
    }

    /// The file's name as errors give it.
    pub fn name(&self) -> &str {
        &self.file
    }

    /// How many frames the file gives values for; `None`: the same values for every frame.
    pub fn frames(&self) -> Option<usize> {
        (!self.every_frame).then_some(self.rows.len())
    }

    /// The values of frame `frame` for its `n_atoms` atoms.
    pub fn for_frame(&self, frame: usize, n_atoms: usize) -> Result<&[f32], Error> {
        let k = if self.every_frame { 0 } else { frame };
        let Some(row) = self.rows.get(k) else {
            return Err(Error::Parse {
                at: Location {
                    frame: Some(frame),
                    ..Location::file(&self.file)
                },
                expected: "a row of values for every frame drawn (row f for frame f)",
                found: format!("{} rows", self.rows.len()),
            });
        };
        if row.len() != n_atoms {
            let what = if self.every_frame {
                "one value per atom, one per line"
            } else {
                "one value per atom in the frame's row"
            };
            return Err(Error::Parse {
                at: Location {
                    frame: Some(frame),
                    line: Some(self.lines[k] as u64),
                    ..Location::file(&self.file)
                },
                expected: what,
                found: format!("{} values for {n_atoms} atoms", row.len()),
            });
        }
        Ok(row)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_rows_comments_and_errors() {
        let col = AtomValues::parse("# x\n1\n2.5\n\n3 # last\n", "c.txt").unwrap();
        assert_eq!(col.frames(), None);
        assert_eq!(col.for_frame(99, 3).unwrap(), [1.0, 2.5, 3.0]);
        let rows = AtomValues::parse("@ xvg header\n1, 2, 3\n4\t5 6\n", "r.csv").unwrap();
        assert_eq!(rows.frames(), Some(2));
        assert_eq!(rows.for_frame(1, 3).unwrap(), [4.0, 5.0, 6.0]);
        let e = rows.for_frame(2, 3).unwrap_err().to_string();
        assert!(e.contains("r.csv") && e.contains("2 rows"), "{e}");
        let e = rows.for_frame(0, 4).unwrap_err().to_string();
        assert!(
            e.contains("line 2") && e.contains("3 values for 4 atoms"),
            "{e}"
        );
        // One row of one value is one frame's single atom.
        assert_eq!(AtomValues::parse("7\n", "one").unwrap().frames(), Some(1));
        let e = AtomValues::parse("1 2\n3 x\n", "bad.txt")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("bad.txt") && e.contains("line 2") && e.contains('x'),
            "{e}"
        );
        let e = AtomValues::parse("1 2\n3\n", "ragged")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2"), "{e}");
        assert!(AtomValues::parse("# nothing\n", "empty").is_err());
        assert!(AtomValues::parse("1\ninf\n", "inf").is_err());
        assert!(AtomValues::parse("1\nnan\n", "nan").unwrap().rows[0][1].is_nan());
    }
}

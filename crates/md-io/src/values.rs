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
//! - **A table with a header row** (a CSV as pandas, a spreadsheet or texmap's own per-atom
//!   tables write it): [`AtomValues::open_column`] takes the column of the name asked for, one
//!   row per atom, the same for every frame; an empty field is no value (nan).
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
        let (name, text) = read(path.as_ref())?;
        AtomValues::parse(&text, &name)
    }

    /// Reads `path` as [`AtomValues::parse_column`] does.
    pub fn open_column(path: impl AsRef<Path>, column: &str) -> Result<AtomValues, Error> {
        let (name, text) = read(path.as_ref())?;
        AtomValues::parse_column(&text, &name, column)
    }

    /// Parses `text` (named `name` in errors) as [`AtomValues::parse`] does when its first line
    /// of data is numbers; when that line is a header of names, takes the column named
    /// `column` from the rows below it, one per atom (fields split at commas when the header
    /// has one, else at spaces and tabs).
    pub fn parse_column(text: &str, name: &str, column: &str) -> Result<AtomValues, Error> {
        let file: Arc<str> = name.into();
        let mut data = text
            .split('\n')
            .enumerate()
            .map(|(k, line)| (k + 1, line.split('#').next().unwrap_or("").trim()))
            .filter(|(_, body)| !body.is_empty() && !body.starts_with('@'));
        let Some((header_line, header)) = data.next() else {
            return AtomValues::parse(text, name);
        };
        let commas = header.contains(',');
        let fields = |body: &'_ str| -> Vec<String> {
            let clean = |t: &str| t.trim().trim_matches('"').to_string();
            if commas {
                body.split(',').map(clean).collect()
            } else {
                body.split([' ', '\t', '\r'])
                    .filter(|t| !t.is_empty())
                    .map(clean)
                    .collect()
            }
        };
        let names = fields(header);
        // A header names every column; a line with a number in it is data (and a stray word
        // among numbers is the plain reading's error, with its line).
        if names.iter().any(|t| t.parse::<f32>().is_ok()) {
            return AtomValues::parse(text, name);
        }
        let at = |line: usize| Location {
            line: Some(line as u64),
            ..Location::file(&file)
        };
        let Some(index) = names.iter().position(|n| n == column) else {
            return Err(Error::Parse {
                at: at(header_line),
                expected: "a header row naming the property's column (or numbers only)",
                found: format!("the columns {}, none named {column}", names.join(", ")),
            });
        };
        let mut values = Vec::new();
        for (line, body) in data {
            let row = fields(body);
            let Some(field) = row.get(index) else {
                return Err(Error::Parse {
                    at: at(line),
                    expected: "a field under every column of the header",
                    found: format!("{} fields, {column} is field {}", row.len(), index + 1),
                });
            };
            let value = if field.is_empty() {
                f32::NAN
            } else {
                match field.parse::<f32>() {
                    Ok(v) if !v.is_infinite() => v,
                    _ => {
                        return Err(Error::Parse {
                            at: at(line),
                            expected: "a number (or nothing) in the column",
                            found: field.clone(),
                        });
                    }
                }
            };
            values.push(value);
        }
        if values.is_empty() {
            return Err(Error::Parse {
                at: at(header_line),
                expected: "rows below the header, one per atom",
                found: "no row".into(),
            });
        }
        Ok(AtomValues {
            file,
            rows: vec![values],
            lines: vec![header_line + 1],
            every_frame: true,
        })
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

/// `path`'s name as errors give it, and its text.
fn read(path: &Path) -> Result<(Arc<str>, String), Error> {
    let name: Arc<str> = path.display().to_string().into();
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        at: Location::file(&name),
        source,
    })?;
    Ok((name, text))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_named_column_under_a_header() {
        let csv = "atom,name,rmsf\n0,CA,0.5\n1,\"CB\",\n2,N,1.25\n";
        let v = AtomValues::parse_column(csv, "t.csv", "rmsf").unwrap();
        let got = v.for_frame(5, 3).unwrap();
        assert_eq!((got[0], got[2]), (0.5, 1.25));
        assert!(got[1].is_nan(), "an empty field is no value");
        let spaced = "# from numpy\n atom  rmsf\n 0  2\n 1  3\n";
        let v = AtomValues::parse_column(spaced, "s.txt", "rmsf").unwrap();
        assert_eq!(v.for_frame(0, 2).unwrap(), [2.0, 3.0]);
        // Numbers only: the plain reading, rows per frame included.
        let v = AtomValues::parse_column("1 2\n3 4\n", "n.txt", "rmsf").unwrap();
        assert_eq!(v.frames(), Some(2));
        let e = AtomValues::parse_column(csv, "t.csv", "bfactor")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("t.csv") && e.contains("line 1") && e.contains("atom, name, rmsf"),
            "{e}"
        );
        let e = AtomValues::parse_column("a,rmsf\n0,1\n1\n", "short.csv", "rmsf")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 3") && e.contains("1 fields"), "{e}");
        let e = AtomValues::parse_column("a,rmsf\n0,x\n", "bad.csv", "rmsf")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2") && e.contains('x'), "{e}");
        assert!(AtomValues::parse_column("a,rmsf\n", "empty.csv", "rmsf").is_err());
        // A word among numbers is a bad value, not a header.
        let e = AtomValues::parse_column("1 x\n2 3\n", "typo.txt", "rmsf")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 1") && e.contains("numbers"), "{e}");
    }

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

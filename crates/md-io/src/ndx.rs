//! GROMACS index files (`.ndx`): named groups of atoms, as `gmx make_ndx` and `gmx select -on`
//! write them and every `gmx` tool reads them with `-n`.
//!
//! ```text
//! [ Protein ]
//!    1    2    3    4    5    6    7    8    9   10   11   12   13   14   15
//!   16   17 ...
//! [ Near_ions_f0_t0.000 ]
//! 1031 1032 1033 ...
//! ```
//!
//! A group is a `[ name ]` line and the 1-based atom numbers after it, any number per line, up
//! to the next group. Blank lines and `;` comments are skipped. Groups keep the file's order
//! (their numbers are the ones `gmx make_ndx` lists, from 0) and their atoms the file's order;
//! names may repeat, as `make_ndx`'s `Water` and `SOL` often hold the same atoms.
//!
//! The selection language reaches the groups with `group NAME` or `group N`
//! ([`crate::select::Selection::parse_with`]); [`IndexGroups::find`] resolves a name the way
//! GROMACS does: exactly, then ignoring case, then by a unique prefix.
//!
//! Reading never trusts the file: a number that is not a positive integer below 2^32, atoms
//! before the first group, and a group name left unclosed are errors naming the line and byte.
//! Whether the atoms exist is checked when a group is applied to a frame.
//!
//! ```
//! use texmap_md_io::ndx::IndexGroups;
//! let groups = IndexGroups::from_bytes(b"[ Protein ]\n1 2 3\n[ CA ]\n2\n", "index.ndx").unwrap();
//! assert_eq!(groups.len(), 2);
//! let ca = groups.find("ca").unwrap();
//! assert_eq!(groups.get(ca).atoms, vec![1]); // 0-based
//! ```

use crate::error::{Error, Location};
use std::io::Write;
use std::path::Path;
use std::sync::Arc;

/// One named group: its atoms as 0-based indices, in the file's order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IndexGroup {
    pub name: String,
    pub atoms: Vec<u32>,
}

/// The groups of one index file, in its order.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct IndexGroups {
    /// The file they came from, for messages.
    pub file: Arc<str>,
    groups: Vec<IndexGroup>,
}

/// Why [`IndexGroups::find`] found no group.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum FindError {
    /// No group has this name, or a name beginning with it.
    Unknown,
    /// Several groups begin with it (their names).
    Ambiguous(Vec<String>),
}

impl IndexGroups {
    /// Groups built in code (for [`write_ndx`], or a selection's `group` keyword).
    pub fn new(file: &str, groups: Vec<IndexGroup>) -> IndexGroups {
        IndexGroups {
            file: file.into(),
            groups,
        }
    }

    /// Reads an index file (see the module docs).
    pub fn read(path: impl AsRef<Path>) -> Result<IndexGroups, Error> {
        let path = path.as_ref();
        let file: Arc<str> = path.display().to_string().into();
        let bytes = std::fs::read(path).map_err(|source| Error::Io {
            at: Location::file(&file),
            source,
        })?;
        IndexGroups::from_bytes(&bytes, &file)
    }

    /// Parses the bytes of an index file; `file` names it in errors.
    pub fn from_bytes(bytes: &[u8], file: &str) -> Result<IndexGroups, Error> {
        let file: Arc<str> = file.into();
        let mut groups: Vec<IndexGroup> = Vec::new();
        let mut byte = 0u64;
        for (k, raw) in bytes.split_inclusive(|&b| b == b'\n').enumerate() {
            let at = |offset: usize| Location {
                file: file.clone(),
                frame: None,
                line: Some(k as u64 + 1),
                byte: Some(byte + offset as u64),
            };
            let line = raw.split(|&b| b == b';').next().unwrap_or_default();
            let start = line.iter().position(|b| !b.is_ascii_whitespace());
            if let Some(s) = start
                && line[s] == b'['
            {
                let Some(close) = line.iter().rposition(|&b| b == b']') else {
                    return Err(Error::Parse {
                        at: at(s),
                        expected: "a group name closed by ']'",
                        found: Error::found(raw),
                    });
                };
                let name = String::from_utf8_lossy(&line[s + 1..close])
                    .trim()
                    .to_string();
                if name.is_empty() || line[close + 1..].iter().any(|b| !b.is_ascii_whitespace()) {
                    return Err(Error::Parse {
                        at: at(s),
                        expected: "'[ name ]' alone on its line",
                        found: Error::found(raw),
                    });
                }
                groups.push(IndexGroup {
                    name,
                    atoms: Vec::new(),
                });
            } else if start.is_some() {
                let mut offset = 0;
                for word in line.split(|b| b.is_ascii_whitespace()) {
                    let here = offset;
                    offset += word.len() + 1;
                    if word.is_empty() {
                        continue;
                    }
                    let Some(group) = groups.last_mut() else {
                        return Err(Error::Parse {
                            at: at(here),
                            expected: "a '[ name ]' line before the first atom number",
                            found: Error::found(word),
                        });
                    };
                    let number = std::str::from_utf8(word)
                        .ok()
                        .and_then(|w| w.parse::<u64>().ok())
                        .filter(|&n| (1..=u32::MAX as u64).contains(&n));
                    let Some(number) = number else {
                        return Err(Error::Parse {
                            at: at(here),
                            expected: "an atom number (1-based, positive)",
                            found: Error::found(word),
                        });
                    };
                    group.atoms.push((number - 1) as u32);
                }
            }
            byte += raw.len() as u64;
        }
        Ok(IndexGroups { file, groups })
    }

    /// The number of groups.
    pub fn len(&self) -> usize {
        self.groups.len()
    }

    /// True when the file has no group.
    pub fn is_empty(&self) -> bool {
        self.groups.is_empty()
    }

    /// Group `i` (0-based, `gmx make_ndx`'s numbering).
    pub fn get(&self, i: usize) -> &IndexGroup {
        &self.groups[i]
    }

    /// Every group, in the file's order.
    pub fn groups(&self) -> &[IndexGroup] {
        &self.groups
    }

    /// The group a user means by `name`, as GROMACS resolves it: the first with exactly this
    /// name, else the first with this name in any case, else the one group whose name begins
    /// with it (any case).
    pub fn find(&self, name: &str) -> Result<usize, FindError> {
        if let Some(i) = self.groups.iter().position(|g| g.name == name) {
            return Ok(i);
        }
        if let Some(i) = self
            .groups
            .iter()
            .position(|g| g.name.eq_ignore_ascii_case(name))
        {
            return Ok(i);
        }
        let lower = name.to_ascii_lowercase();
        let prefixed: Vec<usize> = (0..self.groups.len())
            .filter(|&i| self.groups[i].name.to_ascii_lowercase().starts_with(&lower))
            .collect();
        match prefixed.as_slice() {
            [] => Err(FindError::Unknown),
            [i] => Ok(*i),
            many => Err(FindError::Ambiguous(
                many.iter().map(|&i| self.groups[i].name.clone()).collect(),
            )),
        }
    }
}

/// Writes `groups` as `gmx make_ndx` does: `[ name ]`, then the 1-based atom numbers, 15 to a
/// line, each right-aligned in 4 columns (wider when a number needs it) and separated by a
/// space.
pub fn write_ndx<W: Write>(groups: &[IndexGroup], out: &mut W) -> std::io::Result<()> {
    for g in groups {
        writeln!(out, "[ {} ]", g.name)?;
        for line in g.atoms.chunks(15) {
            let mut sep = "";
            for a in line {
                write!(out, "{sep}{:>4}", *a as u64 + 1)?;
                sep = " ";
            }
            writeln!(out)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_keep_order_and_repeat_names() {
        let g = IndexGroups::from_bytes(
            b"; made by hand\n[ Water ]\n4 5 6\n\n[ SOL ]\n 4\t5  6 ; the same\n[ Ion ]\n",
            "i.ndx",
        )
        .unwrap();
        assert_eq!(g.len(), 3);
        assert_eq!(g.get(1).atoms, vec![3, 4, 5]);
        assert!(g.get(2).atoms.is_empty());
        assert_eq!(g.find("SOL"), Ok(1));
        assert_eq!(g.find("sol"), Ok(1));
        assert_eq!(g.find("wat"), Ok(0));
        assert_eq!(g.find("x"), Err(FindError::Unknown));
    }

    #[test]
    fn a_prefix_of_two_names_is_ambiguous() {
        let g =
            IndexGroups::from_bytes(b"[ SideChain ]\n1\n[ SideChain-H ]\n1\n", "i.ndx").unwrap();
        assert_eq!(g.find("sidechain"), Ok(0));
        assert_eq!(
            g.find("side"),
            Err(FindError::Ambiguous(vec![
                "SideChain".into(),
                "SideChain-H".into()
            ]))
        );
    }

    #[test]
    fn bad_numbers_name_their_line_and_byte() {
        for (text, line, byte) in [
            (&b"[ A ]\n1 2 x\n"[..], 2, 10),
            (b"[ A ]\n1\n0\n", 3, 8),
            (b"7 8\n[ A ]\n", 1, 0),
            (b"[ A ]\n[ B\n", 2, 6),
            (b"[ A ] 3\n", 1, 0),
            (b"[ A ]\n-3\n", 2, 6),
            (b"[ A ]\n99999999999\n", 2, 6),
        ] {
            match IndexGroups::from_bytes(text, "i.ndx") {
                Err(Error::Parse { at, .. }) => {
                    assert_eq!((at.line, at.byte), (Some(line), Some(byte)), "{text:?}")
                }
                other => panic!("{text:?}: {other:?}"),
            }
        }
    }

    #[test]
    fn written_groups_read_back() {
        let groups = vec![
            IndexGroup {
                name: "Protein".into(),
                atoms: (0..40).collect(),
            },
            IndexGroup {
                name: "far".into(),
                atoms: vec![99_999, 123_456],
            },
        ];
        let mut out = Vec::new();
        write_ndx(&groups, &mut out).unwrap();
        let text = String::from_utf8(out.clone()).unwrap();
        assert!(text.starts_with("[ Protein ]\n   1    2    3"));
        assert_eq!(text.lines().nth(1).unwrap().split_whitespace().count(), 15);
        let back = IndexGroups::from_bytes(&out, "w.ndx").unwrap();
        assert_eq!(back.groups(), &groups[..]);
    }
}

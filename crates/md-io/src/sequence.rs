//! A trajectory in several files read as one ([`Sequence`]): a run continued in parts
//! (`prod1.xtc prod2.xtc`, GROMACS's `-noappend` `traj.part0002.xtc`, AMBER's `md1.nc md2.nc`)
//! or a LAMMPS dump written one file per step (`dump.*.lammpstrj`), as VMD's `mol addfile`,
//! MDAnalysis's `ChainReader` and OVITO's file sequences read them.
//!
//! Frames are numbered across the parts in the order given: frame `n` of the sequence is frame
//! `n − (frames before its part)` of its part. Each part is a [`Trajectory`] of its own (its
//! format told by its own name or bytes, or the format given for all), so an error names the
//! part's file and its frame there. Only one part is open at a time, whatever the count (a
//! sequence of 10,000 dump files holds one file handle); a part's frame count is learnt once.
//! Parts are not required to hold the same atoms (a LAMMPS dump's atom count may change); what
//! draws them checks what it needs.
//!
//! [`expand`] turns a pattern with `*` or `?` in its file name into the files it matches in
//! natural order (`dump.200` before `dump.1000`: runs of digits compared as numbers, as
//! OVITO orders a wildcard sequence), for patterns the shell did not expand (quoted).
//!
//! ```no_run
//! use texmap_md_io::{Frame, ReadOptions, Sequence};
//! let parts = texmap_md_io::sequence::expand("run/dump.*.lammpstrj")?;
//! let mut seq = Sequence::open(&parts, None, ReadOptions::new())?;
//! let mut frame = Frame::new();
//! println!("{} frames in {} files", seq.n_frames()?, parts.len());
//! seq.read_frame(0, &mut frame)?;
//! # Ok::<(), texmap_md_io::Error>(())
//! ```

use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::cells::CellOverride;
use crate::error::{Error, Location};
use crate::format::Format;
use crate::frame::Frame;
use crate::trajectory::{FrameSource, ReadOptions, Trajectory};

/// Several trajectory files read as one; see the module docs.
pub struct Sequence {
    paths: Vec<PathBuf>,
    format: Option<Format>,
    options: ReadOptions,
    /// The name errors and captions give the whole: the one file's, or the first's and a count.
    name: Arc<str>,
    /// Each part's frame count, once learnt.
    counts: Vec<Option<usize>>,
    /// The open part: its index, its trajectory and the frame of it that trajectory reads next.
    open: Option<(usize, Trajectory<File>, usize)>,
    /// Where `read_next` reads: the part and the frame in it.
    cursor: (usize, usize),
    /// The warnings of the parts closed so far (the open part's are read from it).
    warnings: Vec<Error>,
    /// The first part's format.
    first_format: Format,
    /// A cell given to every frame read ([`Sequence::set_cells`]).
    cells: Option<CellOverride>,
}

impl Sequence {
    /// Opens the parts `paths` (at least one), each as `format` or, with `None`, as its name
    /// or bytes tell ([`Trajectory::open`]). The first part is opened now (its errors are this
    /// call's); the others when they are read.
    pub fn open(
        paths: &[PathBuf],
        format: Option<Format>,
        options: ReadOptions,
    ) -> Result<Sequence, Error> {
        let Some(first) = paths.first() else {
            return Err(Error::InvalidValue {
                what: "a trajectory sequence needs at least one file".into(),
            });
        };
        let traj = open_part(first, format, options.clone())?;
        let name: Arc<str> = match paths.len() {
            1 => traj.name().into(),
            n => format!("{} (+{} more files)", traj.name(), n - 1).into(),
        };
        Ok(Sequence {
            paths: paths.to_vec(),
            format,
            options,
            name,
            counts: vec![None; paths.len()],
            first_format: traj.format(),
            open: Some((0, traj, 0)),
            cursor: (0, 0),
            warnings: Vec::new(),
            cells: None,
        })
    }

    /// Gives every frame read from now on a cell from outside the files: a fixed box, or a
    /// CP2K `.cell` file's cell at the frame's step (see [`crate::cells`]). A frame the
    /// override cannot place is an error naming the frame.
    pub fn set_cells(&mut self, cells: Option<CellOverride>) {
        self.cells = cells;
    }

    /// Sets frame `n`'s cell from the override, if one is set.
    fn place(&self, n: usize, frame: &mut Frame) -> Result<(), Error> {
        match &self.cells {
            Some(c) => c.apply(frame, n, &self.name),
            None => Ok(()),
        }
    }

    /// The sequence's frame number of frame `local` of part `k` (whose earlier parts' counts
    /// are known: they were read through).
    fn global(&self, k: usize, local: usize) -> usize {
        self.counts[..k]
            .iter()
            .map(|c| c.unwrap_or(0))
            .sum::<usize>()
            + local
    }

    /// The parts, in order.
    pub fn paths(&self) -> &[PathBuf] {
        &self.paths
    }

    /// [`Trajectory::without_positions`] of the frame read last.
    pub fn without_positions(&self) -> Option<crate::WithoutPositions> {
        self.open.as_ref().and_then(|o| o.1.without_positions())
    }

    /// The first part's format.
    pub fn format(&self) -> Format {
        self.first_format
    }

    /// The one part's name; for several, the first's and how many more.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The warnings of every part opened so far (see [`Trajectory::warnings`]), in order.
    pub fn warnings(&self) -> Vec<&Error> {
        let open = self.open.as_ref().map(|o| o.1.warnings()).unwrap_or(&[]);
        self.warnings.iter().chain(open).collect()
    }

    /// Part `k` opened (and the part open before closed) if need be: its trajectory and the
    /// frame of it that trajectory reads next.
    fn part(&mut self, k: usize) -> Result<(&mut Trajectory<File>, &mut usize), Error> {
        if self.open.as_ref().is_none_or(|o| o.0 != k) {
            if let Some((_, mut closed, _)) = self.open.take() {
                self.warnings.append(&mut closed.take_warnings());
            }
            let traj = open_part(&self.paths[k], self.format, self.options.clone())?;
            self.open = Some((k, traj, 0));
        }
        let (_, traj, at) = self.open.as_mut().expect("opened above");
        Ok((traj, at))
    }

    /// The frame count of part `k` (learnt once; counting keeps the part's read position).
    fn count(&mut self, k: usize) -> Result<usize, Error> {
        if let Some(n) = self.counts[k] {
            return Ok(n);
        }
        let n = self.part(k)?.0.n_frames()?;
        self.counts[k] = Some(n);
        Ok(n)
    }

    /// Number of frames over every part (each part counted once: text parts are scanned).
    pub fn n_frames(&mut self) -> Result<usize, Error> {
        let mut total = 0;
        for k in 0..self.paths.len() {
            total += self.count(k)?;
        }
        Ok(total)
    }

    /// The part holding frame `n` (its index in [`Sequence::paths`]) and the frame's number in
    /// it; `None` past the last frame.
    pub fn locate(&mut self, n: usize) -> Result<Option<(usize, usize)>, Error> {
        let mut before = 0;
        for k in 0..self.paths.len() {
            let count = self.count(k)?;
            if n < before + count {
                return Ok(Some((k, n - before)));
            }
            before += count;
        }
        Ok(None)
    }

    /// Reads frame `n` (0-based over the parts) into `frame`; the next `read_next` reads frame
    /// `n + 1`.
    pub fn read_frame(&mut self, n: usize, frame: &mut Frame) -> Result<(), Error> {
        let Some((k, local)) = self.locate(n)? else {
            let n_frames = self.n_frames()?;
            return Err(Error::FrameOutOfRange {
                file: self.name.clone(),
                requested: n,
                n_frames,
            });
        };
        let (traj, at) = self.part(k)?;
        traj.read_frame(local, frame)?;
        *at = local + 1;
        self.cursor = (k, local + 1);
        self.place(n, frame)
    }

    /// Reads the next frame into `frame`, going on to the next part when one ends;
    /// `Ok(false)` after the last frame of the last part.
    pub fn read_next(&mut self, frame: &mut Frame) -> Result<bool, Error> {
        while self.cursor.0 < self.paths.len() {
            let (k, local) = self.cursor;
            let positioned = self.open.as_ref().is_some_and(|o| o.0 == k && o.2 == local);
            let got = if positioned {
                let (traj, at) = self.part(k)?;
                let got = traj.read_next(frame)?;
                *at += got as usize;
                got
            } else if local < self.count(k)? {
                let (traj, at) = self.part(k)?;
                traj.read_frame(local, frame)?;
                *at = local + 1;
                true
            } else {
                false
            };
            if got {
                self.cursor.1 += 1;
                if self.cells.is_some() {
                    let n = self.global(k, local);
                    self.place(n, frame)?;
                }
                return Ok(true);
            }
            // Part k ended after `local` frames: its count, for frame numbers of later parts.
            self.counts[k].get_or_insert(local);
            self.cursor = (k + 1, 0);
        }
        frame.clear();
        Ok(false)
    }
}

impl FrameSource for Sequence {
    fn read_frame(&mut self, n: usize, frame: &mut Frame) -> Result<(), Error> {
        Sequence::read_frame(self, n, frame)
    }
    fn name(&self) -> &str {
        Sequence::name(self)
    }
}

fn open_part(
    path: &Path,
    format: Option<Format>,
    options: ReadOptions,
) -> Result<Trajectory<File>, Error> {
    match format {
        Some(f) => Trajectory::open_as_with(path, f, options),
        None => Trajectory::open_with(path, options),
    }
}

/// The files a pattern with `*` (any run of characters) or `?` (one character) in its last
/// component matches, in natural order (see the module docs); a path without either is
/// returned as it is. No match is an error naming the pattern.
pub fn expand(pattern: &str) -> Result<Vec<PathBuf>, Error> {
    let path = Path::new(pattern);
    let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
        return Ok(vec![path.to_path_buf()]);
    };
    if !name.contains(['*', '?']) {
        return Ok(vec![path.to_path_buf()]);
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let at = Location::file(&Arc::from(pattern));
    let entries = std::fs::read_dir(&dir).map_err(|source| Error::Io {
        at: at.clone(),
        source,
    })?;
    let mut found: Vec<(String, PathBuf)> = Vec::new();
    for entry in entries {
        let entry = entry.map_err(|source| Error::Io {
            at: at.clone(),
            source,
        })?;
        let file_name = entry.file_name();
        let Some(candidate) = file_name.to_str() else {
            continue;
        };
        if wildcard_match(name.as_bytes(), candidate.as_bytes())
            && entry.file_type().is_ok_and(|t| !t.is_dir())
        {
            found.push((candidate.to_string(), path.with_file_name(candidate)));
        }
    }
    if found.is_empty() {
        return Err(Error::InvalidValue {
            what: format!("{pattern}: no file matches the pattern"),
        });
    }
    found.sort_by(|a, b| natural_cmp(&a.0, &b.0));
    Ok(found.into_iter().map(|(_, p)| p).collect())
}

/// Whether `name` matches `pattern` (`*` any run, `?` one byte, others themselves).
fn wildcard_match(pattern: &[u8], name: &[u8]) -> bool {
    // The classic greedy match with one backtrack point (the last `*`).
    let (mut p, mut n) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while n < name.len() {
        if p < pattern.len() && (pattern[p] == b'?' || pattern[p] == name[n]) {
            p += 1;
            n += 1;
        } else if p < pattern.len() && pattern[p] == b'*' {
            star = Some((p, n));
            p += 1;
        } else if let Some((sp, sn)) = star {
            p = sp + 1;
            n = sn + 1;
            star = Some((sp, sn + 1));
        } else {
            return false;
        }
    }
    pattern[p..].iter().all(|c| *c == b'*')
}

/// Natural order: runs of ASCII digits compare as numbers (then by length, so `007` after
/// `7`), other bytes as bytes.
pub fn natural_cmp(a: &str, b: &str) -> std::cmp::Ordering {
    use std::cmp::Ordering;
    let (a, b) = (a.as_bytes(), b.as_bytes());
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        if a[i].is_ascii_digit() && b[j].is_ascii_digit() {
            let (si, sj) = (i, j);
            while i < a.len() && a[i].is_ascii_digit() {
                i += 1;
            }
            while j < b.len() && b[j].is_ascii_digit() {
                j += 1;
            }
            let (da, db) = (&a[si..i], &b[sj..j]);
            let trim = |d: &[u8]| -> usize { d.iter().take_while(|c| **c == b'0').count() };
            let (va, vb) = (&da[trim(da)..], &db[trim(db)..]);
            let by_value = va.len().cmp(&vb.len()).then_with(|| va.cmp(vb));
            match by_value.then_with(|| da.len().cmp(&db.len())) {
                Ordering::Equal => continue,
                o => return o,
            }
        }
        match a[i].cmp(&b[j]) {
            Ordering::Equal => {
                i += 1;
                j += 1;
            }
            o => return o,
        }
    }
    (a.len() - i).cmp(&(b.len() - j))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn natural_order_compares_numbers_as_numbers() {
        let mut names = vec![
            "dump.1000.lammpstrj",
            "dump.200.lammpstrj",
            "dump.0.lammpstrj",
            "dump.30.lammpstrj",
            "dump.007.lammpstrj",
            "dump.7.lammpstrj",
        ];
        names.sort_by(|a, b| natural_cmp(a, b));
        assert_eq!(
            names,
            [
                "dump.0.lammpstrj",
                "dump.7.lammpstrj",
                "dump.007.lammpstrj",
                "dump.30.lammpstrj",
                "dump.200.lammpstrj",
                "dump.1000.lammpstrj"
            ]
        );
        assert_eq!(
            natural_cmp("part2.xtc", "part10.xtc"),
            std::cmp::Ordering::Less
        );
        assert_eq!(natural_cmp("a", "a1"), std::cmp::Ordering::Less);
    }

    #[test]
    fn wildcards_match_as_shells_do() {
        let m = |p: &str, n: &str| wildcard_match(p.as_bytes(), n.as_bytes());
        assert!(m("dump.*.lammpstrj", "dump.100.lammpstrj"));
        assert!(m("dump.*.lammpstrj", "dump..lammpstrj"));
        assert!(!m("dump.*.lammpstrj", "dump.100.lammpstrj.gz"));
        assert!(m("md?.nc", "md1.nc"));
        assert!(!m("md?.nc", "md10.nc"));
        assert!(m("*", "anything"));
        assert!(m("a*b*c", "axxbyyc"));
        assert!(!m("a*b*c", "axxbyy"));
    }
}

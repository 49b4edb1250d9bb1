//! The machinery every text format shares: a line splitter over a big buffered chunk
//! ([`LineReader`]), the lazily built frame index, and [`TextReader`], which turns a per-format
//! frame parser ([`TextFormat`]) into streaming and random access.
//!
//! Lines are found with `memchr` in a 1 MiB chunk read straight from the source (no `BufRead`
//! and no copy per line); a line is handed out as a slice of the chunk with its 1-based number
//! and the byte offset of its first byte, which is all an error needs to say where it happened.
//!
//! The frame index holds (byte offset, line number) of every frame start seen so far: streaming
//! fills it for free, and random access past the known frames scans forward with the format's
//! `skip`, which splits lines but parses no numbers.

use crate::error::{Error, Location};
use crate::frame::Frame;
use std::io::{Read, Seek, SeekFrom};
use std::sync::Arc;

/// Most atoms a reader reserves room for from a count in the file before seeing the atoms: a
/// corrupt count must not make a huge allocation; larger frames grow as they are read. The
/// reserve is also capped by the file: an atom line takes at least [`MIN_ATOM_LINE`] bytes.
pub(crate) const MAX_RESERVE: usize = 1 << 16;

/// Fewest bytes of an atom line in any text format ("H 0 0 0\n").
const MIN_ATOM_LINE: u64 = 8;

/// Size of the chunk lines are split from (smaller for a smaller file: memory stays bounded by
/// the file's size; a longer line grows the buffer as it is read).
const CHUNK: usize = 1 << 20;

/// Where a line starts: its 1-based number and the byte offset of its first byte.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Pos {
    pub line: u64,
    pub byte: u64,
}

/// Splits a byte source into lines ('\n', with a trailing '\r' removed).
pub(crate) struct LineReader<R> {
    src: R,
    buf: Vec<u8>,
    /// Valid bytes are `buf[start..end]`.
    start: usize,
    end: usize,
    eof: bool,
    /// File offset of `buf[start]`.
    offset: u64,
    /// Number of the next line.
    line: u64,
    /// The number of the data's last line when it has no '\n' (once met): where a file cut
    /// mid-line ends.
    pub unterminated: Option<u64>,
}

impl<R: Read> LineReader<R> {
    /// A line reader whose first chunk is `chunk` bytes (at least 64).
    pub fn new(src: R, chunk: usize) -> LineReader<R> {
        LineReader {
            src,
            buf: vec![0; chunk.max(64)],
            start: 0,
            end: 0,
            eof: false,
            offset: 0,
            line: 1,
            unterminated: None,
        }
    }

    /// Position of the next line.
    pub fn pos(&self) -> Pos {
        Pos {
            line: self.line,
            byte: self.offset,
        }
    }

    /// Moves the data left and reads more; grows the buffer when one line fills it.
    fn refill(&mut self) -> std::io::Result<()> {
        if self.start > 0 {
            self.buf.copy_within(self.start..self.end, 0);
            self.end -= self.start;
            self.start = 0;
        }
        if self.end == self.buf.len() {
            let n = self.buf.len();
            self.buf.resize(n * 2, 0);
        }
        loop {
            match self.src.read(&mut self.buf[self.end..]) {
                Ok(0) => {
                    self.eof = true;
                    return Ok(());
                }
                Ok(k) => {
                    self.end += k;
                    return Ok(());
                }
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(e),
            }
        }
    }

    /// The next line and where it starts, `None` at the end of the data. A last line without
    /// '\n' is returned as a line.
    #[inline]
    pub fn next_line(&mut self) -> std::io::Result<Option<(Pos, &[u8])>> {
        let mut searched = 0;
        loop {
            let hay = &self.buf[self.start + searched..self.end];
            if let Some(k) = memchr::memchr(b'\n', hay) {
                let s = self.start;
                let e = s + searched + k;
                let pos = self.pos();
                self.start = e + 1;
                self.offset += (e + 1 - s) as u64;
                self.line += 1;
                let mut line = &self.buf[s..e];
                if let [rest @ .., b'\r'] = line {
                    line = rest;
                }
                return Ok(Some((pos, line)));
            }
            if self.eof {
                if self.start == self.end {
                    return Ok(None);
                }
                let (s, e) = (self.start, self.end);
                let pos = self.pos();
                self.unterminated = Some(pos.line);
                self.start = e;
                self.offset += (e - s) as u64;
                self.line += 1;
                let mut line = &self.buf[s..e];
                if let [rest @ .., b'\r'] = line {
                    line = rest;
                }
                return Ok(Some((pos, line)));
            }
            searched = self.end - self.start;
            self.refill()?;
            // After a refill the data starts at 0 and the first `searched` bytes hold no '\n'.
        }
    }

    /// Gives back the line just returned by `next_line`, which started at `pos`: its bytes are
    /// still in the buffer, just before `start`, because `next_line` never refills after
    /// finding a line.
    pub fn unread(&mut self, pos: Pos) {
        let back = (self.offset - pos.byte) as usize;
        debug_assert!(back <= self.start);
        self.start -= back;
        self.offset = pos.byte;
        self.line = pos.line;
    }

    /// Skips `n` lines; returns how many could not be skipped because the data ended.
    pub fn skip_lines(&mut self, mut n: usize) -> std::io::Result<usize> {
        while n > 0 {
            let hay = &self.buf[self.start..self.end];
            // Count newlines in the chunk, stopping at the n-th.
            let mut consumed = 0;
            let mut found = 0;
            for k in memchr::memchr_iter(b'\n', hay) {
                found += 1;
                consumed = k + 1;
                if found == n {
                    break;
                }
            }
            self.start += consumed;
            self.offset += consumed as u64;
            self.line += found as u64;
            n -= found;
            if n == 0 {
                break;
            }
            if self.eof {
                // A last line without '\n' counts as a line.
                if self.start < self.end {
                    self.unterminated = Some(self.line);
                    self.offset += (self.end - self.start) as u64;
                    self.start = self.end;
                    self.line += 1;
                    n -= 1;
                }
                return Ok(n);
            }
            self.refill()?;
        }
        Ok(0)
    }
}

impl<R: Read + Seek> LineReader<R> {
    /// Continues reading at `pos`.
    pub fn seek(&mut self, pos: Pos) -> std::io::Result<()> {
        self.src.seek(SeekFrom::Start(pos.byte))?;
        self.start = 0;
        self.end = 0;
        self.eof = false;
        self.offset = pos.byte;
        self.line = pos.line;
        Ok(())
    }
}

/// What a format's parser needs to build an error: the file and the frame being read.
#[derive(Clone, Debug)]
pub(crate) struct Ctx {
    pub file: Arc<str>,
    pub frame: usize,
    /// Most atoms to reserve room for from a count in the file (see [`MAX_RESERVE`]).
    pub reserve: usize,
}

impl Ctx {
    pub fn at(&self, pos: Pos) -> Location {
        Location::text(&self.file, self.frame, pos.line, pos.byte)
    }

    pub fn io(&self, pos: Pos, source: std::io::Error) -> Error {
        Error::Io {
            at: self.at(pos),
            source,
        }
    }

    /// A parse error at `token`, a sub-slice of `line` (which starts at `pos`): the byte offset
    /// points at the token itself.
    pub fn parse(&self, pos: Pos, line: &[u8], token: &[u8], expected: &'static str) -> Error {
        let col = (token.as_ptr() as usize).wrapping_sub(line.as_ptr() as usize);
        let col = if col <= line.len() { col } else { 0 };
        Error::Parse {
            at: self.at(Pos {
                line: pos.line,
                byte: pos.byte + col as u64,
            }),
            expected,
            found: Error::found(token),
        }
    }

    pub fn truncated(&self, pos: Pos, expected: String) -> Error {
        Error::Truncated {
            at: self.at(pos),
            expected,
        }
    }
}

/// One text format's frame parser.
pub(crate) trait TextFormat {
    /// Parses the frame starting at the next line into `frame` (cleared by the caller); `Ok(false)`
    /// when the data ends cleanly before a frame starts.
    fn read<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: &mut Frame,
    ) -> Result<bool, Error>;

    /// Moves past the frame starting at the next line, checking its structure (line counts,
    /// record order) but parsing no coordinates; `Ok(false)` when no frame starts there. A frame
    /// `skip` accepts may still fail in `read` (a bad number), never the other way round.
    fn skip<R: Read>(&mut self, lines: &mut LineReader<R>, ctx: &Ctx) -> Result<bool, Error>;

    /// Whether blank lines before a frame are passed over before `read` or `skip` is called
    /// (false for a format whose first line, a title, may be blank: AMBER's).
    const SKIPS_BLANK_LINES: bool = true;

    /// Called when the data ends where frame `ctx.frame` would start (at `at`): a format whose
    /// header announces more frames (XSF's `ANIMSTEPS`) returns the cut there.
    fn end(&mut self, _ctx: &Ctx, _at: Pos) -> Result<(), Error> {
        Ok(())
    }
}

/// A text format whose `read` and `skip` are one walk over a frame's records, parsing them into
/// a frame when given one and checking their structure when not (PDB, PDBx/mmCIF).
pub(crate) trait FrameWalk {
    fn walk<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: Option<&mut Frame>,
    ) -> Result<bool, Error>;

    /// [`TextFormat::SKIPS_BLANK_LINES`].
    const SKIPS_BLANK_LINES: bool = true;

    /// As [`TextFormat::end`].
    fn end(&mut self, _ctx: &Ctx, _at: Pos) -> Result<(), Error> {
        Ok(())
    }
}

impl<T: FrameWalk> TextFormat for T {
    fn read<R: Read>(
        &mut self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        frame: &mut Frame,
    ) -> Result<bool, Error> {
        self.walk(lines, ctx, Some(frame))
    }

    fn skip<R: Read>(&mut self, lines: &mut LineReader<R>, ctx: &Ctx) -> Result<bool, Error> {
        self.walk(lines, ctx, None)
    }

    const SKIPS_BLANK_LINES: bool = T::SKIPS_BLANK_LINES;

    fn end(&mut self, ctx: &Ctx, at: Pos) -> Result<(), Error> {
        FrameWalk::end(self, ctx, at)
    }
}

/// What the multi-model text formats (PDB, PDBx/mmCIF) check across frames: every model must
/// hold as many atoms as model 1 (frame 0). A model with another count lost or gained atom
/// records: an error, or with `lenient` (`ReadOptions::allow_truncated`) a warning and the model
/// passed on as it is. Also keeps the parser's warnings until the `Trajectory` gathers them,
/// each once per frame and kind (a frame is walked by the scan and again by the read).
#[derive(Default)]
pub(crate) struct ModelCheck {
    first: Option<usize>,
    lenient: bool,
    warnings: Vec<Error>,
    warned: std::collections::BTreeSet<(usize, &'static str)>,
}

impl ModelCheck {
    /// A check; `lenient` turns an atom count that differs from model 1's into a warning.
    pub fn new(lenient: bool) -> ModelCheck {
        ModelCheck {
            lenient,
            ..ModelCheck::default()
        }
    }

    /// The warnings kept so far (emptied).
    pub fn take_warnings(&mut self) -> Vec<Error> {
        std::mem::take(&mut self.warnings)
    }

    /// Keeps `w` as a warning about frame `frame`, unless one of the same `kind` is kept already.
    pub fn warn(&mut self, frame: usize, kind: &'static str, w: Error) {
        if self.warned.insert((frame, kind)) {
            self.warnings.push(w);
        }
    }

    /// Checks a finished frame's atom count against model 1's (frame 0 sets it); `expected`
    /// names the records counted, e.g. "as many ATOM/HETATM records as model 1 (frame 0)".
    pub fn check(
        &mut self,
        ctx: &Ctx,
        pos: Pos,
        n_atoms: usize,
        expected: &'static str,
    ) -> Result<(), Error> {
        self.check_at(ctx.frame, || ctx.at(pos), n_atoms, expected)
    }

    /// [`ModelCheck::check`] for frame `frame`, the error (or warning) located by `at` (a
    /// binary format has no lines: the BinaryCIF reader's rows).
    pub fn check_at(
        &mut self,
        frame: usize,
        at: impl FnOnce() -> Location,
        n_atoms: usize,
        expected: &'static str,
    ) -> Result<(), Error> {
        if frame == 0 {
            self.first = Some(n_atoms);
            return Ok(());
        }
        let Some(first) = self.first else {
            return Ok(());
        };
        if first == n_atoms {
            return Ok(());
        }
        let e = Error::Parse {
            at: at(),
            expected,
            found: format!("{n_atoms} atoms, model 1 has {first}"),
        };
        if !self.lenient {
            return Err(e);
        }
        self.warn(frame, expected, e);
        Ok(())
    }
}

/// The next line, or the cut-file error naming what was expected there.
pub(crate) fn need_line<'a, R: Read>(
    lines: &'a mut LineReader<R>,
    ctx: &Ctx,
    expected: &str,
) -> Result<(Pos, &'a [u8]), Error> {
    need_line_with(lines, ctx, &|| expected.to_string())
}

/// [`need_line`], what was expected written only when the data ends (a count of lines still
/// due, which would cost a `format!` a line).
pub(crate) fn need_line_with<'a, R: Read>(
    lines: &'a mut LineReader<R>,
    ctx: &Ctx,
    expected: &dyn Fn() -> String,
) -> Result<(Pos, &'a [u8]), Error> {
    let p = lines.pos();
    match lines.next_line().map_err(|e| ctx.io(p, e))? {
        Some(l) => Ok(l),
        None => Err(ctx.truncated(p, expected())),
    }
}

/// Where the next frame starts: past any blank lines when `skip` is set; `None` at the end.
fn frame_start<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    skip: bool,
) -> Result<Option<Pos>, Error> {
    if skip {
        return skip_blank(lines, ctx);
    }
    let pos = lines.pos();
    match lines.next_line().map_err(|e| ctx.io(pos, e))? {
        None => Ok(None),
        Some((p, _)) => {
            lines.unread(p);
            Ok(Some(pos))
        }
    }
}

/// Skips blank lines; returns the first non-blank line's position, or `None` at the end.
pub(crate) fn skip_blank<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
) -> Result<Option<Pos>, Error> {
    loop {
        let pos = lines.pos();
        // Peek: read a line, and give it back if it is not blank.
        match lines.next_line().map_err(|e| ctx.io(pos, e))? {
            None => return Ok(None),
            Some((_, l)) if crate::parse::trim(l).is_empty() => continue,
            Some((p, _)) => {
                lines.unread(p);
                return Ok(Some(pos));
            }
        }
    }
}

/// Streaming and random access over a text format.
pub(crate) struct TextReader<R, F> {
    lines: LineReader<R>,
    format: F,
    file: Arc<str>,
    /// Starts of the frames seen so far.
    starts: Vec<Pos>,
    /// True once a scan reached the end of the data.
    complete: bool,
    /// Index of the frame the next `read_next` reads.
    next: usize,
    /// Most atoms to reserve from a count in the file.
    reserve: usize,
    /// Once checked: whether the last frame is cut inside its last line (see
    /// `last_frame_cut`), as the location and what was expected.
    last_cut: Option<Option<(Location, String)>>,
}

impl<R: Read + Seek, F: TextFormat> TextReader<R, F> {
    /// A reader over `src`, which starts at byte 0. Its length (when it can seek) bounds the
    /// first line chunk and the atoms reserved from a count, so that memory follows the file.
    pub fn new(mut src: R, format: F, file: Arc<str>) -> TextReader<R, F> {
        let len = src
            .seek(SeekFrom::End(0))
            .and_then(|n| src.seek(SeekFrom::Start(0)).map(|_| n))
            .ok();
        let (chunk, reserve) = match len {
            Some(n) => (
                (n as usize).saturating_add(1).min(CHUNK),
                ((n / MIN_ATOM_LINE) as usize)
                    .saturating_add(1)
                    .min(MAX_RESERVE),
            ),
            None => (CHUNK, MAX_RESERVE),
        };
        TextReader {
            lines: LineReader::new(src, chunk),
            format,
            file,
            starts: Vec::new(),
            complete: false,
            next: 0,
            reserve,
            last_cut: None,
        }
    }

    /// The format's parser (for its warnings).
    pub fn format_mut(&mut self) -> &mut F {
        &mut self.format
    }

    fn ctx(&self) -> Ctx {
        Ctx {
            file: self.file.clone(),
            frame: self.next,
            reserve: self.reserve,
        }
    }

    /// Reads the next frame; `Ok(false)` at the end.
    pub fn read_next(&mut self, frame: &mut Frame) -> Result<bool, Error> {
        let ctx = self.ctx();
        frame.clear();
        let Some(start) = frame_start(&mut self.lines, &ctx, F::SKIPS_BLANK_LINES)? else {
            self.format.end(&ctx, self.lines.pos())?;
            if self.next == self.starts.len() {
                self.complete = true;
            }
            return Ok(false);
        };
        let pushed = self.next == self.starts.len();
        if pushed {
            self.starts.push(start);
        }
        let ok = self
            .format
            .read(&mut self.lines, &ctx, frame)
            .and_then(|ok| {
                // Finite but absurd coordinates are damage too: name the frame and the atom.
                match crate::cursor::first_out_of_bounds(&frame.positions) {
                    Some(bad) if ok => Err(Error::Parse {
                        at: Location::text(&self.file, self.next, start.line, start.byte),
                        expected: crate::cursor::IN_BOUNDS,
                        found: format!("atom {bad}: {:?}", frame.positions[bad]),
                    }),
                    _ => Ok(ok),
                }
            });
        match ok {
            Ok(true) => {
                self.next += 1;
                Ok(true)
            }
            Ok(false) => {
                // Only trailer records (e.g. PDB CONECT/END) were left: no frame starts here.
                if pushed {
                    self.starts.pop();
                    self.complete = true;
                }
                frame.clear();
                Ok(false)
            }
            Err(e) => {
                // Leave the cursor at the damaged frame so a retry gives the same error.
                frame.clear();
                let start = self.starts[self.next];
                let e = self.explain_cut(e, start);
                let _ = self.lines.seek(start);
                Err(e)
            }
        }
    }

    /// The error to give for the frame starting at `start` that failed to parse with `e`: when
    /// the data ends inside the frame, the parser meets a partial last line first, but the cut
    /// is what happened (and what `allow_truncated` forgives). The cut is found as `n_frames`
    /// finds it, by the format's scan of the frame from its start, or it is the failing line
    /// itself when that is the data's last line and has no end of line.
    fn explain_cut(&mut self, e: Error, start: Pos) -> Error {
        let Error::Parse { .. } = &e else {
            return e;
        };
        if self.lines.seek(start).is_err() {
            return e;
        }
        let ctx = self.ctx();
        if let Err(cut @ Error::Truncated { .. }) = self.format.skip(&mut self.lines, &ctx) {
            return cut;
        }
        self.cut_line(e)
    }

    /// `e` as the cut it is when it is a parse error on the data's last line and that line has
    /// no end of line (a file cut mid-line); else `e`.
    fn cut_line(&self, e: Error) -> Error {
        match (&e, self.lines.unterminated) {
            (Error::Parse { at, .. }, Some(last)) if at.line == Some(last) => Error::Truncated {
                at: at.clone(),
                expected: format!(
                    "the rest of line {last}: the file ends inside it, without an end of line"
                ),
            },
            _ => e,
        }
    }

    /// Scans forward until `n + 1` frame starts are known or the data ends.
    fn scan_to(&mut self, n: usize) -> Result<(), Error> {
        if self.complete || n < self.starts.len() {
            return Ok(());
        }
        // Continue from the end of the last known frame.
        if let Some(&last) = self.starts.last() {
            self.next = self.starts.len() - 1;
            self.lines.seek(last).map_err(|e| self.ctx().io(last, e))?;
            let ctx = self.ctx();
            let skipped = self.format.skip(&mut self.lines, &ctx);
            if !skipped.map_err(|e| self.cut_line(e))? {
                self.complete = true;
                return Ok(());
            }
            self.next += 1;
        } else {
            self.next = 0;
            let p = Pos { line: 1, byte: 0 };
            self.lines.seek(p).map_err(|e| self.ctx().io(p, e))?;
        }
        while self.starts.len() <= n {
            let ctx = self.ctx();
            let Some(start) = frame_start(&mut self.lines, &ctx, F::SKIPS_BLANK_LINES)? else {
                self.format.end(&ctx, self.lines.pos())?;
                self.complete = true;
                return Ok(());
            };
            self.starts.push(start);
            let skipped = self.format.skip(&mut self.lines, &ctx);
            if !skipped.map_err(|e| self.cut_line(e))? {
                self.starts.pop();
                self.complete = true;
                return Ok(());
            }
            self.next += 1;
        }
        Ok(())
    }

    /// Positions the reader so that `read_next` reads frame `n`; false when there is no frame `n`.
    pub fn seek_frame(&mut self, n: usize) -> Result<bool, Error> {
        if let Err(e) = self.scan_to(n) {
            // A damaged frame stopped the scan; its start is the last one known: stay there so
            // that `read_next` reports the same damage.
            if let Some(&p) = self.starts.last() {
                self.next = self.starts.len() - 1;
                let _ = self.lines.seek(p);
            }
            return Err(e);
        }
        if n < self.starts.len() {
            let p = self.starts[n];
            self.lines.seek(p).map_err(|e| self.ctx().io(p, e))?;
            self.next = n;
            Ok(true)
        } else {
            Ok(false)
        }
    }

    /// Number of frames (scans the whole file once; keeps the read position).
    pub fn n_frames(&mut self) -> Result<usize, Error> {
        if !self.complete {
            // Scan, then resume exactly where the next read would have started, even when the
            // scan stopped at a damaged frame.
            let (keep, resume) = (self.next, self.lines.pos());
            let scanned = self.scan_to(usize::MAX - 1);
            self.lines
                .seek(resume)
                .map_err(|e| self.ctx().io(resume, e))?;
            self.next = keep;
            scanned?;
        }
        if let Some((at, expected)) = self.last_frame_cut()? {
            return Err(Error::Truncated { at, expected });
        }
        Ok(self.starts.len())
    }

    /// A scan counts lines, so it takes a last frame that the data ends inside its last line
    /// (no end of line) for whole; parsing that frame tells (once, after a complete scan).
    fn last_frame_cut(&mut self) -> Result<Option<(Location, String)>, Error> {
        if self.lines.unterminated.is_none() || self.starts.is_empty() {
            return Ok(None);
        }
        if self.last_cut.is_none() {
            let (keep, resume) = (self.next, self.lines.pos());
            self.next = self.starts.len() - 1;
            let start = self.starts[self.next];
            self.lines
                .seek(start)
                .map_err(|e| self.ctx().io(start, e))?;
            let ctx = self.ctx();
            let mut scratch = Frame::new();
            let read = self.format.read(&mut self.lines, &ctx, &mut scratch);
            let cut = match read {
                Err(e) => match self.explain_cut(e, start) {
                    Error::Truncated { at, expected } => Some((at, expected)),
                    _ => None,
                },
                Ok(_) => None,
            };
            self.lines
                .seek(resume)
                .map_err(|e| self.ctx().io(resume, e))?;
            self.next = keep;
            self.last_cut = Some(cut);
        }
        Ok(self.last_cut.clone().flatten())
    }
}

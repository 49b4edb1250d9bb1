//! CIF 1.1 tokens, shared by the PDBx/mmCIF reader ([`crate::mmcif`]) and the crystallographic
//! CIF reader ([`crate::crystal_cif`]).
//!
//! Tokens are separated by blanks; a value is bare, or in single or double quotes (a quote
//! closes only when a blank or the line end follows it, so `'O5''` is `O5'`), or a text field
//! from a line starting with `;` to the next line starting with `;`. `#` starts a comment at a
//! token start. Bare `.` and `?` are the missing values; reserved words (`data_`, `loop_`,
//! `save_`, `global_`, `stop_`) are case-insensitive. The lexer copies nothing but the lines of
//! a text field, which it joins by spaces.
//!
//! # References
//! - S. R. Hall, F. H. Allen, I. D. Brown, "The Crystallographic Information File (CIF)", Acta
//!   Cryst. A47 (1991) 655; CIF 1.1 syntax specification (IUCr, 2003), paragraphs 2-22.

use crate::error::Error;
use crate::parse::parse_f64;
use crate::text::{Ctx, Pos};

/// What a token is, by the CIF grammar.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    /// An unquoted value (bare `.` and `?` are the missing values).
    Bare,
    /// A quoted value or a text field: always a value, never a keyword.
    Quoted,
    /// A tag: `_category.item` (DDL2, PDBx/mmCIF) or `_category_item` (DDL1, core CIF).
    Tag,
    /// `loop_`.
    Loop,
    /// `data_name`.
    Data,
    /// `save_…`, `global_`, `stop_`: not used by the data files read here.
    Reserved,
}

/// One token: its bytes (quotes removed) and where it starts.
#[derive(Clone, Copy)]
pub(crate) struct Tok<'a> {
    pub kind: Kind,
    pub text: &'a [u8],
    /// The token's line and the byte offset of its first byte (a text field: its opening `;`).
    pub at: Pos,
    /// True when only blanks precede it on its line.
    pub starts_line: bool,
}

impl Tok<'_> {
    pub fn is_value(&self) -> bool {
        matches!(self.kind, Kind::Bare | Kind::Quoted)
    }

    /// A bare `.` (inapplicable) or `?` (unknown).
    pub fn missing(&self) -> bool {
        self.kind == Kind::Bare && matches!(self.text, b"." | b"?")
    }

    /// A parse error at this token.
    pub fn error(&self, ctx: &Ctx, expected: &'static str) -> Error {
        Error::Parse {
            at: ctx.at(self.at),
            expected,
            found: Error::found(self.text),
        }
    }
}

/// The kind of a bare token (reserved words are case-insensitive).
pub(crate) fn classify(t: &[u8]) -> Kind {
    let starts = |p: &[u8]| t.len() >= p.len() && t[..p.len()].eq_ignore_ascii_case(p);
    if t.first() == Some(&b'_') {
        Kind::Tag
    } else if t.eq_ignore_ascii_case(b"loop_") {
        Kind::Loop
    } else if starts(b"data_") {
        Kind::Data
    } else if starts(b"save_")
        || t.eq_ignore_ascii_case(b"global_")
        || t.eq_ignore_ascii_case(b"stop_")
    {
        Kind::Reserved
    } else {
        Kind::Bare
    }
}

/// Splits lines into tokens and carries an open text field from line to line.
#[derive(Default)]
pub(crate) struct Lexer {
    /// Where the open text field started (its `;`), if one is open.
    pub open: Option<Pos>,
    /// The open text field's lines, joined by spaces.
    text: Vec<u8>,
}

impl Lexer {
    /// Feeds the tokens of `line` (which starts at `pos`) to `f` until it asks to stop
    /// (`Some`), and gives back what it stopped with; `None` when the line is used up.
    pub fn line<S>(
        &mut self,
        line: &[u8],
        pos: Pos,
        ctx: &Ctx,
        mut f: impl FnMut(Tok<'_>) -> Result<Option<S>, Error>,
    ) -> Result<Option<S>, Error> {
        let mut i = 0;
        let mut first = true;
        if let Some(open) = self.open {
            if line.first() != Some(&b';') {
                // Another line of the text field.
                if !self.text.is_empty() {
                    self.text.push(b' ');
                }
                self.text.extend_from_slice(line);
                return Ok(None);
            }
            // The field closes; the rest of this line holds ordinary tokens.
            self.open = None;
            let tok = Tok {
                kind: Kind::Quoted,
                text: &self.text,
                at: open,
                starts_line: true,
            };
            if let Some(stop) = f(tok)? {
                return Ok(Some(stop));
            }
            i = 1;
            first = false;
        }
        loop {
            while i < line.len() && matches!(line[i], b' ' | b'\t') {
                i += 1;
            }
            if i >= line.len() {
                return Ok(None);
            }
            let at = Pos {
                line: pos.line,
                byte: pos.byte + i as u64,
            };
            let starts_line = std::mem::replace(&mut first, false);
            let tok = match line[i] {
                b'#' => return Ok(None),
                b';' if i == 0 => {
                    self.open = Some(at);
                    self.text.clear();
                    self.text.extend_from_slice(&line[1..]);
                    return Ok(None);
                }
                q @ (b'\'' | b'"') => {
                    // A quote closes only before a blank or the end of the line.
                    let close = (i + 1..line.len()).find(|&j| {
                        line[j] == q && line.get(j + 1).is_none_or(|&b| matches!(b, b' ' | b'\t'))
                    });
                    let Some(j) = close else {
                        return Err(Error::Parse {
                            at: ctx.at(at),
                            expected: if q == b'\'' {
                                "a closing ' (followed by a blank or the line end) on the same line"
                            } else {
                                "a closing \" (followed by a blank or the line end) on the same line"
                            },
                            found: Error::found(&line[i..]),
                        });
                    };
                    let tok = Tok {
                        kind: Kind::Quoted,
                        text: &line[i + 1..j],
                        at,
                        starts_line,
                    };
                    i = j + 1;
                    tok
                }
                _ => {
                    let j = line[i..]
                        .iter()
                        .position(|b| matches!(b, b' ' | b'\t'))
                        .map_or(line.len(), |k| i + k);
                    let text = &line[i..j];
                    i = j;
                    Tok {
                        kind: classify(text),
                        text,
                        at,
                        starts_line,
                    }
                }
            };
            if let Some(stop) = f(tok)? {
                return Ok(Some(stop));
            }
        }
    }
}

/// A CIF number (a standard uncertainty in parentheses, `1.234(5)`, is dropped).
pub(crate) fn number(tok: &Tok) -> Option<f64> {
    if tok.missing() {
        return None;
    }
    parse_f64(strip_esd(tok.text))
}

/// A `_cell` length or angle: its number, `None` when missing (`.`, `?`); anything else is an
/// error at the token.
pub(crate) fn cell_number(tok: &Tok, ctx: &Ctx) -> Result<Option<f64>, Error> {
    if !tok.missing() && number(tok).is_none() {
        return Err(tok.error(ctx, "a number for a _cell length or angle"));
    }
    Ok(number(tok))
}

/// The lengths and angles of the six `_cell` values (angles 90° when absent); `None` without
/// all three lengths.
pub(crate) fn cell_parameters(v: [Option<f64>; 6]) -> Option<([f64; 3], [f64; 3])> {
    let (Some(a), Some(b), Some(c)) = (v[0], v[1], v[2]) else {
        return None;
    };
    Some(([a, b, c], [v[3], v[4], v[5]].map(|x| x.unwrap_or(90.0))))
}

/// The cell of `lengths` and `angles`, or a parse error at `at` (the first `_cell` value)
/// saying what was `expected`.
pub(crate) fn cell_of(
    lengths: [f64; 3],
    angles: [f64; 3],
    ctx: &Ctx,
    at: Pos,
    expected: &'static str,
) -> Result<crate::frame::UnitCell, Error> {
    crate::frame::UnitCell::from_lengths_angles(lengths, angles).map_err(|e| Error::Parse {
        at: ctx.at(at),
        expected,
        found: e.to_string(),
    })
}

/// `t` without a trailing standard uncertainty in parentheses (`12.345(6)` -> `12.345`).
pub(crate) fn strip_esd(t: &[u8]) -> &[u8] {
    match t {
        [head @ .., b')'] => match head.iter().rposition(|b| *b == b'(') {
            Some(k) if head[k + 1..].iter().all(u8::is_ascii_digit) => &head[..k],
            _ => t,
        },
        _ => t,
    }
}

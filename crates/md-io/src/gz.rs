//! Transparent compressed input: `1abc.cif.gz`, `run.xyz.gz`, `top.psf.gz`, `prod.mdcrd.bz2`
//! read like the plain files.
//!
//! A file is gzip when its first two bytes are the gzip magic `1f 8b` (RFC 1952 §2.3.1), and
//! bzip2 when its first four are `BZh` and a block-size digit `1`-`9`, whatever its name; a name
//! ending in `.gz` or `.bz2` over bytes that are not of that kind is an error rather than a
//! guess. A pipe or device is looked at only when its name ends in `.gz` or `.bz2` (bytes read
//! from it to see the magic could not be put back), and is then decompressed without a seek.
//! The format of what is inside comes from the name without `.gz` / `.bz2` (see
//! [`inner_path`]), else from the decompressed bytes, as for a plain file. Everything below
//! about gzip holds for bzip2 (every stream of a concatenated file read, `MultiBzDecoder`;
//! errors say "bzip2").
//!
//! The readers need `Read + Seek` (frame index, random access) and [`crate::Trajectory::open`]
//! returns a `Trajectory<File>`, so the file is decompressed once, streaming, into an anonymous
//! temporary file (`tempfile::tempfile`: deleted by the operating system when closed) that the
//! readers then read as they read any file. Memory stays bounded by the decoder's buffers; disk
//! use is the decompressed size, in the system's temporary directory, for as long as the
//! trajectory is open. Byte offsets in later errors therefore count decompressed bytes, under the
//! `.gz` file's name.
//!
//! Every member of the file is read (`MultiGzDecoder`), so `cat a.gz b.gz` and bgzip files read
//! whole. A damaged or cut stream is an [`Error::Parse`] naming the file, saying "gzip" and giving
//! the compressed byte offset where decoding stopped; a stream cut before its 8-byte trailer is
//! such an error too, never a shorter file. The one exception is a trajectory opened with
//! `allow_truncated` ([`crate::ReadOptions`]): a stream that simply ends early (a simulation
//! killed while writing `run.xyz.gz`, a partial download) gives what inflated up to the cut,
//! with the cut as a warning (the [`Error::Parse`] it would have been), and the reader then keeps
//! the complete frames as it does for a cut plain file. Corrupt data stays an error either way.
//!
//! Rejected: inflating into memory (`Cursor<Vec<u8>>`), since memory would then grow with the
//! file, which no reader of the crate does; and random access inside the compressed stream
//! (restart points as in zlib's zran.c or bgzip's `.gzi` index), which avoids the temporary file
//! but re-inflates from a restart point on every backward seek and needs a reader type of its
//! own where `Trajectory::open` gives a `Trajectory<File>`.
//!
//! # References
//! - RFC 1952, GZIP file format specification version 4.3 (member layout, magic, trailer).
//! - J. Seward, bzip2 and libbzip2 manual, and the bzip2 format's stream header (`BZh1`-`BZh9`).

use std::borrow::Cow;
use std::fs::File;
use std::io::{self, BufRead, BufReader, Read, Seek, Write};
use std::path::Path;
use std::sync::Arc;

use bzip2::bufread::MultiBzDecoder;
use flate2::bufread::MultiGzDecoder;

use crate::error::{Error, Location};

/// The first two bytes of every gzip member (RFC 1952 §2.3.1: ID1, ID2).
const MAGIC: [u8; 2] = [0x1f, 0x8b];

/// The compressions read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Codec {
    Gzip,
    Bzip2,
}

impl Codec {
    /// The codec whose magic `head` starts with.
    fn of(head: &[u8]) -> Option<Codec> {
        if head.starts_with(&MAGIC) {
            return Some(Codec::Gzip);
        }
        match head {
            [b'B', b'Z', b'h', b'1'..=b'9', ..] => Some(Codec::Bzip2),
            _ => None,
        }
    }

    /// The codec a path's last extension names (`gz`, `bz2`; any case).
    fn of_path(path: &Path) -> Option<Codec> {
        let e = path.extension()?;
        if e.eq_ignore_ascii_case("gz") {
            Some(Codec::Gzip)
        } else if e.eq_ignore_ascii_case("bz2") {
            Some(Codec::Bzip2)
        } else {
            None
        }
    }

    fn name(self) -> &'static str {
        match self {
            Codec::Gzip => "gzip",
            Codec::Bzip2 => "bzip2",
        }
    }
}

/// True when `path`'s last extension names a compression (`gz`, `bz2`; any case).
fn has_gz_extension(path: &Path) -> bool {
    Codec::of_path(path).is_some()
}

/// `path` without a trailing `.gz` or `.bz2` (any case): the name that tells the format of what
/// is inside (`1abc.pdb.gz` -> `1abc.pdb`). Other paths are given back unchanged.
pub(crate) fn inner_path(path: &Path) -> Cow<'_, Path> {
    if has_gz_extension(path) {
        Cow::Owned(path.with_extension(""))
    } else {
        Cow::Borrowed(path)
    }
}

/// Opens `path` (called `name` in errors) for reading: the file itself, or when it is gzip, an
/// anonymous temporary file holding its decompressed bytes, positioned at the start. With
/// `keep_cut`, a gzip stream that ends early gives the bytes inflated up to there and the cut as
/// a warning (the second value); otherwise the cut is the error.
pub(crate) fn open(
    path: &Path,
    name: &Arc<str>,
    keep_cut: bool,
) -> Result<(File, Option<Error>), Error> {
    let io_at = |byte: Option<u64>| {
        move |source| Error::Io {
            at: Location {
                byte,
                ..Location::file(name)
            },
            source,
        }
    };
    let mut file = File::open(path).map_err(io_at(None))?;
    let regular = file.metadata().is_ok_and(|m| m.is_file());
    if !regular && !has_gz_extension(path) {
        // A pipe or device cannot give back the bytes a look at its magic would take: it is read
        // as it is, as before gzip input existed (the text readers stream without seeking).
        return Ok((file, None));
    }
    // Read the magic (and a few bytes more, to show what a misnamed file holds).
    let mut head = Vec::with_capacity(16);
    (&mut file)
        .take(16)
        .read_to_end(&mut head)
        .map_err(io_at(Some(0)))?;
    let codec = Codec::of(&head);
    let named = Codec::of_path(path);
    if named.is_some() && codec != named {
        return Err(Error::Parse {
            at: Location {
                byte: Some(0),
                ..Location::file(name)
            },
            expected: match named {
                Some(Codec::Bzip2) => {
                    "the bzip2 magic bytes BZh1-BZh9 (the name ends in .bz2, but the file is not bzip2)"
                }
                _ => "the gzip magic bytes 1f 8b (the name ends in .gz, but the file is not gzip)",
            },
            found: Error::found(&head),
        });
    }
    let Some(codec) = codec else {
        file.rewind().map_err(io_at(Some(0)))?;
        return Ok((file, None));
    };
    // The bytes already read go first, so that a pipe named `.gz` needs no seek either.
    decompress(io::Cursor::new(head).chain(file), codec, name, keep_cut)
}

/// Inflates every member of `src` into a new anonymous temporary file, rewound; with
/// `keep_cut`, a stream that ends early stops there with the cut as a warning.
fn decompress(
    src: impl Read,
    codec: Codec,
    name: &Arc<str>,
    keep_cut: bool,
) -> Result<(File, Option<Error>), Error> {
    let mut out = tempfile::tempfile().map_err(|e| temp_error(codec, name, e))?;
    let mut input = Counting {
        inner: BufReader::with_capacity(64 * 1024, src),
        consumed: 0,
        failed: false,
    };
    let mut decoder: Box<dyn Read + '_> = match codec {
        Codec::Gzip => Box::new(MultiGzDecoder::new(&mut input)),
        Codec::Bzip2 => Box::new(MultiBzDecoder::new(&mut input)),
    };
    let mut buf = vec![0u8; 64 * 1024];
    let mut cut = None;
    loop {
        let n = match decoder.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
            Err(e) => {
                drop(decoder);
                let ended_early = e.kind() == io::ErrorKind::UnexpectedEof;
                let e = stream_error(codec, name, &input, e);
                match e {
                    // The decoder ran out of input (not a read failure): a cut, not corruption.
                    Error::Parse { at, found, .. } if keep_cut && ended_early && !input.failed => {
                        cut = Some(Error::Parse {
                            at,
                            expected: match codec {
                                Codec::Gzip => {
                                    "the rest of the gzip stream (the data before the cut is read)"
                                }
                                Codec::Bzip2 => {
                                    "the rest of the bzip2 stream (the data before the cut is read)"
                                }
                            },
                            found,
                        });
                        break;
                    }
                    e => return Err(e),
                }
            }
        };
        out.write_all(&buf[..n])
            .map_err(|e| temp_error(codec, name, e))?;
    }
    out.rewind().map_err(|e| temp_error(codec, name, e))?;
    Ok((out, cut))
}

/// An error of the compressed stream at the offset `input` has reached: the operating
/// system's read failure as [`Error::Io`], the decoder's complaint as [`Error::Parse`].
fn stream_error<R>(codec: Codec, name: &Arc<str>, input: &Counting<R>, e: io::Error) -> Error {
    let at = Location {
        byte: Some(input.consumed),
        ..Location::file(name)
    };
    if input.failed {
        return Error::Io { at, source: e };
    }
    if e.kind() == io::ErrorKind::UnexpectedEof {
        return Error::Parse {
            at,
            expected: match codec {
                Codec::Gzip => "the rest of the gzip stream",
                Codec::Bzip2 => "the rest of the bzip2 stream",
            },
            found: "end of file".into(),
        };
    }
    Error::Parse {
        at,
        expected: match codec {
            Codec::Gzip => "intact gzip data",
            Codec::Bzip2 => "intact bzip2 data",
        },
        found: e.to_string(),
    }
}

/// A failure to write or rewind the temporary file (a full temporary directory, say).
fn temp_error(codec: Codec, name: &Arc<str>, e: io::Error) -> Error {
    Error::Io {
        at: Location::file(name),
        source: io::Error::new(
            e.kind(),
            format!(
                "writing the decompressed {} data to a temporary file: {e}",
                codec.name()
            ),
        ),
    }
}

/// A buffered reader that counts the bytes the decoder has consumed (the compressed offset of
/// an error) and remembers whether the file itself failed a read.
struct Counting<R> {
    inner: R,
    consumed: u64,
    failed: bool,
}

impl<R: BufRead> Read for Counting<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf).inspect_err(|_| self.failed = true)?;
        self.consumed += n as u64;
        Ok(n)
    }
}

impl<R: BufRead> BufRead for Counting<R> {
    fn fill_buf(&mut self) -> io::Result<&[u8]> {
        match self.inner.fill_buf() {
            Ok(b) => Ok(b),
            Err(e) => {
                self.failed = true;
                Err(e)
            }
        }
    }

    fn consume(&mut self, amt: usize) {
        self.consumed += amt as u64;
        self.inner.consume(amt);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flate2::Compression;
    use flate2::write::GzEncoder;

    fn gzip(bytes: &[u8]) -> Vec<u8> {
        let mut e = GzEncoder::new(Vec::new(), Compression::default());
        e.write_all(bytes).unwrap();
        e.finish().unwrap()
    }

    fn inflate(gz: &[u8]) -> Result<Vec<u8>, Error> {
        let mut f = tempfile::tempfile().unwrap();
        f.write_all(gz).unwrap();
        f.rewind().unwrap();
        let mut out = Vec::new();
        decompress(f, Codec::Gzip, &"t.gz".into(), false)?
            .0
            .read_to_end(&mut out)
            .unwrap();
        Ok(out)
    }

    #[test]
    fn inner_path_drops_only_a_final_gz() {
        assert_eq!(
            inner_path(Path::new("a/1abc.pdb.gz")),
            Path::new("a/1abc.pdb")
        );
        assert_eq!(inner_path(Path::new("run.XYZ.GZ")), Path::new("run.XYZ"));
        assert_eq!(inner_path(Path::new("plain.gro")), Path::new("plain.gro"));
        assert_eq!(inner_path(Path::new("x.gz.pdb")), Path::new("x.gz.pdb"));
    }

    #[test]
    fn members_concatenate_and_every_cut_is_an_error_at_its_offset() {
        let text = b"3\nwater\nO 0 0 0\nH 0.96 0 0\nH -0.24 0.93 0\n".repeat(50);
        let mut two = gzip(&text[..777]);
        two.extend(gzip(&text[777..]));
        assert_eq!(inflate(&two).unwrap(), text);
        // Every proper prefix is cut somewhere: header, deflate data, trailer or between members
        // (a prefix ending exactly after the first member is a whole file of its own).
        let first = gzip(&text[..777]).len();
        for cut in (0..two.len()).filter(|&c| c != first) {
            let e = inflate(&two[..cut]).unwrap_err();
            let Error::Parse { at, .. } = &e else {
                panic!("cut at {cut}: {e:?}");
            };
            assert!(e.to_string().contains("gzip"), "{e}");
            assert!(at.byte.unwrap() <= cut as u64, "cut at {cut}: {e}");
        }
    }
}

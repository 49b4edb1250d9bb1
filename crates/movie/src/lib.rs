//! # texmap-movie — movies from rendered frames
//!
//! A renderer hands frames (8-bit sRGB RGBA, row-major) one at a time to a [`MovieWriter`]; the
//! writer streams them to the file and never holds more than one frame. The output file's
//! extension picks the format ([`Container::from_path`]):
//!
//! | extension | format | written by |
//! |---|---|---|
//! | `.apng` | animated PNG, lossless | this crate (the `png` crate's APNG encoder), no external tool |
//! | `.mp4` | H.264 in MP4 (yuv420p, CRF 18, `+faststart`) | ffmpeg, through a pipe |
//! | `.webm` | VP9 in WebM (constant quality) | ffmpeg |
//! | `.gif` | GIF with a palette made from the whole movie | ffmpeg |
//!
//! ffmpeg is what users have for video (Debian/Ubuntu: `apt-get install ffmpeg`); when it is not
//! on `PATH` the writer says so and suggests `.apng`. Frames are piped raw, so no intermediate
//! image files are written. Odd image sizes are padded by one black row or column for the
//! yuv420p formats, which need even sizes.
//!
//! **No partial files.** The movie is written to a hidden temporary file beside the destination
//! and renamed over it only by [`MovieWriter::finish`] after the encoder succeeded; a writer
//! dropped before that (a failed render) removes the temporary file.
//!
//! ```
//! use texmap_movie::{MovieOptions, MovieWriter};
//!
//! let dir = tempfile::tempdir()?;
//! let path = dir.path().join("spin.apng");
//! let opts = MovieOptions::new(4, 2, 3); // 4x2 pixels, 3 frames
//! let mut movie = MovieWriter::create(&path, &opts)?;
//! for k in 0..3u8 {
//!     movie.push(&[[k * 80, 0, 255 - k * 80, 255]; 8])?;
//! }
//! movie.finish()?;
//! assert!(path.exists());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! **Invariant:** this crate depends on no other crate of ours.

mod error;
mod ffmpeg;

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

pub use error::MovieError;

/// The movie formats, chosen by the output file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Container {
    Apng,
    Mp4,
    Webm,
    Gif,
}

impl Container {
    /// Every format, in the order the help text lists them.
    pub const ALL: [Container; 4] = [
        Container::Mp4,
        Container::Webm,
        Container::Gif,
        Container::Apng,
    ];

    /// The file extension (lower case, no dot).
    pub fn extension(self) -> &'static str {
        match self {
            Container::Apng => "apng",
            Container::Mp4 => "mp4",
            Container::Webm => "webm",
            Container::Gif => "gif",
        }
    }

    /// The format a path's extension names (case-insensitive), `None` for any other extension.
    pub fn from_path(path: &Path) -> Option<Container> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Container::ALL.into_iter().find(|c| c.extension() == ext)
    }

    /// Whether this format needs ffmpeg.
    pub fn needs_ffmpeg(self) -> bool {
        self != Container::Apng
    }
}

/// How a movie is written.
#[derive(Clone, Debug, PartialEq)]
pub struct MovieOptions {
    pub width: u32,
    pub height: u32,
    /// The number of frames that will be pushed (the APNG header states it up front; every
    /// format checks it at [`MovieWriter::finish`], so a short movie is an error, not a surprise).
    pub frames: u32,
    /// Frames per second (default 25).
    pub fps: f64,
    /// The ffmpeg program to run (default `ffmpeg`, found on `PATH`).
    pub ffmpeg: PathBuf,
}

impl MovieOptions {
    /// `frames` frames of `width` x `height` pixels at 25 frames per second.
    pub fn new(width: u32, height: u32, frames: u32) -> MovieOptions {
        MovieOptions {
            width,
            height,
            frames,
            fps: 25.0,
            ffmpeg: PathBuf::from("ffmpeg"),
        }
    }
}

enum Backend {
    Apng(png::Writer<BufWriter<File>>),
    Ffmpeg(ffmpeg::Pipe),
}

/// Writes a movie frame by frame (see the crate docs).
pub struct MovieWriter {
    backend: Option<Backend>,
    dest: PathBuf,
    tmp: PathBuf,
    opts: MovieOptions,
    pushed: u32,
}

impl MovieWriter {
    /// Start a movie at `path`, in the format its extension names.
    ///
    /// Errors: an extension that names no movie format, a zero size or frame count, a frame rate
    /// that is not finite and positive, ffmpeg missing (for the formats that need it), or the
    /// temporary file not creatable.
    pub fn create(path: &Path, opts: &MovieOptions) -> Result<MovieWriter, MovieError> {
        let container = Container::from_path(path).ok_or_else(|| MovieError::UnknownFormat {
            path: path.to_path_buf(),
        })?;
        if opts.width == 0 || opts.height == 0 || opts.frames == 0 {
            return Err(MovieError::BadOptions {
                path: path.to_path_buf(),
                message: format!(
                    "{}x{} pixels and {} frames: need at least one pixel and one frame",
                    opts.width, opts.height, opts.frames
                ),
            });
        }
        if !(opts.fps.is_finite() && opts.fps > 0.0 && opts.fps <= 1000.0) {
            return Err(MovieError::BadOptions {
                path: path.to_path_buf(),
                message: format!("frame rate {} must be in (0, 1000]", opts.fps),
            });
        }
        let tmp = temp_path(path);
        let backend = match container {
            Container::Apng => Backend::Apng(apng_writer(&tmp, opts).inspect_err(|_| {
                let _ = std::fs::remove_file(&tmp);
            })?),
            c => Backend::Ffmpeg(ffmpeg::Pipe::spawn(c, &tmp, path, opts)?),
        };
        Ok(MovieWriter {
            backend: Some(backend),
            dest: path.to_path_buf(),
            tmp,
            opts: opts.clone(),
            pushed: 0,
        })
    }

    /// The frames pushed so far.
    pub fn frames_written(&self) -> u32 {
        self.pushed
    }

    /// Append one frame: `width · height` RGBA pixels (8-bit sRGB), row-major from the top.
    pub fn push(&mut self, rgba: &[[u8; 4]]) -> Result<(), MovieError> {
        let expected = self.opts.width as usize * self.opts.height as usize;
        if rgba.len() != expected {
            return Err(MovieError::FrameSize {
                path: self.dest.clone(),
                frame: self.pushed,
                pixels: rgba.len(),
                expected,
            });
        }
        if self.pushed >= self.opts.frames {
            return Err(MovieError::FrameCount {
                path: self.dest.clone(),
                pushed: self.pushed + 1,
                declared: self.opts.frames,
            });
        }
        let bytes = rgba.as_flattened();
        match self.backend.as_mut().expect("backend present until finish") {
            Backend::Apng(w) => w.write_image_data(bytes).map_err(|e| MovieError::Apng {
                path: self.dest.clone(),
                message: e.to_string(),
            })?,
            Backend::Ffmpeg(p) => p.write_frame(bytes, &self.dest)?,
        }
        self.pushed += 1;
        Ok(())
    }

    /// Close the encoder and move the movie to its destination. Errors when fewer frames were
    /// pushed than declared, or the encoder failed; the destination is then left untouched.
    pub fn finish(mut self) -> Result<PathBuf, MovieError> {
        if self.pushed != self.opts.frames {
            return Err(MovieError::FrameCount {
                path: self.dest.clone(),
                pushed: self.pushed,
                declared: self.opts.frames,
            });
        }
        let closed = match self.backend.take().expect("backend present until finish") {
            Backend::Apng(w) => w.finish().map_err(|e| MovieError::Apng {
                path: self.dest.clone(),
                message: e.to_string(),
            }),
            Backend::Ffmpeg(p) => p.finish(&self.dest),
        };
        let moved = closed.and_then(|()| {
            std::fs::rename(&self.tmp, &self.dest).map_err(|source| MovieError::Io {
                path: self.dest.clone(),
                source,
            })
        });
        if let Err(e) = moved {
            let _ = std::fs::remove_file(&self.tmp);
            return Err(e);
        }
        Ok(self.dest.clone())
    }
}

impl Drop for MovieWriter {
    fn drop(&mut self) {
        // Not finished (a failed render or encoder): leave no partial movie behind.
        if let Some(backend) = self.backend.take() {
            if let Backend::Ffmpeg(p) = backend {
                p.abort();
            }
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// A hidden file beside `path` with the same extension (ffmpeg and viewers go by it).
fn temp_path(path: &Path) -> PathBuf {
    let stem = path
        .file_stem()
        .map_or_else(|| "movie".into(), |n| n.to_string_lossy().into_owned());
    let ext = path
        .extension()
        .map_or_else(String::new, |e| e.to_string_lossy().into_owned());
    path.with_file_name(format!(".{stem}.partial-{}.{ext}", std::process::id()))
}

fn apng_writer(
    tmp: &Path,
    opts: &MovieOptions,
) -> Result<png::Writer<BufWriter<File>>, MovieError> {
    let file = File::create(tmp).map_err(|source| MovieError::Io {
        path: tmp.to_path_buf(),
        source,
    })?;
    let png_err = |e: png::EncodingError| MovieError::Apng {
        path: tmp.to_path_buf(),
        message: e.to_string(),
    };
    let mut enc = png::Encoder::new(BufWriter::new(file), opts.width, opts.height);
    enc.set_color(png::ColorType::Rgba);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_animated(opts.frames, 0).map_err(png_err)?;
    // The frame delay as a fraction of a second: 1/fps, in hundredths for non-integer rates.
    let (num, den) = if opts.fps.fract() == 0.0 && opts.fps <= u16::MAX as f64 {
        (1, opts.fps as u16)
    } else {
        (
            100,
            (opts.fps * 100.0).round().clamp(1.0, u16::MAX as f64) as u16,
        )
    };
    enc.set_frame_delay(num, den).map_err(png_err)?;
    enc.write_header().map_err(png_err)
}

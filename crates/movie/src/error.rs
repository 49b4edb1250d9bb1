//! The crate's one error type; every variant names the movie file.

use std::path::PathBuf;

/// What went wrong writing a movie.
#[derive(Debug)]
#[non_exhaustive]
pub enum MovieError {
    /// The extension names no movie format.
    UnknownFormat { path: PathBuf },
    /// Size, frame count or frame rate out of range.
    BadOptions { path: PathBuf, message: String },
    /// A pushed frame has the wrong number of pixels.
    FrameSize {
        path: PathBuf,
        frame: u32,
        pixels: usize,
        expected: usize,
    },
    /// More or fewer frames than declared.
    FrameCount {
        path: PathBuf,
        pushed: u32,
        declared: u32,
    },
    /// The format needs ffmpeg and it cannot be started.
    EncoderMissing {
        path: PathBuf,
        program: PathBuf,
        source: std::io::Error,
    },
    /// ffmpeg stopped with an error (the end of what it printed is kept).
    Encoder {
        path: PathBuf,
        status: String,
        stderr: String,
    },
    /// The APNG encoder refused the data.
    Apng { path: PathBuf, message: String },
    /// A file could not be written or moved.
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

impl std::fmt::Display for MovieError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MovieError::UnknownFormat { path } => write!(
                f,
                "{}: the extension names no movie format (use .mp4, .webm, .gif or .apng)",
                path.display()
            ),
            MovieError::BadOptions { path, message } => write!(f, "{}: {message}", path.display()),
            MovieError::FrameSize {
                path,
                frame,
                pixels,
                expected,
            } => write!(
                f,
                "{}: frame {frame} has {pixels} pixels, the movie's size needs {expected}",
                path.display()
            ),
            MovieError::FrameCount {
                path,
                pushed,
                declared,
            } => write!(
                f,
                "{}: {pushed} frames given for a movie declared with {declared}",
                path.display()
            ),
            MovieError::EncoderMissing {
                path,
                program,
                source,
            } => write!(
                f,
                "{}: cannot run {} ({source}); movies in this format are encoded by ffmpeg: \
                 install it (Debian/Ubuntu: apt-get install ffmpeg) or write an animated PNG \
                 (-o movie.apng), which needs no external program",
                path.display(),
                program.display()
            ),
            MovieError::Encoder {
                path,
                status,
                stderr,
            } => write!(
                f,
                "{}: ffmpeg failed ({status}): {}",
                path.display(),
                stderr.trim()
            ),
            MovieError::Apng { path, message } => {
                write!(f, "{}: APNG: {message}", path.display())
            }
            MovieError::Io { path, source } => write!(f, "{}: {source}", path.display()),
        }
    }
}

impl std::error::Error for MovieError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            MovieError::EncoderMissing { source, .. } | MovieError::Io { source, .. } => {
                Some(source)
            }
            _ => None,
        }
    }
}

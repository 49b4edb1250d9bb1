//! Where rendered frames go: PNG images (one per frame, a `%04d` pattern or `_NNNN` names) or one
//! movie file whose extension names its format (`texmap-movie`), and `texmap movie`, which turns a
//! directory of PNG frames into a movie (the last step of a sharded render).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use texmap_core::frame::Frame;
use texmap_movie::{Container, MovieOptions, MovieWriter};

use crate::args::UsageError;
use crate::output::{frame_path, write_png};

/// What `-o` asks for, decided from its extension before any frame is drawn.
pub enum Sink {
    /// PNG images; the path may hold a `%04d` pattern; `dpi` goes into each.
    Frames {
        pattern: PathBuf,
        multi: bool,
        dpi: Option<f32>,
    },
    /// One movie; the writer is opened at the first frame, when the image size is known.
    Movie {
        path: PathBuf,
        frames: u32,
        fps: f64,
        writer: Option<Box<MovieWriter>>,
    },
}

impl Sink {
    /// The sink for output path `out` and `frames` frames. Extensions other than `.png` and the
    /// movie formats are refused (a usage error), as are `--depth` and `--dpi` with a movie.
    pub fn new(out: &Path, frames: usize, fps: f64, depth: bool, dpi: Option<f32>) -> Result<Sink> {
        let ext = out
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        if Container::from_path(out).is_some() {
            if depth {
                return Err(UsageError(format!(
                    "{}: --depth writes one EXR per frame beside PNG frames; it cannot go into a movie \
                     (render PNG frames with --depth, then texmap movie)",
                    out.display()
                ))
                .into());
            }
            if dpi.is_some() {
                return Err(UsageError(format!(
                    "{}: --dpi is a print resolution for PNG images; a movie has none",
                    out.display()
                ))
                .into());
            }
            if !(fps.is_finite() && fps > 0.0 && fps <= 1000.0) {
                return Err(UsageError(format!("--fps {fps}: must be in (0, 1000]")).into());
            }
            return Ok(Sink::Movie {
                path: out.to_path_buf(),
                frames: u32::try_from(frames).context("too many frames for one movie")?,
                fps,
                writer: None,
            });
        }
        match ext.as_deref() {
            Some("png") => Ok(Sink::Frames {
                pattern: out.to_path_buf(),
                multi: frames > 1,
                dpi,
            }),
            _ => Err(UsageError(format!(
                "{}: the output's extension decides what is written: .png for images (with %04d for \
                 a frame number), or a movie: .mp4, .webm, .gif (through ffmpeg) or .apng",
                out.display()
            ))
            .into()),
        }
    }

    /// Write frame number `f` (its index in the trajectory); returns the files written.
    pub fn write(&mut self, f: usize, frame: &Frame, depth: bool) -> Result<Vec<PathBuf>> {
        match self {
            Sink::Frames {
                pattern,
                multi,
                dpi,
            } => {
                let path = frame_path(pattern, f, *multi)?;
                match dpi {
                    Some(dpi) => crate::output::write_png_dpi(frame, &path, *dpi)?,
                    None => write_png(frame, &path)?,
                }
                let mut out = vec![path.clone()];
                if depth {
                    let exr = path.with_extension("exr");
                    crate::output::write_depth_exr(frame, &exr)?;
                    out.push(exr);
                }
                Ok(out)
            }
            Sink::Movie {
                path,
                frames,
                fps,
                writer,
            } => {
                if writer.is_none() {
                    let mut o = MovieOptions::new(frame.width(), frame.height(), *frames);
                    o.fps = *fps;
                    *writer = Some(Box::new(MovieWriter::create(path, &o)?));
                }
                writer.as_mut().expect("opened above").push(&frame.color)?;
                Ok(Vec::new())
            }
        }
    }

    /// Close the movie (nothing to do for PNG frames); returns the movie's path.
    pub fn finish(self) -> Result<Option<PathBuf>> {
        match self {
            Sink::Frames { .. } => Ok(None),
            Sink::Movie { writer, path, .. } => match writer {
                Some(w) => Ok(Some(w.finish()?)),
                None => bail!(
                    "{}: no frame was drawn, so no movie was written",
                    path.display()
                ),
            },
        }
    }
}

/// The PNG frames of `dir` in the order a movie plays them: file names sorted with their digit
/// runs compared as numbers (`f2.png` before `f10.png`).
pub fn frame_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let entries = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read directory {}", dir.display()))?;
    let mut files = Vec::new();
    for e in entries {
        let e = e.with_context(|| format!("cannot read directory {}", dir.display()))?;
        let p = e.path();
        let is_png = p.extension().is_some_and(|x| x.eq_ignore_ascii_case("png"));
        let hidden = p
            .file_name()
            .is_some_and(|n| n.to_string_lossy().starts_with('.'));
        if is_png && !hidden && p.is_file() {
            files.push(p);
        }
    }
    let name = |p: &PathBuf| {
        p.file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned()
    };
    files.sort_by(|a, b| texmap_md_io::sequence::natural_cmp(&name(a), &name(b)));
    Ok(files)
}

/// `texmap movie DIR -o OUT`: every PNG frame of `dir`, in order, into the movie `out`.
pub fn assemble(dir: &Path, out: &Path, fps: f64) -> Result<()> {
    if Container::from_path(out).is_none() {
        return Err(UsageError(format!(
            "{}: a movie's extension must be .mp4, .webm, .gif or .apng",
            out.display()
        ))
        .into());
    }
    let files = frame_files(dir)?;
    if files.is_empty() {
        bail!("{}: no PNG frame in this directory", dir.display());
    }
    let pb = crate::commands::progress(files.len() as u64, "encoding");
    let mut sink = Sink::new(out, files.len(), fps, false, None)?;
    let mut size: Option<(u32, u32)> = None;
    for (k, path) in files.iter().enumerate() {
        let img = image::open(path)
            .with_context(|| format!("{}: cannot read the PNG frame", path.display()))?
            .to_rgba8();
        let (w, h) = img.dimensions();
        if let Some((w0, h0)) = size
            && (w, h) != (w0, h0)
        {
            bail!(
                "{}: {w}x{h} pixels, but the first frame ({}) is {w0}x{h0}: a movie's frames share one size",
                path.display(),
                files[0].display()
            );
        }
        size = Some((w, h));
        let mut frame = Frame::new(w, h, [0, 0, 0, 255]);
        for (dst, src) in frame.color.iter_mut().zip(img.pixels()) {
            *dst = src.0;
        }
        sink.write(k, &frame, false)?;
        pb.inc(1);
    }
    pb.finish_and_clear();
    sink.finish()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_sort_by_their_numbers() {
        let mut v = vec!["f10.png", "f2.png", "f1.png", "a.png", "f02b.png"];
        v.sort_by(|a, b| texmap_md_io::sequence::natural_cmp(a, b));
        assert_eq!(v, ["a.png", "f1.png", "f2.png", "f02b.png", "f10.png"]);
    }

    #[test]
    fn the_extension_decides_and_unknown_ones_are_refused() {
        let movie = Sink::new(Path::new("m.mp4"), 3, 25.0, false, None).unwrap();
        assert!(matches!(movie, Sink::Movie { .. }));
        let frames = Sink::new(Path::new("f%04d.png"), 3, 25.0, false, None).unwrap();
        assert!(matches!(frames, Sink::Frames { .. }));
        for bad in ["x.jpg", "noext", "movie.mp4.bak"] {
            let e = Sink::new(Path::new(bad), 3, 25.0, false, None)
                .err()
                .unwrap();
            assert!(e.downcast_ref::<UsageError>().is_some(), "{bad}: {e}");
        }
        assert!(Sink::new(Path::new("m.gif"), 3, 25.0, true, None).is_err());
        assert!(Sink::new(Path::new("m.gif"), 3, 0.0, false, None).is_err());
    }
}

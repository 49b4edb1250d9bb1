//! Files out: PNG colour, EXR depth, output-name patterns. Every file is written to a temporary
//! name beside its destination and renamed into place only when complete, so an interrupted or
//! failed run never leaves a partial image under the final name.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use texmap_core::frame::Frame;

/// Expand a printf-style frame pattern: the first `%0Nd` or `%d` becomes the frame number.
/// Without a pattern, a multi-frame render inserts `_NNNN` before the extension.
pub fn frame_path(pattern: &Path, frame: usize, multi: bool) -> Result<PathBuf> {
    let s = pattern.to_string_lossy();
    if let Some(start) = s.find('%') {
        let rest = &s[start + 1..];
        let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
        let after = &rest[digits.len()..];
        if !after.starts_with('d') {
            bail!("output pattern {s:?}: after '%' expected digits then 'd' (as in %04d)");
        }
        let width: usize = if digits.is_empty() {
            0
        } else {
            digits.parse().context("pattern width")?
        };
        if width > 12 {
            bail!("output pattern {s:?}: width {width} is absurd (at most 12 digits)");
        }
        let num = format!("{frame:0width$}");
        return Ok(PathBuf::from(format!(
            "{}{}{}",
            &s[..start],
            num,
            &after[1..]
        )));
    }
    if !multi {
        return Ok(pattern.to_path_buf());
    }
    let stem = pattern
        .file_stem()
        .map(|x| x.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = pattern
        .extension()
        .map(|x| format!(".{}", x.to_string_lossy()))
        .unwrap_or_default();
    Ok(pattern.with_file_name(format!("{stem}_{frame:04}{ext}")))
}

fn temp_beside(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    path.with_file_name(format!(".{name}.partial-{}", std::process::id()))
}

/// Write `bytes` to `path` atomically (temporary file + rename).
pub fn write_atomic(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create directory {}", dir.display()))?;
    }
    let tmp = temp_beside(path);
    let result = write(&tmp).and_then(|()| {
        std::fs::rename(&tmp, path)
            .with_context(|| format!("cannot move {} into place", path.display()))
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// A file written piece by piece (a table growing frame by frame) under a temporary name beside
/// its destination, moved into place by [`AtomicFile::commit`]; dropped without it (an error on
/// the way), it removes the temporary file, so no partial file is left under either name.
pub struct AtomicFile {
    path: PathBuf,
    tmp: PathBuf,
    out: Option<std::io::BufWriter<std::fs::File>>,
}

impl AtomicFile {
    /// Start writing `path` (its directory created if needed).
    pub fn create(path: &Path) -> Result<AtomicFile> {
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create directory {}", dir.display()))?;
        }
        let tmp = temp_beside(path);
        let file = std::fs::File::create(&tmp)
            .with_context(|| format!("cannot write {}", path.display()))?;
        Ok(AtomicFile {
            path: path.to_path_buf(),
            tmp,
            out: Some(std::io::BufWriter::new(file)),
        })
    }

    /// Append `text`.
    pub fn write(&mut self, text: &str) -> Result<()> {
        use std::io::Write;
        let out = self.out.as_mut().expect("open until committed");
        out.write_all(text.as_bytes())
            .with_context(|| format!("cannot write {}", self.path.display()))
    }

    /// Flush and move the file into place.
    pub fn commit(mut self) -> Result<()> {
        let out = self.out.take().expect("open until committed");
        let done = out
            .into_inner()
            .map_err(|e| e.into_error())
            .and_then(|f| f.sync_all())
            .with_context(|| format!("cannot write {}", self.path.display()))
            .and_then(|()| {
                std::fs::rename(&self.tmp, &self.path)
                    .with_context(|| format!("cannot move {} into place", self.path.display()))
            });
        if done.is_err() {
            let _ = std::fs::remove_file(&self.tmp);
        }
        done
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if self.out.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Write the colour of a frame as an 8-bit sRGB RGBA PNG.
pub fn write_png(frame: &Frame, path: &Path) -> Result<()> {
    write_atomic(path, |tmp| {
        image::save_buffer_with_format(
            tmp,
            frame.color_bytes(),
            frame.width(),
            frame.height(),
            image::ExtendedColorType::Rgba8,
            image::ImageFormat::Png,
        )
        .with_context(|| format!("cannot write PNG {}", path.display()))
    })
}

/// [`write_png`] with the print resolution `dpi` in the PNG's pHYs chunk (pixels per metre,
/// the unit the PNG specification gives), through the png crate (the image crate writes no
/// pHYs).
pub fn write_png_dpi(frame: &Frame, path: &Path, dpi: f32) -> Result<()> {
    write_atomic(path, |tmp| {
        let file = std::fs::File::create(tmp)
            .with_context(|| format!("cannot create {}", tmp.display()))?;
        let mut enc =
            png::Encoder::new(std::io::BufWriter::new(file), frame.width(), frame.height());
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        let per_metre = (dpi as f64 / 0.0254).round() as u32;
        enc.set_pixel_dims(Some(png::PixelDimensions {
            xppu: per_metre,
            yppu: per_metre,
            unit: png::Unit::Meter,
        }));
        let mut w = enc
            .write_header()
            .with_context(|| format!("cannot write PNG {}", path.display()))?;
        w.write_image_data(frame.color_bytes())
            .with_context(|| format!("cannot write PNG {}", path.display()))?;
        w.finish()
            .with_context(|| format!("cannot write PNG {}", path.display()))
    })
}

/// Write the depth of a frame as a one-channel (`Z`, f32) OpenEXR file; uncovered pixels hold
/// +infinity, as OpenEXR depth conventions expect for "no surface".
pub fn write_depth_exr(frame: &Frame, path: &Path) -> Result<()> {
    use exr::prelude::*;
    let w = frame.width() as usize;
    let depth = &frame.depth;
    write_atomic(path, |tmp| {
        let channels = SpecificChannels::build()
            .with_channel("Z")
            .with_pixel_fn(|p: Vec2<usize>| (depth[p.y() * w + p.x()],));
        Image::from_channels((w, frame.height() as usize), channels)
            .write()
            .to_file(tmp)
            .with_context(|| format!("cannot write EXR {}", path.display()))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_expand() {
        let p = |s: &str, f, m| frame_path(Path::new(s), f, m).unwrap();
        assert_eq!(p("out/f%04d.png", 7, true), PathBuf::from("out/f0007.png"));
        assert_eq!(p("f%d.png", 12, true), PathBuf::from("f12.png"));
        assert_eq!(p("one.png", 3, false), PathBuf::from("one.png"));
        assert_eq!(p("dir/a.png", 3, true), PathBuf::from("dir/a_0003.png"));
        assert!(frame_path(Path::new("f%s.png"), 1, true).is_err());
    }

    #[test]
    fn png_and_exr_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let mut f = Frame::new(5, 3, [10, 20, 30, 255]);
        f.depth[4] = 2.5;
        let png = dir.path().join("a.png");
        write_png(&f, &png).unwrap();
        let img = image::open(&png).unwrap().to_rgba8();
        assert_eq!(img.dimensions(), (5, 3));
        assert_eq!(img.get_pixel(1, 1).0, [10, 20, 30, 255]);
        let exr_path = dir.path().join("d.exr");
        write_depth_exr(&f, &exr_path).unwrap();
        let back = exr::prelude::read_first_flat_layer_from_file(&exr_path).unwrap();
        let ch = &back.layer_data.channel_data.list[0];
        assert_eq!(ch.name, exr::prelude::Text::from("Z"));
        let v: Vec<f32> = ch.sample_data.values_as_f32().collect();
        assert_eq!(v[4], 2.5);
        assert!(v[0].is_infinite());
        // No partial files left behind.
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 2);
    }
}

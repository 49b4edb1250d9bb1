//! Movies written by this crate, read back by another program (ffmpeg decodes every format to raw
//! RGBA), and the failure modes: no partial file, clear errors.
//!
//! Where ffmpeg is not installed the ffmpeg formats cannot be tested: those tests say so on
//! stderr and pass; the APNG test then decodes with the `png` crate instead.

use std::path::Path;
use std::process::Command;

use texmap_movie::{Container, MovieError, MovieOptions, MovieWriter};

fn ffmpeg_available() -> bool {
    Command::new("ffmpeg")
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success())
}

fn skip(what: &str) {
    eprintln!("SKIPPED {what}: ffmpeg is not installed (Debian/Ubuntu: apt-get install ffmpeg)");
}

/// A test pattern that moves with `k`: smooth gradients plus a moving bright square.
fn pattern(w: u32, h: u32, k: u32) -> Vec<[u8; 4]> {
    let mut v = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let inside = x.abs_diff(4 + 3 * k) < 5 && y.abs_diff(h / 2) < 5;
            v.push(if inside {
                [250, 240, 40, 255]
            } else {
                [
                    (x * 255 / w) as u8,
                    (y * 255 / h) as u8,
                    ((k * 20) % 256) as u8,
                    255,
                ]
            });
        }
    }
    v
}

/// Every frame of `path` as RGBA, decoded by ffmpeg; with the decoded size.
fn ffmpeg_decode(path: &Path) -> (u32, u32, Vec<Vec<u8>>) {
    let probe = Command::new("ffprobe")
        .args(["-v", "error", "-select_streams", "v:0", "-show_entries"])
        .args(["stream=width,height", "-of", "csv=p=0"])
        .arg(path)
        .output()
        .expect("ffprobe runs");
    let text = String::from_utf8(probe.stdout).unwrap();
    let mut it = text.trim().split(',').map(|s| s.parse::<u32>().unwrap());
    let (w, h) = (it.next().unwrap(), it.next().unwrap());
    let out = Command::new("ffmpeg")
        .args(["-v", "error", "-i"])
        .arg(path)
        .args(["-f", "rawvideo", "-pix_fmt", "rgba", "pipe:1"])
        .output()
        .expect("ffmpeg runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let size = (w * h * 4) as usize;
    assert_eq!(out.stdout.len() % size, 0);
    (w, h, out.stdout.chunks(size).map(<[u8]>::to_vec).collect())
}

/// PSNR of the luma (Rec. 601 weights) over the `w` x `h` top-left region of a decoded frame of
/// width `dw`. Luma, because yuv420p keeps chroma at half resolution by design: sharp colour
/// edges lose chroma in every such movie, and that loss is the format's, not the writer's.
fn luma_psnr(original: &[[u8; 4]], w: u32, h: u32, decoded: &[u8], dw: u32) -> f64 {
    let y = |r: u8, g: u8, b: u8| 0.299 * r as f64 + 0.587 * g as f64 + 0.114 * b as f64;
    let mut se = 0.0f64;
    for py in 0..h {
        for px in 0..w {
            let a = original[(py * w + px) as usize];
            let i = ((py * dw + px) * 4) as usize;
            let d = y(a[0], a[1], a[2]) - y(decoded[i], decoded[i + 1], decoded[i + 2]);
            se += d * d;
        }
    }
    let mse = se / (w * h) as f64;
    if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0f64 * 255.0 / mse).log10()
    }
}

fn write(path: &Path, w: u32, h: u32, frames: u32) -> Vec<Vec<[u8; 4]>> {
    let opts = MovieOptions::new(w, h, frames);
    let mut movie = MovieWriter::create(path, &opts).expect("movie starts");
    let mut all = Vec::new();
    for k in 0..frames {
        let f = pattern(w, h, k);
        movie.push(&f).expect("frame written");
        all.push(f);
    }
    assert_eq!(movie.frames_written(), frames);
    movie.finish().expect("movie finishes");
    all
}

#[test]
fn animated_png_is_lossless_frame_for_frame() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.apng");
    // Odd sizes: APNG has no even-size constraint.
    let frames = write(&path, 37, 23, 7);
    if ffmpeg_available() {
        let (w, h, decoded) = ffmpeg_decode(&path);
        assert_eq!((w, h), (37, 23));
        assert_eq!(decoded.len(), 7, "ffmpeg decodes every frame");
        for (k, (a, b)) in frames.iter().zip(&decoded).enumerate() {
            assert_eq!(a.as_flattened(), &b[..], "frame {k} differs");
        }
    } else {
        skip("APNG decoding by ffmpeg (decoded with the png crate instead)");
        let dec = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
        let mut reader = dec.read_info().unwrap();
        assert_eq!(reader.info().animation_control().unwrap().num_frames, 7);
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        for (k, a) in frames.iter().enumerate() {
            reader.next_frame(&mut buf).unwrap();
            assert_eq!(a.as_flattened(), &buf[..], "frame {k} differs");
        }
    }
    // No temporary file is left beside the movie.
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(names.len(), 1);
}

#[test]
fn mp4_webm_and_gif_decode_to_the_frames_within_their_loss() {
    if !ffmpeg_available() {
        return skip("MP4/WebM/GIF round trips");
    }
    let dir = tempfile::tempdir().unwrap();
    // (format, minimum luma PSNR over every frame; measured 42.8, 40.6 and 28.0 dB here): H.264
    // at CRF 18 and VP9 at CRF 30 keep the pattern well above 34 dB; GIF's 256-colour palette
    // with dithering costs more.
    for (ext, min_db) in [("mp4", 38.0), ("webm", 34.0), ("gif", 26.0)] {
        let path = dir.path().join(format!("m.{ext}"));
        let frames = write(&path, 64, 48, 12);
        let (w, h, decoded) = ffmpeg_decode(&path);
        assert_eq!((w, h), (64, 48), "{ext}");
        assert_eq!(decoded.len(), 12, "{ext}: frame count");
        let worst = frames
            .iter()
            .zip(&decoded)
            .map(|(a, b)| luma_psnr(a, 64, 48, b, w))
            .fold(f64::INFINITY, f64::min);
        eprintln!("{ext}: worst frame PSNR {worst:.2} dB");
        assert!(worst >= min_db, "{ext}: {worst:.2} dB < {min_db} dB");
    }
}

#[test]
fn odd_sizes_are_padded_for_yuv420p_and_the_picture_kept() {
    if !ffmpeg_available() {
        return skip("odd-size MP4");
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("odd.mp4");
    let frames = write(&path, 63, 47, 3);
    let (w, h, decoded) = ffmpeg_decode(&path);
    assert_eq!((w, h), (64, 48), "padded to even");
    for (a, b) in frames.iter().zip(&decoded) {
        let db = luma_psnr(a, 63, 47, b, w);
        assert!(db >= 33.0, "{db:.2} dB");
    }
}

#[test]
fn bad_extensions_sizes_and_counts_are_clear_errors_and_leave_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let e = MovieWriter::create(&dir.path().join("x.png"), &MovieOptions::new(4, 4, 2))
        .err()
        .expect("png is not a movie");
    assert!(matches!(e, MovieError::UnknownFormat { .. }), "{e}");
    assert!(e.to_string().contains(".apng"), "{e}");
    assert_eq!(
        Container::from_path(Path::new("a/b.MP4")),
        Some(Container::Mp4)
    );
    assert_eq!(Container::from_path(Path::new("noext")), None);

    let path = dir.path().join("short.apng");
    let mut m = MovieWriter::create(&path, &MovieOptions::new(4, 4, 3)).unwrap();
    let e = m.push(&[[0; 4]; 15]).unwrap_err();
    assert!(e.to_string().contains("15 pixels"), "{e}");
    m.push(&[[0; 4]; 16]).unwrap();
    let e = m.finish().unwrap_err();
    assert!(
        matches!(
            e,
            MovieError::FrameCount {
                pushed: 1,
                declared: 3,
                ..
            }
        ),
        "{e}"
    );
    assert!(!path.exists(), "a short movie must not be left behind");

    // A writer dropped mid-movie (a failed render) removes its temporary file.
    let path = dir.path().join("dropped.apng");
    let mut m = MovieWriter::create(&path, &MovieOptions::new(4, 4, 3)).unwrap();
    m.push(&[[9; 4]; 16]).unwrap();
    drop(m);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);

    let mut o = MovieOptions::new(4, 4, 3);
    o.fps = 0.0;
    assert!(MovieWriter::create(&dir.path().join("z.apng"), &o).is_err());
}

#[test]
fn a_missing_encoder_says_how_to_get_one() {
    let dir = tempfile::tempdir().unwrap();
    let mut o = MovieOptions::new(8, 8, 2);
    o.ffmpeg = dir.path().join("no-such-ffmpeg");
    let e = MovieWriter::create(&dir.path().join("m.mp4"), &o)
        .err()
        .expect("no encoder");
    let msg = e.to_string();
    assert!(matches!(e, MovieError::EncoderMissing { .. }), "{msg}");
    assert!(
        msg.contains("apt-get install ffmpeg") && msg.contains(".apng"),
        "{msg}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn an_encoder_failure_is_reported_with_what_it_said() {
    if !ffmpeg_available() {
        return skip("encoder failure report");
    }
    // A GIF of 2 frames whose directory vanishes before ffmpeg writes: ffmpeg fails at the end.
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("gone");
    std::fs::create_dir(&sub).unwrap();
    let path = sub.join("m.gif");
    let mut m = MovieWriter::create(&path, &MovieOptions::new(8, 8, 2)).unwrap();
    std::fs::remove_dir_all(&sub).unwrap();
    let pushed = m.push(&[[1; 4]; 64]).and_then(|()| m.push(&[[2; 4]; 64]));
    let e = match pushed {
        Err(e) => e,
        Ok(()) => m.finish().unwrap_err(),
    };
    assert!(
        matches!(e, MovieError::Encoder { .. } | MovieError::Io { .. }),
        "{e}"
    );
    assert!(e.to_string().contains("m.gif"), "{e}");
}

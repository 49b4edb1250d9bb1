//! What every target checks: a mutant opens, counts, streams and seeks through the public API,
//! strict and with `allow_truncated`, and ends in `Ok` or an error that names the file and the
//! place. Anything else (a panic, an unlocated error, a frame that breaks its invariants, a
//! coordinate beyond the readers' bound) aborts, which libFuzzer reports as a crash; memory is
//! bounded by libFuzzer's `-malloc_limit_mb` / `-rss_limit_mb`.

use std::io::Cursor;

use texmap_md_io::{Error, Format, Frame, MAX_COORDINATE, ReadOptions, Trajectory};

const NAME: &str = "fuzz";

fn check_located(e: &Error) {
    let at = e
        .location()
        .unwrap_or_else(|| panic!("an error without a location: {e}"));
    assert_eq!(&*at.file, NAME, "{e}");
    assert!(
        at.byte.is_some() || at.line.is_some(),
        "no byte or line: {e}"
    );
}

fn read(data: &[u8], format: Format, options: ReadOptions) {
    let mut t = match Trajectory::from_reader_with(Cursor::new(data), format, NAME, options) {
        Ok(t) => t,
        Err(e) => return check_located(&e),
    };
    let count = t.n_frames();
    if let Err(e) = &count {
        check_located(e);
    }
    let mut f = Frame::new();
    let mut k = 0usize;
    loop {
        match t.read_next(&mut f) {
            Ok(true) => {
                if let Err(why) = f.check() {
                    panic!("frame {k}: {why}");
                }
                let limit = MAX_COORDINATE as f32;
                assert!(
                    f.positions.iter().flatten().all(|v| v.abs() <= limit),
                    "frame {k}: a coordinate beyond the bound"
                );
                k += 1;
            }
            Ok(false) => break,
            Err(e) => {
                check_located(&e);
                assert_eq!(e.location().and_then(|at| at.frame), Some(k), "{e}");
                return;
            }
        }
    }
    let n = count.expect("n_frames failed but every frame streamed");
    assert_eq!(n, k, "n_frames and streaming disagree");
    if n > 0 {
        t.read_frame(n - 1, &mut f)
            .expect("a streamed frame by index");
        t.read_frame(0, &mut f).expect("frame 0 by index");
    }
}

/// Reads `data` as `format`, strict and lenient.
pub fn run(data: &[u8], format: Format) {
    read(data, format, ReadOptions::new());
    read(data, format, ReadOptions::new().allow_truncated(true));
}

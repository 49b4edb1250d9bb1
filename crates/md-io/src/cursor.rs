//! What the binary readers (DCD, XTC, TRR, NetCDF, GSD) share: the coordinate and GROMACS-box
//! checks, and the frame cursor: their frame index is complete at open time, and a damaged frame
//! right after the last good one still counts as present, so that reading it reports the damage
//! instead of a silent end.

use std::sync::Arc;

use crate::error::{Error, Location};
use crate::frame::{Frame, MAX_COORDINATE, UnitCell};

/// Point `next` at frame `n` when it exists: `n < complete`, or `n == complete` with a damaged
/// tail. Returns whether it does.
pub(crate) fn seek(next: &mut usize, n: usize, complete: usize, damaged_tail: bool) -> bool {
    if n < complete || (n == complete && damaged_tail) {
        *next = n;
        true
    } else {
        false
    }
}

/// What `read_next` answers at frame `k` when it is not one of the `complete` frames: the error
/// of the first cut frame (`cut` makes it, called only here) at `k == complete`, else the end;
/// `None` when frame `k` is to be read.
pub(crate) fn past_complete(
    k: usize,
    complete: usize,
    cut: impl FnOnce() -> Option<Error>,
) -> Option<Result<bool, Error>> {
    if k < complete {
        return None;
    }
    Some(match cut() {
        Some(e) if k == complete => Err(e),
        _ => Ok(false),
    })
}

/// Finish a frame read: on success store the cell and advance; on error leave `frame` empty and
/// the cursor at the damaged frame.
pub(crate) fn settle(
    read: Result<Option<UnitCell>, Error>,
    frame: &mut Frame,
    next: &mut usize,
) -> Result<bool, Error> {
    match read {
        Ok(cell) => {
            frame.cell = cell;
            *next += 1;
            Ok(true)
        }
        Err(e) => {
            frame.clear();
            Err(e)
        }
    }
}

/// True if every value is finite and within ±[`MAX_COORDINATE`] Å (branch-free over chunks of 8
/// values; NaN fails the comparison).
pub(crate) fn all_in_bounds(p: &[[f32; 3]]) -> bool {
    const MAX: f32 = MAX_COORDINATE as f32;
    let flat = p.as_flattened();
    let mut chunks = flat.chunks_exact(8);
    let mut ok = true;
    for c in &mut chunks {
        let mut lane = true;
        for v in c {
            lane &= v.abs() <= MAX;
        }
        ok &= lane;
    }
    ok && chunks.remainder().iter().all(|v| v.abs() <= MAX)
}

/// The first atom whose position is not finite or beyond ±[`MAX_COORDINATE`] Å.
pub(crate) fn first_out_of_bounds(p: &[[f32; 3]]) -> Option<usize> {
    const MAX: f32 = MAX_COORDINATE as f32;
    p.iter().position(|a| !a.iter().all(|v| v.abs() <= MAX))
}

/// What a reader reports for an atom out of bounds.
pub(crate) const IN_BOUNDS: &str = "finite coordinates within ±1e7 Å";

/// True if every value is finite (branch-free over chunks of 8 values).
pub(crate) fn all_finite(p: &[[f32; 3]]) -> bool {
    let flat = p.as_flattened();
    let mut chunks = flat.chunks_exact(8);
    let mut ok = true;
    for c in &mut chunks {
        let mut lane = true;
        for v in c {
            lane &= v.is_finite();
        }
        ok &= lane;
    }
    ok && chunks.remainder().iter().all(|v| v.is_finite())
}

/// The cell of a GROMACS box (rows, Å); an all-zero box means none.
pub(crate) fn cell_of(
    m: [[f64; 3]; 3],
    file: &Arc<str>,
    index: usize,
    byte: u64,
) -> Result<Option<UnitCell>, Error> {
    if m.as_flattened().iter().all(|v| *v == 0.0) {
        return Ok(None);
    }
    UnitCell::from_matrix(m)
        .map(Some)
        .map_err(|e| Error::Parse {
            at: Location::binary(file, index, byte),
            expected: "box vectors with volume > 0",
            found: e.to_string(),
        })
}

//! The frame cursor the binary readers (DCD, XTC, TRR) share: their frame index is complete at
//! open time, and a damaged frame right after the last good one still counts as present, so
//! that reading it reports the damage instead of a silent end.

use crate::error::Error;
use crate::frame::{Frame, UnitCell};

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

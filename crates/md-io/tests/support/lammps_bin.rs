//! The frames of a LAMMPS binary dump as LAMMPS 29 Sep 2021 writes them (little-endian, format
//! revision 2: magic header, units, time, column names), walked from LAMMPS's `header_binary*`
//! and `write_binary` layout independently of the reader under test, and the older layouts
//! (no magic header; revision 1) and the big-endian twin rebuilt from such a file.

/// Where the parts of one frame are (byte offsets from the start of the file).
pub struct BinFrame {
    pub start: usize,
    pub endian: usize,
    pub revision: usize,
    pub step: usize,
    pub natoms: usize,
    pub triclinic: usize,
    pub boundary: usize,
    /// The box values (6, 9 or 12 doubles).
    pub box_at: usize,
    pub box_len: usize,
    pub size_one: usize,
    /// The unit style's length (an i32), then its bytes.
    pub units: usize,
    /// The time flag (a byte), then the time when it is 1.
    pub time_flag: usize,
    pub time: Option<usize>,
    /// The column names' length (an i32), then the names.
    pub columns: usize,
    pub nchunk: usize,
    /// Each chunk's count (an i32) and values: (count byte, values byte, values).
    pub chunks: Vec<(usize, usize, usize)>,
    pub end: usize,
}

fn i32_at(b: &[u8], at: usize) -> i32 {
    i32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

fn i64_at(b: &[u8], at: usize) -> i64 {
    i64::from_le_bytes(b[at..at + 8].try_into().unwrap())
}

/// Every frame of a revision-2, little-endian binary dump.
pub fn walk(b: &[u8]) -> Vec<BinFrame> {
    let mut out = Vec::new();
    let mut at = 0;
    while at < b.len() {
        let start = at;
        let marker = i64_at(b, at);
        assert!(marker < 0, "byte {at}: a magic header");
        at += 8 + marker.unsigned_abs() as usize;
        let (endian, revision, step, natoms, triclinic) = (at, at + 4, at + 8, at + 16, at + 24);
        assert_eq!(i32_at(b, endian), 1);
        assert_eq!(i32_at(b, revision), 2);
        let boundary = at + 28;
        let box_at = at + 52;
        let box_len = 8 * [6, 9, 12][i32_at(b, triclinic) as usize];
        let size_one = box_at + box_len;
        let units = size_one + 4;
        let time_flag = units + 4 + i32_at(b, units) as usize;
        let time = (b[time_flag] == 1).then_some(time_flag + 1);
        let columns = time_flag + 1 + if time.is_some() { 8 } else { 0 };
        let nchunk = columns + 4 + i32_at(b, columns) as usize;
        at = nchunk + 4;
        let mut chunks = Vec::new();
        for _ in 0..i32_at(b, nchunk) {
            let n = i32_at(b, at) as usize;
            chunks.push((at, at + 4, n));
            at += 4 + 8 * n;
        }
        out.push(BinFrame {
            start,
            endian,
            revision,
            step,
            natoms,
            triclinic,
            boundary,
            box_at,
            box_len,
            size_one,
            units,
            time_flag,
            time,
            columns,
            nchunk,
            chunks,
            end: at,
        });
    }
    assert_eq!(at, b.len(), "frames tile the file");
    out
}

/// The file's column names (frame 0's).
pub fn column_names(b: &[u8]) -> String {
    let f = &walk(b)[0];
    let n = i32_at(b, f.columns) as usize;
    String::from_utf8(b[f.columns + 4..f.columns + 4 + n].to_vec()).unwrap()
}

/// What an older LAMMPS wrote for the same frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// No magic header: the timestep first, no units, time or names.
    Bare,
    /// The magic header with revision 1: no units, time or names.
    Revision1,
    /// As LAMMPS 2021+ writes it (revision 2), only the byte order may change.
    Revision2,
}

/// `b` (revision 2, little-endian) rewritten in `layout`, big-endian when `big`: every field
/// and value kept, in the other byte order.
pub fn rewrite(b: &[u8], layout: Layout, big: bool) -> Vec<u8> {
    let mut out = Vec::new();
    // A field of `n` bytes at `at`, in the chosen order.
    let put = |out: &mut Vec<u8>, at: usize, n: usize| {
        let mut v = b[at..at + n].to_vec();
        if big {
            v.reverse();
        }
        out.extend_from_slice(&v);
    };
    for f in walk(b) {
        if layout != Layout::Bare {
            put(&mut out, f.start, 8);
            let len = i64_at(b, f.start).unsigned_abs() as usize;
            out.extend_from_slice(&b[f.start + 8..f.start + 8 + len]);
            put(&mut out, f.endian, 4);
            if layout == Layout::Revision1 {
                out.extend_from_slice(&if big {
                    1i32.to_be_bytes()
                } else {
                    1i32.to_le_bytes()
                });
            } else {
                put(&mut out, f.revision, 4);
            }
        }
        put(&mut out, f.step, 8);
        put(&mut out, f.natoms, 8);
        put(&mut out, f.triclinic, 4);
        for k in 0..6 {
            put(&mut out, f.boundary + 4 * k, 4);
        }
        for k in 0..f.box_len / 8 {
            put(&mut out, f.box_at + 8 * k, 8);
        }
        put(&mut out, f.size_one, 4);
        if layout == Layout::Revision2 {
            put(&mut out, f.units, 4);
            out.extend_from_slice(&b[f.units + 4..f.time_flag]);
            out.push(b[f.time_flag]);
            if let Some(t) = f.time {
                put(&mut out, t, 8);
            }
            put(&mut out, f.columns, 4);
            out.extend_from_slice(&b[f.columns + 4..f.nchunk]);
        }
        put(&mut out, f.nchunk, 4);
        for (count, values, n) in f.chunks {
            put(&mut out, count, 4);
            for k in 0..n {
                put(&mut out, values + 8 * k, 8);
            }
        }
    }
    out
}

/// The frame ends of a file in the [`Layout::Bare`] layout, little-endian (what [`rewrite`]
/// makes), with the byte of each frame's chunk count.
pub fn walk_bare(b: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut at = 0;
    while at < b.len() {
        let box_len = 8 * [6, 9, 12][i32_at(b, at + 16) as usize];
        let nchunk = at + 44 + box_len + 4;
        at = nchunk + 4;
        for _ in 0..i32_at(b, nchunk) {
            at += 4 + 8 * i32_at(b, at) as usize;
        }
        out.push((at, nchunk));
    }
    assert_eq!(at, b.len(), "frames tile the file");
    out
}

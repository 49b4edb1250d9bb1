//! The chunks of a GSD file, walked from its header, namelist and index as the GSD file layer
//! specification lays them out (file format 1.0 and 2.x): what the tests that damage GSD files
//! use to find a chunk's index entry and data, independently of the reader under test.

/// One used index entry.
pub struct Chunk {
    pub frame: u64,
    pub name: String,
    /// Byte of the 32-byte index entry.
    pub entry: usize,
    /// Byte of the data.
    pub location: usize,
    pub rows: u64,
    pub cols: u32,
    /// The GSD type code (1 uint8 … 9 float, 10 double, 11 char).
    pub ty: u8,
}

impl Chunk {
    /// Bytes of data.
    pub fn bytes(&self) -> usize {
        let size = [0, 1, 2, 4, 8, 1, 2, 4, 8, 4, 8, 1][self.ty as usize];
        self.rows as usize * self.cols as usize * size
    }
}

fn u64_at(b: &[u8], at: usize) -> usize {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap()) as usize
}

/// The namelist: NUL-separated names (2.x), or one name per 64-byte segment (1.0).
pub fn names(b: &[u8]) -> Vec<String> {
    let (at, segments) = (u64_at(b, 24), u64_at(b, 32));
    let block = &b[at..at + 64 * segments];
    let v1 = u32::from_le_bytes(b[44..48].try_into().unwrap()) >> 16 == 1;
    let names: Vec<&[u8]> = if v1 {
        block
            .chunks(64)
            .map(|s| s.split(|c| *c == 0).next().unwrap())
            .collect()
    } else {
        block.split(|c| *c == 0).collect()
    };
    names
        .into_iter()
        .take_while(|s| !s.is_empty())
        .map(|s| String::from_utf8(s.to_vec()).unwrap())
        .collect()
}

/// Every used index entry (location ≠ 0), in index order.
pub fn chunks(b: &[u8]) -> Vec<Chunk> {
    let names = names(b);
    let (index, slots) = (u64_at(b, 8), u64_at(b, 16));
    (0..slots)
        .map(|k| index + 32 * k)
        .filter(|&at| u64_at(b, at + 16) != 0)
        .map(|at| Chunk {
            frame: u64_at(b, at) as u64,
            name: names[u16::from_le_bytes([b[at + 28], b[at + 29]]) as usize].clone(),
            entry: at,
            location: u64_at(b, at + 16),
            rows: u64_at(b, at + 8) as u64,
            cols: u32::from_le_bytes(b[at + 24..at + 28].try_into().unwrap()),
            ty: b[at + 30],
        })
        .collect()
}

/// The chunk `name` of frame `frame`.
pub fn chunk(b: &[u8], frame: u64, name: &str) -> Chunk {
    chunks(b)
        .into_iter()
        .find(|c| c.frame == frame && c.name == name)
        .unwrap_or_else(|| panic!("no chunk {name} in frame {frame}"))
}

//! The one error type of the crate. Every variant names the file (or the name given to bytes in
//! memory) and where in it the problem is: a line, a byte offset, a TIFF tag, a chunk.

use std::path::PathBuf;

/// What went wrong reading an elevation grid or an orthophoto, meshing, or writing a database.
#[derive(Debug)]
#[non_exhaustive]
pub enum TerrainError {
    /// A file or directory could not be read, written or renamed.
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The file's content is not what the format requires; `at` says where (line, tag, byte).
    Format {
        source: String,
        at: String,
        expected: String,
    },
    /// A feature the file uses that the reader does not support (named, with where it was found).
    Unsupported { source: String, what: String },
    /// The grid's size cannot be meshed: fewer than 2 samples a side, or more than the limit.
    BadSize {
        source: String,
        width: u64,
        height: u64,
        reason: &'static str,
    },
    /// A sample is NaN or infinite where a height or no-data marker was expected.
    NonFinite { source: String, col: u32, row: u32 },
    /// Every sample of the grid is no-data: there is no terrain.
    AllNoData { source: String },
    /// The orthophoto and the grid do not overlap.
    NoOverlap { photo: String, dem: String },
    /// A parameter is out of its documented range.
    BadParameter {
        name: &'static str,
        value: String,
        expected: &'static str,
    },
    /// The output exists already (a build never overwrites a database).
    Exists { path: PathBuf },
    /// A viewshed's observer at `(x, y)` (map coordinates, or a sample's column and row) falls at
    /// sample `(col, row)`, outside the `width x height` grid.
    ObserverOutside {
        x: f64,
        y: f64,
        col: f64,
        row: f64,
        width: u32,
        height: u32,
    },
    /// A viewshed's observer stands on a no-data sample: there is no ground to stand on.
    ObserverNoData { col: u32, row: u32 },
    /// A mesh could not be written.
    Mesh(texmap_mesh::MeshError),
}

impl std::fmt::Display for TerrainError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TerrainError::Io { path, source } => write!(f, "{}: {source}", path.display()),
            TerrainError::Format {
                source,
                at,
                expected,
            } => write!(f, "{source}: {at}: expected {expected}"),
            TerrainError::Unsupported { source, what } => {
                write!(f, "{source}: not supported: {what}")
            }
            TerrainError::BadSize {
                source,
                width,
                height,
                reason,
            } => write!(f, "{source}: grid of {width} x {height} samples: {reason}"),
            TerrainError::NonFinite { source, col, row } => write!(
                f,
                "{source}: sample at column {col}, row {row} is NaN or infinite (expected a height or the no-data value)"
            ),
            TerrainError::AllNoData { source } => {
                write!(
                    f,
                    "{source}: every sample is no-data: there is no terrain to mesh"
                )
            }
            TerrainError::NoOverlap { photo, dem } => write!(
                f,
                "{photo}: the orthophoto does not overlap the elevation grid {dem}"
            ),
            TerrainError::BadParameter {
                name,
                value,
                expected,
            } => write!(f, "{name} = {value}: expected {expected}"),
            TerrainError::Exists { path } => write!(
                f,
                "{}: exists already (choose a new output directory)",
                path.display()
            ),
            TerrainError::ObserverOutside {
                x,
                y,
                col,
                row,
                width,
                height,
            } => write!(
                f,
                "observer ({x}, {y}) is at sample ({col:.2}, {row:.2}), outside the {width} x \
                 {height} grid (expected columns 0..={} and rows 0..={})",
                width.saturating_sub(1),
                height.saturating_sub(1)
            ),
            TerrainError::ObserverNoData { col, row } => write!(
                f,
                "observer stands on sample ({col}, {row}), which is no-data: there is no ground \
                 to stand on (choose another point, or fill the grid's holes)"
            ),
            TerrainError::Mesh(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for TerrainError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        // Display already prints the underlying I/O or mesh error; chaining it again through
        // `source` would print it twice in the usual report of an error and its causes.
        None
    }
}

impl From<texmap_mesh::MeshError> for TerrainError {
    fn from(e: texmap_mesh::MeshError) -> Self {
        TerrainError::Mesh(e)
    }
}

/// Shorthand for an I/O error on `path`.
pub(crate) fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> TerrainError {
    let path = path.into();
    move |source| TerrainError::Io { path, source }
}

/// Shorthand for a format error.
pub(crate) fn format_err(
    source: &str,
    at: impl Into<String>,
    expected: impl Into<String>,
) -> TerrainError {
    TerrainError::Format {
        source: source.to_string(),
        at: at.into(),
        expected: expected.into(),
    }
}

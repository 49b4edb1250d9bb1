//! The one error type of the rasteriser.

/// Why a framebuffer, mesh or draw call was refused.
///
/// Bad *geometry* (NaN vertices, zero-area or back-facing triangles, empty draws) is never an
/// error: it is skipped and counted in [`crate::DrawStats`]. Errors are for inconsistent input
/// that the caller must fix: sizes that do not match, indices out of range.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum RasterError {
    /// Width or height is zero or larger than [`texmap_core::camera::MAX_IMAGE_SIDE`].
    BadSize { width: u32, height: u32 },
    /// The camera's image size differs from the framebuffer's.
    SizeMismatch {
        camera: (u32, u32),
        target: (u32, u32),
    },
    /// Triangle `triangle` refers to vertex `index`, but the mesh has `vertex_count` vertices.
    IndexOutOfRange {
        triangle: usize,
        index: u32,
        vertex_count: usize,
    },
    /// A per-vertex attribute array does not have one entry per vertex.
    AttributeLength {
        attribute: &'static str,
        len: usize,
        expected: usize,
    },
    /// The shading program needs a per-vertex attribute the mesh does not carry.
    MissingAttribute { attribute: &'static str },
    /// More primitives in one draw than the bin format can address (2^31 − 1).
    TooManyPrimitives { count: usize },
    /// A tile side that is not a power of two in `1..=MAX_IMAGE_SIDE` ([`crate::bin::TileGrid`]).
    BadTileSize { tile: u32 },
}

impl std::fmt::Display for RasterError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RasterError::BadSize { width, height } => write!(
                f,
                "framebuffer size {width}x{height} is not allowed (each side must be 1..={})",
                texmap_core::camera::MAX_IMAGE_SIDE
            ),
            RasterError::SizeMismatch { camera, target } => write!(
                f,
                "camera image is {}x{} but the framebuffer is {}x{}",
                camera.0, camera.1, target.0, target.1
            ),
            RasterError::IndexOutOfRange {
                triangle,
                index,
                vertex_count,
            } => write!(
                f,
                "triangle {triangle} refers to vertex {index}, but the mesh has {vertex_count} vertices"
            ),
            RasterError::AttributeLength {
                attribute,
                len,
                expected,
            } => write!(
                f,
                "attribute `{attribute}` has {len} entries, expected one per vertex ({expected})"
            ),
            RasterError::MissingAttribute { attribute } => {
                write!(f, "the shading program needs per-vertex `{attribute}`")
            }
            RasterError::TooManyPrimitives { count } => write!(
                f,
                "{count} primitives in one draw; at most {} are supported",
                i32::MAX
            ),
            RasterError::BadTileSize { tile } => write!(
                f,
                "tile side {tile} is not allowed (a power of two up to {})",
                texmap_core::camera::MAX_IMAGE_SIDE
            ),
        }
    }
}

impl std::error::Error for RasterError {}

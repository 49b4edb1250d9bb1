//! The one error type of the crate: every variant names its source (a path, or the name given to
//! bytes in memory) and, where it applies, the mesh and triangle.

use std::path::PathBuf;

/// What went wrong reading, checking or writing a mesh.
#[derive(Debug)]
#[non_exhaustive]
pub enum MeshError {
    /// The file could not be read or written.
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The OBJ parser refused the input.
    Obj { source: String, message: String },
    /// The glTF parser refused the input, or a buffer could not be resolved.
    Gltf { source: String, message: String },
    /// A primitive of a glTF mesh is not made of triangles.
    UnsupportedPrimitive {
        source: String,
        mesh: usize,
        mode: String,
    },
    /// A triangle refers to a vertex that does not exist.
    IndexOutOfRange {
        source: String,
        mesh: usize,
        triangle: usize,
        index: u32,
        vertex_count: usize,
    },
    /// A flat index list whose length is not a multiple of three.
    IndicesNotTriangles {
        source: String,
        mesh: usize,
        len: usize,
    },
    /// A vertex attribute has a different number of entries than there are vertices (or, for flat
    /// coordinate lists, not a whole number of vectors: `expected` is then 0).
    AttributeLength {
        source: String,
        mesh: usize,
        attribute: &'static str,
        len: usize,
        expected: usize,
    },
    /// The input holds no triangle at all.
    NoTriangles { source: String },
}

impl std::fmt::Display for MeshError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MeshError::Io { path, source } => write!(f, "{}: {source}", path.display()),
            MeshError::Obj { source, message } => write!(f, "{source}: OBJ: {message}"),
            MeshError::Gltf { source, message } => write!(f, "{source}: glTF: {message}"),
            MeshError::UnsupportedPrimitive { source, mesh, mode } => write!(
                f,
                "{source}: mesh {mesh}: primitive mode {mode} is not supported (need triangles)"
            ),
            MeshError::IndexOutOfRange {
                source,
                mesh,
                triangle,
                index,
                vertex_count,
            } => write!(
                f,
                "{source}: mesh {mesh}: triangle {triangle} refers to vertex {index}, but there are {vertex_count} vertices"
            ),
            MeshError::IndicesNotTriangles { source, mesh, len } => write!(
                f,
                "{source}: mesh {mesh}: {len} indices is not a whole number of triangles"
            ),
            MeshError::AttributeLength {
                source,
                mesh,
                attribute,
                len,
                expected: 0,
            } => write!(
                f,
                "{source}: mesh {mesh}: attribute {attribute} has {len} values, not a whole number of vectors"
            ),
            MeshError::AttributeLength {
                source,
                mesh,
                attribute,
                len,
                expected,
            } => write!(
                f,
                "{source}: mesh {mesh}: attribute {attribute} has {len} entries, expected one per vertex ({expected})"
            ),
            MeshError::NoTriangles { source } => write!(f, "{source}: no triangles"),
        }
    }
}

impl std::error::Error for MeshError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            MeshError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

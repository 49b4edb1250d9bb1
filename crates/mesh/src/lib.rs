//! # texmap-mesh — triangle meshes and the files they come in
//!
//! One owned, indexed triangle mesh ([`TriMesh`]) and the readers for the files users have:
//! Wavefront OBJ (through `tobj`) and glTF 2.0 (`.gltf` and `.glb`, through `gltf`). The
//! reference ray tracer, the terrain database and the environment-mapping scenes all take their
//! meshes from here, so that no method crate depends on the oracle to open a file.
//!
//! Conventions: positions in world units, triangles counter-clockwise seen from the front,
//! texture coordinates with `v` growing down the image rows (glTF's convention; OBJ's upward `v`
//! is flipped on reading). Every error names its source (a path or the name given to bytes) and the
//! mesh it concerns.
//!
//! **Invariant:** this crate depends on no other crate of ours.
//!
//! ```
//! use texmap_mesh::read_obj_bytes;
//!
//! let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
//! let meshes = read_obj_bytes(obj.as_bytes(), "quad.obj")?;
//! assert_eq!(meshes[0].triangles.len(), 2); // the quad is triangulated
//! assert_eq!(meshes[0].bounds(), Some((glam::Vec3::ZERO, glam::Vec3::new(1.0, 1.0, 0.0))));
//! # Ok::<(), texmap_mesh::MeshError>(())
//! ```

pub use glam;

mod error;
mod read;
pub mod write;

pub use error::MeshError;
pub use read::{
    BaseColor, read_gltf, read_gltf_base_color, read_gltf_bytes, read_obj, read_obj_bytes,
};
pub use write::{write_glb, write_obj};

use glam::{Vec2, Vec3};

/// An owned indexed triangle mesh.
///
/// # Guarantees
/// Meshes returned by this crate's readers and by [`TriMesh::new`] have every index below the
/// vertex count and one entry per vertex in every attribute present. Vertex *values* are not
/// checked (a consumer skips or rejects non-finite vertices in its own way).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    pub positions: Vec<Vec3>,
    /// Three vertex indices per triangle.
    pub triangles: Vec<[u32; 3]>,
    /// One texture coordinate per vertex, if any (`v` grows down the image rows).
    pub uvs: Option<Vec<Vec2>>,
    /// One vertex normal per vertex, if the file has them (not necessarily unit length).
    pub normals: Option<Vec<Vec3>>,
}

impl TriMesh {
    /// A mesh of `positions` and `triangles`, with every index checked against the vertex count.
    pub fn new(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<TriMesh, MeshError> {
        let mesh = TriMesh {
            positions,
            triangles,
            uvs: None,
            normals: None,
        };
        mesh.validate("mesh", 0)?;
        Ok(mesh)
    }

    /// The same mesh with one texture coordinate per vertex.
    pub fn with_uvs(mut self, uvs: Vec<Vec2>) -> Result<TriMesh, MeshError> {
        self.uvs = Some(uvs);
        self.validate("mesh", 0)?;
        Ok(self)
    }

    /// The same mesh with one normal per vertex.
    pub fn with_normals(mut self, normals: Vec<Vec3>) -> Result<TriMesh, MeshError> {
        self.normals = Some(normals);
        self.validate("mesh", 0)?;
        Ok(self)
    }

    /// The indices as one flat slice, three per triangle.
    pub fn indices(&self) -> &[u32] {
        self.triangles.as_flattened()
    }

    /// The axis-aligned bounds of the vertices referenced or not (`None` for no vertex).
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let first = *self.positions.first()?;
        Some(
            self.positions
                .iter()
                .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))),
        )
    }

    /// Check the guarantees: every index below the vertex count, every attribute one per vertex.
    /// `source` and `mesh` name the mesh in the error.
    pub fn validate(&self, source: &str, mesh: usize) -> Result<(), MeshError> {
        let n = self.positions.len();
        for (attribute, len) in [
            ("uvs", self.uvs.as_ref().map(Vec::len)),
            ("normals", self.normals.as_ref().map(Vec::len)),
        ] {
            if let Some(len) = len
                && len != n
            {
                return Err(MeshError::AttributeLength {
                    source: source.to_string(),
                    mesh,
                    attribute,
                    len,
                    expected: n,
                });
            }
        }
        for (t, tri) in self.triangles.iter().enumerate() {
            if let Some(&index) = tri.iter().find(|&&i| i as usize >= n) {
                return Err(MeshError::IndexOutOfRange {
                    source: source.to_string(),
                    mesh,
                    triangle: t,
                    index,
                    vertex_count: n,
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn new_refuses_an_index_past_the_vertices() {
        let e = TriMesh::new(vec![Vec3::ZERO; 3], vec![[0, 1, 3]]).unwrap_err();
        assert!(
            matches!(
                e,
                MeshError::IndexOutOfRange {
                    triangle: 0,
                    index: 3,
                    vertex_count: 3,
                    ..
                }
            ),
            "{e}"
        );
        let e = TriMesh::new(vec![Vec3::ZERO; 3], vec![[0, 1, 2]])
            .unwrap()
            .with_uvs(vec![Vec2::ZERO; 2])
            .unwrap_err();
        assert!(e.to_string().contains("uvs"), "{e}");
    }

    #[test]
    fn flat_indices_follow_the_triangles() {
        let m = TriMesh::new(vec![Vec3::ZERO; 4], vec![[0, 1, 2], [2, 3, 0]]).unwrap();
        assert_eq!(m.indices(), &[0, 1, 2, 2, 3, 0]);
    }
}

//! Borrowed, validated triangle meshes.

use glam::{Vec2, Vec3};

use crate::RasterError;

/// An indexed triangle mesh borrowed from the caller (terrain and sphere tessellations are drawn
/// without copying).
///
/// # Guarantees
/// Every index is below the vertex count, every attribute array present has one entry per vertex,
/// and there are at most `i32::MAX` triangles. Vertex *values* are not checked: a triangle with a
/// non-finite vertex is skipped at draw time and counted in [`crate::DrawStats::skipped_invalid`].
#[derive(Clone, Copy, Debug)]
pub struct Mesh<'a> {
    positions: &'a [Vec3],
    indices: &'a [[u32; 3]],
    normals: Option<&'a [Vec3]>,
    uvs: Option<&'a [Vec2]>,
    colors: Option<&'a [Vec3]>,
}

impl<'a> Mesh<'a> {
    /// A mesh of world-space `positions` and triangles `indices` (three vertex indices each;
    /// counter-clockwise as seen from the front, the right-handed convention).
    pub fn new(positions: &'a [Vec3], indices: &'a [[u32; 3]]) -> Result<Mesh<'a>, RasterError> {
        if indices.len() > i32::MAX as usize {
            return Err(RasterError::TooManyPrimitives {
                count: indices.len(),
            });
        }
        let n = positions.len();
        for (t, tri) in indices.iter().enumerate() {
            for &i in tri {
                if i as usize >= n {
                    return Err(RasterError::IndexOutOfRange {
                        triangle: t,
                        index: i,
                        vertex_count: n,
                    });
                }
            }
        }
        Ok(Mesh {
            positions,
            indices,
            normals: None,
            uvs: None,
            colors: None,
        })
    }

    fn check_len(&self, attribute: &'static str, len: usize) -> Result<(), RasterError> {
        if len != self.positions.len() {
            return Err(RasterError::AttributeLength {
                attribute,
                len,
                expected: self.positions.len(),
            });
        }
        Ok(())
    }

    /// The same mesh with per-vertex world-space normals (need not be unit length: they are
    /// normalised per fragment).
    pub fn with_normals(mut self, normals: &'a [Vec3]) -> Result<Mesh<'a>, RasterError> {
        self.check_len("normals", normals.len())?;
        self.normals = Some(normals);
        Ok(self)
    }

    /// The same mesh with per-vertex texture coordinates (map units, as the samplers expect).
    pub fn with_uvs(mut self, uvs: &'a [Vec2]) -> Result<Mesh<'a>, RasterError> {
        self.check_len("uvs", uvs.len())?;
        self.uvs = Some(uvs);
        Ok(self)
    }

    /// The same mesh with per-vertex linear RGB colours.
    pub fn with_colors(mut self, colors: &'a [Vec3]) -> Result<Mesh<'a>, RasterError> {
        self.check_len("colors", colors.len())?;
        self.colors = Some(colors);
        Ok(self)
    }

    #[inline]
    pub fn positions(&self) -> &'a [Vec3] {
        self.positions
    }
    #[inline]
    pub fn indices(&self) -> &'a [[u32; 3]] {
        self.indices
    }
    #[inline]
    pub fn normals(&self) -> Option<&'a [Vec3]> {
        self.normals
    }
    #[inline]
    pub fn uvs(&self) -> Option<&'a [Vec2]> {
        self.uvs
    }
    #[inline]
    pub fn colors(&self) -> Option<&'a [Vec3]> {
        self.colors
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_indices_and_lengths_are_errors() {
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y];
        assert!(Mesh::new(&p, &[[0, 1, 2]]).is_ok());
        assert_eq!(
            Mesh::new(&p, &[[0, 1, 2], [0, 3, 1]]).unwrap_err(),
            RasterError::IndexOutOfRange {
                triangle: 1,
                index: 3,
                vertex_count: 3
            }
        );
        let m = Mesh::new(&p, &[[0, 1, 2]]).unwrap();
        assert_eq!(
            m.with_uvs(&[Vec2::ZERO]).unwrap_err(),
            RasterError::AttributeLength {
                attribute: "uvs",
                len: 1,
                expected: 3
            }
        );
        assert!(m.with_normals(&p).is_ok());
    }
}

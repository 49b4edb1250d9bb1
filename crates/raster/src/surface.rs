//! Surface shaders of the caller's own: the open extension point of the rasteriser.
//!
//! [`crate::Shading`] is a closed set of lighting programs, and [`crate::QuadSampler`] colours a
//! quad from texture coordinates. Some methods need more per pixel: an environment-mapped
//! reflection needs the surface normal and the eye ray at each pixel (Seed 003: the reflected
//! eye vector indexes the sphere map), a box-projected cube map the surface position too. A
//! [`SurfaceShader`] receives, for each covered 2x2 quad, the pixel centres, the depth, the
//! perspective-correct interpolated **world-space** normal and the triangle, and returns the
//! quad's linear RGB. [`crate::Framebuffer::draw_surface`] runs it with the same coverage,
//! depth test, tiling and determinism as every other draw; the shader is monomorphised into the
//! tile loop (no `dyn`).
//!
//! Normals come from the mesh's vertex normals when it has them (interpolated, not
//! renormalised: [`SurfaceQuad::normal`] normalises), else the triangle's face normal from its
//! counter-clockwise winding. On back faces the normal is flipped toward the viewer, as the
//! lighting programs do.

use glam::Vec3;
use texmap_core::camera::Camera;

use crate::mesh::Mesh;
use crate::program::{FragProgram, QuadFrag};
use crate::project::{MAX_VAR, Var};

/// What a [`SurfaceShader`] knows of one 2x2 quad; lanes in the order `(0,0), (1,0), (0,1),
/// (1,1)`.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceQuad {
    /// Pixel-centre screen coordinates.
    pub x: [f32; 4],
    pub y: [f32; 4],
    /// Depth along the view axis (what the depth buffer stores).
    pub depth: [f32; 4],
    /// The interpolated world-space normal, not normalised; toward the viewer on back faces.
    pub normal_raw: [Vec3; 4],
    /// Lanes that will be written (bit l = lane l); the others hold no meaningful values.
    pub mask: u8,
    /// Whether the triangle faces the viewer.
    pub front: bool,
    /// The index of the triangle in the mesh.
    pub triangle: u32,
}

impl SurfaceQuad {
    /// The unit world-space normal of lane `l` (zero for a degenerate normal).
    #[inline]
    pub fn normal(&self, l: usize) -> Vec3 {
        self.normal_raw[l].normalize_or_zero()
    }

    /// The world-space point seen by lane `l`, from `camera` (the camera the draw used) and the
    /// lane's depth.
    #[inline]
    pub fn world_position(&self, camera: &Camera, l: usize) -> Vec3 {
        let ray = camera.ray(self.x[l], self.y[l]);
        // Depth runs along the view axis: t = depth / cos(angle to the axis).
        ray.origin + ray.dir * (self.depth[l] / ray.dir.dot(camera.forward()))
    }

    /// The unit world-space direction of the eye ray through lane `l` (from the eye toward the
    /// surface).
    #[inline]
    pub fn view_ray(&self, camera: &Camera, l: usize) -> Vec3 {
        camera.ray(self.x[l], self.y[l]).dir
    }
}

/// A per-pixel surface program (see the module docs).
pub trait SurfaceShader: Sync {
    /// Linear RGB of the quad's four lanes (lanes outside `q.mask` are not written).
    fn shade(&self, q: &SurfaceQuad) -> [Vec3; 4];
}

/// The fragment program that runs a [`SurfaceShader`].
pub(crate) struct SurfaceProg<'a, S: SurfaceShader + ?Sized> {
    pub shader: &'a S,
    pub has_normals: bool,
}

/// Per-triangle constants: the face normal (used when the mesh has no vertex normals).
#[derive(Clone, Copy)]
pub(crate) struct SurfaceTri {
    face: Vec3,
    triangle: u32,
}

impl<S: SurfaceShader + ?Sized> FragProgram for SurfaceProg<'_, S> {
    const NV: usize = 3;
    type Vars = [Var; 3];
    type TriConst = SurfaceTri;
    #[inline]
    fn vertex_var(&self, mesh: &Mesh, vi: usize) -> Var {
        let n = mesh.normals().map_or(Vec3::ZERO, |n| n[vi]);
        let mut v = [0.0; MAX_VAR];
        v[..3].copy_from_slice(&[n.x, n.y, n.z]);
        v
    }
    fn tri_const(&self, mesh: &Mesh, tri: u32, _front: bool) -> SurfaceTri {
        let p = mesh.positions();
        let v = mesh.indices()[tri as usize].map(|i| p[i as usize]);
        SurfaceTri {
            face: (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero(),
            triangle: tri,
        }
    }
    #[inline]
    fn shade(&self, c: &SurfaceTri, f: &QuadFrag, front: bool) -> [[f32; 4]; 3] {
        let sign = if front { 1.0 } else { -1.0 };
        let normal_raw = std::array::from_fn(|l| {
            let n = if self.has_normals {
                Vec3::new(f.var[0][l], f.var[1][l], f.var[2][l])
            } else {
                c.face
            };
            n * sign
        });
        let q = SurfaceQuad {
            x: f.x,
            y: f.y,
            depth: f.depth,
            normal_raw,
            mask: f.mask,
            front,
            triangle: c.triangle,
        };
        let rgb = self.shader.shade(&q);
        [rgb.map(|c| c.x), rgb.map(|c| c.y), rgb.map(|c| c.z)]
    }
}

impl<F> SurfaceShader for F
where
    F: Fn(&SurfaceQuad) -> [Vec3; 4] + Sync,
{
    #[inline]
    fn shade(&self, q: &SurfaceQuad) -> [Vec3; 4] {
        self(q)
    }
}

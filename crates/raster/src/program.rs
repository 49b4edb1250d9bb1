//! Fragment programs: what colour a covered pixel gets.
//!
//! The program of a draw is chosen once, before any pixel loop: [`Shading`] (a closed set) and
//! textured draws are turned into a concrete type implementing `FragProgram`, and the tile
//! rasteriser is monomorphised over it, so the per-quad code holds no `dyn`, no allocation and no
//! per-pixel `match` on the shading mode.
//!
//! Every program works on a whole 2x2 quad at once: that is where texture derivatives (and Seed
//! 000's spans) come from.

use glam::{Vec2, Vec3};
use texmap_core::lanes::{F32x4, pow01_x4};
use texmap_core::mip::MipTexture;
use texmap_core::sample::Sampler;
use texmap_core::shade::{Lighting, MAX_LIGHTS, Material};

use crate::mesh::Mesh;
use crate::project::{MAX_VAR, Proj, Var};
use crate::record::VarStore;

/// How the triangles of [`crate::Framebuffer::draw_mesh`] are coloured. All colours are linear RGB.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum Shading {
    /// One constant colour.
    Flat(Vec3),
    /// Gouraud: per-vertex colours (the mesh must carry colours), interpolated
    /// perspective-correctly.
    VertexColor,
    /// Flat: each triangle in the colour of its first vertex (OpenGL's flat shading, first
    /// vertex provoking; the mesh must carry colours). Nothing is interpolated per pixel.
    FirstVertexColor,
    /// [`Lighting::shade`] with one face normal per triangle (from the winding), evaluated once
    /// per triangle at its centroid.
    LitFlat {
        lighting: Lighting,
        material: Material,
    },
    /// Phong: [`Lighting::shade`] per pixel with the perspective-correct interpolated vertex
    /// normal (the mesh must carry normals) and the exact view direction of the pixel.
    LitSmooth {
        lighting: Lighting,
        material: Material,
    },
}

/// The four fragments of a 2x2 quad, lanes in the order `(0,0), (1,0), (0,1), (1,1)`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct QuadFrag {
    /// Pixel-centre screen coordinates.
    pub x: [f32; 4],
    pub y: [f32; 4],
    /// Perspective-correct varyings, `var[k][lane]`.
    pub var: [[f32; 4]; MAX_VAR],
    /// Depth along the view axis, as written to the depth buffer.
    pub depth: [f32; 4],
    /// Lanes that will be written (bit l = lane l).
    pub mask: u8,
}

/// A per-draw fragment program (see the module docs).
pub(crate) trait FragProgram: Sync {
    /// Varyings used (at most [`MAX_VAR`]).
    const NV: usize;
    /// What the program computes once per triangle.
    type TriConst: Copy;
    /// How binned records store the varyings: `()` when `NV == 0`, else `[Var; 3]`.
    type Vars: VarStore;
    /// The varyings of mesh vertex `vi`.
    fn vertex_var(&self, mesh: &Mesh, vi: usize) -> Var;
    /// Per-triangle constants of source triangle `tri`; `front` says how it faces the viewer.
    fn tri_const(&self, mesh: &Mesh, tri: u32, front: bool) -> Self::TriConst;
    /// Planar linear RGB of the four lanes.
    fn shade(&self, c: &Self::TriConst, f: &QuadFrag, front: bool) -> [[f32; 4]; 3];
}

const NO_VAR: Var = [0.0; MAX_VAR];

/// `Shading::Flat`.
pub(crate) struct FlatProg(pub Vec3);

impl FragProgram for FlatProg {
    const NV: usize = 0;
    type Vars = ();
    type TriConst = ();
    #[inline]
    fn vertex_var(&self, _: &Mesh, _: usize) -> Var {
        NO_VAR
    }
    #[inline]
    fn tri_const(&self, _: &Mesh, _: u32, _: bool) {}
    #[inline]
    fn shade(&self, _: &(), _: &QuadFrag, _: bool) -> [[f32; 4]; 3] {
        [[self.0.x; 4], [self.0.y; 4], [self.0.z; 4]]
    }
}

/// `Shading::VertexColor`.
pub(crate) struct VertexColorProg;

impl FragProgram for VertexColorProg {
    const NV: usize = 3;
    type Vars = [Var; 3];
    type TriConst = ();
    #[inline]
    fn vertex_var(&self, mesh: &Mesh, vi: usize) -> Var {
        let c = mesh.colors().map_or(Vec3::ONE, |c| c[vi]);
        [c.x, c.y, c.z]
    }
    #[inline]
    fn tri_const(&self, _: &Mesh, _: u32, _: bool) {}
    #[inline]
    fn shade(&self, _: &(), f: &QuadFrag, _: bool) -> [[f32; 4]; 3] {
        [f.var[0], f.var[1], f.var[2]]
    }
}

/// A colour computed once per triangle, for [`PerTriangle`].
pub(crate) trait TriangleColour: Sync {
    /// The colour of triangle `tri` of `mesh` (`front`: seen from its front side).
    fn colour(&self, mesh: &Mesh, tri: u32, front: bool) -> Vec3;
}

/// A program that fills each triangle with one [`TriangleColour`]: nothing is interpolated.
pub(crate) struct PerTriangle<C>(pub C);

impl<C: TriangleColour> FragProgram for PerTriangle<C> {
    const NV: usize = 0;
    type Vars = ();
    type TriConst = Vec3;
    #[inline]
    fn vertex_var(&self, _: &Mesh, _: usize) -> Var {
        NO_VAR
    }
    #[inline]
    fn tri_const(&self, mesh: &Mesh, tri: u32, front: bool) -> Vec3 {
        self.0.colour(mesh, tri, front)
    }
    #[inline]
    fn shade(&self, c: &Vec3, _: &QuadFrag, _: bool) -> [[f32; 4]; 3] {
        [[c.x; 4], [c.y; 4], [c.z; 4]]
    }
}

/// `Shading::FirstVertexColor`.
pub(crate) struct FirstVertexColour;

impl TriangleColour for FirstVertexColour {
    #[inline]
    fn colour(&self, mesh: &Mesh, tri: u32, _: bool) -> Vec3 {
        let first = mesh.indices()[tri as usize][0] as usize;
        mesh.colors().map_or(Vec3::ONE, |c| c[first])
    }
}

/// `Shading::LitFlat`: lighting in eye space, one colour per triangle.
pub(crate) struct LitFlat {
    pub lighting: Lighting,
    pub material: Material,
    pub proj: Proj,
}

impl TriangleColour for LitFlat {
    fn colour(&self, mesh: &Mesh, tri: u32, front: bool) -> Vec3 {
        let p = mesh.positions();
        let e = mesh.indices()[tri as usize].map(|i| self.proj.to_eye(p[i as usize]));
        // Face normal from the counter-clockwise winding, toward the viewer when front-facing.
        let mut n = (e[1] - e[0]).cross(e[2] - e[0]).normalize_or_zero();
        if !front {
            n = -n;
        }
        let centroid = (e[0] + e[1] + e[2]) / 3.0;
        let v = if self.proj.persp {
            (-centroid).normalize_or(Vec3::Z)
        } else {
            Vec3::Z
        };
        self.lighting.shade(&self.material, n, v)
    }
}

/// `Shading::LitSmooth`: eye-space normals interpolated, lit per pixel.
pub(crate) struct LitSmoothProg {
    pub proj: Proj,
    /// The lighting and material as four-lane constants, made once per draw.
    lanes: LightLanes,
}

impl LitSmoothProg {
    /// `lighting` in eye space.
    pub fn new(lighting: Lighting, material: Material, proj: Proj) -> Self {
        LitSmoothProg {
            proj,
            lanes: LightLanes::new(&lighting, &material),
        }
    }
}

/// One directional light as four-lane constants.
#[derive(Clone, Copy)]
struct LightLane {
    to_light: [F32x4; 3],
    color: [F32x4; 3],
}

/// A [`Lighting`] and [`Material`] splatted into lanes once per draw, so the per-quad shading
/// builds no constants.
#[derive(Clone, Copy)]
struct LightLanes {
    base: [F32x4; 3],
    /// `ambient · base`, computed as `Lighting::shade` does.
    ambient: [F32x4; 3],
    lights: [LightLane; MAX_LIGHTS],
    count: usize,
    specular: F32x4,
    specular_f: f32,
    shininess: f32,
}

impl LightLanes {
    fn new(l: &Lighting, m: &Material) -> Self {
        let v3 = |v: Vec3| [F32x4::splat(v.x), F32x4::splat(v.y), F32x4::splat(v.z)];
        let zero = LightLane {
            to_light: v3(Vec3::ZERO),
            color: v3(Vec3::ZERO),
        };
        let mut lights = [zero; MAX_LIGHTS];
        for (dst, src) in lights.iter_mut().zip(l.lights()) {
            *dst = LightLane {
                to_light: v3(src.to_light),
                color: v3(src.color),
            };
        }
        LightLanes {
            base: v3(m.base_color),
            ambient: v3(l.ambient * m.base_color),
            lights,
            count: l.lights().len(),
            specular: F32x4::splat(m.specular),
            specular_f: m.specular,
            shininess: m.shininess,
        }
    }
}

impl FragProgram for LitSmoothProg {
    const NV: usize = 3;
    type Vars = [Var; 3];
    type TriConst = ();
    #[inline]
    fn vertex_var(&self, mesh: &Mesh, vi: usize) -> Var {
        let n = mesh
            .normals()
            .map_or(Vec3::Z, |n| self.proj.dir_to_eye(n[vi]));
        [n.x, n.y, n.z]
    }
    #[inline]
    fn tri_const(&self, _: &Mesh, _: u32, _: bool) {}
    #[inline]
    fn shade(&self, _: &(), f: &QuadFrag, front: bool) -> [[f32; 4]; 3] {
        let s = F32x4::splat;
        // Normalised interpolated normal (two-sided: flipped on back faces).
        let sign = s(if front { 1.0 } else { -1.0 });
        let n =
            normalize_or_zero4([f.var[0], f.var[1], f.var[2]].map(F32x4::new)).map(|c| c.mul(sign));
        // Unit vector toward the viewer, per pixel (`Proj::view_dir`).
        let v = if self.proj.persp {
            let k = s(self.proj.k);
            normalize4([
                s(self.proj.cx).sub(F32x4::new(f.x)).div(k),
                F32x4::new(f.y).sub(s(self.proj.cy)).div(k),
                s(1.0),
            ])
        } else {
            [s(0.0), s(0.0), s(1.0)]
        };
        shade4(&self.lanes, n, v, f.mask)
    }
}

/// `a·b` over four lanes, summed as glam's `Vec3::dot`: `(x·x + y·y) + z·z`.
#[inline(always)]
fn dot4(a: &[F32x4; 3], b: &[F32x4; 3]) -> F32x4 {
    a[0].mul(b[0]).add(a[1].mul(b[1])).add(a[2].mul(b[2]))
}

/// glam's `Vec3::normalize` over four lanes: `v · (1 / sqrt(v·v))`.
#[inline(always)]
fn normalize4(v: [F32x4; 3]) -> [F32x4; 3] {
    let rcp = F32x4::splat(1.0).div(dot4(&v, &v).sqrt());
    v.map(|c| c.mul(rcp))
}

/// glam's `Vec3::normalize_or_zero` over four lanes (zero where `1 / |v|` is not finite and
/// positive).
#[inline(always)]
fn normalize_or_zero4(v: [F32x4; 3]) -> [F32x4; 3] {
    let rcp = F32x4::splat(1.0).div(dot4(&v, &v).sqrt());
    let ok = F32x4::splat(0.0)
        .lt(rcp)
        .and(rcp.lt(F32x4::splat(f32::INFINITY)));
    v.map(|c| F32x4::select(ok, c.mul(rcp), F32x4::splat(0.0)))
}

/// [`Lighting::shade`] for the four lanes of a quad, the same operations in the same order,
/// except the Blinn-Phong power: [`pow01_x4`] (relative error < 1e-5) for exponents in
/// `(0, 65536]`, `powf` per lit lane otherwise. Without a specular term the result is
/// bit-identical to four scalar calls; with it, within 1e-5 of them (tested).
#[inline(always)]
fn shade4(ll: &LightLanes, n: [F32x4; 3], v: [F32x4; 3], mask: u8) -> [[f32; 4]; 3] {
    let s = F32x4::splat;
    let mut c = ll.ambient;
    for light in &ll.lights[..ll.count] {
        let l = light.to_light;
        let ndl = dot4(&n, &l);
        let lit = s(0.0).lt(ndl);
        let lit_bits = lit.bits() as u8 & mask;
        if lit_bits == 0 {
            continue;
        }
        let mut term = ll.base.map(|b| b.mul(ndl));
        if ll.specular_f > 0.0 {
            // Blinn-Phong half vector, n·h clamped at 0, raised to the shininess per lane.
            let h = normalize_or_zero4([l[0].add(v[0]), l[1].add(v[1]), l[2].add(v[2])]);
            let ndh = dot4(&n, &h).max(s(0.0));
            let spec = if ll.shininess > 0.0 && ll.shininess <= 65536.0 {
                ll.specular.mul(pow01_x4(ndh, ll.shininess))
            } else {
                // Exponents outside pow01_x4's range: powf per lit lane.
                let ndh = ndh.to_array();
                let mut spec = [0.0f32; 4];
                for (lane, sp) in spec.iter_mut().enumerate() {
                    if lit_bits & (1 << lane) != 0 {
                        *sp = ll.specular_f * ndh[lane].powf(ll.shininess);
                    }
                }
                F32x4::new(spec)
            };
            term = term.map(|t| t.add(spec));
        }
        for k in 0..3 {
            c[k] = F32x4::select(lit, c[k].add(light.color[k].mul(term[k])), c[k]);
        }
    }
    c.map(F32x4::to_array)
}

/// The texture coordinates of a 2x2 quad of pixels, handed to a [`QuadSampler`].
///
/// Lanes are in the order `(0,0), (1,0), (0,1), (1,1)` (x right, y down). All four lanes carry
/// perspective-correct coordinates, including pixels outside the triangle ("helper" lanes,
/// extrapolated on the triangle's plane), so derivatives are available at every covered pixel;
/// a helper lane whose extrapolation is not finite gets the coordinates of a covered lane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexQuad {
    /// Texture coordinates (map units) at the four pixel centres.
    pub uv: [Vec2; 4],
    /// Pixel-centre screen position of lane 0 (the quad's top-left pixel).
    pub origin: Vec2,
    /// Lanes whose colour will be used (bit l = lane l).
    pub mask: u8,
    /// Index of the drawn mesh's triangle the quad belongs to: one draw call can texture parts
    /// of a mesh from different textures (e.g. terrain chunks, each with its own map).
    pub triangle: u32,
}

impl TexQuad {
    /// Coarse screen derivatives `(∂uv/∂x, ∂uv/∂y)` of the quad (lane 1 − lane 0, lane 2 − lane 0),
    /// the finite differences a 2x2 span provides for free.
    #[inline]
    pub fn derivatives(&self) -> (Vec2, Vec2) {
        (self.uv[1] - self.uv[0], self.uv[2] - self.uv[0])
    }
}

/// A texture lookup for textured triangles: linear RGB at the four pixels of a quad.
///
/// Implement it for any sampler; per-pixel samplers use [`TexQuad::derivatives`] for their level
/// of detail, and a Seed 000 span sampler takes the whole quad (its four map coordinates are
/// exactly the span's `r_m(u, v)` of Eq. 8). Closures `Fn(&TexQuad) -> [Vec3; 4]` implement it.
pub trait QuadSampler: Sync {
    /// Linear RGB at the four lanes (values of lanes outside `quad.mask` are ignored).
    fn sample_quad(&self, quad: &TexQuad) -> [Vec3; 4];
}

impl<F> QuadSampler for F
where
    F: Fn(&TexQuad) -> [Vec3; 4] + Sync,
{
    #[inline]
    fn sample_quad(&self, quad: &TexQuad) -> [Vec3; 4] {
        self(quad)
    }
}

/// A texmap-core [`Sampler`] bound to its [`MipTexture`]: the way to texture triangles with
/// nearest, bilinear, trilinear (Seed 000 Eq. 4), span-parallel (Eq. 8–10, the whole quad is the
/// span), quadratic 3x3 or anisotropic sampling. Colour is the texture's linear RGB (alpha is dropped).
#[derive(Clone, Copy, Debug)]
pub struct MipSampler<'a> {
    pub texture: &'a MipTexture,
    pub sampler: Sampler,
}

impl QuadSampler for MipSampler<'_> {
    #[inline]
    fn sample_quad(&self, quad: &TexQuad) -> [Vec3; 4] {
        self.sampler
            .sample_quad(self.texture, quad.uv)
            .map(|c| c.truncate())
    }
}

/// Textured triangles: uv varyings handed to a [`QuadSampler`].
pub(crate) struct TexturedProg<'s, S: QuadSampler + ?Sized>(pub &'s S);

impl<S: QuadSampler + ?Sized> FragProgram for TexturedProg<'_, S> {
    const NV: usize = 2;
    type Vars = [Var; 3];
    type TriConst = u32;
    #[inline]
    fn vertex_var(&self, mesh: &Mesh, vi: usize) -> Var {
        let uv = mesh.uvs().map_or(Vec2::ZERO, |u| u[vi]);
        [uv.x, uv.y, 0.0]
    }
    #[inline]
    fn tri_const(&self, _: &Mesh, tri: u32, _: bool) -> u32 {
        tri
    }
    #[inline]
    fn shade(&self, tri: &u32, f: &QuadFrag, _: bool) -> [[f32; 4]; 3] {
        let mut uv = [Vec2::ZERO; 4];
        for (l, v) in uv.iter_mut().enumerate() {
            *v = Vec2::new(f.var[0][l], f.var[1][l]);
        }
        // Helper lanes far outside the triangle can extrapolate past the horizon (1/W <= 0):
        // give them a covered lane's coordinates so samplers never see a non-finite value.
        let first = f.mask.trailing_zeros().min(3) as usize;
        let fallback = if uv[first].is_finite() {
            uv[first]
        } else {
            Vec2::ZERO
        };
        for v in &mut uv {
            if !v.is_finite() {
                *v = fallback;
            }
        }
        let c = self.0.sample_quad(&TexQuad {
            uv,
            origin: Vec2::new(f.x[0], f.y[0]),
            mask: f.mask,
            triangle: *tri,
        });
        [
            [c[0].x, c[1].x, c[2].x, c[3].x],
            [c[0].y, c[1].y, c[2].y, c[3].y],
            [c[0].z, c[1].z, c[2].z, c[3].z],
        ]
    }
}

#[cfg(test)]
mod tests {
    use texmap_core::camera::Camera;

    use super::*;

    #[test]
    #[allow(clippy::needless_range_loop)] // a lane index addresses several arrays
    fn four_lane_smooth_lighting_matches_the_shared_model() {
        let mut st = 11u64;
        let mut r = || {
            st = st
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (st >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        let cams = [
            Camera::perspective_look_at(
                Vec3::new(1.0, 2.0, 5.0),
                Vec3::ZERO,
                Vec3::Y,
                55.0,
                320,
                200,
            )
            .unwrap(),
            Camera::orthographic_look_at(
                Vec3::new(0.0, 0.0, 5.0),
                Vec3::ZERO,
                Vec3::Y,
                4.0,
                64,
                64,
            )
            .unwrap(),
        ];
        let mut checked = [0usize; 2];
        for (ci, cam) in cams.iter().enumerate() {
            for round in 0..200 {
                let nl = round % 5;
                let lights: Vec<(Vec3, Vec3)> = (0..nl)
                    .map(|_| {
                        (
                            Vec3::new(r(), r(), r() + 1.2),
                            Vec3::new(r(), r(), r()).abs(),
                        )
                    })
                    .collect();
                let lighting = Lighting::new(Vec3::new(r(), r(), r()).abs() * 0.2, &lights)
                    .unwrap()
                    .to_eye(cam);
                let material = if round % 3 == 0 {
                    Material::matte(Vec3::new(r(), r(), r()).abs())
                } else {
                    Material {
                        base_color: Vec3::new(r(), r(), r()).abs(),
                        specular: r().abs(),
                        shininess: 1.0 + 80.0 * r().abs(),
                    }
                };
                let prog = LitSmoothProg::new(lighting, material, Proj::new(cam));
                let mut f = QuadFrag {
                    x: [0.0; 4],
                    y: [0.0; 4],
                    var: [[0.0; 4]; MAX_VAR],
                    depth: [1.0; 4],
                    mask: (round % 16) as u8 | 1,
                };
                for l in 0..4 {
                    f.x[l] = (r() + 1.0) * 200.0;
                    f.y[l] = (r() + 1.0) * 120.0;
                    for k in 0..3 {
                        // Some zero and some huge normals reach the normalize_or_zero fallback.
                        f.var[k][l] = match round % 7 {
                            0 => 0.0,
                            1 => r() * 1e-30,
                            _ => r(),
                        };
                    }
                }
                let front = round % 2 == 0;
                let got = prog.shade(&(), &f, front);
                for l in 0..4 {
                    if f.mask & (1 << l) == 0 {
                        continue;
                    }
                    let sign = if front { 1.0 } else { -1.0 };
                    let n =
                        Vec3::new(f.var[0][l], f.var[1][l], f.var[2][l]).normalize_or_zero() * sign;
                    let v = prog.proj.view_dir(f.x[l], f.y[l]);
                    let want = lighting.shade(&material, n, v);
                    for k in 0..3 {
                        if material.specular == 0.0 {
                            // No power term: the same operations in the same order.
                            assert_eq!(
                                got[k][l].to_bits(),
                                want[k].to_bits(),
                                "lane {l} channel {k}: expected {} got {}",
                                want[k],
                                got[k][l]
                            );
                        } else {
                            // pow01_x4's relative error (< 1e-5) on a specular term <= Σ colour.
                            let tol = 1e-5 * (1.0 + want[k].abs());
                            let err = (got[k][l] - want[k]).abs();
                            assert!(
                                err <= tol,
                                "lane {l} channel {k}: expected {} got {} tol {tol}",
                                want[k],
                                got[k][l]
                            );
                        }
                    }
                    checked[ci] += 1;
                }
            }
        }
        assert!(checked.iter().all(|&c| c > 300), "{checked:?}");
    }
}

//! Scenes: primitives collected by a [`SceneBuilder`], one obvhs BVH built over all of them, and
//! closest-hit queries.
//!
//! Every primitive kind lives in one BVH; the leaf callback dispatches on a small `Prim` enum stored
//! in BVH leaf order (so a leaf's primitives are contiguous in memory and a sphere needs no second
//! lookup). Intersection is ours ([`crate::geom`]), not obvhs's: its triangle test is not watertight.
//!
//! # Degenerate input
//! Nothing here panics on bad data:
//! - a sphere with a non-finite centre or a radius that is not finite and positive is **skipped and
//!   counted** ([`BuildStats::skipped_spheres`]); it still consumes its id, so ids stay aligned with
//!   the caller's arrays;
//! - a cylinder with non-finite end points or radius, a radius ≤ 0 or coincident end points is
//!   skipped and counted the same way;
//! - a triangle with a non-finite vertex or exactly zero area is skipped and counted
//!   ([`BuildStats::skipped_triangles`]); a mesh whose indices are out of range or not a multiple of
//!   three, or whose uv count differs from its vertex count, is **rejected** with a [`SceneError`];
//! - an empty scene builds and every ray misses.
//!
//! # BVH robustness
//! Each primitive's box is padded by a small relative margin (`BOX_PAD_REL`) before the build, so the
//! BVH's slab tests, which round, can never cull a ray that grazes a primitive exactly on its box
//! boundary (a ray along a shared heightfield edge is the typical case). The leaf tests decide.

use std::time::Duration;

use glam::{Vec2, Vec3, Vec3A, Vec4};
use obvhs::{
    BvhBuildParams,
    aabb::Aabb,
    bvh2::{Bvh2, builder::build_bvh2},
    cwbvh::{CwBvh, builder::build_cwbvh},
    ray::{Ray as BvhRay, RayHit},
};
use texmap_core::camera::Ray;
use texmap_mesh::TriMesh;

use crate::error::SceneError;
use crate::geom::{CylinderPart, RayPre, intersect_cylinder, intersect_sphere, intersect_triangle};
use crate::wide::{SlabRay, TraversalStack, Wide4};

thread_local! {
    /// Each thread's traversal stack for [`Wide4`] (no allocation per ray; never re-entered,
    /// since leaf tests do not trace).
    static STACK: std::cell::RefCell<TraversalStack> =
        const { std::cell::RefCell::new(TraversalStack::new()) };
}

/// Relative padding of primitive boxes (see module docs "BVH robustness").
const BOX_PAD_REL: f32 = 1e-5;

/// Which BVH layout and traversal the scene uses. All three are built by obvhs (PLOC +
/// reinsertion); they differ in layout and in who walks them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BvhKind {
    /// obvhs's binary BVH (PLOC + reinsertion + leaf collapse) and its traversal.
    Bvh2,
    /// obvhs's compressed 8-wide BVH (Ylitie et al. 2017) converted from a PLOC BVH2, and its
    /// traversal.
    CwBvh,
    /// obvhs's binary BVH collapsed into a 4-wide BVH with full-precision boxes in SIMD lanes,
    /// walked by this crate (`wide` module). The default: the fastest here (see
    /// docs/PERFORMANCE.md, "Reference ray tracer"). A tree too deep for its fixed stack keeps
    /// the binary traversal ([`Scene::bvh_kind`] then says [`BvhKind::Bvh2`]).
    #[default]
    Wide4,
}

/// How a mesh's surface normal is chosen at a hit (for shading and secondary-ray directions;
/// the geometric normal always decides the side and the secondary-ray offset).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum MeshShading {
    /// The triangle's geometric normal (faceted look). The default, and what
    /// [`SceneBuilder::add_mesh`] gives.
    #[default]
    Flat,
    /// The vertex normals interpolated with the hit's barycentric weights and renormalised
    /// (Phong 1975); a mesh given without normals is flat shaded.
    VertexNormals,
    /// As [`MeshShading::VertexNormals`]; a mesh given without normals gets, at each vertex, the
    /// angle-weighted mean of the unit normals of the triangles that share it (Thürmer and
    /// Wüthrich 1998). Only triangles that share a vertex *index* are averaged: a mesh whose
    /// vertices are duplicated per face stays faceted.
    VertexNormalsOrAveraged,
}

/// What was added and what was skipped as degenerate.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BuildStats {
    pub spheres: usize,
    pub cylinders: usize,
    pub triangles: usize,
    pub meshes: usize,
    pub skipped_spheres: usize,
    pub skipped_cylinders: usize,
    pub skipped_triangles: usize,
}

/// What kind of primitive a [`Hit`] is on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HitKind {
    Sphere,
    Cylinder {
        part: CylinderPart,
    },
    /// A mesh triangle; `bary` are the barycentric weights of the triangle's 2nd and 3rd vertex.
    Triangle {
        mesh: u32,
        bary: Vec2,
    },
}

/// The closest intersection along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter (distance for a unit direction).
    pub t: f32,
    /// World-space hit point (re-projected onto the sphere for spheres, barycentric for triangles,
    /// which is more accurate than `origin + t·dir`).
    pub point: Vec3,
    /// Unit geometric normal: outward for spheres and cylinders, `(v1 − v0) × (v2 − v0)` for
    /// triangles (not flipped toward the ray).
    pub normal: Vec3,
    /// Unit shading normal: equal to `normal` except on smooth-shaded meshes
    /// ([`MeshShading`]), where it is the interpolated vertex normal turned to the same side as
    /// `normal`.
    pub shading_normal: Vec3,
    /// Sphere id, cylinder id (the return values of `add_sphere`/`add_cylinder`), or the
    /// triangle's index within its mesh.
    pub prim_id: u32,
    pub material_id: u32,
    pub kind: HitKind,
}

#[derive(Clone, Copy, Debug)]
struct Cylinder {
    a: Vec3,
    b: Vec3,
    radius: f32,
    material: u32,
}

#[derive(Clone, Copy, Debug)]
struct TriMeta {
    mesh: u32,
    index: u32,
    idx: [u32; 3],
}

#[derive(Clone, Debug)]
struct MeshInfo {
    uvs: Option<Vec<Vec2>>,
    /// Unit vertex normals (zero where the given one was unusable), or `None` for flat shading.
    normals: Option<Vec<Vec3>>,
    material: u32,
}

/// One BVH leaf entry; spheres carry their geometry inline.
#[derive(Clone, Copy, Debug)]
enum Prim {
    Sphere { center: Vec3, radius: f32, id: u32 },
    Cylinder { id: u32 },
    Triangle { tri: u32 },
}

/// Collects primitives; [`SceneBuilder::build`] builds the BVH once.
///
/// ```
/// use texmap_reftrace::{SceneBuilder, glam::Vec3};
/// use texmap_core::camera::Ray;
/// let mut b = SceneBuilder::new();
/// let id = b.add_sphere(Vec3::ZERO, 1.0, 0);
/// let scene = b.build();
/// let hit = scene.intersect(&Ray { origin: Vec3::new(0.0, 0.0, 5.0), dir: Vec3::NEG_Z }).unwrap();
/// assert_eq!(hit.prim_id, id);
/// assert!((hit.t - 4.0).abs() < 1e-6);
/// ```
#[derive(Clone, Debug, Default)]
pub struct SceneBuilder {
    kind: BvhKind,
    spheres: Vec<[f32; 4]>,
    sphere_material: Vec<u32>,
    cylinders: Vec<Cylinder>,
    tris: Vec<[Vec3; 3]>,
    tri_meta: Vec<TriMeta>,
    meshes: Vec<MeshInfo>,
    stats: BuildStats,
}

impl SceneBuilder {
    pub fn new() -> SceneBuilder {
        SceneBuilder::default()
    }

    /// A builder with room for `spheres` spheres (no reallocation while adding them).
    pub fn with_sphere_capacity(spheres: usize) -> SceneBuilder {
        SceneBuilder {
            spheres: Vec::with_capacity(spheres),
            sphere_material: Vec::with_capacity(spheres),
            ..SceneBuilder::default()
        }
    }

    /// Choose the BVH layout (default [`BvhKind::CwBvh`]).
    pub fn bvh(mut self, kind: BvhKind) -> SceneBuilder {
        self.kind = kind;
        self
    }

    /// Add a sphere; returns its id (ids count from 0 in call order, skipped spheres included).
    /// A sphere with a non-finite centre or a radius that is not finite and positive is skipped
    /// and counted in [`BuildStats::skipped_spheres`].
    pub fn add_sphere(&mut self, center: Vec3, radius: f32, material_id: u32) -> u32 {
        let id = self.spheres.len() as u32;
        self.spheres.push([center.x, center.y, center.z, radius]);
        self.sphere_material.push(material_id);
        id
    }

    /// Add a capped cylinder (a bond) from `a` to `b`; returns its id (call order, from 0).
    /// Degenerate cylinders are skipped and counted (see module docs).
    pub fn add_cylinder(&mut self, a: Vec3, b: Vec3, radius: f32, material_id: u32) -> u32 {
        let id = self.cylinders.len() as u32;
        self.cylinders.push(Cylinder {
            a,
            b,
            radius,
            material: material_id,
        });
        id
    }

    /// Add a triangle mesh; returns the mesh id (call order, from 0). Zero-area triangles and
    /// triangles with a non-finite vertex are skipped and counted; malformed index or uv lists are
    /// refused.
    pub fn add_mesh(
        &mut self,
        positions: &[Vec3],
        indices: &[u32],
        uvs: Option<&[Vec2]>,
        material_id: u32,
    ) -> Result<u32, SceneError> {
        self.add_mesh_shaded(
            positions,
            indices,
            uvs,
            None,
            MeshShading::Flat,
            material_id,
        )
    }

    /// [`SceneBuilder::add_mesh`] with vertex normals (one per vertex, any length) and a choice
    /// of [`MeshShading`]. A given normal that is zero or not finite makes the shading normal
    /// fall back to the geometric one wherever that vertex has weight; a normal-count mismatch is
    /// refused.
    ///
    /// ```
    /// use texmap_core::camera::Ray;
    /// use texmap_reftrace::{MeshShading, SceneBuilder, glam::Vec3};
    /// // One triangle in the plane z = 0 whose vertex normals lean apart.
    /// let p = [Vec3::ZERO, Vec3::X, Vec3::Y];
    /// let n = [Vec3::Z, Vec3::new(1.0, 0.0, 1.0), Vec3::new(0.0, 1.0, 1.0)];
    /// let mut b = SceneBuilder::new();
    /// b.add_mesh_shaded(&p, &[0, 1, 2], None, Some(&n), MeshShading::VertexNormals, 0)
    ///     .unwrap();
    /// let ray = Ray { origin: Vec3::new(0.25, 0.25, 1.0), dir: Vec3::NEG_Z };
    /// let hit = b.build().intersect(&ray).unwrap();
    /// assert_eq!(hit.normal, Vec3::Z); // geometric
    /// // Interpolated with weights (0.5, 0.25, 0.25): leans toward +x and +y.
    /// let s = hit.shading_normal;
    /// assert!(s.x > 0.1 && (s.x - s.y).abs() < 1e-6 && (s.length() - 1.0).abs() < 1e-6);
    /// ```
    pub fn add_mesh_shaded(
        &mut self,
        positions: &[Vec3],
        indices: &[u32],
        uvs: Option<&[Vec2]>,
        normals: Option<&[Vec3]>,
        shading: MeshShading,
        material_id: u32,
    ) -> Result<u32, SceneError> {
        // Validate the whole mesh before touching the builder.
        if let Some(n) = normals
            && n.len() != positions.len()
        {
            return Err(SceneError::NormalCountMismatch {
                normals: n.len(),
                vertices: positions.len(),
            });
        }
        if !indices.len().is_multiple_of(3) {
            return Err(SceneError::IndicesNotTriangles { len: indices.len() });
        }
        if let Some(uv) = uvs
            && uv.len() != positions.len()
        {
            return Err(SceneError::UvCountMismatch {
                uvs: uv.len(),
                vertices: positions.len(),
            });
        }
        for (k, &i) in indices.iter().enumerate() {
            if i as usize >= positions.len() {
                return Err(SceneError::IndexOutOfRange {
                    triangle: k / 3,
                    index: i,
                    vertex_count: positions.len(),
                });
            }
        }
        if self.tris.len() + indices.len() / 3 >= u32::MAX as usize
            || self.meshes.len() >= u32::MAX as usize
        {
            return Err(SceneError::TooManyPrimitives);
        }
        let mesh = self.meshes.len() as u32;
        // Vertex normals for smooth shading: given ones normalised, or averaged from the faces.
        let vertex_normals = match (shading, normals) {
            (MeshShading::Flat, _) | (MeshShading::VertexNormals, None) => None,
            (_, Some(n)) => Some(
                n.iter()
                    .map(|v| {
                        let u = v.normalize_or_zero();
                        if u.is_finite() { u } else { Vec3::ZERO }
                    })
                    .collect(),
            ),
            (MeshShading::VertexNormalsOrAveraged, None) => {
                Some(averaged_vertex_normals(positions, indices))
            }
        };
        self.meshes.push(MeshInfo {
            uvs: uvs.map(|u| u.to_vec()),
            normals: vertex_normals,
            material: material_id,
        });
        self.stats.meshes += 1;
        // Copy each usable triangle's vertices (bit-exact, so shared edges stay shared).
        self.tris.reserve(indices.len() / 3);
        self.tri_meta.reserve(indices.len() / 3);
        for (k, t) in indices.chunks_exact(3).enumerate() {
            let v = [
                positions[t[0] as usize],
                positions[t[1] as usize],
                positions[t[2] as usize],
            ];
            let area2 = (v[1] - v[0]).cross(v[2] - v[0]);
            let ok = v.iter().all(|p| p.is_finite())
                && area2.is_finite()
                && area2.length_squared() > 0.0;
            if !ok {
                self.stats.skipped_triangles += 1;
                continue;
            }
            self.tris.push(v);
            self.tri_meta.push(TriMeta {
                mesh,
                index: k as u32,
                idx: [t[0], t[1], t[2]],
            });
        }
        Ok(mesh)
    }

    /// [`SceneBuilder::add_mesh`] for a [`TriMesh`] (flat shaded), e.g. one read from OBJ or glTF
    /// by `texmap_mesh`.
    pub fn add_mesh_data(&mut self, mesh: &TriMesh, material_id: u32) -> Result<u32, SceneError> {
        self.add_mesh_data_shaded(mesh, MeshShading::Flat, material_id)
    }

    /// [`SceneBuilder::add_mesh_shaded`] for a [`TriMesh`]: its normals (if the file had them)
    /// with the chosen [`MeshShading`].
    pub fn add_mesh_data_shaded(
        &mut self,
        mesh: &TriMesh,
        shading: MeshShading,
        material_id: u32,
    ) -> Result<u32, SceneError> {
        self.add_mesh_shaded(
            &mesh.positions,
            mesh.indices(),
            mesh.uvs.as_deref(),
            mesh.normals.as_deref(),
            shading,
            material_id,
        )
    }

    /// Build the BVH over every valid primitive.
    pub fn build(self) -> Scene {
        let SceneBuilder {
            kind,
            spheres,
            sphere_material,
            cylinders,
            tris,
            tri_meta,
            meshes,
            mut stats,
        } = self;
        // Gather valid primitives and their boxes.
        let mut prims = Vec::with_capacity(spheres.len() + cylinders.len() + tris.len());
        let mut boxes = Vec::with_capacity(prims.capacity());
        let mut max_material: Option<u32> = None;
        let mut use_material = |m: u32| {
            max_material = Some(max_material.map_or(m, |x| x.max(m)));
        };
        for (id, s) in spheres.iter().enumerate() {
            let c = Vec3::new(s[0], s[1], s[2]);
            let r = s[3];
            if !(c.is_finite() && r.is_finite() && r > 0.0 && (c.abs() + r).is_finite()) {
                stats.skipped_spheres += 1;
                continue;
            }
            stats.spheres += 1;
            use_material(sphere_material[id]);
            prims.push(Prim::Sphere {
                center: c,
                radius: r,
                id: id as u32,
            });
            boxes.push(padded(c - Vec3::splat(r), c + Vec3::splat(r)));
        }
        for (id, c) in cylinders.iter().enumerate() {
            let ok = c.a.is_finite()
                && c.b.is_finite()
                && c.radius.is_finite()
                && c.radius > 0.0
                && (c.b - c.a).length() > 0.0
                && (c.b - c.a).length().is_finite();
            if !ok {
                stats.skipped_cylinders += 1;
                continue;
            }
            stats.cylinders += 1;
            use_material(c.material);
            prims.push(Prim::Cylinder { id: id as u32 });
            // Box of the two end discs: per axis, the disc extent is r·sqrt(1 − u_k²).
            let u = (c.b - c.a).normalize();
            let e = Vec3::splat(c.radius) * (Vec3::ONE - u * u).max(Vec3::ZERO).sqrt();
            boxes.push(padded(c.a.min(c.b) - e, c.a.max(c.b) + e));
        }
        for (i, t) in tris.iter().enumerate() {
            prims.push(Prim::Triangle { tri: i as u32 });
            boxes.push(padded(t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2])));
        }
        stats.triangles = tris.len();
        for m in &meshes {
            if stats.triangles > 0 {
                use_material(m.material);
            }
        }
        // Build the BVH and lay the primitives out in leaf order.
        let params = BvhBuildParams::medium_build();
        // The 4-wide tree wants one primitive per binary leaf: its four-box test is cheaper than
        // a second leaf test (callgrind, S2-like scene: leaves of ≤ 8 / 4 / 2 / 1 primitives
        // cost 496 / 480 / 439 / 424 M instructions per 480x270 frame).
        let wide_params = BvhBuildParams {
            max_prims_per_leaf: 1,
            collapse_traversal_cost: 1.0,
            ..params
        };
        let mut t = Duration::ZERO;
        let accel = if boxes.is_empty() {
            Accel::Empty
        } else {
            match kind {
                BvhKind::Bvh2 => Accel::Bvh2(build_bvh2(&boxes, params, &mut t)),
                BvhKind::CwBvh => Accel::CwBvh(build_cwbvh(&boxes, params, &mut t)),
                BvhKind::Wide4 => {
                    let b2 = build_bvh2(&boxes, wide_params, &mut t);
                    match Wide4::from_bvh2(&b2) {
                        Some(w) => Accel::Wide4(w, b2.primitive_indices),
                        None => Accel::Bvh2(b2),
                    }
                }
            }
        };
        let order: &[u32] = match &accel {
            Accel::Empty => &[],
            Accel::Wide4(_, order) => order,
            Accel::Bvh2(b) => &b.primitive_indices,
            Accel::CwBvh(b) => &b.primitive_indices,
        };
        let leaf_prims: Vec<Prim> = order.iter().map(|&i| prims[i as usize]).collect();
        // A scene of spheres alone gets the sphere-only leaf kernel over a flat array.
        let sphere_slots = if stats.cylinders == 0 && stats.triangles == 0 {
            leaf_prims
                .iter()
                .map(|p| match *p {
                    Prim::Sphere { center, radius, .. } => center.extend(radius),
                    _ => Vec4::ZERO,
                })
                .collect()
        } else {
            Vec::new()
        };
        Scene {
            accel,
            prims: leaf_prims,
            sphere_slots,
            spheres,
            sphere_material,
            cylinders,
            tris,
            tri_meta,
            meshes,
            stats,
            max_material,
        }
    }
}

/// Angle-weighted vertex normals (Thürmer and Wüthrich 1998): each triangle adds its unit
/// normal, weighted by its interior angle at the vertex, to its three vertices; computed in f64.
/// Zero-area and non-finite triangles add nothing; a vertex no usable triangle touches gets zero
/// (its weight then falls back to the geometric normal at a hit). Indices must be in range.
fn averaged_vertex_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut acc = vec![glam::DVec3::ZERO; positions.len()];
    for t in indices.chunks_exact(3) {
        let p = [t[0], t[1], t[2]].map(|i| positions[i as usize].as_dvec3());
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let len = n.length();
        if !(len > 0.0 && len.is_finite()) {
            continue;
        }
        let n = n / len;
        for k in 0..3 {
            // Interior angle at corner k from the two unit edges leaving it.
            let e1 = (p[(k + 1) % 3] - p[k]).normalize_or_zero();
            let e2 = (p[(k + 2) % 3] - p[k]).normalize_or_zero();
            let angle = e1.dot(e2).clamp(-1.0, 1.0).acos();
            acc[t[k] as usize] += n * angle;
        }
    }
    acc.iter()
        .map(|a| {
            let u = a.normalize_or_zero().as_vec3();
            if u.is_finite() { u } else { Vec3::ZERO }
        })
        .collect()
}

/// A primitive box padded by [`BOX_PAD_REL`] of its magnitude.
fn padded(lo: Vec3, hi: Vec3) -> Aabb {
    let mag = lo.abs().max(hi.abs()).max_element() + (hi - lo).max_element();
    let pad = Vec3::splat(mag * BOX_PAD_REL + f32::MIN_POSITIVE);
    Aabb::new(Vec3A::from(lo - pad), Vec3A::from(hi + pad))
}

#[derive(Clone)]
enum Accel {
    Empty,
    Bvh2(Bvh2),
    CwBvh(CwBvh),
    /// The 4-wide tree and the leaf order of the primitives.
    Wide4(Wide4, Vec<u32>),
}

/// The closest hit found so far during traversal (slot index into leaf order).
#[derive(Clone, Copy, Debug)]
pub(crate) struct RawHit {
    pub t: f32,
    slot: u32,
    b1: f32,
    b2: f32,
    part: CylinderPart,
    normal: Vec3,
}

/// A built scene: immutable, `Sync`, queried by many threads at once.
#[derive(Clone)]
pub struct Scene {
    accel: Accel,
    prims: Vec<Prim>,
    /// `(centre, radius)` per leaf slot when the scene holds spheres only, else empty.
    sphere_slots: Vec<Vec4>,
    spheres: Vec<[f32; 4]>,
    sphere_material: Vec<u32>,
    cylinders: Vec<Cylinder>,
    tris: Vec<[Vec3; 3]>,
    tri_meta: Vec<TriMeta>,
    meshes: Vec<MeshInfo>,
    stats: BuildStats,
    max_material: Option<u32>,
}

impl std::fmt::Debug for Scene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Scene")
            .field("stats", &self.stats)
            .field("max_material", &self.max_material)
            .finish_non_exhaustive()
    }
}

impl Scene {
    /// Counts of primitives added and skipped.
    pub fn stats(&self) -> BuildStats {
        self.stats
    }

    /// The radius of the sphere or cylinder `hit` lies on; `None` for a triangle.
    pub(crate) fn hit_radius(&self, hit: &Hit) -> Option<f32> {
        match hit.kind {
            HitKind::Sphere => Some(self.spheres[hit.prim_id as usize][3]),
            HitKind::Cylinder { .. } => Some(self.cylinders[hit.prim_id as usize].radius),
            HitKind::Triangle { .. } => None,
        }
    }

    /// The largest material id a primitive of the scene uses (`None` for an empty scene).
    pub fn max_material_id(&self) -> Option<u32> {
        self.max_material
    }

    /// The BVH layout in use (`None` for an empty scene).
    pub fn bvh_kind(&self) -> Option<BvhKind> {
        match self.accel {
            Accel::Empty => None,
            Accel::Bvh2(_) => Some(BvhKind::Bvh2),
            Accel::CwBvh(_) => Some(BvhKind::CwBvh),
            Accel::Wide4(..) => Some(BvhKind::Wide4),
        }
    }

    /// Closest hit with `t > 0`. A ray with a non-finite origin, or a direction that is zero or
    /// not finite, misses.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.intersect_range(ray, 0.0, f32::INFINITY)
    }

    /// Closest hit with `tmin < t < tmax`.
    pub fn intersect_range(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
        if !valid_ray(ray) || tmin.is_nan() || tmax.is_nan() {
            return None;
        }
        let pre = RayPre::new(ray.origin, ray.dir);
        self.closest(&pre, tmin, tmax)
            .map(|r| self.finish(&pre, &r))
    }

    /// The same query by testing every primitive (no BVH): slow, exact same leaf tests. For
    /// tests of the BVH and of other crates.
    pub fn intersect_brute_force(&self, ray: &Ray) -> Option<Hit> {
        if !valid_ray(ray) {
            return None;
        }
        let pre = RayPre::new(ray.origin, ray.dir);
        let mut best = RawHit::none(f32::INFINITY);
        for slot in 0..self.prims.len() {
            self.test_prim(&pre, 0.0, slot, &mut best);
        }
        (best.t < f32::INFINITY).then(|| self.finish(&pre, &best))
    }

    /// Test primitive `slot` and keep it in `best` if nearer.
    #[inline(always)]
    fn test_prim(&self, pre: &RayPre, tmin: f32, slot: usize, best: &mut RawHit) -> f32 {
        match self.prims[slot] {
            Prim::Sphere { center, radius, .. } => {
                if let Some(t) = intersect_sphere(pre.origin, pre.dir, center, radius, tmin, best.t)
                {
                    *best = RawHit {
                        t,
                        slot: slot as u32,
                        ..*best
                    };
                    return t;
                }
            }
            Prim::Cylinder { id } => {
                let c = &self.cylinders[id as usize];
                if let Some(h) =
                    intersect_cylinder(pre.origin, pre.dir, c.a, c.b, c.radius, tmin, best.t)
                {
                    *best = RawHit {
                        t: h.t,
                        slot: slot as u32,
                        b1: 0.0,
                        b2: 0.0,
                        part: h.part,
                        normal: h.normal,
                    };
                    return h.t;
                }
            }
            Prim::Triangle { tri } => {
                let v = &self.tris[tri as usize];
                if let Some(h) = intersect_triangle(pre, v[0], v[1], v[2], tmin, best.t) {
                    *best = RawHit {
                        t: h.t,
                        slot: slot as u32,
                        b1: h.b1,
                        b2: h.b2,
                        ..*best
                    };
                    return h.t;
                }
            }
        }
        f32::INFINITY
    }

    /// BVH closest-hit query on a precomputed ray. `pre` must hold a valid ray.
    #[inline]
    pub(crate) fn closest(&self, pre: &RayPre, tmin: f32, tmax: f32) -> Option<RawHit> {
        let mut best = RawHit::none(tmax);
        let bvh_ray = || BvhRay::new(Vec3A::from(pre.origin), Vec3A::from(pre.dir), tmin, tmax);
        match &self.accel {
            Accel::Empty => {}
            Accel::Bvh2(b) => {
                b.ray_traverse(bvh_ray(), &mut RayHit::none(), |_, i| {
                    self.test_prim(pre, tmin, i, &mut best)
                });
            }
            Accel::CwBvh(b) => {
                b.ray_traverse(bvh_ray(), &mut RayHit::none(), |_, i| {
                    self.test_prim(pre, tmin, i, &mut best)
                });
            }
            Accel::Wide4(w, _) if !self.sphere_slots.is_empty() => {
                // Spheres only: the kernel is chosen here, outside the traversal loop.
                let slab = SlabRay::new(pre.origin, pre.dir);
                let spheres = &self.sphere_slots[..];
                let (o, d) = (pre.origin, pre.dir);
                let mut best_slot = u32::MAX;
                let mut best_t = tmax;
                STACK.with(|s| {
                    let mut stack = s.borrow_mut();
                    w.traverse(&slab, tmin, tmax, &mut stack, |slot| {
                        let s = spheres[slot];
                        if let Some(t) = intersect_sphere(o, d, s.truncate(), s.w, tmin, best_t) {
                            best_t = t;
                            best_slot = slot as u32;
                        }
                        best_t
                    });
                });
                if best_slot != u32::MAX {
                    best.t = best_t;
                    best.slot = best_slot;
                }
            }
            Accel::Wide4(w, _) => {
                let slab = SlabRay::new(pre.origin, pre.dir);
                STACK.with(|s| {
                    let mut stack = s.borrow_mut();
                    w.traverse(&slab, tmin, tmax, &mut stack, |slot| {
                        self.test_prim(pre, tmin, slot, &mut best);
                        best.t
                    });
                });
            }
        }
        (best.t < tmax).then_some(best)
    }

    /// Turn a raw hit into a public [`Hit`] (normal, exact point, ids).
    pub(crate) fn finish(&self, pre: &RayPre, r: &RawHit) -> Hit {
        match self.prims[r.slot as usize] {
            Prim::Sphere { center, radius, id } => {
                // Re-project the hit point onto the sphere to remove the error of o + t·d.
                let p = pre.origin + pre.dir * r.t;
                let n = (p - center).normalize_or(-pre.dir.normalize());
                Hit {
                    t: r.t,
                    point: center + n * radius,
                    normal: n,
                    shading_normal: n,
                    prim_id: id,
                    material_id: self.sphere_material[id as usize],
                    kind: HitKind::Sphere,
                }
            }
            Prim::Cylinder { id } => Hit {
                t: r.t,
                point: pre.origin + pre.dir * r.t,
                normal: r.normal,
                shading_normal: r.normal,
                prim_id: id,
                material_id: self.cylinders[id as usize].material,
                kind: HitKind::Cylinder { part: r.part },
            },
            Prim::Triangle { tri } => {
                let v = &self.tris[tri as usize];
                let m = &self.tri_meta[tri as usize];
                let b0 = 1.0 - r.b1 - r.b2;
                let n = (v[1] - v[0])
                    .cross(v[2] - v[0])
                    .normalize_or(-pre.dir.normalize());
                let info = &self.meshes[m.mesh as usize];
                let shading_normal = match &info.normals {
                    None => n,
                    Some(vn) => {
                        // Phong: interpolate the vertex normals with the hit's barycentrics,
                        // renormalise, and turn to the geometric normal's side.
                        let s = vn[m.idx[0] as usize] * b0
                            + vn[m.idx[1] as usize] * r.b1
                            + vn[m.idx[2] as usize] * r.b2;
                        let s = s.normalize_or_zero();
                        if s == Vec3::ZERO || !s.is_finite() {
                            n
                        } else if s.dot(n) < 0.0 {
                            -s
                        } else {
                            s
                        }
                    }
                };
                Hit {
                    t: r.t,
                    point: v[0] * b0 + v[1] * r.b1 + v[2] * r.b2,
                    normal: n,
                    shading_normal,
                    prim_id: m.index,
                    material_id: info.material,
                    kind: HitKind::Triangle {
                        mesh: m.mesh,
                        bary: Vec2::new(r.b1, r.b2),
                    },
                }
            }
        }
    }

    /// For a triangle hit: the triangle's vertices and its texture coordinates (if its mesh has
    /// any).
    pub(crate) fn triangle_uv_data(&self, hit: &Hit) -> Option<([Vec3; 3], [Vec2; 3])> {
        let HitKind::Triangle { mesh, .. } = hit.kind else {
            return None;
        };
        let info = &self.meshes[mesh as usize];
        let uvs = info.uvs.as_ref()?;
        // Find the triangle's record: meshes are stored contiguously, search by (mesh, index).
        let k = self
            .tri_meta
            .partition_point(|m| (m.mesh, m.index) < (mesh, hit.prim_id));
        let m = self.tri_meta.get(k)?;
        debug_assert!(m.mesh == mesh && m.index == hit.prim_id);
        let idx = m.idx;
        Some((
            self.tris[k],
            [
                uvs[idx[0] as usize],
                uvs[idx[1] as usize],
                uvs[idx[2] as usize],
            ],
        ))
    }

    /// The sphere with id `id` as (centre, radius), as added (also for skipped ones).
    pub fn sphere(&self, id: u32) -> Option<(Vec3, f32)> {
        self.spheres
            .get(id as usize)
            .map(|s| (Vec3::new(s[0], s[1], s[2]), s[3]))
    }
}

impl RawHit {
    #[inline]
    fn none(tmax: f32) -> RawHit {
        RawHit {
            t: tmax,
            slot: u32::MAX,
            b1: 0.0,
            b2: 0.0,
            part: CylinderPart::Side,
            normal: Vec3::ZERO,
        }
    }
}

#[inline]
pub(crate) fn valid_ray(ray: &Ray) -> bool {
    ray.origin.is_finite() && ray.dir.is_finite() && ray.dir.length_squared() > 0.0
}

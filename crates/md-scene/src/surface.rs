//! Molecular surfaces as VMD's QuickSurf draws them: one Gaussian per atom summed on a grid,
//! the isosurface extracted by surface nets, every vertex then moved onto the exact isosurface
//! and given its exact normal and the colour of the atom that dominates it; drawn by the
//! rasteriser and composited by depth over the frame the sphere methods made ([`draw_mesh`]).
//!
//! # The density
//! `ρ(p) = Σ_i exp(−|p − c_i|² / (2 σ_i²))` with `σ_i = s · r_i / √(2 ln(1/ρ₀))`, so that the
//! surface `ρ = ρ₀` of an isolated atom is the sphere of radius `s · r_i` (`s` the radius scale:
//! 1, the default, gives the van der Waals surface, smoothed where atoms overlap; `ρ₀` the
//! isovalue, 0.5 as in VMD). Each Gaussian is cut off where it falls below [`CUTOFF`] of its
//! peak ([`CUT_SIGMAS`] σ), and the sampled density, which only decides where the vertices
//! start, where it falls below 1e-3: an atom touches a bounded block of the grid.
//!
//! # Extraction
//! The density is sampled on a grid of spacing `h` (at most [`MAX_VOXELS`] samples: a larger
//! system is sampled coarser and [`MolMesh::spacing`] says how coarse), summed per atom over
//! slabs of planes in parallel, each sample's sum in atom order, so the result is the same for
//! any thread count. Surface nets (Gibson 1998): one vertex per grid cell whose corners straddle
//! `ρ₀`, at the mean of its edges' linear crossings; one quad per grid edge that crosses, joining
//! the four cells around it, wound counter-clockwise seen from outside. The mesh is closed: a
//! crossing edge is shared by exactly four cells, each of which therefore has a vertex, and the
//! grid is padded so that no crossing lies on its border.
//!
//! Each vertex then takes up to [`NEWTON_STEPS`] Newton steps `p ← p − (ρ(p) − ρ₀) ∇ρ / |∇ρ|²` (each
//! at most half a cell) on the exact, not the sampled, density: vertices lie on the true
//! isosurface to within float rounding, and the normal `−∇ρ / |∇ρ|` there is exact too, so the
//! grid only decides how finely the surface is cut into triangles. Each vertex takes the
//! material of the atom contributing most to the density there, as PyMOL colours a surface by
//! its nearest atom; a triangle whose vertices differ is cut between its edges' midpoints (and
//! its centroid, for three materials), the new vertices projected onto the surface too, and each
//! piece takes its vertex's material, so colour boundaries cross triangles rather than follow
//! their edges in steps.
//!
//! ```
//! use glam::Vec3;
//! use texmap_md_scene::surface::{MolMesh, SurfaceAtoms, SurfaceOptions};
//!
//! // One carbon-sized atom: its surface is its sphere of radius 1.7 Å.
//! let mut atoms = SurfaceAtoms::default();
//! atoms.push(Vec3::new(1.0, 2.0, 3.0), 1.7, 0);
//! let s = MolMesh::surface(&atoms, &SurfaceOptions::default()).unwrap();
//! for p in &s.positions {
//!     assert!(((*p - Vec3::new(1.0, 2.0, 3.0)).length() - 1.7).abs() < 1e-4);
//! }
//! // Closed and wound outward: the enclosed volume is the sphere's, less the chords' sag.
//! let sphere = 4.0 / 3.0 * std::f64::consts::PI * 1.7f64.powi(3);
//! assert!(s.volume() > 0.95 * sphere && s.volume() < sphere);
//! ```

use glam::Vec3;
use rayon::prelude::*;
use texmap_core::camera::Camera;
use texmap_core::color::{linear_to_srgb8, srgb8_to_linear_rgb};
use texmap_core::frame::Frame;
use texmap_core::shade::{Lighting, Material};
use texmap_mesh::TriMesh;
use texmap_raster::{DrawState, Framebuffer, Mesh, RasterError, Shading};

/// A Gaussian is cut off where it falls below this fraction of its peak.
pub const CUTOFF: f32 = 1e-6;
/// The cut-off radius in units of σ: `√(2 ln(1/CUTOFF))`.
pub const CUT_SIGMAS: f32 = 5.256_521;
/// The sampled density's cut-off radius in units of σ, `√(2 ln 1000)`: it only decides which
/// cells hold a vertex, so it stops at 1e-3 of each peak (a third of the samples per atom).
const GRID_CUT_SIGMAS: f32 = 3.716_922;
/// Most density samples one surface allocates (128 MiB of f32, plus as many vertex slots).
pub const MAX_VOXELS: usize = 1 << 25;
/// Most Newton steps that move a vertex onto the exact isosurface.
pub const NEWTON_STEPS: usize = 6;
/// A vertex whose density is this close to the isovalue takes no further step.
const CONVERGED: f32 = 2e-6;
/// Grid planes per parallel slab of the density sum.
const SLAB: usize = 4;

/// How a surface is made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceOptions {
    /// Grid spacing (Å): finer cuts the surface into more, smaller triangles.
    pub spacing: f32,
    /// An isolated atom's surface radius as a multiple of its radius.
    pub radius_scale: f32,
    /// The density level of the surface, in (0, 1).
    pub isovalue: f32,
}

impl Default for SurfaceOptions {
    /// Spacing 0.5 Å, radius scale 1, isovalue 0.5.
    fn default() -> SurfaceOptions {
        SurfaceOptions {
            spacing: 0.5,
            radius_scale: 1.0,
            isovalue: 0.5,
        }
    }
}

/// A surface option out of its range.
#[derive(Clone, Debug, PartialEq)]
pub enum SurfaceError {
    /// The option's name, its value and the range it must lie in.
    BadOption {
        name: &'static str,
        value: f32,
        expected: &'static str,
    },
}

impl std::fmt::Display for SurfaceError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SurfaceError::BadOption {
                name,
                value,
                expected,
            } => write!(f, "surface {name} {value}: expected {expected}"),
        }
    }
}

impl std::error::Error for SurfaceError {}

/// The atoms a surface wraps: centres (Å), radii and material indices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SurfaceAtoms {
    pub centers: Vec<Vec3>,
    pub radii: Vec<f32>,
    pub kinds: Vec<u16>,
}

impl SurfaceAtoms {
    pub fn push(&mut self, center: Vec3, radius: f32, kind: u16) {
        self.centers.push(center);
        self.radii.push(radius);
        self.kinds.push(kind);
    }

    pub fn len(&self) -> usize {
        self.centers.len()
    }

    pub fn is_empty(&self) -> bool {
        self.centers.is_empty()
    }

    pub fn clear(&mut self) {
        self.centers.clear();
        self.radii.clear();
        self.kinds.clear();
    }
}

/// A closed triangle mesh drawn over a frame by [`draw_mesh`]: a molecular surface
/// ([`MolMesh::surface`]) or a protein cartoon ([`crate::cartoon`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MolMesh {
    pub positions: Vec<Vec3>,
    /// Unit outward normals, one per vertex.
    pub normals: Vec<Vec3>,
    /// Counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
    /// The material index of each triangle.
    pub kinds: Vec<u16>,
    /// A surface's grid spacing (Å): the one asked for, or coarser when the grid would have
    /// held more than [`MAX_VOXELS`] samples (0 for a cartoon).
    pub spacing: f32,
}

/// One valid atom's Gaussian.
#[derive(Clone, Copy)]
struct Blob {
    center: Vec3,
    /// `1 / (2 σ²)`.
    inv2s2: f32,
    cut: f32,
    /// The cut-off radius of the sampled density.
    grid_cut: f32,
    /// The atom's position in the input (for the dominant atom's kind).
    atom: u32,
}

/// The atoms binned in cubes of half the largest cut-off, stored cell by cell (each cell's in
/// input order), for exact evaluation at a point: the 5x5x5 cells around a point hold every atom
/// within reach with 42 % fewer to test than 3x3x3 cells of the whole cut-off.
struct Lookup {
    /// The blobs in cell order.
    blobs: Vec<Blob>,
    origin: Vec3,
    cell: f32,
    dims: [usize; 3],
    /// `blobs[start[c]..start[c + 1]]` are cell `c`'s.
    start: Vec<u32>,
}

/// Cells each side of a point's own that [`Lookup::eval`] visits.
const REACH: i64 = 2;

impl Lookup {
    fn new(blobs: Vec<Blob>, lo: Vec3, hi: Vec3) -> Lookup {
        let cut = blobs.iter().map(|b| b.cut).fold(0.0f32, f32::max).max(1e-3);
        let mut cell = (cut / REACH as f32) as f64;
        // At most ~2M cells: a sparse system's cells grow instead (in f64: the extent of atoms
        // near ±f32::MAX does not fit an f32).
        let extent = (hi.as_dvec3() - lo.as_dvec3()).max(glam::DVec3::splat(cell));
        let dims = loop {
            let d = (extent / cell).ceil().max(glam::DVec3::ONE);
            if d.x * d.y * d.z <= (1 << 21) as f64 {
                break [d.x as usize, d.y as usize, d.z as usize];
            }
            cell *= 2.0;
        };
        let cell = cell as f32;
        let n = dims[0] * dims[1] * dims[2];
        let cell_of = |p: Vec3| -> usize {
            let q = ((p - lo) / cell).floor();
            let c = |v: f32, d: usize| (v.max(0.0) as usize).min(d - 1);
            (c(q.z, dims[2]) * dims[1] + c(q.y, dims[1])) * dims[0] + c(q.x, dims[0])
        };
        let mut start = vec![0u32; n + 1];
        for b in &blobs {
            start[cell_of(b.center) + 1] += 1;
        }
        for c in 0..n {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut sorted = blobs.clone();
        for b in &blobs {
            let c = cell_of(b.center);
            sorted[fill[c] as usize] = *b;
            fill[c] += 1;
        }
        Lookup {
            blobs: sorted,
            origin: lo,
            cell,
            dims,
            start,
        }
    }

    /// `p0` moved onto the isosurface `ρ = iso` by up to [`NEWTON_STEPS`] Newton steps of at most
    /// `max_step` each; with the unit normal `−∇ρ / |∇ρ|` there and the atom contributing most.
    fn project(&self, p0: Vec3, iso: f32, max_step: f32) -> (Vec3, Vec3, u32) {
        let mut p = p0;
        let mut at = self.eval(p);
        for _ in 0..NEWTON_STEPS {
            let (r, g, _) = at;
            let g2 = g.length_squared();
            if (r - iso).abs() <= CONVERGED || g2 <= 0.0 || !g2.is_finite() {
                break;
            }
            let step = g * ((r - iso) / g2);
            let len = step.length();
            p -= if len > max_step {
                step * (max_step / len)
            } else {
                step
            };
            at = self.eval(p);
        }
        let (_, g, best) = at;
        (p, (-g).normalize_or_zero(), best)
    }

    /// `ρ(p)`, `∇ρ(p)` and the blob contributing most (its input index; `u32::MAX` if none).
    fn eval(&self, p: Vec3) -> (f32, Vec3, u32) {
        let q = ((p - self.origin) / self.cell).floor();
        let (mut rho, mut grad, mut best, mut best_w) = (0.0f32, Vec3::ZERO, u32::MAX, 0.0f32);
        let range = |v: f32, d: usize| {
            let v = v.clamp(-1.0, d as f32) as i64;
            (v - REACH).max(0) as usize..=((v + REACH).min(d as i64 - 1)).max(0) as usize
        };
        let xs = range(q.x, self.dims[0]);
        for z in range(q.z, self.dims[2]) {
            for y in range(q.y, self.dims[1]) {
                // The row's cells are contiguous: one run of blobs.
                let row = (z * self.dims[1] + y) * self.dims[0];
                let from = self.start[row + xs.start()] as usize;
                let to = self.start[row + xs.end() + 1] as usize;
                for b in &self.blobs[from..to] {
                    let d = p - b.center;
                    let d2 = d.length_squared();
                    if d2 >= b.cut * b.cut {
                        continue;
                    }
                    let w = (-d2 * b.inv2s2).exp();
                    rho += w;
                    grad += d * (-2.0 * b.inv2s2 * w);
                    if w > best_w {
                        (best, best_w) = (b.atom, w);
                    }
                }
            }
        }
        (rho, grad, best)
    }
}

impl MolMesh {
    /// The surface of `atoms` (atoms with a non-finite centre or a radius that is not positive
    /// and finite are left out; none left gives an empty mesh).
    pub fn surface(
        atoms: &SurfaceAtoms,
        options: &SurfaceOptions,
    ) -> Result<MolMesh, SurfaceError> {
        let bad = |name, value, expected| {
            Err(SurfaceError::BadOption {
                name,
                value,
                expected,
            })
        };
        let o = *options;
        if !(o.spacing.is_finite() && o.spacing > 0.0) {
            return bad("spacing", o.spacing, "a positive length in Å");
        }
        if !(o.radius_scale.is_finite() && o.radius_scale > 0.0) {
            return bad("radius scale", o.radius_scale, "a positive number");
        }
        if !(o.isovalue > 0.0 && o.isovalue < 1.0) {
            return bad("isovalue", o.isovalue, "a number between 0 and 1");
        }
        let k = (2.0 * (1.0 / o.isovalue).ln()).sqrt();
        let n = atoms
            .centers
            .len()
            .min(atoms.radii.len())
            .min(atoms.kinds.len());
        let blobs: Vec<Blob> = (0..n)
            .filter(|&i| {
                let r = atoms.radii[i] * o.radius_scale;
                // The cut-off box must be finite too (no radius or position near f32::MAX).
                let reach = atoms.centers[i].abs().max_element() + CUT_SIGMAS * r;
                r.is_finite() && r > 0.0 && reach.is_finite()
            })
            .map(|i| {
                let sigma = atoms.radii[i] * o.radius_scale / k;
                Blob {
                    center: atoms.centers[i],
                    inv2s2: 1.0 / (2.0 * sigma * sigma),
                    cut: CUT_SIGMAS * sigma,
                    grid_cut: GRID_CUT_SIGMAS * sigma,
                    atom: i as u32,
                }
            })
            .collect();
        let mut surface = MolMesh {
            spacing: o.spacing,
            ..Default::default()
        };
        if blobs.is_empty() {
            return Ok(surface);
        }
        let (lo, hi) = blobs.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), b| (lo.min(b.center - b.grid_cut), hi.max(b.center + b.grid_cut)),
        );
        // The grid: one spacing of padding beyond every cut-off, so no crossing on its border.
        let mut h = o.spacing as f64;
        let extent = hi.as_dvec3() - lo.as_dvec3();
        let dims = loop {
            let d = (extent / h).ceil() + 3.0;
            let count = d.x * d.y * d.z;
            if count <= MAX_VOXELS as f64 {
                break [d.x as usize, d.y as usize, d.z as usize];
            }
            h *= (count / MAX_VOXELS as f64).cbrt() * 1.001;
        };
        let h = h as f32;
        surface.spacing = h;
        let origin = lo - Vec3::splat(h);
        let rho = density(&blobs, origin, h, dims);
        let lookup = Lookup::new(blobs, lo, hi);
        surface.extract(&rho, &lookup, origin, dims, o.isovalue, atoms);
        Ok(surface)
    }

    /// Surface nets over the sampled density, then the vertices projected onto the exact one.
    fn extract(
        &mut self,
        rho: &[f32],
        lookup: &Lookup,
        origin: Vec3,
        [nx, ny, nz]: [usize; 3],
        iso: f32,
        atoms: &SurfaceAtoms,
    ) {
        let h = self.spacing;
        let at = |x: usize, y: usize, z: usize| rho[(z * ny + y) * nx + x];
        let (cx, cy, cz) = (nx - 1, ny - 1, nz - 1);
        // Vertices: per plane of cells in parallel, concatenated in plane order.
        let planes: Vec<Vec<(u32, Vec3)>> = (0..cz)
            .into_par_iter()
            .map(|z| {
                let mut out = Vec::new();
                for y in 0..cy {
                    for x in 0..cx {
                        let mut c = [0.0f32; 8];
                        let mut inside = 0u32;
                        for (i, v) in c.iter_mut().enumerate() {
                            *v = at(x + (i & 1), y + ((i >> 1) & 1), z + (i >> 2));
                            inside += (*v > iso) as u32;
                        }
                        if inside == 0 || inside == 8 {
                            continue;
                        }
                        let (mut sum, mut count) = (Vec3::ZERO, 0.0f32);
                        for (a, b) in CUBE_EDGES {
                            let (va, vb) = (c[a], c[b]);
                            if (va > iso) != (vb > iso) {
                                let t = (iso - va) / (vb - va);
                                sum += corner(a).lerp(corner(b), t);
                                count += 1.0;
                            }
                        }
                        let local = sum / count;
                        let p = origin + (Vec3::new(x as f32, y as f32, z as f32) + local) * h;
                        out.push((((z * cy + y) * cx + x) as u32, p));
                    }
                }
                out
            })
            .collect();
        let mut slot = vec![u32::MAX; cx * cy * cz];
        let mut positions = Vec::with_capacity(planes.iter().map(Vec::len).sum());
        for plane in &planes {
            for &(cell, p) in plane {
                slot[cell as usize] = positions.len() as u32;
                positions.push(p);
            }
        }
        drop(planes);
        // Onto the exact isosurface; the exact normal and the dominant atom there.
        let projected: Vec<(Vec3, Vec3, u32)> = positions
            .par_iter()
            .map(|&p0| lookup.project(p0, iso, 0.5 * h))
            .collect();
        let vertex_atom: Vec<u32> = projected.iter().map(|v| v.2).collect();
        self.positions = projected.iter().map(|v| v.0).collect();
        self.normals = projected.iter().map(|v| v.1).collect();
        // Quads: per plane of grid edges (edges whose lower sample is in plane z), in parallel.
        let positions = &self.positions;
        let cell = |x: usize, y: usize, z: usize| slot[(z * cy + y) * cx + x];
        let quads: Vec<Vec<[u32; 3]>> = (1..nz - 1)
            .into_par_iter()
            .map(|z| {
                let mut out = Vec::new();
                let mut quad = |q: [u32; 4], outward_positive: bool| {
                    let q = if outward_positive {
                        q
                    } else {
                        [q[3], q[2], q[1], q[0]]
                    };
                    if q.contains(&u32::MAX) {
                        return; // not reached: the four cells of a crossing edge have vertices
                    }
                    let p = q.map(|i| positions[i as usize]);
                    if (p[0] - p[2]).length_squared() <= (p[1] - p[3]).length_squared() {
                        out.push([q[0], q[1], q[2]]);
                        out.push([q[0], q[2], q[3]]);
                    } else {
                        out.push([q[0], q[1], q[3]]);
                        out.push([q[1], q[2], q[3]]);
                    }
                };
                for y in 1..ny - 1 {
                    for x in 1..nx - 1 {
                        let v = at(x, y, z) > iso;
                        // Edge along x from (x, y, z): cells (x, y-1..y, z-1..z).
                        if v != (at(x + 1, y, z) > iso) {
                            let q = [
                                cell(x, y - 1, z - 1),
                                cell(x, y, z - 1),
                                cell(x, y, z),
                                cell(x, y - 1, z),
                            ];
                            quad(q, v);
                        }
                        if v != (at(x, y + 1, z) > iso) {
                            let q = [
                                cell(x - 1, y, z - 1),
                                cell(x - 1, y, z),
                                cell(x, y, z),
                                cell(x, y, z - 1),
                            ];
                            quad(q, v);
                        }
                        if v != (at(x, y, z + 1) > iso) {
                            let q = [
                                cell(x - 1, y - 1, z),
                                cell(x, y - 1, z),
                                cell(x, y, z),
                                cell(x - 1, y, z),
                            ];
                            quad(q, v);
                        }
                    }
                }
                out
            })
            .collect();
        self.triangles = quads.concat();
        self.split_colour_boundaries(&vertex_atom, atoms, lookup, iso);
    }

    /// Where a triangle's vertices have different materials, cut it where each such edge crosses
    /// the boundary between its ends' dominant atoms (and at its centroid, for three materials)
    /// and give each piece the material of the vertex it holds, so that a colour boundary runs
    /// through the triangles instead of stepping along their edges. An edge's cut vertex is
    /// shared by both its triangles (the mesh stays closed); the new vertices are projected onto
    /// the exact surface as the others.
    fn split_colour_boundaries(
        &mut self,
        vertex_atom: &[u32],
        atoms: &SurfaceAtoms,
        lookup: &Lookup,
        iso: f32,
    ) {
        let kind_of = |atom: u32| atoms.kinds.get(atom as usize).copied().unwrap_or(0);
        let vertex_kind: Vec<u16> = vertex_atom.iter().map(|&a| kind_of(a)).collect();
        // Each atom's Gaussian (centre, 1 / 2σ²), by input index.
        let mut gauss = vec![(Vec3::ZERO, 0.0f32); atoms.kinds.len()];
        for b in &lookup.blobs {
            gauss[b.atom as usize] = (b.center, b.inv2s2);
        }
        let base = self.positions.len() as u32;
        let mut start: Vec<Vec3> = Vec::new();
        let mut mids: std::collections::HashMap<u64, u32> = std::collections::HashMap::new();
        let positions = &self.positions;
        let mut mid = |a: u32, b: u32, start: &mut Vec<Vec3>| -> u32 {
            let key = (a.min(b) as u64) << 32 | a.max(b) as u64;
            *mids.entry(key).or_insert_with(|| {
                // Where ln w_A − ln w_B (A, B the ends' dominant atoms) changes sign along the
                // edge: linear in the position for equal σ, interpolated linearly otherwise.
                let (p, q) = (positions[a as usize], positions[b as usize]);
                let [ga, gb] = [a, b].map(|v| {
                    gauss
                        .get(vertex_atom[v as usize] as usize)
                        .copied()
                        .unwrap_or_default()
                });
                let f = |x: Vec3| {
                    -(x - ga.0).length_squared() * ga.1 + (x - gb.0).length_squared() * gb.1
                };
                let (f0, f1) = (f(p), f(q));
                let t = f0 / (f0 - f1);
                let t = if t.is_finite() {
                    t.clamp(0.0, 1.0)
                } else {
                    0.5
                };
                start.push(p.lerp(q, t));
                base + start.len() as u32 - 1
            })
        };
        let mut triangles = Vec::with_capacity(self.triangles.len());
        let mut kinds = Vec::with_capacity(self.triangles.len());
        for &[a, b, c] in &self.triangles {
            let k = [a, b, c].map(|i| vertex_kind[i as usize]);
            if k[0] == k[1] && k[1] == k[2] {
                triangles.push([a, b, c]);
                kinds.push(k[0]);
            } else if k[0] != k[1] && k[1] != k[2] && k[0] != k[2] {
                let ab = mid(a, b, &mut start);
                let bc = mid(b, c, &mut start);
                let ca = mid(c, a, &mut start);
                let g = base + start.len() as u32;
                let p = |i: u32| positions[i as usize];
                start.push((p(a) + p(b) + p(c)) / 3.0);
                for (v, out, back, kind) in
                    [(a, ab, ca, k[0]), (b, bc, ab, k[1]), (c, ca, bc, k[2])]
                {
                    triangles.extend([[v, out, g], [v, g, back]]);
                    kinds.extend([kind, kind]);
                }
            } else {
                // Rotated (winding kept) so that `c` is the odd one out.
                let [a, b, c] = if k[0] == k[1] {
                    [a, b, c]
                } else if k[1] == k[2] {
                    [b, c, a]
                } else {
                    [c, a, b]
                };
                let (bc, ca) = (mid(b, c, &mut start), mid(c, a, &mut start));
                let (kab, kc) = (vertex_kind[a as usize], vertex_kind[c as usize]);
                triangles.extend([[a, b, bc], [a, bc, ca], [ca, bc, c]]);
                kinds.extend([kab, kab, kc]);
            }
        }
        let placed: Vec<(Vec3, Vec3, u32)> = start
            .par_iter()
            .map(|&p| lookup.project(p, iso, 0.5 * self.spacing))
            .collect();
        self.positions.extend(placed.iter().map(|v| v.0));
        self.normals.extend(placed.iter().map(|v| v.1));
        self.triangles = triangles;
        self.kinds = kinds;
    }

    /// The triangles grouped by kind, `kinds + 1` groups in kind order (the last holds every
    /// kind from `kinds` up), each in mesh order.
    pub fn by_kind(&self, kinds: usize) -> Vec<Vec<[u32; 3]>> {
        let mut groups = vec![Vec::new(); kinds + 1];
        for (t, &k) in self.triangles.iter().zip(&self.kinds) {
            groups[(k as usize).min(kinds)].push(*t);
        }
        groups
    }

    /// Appends `other`'s vertices and triangles (its indices shifted past ours).
    pub fn append(&mut self, other: &MolMesh) {
        let base = self.positions.len() as u32;
        self.positions.extend_from_slice(&other.positions);
        self.normals.extend_from_slice(&other.normals);
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + base)));
        self.kinds.extend_from_slice(&other.kinds);
    }

    /// The mesh for a file (glTF, OBJ: `texmap_mesh::write_glb`, `write_obj`), coloured through
    /// a texture: a one-row palette of the materials' base colours in sRGB (`materials.len() + 1`
    /// texels, the last grey for kinds past them), each triangle's vertices copied per kind with
    /// the uv of their kind's texel centre, which any filtering samples exactly. Positions in Å.
    pub fn to_textured(&self, materials: &[Material]) -> (TriMesh, image::RgbaImage) {
        let n = materials.len() + 1;
        let mut palette = image::RgbaImage::new(n as u32, 1);
        for (k, px) in palette.pixels_mut().enumerate() {
            let c = materials.get(k).map_or(Vec3::splat(0.6), |m| m.base_color);
            *px = image::Rgba(linear_to_srgb8(c, 255));
        }
        let (mut positions, mut normals, mut uvs, mut triangles) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for (k, group) in self.by_kind(materials.len()).iter().enumerate() {
            // This kind's vertices, numbered in first use.
            let mut index = std::collections::HashMap::new();
            let uv = glam::Vec2::new((k as f32 + 0.5) / n as f32, 0.5);
            for t in group {
                triangles.push(t.map(|v| {
                    *index.entry(v).or_insert_with(|| {
                        positions.push(self.positions[v as usize]);
                        normals.push(self.normals[v as usize]);
                        uvs.push(uv);
                        positions.len() as u32 - 1
                    })
                }));
            }
        }
        let mesh = TriMesh {
            positions,
            triangles,
            uvs: Some(uvs),
            normals: Some(normals),
        };
        (mesh, palette)
    }

    /// The enclosed volume (Å³), by the divergence theorem over the triangles: positive when
    /// they are wound counter-clockwise seen from outside.
    pub fn volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.positions[i as usize].as_dvec3());
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// The surface area (Å²).
    pub fn area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.positions[i as usize].as_dvec3());
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }
}

/// The unit cube's corner `i` (bit 0 x, bit 1 y, bit 2 z).
fn corner(i: usize) -> Vec3 {
    Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, (i >> 2) as f32)
}

/// The unit cube's twelve edges as corner pairs (corners numbered as by [`corner`]).
pub(crate) const CUBE_EDGES: [(usize, usize); 12] = [
    (0, 1),
    (2, 3),
    (4, 5),
    (6, 7),
    (0, 2),
    (1, 3),
    (4, 6),
    (5, 7),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];

/// The density sampled at `origin + h · (x, y, z)`: each Gaussian added over its cut-off block
/// as a product of three one-dimensional factors, slab by slab in parallel, atoms in order.
fn density(blobs: &[Blob], origin: Vec3, h: f32, [nx, ny, nz]: [usize; 3]) -> Vec<f32> {
    let slabs = nz.div_ceil(SLAB);
    let range = |c: f32, o: f32, cut: f32, n: usize| {
        let a = ((c - cut - o) / h).ceil().max(0.0) as usize;
        let b = (((c + cut - o) / h).floor().max(0.0) as usize).min(n - 1);
        a..b + 1
    };
    let mut lists: Vec<Vec<u32>> = vec![Vec::new(); slabs];
    for (i, b) in blobs.iter().enumerate() {
        let zr = range(b.center.z, origin.z, b.grid_cut, nz);
        if zr.is_empty() {
            continue;
        }
        for list in &mut lists[zr.start / SLAB..=(zr.end - 1) / SLAB] {
            list.push(i as u32);
        }
    }
    let mut rho = vec![0.0f32; nx * ny * nz];
    rho.par_chunks_mut(nx * ny * SLAB)
        .zip(lists.par_iter())
        .enumerate()
        .for_each(|(s, (slab, list))| {
            let z0 = s * SLAB;
            let planes = slab.len() / (nx * ny);
            let (mut ex, mut ey) = (Vec::new(), Vec::new());
            for &i in list {
                let b = &blobs[i as usize];
                let factors = |r: std::ops::Range<usize>, c: f32, o: f32, out: &mut Vec<f32>| {
                    out.clear();
                    out.extend(r.map(|k| {
                        let d = o + k as f32 * h - c;
                        (-d * d * b.inv2s2).exp()
                    }));
                };
                let xr = range(b.center.x, origin.x, b.grid_cut, nx);
                let yr = range(b.center.y, origin.y, b.grid_cut, ny);
                let zr = range(b.center.z, origin.z, b.grid_cut, nz);
                factors(xr.clone(), b.center.x, origin.x, &mut ex);
                factors(yr.clone(), b.center.y, origin.y, &mut ey);
                for z in zr.start.max(z0)..zr.end.min(z0 + planes) {
                    let d = origin.z + z as f32 * h - b.center.z;
                    let fz = (-d * d * b.inv2s2).exp();
                    for (y, &fy) in yr.clone().zip(&ey) {
                        let fyz = fy * fz;
                        let row = ((z - z0) * ny + y) * nx;
                        for (v, &fx) in slab[row + xr.start..row + xr.end].iter_mut().zip(&ex) {
                            *v += fx * fyz;
                        }
                    }
                }
            }
        });
    rho
}

/// Draw `mesh` as `camera` sees it, lit per pixel as the sphere methods light their atoms
/// (`materials` indexed by the triangles' kinds; a kind past them is drawn grey), over `frame`
/// where it is nearer, at `opacity` ([`composite`]). Returns the triangles drawn.
pub fn draw_mesh(
    surface: &MolMesh,
    materials: &[Material],
    camera: &Camera,
    lighting: &Lighting,
    opacity: f32,
    frame: &mut Frame,
) -> Result<usize, RasterError> {
    if surface.triangles.is_empty() {
        return Ok(0);
    }
    let mut fb = Framebuffer::new(camera.width(), camera.height())?;
    fb.clear([0, 0, 0, 0]);
    let groups = surface.by_kind(materials.len());
    let mut drawn = 0;
    for (k, group) in groups.iter().enumerate() {
        if group.is_empty() {
            continue;
        }
        let material = materials
            .get(k)
            .copied()
            .unwrap_or(Material::plastic(Vec3::splat(0.6)));
        let mesh = Mesh::new(&surface.positions, group)?.with_normals(&surface.normals)?;
        let shading = Shading::LitSmooth {
            lighting: *lighting,
            material,
        };
        drawn += fb
            .draw_mesh(camera, &mesh, &shading, &DrawState::default())?
            .binned;
    }
    if frame.width() != camera.width() || frame.height() != camera.height() {
        *frame = Frame::new(camera.width(), camera.height(), [0, 0, 0, 255]);
    }
    composite(frame, &fb.to_frame(), opacity);
    Ok(drawn)
}

/// `layer` over `frame` where it is nearer: replacing colour and depth at `opacity` ≥ 1, else
/// mixing the colours in linear light, `opacity · layer + (1 − opacity) · frame`, and keeping the
/// frame's depth (what shows through stays the depth of record). One layer: a transparent
/// closed surface shows its front, not its back. Frames of other sizes are left as they are.
pub fn composite(frame: &mut Frame, layer: &Frame, opacity: f32) {
    if frame.width() != layer.width() || frame.height() != layer.height() {
        return;
    }
    let a = opacity.clamp(0.0, 1.0);
    for (i, &d) in layer.depth.iter().enumerate() {
        if d < frame.depth[i] {
            if a >= 1.0 {
                frame.depth[i] = d;
                frame.color[i] = layer.color[i];
            } else {
                let over = srgb8_to_linear_rgb(layer.color[i]);
                let under = srgb8_to_linear_rgb(frame.color[i]);
                let alpha = frame.color[i][3];
                frame.color[i] = linear_to_srgb8(over * a + under * (1.0 - a), alpha);
            }
        }
    }
}

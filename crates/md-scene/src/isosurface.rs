//! Isosurfaces of volumetric data (an md-io [`Volume`]: a Gaussian cube file's orbital or
//! density, a VASP CHGCAR's charge density), as VMD, VESTA and Avogadro draw them: the surface
//! where the values cross a level, the two signs of an orbital as two surfaces.
//!
//! # Which side is inside
//! The caller says which side of the level the surface encloses ([`Side`]): the values above
//! it (a density, an orbital's positive lobe) or below it (the negative lobe at `−L`). The mesh
//! is wound counter-clockwise seen from outside, its normals point out of the enclosed region,
//! so a positive and a negative lobe are both lit on their outside.
//!
//! # Extraction
//! Surface nets (Gibson 1998) on the grid itself, in index space, mapped to Å through the
//! volume's (possibly skewed) steps: one vertex per grid cell whose corners straddle the level,
//! at the mean of its edges' linear crossings; one quad (two triangles) per grid edge that
//! crosses, joining the four cells around it. The grid is conceptually padded by one layer of
//! points on every side:
//! - a cube file's grid (not periodic) is padded with points outside the region, so a region
//!   that reaches the grid's border is closed there by a flat cap on the border (the mesh is
//!   closed: every edge has two triangles);
//! - a periodic grid (VASP's) is padded with the values of the next periodic image, so the
//!   surface runs on across the cell's faces instead of being capped: it covers one period,
//!   from half a grid cell before the cell's origin faces to half a cell past its far faces,
//!   and fits the same surface of the neighbouring cells.
//!
//! [`bands`] cuts a surface into colour bands of another quantity given at its vertices (an
//! electrostatic potential on a density surface), along the lines where it crosses each band's
//! boundary, so the colours change on smooth contours instead of in triangle steps.
//!
//! Vertex normals are the value's gradient (central differences at the grid points, one-sided
//! at a border, interpolated trilinearly to the vertex and taken to Å through the inverse
//! transpose of the steps); a vertex of a cell on a cap, where the region is cut rather than
//! bounded by the level, takes the mean of its triangles' normals instead.
//!
//! ```
//! use glam::Vec3;
//! use texmap_md_io::volume::Volume;
//! use texmap_md_scene::isosurface::{Side, isosurface};
//!
//! // exp(−r²/2) on a 61³ grid 0.1 Å apart centred on the origin: the level exp(−1/2)
//! // is the sphere of radius 1 Å.
//! let n = 61;
//! let h = 0.1;
//! let o = -3.0;
//! let data = (0..n * n * n)
//!     .map(|p| {
//!         let (i, j, k) = (p % n, (p / n) % n, p / (n * n));
//!         let r2 = [i, j, k].iter().map(|&c| (o + h * c as f64).powi(2)).sum::<f64>();
//!         (-r2 / 2.0).exp() as f32
//!     })
//!     .collect();
//! let steps = [[h, 0.0, 0.0], [0.0, h, 0.0], [0.0, 0.0, h]];
//! let v = Volume::new([o; 3], steps, [n, n, n], data, false, "gaussian").unwrap();
//! let mesh = isosurface(&v, (-0.5f32).exp(), Side::Above, 0).unwrap();
//! for p in &mesh.positions {
//!     assert!((p.length() - 1.0).abs() < 0.02);
//! }
//! let sphere = 4.0 / 3.0 * std::f64::consts::PI;
//! let rel = mesh.volume() / sphere - 1.0;
//! assert!(rel.abs() < 0.015, "{rel}");
//! ```

use glam::{DMat3, DVec3, Vec3};
use rayon::prelude::*;
use texmap_md_io::volume::Volume;

use crate::surface::{CUBE_EDGES, MolMesh};

/// Most grid cells one isosurface walks (the data's points, padded).
pub const MAX_CELLS: usize = 1 << 30;

/// Which values an isosurface encloses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// The values above the level.
    Above,
    /// The values below the level.
    Below,
}

/// Why no isosurface was made.
#[derive(Clone, Debug, PartialEq)]
pub enum IsoError {
    /// The level is not a finite number.
    BadLevel(f32),
    /// The grid has more cells than [`MAX_CELLS`].
    TooLarge { cells: usize },
}

impl std::fmt::Display for IsoError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            IsoError::BadLevel(l) => write!(f, "isosurface level {l}: expected a finite number"),
            IsoError::TooLarge { cells } => write!(
                f,
                "an isosurface over {cells} grid cells: at most {MAX_CELLS} (2^30)"
            ),
        }
    }
}

impl std::error::Error for IsoError {}

/// The grid seen through its padding: values as `s·(v − level)` (positive inside), point
/// indices from −1 to n along each axis.
struct Field<'a> {
    vol: &'a Volume,
    level: f32,
    /// +1 when the values above the level are inside, −1 below.
    sign: f32,
    n: [i64; 3],
}

impl Field<'_> {
    /// Whether padded point p is a real grid point (always, for a periodic grid).
    #[inline]
    fn real(&self, p: [i64; 3]) -> bool {
        self.vol.periodic || (0..3).all(|a| p[a] >= 0 && p[a] < self.n[a])
    }

    /// The real grid point a padded index stands for (wrapped, or clamped into the grid).
    #[inline]
    fn wrap(&self, p: [i64; 3]) -> [usize; 3] {
        std::array::from_fn(|a| {
            if self.vol.periodic {
                p[a].rem_euclid(self.n[a]) as usize
            } else {
                p[a].clamp(0, self.n[a] - 1) as usize
            }
        })
    }

    /// `s·(v − level)` at padded point p: positive inside; `−∞` on the padding of a grid that
    /// does not wrap.
    #[inline]
    fn f(&self, p: [i64; 3]) -> f32 {
        if !self.real(p) {
            return f32::NEG_INFINITY;
        }
        let [i, j, k] = self.wrap(p);
        self.sign * (self.vol.at(i, j, k) - self.level)
    }

    /// The gradient of `s·v` in index space at real point p (central differences; one-sided
    /// at the border of a grid that does not wrap).
    fn grad(&self, p: [i64; 3]) -> DVec3 {
        let mut g = [0.0f64; 3];
        for (a, ga) in g.iter_mut().enumerate() {
            let (mut lo, mut hi) = (p, p);
            lo[a] -= 1;
            hi[a] += 1;
            let v = |q: [i64; 3]| {
                let [i, j, k] = self.wrap(q);
                self.sign as f64 * self.vol.at(i, j, k) as f64
            };
            let (lo_ok, hi_ok) = (self.real(lo), self.real(hi));
            *ga = match (lo_ok, hi_ok) {
                (true, true) => (v(hi) - v(lo)) / 2.0,
                (true, false) => v(p) - v(lo),
                (false, true) => v(hi) - v(p),
                (false, false) => 0.0,
            };
        }
        DVec3::from(g)
    }
}

/// Corner `c` (bits x, y, z) of a cell as an index offset.
#[inline]
fn corner(c: usize) -> [i64; 3] {
    [(c & 1) as i64, ((c >> 1) & 1) as i64, ((c >> 2) & 1) as i64]
}

/// A cell's vertex: its key (padded cell index), position in index space, gradient normal in
/// Å (`None` on a cap).
struct CellVertex {
    key: u64,
    pos: DVec3,
    normal: Option<Vec3>,
}

/// The isosurface of `vol` at `level` enclosing the values on `side` of it (see the module
/// docs for the caps and periodic grids), every triangle of material `kind`. Empty when no
/// value crosses the level.
///
/// Errors: a level that is not finite, or more than [`MAX_CELLS`] cells.
pub fn isosurface(vol: &Volume, level: f32, side: Side, kind: u16) -> Result<MolMesh, IsoError> {
    if !level.is_finite() {
        return Err(IsoError::BadLevel(level));
    }
    let n = vol.dims.map(|d| d as i64);
    // Cells −1..n−1 along each axis (n + 1 of them).
    let cn = n.map(|d| d + 1);
    let cells = cn
        .iter()
        .try_fold(1usize, |a, &c| a.checked_mul(c as usize))
        .unwrap_or(usize::MAX);
    if cells > MAX_CELLS {
        return Err(IsoError::TooLarge { cells });
    }
    let field = Field {
        vol,
        level,
        sign: match side {
            Side::Above => 1.0,
            Side::Below => -1.0,
        },
        n,
    };
    let key =
        |c: [i64; 3]| -> u64 { (((c[2] + 1) * cn[1] + (c[1] + 1)) * cn[0] + (c[0] + 1)) as u64 };
    let steps = DMat3::from_cols_array_2d(&vol.steps);
    // Index space to Å: x = origin + M·(i, j, k) with M's columns the steps; gradients go
    // through M^−T.
    let to_world = |q: DVec3| DVec3::from(vol.origin) + steps * q;
    let normal_map = steps.inverse().transpose();
    let mirrored = steps.determinant() < 0.0;

    // Pass 1: a vertex in every cell whose corners straddle the level, slab by slab (cell
    // z), each slab in key order, so the concatenation is sorted by key.
    let slabs: Vec<Vec<CellVertex>> = (-1..n[2])
        .into_par_iter()
        .map(|z| {
            let mut out = Vec::new();
            for y in -1..n[1] {
                for x in -1..n[0] {
                    let base = [x, y, z];
                    let at = |c: usize| {
                        let o = corner(c);
                        [base[0] + o[0], base[1] + o[1], base[2] + o[2]]
                    };
                    let f: [f32; 8] = std::array::from_fn(|c| field.f(at(c)));
                    let inside = f.iter().filter(|v| **v > 0.0).count();
                    if inside == 0 || inside == 8 {
                        continue;
                    }
                    let (mut sum, mut count) = (DVec3::ZERO, 0.0);
                    for (a, b) in CUBE_EDGES {
                        if (f[a] > 0.0) != (f[b] > 0.0) {
                            // The crossing: on the level, or on the real point when the other
                            // end is padding.
                            let t = if f[b] == f32::NEG_INFINITY {
                                0.0
                            } else if f[a] == f32::NEG_INFINITY {
                                1.0
                            } else {
                                (f[a] / (f[a] - f[b])) as f64
                            };
                            let (pa, pb) = (corner(a), corner(b));
                            sum += DVec3::new(
                                pa[0] as f64 + t * (pb[0] - pa[0]) as f64,
                                pa[1] as f64 + t * (pb[1] - pa[1]) as f64,
                                pa[2] as f64 + t * (pb[2] - pa[2]) as f64,
                            );
                            count += 1.0;
                        }
                    }
                    let local = sum / count;
                    let capped = (0..8).any(|c| !field.real(at(c)));
                    let normal = (!capped).then(|| {
                        // Trilinear interpolation of the corners' gradients.
                        let mut g = DVec3::ZERO;
                        for c in 0..8 {
                            let o = corner(c);
                            let w = (0..3)
                                .map(|a| if o[a] == 1 { local[a] } else { 1.0 - local[a] })
                                .product::<f64>();
                            g += field.grad(at(c)) * w;
                        }
                        (-(normal_map * g)).normalize_or_zero().as_vec3()
                    });
                    out.push(CellVertex {
                        key: key(base),
                        pos: DVec3::new(x as f64, y as f64, z as f64) + local,
                        normal,
                    });
                }
            }
            out
        })
        .collect();
    let verts: Vec<CellVertex> = slabs.into_iter().flatten().collect();
    let index_of = |c: [i64; 3]| -> u32 {
        let k = key(c);
        verts
            .binary_search_by_key(&k, |v| v.key)
            .expect("every cell around a crossing edge straddles the level") as u32
    };

    // Pass 2: a quad per crossing edge, by the edge's lower point's z, in a fixed order.
    // Edges along axis a from point p to p + e_a: p[a] from −1 (padding, only where the grid
    // does not wrap) to n − 1; the other coordinates 0..n − 1 (their cells −1..n − 1).
    let a_lo = if vol.periodic { 0 } else { -1 };
    let quads: Vec<Vec<[u32; 4]>> = (-1..n[2])
        .into_par_iter()
        .map(|z| {
            let mut out = Vec::new();
            for y in -1..n[1] {
                for x in -1..n[0] {
                    let p = [x, y, z];
                    let fp = field.f(p);
                    for a in 0..3 {
                        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                        if p[a] < a_lo || p[b] < 0 || p[c] < 0 {
                            continue;
                        }
                        let mut q = p;
                        q[a] += 1;
                        let fq = field.f(q);
                        if (fp > 0.0) == (fq > 0.0) {
                            continue;
                        }
                        let cell = |db: i64, dc: i64| {
                            let mut s = p;
                            s[b] -= db;
                            s[c] -= dc;
                            index_of(s)
                        };
                        // Counter-clockwise around +a (b then c): seen from outside when
                        // outside lies towards +a, i.e. p is inside.
                        let mut quad = [cell(1, 1), cell(0, 1), cell(0, 0), cell(1, 0)];
                        if (fp > 0.0) == mirrored {
                            quad.reverse();
                        }
                        out.push(quad);
                    }
                }
            }
            out
        })
        .collect();

    let mut mesh = MolMesh {
        positions: verts.iter().map(|v| to_world(v.pos).as_vec3()).collect(),
        normals: verts
            .iter()
            .map(|v| v.normal.unwrap_or(Vec3::ZERO))
            .collect(),
        spacing: (0..3)
            .map(|a| DVec3::from(vol.steps[a]).length())
            .sum::<f64>() as f32
            / 3.0,
        ..MolMesh::default()
    };
    for q in quads.into_iter().flatten() {
        mesh.triangles.push([q[0], q[1], q[2]]);
        mesh.triangles.push([q[0], q[2], q[3]]);
    }
    mesh.kinds = vec![kind; mesh.triangles.len()];
    // Cap vertices (and any whose gradient vanished): the area-weighted mean of their
    // triangles' normals.
    let fallback: Vec<bool> = mesh.normals.iter().map(|n| *n == Vec3::ZERO).collect();
    let mut acc = vec![Vec3::ZERO; verts.len()];
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let n = (b - a).cross(c - a);
        for &i in t {
            if fallback[i as usize] {
                acc[i as usize] += n;
            }
        }
    }
    for (i, f) in fallback.into_iter().enumerate() {
        if f {
            mesh.normals[i] = acc[i].normalize_or(Vec3::Z);
        }
    }
    Ok(mesh)
}

/// `mesh` cut into colour bands of a value given at its vertices, as a map is coloured between
/// contour lines: `values` (one per vertex, NaN where there is none) run from band 0 at `lo`
/// to band `bins − 1` at `hi` (`hi < lo` reverses them; values beyond either end take the end
/// band), each band `1 / bins` of the range. Every triangle is cut along the straight lines
/// where the linearly interpolated value crosses a band boundary, each piece taking kind
/// `first_kind + band`; a triangle with a NaN vertex keeps its shape and takes `off_kind`.
/// The cut points are shared by the triangles on both sides of an edge, so a closed mesh stays
/// closed, and its area and enclosed volume do not change.
pub fn bands(
    mesh: &MolMesh,
    values: &[f64],
    (lo, hi): (f64, f64),
    bins: u16,
    first_kind: u16,
    off_kind: u16,
) -> MolMesh {
    let n = bins.max(1) as i64;
    let scale = n as f64 / (hi - lo);
    let u: Vec<f64> = values.iter().map(|v| (v - lo) * scale).collect();
    let band = |u: f64| (u.floor() as i64).clamp(0, n - 1);
    let mut out = MolMesh {
        positions: mesh.positions.clone(),
        normals: mesh.normals.clone(),
        spacing: mesh.spacing,
        ..MolMesh::default()
    };
    // The cut point of edge (i, j) at band boundary `level`, shared by both triangles.
    let mut cuts: std::collections::HashMap<(u32, u32, i64), u32> = Default::default();
    let mut cut = |out: &mut MolMesh, a: u32, b: u32, level: i64| -> u32 {
        let (i, j) = (a.min(b), a.max(b));
        *cuts.entry((i, j, level)).or_insert_with(|| {
            let (ui, uj) = (u[i as usize], u[j as usize]);
            let t = ((level as f64 - ui) / (uj - ui)) as f32;
            let (pi, pj) = (mesh.positions[i as usize], mesh.positions[j as usize]);
            let (ni, nj) = (mesh.normals[i as usize], mesh.normals[j as usize]);
            out.positions.push(pi + (pj - pi) * t);
            out.normals.push(ni.lerp(nj, t).normalize_or(ni));
            (out.positions.len() - 1) as u32
        })
    };
    let mut poly: Vec<u32> = Vec::with_capacity(8);
    for (t, _) in mesh.triangles.iter().zip(&mesh.kinds) {
        let ut = t.map(|i| u.get(i as usize).copied().unwrap_or(f64::NAN));
        if ut.iter().any(|v| v.is_nan()) {
            // Kept whole, but with the cut points its neighbours put on its edges whose ends
            // both have values (fanned from a corner: pieces along an edge have no area, so
            // that every edge still has its twin).
            poly.clear();
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                let (ua, ub) = (ut[e], ut[(e + 1) % 3]);
                poly.push(a);
                if ua.is_nan() || ub.is_nan() {
                    continue;
                }
                let (l0, l1) = (ua.min(ub).floor() as i64 + 1, ua.max(ub).ceil() as i64 - 1);
                let levels = l0.max(1)..=l1.min(n - 1);
                if ua < ub {
                    for l in levels {
                        poly.push(cut(&mut out, a, b, l));
                    }
                } else {
                    for l in levels.rev() {
                        poly.push(cut(&mut out, a, b, l));
                    }
                }
            }
            for w in 1..poly.len() - 1 {
                out.triangles.push([poly[0], poly[w], poly[w + 1]]);
                out.kinds.push(off_kind);
            }
            continue;
        }
        let bt = ut.map(band);
        let (kmin, kmax) = (
            bt.iter().min().copied().unwrap(),
            bt.iter().max().copied().unwrap(),
        );
        if kmin == kmax {
            out.triangles.push(*t);
            out.kinds.push(first_kind + kmin as u16);
            continue;
        }
        for k in kmin..=kmax {
            // Band k's polygon: the triangle's corners in it (boundaries included) and the cut
            // points of its two boundaries (levels k and k + 1, interior ones only), in order
            // around the triangle.
            poly.clear();
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                let (ua, ub) = (ut[e], ut[(e + 1) % 3]);
                // Corners on a boundary belong to the bands on both sides of it.
                let uc = ua.clamp(0.0, n as f64);
                if k as f64 <= uc && uc <= (k + 1) as f64 {
                    poly.push(a);
                }
                let levels = [k, k + 1]
                    .into_iter()
                    .filter(|&l| l >= 1 && l < n)
                    .filter(|&l| ua.min(ub) < l as f64 && (l as f64) < ua.max(ub));
                let mut ls: [i64; 2] = [0; 2];
                let mut m = 0;
                for l in levels {
                    ls[m] = l;
                    m += 1;
                }
                if m == 2 && ua > ub {
                    ls.swap(0, 1);
                }
                for &l in &ls[..m] {
                    poly.push(cut(&mut out, a, b, l));
                }
            }
            for w in 1..poly.len().saturating_sub(1) {
                out.triangles.push([poly[0], poly[w], poly[w + 1]]);
                out.kinds.push(first_kind + k as u16);
            }
        }
    }
    out
}

/// Why no slice was made.
#[derive(Clone, Debug, PartialEq)]
pub enum SliceError {
    /// The axis is not 0, 1 or 2.
    BadAxis(usize),
    /// The position along the axis is not a fraction in [0, 1].
    BadFraction(f64),
}

impl std::fmt::Display for SliceError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SliceError::BadAxis(a) => write!(f, "slice axis {a}: expected 0, 1 or 2 (a, b, c)"),
            SliceError::BadFraction(x) => {
                write!(f, "slice position {x}: expected a fraction from 0 to 1")
            }
        }
    }
}

impl std::error::Error for SliceError {}

/// A plane through the grid, as VESTA draws a section and VMD a VolumeSlice: the points whose
/// index along `axis` is `fraction` of the way across the grid (`fraction · (n − 1)`; on a
/// periodic grid `fraction · n`, the whole cell), spanned by the other two axes' grid points (a
/// periodic grid's plane covers the whole cell: one more row and column, the first ones
/// again). Each triangle is there twice, facing both ways, so that the plane is seen from
/// either side; with it, the data's value at each vertex (interpolated along `axis` only), for
/// [`bands`]. Every triangle has material `kind`.
pub fn slice(
    vol: &Volume,
    axis: usize,
    fraction: f64,
    kind: u16,
) -> Result<(MolMesh, Vec<f64>), SliceError> {
    if axis > 2 {
        return Err(SliceError::BadAxis(axis));
    }
    if !(0.0..=1.0).contains(&fraction) {
        return Err(SliceError::BadFraction(fraction));
    }
    let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
    let extra = usize::from(vol.periodic);
    let (nb, nc) = (vol.dims[b] + extra, vol.dims[c] + extra);
    let along = if vol.periodic {
        fraction * vol.dims[axis] as f64
    } else {
        fraction * (vol.dims[axis] - 1) as f64
    };
    let steps = vol.steps.map(DVec3::from);
    let normal = steps[b].cross(steps[c]).normalize_or_zero().as_vec3();
    let mut mesh = MolMesh {
        spacing: (steps[b].length() + steps[c].length()) as f32 / 2.0,
        ..MolMesh::default()
    };
    let mut values = Vec::with_capacity(2 * nb * nc);
    for side in [1.0f32, -1.0] {
        for jc in 0..nc {
            for jb in 0..nb {
                let mut q = [0.0f64; 3];
                q[axis] = along;
                q[b] = jb as f64;
                q[c] = jc as f64;
                let p = vol.point(q[0], q[1], q[2]);
                mesh.positions.push(DVec3::from(p).as_vec3());
                mesh.normals.push(normal * side);
                // On the plane itself, so inside the grid (or its periodic images).
                values.push(vol.interpolate(p).unwrap_or(f64::NAN));
            }
        }
    }
    let at = |s: usize, jb: usize, jc: usize| (s * nb * nc + jc * nb + jb) as u32;
    for jc in 0..nc - 1 {
        for jb in 0..nb - 1 {
            let q = [
                at(0, jb, jc),
                at(0, jb + 1, jc),
                at(0, jb + 1, jc + 1),
                at(0, jb, jc + 1),
            ];
            // Counter-clockwise seen along +normal (b then c) on the front copy.
            mesh.triangles.push([q[0], q[1], q[2]]);
            mesh.triangles.push([q[0], q[2], q[3]]);
            let r = [
                at(1, jb, jc),
                at(1, jb + 1, jc),
                at(1, jb + 1, jc + 1),
                at(1, jb, jc + 1),
            ];
            mesh.triangles.push([r[0], r[2], r[1]]);
            mesh.triangles.push([r[0], r[3], r[2]]);
        }
    }
    mesh.kinds = vec![kind; mesh.triangles.len()];
    Ok((mesh, values))
}

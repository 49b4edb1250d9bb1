//! Voronoi cells of the atoms of a periodic frame, as OVITO's Voronoi analysis modifier computes
//! them (voro++ underneath): each atom's atomic volume, its Voronoi coordination (the faces of
//! its cell: the neighbours that share one) and its Voronoi index `⟨n₃, n₄, n₅, n₆⟩` (faces with
//! 3, 4, 5 and 6 edges), with which metallic-glass and liquid studies find icosahedral order
//! (`⟨0, 0, 12, 0⟩`) and crystals show their cells (FCC's rhombic dodecahedron `⟨0, 12, 0, 0⟩`).
//!
//! Per atom: a cube around it is clipped by the bisector plane of each neighbour, nearest first
//! (neighbours at their nearest periodic image, from the cell grid CNA uses, so the periodic cell
//! must be wider than twice the largest Voronoi cell's radius, as any box of a few atomic
//! spacings is); the cell is
//! complete when its farthest vertex is closer than half the distance to the next neighbour not
//! yet used (no farther atom's plane can reach it), otherwise more neighbours are taken. A vertex
//! within 10⁻⁹ Å of a plane lies on it, so a plane through a vertex adds no sliver face. The
//! volume sums each face's area times its distance from the atom, over three. The cells of a
//! periodic frame tile its cell: their volumes sum to its volume (a test pins that). Atoms are
//! computed in parallel; the result does not depend on the thread count.
//!
//! ```
//! use texmap_md_io::voronoi::voronoi;
//! use texmap_md_io::{Frame, UnitCell};
//! // A periodic simple cubic crystal (a = 2 Å): every cell is a 2 Å cube, six square faces.
//! let mut frame = Frame::new();
//! for n in 0..64 {
//!     frame.positions.push([(n % 4) as f32 * 2.0, (n / 4 % 4) as f32 * 2.0, (n / 16) as f32 * 2.0]);
//! }
//! frame.cell = Some(UnitCell::orthorhombic(8.0, 8.0, 8.0).unwrap());
//! let v = voronoi(&frame).unwrap();
//! assert!(v.volume.iter().all(|&x| (x - 8.0).abs() < 1e-4));
//! assert!(v.faces.iter().all(|&f| f == 6));
//! assert!(v.index.iter().all(|i| *i == [0, 6, 0, 0]));
//! ```

use std::fmt;

use glam::DVec3;

use crate::frame::Frame;
use crate::neighbours::{Grid, Scratch};

/// What [`voronoi`] finds, per atom.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Voronoi {
    /// The cell's volume, Å³.
    pub volume: Vec<f32>,
    /// The cell's faces (the Voronoi coordination).
    pub faces: Vec<u32>,
    /// Faces with 3, 4, 5 and 6 edges.
    pub index: Vec<[u32; 4]>,
}

/// Why the cells cannot be computed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum VoronoiError {
    /// The frame has no periodic cell (an open system's outer cells are unbounded).
    NotPeriodic,
    /// Fewer than two atoms, or an atom with non-finite coordinates.
    BadAtoms(String),
}

impl fmt::Display for VoronoiError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            VoronoiError::NotPeriodic => write!(
                f,
                "the frame has no cell periodic along all three edges: the Voronoi cells of \
                 the atoms at an open surface are unbounded"
            ),
            VoronoiError::BadAtoms(why) => write!(f, "{why}"),
        }
    }
}

impl std::error::Error for VoronoiError {}

/// The largest number of neighbours examined per atom.
const MAX_NEIGHBOURS: usize = 512;
/// Distance within which a vertex lies on a plane, Å.
const ON_PLANE: f64 = 1e-9;

/// The Voronoi cell of every atom of a periodic `frame` (see the module docs).
pub fn voronoi(frame: &Frame) -> Result<Voronoi, VoronoiError> {
    use rayon::prelude::*;
    if !frame.cell.is_some_and(|c| c.is_fully_periodic()) {
        return Err(VoronoiError::NotPeriodic);
    }
    let n = frame.n_atoms();
    if n < 2 {
        return Err(VoronoiError::BadAtoms(format!(
            "a Voronoi analysis needs two atoms or more, the frame has {n}"
        )));
    }
    if let Some(i) = frame
        .positions
        .iter()
        .position(|p| !p.iter().all(|v| v.is_finite()))
    {
        return Err(VoronoiError::BadAtoms(format!(
            "atom {i} has non-finite coordinates {:?}",
            frame.positions[i]
        )));
    }
    let grid = Grid::new(&frame.positions, frame.cell.as_ref());
    let cells: Vec<(f64, u32, [u32; 4])> = (0..n)
        .into_par_iter()
        .map_init(
            || (Scratch::default(), Cell::default()),
            |(scratch, cell), i| {
                let mut k = 24.min(n - 1);
                loop {
                    grid.nearest(i, k, scratch);
                    let near = &scratch.near;
                    let reach = near.last().map_or(f64::INFINITY, |x| x.1);
                    cell.reset(reach.max(1e-3));
                    let mut complete = false;
                    for (v, d) in near.iter() {
                        // Nearest first: once a plane lies beyond the cell's farthest vertex,
                        // so do all the others.
                        if 0.5 * d > cell.radius() {
                            complete = true;
                            break;
                        }
                        if *d > 0.0 {
                            cell.clip(DVec3::from(*v) / *d, 0.5 * d);
                        }
                    }
                    let complete = complete || cell.radius() * 2.0 < reach;
                    if complete || k >= (n - 1).min(MAX_NEIGHBOURS) {
                        return cell.measure();
                    }
                    k = (2 * k).min(n - 1).min(MAX_NEIGHBOURS);
                }
            },
        )
        .collect();
    let mut out = Voronoi::default();
    for (volume, faces, index) in cells {
        out.volume.push(volume as f32);
        out.faces.push(faces);
        out.index.push(index);
    }
    Ok(out)
}

/// A convex polyhedron around the origin: vertices, and faces as vertex loops ordered
/// counter-clockwise seen from outside, each with its plane's distance from the origin.
#[derive(Default)]
struct Cell {
    vertices: Vec<DVec3>,
    faces: Vec<(Vec<usize>, f64)>,
    // Scratch.
    side: Vec<i8>,
    /// The edges cut by the current plane (lower vertex, higher vertex) and the new vertex on
    /// each: a handful per plane, searched in order.
    cut: Vec<(usize, usize, usize)>,
    on_plane: Vec<usize>,
    next_faces: Vec<(Vec<usize>, f64)>,
}

impl Cell {
    /// A cube of half-width `h`.
    fn reset(&mut self, h: f64) {
        self.vertices.clear();
        for k in 0..8 {
            let s = |b: usize| if k & b != 0 { h } else { -h };
            self.vertices.push(DVec3::new(s(1), s(2), s(4)));
        }
        // Loops counter-clockwise seen from outside (vertex k has x = bit 0, y = bit 1, z = bit 2).
        self.faces.clear();
        for face in [
            [0, 2, 6, 4], // −x
            [1, 5, 7, 3], // +x
            [0, 4, 5, 1], // −y
            [2, 3, 7, 6], // +y
            [0, 1, 3, 2], // −z
            [4, 6, 7, 5], // +z
        ] {
            self.faces.push((face.to_vec(), h));
        }
    }

    /// The farthest vertex's distance from the origin.
    fn radius(&self) -> f64 {
        self.vertices.iter().map(|v| v.length()).fold(0.0, f64::max)
    }

    /// Keeps the part with `normal · x <= h` (`normal` a unit vector).
    fn clip(&mut self, normal: DVec3, h: f64) {
        self.side.clear();
        let mut any_out = false;
        for v in &self.vertices {
            let s = normal.dot(*v) - h;
            let side = if s > ON_PLANE {
                any_out = true;
                1
            } else if s < -ON_PLANE {
                -1
            } else {
                0
            };
            self.side.push(side);
        }
        if !any_out {
            return;
        }
        self.cut.clear();
        self.on_plane.clear();
        self.next_faces.clear();
        for (face, dist) in &self.faces {
            let mut kept = Vec::with_capacity(face.len() + 1);
            for k in 0..face.len() {
                let (a, b) = (face[k], face[(k + 1) % face.len()]);
                let (sa, sb) = (self.side[a], self.side[b]);
                if sa <= 0 {
                    kept.push(a);
                    if sa == 0 {
                        self.on_plane.push(a);
                    }
                }
                if (sa < 0 && sb > 0) || (sa > 0 && sb < 0) {
                    let (lo, hi) = (a.min(b), a.max(b));
                    let index = match self.cut.iter().find(|c| c.0 == lo && c.1 == hi) {
                        Some(c) => c.2,
                        None => {
                            // From the lower vertex, so both faces get the same point.
                            let (pa, pb) = (self.vertices[lo], self.vertices[hi]);
                            let (da, db) = (normal.dot(pa) - h, normal.dot(pb) - h);
                            let t = da / (da - db);
                            self.vertices.push(pa + (pb - pa) * t);
                            let index = self.vertices.len() - 1;
                            self.cut.push((lo, hi, index));
                            index
                        }
                    };
                    kept.push(index);
                    self.on_plane.push(index);
                }
            }
            if kept.len() >= 3 {
                self.next_faces.push((kept, *dist));
            }
        }
        // The new face: the vertices on the plane, in order around it.
        self.on_plane.sort_unstable();
        self.on_plane.dedup();
        if self.on_plane.len() >= 3 {
            let centre = self
                .on_plane
                .iter()
                .map(|&v| self.vertices[v])
                .sum::<DVec3>()
                / self.on_plane.len() as f64;
            let u = normal.any_orthonormal_vector();
            let w = normal.cross(u);
            let vertices = &self.vertices;
            // A pseudo-angle in [0, 4), increasing with the angle (no trigonometry).
            let angle = |v: usize| {
                let d = vertices[v] - centre;
                let (x, y) = (d.dot(u), d.dot(w));
                let p = y / (x.abs() + y.abs()).max(f64::MIN_POSITIVE);
                if x < 0.0 {
                    2.0 - p
                } else if y < 0.0 {
                    4.0 + p
                } else {
                    p
                }
            };
            let mut ring = self.on_plane.clone();
            // Counter-clockwise about the outward normal.
            ring.sort_by(|&a, &b| angle(a).total_cmp(&angle(b)));
            self.next_faces.push((ring, h));
        }
        std::mem::swap(&mut self.faces, &mut self.next_faces);
        // Drop the vertices no face uses any more.
        let mut remap = vec![usize::MAX; self.vertices.len()];
        let mut kept = Vec::with_capacity(self.vertices.len());
        for (face, _) in &mut self.faces {
            for v in face.iter_mut() {
                if remap[*v] == usize::MAX {
                    remap[*v] = kept.len();
                    kept.push(self.vertices[*v]);
                }
                *v = remap[*v];
            }
        }
        self.vertices = kept;
    }

    /// Volume, face count and index ⟨n₃, n₄, n₅, n₆⟩.
    fn measure(&self) -> (f64, u32, [u32; 4]) {
        let mut volume = 0.0;
        let mut index = [0u32; 4];
        for (face, dist) in &self.faces {
            let p0 = self.vertices[face[0]];
            let mut area = DVec3::ZERO;
            for k in 1..face.len() - 1 {
                area += (self.vertices[face[k]] - p0).cross(self.vertices[face[k + 1]] - p0);
            }
            volume += 0.5 * area.length() * dist / 3.0;
            if (3..=6).contains(&face.len()) {
                index[face.len() - 3] += 1;
            }
        }
        (volume, self.faces.len() as u32, index)
    }
}

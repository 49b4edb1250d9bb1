//! Volumetric data on a grid: the values a Gaussian cube file, a VASP CHGCAR / PARCHG /
//! LOCPOT / ELFCAR or an XCrySDen XSF file holds next to its atoms (electron densities,
//! orbitals, potentials), the input of isosurfaces.
//!
//! A [`Volume`] is a grid of `nx x ny x nz` points at `origin + i·steps[0] + j·steps[1] +
//! k·steps[2]` (Å; the steps need not be orthogonal), its values stored with `i` fastest.
//! A periodic volume (VASP's, on the unit cell) wraps: point `nx` along the first axis is
//! point 0 again, so the cells between the last points and the first are part of it too.
//!
//! # Reading files
//! [`read_volumes`] gives a file's atoms as a [`Frame`] (elements, positions in Å, a VASP
//! file's cell) and every data set in it, in file order; the name tells the format
//! ([`VolumeFormat::from_path`]; a `.gz` is read decompressed). [`read_volumes_from`] reads
//! from memory or a pipe. The same files open as one-frame trajectories (the atoms):
//! `Format::Cube`, and `Format::Vasp` for the VASP names; an XSF file's structures are
//! frames (`Format::Xsf`).
//!
//! **Gaussian cube** (`.cube`, `.cub`; Gaussian's cubegen, Paul Bourke's description):
//! 1. two comment lines (the first non-blank one names a single data set, else `values`);
//! 2. `natoms x0 y0 z0 [NVAL]`: the atom count, the origin, and optionally the values per point;
//! 3. three axis lines `n_i sx sy sz`: the point count and the step along axis i. A positive
//!    count means Bohr (0.529177210903 Å, CODATA 2018) for the steps, the origin and the atom
//!    positions, a negative one Å (|n_i| points; the three signs must agree);
//! 4. |natoms| atom lines `Z charge x y z` (element by atomic number; 0 or beyond the table is
//!    [`crate::Element::UNKNOWN`]);
//! 5. when natoms < 0, a DSET_IDS record `m id1 … idm` over as many lines as it takes: each
//!    point holds m values, one volume per id named `orbital <id>` (NVAL must be absent, 1 or
//!    m); otherwise NVAL values per point, named `value 1`, `value 2`, … when NVAL > 1;
//! 6. the values: whitespace-separated numbers in any line layout (`1.23456E-05`; Fortran's
//!    `1.0-100`, an exponent that lost its `E`, is an error naming the line), x outermost, then
//!    y, z fastest, the values of one point together. They are stored transposed into the
//!    volume's i-fastest layout. Nothing but blank lines may follow them.
//!
//! A cube grid is not periodic and its frame has no cell.
//!
//! **VASP volumetric files** (named as [`VaspQuantity::from_file_name`] tells: `CHGCAR`,
//! `CHG`, `PARCHG`, `LOCPOT`, `ELFCAR`, `AECCAR0/1/2`, also `CHGCAR_spin`,
//! `PARCHG.0012.ALLK`, `run1.CHGCAR`, `CHGCAR.vasp`): a POSCAR block (comment, scaling
//! factor, lattice, species, counts, coordinates: the structure, read as a POSCAR is), a
//! blank line, `NGX NGY NGZ`, then NGX·NGY·NGZ values with x fastest (Fortran's order, the
//! volume's own), 5 per line in a CHGCAR, 10 in a CHG. After a grid may come augmentation
//! occupancies (`augmentation occupancies <atom> <count>` and that many numbers: checked,
//! not kept) and a line of per-atom magnetic moments (one number per atom, as some VASP
//! versions write), then the next grid: its dimension line (the first's again) and its
//! values. The grids are periodic over the cell: origin 0, steps the lattice vectors / N.
//!
//! | file | holds | read as | data sets |
//! |---|---|---|---|
//! | `CHGCAR`, `CHG` | the charge density times the cell volume, ρ·V_cell (CHG: fewer digits, no occupancies) | ρ in e/Å³: divided by the cell volume (pymatgen's `data["total"] / structure.volume`) | `total density (e/Å³)`; spin-polarised (ISPIN=2) also `magnetisation density (e/Å³)` (ρ↑ − ρ↓); non-collinear `magnetisation x/y/z density (e/Å³)` |
//! | `PARCHG` | the partial (band- or energy-resolved) density, ρ·V_cell | as CHGCAR | as CHGCAR |
//! | `AECCAR0`, `AECCAR1`, `AECCAR2` | the core, proto-atomic valence and self-consistent valence all-electron densities (LAECHG), ρ·V_cell | as CHGCAR | `total density (e/Å³)` |
//! | `LOCPOT` | the local potential, eV | as written | `local potential (eV)`; ISPIN=2 `local potential, spin up (eV)` and `… spin down (eV)`; non-collinear also `local potential B1 (eV)` to `B3` |
//! | `ELFCAR` | the electron localisation function, 0 to 1 | as written | `ELF`; ISPIN=2 `ELF, spin up` and `ELF, spin down` |
//!
//! **XCrySDen XSF / AXSF** (`.xsf`, `.axsf`: Quantum ESPRESSO pp.x `output_format=5`, ASE,
//! pymatgen; src/xsf.rs gives the whole layout): the frame is the file's last structure
//! (as ASE's `read_xsf(read_data=True)` gives it), with its cell when periodic; each grid of
//! every `BEGIN_BLOCK_DATAGRID_3D` block is a volume named `<block>: <grid>`, its values as
//! written (pp.x writes its atomic units: a density in e/bohr³). XSF grids are *general*: their
//! n points per axis include both ends, step span/(n−1). A grid over a `CRYSTAL`'s cell (its
//! spanning vectors the cell vectors, its last plane along each axis a repeat of the first, as
//! pp.x writes n = N + 1) is read as the periodic grid it is: the repeated planes dropped, N
//! points per axis, steps the cell vectors / N, periodic. Any other grid (a slab's, a
//! molecule's, ASE's default with spans cell·(n+1)/n) keeps all its points and is not
//! periodic. 2-D grids are refused.
//!
//! **OpenDX** (`.dx`: APBS's electrostatic potentials in kT/e, VMD's `volmap` and
//! MDAnalysis's `DensityAnalysis` densities, GridDataFormats, PyMOL's and Chimera's exports):
//! `#` comment lines; `object 1 class gridpositions counts nx ny nz`, `origin x y z` and three
//! `delta` lines (the steps along the first, second and third count's axis, Å; they may be
//! skewed); `object 2 class gridconnections counts …` (the same counts); `object 3 class array
//! type <t> rank 0 items <nx·ny·nz> data follows`; the values as text, x outermost and z
//! fastest (C order, transposed into the volume's layout), any number per line; then
//! `attribute`, `component` and `object "<name>" class field` lines (the name is the
//! volume's, else `values`). A DX grid is not periodic and the file has no atoms. Binary
//! (`ieee`, `binary`) arrays, values in another file, vector fields (rank ≥ 1) and grids that
//! are not 3-D are refused at their line. [`write_dx`] writes the layout GridDataFormats
//! writes.
//!
//! **CCP4 / MRC maps** (`.mrc`, `.map`, `.ccp4`, `.rec`: EMDB's cryo-EM maps, CCP4's
//! crystallographic maps, tomograms; MRC2014 as mrcfile writes it): a 1024-byte header in
//! either byte order (MACHST, else whichever order reads as a sane header), an extended header
//! of NSYMBT bytes (skipped), then NC·NR·NS values, columns fastest, of MODE 0 (int8), 1
//! (int16), 2 (float32), 6 (uint16) or 12 (float16). MAPC, MAPR and MAPS say which axis the
//! columns, rows and sections run along; the values are reordered onto x, y, z. The steps are
//! the cell's edges (CELLA, and CELLB's angles: a along x, b in the xy plane) over the
//! sampling MX, MY, MZ; the first point lies at ORIGIN plus NXSTART, NYSTART, NZSTART steps
//! along their axes, as GridDataFormats places it (files set one or the other). The first
//! non-empty label names the volume (else `density`). A map is not taken as periodic; the file
//! has no atoms. Complex and 4-bit modes, a header whose counts, sampling, cell or axes make
//! no sense, and a non-finite value are refused at their byte; with the file's length known,
//! a map longer than the file is refused before any value is read.
//!
//! # Damage and memory
//! Errors are the crate's [`Error`]: the file, line and byte offset and what was expected
//! there, as the trajectory readers give them. A file that ends inside a data set is an
//! [`Error::Truncated`] naming the set, the values expected and found, at the end of the file;
//! a value that is not a number, or not finite within f32 once scaled, an [`Error::Parse`] at
//! its line. (A cut between two data sets of a VASP file, where the rest is optional, or inside
//! the last number, where what is left still parses, cannot be told from a whole file.)
//! Nothing is sized from a count in a header: values are pushed as they are parsed; a grid
//! of more than [`MAX_POINTS`] points, or, the file's length known ([`read_volumes`]), more
//! values or atoms than its bytes could hold (2 bytes a value, 8 an atom line), is refused at
//! its header line.
//!
//! # Example
//! ```
//! use texmap_md_io::volume::Volume;
//!
//! // A 3 x 2 x 2 grid, 0.5 Å apart, values i + 10 j + 100 k.
//! let data = (0..12).map(|n| ((n % 3) + 10 * ((n / 3) % 2) + 100 * (n / 6)) as f32).collect();
//! let steps = [[0.5, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 0.5]];
//! let v = Volume::new([0.0; 3], steps, [3, 2, 2], data, false, "demo").unwrap();
//! assert_eq!(v.at(2, 1, 1), 112.0);
//! assert_eq!(v.point(2, 1, 1), [1.0, 0.5, 0.5]);
//! assert_eq!(v.range(), Some((0.0, 112.0)));
//! ```

use crate::error::Error;
use crate::frame::Frame;
use crate::parse::{fields, parse_f64};
use crate::text::{Ctx, LineReader};
use std::io::Read;
use std::path::Path;
use std::sync::Arc;

/// Values on a grid of points (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Volume {
    /// Position (Å) of grid point (0, 0, 0).
    pub origin: [f64; 3],
    /// The steps (Å) from point (i, j, k) to (i + 1, j, k), (i, j + 1, k) and (i, j, k + 1).
    pub steps: [[f64; 3]; 3],
    /// Points along each axis (each at least 2, or 1 along a periodic axis).
    pub dims: [usize; 3],
    /// `dims[0]·dims[1]·dims[2]` finite values, point (i, j, k) at `(k·ny + j)·nx + i`.
    pub data: Vec<f32>,
    /// The grid wraps around (VASP's grids over the unit cell); a cube file's does not.
    pub periodic: bool,
    /// What the values are, as the file says it (`"total density (e/Å³)"`, `"orbital 12"`).
    pub name: String,
}

/// Why [`Volume::new`] refused its arguments.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VolumeShapeError(pub String);

impl std::fmt::Display for VolumeShapeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for VolumeShapeError {}

impl Volume {
    /// A volume, checked: as many finite values as points, at least two points along each
    /// axis that does not wrap, finite steps spanning a non-zero volume, a finite origin.
    pub fn new(
        origin: [f64; 3],
        steps: [[f64; 3]; 3],
        dims: [usize; 3],
        data: Vec<f32>,
        periodic: bool,
        name: &str,
    ) -> Result<Volume, VolumeShapeError> {
        let err = |m: String| Err(VolumeShapeError(m));
        let min = if periodic { 1 } else { 2 };
        if dims.iter().any(|&d| d < min) {
            return err(format!(
                "a grid of {}x{}x{} points (at least {min} along each axis)",
                dims[0], dims[1], dims[2]
            ));
        }
        let n = dims.iter().try_fold(1usize, |a, &d| a.checked_mul(d));
        if n != Some(data.len()) {
            return err(format!(
                "{} values for a grid of {}x{}x{} points",
                data.len(),
                dims[0],
                dims[1],
                dims[2]
            ));
        }
        if let Some(i) = data.iter().position(|v| !v.is_finite()) {
            return err(format!("value {i} is not a finite number"));
        }
        if !origin
            .iter()
            .chain(steps.iter().flatten())
            .all(|v| v.is_finite())
        {
            return err("a grid origin or step that is not a finite number".into());
        }
        let det = det3(steps);
        if det == 0.0 || !det.is_finite() {
            return err("grid steps that span no volume".into());
        }
        Ok(Volume {
            origin,
            steps,
            dims,
            data,
            periodic,
            name: name.to_string(),
        })
    }

    /// The value at point (i, j, k) (panics outside the grid).
    #[inline]
    pub fn at(&self, i: usize, j: usize, k: usize) -> f32 {
        let [nx, ny, _] = self.dims;
        self.data[(k * ny + j) * nx + i]
    }

    /// The position (Å) of point (i, j, k); fractional indices are allowed.
    #[inline]
    pub fn point(&self, i: impl Into<f64>, j: impl Into<f64>, k: impl Into<f64>) -> [f64; 3] {
        let (i, j, k) = (i.into(), j.into(), k.into());
        std::array::from_fn(|a| {
            self.origin[a] + i * self.steps[0][a] + j * self.steps[1][a] + k * self.steps[2][a]
        })
    }

    /// The smallest and largest value (`None` for no values).
    pub fn range(&self) -> Option<(f32, f32)> {
        let mut it = self.data.iter().copied();
        let first = it.next()?;
        Some(it.fold((first, first), |(lo, hi), v| (lo.min(v), hi.max(v))))
    }

    /// The volume (Å³) of one grid cell: `|det(steps)|`.
    pub fn cell_volume(&self) -> f64 {
        det3(self.steps).abs()
    }

    /// The integral of the values over the grid (sum times cell volume; for a periodic grid,
    /// over the unit cell): a density's electron count.
    pub fn integral(&self) -> f64 {
        self.data.iter().map(|&v| v as f64).sum::<f64>() * self.cell_volume()
    }

    /// The grid's fractional point indices of position `p` (Å): `(i, j, k)` with
    /// `p = origin + i·steps[0] + j·steps[1] + k·steps[2]`.
    pub fn index_of(&self, p: [f64; 3]) -> [f64; 3] {
        let m = self.steps;
        let d = [0, 1, 2].map(|a| p[a] - self.origin[a]);
        let det = det3(m);
        // Cramer's rule on the columns' system d = i·s0 + j·s1 + k·s2.
        std::array::from_fn(|c| {
            let mut mc = m;
            mc[c] = d;
            det3(mc) / det
        })
    }

    /// The value at position `p` (Å) by trilinear interpolation of the eight grid points
    /// around it: through the periodic images on a periodic grid, `None` outside a bounded
    /// grid's points (beyond half a step's rounding).
    pub fn interpolate(&self, p: [f64; 3]) -> Option<f64> {
        let q = self.index_of(p);
        let mut base = [0usize; 3];
        let mut frac = [0.0f64; 3];
        for a in 0..3 {
            let n = self.dims[a];
            let x = q[a];
            if !x.is_finite() {
                return None;
            }
            if self.periodic {
                let x = x.rem_euclid(n as f64);
                let f = x.floor();
                base[a] = (f as usize).min(n - 1);
                frac[a] = x - f;
            } else {
                let top = (n - 1) as f64;
                if x < -1e-9 || x > top + 1e-9 {
                    return None;
                }
                let x = x.clamp(0.0, top);
                let f = x.floor().min(top - 1.0);
                base[a] = f as usize;
                frac[a] = x - f;
            }
        }
        let mut v = 0.0;
        for c in 0..8 {
            let mut w = 1.0;
            let mut ix = [0usize; 3];
            for a in 0..3 {
                let up = (c >> a) & 1 == 1;
                w *= if up { frac[a] } else { 1.0 - frac[a] };
                ix[a] = if up {
                    (base[a] + 1) % self.dims[a]
                } else {
                    base[a]
                };
            }
            if w != 0.0 {
                v += w * self.at(ix[0], ix[1], ix[2]) as f64;
            }
        }
        Some(v)
    }
}

/// Most points (and values) one grid may have: 2^30, 4 GiB of `f32`.
pub const MAX_POINTS: usize = 1 << 30;

/// A volumetric file format, told by [`VolumeFormat::from_path`] or given to
/// [`read_volumes_from`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum VolumeFormat {
    /// Gaussian cube: `.cube`, `.cub`.
    Cube,
    /// VASP volumetric data (a POSCAR block, then grids) holding this quantity.
    Vasp(VaspQuantity),
    /// XCrySDen XSF / AXSF: `.xsf`, `.axsf` (its `DATAGRID_3D` grids).
    Xsf,
    /// OpenDX: `.dx` (APBS potentials, VMD volmap and MDAnalysis densities; no atoms).
    Dx,
    /// CCP4 / MRC maps: `.mrc`, `.map`, `.ccp4`, `.rec` (cryo-EM, crystallographic and
    /// tomographic densities; no atoms).
    Mrc,
}

/// What a VASP volumetric file's values are; the file's name tells (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum VaspQuantity {
    /// `CHGCAR`, `CHG`, `PARCHG`, `AECCAR0/1/2`: charge densities, stored by VASP as ρ·V_cell
    /// and read as ρ in e/Å³.
    Density,
    /// `LOCPOT`: the local potential in eV, as written.
    Potential,
    /// `ELFCAR`: the electron localisation function (0 to 1), as written.
    Elf,
}

impl VaspQuantity {
    /// The quantity a VASP file name holds: one of its parts (split at `.`, `_`, `-`) is
    /// `CHGCAR`, `CHG`, `PARCHG`, `LOCPOT`, `ELFCAR` or `AECCAR`, in any case, optionally
    /// followed by digits (`AECCAR2`, `CHGCAR_spin`, `PARCHG.0012.ALLK`, `run1.CHGCAR`).
    pub fn from_file_name(name: &str) -> Option<VaspQuantity> {
        const NAMES: [(&str, VaspQuantity); 6] = [
            ("CHGCAR", VaspQuantity::Density),
            ("PARCHG", VaspQuantity::Density),
            ("AECCAR", VaspQuantity::Density),
            ("CHG", VaspQuantity::Density),
            ("LOCPOT", VaspQuantity::Potential),
            ("ELFCAR", VaspQuantity::Elf),
        ];
        name.split(['.', '_', '-']).find_map(|part| {
            NAMES.iter().find_map(|(n, q)| {
                let head = part.get(..n.len())?;
                let tail = &part[n.len()..];
                (head.eq_ignore_ascii_case(n) && tail.bytes().all(|b| b.is_ascii_digit()))
                    .then_some(*q)
            })
        })
    }

    /// The name of data set `k` (0-based) of `count` in a file of this quantity.
    fn set_name(self, k: usize, count: usize) -> String {
        const XYZ: [&str; 3] = ["x", "y", "z"];
        match (self, count, k) {
            (VaspQuantity::Density, _, 0) => "total density (e/Å³)".into(),
            (VaspQuantity::Density, 2, 1) => "magnetisation density (e/Å³)".into(),
            (VaspQuantity::Density, 4, _) => {
                format!("magnetisation {} density (e/Å³)", XYZ[k - 1])
            }
            (VaspQuantity::Density, _, _) => format!("data set {} (e/Å³)", k + 1),
            (VaspQuantity::Potential, 1, _) => "local potential (eV)".into(),
            (VaspQuantity::Potential, 2, _) => {
                format!("local potential, spin {} (eV)", ["up", "down"][k])
            }
            (VaspQuantity::Potential, 4, 0) => "local potential (eV)".into(),
            (VaspQuantity::Potential, 4, _) => format!("local potential B{} (eV)", k),
            (VaspQuantity::Potential, _, _) => format!("local potential, data set {} (eV)", k + 1),
            (VaspQuantity::Elf, 1, _) => "ELF".into(),
            (VaspQuantity::Elf, 2, _) => format!("ELF, spin {}", ["up", "down"][k]),
            (VaspQuantity::Elf, _, _) => format!("ELF, data set {}", k + 1),
        }
    }
}

impl VolumeFormat {
    /// The format a path names: `.cube` / `.cub` (any case) is a cube file, `.xsf` / `.axsf`
    /// an XSF file, `.dx` an OpenDX file, `.mrc` / `.map` / `.ccp4` / `.rec` a CCP4/MRC map,
    /// a VASP name ([`VaspQuantity::from_file_name`]) VASP volumetric data; a
    /// final `.gz` is looked through.
    pub fn from_path(path: &Path) -> Option<VolumeFormat> {
        let inner = crate::gz::inner_path(path);
        let ext = inner.extension().and_then(|e| e.to_str()).unwrap_or("");
        if ext.eq_ignore_ascii_case("cube") || ext.eq_ignore_ascii_case("cub") {
            return Some(VolumeFormat::Cube);
        }
        if ext.eq_ignore_ascii_case("xsf") || ext.eq_ignore_ascii_case("axsf") {
            return Some(VolumeFormat::Xsf);
        }
        if ext.eq_ignore_ascii_case("dx") {
            return Some(VolumeFormat::Dx);
        }
        if ["mrc", "map", "ccp4", "rec"]
            .iter()
            .any(|e| ext.eq_ignore_ascii_case(e))
        {
            return Some(VolumeFormat::Mrc);
        }
        let name = inner.file_name()?.to_str()?;
        VaspQuantity::from_file_name(name).map(VolumeFormat::Vasp)
    }
}

/// Reads a volumetric file: its atoms (elements and positions in Å; a VASP file's cell) as a
/// [`Frame`], and every data set in file order. The format comes from the name
/// ([`VolumeFormat::from_path`]); a gzip file is read decompressed, as
/// [`crate::Trajectory::open`] reads one.
pub fn read_volumes(path: impl AsRef<Path>) -> Result<(Frame, Vec<Volume>), Error> {
    let path = path.as_ref();
    let name: Arc<str> = path.display().to_string().into();
    let kind = VolumeFormat::from_path(path).ok_or_else(|| Error::Unsupported {
        file: name.clone(),
        what: "volumetric data from a file not named .cube / .cub, .xsf / .axsf, .dx, \
               .mrc / .map / .ccp4 / .rec or as VASP names its volumetric files (CHGCAR, \
               CHG, PARCHG, LOCPOT, ELFCAR, AECCAR0/1/2)",
    })?;
    let (file, _) = crate::gz::open(path, &name, false)?;
    let len = file.metadata().ok().map(|m| m.len());
    read_sized(file, kind, name, Budget { len })
}

/// Reads volumetric data of format `kind` from `src`; `name` is what errors call the file.
/// Without the file's length, nothing is reserved beyond 2^16 values ahead of reading them.
///
/// ```
/// use texmap_md_io::volume::{read_volumes_from, VolumeFormat};
/// // Two atoms and a 2 x 2 x 3 grid, axes in Å (negative counts), x outermost, z fastest.
/// let cube = "title\ncomment\n 2 0.0 0.0 0.0\n-2 0.5 0 0\n-2 0 0.5 0\n-3 0 0 0.25\n\
///             8 8.0 0 0 0\n1 1.0 0.96 0 0\n\
///             0 1 2\n10 11 12\n100 101 102\n110 111 112\n";
/// let (atoms, sets) = read_volumes_from(cube.as_bytes(), VolumeFormat::Cube, "w.cube")?;
/// assert_eq!(atoms.elements[1].symbol(), "H");
/// assert_eq!(atoms.positions[1], [0.96, 0.0, 0.0]);
/// let v = &sets[0];
/// assert_eq!((v.dims, v.name.as_str()), ([2, 2, 3], "title"));
/// assert_eq!(v.at(1, 0, 2), 102.0); // x = 1, y = 0, z = 2
/// assert_eq!(v.point(1, 1, 2), [0.5, 0.5, 0.5]);
/// # Ok::<(), texmap_md_io::Error>(())
/// ```
pub fn read_volumes_from<R: Read>(
    src: R,
    kind: VolumeFormat,
    name: &str,
) -> Result<(Frame, Vec<Volume>), Error> {
    read_sized(src, kind, name.into(), Budget { len: None })
}

fn read_sized<R: Read>(
    src: R,
    kind: VolumeFormat,
    file: Arc<str>,
    budget: Budget,
) -> Result<(Frame, Vec<Volume>), Error> {
    if kind == VolumeFormat::Mrc {
        return Ok((Frame::new(), crate::mrc::read(src, file, budget.len)?));
    }
    let ctx = Ctx {
        file,
        frame: 0,
        reserve: budget.max_atoms().min(1 << 10),
    };
    let mut lines = LineReader::new(src, 1 << 16);
    let mut frame = Frame::new();
    let sets = match kind {
        VolumeFormat::Cube => crate::cube::read(&mut lines, &ctx, &mut frame, &budget)?,
        VolumeFormat::Xsf => crate::xsf::read(&mut lines, &ctx, &mut frame, &budget)?,
        VolumeFormat::Dx => crate::dx::read(&mut lines, &ctx, &budget)?,
        VolumeFormat::Mrc => unreachable!("read above"),
        VolumeFormat::Vasp(q) => {
            let grids = crate::chgcar::read(&mut lines, &ctx, &mut frame, q, &budget)?;
            let count = grids.len();
            grids
                .into_iter()
                .enumerate()
                .map(|(k, g)| {
                    Volume::new(
                        [0.0; 3],
                        g.steps,
                        g.dims,
                        g.data,
                        true,
                        &q.set_name(k, count),
                    )
                    .map_err(|e| Error::InvalidValue { what: e.0 })
                })
                .collect::<Result<_, _>>()?
        }
    };
    Ok((frame, sets))
}

/// Writes `v` as an OpenDX file (`.dx`) that VMD, PyMOL, Chimera, APBS tools and
/// GridDataFormats read: `comments` first (one `#` line each), then the grid and its values
/// (see the module docs). A periodic volume's points are written as they are.
///
/// ```
/// use texmap_md_io::volume::{read_volumes_from, write_dx, Volume, VolumeFormat};
/// let steps = [[0.5, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 0.5]];
/// let data = (0..12).map(|n| n as f32 * 0.25).collect();
/// let v = Volume::new([1.0, 2.0, 3.0], steps, [3, 2, 2], data, false, "density").unwrap();
/// let mut text = Vec::new();
/// write_dx(&v, &["made by texmap"], &mut text).unwrap();
/// let (_, back) = read_volumes_from(&text[..], VolumeFormat::Dx, "d.dx")?;
/// assert_eq!(back[0], v);
/// # Ok::<(), texmap_md_io::Error>(())
/// ```
pub fn write_dx(
    v: &Volume,
    comments: &[&str],
    out: &mut impl std::io::Write,
) -> std::io::Result<()> {
    crate::dx::write(v, comments, out)
}

/// What the file's size allows: a reader sizes nothing from a count beyond it.
pub(crate) struct Budget {
    /// The file's length in bytes, when known.
    pub(crate) len: Option<u64>,
}

impl Budget {
    /// No length known: counts are bounded by [`MAX_POINTS`] only, and reserves are small.
    pub fn unknown() -> Budget {
        Budget { len: None }
    }

    /// Most atoms the file can hold: an atom line takes at least 8 bytes.
    pub fn max_atoms(&self) -> usize {
        self.len.map_or(usize::MAX, |l| (l / 8) as usize)
    }

    /// Most values the file can hold: a value and its separator take at least 2 bytes.
    pub fn max_values(&self) -> usize {
        self.len
            .map_or(MAX_POINTS, |l| ((l / 2) as usize).min(MAX_POINTS))
    }

    /// Values to reserve room for before reading them.
    pub fn reserve_values(&self) -> usize {
        self.len.map_or(1 << 16, |_| self.max_values())
    }
}

/// What a walk over grid values does with them.
pub(crate) enum Values<'a> {
    /// Counts their fields (a scan: the structure only).
    Count,
    /// Parses each (a finite number, within f32 once scaled) and drops it.
    Check,
    /// Parses each and keeps it, scaled.
    Keep(&'a mut Vec<f32>),
}

/// Walks `n` whitespace-separated values over as many lines as they take (the last of them
/// must hold nothing after the last value), multiplied by `scale`; `what` names the data set
/// in the error of a file that ends before them.
pub(crate) fn walk_values<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    n: usize,
    scale: f64,
    mode: &mut Values,
    what: &str,
) -> Result<(), Error> {
    const VALUE: &str = "a number (a grid value: finite, within f32 range; Fortran's 1.0-100 \
                         for 1.0E-100 is not one)";
    let mut got = 0usize;
    while got < n {
        let p = lines.pos();
        let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
            return Err(ctx.truncated(p, format!("{n} values of {what}, found {got}")));
        };
        for t in fields(line) {
            if got == n {
                return Err(ctx.parse(pos, line, t, "nothing after the data set's last value"));
            }
            got += 1;
            let keep = match mode {
                Values::Count => continue,
                Values::Check => None,
                Values::Keep(v) => Some(v),
            };
            let v = parse_f64(t)
                .map(|v| (v * scale) as f32)
                .filter(|v| v.is_finite())
                .ok_or_else(|| ctx.parse(pos, line, t, VALUE))?;
            if let Some(k) = keep {
                k.push(v);
            }
        }
    }
    Ok(())
}

/// The determinant of the rows `m`.
pub(crate) fn det3(m: [[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_volume_refuses_what_it_cannot_hold() {
        let s = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(Volume::new([0.0; 3], s, [2, 2, 2], vec![0.0; 7], false, "").is_err());
        assert!(Volume::new([0.0; 3], s, [1, 2, 2], vec![0.0; 4], false, "").is_err());
        assert!(Volume::new([0.0; 3], s, [1, 2, 2], vec![0.0; 4], true, "").is_ok());
        let mut nan = vec![0.0; 8];
        nan[5] = f32::NAN;
        let e = Volume::new([0.0; 3], s, [2, 2, 2], nan, false, "").unwrap_err();
        assert!(e.0.contains("value 5"), "{e}");
        let flat = [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
        assert!(Volume::new([0.0; 3], flat, [2, 2, 2], vec![0.0; 8], false, "").is_err());
        assert!(
            Volume::new([0.0; 3], s, [usize::MAX, 2, 2], vec![], false, "").is_err(),
            "an overflowing point count"
        );
    }

    #[test]
    fn interpolation_reproduces_a_linear_field_and_wraps_a_periodic_grid() {
        // f = 1 + 2x − y + 0.5z on a skewed grid: trilinear interpolation is exact for it.
        let s = [[0.5, 0.0, 0.0], [0.25, 0.5, 0.0], [0.1, -0.2, 0.4]];
        let o = [1.0, -2.0, 0.5];
        let dims = [5, 4, 6];
        let f = |p: [f64; 3]| 1.0 + 2.0 * p[0] - p[1] + 0.5 * p[2];
        let mut data = Vec::new();
        for k in 0..6 {
            for j in 0..4 {
                for i in 0..5 {
                    let p: [f64; 3] = std::array::from_fn(|a| {
                        o[a] + i as f64 * s[0][a] + j as f64 * s[1][a] + k as f64 * s[2][a]
                    });
                    data.push(f(p) as f32);
                }
            }
        }
        let v = Volume::new(o, s, dims, data, false, "linear").unwrap();
        for (i, j, k) in [
            (0.0, 0.0, 0.0),
            (3.7, 1.2, 4.9),
            (4.0, 3.0, 5.0),
            (0.5, 2.5, 0.01),
        ] {
            let p = v.point(i, j, k);
            let q = v.index_of(p);
            assert!(
                (q[0] - i).abs() < 1e-12 && (q[1] - j).abs() < 1e-12 && (q[2] - k).abs() < 1e-12
            );
            let got = v.interpolate(p).unwrap();
            assert!(
                (got - f(p)).abs() < 1e-5,
                "{got} vs {} at ({i}, {j}, {k})",
                f(p)
            );
        }
        assert_eq!(v.interpolate(v.point(-0.1, 1.0, 1.0)), None);
        assert_eq!(v.interpolate(v.point(1.0, 1.0, 5.2)), None);
        // Periodic: a point one period over reads the same value; between the last point and
        // the first image, the two are mixed.
        let mut w = v.clone();
        w.periodic = true;
        let a = w.interpolate(w.point(1.3, 2.2, 3.1)).unwrap();
        let b = w
            .interpolate(w.point(1.3 + 5.0, 2.2 - 4.0, 3.1 + 12.0))
            .unwrap();
        assert!((a - b).abs() < 1e-9);
        let mid = w.interpolate(w.point(4.5, 0.0, 0.0)).unwrap();
        let want = (w.at(4, 0, 0) as f64 + w.at(0, 0, 0) as f64) / 2.0;
        assert!((mid - want).abs() < 1e-6);
    }

    #[test]
    fn the_integral_of_a_constant_is_its_value_times_the_volume() {
        // A skewed cell: steps (0.5, 0, 0), (0.25, 0.5, 0), (0, 0, 0.4): cell volume 0.1 Å³.
        let s = [[0.5, 0.0, 0.0], [0.25, 0.5, 0.0], [0.0, 0.0, 0.4]];
        let v = Volume::new([1.0, 2.0, 3.0], s, [4, 5, 6], vec![2.0; 120], true, "c").unwrap();
        assert!((v.cell_volume() - 0.1).abs() < 1e-12);
        assert!((v.integral() - 24.0).abs() < 1e-9);
        assert_eq!(v.point(1, 2, 0.5), [2.0, 3.0, 3.2]);
    }
}

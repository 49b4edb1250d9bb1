//! One frame of a trajectory: positions in Ångström plus whatever per-atom information the file
//! had, and the periodic cell.
//!
//! A [`Frame`] is a set of reusable buffers: readers fill it in place (`read_next(&mut frame)`),
//! so streaming a trajectory allocates nothing per frame once the buffers have grown to the
//! largest frame.
//!
//! # Guarantees of a frame filled by a reader
//! - every per-atom vector is either empty (the file does not have that column) or exactly
//!   [`Frame::n_atoms`] long, and so is every property's;
//! - positions (and velocities, radii, colours) are finite: a reader rejects NaN and infinities
//!   (property values are non-finite only where a LAMMPS dump or an extended-XYZ property
//!   column writes `nan` or `inf`);
//! - positions lie within ±[`MAX_COORDINATE`] Å and cell lengths are at most that: a finite but
//!   absurd value (1e38 from a flipped exponent bit, a cell of 1e300) is a damaged file, reported
//!   by the reader with the file, frame and atom, not a failure later in a renderer's camera;
//! - positions are in Å, velocities in Å/ps, time in ps, whatever the file's units.

use crate::elements::Element;
use crate::error::Error;
use std::fmt;

/// Largest |coordinate| and cell length (Å) a reader accepts: 10^7 Å = 1 mm, a thousand times
/// the largest simulation boxes in use, and far below where f32 positions stop resolving atoms
/// (spacing 1 Å at 1.6·10^7). Anything beyond it in a trajectory is damage.
pub const MAX_COORDINATE: f64 = 1e7;

/// A short string stored inline (at most [`Label::CAPACITY`] bytes of UTF-8): atom names, types,
/// residue names. `Copy`, so filling per-atom labels allocates nothing.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Label {
    len: u8,
    bytes: [u8; Label::CAPACITY],
}

impl Label {
    /// Longest label in bytes.
    pub const CAPACITY: usize = 15;

    /// The label for `s`, or `None` when `s` is longer than [`Label::CAPACITY`] bytes.
    pub fn new(s: &str) -> Option<Label> {
        Label::from_utf8(s.as_bytes())
    }

    /// The label for UTF-8 bytes, or `None` when they are too long or not UTF-8.
    pub fn from_utf8(b: &[u8]) -> Option<Label> {
        if b.len() > Label::CAPACITY || !(b.is_ascii() || std::str::from_utf8(b).is_ok()) {
            return None;
        }
        let mut bytes = [0u8; Label::CAPACITY];
        bytes[..b.len()].copy_from_slice(b);
        Some(Label {
            len: b.len() as u8,
            bytes,
        })
    }

    /// The label as one 128-bit value (length byte and the zero-padded bytes): equal labels
    /// give equal keys, so a per-atom comparison is one integer compare.
    #[inline]
    pub(crate) fn key(&self) -> u128 {
        let mut b = [0u8; 16];
        b[0] = self.len;
        b[1..].copy_from_slice(&self.bytes);
        u128::from_le_bytes(b)
    }

    /// The label's bytes (UTF-8).
    #[inline]
    pub fn as_bytes(&self) -> &[u8] {
        &self.bytes[..self.len as usize]
    }

    /// The label as a string slice.
    pub fn as_str(&self) -> &str {
        // Constructors accept UTF-8 only, so this cannot fail; fall back to "" defensively.
        std::str::from_utf8(&self.bytes[..self.len as usize]).unwrap_or("")
    }

    /// True for the empty label.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

impl std::ops::Deref for Label {
    type Target = str;
    fn deref(&self) -> &str {
        self.as_str()
    }
}

impl fmt::Debug for Label {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self.as_str(), f)
    }
}

impl fmt::Display for Label {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl PartialEq<str> for Label {
    fn eq(&self, other: &str) -> bool {
        self.as_str() == other
    }
}

impl PartialEq<&str> for Label {
    fn eq(&self, other: &&str) -> bool {
        self.as_str() == *other
    }
}

/// A simulation cell: three edge vectors (the rows of [`UnitCell::matrix`], in Å), an origin,
/// and whether the system repeats along each edge ([`UnitCell::periodic`]).
///
/// Lengths a, b, c (Å) and angles α = ∠(b,c), β = ∠(a,c), γ = ∠(a,b) (degrees) are kept beside
/// the matrix so that a cell read as lengths and angles writes back exactly.
///
/// A cell is periodic along all three edges unless the file says otherwise: LAMMPS's `ff`,
/// `ss`, `fs`, `fm`… boundaries (a slab, a nanoparticle, a cascade with a free surface),
/// extended XYZ's `pbc="T T F"`, XSF's SLAB, POLYMER and MOLECULE. Along an edge that is not
/// periodic no atom has an image: nearest images ([`crate::pbc::minimum_image`]), wrapping,
/// bonds and neighbours (CNA, coordination, g(r)…) see the atoms as they are, as OVITO does.
///
/// # Guarantees
/// Lengths are finite and > 0, angles in (0°, 180°), the volume is > 0 (right-handed edges).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitCell {
    lengths: [f64; 3],
    angles: [f64; 3],
    matrix: [[f64; 3]; 3],
    origin: [f64; 3],
    periodic: [bool; 3],
}

fn cos_deg(a: f64) -> f64 {
    // Exact zero for right angles, so orthorhombic cells have an exactly diagonal matrix.
    if a == 90.0 { 0.0 } else { a.to_radians().cos() }
}

fn det3(m: &[[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl UnitCell {
    /// An orthorhombic box with edges along x, y, z.
    pub fn orthorhombic(a: f64, b: f64, c: f64) -> Result<UnitCell, Error> {
        UnitCell::from_lengths_angles([a, b, c], [90.0, 90.0, 90.0])
    }

    /// The cell from lengths (Å) and angles (degrees), in the usual orientation: a along x, b in
    /// the xy plane, c completing a right-handed set (the convention of PDB CRYST1 and LAMMPS).
    pub fn from_lengths_angles(lengths: [f64; 3], angles: [f64; 3]) -> Result<UnitCell, Error> {
        if lengths
            .iter()
            .any(|l| !(l.is_finite() && *l > 0.0 && *l <= MAX_COORDINATE))
        {
            return Err(Error::InvalidValue {
                what: format!("cell lengths must be > 0 and at most 1e7 Å, got {lengths:?}"),
            });
        }
        if angles
            .iter()
            .any(|a| !(a.is_finite() && *a > 0.0 && *a < 180.0))
        {
            return Err(Error::InvalidValue {
                what: format!("cell angles must be in (0, 180) degrees, got {angles:?}"),
            });
        }
        let [a, b, c] = lengths;
        let (ca, cb, cg) = (cos_deg(angles[0]), cos_deg(angles[1]), cos_deg(angles[2]));
        let sg = if angles[2] == 90.0 {
            1.0
        } else {
            angles[2].to_radians().sin()
        };
        // Build the edge vectors: a along x, b in xy, c from the two remaining dot products.
        let cx = c * cb;
        let cy = c * (ca - cb * cg) / sg;
        let cz2 = c * c - cx * cx - cy * cy;
        if cz2.is_nan() || cz2 <= 0.0 {
            return Err(Error::InvalidValue {
                what: format!("cell angles {angles:?} do not describe a cell with volume > 0"),
            });
        }
        let matrix = [[a, 0.0, 0.0], [b * cg, b * sg, 0.0], [cx, cy, cz2.sqrt()]];
        Ok(UnitCell {
            lengths,
            angles,
            matrix,
            origin: [0.0; 3],
            periodic: [true; 3],
        })
    }

    /// The cell from its three edge vectors (rows, Å), in any orientation.
    pub fn from_matrix(matrix: [[f64; 3]; 3]) -> Result<UnitCell, Error> {
        if matrix.iter().flatten().any(|v| !v.is_finite()) {
            return Err(Error::InvalidValue {
                what: format!("cell matrix must be finite, got {matrix:?}"),
            });
        }
        let vol = det3(&matrix);
        if vol.is_nan() || vol <= 0.0 {
            return Err(Error::InvalidValue {
                what: format!(
                    "cell edge vectors must be right-handed with volume > 0, got {matrix:?}"
                ),
            });
        }
        let len = |v: [f64; 3]| dot(v, v).sqrt();
        let lengths = [len(matrix[0]), len(matrix[1]), len(matrix[2])];
        if lengths.iter().any(|l| *l > MAX_COORDINATE) {
            return Err(Error::InvalidValue {
                what: format!("cell edges must be at most 1e7 Å long, got {matrix:?}"),
            });
        }
        let angle = |u: [f64; 3], v: [f64; 3], lu: f64, lv: f64| {
            (dot(u, v) / (lu * lv)).clamp(-1.0, 1.0).acos().to_degrees()
        };
        let angles = [
            angle(matrix[1], matrix[2], lengths[1], lengths[2]),
            angle(matrix[0], matrix[2], lengths[0], lengths[2]),
            angle(matrix[0], matrix[1], lengths[0], lengths[1]),
        ];
        Ok(UnitCell {
            lengths,
            angles,
            matrix,
            origin: [0.0; 3],
            periodic: [true; 3],
        })
    }

    /// The same cell with its corner at `origin` (Å), e.g. LAMMPS (xlo, ylo, zlo).
    pub fn with_origin(mut self, origin: [f64; 3]) -> UnitCell {
        self.origin = origin;
        self
    }

    /// The same cell, periodic along edge k where `periodic[k]`.
    pub fn with_periodic(mut self, periodic: [bool; 3]) -> UnitCell {
        self.periodic = periodic;
        self
    }

    /// Whether the system repeats along each edge a, b, c (see the type's docs).
    pub fn periodic(&self) -> [bool; 3] {
        self.periodic
    }

    /// True when the system repeats along all three edges.
    pub fn is_fully_periodic(&self) -> bool {
        self.periodic == [true; 3]
    }

    /// Edge lengths a, b, c in Å.
    pub fn lengths(&self) -> [f64; 3] {
        self.lengths
    }

    /// Angles α, β, γ in degrees.
    pub fn angles(&self) -> [f64; 3] {
        self.angles
    }

    /// Edge vectors as rows, in Å.
    pub fn matrix(&self) -> [[f64; 3]; 3] {
        self.matrix
    }

    /// The corner of the cell, in Å (zero unless the file gave one).
    pub fn origin(&self) -> [f64; 3] {
        self.origin
    }

    /// Volume in Å³.
    pub fn volume(&self) -> f64 {
        det3(&self.matrix)
    }

    /// The narrowest perpendicular width of the cell (Å): the distance between its closest pair
    /// of opposite faces, volume over the area of a face.
    pub fn min_width(&self) -> f64 {
        let m = self.matrix.map(glam::DVec3::from_array);
        let volume = self.volume();
        [(1, 2), (2, 0), (0, 1)]
            .map(|(a, b)| volume / m[a].cross(m[b]).length())
            .into_iter()
            .fold(f64::INFINITY, f64::min)
    }

    /// The narrowest perpendicular width between opposite faces across which the system
    /// repeats (Å): how far a cutoff may reach before an atom meets its own image. Infinite
    /// when no edge is periodic.
    pub fn min_periodic_width(&self) -> f64 {
        let m = self.matrix.map(glam::DVec3::from_array);
        let volume = self.volume();
        [(1, 2), (2, 0), (0, 1)]
            .into_iter()
            .zip(self.periodic)
            .filter(|(_, p)| *p)
            .map(|((a, b), _)| volume / m[a].cross(m[b]).length())
            .fold(f64::INFINITY, f64::min)
    }

    /// True when all three angles are 90°.
    pub fn is_orthorhombic(&self) -> bool {
        self.angles.iter().all(|a| (a - 90.0).abs() < 1e-9)
    }

    /// Cartesian position (Å) of fractional coordinates `f`: origin + f·M.
    pub fn to_cartesian(&self, f: [f64; 3]) -> [f64; 3] {
        let m = &self.matrix;
        let mut out = self.origin;
        for (k, o) in out.iter_mut().enumerate() {
            *o += f[0] * m[0][k] + f[1] * m[1][k] + f[2] * m[2][k];
        }
        out
    }
}

/// One frame: positions and optional per-atom information (empty vector = absent).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Frame {
    /// Positions in Å.
    pub positions: Vec<[f32; 3]>,
    /// Velocities in Å/ps (empty when the file has none).
    pub velocities: Vec<[f32; 3]>,
    /// The periodic cell, if the frame has one.
    pub cell: Option<UnitCell>,
    /// MD step number, if the file gives one.
    pub step: Option<i64>,
    /// Simulation time in ps, if the file gives one.
    pub time: Option<f64>,
    /// Atom names (PDB/GRO atom name, XYZ species).
    pub names: Vec<Label>,
    /// Elements (from an element column, else guessed from names: see [`crate::elements`]).
    pub elements: Vec<Element>,
    /// Atom types (LAMMPS `type`, extended-XYZ `type`).
    pub types: Vec<Label>,
    /// Atom ids / serial numbers as written in the file.
    pub ids: Vec<i64>,
    /// Residue names (PDB, GRO).
    pub res_names: Vec<Label>,
    /// Residue numbers (PDB, GRO).
    pub res_ids: Vec<i64>,
    /// Chain identifiers (PDB column 22, mmCIF `auth_asym_id` else `label_asym_id`, a PQR's
    /// chain field); an atom whose field is blank has an empty label.
    pub chains: Vec<Label>,
    /// Segment identifiers (PDB columns 73-76, PSF `segid`, CHARMM CRD SEGID); blank is an
    /// empty label.
    pub segments: Vec<Label>,
    /// Per-atom radii in Å from a `radius` column (OVITO convention).
    pub radii: Vec<f32>,
    /// Per-atom colours from colour columns (extended XYZ `color`, LAMMPS dump `ColorR ColorG
    /// ColorB` / `Color.R …`), sRGB-encoded RGB stored as written: normally in [0, 1], but a file
    /// may hold values outside it ([`crate::AtomStyle`] clamps them for drawing).
    pub colors: Vec<[f32; 3]>,
    /// Named per-atom numbers, in the file's column order: PDB and mmCIF `occupancy` and
    /// `bfactor`, MOL2 and PQR `charge`, PQR `radius` (the electrostatics radius, not drawn),
    /// CHARMM CRD `wmain`, every LAMMPS dump column not read into another field (`q`, `mass`, `c_pe`,
    /// `v_stress`, `fx`, ...), extended-XYZ real or integer columns of one component. What
    /// OVITO calls particle properties and colours by; see [`Frame::property`].
    pub properties: Vec<Property>,
    /// The bonds the file lists with the atoms (MDL SDF/MOL, Tripos MOL2): atom index pairs
    /// `[i, j]` with `i < j`, sorted, each once; empty for formats without bonds (whose bonds
    /// come from a topology or from distances).
    pub bonds: Vec<[u32; 2]>,
    /// The order of each of [`Frame::bonds`] as the file gives it (SDF/MOL bond types, MOL2
    /// bond orders), or empty: 1 single, 2 double, 3 triple, [`BOND_AROMATIC`] aromatic, 0 any
    /// other (an SDF query type, a MOL2 `du`, `un` or `nc`; a MOL2 amide `am` is 1).
    pub bond_orders: Vec<u8>,
    /// The frame's title / comment line (XYZ comment, GRO title, PDB TITLE), if any.
    pub comment: String,
}

/// The [`Frame::bond_orders`] value of an aromatic bond.
pub const BOND_AROMATIC: u8 = 4;

/// Sorts `bonds` (pairs `i < j`) with their `orders` alongside, each pair once (the lowest
/// order of a repeated pair kept), into a frame's [`Frame::bonds`] and [`Frame::bond_orders`].
pub(crate) fn set_ordered_bonds(frame: &mut Frame, mut bonds: Vec<([u32; 2], u8)>) {
    bonds.sort_unstable();
    bonds.dedup_by_key(|b| b.0);
    frame.bonds = bonds.iter().map(|b| b.0).collect();
    frame.bond_orders = bonds.iter().map(|b| b.1).collect();
}

/// One named per-atom number column of a [`Frame`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Property {
    /// The column's name as the file writes it (`bfactor`, `c_pe`, `v_stress[1]`).
    pub name: String,
    /// One value per atom: finite, except where a LAMMPS dump or an extended-XYZ property column
    /// writes `nan` (NaN) or `inf` / `-inf` (infinities).
    pub values: Vec<f32>,
}

impl Frame {
    /// An empty frame.
    pub fn new() -> Frame {
        Frame::default()
    }

    /// Number of atoms (the length of `positions`).
    pub fn n_atoms(&self) -> usize {
        self.positions.len()
    }

    /// The comment's `key=value` pairs, as extended XYZ writes a frame's scalars (ASE's
    /// `info`, `energy=-12.3 config_type="bulk"`; our ASE trajectory and pw.x readers put the
    /// energy there too): every pair, in order, quotes taken off the values.
    ///
    /// ```
    /// let mut f = texmap_md_io::Frame::new();
    /// f.comment = r#"Lattice="5 0 0 0 5 0 0 0 5" energy=-12.5 config_type="bulk Si" pbc="T T T""#.into();
    /// assert_eq!(f.comment_value("energy"), Some("-12.5"));
    /// assert_eq!(f.comment_value("config_type"), Some("bulk Si"));
    /// assert_eq!(f.comment_value("Energy"), None);
    /// ```
    pub fn comment_pairs(&self) -> impl Iterator<Item = (&str, &str)> {
        crate::xyz::key_values(self.comment.as_bytes())
            .filter_map(|(k, v)| Some((std::str::from_utf8(k).ok()?, std::str::from_utf8(v).ok()?)))
    }

    /// Whether `name` can be a key of [`Frame::comment_pairs`] that tools name things by: a
    /// letter or `_`, then letters, digits, `_`, `-` and `.` (`energy`, `minimizedAffinity`,
    /// `c_pe.1`).
    pub fn is_comment_key(name: &[u8]) -> bool {
        name.first()
            .is_some_and(|b| b.is_ascii_alphabetic() || *b == b'_')
            && name
                .iter()
                .all(|b| b.is_ascii_alphanumeric() || matches!(b, b'_' | b'-' | b'.'))
    }

    /// The value of `key` (case as written) among [`Frame::comment_pairs`].
    pub fn comment_value(&self, key: &str) -> Option<&str> {
        self.comment_pairs()
            .find(|(k, _)| *k == key)
            .map(|(_, v)| v)
    }

    /// Empties every buffer, keeping its capacity.
    pub fn clear(&mut self) {
        self.positions.clear();
        self.velocities.clear();
        self.cell = None;
        self.step = None;
        self.time = None;
        self.names.clear();
        self.elements.clear();
        self.types.clear();
        self.ids.clear();
        self.res_names.clear();
        self.res_ids.clear();
        self.chains.clear();
        self.segments.clear();
        self.radii.clear();
        self.colors.clear();
        self.properties.clear();
        self.bonds.clear();
        self.bond_orders.clear();
        self.comment.clear();
    }

    /// Adds `other`'s atoms after this frame's, as one scene of several files (a receptor and a
    /// ligand's poses): positions and every per-atom column, [`Frame::bonds`] renumbered. The
    /// cell, time, step and comment stay this frame's. A column only one of the two frames has
    /// is filled for the other's atoms: empty labels (names, types, residues, chains,
    /// segments), [`Element::UNKNOWN`], ids and residue numbers 0, zero velocities, NaN
    /// property values; except radii and colours, which are dropped unless both frames have
    /// them (the atoms are then drawn at their elements' radii and colours, as without the
    /// column, rather than at a made-up one).
    ///
    /// ```
    /// use texmap_md_io::{Element, Frame};
    /// let mut receptor = Frame::new();
    /// receptor.positions = vec![[0.0; 3]; 2];
    /// receptor.elements = vec![Element::from_symbol("N").unwrap(); 2];
    /// let mut ligand = Frame::new();
    /// ligand.positions = vec![[5.0, 0.0, 0.0], [6.2, 0.0, 0.0]];
    /// ligand.bonds = vec![[0, 1]];
    /// receptor.append(&ligand);
    /// assert_eq!(receptor.n_atoms(), 4);
    /// assert_eq!(receptor.bonds, [[2, 3]]);
    /// assert_eq!(receptor.elements[3], Element::UNKNOWN);
    /// assert_eq!(receptor.check(), Ok(()));
    /// ```
    pub fn append(&mut self, other: &Frame) {
        let (n, m) = (self.n_atoms(), other.n_atoms());
        fn join<T: Clone>(a: &mut Vec<T>, b: &[T], n: usize, m: usize, fill: T) {
            if a.is_empty() && b.is_empty() {
                return;
            }
            if a.is_empty() {
                a.resize(n, fill.clone());
            }
            if b.is_empty() {
                a.resize(n + m, fill);
            } else {
                a.extend_from_slice(b);
            }
        }
        let blank = Label::default();
        join(&mut self.velocities, &other.velocities, n, m, [0.0; 3]);
        join(&mut self.names, &other.names, n, m, blank);
        join(&mut self.elements, &other.elements, n, m, Element::UNKNOWN);
        join(&mut self.types, &other.types, n, m, blank);
        join(&mut self.ids, &other.ids, n, m, 0);
        join(&mut self.res_names, &other.res_names, n, m, blank);
        join(&mut self.res_ids, &other.res_ids, n, m, 0);
        join(&mut self.chains, &other.chains, n, m, blank);
        join(&mut self.segments, &other.segments, n, m, blank);
        if self.radii.is_empty() || other.radii.is_empty() {
            self.radii.clear();
        } else {
            self.radii.extend_from_slice(&other.radii);
        }
        if self.colors.is_empty() || other.colors.is_empty() {
            self.colors.clear();
        } else {
            self.colors.extend_from_slice(&other.colors);
        }
        for p in &mut self.properties {
            match other.property(&p.name) {
                Some(v) => p.values.extend_from_slice(v),
                None => p.values.resize(n + m, f32::NAN),
            }
        }
        for p in &other.properties {
            if self.property(&p.name).is_none() {
                let mut values = vec![f32::NAN; n];
                values.extend_from_slice(&p.values);
                self.properties.push(Property {
                    name: p.name.clone(),
                    values,
                });
            }
        }
        let shift = n as u32;
        // Orders for every bond once either frame has some (0: not given).
        let ordered = |f: &Frame| !f.bond_orders.is_empty() && f.bond_orders.len() == f.bonds.len();
        if ordered(self) || ordered(other) {
            self.bond_orders.resize(self.bonds.len(), 0);
            if ordered(other) {
                self.bond_orders.extend_from_slice(&other.bond_orders);
            } else {
                self.bond_orders
                    .resize(self.bonds.len() + other.bonds.len(), 0);
            }
        }
        self.bonds
            .extend(other.bonds.iter().map(|[i, j]| [i + shift, j + shift]));
        self.positions.extend_from_slice(&other.positions);
    }

    /// Keeps the atoms whose `keep` entry is true, in order, with every per-atom column and
    /// property; [`Frame::bonds`] between two kept atoms stay (renumbered, with their orders),
    /// the others go. The cell, time, step and comment stay. `keep` has one entry per atom.
    ///
    /// ```
    /// use texmap_md_io::Frame;
    /// let mut f = Frame::new();
    /// f.positions = vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
    /// f.ids = vec![10, 11, 12];
    /// f.bonds = vec![[0, 1], [1, 2]];
    /// f.retain_atoms(&[false, true, true]);
    /// assert_eq!(f.ids, [11, 12]);
    /// assert_eq!(f.bonds, [[0, 1]]);
    /// assert_eq!(f.check(), Ok(()));
    /// ```
    ///
    /// # Panics
    /// If `keep.len()` is not the number of atoms.
    pub fn retain_atoms(&mut self, keep: &[bool]) {
        let n = self.n_atoms();
        assert_eq!(keep.len(), n, "one keep flag per atom");
        fn retain<T>(v: &mut Vec<T>, keep: &[bool]) {
            if v.len() == keep.len() {
                let mut k = keep.iter();
                v.retain(|_| *k.next().expect("lengths checked"));
            }
        }
        retain(&mut self.positions, keep);
        retain(&mut self.velocities, keep);
        retain(&mut self.names, keep);
        retain(&mut self.elements, keep);
        retain(&mut self.types, keep);
        retain(&mut self.ids, keep);
        retain(&mut self.res_names, keep);
        retain(&mut self.res_ids, keep);
        retain(&mut self.chains, keep);
        retain(&mut self.segments, keep);
        retain(&mut self.radii, keep);
        retain(&mut self.colors, keep);
        for p in &mut self.properties {
            retain(&mut p.values, keep);
        }
        // New index of each kept atom.
        let mut index = vec![u32::MAX; n];
        let mut next = 0u32;
        for (slot, &k) in index.iter_mut().zip(keep) {
            if k {
                *slot = next;
                next += 1;
            }
        }
        let ordered = self.bond_orders.len() == self.bonds.len() && !self.bond_orders.is_empty();
        let mut bonds = Vec::with_capacity(self.bonds.len());
        let mut orders = Vec::new();
        for (b, [i, j]) in self.bonds.iter().enumerate() {
            let (a, c) = (index[*i as usize], index[*j as usize]);
            if a != u32::MAX && c != u32::MAX {
                bonds.push([a, c]);
                if ordered {
                    orders.push(self.bond_orders[b]);
                }
            }
        }
        self.bonds = bonds;
        self.bond_orders = orders;
    }

    /// The values of the property named `name` (exact match), if the frame has it.
    pub fn property(&self, name: &str) -> Option<&[f32]> {
        self.properties
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.values.as_slice())
    }

    /// Reserves room for `n` more positions, names and elements (a reader's atoms; the caller
    /// bounds `n`, see [`crate::text::MAX_RESERVE`]).
    pub(crate) fn reserve_named(&mut self, n: usize) {
        self.positions.reserve(n);
        self.names.reserve(n);
        self.elements.reserve(n);
    }

    /// The values of the property `name`, a new empty one added if the frame has none yet.
    pub(crate) fn property_mut(&mut self, name: &str) -> &mut Vec<f32> {
        let k = match self.properties.iter().position(|p| p.name == name) {
            Some(k) => k,
            None => {
                self.properties.push(Property {
                    name: name.to_string(),
                    values: Vec::new(),
                });
                self.properties.len() - 1
            }
        };
        &mut self.properties[k].values
    }

    /// Checks the guarantees of a frame (see the module doc); the message names the first broken
    /// one. Writers call this before writing.
    pub fn check(&self) -> Result<(), String> {
        let n = self.n_atoms();
        let lens = [
            ("velocities", self.velocities.len()),
            ("names", self.names.len()),
            ("elements", self.elements.len()),
            ("types", self.types.len()),
            ("ids", self.ids.len()),
            ("res_names", self.res_names.len()),
            ("res_ids", self.res_ids.len()),
            ("chains", self.chains.len()),
            ("segments", self.segments.len()),
            ("radii", self.radii.len()),
            ("colors", self.colors.len()),
        ];
        for (what, len) in lens {
            if len != 0 && len != n {
                return Err(format!("{what} has {len} entries but there are {n} atoms"));
            }
        }
        let finite3 = |v: &[[f32; 3]]| v.iter().position(|p| p.iter().any(|x| !x.is_finite()));
        if let Some(i) = finite3(&self.positions) {
            return Err(format!("position of atom {i} is not finite"));
        }
        if let Some(i) = finite3(&self.velocities) {
            return Err(format!("velocity of atom {i} is not finite"));
        }
        if let Some(i) = self
            .radii
            .iter()
            .position(|r| !(r.is_finite() && *r >= 0.0))
        {
            return Err(format!("radius of atom {i} is not finite and >= 0"));
        }
        if let Some(i) = finite3(&self.colors) {
            return Err(format!("colour of atom {i} is not finite"));
        }
        for p in &self.properties {
            if p.values.len() != n {
                return Err(format!(
                    "property {} has {} entries but there are {n} atoms",
                    p.name,
                    p.values.len()
                ));
            }
        }
        if let Some(b) = self
            .bonds
            .iter()
            .find(|b| b[0] >= b[1] || b[1] as usize >= n)
        {
            return Err(format!(
                "bond {b:?} is not two atom indices i < j below {n}"
            ));
        }
        if self.bonds.windows(2).any(|w| w[0] >= w[1]) {
            return Err("bonds are not sorted, each once".into());
        }
        if !self.bond_orders.is_empty() && self.bond_orders.len() != self.bonds.len() {
            return Err(format!(
                "{} bond orders for {} bonds",
                self.bond_orders.len(),
                self.bonds.len()
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(expected: f64, actual: f64, tol: f64) {
        assert!(
            (expected - actual).abs() <= tol,
            "expected {expected}, actual {actual}, tolerance {tol}"
        );
    }

    #[test]
    fn label_round_trip_and_limits() {
        let l = Label::new("CA").unwrap();
        assert_eq!(l, "CA");
        assert_eq!(l.len(), 2);
        assert!(Label::new("0123456789abcdef").is_none());
        assert!(Label::from_utf8(&[0xff]).is_none());
    }

    #[test]
    fn lengths_angles_round_trip_through_matrix() {
        // A triclinic cell: rebuild lengths and angles from the matrix by dot products (f64).
        let c = UnitCell::from_lengths_angles([10.0, 12.0, 15.0], [70.0, 80.0, 100.0]).unwrap();
        let c2 = UnitCell::from_matrix(c.matrix()).unwrap();
        for k in 0..3 {
            close(c.lengths()[k], c2.lengths()[k], 1e-12);
            close(c.angles()[k], c2.angles()[k], 1e-10);
        }
        // Volume against the closed form abc·sqrt(1 - cos²α - cos²β - cos²γ + 2 cosα cosβ cosγ).
        let (ca, cb, cg) = (
            70f64.to_radians().cos(),
            80f64.to_radians().cos(),
            100f64.to_radians().cos(),
        );
        let v =
            10.0 * 12.0 * 15.0 * (1.0 - ca * ca - cb * cb - cg * cg + 2.0 * ca * cb * cg).sqrt();
        close(v, c.volume(), 1e-9);
    }

    #[test]
    fn bad_cells_are_rejected() {
        assert!(UnitCell::orthorhombic(0.0, 1.0, 1.0).is_err());
        assert!(UnitCell::orthorhombic(f64::NAN, 1.0, 1.0).is_err());
        assert!(UnitCell::from_lengths_angles([1.0; 3], [120.0, 120.0, 130.0]).is_err());
        assert!(
            UnitCell::from_matrix([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]).is_err()
        );
        let c = UnitCell::orthorhombic(2.0, 3.0, 4.0).unwrap();
        assert_eq!(
            c.matrix(),
            [[2.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 4.0]]
        );
        assert!(c.is_orthorhombic());
    }

    #[test]
    fn check_finds_ragged_columns_and_nan() {
        let mut f = Frame::new();
        f.positions = vec![[0.0; 3]; 2];
        f.names = vec![Label::new("C").unwrap()];
        assert!(f.check().unwrap_err().contains("names"));
        f.names.clear();
        f.positions[1][2] = f32::NAN;
        assert!(f.check().unwrap_err().contains("atom 1"));
    }
}

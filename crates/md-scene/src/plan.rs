//! What happens to a frame between reading and drawing: the topology's labels, the bonds, the
//! periodic boundaries, the per-selection colours and radii, the draw style and the selection
//! of the atoms that are drawn.
//!
//! [`MolPlan::build`] runs, in this order:
//! 1. the bonds as [`BondSource`] asks (the topology's, or found by distance), found only when
//!    they are drawn or needed to unwrap;
//! 2. the periodic boundaries ([`Pbc`]): atoms wrapped into the box, or molecules made whole
//!    across it (with bonds by distance when none are drawn); with
//!    [`MolOptions::replicate`], the frame and its bonds then copied along the cell vectors
//!    ([`texmap_md_io::replicate`]: bonds across inner faces become whole, and every later
//!    step sees the copies, so `index` counts their atoms too); with
//!    [`MolOptions::coordination`], each atom's neighbour count as the property
//!    [`COORDINATION`], with [`MolOptions::clusters`] each atom's cluster as [`CLUSTER`], with
//!    [`MolOptions::centrosymmetry`] each atom's [`CENTROSYMMETRY`], and with
//!    [`MolOptions::strain`] its [`SHEAR_STRAIN`], [`VOLUMETRIC_STRAIN`] and [`D2MIN`] against
//!    the reference configuration (the first frame built at this step, or the one given to
//!    [`MolPlan::set_displacement_reference`]), with [`MolOptions::wigner_seitz`] its point
//!    defects ([`WsOutput`]: the atoms with their sites' occupancy, or the sites instead of
//!    the atoms), with [`MolOptions::voronoi`] each atom's Voronoi cell; then each of
//!    [`MolOptions::computes`], in order, as the property it names,
//!    and [`MolOptions::freeze`]'s properties set to their values at the first frame built;
//!    bonds that still cross the (enlarged) box are dropped, so no stick
//!    spans it; with [`MolOptions::displacement`] (after the alignment of step 3), each atom's
//!    distance from the first frame built as the property [`DISPLACEMENT`];
//! 3. with [`MolOptions::align`], the frame superposed on a reference: the first frame built,
//!    or a structure given ([`Alignment::reference`]). The alignment selection is evaluated
//!    once, at the first frame (and in the reference), and every frame's positions,
//!    velocities and cell are moved by the rotation and translation that fit those atoms onto
//!    the reference's in least squares, unweighted or by mass ([`crate::align`]; MDAnalysis's
//!    `AlignTraj`), so the picked molecule holds still while the rest moves relative to it;
//!    then, with [`MolOptions::slice`], which atoms lie on the kept side of a plane or in a
//!    slab ([`Slice`]): only those are drawn (step 6), while colourings, analyses and
//!    selections still see the whole system, as with OVITO's Slice at the end of a pipeline
//!    (atoms at the cut keep their crystal structure and coordination);
//! 4. every atom styled by the [`SceneBuilder`] (a scalar colouring's range, unless given,
//!    fitted at the first frame to the atoms the selection draws), then the colour rules and the
//!    radius rules, each list in order, so that a later rule wins over an earlier one for the
//!    atoms both select;
//! 5. per [`Representation`] (one, of [`MolOptions::select`] and [`MolOptions::draw`], unless
//!    [`MolOptions::reps`] lists several, each then drawn on its own and the scenes
//!    concatenated, every bond with its style's radius in [`SphereScene::bond_radii`]):
//!    its own colouring ([`RepColor`]) if it has one, under the colour rules again; then the
//!    [`DrawStyle`]: radii scaled for ball-and-stick, or all set to [`LICORICE_RADIUS`];
//! 6. the selection (and the slice): the selected atoms are kept in their order and the bonds between two kept
//!    atoms are renumbered to the kept atoms' indices; bonds to a dropped atom are dropped;
//! 7. for [`DrawStyle::Tube`], the selected atoms of protein and nucleic residues give way to
//!    the backbone tube through their CA (P) atoms, appended as spheres joined by bonds; for
//!    [`DrawStyle::Cartoon`], protein and nucleic residues give way to the cartoon mesh
//!    ([`MolPlan::cartoon_mesh`]); for [`DrawStyle::Surface`], the
//!    selected atoms leave the scene for [`MolPlan::surface_atoms`]; for [`DrawStyle::HBonds`],
//!    the atoms give way to the hydrogen bonds among them (below); for
//!    [`DrawStyle::Polyhedra`], the selected atoms give way to their coordination polyhedra
//!    ([`MolPlan::polyhedra_mesh`], [`crate::polyhedra`]), whose ligands are the atoms of
//!    another element bonded to them in step 2, before bonds across the box are dropped (by
//!    distance when no bonds are drawn); for [`DrawStyle::Arrows`], the selected atoms give
//!    way to their arrows ([`MolPlan::arrows_mesh`], [`crate::arrows`]), the vectors taken
//!    after the alignment (displacements from the first frame built, as it was then).
//!
//! # Bond orders
//! With [`MolOptions::bond_orders`], the ball-and-stick and licorice styles draw the orders a
//! file gives its bonds ([`Frame::bond_orders`]) as PyMOL's valence mode does: a double bond
//! as two sticks of [`VALENCE_RADIUS`] times the style's bond radius, [`VALENCE_OFFSET`] bond
//! radii either side of the bond, a triple as three thinner ones, an aromatic bond as a thin
//! stick with a dashed line beside it; the second line lies toward a third atom bonded to one
//! end (an aromatic neighbour first, so a ring's dashes lie inside it). Each stick ends in
//! spheres of its radius at the atoms' centres, hidden inside the atoms.
//!
//! # Measurements
//! [`MolOptions::measures`] are measured in every frame [`MolPlan::prepare`] takes (after the
//! periodic treatment, the images and the alignment; [`crate::measure`]), so a program that
//! writes frames has their values too, and [`MolPlan::build`] draws them as
//! [`crate::measure::MEASURE_DASHES`] yellow dashes per segment of radius
//! [`crate::measure::MEASURE_RADIUS`], appended after every representation with their own
//! bond radius; [`MolPlan::last_measurements`] gives their values and label places.
//!
//! # Trails
//! [`DrawStyle::Trails`] draws where atoms went, as OVITO's Generate trajectory lines: the
//! atoms its representation selects at the first frame built are followed from then on, each
//! frame built adding a point to each one's path. The path is unwrapped: a step is taken to
//! the nearest periodic image, so an atom that crossed a face of the box has a trail that
//! leaves the box through the face it came in by, instead of a line back across the box (the
//! frames drawn must then be close enough that no atom moves half a box between two of them).
//! The path is drawn moved as a whole to end at the atom as it is drawn. The last [`MolOptions::trail_length`] points
//! are drawn, as spheres of [`TRAIL_RADIUS`] joined by sticks, in each atom's current colour.
//! Points are added by [`MolPlan::build`], so a trail holds the frames built before, in the
//! order they were built.
//!
//! # Hydrogen bonds
//! [`DrawStyle::HBonds`] draws the hydrogen bonds among a representation's atoms
//! ([`texmap_md_io::hbonds`]: MDAnalysis's criterion, [`MolOptions::hbonds`] its cutoffs; the
//! donor–hydrogen pairs are taken from the frame's bonds in step 2, before bonds across the
//! box are dropped, or by distance when no bonds are drawn) as VMD's HBonds and ChimeraX's
//! `hbonds` show them: a dashed line from each hydrogen to its acceptor (to the acceptor's
//! nearest image, so a bond across the box leaves the box), [`HBOND_DASHES`] dashes of radius
//! [`HBOND_RADIUS`] with round ends, as long as the gaps between them, in the
//! representation's colour, else [`HBOND_COLOR`]. Explicit hydrogens are needed (a crystal
//! structure without them has none to find); [`MolPlan::last_hbonds`] lists the last frame's.
//!
//! # The tube
//! VMD's Tube representation: per chain, a uniform Catmull-Rom spline through the consecutive
//! CA atoms of protein residues (P atoms of nucleic residues), which it passes through exactly,
//! sampled [`TUBE_SUBDIVISIONS`] times per interval and drawn as spheres of [`TUBE_RADIUS`]
//! joined by cylinders of the same radius. A trace breaks where the chain or segment changes or
//! two neighbours are further apart than a bonded pair can be ([`MAX_CA_GAP`], [`MAX_P_GAP`]).
//! Each half interval takes the colour of its nearer CA (P) atom, so colour rules and
//! `ColorBy::Chain` colour the tube. A lone CA (P) is one sphere. Ends are extended by mirroring
//! the neighbour, so the tube ends at the first and last atom.

use std::fmt;

use texmap_impostor::SphereScene;
use texmap_md_io::centrosymmetry::{CentroError, CspMode};
use texmap_md_io::coordination::CoordinationError;
use texmap_md_io::expr::{ExprError, Expression};
use texmap_md_io::grains::{Grain, GrainOptions};
use texmap_md_io::hbonds::{self, Criteria, HBond, HBondError};
use texmap_md_io::replicate::ReplicateError;
use texmap_md_io::strain::StrainError;
use texmap_md_io::voronoi::VoronoiError;
use texmap_md_io::wigner_seitz::WignerSeitzError;
use texmap_md_io::{
    BOND_AROMATIC, Frame, Property, Selection, SelectionError, Topology, atom_element,
};

use crate::arrows::{ArrowError, ArrowOptions, ArrowSource};
use crate::ellipsoids::{Ellipsoid, EllipsoidError, EllipsoidOptions};
use crate::measure::{
    MEASURE_COLOR, MEASURE_DASHES, MEASURE_RADIUS, Measure, MeasureError, Measured,
};
use crate::surface::{MolMesh, SurfaceAtoms};
use crate::{ColorBy, SceneBuilder};

/// Ball-and-stick atoms are this fraction of their Bondi (van der Waals) radii.
pub const BALL_AND_STICK_RADIUS_SCALE: f32 = 0.3;
/// The sticks of a double bond ([`MolOptions::bond_orders`]): each of this fraction of the
/// style's bond radius, their axes this many bond radii from the bond's.
pub const VALENCE_RADIUS: f32 = 0.5;
pub const VALENCE_OFFSET: f32 = 1.2;
/// Radius (Å) of the spheres and sticks of [`DrawStyle::Trails`].
pub const TRAIL_RADIUS: f32 = 0.1;
/// Radius (Å) of the dashes of [`DrawStyle::HBonds`] (ChimeraX draws its hydrogen bonds at
/// 0.075 Å).
pub const HBOND_RADIUS: f32 = 0.075;
/// Dashes per hydrogen bond of [`DrawStyle::HBonds`].
pub const HBOND_DASHES: usize = 4;
/// The colour (sRGB) of [`DrawStyle::HBonds`] without a colour of its own: ChimeraX's deep sky
/// blue.
pub const HBOND_COLOR: [f32; 3] = [0.0, 0.75, 1.0];
/// Ball-and-stick bond radius in Å: thinner than the smallest scaled atom (H, 0.36 Å), so the
/// bond ends are hidden inside the atoms.
pub const BALL_AND_STICK_BOND_RADIUS: f32 = 0.2;
/// Atom and stick radius of [`DrawStyle::Licorice`] (Å), as VMD's Licorice default (0.3).
pub const LICORICE_RADIUS: f32 = 0.3;
/// Radius of [`DrawStyle::Tube`]'s backbone tube (Å), as VMD's Tube default (0.3); equal to
/// [`LICORICE_RADIUS`], since a scene has one bond radius and ligands are drawn as licorice.
pub const TUBE_RADIUS: f32 = LICORICE_RADIUS;
/// Spline points per CA-CA (P-P) interval of the tube.
pub const TUBE_SUBDIVISIONS: usize = 8;
/// Largest CA-CA distance (Å) joined by the tube: 3.8 Å in a chain (2.9 Å for a cis peptide),
/// so a longer gap is a chain break (a missing loop).
pub const MAX_CA_GAP: f32 = 4.3;
/// Largest P-P distance (Å) joined by the tube: 5.5-7.5 Å between nucleotides.
pub const MAX_P_GAP: f32 = 8.0;

/// Where the bonds come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BondSource {
    /// No bonds.
    None,
    /// Only the bonds the files list: the topology's, else the frame's own
    /// ([`Frame::bonds`]: SDF, MOL2).
    Topology,
    /// The bonds the files list when they list any (the topology's, else the frame's), else
    /// bonds by distance.
    Auto,
}

/// How atoms and bonds are drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DrawStyle {
    /// Atoms at their full radii, no bonds.
    Spacefill,
    /// Atoms at [`BALL_AND_STICK_RADIUS_SCALE`] of their radii, bonds of
    /// [`BALL_AND_STICK_BOND_RADIUS`].
    BallStick,
    /// Atoms and bonds all of [`LICORICE_RADIUS`].
    Licorice,
    /// Protein and nucleic-acid backbones as a smooth tube (see the module docs); other atoms
    /// (ligands, ions, water) as [`DrawStyle::Licorice`].
    Tube,
    /// Protein backbones as a cartoon (VMD's NewCartoon: helices as ribbons, strands as arrows,
    /// coil as a tube, [`crate::cartoon`]), nucleic acids as a tube through the P atoms with a
    /// rung to each base, other atoms (ligands, ions, water) as [`DrawStyle::Licorice`].
    Cartoon,
    /// The selected atoms wrapped in a molecular surface (VMD's QuickSurf: a Gaussian density
    /// surface, [`crate::surface`]); they are not drawn as spheres, and nothing is bonded.
    Surface,
    /// The hydrogen bonds among the selected atoms as dashed lines from hydrogen to acceptor
    /// (VMD's HBonds; see the module docs); the atoms themselves are not drawn.
    HBonds,
    /// Coordination polyhedra (VESTA's): around each selected atom, the convex hull of the
    /// atoms of other elements bonded to it, at their nearest periodic images, in the centre
    /// atom's colour
    /// ([`crate::polyhedra`]); the atoms themselves are not drawn.
    Polyhedra,
    /// An arrow from each selected atom along its vector ([`MolOptions::arrows`]: velocity,
    /// displacement from the first frame, or a vector property; [`crate::arrows`]); the atoms
    /// themselves are not drawn.
    Arrows,
    /// The path each selected atom took over the frames drawn so far (OVITO's trajectory
    /// lines; see the module docs): the atoms picked at the first frame, the path unwrapped
    /// across the box, [`MolOptions::trail_length`] frames long; the atoms themselves are not
    /// drawn.
    Trails,
    /// Each selected atom as an ellipsoid of its aspherical shape and orientation
    /// ([`MolOptions::ellipsoids`], [`crate::ellipsoids`]: LAMMPS `shapex..` and `quatw..`, or
    /// one shape for all), tessellated for the view by the caller from
    /// [`MolPlan::ellipsoids`]; an atom whose shape is three zeros (a LAMMPS sphere) stays a
    /// sphere; nothing is bonded.
    Ellipsoids,
}

/// The periodic-boundary treatment (frames without a cell are left as they are).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pbc {
    /// Positions as read.
    None,
    /// Every atom moved into the box.
    Wrap,
    /// Molecules split across the box joined along their bonds.
    Unwrap,
}

/// The per-atom property [`MolOptions::coordination`] adds to each frame.
pub const COORDINATION: &str = "coordination";
/// The per-atom property [`MolOptions::clusters`] adds to each frame (0 the largest cluster, −1
/// for atoms not clustered).
pub const CLUSTER: &str = "cluster";

/// The per-atom property [`MolOptions::sasa`] adds to each frame: the solvent-accessible area
/// in Å² (NaN for atoms not measured).
pub const SASA: &str = "sasa";
/// The per-atom property [`MolOptions::centrosymmetry`] adds to each frame (Å²).
pub const CENTROSYMMETRY: &str = "centrosymmetry";
/// The per-atom von Mises shear strain [`MolOptions::strain`] adds to each frame.
pub const SHEAR_STRAIN: &str = "shear_strain";
/// The per-atom volumetric strain [`MolOptions::strain`] adds to each frame.
pub const VOLUMETRIC_STRAIN: &str = "volumetric_strain";
/// The per-atom non-affine squared displacement (Å²) [`MolOptions::strain`] adds to each frame.
pub const D2MIN: &str = "d2min";
/// The per-atom property [`MolOptions::wigner_seitz`] adds: the occupancy of the atom's site
/// (or, drawing the sites, of the site).
pub const SITE_OCCUPANCY: &str = "site_occupancy";
/// The per-atom property [`MolOptions::wigner_seitz`] adds: the index of the atom's site in the
/// reference (or, drawing the sites, the site's own).
pub const SITE: &str = "site";
/// The per-atom Voronoi cell volume (Å³) [`MolOptions::voronoi`] adds.
pub const VORONOI_VOLUME: &str = "voronoi_volume";
/// The per-atom Voronoi face count (the Voronoi coordination) [`MolOptions::voronoi`] adds.
pub const VORONOI_FACES: &str = "voronoi_faces";
/// The per-atom counts of Voronoi faces with 3, 4, 5 and 6 edges [`MolOptions::voronoi`] adds.
pub const VORONOI_INDEX: [&str; 4] = ["voronoi_n3", "voronoi_n4", "voronoi_n5", "voronoi_n6"];
/// The per-atom lattice orientation quaternion components (x, y, z, w) [`MolOptions::orientations`]
/// adds: NaN for atoms that are not FCC, HCP or BCC.
pub const ORIENTATION: [&str; 4] = [
    "orientation_x",
    "orientation_y",
    "orientation_z",
    "orientation_w",
];
/// The per-atom deviation from the ideal lattice (PTM's RMSD) [`MolOptions::orientations`]
/// adds: NaN for atoms that are not FCC, HCP or BCC.
pub const LATTICE_RMSD: &str = "lattice_rmsd";
/// The per-atom grain [`MolOptions::grains`] adds (0 the largest, −1 for atoms in none).
pub const GRAIN: &str = "grain";
/// Each atom's squared displacement (Å²) from the first frame, followed across the periodic
/// boundaries, that [`MolOptions::msd`] adds.
pub const MSD: &str = "msd";
/// The per-atom property [`MolOptions::displacement`] adds to each frame.
pub const DISPLACEMENT: &str = "displacement";

/// The options of a [`MolPlan`]; selections are parsed by the caller.
#[derive(Clone, Debug)]
pub struct MolOptions {
    /// Per-atom labels (names, residues, elements) and bonds given to every frame.
    pub topology: Option<Topology>,
    /// The atoms drawn (all when `None`).
    pub select: Option<Selection>,
    /// Colour rules (sRGB fractions of 1), applied in order.
    pub colors: Vec<(Selection, [f32; 3])>,
    /// Radius rules (Å, before the style's radius scale), applied in order.
    pub radii: Vec<(Selection, f32)>,
    /// Where bonds come from.
    pub bonds: BondSource,
    /// How atoms and bonds are drawn.
    pub draw: DrawStyle,
    /// The periodic-boundary treatment.
    pub pbc: Pbc,
    /// Periodic images `[nx, ny, nz]` drawn with the frame (OVITO's Replicate modifier:
    /// [`texmap_md_io::replicate`]), after the periodic treatment; `None` draws the frame alone.
    pub replicate: Option<[usize; 3]>,
    /// Count each atom's neighbours within this cutoff (Å) every frame, after the periodic
    /// images, as the per-atom property `coordination` (OVITO's Coordination analysis:
    /// [`texmap_md_io::coordination`]), for colouring and selections (`prop coordination < 12`).
    pub coordination: Option<f32>,
    /// Group atoms into clusters of neighbours within a cutoff every frame, after the
    /// coordination, as the per-atom property `cluster` (OVITO's Cluster analysis:
    /// [`texmap_md_io::coordination::clusters`]), for colouring ([`crate::ColorBy::Cluster`])
    /// and selections (`prop cluster == 0`: the largest).
    pub clusters: Option<ClusterOptions>,
    /// Every atom's solvent-accessible surface area every frame, after the clusters, as the
    /// per-atom property [`SASA`] (Å²; Shrake–Rupley as MDTraj's, VMD's `measure sasa`:
    /// [`texmap_md_io::sasa`]), for colouring (`--color-by sasa`) and selections
    /// (`prop sasa > 30`: the exposed residues' atoms).
    pub sasa: Option<SasaOptions>,
    /// The centrosymmetry parameter of every atom every frame, after the clusters, as the
    /// per-atom property `centrosymmetry` (OVITO's Centrosymmetry modifier, LAMMPS's
    /// `centro/atom`: [`texmap_md_io::centrosymmetry`]), for colouring and for hiding the
    /// perfect crystal (`prop centrosymmetry > 1`).
    pub centrosymmetry: Option<CentroOptions>,
    /// The atomic strain of every atom every frame against the reference configuration, from
    /// its neighbours within this cutoff (Å) in the reference, after the centrosymmetry, as the
    /// per-atom properties `shear_strain`, `volumetric_strain` and `d2min` (OVITO's Atomic strain
    /// modifier: [`texmap_md_io::strain`]). The reference is the first frame built, as it is at
    /// this step, or the frame given to [`MolPlan::set_displacement_reference`].
    pub strain: Option<f32>,
    /// Per-atom properties computed from formulas every frame, after the analyses above, in
    /// order (a later formula may use an earlier one's name): OVITO's Compute property
    /// modifier ([`texmap_md_io::expr`]). Each `(name, formula)` sets the property `name`.
    pub computes: Vec<(String, Expression)>,
    /// Point defects against the reference configuration every frame, after the strain
    /// (OVITO's Wigner-Seitz defect analysis: [`texmap_md_io::wigner_seitz`]): the reference
    /// is the first frame built, as it is at this step, or the frame given to
    /// [`MolPlan::set_displacement_reference`]. [`MolPlan::last_defects`] counts vacancies and
    /// interstitials; see [`WsOutput`] for what is drawn.
    pub wigner_seitz: Option<WsOutput>,
    /// Every atom's Voronoi cell every frame, after the Wigner–Seitz analysis (OVITO's Voronoi
    /// analysis: [`texmap_md_io::voronoi`]), as the properties [`VORONOI_VOLUME`],
    /// [`VORONOI_FACES`] and [`VORONOI_INDEX`] (`prop voronoi_n5 == 12 and prop voronoi_faces
    /// == 12`: the icosahedra of a metallic glass). Needs a periodic cell.
    pub voronoi: bool,
    /// Every crystalline atom's lattice orientation every frame, after the Voronoi cells (the
    /// orientation and RMSD of OVITO's Polyhedral template matching, on the FCC, HCP and BCC
    /// atoms of adaptive CNA: [`texmap_md_io::orientation`]), as the properties
    /// [`ORIENTATION`] and [`LATTICE_RMSD`].
    pub orientations: bool,
    /// The grains of a polycrystal every frame, after the orientations (OVITO's Grain
    /// segmentation: [`texmap_md_io::grains`]), as the property [`GRAIN`], for colouring
    /// ([`crate::ColorBy::Grain`]) and selections (`prop grain == 0`: the largest);
    /// [`MolPlan::last_grains`] lists them.
    pub grains: Option<GrainOptions>,
    /// The radial distribution function every frame, after the periodic images (OVITO's
    /// Coordination analysis table: [`texmap_md_io::rdf`]); [`MolPlan::last_rdf`] holds it.
    pub rdf: Option<RdfOptions>,
    /// Each atom's squared displacement (Å²) from the first frame built, followed across the
    /// periodic boundaries ([`texmap_md_io::msd`]), as the property [`MSD`], before the
    /// alignment: the mean squared displacement a diffusion coefficient is read from.
    pub msd: bool,
    /// Per-atom properties frozen at the first frame built (OVITO's Freeze property), after
    /// [`MolOptions::computes`]: every later frame gets the values the first had, atom by atom,
    /// so that colours follow the atoms (a crystal coloured by where each atom started shows
    /// how it deformed or mixed: compute `x0 = x`, freeze `x0`, colour by it).
    pub freeze: Vec<String>,
    /// Draw every atom with the radius a per-atom property gives (Å; PQR's `radius`, any
    /// column of a dump), as a file's `radius` column is drawn; a value of zero or less, or
    /// not a number, leaves the atom its element's radius. A frame without the property is an
    /// error naming the properties it has.
    pub radius_from: Option<String>,
    /// Draw only the atoms on one side of a plane or inside a slab (OVITO's Slice modifier as
    /// the last step of a pipeline), placed after the alignment; `None` draws every atom.
    pub slice: Option<Slice>,
    /// Superpose every frame on a reference (the first frame built, or a structure), fitted
    /// on the atoms a selection picks (see the module docs); `None` leaves positions as read.
    pub align: Option<Alignment>,
    /// Several representations in one scene (see [`Representation`]); when not empty, they
    /// replace `select` and `draw`.
    pub reps: Vec<Representation>,
    /// The cutoffs of [`DrawStyle::HBonds`] and of `hbond_select` (MDAnalysis's 3.0 Å and 150°
    /// by default).
    pub hbonds: Criteria,
    /// The atoms among which [`MolPlan::prepare`] finds the hydrogen bonds of every frame
    /// ([`MolPlan::last_hbonds`]), for a program that writes frames instead of drawing them;
    /// [`MolPlan::build`] lists the bonds its [`DrawStyle::HBonds`] representations draw
    /// instead.
    pub hbond_select: Option<Selection>,
    /// The vectors, scale and radius of [`DrawStyle::Arrows`].
    pub arrows: ArrowOptions,
    /// Where the shapes of [`DrawStyle::Ellipsoids`] come from.
    pub ellipsoids: EllipsoidOptions,
    /// How many frames of path [`DrawStyle::Trails`] draws (the current one included); `None`:
    /// every frame drawn so far.
    pub trail_length: Option<usize>,
    /// Distances, angles and dihedrals drawn as dashes in every frame ([`crate::measure`]);
    /// their values are [`MolPlan::last_measurements`].
    pub measures: Vec<Measure>,
    /// Give every frame the per-atom property [`DISPLACEMENT`]: each atom's distance (Å) from
    /// where it was in the first frame built, to the nearest periodic image (OVITO's
    /// Displacements modifier with frame 0 as the reference), for colouring and selections.
    pub displacement: bool,
    /// Draw the bond orders the files give ([`Frame::bond_orders`]: SDF/MOL, MOL2) in the
    /// ball-and-stick and licorice styles, as PyMOL's valence mode (see the module docs).
    pub bond_orders: bool,
}

/// A cut through the frame, as OVITO's Slice modifier makes it: the plane `n̂·x = distance`
/// (`n̂` the unit normal, `x` in Å in the frame's coordinates). With `width` 0 the atoms with
/// `n̂·x <= distance` are kept (the side the normal points away from); with a `width` > 0 the
/// atoms of the slab `|n̂·x − distance| <= width / 2`. `invert` keeps the others instead.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slice {
    /// The plane's normal (any length but zero).
    pub normal: [f64; 3],
    /// The plane's distance from the origin along the unit normal, Å.
    pub distance: f64,
    /// The slab's width, Å; 0 for a half-space.
    pub width: f64,
    /// Keep the atoms the cut would drop, and drop the others.
    pub invert: bool,
}

impl Slice {
    /// Whether the atom at `p` is kept (see the type's docs).
    pub fn keeps(&self, p: [f32; 3]) -> bool {
        let [a, b, c] = self.normal;
        let len = (a * a + b * b + c * c).sqrt();
        let d = (a * p[0] as f64 + b * p[1] as f64 + c * p[2] as f64) / len - self.distance;
        let inside = if self.width > 0.0 {
            d.abs() <= self.width / 2.0
        } else {
            d <= 0.0
        };
        inside != self.invert
    }
}

/// What [`MolOptions::align`] fits every frame onto, and how.
#[derive(Clone, Debug)]
pub struct Alignment {
    /// The fitted atoms, picked once: in the first frame built, and in `reference`.
    pub select: Selection,
    /// The structure to fit onto (a crystal structure, an equilibrated frame), in its own
    /// coordinates; its picked atoms must be as many as the first frame's, with the same
    /// names where both have names. `None`: the first frame built.
    pub reference: Option<Frame>,
    /// Weight each atom by its element's mass (MDAnalysis's `weights="mass"`); else all
    /// atoms weigh the same (the default of MDAnalysis and VMD).
    pub mass_weighted: bool,
}

impl Alignment {
    /// An unweighted fit of `select` onto the first frame built.
    pub fn on_first_frame(select: Selection) -> Alignment {
        Alignment {
            select,
            reference: None,
            mass_weighted: false,
        }
    }
}

/// One representation, as VMD's: the atoms a selection picks (all when `None`), drawn in one
/// style. Each representation's atoms and bonds are drawn on their own, with that style's radii
/// and bond radius, so one scene can hold a protein's tube, a ligand's balls and sticks and
/// nearby waters as licorice; an atom two selections pick is drawn twice. A representation
/// is coloured by the [`SceneBuilder`]'s colouring unless it has one of its own
/// ([`RepColor`]); the plan's colour rules ([`MolOptions::colors`]) win over both.
#[derive(Clone, Debug)]
pub struct Representation {
    pub select: Option<Selection>,
    pub draw: DrawStyle,
    /// The representation's own colouring (VMD's per-representation colouring method);
    /// `None`: the builder's.
    pub color: Option<RepColor>,
}

/// A [`Representation`]'s own colouring.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RepColor {
    /// Another colouring method, with the builder's palette and per-name rules (see
    /// [`SceneBuilder::kinds_by`]); [`ColorBy::Scalar`] is the builder's number and colour map.
    By(ColorBy),
    /// One colour (sRGB in [0, 1]) for all its atoms (VMD's ColorID).
    Fixed([f32; 3]),
}

impl Default for MolOptions {
    fn default() -> MolOptions {
        MolOptions {
            topology: None,
            select: None,
            colors: Vec::new(),
            radii: Vec::new(),
            bonds: BondSource::Auto,
            draw: DrawStyle::Spacefill,
            pbc: Pbc::None,
            replicate: None,
            coordination: None,
            clusters: None,
            sasa: None,
            centrosymmetry: None,
            strain: None,
            computes: Vec::new(),
            wigner_seitz: None,
            voronoi: false,
            orientations: false,
            grains: None,
            rdf: None,
            msd: false,
            freeze: Vec::new(),
            radius_from: None,
            slice: None,
            align: None,
            reps: Vec::new(),
            hbonds: Criteria::default(),
            hbond_select: None,
            arrows: ArrowOptions::default(),
            ellipsoids: EllipsoidOptions::default(),
            trail_length: None,
            measures: Vec::new(),
            bond_orders: false,
            displacement: false,
        }
    }
}

/// [`MolOptions::rdf`]: the histogram's range and bins, and whether the partial functions of
/// each pair of atom kinds are computed too.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RdfOptions {
    /// The largest distance, Å.
    pub cutoff: f32,
    /// Bins from 0 to the cutoff.
    pub bins: usize,
    /// The partial g_ab of each pair of kinds (type labels, else elements) too.
    pub partial: bool,
}

/// [`MolOptions::clusters`]: the cutoff and the atoms clustered.
#[derive(Clone, Debug)]
pub struct ClusterOptions {
    /// Neighbour cutoff, Å.
    pub cutoff: f32,
    /// Only these atoms are clustered (the others are in cluster −1); `None`: every atom.
    pub atoms: Option<Selection>,
}

/// [`MolOptions::sasa`]: which atoms are measured, and the probe.
#[derive(Clone, Debug)]
pub struct SasaOptions {
    /// Only these atoms are measured and bury each other (a protein without its water); the
    /// others get NaN. `None`: every atom.
    pub atoms: Option<Selection>,
    /// The probe's radius, Å ([`texmap_md_io::sasa::PROBE`]: water).
    pub probe: f32,
}

/// What [`MolOptions::wigner_seitz`] draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WsOutput {
    /// The frame's atoms, each with the properties [`SITE_OCCUPANCY`] (the occupancy of the
    /// site it sits on: `prop site_occupancy > 1` keeps the interstitial atoms, both atoms of a
    /// dumbbell) and [`SITE`] (the site's index in the reference).
    Atoms,
    /// The reference's sites instead of the atoms (OVITO's default output), each with
    /// [`SITE_OCCUPANCY`] (the atoms on it: `prop site_occupancy == 0` keeps the vacancies) and
    /// [`SITE`]; the frame's own atoms, bonds and earlier per-atom properties are not drawn.
    Sites,
}

/// [`MolOptions::centrosymmetry`]: the neighbours per atom and which of their pairs count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CentroOptions {
    /// Nearest neighbours per atom: 12 for FCC (OVITO's default), 8 for BCC.
    pub neighbours: usize,
    /// The conventional N/2 smallest pairs, or the minimum-weight matching.
    pub mode: CspMode,
}

/// Which selection of a [`MolPlan`] failed to evaluate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SelectionRole {
    /// [`MolOptions::select`].
    Select,
    /// A colour rule's selection.
    Color,
    /// A radius rule's selection.
    Radius,
    /// [`MolOptions::align`].
    Align,
    /// [`ClusterOptions::atoms`].
    Cluster,
    /// [`SasaOptions::atoms`].
    Sasa,
    /// [`MolOptions::hbond_select`].
    HBonds,
}

/// Why a [`MolPlan`] was refused or a frame could not be built.
#[derive(Clone, Debug, PartialEq)]
pub enum MolError {
    /// Bonds from the topology are drawn, but there is no topology.
    NoTopology,
    /// Bonds from the topology are drawn, but the topology (named) has none.
    TopologyWithoutBonds {
        /// The topology's name.
        topology: String,
    },
    /// A radius rule's radius is not a finite number > 0 (index of the rule, radius).
    BadRadius {
        /// Index in [`MolOptions::radii`].
        rule: usize,
        /// The refused radius.
        radius: f32,
    },
    /// The alignment selection picks another number of atoms in the reference structure than
    /// in the first frame, or the `index`-th picked atoms differ by name.
    AlignMismatch {
        /// Atoms picked in the first frame.
        frame: usize,
        /// Atoms picked in the reference.
        reference: usize,
        /// The first pair of picked atoms with different names: (position among the picked,
        /// the frame's name, the reference's name).
        names: Option<(usize, String, String)>,
    },
    /// The alignment selection picks fewer than three atoms at the first frame (a fit needs
    /// three), or a frame's picked atoms have non-finite coordinates, or no mass.
    Align {
        /// Atoms picked at the first frame.
        atoms: usize,
        /// Why.
        why: &'static str,
    },
    /// [`MolOptions::replicate`] cannot copy the frame (no cell, too many atoms).
    Replicate(ReplicateError),
    /// [`MolOptions::coordination`] cannot be counted (the cell is too small for the cutoff).
    Coordination(CoordinationError),
    /// [`MolOptions::clusters`] cannot be found (the cell is too small for the cutoff).
    Clusters(CoordinationError),
    /// [`MolOptions::sasa`] cannot be computed (the probe, the cell too small, bad atoms).
    Sasa(texmap_md_io::sasa::SasaError),
    /// [`MolOptions::centrosymmetry`] has a bad neighbour count.
    Centrosymmetry(CentroError),
    /// [`MolOptions::strain`] cannot be computed (a frame of other atoms than the reference,
    /// the cutoff, a cell too small for it).
    Strain(StrainError),
    /// [`MolOptions::voronoi`] on a frame without a periodic cell, or with bad atoms.
    Voronoi(VoronoiError),
    /// [`MolOptions::wigner_seitz`] has no sites (an empty reference).
    WignerSeitz(WignerSeitzError),
    /// [`MolOptions::rdf`] cannot be computed (no cell, the cutoff, the bins).
    Rdf(texmap_md_io::rdf::RdfError),
    /// [`MolOptions::msd`] cannot follow a frame (other atoms than the first's).
    Msd(texmap_md_io::msd::MsdError),
    /// A formula of [`MolOptions::computes`] names what a frame does not have.
    Compute {
        /// The property it computes.
        name: String,
        /// Why.
        error: ExprError,
    },
    /// [`MolOptions::freeze`] names a property the first frame does not have.
    NoFreezeProperty {
        name: String,
        /// The frame's per-atom properties.
        available: Vec<String>,
    },
    /// A frame holds another number of atoms than the first, whose values are frozen.
    FreezeAtoms {
        name: String,
        /// Atoms of the first frame.
        first: usize,
        /// Atoms of this frame.
        frame: usize,
    },
    /// [`MolOptions::radius_from`] names a property a frame does not have.
    NoRadiusProperty {
        name: String,
        /// The frame's per-atom properties.
        available: Vec<String>,
    },
    /// [`MolOptions::slice`] has a zero or non-finite normal, a non-finite distance or a
    /// negative or non-finite width.
    BadSlice,
    /// [`MolOptions::hbonds`] is out of range, or the cell is too small for its cutoff.
    HBonds(HBondError),
    /// The arrows' options are bad, or a frame lacks their vectors.
    Arrows(ArrowError),
    /// The ellipsoids' shape option is bad, or a frame's shapes or orientations are.
    Ellipsoids(EllipsoidError),
    /// A measurement's atoms are not one per selection in a frame, or make no angle.
    Measure(MeasureError),
    /// An atom the trails follow (picked at the first frame) is past a later frame's atoms.
    TrailAtoms {
        /// The atom's index.
        atom: usize,
        /// The frame's atom count.
        frame: usize,
    },
    /// A selection could not be evaluated on a frame.
    Selection {
        /// Which selection.
        role: SelectionRole,
        /// Why.
        error: SelectionError,
    },
}

impl fmt::Display for MolError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MolError::NoTopology => write!(f, "bonds from the topology need a topology"),
            MolError::Replicate(e) => write!(f, "periodic images: {e}"),
            MolError::Coordination(e) => write!(f, "coordination: {e}"),
            MolError::Clusters(e) => write!(f, "clusters: {e}"),
            MolError::Sasa(e) => write!(f, "solvent-accessible surface: {e}"),
            MolError::Centrosymmetry(e) => write!(f, "centrosymmetry: {e}"),
            MolError::Strain(e) => write!(f, "atomic strain: {e}"),
            MolError::WignerSeitz(e) => write!(f, "Wigner-Seitz analysis: {e}"),
            MolError::Voronoi(e) => write!(f, "Voronoi analysis: {e}"),
            MolError::Rdf(e) => write!(f, "radial distribution function: {e}"),
            MolError::Msd(e) => write!(f, "mean squared displacement: {e}"),
            MolError::NoFreezeProperty { name, available } => write!(
                f,
                "freezing '{name}': the first frame has no such per-atom property ({})",
                if available.is_empty() {
                    "it has none".to_string()
                } else {
                    format!("it has {}", available.join(", "))
                }
            ),
            MolError::FreezeAtoms { name, first, frame } => write!(
                f,
                "freezing '{name}': the first frame has {first} atoms and this one {frame}"
            ),
            MolError::Compute { name, error } => write!(f, "computing '{name}': {error}"),
            MolError::NoRadiusProperty { name, available } => write!(
                f,
                "radii from '{name}': the frame has no such per-atom property ({})",
                if available.is_empty() {
                    "it has none".to_string()
                } else {
                    format!("it has {}", available.join(", "))
                }
            ),
            MolError::HBonds(e) => write!(f, "hydrogen bonds: {e}"),
            MolError::Arrows(e) => write!(f, "arrows: {e}"),
            MolError::Ellipsoids(e) => write!(f, "ellipsoids: {e}"),
            MolError::Measure(e) => write!(f, "measure: {e}"),
            MolError::TrailAtoms { atom, frame } => write!(
                f,
                "trails follow the atoms picked at the first frame, and atom {atom} is past this frame's {frame} atoms"
            ),
            MolError::BadSlice => write!(
                f,
                "slice: the normal must be finite and not zero, the distance finite, the width finite and >= 0"
            ),
            MolError::TopologyWithoutBonds { topology } => {
                write!(f, "bonds from the topology: {topology} has no bonds")
            }
            MolError::BadRadius { rule, radius } => {
                write!(f, "radius rule {rule}: {radius} is not a radius > 0 in Å")
            }
            MolError::Align { atoms, why } => {
                write!(
                    f,
                    "alignment: the selection picks {atoms} atom(s) of the first frame: {why}"
                )
            }
            MolError::AlignMismatch {
                frame,
                reference,
                names,
            } => match names {
                Some((k, a, b)) => write!(
                    f,
                    "alignment: picked atom {k} is {a} in the frame but {b} in the reference"
                ),
                None => write!(
                    f,
                    "alignment: the selection picks {frame} atom(s) of the first frame but \
                     {reference} of the reference"
                ),
            },
            MolError::Selection { role, error } => {
                let what = match role {
                    SelectionRole::Align => "the alignment selection",
                    SelectionRole::Cluster => "the selection of clustered atoms",
                    SelectionRole::Sasa => "the selection of atoms measured for their surface",
                    SelectionRole::HBonds => "the selection of atoms searched for hydrogen bonds",
                    SelectionRole::Select => "the selection of drawn atoms",
                    SelectionRole::Color => "a colour rule's selection",
                    SelectionRole::Radius => "a radius rule's selection",
                };
                write!(f, "{what}: {error}")
            }
        }
    }
}

impl std::error::Error for MolError {}

/// What every frame is fitted onto, fixed at the first frame: the picked atoms (indices in the
/// frames), the positions they are fitted onto (the first frame's or the reference
/// structure's) and the weights of a mass-weighted fit.
#[derive(Clone, Debug)]
struct AlignTarget {
    atoms: Vec<usize>,
    positions: Vec<[f64; 3]>,
    weights: Option<Vec<f64>>,
}

/// A frame's way from reading to drawing (see the module docs for the order of the steps).
#[derive(Clone, Debug)]
pub struct MolPlan {
    options: MolOptions,
    /// Scratch: selected atoms' new indices (`u32::MAX` for dropped atoms), bond pairs.
    map: Vec<u32>,
    pairs: Vec<[u32; 2]>,
    last_bond_count: usize,
    /// The alignment's atoms (in the frames), the positions fitted onto (the first frame's or
    /// the reference structure's) and the weights of a mass-weighted fit.
    align_reference: Option<AlignTarget>,
    last_fit_rmsd: Option<f64>,
    /// This frame's atoms inside [`MolOptions::slice`] (drawn); `None` without a slice.
    slice_keep: Option<Vec<bool>>,
    /// Scratch: per atom, the material the colour rules give it (`u16::MAX`: none).
    rule_kinds: Vec<u16>,
    /// The representations: `options.reps`, or the one of `options.select` and `options.draw`.
    reps: Vec<Representation>,
    /// The last frame's atoms drawn as a surface ([`DrawStyle::Surface`]).
    surface: SurfaceAtoms,
    /// The last frame's cartoon ([`DrawStyle::Cartoon`]).
    cartoon: MolMesh,
    /// This frame's donor–hydrogen pairs ([`DrawStyle::HBonds`]), and the hydrogen bonds the
    /// last frame drew.
    donor_h: Vec<[u32; 2]>,
    hbonds: Vec<HBond>,
    /// This frame's bonds before those across the box are dropped (the ligands of
    /// [`DrawStyle::Polyhedra`]), and the last frame's polyhedra.
    ligand_pairs: Vec<[u32; 2]>,
    polyhedra: MolMesh,
    /// Whether this frame's bonds are the files' (else found by distance, or none).
    pairs_listed: bool,
    /// The first frame's positions (for displacements: [`DrawStyle::Arrows`],
    /// [`MolOptions::displacement`]), this frame's arrow vectors and the last frame's arrows.
    arrow_reference: Option<Vec<[f32; 3]>>,
    /// The reference configuration of [`MolOptions::strain`] and
    /// [`MolOptions::wigner_seitz`], as it was before the alignment.
    configuration: Option<Frame>,
    /// The last frame's vacancies and interstitials ([`MolOptions::wigner_seitz`]).
    last_defects: Option<(usize, usize)>,
    /// The last frame's grains ([`MolOptions::grains`]).
    last_grains: Option<Vec<Grain>>,
    last_rdf: Option<texmap_md_io::rdf::Rdf>,
    last_clusters: Option<texmap_md_io::coordination::Clusters>,
    msd: texmap_md_io::msd::Tracker,
    /// The values of [`MolOptions::freeze`]'s properties at the first frame built.
    frozen: Vec<Vec<f32>>,
    arrow_vectors: Vec<glam::Vec3>,
    arrows: MolMesh,
    arrow_atoms: Vec<glam::Vec3>,
    /// This frame's shapes and orientations, one per atom, and the last frame's ellipsoids
    /// ([`DrawStyle::Ellipsoids`]).
    ellipsoid_shapes: Vec<(glam::Vec3, glam::Quat)>,
    ellipsoids: Vec<Ellipsoid>,
    /// [`DrawStyle::Trails`]: the atoms followed (picked at the first frame), each one's path
    /// (unwrapped, the last `trail_length` points) and its last position as read.
    trail_atoms: Option<Vec<u32>>,
    trail_paths: Vec<std::collections::VecDeque<glam::Vec3>>,
    trail_last: Vec<[f32; 3]>,
    /// The last frame's measurements, one per [`MolOptions::measures`].
    measured: Vec<Measured>,
}

impl MolPlan {
    /// The plan for `options`; refused when topology bonds are drawn without a topology that
    /// has bonds, or a radius rule's radius is not finite and > 0.
    pub fn new(options: MolOptions) -> Result<MolPlan, MolError> {
        for (rule, (_, radius)) in options.radii.iter().enumerate() {
            if !(radius.is_finite() && *radius > 0.0) {
                return Err(MolError::BadRadius {
                    rule,
                    radius: *radius,
                });
            }
        }
        let reps = if options.reps.is_empty() {
            vec![Representation {
                select: options.select.clone(),
                draw: options.draw,
                color: None,
            }]
        } else {
            options.reps.clone()
        };
        if let Some(s) = &options.slice {
            let n2: f64 = s.normal.iter().map(|x| x * x).sum();
            let finite = n2.is_finite() && s.distance.is_finite() && s.width.is_finite();
            if !(finite && n2 > 0.0 && s.width >= 0.0) {
                return Err(MolError::BadSlice);
            }
        }
        options.hbonds.check().map_err(MolError::HBonds)?;
        if reps.iter().any(|r| r.draw == DrawStyle::Arrows) {
            options.arrows.check().map_err(MolError::Arrows)?;
        }
        if reps.iter().any(|r| r.draw == DrawStyle::Ellipsoids) {
            options.ellipsoids.check().map_err(MolError::Ellipsoids)?;
        }
        let sticks = reps.iter().any(|r| r.draw != DrawStyle::Spacefill);
        if options.bonds == BondSource::Topology && sticks {
            match &options.topology {
                // The frames may list bonds (SDF, MOL2): checked at the first frame.
                None => {}
                Some(t) if t.bonds.is_empty() => {
                    return Err(MolError::TopologyWithoutBonds {
                        topology: t.name().to_string(),
                    });
                }
                Some(_) => {}
            }
        }
        Ok(MolPlan {
            options,
            map: Vec::new(),
            pairs: Vec::new(),
            last_bond_count: 0,
            align_reference: None,
            last_fit_rmsd: None,
            slice_keep: None,
            rule_kinds: Vec::new(),
            reps,
            surface: SurfaceAtoms::default(),
            cartoon: MolMesh::default(),
            donor_h: Vec::new(),
            ligand_pairs: Vec::new(),
            polyhedra: MolMesh::default(),
            pairs_listed: false,
            arrow_reference: None,
            configuration: None,
            last_defects: None,
            last_grains: None,
            last_rdf: None,
            last_clusters: None,
            msd: texmap_md_io::msd::Tracker::new(),
            frozen: Vec::new(),
            arrow_vectors: Vec::new(),
            arrows: MolMesh::default(),
            arrow_atoms: Vec::new(),
            ellipsoid_shapes: Vec::new(),
            ellipsoids: Vec::new(),
            trail_atoms: None,
            trail_paths: Vec::new(),
            trail_last: Vec::new(),
            measured: Vec::new(),
            hbonds: Vec::new(),
        })
    }

    /// The topology, if any.
    pub fn topology(&self) -> Option<&Topology> {
        self.options.topology.as_ref()
    }

    /// The RMSD (Å) of the last frame's alignment atoms after the fit onto the first frame's;
    /// `None` without [`MolOptions::align`].
    pub fn last_fit_rmsd(&self) -> Option<f64> {
        self.last_fit_rmsd
    }

    /// Step 3 of the module docs: `frame` superposed on the first frame built (which sets the reference: its
    /// alignment atoms, picked once, and their positions).
    fn align(&mut self, frame: &mut Frame) -> Result<(), MolError> {
        let Some(alignment) = &self.options.align else {
            return Ok(());
        };
        let pos = |frame: &Frame, atoms: &[usize]| -> Vec<[f64; 3]> {
            atoms
                .iter()
                .map(|&i| {
                    frame
                        .positions
                        .get(i)
                        .copied()
                        .unwrap_or([f32::NAN; 3])
                        .map(f64::from)
                })
                .collect()
        };
        let picked = |frame: &Frame| {
            alignment
                .select
                .indices(frame)
                .map_err(|error| MolError::Selection {
                    role: SelectionRole::Align,
                    error,
                })
        };
        let AlignTarget {
            atoms,
            positions: reference,
            weights,
        } =
            match &self.align_reference {
                Some(r) => r,
                None => {
                    let atoms = picked(frame)?;
                    if atoms.len() < 3 {
                        return Err(MolError::Align {
                            atoms: atoms.len(),
                            why: "a fit needs at least three",
                        });
                    }
                    let (target, target_atoms) = match &alignment.reference {
                        Some(r) => (r, picked(r)?),
                        None => (&*frame, atoms.clone()),
                    };
                    if target_atoms.len() != atoms.len() {
                        return Err(MolError::AlignMismatch {
                            frame: atoms.len(),
                            reference: target_atoms.len(),
                            names: None,
                        });
                    }
                    let name = |f: &Frame, i: usize| f.names.get(i).map(|n| n.as_str().to_string());
                    let differ = atoms.iter().zip(&target_atoms).enumerate().find_map(
                        |(k, (&i, &j))| match (name(frame, i), name(target, j)) {
                            (Some(a), Some(b)) if a != b => Some((k, a, b)),
                            _ => None,
                        },
                    );
                    if let Some(names) = differ {
                        return Err(MolError::AlignMismatch {
                            frame: atoms.len(),
                            reference: target_atoms.len(),
                            names: Some(names),
                        });
                    }
                    let weights = alignment.mass_weighted.then(|| {
                        target_atoms
                            .iter()
                            .map(|&j| texmap_md_io::atom_mass(target, j))
                            .collect::<Vec<f64>>()
                    });
                    if weights
                        .as_ref()
                        .is_some_and(|w| w.iter().all(|m| *m == 0.0))
                    {
                        return Err(MolError::Align {
                            atoms: atoms.len(),
                            why: "none has an element, so none has a mass",
                        });
                    }
                    let reference = pos(target, &target_atoms);
                    self.align_reference.insert(AlignTarget {
                        atoms,
                        positions: reference,
                        weights,
                    })
                }
            };
        let mobile = pos(frame, atoms);
        let fit = crate::align::superpose_weighted(&mobile, reference, weights.as_deref()).ok_or(
            MolError::Align {
                atoms: atoms.len(),
                why: "some have no finite coordinates in this frame",
            },
        )?;
        self.last_fit_rmsd = Some(fit.rmsd);
        for p in &mut frame.positions {
            *p = fit.apply(p.map(f64::from)).map(|v| v as f32);
        }
        for v in &mut frame.velocities {
            *v = fit.rotate(v.map(f64::from)).map(|v| v as f32);
        }
        rotate_orientations(frame, &fit);
        if let Some(cell) = &frame.cell {
            let m = cell.matrix().map(|row| fit.rotate(row));
            frame.cell = texmap_md_io::UnitCell::from_matrix(m).ok().map(|c| {
                c.with_origin(fit.apply(cell.origin()))
                    .with_periodic(cell.periodic())
            });
        }
        Ok(())
    }

    /// Whether the scene's bonds (cylinders) are drawn at all: some style draws sticks and
    /// bonds are asked for, or some representation draws hydrogen bonds or trails (whose
    /// dashes and paths are cylinders whatever the bond source).
    pub fn draws_bonds(&self) -> bool {
        let sticks = self.reps.iter().any(|r| {
            !matches!(
                r.draw,
                DrawStyle::Spacefill
                    | DrawStyle::Surface
                    | DrawStyle::HBonds
                    | DrawStyle::Polyhedra
                    | DrawStyle::Arrows
                    | DrawStyle::Ellipsoids
            )
        });
        (sticks && self.options.bonds != BondSource::None)
            || self.draws_hbonds()
            || self.draws_trails()
            || !self.options.measures.is_empty()
    }

    /// The bonds of the last frame built, after the periodic treatment and before the
    /// selection.
    pub fn last_bond_count(&self) -> usize {
        self.last_bond_count
    }

    /// Gives `frame` (number `index` of the trajectory named `trajectory`) the topology's
    /// labels; nothing without a topology.
    pub fn label(
        &self,
        frame: &mut Frame,
        trajectory: &str,
        index: usize,
    ) -> Result<(), texmap_md_io::Error> {
        match &self.options.topology {
            Some(t) => t.apply(frame, trajectory, index),
            None => Ok(()),
        }
    }

    /// The bonds of `frame` as [`MolOptions::bonds`] asks (before periodic handling). Bonds
    /// from the files drawn with neither a topology nor bonds in the frame are an error.
    fn find_bonds(&mut self, frame: &Frame, need: bool) -> Result<(), MolError> {
        self.pairs.clear();
        self.pairs_listed = false;
        if !need {
            return Ok(());
        }
        if self.options.bonds == BondSource::None {
            return Ok(());
        }
        // The listed bonds: the topology's and the frame's own (SDF, MOL2, appended parts).
        if let Some(t) = &self.options.topology {
            self.pairs.extend_from_slice(&t.bonds);
        }
        if !frame.bonds.is_empty() {
            self.pairs.extend_from_slice(&frame.bonds);
            self.pairs.sort_unstable();
            self.pairs.dedup();
        }
        self.pairs_listed = !self.pairs.is_empty();
        if self.pairs.is_empty() {
            match self.options.bonds {
                BondSource::Auto => {
                    self.pairs = texmap_md_io::bonds::bonds_by_distance(frame, true).pairs;
                }
                _ if self.draws_bonds() && self.options.topology.is_none() => {
                    return Err(MolError::NoTopology);
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// For a scene of several files, before one file's frame (`part`) is appended to the
    /// others ([`Frame::append`]): gives it the bonds [`BondSource::Auto`] finds for it alone,
    /// by distance, when it lists none itself (nor, for the `first` part, the topology), so
    /// that each part keeps its bonds once the parts' listed bonds are merged. Nothing for
    /// other bond sources, or when no bonds are needed.
    pub fn part_bonds(&self, part: &mut Frame, first: bool) {
        let topology_lists = first
            && self
                .options
                .topology
                .as_ref()
                .is_some_and(|t| !t.bonds.is_empty());
        let needed = self.draws_bonds() || self.options.pbc == Pbc::Unwrap;
        if self.options.bonds == BondSource::Auto
            && needed
            && part.bonds.is_empty()
            && !topology_lists
        {
            part.bonds = texmap_md_io::bonds::bonds_by_distance(part, true).pairs;
        }
    }

    /// Measure displacements (the [`DISPLACEMENT`] property, displacement arrows) from `frame`
    /// instead of from the first frame built: OVITO's reference configuration. Call it before
    /// the first [`build`](Self::build). The frame takes the steps that move atoms before a
    /// build measures them: the periodic treatment ([`MolOptions::pbc`]; unwrapping by bonds
    /// found by distance), the periodic images and the alignment, which then superposes every
    /// frame built on this one (unless it fits onto its own reference structure).
    ///
    /// Errors: those of the images and the alignment; a frame whose atom count differs from a
    /// built frame's is an error of that build.
    pub fn set_displacement_reference(&mut self, frame: &mut Frame) -> Result<(), MolError> {
        let mut pairs = Vec::new();
        match self.options.pbc {
            Pbc::None => {}
            Pbc::Wrap => texmap_md_io::pbc::wrap(frame),
            Pbc::Unwrap => {
                if frame.cell.is_some() {
                    pairs = texmap_md_io::bonds::bonds_by_distance(frame, true).pairs;
                    texmap_md_io::pbc::unwrap(frame, &pairs);
                }
            }
        }
        if let Some(n) = self.options.replicate {
            texmap_md_io::replicate::replicate(frame, &mut pairs, n)
                .map_err(MolError::Replicate)?;
        }
        if self.options.strain.is_some() || self.options.wigner_seitz.is_some() {
            self.configuration = Some(frame.clone());
        }
        self.align(frame)?;
        self.arrow_reference = Some(frame.positions.clone());
        Ok(())
    }

    /// `frame` as the plan sees it, before anything is drawn: periodic boundaries applied,
    /// replicated, every analysis's per-atom properties set (coordination, clusters,
    /// centrosymmetry, strain, Wigner-Seitz, Voronoi, orientations, grains, computed and frozen
    /// properties, displacements), radii taken from a property, aligned. [`MolPlan::build`]
    /// calls it; a program that writes the frames instead of drawing them calls it alone.
    pub fn prepare(&mut self, frame: &mut Frame) -> Result<(), MolError> {
        let unwrap = self.options.pbc == Pbc::Unwrap && frame.cell.is_some();
        self.find_bonds(
            frame,
            self.draws_bonds()
                || unwrap
                || self.draws_polyhedra()
                || self.options.hbond_select.is_some(),
        )?;
        match self.options.pbc {
            Pbc::None => {}
            Pbc::Wrap => texmap_md_io::pbc::wrap(frame),
            Pbc::Unwrap => {
                if unwrap && self.options.bonds == BondSource::None {
                    // Molecules need bonds to be made whole even when none are drawn.
                    self.pairs = texmap_md_io::bonds::bonds_by_distance(frame, true).pairs;
                }
                texmap_md_io::pbc::unwrap(frame, &self.pairs);
            }
        }
        if let Some(n) = self.options.replicate {
            texmap_md_io::replicate::replicate(frame, &mut self.pairs, n)
                .map_err(MolError::Replicate)?;
        }
        if let Some(cutoff) = self.options.coordination {
            let counts = texmap_md_io::coordination::coordination(frame, cutoff)
                .map_err(MolError::Coordination)?;
            let values = counts.into_iter().map(|c| c as f32).collect();
            set_property(frame, COORDINATION, values);
        }
        self.last_clusters = None;
        if let Some(c) = &self.options.clusters {
            let mask = match &c.atoms {
                Some(sel) => Some(sel.evaluate(frame).map_err(|error| MolError::Selection {
                    role: SelectionRole::Cluster,
                    error,
                })?),
                None => None,
            };
            let mut found = texmap_md_io::coordination::clusters(frame, c.cutoff, mask.as_deref())
                .map_err(MolError::Clusters)?;
            let values = found.ids.iter().map(|&c| c as f32).collect();
            set_property(frame, CLUSTER, values);
            found.ids = Vec::new();
            self.last_clusters = Some(found);
        }
        if let Some(s) = &self.options.sasa {
            let mask = match &s.atoms {
                Some(sel) => Some(sel.evaluate(frame).map_err(|error| MolError::Selection {
                    role: SelectionRole::Sasa,
                    error,
                })?),
                None => None,
            };
            let values = texmap_md_io::sasa::sasa(frame, mask.as_deref(), s.probe)
                .map_err(MolError::Sasa)?;
            set_property(frame, SASA, values);
        }
        if let Some(c) = self.options.centrosymmetry {
            let values = texmap_md_io::centrosymmetry::centrosymmetry(frame, c.neighbours, c.mode)
                .map_err(MolError::Centrosymmetry)?;
            set_property(frame, CENTROSYMMETRY, values);
        }
        if (self.options.strain.is_some() || self.options.wigner_seitz.is_some())
            && self.configuration.is_none()
        {
            self.configuration = Some(frame.clone());
        }
        if let Some(cutoff) = self.options.strain {
            let reference = self.configuration.as_ref().expect("set above");
            let s = texmap_md_io::strain::atomic_strain(reference, frame, cutoff)
                .map_err(MolError::Strain)?;
            set_property(frame, SHEAR_STRAIN, s.shear);
            set_property(frame, VOLUMETRIC_STRAIN, s.volumetric);
            set_property(frame, D2MIN, s.d2min);
        }
        self.last_defects = None;
        if let Some(output) = self.options.wigner_seitz {
            let reference = self.configuration.as_ref().expect("set above");
            let ws = texmap_md_io::wigner_seitz::wigner_seitz(reference, frame)
                .map_err(MolError::WignerSeitz)?;
            self.last_defects = Some((ws.vacancies, ws.interstitials));
            let occupancy: Vec<f32> = ws.occupancy.iter().map(|&o| o as f32).collect();
            match output {
                WsOutput::Atoms => {
                    let on_site = |s: &Option<u32>| s.map_or(f32::NAN, |s| occupancy[s as usize]);
                    set_property(frame, SITE_OCCUPANCY, ws.site.iter().map(on_site).collect());
                    let index = |s: &Option<u32>| s.map_or(f32::NAN, |s| s as f32);
                    set_property(frame, SITE, ws.site.iter().map(index).collect());
                }
                WsOutput::Sites => {
                    // The sites take the atoms' place: the reference's atoms at their
                    // positions, with this frame's time; bonds between the atoms go.
                    let mut sites = reference.clone();
                    sites.time = frame.time;
                    sites.step = frame.step;
                    sites.comment = std::mem::take(&mut frame.comment);
                    set_property(&mut sites, SITE_OCCUPANCY, occupancy);
                    let index = (0..sites.n_atoms()).map(|i| i as f32).collect();
                    set_property(&mut sites, SITE, index);
                    *frame = sites;
                    self.pairs.clear();
                }
            }
        }
        self.last_rdf = None;
        if let Some(o) = self.options.rdf {
            let g = texmap_md_io::rdf::rdf(frame, o.cutoff, o.bins, o.partial)
                .map_err(MolError::Rdf)?;
            self.last_rdf = Some(g);
        }
        if self.options.voronoi {
            let v = texmap_md_io::voronoi::voronoi(frame).map_err(MolError::Voronoi)?;
            set_property(frame, VORONOI_VOLUME, v.volume);
            set_property(
                frame,
                VORONOI_FACES,
                v.faces.iter().map(|&f| f as f32).collect(),
            );
            for (k, name) in VORONOI_INDEX.iter().enumerate() {
                set_property(frame, name, v.index.iter().map(|i| i[k] as f32).collect());
            }
        }
        self.last_grains = None;
        if self.options.orientations || self.options.grains.is_some() {
            let types = texmap_md_io::cna::classify(frame);
            let fits = texmap_md_io::orientation::orientations(frame, &types);
            if self.options.orientations {
                for (k, name) in ORIENTATION.iter().enumerate() {
                    let values = fits
                        .iter()
                        .map(|f| f.map_or(f32::NAN, |f| f.orientation[k] as f32));
                    set_property(frame, name, values.collect());
                }
                let values = fits.iter().map(|f| f.map_or(f32::NAN, |f| f.rmsd as f32));
                set_property(frame, LATTICE_RMSD, values.collect());
            }
            if let Some(options) = &self.options.grains {
                let found = texmap_md_io::grains::segment(frame, &types, &fits, options);
                set_property(
                    frame,
                    GRAIN,
                    found.grain.iter().map(|&g| g as f32).collect(),
                );
                self.last_grains = Some(found.grains);
            }
        }
        if self.options.msd {
            let d2 = self.msd.add(frame).map_err(MolError::Msd)?;
            set_property(frame, MSD, d2.into_iter().map(|v| v as f32).collect());
        }
        for (name, formula) in &self.options.computes {
            let values = formula.evaluate(frame).map_err(|error| MolError::Compute {
                name: name.clone(),
                error,
            })?;
            set_property(frame, name, values);
        }
        for (k, name) in self.options.freeze.iter().enumerate() {
            if self.frozen.len() <= k {
                let Some(values) = frame.property(name) else {
                    return Err(MolError::NoFreezeProperty {
                        name: name.clone(),
                        available: frame.properties.iter().map(|p| p.name.clone()).collect(),
                    });
                };
                self.frozen.push(values.to_vec());
            }
            let values = &self.frozen[k];
            if values.len() != frame.n_atoms() {
                return Err(MolError::FreezeAtoms {
                    name: name.clone(),
                    first: values.len(),
                    frame: frame.n_atoms(),
                });
            }
            set_property(frame, name, values.clone());
        }
        if let Some(name) = &self.options.radius_from {
            let Some(values) = frame.property(name) else {
                return Err(MolError::NoRadiusProperty {
                    name: name.clone(),
                    available: frame.properties.iter().map(|p| p.name.clone()).collect(),
                });
            };
            // A radius of zero or less (PQR's hydrogens in some force fields) or not a number
            // is no radius: the atom takes its element's.
            frame.radii = values
                .iter()
                .map(|&r| {
                    if r.is_finite() && r > 0.0 {
                        r
                    } else {
                        f32::NAN
                    }
                })
                .collect();
        }
        self.donor_h.clear();
        if self.draws_hbonds() || self.options.hbond_select.is_some() {
            // Before bonds across the box are dropped: a water split by a face still donates.
            self.donor_h = if self.options.bonds == BondSource::None {
                let by_distance = texmap_md_io::bonds::bonds_by_distance(frame, true).pairs;
                hbonds::donor_hydrogens(frame, &by_distance)
            } else {
                hbonds::donor_hydrogens(frame, &self.pairs)
            };
        }
        self.ligand_pairs.clear();
        if self.draws_polyhedra() {
            // Before bonds across the box are dropped: a centre by a face keeps its ligands.
            // Bonds between atoms of one element are no ligands (rutile's Ti-Ti at 2.96 Å is
            // a bond by distance, not a corner of the TiO6 octahedron).
            // Bonds by distance are found again in the frame as it now is: a bond list made
            // before `replicate` holds one bond per pair of atoms of the unit cell, which loses
            // the second image of a ligand bonded through both faces of a short cell.
            let by_distance;
            let pairs = if self.pairs_listed {
                &self.pairs
            } else {
                let found = texmap_md_io::bonds::bonds_by_distance(frame, true);
                by_distance = match &frame.cell {
                    // A unit cell too narrow for the periodic grid: every pair, nearest images.
                    Some(cell) if !found.periodic => {
                        crate::polyhedra::pairs_in_narrow_cell(frame, cell)
                    }
                    _ => found.pairs,
                };
                &by_distance
            };
            let element = |i: u32| atom_element(frame, i as usize);
            self.ligand_pairs.extend(
                pairs
                    .iter()
                    .filter(|[i, j]| element(*i).is_unknown() || element(*i) != element(*j)),
            );
        }
        texmap_md_io::pbc::drop_crossing(&mut self.pairs, &frame.positions, frame.cell.as_ref());
        self.last_bond_count = self.pairs.len();
        self.align(frame)?;
        self.slice_keep = self
            .options
            .slice
            .map(|s| frame.positions.iter().map(|p| s.keeps(*p)).collect());
        if self.draws_trails() {
            self.extend_trails(frame)?;
        }
        let displaced =
            self.draws_arrows() && self.options.arrows.source == ArrowSource::Displacement;
        if (displaced || self.options.displacement) && self.arrow_reference.is_none() {
            self.arrow_reference = Some(frame.positions.clone());
        }
        if self.options.displacement {
            let d = crate::arrows::vectors(
                frame,
                &ArrowSource::Displacement,
                self.arrow_reference.as_deref(),
            )
            .map_err(MolError::Arrows)?;
            set_property(frame, DISPLACEMENT, d.iter().map(|v| v.length()).collect());
        }
        self.ellipsoid_shapes.clear();
        if self.draws_ellipsoids() {
            self.ellipsoid_shapes = crate::ellipsoids::shapes(frame, &self.options.ellipsoids)
                .map_err(MolError::Ellipsoids)?;
        }
        self.arrow_vectors.clear();
        if self.draws_arrows() {
            let source = &self.options.arrows.source;
            self.arrow_vectors =
                crate::arrows::vectors(frame, source, self.arrow_reference.as_deref())
                    .map_err(MolError::Arrows)?;
        }
        if let Some(sel) = &self.options.hbond_select {
            let mask = sel.evaluate(frame).map_err(|error| MolError::Selection {
                role: SelectionRole::HBonds,
                error,
            })?;
            self.hbonds =
                hbonds::hydrogen_bonds(frame, &self.donor_h, Some(&mask), self.options.hbonds)
                    .map_err(MolError::HBonds)?;
        }
        self.measured.clear();
        for m in &self.options.measures {
            self.measured
                .push(m.measure(frame).map_err(MolError::Measure)?);
        }
        Ok(())
    }

    /// Periodic boundaries applied to `frame` and its analyses computed
    /// ([`MolPlan::prepare`]), then `scene` built from it: selected atoms only, per-selection
    /// colours and radii, bonds between drawn atoms (never across the box).
    pub fn build(
        &mut self,
        builder: &mut SceneBuilder,
        frame: &mut Frame,
        scene: &mut SphereScene,
    ) -> Result<(), MolError> {
        self.prepare(frame)?;
        let failed = |role| move |error| MolError::Selection { role, error };
        // The frame's colour column, for a representation coloured by it when the builder
        // (which drops it otherwise) colours by something else.
        let file_colors = (builder.color_by() != ColorBy::Property
            && self.rep_colorings().any(|c| c == ColorBy::Property))
        .then(|| frame.colors.clone());
        // A scalar colouring's range, once: over the atoms drawn in that colouring.
        if builder.color_by() == ColorBy::Scalar && builder.scalar().range.is_none() {
            let mut mask: Option<Vec<bool>> = Some(vec![false; frame.n_atoms()]);
            let scalar = |rep: &Representation| match rep.color {
                None => true,
                Some(c) => c == RepColor::By(ColorBy::Scalar),
            };
            for rep in self.reps.iter().filter(|r| scalar(r)) {
                match &rep.select {
                    Some(sel) => {
                        let m = sel.evaluate(frame).map_err(failed(SelectionRole::Select))?;
                        if let Some(all) = &mut mask {
                            all.iter_mut().zip(m).for_each(|(a, b)| *a |= b);
                        }
                    }
                    None => mask = None,
                }
            }
            builder.fit_scalar_range(frame, mask.as_deref());
        }
        // Every atom, styled; then the per-selection rules, in order.
        builder.build(frame, scene);
        if let Some(colors) = file_colors {
            frame.colors = colors;
        }
        self.rule_kinds.clear();
        if !self.options.colors.is_empty() {
            self.rule_kinds.resize(frame.n_atoms(), u16::MAX);
            for (sel, rgb) in &self.options.colors {
                let mask = sel.evaluate(frame).map_err(failed(SelectionRole::Color))?;
                let kind = builder.kind_of(*rgb);
                for (k, m) in self.rule_kinds.iter_mut().zip(mask) {
                    if m {
                        *k = kind;
                    }
                }
            }
            overlay(&mut scene.kinds, &self.rule_kinds);
        }
        let scale = builder.radius_scale();
        for (sel, r) in &self.options.radii {
            let mask = sel.evaluate(frame).map_err(failed(SelectionRole::Radius))?;
            for (i, m) in mask.iter().enumerate() {
                if *m {
                    scene.radii[i] = r * scale;
                }
            }
        }
        // The representations are taken out for the call (draw_rep borrows the plan mutably)
        // and put back, whatever the outcome.
        let reps = std::mem::take(&mut self.reps);
        self.surface.clear();
        self.hbonds.clear();
        self.cartoon = MolMesh::default();
        self.polyhedra = MolMesh::default();
        self.arrows = MolMesh::default();
        self.arrow_atoms.clear();
        self.ellipsoids.clear();
        let drawn = self.draw_reps(builder, frame, &reps, scene);
        self.reps = reps;
        if drawn.is_ok() && !self.measured.is_empty() {
            self.draw_measures(builder, scene);
        }
        builder.refresh_materials(scene);
        drawn
    }

    /// The measurements' dashes ([`MolPlan::prepare`] measured them) appended to `scene`,
    /// each bond then with its radius listed.
    fn draw_measures(&self, builder: &mut SceneBuilder, scene: &mut SphereScene) {
        if scene.bond_radii.len() != scene.bonds.len() {
            scene.bond_radii = vec![scene.bond_radius; scene.bonds.len()];
        }
        let kind = builder.kind_of(MEASURE_COLOR);
        for got in &self.measured {
            for w in got.points.windows(2) {
                let before = scene.bonds.len();
                push_dash_line(scene, w[0], w[1], kind, MEASURE_RADIUS, MEASURE_DASHES);
                let added = scene.bonds.len() - before;
                scene
                    .bond_radii
                    .extend(std::iter::repeat_n(MEASURE_RADIUS, added));
            }
        }
    }

    /// The last frame's cartoon ([`DrawStyle::Cartoon`]; empty without one).
    pub fn cartoon_mesh(&self) -> &MolMesh {
        &self.cartoon
    }

    /// Finds the hydrogen bonds among `select`'s atoms in every frame prepared
    /// ([`MolOptions::hbond_select`]).
    pub fn set_hbond_select(&mut self, select: Option<Selection>) {
        self.options.hbond_select = select;
    }

    /// Whether some representation draws hydrogen bonds ([`DrawStyle::HBonds`]).
    pub fn draws_hbonds(&self) -> bool {
        self.reps.iter().any(|r| r.draw == DrawStyle::HBonds)
    }

    /// The hydrogen bonds the last frame built draws ([`DrawStyle::HBonds`]), per
    /// representation in order, each sorted by donor, hydrogen, acceptor (atom indices of the
    /// frame, after periodic images).
    pub fn last_hbonds(&self) -> &[HBond] {
        &self.hbonds
    }

    /// The last frame's vacancies and interstitials ([`MolOptions::wigner_seitz`]; `None`
    /// without it).
    pub fn last_defects(&self) -> Option<(usize, usize)> {
        self.last_defects
    }

    /// Whether every frame's grains are found ([`MolOptions::grains`]).
    pub fn finds_grains(&self) -> bool {
        self.options.grains.is_some()
    }

    /// The last frame's grains, the largest first ([`MolOptions::grains`]; `None` without
    /// it).
    pub fn last_grains(&self) -> Option<&[Grain]> {
        self.last_grains.as_deref()
    }

    /// The last frame's clusters ([`MolOptions::clusters`]; `None` without it): sizes,
    /// centres and radii of gyration, the largest first (the per-atom ids are the property
    /// [`CLUSTER`], not kept here).
    pub fn last_clusters(&self) -> Option<&texmap_md_io::coordination::Clusters> {
        self.last_clusters.as_ref()
    }

    /// The last frame's radial distribution function ([`MolOptions::rdf`]; `None` without
    /// it).
    pub fn last_rdf(&self) -> Option<&texmap_md_io::rdf::Rdf> {
        self.last_rdf.as_ref()
    }

    /// The last frame's measurements ([`MolOptions::measures`], in order): points, values and
    /// where their labels go.
    pub fn last_measurements(&self) -> &[Measured] {
        &self.measured
    }

    /// Each atom's position unwrapped across the periodic boundaries as of the last frame
    /// prepared, before `--align` ([`MolOptions::msd`]; `None` without it): what
    /// [`texmap_md_io::msd::AllOrigins`] averages over every time origin.
    pub fn last_unwrapped(&self) -> Option<&[[f64; 3]]> {
        self.options.msd.then(|| self.msd.unwrapped())
    }

    /// Whether every frame's squared displacements are followed ([`MolOptions::msd`]): each
    /// frame must then be built after the one before it.
    pub fn tracks_msd(&self) -> bool {
        self.options.msd
    }

    /// Whether some representation draws trails ([`DrawStyle::Trails`]).
    pub fn draws_trails(&self) -> bool {
        self.reps.iter().any(|r| r.draw == DrawStyle::Trails)
    }

    /// Appends `frame`'s positions of the followed atoms to their trails (see
    /// [`DrawStyle::Trails`]); the atoms are picked at the first frame, by the first trails
    /// representation's selection.
    fn extend_trails(&mut self, frame: &Frame) -> Result<(), MolError> {
        if self.trail_atoms.is_none() {
            let rep = self.reps.iter().find(|r| r.draw == DrawStyle::Trails);
            let picked: Vec<u32> = match rep.and_then(|r| r.select.as_ref()) {
                Some(sel) => {
                    let mask = sel.evaluate(frame).map_err(|error| MolError::Selection {
                        role: SelectionRole::Select,
                        error,
                    })?;
                    (0..frame.n_atoms() as u32)
                        .filter(|i| mask[*i as usize])
                        .collect()
                }
                None => (0..frame.n_atoms() as u32).collect(),
            };
            self.trail_paths = vec![Default::default(); picked.len()];
            self.trail_last = picked
                .iter()
                .map(|i| frame.positions[*i as usize])
                .collect();
            self.trail_atoms = Some(picked);
        }
        let atoms = self.trail_atoms.as_deref().unwrap_or(&[]);
        if let Some(&i) = atoms.iter().find(|i| **i as usize >= frame.n_atoms()) {
            return Err(MolError::TrailAtoms {
                atom: i as usize,
                frame: frame.n_atoms(),
            });
        }
        let keep = self.options.trail_length.unwrap_or(usize::MAX).max(1);
        let image = frame
            .cell
            .as_ref()
            .and_then(texmap_md_io::pbc::NearestImage::new);
        for ((&i, path), last) in atoms
            .iter()
            .zip(&mut self.trail_paths)
            .zip(&mut self.trail_last)
        {
            let now = frame.positions[i as usize];
            let point = match path.back() {
                None => glam::Vec3::from(now),
                Some(prev) => {
                    // The step from the last frame, through the nearest image: the path goes
                    // on across a face of the box instead of jumping back through it.
                    let mut d: [f64; 3] = std::array::from_fn(|k| now[k] as f64 - last[k] as f64);
                    if let Some(image) = &image {
                        d = image.apply(d);
                    }
                    *prev + glam::DVec3::from_array(d).as_vec3()
                }
            };
            *last = now;
            path.push_back(point);
            while path.len() > keep {
                path.pop_front();
            }
        }
        Ok(())
    }

    /// The followed atoms' trails as they are after the last frame built ([`DrawStyle::Trails`]):
    /// per atom, its index in the frames and its path, oldest point first.
    pub fn trails(&self) -> impl Iterator<Item = (u32, &std::collections::VecDeque<glam::Vec3>)> {
        self.trail_atoms
            .as_deref()
            .unwrap_or(&[])
            .iter()
            .copied()
            .zip(&self.trail_paths)
    }

    /// Whether some representation draws arrows ([`DrawStyle::Arrows`]).
    pub fn draws_arrows(&self) -> bool {
        self.reps.iter().any(|r| r.draw == DrawStyle::Arrows)
    }

    /// Whether the frames built measure displacements (the [`DISPLACEMENT`] property,
    /// displacement arrows, or [`MolOptions::strain`]): what [`set_displacement_reference`](Self::set_displacement_reference)
    /// changes.
    pub fn measures_displacements(&self) -> bool {
        self.options.displacement
            || self.options.strain.is_some()
            || self.options.wigner_seitz.is_some()
            || (self.draws_arrows() && self.options.arrows.source == ArrowSource::Displacement)
    }

    /// The last frame's arrows ([`DrawStyle::Arrows`]; empty without them).
    pub fn arrows_mesh(&self) -> &MolMesh {
        &self.arrows
    }

    /// The centres of the atoms the last frame's arrows start from, one per selected atom
    /// whether its vector is zero or not (an empty picture of zero displacements is still a
    /// picture of those atoms).
    pub fn arrow_atoms(&self) -> &[glam::Vec3] {
        &self.arrow_atoms
    }

    /// Whether some representation draws ellipsoids ([`DrawStyle::Ellipsoids`]).
    pub fn draws_ellipsoids(&self) -> bool {
        self.reps.iter().any(|r| r.draw == DrawStyle::Ellipsoids)
    }

    /// The last frame's ellipsoids ([`DrawStyle::Ellipsoids`]; empty without them), for
    /// [`crate::ellipsoids::tessellate`] once the camera is known.
    pub fn ellipsoids(&self) -> &[Ellipsoid] {
        &self.ellipsoids
    }

    /// Whether some representation draws coordination polyhedra ([`DrawStyle::Polyhedra`]).
    pub fn draws_polyhedra(&self) -> bool {
        self.reps.iter().any(|r| r.draw == DrawStyle::Polyhedra)
    }

    /// The last frame's coordination polyhedra ([`DrawStyle::Polyhedra`]; empty without them).
    pub fn polyhedra_mesh(&self) -> &MolMesh {
        &self.polyhedra
    }

    /// Whether some representation draws a molecular surface ([`DrawStyle::Surface`]).
    pub fn draws_surface(&self) -> bool {
        self.reps.iter().any(|r| r.draw == DrawStyle::Surface)
    }

    /// Whether some representation draws a mesh (a surface, a cartoon, polyhedra or arrows)
    /// rather than spheres.
    pub fn draws_meshes(&self) -> bool {
        self.reps.iter().any(|r| {
            matches!(
                r.draw,
                DrawStyle::Surface
                    | DrawStyle::Cartoon
                    | DrawStyle::Polyhedra
                    | DrawStyle::Arrows
                    | DrawStyle::Ellipsoids
            )
        })
    }

    /// The atoms the last frame built draws as a molecular surface ([`DrawStyle::Surface`]),
    /// at their radii, with their materials (indices into the scene's).
    pub fn surface_atoms(&self) -> &SurfaceAtoms {
        &self.surface
    }

    /// The colourings the representations have of their own, in order.
    pub fn rep_colorings(&self) -> impl Iterator<Item = ColorBy> + '_ {
        self.reps.iter().filter_map(|r| match r.color {
            Some(RepColor::By(c)) => Some(c),
            _ => None,
        })
    }

    /// Whether some representation is coloured by the builder's colouring (so a colour bar for
    /// it belongs in the image).
    pub fn uses_builder_coloring(&self) -> bool {
        self.reps
            .iter()
            .any(|r| matches!(r.color, None | Some(RepColor::By(ColorBy::Scalar))))
    }

    /// `scene`'s materials recoloured by `rep`'s own colouring, if it has one, the colour
    /// rules still winning.
    fn recolor(
        &mut self,
        builder: &mut SceneBuilder,
        frame: &Frame,
        rep: &Representation,
        scene: &mut SphereScene,
    ) {
        let color = match (rep.color, rep.draw) {
            (None, DrawStyle::HBonds) => Some(RepColor::Fixed(HBOND_COLOR)),
            (c, _) => c,
        };
        match color {
            None => return,
            Some(RepColor::By(by)) => builder.kinds_by(frame, by, &mut scene.kinds),
            Some(RepColor::Fixed(rgb)) => {
                let kind = builder.kind_of(rgb);
                scene.kinds.iter_mut().for_each(|k| *k = kind);
            }
        }
        overlay(&mut scene.kinds, &self.rule_kinds);
    }

    /// Steps 5-7 for every representation: one is drawn in place; several are each drawn from
    /// the styled atoms on their own and concatenated, every bond with its representation's
    /// radius.
    fn draw_reps(
        &mut self,
        builder: &mut SceneBuilder,
        frame: &Frame,
        reps: &[Representation],
        scene: &mut SphereScene,
    ) -> Result<(), MolError> {
        if let [rep] = reps {
            self.recolor(builder, frame, rep, scene);
            return self.draw_rep(frame, rep, scene);
        }
        let styled = std::mem::take(scene);
        for (k, rep) in reps.iter().enumerate() {
            let mut part = styled.clone();
            self.recolor(builder, frame, rep, &mut part);
            self.draw_rep(frame, rep, &mut part)?;
            if k == 0 {
                scene.bond_radius = part.bond_radius;
            }
            let offset = scene.centers.len() as u32;
            scene.centers.extend_from_slice(&part.centers);
            scene.radii.extend_from_slice(&part.radii);
            scene.kinds.extend_from_slice(&part.kinds);
            for (b, pair) in part.bonds.iter().enumerate() {
                scene.bonds.push(pair.map(|i| i + offset));
                scene.bond_radii.push(part.bond_radius_of(b));
            }
        }
        Ok(())
    }

    /// Steps 5-7 of the module docs for one representation, in place: `scene` holds every atom
    /// of `frame`, styled, in frame order, and the plan's bond pairs index them.
    fn draw_rep(
        &mut self,
        frame: &Frame,
        rep: &Representation,
        scene: &mut SphereScene,
    ) -> Result<(), MolError> {
        let failed = |role| move |error| MolError::Selection { role, error };
        scene.bond_radii.clear();
        match rep.draw {
            DrawStyle::Spacefill
            | DrawStyle::Surface
            | DrawStyle::HBonds
            | DrawStyle::Polyhedra
            | DrawStyle::Arrows
            | DrawStyle::Trails
            | DrawStyle::Ellipsoids => {}
            DrawStyle::BallStick => {
                for r in &mut scene.radii {
                    *r *= BALL_AND_STICK_RADIUS_SCALE;
                }
                scene.bond_radius = BALL_AND_STICK_BOND_RADIUS;
            }
            DrawStyle::Licorice | DrawStyle::Tube | DrawStyle::Cartoon => {
                for r in &mut scene.radii {
                    *r = LICORICE_RADIUS;
                }
                scene.bond_radius = LICORICE_RADIUS;
            }
        }
        // The selection: keep selected atoms, renumber the bonds between them.
        let mut mask = match &rep.select {
            Some(sel) => Some(sel.evaluate(frame).map_err(failed(SelectionRole::Select))?),
            None => None,
        };
        if let Some(keep) = &self.slice_keep {
            let m = mask.get_or_insert_with(|| vec![true; frame.n_atoms()]);
            m.iter_mut().zip(keep).for_each(|(m, k)| *m &= *k);
        }
        let traces = match rep.draw {
            DrawStyle::Tube => {
                let selected = mask.get_or_insert_with(|| vec![true; frame.n_atoms()]);
                backbone_traces(frame, scene, selected)
            }
            DrawStyle::Cartoon => {
                let selected = mask.get_or_insert_with(|| vec![true; frame.n_atoms()]);
                crate::cartoon::append_cartoon(
                    frame,
                    &scene.centers,
                    &scene.kinds,
                    selected,
                    &mut self.cartoon,
                );
                // Protein and nucleic residues give way to the cartoon.
                use texmap_md_io::select::{NUCLEIC_RESIDUES, PROTEIN_RESIDUES};
                for (keep, res) in selected.iter_mut().zip(&frame.res_names) {
                    if PROTEIN_RESIDUES.contains(&res.as_str())
                        || NUCLEIC_RESIDUES.contains(&res.as_str())
                    {
                        *keep = false;
                    }
                }
                Vec::new()
            }
            _ => Vec::new(),
        };
        if rep.draw == DrawStyle::Trails {
            // Spheres at the path's points joined by sticks, in each atom's colour now.
            let kinds = std::mem::take(&mut scene.kinds);
            scene.centers.clear();
            scene.radii.clear();
            scene.bonds.clear();
            scene.bond_radius = TRAIL_RADIUS;
            for (&i, path) in self
                .trail_atoms
                .as_deref()
                .unwrap_or(&[])
                .iter()
                .zip(&self.trail_paths)
            {
                let kind = kinds[i as usize];
                let first = scene.centers.len() as u32;
                // The path moved as a whole to end at the atom as drawn (wrapped or not).
                let shift = match path.back() {
                    Some(last) => glam::Vec3::from(frame.positions[i as usize]) - *last,
                    None => glam::Vec3::ZERO,
                };
                for (k, p) in path.iter().enumerate() {
                    scene.push(*p + shift, TRAIL_RADIUS, kind);
                    if k > 0 {
                        scene.bonds.push([first + k as u32 - 1, first + k as u32]);
                    }
                }
            }
            return Ok(());
        }
        if rep.draw == DrawStyle::Arrows {
            let o = &self.options.arrows;
            for (i, v) in self.arrow_vectors.iter().enumerate() {
                if mask.as_ref().is_none_or(|m| m[i]) {
                    let from = scene.centers[i];
                    self.arrow_atoms.push(from);
                    crate::arrows::append_arrow(
                        &mut self.arrows,
                        from,
                        *v * o.scale,
                        o.radius,
                        scene.kinds[i],
                    );
                }
            }
            scene.centers.clear();
            scene.radii.clear();
            scene.kinds.clear();
            scene.bonds.clear();
            return Ok(());
        }
        if rep.draw == DrawStyle::Ellipsoids {
            // The selected atoms become ellipsoids, LAMMPS's spheres (shape 0) stay spheres.
            let mut w = 0;
            for i in 0..scene.centers.len() {
                if !mask.as_ref().is_none_or(|m| m[i]) {
                    continue;
                }
                let (semi_axes, rotation) = self.ellipsoid_shapes[i];
                if semi_axes == glam::Vec3::ZERO {
                    scene.centers[w] = scene.centers[i];
                    scene.radii[w] = scene.radii[i];
                    scene.kinds[w] = scene.kinds[i];
                    w += 1;
                } else {
                    self.ellipsoids.push(Ellipsoid {
                        center: scene.centers[i],
                        semi_axes,
                        rotation,
                        kind: scene.kinds[i],
                    });
                }
            }
            scene.centers.truncate(w);
            scene.radii.truncate(w);
            scene.kinds.truncate(w);
            scene.bonds.clear();
            return Ok(());
        }
        if rep.draw == DrawStyle::Polyhedra {
            let all;
            let centre = match &mask {
                Some(m) => m.as_slice(),
                None => {
                    all = vec![true; frame.n_atoms()];
                    &all
                }
            };
            let radii: Vec<f32> = (0..frame.n_atoms())
                .map(|i| atom_element(frame, i).covalent_radius())
                .collect();
            crate::polyhedra::append_polyhedra(
                &scene.centers,
                &radii,
                &scene.kinds,
                centre,
                &self.ligand_pairs,
                frame.cell.as_ref(),
                &mut self.polyhedra,
            );
            scene.centers.clear();
            scene.radii.clear();
            scene.kinds.clear();
            scene.bonds.clear();
            return Ok(());
        }
        if rep.draw == DrawStyle::HBonds {
            let found =
                hbonds::hydrogen_bonds(frame, &self.donor_h, mask.as_deref(), self.options.hbonds)
                    .map_err(MolError::HBonds)?;
            let kinds = std::mem::take(&mut scene.kinds);
            scene.centers.clear();
            scene.radii.clear();
            scene.bonds.clear();
            scene.bond_radius = HBOND_RADIUS;
            for b in &found {
                let h = frame.positions[b.hydrogen as usize];
                let a = frame.positions[b.acceptor as usize];
                let mut v: [f64; 3] = std::array::from_fn(|k| a[k] as f64 - h[k] as f64);
                if let Some(cell) = &frame.cell {
                    v = texmap_md_io::pbc::minimum_image(cell, v);
                }
                let from = glam::Vec3::from(h);
                let to = from + glam::DVec3::from(v).as_vec3();
                push_dashes(scene, from, to, kinds[b.hydrogen as usize]);
            }
            self.hbonds.extend_from_slice(&found);
            return Ok(());
        }
        self.map.clear();
        if let Some(mask) = &mask {
            let mut next = 0u32;
            for &m in mask {
                self.map.push(if m { next } else { u32::MAX });
                next += m as u32;
            }
            let mut w = 0;
            for (i, &m) in mask.iter().enumerate() {
                if m {
                    scene.centers[w] = scene.centers[i];
                    scene.radii[w] = scene.radii[i];
                    scene.kinds[w] = scene.kinds[i];
                    w += 1;
                }
            }
            scene.centers.truncate(w);
            scene.radii.truncate(w);
            scene.kinds.truncate(w);
        }
        scene.bonds.clear();
        if rep.draw == DrawStyle::Surface {
            // The atoms go to the surface instead of the spheres.
            for ((c, r), k) in scene.centers.iter().zip(&scene.radii).zip(&scene.kinds) {
                self.surface.push(*c, *r, *k);
            }
            scene.centers.clear();
            scene.radii.clear();
            scene.kinds.clear();
            return Ok(());
        }
        if rep.draw != DrawStyle::Spacefill && self.options.bonds != BondSource::None {
            let valence = self.options.bond_orders
                && matches!(rep.draw, DrawStyle::BallStick | DrawStyle::Licorice)
                && !frame.bond_orders.is_empty()
                && frame.bond_orders.len() == frame.bonds.len();
            let mut multiple = Vec::new();
            for b in &self.pairs {
                let (i, j) = if self.map.is_empty() {
                    (b[0], b[1])
                } else {
                    (self.map[b[0] as usize], self.map[b[1] as usize])
                };
                if i != u32::MAX && j != u32::MAX {
                    let order = match valence {
                        true => frame
                            .bonds
                            .binary_search(b)
                            .map_or(1, |k| frame.bond_orders[k]),
                        false => 1,
                    };
                    if matches!(order, 2 | 3 | BOND_AROMATIC) {
                        multiple.push((*b, [i, j], order));
                    } else {
                        scene.bonds.push([i, j]);
                    }
                }
            }
            if !multiple.is_empty() {
                self.push_multiple_bonds(frame, scene, &multiple);
            }
        }
        for trace in &traces {
            push_tube(scene, trace);
        }
        Ok(())
    }

    /// Double, triple and aromatic bonds (`(frame pair, scene pair, order)`) drawn as PyMOL's
    /// valence mode draws them (see the module docs), every bond of `scene` then with its
    /// radius listed.
    fn push_multiple_bonds(
        &self,
        frame: &Frame,
        scene: &mut SphereScene,
        bonds: &[([u32; 2], [u32; 2], u8)],
    ) {
        let r = scene.bond_radius;
        if scene.bond_radii.len() != scene.bonds.len() {
            scene.bond_radii = vec![r; scene.bonds.len()];
        }
        let mut neighbours: Vec<Vec<(u32, u8)>> = vec![Vec::new(); frame.n_atoms()];
        for (k, &[i, j]) in frame.bonds.iter().enumerate() {
            let o = frame.bond_orders[k];
            neighbours[i as usize].push((j, o));
            neighbours[j as usize].push((i, o));
        }
        for &(pair, [i, j], order) in bonds {
            let side = valence_side(frame, &neighbours, pair);
            let (pi, pj) = (scene.centers[i as usize], scene.centers[j as usize]);
            let (ki, kj) = (scene.kinds[i as usize], scene.kinds[j as usize]);
            let mut stick = |offset: glam::Vec3, radius: f32| {
                let first = scene.centers.len() as u32;
                scene.push(pi + offset, radius, ki);
                scene.push(pj + offset, radius, kj);
                scene.bonds.push([first, first + 1]);
                scene.bond_radii.push(radius);
            };
            match order {
                2 => {
                    for s in [-1.0, 1.0] {
                        stick(side * (s * VALENCE_OFFSET * r), VALENCE_RADIUS * r);
                    }
                }
                3 => {
                    for s in [-1.0, 0.0, 1.0] {
                        stick(
                            side * (s * 1.6 * VALENCE_OFFSET * r),
                            0.75 * VALENCE_RADIUS * r,
                        );
                    }
                }
                _ => {
                    // Aromatic: the bond itself, thinner, and a dashed line on the ring's side.
                    stick(glam::Vec3::ZERO, VALENCE_RADIUS * r);
                    let off = side * (2.0 * VALENCE_OFFSET * r);
                    let (a, b) = (pi + off, pj + off);
                    let shorten = (b - a) * 0.15;
                    let before = scene.bonds.len();
                    push_dash_line(
                        scene,
                        a + shorten,
                        b - shorten,
                        ki,
                        0.5 * VALENCE_RADIUS * r,
                        3,
                    );
                    let added = scene.bonds.len() - before;
                    scene
                        .bond_radii
                        .extend(std::iter::repeat_n(0.5 * VALENCE_RADIUS * r, added));
                }
            }
        }
    }

    /// Whether `frame`'s atoms have nothing to be told apart by (no names, types or known
    /// elements) and no topology gives them any: every atom is drawn in one colour.
    pub fn atoms_unnamed(&self, frame: &Frame) -> bool {
        let nothing = frame.names.is_empty()
            && frame.types.is_empty()
            && (0..frame.n_atoms()).all(|i| atom_element(frame, i).is_unknown());
        self.options.topology.is_none() && nothing && frame.n_atoms() > 0
    }
}

/// `kinds` with each atom's colour-rule material where it has one (`u16::MAX`: none; an empty
/// `rules` changes nothing).
/// Turns the orientation quaternions a frame holds ([`crate::ellipsoids::ORIENTATION_SOURCES`])
/// by the fit's rotation, as the positions and velocities turn: `q' = r · q`.
fn rotate_orientations(frame: &mut Frame, fit: &crate::align::Superposition) {
    let Some(at) = crate::ellipsoids::orientation_properties(frame) else {
        return;
    };
    let r = glam::DQuat::from_mat3(&glam::DMat3::from_cols_array_2d(&fit.rotation).transpose());
    for i in 0..frame.n_atoms() {
        let v = |k: usize| f64::from(frame.properties[at[k]].values[i]);
        let q = r * glam::DQuat::from_xyzw(v(1), v(2), v(3), v(0));
        for (k, x) in [q.w, q.x, q.y, q.z].into_iter().enumerate() {
            frame.properties[at[k]].values[i] = x as f32;
        }
    }
}

fn overlay(kinds: &mut [u16], rules: &[u16]) {
    for (k, &r) in kinds.iter_mut().zip(rules) {
        if r != u16::MAX {
            *k = r;
        }
    }
}

/// One backbone atom of a tube: where it is and its material.
#[derive(Clone, Copy, Debug)]
struct TracePoint {
    at: glam::Vec3,
    kind: u16,
}

/// The tube traces through the selected CA (protein) and P (nucleic) atoms of `frame`, in file
/// order, split at chain and segment changes and at gaps; clears `selected` for every atom of a
/// protein or nucleic residue (the tube stands for them). `scene` holds every atom of the frame,
/// styled, in frame order.
fn backbone_traces(
    frame: &Frame,
    scene: &SphereScene,
    selected: &mut [bool],
) -> Vec<Vec<TracePoint>> {
    use texmap_md_io::select::{NUCLEIC_RESIDUES, PROTEIN_RESIDUES};
    let mut traces: Vec<Vec<TracePoint>> = Vec::new();
    if frame.res_names.is_empty() || frame.names.is_empty() {
        return traces;
    }
    let label = |v: &[texmap_md_io::Label], i: usize| v.get(i).copied();
    // The previous trace atom: its index and its gap limit.
    let mut last: Option<(usize, f32)> = None;
    for (i, keep) in selected.iter_mut().enumerate() {
        let res = frame.res_names[i].as_str();
        let (atom, gap) = if PROTEIN_RESIDUES.contains(&res) {
            ("CA", MAX_CA_GAP)
        } else if NUCLEIC_RESIDUES.contains(&res) {
            ("P", MAX_P_GAP)
        } else {
            continue;
        };
        if !std::mem::replace(keep, false) || frame.names[i] != atom {
            continue;
        }
        let point = TracePoint {
            at: scene.centers[i],
            kind: scene.kinds[i],
        };
        let joined = last.is_some_and(|(j, last_gap)| {
            last_gap == gap
                && label(&frame.chains, i) == label(&frame.chains, j)
                && label(&frame.segments, i) == label(&frame.segments, j)
                && point.at.distance(scene.centers[j]) <= gap
        });
        match traces.last_mut() {
            Some(t) if joined => t.push(point),
            _ => traces.push(vec![point]),
        }
        last = Some((i, gap));
    }
    traces
}

/// Appends the tube of one trace to `scene`: spline points as spheres, consecutive ones bonded.
/// A dashed line from `from` to `to` into `scene`: [`HBOND_DASHES`] cylinders of
/// [`HBOND_RADIUS`] with round ends, each (ends included) as long as the gaps between them.
fn push_dashes(scene: &mut SphereScene, from: glam::Vec3, to: glam::Vec3, kind: u16) {
    push_dash_line(scene, from, to, kind, HBOND_RADIUS, HBOND_DASHES);
}

/// `n` dashes of radius `r` from `from` to `to` as spheres joined by sticks (round ends).
fn push_dash_line(
    scene: &mut SphereScene,
    from: glam::Vec3,
    to: glam::Vec3,
    kind: u16,
    r: f32,
    n: usize,
) {
    let axis = (to - from).normalize_or_zero();
    // n dashes and n − 1 gaps of one length; a dash's sphere centres lie r inside its ends.
    let step = (to - from).length() / (2 * n - 1) as f32;
    let inset = r.min(step / 2.0);
    for k in 0..n {
        let start = from + axis * (2 * k) as f32 * step;
        let a = start + axis * inset;
        let b = start + axis * (step - inset);
        let first = scene.centers.len() as u32;
        scene.push(a, r, kind);
        scene.push(b, r, kind);
        scene.bonds.push([first, first + 1]);
    }
}

/// Where the second line of a double or aromatic bond `a`–`b` lies: across the bond, toward a
/// third atom bonded to `a` (else to `b`), preferring one bonded aromatically (so an aromatic
/// ring's dashes lie inside it); any direction across the bond without one.
fn valence_side(frame: &Frame, neighbours: &[Vec<(u32, u8)>], [a, b]: [u32; 2]) -> glam::Vec3 {
    let p = |i: u32| glam::Vec3::from(frame.positions[i as usize]);
    let axis = (p(b) - p(a)).normalize_or_zero();
    let across = |from: u32, to: u32| {
        let d = p(to) - p(from);
        (d - axis * d.dot(axis)).normalize_or_zero()
    };
    for (from, other) in [(a, b), (b, a)] {
        let list = &neighbours[from as usize];
        let pick = list
            .iter()
            .filter(|(n, _)| *n != other)
            .max_by_key(|(n, o)| (*o == BOND_AROMATIC, std::cmp::Reverse(*n)));
        if let Some(&(n, _)) = pick {
            let v = across(from, n);
            if v != glam::Vec3::ZERO {
                return v;
            }
        }
    }
    axis.any_orthonormal_vector()
}

fn push_tube(scene: &mut SphereScene, trace: &[TracePoint]) {
    let first = scene.centers.len() as u32;
    let n = trace.len();
    if n == 1 {
        scene.push(trace[0].at, TUBE_RADIUS, trace[0].kind);
        return;
    }
    // Mirrored neighbours past the ends: the spline's end tangents follow the first and last
    // intervals.
    let p = |k: isize| -> glam::Vec3 {
        match k {
            -1 => 2.0 * trace[0].at - trace[1].at,
            k if k as usize >= n => 2.0 * trace[n - 1].at - trace[n - 2].at,
            k => trace[k as usize].at,
        }
    };
    for i in 0..n - 1 {
        let (p0, p1, p2, p3) = (
            p(i as isize - 1),
            p(i as isize),
            p(i as isize + 1),
            p(i as isize + 2),
        );
        for s in 0..TUBE_SUBDIVISIONS {
            let t = s as f32 / TUBE_SUBDIVISIONS as f32;
            let (at, _) = crate::cartoon::catmull_rom(p0, p1, p2, p3, t);
            let kind = if t < 0.5 {
                trace[i].kind
            } else {
                trace[i + 1].kind
            };
            scene.push(at, TUBE_RADIUS, kind);
        }
    }
    scene.push(trace[n - 1].at, TUBE_RADIUS, trace[n - 1].kind);
    let last = scene.centers.len() as u32;
    scene.bonds.extend((first..last - 1).map(|k| [k, k + 1]));
}

/// `frame`'s per-atom property `name` set to `values` (replacing one of that name).
fn set_property(frame: &mut Frame, name: &str, values: Vec<f32>) {
    frame.properties.retain(|p| p.name != name);
    frame.properties.push(Property {
        name: name.to_string(),
        values,
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::StyleOptions;
    use texmap_md_io::{Element, UnitCell};

    /// Carbon atoms at `xs` on the x axis.
    fn carbons(xs: &[f32]) -> Frame {
        let mut frame = Frame::new();
        frame.positions = xs.iter().map(|&x| [x, 0.0, 0.0]).collect();
        frame.elements = vec![Element::from_symbol("C").unwrap(); xs.len()];
        frame
    }

    fn sel(text: &str) -> Selection {
        Selection::parse(text).unwrap()
    }

    fn built(options: MolOptions, frame: &mut Frame) -> (SphereScene, SceneBuilder) {
        let mut builder = SceneBuilder::new(&StyleOptions::default()).unwrap();
        let mut plan = MolPlan::new(options).unwrap();
        let mut scene = SphereScene::default();
        plan.build(&mut builder, frame, &mut scene).unwrap();
        (scene, builder)
    }

    #[test]
    fn the_selection_keeps_its_atoms_in_order_and_renumbers_their_bonds() {
        // A chain of five carbons 1.5 Å apart: bonds 0-1, 1-2, 2-3, 3-4 (C-C cutoff 1.97 Å).
        let xs = [0.0, 1.5, 3.0, 4.5, 6.0];
        let mut frame = carbons(&xs);
        let options = MolOptions {
            select: Some(sel("index 0 1 3 4")),
            draw: DrawStyle::BallStick,
            ..MolOptions::default()
        };
        let (scene, _) = built(options, &mut frame);
        let kept: Vec<f32> = scene.centers.iter().map(|c| c.x).collect();
        assert_eq!(kept, [0.0, 1.5, 4.5, 6.0]);
        // Atom 2 is dropped with its two bonds; 3-4 becomes 2-3.
        let mut bonds: Vec<[u32; 2]> = scene
            .bonds
            .iter()
            .map(|b| [b[0].min(b[1]), b[0].max(b[1])])
            .collect();
        bonds.sort();
        assert_eq!(bonds, [[0, 1], [2, 3]]);
        assert_eq!(scene.bond_radius, BALL_AND_STICK_BOND_RADIUS);
    }

    #[test]
    fn later_colour_and_radius_rules_win() {
        let mut frame = carbons(&[0.0, 5.0, 10.0, 15.0]);
        let (red, blue) = ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
        let options = MolOptions {
            colors: vec![(sel("index 0 1"), red), (sel("index 1 2"), blue)],
            radii: vec![(sel("index 0 1"), 2.0), (sel("index 1"), 3.0)],
            ..MolOptions::default()
        };
        let (scene, mut builder) = built(options, &mut frame);
        let (red, blue) = (builder.kind_of(red), builder.kind_of(blue));
        assert_eq!(scene.kinds[..3], [red, blue, blue]);
        assert_ne!(scene.kinds[3], red);
        assert_ne!(scene.kinds[3], blue);
        let carbon = Element::from_symbol("C").unwrap().vdw_radius();
        assert_eq!(scene.radii, [2.0, 3.0, carbon, carbon]);
    }

    #[test]
    fn unwrapping_joins_a_molecule_split_across_the_box() {
        // Two carbons 1.2 Å apart through the x face of a 10 Å box.
        let split = || {
            let mut f = carbons(&[0.2, 9.0]);
            f.cell = Some(UnitCell::orthorhombic(10.0, 10.0, 10.0).unwrap());
            f
        };
        let gap = |f: &Frame| {
            let (a, b) = (f.positions[0], f.positions[1]);
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
        };
        let mut frame = split();
        built(
            MolOptions {
                pbc: Pbc::Unwrap,
                bonds: BondSource::None,
                ..MolOptions::default()
            },
            &mut frame,
        );
        assert!((gap(&frame) - 1.2).abs() < 1e-4, "{}", gap(&frame));
        let mut kept = split();
        built(MolOptions::default(), &mut kept);
        assert!((gap(&kept) - 8.8).abs() < 1e-4);
    }

    #[test]
    fn listed_bonds_without_a_topology_come_from_the_frame_or_are_refused() {
        let mut plan = MolPlan::new(MolOptions {
            bonds: BondSource::Topology,
            draw: DrawStyle::Licorice,
            ..MolOptions::default()
        })
        .unwrap();
        let mut frame = Frame::new();
        frame.positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [5.0, 0.0, 0.0]];
        frame.elements = vec![Element::from_symbol("C").unwrap(); 3];
        let mut builder = SceneBuilder::new(&StyleOptions::default()).unwrap();
        let mut scene = SphereScene::default();
        let e = plan.build(&mut builder, &mut frame.clone(), &mut scene);
        assert_eq!(e, Err(MolError::NoTopology));
        // The frame's own bonds (an SDF or MOL2 file's) are the listed bonds, however long.
        frame.bonds = vec![[1, 2]];
        plan.build(&mut builder, &mut frame, &mut scene).unwrap();
        assert_eq!(scene.bonds, [[1, 2]]);
        let e = MolPlan::new(MolOptions {
            radii: vec![(sel("all"), f32::NAN)],
            ..MolOptions::default()
        })
        .unwrap_err();
        assert!(matches!(e, MolError::BadRadius { rule: 0, .. }));
    }

    /// Residue-labelled atoms: `(name, residue, chain, x)` on the x axis (y = z = 0).
    fn residues(atoms: &[(&str, &str, &str, f32)]) -> Frame {
        let l = |s: &str| texmap_md_io::Label::new(s).unwrap();
        let mut f = Frame::new();
        for (k, (name, res, chain, x)) in atoms.iter().enumerate() {
            f.positions.push([*x, 0.0, 0.0]);
            f.names.push(l(name));
            f.res_names.push(l(res));
            f.res_ids.push(k as i64);
            f.chains.push(l(chain));
        }
        f
    }

    #[test]
    fn the_tube_passes_through_each_chains_ca_atoms_and_breaks_at_gaps_and_chains() {
        let mut atoms = Vec::new();
        for k in 0..5 {
            atoms.push(("CA", "ALA", "A", 3.8 * k as f32));
            atoms.push(("CB", "ALA", "A", 3.8 * k as f32 + 1.0));
        }
        atoms.push(("CA", "GLY", "A", 3.8 * 4.0 + 10.0)); // a gap: a lone CA
        atoms.push(("O", "HOH", "W", 50.0)); // a water: licorice
        atoms.push(("CA", "ALA", "B", 60.0)); // chain B, two residues 3.8 Å apart
        atoms.push(("CA", "ALA", "B", 63.8));
        let mut frame = residues(&atoms);
        let options = MolOptions {
            draw: DrawStyle::Tube,
            ..MolOptions::default()
        };
        let (scene, _) = built(options.clone(), &mut frame);
        let s = TUBE_SUBDIVISIONS;
        // The water first (kept atoms come before the appended tube), then the traces.
        assert_eq!(scene.len(), 1 + (4 * s + 1) + 1 + (s + 1));
        assert_eq!(scene.centers[0].x, 50.0);
        assert!(scene.radii.iter().all(|r| *r == TUBE_RADIUS));
        // Chain A's tube goes through every CA (every s-th point) along the axis, monotonically.
        let tube_a = &scene.centers[1..2 + 4 * s];
        for k in 0..5 {
            assert!((tube_a[k * s].x - 3.8 * k as f32).abs() < 1e-5);
        }
        assert!(tube_a.iter().all(|c| c.y == 0.0 && c.z == 0.0));
        assert!(tube_a.windows(2).all(|w| w[1].x > w[0].x));
        // Points of a straight, evenly spaced trace are evenly spaced (Catmull-Rom is linear
        // there): the cylinders join without gaps.
        let step = 3.8 / s as f32;
        assert!(
            tube_a
                .windows(2)
                .all(|w| (w[1].x - w[0].x - step).abs() < 1e-4)
        );
        // Bonds: the consecutive points of each trace, none across a break.
        assert_eq!(scene.bonds.len(), 4 * s + s);
        assert!(scene.bonds.iter().all(|b| b[1] == b[0] + 1));
        assert!(
            !scene
                .bonds
                .contains(&[(1 + 4 * s) as u32, (2 + 4 * s) as u32])
        );
        // A selection picks which backbones are drawn.
        let mut frame = residues(&atoms);
        let chain_b = MolOptions {
            select: Some(sel("chain B")),
            ..options
        };
        let (scene, _) = built(chain_b, &mut frame);
        assert_eq!(scene.len(), s + 1);
        assert_eq!(scene.centers[0].x, 60.0);
    }
}

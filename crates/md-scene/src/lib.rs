//! Molecular-dynamics frames as impostor sphere scenes (and molecular surfaces): the join of `texmap-md-io` (atoms,
//! periodic cells, selections) and `texmap-impostor` ([`SphereScene`]), which depend on no
//! crate of each other.
//!
//! - [`style`]: per-name radius and colour rules and the [`SceneBuilder`] that turns each frame
//!   into a scene with them, colouring by the file's colour column, the element or the type.
//! - [`palette`]: one material per distinct 8-bit sRGB colour, at most [`MAX_MATERIALS`] of
//!   them (further colours take the nearest), and the evenly spaced colour of each atom type.
//! - [`camera`]: the automatic camera, fitted so that the sphere around everything a frame draws
//!   fills the image, seen along an axis or the three-quarter [`AUTO_VIEW_DIRECTION`]; the centre
//!   of a selection, which a camera may follow.
//! - [`plan`]: a frame's way from reading to drawing ([`MolPlan`]): the topology's labels, bonds
//!   ([`BondSource`]), periodic boundaries ([`Pbc`]), per-selection colours and radii applied in
//!   order, the [`DrawStyle`] and the selection of drawn atoms with its bonds renumbered.
//! - [`camera_plan`]: the camera of every frame of a render ([`CameraPlan`]): still, orbiting or
//!   along keyframes ([`MotionSpec`]), and following a selection's centre.
//! - [`outline`]: the periodic box drawn as rows of small spheres along its twelve edges (every
//!   sphere method draws spheres; none draws lines).
//! - [`colormap`]: colour coding, a scalar in [0, 1] to an sRGB colour ([`Colormap`]: viridis,
//!   plasma, coolwarm, turbo, gray, within one 8-bit code of matplotlib's).
//! - [`scalar`]: colour coding by a number per atom ([`ScalarSource`]: a property such as the
//!   B-factor or a LAMMPS compute, the speed, the residue, the index) over a range fixed at the
//!   first frame.
//! - hydrogen bonds ([`DrawStyle::HBonds`]): dashed lines from hydrogen to acceptor, found by
//!   [`texmap_md_io::hbonds`] every frame (see [`plan`]).
//! - [`cartoon`]: cartoons as VMD's NewCartoon draws them (helix ribbons, strand arrows, coil
//!   tubes along a spline through the CA atoms; nucleic acids as a P tube with base rungs), a
//!   mesh like the surface's.
//! - trails ([`DrawStyle::Trails`]): the unwrapped paths of atoms over the frames drawn (see
//!   [`plan`]).
//! - [`measure`]: distances, angles and dihedrals between picked atoms, drawn as dashes with
//!   their values (PyMOL's `distance`, `angle`, `dihedral`).
//! - [`arrows`]: an arrow per atom for its velocity, displacement or a vector property (OVITO's
//!   vector display), a mesh like the surface's.
//! - [`ellipsoids`]: aspherical particles (LAMMPS `shapex..`/`quatw..`, one shape for all) as
//!   ellipsoid meshes tessellated no finer than the view needs (OVITO's aspherical shapes).
//! - [`polyhedra`]: coordination polyhedra as VESTA draws them (the convex hull of each centre
//!   atom's bonded neighbours at their nearest periodic images), a mesh like the surface's.
//! - [`surface`]: molecular surfaces as VMD's QuickSurf draws them (one Gaussian per atom, the
//!   isosurface by surface nets with every vertex on the exact surface), drawn by the rasteriser
//!   over a sphere method's frame ([`surface::draw_mesh`]).
//! - [`isosurface`]: isosurfaces of volumetric data (a cube file's orbital, a CHGCAR's density;
//!   md-io's `Volume`) by surface nets on the data's own skewed grid, capped at a bounded grid's
//!   border, continued across a periodic one's, cut into colour bands of another quantity, or
//!   a plane through the data (`isosurface::slice`); a mesh like the surface's.
//! - [`legend`]: a colour bar with its tick labels and title drawn onto a rendered RGBA image
//!   ([`draw_color_bar`]).
//!
//! ```
//! use glam::Vec3;
//! use texmap_impostor::SphereScene;
//! use texmap_md_io::{Frame, UnitCell};
//! use texmap_md_scene::{Palette, ViewAxis, add_box_outline, fit_camera};
//!
//! // Two atoms in a 10 Å cubic box.
//! let mut frame = Frame::new();
//! frame.positions = vec![[2.0, 2.0, 2.0], [8.0, 8.0, 8.0]];
//! frame.cell = Some(UnitCell::orthorhombic(10.0, 10.0, 10.0).unwrap());
//!
//! // One material per colour: both atoms red.
//! let mut palette = Palette::new();
//! let red = palette.kind_of([1.0, 0.0, 0.0]);
//! let mut scene = SphereScene::default();
//! for p in &frame.positions {
//!     scene.push(Vec3::from(*p), 1.5, red);
//! }
//! scene.materials = palette.materials();
//! add_box_outline(frame.cell.as_ref().unwrap(), &mut scene);
//! assert_eq!(scene.materials.len(), 2); // red, and the outline's grey
//!
//! // The automatic camera looks at the centre of what is drawn (here, the box).
//! let (camera, target) = fit_camera(&frame, &scene, ViewAxis::Auto, Some(40.0), 640, 480).unwrap();
//! assert!((target - Vec3::splat(5.0)).length() < 0.1);
//! assert_eq!((camera.width(), camera.height()), (640, 480));
//! ```

pub mod align;
pub mod arrows;
pub mod camera;
pub mod camera_plan;
pub mod cartoon;
pub mod colormap;
pub mod ellipsoids;
pub mod isosurface;
pub mod legend;
pub mod measure;
pub mod outline;
pub mod palette;
pub mod plan;
pub mod polyhedra;
pub mod scalar;
pub mod style;
pub mod surface;

pub use camera::{
    AUTO_VIEW_DIRECTION, FIT_MARGIN, POINT_RADIUS, ViewAxis, centre_of, drawn_bounds, fit_camera,
    push_framed_points,
};
pub use camera_plan::{CameraPlan, CameraPlanError, MotionSpec};
pub use colormap::Colormap;
pub use legend::{
    ColorBar, MAX_LABEL_CHARS, TripodAxis, draw_atom_label, draw_axes_tripod, draw_caption,
    draw_color_bar,
};
pub use outline::{add_box_outline, cell_corners};
pub use palette::{MAX_MATERIALS, Palette, type_color};
pub use plan::{
    Alignment, BALL_AND_STICK_BOND_RADIUS, BALL_AND_STICK_RADIUS_SCALE, BondSource, CENTROSYMMETRY,
    CLUSTER, COORDINATION, CentroOptions, ClusterOptions, D2MIN, DISPLACEMENT, DrawStyle, GRAIN,
    HBOND_COLOR, HBOND_DASHES, HBOND_RADIUS, LATTICE_RMSD, LICORICE_RADIUS, MSD, MolError,
    MolOptions, MolPlan, ORIENTATION, Pbc, RdfOptions, RepColor, Representation, SASA,
    SHEAR_STRAIN, SITE, SITE_OCCUPANCY, SasaOptions, SelectionRole, Slice, TRAIL_RADIUS,
    VALENCE_OFFSET, VALENCE_RADIUS, VOLUMETRIC_STRAIN, VORONOI_FACES, VORONOI_INDEX,
    VORONOI_VOLUME, WsOutput,
};
pub use scalar::{NAN_COLOR, SCALAR_LEVELS, ScalarColor, ScalarSource};
pub use style::{
    CNA_COLORS, ColorBy, DIAMOND_COLORS, IpfAxis, RuleKind, STRUCTURE_COLORS, SceneBuilder,
    StyleError, StyleOptions, StyleWarning, style_from,
};

#[doc(no_inline)]
pub use texmap_impostor::SphereScene;

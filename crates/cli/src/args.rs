//! The command-line definition.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

/// A usage error found after parsing (bad value combinations): exit code 2.
#[derive(Debug)]
pub struct UsageError(pub String);

impl std::fmt::Display for UsageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

/// Shorthand for returning a usage error.
pub fn usage<T>(msg: impl Into<String>) -> anyhow::Result<T> {
    Err(UsageError(msg.into()).into())
}

#[derive(Parser, Debug)]
#[command(
    name = "texmap",
    version,
    about = "Texture mapping on the CPU, every method measured against a reference ray tracer: molecular-dynamics spheres, flight-simulator terrain and environment-mapped reflections",
    long_about = "Texture mapping on the CPU (no GPU, no X server), every method measured for speed and \
against a BVH reference ray tracer for accuracy:\n\
  - molecular dynamics: trajectories drawn as spheres with four methods from classic papers — \
tessellated polygons, Seed 002 colour+depth look-up images, Seed 004 template billboards and exact \
ray-cast impostors (info, render, compare, movie);\n\
  - terrain (Seed 000): databases from elevation grids and orthophotos, flown over with mipmapped \
and span-parallel samplers (terrain build, render, fly, compare);\n\
  - environment mapping (Seed 003): mirror and glass objects with sphere, cube and dual-paraboloid \
maps re-rendered every frame (envmap, envmap compare).\n\n\
Exit codes: 0 success, 1 runtime failure (unreadable or damaged input, unwritable output), 2 bad usage.",
    after_help = "Examples:\n  texmap demo --out demo\n  texmap info traj.xtc\n  texmap render traj.pdb --frames 0:100:10 --size 1280x720 -o frames/f%04d.png\n  texmap compare --scene S1 --out study\n  texmap terrain build --dem N44W072.hgt --out db && texmap terrain render db -o view.png\n  texmap envmap --method cube -o mirror.png"
)]
pub struct Cli {
    /// Worker threads (default: all cores). Output is byte-identical for any count.
    #[arg(long, global = true, value_name = "N")]
    pub threads: Option<usize>,

    /// No progress bars and no "wrote ..." lines; warnings and errors still go to stderr.
    #[arg(short, long, global = true)]
    pub quiet: bool,

    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
#[allow(clippy::large_enum_variant)] // parsed once per run: boxing RenderArgs would buy nothing
pub enum Command {
    /// Print a trajectory's format, atom and frame counts, box and its periodic edges ('pbc':
    /// false along a LAMMPS `ff`/`ss` or extended XYZ `F` edge), chains and segments (with their
    /// atom counts), per-atom properties, the first frame's secondary structure (DSSP: helix,
    /// strand, coil) and first positions as one JSON object; for a topology
    /// file (PSF, AMBER prmtop, GROMACS .top) its atoms, residues, bonds, chains and segments; for a GROMACS
    /// energy file (.edr) or a LAMMPS log its terms with units, rows, time span and each
    /// term's mean, minimum and maximum.
    Info {
        /// Trajectory file (XYZ, extended XYZ, PDB, PDBx/mmCIF and BinaryCIF (.bcif), GRO, LAMMPS dump (text or binary .bin), DCD, XTC, TRR,
        /// AMBER NetCDF, AMBER ASCII mdcrd (with --topology: the file has no atom count) and
        /// rst7/inpcrd, HOOMD-blue GSD, SDF/MOL and MOL2 with their bonds, one frame per
        /// record, VASP POSCAR/CONTCAR/XDATCAR, crystallographic CIF, a LAMMPS data file,
        /// CHARMM .crd/.cor, PQR with charges and radii, AutoDock PDBQT, NAMD binary .coor, Tinker .xyz/.arc, DL_POLY CONFIG/HISTORY,
        /// XCrySDen XSF/AXSF, Quantum ESPRESSO pw.x output (.pwo, or .out: every ionic step)
        /// and input (.pwi, or .in), VASP vasprun.xml and OUTCAR (every ionic step), CP2K's
        /// -pos-1.xyz (step, time and energy; the cell with --cell)),
        /// gzip- or bzip2-compressed or not (1abc.cif.gz, prod.mdcrd.bz2). A quoted pattern ('dump.*.lammpstrj') reads
        /// the files it matches in natural order as one trajectory.
        file: PathBuf,
        /// More parts of the same trajectory, read after FILE as one (prod2.xtc prod3.xtc).
        #[arg(value_name = "MORE")]
        more: Vec<PathBuf>,
        /// Format, when the extension does not tell it.
        #[arg(long)]
        format: Option<String>,
        /// Count only the complete frames of a file whose last frame is cut short (a .gz whose
        /// stream ends early too), with a warning (default: a cut frame is an error naming the
        /// file, frame and byte).
        #[arg(long)]
        allow_truncated: bool,
        /// Column names of a LAMMPS binary dump (.bin) from an older LAMMPS, which does not
        /// name them (no magic header, or format revision 1), as the dump custom command lists
        /// them ('id type x y z vx vy vz'); a newer dump names its own. Without them such a file of 5 or 8 values per
        /// atom is read as dump atom's default ('id type xs ys zs [ix iy iz]').
        #[arg(long, value_name = "NAMES")]
        lammps_columns: Option<String>,
        /// Topology (PDB, PDBx/mmCIF or BinaryCIF, GRO, PSF, AMBER prmtop, GROMACS .tpr or .top, LAMMPS data file) of the trajectory's atoms: its
        /// atom, residue and bond counts are added, and a different atom count is an error.
        #[arg(long, value_name = "FILE")]
        topology: Option<PathBuf>,
        /// A periodic cell for frames whose file holds none (plain XYZ, CP2K, ORCA, xtb), or to
        /// replace the file's: A,B,C in Å (right angles) or A,B,C,ALPHA,BETA,GAMMA (degrees), as
        /// VMD's 'pbc set {A B C}'; or a CP2K cell file (PROJECT-1.cell), each frame's cell found by
        /// its step (the 'i =' of CP2K's .xyz comment lines; a step the file lacks is an error).
        /// --pbc, --replicate and --box-outline then work on such trajectories.
        #[arg(long, value_name = "A,B,C[,ANGLES]|FILE.cell")]
        cell: Option<String>,
    },
    /// Render trajectory frames to PNG (and optionally depth to EXR).
    Render(RenderArgs),
    /// Write a trajectory's frames to another file, analysed and cut down as texmap render
    /// would draw them: a selection, every Nth frame, molecules made whole, superposed, with
    /// the analyses' per-atom numbers as columns (extended XYZ, LAMMPS dump, GROMACS .gro,
    /// PDB, DCD, XTC).
    Convert(crate::convert::ConvertArgs),
    /// Run every method and the reference ray tracer on a scene; write results, images and charts.
    Compare(CompareArgs),
    /// No input needed: simulate a small built-in MD system and render it with every method, build
    /// and fly a built-in terrain with every sampler, draw the environment-mapping scene with every
    /// method, compare each against the reference, and write an index.html that shows it all.
    Demo {
        /// Output directory.
        #[arg(long, default_value = "texmap-demo")]
        out: PathBuf,
        /// MD steps to simulate (frames are taken every --every steps).
        #[arg(long, default_value_t = 300)]
        steps: usize,
        /// Keep one frame every this many steps.
        #[arg(long, default_value_t = 10)]
        every: usize,
        /// Image size for the animation, WxH.
        #[arg(long, default_value = "500x500")]
        size: String,
    },
    /// Terrain databases from elevation grids and orthophotos (Seed 000): build, info, export, maps,
    /// and the flight view: render, fly, compare.
    Terrain {
        #[command(subcommand)]
        cmd: crate::terrain::TerrainCmd,
    },
    /// Environment mapping (Seed 003): a mirror or glass target drawn with sphere, cube or
    /// dual-paraboloid maps; `envmap compare` measures every method against the reference.
    Envmap(crate::envmap::EnvmapArgs),
    /// Draw a table's columns as a line chart, PNG or SVG: the CSV tables texmap convert
    /// writes (RMSD, radius of gyration, SASA, hydrogen bonds, secondary structure over time),
    /// a GROMACS .xvg or energy (.edr) file, or a LAMMPS log's thermo output.
    /// `texmap plot rmsd.csv --y rmsd -o rmsd.png`, `texmap plot ener.edr --y Temperature -o t.png`.
    Plot(crate::plot::PlotArgs),
    /// Assemble a directory of PNG frames (in numeric order: f2.png before f10.png) into one
    /// movie: .mp4, .webm, .gif (ffmpeg) or .apng. The last step of a render split into parts.
    Movie {
        /// Directory holding the PNG frames (all of one size).
        dir: PathBuf,
        /// The movie file; its extension names the format.
        #[arg(short, long)]
        output: PathBuf,
        /// Frames per second.
        #[arg(long, default_value_t = 25.0)]
        fps: f64,
    },
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum MethodArg {
    Raycast,
    Lut,
    Template,
    Polygon,
    /// The reference ray tracer (slow, exact).
    Reference,
}

/// `--color-by`: a colour source, or a number per atom coloured through `--colormap`.
#[derive(Clone, Debug, PartialEq)]
pub enum ColorBy {
    /// The file's per-atom colour columns (extended XYZ `color`, LAMMPS dump `ColorR ColorG
    /// ColorB`) where it has them, else --type-color, else element colours.
    Property,
    /// --type-color, else element colours (CPK/Jmol); colour columns in the file are ignored.
    Element,
    /// --type-color, else one distinct colour per atom type (or name).
    Type,
    /// --type-color, else one distinct colour per chain (PDB column 22, mmCIF auth_asym_id),
    /// or per segment (PSF, PDB columns 73-76) when the file has no chains.
    Chain,
    /// --type-color, else the residue's secondary structure (helix, strand, coil), per frame.
    Structure,
    /// --type-color, else the crystal structure type (adaptive CNA: FCC, HCP, BCC, ICO,
    /// other), per frame, in OVITO's colours.
    Cna,
    /// --type-color, else the diamond structure type (cubic, hexagonal, their first and
    /// second neighbours, other), per frame, in OVITO's colours.
    Diamond,
    /// --type-color, else one distinct colour per cluster (--clusters), the largest first.
    Cluster,
    /// --type-color, else one distinct colour per grain (--grains), the largest first.
    Grain,
    /// --type-color, else the inverse pole figure colour of the lattice orientation along an
    /// axis.
    Ipf(texmap_md_scene::IpfAxis),
    /// A number per atom through --colormap.
    Scalar(texmap_md_scene::ScalarSource),
}

/// Parses `--color-by`: a keyword, or the name of a per-atom property of the file.
pub fn parse_color_by(s: &str) -> Result<ColorBy, String> {
    use texmap_md_scene::ScalarSource;
    Ok(match s {
        "property" => ColorBy::Property,
        "element" => ColorBy::Element,
        "type" => ColorBy::Type,
        "chain" => ColorBy::Chain,
        "structure" | "secondary" | "ss" => ColorBy::Structure,
        "cna" | "structure-type" => ColorBy::Cna,
        "diamond" => ColorBy::Diamond,
        "cluster" | "clusters" => ColorBy::Cluster,
        "grain" | "grains" => ColorBy::Grain,
        "ipf" | "ipf-z" | "orientation" => ColorBy::Ipf(texmap_md_scene::IpfAxis::Z),
        "ipf-x" => ColorBy::Ipf(texmap_md_scene::IpfAxis::X),
        "ipf-y" => ColorBy::Ipf(texmap_md_scene::IpfAxis::Y),
        "speed" | "velocity" => ColorBy::Scalar(ScalarSource::Speed),
        "residue" | "resid" => ColorBy::Scalar(ScalarSource::Residue),
        "index" => ColorBy::Scalar(ScalarSource::Index),
        "beta" | "b" => ColorBy::Scalar(ScalarSource::Property("bfactor".into())),
        "" => return Err("expected a colour source or a property name".into()),
        name => ColorBy::Scalar(ScalarSource::Property(name.to_string())),
    })
}

/// Parses `--replicate`: `NX,NY,NZ` (or one `N` for all three), each 1 to 100.
pub fn parse_replicate(s: &str) -> Result<[usize; 3], String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let counts: Vec<usize> = parts
        .iter()
        .map(|p| match p.parse::<usize>() {
            Ok(n) if (1..=100).contains(&n) => Ok(n),
            _ => Err(format!("{p:?} is not an image count from 1 to 100")),
        })
        .collect::<Result<_, _>>()?;
    match counts[..] {
        [n] => Ok([n; 3]),
        [x, y, z] => Ok([x, y, z]),
        _ => Err("expected NX,NY,NZ (images along the cell's a, b, c) or one N".into()),
    }
}

/// Parses `--ellipsoid-shape A,B,C` (three semi-axes > 0, Å) or one A for a sphere.
pub fn parse_ellipsoid_shape(s: &str) -> Result<[f32; 3], String> {
    let axes: Vec<f32> = s
        .split(',')
        .map(|p| match p.trim().parse::<f32>() {
            Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
            _ => Err(format!("{:?} is not a semi-axis > 0 (Å)", p.trim())),
        })
        .collect::<Result<_, _>>()?;
    match axes[..] {
        [a] => Ok([a; 3]),
        [a, b, c] => Ok([a, b, c]),
        _ => Err("expected A,B,C (the semi-axes along the particle's x, y, z, Å)".into()),
    }
}

/// Parses `--slice NX,NY,NZ:D[:W]` into `[nx, ny, nz, d, w]` (w = 0 without one).
pub fn parse_slice(s: &str) -> Result<[f64; 5], String> {
    let parts: Vec<&str> = s.split(':').map(str::trim).collect();
    let number = |t: &str| t.parse::<f64>().ok().filter(|v| v.is_finite());
    let normal: Vec<Option<f64>> = parts[0].split(',').map(|t| number(t.trim())).collect();
    let (normal, d, w) = match (&normal[..], &parts[1..]) {
        ([Some(x), Some(y), Some(z)], [d]) => ([*x, *y, *z], number(d), Some(0.0)),
        ([Some(x), Some(y), Some(z)], [d, w]) => ([*x, *y, *z], number(d), number(w)),
        _ => {
            return Err(
                "expected NX,NY,NZ:D or NX,NY,NZ:D:W (normal, distance, slab width)".into(),
            );
        }
    };
    if normal.iter().all(|v| *v == 0.0) {
        return Err("the normal must not be zero".into());
    }
    match (d, w) {
        (Some(d), Some(w)) if w >= 0.0 => Ok([normal[0], normal[1], normal[2], d, w]),
        _ => Err("the distance must be a number and the width a number >= 0 (Å)".into()),
    }
}

/// Parses a finite number above 0.
pub fn parse_positive(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("{s:?} is not a number above 0")),
    }
}

/// Parses a length that may be 0 (a margin): a finite number ≥ 0.
pub fn parse_non_negative(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("{s:?} is not a number of 0 or more")),
    }
}

/// Parses `--sasa-probe`: a radius from 0 to 10 Å.
pub fn parse_probe(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(r) if (0.0..=10.0).contains(&r) => Ok(r),
        _ => Err(format!("{s:?} is not a probe radius from 0 to 10 Å")),
    }
}

/// Parses `--coordination`: a cutoff in Å from 0.45 (exclusive) to 20.
pub fn parse_cutoff(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(r) if r > 0.45 && r <= texmap_md_io::coordination::MAX_CUTOFF => Ok(r),
        _ => Err(format!("{s:?} is not a cutoff from 0.45 to 20 Å")),
    }
}

/// Parses `--grains`' threshold: degrees, above 0 and at most 30.
pub fn parse_grain_threshold(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(d) if d > 0.0 && d <= 30.0 => Ok(d),
        _ => Err(format!("{s:?} is not an angle from 0 to 30 degrees")),
    }
}

/// The colour maps of `--colormap`.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ColormapArg {
    /// Perceptually uniform, dark blue to yellow (matplotlib's default).
    #[default]
    Viridis,
    /// Perceptually uniform, dark blue through magenta to yellow.
    Plasma,
    /// Diverging blue-white-red, for signed values such as charges.
    Coolwarm,
    /// Rainbow (Google's Turbo), as VMD's default colour scale looks.
    Turbo,
    /// Black to white.
    Gray,
}

/// Parses `LO:HI` of two finite numbers with LO < HI, the names and example `form` gives
/// (`"LO:HI", "0:80"`); `low` is the least value allowed.
fn parse_interval(s: &str, form: (&str, &str), low: f64) -> Result<(f64, f64), String> {
    let (names, example) = form;
    let (lo, hi) = s
        .split_once(':')
        .ok_or_else(|| format!("{s:?}: expected {names}, e.g. {example}"))?;
    let num = |t: &str| {
        t.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v >= low)
            .ok_or_else(|| match low {
                f64::NEG_INFINITY => format!("{t:?} is not a finite number"),
                _ => format!("{t:?} is not a finite number of at least {low}"),
            })
    };
    let (lo, hi) = (num(lo)?, num(hi)?);
    if lo >= hi {
        let (a, b) = names.split_once(':').unwrap_or((names, names));
        return Err(format!("{s}: {a} must be below {b}"));
    }
    Ok((lo, hi))
}

/// Parses `--msd-fit FROM:TO` (finite, 0 ≤ FROM < TO).
pub fn parse_fit_range(s: &str) -> Result<(f64, f64), String> {
    parse_interval(s, ("FROM:TO", "10:90"), 0.0)
}

/// Parses `--color-range LO:HI` (finite, LO < HI).
pub fn parse_color_range(s: &str) -> Result<(f32, f32), String> {
    let (lo, hi) = parse_interval(s, ("LO:HI", "0:80"), f64::NEG_INFINITY)?;
    let (lo, hi) = (lo as f32, hi as f32);
    if !lo.is_finite() || !hi.is_finite() || lo >= hi {
        return Err(format!(
            "{s}: LO and HI must be finite and apart in single precision"
        ));
    }
    Ok((lo, hi))
}

/// `--type-radius NAME=R`: the radius in Å of the atoms NAME selects.
#[derive(Clone, Debug, PartialEq)]
pub struct TypeRadius {
    pub name: String,
    pub radius: f32,
}

/// `--type-color NAME=COLOUR`: the colour (8-bit sRGB) of the atoms NAME selects.
#[derive(Clone, Debug, PartialEq)]
pub struct TypeColor {
    pub name: String,
    pub rgb: [u8; 3],
}

/// Longest NAME: md-io keeps types and names in 15-byte labels.
const MAX_NAME: usize = texmap_md_io::Label::CAPACITY;

/// Splits `NAME=VALUE`, checking NAME.
fn name_value(s: &str) -> Result<(&str, &str), String> {
    let Some((name, value)) = s.split_once('=') else {
        return Err("expected NAME=VALUE".into());
    };
    let name = name.trim();
    if name.is_empty() {
        return Err("NAME before '=' is empty".into());
    }
    if name.len() > MAX_NAME || name.chars().any(char::is_whitespace) {
        return Err(format!(
            "NAME {name:?} must be one word of at most {MAX_NAME} bytes (a type, atom name or element)"
        ));
    }
    Ok((name, value.trim()))
}

/// Parses `--type-radius NAME=R` (R in Å, finite and > 0).
pub fn parse_type_radius(s: &str) -> Result<TypeRadius, String> {
    let (name, value) = name_value(s)?;
    match value.parse::<f32>() {
        Ok(r) if r.is_finite() && r > 0.0 => Ok(TypeRadius {
            name: name.into(),
            radius: r,
        }),
        _ => Err(format!(
            "radius {value:?} is not a number > 0 (Å), e.g. --type-radius O=1.4"
        )),
    }
}

/// Parses a colour: `#rrggbb` (hex) or `R,G,B` with each 0-255, as --background.
pub fn parse_color(value: &str) -> Result<[u8; 3], String> {
    let bad = || {
        format!(
            "colour {value:?}: expected #rrggbb (e.g. #ff8000) or R,G,B with each 0-255 (e.g. 255,128,0)"
        )
    };
    if let Some(hex) = value.strip_prefix('#') {
        if hex.len() != 6 || !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
            return Err(bad());
        }
        let ch = |k: usize| u8::from_str_radix(&hex[2 * k..2 * k + 2], 16).map_err(|_| bad());
        return Ok([ch(0)?, ch(1)?, ch(2)?]);
    }
    let parts: Vec<Option<u8>> = value.split(',').map(|p| p.trim().parse().ok()).collect();
    match parts.as_slice() {
        [Some(r), Some(g), Some(b)] => Ok([*r, *g, *b]),
        _ => Err(bad()),
    }
}

/// Parses `--type-color NAME=#rrggbb|R,G,B`.
pub fn parse_type_color(s: &str) -> Result<TypeColor, String> {
    let (name, value) = name_value(s)?;
    Ok(TypeColor {
        name: name.into(),
        rgb: parse_color(value)?,
    })
}

/// How atoms look: shared by `render` and `compare FILE`.
#[derive(Args, Clone, Debug)]
#[command(next_help_heading = "Atom style")]
pub struct StyleArgs {
    /// How atoms are coloured: property (the file's colour columns, the default), element,
    /// type, chain, structure (helix, strand, coil), or a number per atom through --colormap: bfactor, occupancy, charge, speed,
    /// residue, index or any per-atom column of the file (a LAMMPS dump's c_pe or q, an extended-XYZ
    /// array).
    #[arg(
        long,
        value_name = "SOURCE",
        default_value = "property",
        value_parser = parse_color_by,
        long_help = concat!(
            "How atoms are coloured.\n",
            "  property   the file's per-atom colour columns (extended XYZ `color`, LAMMPS `ColorR ColorG\n",
            "             ColorB`) where it has them, else --type-color, else element colours (default)\n",
            "  element    --type-color, else element colours (CPK/Jmol)\n",
            "  type       --type-color, else one distinct colour per atom type (or name)\n",
            "  chain      --type-color, else one colour per chain (or per segment without chains)\n",
            "  structure  --type-color, else the residue's secondary structure in VMD's colours: helix\n",
            "             purple, strand yellow, coil white (DSSP's hydrogen bonds, as MDAnalysis assigns\n",
            "             them, recomputed every frame); water and ligands keep element colours\n",
            "  cna        --type-color, else the crystal structure type by adaptive common neighbour\n",
            "             analysis in OVITO's colours: FCC green, HCP red, BCC blue, icosahedral yellow,\n",
            "             other white (as OVITO assigns them, recomputed every frame); with --select\n",
            "             'not cna fcc' only the defects, stacking faults and surfaces are drawn\n",
            "  diamond    --type-color, else the diamond structure type (silicon, germanium, carbon,\n",
            "             ice) in OVITO's colours: cubic blue, hexagonal orange, their first and second\n",
            "             neighbours (surfaces, defects) lighter; with --select 'not diamond cubic' only\n",
            "             the defects and surfaces are drawn\n",
            "  ipf        --type-color, else the lattice orientation as an inverse pole figure (EBSD's\n",
            "             IPF-Z: the crystal direction along z; cubic [001] red, [101] green, [111] blue;\n",
            "             hexagonal [0001] red, [2-1-10] green, [10-10] blue), on the FCC, HCP and BCC\n",
            "             atoms of cna, as OVITO's PTM orients them; others white. ipf-x, ipf-y: along x, y\n",
            "  grain      --type-color, else one colour per grain of a polycrystal (--grains), the\n",
            "             largest first\n",
            "A number per atom, mapped through --colormap over --color-range (default: the range of the\n",
            "first frame's drawn atoms, then fixed, so a colour means one value in every frame) with a\n",
            "colour bar (--no-color-bar to leave it out):\n",
            "  bfactor, occupancy   PDB columns 61-66 / 55-60, mmCIF B_iso_or_equiv / occupancy\n",
            "  charge               partial charges of the --topology (PSF, AMBER prmtop, GROMACS tpr/top, LAMMPS data)\n",
            "  speed                |v| in Å/ps (GRO, TRR, NetCDF, LAMMPS vx vy vz, extended XYZ velo)\n",
            "  residue              the residue's position in the file, 0, 1, 2, ... (a rainbow along chains)\n",
            "  index                the atom index\n",
            "  NAME                 any other per-atom column: a LAMMPS dump's c_pe, v_stress, q, mass, an\n",
            "                       extended-XYZ array (`texmap info FILE` lists them as `properties`)\n",
            "Examples: --color-by bfactor --colormap coolwarm   --color-by c_pe --color-range=-4:-2",
        )
    )]
    pub color_by: ColorBy,
    /// The colour map of a numeric --color-by.
    #[arg(long, value_enum, default_value_t = ColormapArg::Viridis)]
    pub colormap: ColormapArg,
    /// The values mapped to the colour map's ends, LO:HI (a numeric --color-by); values beyond
    /// take the end colours. Default: the first frame's range over the drawn atoms.
    #[arg(long, value_name = "LO:HI", value_parser = parse_color_range, allow_hyphen_values = true)]
    pub color_range: Option<(f32, f32)>,
    /// Leave out the colour bar a numeric --color-by draws at the right edge.
    #[arg(long)]
    pub no_color_bar: bool,
    /// Multiply every atom radius (file column, --type-radius or table) by S.
    #[arg(long, default_value_t = 1.0, value_name = "S")]
    pub radius_scale: f32,
    /// Radius in Å of the atoms NAME selects; repeatable. NAME is a type (LAMMPS `type`), an atom
    /// name or an element symbol. Example: --type-radius 1=0.8 --type-radius O=1.4
    #[arg(
        long,
        value_name = "NAME=R",
        value_parser = parse_type_radius,
        long_help = "Radius in Å of the atoms NAME selects; repeatable.\n\
NAME is matched against each atom's type (LAMMPS `type`), its name (PDB/GRO atom name, XYZ\n\
species) and its element (a symbol, any case): an atom takes the rule of its type first, then\n\
of its name, then of its element. A radius column in the file (`radius`, LAMMPS `diameter`)\n\
wins over this flag. --radius-scale multiplies the result.\n\
Examples: --type-radius 1=0.8 --type-radius 2=1.2 (LAMMPS types 1 and 2)\n          \
--type-radius O=1.4 (every oxygen)   --type-radius CA=2.0 (atoms named CA)"
    )]
    pub type_radius: Vec<TypeRadius>,
    /// Colour of the atoms NAME selects, #rrggbb or R,G,B (0-255); repeatable. NAME as for
    /// --type-radius. Example: --type-color 1=#ff8000 --type-color O=255,0,0
    #[arg(
        long,
        value_name = "NAME=COLOUR",
        value_parser = parse_type_color,
        long_help = "Colour of the atoms NAME selects, #rrggbb or R,G,B (each 0-255, sRGB); repeatable.\n\
NAME is matched as for --type-radius (type, then name, then element). With --color-by\n\
property (the default) a colour column in the file (extended XYZ `color`, LAMMPS `ColorR\n\
ColorG ColorB`) wins over this flag; with --color-by element this flag wins over the element\n\
colours; with --color-by type over the per-type palette.\n\
Examples: --type-color 1=#ff8000 --type-color 2=40,40,255 (LAMMPS types 1 and 2)\n          \
--type-color C=#909090 --type-color CA=#00ff00 (alpha carbons green, other carbons grey)"
    )]
    pub type_color: Vec<TypeColor>,
}

#[derive(Args, Debug)]
#[command(after_help = RENDER_AFTER_HELP)]
pub struct RenderArgs {
    /// Trajectory file (any format `texmap info` reads; gzip- or bzip2-compressed files too). A quoted
    /// pattern ('dump.*.lammpstrj', as OVITO's file sequences) reads the files it matches in
    /// natural order (dump.200 before dump.1000) as one trajectory.
    pub file: PathBuf,
    /// More parts of the same trajectory, read after FILE as one: a run continued in parts
    /// (texmap render prod1.xtc prod2.xtc --topology system.gro). Frames are numbered across
    /// the parts; errors name the part and its frame.
    #[arg(value_name = "MORE")]
    pub more: Vec<PathBuf>,
    /// Format, when the extension does not tell it.
    #[arg(long)]
    pub format: Option<String>,
    /// Another file drawn in the same scene, its atoms after FILE's (a ligand beside its
    /// receptor, docking poses around it): 'texmap render poses.sdf --add receptor.pdb' draws
    /// each pose in its pocket, one pose per frame. A file of one frame is drawn with every
    /// frame; one of several frames gives its frame N to frame N, and needs at least as many
    /// as FILE. Each file keeps its own bonds (listed in it, or by distance with --bonds
    /// auto); --topology labels FILE's atoms only. Every atom has the number 'file': 0 for FILE,
    /// 1, 2, ... for the added files in order, so --rep 'prop file == 0=tube' --rep 'prop file
    /// == 1=ball-stick' draws a receptor as a tube and its ligand in balls and sticks.
    /// Repeatable.
    #[arg(long = "add", value_name = "FILE")]
    pub add: Vec<PathBuf>,
    /// Keep the complete frames of a file whose last frame is cut short (a crashed or running
    /// simulation, a partial copy; a .gz whose stream ends early too), with a warning
    /// (default: a cut frame is an error naming the file, frame and byte).
    #[arg(long)]
    pub allow_truncated: bool,
    /// Column names of a LAMMPS binary dump (.bin) from an older LAMMPS, which does not
    /// name them (no magic header, or format revision 1), as the dump custom command lists
    /// them ('id type x y z vx vy vz'); a newer dump names its own. Without them such a file of 5 or 8 values per
    /// atom is read as dump atom's default ('id type xs ys zs [ix iy iz]').
    #[arg(long, value_name = "NAMES")]
    pub lammps_columns: Option<String>,
    /// Frames to render, A:B:STEP (B exclusive, each part optional: "::10", "5:", "3").
    #[arg(long, default_value = "0:")]
    pub frames: String,
    /// Smooth the motion, as VMD's trajectory smoothing: each drawn frame's positions are the
    /// mean over the 2N+1 consecutive frames of the file centred on it (fewer near the ends,
    /// where the window shrinks on both sides so that steady motion is not pulled back; the
    /// first and last frames are drawn as read). Takes the thermal jitter out of a movie.
    /// Positions only, as read, before --pbc and --align; in a periodic box each neighbour
    /// counts at its nearest image, so wrapped atoms do not jump (while no atom moves half a
    /// box within a window).
    #[arg(long, value_name = "N", default_value_t = 0,
          value_parser = clap::value_parser!(u32).range(0..=1000))]
    pub smooth: u32,
    /// Drawing method.
    #[arg(long, value_enum, default_value_t = MethodArg::Raycast)]
    pub method: MethodArg,
    /// Image size, projection and the camera's pose.
    #[command(flatten)]
    pub camera: ViewArgs,
    /// Camera motion over the frames: orbit, keyframes, following a selection.
    #[command(flatten)]
    pub path: PathArgs,
    /// Background: a colour R,G,B (0-255), or `transparent` (PNG alpha 0 where no atom is;
    /// with --aa, edges carry their covered fraction as alpha).
    #[arg(long, default_value = "0,0,0")]
    pub background: String,
    /// Draw the periodic box outline when the file has a box.
    #[arg(long)]
    pub box_outline: bool,
    /// Print resolution, dots per inch: written into each PNG (its pHYs chunk, which Word,
    /// Illustrator, Inkscape and LaTeX read for the printed size), and the pixels of a --size
    /// given in cm, mm or in (--size 8.5cmx6cm --dpi 300 is 1004x709 pixels).
    #[arg(long, value_name = "DPI")]
    pub dpi: Option<f32>,
    /// A coordinate tripod at the bottom left (OVITO's tripod, VESTA's axes): `xyz` the
    /// Cartesian axes, `cell` the frame's cell vectors a, b, c (x, y, z for a frame without a
    /// cell); red, green, blue, turned as the camera sees them (after --align too).
    #[arg(long, value_enum, value_name = "AXES")]
    pub axes_tripod: Option<TripodArg>,
    /// Also write depth as a one-channel EXR beside each PNG (same name, .exr).
    #[arg(long)]
    pub depth: bool,
    /// Also write the cartoon and surface of the first rendered frame as a mesh file, for
    /// Blender, ChimeraX or a 3D printer's slicer: .glb (binary glTF 2.0) or .obj (with its
    /// .mtl and .png beside it); coloured as drawn (a palette texture), 1 unit = 1 Å.
    #[arg(long, value_name = "FILE.glb|FILE.obj")]
    pub export_mesh: Option<PathBuf>,
    /// Anti-alias by supersampling: draw each image at N times its size in each direction and
    /// average each N x N block in linear light (depth: the nearest), with any method, style
    /// and --quality; N² times the drawing time. 3 smooths the edges of cartoons and surfaces
    /// drawn without --quality.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub supersample: u32,
    /// A caption at the top left of every image, on a light backdrop, for movies:
    /// 't = {ns} ns'. {time} is the frame's time in ps, {ns} in ns, {step} its MD step,
    /// {frame} its index in the file, {hbonds} the hydrogen bonds an hbonds representation
    /// draws in it, {vacancies} and {interstitials} the --wigner-seitz counts, {grains} the --grains count, {title} its title (an XYZ comment, a PDB TITLE, a Vina pose's 'VINA
    /// RESULT: -7.5 ...'), and {KEY} the value of KEY=... in the frame's comment, with N decimals
    /// as {KEY:.N}: 'E = {energy:.3} eV' for extended XYZ, ASE trajectories and pw.x outputs; a
    /// file whose frames carry no time (XYZ, PDB) takes {frame}. ASCII
    /// only; the text is cut at half the image width.
    #[arg(long, value_name = "TEXT")]
    pub label: Option<String>,
    /// Label the atoms SEL picks, as PyMOL's and VMD's labels: each gets TEXT just above it,
    /// drawn over the scene on a light backdrop. TEXT may hold {name}, {resname}, {resid},
    /// {chain}, {segid}, {element}, {type}, {index} (from 0), {serial} (from 1) and {id}:
    /// --atom-label 'name CA and resid 10 20 30={resname}{resid}'. Repeatable; the selection
    /// is evaluated every frame, so labels follow their atoms. ASCII, at most 40 characters.
    #[arg(long = "atom-label", value_name = "SEL=TEXT")]
    pub atom_labels: Vec<String>,
    /// Output: PNG image(s) — the name may hold a %04d frame-number pattern; without one, several
    /// frames get _NNNN — or one movie whose extension names its format: .mp4, .webm, .gif
    /// (encoded by ffmpeg: apt-get install ffmpeg) or .apng (no external program). Any other
    /// extension is refused.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Frames per second of a movie output.
    #[arg(long, default_value_t = 25.0)]
    pub fps: f64,
    /// Render only part I of N (0-based) of the frames, as one task of a job array: the frames are
    /// split into N contiguous blocks, each part writes its PNG frames under the names a single
    /// render would give (the camera is fitted to the first frame of the whole render, so the
    /// images are byte-identical), and `texmap movie DIR -o movie.mp4` assembles them. Default:
    /// SLURM_ARRAY_TASK_ID - SLURM_ARRAY_TASK_MIN of SLURM_ARRAY_TASK_COUNT when Slurm sets them.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// Anti-aliasing, ambient occlusion, shadows, depth cueing, outlines.
    #[command(flatten)]
    pub quality: QualityArgs,
    /// Topology, selection, bonds and periodic boundaries.
    #[command(flatten)]
    pub mol: MolArgs,
    /// How atoms look (last: its help heading applies to the fields after it).
    #[command(flatten)]
    pub style: StyleArgs,
}

/// Horizontal field of view (degrees) of `texmap render`'s camera and of `texmap compare FILE`.
pub const DEFAULT_FOV: f32 = 40.0;

/// The camera of `texmap render` (and of `texmap compare FILE`): image size, projection and
/// pose; without --eye/--target/--up it is fitted to what the first frame draws.
#[derive(Args, Clone, Debug)]
pub struct ViewArgs {
    /// Image size WxH in pixels, or (texmap render, with --dpi) in print units: 8.5cmx6cm,
    /// 85mmx60mm, 3.3inx2.4in.
    #[arg(long, default_value = "1280x720")]
    pub size: String,
    /// Orthographic projection (parallel rays).
    #[arg(long)]
    pub ortho: bool,
    /// Horizontal field of view in degrees (the project's convention), perspective only.
    #[arg(long, default_value_t = DEFAULT_FOV)]
    pub fov: f32,
    /// View direction for the automatic camera: auto (a three-quarter view), x, y, z, -x, -y, -z.
    #[arg(long, default_value = "auto", allow_hyphen_values = true)]
    pub view: String,
    /// Camera position X,Y,Z in Å (with --target and --up: exactly this camera, no auto-fit).
    #[arg(long, allow_hyphen_values = true)]
    pub eye: Option<String>,
    /// Point looked at, X,Y,Z in Å.
    #[arg(long, allow_hyphen_values = true)]
    pub target: Option<String>,
    /// Up direction X,Y,Z.
    #[arg(long, allow_hyphen_values = true)]
    pub up: Option<String>,
}

impl Default for ViewArgs {
    fn default() -> ViewArgs {
        ViewArgs {
            size: "1280x720".into(),
            ortho: false,
            fov: DEFAULT_FOV,
            view: "auto".into(),
            eye: None,
            target: None,
            up: None,
        }
    }
}

/// How the camera moves over the frames of a render (`--orbit`, `--orbit-turns`,
/// `--keyframes`, `--follow`).
#[derive(Args, Clone, Debug, Default)]
#[command(next_help_heading = "Camera path")]
pub struct PathArgs {
    /// Turn the camera about the target by DEG degrees per rendered frame, about the image's up
    /// axis (positive: counter-clockwise seen from above).
    #[arg(long, value_name = "DEG", allow_hyphen_values = true, conflicts_with_all = ["orbit_turns", "keyframes"])]
    pub orbit: Option<f32>,
    /// Turn the camera T full turns over the rendered frames; a movie of one turn loops without
    /// a repeated frame (the last frame stops one step short of the first).
    #[arg(
        long,
        value_name = "T",
        allow_hyphen_values = true,
        conflicts_with = "keyframes"
    )]
    pub orbit_turns: Option<f32>,
    /// Camera keyframes, one per line: FRAME EX EY EZ TX TY TZ [UX UY UZ [FOV]] (spaces or
    /// commas; # comments; a CSV header line is skipped). FRAME counts the rendered frames from
    /// 0; the camera passes through every key smoothly (Catmull-Rom) and holds the first and
    /// last pose outside them; a key without UP or FOV takes the automatic camera's.
    #[arg(long, value_name = "FILE")]
    pub keyframes: Option<PathBuf>,
    /// Keep the atoms SEL selects at the same place in the image: the camera (and any orbit or
    /// keyframes) moves with their centre, frame by frame. With a periodic box use --pbc unwrap
    /// so that the centre does not jump when a molecule crosses the box.
    #[arg(long, value_name = "SEL")]
    pub follow: Option<String>,
}

/// `--quality` presets.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum QualityPreset {
    /// The exact ray-cast image, nothing added (the default look).
    Draft,
    /// 4 samples on edges, ambient occlusion with 8 rays, shadows.
    Good,
    /// 16 samples on edges, ambient occlusion with 32 rays, shadows, a 1-pixel black outline.
    Publication,
}

/// Image quality of `texmap render` (ray-cast method, and the reference with the same effects
/// traced: ⌈√aa⌉² samples per pixel, at least as many AO and soft-shadow rays, outlines by the
/// same rule on every sample): each flag overrides its preset's value. A frame with a cartoon,
/// surface, polyhedra, arrows, ellipsoids or an isosurface is traced by the reference with
/// these effects, whatever the method (slower: seconds a frame), so the meshes cast and
/// receive the same occlusion and shadows as the atoms.
#[derive(Args, Clone, Debug, Default)]
#[command(next_help_heading = "Quality (raycast and reference methods)")]
pub struct QualityArgs {
    /// A preset to start from: draft, good, publication (see --help for what each turns on).
    #[arg(long, value_enum)]
    pub quality: Option<QualityPreset>,
    /// Anti-aliasing: samples per pixel on silhouettes and shadow edges (1-256; 1 = off). Only
    /// edge pixels are traced again, so the cost grows with the outline, not the image.
    #[arg(long, value_name = "N")]
    pub aa: Option<u32>,
    /// Ambient occlusion: hemisphere rays per pixel (0-4096; 0 = off), deterministic noise.
    #[arg(long, value_name = "SAMPLES")]
    pub ao: Option<u32>,
    /// How far (Å) an occluder darkens a surface (default: 4 mean atom radii).
    #[arg(long, value_name = "D", allow_hyphen_values = true)]
    pub ao_distance: Option<f32>,
    /// Hard shadows from the key light.
    #[arg(long)]
    pub shadows: bool,
    /// Soft shadows: the key light is a disc (see --light-size) sampled with SAMPLES shadow rays
    /// per point (1-1024); turns shadows on.
    #[arg(long, value_name = "SAMPLES")]
    pub soft_shadows: Option<u32>,
    /// Apparent diameter of the key light for --soft-shadows, in degrees (0-30, default 4;
    /// 0 = hard shadows).
    #[arg(
        long,
        value_name = "DEG",
        allow_hyphen_values = true,
        requires = "soft_shadows"
    )]
    pub light_size: Option<f32>,
    /// Depth cueing: atoms fade toward the background colour from the front to the back of
    /// the scene.
    #[arg(long)]
    pub fog: bool,
    /// A black silhouette line of PX pixels (1-16) where depth jumps, as QuteMol draws.
    #[arg(long, value_name = "PX")]
    pub outline: Option<u32>,
}

/// Where bonds come from (`--bonds`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BondsArg {
    /// The bonds the files list when they list some (the topology's, else an SDF or MOL2
    /// file's own), else by distance (covalent radii + 0.45 Å, minimum image in a periodic box).
    #[default]
    Auto,
    /// Only the bonds the files list (PDB CONECT, PSF !NBOND, prmtop BONDS_*, a .tpr's or
    /// GROMACS .top's chemical bonds, LAMMPS data Bonds, SDF/MOL and MOL2 bond blocks).
    Topology,
    /// No bonds.
    None,
}

/// How `--contacts-table` counts a frame's native pairs.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ContactsMethodArg {
    /// No longer than in the reference (MDAnalysis's hard_cut).
    #[default]
    Hard,
    /// Within the radius (MDAnalysis's radius_cut).
    Radius,
    /// The sigmoid of Best, Hummer and Eaton (MDAnalysis's soft_cut).
    Soft,
}

/// `--pca-landscape-axes`: two different components, each from 1.
fn parse_component_pair(text: &str) -> Result<(u32, u32), String> {
    let bad = || format!("'{text}': expected two different components 'I,J', each from 1 (1,2)");
    let (i, j) = text.split_once(',').ok_or_else(bad)?;
    let i: u32 = i.trim().parse().map_err(|_| bad())?;
    let j: u32 = j.trim().parse().map_err(|_| bad())?;
    if i == 0 || j == 0 || i == j {
        return Err(bad());
    }
    Ok((i, j))
}

/// How `--rmsd-clusters` groups the frames (gmx cluster's -method).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum RmsdClusterMethodArg {
    /// Daura et al.: the frame with the most neighbours within the cutoff and its
    /// neighbours are a cluster; repeated on the frames left (largest clusters first).
    #[default]
    Gromos,
    /// Single linkage: a frame joins any cluster holding a frame within the cutoff (a slow
    /// drift chains shapes together).
    Linkage,
}

/// Which sides of the data `--isosurface` draws.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum IsoSignArg {
    #[default]
    Both,
    Positive,
    Negative,
}

/// How molecules are drawn (`--style`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DrawStyle {
    /// Atoms at their radii, no bonds (VMD's VDW, PyMOL's spheres).
    #[default]
    #[value(alias = "vdw", alias = "spheres")]
    Spacefill,
    /// Atoms at 0.3 of their radii, bonds as sticks of 0.2 Å (VMD's CPK).
    #[value(alias = "cpk", alias = "ball-and-stick")]
    BallStick,
    /// Bonds as sticks of 0.3 Å, atoms as 0.3 Å joints (PyMOL's sticks).
    #[value(alias = "sticks")]
    Licorice,
    /// Protein and nucleic-acid backbones as a smooth 0.3 Å tube through the CA (P) atoms of
    /// each chain (VMD's Tube and Trace); ligands, ions and water as licorice.
    #[value(alias = "trace")]
    Tube,
    /// Protein backbones as a cartoon (VMD's NewCartoon): helices as ribbons, strands as arrows,
    /// coil as a thin tube, from the secondary structure of each frame; nucleic acids as a tube
    /// through the P atoms with a rung to each base; ligands, ions and water as licorice.
    #[value(alias = "newcartoon")]
    Cartoon,
    /// A molecular surface around the atoms (VMD's QuickSurf: the isosurface of one Gaussian per
    /// atom, an isolated atom's at its radius), coloured by the atom nearest under it.
    #[value(alias = "quicksurf", alias = "surf")]
    Surface,
    /// The hydrogen bonds among the atoms as dashed lines from hydrogen to acceptor (VMD's
    /// HBonds), found every frame by MDAnalysis's criterion (see --hbond-distance); needs
    /// explicit hydrogens. Usually one --rep among others: --rep 'protein=cartoon'
    /// --rep 'all=hbonds'.
    #[value(name = "hbonds")]
    HBonds,
    /// Coordination polyhedra (VESTA's): around each atom, the convex hull of the atoms of other
    /// elements bonded to it (at their nearest periodic images), in the atom's colour, lit
    /// flat. Usually one --rep among others: --rep 'all=ball-stick' --rep 'element Ti=polyhedra'.
    Polyhedra,
    /// An arrow from each atom along its vector (OVITO's vector display): --arrows velocity
    /// (the default), displacement (from the first frame drawn) or a property stem (f for a
    /// LAMMPS dump's fx fy fz), times --arrow-scale. Usually one --rep among others:
    /// --rep 'all=ball-stick' --rep 'all=arrows'.
    Arrows,
    /// The paths the atoms (picked at the first frame) took over the frames drawn so far, as
    /// thin tubes unwrapped across the box (OVITO's trajectory lines); --trail-length N keeps
    /// the last N frames. Usually one --rep among others: --rep 'all=ball-stick'
    /// --rep 'resname LI=trails'.
    Trails,
    /// Each atom as an ellipsoid (OVITO's aspherical particles: LAMMPS atom_style ellipsoid,
    /// Gay-Berne liquid crystals): the semi-axes are half the shapex shapey shapez properties
    /// (LAMMPS's diameters) or --ellipsoid-shape A,B,C for every atom, the orientation the
    /// quatw quati quatj quatk properties (none: the axes along x, y, z). An atom of shape
    /// 0 0 0 (a LAMMPS sphere) stays a sphere. Tessellated no finer than the picture needs.
    Ellipsoids,
}

/// The axes of `--axes-tripod`.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum TripodArg {
    /// The Cartesian x, y, z.
    Xyz,
    /// The cell vectors a, b, c.
    Cell,
}

/// Periodic boundaries (`--pbc`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PbcArg {
    /// Positions as the file has them (bonds across the box are not drawn).
    #[default]
    None,
    /// Every atom moved into the box.
    Wrap,
    /// Bonded molecules made whole across the box.
    Unwrap,
}

/// What `--wigner-seitz` draws.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum WignerSeitzArg {
    /// The reference's sites instead of the atoms, each with 'site_occupancy' (OVITO's
    /// default): --select 'prop site_occupancy != 1' shows vacancies (0) and interstitial sites
    /// (2 or more).
    Sites,
    /// The atoms, each with the occupancy of its site: --select 'prop site_occupancy > 1'
    /// shows the interstitial atoms (both atoms of a dumbbell).
    Atoms,
}

/// `texmap render` options for molecules: topology, selection, per-selection looks, bonds,
/// periodic boundaries.
#[derive(Args, Clone, Debug, Default)]
#[command(next_help_heading = "Molecules")]
pub struct MolArgs {
    /// Topology giving names, elements, residues and bonds to a trajectory of the same atoms
    /// (XTC, DCD, TRR, NetCDF carry coordinates only): PDB (CONECT bonds), PDBx/mmCIF or a crystallographic CIF (.cif), BinaryCIF (.bcif),
    /// GRO, a CHARMM/NAMD PSF (.psf: !NBOND bonds), an AMBER prmtop (.prmtop, .parm7: bonds,
    /// chains), a GROMACS run input (.tpr: the force field's bonds, masses, charges, molecule
    /// types as segments) or topology (.top with its #included .itp files, the same), or a
    /// LAMMPS data file (.data, .lmp, data.*).
    #[arg(long, value_name = "FILE")]
    pub topology: Option<PathBuf>,
    /// A periodic cell for frames whose file holds none (plain XYZ, CP2K, ORCA, xtb), or to
    /// replace the file's: A,B,C in Å (right angles) or A,B,C,ALPHA,BETA,GAMMA (degrees), as
    /// VMD's 'pbc set {A B C}'; or a CP2K cell file (PROJECT-1.cell), each frame's cell found by
    /// its step (the 'i =' of CP2K's .xyz comment lines; a step the file lacks is an error).
    /// --pbc, --replicate and --box-outline then work on such trajectories.
    #[arg(long, value_name = "A,B,C[,ANGLES]|FILE.cell")]
    pub cell: Option<String>,
    /// A GROMACS index file (.ndx, from gmx make_ndx or gmx select -on): its groups become the
    /// selection keyword 'group NAME' or 'group N' (numbered from 0 as make_ndx lists them; a
    /// name matches exactly, in any case or by a unique prefix, as GROMACS matches it; quote a
    /// name with parentheses): --index index.ndx --select 'group Protein_LIG or group 13'.
    #[arg(long, value_name = "FILE.ndx")]
    pub index: Option<PathBuf>,
    /// Preprocessor defines for a GROMACS --topology .top, as in the run's .mdp ('define =
    /// -DPOSRES -DHEAVY_H'): --define HEAVY_H --define POSRES (or NAME=VALUE). Give the ones
    /// grompp was given, or masses and bonds that depend on them differ from the run's.
    #[arg(long, value_name = "NAME")]
    pub define: Vec<String>,
    /// Draw only the atoms SEL selects, in the VMD/MDAnalysis language: 'not resname SOL',
    /// 'name CA', 'element O and resid 1 to 20', 'chain A', 'segid PROA',
    /// 'protein or within 5 of resname LIG', 'byres around 5 resname LIG' (whole residues),
    /// 'same resname as within 3 of name NA', 'helix', 'not cna fcc' (crystal defects), 'prop bfactor > 50' (VMD: 'beta > 50'),
    /// 'prop abs charge > 0.5', 'mass 30 to 40', 'bonded name CA', 'same fragment as resname LIG',
    /// 'sphzone 8 resname LIG' (about its centre), 'cyzone 10 5 -5 resname LIG',
    /// 'isolayer 0 3.5 protein' (a solvation shell), 'group Pocket' (with --index).
    /// within/around/byres/same...as and the zones take the rest of the expression,
    /// as MDAnalysis reads it: parenthesise to end them sooner. within and around reach through
    /// the periodic box, as MDAnalysis's do.
    #[arg(long, value_name = "SEL")]
    pub select: Option<String>,
    /// Colour of the atoms SEL selects, #rrggbb or R,G,B: --color 'resname SOL=#4080ff';
    /// repeatable, applied in order (a later rule wins), over every other colour source.
    #[arg(long = "color", value_name = "SEL=COLOUR")]
    pub color_rules: Vec<String>,
    /// Radius in Å (before --radius-scale) of the atoms SEL selects: --radius 'name CA=2';
    /// repeatable, applied in order, over every other radius source.
    #[arg(long = "radius", value_name = "SEL=R")]
    pub radius_rules: Vec<String>,
    /// Bonds: auto (the files' bonds, else by distance), topology (the files' only), none.
    #[arg(long, value_enum, default_value_t = BondsArg::Auto)]
    pub bonds: BondsArg,
    /// Drawing style: spacefill, ball-stick, licorice (the last two draw bonds), tube (backbones
    /// as a tube, other atoms as licorice), cartoon (helix ribbons, strand arrows, coil tubes; other
    /// atoms as licorice), surface (a molecular surface, see --surface-spacing), hbonds (hydrogen
    /// bonds as dashed lines, see --hbond-distance).
    #[arg(long = "style", value_enum, default_value_t = DrawStyle::Spacefill)]
    pub draw: DrawStyle,
    /// The surface style's grid spacing in Å: finer cuts the surface into more, smaller
    /// triangles (every vertex lies on the exact surface whatever the spacing). A system whose
    /// grid would pass 2^25 samples is sampled coarser, with a warning.
    #[arg(long, value_name = "Å", default_value_t = 0.5)]
    pub surface_spacing: f32,
    /// The surface style's radius scale: an isolated atom's surface lies at this multiple of its
    /// radius (1: the van der Waals surface, smoothed where atoms overlap; 1.4 is fuller).
    #[arg(long, value_name = "S", default_value_t = 1.0)]
    pub surface_scale: f32,
    /// The surface style's opacity, 0.05 to 1: below 1 the surface's front is laid over what
    /// lies behind it (mixed in linear light), so a cartoon or ligand inside shows through, as
    /// VMD's Transparent material (one layer: the surface's back is not seen through its front).
    #[arg(long, value_name = "A", default_value_t = 1.0)]
    pub surface_opacity: f32,
    /// Colour the molecular surface (--style surface, or a --rep's) by volumetric data at its
    /// vertices, as PyMOL and VMD colour a surface by an APBS electrostatic potential: an
    /// OpenDX file (APBS's pqr.dx, a --density-map), a CCP4/MRC map, or a cube, XSF or CHGCAR-family file in
    /// the structure's coordinates (its first data set), through --volume-colormap over
    /// --volume-range (fixed at the first frame), with a colour bar. `--volume-range 5:-5`
    /// draws an APBS potential in kT/e as PyMOL does: negative red, positive blue. Surface
    /// outside the grid is grey.
    #[arg(long, value_name = "FILE")]
    pub surface_color_by: Option<PathBuf>,
    /// The polyhedra style's opacity, 0.05 to 1: below 1 the polyhedra's fronts are laid over
    /// what lies behind them (the centre atoms, when another --rep draws them), as the surface's.
    #[arg(long, value_name = "A", default_value_t = 1.0)]
    pub polyhedra_opacity: f32,
    /// Draw the isosurface of volumetric data at this level, as VMD, VESTA and Avogadro do: the
    /// volume of a Gaussian cube file, an XSF file's DATAGRID_3D or a VASP CHGCAR / PARCHG /
    /// LOCPOT / ELFCAR given as the input, or of --volume (also an OpenDX file: an APBS
    /// potential, a --density-map; or a CCP4/MRC map: a cryo-EM density). Where the data also runs below −LEVEL (an orbital's
    /// negative lobe, a negative potential) that surface is drawn too, in
    /// --isosurface-negative-color (see --isosurface-sign). A CHGCAR's density is in e/Å³, a
    /// cube or XSF file's values as written (often e/bohr³), APBS's in kT/e, a density map's
    /// in atoms/Å³; `texmap info FILE` prints each data set's range. Not with --align-to, which would move
    /// the atoms away from the grid.
    #[arg(
        long,
        value_name = "LEVEL",
        allow_negative_numbers = true,
        conflicts_with = "align_to"
    )]
    pub isosurface: Option<f32>,
    /// The volumetric data for --isosurface and --volume-slice when the input is not itself a
    /// cube, XSF or CHGCAR file: render a POSCAR or PDB with the density of another file, an
    /// OpenDX file's (.dx: APBS's electrostatic potential, VMD's volmap, MDAnalysis's or
    /// --density-map's densities) or a CCP4/MRC map's (.mrc, .map, .ccp4: a cryo-EM map with
    /// its fitted model). Its grid must be in the same coordinates.
    #[arg(long, value_name = "FILE")]
    pub volume: Option<PathBuf>,
    /// Which data set of the volumetric file --isosurface and --volume-slice draw, from 1: a
    /// CHGCAR's 1 is the
    /// total density and 2 the magnetisation (spin-polarised runs); a cube file's the orbitals
    /// in the order it lists them; an XSF file's its grids in file order.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub volume_set: usize,
    /// Which sides --isosurface draws: both (+LEVEL and −LEVEL where the data reaches it),
    /// positive (+LEVEL only) or negative (−LEVEL only).
    #[arg(long, value_enum, default_value_t = IsoSignArg::Both)]
    pub isosurface_sign: IsoSignArg,
    /// Colour of the +LEVEL surface, #rrggbb or R,G,B.
    #[arg(long, value_name = "COLOUR", default_value = "#3b6fd8")]
    pub isosurface_color: String,
    /// Colour of the −LEVEL surface, #rrggbb or R,G,B.
    #[arg(long, value_name = "COLOUR", default_value = "#d84a3b")]
    pub isosurface_negative_color: String,
    /// Colour the isosurface by the values of another volumetric file at its vertices, as an
    /// electrostatic potential is mapped onto an electron density surface (GaussView's and
    /// VMD's ESP maps): a cube, XSF, OpenDX (APBS) or CHGCAR-family file in the same coordinates, through
    /// --volume-colormap over --volume-range, with a colour bar.
    #[arg(long, value_name = "FILE", requires = "isosurface")]
    pub isosurface_color_by: Option<PathBuf>,
    /// Draw a plane through the volumetric data coloured by its values, as VESTA draws a
    /// section and VMD a VolumeSlice: AXIS (a, b or c: the grid's first, second or third axis,
    /// a VASP file's lattice vectors) and the position along it as a fraction of the grid
    /// (0 to 1), through --volume-colormap over --volume-range, with a colour bar. The data are
    /// the input's (or --volume's, --volume-set). Repeatable: --volume-slice c:0.5
    /// --volume-slice a:0.
    #[arg(
        long = "volume-slice",
        value_name = "AXIS:F",
        conflicts_with = "align_to"
    )]
    pub volume_slices: Vec<String>,
    /// The colour map of --isosurface-color-by, --surface-color-by and --volume-slice.
    #[arg(long, value_enum, default_value_t = ColormapArg::Coolwarm)]
    pub volume_colormap: ColormapArg,
    /// The values at the two ends of --volume-colormap, LO:HI (default: ±the largest
    /// magnitude drawn for values of both signs, else their range). HI:LO reverses the map:
    /// --volume-range 0.05:-0.05 with coolwarm draws negative potentials red and positive
    /// ones blue, GaussView's convention.
    #[arg(long, value_name = "LO:HI", allow_hyphen_values = true)]
    pub volume_range: Option<String>,
    /// The opacity of --isosurface's surfaces and --volume-slice's planes, 0.05 to 1 (below 1
    /// the atoms inside show through, as the surface style's --surface-opacity).
    #[arg(long, value_name = "A", default_value_t = 1.0)]
    pub isosurface_opacity: f32,
    /// The arrows style's vectors: `velocity` (the file's, Å/ps), `displacement` (from the
    /// first frame drawn or --displacement-reference, to the nearest periodic image: OVITO's
    /// Displacements) or the stem of
    /// three per-atom properties (`f` for a LAMMPS dump's fx fy fz, `c_disp` for
    /// c_disp[1] c_disp[2] c_disp[3]).
    #[arg(long, value_name = "SOURCE", default_value = "velocity")]
    pub arrows: String,
    /// The arrows style's length per unit of the vector (Å per Å/ps for velocities; 1 draws a
    /// displacement at its true length).
    #[arg(long, value_name = "S", default_value_t = 1.0)]
    pub arrow_scale: f32,
    /// The arrows style's shaft radius, Å (the head is 2.5 times as wide).
    #[arg(long, value_name = "Å", default_value_t = 0.1)]
    pub arrow_radius: f32,
    /// The ellipsoids style's semi-axes for every atom, Å: A,B,C along the particle's own x, y,
    /// z (its quatw..quatk orientation), instead of the file's shapex shapey shapez.
    #[arg(long, value_name = "A,B,C", value_parser = parse_ellipsoid_shape)]
    pub ellipsoid_shape: Option<[f32; 3]>,
    /// The trails style's length in frames drawn (the current one included); default: every
    /// frame drawn so far.
    #[arg(long, value_name = "N")]
    pub trail_length: Option<usize>,
    /// Draw the bond orders an SDF/MOL or MOL2 file gives (PyMOL's valence mode) in the
    /// ball-stick and licorice styles: double bonds as two sticks, triple as three, aromatic
    /// as a stick with a dashed line inside the ring.
    #[arg(long)]
    pub bond_orders: bool,
    /// Draw each atom with the radius (Å) a per-atom property gives: PQR's 'radius'
    /// (PDB2PQR/APBS radii), any dump column (texmap info lists them), --property FILE's
    /// numbers. As a file's radius column: --radius-scale does not apply, ball-and-stick
    /// scales it. Zero, negative or missing values leave the element's radius.
    #[arg(long, value_name = "PROPERTY")]
    pub radius_from: Option<String>,
    /// Cut the system open, as OVITO's Slice modifier: 'NX,NY,NZ:D' keeps the atoms behind the
    /// plane n·x = D (n the unit normal: the side n points away from), 'NX,NY,NZ:D:W' the
    /// slab of width W Å centred on it: --slice 1,1,1:20:6 shows one (111) slab of an FCC
    /// crystal, --slice 0,0,1:0 the lower half of a membrane. Only the drawing is cut, as by a
    /// Slice at the end of an OVITO pipeline: colourings (cna, coordination, structure) and
    /// selections see the whole system, so atoms at the cut keep their crystal structure. The
    /// plane is placed after --align, so it stays put relative to an aligned molecule.
    #[arg(long, value_name = "NX,NY,NZ:D[:W]", value_parser = parse_slice, allow_hyphen_values = true)]
    pub slice: Option<[f64; 5]>,
    /// Keep the atoms --slice would remove instead (the other side, or all but the slab).
    #[arg(long, requires = "slice")]
    pub slice_invert: bool,
    /// A representation, as VMD's: 'SEL=STYLE' draws the atoms SEL selects in STYLE (spacefill,
    /// ball-stick, licorice, tube, cartoon, surface, hbonds), each with its own radii and bond radius; repeat it
    /// to draw several in one image: --rep 'protein=tube' --rep 'resname LIG=ball-stick'
    /// --rep 'water and within 5 of resname LIG=licorice'; --rep 'protein=surface' --rep
    /// 'resname LIG=ball-stick' shows a ligand in its pocket (surface representations share
    /// one surface). 'SEL=STYLE:COLOUR' gives it its own
    /// colouring: element, type, chain, structure, cna, property, or one colour #rrggbb or R,G,B
    /// (--rep 'protein=tube:structure' --rep 'resname LIG=ball-stick:element'); without one it
    /// takes --color-by, and --color rules win over both. Replaces --select and --style; an
    /// atom two representations select is drawn by both.
    #[arg(
        long = "rep",
        value_name = "SEL=STYLE[:COLOUR]",
        conflicts_with_all = ["select", "draw"]
    )]
    pub reps: Vec<String>,
    /// The analyses, periodic boundaries and alignment applied to every frame.
    #[command(flatten)]
    pub analysis: AnalysisArgs,
}

impl AnalysisArgs {
    /// Every output of the analyses (tables, maps, charts) by its flag, and whether it was given.
    pub fn outputs(&self) -> Vec<(&'static str, bool)> {
        [
            ("--rdf-table", &self.rdf_table),
            ("--msd-table", &self.msd_table),
            ("--msd-lags", &self.msd_lags),
            ("--vacf-table", &self.vacf_table),
            ("--vdos-table", &self.vdos_table),
            ("--rmsd-table", &self.rmsd_table),
            ("--rmsf-table", &self.rmsf_table),
            ("--profile-table", &self.profile_table),
            ("--dihedral-table", &self.dihedral_table),
            ("--sasa-table", &self.sasa_table),
            ("--sasa-residue-table", &self.sasa_residue_table),
            ("--gyration-table", &self.gyration_table),
            ("--cluster-table", &self.cluster_table),
            ("--grain-table", &self.grain_table),
            ("--defect-table", &self.defect_table),
            ("--density-map", &self.density_map),
            ("--contacts-table", &self.contacts_table),
            ("--survival-table", &self.survival_table),
            ("--pca-table", &self.pca_table),
            ("--pca-projection", &self.pca_projection),
            ("--pca-vectors", &self.pca_vectors),
            ("--pca-extremes", &self.pca_extremes),
            ("--pca-landscape", &self.pca_landscape),
            ("--pca-landscape-table", &self.pca_landscape_table),
            ("--dssp-table", &self.dssp_table),
            ("--dssp-residue-table", &self.dssp_residue_table),
            ("--dssp-timeline", &self.dssp_timeline),
            ("--measure-table", &self.measure_table),
            ("--rmsd-matrix", &self.rmsd_matrix),
            ("--hbond-table", &self.hbond_table),
            ("--hbond-lifetime", &self.hbond_lifetime),
            ("--hbond-occupancy", &self.hbond_occupancy),
            ("--saltbridge-table", &self.saltbridge_table),
            ("--saltbridge-occupancy", &self.saltbridge_occupancy),
            ("--rmsd-matrix-chart", &self.rmsd_matrix_chart),
            ("--ramachandran", &self.ramachandran),
            ("--distance-map", &self.distance_map),
            ("--distance-map-chart", &self.distance_map_chart),
            ("--contact-map", &self.contact_map),
            ("--contact-map-chart", &self.contact_map_chart),
            ("--rmsd-clusters", &self.rmsd_clusters),
            ("--rmsd-cluster-table", &self.rmsd_cluster_table),
            ("--rmsd-cluster-middles", &self.rmsd_cluster_middles),
            ("--order-table", &self.order_table),
            ("--order-chart", &self.order_chart),
            ("--membrane-table", &self.membrane_table),
        ]
        .into_iter()
        .map(|(flag, path)| (flag, path.is_some()))
        .collect()
    }
}

/// What `texmap render` and `texmap convert` do to every frame before it is drawn or written:
/// periodic boundaries, periodic images, per-atom analyses (OVITO's modifiers), properties from
/// files and formulas, alignment, and the per-frame tables of the analyses.
#[derive(Args, Clone, Debug, Default)]
#[command(next_help_heading = "Analysis")]
#[command(group(clap::ArgGroup::new("pca_out").multiple(true)
    .args(["pca_table", "pca_projection", "pca_vectors", "pca_extremes", "pca_landscape",
        "pca_landscape_table"])))]
#[command(group(clap::ArgGroup::new("pca_landscape_out").multiple(true)
    .args(["pca_landscape", "pca_landscape_table"])))]
#[command(group(clap::ArgGroup::new("rmsd_matrix_out").multiple(true)
    .args(["rmsd_matrix", "rmsd_matrix_chart", "rmsd_clusters", "rmsd_cluster_table",
        "rmsd_cluster_middles"])))]
#[command(group(clap::ArgGroup::new("residue_map_out").multiple(true)
    .args(["distance_map", "distance_map_chart", "contact_map", "contact_map_chart"])))]
#[command(group(clap::ArgGroup::new("saltbridge_out").multiple(true)
    .args(["saltbridge_table", "saltbridge_occupancy"])))]
#[command(group(clap::ArgGroup::new("rmsd_cluster_out").multiple(true)
    .args(["rmsd_clusters", "rmsd_cluster_table", "rmsd_cluster_middles"])))]
pub struct AnalysisArgs {
    /// Give every atom the property `displacement`: its distance (Å) from where it was in the
    /// first frame drawn (or --displacement-reference), to the nearest periodic image (OVITO's
    /// Displacements modifier), for
    /// selections (--select 'prop displacement > 2') and colours (--color-by displacement
    /// turns it on by itself).
    #[arg(long)]
    pub displacements: bool,
    /// Give the atoms a property NAME read from FILE, for --color-by NAME and selections
    /// ('prop NAME > 0.5'), as VMD's user field or PyMOL's alter b=: one number per line (the
    /// same for every frame) or one row per frame of one number per atom (frame f takes row
    /// f), separated by spaces or commas; '#' comments; nan for no value; or a table whose
    /// header row names a column NAME, one row per atom (a CSV from pandas, or --rmsf-table's).
    /// The atoms of FILE (the trajectory), not of --add's files. Repeatable: --property
    /// rmsf=rmsf.csv.
    #[arg(long = "property", value_name = "NAME=FILE")]
    pub properties: Vec<String>,
    /// Measure displacements (--displacements, --color-by displacement, --arrows
    /// displacement) and --strain from this reference instead of the first frame drawn: a frame number of
    /// the trajectory (0 for its first) or a structure file of the same atoms (its first
    /// frame), OVITO's reference configuration. It is wrapped, unwrapped, replicated and
    /// aligned as the frames are; with --align, the frames are superposed on it.
    #[arg(long, value_name = "FRAME|FILE")]
    pub displacement_reference: Option<String>,
    /// Periodic boundaries: none, wrap (atoms into the box), unwrap (molecules whole).
    #[arg(long, value_enum, default_value_t = PbcArg::None)]
    pub pbc: PbcArg,
    /// Draw NX x NY x NZ periodic images of the cell, as OVITO's Replicate modifier: '3,3,1'
    /// shows a slab as the surface it models, '2' a 2x2x2 block. Images run from -(N-1)/2 to
    /// N/2 along each cell vector (2 is the cell and the next one, 3 is centred on it); bonds
    /// across the faces join the neighbouring copy, so a crystal's bonds are whole inside the
    /// block. After --pbc (wrap first for a tidy block); every selection, colour rule and
    /// --align sees the copies (atom ids are offset per copy so they stay unique, as in OVITO).
    /// Needs a periodic cell.
    #[arg(long, value_name = "NX,NY,NZ", value_parser = parse_replicate)]
    pub replicate: Option<[usize; 3]>,
    /// Count each atom's neighbours within R Å every frame, as OVITO's Coordination analysis,
    /// into the per-atom number 'coordination': colour by it (--color-by coordination) or
    /// select by it (--select 'prop coordination < 12' leaves the surface and the atoms next to
    /// vacancies of an FCC crystal; pick R between the first and second neighbour shells).
    /// Counted after --pbc and --replicate, under the minimum image; a periodic cell narrower
    /// than 3 R is refused (replicate it). R from 0.45 to 20 Å.
    #[arg(long, value_name = "R", value_parser = parse_cutoff)]
    pub coordination: Option<f32>,
    /// Group atoms into clusters of neighbours within R Å every frame, as OVITO's Cluster
    /// analysis (sorted by size; ids from 0, the largest, as OVITO 3.17 numbers them), into the
    /// per-atom number 'cluster': --color-by cluster gives each cluster its own colour, --select
    /// 'prop cluster == 0' keeps the largest (a precipitate, a droplet, the percolating
    /// network). Counted after --coordination, under the minimum image (a periodic cell
    /// narrower than 3 R is refused). R from 0.45 to 20 Å.
    #[arg(long, value_name = "R", value_parser = parse_cutoff)]
    pub clusters: Option<f32>,
    /// Cluster only the atoms this selection picks (e.g. 'element Cu' for precipitates in a
    /// matrix, 'prop coordination >= 10' for solid-like atoms); the others are in cluster -1.
    #[arg(long, value_name = "SEL", requires = "clusters")]
    pub cluster_atoms: Option<String>,
    /// Also write the size and shape of --gyration-select's atoms every frame as a CSV table
    /// (MDAnalysis's radius_of_gyration and asphericity, gmx gyrate): frame, time (ps, when the
    /// file has it), rg (Å), rg_x, rg_y, rg_z (about the axes through the centre) and
    /// asphericity (the gyration tensor's relative shape anisotropy: 0 a sphere, 1 a rod),
    /// mass-weighted (the masses a .tpr or LAMMPS data file gives, else the elements') unless
    /// --gyration-unweighted. The atoms are taken as they are after --pbc:
    /// give --pbc unwrap for a molecule the trajectory wrapped. Written whole or not at all.
    #[arg(long, value_name = "FILE.csv")]
    pub gyration_table: Option<PathBuf>,
    /// Also write the fraction of native contacts every frame as a CSV table (MDAnalysis's
    /// contacts.Contacts: the folding coordinate Q): frame, time (ps, when the file has it),
    /// q. The native contacts are the pairs of the two --contacts groups within
    /// --contacts-radius in the first frame written or drawn (every pair MDAnalysis counts:
    /// both orders, and an atom with itself, when the groups overlap); distances to the nearest
    /// periodic image. Written whole or not at all.
    #[arg(long, value_name = "FILE.csv", requires = "contacts")]
    pub contacts_table: Option<PathBuf>,
    /// Also write how long atoms stay in --survival-select, a selection evaluated every frame
    /// (water in a protein's first shell: 'name OW and around 3.5 protein'), as a CSV table:
    /// lag (frames), time (ps, when the frames' times are evenly spaced), survival: of the
    /// atoms selected at a frame, the share selected at every frame up to the lag, averaged
    /// over every frame as the origin (the waterdynamics MDAKit's SurvivalProbability). Prints
    /// the residence time ∫ S dτ up to --survival-max. Written whole or not at all; not with
    /// --shard.
    #[arg(long, value_name = "FILE.csv", requires = "survival_select")]
    pub survival_table: Option<PathBuf>,
    /// The atoms whose stay --survival-table measures (a selection re-evaluated every frame).
    #[arg(long, value_name = "SEL", requires = "survival_table")]
    pub survival_select: Option<String>,
    /// The longest lag of --survival-table, in frames (the MDAKit's tau_max).
    #[arg(
        long,
        value_name = "FRAMES",
        default_value_t = 20,
        requires = "survival_table"
    )]
    pub survival_max: usize,
    /// --survival-table counts an atom absent for up to N consecutive frames between two frames
    /// that select it as staying (the MDAKit's intermittency; 0 is the continuous survival).
    #[arg(
        long,
        value_name = "N",
        default_value_t = 0,
        requires = "survival_table"
    )]
    pub survival_intermittency: usize,
    /// The hydrogen bonds' largest donor-acceptor distance (the hbonds style's, --hbonds'), Å (MDAnalysis's default 3.0; up to
    /// 6). A hydrogen bonded to an N or O donates to an N or O acceptor within it when the
    /// donor-hydrogen-acceptor angle is at least --hbond-angle; distances use the nearest
    /// periodic image.
    #[arg(long, value_name = "Å", default_value_t = texmap_md_io::hbonds::DEFAULT_DISTANCE)]
    pub hbond_distance: f32,
    /// The hydrogen bonds' smallest donor-hydrogen-acceptor angle, degrees (MDAnalysis's
    /// default 150; VMD's angle cutoff of 20 is 160 here).
    #[arg(long, value_name = "DEG", default_value_t = texmap_md_io::hbonds::DEFAULT_ANGLE)]
    pub hbond_angle: f32,
    /// Also write the hydrogen bonds as a CSV table, one row per bond and frame (texmap render:
    /// those its hbonds style draws; texmap convert: those among --hbonds' atoms): frame, donor, hydrogen, acceptor (0-based atom indices, as MDAnalysis's
    /// results.hbonds), the three atoms as RESNAME RESID:NAME, the donor-acceptor distance (Å)
    /// and the donor-hydrogen-acceptor angle (degrees). Written whole or not at all.
    #[arg(long, value_name = "FILE.csv")]
    pub hbond_table: Option<PathBuf>,
    /// Also write how long the hydrogen bonds (as --hbond-table's) last, as a CSV table (MDAnalysis's
    /// HydrogenBondAnalysis.lifetime): lag (frames drawn), time (ps, when the frames' times
    /// are evenly spaced), survival: of the bonds at a frame, the share present at every frame
    /// up to the lag, averaged over every frame as the origin (a bond is its hydrogen and
    /// acceptor). Prints the lifetime, ∫ S dτ by the trapezoid rule up to --hbond-lifetime-max
    /// (longer when S has not decayed there). Written whole or not at all; not with --shard.
    #[arg(long, value_name = "FILE.csv")]
    pub hbond_lifetime: Option<PathBuf>,
    /// Also write each hydrogen bond's occupancy over the run as a CSV table (VMD's hbonds
    /// plugin's detailed output, MDAnalysis's count_by_ids): one row per donor, hydrogen and
    /// acceptor seen (the bonds of --hbond-table), the most present first: the three atom
    /// indices and labels, frames present, occupancy (the fraction of the frames), the mean
    /// distance (Å) and angle (degrees) while present. Written whole or not at all; not with
    /// --shard.
    #[arg(long, value_name = "FILE.csv")]
    pub hbond_occupancy: Option<PathBuf>,
    /// The longest lag of --hbond-lifetime, in frames drawn (MDAnalysis's tau_max).
    #[arg(
        long,
        value_name = "FRAMES",
        default_value_t = 20,
        requires = "hbond_lifetime"
    )]
    pub hbond_lifetime_max: usize,
    /// --hbond-lifetime counts a bond absent for up to N consecutive frames between two
    /// frames that have it as unbroken (MDAnalysis's intermittency; 0, the default, is the
    /// continuous lifetime).
    #[arg(
        long,
        value_name = "N",
        default_value_t = 0,
        requires = "hbond_lifetime"
    )]
    pub hbond_intermittency: usize,
    /// Also write the salt bridges as a CSV table, one row per bridge and frame (VMD's Salt
    /// Bridges plugin, saltbr): an acidic residue (ASP, GLU) and a basic one (ARG, LYS; HIS with
    /// --saltbridge-his) form one when any oxygen of the acid's side chain (OD1 OD2 / OE1 OE2)
    /// and any nitrogen of the base's (NH1 NH2 NE / NZ / ND1 NE2) are within
    /// --saltbridge-cutoff, through the nearest periodic image; the termini do not count.
    /// Columns: frame, time (ps, when the file has it), acid and base (RESNAME RESID), their
    /// chains, distance (Å, between the oxygens' and the nitrogens' centroids: what saltbr
    /// writes per bridge) and min_distance (Å, the shortest O-N distance). Only the frames a
    /// bridge is formed in have its row (saltbr lists every frame of a bridge formed once).
    /// Among --saltbridge-select's atoms. Written whole or not at all; not with --shard.
    #[arg(long, value_name = "FILE.csv")]
    pub saltbridge_table: Option<PathBuf>,
    /// Also write each salt bridge's occupancy over the run as a CSV table (as --hbond-occupancy
    /// for hydrogen bonds): one row per acid-base residue pair formed in some frame (the
    /// bridges of --saltbridge-table), the most present first: acid, base, their chains,
    /// frames present, occupancy (the fraction of the frames), the mean centroid distance and
    /// the mean shortest O-N distance (Å) while present. Written whole or not at all; not with
    /// --shard.
    #[arg(long, value_name = "FILE.csv")]
    pub saltbridge_occupancy: Option<PathBuf>,
    /// The salt bridges' largest oxygen-nitrogen distance, Å (VMD saltbr's default 3.2; up to
    /// 8; 4.0 is the other common choice, as Barlow and Thornton's).
    #[arg(long, value_name = "Å", default_value_t = texmap_md_io::saltbridges::DEFAULT_CUTOFF,
          requires = "saltbridge_out")]
    pub saltbridge_cutoff: f32,
    /// The atoms among which --saltbridge-table and --saltbridge-occupancy look for salt
    /// bridges (saltbr's selection; 'protein' by default, 'chain A or chain B' for the bridges
    /// of two chains).
    #[arg(
        long,
        value_name = "SEL",
        default_value = "protein",
        requires = "saltbridge_out"
    )]
    pub saltbridge_select: String,
    /// Count histidines (every spelling: HIS, HSD, HSE, HSP, HID, HIE, HIP, HISA, HISB, HISH...)
    /// as basic for the salt bridges, through ND1 and NE2. Off by default, since a file's
    /// histidine names rarely say which are charged (VMD's basic macro takes HIS and HSP).
    #[arg(long, requires = "saltbridge_out")]
    pub saltbridge_his: bool,
    /// Measure, as PyMOL's distance, angle and dihedral: 'SEL; SEL' (a distance, Å),
    /// 'SEL; SEL; SEL' (the angle at the middle atom) or four (the dihedral about the middle
    /// bond, IUPAC's sign), each SEL picking exactly one atom in every frame, through the
    /// nearest periodic images. texmap render draws it (yellow dashes through the atoms, the
    /// value as a label); --measure-table lists the values. Repeatable:
    /// --measure 'resid 10 and name OG; resname LIG and name O1'.
    #[arg(long = "measure", value_name = "SEL; SEL[; SEL[; SEL]]")]
    pub measures: Vec<String>,
    /// Also write the --measure values as a CSV table, one row per measurement and frame:
    /// frame, measure (0-based, in the order given), kind (distance, angle, dihedral), value
    /// (Å or degrees), the atoms' 0-based indices joined by spaces, and the spec as given.
    /// Written whole or not at all.
    #[arg(long, value_name = "FILE.csv")]
    pub measure_table: Option<PathBuf>,
    /// Also write the secondary structure of every frame as a CSV table (MDAnalysis's
    /// analysis.dssp.DSSP, gmx dssp's -o): frame, time, helix, strand, coil (how many residues
    /// of each) and ss, one code per residue with a backbone in file order (H helix, E strand,
    /// a dash coil; DSSP's hydrogen bonds, every frame). Give --pbc unwrap for a protein the
    /// trajectory wrapped. Written whole or not at all.
    #[arg(long, value_name = "FILE.csv")]
    pub dssp_table: Option<PathBuf>,
    /// Also write each residue's share of the frames in each class as a CSV table: chain,
    /// resid, resname, helix, strand, coil (fractions of the frames): a residue's helicity
    /// over the run.
    #[arg(long, value_name = "FILE.csv")]
    pub dssp_residue_table: Option<PathBuf>,
    /// Also draw the secondary structure of every residue in every frame as a chart, PNG or
    /// SVG by the name (VMD's Timeline, gmx dssp's map): residues up, frames across (their
    /// times when the file has them), helices purple, strands yellow, coil white.
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub dssp_timeline: Option<PathBuf>,
    /// Also write the RMSD between every pair of frames as a CSV matrix (Å; gmx rms -m,
    /// cpptraj's 2drms, MDAnalysis's DistanceMatrix with a superposing rms.rmsd): a header
    /// row of frame numbers, then one row per frame, its number first. Each pair of
    /// --rmsd-matrix-select's atoms is superposed on its own (centred, best rotation,
    /// unweighted). Blocks of low values are the conformations the run visits. Written whole
    /// or not at all; not with --shard.
    #[arg(long, value_name = "FILE.csv")]
    pub rmsd_matrix: Option<PathBuf>,
    /// Also draw the pairwise RMSD matrix as a heatmap, PNG or SVG by the name: viridis from
    /// 0 to the largest RMSD with a colour bar, frames (their times when the file has them)
    /// along both axes; past 300 frames a cell is the mean of a block of frames.
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub rmsd_matrix_chart: Option<PathBuf>,
    /// The atoms --rmsd-matrix and --rmsd-clusters superpose (evaluated at the first frame;
    /// 'name CA' by default).
    #[arg(
        long,
        value_name = "SEL",
        default_value = "name CA",
        requires = "rmsd_matrix_out"
    )]
    pub rmsd_matrix_select: String,
    /// Also cluster the frames' conformations on their pairwise RMSD (gmx cluster; the
    /// matrix of --rmsd-matrix, over --rmsd-matrix-select's atoms) and write each frame's
    /// cluster as CSV: frame, time, cluster (1 the first; gmx cluster -clid; `texmap plot
    /// clid.csv` draws it). With the gromos method clusters are numbered largest first. Pick --rmsd-cluster-cutoff from the
    /// --rmsd-matrix-chart: inside its blocks, below the RMSD between them. Written whole or
    /// not at all; not with --shard.
    #[arg(long, value_name = "FILE.csv")]
    pub rmsd_clusters: Option<PathBuf>,
    /// Also write one row per cluster of --rmsd-clusters: cluster, frames, fraction of the
    /// run, the middle frame (the member with the smallest mean RMSD to the others: the
    /// structure to show for it) and its time, that mean, the cluster's mean and largest
    /// RMSD, its first and last frame, and how many times the run enters it.
    #[arg(long, value_name = "FILE.csv")]
    pub rmsd_cluster_table: Option<PathBuf>,
    /// Also write each cluster's middle structure, every atom of its frame, one frame per
    /// cluster in cluster order (gmx cluster -cl), in the format the name gives (.pdb, .cif,
    /// .xyz, .gro, .xtc, .dcd, ...): the representative conformations to render or compare. Keeps
    /// every frame's positions until the end (12 bytes per atom and frame, within
    /// --msd-memory).
    #[arg(long, value_name = "FILE")]
    pub rmsd_cluster_middles: Option<PathBuf>,
    /// How --rmsd-clusters groups the frames.
    #[arg(
        long,
        value_enum,
        default_value = "gromos",
        requires = "rmsd_cluster_out"
    )]
    pub rmsd_cluster_method: RmsdClusterMethodArg,
    /// The RMSD (Å) below which two frames are neighbours for --rmsd-clusters (gmx cluster's
    /// -cutoff, 0.1 nm by default).
    #[arg(
        long,
        value_name = "Å",
        default_value_t = 1.0,
        requires = "rmsd_cluster_out",
        value_parser = parse_positive
    )]
    pub rmsd_cluster_cutoff: f64,
    /// Also write the principal components of --pca-select's motion as a CSV table
    /// (MDAnalysis's analysis.pca.PCA, gmx covar): component, variance (Å², an eigenvalue of
    /// the positions' covariance over the frames), fraction of the total, cumulated fraction,
    /// and for the first --pca-components the cosine content of the frames' projection (Hess:
    /// near 1 the run only diffused along it, so it is not yet sampled). Give --align with the
    /// same atoms, or the tumbling is the first component; --pbc unwrap keeps them whole.
    /// Written whole or not at all; not with --shard.
    #[arg(long, value_name = "FILE.csv")]
    pub pca_table: Option<PathBuf>,
    /// Also write every frame's projection onto the first --pca-components principal
    /// components (Å; MDAnalysis's PCA.transform, gmx anaeig -proj): frame, time, pc1, pc2, …
    /// Plot pc1 against pc2 for the conformational landscape.
    #[arg(long, value_name = "FILE.csv")]
    pub pca_projection: Option<PathBuf>,
    /// Also write the first --pca-components principal components per atom, one row per
    /// atom of the frame (empty outside --pca-select): atom, id, name, resname, resid, chain,
    /// the mean position (mean_x, mean_y, mean_z, Å) and pc1x, pc1y, pc1z, pc2x, … (unit
    /// vectors over all the atoms). For a porcupine plot read a component back: render
    /// --property pc1x=FILE.csv --property pc1y=FILE.csv --property pc1z=FILE.csv
    /// --rep 'name CA=arrows' --arrows pc1.
    #[arg(long, value_name = "FILE.csv")]
    pub pca_vectors: Option<PathBuf>,
    /// Also write --pca-select's atoms moving along principal component --pca-mode, from its
    /// smallest projection in the run to its largest, as a trajectory of --pca-extreme-frames
    /// frames (gmx anaeig -extr; .pdb, .cif, .xtc, .dcd, .gro, .xyz or .lammpstrj by the name):
    /// `texmap render` makes it a movie of the motion.
    #[arg(long, value_name = "FILE")]
    pub pca_extremes: Option<PathBuf>,
    /// The atoms the principal component analysis takes (evaluated at the first frame;
    /// 'name CA' by default, 'backbone', 'protein and not name H*').
    #[arg(
        long,
        value_name = "SEL",
        default_value = "name CA",
        requires = "pca_out"
    )]
    pub pca_select: String,
    /// How many principal components --pca-projection, --pca-vectors and the cosine content
    /// of --pca-table take.
    #[arg(long, value_name = "K", default_value_t = 10, requires = "pca_out",
          value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub pca_components: u32,
    /// The principal component --pca-extremes moves along (1 is the largest).
    #[arg(long, value_name = "K", default_value_t = 1, requires = "pca_extremes",
          value_parser = clap::value_parser!(u32).range(1..=1000))]
    pub pca_mode: u32,
    /// Frames of --pca-extremes (2: the two extremes only).
    #[arg(long, value_name = "N", default_value_t = 20, requires = "pca_extremes",
          value_parser = clap::value_parser!(u32).range(2..=100_000))]
    pub pca_extreme_frames: u32,
    /// Also draw the free-energy landscape over two principal components, PNG or SVG by the
    /// name (gmx sham's Gibbs landscape, the PC1–PC2 map of MD papers): the frames' projections
    /// binned on a --pca-landscape-bins grid over their range, each bin's ΔG = −RT ln(n / n_max)
    /// in kJ/mol at --pca-landscape-temperature, 0 (dark) at the most visited, empty bins white.
    /// Its basins are the conformations the run dwells in; a landscape from a run that has
    /// not converged (see the cosine content of --pca-table) is not a free energy.
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub pca_landscape: Option<PathBuf>,
    /// Also write the landscape as a CSV table, one row per bin: the bin's centre on the two
    /// components (Å), its frames and ΔG (kJ/mol; empty where no frame fell).
    #[arg(long, value_name = "FILE.csv")]
    pub pca_landscape_table: Option<PathBuf>,
    /// The two components of the landscape, 'I,J' (1 is the largest).
    #[arg(long, value_name = "I,J", default_value = "1,2", requires = "pca_landscape_out",
          value_parser = parse_component_pair)]
    pub pca_landscape_axes: (u32, u32),
    /// Bins a side of the landscape (gmx sham's -ngrid).
    #[arg(long, value_name = "N", default_value_t = 32, requires = "pca_landscape_out",
          value_parser = clap::value_parser!(u32).range(2..=1000))]
    pub pca_landscape_bins: u32,
    /// The temperature of the landscape's ΔG, in K.
    #[arg(long, value_name = "K", default_value_t = 300.0, requires = "pca_landscape_out",
          value_parser = parse_positive)]
    pub pca_landscape_temperature: f64,
    /// The two groups of --contacts-table, 'SEL_A;SEL_B': 'name N;name O' (backbone),
    /// 'resname ASP GLU and name OD1 OD2 OE1 OE2;resname LYS ARG and name NZ NH1 NH2' (salt
    /// bridges), 'name CA;name CA'.
    #[arg(long, value_name = "SEL_A;SEL_B", requires = "contacts_table")]
    pub contacts: Option<String>,
    /// The native contacts' radius (Å; MDAnalysis's default 4.5).
    #[arg(long, value_name = "Å", default_value_t = 4.5, requires = "contacts_table", value_parser = parse_positive)]
    pub contacts_radius: f64,
    /// How a frame's pairs count, r0 being a pair's distance in the first frame: hard (r ≤ r0,
    /// MDAnalysis's default hard_cut: any stretch breaks a contact), radius (r ≤
    /// --contacts-radius, radius_cut) or soft (1 / (1 + exp(5 (r − 1.8 r0))), Best, Hummer and
    /// Eaton's soft_cut).
    #[arg(long, value_enum, default_value_t = ContactsMethodArg::Hard, requires = "contacts_table")]
    pub contacts_method: ContactsMethodArg,
    /// The atoms --gyration-table measures (e.g. 'protein', 'resname POPC').
    #[arg(
        long,
        value_name = "SEL",
        default_value = "all",
        requires = "gyration_table"
    )]
    pub gyration_select: String,
    /// Weigh every atom of --gyration-table alike instead of by its mass (for atoms without
    /// elements, or the geometric size).
    #[arg(long, requires = "gyration_table")]
    pub gyration_unweighted: bool,
    /// Every atom's solvent-accessible surface area every frame (Å², Shrake–Rupley with 960
    /// points, as MDTraj's shrake_rupley, VMD's measure sasa and PyMOL's get_area compute it;
    /// MDTraj's radii: Bondi's for H C N O P S, ionic for Na K Mg Ca Cl), into the per-atom
    /// number 'sasa': --color-by sasa shows the exposed atoms, --select 'prop sasa > 20' keeps
    /// them. SEL picks the atoms measured, which alone bury each other: '--sasa protein'
    /// measures the protein without its water (the default, every atom, buries a solvated
    /// protein in its solvent). Under the minimum image in a periodic cell (narrower than three
    /// sphere diameters is refused: replicate it); give --pbc unwrap so molecules are whole.
    #[arg(long, value_name = "SEL", num_args = 0..=1, default_missing_value = "all")]
    pub sasa: Option<String>,
    /// The probe radius of --sasa, Å (1.4: water).
    #[arg(long, value_name = "R", default_value_t = texmap_md_io::sasa::PROBE, requires = "sasa",
          value_parser = parse_probe)]
    pub sasa_probe: f32,
    /// Also write the --sasa total of every frame as a CSV table: frame, time (ps, when the file
    /// has it), sasa (Å², the sum over the measured atoms), as a protein's folding or unfolding
    /// shows in it (gmx sasa's total). Written whole or not at all.
    #[arg(long, value_name = "FILE.csv", requires = "sasa")]
    pub sasa_table: Option<PathBuf>,
    /// Also write the --sasa of every residue in every frame as a CSV table: frame, time,
    /// chain, resid, resname, sasa (Å², the sum over the residue's measured atoms): which
    /// residues are exposed, as MDTraj's shrake_rupley(mode='residue') gives it. Written whole
    /// or not at all.
    #[arg(long, value_name = "FILE.csv", requires = "sasa")]
    pub sasa_residue_table: Option<PathBuf>,
    /// Also write the --clusters of every frame as a CSV table, one row per cluster, the largest
    /// first: frame, cluster, atoms, the centre x, y, z (Å; the mean of its atoms taken whole
    /// across the cell's faces) and the radius of gyration (Å, unweighted): nucleation and
    /// growth, the largest cluster over a run. Written whole or not at all.
    #[arg(long, value_name = "FILE.csv", requires = "clusters")]
    pub cluster_table: Option<PathBuf>,
    /// The centrosymmetry parameter of every atom from its N nearest neighbours (12 for FCC,
    /// 8 for BCC), as OVITO's Centrosymmetry modifier and LAMMPS's compute centro/atom, into
    /// the per-atom number 'centrosymmetry' (Å²): about 0 in the perfect crystal, large at
    /// dislocation cores, stacking faults and surfaces. --color-by centrosymmetry (which turns
    /// it on with N = 12 by itself), or hide the crystal: --select 'prop centrosymmetry > 4'.
    /// Nearest images in a periodic cell; N even, 2 to 32.
    #[arg(long, value_name = "N")]
    pub centrosymmetry: Option<usize>,
    /// Sum the centrosymmetry over the pairing of the N neighbours with the least weight
    /// (OVITO's matching mode, N up to 16) instead of the N/2 smallest pair weights (the
    /// conventional mode of OVITO and LAMMPS, which can count one neighbour twice).
    #[arg(long)]
    pub centrosymmetry_matching: bool,
    /// The atomic strain of every atom against the reference configuration (the first frame
    /// drawn, or --displacement-reference), from its neighbours within R Å in the reference, as
    /// OVITO's Atomic strain modifier: the per-atom numbers 'shear_strain' (von Mises),
    /// 'volumetric_strain' and 'd2min' (the non-affine squared displacement, Å²) show shear
    /// bands, slip and plastic events: --color-by shear_strain --color-range 0:0.2. Pick R
    /// between the first and second neighbour shells (3.0 for copper). Atoms wrapped across
    /// the box between the frames and a sheared cell are followed; atoms with fewer than three
    /// neighbours get 0. R from 0.45 to 20 Å.
    #[arg(long, value_name = "R", value_parser = parse_cutoff)]
    pub strain: Option<f32>,
    /// Compute a per-atom number NAME from a formula every frame, as OVITO's Compute property
    /// modifier (muparser's syntax), for --color-by NAME and selections ('prop NAME > 1'):
    /// --compute 'speed=sqrt(vx^2+vy^2+vz^2)', --compute 'ke=0.5*mass*(vx^2+vy^2+vz^2)',
    /// --compute 'r=sqrt((x-20)^2+(y-20)^2)'. Names: x y z, vx vy vz, index (from 0), id, mass
    /// (the element's), N, pi and every per-atom property (texmap info lists a file's; bfactor,
    /// c_pe, coordination, centrosymmetry, shear_strain, an earlier --compute). Operators + - *
    /// / ^, comparisons, && || !, cond ? a : b; functions sqrt abs exp ln log10 log2 sin cos
    /// tan asin acos atan atan2 sinh cosh tanh pow fmod min max floor ceil rint sign.
    /// Repeatable, evaluated in order after the analyses (--coordination, --strain, ...).
    #[arg(long = "compute", value_name = "NAME=FORMULA")]
    pub computes: Vec<String>,
    /// Keep a per-atom number at its value in the first frame drawn, as OVITO's Freeze
    /// property: colours then follow the atoms. --compute 'x0=x' --freeze x0 --color-by x0
    /// colours a crystal by where each atom started (shear, mixing, diffusion);
    /// --freeze coordination keeps the first frame's counts. After --compute. Repeatable.
    #[arg(long = "freeze", value_name = "NAME")]
    pub freeze: Vec<String>,
    /// Point defects, as OVITO's Wigner-Seitz defect analysis (radiation damage, diffusion):
    /// each atom is counted on the nearest site of the reference configuration (the first frame
    /// drawn, or --displacement-reference: the perfect crystal), giving the per-atom numbers
    /// 'site_occupancy' and 'site'; 0 on a site is a vacancy, 2 or more an interstitial.
    /// 'sites' (the default) draws the reference's sites instead of the atoms, 'atoms' the
    /// atoms. --label '{vacancies} vacancies, {interstitials} interstitials' captions the
    /// counts; --defect-table FILE.csv lists them per frame. A box that changes shape is mapped
    /// onto the reference's first.
    #[arg(long, value_enum, value_name = "sites|atoms", num_args = 0..=1, default_missing_value = "sites")]
    pub wigner_seitz: Option<WignerSeitzArg>,
    /// Also write the --wigner-seitz counts as a CSV table, one row per frame: frame,
    /// vacancies, interstitials. Written whole or not at all.
    #[arg(long, value_name = "FILE.csv", requires = "wigner_seitz")]
    pub defect_table: Option<PathBuf>,
    /// Every atom's Voronoi cell every frame, as OVITO's Voronoi analysis: the per-atom numbers
    /// 'voronoi_volume' (Å³), 'voronoi_faces' (the Voronoi coordination) and 'voronoi_n3' ..
    /// 'voronoi_n6' (faces with 3 to 6 edges: the Voronoi index). --select 'prop voronoi_n5 ==
    /// 12 and prop voronoi_faces == 12' keeps the icosahedral atoms of a metallic glass,
    /// --color-by voronoi_volume shows free volume. Needs a periodic cell.
    #[arg(long)]
    pub voronoi: bool,
    /// Every crystalline atom's lattice orientation every frame, as OVITO's Polyhedral template
    /// matching gives it (on the FCC, HCP and BCC atoms of adaptive CNA): the per-atom numbers
    /// 'orientation_x' .. 'orientation_w' (the quaternion from the ideal crystal's axes) and
    /// 'lattice_rmsd' (the deviation from the ideal crystal, scale-free); NaN for other atoms.
    /// --color-by lattice_rmsd turns it on; --color-by ipf colours by the orientation.
    #[arg(long)]
    pub orientations: bool,
    /// The grains of a polycrystal every frame, as OVITO's Grain segmentation: crystalline
    /// atoms (FCC, HCP, BCC) join a grain while their lattice orientation is within DEG
    /// (default 4) of its mean; grains of fewer than --grain-min-size atoms are dissolved and
    /// the atoms between grains join the nearest. Gives the per-atom number 'grain' (0 the
    /// largest, -1 none): --color-by grain, --select 'prop grain == 0', --grain-table
    /// FILE.csv lists each frame's grains (grain growth over a run).
    #[arg(long, value_name = "DEG", num_args = 0..=1, default_missing_value = "4", value_parser = parse_grain_threshold)]
    pub grains: Option<f64>,
    /// With --grains (or --color-by grain): grains of fewer crystalline atoms are dissolved
    /// (OVITO's default: 100).
    #[arg(long, value_name = "N", default_value_t = 100)]
    pub grain_min_size: usize,
    /// With --grains: leave the atoms between grains (grain boundaries, dislocation cores,
    /// surfaces) at grain -1 instead of giving them to the nearest grain.
    #[arg(long)]
    pub grain_keep_orphans: bool,
    /// With --grains: give the HCP layers of stacking faults and twin boundaries in an FCC
    /// crystal (or FCC layers in HCP) grains of their own instead of joining them to the grain
    /// they lie in (OVITO's "handle stacking faults" off).
    #[arg(long)]
    pub grain_separate_faults: bool,
    /// The radial distribution function g(r) out to R Å (OVITO's Coordination analysis table,
    /// VMD's g(r), MDAnalysis's InterRDF): pairs counted under the minimum image after --pbc
    /// and --replicate, each frame normalised by its own cell's density, averaged over the
    /// frames into --rdf-table. R up to half the cell's narrowest width; a cell narrower than
    /// three R has every pair of its atoms tested (up to 48,000 atoms).
    #[arg(long, value_name = "R", value_parser = parse_cutoff, requires = "rdf_table")]
    pub rdf: Option<f32>,
    /// With --rdf: histogram bins from 0 to R (OVITO's default: 200).
    #[arg(long, value_name = "N", default_value_t = 200)]
    pub rdf_bins: usize,
    /// With --rdf: also the partial g(r) of every pair of atom kinds (their types, else their
    /// elements: Si-Si, Si-O, O-O), as OVITO's "compute partial RDFs".
    #[arg(long, requires = "rdf")]
    pub rdf_partial: bool,
    /// Write --rdf's g(r), averaged over the frames, as a CSV table: r (the bin's centre, Å),
    /// g, then with --rdf-partial one column per pair of kinds (g_Si-O). Written whole or not
    /// at all.
    #[arg(long, value_name = "FILE.csv", requires = "rdf")]
    pub rdf_table: Option<PathBuf>,
    /// Give every atom the property 'msd': its squared displacement (Å²) from the first frame
    /// written or drawn, followed across the periodic boundaries (GROMACS's trjconv -pbc
    /// nojump, MDAnalysis's NoJump), before --align: --color-by msd shows the mobile atoms,
    /// --select 'prop msd > 100' keeps them. Frames must be close enough that no atom moves half
    /// a cell between two of them (mind a large --frames step).
    #[arg(long)]
    pub msd: bool,
    /// Also write the mean squared displacement as a CSV table, one row per frame: frame, time
    /// (ps, when the file has it), msd (Å², over every atom), then one column per kind of atom
    /// (their types, else their elements: msd_O, msd_Na): a diffusion coefficient is the slope
    /// over 6 at long times. Turns on --msd. Written whole or not at all.
    #[arg(long, value_name = "FILE.csv")]
    pub msd_table: Option<PathBuf>,
    /// Also write the mean squared displacement against lag time, averaged over every time
    /// origin (MDAnalysis's EinsteinMSD, the curve a diffusion coefficient is read from), as a
    /// CSV table: lag (frames), time (ps, when the frames' times are evenly spaced), msd (Å²,
    /// over every atom), then one column per kind of atom (msd_O, msd_Na). Prints each
    /// column's diffusion coefficient, the slope over 6 fitted over --msd-fit, in 10⁻⁵ cm²/s
    /// as gmx msd does. Keeps every frame's unwrapped positions (12 bytes per atom per frame,
    /// up to --msd-memory). Turns on --msd. Written whole or not at all; not with --shard.
    #[arg(long, value_name = "FILE.csv")]
    pub msd_lags: Option<PathBuf>,
    /// Also write each atom's RMS fluctuation about its mean position over the frames written
    /// or drawn (Å; MDAnalysis's rms.RMSF, gmx rmsf), after --align (give it, or the molecule's
    /// tumbling counts): a CSV table, one row per atom: atom (from 0), id, name, resname, resid,
    /// chain, rmsf. `--property rmsf=FILE.csv` reads its column back to colour by
    /// (`--color-by rmsf`) or select ('prop rmsf > 2'). Written whole or not at all; not with
    /// --shard.
    #[arg(long, value_name = "FILE.csv")]
    pub rmsf_table: Option<PathBuf>,
    /// Also write where the atoms of --density-select spend their time, as a 3-D map: the
    /// number density (atoms per Å³) in cells --density-delta wide, averaged over the frames
    /// written or drawn, after --align (superpose the protein first to see the water and ions
    /// that stay around it), as MDAnalysis's DensityAnalysis and VMD's volmap density compute
    /// it. An OpenDX file that VMD, PyMOL, Chimera and `texmap render --volume FILE.dx
    /// --isosurface LEVEL` draw (bulk water has 0.0334 oxygens per Å³). The grid spans the
    /// first frame's selected atoms and --density-padding beyond them; positions that later
    /// leave it are not counted, and their number is reported. Written whole or not at all;
    /// not with --shard.
    #[arg(long, value_name = "FILE.dx")]
    pub density_map: Option<PathBuf>,
    /// The atoms whose density --density-map writes: 'name OW', 'resname SOL and name OW',
    /// 'name NA CL', 'resname LIG' (re-evaluated every frame, so 'around' works).
    #[arg(
        long,
        value_name = "SEL",
        default_value = "all",
        requires = "density_map"
    )]
    pub density_select: String,
    /// The units of --density-map's values: A^-3 (atoms per Å³), nm^-3, molar (mol/L), or
    /// relative to bulk water's molecules: water (0.997 g/cm³, so 1 is bulk water's oxygen
    /// density and 2 twice it), SPC, TIP3P, TIP4P (each model's own bulk density) — the units
    /// MDAnalysis's Density.convert_density takes.
    #[arg(long, value_name = "UNIT", default_value = "A^-3", requires = "density_map",
          value_parser = ["A^-3", "nm^-3", "molar", "water", "SPC", "TIP3P", "TIP4P"])]
    pub density_units: String,
    /// --density-map's cell width (Å).
    #[arg(long, value_name = "Å", default_value_t = 1.0, requires = "density_map", value_parser = parse_positive)]
    pub density_delta: f64,
    /// How far --density-map's grid reaches beyond the first frame's selected atoms (Å).
    #[arg(long, value_name = "Å", default_value_t = 2.0, requires = "density_map", allow_negative_numbers = true, value_parser = parse_non_negative)]
    pub density_padding: f64,
    /// Also write every protein residue's backbone dihedrals per frame as a CSV table (the
    /// Ramachandran plot's data: MDAnalysis's Ramachandran, gmx rama): frame, time, chain,
    /// resid, resname, phi, psi, omega (degrees, −180 to 180); an angle that needs a residue
    /// missing (a terminus, a chain break, a gap longer than a peptide bond) is left empty.
    /// Written whole or not at all.
    #[arg(long, value_name = "FILE.csv")]
    pub dihedral_table: Option<PathBuf>,
    /// Also draw the Ramachandran plot of --ramachandran-select's residues over every frame,
    /// PNG or SVG by the name (MDAnalysis's Ramachandran.plot, gmx rama): φ across, ψ up, one
    /// dot per residue and frame up to 20,000 dots, past them their density on 2° bins as
    /// −ln(p / p_max) (0, dark, the most visited). Helices gather near (−60°, −45°), strands
    /// near (−120°, 130°). Not with --shard.
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub ramachandran: Option<PathBuf>,
    /// The residues --ramachandran plots: those with an atom in the selection at the first
    /// frame ('protein' by default; 'not resname GLY PRO' leaves out the two whose regions
    /// differ).
    #[arg(
        long,
        value_name = "SEL",
        default_value = "protein",
        requires = "ramachandran"
    )]
    pub ramachandran_select: String,
    /// Also write the residue–residue distance map as a CSV matrix (gmx mdmat's -mean): for
    /// each pair of --distance-map-select's residues the smallest distance between their
    /// atoms (Å, to the nearest periodic image), averaged over the frames. A header row of
    /// residue labels (chain:RESNAME resid), then one row per residue. Not with --shard.
    #[arg(long, value_name = "FILE.csv")]
    pub distance_map: Option<PathBuf>,
    /// Also draw the distance map as a heatmap, PNG or SVG by the name (viridis, dark near):
    /// helices and sheets show as bands beside and across the diagonal.
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub distance_map_chart: Option<PathBuf>,
    /// Also write the contact map as a CSV matrix: for each pair of residues the fraction of
    /// frames in which their smallest atom distance is below --contact-map-cutoff (1 on the
    /// diagonal); the same layout as --distance-map.
    #[arg(long, value_name = "FILE.csv")]
    pub contact_map: Option<PathBuf>,
    /// Also draw the contact map as a heatmap, PNG or SVG by the name (yellow: always in
    /// contact).
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub contact_map_chart: Option<PathBuf>,
    /// The residues of --distance-map and --contact-map: those with an atom in the selection
    /// at the first frame, each with its selected atoms ('protein' by default; 'name CA' for
    /// the CA–CA map).
    #[arg(
        long,
        value_name = "SEL",
        default_value = "protein",
        requires = "residue_map_out"
    )]
    pub distance_map_select: String,
    /// Write lipid tail order parameters as a CSV table: for each carbon of the --order-select
    /// atoms, grouped by residue and atom name (one row per carbon of each chain: C22..C218 and
    /// C32..C316 of POPC), S = <(3 cos²θ − 1) / 2> of its bonds against the --order-normal axis,
    /// averaged over the lipids and frames, with −S (−S_CD, as papers plot it and NMR gives
    /// it) and the standard error over the lipids. Columns: resname, atom, chain and position
    /// (the carbon's chain within its lipid and its place along it, from the bonds among the
    /// selected atoms), sites (lipids), vectors (bonds per site), s, minus_s, sem. Bonds come
    /// from the topology, else from distances at the first frame; bonds across the box are
    /// taken to their nearest image.
    #[arg(long, value_name = "FILE.csv", requires = "order_select")]
    pub order_table: Option<PathBuf>,
    /// Also draw --order-table's −S against the position along the chain, a line per chain of
    /// each lipid kind, PNG or SVG by the name: the order profile membrane papers show.
    #[arg(long, value_name = "FILE.png|FILE.svg", requires = "order_table")]
    pub order_chart: Option<PathBuf>,
    /// The atoms --order-table measures: the tail carbons, as
    /// 'resname POPC and name C2* C3*' (hydrogens come from the bonds), or a Martini lipid's
    /// beads ('resname POPC' with --order-method bonds).
    #[arg(long, value_name = "SEL", requires = "order_table")]
    pub order_select: Option<String>,
    /// How --order-table finds each carbon's vectors: hydrogens (all-atom force fields such as
    /// CHARMM36, Slipids, Lipid21: the C–H bonds, S_CH), united-atom (GROMOS, Berger: gmx
    /// order's construction from the two neighbouring carbons, S_CD) or bonds (coarse-grained
    /// Martini: each bond between two selected beads, a row per bond such as NC3-PO4).
    #[arg(long, value_name = "METHOD", default_value = "hydrogens",
          value_parser = ["hydrogens", "united-atom", "bonds"], requires = "order_table")]
    pub order_method: String,
    /// The membrane normal of --order-table: the x, y or z axis (z for a bilayer in the xy
    /// plane; the sign does not matter).
    #[arg(long, value_name = "AXIS", default_value = "z", value_parser = ["x", "y", "z"],
          requires = "order_table")]
    pub order_normal: String,
    /// Write a bilayer's thickness and area per lipid per frame as a CSV table: the leaflets
    /// are found at the first frame as MDAnalysis's LeafletFinder finds them (the
    /// --membrane-select head atoms joined below --membrane-cutoff, nearest images included;
    /// the two largest sets), then each frame gives the distance between the leaflets' mean
    /// head heights along --membrane-normal, through the bilayer (each head's tail, the atom of
    /// its residue farthest from it, says which way that is, so a bilayer across the box's
    /// faces is measured through its tails) and the box face's area over each leaflet's
    /// lipids. Columns: frame, time, upper, lower (lipids), thickness (Å), area (Å²),
    /// apl_upper, apl_lower (Å²).
    #[arg(long, value_name = "FILE.csv")]
    pub membrane_table: Option<PathBuf>,
    /// The head atoms of --membrane-table, one per lipid ('name P' by default: the phosphates
    /// of phospholipids; 'name PO4' for Martini, 'name P or name ROH' with cholesterol).
    #[arg(
        long,
        value_name = "SEL",
        default_value = "name P",
        requires = "membrane_table"
    )]
    pub membrane_select: String,
    /// The distance below which two head atoms are in one leaflet for --membrane-table (Å;
    /// MDAnalysis's LeafletFinder default). It must be shorter than the bilayer's thickness
    /// and longer than the spacing of the heads.
    #[arg(long, value_name = "Å", default_value_t = 15.0, requires = "membrane_table",
          value_parser = parse_positive)]
    pub membrane_cutoff: f64,
    /// The membrane normal of --membrane-table: the x, y or z axis.
    #[arg(long, value_name = "AXIS", default_value = "z", value_parser = ["x", "y", "z"],
          requires = "membrane_table")]
    pub membrane_normal: String,
    /// The distance below which two residues are in contact for --contact-map (Å).
    #[arg(long, value_name = "Å", default_value_t = 4.5, requires = "residue_map_out",
          value_parser = parse_positive)]
    pub contact_map_cutoff: f64,
    /// The lag times the diffusion coefficient is fitted over, FROM:TO in ps (in frames when the
    /// frames carry no times); by default 10 % to 90 % of the longest lag, as gmx msd's
    /// -beginfit and -endfit.
    #[arg(long, value_name = "FROM:TO", requires = "msd_lags", value_parser = parse_fit_range)]
    pub msd_fit: Option<(f64, f64)>,
    /// The most memory --msd-lags may keep positions in, and --vacf-table and --vdos-table
    /// velocities, in MB: 12 bytes per atom per frame each (1,000 frames of 100,000 atoms take
    /// 1,145 MB); also the limit of the frames the principal components keep (12 bytes per
    /// atom and frame), of --rmsd-matrix (8 bytes per pair of frames and 24 per atom and
    /// frame), of --rmsd-cluster-middles (12 more per atom and frame) and of --distance-map
    /// and --contact-map (12 bytes per pair of residues). A run stops at the
    /// frame that would pass it.
    #[arg(long, value_name = "MB", default_value_t = 4096)]
    pub msd_memory: usize,
    /// Also write the velocity autocorrelation function averaged over every time origin as a
    /// CSV table (gmx velacc, LAMMPS's compute vacf): lag (frames), time (ps, when the frames'
    /// times are evenly spaced), vacf (Å²/ps², ⟨v(0)·v(t)⟩ over every atom), then one column
    /// per kind of atom (vacf_O, vacf_H). Prints each column's Green–Kubo diffusion
    /// coefficient, ⅓ ∫ C(t) dt up to --vacf-integrate, in 10⁻⁵ cm²/s. Needs velocities in the
    /// frames: a .trr written with nstvout, a LAMMPS dump with vx vy vz, AMBER NetCDF or GSD
    /// with velocities, a .gro with them. Keeps every frame's velocities (up to --msd-memory).
    /// Written whole or not at all; not with --shard, nor --align (it turns the velocities
    /// with the fit, frame by frame).
    #[arg(long, value_name = "FILE.csv", conflicts_with = "align")]
    pub vacf_table: Option<PathBuf>,
    /// The upper limit τ (ps; frames when the frames carry no times) of --vacf-table's
    /// Green–Kubo integral: where C(t) has decayed, since the longer lags add noise. By
    /// default the lag of half the frames.
    #[arg(long, value_name = "TAU", requires = "vacf_table", value_parser = parse_positive)]
    pub vacf_integrate: Option<f64>,
    /// Also write the vibrational density of states, the spectrum of the velocities (gmx dos),
    /// as a CSV table: frequency (THz), wavenumber (cm⁻¹), vdos (over every atom, each
    /// weighted by its mass as gmx dos weighs it; unweighted when an atom has no element),
    /// then one column per kind of atom (vdos_O, vdos_H); every column integrates to 3 over
    /// the frequencies (three degrees of freedom per atom). The frequency step is 1 / (n Δt),
    /// n the power of two at or above twice the frames. Needs velocities and evenly spaced
    /// frame times. Written whole or not at all; not with --shard or --align.
    #[arg(long, value_name = "FILE.csv", conflicts_with = "align")]
    pub vdos_table: Option<PathBuf>,
    /// Also write --align's fit as a CSV table, one row per frame: frame, time (ps, when the
    /// file has it), rmsd (Å: the aligned atoms' RMSD from the reference after the fit, mass
    /// weighted with --align-mass), as MDAnalysis's rms.RMSD. Written whole or not at all.
    #[arg(long, value_name = "FILE.csv", requires = "align")]
    pub rmsd_table: Option<PathBuf>,
    /// Write the density profile across the cell, averaged over the frames, as a CSV table
    /// (MDAnalysis's LinearDensity, gmx density, OVITO's Spatial binning): the cell cut into
    /// --profile-bins slabs along --profile-axis, one row per slab: its centre (Å), number
    /// (atoms/Å³), mass (g/cm³, the elements' standard weights), charge (e/Å³, when the atoms
    /// carry charges), then number_<kind> per kind of atom (their types, else elements). For
    /// interfaces, membranes and confined liquids. Written whole or not at all; not with
    /// --align (the slabs are the cell's) or --shard.
    #[arg(long, value_name = "FILE.csv", conflicts_with = "align")]
    pub profile_table: Option<PathBuf>,
    /// The edge --profile-table cuts across: x, y, z (an orthorhombic cell's axes) or a, b, c
    /// (a skewed cell's edge vectors: slabs parallel to the two other edges).
    #[arg(long, value_name = "AXIS", default_value = "z", value_parser = ["x", "y", "z", "a", "b", "c"], requires = "profile_table")]
    pub profile_axis: String,
    /// The number of slabs of --profile-table.
    #[arg(long, value_name = "N", default_value_t = 100, requires = "profile_table",
          value_parser = clap::value_parser!(u32).range(1..=1_048_576))]
    pub profile_bins: u32,
    /// Also write the grains of every frame as a CSV table, one row per grain: frame, grain,
    /// atoms, crystalline atoms, structure, and the mean orientation's quaternion. Written whole
    /// or not at all.
    #[arg(long, value_name = "FILE.csv")]
    pub grain_table: Option<PathBuf>,
    /// Superpose every frame on the first rendered frame (or on --align-to's structure) by the
    /// least-squares fit of the atoms SEL picks ('backbone', 'name CA', 'protein and not name
    /// H*'), so the molecule holds still while it tumbles and diffuses, as MDAnalysis's
    /// AlignTraj and VMD's 'measure fit' do before a movie. SEL is evaluated once, at the first
    /// frame; the fit is unweighted (see --align-mass) and after --pbc (use --pbc unwrap so the
    /// fitted molecule is whole).
    #[arg(long, value_name = "SEL")]
    pub align: Option<String>,
    /// The structure --align fits onto, instead of the first frame: a crystal structure or an
    /// equilibrated frame (the first frame of any file texmap reads: PDB, PDBx/mmCIF, GRO,
    /// XYZ, ...), in its own coordinates, so every frame is drawn where that structure sits.
    /// SEL must pick as many atoms in it as in the trajectory, with the same names where both
    /// have names (MDAnalysis's AlignTraj with a reference universe).
    #[arg(long, value_name = "FILE", requires = "align")]
    pub align_to: Option<PathBuf>,
    /// Weight --align's fit by the atoms' masses (the topology's or file's masses: a GROMACS
    /// .tpr, a LAMMPS data file; else their elements' standard atomic weights), as
    /// MDAnalysis's AlignTraj(weights="mass").
    #[arg(long, requires = "align")]
    pub align_mass: bool,
}

/// How an atom's look is chosen and examples, after `texmap render --help`.
const RENDER_AFTER_HELP: &str = "\
How each atom's look is chosen (the first that applies):
  colour: --color SEL=COLOUR rules (in order, the last that selects the atom wins) > the
          file's colour column (--color-by property, the default; extended XYZ `color`,
          LAMMPS dump `ColorR ColorG ColorB` or `Color.R ...` as OVITO names them; values are
          fractions of 1, clamped to [0, 1]) > --type-color > element colour (CPK/Jmol), or one
          colour per type with --color-by type (the default for atoms that have only types,
          such as LAMMPS dumps with numeric types), per chain with --color-by chain, or by
          secondary structure with --color-by structure (helix purple, strand yellow, coil white)
  radius: --radius SEL=R rules > the file's radius column (`radius`, LAMMPS `diameter` / 2) >
          --type-radius > van der Waals radius of the element; then times --radius-scale
  A NAME rule matches the atom's type first, then its name, then its element.
  SEL is a selection in the VMD/MDAnalysis language (see --select), e.g. 'chain A' or
  'segid PROA'.

Coordinate-only trajectories (XTC, DCD, TRR, AMBER NetCDF) take names, elements, residues and
bonds from --topology. The automatic camera frames the drawn (selected) atoms.

If a frame cannot be read or drawn, rendering stops there: the images of the frames before it
stay (each is complete: written to a temporary name, then renamed) and the error lists them.

Examples:
  texmap render traj.pdb --frames 0:100:10 --size 1280x720 -o frames/f%04d.png
  texmap render run.xtc --topology conf.gro --select 'not resname SOL' --style ball-stick --pbc unwrap -o f.png
  texmap render md.nc --topology system.prmtop --color 'protein=#a0a0ff' --color 'resname LIG=#ff8000' -o f.png
  texmap render dump.lammpstrj --type-color 1=#ff8000 --type-color 2=40,40,255 --type-radius 2=0.6 -o f.png
  texmap render 1abc.cif.gz --style tube --color-by chain --select 'not water' -o chains.png
  texmap render 1abc.cif --color-by bfactor --colormap coolwarm -o b.png
  texmap render 1abc.cif --style cartoon --color-by structure --supersample 3 -o fold.png
  texmap render 1abc.cif --rep 'protein=cartoon' --rep 'protein=surface:#8080ff' --surface-opacity 0.35 -o see.png
  texmap render md.xtc --topology md.gro --rep 'protein=cartoon' --rep 'resname LIG=licorice' --rep 'protein or resname LIG=hbonds' -o hb.png
  texmap render 1abc.cif --rep 'not resname LIG=surface' --rep 'resname LIG=ball-stick' --export-mesh pocket.glb -o pocket.png
  texmap render md.xtc --topology protein.pdb --align backbone --style tube --color-by structure --label 't = {ns} ns' -o md.mp4
  texmap render XDATCAR --rep 'element Ti=polyhedra' --rep 'element O=ball-stick' --replicate 2,2,2 -o tio2.mp4
  texmap render dump.lammpstrj --rep 'all=ball-stick' --rep 'type 2=trails' --trail-length 50 --color-by displacement -o diffusion.mp4
  texmap render run.xtc --topology conf.gro --style licorice --select protein --measure 'resid 10 and name CA; resid 20 and name CA' --measure-table d.csv -o d.png
  texmap render CONTCAR --rep 'all=ball-stick' --rep 'all=arrows' --arrow-scale 0.3 -o v.png
  texmap render poses.sdf --style licorice --bond-orders -o poses.png
  texmap render homo.cube --style ball-stick --isosurface 0.02 --isosurface-opacity 0.7 -o homo.png
  texmap render CHGCAR --style ball-stick --isosurface 0.05 --replicate 2,2,1 -o rho.png
  texmap render water.gro --color-by element --type-color OW=#ff0000 --radius-scale 0.5 -o w.png
  texmap render md.xyz --eye 0,0,50 --target 0,0,0 --up 0,1,0 --fov 30 --depth -o md.png";

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneArg {
    S1,
    S2,
    S3,
    Molecule,
    /// The molecule as ball and stick (atoms at 0.3 of their radii, bonds drawn and traced).
    #[value(name = "molecule-bs")]
    MoleculeBallStick,
}

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// A trajectory file whose first frame is the scene (instead of --scene).
    pub file: Option<PathBuf>,
    /// A built-in scene: S1 (Seed 004 system, 1,115 atoms, 500x500), S2 (100k spheres, 1080p),
    /// S3 (1M spheres, 1080p), molecule (~300 atoms, Seed 002), molecule-bs (the same molecule
    /// as ball and stick: 299 bonds drawn as cylinders by every method and traced by the reference).
    #[arg(
        long,
        value_enum,
        ignore_case = true,
        conflicts_with_all = ["file", "color_by", "radius_scale", "type_radius", "type_color"]
    )]
    pub scene: Option<SceneArg>,
    /// Output directory for results.csv, results.json, images and charts.
    #[arg(long)]
    pub out: PathBuf,
    /// Timed runs per method (the median is reported).
    #[arg(long, default_value_t = 5)]
    pub runs: usize,
    /// Also run the stability sweeps (FOV, angle, distance, size) and chart them.
    #[arg(long)]
    pub sweeps: bool,
    /// Also run the quality axis: the ray-cast image with anti-aliasing, ambient occlusion and
    /// shadows (texmap render --aa/--ao/--shadows) timed and measured against an 8x8
    /// supersampled reference traced with the same effects (256 AO rays per pixel): quality.csv,
    /// quality.json, quality.svg. Minutes on S2/S3 (the reference is the cost).
    #[arg(long)]
    pub quality_axis: bool,
    /// Image size WxH for a trajectory file.
    #[arg(long, default_value = "800x600")]
    pub size: String,
    /// How a trajectory file's atoms look (not with --scene).
    #[command(flatten)]
    pub style: StyleArgs,
}

/// A file's name without its directory, a final `.gz` and then its extension:
/// `data/esp.cube.gz` is `esp`.
pub fn strip_gz_stem(path: &std::path::Path) -> String {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    let name = name.strip_suffix(".gz").unwrap_or(name);
    match name.rsplit_once('.') {
        Some((stem, _)) if !stem.is_empty() => stem.to_string(),
        _ => name.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn type_values_parse_or_explain() {
        assert_eq!(
            parse_type_radius(" 1 = 0.75 ").unwrap(),
            TypeRadius {
                name: "1".into(),
                radius: 0.75
            }
        );
        assert_eq!(parse_type_color("CA=#00Ff80").unwrap().rgb, [0, 255, 128]);
        assert_eq!(parse_type_color("2=1, 2 ,3").unwrap().rgb, [1, 2, 3]);
        for bad in [
            "O",
            "=1",
            "O=0",
            "O=-2",
            "O=inf",
            "a b=1",
            "ABCDEFGHIJKLMNOP=1",
        ] {
            assert!(parse_type_radius(bad).is_err(), "{bad}");
        }
        for bad in [
            "O=#fff",
            "O=#ff00000",
            "O=#xx0000",
            "O=256,0,0",
            "O=1,2",
            "O=0.5,0,0",
            "O=",
        ] {
            let e = parse_type_color(bad).unwrap_err();
            assert!(!e.is_empty(), "{bad}");
        }
    }
}

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
    about = "Render molecular-dynamics trajectories as spheres on the CPU and compare sphere-drawing methods for speed and accuracy",
    long_about = "Render molecular-dynamics trajectories as spheres on the CPU (no GPU needed) with four \
methods from classic texture-mapping papers — tessellated polygons, Seed 002 colour+depth look-up \
images, Seed 004 template billboards and exact ray-cast impostors — and measure each against a BVH \
reference ray tracer.\n\nExit codes: 0 success, 1 runtime failure (unreadable or damaged input, \
unwritable output), 2 bad usage.",
    after_help = "Examples:\n  texmap demo --out demo\n  texmap info traj.xtc\n  texmap render traj.pdb --frames 0:100:10 --size 1280x720 -o frames/f%04d.png\n  texmap compare --scene S1 --out study"
)]
pub struct Cli {
    /// Worker threads (default: all cores). Output is byte-identical for any count.
    #[arg(long, global = true, value_name = "N")]
    pub threads: Option<usize>,

    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Print a trajectory's format, atom and frame counts, box and first positions as one JSON object.
    Info {
        /// Trajectory file (XYZ, extended XYZ, PDB, GRO, LAMMPS dump, DCD, XTC, TRR).
        file: PathBuf,
        /// Format, when the extension does not tell it.
        #[arg(long)]
        format: Option<String>,
    },
    /// Render trajectory frames to PNG (and optionally depth to EXR).
    Render(RenderArgs),
    /// Run every method and the reference ray tracer on a scene; write results, images and charts.
    Compare(CompareArgs),
    /// No input needed: simulate a small built-in MD system, render it with every method, compare,
    /// and write an index.html that shows it all.
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

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorBy {
    /// Element colours (CPK/Jmol), from element columns or atom names.
    Element,
    /// One distinct colour per atom type/name.
    Type,
    /// Per-atom colour columns in the file (extended XYZ, LAMMPS dump), element colours otherwise.
    Property,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Trajectory file.
    pub file: PathBuf,
    /// Format, when the extension does not tell it.
    #[arg(long)]
    pub format: Option<String>,
    /// Frames to render, A:B:STEP (B exclusive, each part optional: "::10", "5:", "3").
    #[arg(long, default_value = "0:")]
    pub frames: String,
    /// Drawing method.
    #[arg(long, value_enum, default_value_t = MethodArg::Raycast)]
    pub method: MethodArg,
    /// Image size WxH in pixels.
    #[arg(long, default_value = "1280x720")]
    pub size: String,
    /// Orthographic projection (parallel rays).
    #[arg(long)]
    pub ortho: bool,
    /// Horizontal field of view in degrees (the project's convention), perspective only.
    #[arg(long, default_value_t = 40.0)]
    pub fov: f32,
    /// View direction for the automatic camera: auto (a three-quarter view), x, y, z, -x, -y, -z.
    #[arg(long, default_value = "auto")]
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
    /// How atoms are coloured.
    #[arg(long, value_enum, default_value_t = ColorBy::Element)]
    pub color_by: ColorBy,
    /// Multiply every atom radius by S.
    #[arg(long, default_value_t = 1.0)]
    pub radius_scale: f32,
    /// Background colour R,G,B (0-255).
    #[arg(long, default_value = "0,0,0")]
    pub background: String,
    /// Draw the periodic box outline when the file has a box.
    #[arg(long)]
    pub box_outline: bool,
    /// Also write depth as a one-channel EXR beside each PNG (same name, .exr).
    #[arg(long)]
    pub depth: bool,
    /// Output PNG; may hold a %04d frame-number pattern. Without one, several frames get _NNNN.
    #[arg(short, long)]
    pub output: PathBuf,
}

#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneArg {
    S1,
    S2,
    S3,
    Molecule,
}

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// A trajectory file whose first frame is the scene (instead of --scene).
    pub file: Option<PathBuf>,
    /// A built-in scene: S1 (Seed 004 system, 1,115 atoms, 500x500), S2 (100k spheres, 1080p),
    /// S3 (1M spheres, 1080p), molecule (~300 atoms, Seed 002).
    #[arg(long, value_enum, conflicts_with = "file")]
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
    /// Image size WxH for a trajectory file.
    #[arg(long, default_value = "800x600")]
    pub size: String,
}

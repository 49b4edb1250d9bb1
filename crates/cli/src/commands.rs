//! The subcommands: glue between files, the libraries and the terminal.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use texmap_core::shade::Lighting;
use texmap_impostor::{Method, Renderer, SphereScene};
use texmap_md_io::{Format, Frame as MdFrame, ReadOptions, Sequence};
use texmap_study::harness::{self, HarnessOptions, SceneReport};
use texmap_study::scenes::{self, NamedScene, SceneId};

use crate::args::{Cli, Command, CompareArgs, MethodArg, RenderArgs, SceneArg, usage};
use crate::output::{write_atomic, write_png};
use crate::scene::{parse_background, parse_size, warning_text};
use crate::tables::AnalysisTables;

/// `--quiet`: no progress bars and no notes (warnings and errors still print).
static QUIET: AtomicBool = AtomicBool::new(false);

/// Whether `--quiet` was given.
pub(crate) fn quiet() -> bool {
    QUIET.load(Ordering::Relaxed)
}

/// A line on stderr about what was done (`texmap: wrote ...`), unless `--quiet`.
#[macro_export]
macro_rules! note {
    ($($arg:tt)*) => {
        if !$crate::commands::quiet() {
            eprintln!("texmap: {}", format_args!($($arg)*));
        }
    };
}

pub fn run(cli: Cli) -> Result<()> {
    QUIET.store(cli.quiet, Ordering::Relaxed);
    match cli.command {
        Command::Info {
            file,
            more,
            format,
            allow_truncated,
            lammps_columns,
            topology,
            cell,
        } => info(
            &file,
            &more,
            format.as_deref(),
            read_options(allow_truncated, lammps_columns.as_deref()),
            topology.as_deref(),
            cell.as_deref(),
        ),
        Command::Render(a) => {
            crate::scene::load_index(a.mol.index.as_deref())?;
            crate::scene::set_defines(&a.mol.define);
            render(&a)
        }
        Command::Convert(a) => {
            crate::scene::load_index(a.index.as_deref())?;
            crate::scene::set_defines(&a.define);
            crate::convert::convert(&a)
        }
        Command::Compare(a) => compare(&a),
        Command::Demo {
            out,
            steps,
            every,
            size,
        } => demo(&out, steps, every, &size),
        Command::Terrain { cmd } => crate::terrain::run(cmd),
        Command::Envmap(a) => crate::envmap::run(a),
        Command::Movie { dir, output, fps } => crate::movie::assemble(&dir, &output, fps),
        Command::Plot(a) => crate::plot::plot(&a),
    }
}

pub(crate) fn progress(len: u64, what: &str) -> ProgressBar {
    if quiet() {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::new(len);
    pb.set_style(
        ProgressStyle::with_template(&format!(
            "{{spinner}} {what} [{{bar:30}}] {{pos}}/{{len}} {{per_sec}} ETA {{eta}} {{msg}}"
        ))
        .expect("static template")
        .progress_chars("=> "),
    );
    pb
}

/// A spinner with `what` for work whose length is not known in steps (hidden with --quiet).
pub(crate) fn spinner(what: &str) -> ProgressBar {
    if quiet() {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::new_spinner();
    pb.set_message(what.to_string());
    pb.enable_steady_tick(std::time::Duration::from_millis(200));
    pb
}

pub(crate) fn open_trajectory(file: &Path, format: Option<&str>) -> Result<Sequence> {
    open_trajectory_with(file, format, ReadOptions::new())
}

/// Prints the reader's warnings (once each): what it tolerated under --allow-truncated, and the
/// alternate locations of PDBx/mmCIF atoms it dropped after the first.
pub(crate) fn print_warnings(traj: &Sequence, shown: &mut usize) {
    for w in &traj.warnings()[*shown..] {
        if texmap_md_io::is_altloc_warning(w) {
            eprintln!("texmap: warning: {w}");
        } else {
            eprintln!("texmap: warning: {w} (dropped: --allow-truncated)");
        }
    }
    *shown = traj.warnings().len();
}

/// The read options of the input flags: --allow-truncated, --lammps-columns.
fn read_options(allow_truncated: bool, lammps_columns: Option<&str>) -> ReadOptions {
    let options = ReadOptions::new().allow_truncated(allow_truncated);
    match lammps_columns {
        Some(names) => options.lammps_columns(names),
        None => options,
    }
}

/// `options` with what a trajectory may need from its topology: the atom count and box angles
/// an AMBER ASCII trajectory does not hold (other formats ignore them).
fn with_topology(options: ReadOptions, topology: Option<&texmap_md_io::Topology>) -> ReadOptions {
    let Some(t) = topology else {
        return options;
    };
    let options = options.atoms(t.n_atoms());
    match t.box_angles {
        Some(angles) => options.box_angles(angles),
        None => options,
    }
}

fn open_trajectory_with(
    file: &Path,
    format: Option<&str>,
    options: ReadOptions,
) -> Result<Sequence> {
    open_parts(&[file.to_path_buf()], format, options)
}

/// The trajectory in `files` (parts read as one; a quoted pattern expanded in natural order).
fn open_parts(files: &[PathBuf], format: Option<&str>, options: ReadOptions) -> Result<Sequence> {
    let mut parts = Vec::new();
    for file in files {
        let text = file.to_string_lossy();
        let found = if text.contains(['*', '?']) && !file.exists() {
            texmap_md_io::sequence::expand(&text)?
        } else {
            vec![file.clone()]
        };
        for part in found {
            if !part.exists() {
                bail!("{}: no such file", part.display());
            }
            if part.is_dir() {
                bail!("{}: is a directory, not a trajectory file", part.display());
            }
            parts.push(part);
        }
    }
    // A shell sorts an unquoted pattern's names as text (dump.10 before dump.2): kept as
    // given, but said.
    let names: Vec<String> = parts.iter().map(|p| p.display().to_string()).collect();
    if let Some(k) = (1..names.len())
        .find(|&k| texmap_md_io::sequence::natural_cmp(&names[k - 1], &names[k]).is_gt())
    {
        eprintln!(
            "texmap: warning: the trajectory's parts are read in the order given, and {} comes before {}: a shell sorts names as text; quote the pattern ('dump.*.lammpstrj') to read the files in natural order",
            names[k - 1],
            names[k]
        );
    }
    let format = match format {
        Some(name) => match Format::from_extension(name) {
            Some(f) => Some(f),
            None => {
                let names: Vec<&str> = Format::ALL.iter().map(|f| f.name()).collect();
                return usage(format!(
                    "--format {name:?}: expected one of {} (or a file extension: lammpstrj, nc, cif, mol, ...)",
                    names.join(", ")
                ));
            }
        },
        None => None,
    };
    Ok(Sequence::open(&parts, format, options)?)
}

/// Each data set of volumetric file `file`: its grid and range, what --isosurface and
/// --volume-set choose from.
fn volumes_json(file: &Path) -> Result<serde_json::Value> {
    let (_, sets) = texmap_md_io::volume::read_volumes(file)?;
    let sets: Vec<_> = sets
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let (lo, hi) = v.range().unwrap_or((0.0, 0.0));
            json!({
                "set": i + 1,
                "name": v.name,
                "points": v.dims,
                "origin": v.origin,
                "steps": v.steps,
                "periodic": v.periodic,
                "min": lo,
                "max": hi,
                "integral": v.integral(),
            })
        })
        .collect();
    Ok(json!(sets))
}

fn info(
    file: &Path,
    more: &[PathBuf],
    format: Option<&str>,
    options: ReadOptions,
    topology: Option<&Path>,
    cell: Option<&str>,
) -> Result<()> {
    use texmap_md_io::TopologyFormat;
    if format.is_none()
        && matches!(
            TopologyFormat::from_path(file),
            Some(TopologyFormat::Psf | TopologyFormat::Prmtop | TopologyFormat::GromacsTop)
        )
    {
        return topology_info(file);
    }
    // A GROMACS energy file or a LAMMPS log holds energies over time, no atoms.
    if format.is_none() {
        let mut head = Vec::new();
        if let Ok(f) = std::fs::File::open(file) {
            let _ = std::io::Read::read_to_end(&mut std::io::Read::take(f, 4096), &mut head);
        }
        let edr = file
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("edr"))
            || texmap_md_io::energy::is_edr(&head);
        if edr || texmap_md_io::energy::is_lammps_log(&head) {
            return energy_info(file, edr);
        }
    }
    // An OpenDX file or a CCP4/MRC map holds a grid and no atoms.
    let grid_only = match texmap_md_io::volume::VolumeFormat::from_path(file) {
        Some(texmap_md_io::volume::VolumeFormat::Dx) => Some("OpenDX"),
        Some(texmap_md_io::volume::VolumeFormat::Mrc) => Some("CCP4/MRC"),
        _ => None,
    };
    if let (None, Some(kind)) = (format, grid_only) {
        let obj = json!({
            "file": file.display().to_string(),
            "format": kind,
            "volumes": volumes_json(file)?,
        });
        println!("{obj}");
        return Ok(());
    }
    let files: Vec<PathBuf> = std::iter::once(file.to_path_buf())
        .chain(more.iter().cloned())
        .collect();
    let topo = topology.map(crate::scene::open_topology).transpose()?;
    let options = with_topology(options, topo.as_ref());
    let cells = cell.map(cell_override).transpose()?;
    let mut traj = open_parts(&files, format, options)?;
    traj.set_cells(cells);
    let mut frame = MdFrame::new();
    let frames = traj.n_frames()?;
    print_warnings(&traj, &mut 0);
    if frames == 0 {
        bail!("{}: the file holds no frame", file.display());
    }
    traj.read_frame(0, &mut frame)?;
    let topo_json = match &topo {
        Some(t) => {
            t.apply(&mut frame, traj.name(), 0)?;
            json!({
                "file": t.name(),
                "atoms": t.n_atoms(),
                "residues": t.n_residues(),
                "bonds": t.bonds.len(),
            })
        }
        None => serde_json::Value::Null,
    };
    let bx = frame.cell.as_ref().map(|c| {
        let l = c.lengths();
        let a = c.angles();
        json!([l[0], l[1], l[2], a[0], a[1], a[2]])
    });
    let first: Vec<_> = frame
        .positions
        .iter()
        .take(3)
        .map(|p| json!([p[0], p[1], p[2]]))
        .collect();
    let mut obj = json!({
        "format": traj.format().name(),
        "atoms": frame.n_atoms(),
        "frames": frames,
        "box": bx,
        "pbc": frame.cell.as_ref().map(|c| c.periodic()),
        "first_positions": first,
    });
    // A trajectory in several files: how many, in the order read.
    if traj.paths().len() > 1 {
        obj["files"] = json!(traj.paths().len());
    }
    // Chains and segments with their atom counts, in order of first appearance: what a user
    // needs to write `chain A` or `segid PROA` selections.
    for (key, labels) in [("chains", &frame.chains), ("segments", &frame.segments)] {
        if !labels.is_empty() {
            obj[key] = json!(label_counts(labels));
        }
    }
    // Bonds the file lists with its atoms (SDF, MOL2, LAMMPS data).
    if !frame.bonds.is_empty() {
        obj["bonds"] = json!(frame.bonds.len());
    }
    // A LAMMPS data file is a topology too: its molecules, as `--topology` counts them.
    if traj.format() == Format::LammpsData {
        let t = texmap_md_io::Topology::from_frame(&frame, traj.name());
        obj["residues"] = json!(t.n_residues());
    }
    // Volumetric data (a cube file, a CHGCAR): each data set's grid and range, what
    // --isosurface and --volume-set choose from.
    if format.is_none() && texmap_md_io::volume::VolumeFormat::from_path(file).is_some() {
        obj["volumes"] = volumes_json(file)?;
    }
    // Per-atom numbers a --color-by can name.
    if !frame.properties.is_empty() {
        let names: Vec<&str> = frame.properties.iter().map(|p| p.name.as_str()).collect();
        obj["properties"] = json!(names);
    }
    // The first frame's secondary structure (what `helix`, `sheet`, `coil` and
    // --color-by structure will see), when it has protein backbones.
    let ss = texmap_md_io::secondary::assign(&frame);
    if !ss.residues().is_empty() {
        let [coil, helix, strand] = ss.counts();
        obj["secondary_structure"] = json!({
            "residues": ss.residues().len(),
            "helix": helix,
            "strand": strand,
            "coil": coil,
            "dssp": ss.codes(),
        });
    }
    if !topo_json.is_null() {
        obj["topology"] = topo_json;
    }
    println!("{obj}");
    Ok(())
}

/// `texmap info` of a file that holds a topology and no coordinates (PSF, AMBER prmtop, GROMACS
/// .top): atoms, residues, bonds, chains and segments, and the properties it gives frames.
fn topology_info(file: &Path) -> Result<()> {
    let t = crate::scene::open_topology(file)?;
    let format = match texmap_md_io::Topology::format_of(file)? {
        Some(texmap_md_io::TopologyFormat::Psf) => "psf",
        Some(texmap_md_io::TopologyFormat::GromacsTop) => "gromacs-top",
        _ => "prmtop",
    };
    let mut obj = json!({
        "format": format,
        "topology_only": true,
        "atoms": t.n_atoms(),
        "residues": t.n_residues(),
        "bonds": t.bonds.len(),
    });
    for (key, labels) in [("chains", &t.chains), ("segments", &t.segments)] {
        if !labels.is_empty() {
            obj[key] = json!(label_counts(labels));
        }
    }
    let properties: Vec<&str> = [("charge", &t.charges), ("mass", &t.masses)]
        .into_iter()
        .filter(|(_, v)| !v.is_empty())
        .map(|(name, _)| name)
        .collect();
    if !properties.is_empty() {
        obj["properties"] = json!(properties);
    }
    println!("{obj}");
    Ok(())
}

/// `texmap info` of a GROMACS energy file or a LAMMPS log: its terms (with units) as `gmx
/// energy`'s menu lists them, the rows and the span of time or steps, and each term's mean,
/// minimum and maximum over the rows that have it (the averages `gmx energy` prints).
fn energy_info(file: &Path, edr: bool) -> Result<()> {
    use texmap_md_io::energy;
    let t = if edr {
        energy::read_edr(file)?
    } else {
        energy::read_lammps_log(file)?
    };
    let x = if edr { "Time" } else { "Step" };
    let span = t.column(x).map(|c| {
        let finite: Vec<f64> = c.iter().copied().filter(|v| v.is_finite()).collect();
        json!([finite.first(), finite.last()])
    });
    let terms: Vec<serde_json::Value> = t
        .names
        .iter()
        .zip(&t.units)
        .zip(&t.columns)
        .filter(|((name, _), _)| name.as_str() != x)
        .map(|((name, unit), c)| {
            let v: Vec<f64> = c.iter().copied().filter(|v| v.is_finite()).collect();
            let mean = (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64);
            let min = v.iter().copied().reduce(f64::min);
            let max = v.iter().copied().reduce(f64::max);
            json!({ "name": name, "unit": unit, "mean": mean, "min": min, "max": max })
        })
        .collect();
    let mut obj = json!({
        "file": file.display().to_string(),
        "format": if edr { "edr" } else { "lammps-log" },
        "rows": t.n_rows(),
        "terms": terms,
    });
    obj[if edr { "time_ps" } else { "steps" }] = span.unwrap_or(serde_json::Value::Null);
    if !edr {
        obj["runs"] = json!(t.runs);
        obj["skipped_lines"] = json!(t.skipped_lines);
    }
    if t.truncated_rows > 0 {
        obj["truncated_rows"] = json!(t.truncated_rows);
    }
    println!("{obj}");
    Ok(())
}

/// Each distinct label with its count, `[label, count]`, in order of first appearance.
fn label_counts(labels: &[texmap_md_io::Label]) -> Vec<(String, usize)> {
    let mut out: Vec<(texmap_md_io::Label, usize)> = Vec::new();
    for l in labels {
        match out.iter_mut().find(|(k, _)| k == l) {
            Some((_, n)) => *n += 1,
            None => out.push((*l, 1)),
        }
    }
    out.into_iter().map(|(k, n)| (k.to_string(), n)).collect()
}

/// `--shard I/N`, or Slurm's job-array variables when the flag is absent: `(I, N)` with
/// `I < N`, or `None` for an unsharded render.
fn shard_spec(a: &RenderArgs) -> Result<Option<(usize, usize)>> {
    let parse = |spec: &str, what: &str| -> Result<(usize, usize)> {
        let bad = || -> Result<(usize, usize)> {
            usage(format!(
                "{what} {spec:?}: expected I/N with 0 <= I < N, e.g. 0/4"
            ))
        };
        let Some((i, n)) = spec.split_once('/') else {
            return bad();
        };
        match (i.trim().parse::<usize>(), n.trim().parse::<usize>()) {
            (Ok(i), Ok(n)) if i < n && n <= 1_000_000 => Ok((i, n)),
            _ => bad(),
        }
    };
    if let Some(spec) = &a.shard {
        return parse(spec, "--shard").map(Some);
    }
    let var = |k: &str| std::env::var(k).ok();
    match (var("SLURM_ARRAY_TASK_ID"), var("SLURM_ARRAY_TASK_COUNT")) {
        (Some(id), Some(count)) => {
            let min = var("SLURM_ARRAY_TASK_MIN").unwrap_or_else(|| "0".into());
            let (Ok(id), Ok(min)) = (id.trim().parse::<usize>(), min.trim().parse::<usize>())
            else {
                return usage(format!(
                    "SLURM_ARRAY_TASK_ID {id:?} / SLURM_ARRAY_TASK_MIN {min:?}: not whole numbers"
                ));
            };
            let spec = format!("{}/{}", id.saturating_sub(min), count.trim());
            parse(
                &spec,
                "Slurm's job array (SLURM_ARRAY_TASK_ID - MIN / COUNT)",
            )
            .map(Some)
        }
        _ => Ok(None),
    }
}

/// Parse `A:B:STEP` against `n` frames (B exclusive, each part optional, a lone `A` is one frame).
pub fn parse_frames(spec: &str, n: usize) -> Result<Vec<usize>> {
    let bad = |why: &str| -> Result<Vec<usize>> {
        usage(format!(
            "--frames {spec:?}: {why} (expected A:B:STEP, e.g. 0:100:10)"
        ))
    };
    let parts: Vec<&str> = spec.split(':').collect();
    if parts.len() > 3 {
        return bad("too many ':'");
    }
    let num = |s: &str, default: usize| -> Option<usize> {
        if s.trim().is_empty() {
            Some(default)
        } else {
            s.trim().parse().ok()
        }
    };
    let Some(a) = num(parts[0], 0) else {
        return bad("start is not a whole number");
    };
    let b = if parts.len() == 1 {
        a + 1
    } else {
        match num(parts[1], n) {
            Some(b) => b.min(n),
            None => return bad("end is not a whole number"),
        }
    };
    let step = match parts.get(2).map(|s| num(s, 1)) {
        None => 1,
        Some(Some(0)) => return bad("step must be at least 1"),
        Some(Some(s)) => s,
        Some(None) => return bad("step is not a whole number"),
    };
    if a >= n {
        return bad(&format!(
            "start frame {a} is past the last frame ({n} frames)"
        ));
    }
    if b <= a {
        return bad(&format!(
            "end {b} is not after start {a}: no frame to render"
        ));
    }
    Ok((a..b).step_by(step).collect())
}

fn method_of(m: MethodArg) -> Option<Method> {
    match m {
        MethodArg::Raycast => Some(Method::Raycast),
        MethodArg::Lut => Some(Method::Lut),
        MethodArg::Template => Some(Method::Template),
        MethodArg::Polygon => Some(Method::Polygon),
        MethodArg::Reference => None,
    }
}

/// Gives every atom of `frame` the property `file`: which file of a several-file scene it
/// came from (0 for FILE, then the --add files in order), for `prop file == 1` selections.
fn set_file_number(frame: &mut MdFrame, number: usize) {
    frame.properties.retain(|p| p.name != "file");
    frame.properties.push(texmap_md_io::Property {
        name: "file".into(),
        values: vec![number as f32; frame.n_atoms()],
    });
}

/// A frame traced by the reference ray tracer (`trace`: the spheres, whether their bonds are
/// drawn, the opaque meshes): the spheres with the opaque `layers`, then each transparent
/// layer traced on its own and laid over the rest as the methods lay it
/// ([`texmap_md_scene::surface::composite`]).
fn trace_layers<E: Into<anyhow::Error>>(
    scene: &SphereScene,
    bonds: bool,
    layers: &[(&texmap_md_scene::surface::MolMesh, f32)],
    trace: impl Fn(
        &SphereScene,
        bool,
        &[&texmap_md_scene::surface::MolMesh],
    ) -> std::result::Result<texmap_core::frame::Frame, E>,
) -> Result<texmap_core::frame::Frame> {
    let opaque: Vec<&texmap_md_scene::surface::MolMesh> =
        layers.iter().filter(|l| l.1 >= 1.0).map(|l| l.0).collect();
    let mut base = trace(scene, bonds, &opaque).map_err(Into::into)?;
    for &(mesh, opacity) in layers.iter().filter(|l| l.1 < 1.0) {
        if mesh.triangles.is_empty() {
            continue;
        }
        let alone = SphereScene::new(scene.materials.clone());
        let layer = trace(&alone, false, &[mesh]).map_err(Into::into)?;
        texmap_md_scene::surface::composite(&mut base, &layer, opacity);
    }
    Ok(base)
}

/// A trajectory's topology (if given), its parts opened as one, and the read options used.
pub(crate) fn open_input(
    file: &Path,
    more: &[PathBuf],
    format: Option<&str>,
    allow_truncated: bool,
    lammps_columns: Option<&str>,
    topology: Option<&Path>,
    cell: Option<&str>,
) -> Result<(Option<texmap_md_io::Topology>, Sequence, ReadOptions)> {
    let topology = topology.map(crate::scene::open_topology).transpose()?;
    let cells = cell.map(cell_override).transpose()?;
    let options = read_options(allow_truncated, lammps_columns);
    let files: Vec<PathBuf> = std::iter::once(file.to_path_buf())
        .chain(more.iter().cloned())
        .collect();
    let mut traj = open_parts(
        &files,
        format,
        with_topology(options.clone(), topology.as_ref()),
    )?;
    traj.set_cells(cells);
    Ok((topology, traj, options))
}

/// `--cell SPEC`: A,B,C[,ALPHA,BETA,GAMMA] (Å, degrees) for every frame, or a CP2K `.cell`
/// file's cells by step.
pub(crate) fn cell_override(spec: &str) -> Result<texmap_md_io::cells::CellOverride> {
    use texmap_md_io::cells::{CellOverride, CellTable};
    let numbers: Option<Vec<f64>> = spec.split(',').map(|p| p.trim().parse().ok()).collect();
    match numbers {
        Some(v) if v.len() == 3 || v.len() == 6 => {
            let angles = if v.len() == 6 {
                [v[3], v[4], v[5]]
            } else {
                [90.0; 3]
            };
            match texmap_md_io::UnitCell::from_lengths_angles([v[0], v[1], v[2]], angles) {
                Ok(cell) => Ok(CellOverride::Fixed(cell)),
                Err(e) => usage(format!("--cell {spec}: {e}")),
            }
        }
        Some(_) => usage(format!(
            "--cell {spec}: expected A,B,C or A,B,C,ALPHA,BETA,GAMMA (Å, degrees), or a CP2K .cell file"
        )),
        None if Path::new(spec).is_file() => Ok(CellOverride::Steps(
            CellTable::read(spec).context("--cell")?.into(),
        )),
        None => usage(format!(
            "--cell {spec}: no such file, and not A,B,C or A,B,C,ALPHA,BETA,GAMMA (Å, degrees)"
        )),
    }
}

/// `--property NAME=FILE` values: per-atom numbers from files, by name.
pub(crate) type AtomValueFiles = Vec<(String, texmap_md_io::values::AtomValues)>;

/// Opens the files of `--property NAME=FILE` options.
pub(crate) fn atom_value_files(specs: &[String]) -> Result<AtomValueFiles> {
    let mut atom_values = Vec::with_capacity(specs.len());
    for spec in specs {
        let Some((name, file)) = spec.split_once('=') else {
            return usage(format!("--property {spec:?}: expected NAME=FILE"));
        };
        let name = name.trim();
        let valid = !name.is_empty()
            && name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '[' | ']' | '.'));
        if !valid {
            return usage(format!(
                "--property {spec:?}: the name must be letters, digits, _ . [ ] (what selections and --color-by can name)"
            ));
        }
        let values = texmap_md_io::values::AtomValues::open_column(file.trim(), name)
            .with_context(|| format!("--property {name}"))?;
        atom_values.push((name.to_string(), values));
    }
    Ok(atom_values)
}

/// Frame `f`'s `--property` values set on `md` (a property of the same name replaced).
pub(crate) fn set_atom_values(md: &mut MdFrame, f: usize, values: &AtomValueFiles) -> Result<()> {
    for (name, file) in values {
        let v = file
            .for_frame(f, md.n_atoms())
            .with_context(|| format!("--property {name}"))?;
        md.properties.retain(|p| p.name != *name);
        md.properties.push(texmap_md_io::Property {
            name: name.clone(),
            values: v.to_vec(),
        });
    }
    Ok(())
}

/// `--displacement-reference FRAME|FILE` given to `plan`: a frame of `traj` (the trajectory
/// `file`) or the first frame of another file.
pub(crate) fn set_displacement_reference(
    plan: &mut texmap_md_scene::MolPlan,
    r: &str,
    traj: &mut Sequence,
    file: &Path,
    options: ReadOptions,
) -> Result<()> {
    if !plan.measures_displacements() {
        return usage(format!(
            "--displacement-reference {r}: nothing measures displacements; add --displacements, --color-by displacement, --arrows displacement, --strain R or --wigner-seitz"
        ));
    }
    let n = traj.n_frames()?;
    let mut reference = MdFrame::new();
    match r.parse::<usize>() {
        Ok(k) if k < n => {
            traj.read_frame(k, &mut reference)?;
            plan.label(&mut reference, traj.name(), k)?;
        }
        Ok(k) => {
            return usage(format!(
                "--displacement-reference {k}: {} has {n} frames (0 to {})",
                file.display(),
                n - 1
            ));
        }
        Err(_) => {
            let mut t = open_trajectory_with(Path::new(r), None, options)?;
            t.read_frame(0, &mut reference)?;
            plan.label(&mut reference, t.name(), 0)?;
        }
    }
    plan.set_displacement_reference(&mut reference)
        .map_err(crate::scene::mol_error)
        .with_context(|| format!("--displacement-reference {r}"))
}

fn render(a: &RenderArgs) -> Result<()> {
    let background = parse_background(&a.background)?;
    if let Some(dpi) = a.dpi
        && !(dpi.is_finite() && (1.0..=100_000.0).contains(&dpi))
    {
        return usage(format!("--dpi {dpi}: expected 1 to 100000 dots per inch"));
    }
    let size = crate::scene::parse_print_size(&a.camera.size, a.dpi)?;
    let (topology, mut traj, options) = open_input(
        &a.file,
        &a.more,
        a.format.as_deref(),
        a.allow_truncated,
        a.lammps_columns.as_deref(),
        a.mol.topology.as_deref(),
        a.mol.cell.as_deref(),
    )?;
    let n = traj.n_frames()?;
    let mut shown = 0;
    print_warnings(&traj, &mut shown);
    if n == 0 {
        bail!("{}: the file holds no frame", a.file.display());
    }
    let frames = parse_frames(&a.frames, n)?;
    let atom_values = atom_value_files(&a.mol.analysis.properties)?;
    // The other files of the scene: each with one frame, or at least as many as the file.
    let mut adds = Vec::with_capacity(a.add.len());
    for file in &a.add {
        let mut t = open_trajectory_with(file, None, options.clone())?;
        let k = t.n_frames()?;
        print_warnings(&t, &mut shown);
        if k != 1 && k < n {
            bail!(
                "--add {}: {k} frames; an added file has one frame (drawn with every frame) or at least as many as {} ({n})",
                file.display(),
                a.file.display()
            );
        }
        adds.push((t, k, MdFrame::new()));
    }
    let label = a
        .label
        .as_deref()
        .map(crate::scene::parse_label)
        .transpose()?;
    let atom_labels = a
        .atom_labels
        .iter()
        .map(|s| crate::scene::parse_atom_label(s))
        .collect::<Result<Vec<_>>>()?;
    let mut sink = crate::movie::Sink::new(&a.output, frames.len(), a.fps, a.depth, a.dpi)?;
    // This part's frames (all of them unless sharded): positions in `frames`.
    let mine = match shard_spec(a)? {
        None => 0..frames.len(),
        Some((i, parts)) => {
            if !matches!(sink, crate::movie::Sink::Frames { .. }) {
                return usage(
                    "--shard writes PNG frames (each part its own); assemble them with texmap movie DIR -o movie.mp4",
                );
            }
            i * frames.len() / parts..(i + 1) * frames.len() / parts
        }
    };
    let quality = crate::scene::quality_options(&a.quality, background)?;
    if quality.is_some() && !matches!(a.method, MethodArg::Raycast | MethodArg::Reference) {
        return usage(
            "--quality, --aa, --ao, --ao-distance, --shadows, --soft-shadows, --light-size, --fog and --outline apply to --method raycast (the default) and reference",
        );
    }
    let mut quality_renderer = texmap_quality::QualityRenderer::new();
    let mut builder = crate::scene::scene_builder(&a.style)?;
    let mut plan = crate::scene::mol_plan(&a.mol, &a.style, topology)?;
    let surface_options = crate::scene::surface_options(&a.mol)?;
    let surface_opacity = a.mol.surface_opacity;
    let polyhedra_opacity = a.mol.polyhedra_opacity;
    let ss = a.supersample;
    if !(1..=8).contains(&ss) {
        return usage(format!("--supersample {ss}: expected 1 to 8"));
    }
    if !(surface_opacity.is_finite() && (0.05..=1.0).contains(&surface_opacity)) {
        return usage(format!(
            "--surface-opacity {surface_opacity}: expected an opacity from 0.05 to 1"
        ));
    }
    if !(polyhedra_opacity.is_finite() && (0.05..=1.0).contains(&polyhedra_opacity)) {
        return usage(format!(
            "--polyhedra-opacity {polyhedra_opacity}: expected an opacity from 0.05 to 1"
        ));
    }
    let isosurfaces = crate::scene::isosurfaces(&a.file, &a.mol)?;
    let mut iso_mesh = texmap_md_scene::surface::MolMesh::default();
    let iso_opacity = isosurfaces.as_ref().map_or(1.0, |i| i.opacity);
    let mut surface = texmap_md_scene::surface::MolMesh::default();
    let mut surface_coloring = crate::scene::surface_coloring(&a.mol)?;
    let mut coarser_warned = false;
    let mut smoother = texmap_md_io::smooth::Smoother::new(a.smooth as usize);
    let mut md = MdFrame::new();
    let mut scene = SphereScene::default();
    let mut renderer = Renderer::new();
    let mut camera: Option<texmap_md_scene::CameraPlan> = None;
    let pb = progress(mine.len() as u64, "rendering");
    let mut skipped_total = 0usize;
    // Frames whose image is on disk, for the error if a later frame fails.
    let mut written: Vec<PathBuf> = Vec::new();
    let export_glb = match &a.export_mesh {
        None => false,
        Some(p) => match p
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
        {
            Some(e) if e == "glb" => true,
            Some(e) if e == "obj" => {
                // An OBJ's texture and material library go beside it, named after it.
                if ["png", "mtl"]
                    .map(|e| p.with_extension(e))
                    .contains(&a.output)
                {
                    return usage(format!(
                        "--export-mesh {} writes its texture and materials to {} and {}, and -o {} is one of them: give the mesh or the image another name",
                        p.display(),
                        p.with_extension("png").display(),
                        p.with_extension("mtl").display(),
                        a.output.display()
                    ));
                }
                false
            }
            _ => {
                return usage(format!(
                    "--export-mesh {}: expected a .glb or .obj file name",
                    p.display()
                ));
            }
        },
    };
    if label.as_ref().is_some_and(|parts| {
        parts
            .iter()
            .any(|p| matches!(p, crate::scene::LabelPart::HBonds))
    }) && !plan.draws_hbonds()
    {
        return usage(
            "--label {hbonds} counts the hydrogen bonds the hbonds style draws: add a representation of them, as --rep 'protein or water=hbonds'",
        );
    }
    if label.as_ref().is_some_and(|parts| {
        parts.iter().any(|p| {
            matches!(
                p,
                crate::scene::LabelPart::Vacancies | crate::scene::LabelPart::Interstitials
            )
        })
    }) && a.mol.analysis.wigner_seitz.is_none()
    {
        return usage(
            "--label {vacancies} and {interstitials} count the point defects --wigner-seitz finds: add --wigner-seitz",
        );
    }
    if label
        .as_ref()
        .is_some_and(|parts| parts.contains(&crate::scene::LabelPart::Grains))
        && !plan.finds_grains()
    {
        return usage("--label {grains} counts the grains --grains finds: add --grains");
    }
    for (given, flag) in [
        (a.mol.analysis.hbond_table.is_some(), "--hbond-table"),
        (a.mol.analysis.hbond_lifetime.is_some(), "--hbond-lifetime"),
        (
            a.mol.analysis.hbond_occupancy.is_some(),
            "--hbond-occupancy",
        ),
    ] {
        if given && !plan.draws_hbonds() {
            return usage(format!(
                "{flag} follows the hydrogen bonds the hbonds style draws: add a representation of them, as --rep 'protein or water=hbonds'"
            ));
        }
    }
    let whole = mine.len() == frames.len();
    let mut analysis_tables = AnalysisTables::create(&a.mol.analysis, whole)?;
    if let Some(r) = &a.mol.analysis.displacement_reference {
        set_displacement_reference(&mut plan, r, &mut traj, &a.file, options)?;
    } else if plan.draws_arrows()
        && a.mol.arrows.starts_with("displacement")
        && frames.first().is_some_and(|f| *f != 0)
    {
        crate::note!(
            "--arrows displacement measures from frame {} (the first frame drawn); start --frames at 0 to measure from the trajectory's first frame",
            frames[0]
        );
    }
    if a.export_mesh.is_some() && !plan.draws_meshes() && isosurfaces.is_none() {
        return usage(
            "--export-mesh writes the cartoon, surface, polyhedra, arrows and ellipsoids styles' meshes and --isosurface's: draw some atoms with one of those styles (or a --rep of them), or give --isosurface",
        );
    }
    for (k, &f) in frames.iter().enumerate() {
        // A part renders its own frames; the first frame of the whole render is read by every
        // part, for the camera, and with trails or squared displacements every frame before its
        // own, for their paths (followed frame by frame across the cell's faces).
        let trail = (plan.draws_trails() || plan.tracks_msd()) && k < mine.start;
        if !mine.contains(&k) && camera.is_some() && !trail {
            continue;
        }
        let fail = |e: anyhow::Error, written: &[PathBuf]| -> anyhow::Error {
            if written.is_empty() {
                return e.context(format!("frame {f}: nothing was written"));
            }
            let list: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
            e.context(format!(
                "frame {f}: stopped after {} complete image(s) of the frames before it: {}",
                written.len(),
                list.join(", ")
            ))
        };
        traj.read_frame(f, &mut md)
            .map_err(|e| fail(e.into(), &written))?;
        smoother
            .smooth(&mut traj, n, f, &mut md)
            .map_err(|e| fail(e.into(), &written))?;
        print_warnings(&traj, &mut shown);
        plan.label(&mut md, traj.name(), f)
            .map_err(|e| fail(e.into(), &written))?;
        set_atom_values(&mut md, f, &atom_values).map_err(|e| fail(e, &written))?;
        if !adds.is_empty() {
            plan.part_bonds(&mut md, true);
            set_file_number(&mut md, 0);
            for (number, (t, k, part)) in adds.iter_mut().enumerate() {
                // A file of one frame is read (and bonded) once, for every frame.
                if *k != 1 || part.n_atoms() == 0 {
                    let at = if *k == 1 { 0 } else { f };
                    t.read_frame(at, part)
                        .map_err(|e| fail(e.into(), &written))?;
                    plan.part_bonds(part, false);
                    set_file_number(part, number + 1);
                }
                md.append(part);
            }
        }
        plan.build(&mut builder, &mut md, &mut scene)
            .map_err(|e| fail(crate::scene::mol_error(e), &written))?;
        if let Some(iso) = &isosurfaces {
            let (mesh, materials) = iso.for_scene(scene.materials.len());
            scene.materials.extend(materials);
            iso_mesh = mesh;
        }
        if mine.contains(&k) {
            analysis_tables
                .write(f, &plan, &md)
                .map_err(|e| fail(e, &written))?;
        }
        if a.box_outline
            && let Some(cell) = &md.cell
        {
            texmap_md_scene::add_box_outline(cell, &mut scene);
        }
        if plan.draws_surface() && mine.contains(&k) {
            surface =
                texmap_md_scene::surface::MolMesh::surface(plan.surface_atoms(), &surface_options)
                    .map_err(|e| fail(e.into(), &written))?;
            if surface.spacing > surface_options.spacing && !coarser_warned {
                coarser_warned = true;
                pb.suspend(|| {
                    eprintln!(
                        "texmap: warning: frame {f}: the surface is sampled every {:.3} Å instead of --surface-spacing {} (its grid would have held more than 2^25 samples)",
                        surface.spacing, surface_options.spacing
                    )
                });
            }
            if let Some(c) = &mut surface_coloring {
                surface = pb
                    .suspend(|| c.apply(&surface, &mut scene.materials, &a.mol))
                    .map_err(|e| fail(e, &written))?;
            }
        }
        if surface_coloring.is_some() && camera.is_none() && !plan.draws_surface() {
            let e = crate::args::UsageError(
                "--surface-color-by colours the molecular surface: draw one with --style surface or --rep 'protein=surface'".into(),
            );
            return Err(fail(e.into(), &written));
        }
        if camera.is_none() {
            // First frame: the camera, and warnings about the style flags.
            let rep_warnings: Vec<_> = plan
                .rep_colorings()
                .flat_map(|c| builder.color_warnings(&md, c))
                .collect();
            for w in builder.warnings(&md).into_iter().chain(rep_warnings) {
                if matches!(w, texmap_md_scene::StyleWarning::NoScalar { .. }) {
                    return Err(fail(anyhow::anyhow!(warning_text(&w)), &written));
                }
                pb.suspend(|| eprintln!("texmap: warning: {}", warning_text(&w)));
            }
            if let Some(w) = crate::scene::unnamed_warning(&plan, &md, traj.name()) {
                pb.suspend(|| eprintln!("texmap: warning: {w}"));
            }
            if a.mol.analysis.pbc != crate::args::PbcArg::Unwrap
                && let Some(w) = crate::scene::split_chain_warning(&md, f)
            {
                pb.suspend(|| eprintln!("texmap: warning: {w}"));
            }
            for w in crate::scene::empty_rep_warnings(&a.mol, &md, f) {
                pb.suspend(|| eprintln!("texmap: warning: {w}"));
            }
            let hydrogens =
                (0..md.n_atoms()).any(|i| texmap_md_io::atom_element(&md, i).symbol() == "H");
            if plan.draws_hbonds() && !hydrogens {
                pb.suspend(|| {
                    eprintln!(
                        "texmap: warning: frame {f} of {} has no hydrogen atoms, so the hbonds style finds no hydrogen bonds: they need explicit hydrogens (add them with pdbfixer, reduce or gmx pdb2gmx)",
                        traj.name()
                    )
                });
            }
            if scene.is_empty()
                && plan.surface_atoms().is_empty()
                && plan.cartoon_mesh().triangles.is_empty()
                && plan.polyhedra_mesh().triangles.is_empty()
                && plan.arrow_atoms().is_empty()
                && plan.ellipsoids().is_empty()
                && iso_mesh.triangles.is_empty()
            {
                let why = if a.mol.reps.is_empty() {
                    a.mol
                        .select
                        .as_deref()
                        .map(|s| format!(": --select {s:?} selects none of frame {f}'s atoms"))
                        .unwrap_or_default()
                } else if plan.draws_hbonds() {
                    format!(
                        ": no --rep selects any of frame {f}'s atoms, and the hbonds representations find no hydrogen bond among theirs"
                    )
                } else {
                    format!(": no --rep selects any of frame {f}'s atoms")
                };
                let hint = if md.cell.is_some() && !a.box_outline {
                    " (a movie whose first frame has nothing selected yet, such as defects to come, can frame the cell instead: add --box-outline)"
                } else {
                    ""
                };
                let e = anyhow::anyhow!("no atom to draw{why}{hint}");
                return Err(fail(e, &written));
            }
            // The camera frames the surface's atoms too, at the surface's radii.
            let mut framed = scene.clone();
            let atoms = plan.surface_atoms();
            for ((c, r), kind) in atoms.centers.iter().zip(&atoms.radii).zip(&atoms.kinds) {
                framed.push(*c, r * surface_options.radius_scale, *kind);
            }
            for p in &plan.cartoon_mesh().positions {
                framed.push(*p, texmap_md_scene::cartoon::COIL_RADIUS, 0);
            }
            for e in plan.ellipsoids() {
                framed.push(e.center, e.bounding_radius(), e.kind);
            }
            texmap_md_scene::push_framed_points(
                &mut framed,
                plan.polyhedra_mesh()
                    .positions
                    .iter()
                    .chain(&plan.arrows_mesh().positions)
                    .chain(plan.arrow_atoms())
                    .chain(&iso_mesh.positions),
            );
            let plan =
                crate::scene::camera_plan(&a.camera, size, &a.path, &md, &framed, frames.len())
                    .map_err(|e| fail(e, &written))?;
            camera = Some(plan);
        }
        if !mine.contains(&k) {
            continue;
        }
        let cam = camera
            .as_ref()
            .expect("planned at the first frame")
            .camera(k, &md)
            .map_err(|e| fail(crate::scene::camera_error(e, &a.path), &written))?;
        // Supersampled: drawn at ss times the size and box-filtered down (labels, captions and
        // the colour bar are drawn after, on the output size, through `shown`).
        let shown = cam.clone();
        let cam = if ss > 1 {
            cam.with_size(cam.width() * ss, cam.height() * ss)
                .map_err(|e| fail(anyhow::anyhow!("--supersample {ss}: {e}"), &written))?
        } else {
            cam
        };
        let lighting = Lighting::default_for(&cam);
        // The ellipsoids: impostors for a sphere method; for the reference ray tracer (and
        // --quality, which traces), meshes tessellated for this view.
        let traced = method_of(a.method).is_none() || quality.is_some();
        let ellipsoid_mesh = if traced {
            texmap_md_scene::ellipsoids::tessellate(
                plan.ellipsoids(),
                Some(&cam),
                texmap_md_scene::ellipsoids::TOLERANCE_PX,
            )
        } else {
            texmap_md_scene::surface::MolMesh::default()
        };
        // The meshes drawn over the spheres, each with its opacity.
        let layers = [
            (plan.cartoon_mesh(), 1.0),
            (&ellipsoid_mesh, 1.0),
            (plan.arrows_mesh(), 1.0),
            (&surface, surface_opacity),
            (plan.polyhedra_mesh(), polyhedra_opacity),
            (&iso_mesh, iso_opacity),
        ];
        let meshes_drawn = layers.iter().any(|l| !l.0.triangles.is_empty());
        // This frame's quality options: bonds as drawn, fog over this frame's depth (the
        // meshes' too).
        let quality = quality.map(|mut q| {
            q.draw_bonds = plan.draws_bonds();
            if a.quality.fog {
                let mut extent = scene.clone();
                texmap_md_scene::push_framed_points(
                    &mut extent,
                    layers.iter().flat_map(|l| &l.0.positions),
                );
                q.fog = texmap_quality::Fog::for_scene(
                    &extent,
                    &cam,
                    [background[0], background[1], background[2]],
                );
            }
            q
        });
        if meshes_drawn && quality.is_some() && method_of(a.method).is_some() && k == mine.start {
            crate::note!(
                "--quality with a cartoon, surface, polyhedra, arrows, ellipsoids or isosurface: the frame is traced by the reference ray tracer (a BVH over the spheres and the meshes), slower than the sphere methods"
            );
        }
        let out = match (method_of(a.method), quality) {
            (Some(_), Some(q)) if !meshes_drawn => {
                quality_renderer
                    .render(&scene, &cam, &lighting, &q)
                    .map_err(|e| fail(anyhow::anyhow!("{e}"), &written))?
                    .frame
            }
            (_, Some(q)) => {
                // Meshes (or --method reference): the reference ray tracer with the quality's
                // effects; a transparent mesh traced on its own and laid over the rest.
                trace_layers(
                    &scene,
                    plan.draws_bonds(),
                    &layers,
                    |spheres, bonds, meshes| {
                        texmap_study::quality::reference_with(
                            spheres, bonds, meshes, &cam, lighting, &q,
                        )
                    },
                )
                .map_err(|e| fail(e, &written))?
            }
            (Some(m), None) => {
                let mut o = texmap_impostor::Options::new(m, lighting);
                o.background = background;
                o.draw_bonds = plan.draws_bonds();
                let mut r = renderer.render(&scene, &cam, &o);
                skipped_total += r.stats.skipped_invalid;
                texmap_md_scene::ellipsoids::draw(
                    plan.ellipsoids(),
                    &scene.materials,
                    &cam,
                    &lighting,
                    &mut r.frame,
                )
                .map_err(|e| fail(e.into(), &written))?;
                // The opaque meshes first: a transparent one shows what is under it.
                let opaque = layers.iter().filter(|l| l.1 >= 1.0);
                for &(mesh, opacity) in opaque.chain(layers.iter().filter(|l| l.1 < 1.0)) {
                    texmap_md_scene::surface::draw_mesh(
                        mesh,
                        &scene.materials,
                        &cam,
                        &lighting,
                        opacity,
                        &mut r.frame,
                    )
                    .map_err(|e| fail(e.into(), &written))?;
                }
                r.frame
            }
            (None, None) => trace_layers(
                &scene,
                plan.draws_bonds(),
                &layers,
                |spheres, bonds, meshes| {
                    harness::render_reference(
                        &harness::reference_scene_with_meshes(spheres, bonds, meshes),
                        &harness::reference_materials(&scene),
                        &cam,
                        lighting,
                        background,
                        1,
                    )
                },
            )
            .map_err(|e| fail(e, &written))?,
        };
        let mut out = out;
        if ss > 1 {
            out = out
                .downsample(ss)
                .expect("the image is ss times the output size");
        }
        // The first frame of the render (with --shard, the part that draws it writes it).
        if let Some(path) = &a.export_mesh
            && k == 0
        {
            let mut all = plan.cartoon_mesh().clone();
            all.append(&surface);
            all.append(plan.polyhedra_mesh());
            all.append(plan.arrows_mesh());
            all.append(&iso_mesh);
            // The whole model, not the view's share of it.
            all.append(&texmap_md_scene::ellipsoids::tessellate(
                plan.ellipsoids(),
                None,
                0.0,
            ));
            if all.triangles.is_empty() {
                let e = anyhow::anyhow!(
                    "--export-mesh: frame {f} has no cartoon, surface, polyhedra, arrows, ellipsoids or isosurface to write"
                );
                return Err(fail(e, &written));
            }
            let (mesh, palette) = all.to_textured(&scene.materials);
            let result = if export_glb {
                texmap_mesh::write_glb(path, &mesh, Some(&palette))
            } else {
                texmap_mesh::write_obj(path, &mesh, Some(&palette))
            };
            result.map_err(|e| fail(e.into(), &written))?;
        }
        let atom_bar =
            plan.uses_builder_coloring() && builder.color_by() == texmap_md_scene::ColorBy::Scalar;
        if plan.uses_builder_coloring() {
            crate::scene::draw_color_bar(&builder, &a.style, &mut out);
        }
        // A mapped isosurface's bar, unless the atoms' own takes the place.
        if let Some(iso) = &isosurfaces {
            iso.draw_color_bar(a.style.no_color_bar || atom_bar, &mut out);
        }
        if let Some(bar) = surface_coloring.as_ref().and_then(|c| c.bar()) {
            let iso_bar = isosurfaces.as_ref().is_some_and(|i| i.bar.is_some());
            if !(a.style.no_color_bar || atom_bar || iso_bar) {
                crate::scene::draw_volume_bar(&bar, &mut out);
            }
        }
        if !atom_labels.is_empty() {
            let at = format!("frame {f} of {}", traj.name());
            let empty = crate::scene::draw_atom_labels(&atom_labels, &md, &shown, &mut out, &at)
                .map_err(|e| fail(e, &written))?;
            if k == mine.start {
                for spec in empty {
                    pb.suspend(|| {
                        eprintln!("texmap: warning: --atom-label {spec:?} selects no atom of {at}")
                    });
                }
            }
        }
        for m in plan.last_measurements() {
            if let Some((xy, _)) = shown.project(m.label_at) {
                let (w, h) = (out.width() as usize, out.height() as usize);
                let rgba = out.color.as_flattened_mut();
                texmap_md_scene::draw_atom_label(rgba, w, h, xy.to_array(), &m.text());
            }
        }
        if let Some(which) = a.axes_tripod {
            let (w, h) = (out.width() as usize, out.height() as usize);
            let axes = crate::scene::tripod_axes(which, md.cell.as_ref(), &shown);
            texmap_md_scene::draw_axes_tripod(out.color.as_flattened_mut(), w, h, &axes);
        }
        if let Some(parts) = &label {
            let hbonds = plan.last_hbonds().len();
            let text = crate::scene::label_text(
                parts,
                f,
                &md,
                traj.name(),
                hbonds,
                plan.last_defects(),
                plan.last_grains().map(|g| g.len()),
            )
            .map_err(|e| fail(e, &written))?;
            let (w, h) = (out.width() as usize, out.height() as usize);
            texmap_md_scene::draw_caption(out.color.as_flattened_mut(), w, h, &text);
        }
        let files = sink
            .write(f, &out, a.depth)
            .map_err(|e| fail(e, &written))?;
        written.extend(files);
        pb.inc(1);
    }
    pb.finish_and_clear();
    let movie = sink.finish()?;
    analysis_tables.commit()?;
    if builder.merged_colors() > 0 {
        eprintln!(
            "texmap: warning: {} more distinct colours than the {} materials a scene holds; each was drawn with the nearest of the first {}",
            builder.merged_colors(),
            crate::scene::MAX_MATERIALS,
            crate::scene::MAX_MATERIALS
        );
    }
    if skipped_total > 0 {
        eprintln!(
            "texmap: warning: {skipped_total} atoms skipped over {} frames (non-finite position or radius)",
            frames.len()
        );
    }
    if mine.len() != frames.len() {
        crate::note!(
            "this part rendered frames {}..{} of the {} asked for",
            mine.start,
            mine.end,
            frames.len()
        );
    }
    match movie {
        Some(path) => crate::note!(
            "wrote {} ({} frames at {} frames/s)",
            path.display(),
            frames.len(),
            a.fps
        ),
        None => crate::note!("wrote {} frame(s)", mine.len()),
    }
    Ok(())
}

fn named_scene(a: &CompareArgs) -> Result<NamedScene> {
    match (&a.scene, &a.file) {
        (Some(s), None) => {
            let id = match s {
                SceneArg::S1 => SceneId::S1,
                SceneArg::S2 => SceneId::S2,
                SceneArg::S3 => SceneId::S3,
                SceneArg::Molecule => SceneId::Molecule,
                SceneArg::MoleculeBallStick => SceneId::MoleculeBallStick,
            };
            Ok(scenes::build(id))
        }
        (None, Some(file)) => {
            // The first frame of the file, styled as `render` would, with the automatic camera.
            let mut builder = crate::scene::scene_builder(&a.style)?;
            let mut traj = open_trajectory(file, None)?;
            let mut md = MdFrame::new();
            if !traj.read_next(&mut md)? {
                bail!("{}: the file holds no frame", file.display());
            }
            let mut spheres = SphereScene::default();
            builder.build(&mut md, &mut spheres);
            for w in builder.warnings(&md) {
                eprintln!("texmap: warning: {}", warning_text(&w));
            }
            let (w, h) = parse_size(&a.size)?;
            let (camera, _) = texmap_md_scene::fit_camera(
                &md,
                &spheres,
                texmap_md_scene::ViewAxis::Auto,
                Some(crate::args::DEFAULT_FOV),
                w,
                h,
            )
            .context("automatic camera")?;
            let stem = file
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "file".into());
            Ok(NamedScene::custom(&stem, spheres, camera))
        }
        _ => usage("give a trajectory FILE or --scene S1|S2|S3|molecule|molecule-bs"),
    }
}

fn write_report(out: &Path, report: &SceneReport) -> Result<()> {
    use texmap_study::report::ERROR_GAIN;
    let dir = out.join(&report.scene);
    write_png(&report.reference, &dir.join("reference.png"))?;
    for run in &report.runs {
        let name = run.method.name();
        write_png(&run.frame, &dir.join(format!("{name}.png")))?;
        let err = harness::error_image(&run.frame, &report.reference, ERROR_GAIN)?;
        write_png(&err, &dir.join(format!("{name}_error.png")))?;
    }
    Ok(())
}

/// `results.csv` and `results.json` of `records` in `out` (created if missing).
fn write_results(out: &Path, records: &[harness::Record]) -> Result<()> {
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create directory {}", out.display()))?;
    texmap_study::record::write_results(out, records)?;
    Ok(())
}

fn compare(a: &CompareArgs) -> Result<()> {
    if a.runs == 0 {
        return usage("--runs must be at least 1");
    }
    let scene = named_scene(a)?;
    let opts = HarnessOptions {
        runs: a.runs,
        ..HarnessOptions::default()
    };
    crate::note!(
        "comparing {} methods and the reference on {} ({} spheres, {}x{})",
        opts.methods.len(),
        scene.name(),
        scene.spheres.len(),
        scene.camera.width(),
        scene.camera.height()
    );
    let pb = progress(1 + opts.methods.len() as u64, "comparing");
    let mut first = true;
    let report = harness::run_scene_with_progress(&scene, &opts, &mut |stage| {
        if !std::mem::take(&mut first) {
            pb.inc(1);
        }
        pb.set_message(stage.to_string());
    })?;
    pb.finish_and_clear();
    write_report(&a.out, &report)?;
    write_results(&a.out, &report.records)?;
    let series = if a.sweeps {
        crate::note!("running the stability sweeps");
        let s = texmap_study::sweeps::run_all_sweeps(128)?;
        let csv = texmap_study::sweeps::series_to_csv(&s);
        write_atomic(&a.out.join("sweeps.csv"), |p| {
            std::fs::write(p, &csv).context("sweeps.csv")
        })?;
        s
    } else {
        Vec::new()
    };
    texmap_study::chart::write_charts(&a.out, &report.records, &series)?;
    print_table(&report.records);
    if a.quality_axis {
        crate::note!(
            "quality axis: anti-aliasing, ambient occlusion and shadow settings against an 8x8 reference with 256 AO rays per pixel"
        );
        let sp = spinner("quality axis");
        let q = texmap_study::quality::run_quality(
            &scene,
            &texmap_study::quality::QualityStudyOptions::default(),
        )?;
        sp.finish_and_clear();
        let records: Vec<harness::Record> = q.runs.iter().map(|r| r.record.clone()).collect();
        texmap_study::quality::write_quality(&a.out, &records)?;
        for r in &q.runs {
            write_png(
                &r.frame,
                &a.out
                    .join(&report.scene)
                    .join(format!("quality_{}.png", r.record.method)),
            )?;
        }
        print_table(&records);
    }
    Ok(())
}

fn print_table(records: &[harness::Record]) {
    println!(
        "{:<10} {:<18} {:>12} {:>9} {:>7} {:>12} {:>12}",
        "scene", "method", "ms/frame", "PSNR dB", "SSIM", "depth mean", "silhouette px"
    );
    for r in records {
        println!(
            "{:<10} {:<18} {:>12.3} {:>9.2} {:>7.4} {:>12.3e} {:>12.3}",
            r.scene, r.method, r.ms_per_frame, r.psnr_db, r.ssim, r.depth_err_mean, r.silhouette_px
        );
    }
}

fn demo(out: &Path, steps: usize, every: usize, size: &str) -> Result<()> {
    use texmap_study::md::{MdParams, MdSystem};
    use texmap_study::report::{AnimationSummary, Section, demo_index_html};
    use texmap_study::scenes::{SCENE_SEED, Seed004System, box_camera};
    let (w, h) = parse_size(size)?;
    if steps == 0 || every == 0 {
        return usage("--steps and --every must be at least 1");
    }
    if steps / every > 5000 {
        return usage("at most 5000 frames: raise --every or lower --steps");
    }
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create output directory {}", out.display()))?;

    // Simulate the Seed 004 system.
    crate::note!("simulating the Seed 004 silicate system (1,115 particles, {steps} LJ steps)");
    let system = Seed004System::generate(SCENE_SEED);
    let mut md = MdSystem::new(&system, MdParams::default())?;
    let frames = md.run(steps, every);
    let center = glam::Vec3::splat(Seed004System::BOX_LEN as f32 * 0.5);
    let cam = box_camera(center, Seed004System::BOX_LEN as f32, w, h)?;
    let lighting = Lighting::default_for(&cam);

    // Animate with every method.
    let pb = progress((frames.len() * Method::ALL.len()) as u64, "animating");
    let mut summaries = Vec::new();
    // The exact method's animation also goes into one movie file: an animated PNG, which needs
    // no external program (texmap movie frames/raycast -o md.mp4 makes an MP4 with ffmpeg).
    let (cam_w, cam_h) = (cam.width(), cam.height());
    let mut movie_opts = texmap_movie::MovieOptions::new(cam_w, cam_h, frames.len() as u32);
    movie_opts.fps = 12.0;
    let mut movie = texmap_movie::MovieWriter::create(&out.join("md.apng"), &movie_opts)?;
    for method in Method::ALL {
        let mut renderer = Renderer::new();
        let opts = harness::study_options(method, lighting);
        let mut total = 0.0;
        for (i, pos) in frames.iter().enumerate() {
            let p64: Vec<glam::DVec3> = pos.iter().map(|v| v.as_dvec3()).collect();
            let scene = system.to_scene(&p64);
            let t = Instant::now();
            let r = renderer.render(&scene, &cam, &opts);
            total += t.elapsed().as_secs_f64() * 1e3;
            write_png(
                &r.frame,
                &out.join("frames")
                    .join(method.name())
                    .join(format!("{i:04}.png")),
            )?;
            if method == Method::Raycast {
                movie.push(&r.frame.color)?;
            }
            pb.inc(1);
        }
        summaries.push(AnimationSummary {
            method: method.name(),
            frames: frames.len(),
            ms_per_frame: total / frames.len() as f64,
        });
    }
    pb.finish_and_clear();
    movie.finish()?;

    // Compare every method with the reference on S1 and run the sweeps.
    crate::note!("comparing every method with the reference ray tracer (S1)");
    let sp = spinner("comparing every method with the reference (S1)");
    let scene = scenes::build_sized(SceneId::S1, w, h)?;
    let report = harness::run_scene(&scene, &HarnessOptions::default())?;
    sp.finish_and_clear();
    write_report(out, &report)?;
    write_results(out, &report.records)?;
    crate::note!("stability sweeps");
    let sp = spinner("stability sweeps");
    let series = texmap_study::sweeps::run_all_sweeps(128)?;
    sp.finish_and_clear();
    let csv = texmap_study::sweeps::series_to_csv(&series);
    write_atomic(&out.join("sweeps.csv"), |p| {
        std::fs::write(p, &csv).context("sweeps.csv")
    })?;
    let charts = texmap_study::chart::write_charts(out, &report.records, &series)?;
    let mut sections: Vec<Section> = Vec::new();

    // Environment mapping (Seed 003): the study at a small size, and one image per method.
    crate::note!("environment mapping (Seed 003)");
    let env_dir = out.join("envmap");
    let env_opts = texmap_study::envmap::EnvStudyOptions {
        width: 160,
        height: 120,
        samples: 2,
        timed_frames: 3,
        map_size: 128,
        ..Default::default()
    };
    let sp = spinner("environment-mapping study");
    let env_records = texmap_study::envmap::run(&env_opts)?;
    sp.finish_and_clear();
    texmap_study::envmap::write(&env_dir, &env_records)?;
    let mut names = Vec::new();
    for (name, frame) in texmap_study::envmap::demo_frames(240, 180, 256, 2)? {
        write_png(&frame, &env_dir.join(format!("{name}.png")))?;
        names.push(name);
    }
    sections.push(texmap_study::report::envmap_section(
        &env_records,
        &names,
        "envmap",
    ));

    // Terrain (Seed 000): a built-in DEM and photo, a fly-through and the sampler comparison.
    crate::note!("terrain flight view (Seed 000)");
    let sp = spinner("terrain flight view and sampler study");
    sections.push(Section {
        title: "Terrain flight view (Seed 000)".into(),
        html: texmap_study::terrain::demo_section(out)?,
    });
    sp.finish_and_clear();
    // Materials: a built-in crystal as VESTA draws it.
    crate::note!("materials (coordination polyhedra)");
    sections.push(Section {
        title: "Materials: a crystal's coordination polyhedra".into(),
        html: texmap_study::materials::demo_section(out)?,
    });
    let html = demo_index_html(&summaries, &report, &charts, out, &sections);
    write_atomic(&out.join("index.html"), |p| {
        std::fs::write(p, &html).context("index.html")
    })?;
    print_table(&report.records);
    crate::note!("open {}", out.join("index.html").display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_ranges_parse_like_python_slices() {
        assert_eq!(parse_frames("0:", 5).unwrap(), vec![0, 1, 2, 3, 4]);
        assert_eq!(parse_frames("::2", 5).unwrap(), vec![0, 2, 4]);
        assert_eq!(parse_frames("1:100:2", 6).unwrap(), vec![1, 3, 5]);
        assert_eq!(parse_frames("3", 5).unwrap(), vec![3]);
        for bad in ["7", "0:5:0", "a:b", "1:2:3:4", "-1:", "4:2", "3:3"] {
            assert!(parse_frames(bad, 5).is_err(), "{bad}");
        }
    }
}

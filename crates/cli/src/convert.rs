//! `texmap convert`: a trajectory read, analysed and cut down as `texmap render` would draw it,
//! then written to a file instead of drawn (OVITO's Export File, `gmx trjconv`, VMD's
//! `animate write`).
//!
//! Each frame goes through the same steps as a render's: read, smoothed, labelled from the
//! topology, `--property` files, then [`texmap_md_scene::MolPlan::prepare`] (periodic
//! boundaries, replication, the analyses, `--compute`, alignment). `--select` is evaluated on
//! the prepared frame, so it can name what the analyses computed, and the atoms it picks are
//! written with the properties `--columns` names (all of them by default).

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::{Args, FromArgMatches};
use texmap_md_io::{Dropped, Format, Frame as MdFrame, Per, Writer};

use crate::args::{AnalysisArgs, MolArgs, StyleArgs, usage};

#[derive(Args, Debug)]
#[command(after_help = CONVERT_AFTER_HELP)]
pub struct ConvertArgs {
    /// Trajectory file (any format `texmap info` reads; gzip- or bzip2-compressed files too; a
    /// quoted pattern such as 'dump.*.lammpstrj' reads the files it matches in natural order).
    pub file: PathBuf,
    /// More parts of the same trajectory, read after FILE as one (prod2.xtc prod3.xtc).
    #[arg(value_name = "MORE")]
    pub more: Vec<PathBuf>,
    /// Format of the input, when the extension does not tell it.
    #[arg(long)]
    pub format: Option<String>,
    /// Read only the complete frames of a file whose last frame is cut short, with a warning.
    #[arg(long)]
    pub allow_truncated: bool,
    /// Column names of a LAMMPS binary dump (.bin) from an older LAMMPS, which does not
    /// name them (no magic header, or format revision 1), as the dump custom command lists
    /// them ('id type x y z vx vy vz'); a newer dump names its own. Without them such a file of 5 or 8 values per
    /// atom is read as dump atom's default ('id type xs ys zs [ix iy iz]').
    #[arg(long, value_name = "NAMES")]
    pub lammps_columns: Option<String>,
    /// Topology giving names, elements, residues and bonds to the trajectory's atoms (PDB,
    /// PDBx/mmCIF or BinaryCIF, GRO, PSF, AMBER prmtop, GROMACS .tpr or .top, LAMMPS data file), as for texmap
    /// render.
    #[arg(long, value_name = "FILE")]
    pub topology: Option<PathBuf>,
    /// A periodic cell for frames whose file holds none (plain XYZ, CP2K, ORCA, xtb), or to
    /// replace the file's: A,B,C in Å (right angles) or A,B,C,ALPHA,BETA,GAMMA (degrees), as
    /// VMD's 'pbc set {A B C}'; or a CP2K cell file (PROJECT-1.cell), each frame's cell found by
    /// its step (the 'i =' of CP2K's .xyz comment lines; a step the file lacks is an error).
    /// --pbc and the analyses that need a box then work on such trajectories.
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
    /// Frames to write, A:B:STEP (B exclusive, each part optional: "::10", "5:", "3").
    #[arg(long, default_value = "0:")]
    pub frames: String,
    /// Average each atom's position over 2N+1 frames centred on the frame (VMD's trajectory
    /// smoothing; fewer at the ends), before anything else.
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub smooth: u32,
    /// Write only the atoms SEL selects, in the VMD/MDAnalysis language, evaluated on every
    /// frame after the analyses (OVITO's Expression selection and Delete selected): 'protein',
    /// 'not resname SOL', 'not cna fcc' (a crystal's defects), 'prop grain == 0',
    /// 'prop site_occupancy != 1' (point defects). The atoms keep their ids (their numbers in
    /// the whole frame, from 1, when the file has none). A .gro, .pdb, .cif, .dcd or .xtc
    /// output holds the same atoms in every frame, so there the selection must pick as many in
    /// each.
    #[arg(long, value_name = "SEL")]
    pub select: Option<String>,
    /// The per-atom properties to write, in this order (extended XYZ and LAMMPS dump outputs):
    /// --columns cna,grain,shear_strain. Default: every property the file has and the analyses
    /// computed (texmap info lists a file's). 'cna' and 'diamond' name the structure types as
    /// OVITO numbers them (adaptive CNA: 0 other, 1 FCC, 2 HCP, 3 BCC, 4 icosahedral; Identify
    /// diamond structure: 0 other, 1 cubic, 2-3 its neighbours, 4 hexagonal, 5-6 its), computed
    /// when asked for. Positions, ids, types, velocities and radii are written whenever the
    /// frame has them.
    #[arg(long, value_name = "NAME,...", value_delimiter = ',')]
    pub columns: Option<Vec<String>>,
    /// The output file; its extension names the format: .xyz/.extxyz (extended XYZ with every
    /// column, as OVITO, ASE and QUIP read it), .lammpstrj/.dump (a LAMMPS dump: id type x y z
    /// and the columns, read by LAMMPS's rerun, OVITO and MDAnalysis), .data/.lmp (one frame as
    /// a LAMMPS data file for read_data: atom style full, molecular, charge or atomic by
    /// whether the frame has bonds and charges, types with their masses, bonds typed by their
    /// atoms' types, the Velocities a data file had (not a trajectory's: warned), image flags
    /// (ix iy iz) in the Atoms lines, the cell
    /// rotated into LAMMPS's restricted triclinic box), .gro (GROMACS: residues,
    /// names, positions to 0.001 nm, velocities, the box), .pdb (multi-MODEL, the 'occupancy'
    /// and 'bfactor' properties in their columns), .cif/.mmcif (PDBx/mmCIF, for ChimeraX, PyMOL,
    /// VMD and gemmi: frames as models, the 'occupancy' and 'bfactor'
    /// properties, the first frame's box; no limit on atoms, residue numbers or chain names),
    /// .dcd, .xtc (positions, the box, steps and times; a .dcd's times are its steps × its
    /// time step), .trr (GROMACS, single precision: positions,
    /// the box, velocities, and the forces fx fy fz in kJ/(mol Å) as a TRR gives them; frames of
    /// a TRR without positions, which no frame can carry, are skipped with a warning naming the
    /// velocities and forces they held), .nc/.ncdf (AMBER NetCDF for cpptraj,
    /// MDAnalysis, MDTraj, VMD: time, coordinates, the box as lengths and angles, velocities in
    /// AMBER's units with its scale_factor; no forces), .gsd (HOOMD-blue: the box in HOOMD's
    /// centred form, atoms wrapped into it with their images, types, velocities, diameters,
    /// masses, charges, orientations, bonds), POSCAR/.vasp (VASP 5, one frame: Direct
    /// coordinates, each run of one element its own species group in the input's order,
    /// velocities), XDATCAR (a VASP trajectory; the header repeated when the cell changes) or
    /// .sdf/.sd/.mol (MDL SD file for RDKit, Open Babel, PyMOL, ChimeraX and docking tools: one
    /// molfile record per frame, elements, positions, bonds with their orders, integer
    /// 'charge' values as formal charges; bonds the input lacks come from --topology, else from
    /// distances, without orders).
    /// Data the output has no place for (velocities in a .dcd, a property other than
    /// occupancy and bfactor in a .pdb, partial charges in an .sdf, bonds in a .xyz, the box
    /// in an .sdf, ...) is named in a warning at the end, one per kind, with the formats that
    /// keep it.
    /// Not compressed: gzip the file afterwards.
    /// Written whole or not at all. Without it, only the analyses' outputs are written (the
    /// --*-table options, --msd-lags, --density-map, --pca-projection, --pca-vectors,
    /// --pca-extremes, --dssp-timeline).
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Find the hydrogen bonds among the atoms SEL picks in every frame (MDAnalysis's
    /// HydrogenBondAnalysis criterion: --hbond-distance, --hbond-angle; donors from the
    /// topology's bonds, or bonds by distance) for --hbond-table and --hbond-lifetime:
    /// 'protein', 'protein or water'.
    #[arg(long, value_name = "SEL")]
    pub hbonds: Option<String>,
    #[command(flatten)]
    pub analysis: AnalysisArgs,
}

const CONVERT_AFTER_HELP: &str = "\
Examples:
  texmap convert md.xtc --topology md.gro --select protein --frames ::10 -o protein.xtc   # a smaller trajectory
  texmap convert md.xtc --topology md.gro --pbc unwrap --align backbone -o fitted.dcd      # molecules whole, superposed
  texmap convert dump.lammpstrj --select 'not cna fcc' -o defects.xyz                      # the defects and their structure types
  texmap convert anneal.lammpstrj --grains --columns grain,lattice_rmsd -o grains.lammpstrj  # OVITO's Grain segmentation, per atom
  texmap convert cascade.lammpstrj --wigner-seitz atoms --select 'prop site_occupancy != 1' -o defects.xyz
  texmap convert 1abc.cif --compute 'bfactor=coordination' --coordination 3.5 -o coord.pdb  # a property in the B-factor column (PyMOL, ChimeraX)
  texmap convert md.xtc --topology md.gro --select 'not water' --frames ::10 -o models.cif   # PDBx/mmCIF models, any size (ChimeraX, PyMOL, gemmi)
  texmap convert md.trr --topology md.tpr --select protein -o prot.trr                       # velocities and forces kept (GROMACS TRR)
  texmap convert dump.lammpstrj -o run.gsd                                                    # HOOMD-blue GSD; or run.nc (AMBER NetCDF), XDATCAR (VASP)
  texmap convert relaxed.cif --frames 0 -o POSCAR                                             # one structure for VASP
  texmap convert melt.lammpstrj --frames 100: --rdf 10 --rdf-partial --rdf-table gr.csv    # g(r), total and per pair of types, averaged over frames 100 on
  texmap convert md.xtc --topology md.gro --msd-lags lags.csv                               # MSD over every time origin; prints D per kind
  texmap convert md.xtc --topology md.gro --align backbone --rmsf-table rmsf.csv            # flexibility; colour by it: render --property rmsf=rmsf.csv
  texmap convert md.trr --topology md.gro --vacf-table vacf.csv --vdos-table vdos.csv       # velocity autocorrelation (Green-Kubo D) and its spectrum
  texmap convert slab.lammpstrj --profile-table rho.csv --profile-axis z --profile-bins 200  # density profile across an interface
  texmap convert md.xtc --topology md.psf --order-table scd.csv --order-select 'resname POPC and name C2* C3*' --order-chart scd.png  # lipid tail order, -S_CD per carbon
  texmap convert md.xtc --topology md.gro --membrane-table mem.csv --membrane-select 'name P'  # bilayer thickness and area per lipid per frame
  texmap convert md.xtc --topology md.gro --sasa protein --sasa-residue-table exposed.csv   # solvent-accessible area per residue and frame (MDTraj's shrake_rupley)
  texmap convert md.xtc --topology md.gro --pbc unwrap --gyration-table rg.csv --gyration-select protein  # compactness over time
  texmap convert md.xtc --topology md.gro --dihedral-table rama.csv                         # phi, psi, omega per residue and frame
  texmap convert md.xtc --topology md.gro --survival-table sp.csv --survival-select 'name OW and around 3.5 protein'  # water residence
  texmap convert md.xtc --topology md.gro --pbc unwrap --align 'name CA' --pca-table pca.csv --pca-projection proj.csv  # principal components (gmx covar)
  texmap convert md.xtc --topology md.gro --pbc unwrap --align 'name CA' --pca-extremes pc1.pdb && texmap render pc1.pdb --style tube -o pc1.mp4  # PC1's motion as a movie
  texmap convert md.xtc --topology md.gro --pbc unwrap --dssp-table ss.csv --dssp-timeline ss.png  # secondary structure per frame and its timeline (gmx dssp)
  texmap convert md.xtc --topology md.gro --contacts-table q.csv --contacts 'name CA;name CA' --contacts-radius 8  # native contacts Q(t)
  texmap convert md.xtc --topology md.gro --align protein --density-map water.dx --density-select 'name OW'  # where water stays (VMD volmap);
  texmap render md.xtc --topology md.gro --frames 0 --volume water.dx --isosurface 0.05 -o sites.png  # over the frame it was aligned to

The selection and the analyses are those of texmap render; an analysis's property (cna is a
selection keyword; coordination, grain, centrosymmetry, shear_strain, ... are properties) is
written as a column of the output.";

/// The format of `flag`'s `output`, from its extension; only the formats with a writer. A
/// `.cif` is written as PDBx/mmCIF (`Format::from_path` names it so; reading tells a
/// crystallographic CIF by its content). The writers do not compress: a `.gz` or `.bz2` name
/// is refused rather than given uncompressed bytes that no reader would take for gzip.
pub(crate) fn output_format(flag: &str, output: &std::path::Path) -> Result<Format> {
    let compressed = output
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gz") || e.eq_ignore_ascii_case("bz2"));
    if compressed {
        return usage(format!(
            "{flag} {}: trajectories are written uncompressed; write {} and compress it afterwards",
            output.display(),
            output.with_extension("").display()
        ));
    }
    let format = Format::from_path(output);
    match format {
        Some(
            f @ (Format::Xyz
            | Format::LammpsDump
            | Format::LammpsData
            | Format::Gro
            | Format::Pdb
            | Format::Mmcif
            | Format::Dcd
            | Format::Xtc
            | Format::Trr
            | Format::Netcdf
            | Format::Vasp
            | Format::Gsd
            | Format::Sdf),
        ) if !is_restart(output) => Ok(f),
        _ => usage(format!(
            "{flag} {}: expected a .xyz/.extxyz, .lammpstrj/.dump, .data/.lmp, .gro, .pdb, .cif/.mmcif, .dcd, .xtc, .trr, .nc/.ncdf, .gsd, .sdf/.sd/.mol, POSCAR/.vasp or XDATCAR file name",
            output.display()
        )),
    }
}

/// Whether no atom number repeats (an empty list: the writer numbers atoms 1, 2, ...).
fn unique_ids(ids: &[i64]) -> bool {
    let mut seen = std::collections::HashSet::with_capacity(ids.len());
    ids.iter().all(|id| seen.insert(*id))
}

/// An AMBER restart name (`.ncrst`): read as NetCDF, but the writer writes trajectories, which
/// AMBER would not take for a restart.
fn is_restart(output: &std::path::Path) -> bool {
    output
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("ncrst"))
}

/// The render options `mol_plan` takes, at their command-line defaults, with the convert's
/// topology and analyses.
fn plan_args(a: &ConvertArgs) -> Result<(MolArgs, StyleArgs)> {
    fn defaults<T: Args + FromArgMatches>() -> Result<T> {
        let command = T::augment_args(clap::Command::new("texmap"));
        let matches = command.try_get_matches_from(["texmap"])?;
        Ok(T::from_arg_matches(&matches)?)
    }
    let mut mol: MolArgs = defaults()?;
    mol.topology = a.topology.clone();
    mol.index = a.index.clone();
    mol.define = a.define.clone();
    mol.analysis = a.analysis.clone();
    Ok((mol, defaults()?))
}

pub fn convert(a: &ConvertArgs) -> Result<()> {
    let format = match &a.output {
        Some(out) => Some(output_format("-o", out)?),
        None => {
            let tables = a.analysis.outputs();
            if tables.iter().all(|(_, given)| !given) {
                let names: Vec<&str> = tables.iter().map(|(flag, _)| *flag).collect();
                return usage(format!(
                    "nothing to write: give -o FILE, or a table of the analyses ({})",
                    names.join(", ")
                ));
            }
            if a.select.is_some() || a.columns.is_some() {
                return usage(
                    "--select and --columns choose what -o FILE holds (the tables see every atom): give -o FILE",
                );
            }
            None
        }
    };
    let fixed_atoms = matches!(
        format,
        Some(
            Format::Gro
                | Format::Pdb
                | Format::Mmcif
                | Format::Dcd
                | Format::Xtc
                | Format::Trr
                | Format::Netcdf
        )
    );
    if let (Some(out), Some(_)) = (&a.output, &a.columns)
        && !matches!(format, Some(Format::Xyz | Format::LammpsDump))
    {
        return usage(format!(
            "--columns: {} holds no per-atom columns of our choosing; write .xyz or .lammpstrj (a .pdb or .cif writes the 'occupancy' and 'bfactor' properties: --compute 'bfactor=NAME')",
            out.display()
        ));
    }
    let (topology, mut traj, options) = crate::commands::open_input(
        &a.file,
        &a.more,
        a.format.as_deref(),
        a.allow_truncated,
        a.lammps_columns.as_deref(),
        a.topology.as_deref(),
        a.cell.as_deref(),
    )?;
    let n = traj.n_frames()?;
    let mut shown = 0;
    crate::commands::print_warnings(&traj, &mut shown);
    if n == 0 {
        anyhow::bail!("{}: the file holds no frame", a.file.display());
    }
    let frames = crate::commands::parse_frames(&a.frames, n)?;
    let atom_values = crate::commands::atom_value_files(&a.analysis.properties)?;
    let select = a
        .select
        .as_deref()
        .map(|s| crate::scene::parse_selection("--select", s))
        .transpose()?;
    let (mol, style) = plan_args(a)?;
    let mut plan = crate::scene::mol_plan(&mol, &style, topology)?;
    let wants_hbonds = a.analysis.hbond_table.is_some()
        || a.analysis.hbond_lifetime.is_some()
        || a.analysis.hbond_occupancy.is_some();
    match (&a.hbonds, wants_hbonds) {
        (Some(sel), true) => {
            plan.set_hbond_select(Some(crate::scene::parse_selection("--hbonds", sel)?))
        }
        (Some(_), false) => {
            return usage(
                "--hbonds finds the bonds --hbond-table, --hbond-lifetime and --hbond-occupancy write: add one",
            );
        }
        (None, true) => {
            return usage(
                "--hbond-table, --hbond-lifetime and --hbond-occupancy list the hydrogen bonds among --hbonds' atoms: add it, as --hbonds 'protein or water'",
            );
        }
        (None, false) => {}
    }
    if let Some(r) = &a.analysis.displacement_reference {
        crate::commands::set_displacement_reference(&mut plan, r, &mut traj, &a.file, options)?;
    }
    let mut tables = crate::tables::AnalysisTables::create(&a.analysis, true)?;
    let mut smoother = texmap_md_io::smooth::Smoother::new(a.smooth as usize);
    let mut md = MdFrame::new();
    let pb = crate::commands::progress(frames.len() as u64, "converting");
    let mut first_atoms: Option<usize> = None;
    let mut atoms_written = 0usize;
    let mut without_positions = Skipped::default();
    let mut lost = std::collections::BTreeMap::<Dropped, Lost>::new();
    let mut conect_note_shown = false;
    let mut run = |mut writer: Option<Writer>| -> Result<()> {
        for &f in &frames {
            let at = |e: anyhow::Error| e.context(format!("frame {f}: nothing was written"));
            traj.read_frame(f, &mut md).map_err(|e| at(e.into()))?;
            if let Some(w) = traj.without_positions() {
                // mdrun writes frames of only velocities or forces when nstvout or nstfout
                // differ from nstxout: without positions there is nothing to analyse or write,
                // and what they held is named at the end.
                without_positions.frames += 1;
                without_positions.atoms = without_positions.atoms.max(w.atoms);
                without_positions.velocities += usize::from(w.velocities);
                without_positions.forces += usize::from(w.forces);
                pb.inc(1);
                continue;
            }
            smoother
                .smooth(&mut traj, n, f, &mut md)
                .map_err(|e| at(e.into()))?;
            crate::commands::print_warnings(&traj, &mut shown);
            plan.label(&mut md, traj.name(), f)
                .map_err(|e| at(e.into()))?;
            crate::commands::set_atom_values(&mut md, f, &atom_values).map_err(at)?;
            plan.prepare(&mut md)
                .map_err(|e| at(crate::scene::mol_error(e)))?;
            tables.write(f, &plan, &md).map_err(at)?;
            // A PDB keeps the topology's bonds as CONECT records (the frame's own, an SDF's or
            // a MOL2's, when it has them); --select keeps those among the atoms it keeps. Not
            // when the atoms' numbers repeat (a GRO's wrap at 100,000): CONECT names atoms by
            // number, so the file is written without them, as before, and says so.
            if format == Some(Format::Pdb)
                && md.bonds.is_empty()
                && let Some(t) = plan.topology()
                && !t.bonds.is_empty()
            {
                if unique_ids(&md.ids) {
                    md.bonds.clone_from(&t.bonds);
                    md.bond_orders.clear();
                } else if !conect_note_shown {
                    conect_note_shown = true;
                    crate::note!(
                        "{}: the atoms' numbers repeat (a GRO numbers past 99,999 from 0 again), so the topology's bonds are not written as CONECT records, which name atoms by number",
                        a.file.display()
                    );
                }
            }
            // An SD file is a molecule with its bonds: those the frame lists (an SDF's, a
            // MOL2's), else the topology's, else those of the positions by distance (a PDBQT
            // pose, an XYZ), without orders (written single); --select keeps those among the
            // atoms it keeps.
            if format == Some(Format::Sdf) && md.bonds.is_empty() {
                md.bond_orders.clear();
                match plan.topology().filter(|t| !t.bonds.is_empty()) {
                    Some(t) => md.bonds.clone_from(&t.bonds),
                    None => md.bonds = texmap_md_io::bonds::bonds_by_distance(&md, false).pairs,
                }
            }
            if let Some(columns) = &a.columns {
                structure_columns(&mut md, columns);
            }
            if let Some(sel) = &select {
                if md.ids.is_empty() {
                    // The kept atoms keep their numbers in the whole frame (1, 2, ...).
                    md.ids = (1..=md.n_atoms() as i64).collect();
                }
                let keep = sel.evaluate(&md).map_err(|error| {
                    at(crate::scene::mol_error(
                        texmap_md_scene::MolError::Selection {
                            role: texmap_md_scene::SelectionRole::Select,
                            error,
                        },
                    ))
                })?;
                md.retain_atoms(&keep);
            }
            if let Some(columns) = &a.columns {
                keep_columns(&mut md, columns).map_err(at)?;
            }
            let count = md.n_atoms();
            match first_atoms {
                None => first_atoms = Some(count),
                Some(first) if fixed_atoms && count != first => {
                    let what = if select.is_some() {
                        format!("--select picks {count} atoms here")
                    } else {
                        format!("this frame has {count} atoms")
                    };
                    return Err(at(anyhow::anyhow!(
                        "{what} and {first} in the first frame written; a {} file holds the same atoms in every frame: write .xyz or .lammpstrj, whose frames may differ, or select by something that does not change",
                        format.map_or("", |f| f.name())
                    )));
                }
                Some(_) => {}
            }
            if let (Some(w), Some(out)) = (&mut writer, &a.output) {
                // What the format has no place for, named once at the end.
                for kind in w.dropped(&md) {
                    let l = lost.entry(kind).or_insert_with_key(|kind| Lost {
                        reason: w.why_dropped(kind),
                        kept_by: kind.kept_by(&md),
                        output: w.output_name(),
                        ..Lost::default()
                    });
                    l.frames += 1;
                    l.atoms = l.atoms.max(count);
                    l.bonds = l.bonds.max(md.bonds.len());
                }
                w.write_frame(&md)
                    .map_err(|e| at(e.into()))
                    .with_context(|| format!("-o {}", out.display()))?;
                atoms_written += count;
            }
            pb.inc(1);
        }
        if let Some(w) = writer {
            w.finish()?;
        }
        Ok(())
    };
    match (&a.output, format) {
        (Some(out), Some(format)) => {
            crate::output::write_atomic(out, |tmp| run(Some(Writer::create_as(tmp, format, out)?)))?
        }
        _ => run(None)?,
    }
    pb.finish_and_clear();
    tables.commit()?;
    let w = without_positions;
    if w.frames > 0 {
        let wrote = if a.output.is_some() {
            "not written"
        } else {
            "not analysed"
        };
        crate::note!(
            "warning: {} frame(s) of {} have no positions (TRR frames of only velocities or forces: mdrun's nstvout or nstfout differs from nstxout), so their velocities ({} frame(s)) and forces ({} frame(s)) of {} atoms were {wrote}; write those steps with positions (nstxout) to keep them",
            w.frames,
            a.file.display(),
            w.velocities,
            w.forces,
            w.atoms
        );
    }
    // A trajectory of coordinates is read with its topology: the atoms' names, residues and
    // bonds it has no place for are one note, not a warning each.
    let coordinates_only = matches!(
        format,
        Some(Format::Dcd | Format::Xtc | Format::Trr | Format::Netcdf)
    );
    let topological = |k: &Dropped| {
        coordinates_only
            && matches!(
                k,
                Dropped::Names
                    | Dropped::Types
                    | Dropped::Residues
                    | Dropped::Chains
                    | Dropped::Segments
                    | Dropped::Bonds
                    | Dropped::BondOrders
            )
    };
    let topology: Vec<String> = lost
        .keys()
        .filter(|k| topological(k))
        .map(Dropped::what)
        .collect();
    if let (false, Some(out)) = (topology.is_empty(), &a.output) {
        crate::note!(
            "note: {} holds coordinates, not {}: read it with its topology (the --topology file, or this conversion again with --frames 0 -o topology.pdb)",
            out.display(),
            topology.join(", ")
        );
    }
    for (kind, l) in lost.iter().filter(|(k, _)| !topological(k)) {
        crate::note!("warning: {}", l.message(kind));
    }
    if let Some(out) = &a.output {
        crate::note!(
            "wrote {} frame(s), {} atoms in all, to {}",
            frames.len() - w.frames,
            atoms_written,
            out.display()
        );
    }
    Ok(())
}

/// TRR frames without positions, which no frame can carry: how many, the atoms in the largest,
/// and how many held velocities and forces.
#[derive(Default, Clone, Copy)]
struct Skipped {
    frames: usize,
    atoms: usize,
    velocities: usize,
    forces: usize,
}

/// One kind of data the output does not hold ([`Writer::dropped`]), over the frames written:
/// how many frames carried it, the atoms and bonds of the largest, why the output lost it and
/// which outputs keep it (as the first frame that carried it tells).
#[derive(Default)]
struct Lost {
    frames: usize,
    atoms: usize,
    bonds: usize,
    reason: String,
    kept_by: Vec<&'static str>,
    output: &'static str,
}

impl Lost {
    /// "the per-atom property 'grain' of 4000 atoms (10 frames) was not written: a .gro file
    /// has no place for it (.xyz, .lammpstrj keep it)".
    fn message(&self, kind: &Dropped) -> String {
        let frames = match self.frames {
            1 => "1 frame".to_string(),
            n => format!("{n} frames"),
        };
        let counted = match kind.per() {
            Per::Atom => format!("of {} atoms ({frames})", self.atoms),
            Per::Bond => format!("of {} bonds ({frames})", self.bonds),
            Per::Frame => format!("of {frames}"),
        };
        let (was, it) = if kind.singular() {
            ("was", "it")
        } else {
            ("were", "them")
        };
        let others: Vec<&str> = self
            .kept_by
            .iter()
            .copied()
            .filter(|o| *o != self.output)
            .collect();
        let keep = if others.is_empty() {
            String::new()
        } else {
            format!(" ({} keep {it})", others.join(", "))
        };
        format!(
            "{} {counted} {was} not written: {}{keep}",
            kind.what(),
            self.reason
        )
    }
}

/// The structure types `columns` asks for and the frame does not have yet, as OVITO numbers
/// them: 'cna' (adaptive CNA: 0 other, 1 FCC, 2 HCP, 3 BCC, 4 icosahedral) and 'diamond'
/// (0 other, 1 cubic, 2 and 3 its first and second neighbours, 4 hexagonal, 5 and 6 its).
/// Computed on the whole frame, before --select.
fn structure_columns(md: &mut MdFrame, columns: &[String]) {
    let wants = |md: &MdFrame, name: &str| {
        columns.iter().any(|c| c.trim() == name) && md.property(name).is_none()
    };
    for name in ["cna", "diamond"] {
        if wants(md, name) {
            let values = if name == "cna" {
                let types = texmap_md_io::cna::classify(md);
                types.iter().map(|&t| t as u8 as f32).collect()
            } else {
                let types = texmap_md_io::cna::classify_diamond(md);
                types.iter().map(|&t| t as u8 as f32).collect()
            };
            md.properties.push(texmap_md_io::Property {
                name: name.into(),
                values,
            });
        }
    }
}

/// Keeps the properties `columns` names, in that order; a name the frame lacks is an error
/// listing the ones it has.
fn keep_columns(md: &mut MdFrame, columns: &[String]) -> Result<()> {
    let mut kept = Vec::with_capacity(columns.len());
    for name in columns {
        let name = name.trim();
        match md.properties.iter().position(|p| p.name == name) {
            Some(k) => kept.push(md.properties.swap_remove(k)),
            None if kept.iter().any(|p: &texmap_md_io::Property| p.name == name) => {}
            None => {
                let mut available: Vec<&str> = kept
                    .iter()
                    .chain(&md.properties)
                    .map(|p| p.name.as_str())
                    .collect();
                available.sort_unstable();
                let hint = crate::scene::ANALYSIS_PROPERTIES
                    .iter()
                    .find(|(p, _)| *p == name)
                    .map(|(_, flag)| format!("; {flag} computes it"))
                    .unwrap_or_default();
                anyhow::bail!(
                    "--columns: this frame has no property '{name}' (it has: {}){hint}",
                    if available.is_empty() {
                        "none".to_string()
                    } else {
                        available.join(", ")
                    }
                );
            }
        }
    }
    md.properties = kept;
    Ok(())
}

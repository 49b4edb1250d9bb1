//! The CSV tables of the analyses that `texmap render` and `texmap convert` write beside
//! their frames: per frame (defects, grains, clusters, MSD, RMSD, dihedrals) or over the whole
//! run (g(r), the MSD and the velocity autocorrelation over every time origin, the vibrational
//! density of states, RMSF, density profiles). Each is written under a
//! temporary name and moved into place at the end, so a failed run leaves none.

use std::path::PathBuf;

use anyhow::{Result, bail};
use texmap_md_io::Frame as MdFrame;

use crate::args::{AnalysisArgs, usage};

/// A per-frame CSV table for `flag` at `path`, its `header` row written (unless empty: a
/// header known only at the first frame); refused when the run
/// draws only part of the frames (`whole` false: --shard), where every part would write it.
pub(crate) fn per_frame_table(
    path: &Option<PathBuf>,
    flag: &str,
    header: &str,
    whole: bool,
) -> Result<Option<crate::output::AtomicFile>> {
    let why = "every part would write the same table";
    let Some(mut t) = whole_run_table(path, flag, why, whole)? else {
        return Ok(None);
    };
    if !header.is_empty() {
        t.write(&format!("{header}\n"))?;
    }
    Ok(Some(t))
}

/// The file of a table that needs every frame in one run (`whole`): refused for a part of a
/// render split with --shard, saying `why`.
fn whole_run_table(
    path: &Option<PathBuf>,
    flag: &str,
    why: &str,
    whole: bool,
) -> Result<Option<crate::output::AtomicFile>> {
    match path {
        None => Ok(None),
        Some(_) if !whole => usage(format!(
            "{flag} with --shard (or a Slurm array): {why}; write it in a run of its own"
        )),
        Some(p) => Ok(Some(crate::output::AtomicFile::create(p)?)),
    }
}

/// A trajectory that only a whole run can write, with the format its name gives; refused
/// under `--shard` for the reason `why`.
fn whole_run_trajectory(
    path: &Option<PathBuf>,
    flag: &str,
    why: &str,
    whole: bool,
) -> Result<Option<(PathBuf, texmap_md_io::Format)>> {
    match path {
        None => Ok(None),
        Some(_) if !whole => usage(format!(
            "{flag} with --shard (or a Slurm array): {why}; write it in a run of its own"
        )),
        Some(p) => Ok(Some((p.clone(), crate::convert::output_format(flag, p)?))),
    }
}

/// The per-frame tables of the analyses (`--defect-table`, `--grain-table`), shared by
/// `texmap render` and `texmap convert`.
pub(crate) struct AnalysisTables {
    defect: Option<crate::output::AtomicFile>,
    grain: Option<crate::output::AtomicFile>,
    rdf: Option<(crate::output::AtomicFile, RdfMean)>,
    /// `--msd-table`, and the kinds of its columns (set at the first frame).
    msd: Option<(crate::output::AtomicFile, Vec<texmap_md_io::Label>)>,
    rmsd: Option<crate::output::AtomicFile>,
    cluster: Option<crate::output::AtomicFile>,
    msd_lags: Option<MsdLags>,
    velocities: Option<VelocityTables>,
    sasa: Option<crate::output::AtomicFile>,
    /// `--gyration-table`, its atoms and whether by mass.
    gyration: Option<(
        crate::output::AtomicFile,
        texmap_md_io::select::Selection,
        bool,
    )>,
    sasa_residues: Option<crate::output::AtomicFile>,
    dihedral: Option<crate::output::AtomicFile>,
    ramachandran: Option<RamachandranPlot>,
    profile: Option<(crate::output::AtomicFile, ProfileMean)>,
    /// `--rmsf-table`, the fluctuations so far and each atom's first columns (the first
    /// frame's).
    rmsf: Option<(
        crate::output::AtomicFile,
        texmap_md_io::rmsf::Fluctuation,
        Vec<String>,
    )>,
    density: Option<DensityTable>,
    contacts: Option<ContactsTable>,
    survival: Option<SurvivalTable>,
    pca: Option<PcaTables>,
    dssp: Option<DsspTables>,
    rmsd_matrix: Option<RmsdMatrix>,
    residue_map: Option<ResidueMap>,
    order: Option<OrderTable>,
    membrane: Option<MembraneTable>,
    /// `--hbond-table` and `--hbond-lifetime`: the plan's hydrogen bonds of every frame.
    hbond: Option<crate::output::AtomicFile>,
    hbond_lifetime: Option<SurvivalTable>,
    hbond_occupancy: Option<(crate::output::AtomicFile, HbondOccupancy)>,
    /// `--measure-table`, and the specs of its rows.
    measure: Option<(crate::output::AtomicFile, Vec<String>)>,
    saltbridges: Option<SaltBridgeTables>,
}

/// `--contacts-table`: its file, groups and method, and the native contacts (set at the
/// first frame).
struct ContactsTable {
    file: crate::output::AtomicFile,
    groups: [texmap_md_io::select::Selection; 2],
    radius: f64,
    method: texmap_md_io::contacts::Method,
    native: Option<texmap_md_io::contacts::NativeContacts>,
}

impl ContactsTable {
    fn create(analysis: &AnalysisArgs, whole: bool) -> Result<Option<ContactsTable>> {
        let Some(file) = per_frame_table(
            &analysis.contacts_table,
            "--contacts-table",
            "frame,time,q",
            whole,
        )?
        else {
            return Ok(None);
        };
        let spec = analysis.contacts.as_deref().unwrap_or_default();
        let Some((a, b)) = spec.split_once(';') else {
            return usage(format!(
                "--contacts {spec:?}: expected two selections, 'SEL_A;SEL_B' (e.g. 'name N;name O')"
            ));
        };
        let parse = |s: &str| crate::scene::parse_selection(&format!("--contacts {s:?}"), s.trim());
        Ok(Some(ContactsTable {
            file,
            groups: [parse(a)?, parse(b)?],
            radius: analysis.contacts_radius,
            method: match analysis.contacts_method {
                crate::args::ContactsMethodArg::Hard => texmap_md_io::contacts::Method::HardCut,
                crate::args::ContactsMethodArg::Radius => texmap_md_io::contacts::Method::RadiusCut,
                crate::args::ContactsMethodArg::Soft => texmap_md_io::contacts::Method::SOFT,
            },
            native: None,
        }))
    }

    /// Frame `f`'s row (the native contacts found in it when it is the first).
    fn add(&mut self, f: usize, time: &str, md: &MdFrame) -> Result<()> {
        let native = match &self.native {
            Some(n) => n,
            None => {
                let mut groups = [Vec::new(), Vec::new()];
                for (g, sel) in groups.iter_mut().zip(&self.groups) {
                    let pick = sel
                        .evaluate(md)
                        .map_err(|e| anyhow::anyhow!("--contacts: frame {f}: {e}"))?;
                    g.extend((0..md.n_atoms()).filter(|&i| pick[i]));
                }
                let n = texmap_md_io::contacts::NativeContacts::new(
                    &md.positions,
                    md.cell.as_ref(),
                    &groups[0],
                    &groups[1],
                    self.radius,
                )
                .map_err(|e| anyhow::anyhow!("--contacts: frame {f}: {e}"))?;
                if n.pairs().is_empty() {
                    bail!(
                        "--contacts: frame {f} has no pair of the two groups within {} Å, so no native contacts (a larger --contacts-radius?)",
                        self.radius
                    );
                }
                crate::note!(
                    "--contacts-table: {} native contacts in frame {f}",
                    n.pairs().len()
                );
                self.native.insert(n)
            }
        };
        let q = native
            .q(&md.positions, md.cell.as_ref(), self.method)
            .map_err(|e| anyhow::anyhow!("--contacts-table: frame {f}: {e}"))?;
        self.file.write(&format!("{f},{time},{q:.6}\n"))
    }
}

/// `--density-map`: its file, atoms and grid (set at the first frame).
struct DensityTable {
    file: crate::output::AtomicFile,
    select: texmap_md_io::select::Selection,
    text: String,
    delta: f64,
    padding: f64,
    map: Option<texmap_md_io::density::DensityMap>,
    first: usize,
    positions: u64,
    /// `--density-units`: the name and the units in one atom per Å³.
    units: (String, f64),
}

impl DensityTable {
    /// Frame `f`'s selected positions into the map (the grid set around them at the first).
    fn add(&mut self, f: usize, md: &MdFrame) -> Result<()> {
        let pick = self
            .select
            .evaluate(md)
            .map_err(|e| anyhow::anyhow!("--density-select: frame {f}: {e}"))?;
        let positions: Vec<[f32; 3]> = (0..md.n_atoms())
            .filter(|&i| pick[i])
            .map(|i| md.positions[i])
            .collect();
        let map = match &mut self.map {
            Some(m) => m,
            None => {
                let m = texmap_md_io::density::DensityMap::around(
                    &positions,
                    self.delta,
                    self.padding,
                )
                .map_err(|e| {
                    anyhow::anyhow!(
                        "--density-map: the grid around frame {f}'s atoms of --density-select '{}': {e}",
                        self.text
                    )
                })?;
                self.first = f;
                self.map.insert(m)
            }
        };
        map.add(positions.iter().copied());
        self.positions += positions.len() as u64;
        Ok(())
    }

    /// The map written as OpenDX; what was left outside the grid reported.
    fn finish(mut self) -> Result<crate::output::AtomicFile> {
        let Some(map) = self.map else {
            bail!("--density-map: no frame was written or drawn, so there is no density");
        };
        let mut v = map.to_volume("density");
        let (unit, factor) = (&self.units.0, self.units.1);
        for x in &mut v.data {
            *x = (f64::from(*x) * factor) as f32;
        }
        let [nx, ny, nz] = v.dims;
        let intro = format!(
            "texmap --density-map: number density ({unit}) of '{}'",
            self.text
        );
        let grid = format!(
            "mean over {} frames; {} A cells around frame {}'s atoms, {} A padding",
            map.frames(),
            crate::scene::compact(self.delta, 6),
            self.first,
            crate::scene::compact(self.padding, 6)
        );
        let mut text = Vec::new();
        texmap_md_io::volume::write_dx(&v, &[&intro, &grid], &mut text)?;
        self.file.write(&String::from_utf8_lossy(&text))?;
        let (_, top) = v.range().unwrap_or((0.0, 0.0));
        let water = texmap_md_io::density::UNITS[3].1;
        crate::note!(
            "--density-map: {nx}x{ny}x{nz} cells over {} frames, the densest {top:.4} {unit} ({:.2}x bulk water's oxygens)",
            map.frames(),
            f64::from(top) / factor * water
        );
        if map.outside() > 0 {
            eprintln!(
                "texmap: warning: --density-map: {} of {} positions fell outside the grid set around frame {}'s atoms and were not counted (a larger --density-padding takes them in)",
                map.outside(),
                self.positions,
                self.first
            );
        }
        Ok(self.file)
    }
}

/// Atom `i`'s first columns in the per-atom tables: its index, id, name, residue name,
/// residue number and chain (empty where the file has none).
fn atom_columns(md: &MdFrame, i: usize) -> String {
    let text = |v: &[texmap_md_io::Label]| v.get(i).map(|l| l.to_string()).unwrap_or_default();
    let number = |v: &[i64]| v.get(i).map(|n| n.to_string()).unwrap_or_default();
    format!(
        "{i},{},{},{},{},{}",
        number(&md.ids),
        text(&md.names),
        text(&md.res_names),
        number(&md.res_ids),
        text(&md.chains)
    )
}

/// Frame `f`'s `--gyration-table` row: the size and shape of `sel`'s atoms of `md`.
fn gyration_row(
    f: usize,
    time: &str,
    md: &MdFrame,
    sel: &texmap_md_io::select::Selection,
    by_mass: bool,
) -> Result<String> {
    let pick = sel
        .evaluate(md)
        .map_err(|e| anyhow::anyhow!("--gyration-select: frame {f}: {e}"))?;
    let atoms: Vec<usize> = (0..md.n_atoms()).filter(|&i| pick[i]).collect();
    if atoms.is_empty() {
        bail!("--gyration-select: frame {f} has none of the atoms it picks");
    }
    let mut weights = Vec::with_capacity(atoms.len());
    for &i in &atoms {
        let w = if by_mass { mass_of(md, i) } else { Some(1.0) };
        let Some(w) = w else {
            bail!(
                "--gyration-table: atom {i} of frame {f} has no mass: no element, and the files give none (give --gyration-unweighted)"
            );
        };
        weights.push(w);
    }
    if weights.iter().sum::<f64>() <= 0.0 {
        bail!("--gyration-table: frame {f}: every atom --gyration-select picks is massless");
    }
    let positions: Vec<[f32; 3]> = atoms.iter().map(|&i| md.positions[i]).collect();
    let g = texmap_md_io::shape::gyration(&positions, &weights)
        .ok_or_else(|| anyhow::anyhow!("--gyration-table: frame {f}: a position is not finite"))?;
    Ok(format!(
        "{f},{time},{:.6},{:.6},{:.6},{:.6},{:.6}\n",
        g.rg, g.about[0], g.about[1], g.about[2], g.asphericity
    ))
}

/// Frame `f`'s `--sasa-residue-table` rows: each residue with a measured atom (consecutive
/// atoms of one chain, residue number and name), the sum of its atoms' `area`.
fn residue_sums(f: usize, time: &str, md: &MdFrame, area: &[f32]) -> String {
    let label =
        |v: &[texmap_md_io::Label], i: usize| v.get(i).map(|l| l.to_string()).unwrap_or_default();
    let key = |i: usize| {
        (
            label(&md.chains, i),
            md.res_ids.get(i).copied(),
            label(&md.res_names, i),
        )
    };
    let mut rows = String::new();
    let mut i = 0;
    while i < area.len() {
        let k = key(i);
        let mut j = i;
        let mut sum = 0.0f64;
        let mut measured = false;
        while j < area.len() && key(j) == k {
            if area[j].is_finite() {
                sum += f64::from(area[j]);
                measured = true;
            }
            j += 1;
        }
        if measured {
            let resid = k.1.map(|r| r.to_string()).unwrap_or_default();
            rows.push_str(&format!("{f},{time},{},{resid},{},{sum:.3}\n", k.0, k.2));
        }
        i = j;
    }
    rows
}

/// `--msd-lags`: every frame's unwrapped positions, averaged over every time origin at the end.
struct MsdLags {
    file: crate::output::AtomicFile,
    all: texmap_md_io::msd::AllOrigins,
    /// Each kept frame's time (ps), if it has one.
    times: Vec<Option<f64>>,
    /// The kinds of the columns, sorted by name, and each atom's (set at the first frame).
    kinds: Vec<texmap_md_io::Label>,
    kind: Vec<usize>,
    fit: Option<(f64, f64)>,
}

impl MsdLags {
    fn add(&mut self, f: usize, unwrapped: &[[f64; 3]], md: &MdFrame) -> Result<()> {
        if self.all.frames() == 0 {
            // The first frame sets the kinds, so every atom has one.
            self.kind = kinds_of(md, &mut self.kinds).unwrap_or_default();
        }
        self.all
            .push(unwrapped)
            .map_err(|e| anyhow::anyhow!("--msd-lags: frame {f}: {e}"))?;
        self.times.push(md.time);
        Ok(())
    }

    /// The table written, each column's diffusion coefficient printed.
    fn finish(mut self) -> Result<crate::output::AtomicFile> {
        let lags = self
            .all
            .mean(&self.kind, self.kinds.len())
            .map_err(|e| anyhow::anyhow!("--msd-lags: {e}"))?;
        let times = even_lag_times(&self.times);
        let (text, x, unit) =
            lag_table("msd", &self.kinds, &times, &lags.total, &lags.kinds, |v| {
                format!("{v:.6}")
            });
        self.file.write(&text)?;
        let longest = x.last().copied().unwrap_or(0.0);
        let (from, to) = self.fit.unwrap_or((0.1 * longest, 0.9 * longest));
        let span = format!(
            "{}–{}",
            crate::scene::compact(from, 4),
            crate::scene::compact(to, 4)
        );
        let names = std::iter::once("every atom".to_string())
            .chain(self.kinds.iter().map(|k| format!("the {k} atoms")));
        for (name, msd) in names.zip(std::iter::once(&lags.total).chain(&lags.kinds)) {
            match texmap_md_io::msd::fit_diffusion(&x, msd, from, to) {
                // Å²/ps over 6 is 10⁻⁴ cm²/s.
                Some(fit) if times.is_some() => eprintln!(
                    "texmap: --msd-lags: D = {:.4} × 10⁻⁵ cm²/s for {name} (MSD = 6 D t fitted over {span} ps, {} lags)",
                    fit.d * 10.0,
                    fit.points
                ),
                Some(fit) => eprintln!(
                    "texmap: --msd-lags: D = {:.6} Å² per frame for {name} (the frames carry no evenly spaced times; MSD = 6 D t fitted over lags {span} {unit}, {} lags)",
                    fit.d, fit.points
                ),
                None => eprintln!(
                    "texmap: warning: --msd-lags: fewer than two lags in {span} {unit} to fit a diffusion coefficient for {name} (--msd-fit)"
                ),
            }
        }
        Ok(self.file)
    }
}

/// The lag times (ps) of frames at `times` when every frame has a time and they are evenly
/// spaced.
fn even_lag_times(times: &[Option<f64>]) -> Option<Vec<f64>> {
    let times: Vec<f64> = times.iter().copied().collect::<Option<_>>()?;
    let t = times.len();
    if t < 2 {
        return None;
    }
    let dt = (times[t - 1] - times[0]) / (t - 1) as f64;
    let even = dt > 0.0
        && times
            .iter()
            .enumerate()
            .all(|(k, x)| (x - times[0] - k as f64 * dt).abs() <= 1e-3 * dt + 1e-6 * x.abs());
    even.then(|| (0..t).map(|m| m as f64 * dt).collect())
}

/// A table of `name` per lag (`total` over every atom, then one column per kind of `kinds`),
/// each value written by `value`, with each lag's time when `times` has them; also the lags'
/// abscissae and their unit (ps, else frames).
fn lag_table(
    name: &str,
    kinds: &[texmap_md_io::Label],
    times: &Option<Vec<f64>>,
    total: &[f64],
    columns: &[Vec<f64>],
    value: impl Fn(f64) -> String,
) -> (String, Vec<f64>, &'static str) {
    let mut text = format!("lag,time,{name}");
    for k in kinds {
        text.push_str(&format!(",{name}_{k}"));
    }
    text.push('\n');
    for m in 0..total.len() {
        let time = times
            .as_ref()
            .map(|t| crate::scene::compact(t[m], 6))
            .unwrap_or_default();
        text.push_str(&format!("{m},{time},{}", value(total[m])));
        for column in columns {
            text.push(',');
            text.push_str(&value(column[m]));
        }
        text.push('\n');
    }
    match times {
        Some(t) => (text, t.clone(), "ps"),
        None => (text, (0..total.len()).map(|m| m as f64).collect(), "frames"),
    }
}

/// A survival table (`--hbond-lifetime`, `--survival-table`): every frame's members,
/// correlated at the end.
pub(crate) struct SurvivalTable {
    flag: &'static str,
    /// What a member is, for the messages ("hydrogen bond", "atom").
    member: &'static str,
    file: crate::output::AtomicFile,
    frames: Vec<Vec<u64>>,
    times: Vec<Option<f64>>,
    tau_max: usize,
    intermittency: usize,
    /// `--survival-select`: the set, evaluated every frame.
    select: Option<texmap_md_io::select::Selection>,
}

impl SurvivalTable {
    /// The table `path` asks for (`whole`: see [`per_frame_table`]).
    pub(crate) fn create(
        path: &Option<PathBuf>,
        flag: &'static str,
        (tau_max, intermittency): (usize, usize),
        whole: bool,
        select: Option<texmap_md_io::select::Selection>,
    ) -> Result<Option<SurvivalTable>> {
        let why = "the average over every time origin needs every frame in one run";
        Ok(
            whole_run_table(path, flag, why, whole)?.map(|file| SurvivalTable {
                flag,
                member: if select.is_some() {
                    "atom"
                } else {
                    "hydrogen bond"
                },
                file,
                frames: Vec::new(),
                times: Vec::new(),
                tau_max,
                intermittency,
                select,
            }),
        )
    }

    /// One frame's hydrogen bonds.
    pub(crate) fn add_hbonds(&mut self, hbonds: &[texmap_md_io::hbonds::HBond], time: Option<f64>) {
        self.frames.push(
            hbonds
                .iter()
                .map(|h| texmap_md_io::hbonds::bond_key(h.hydrogen, h.acceptor))
                .collect(),
        );
        self.times.push(time);
    }

    /// Frame `f`'s atoms of the selection.
    fn add_selected(&mut self, f: usize, md: &MdFrame) -> Result<()> {
        let Some(sel) = &self.select else {
            return Ok(());
        };
        let pick = sel
            .evaluate(md)
            .map_err(|e| anyhow::anyhow!("--survival-select: frame {f}: {e}"))?;
        self.frames.push(
            (0..md.n_atoms())
                .filter(|&i| pick[i])
                .map(|i| i as u64)
                .collect(),
        );
        self.times.push(md.time);
        Ok(())
    }

    /// The table written, the lifetime printed.
    pub(crate) fn finish(mut self) -> Result<crate::output::AtomicFile> {
        let flag = self.flag;
        if self.frames.len() < 2 {
            bail!(
                "{flag}: {} frame(s): a survival curve needs two or more",
                self.frames.len()
            );
        }
        let c = texmap_md_io::survival::survival_probability(
            &self.frames,
            self.tau_max,
            self.intermittency,
        );
        if c.get(1).is_none_or(|v| v.is_nan()) {
            bail!(
                "{flag}: no {} in any of the {} frames",
                self.member,
                self.frames.len()
            );
        }
        let times = even_lag_times(&self.times);
        let (text, x, unit) = lag_table("survival", &[], &times, &c, &[], |v| format!("{v:.6}"));
        self.file.write(&text)?;
        let area: f64 = (1..c.len())
            .map(|k| 0.5 * (c[k] + c[k - 1]) * (x[k] - x[k - 1]))
            .sum();
        let last = c[c.len() - 1];
        crate::note!(
            "{flag}: lifetime ∫S dτ = {} {unit} over lags 0–{} {unit} (S there {last:.3}{})",
            crate::scene::compact(area, 4),
            crate::scene::compact(x[c.len() - 1], 4),
            if last > 0.05 {
                ": not yet decayed, so the lifetime is longer; raise the longest lag"
            } else {
                ""
            }
        );
        Ok(self.file)
    }
}

/// `--dssp-table`, `--dssp-residue-table` and `--dssp-timeline`: every frame's secondary
/// structure.
struct DsspTables {
    table: Option<crate::output::AtomicFile>,
    residues: Option<crate::output::AtomicFile>,
    timeline: Option<PathBuf>,
    /// The first frame's residues with a backbone: chain, resid, resname.
    labels: Vec<(String, i64, String)>,
    /// Per residue, the frames it was coil, helix, strand.
    counts: Vec<[u32; 3]>,
    /// Every frame's classes (kept for the timeline only).
    classes: Vec<Vec<texmap_md_io::secondary::Structure>>,
    frames: Vec<usize>,
    times: Vec<Option<f64>>,
}

impl DsspTables {
    fn create(analysis: &AnalysisArgs, whole: bool) -> Result<Option<DsspTables>> {
        let why = "every part would write its own";
        let table = per_frame_table(
            &analysis.dssp_table,
            "--dssp-table",
            "frame,time,helix,strand,coil,ss",
            whole,
        )?;
        let residues = whole_run_table(
            &analysis.dssp_residue_table,
            "--dssp-residue-table",
            why,
            whole,
        )?;
        let timeline = chart_file(&analysis.dssp_timeline, "--dssp-timeline", why, whole)?;
        Ok(
            (table.is_some() || residues.is_some() || timeline.is_some()).then(|| DsspTables {
                table,
                residues,
                timeline,
                labels: Vec::new(),
                counts: Vec::new(),
                classes: Vec::new(),
                frames: Vec::new(),
                times: Vec::new(),
            }),
        )
    }

    /// Frame `f`'s assignment.
    fn add(&mut self, f: usize, time: &str, md: &MdFrame) -> Result<()> {
        let ss = texmap_md_io::secondary::assign(md);
        if self.frames.is_empty() {
            if ss.residues().is_empty() {
                bail!(
                    "--dssp: frame {f} has no residue with the backbone atoms N, CA, C and O (a protein's), so no secondary structure"
                );
            }
            let text = |v: &[texmap_md_io::Label], i: usize| {
                v.get(i).map(|l| l.to_string()).unwrap_or_default()
            };
            self.labels = ss
                .residues()
                .iter()
                .map(|r| {
                    let i = r.atoms.start;
                    (text(&md.chains, i), r.res_id, text(&md.res_names, i))
                })
                .collect();
            self.counts = vec![[0; 3]; self.labels.len()];
        } else if ss.residues().len() != self.labels.len() {
            bail!(
                "--dssp: frame {f} has {} residues with a backbone and the first {}: every frame must hold the same residues",
                ss.residues().len(),
                self.labels.len()
            );
        }
        for (n, c) in self.counts.iter_mut().zip(ss.classes()) {
            n[*c as usize] += 1;
        }
        if let Some(t) = &mut self.table {
            let [coil, helix, strand] = ss.counts();
            t.write(&format!(
                "{f},{time},{helix},{strand},{coil},{}\n",
                ss.codes()
            ))?;
        }
        if self.timeline.is_some() {
            self.classes.push(ss.classes().to_vec());
        }
        self.frames.push(f);
        self.times.push(md.time);
        Ok(())
    }

    /// The per-residue table written, the timeline drawn.
    fn finish(mut self) -> Result<Vec<crate::output::AtomicFile>> {
        let n = self.frames.len().max(1) as f64;
        if let Some(t) = &mut self.residues {
            let mut text = String::from("chain,resid,resname,helix,strand,coil\n");
            for ((chain, resid, resname), [coil, helix, strand]) in
                self.labels.iter().zip(&self.counts)
            {
                text.push_str(&format!(
                    "{chain},{resid},{resname},{:.4},{:.4},{:.4}\n",
                    f64::from(*helix) / n,
                    f64::from(*strand) / n,
                    f64::from(*coil) / n
                ));
            }
            t.write(&text)?;
        }
        if let Some(path) = &self.timeline {
            let (x, label) = frame_axis(&self.frames, &self.times);
            let resids: Vec<i64> = self.labels.iter().map(|l| l.1).collect();
            write_chart(path, texmap_study::chart::TIMELINE_SIZE, |t| {
                texmap_study::chart::structure_timeline(&x, label, &resids, &self.classes, t)
            })?;
        }
        Ok([self.table, self.residues].into_iter().flatten().collect())
    }
}

/// The file of a chart `flag` asks for: a .png or .svg name, refused for a part of a render
/// split with --shard (`whole` false), saying `why`.
fn chart_file(
    path: &Option<PathBuf>,
    flag: &str,
    why: &str,
    whole: bool,
) -> Result<Option<PathBuf>> {
    match path {
        None => Ok(None),
        Some(_) if !whole => usage(format!(
            "{flag} with --shard (or a Slurm array): {why}; draw it in a run of its own"
        )),
        Some(p) => match p
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("png" | "svg") => Ok(Some(p.clone())),
            _ => usage(format!(
                "{flag} {}: expected a .png or .svg file name",
                p.display()
            )),
        },
    }
}

/// A chart's axis over the frames: their times (ps) when every frame has one and they
/// increase, else the frame numbers; with the axis's title.
fn frame_axis(frames: &[usize], times: &[Option<f64>]) -> (Vec<f64>, &'static str) {
    let timed = times.iter().all(Option::is_some) && times.windows(2).all(|w| w[1] > w[0]);
    if timed {
        (times.iter().flatten().copied().collect(), "time (ps)")
    } else {
        (frames.iter().map(|&f| f as f64).collect(), "frame")
    }
}

/// Draws a chart of `size` pixels into `path`, SVG or PNG by its extension, whole or not at all.
pub(crate) fn write_chart(
    path: &std::path::Path,
    size: (u32, u32),
    draw: impl Fn(texmap_study::chart::Target) -> Result<(), texmap_study::StudyError>,
) -> Result<()> {
    use texmap_study::chart::Target;
    let svg = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("svg"));
    crate::output::write_atomic(path, |tmp| {
        if svg {
            let mut text = String::new();
            draw(Target::Svg(&mut text))?;
            std::fs::write(tmp, text)?;
        } else {
            let (w, h) = size;
            let mut rgb = vec![0u8; 3 * w as usize * h as usize];
            draw(Target::Rgb(&mut rgb))?;
            image::RgbImage::from_raw(w, h, rgb)
                .expect("the chart's size")
                .save_with_format(tmp, image::ImageFormat::Png)?;
        }
        Ok(())
    })
}

/// The atoms a selection (`flag`'s) picks at the first frame, followed through the later
/// frames, which must hold as many atoms.
struct Picked {
    flag: &'static str,
    select: texmap_md_io::select::Selection,
    atoms: Vec<usize>,
    n_atoms: usize,
}

impl Picked {
    fn new(flag: &'static str, text: &str) -> Result<Picked> {
        Ok(Picked {
            flag,
            select: crate::scene::parse_selection(flag, text)?,
            atoms: Vec::new(),
            n_atoms: 0,
        })
    }

    /// Frame `f`'s positions of the picked atoms, picking them first when `first`.
    fn positions(&mut self, f: usize, md: &MdFrame, first: bool) -> Result<Vec<[f32; 3]>> {
        let flag = self.flag;
        if first {
            let pick = self
                .select
                .evaluate(md)
                .map_err(|e| anyhow::anyhow!("{flag}: frame {f}: {e}"))?;
            self.atoms = (0..md.n_atoms()).filter(|&i| pick[i]).collect();
            if self.atoms.is_empty() {
                bail!("{flag}: frame {f} has none of the atoms it picks");
            }
            self.n_atoms = md.n_atoms();
        } else if md.n_atoms() != self.n_atoms {
            bail!(
                "{flag}: frame {f} has {} atoms and the first {}: every frame must hold the same atoms",
                md.n_atoms(),
                self.n_atoms
            );
        }
        Ok(self.atoms.iter().map(|&i| md.positions[i]).collect())
    }

    /// The picked atoms as a mask over the first frame's.
    fn mask(&self) -> Vec<bool> {
        let mut mask = vec![false; self.n_atoms];
        for &i in &self.atoms {
            mask[i] = true;
        }
        mask
    }
}

/// `--rmsd-matrix`, `--rmsd-matrix-chart` and the `--rmsd-clusters` outputs: the selected
/// atoms' positions every frame (and every atom's for `--rmsd-cluster-middles`), the pairwise
/// RMSD and its clusters at the end.
struct RmsdMatrix {
    table: Option<crate::output::AtomicFile>,
    chart: Option<PathBuf>,
    clusters: Option<crate::output::AtomicFile>,
    cluster_table: Option<crate::output::AtomicFile>,
    middles: Option<(PathBuf, texmap_md_io::Format)>,
    method: texmap_md_io::conformations::Method,
    cutoff: f64,
    picked: Picked,
    positions: Vec<Vec<[f32; 3]>>,
    /// Every atom's positions every frame, for `--rmsd-cluster-middles`, and the first frame
    /// as the template of the middles written.
    whole: Vec<Vec<[f32; 3]>>,
    template: MdFrame,
    frames: Vec<usize>,
    times: Vec<Option<f64>>,
    limit: usize,
}

impl RmsdMatrix {
    fn create(analysis: &AnalysisArgs, whole: bool) -> Result<Option<RmsdMatrix>> {
        let why = "the matrix pairs every frame with every other";
        let table = whole_run_table(&analysis.rmsd_matrix, "--rmsd-matrix", why, whole)?;
        let chart = chart_file(
            &analysis.rmsd_matrix_chart,
            "--rmsd-matrix-chart",
            why,
            whole,
        )?;
        let clusters = whole_run_table(&analysis.rmsd_clusters, "--rmsd-clusters", why, whole)?;
        let cluster_table = whole_run_table(
            &analysis.rmsd_cluster_table,
            "--rmsd-cluster-table",
            why,
            whole,
        )?;
        let middles = whole_run_trajectory(
            &analysis.rmsd_cluster_middles,
            "--rmsd-cluster-middles",
            why,
            whole,
        )?;
        if table.is_none()
            && chart.is_none()
            && clusters.is_none()
            && cluster_table.is_none()
            && middles.is_none()
        {
            return Ok(None);
        }
        Ok(Some(RmsdMatrix {
            table,
            chart,
            clusters,
            cluster_table,
            middles,
            method: match analysis.rmsd_cluster_method {
                crate::args::RmsdClusterMethodArg::Gromos => {
                    texmap_md_io::conformations::Method::Gromos
                }
                crate::args::RmsdClusterMethodArg::Linkage => {
                    texmap_md_io::conformations::Method::Linkage
                }
            },
            cutoff: analysis.rmsd_cluster_cutoff,
            picked: Picked::new("--rmsd-matrix-select", &analysis.rmsd_matrix_select)?,
            positions: Vec::new(),
            whole: Vec::new(),
            template: MdFrame::new(),
            frames: Vec::new(),
            times: Vec::new(),
            limit: analysis.msd_memory.saturating_mul(1 << 20),
        }))
    }

    /// The flag that asked for the matrix, for messages.
    fn flag(&self) -> &'static str {
        if self.table.is_some() || self.chart.is_some() {
            "--rmsd-matrix"
        } else {
            "--rmsd-clusters"
        }
    }

    /// Frame `f`'s positions of the atoms selected at the first.
    fn add(&mut self, f: usize, md: &MdFrame) -> Result<()> {
        let first = self.frames.is_empty();
        let positions = self.picked.positions(f, md, first)?;
        // Stop at the memory limit now rather than after reading every frame.
        let kept = if self.middles.is_some() {
            md.n_atoms()
        } else {
            0
        };
        let bytes = texmap_md_io::rmsd::matrix_bytes(self.frames.len() + 1, positions.len())
            .saturating_add(
                (self.frames.len() + 1)
                    .saturating_mul(kept)
                    .saturating_mul(12),
            );
        if bytes > self.limit {
            let e = texmap_md_io::msd::MsdError::Matrix {
                frames: self.frames.len() + 1,
                bytes,
                limit: self.limit,
            };
            bail!("{}: frame {f}: {e}", self.flag());
        }
        if self.middles.is_some() {
            if first {
                self.template = md.clone();
            }
            self.whole.push(md.positions.clone());
        }
        self.positions.push(positions);
        self.frames.push(f);
        self.times.push(md.time);
        Ok(())
    }

    /// The matrix written and drawn, its clusters written.
    fn finish(mut self) -> Result<Vec<crate::output::AtomicFile>> {
        let flag = self.flag();
        let m = texmap_md_io::rmsd::rmsd_matrix(&self.positions, self.limit)
            .map_err(|e| anyhow::anyhow!("{flag}: {e}"))?;
        let n = self.frames.len();
        if let Some(t) = &mut self.table {
            let mut text = String::from("frame");
            for f in &self.frames {
                text.push_str(&format!(",{f}"));
            }
            text.push('\n');
            for (f, row) in self.frames.iter().zip(m.chunks(n.max(1))) {
                text.push_str(&f.to_string());
                for v in row {
                    text.push_str(&format!(",{v:.4}"));
                }
                text.push('\n');
            }
            t.write(&text)?;
        }
        if let Some(path) = &self.chart {
            let (x, label) = frame_axis(&self.frames, &self.times);
            write_chart(path, texmap_study::chart::HEATMAP_SIZE, |t| {
                texmap_study::chart::matrix_heatmap(&x, label, &m, "RMSD (Å)", t)
            })?;
        }
        if self.clusters.is_some() || self.cluster_table.is_some() || self.middles.is_some() {
            self.write_clusters(&m)?;
        }
        Ok([self.table, self.clusters, self.cluster_table]
            .into_iter()
            .flatten()
            .collect())
    }

    /// `--rmsd-clusters`, `--rmsd-cluster-table` and `--rmsd-cluster-middles` from the matrix.
    fn write_clusters(&mut self, m: &[f64]) -> Result<()> {
        use texmap_md_io::conformations::cluster;
        let n = self.frames.len();
        let c = cluster(m, n, self.cutoff, self.method)
            .map_err(|e| anyhow::anyhow!("--rmsd-clusters: {e}"))?;
        let time = |k: usize| {
            self.times[k]
                .map(|t| crate::scene::compact(t, 6))
                .unwrap_or_default()
        };
        if let Some(t) = &mut self.clusters {
            let mut text = String::from("frame,time,cluster\n");
            for (k, id) in c.of_frame.iter().enumerate() {
                text.push_str(&format!("{},{},{}\n", self.frames[k], time(k), id + 1));
            }
            t.write(&text)?;
        }
        if let Some(t) = &mut self.cluster_table {
            let mut text = String::from(
                "cluster,frames,fraction,middle_frame,middle_time,middle_rmsd,mean_rmsd,max_rmsd,first_frame,last_frame,entries\n",
            );
            for (id, cl) in c.clusters.iter().enumerate() {
                // The run enters a cluster at its first frame and at every frame whose
                // predecessor lies in another.
                let entries = cl
                    .members
                    .iter()
                    .filter(|&&k| k == 0 || c.of_frame[k - 1] != id)
                    .count();
                text.push_str(&format!(
                    "{},{},{:.6},{},{},{:.4},{:.4},{:.4},{},{},{entries}\n",
                    id + 1,
                    cl.members.len(),
                    cl.members.len() as f64 / n.max(1) as f64,
                    self.frames[cl.middle],
                    time(cl.middle),
                    cl.middle_rmsd,
                    cl.mean_rmsd,
                    cl.max_rmsd,
                    self.frames[cl.members[0]],
                    self.frames[*cl.members.last().unwrap_or(&0)],
                ));
            }
            t.write(&text)?;
        }
        if let Some((path, format)) = &self.middles {
            let mut frame = self.template.clone();
            crate::output::write_atomic(path, |tmp| {
                let mut w = texmap_md_io::Writer::create_as(tmp, *format, path)?;
                for cl in &c.clusters {
                    frame.positions.clone_from(&self.whole[cl.middle]);
                    frame.time = self.times[cl.middle];
                    w.write_frame(&frame)?;
                }
                w.finish()?;
                Ok(())
            })?;
        }
        let sizes: Vec<String> = c
            .clusters
            .iter()
            .take(5)
            .map(|cl| {
                format!(
                    "{} frames (middle frame {})",
                    cl.members.len(),
                    self.frames[cl.middle]
                )
            })
            .collect();
        let lone = c.clusters.iter().filter(|cl| cl.members.len() == 1).count();
        crate::note!(
            "{} clusters of {n} frames at {} Å ({}): {}{}; {} transitions between them",
            c.clusters.len(),
            crate::scene::compact(self.cutoff, 4),
            self.method.name(),
            sizes.join(", "),
            if c.clusters.len() > 5 { ", ..." } else { "" },
            c.transitions()
        );
        if n > 1 && lone * 2 > n {
            eprintln!(
                "texmap: warning: --rmsd-clusters: {lone} of {n} frames are clusters of their own: the cutoff of {} Å is below most frames' distance to their nearest; raise --rmsd-cluster-cutoff (the --rmsd-matrix-chart shows the distances)",
                crate::scene::compact(self.cutoff, 4)
            );
        }
        Ok(())
    }
}

/// `--ramachandran`: the chart, the residues' selection (a mask over the atoms, set at the
/// first frame) and the (φ, ψ) pairs so far.
struct RamachandranPlot {
    path: PathBuf,
    select: texmap_md_io::select::Selection,
    mask: Option<Vec<bool>>,
    plot: texmap_study::chart::Ramachandran,
}

impl RamachandranPlot {
    fn create(analysis: &AnalysisArgs, whole: bool) -> Result<Option<RamachandranPlot>> {
        let why = "the plot gathers every frame";
        let Some(path) = chart_file(&analysis.ramachandran, "--ramachandran", why, whole)? else {
            return Ok(None);
        };
        let select =
            crate::scene::parse_selection("--ramachandran-select", &analysis.ramachandran_select)?;
        Ok(Some(RamachandranPlot {
            path,
            select,
            mask: None,
            plot: Default::default(),
        }))
    }

    /// Frame `f`'s selected residues with both angles.
    fn add(&mut self, f: usize, md: &MdFrame) -> Result<()> {
        if self.mask.is_none() {
            let picked = self
                .select
                .evaluate(md)
                .map_err(|e| anyhow::anyhow!("--ramachandran-select: frame {f}: {e}"))?;
            self.mask = Some(picked);
        }
        let mask = self.mask.as_deref().unwrap_or_default();
        if mask.len() != md.n_atoms() {
            bail!(
                "--ramachandran: frame {f} has {} atoms and the first {}: every frame must hold the same atoms",
                md.n_atoms(),
                mask.len()
            );
        }
        for r in texmap_md_io::dihedrals::backbone_dihedrals(md) {
            if let (Some(phi), Some(psi)) = (r.phi, r.psi)
                && mask[r.atoms.clone()].iter().any(|&m| m)
            {
                self.plot.add(phi, psi);
            }
        }
        Ok(())
    }

    /// The chart drawn.
    fn finish(&self) -> Result<()> {
        if self.plot.is_empty() {
            bail!(
                "--ramachandran: no residue of --ramachandran-select has both φ and ψ (a protein backbone with N, CA and C named so)"
            );
        }
        write_chart(&self.path, texmap_study::chart::HEATMAP_SIZE, |t| {
            self.plot.draw(t)
        })?;
        crate::note!(
            "Ramachandran plot of {} residue-frames written to {}",
            self.plot.len(),
            self.path.display()
        );
        Ok(())
    }
}

/// `--distance-map`, `--contact-map` and their charts: the selected residues' smallest
/// distances every frame, written at the end.
struct ResidueMap {
    distance: Option<crate::output::AtomicFile>,
    distance_chart: Option<PathBuf>,
    contact: Option<crate::output::AtomicFile>,
    contact_chart: Option<PathBuf>,
    select: texmap_md_io::select::Selection,
    cutoff: f64,
    limit: usize,
    /// Set at the first frame: the map, each residue's label and number, the atom count.
    map: Option<texmap_md_io::distance_map::DistanceMap>,
    labels: Vec<String>,
    resids: Vec<f64>,
    n_atoms: usize,
}

impl ResidueMap {
    fn create(analysis: &AnalysisArgs, whole: bool) -> Result<Option<ResidueMap>> {
        let why = "the map averages every frame";
        let distance = whole_run_table(&analysis.distance_map, "--distance-map", why, whole)?;
        let distance_chart = chart_file(
            &analysis.distance_map_chart,
            "--distance-map-chart",
            why,
            whole,
        )?;
        let contact = whole_run_table(&analysis.contact_map, "--contact-map", why, whole)?;
        let contact_chart = chart_file(
            &analysis.contact_map_chart,
            "--contact-map-chart",
            why,
            whole,
        )?;
        if distance.is_none()
            && distance_chart.is_none()
            && contact.is_none()
            && contact_chart.is_none()
        {
            return Ok(None);
        }
        Ok(Some(ResidueMap {
            distance,
            distance_chart,
            contact,
            contact_chart,
            select: crate::scene::parse_selection(
                "--distance-map-select",
                &analysis.distance_map_select,
            )?,
            cutoff: analysis.contact_map_cutoff,
            limit: analysis.msd_memory.saturating_mul(1 << 20),
            map: None,
            labels: Vec::new(),
            resids: Vec::new(),
            n_atoms: 0,
        }))
    }

    /// The flag that asked for the map, for messages.
    fn flag(&self) -> &'static str {
        if self.distance.is_some() || self.distance_chart.is_some() {
            "--distance-map"
        } else {
            "--contact-map"
        }
    }

    fn add(&mut self, f: usize, md: &MdFrame) -> Result<()> {
        let flag = self.flag();
        if self.map.is_none() {
            let picked = self
                .select
                .evaluate(md)
                .map_err(|e| anyhow::anyhow!("--distance-map-select: frame {f}: {e}"))?;
            let mut groups = Vec::new();
            for r in texmap_md_io::secondary::residue_ranges(md) {
                let atoms: Vec<usize> = r.clone().filter(|&i| picked[i]).collect();
                if atoms.is_empty() {
                    continue;
                }
                let i = r.start;
                let chain = md.chains.get(i).map(|c| c.to_string()).unwrap_or_default();
                let name = md
                    .res_names
                    .get(i)
                    .map(|c| c.to_string())
                    .unwrap_or_default();
                let resid = md.res_ids.get(i).copied().unwrap_or_default();
                self.labels.push(if chain.is_empty() {
                    format!("{name}{resid}")
                } else {
                    format!("{chain}:{name}{resid}")
                });
                self.resids.push(resid as f64);
                groups.push(atoms);
            }
            if groups.len() < 2 {
                bail!(
                    "{flag}: frame {f}: --distance-map-select picks atoms of {} residue(s): a map needs two (and residue names and numbers)",
                    groups.len()
                );
            }
            let bytes = texmap_md_io::distance_map::DistanceMap::bytes(groups.len());
            if bytes > self.limit {
                bail!(
                    "{flag}: {} residues need {} MB for the map, over the --msd-memory limit of {} MB: select fewer residues",
                    groups.len(),
                    bytes.div_ceil(1 << 20),
                    self.limit >> 20
                );
            }
            self.n_atoms = md.n_atoms();
            self.map = texmap_md_io::distance_map::DistanceMap::new(groups, self.cutoff);
        } else if md.n_atoms() != self.n_atoms {
            bail!(
                "{flag}: frame {f} has {} atoms and the first {}: every frame must hold the same atoms",
                md.n_atoms(),
                self.n_atoms
            );
        }
        if let Some(map) = &mut self.map {
            map.add(&md.positions, md.cell.as_ref())
                .map_err(|e| anyhow::anyhow!("{flag}: frame {f}: {e}"))?;
        }
        Ok(())
    }

    /// The matrices written and drawn.
    fn finish(mut self) -> Result<Vec<crate::output::AtomicFile>> {
        let Some(map) = self.map.take() else {
            bail!("{}: no frame was read", self.flag());
        };
        let n = map.residues();
        let matrix_csv = |m: &[f64], digits: usize| {
            let mut text = String::from("residue");
            for l in &self.labels {
                text.push_str(&format!(",{l}"));
            }
            text.push('\n');
            for (l, row) in self.labels.iter().zip(m.chunks(n)) {
                text.push_str(l);
                for v in row {
                    text.push_str(&format!(",{v:.digits$}"));
                }
                text.push('\n');
            }
            text
        };
        if self.distance.is_some() || self.distance_chart.is_some() {
            let mean = map.mean();
            if let Some(t) = &mut self.distance {
                t.write(&matrix_csv(&mean, 3))?;
            }
            if let Some(path) = &self.distance_chart {
                write_chart(path, texmap_study::chart::HEATMAP_SIZE, |t| {
                    let label = "smallest distance (Å)";
                    texmap_study::chart::matrix_heatmap(&self.resids, "residue", &mean, label, t)
                })?;
            }
        }
        if self.contact.is_some() || self.contact_chart.is_some() {
            let fraction = map.contact_fraction();
            if let Some(t) = &mut self.contact {
                t.write(&matrix_csv(&fraction, 4))?;
            }
            if let Some(path) = &self.contact_chart {
                write_chart(path, texmap_study::chart::HEATMAP_SIZE, |t| {
                    let label = "contact fraction";
                    texmap_study::chart::matrix_heatmap(
                        &self.resids,
                        "residue",
                        &fraction,
                        label,
                        t,
                    )
                })?;
            }
        }
        crate::note!("residue map of {n} residues over {} frames", map.frames());
        Ok([self.distance, self.contact]
            .into_iter()
            .flatten()
            .collect())
    }
}

/// `--pca-table`, `--pca-projection`, `--pca-vectors`, `--pca-extremes`: the selected atoms'
/// positions every frame, analysed at the end.
struct PcaTables {
    table: Option<crate::output::AtomicFile>,
    projection: Option<crate::output::AtomicFile>,
    vectors: Option<crate::output::AtomicFile>,
    extremes: Option<(PathBuf, texmap_md_io::Format)>,
    /// `--pca-landscape` and `--pca-landscape-table`, over the components `axes` (0-based).
    landscape: Option<PathBuf>,
    landscape_table: Option<crate::output::AtomicFile>,
    axes: (usize, usize),
    bins: usize,
    temperature: f64,
    picked: Picked,
    components: usize,
    /// `--pca-mode` (0-based) and `--pca-extreme-frames`.
    mode: usize,
    extreme_frames: usize,
    /// The first frame: each atom's first columns, the selected atoms alone (the extremes'
    /// template).
    rows: Vec<String>,
    template: MdFrame,
    pca: texmap_md_io::pca::Pca,
    frames: Vec<usize>,
    times: Vec<Option<f64>>,
}

impl PcaTables {
    fn create(analysis: &AnalysisArgs, whole: bool) -> Result<Option<PcaTables>> {
        let why = "the covariance needs every frame in one run";
        let table = whole_run_table(&analysis.pca_table, "--pca-table", why, whole)?;
        let projection = whole_run_table(&analysis.pca_projection, "--pca-projection", why, whole)?;
        let vectors = whole_run_table(&analysis.pca_vectors, "--pca-vectors", why, whole)?;
        let extremes = whole_run_trajectory(&analysis.pca_extremes, "--pca-extremes", why, whole)?;
        let landscape = chart_file(&analysis.pca_landscape, "--pca-landscape", why, whole)?;
        let landscape_table = whole_run_table(
            &analysis.pca_landscape_table,
            "--pca-landscape-table",
            why,
            whole,
        )?;
        if table.is_none()
            && projection.is_none()
            && vectors.is_none()
            && extremes.is_none()
            && landscape.is_none()
            && landscape_table.is_none()
        {
            return Ok(None);
        }
        let components = analysis.pca_components as usize;
        let mode = analysis.pca_mode as usize - 1;
        if extremes.is_some() && mode >= components {
            return usage(format!(
                "--pca-mode {}: past the --pca-components {components} computed (raise it)",
                mode + 1
            ));
        }
        let (i, j) = analysis.pca_landscape_axes;
        let axes = (i as usize - 1, j as usize - 1);
        if (landscape.is_some() || landscape_table.is_some()) && axes.0.max(axes.1) >= components {
            return usage(format!(
                "--pca-landscape-axes {i},{j}: past the --pca-components {components} computed (raise it)"
            ));
        }
        Ok(Some(PcaTables {
            table,
            projection,
            vectors,
            extremes,
            landscape,
            landscape_table,
            axes,
            bins: analysis.pca_landscape_bins as usize,
            temperature: analysis.pca_landscape_temperature,
            picked: Picked::new("--pca-select", &analysis.pca_select)?,
            components,
            mode,
            extreme_frames: analysis.pca_extreme_frames as usize,
            rows: Vec::new(),
            template: MdFrame::new(),
            pca: texmap_md_io::pca::Pca::new(analysis.msd_memory.saturating_mul(1 << 20)),
            frames: Vec::new(),
            times: Vec::new(),
        }))
    }

    /// Frame `f`'s positions of the atoms selected at the first.
    fn add(&mut self, f: usize, md: &MdFrame) -> Result<()> {
        let first = self.frames.is_empty();
        let positions = self.picked.positions(f, md, first)?;
        if first {
            self.rows = (0..md.n_atoms()).map(|i| atom_columns(md, i)).collect();
            self.template = md.clone();
            self.template.retain_atoms(&self.picked.mask());
        }
        self.pca
            .add(&positions)
            .map_err(|e| anyhow::anyhow!("--pca-select: frame {f}: {e}"))?;
        self.frames.push(f);
        self.times.push(md.time);
        Ok(())
    }

    /// The tables written and the extremes' trajectory, the leading variances printed.
    fn finish(mut self) -> Result<Vec<crate::output::AtomicFile>> {
        let c = self
            .pca
            .solve(self.components)
            .map_err(|e| anyhow::anyhow!("principal components of --pca-select: {e}"))?;
        let k = c.vectors.len();
        let cosine: Vec<f64> = (0..k)
            .map(|j| {
                let p: Vec<f64> = c.projections.iter().map(|p| p[j]).collect();
                texmap_md_io::pca::cosine_content(&p, j)
            })
            .collect();
        if let Some(t) = &mut self.table {
            let mut text = String::from("component,variance,fraction,cumulated,cosine_content\n");
            for (j, v) in c.variance.iter().enumerate() {
                let fraction = if c.total_variance > 0.0 {
                    v / c.total_variance
                } else {
                    0.0
                };
                text.push_str(&format!(
                    "{},{v:.6},{fraction:.6},{:.6},{}\n",
                    j + 1,
                    c.cumulated(j),
                    cosine.get(j).map(|x| format!("{x:.6}")).unwrap_or_default()
                ));
            }
            t.write(&text)?;
        }
        if let Some(t) = &mut self.projection {
            let mut text = String::from("frame,time");
            for j in 0..k {
                text.push_str(&format!(",pc{}", j + 1));
            }
            text.push('\n');
            for ((f, time), p) in self.frames.iter().zip(&self.times).zip(&c.projections) {
                let time = time
                    .map(|t| crate::scene::compact(t, 6))
                    .unwrap_or_default();
                text.push_str(&format!("{f},{time}"));
                for x in p {
                    text.push_str(&format!(",{x:.6}"));
                }
                text.push('\n');
            }
            t.write(&text)?;
        }
        if let Some(t) = &mut self.vectors {
            let mut text = String::from("atom,id,name,resname,resid,chain,mean_x,mean_y,mean_z");
            for j in 0..k {
                let n = j + 1;
                text.push_str(&format!(",pc{n}x,pc{n}y,pc{n}z"));
            }
            text.push('\n');
            let mut at = self.picked.atoms.iter().enumerate().peekable();
            for (i, row) in self.rows.iter().enumerate() {
                text.push_str(row);
                match at.next_if(|(_, a)| **a == i) {
                    Some((s, _)) => {
                        for x in c.mean[s] {
                            text.push_str(&format!(",{x:.4}"));
                        }
                        for v in &c.vectors {
                            for x in v[s] {
                                text.push_str(&format!(",{x:.6}"));
                            }
                        }
                    }
                    None => text.push_str(&",".repeat(3 + 3 * k)),
                }
                text.push('\n');
            }
            t.write(&text)?;
        }
        if let Some((path, format)) = &self.extremes {
            let mut frame = self.template.clone();
            crate::output::write_atomic(path, |tmp| {
                let mut w = texmap_md_io::Writer::create_as(tmp, *format, path)?;
                for (i, positions) in c
                    .along(self.mode, self.extreme_frames)
                    .into_iter()
                    .enumerate()
                {
                    frame.positions = positions;
                    frame.time = Some(i as f64);
                    w.write_frame(&frame)?;
                }
                w.finish()?;
                Ok(())
            })?;
        }
        if self.landscape.is_some() || self.landscape_table.is_some() {
            self.write_landscape(&c)?;
        }
        let shown: Vec<String> = (0..c.variance.len().min(3))
            .map(|j| {
                format!(
                    "PC{} {} Å² ({:.1} %)",
                    j + 1,
                    crate::scene::compact(c.variance[j], 4),
                    100.0 * c.variance[j] / c.total_variance.max(f64::MIN_POSITIVE)
                )
            })
            .collect();
        crate::note!(
            "principal components of {} atoms over {} frames: {}; the first {} carry {:.1} %",
            self.picked.atoms.len(),
            self.frames.len(),
            shown.join(", "),
            k.min(c.variance.len()),
            100.0 * c.cumulated(k.saturating_sub(1))
        );
        if let Some(j) = cosine.iter().take(3).position(|x| *x > 0.7) {
            eprintln!(
                "texmap: warning: PC{}'s projection has a cosine content of {:.2}: the run diffused along it rather than sampling it (Hess 2002); a longer run is needed before reading it as a motion",
                j + 1,
                cosine[j]
            );
        }
        Ok([
            self.table,
            self.projection,
            self.vectors,
            self.landscape_table,
        ]
        .into_iter()
        .flatten()
        .collect())
    }

    /// `--pca-landscape` and `--pca-landscape-table` from the frames' projections.
    fn write_landscape(&mut self, c: &texmap_md_io::pca::Components) -> Result<()> {
        use texmap_md_io::pca::{GAS_CONSTANT, Landscape};
        let (i, j) = self.axes;
        if c.vectors.len() <= i.max(j) {
            bail!(
                "--pca-landscape-axes {},{}: the motion has only {} components",
                i + 1,
                j + 1,
                c.vectors.len()
            );
        }
        let points: Vec<(f64, f64)> = c.projections.iter().map(|p| (p[i], p[j])).collect();
        let l = Landscape::new(&points, self.bins, GAS_CONSTANT * self.temperature)
            .ok_or_else(|| anyhow::anyhow!("--pca-landscape: no finite projections to bin"))?;
        let (x, y) = (format!("pc{}", i + 1), format!("pc{}", j + 1));
        if let Some(t) = &mut self.landscape_table {
            let mut text = format!("{x},{y},frames,free_energy\n");
            for b in 0..self.bins {
                for a in 0..self.bins {
                    let k = b * self.bins + a;
                    let (cx, cy) = l.centre(a, b);
                    let g = l.free_energy[k]
                        .map(|g| format!("{g:.4}"))
                        .unwrap_or_default();
                    text.push_str(&format!("{cx:.4},{cy:.4},{},{g}\n", l.counts[k]));
                }
            }
            t.write(&text)?;
        }
        if let Some(path) = &self.landscape {
            let (xl, yl) = (format!("PC{} (Å)", i + 1), format!("PC{} (Å)", j + 1));
            write_chart(path, texmap_study::chart::HEATMAP_SIZE, |t| {
                texmap_study::chart::landscape(&l, &xl, &yl, "ΔG (kJ/mol)", t)
            })?;
        }
        let top = l
            .free_energy
            .iter()
            .flatten()
            .fold(0.0f64, |m, g| m.max(*g));
        let visited = l.counts.iter().filter(|&&n| n > 0).count();
        crate::note!(
            "free-energy landscape on {x}-{y}: {visited} of {} bins visited, ΔG up to {} kJ/mol at {} K",
            self.bins * self.bins,
            crate::scene::compact(top, 3),
            crate::scene::compact(self.temperature, 4)
        );
        Ok(())
    }
}

/// `--vacf-table` and `--vdos-table`: every frame's velocities, correlated at the end.
struct VelocityTables {
    vacf: Option<crate::output::AtomicFile>,
    vdos: Option<crate::output::AtomicFile>,
    all: texmap_md_io::vacf::Velocities,
    times: Vec<Option<f64>>,
    kinds: Vec<texmap_md_io::Label>,
    kind: Vec<usize>,
    /// Each atom's mass, or `None` when an atom has none (no element, no mass in the files) (the spectrum is then unweighted):
    /// the index of the first such atom.
    mass: std::result::Result<Vec<f64>, usize>,
    integrate: Option<f64>,
}

impl VelocityTables {
    fn flags(&self) -> &'static str {
        match (&self.vacf, &self.vdos) {
            (Some(_), None) => "--vacf-table",
            (None, Some(_)) => "--vdos-table",
            _ => "--vacf-table/--vdos-table",
        }
    }

    fn add(&mut self, f: usize, md: &MdFrame) -> Result<()> {
        let flags = self.flags();
        if md.velocities.is_empty() {
            bail!(
                "{flags}: frame {f} has no velocities (write them: a .trr with nstvout, a LAMMPS dump with vx vy vz, AMBER's ntwv)"
            );
        }
        if self.all.frames() == 0 {
            self.kind = kinds_of(md, &mut self.kinds).unwrap_or_default();
            let mass: Vec<Option<f64>> = (0..md.n_atoms()).map(|i| mass_of(md, i)).collect();
            self.mass = match mass.iter().position(Option::is_none) {
                Some(i) => Err(i),
                None => Ok(mass.into_iter().flatten().collect()),
            };
        }
        self.all
            .push(&md.velocities)
            .map_err(|e| anyhow::anyhow!("{flags}: frame {f}: {e}"))?;
        self.times.push(md.time);
        Ok(())
    }

    /// The tables written (the Green–Kubo coefficients printed), in the order vacf, vdos.
    fn finish(mut self) -> Result<Vec<crate::output::AtomicFile>> {
        let times = even_lag_times(&self.times);
        let mut done = Vec::new();
        if let Some(mut file) = self.vacf.take() {
            let c = self
                .all
                .autocorrelation(&self.kind, self.kinds.len())
                .map_err(|e| anyhow::anyhow!("--vacf-table: {e}"))?;
            let (text, x, unit) = lag_table("vacf", &self.kinds, &times, &c.total, &c.kinds, |v| {
                format!("{v:.8e}")
            });
            file.write(&text)?;
            // By default up to lag ⌊T/2⌋.
            let to = self
                .integrate
                .unwrap_or(x.get(x.len() / 2).copied().unwrap_or(0.0));
            let names = std::iter::once("every atom".to_string())
                .chain(self.kinds.iter().map(|k| format!("the {k} atoms")));
            for (name, column) in names.zip(std::iter::once(&c.total).chain(&c.kinds)) {
                let upto = crate::scene::compact(to, 4);
                match texmap_md_io::vacf::green_kubo(&x, column, to) {
                    // Å²/ps is 10⁻⁴ cm²/s.
                    Some(d) if times.is_some() => eprintln!(
                        "texmap: --vacf-table: D = {:.4} × 10⁻⁵ cm²/s for {name} (Green–Kubo, ⅓ ∫ C(t) dt over 0–{upto} ps)",
                        d * 10.0
                    ),
                    Some(d) => eprintln!(
                        "texmap: --vacf-table: ⅓ ∫ C dt = {d:.6} Å²/ps² × frames for {name} over lags 0–{upto} {unit} (the frames carry no evenly spaced times)"
                    ),
                    None => eprintln!(
                        "texmap: warning: --vacf-table: fewer than two lags in 0–{upto} {unit} to integrate for {name} (--vacf-integrate)"
                    ),
                }
            }
            done.push(file);
        }
        if let Some(mut file) = self.vdos.take() {
            let Some(t) = &times else {
                bail!(
                    "--vdos-table: the frames' times are missing or not evenly spaced, so the spectrum has no frequency axis (the frames written: {})",
                    self.times.len()
                );
            };
            let dt = t[1];
            let mass = match &self.mass {
                Ok(m) => m.clone(),
                Err(i) => {
                    eprintln!(
                        "texmap: warning: --vdos-table: atom {i} has no mass (no element, and the files give none): the spectrum over every atom is unweighted"
                    );
                    vec![1.0; self.kind.len()]
                }
            };
            let g = self
                .all
                .density_of_states(&self.kind, self.kinds.len(), &mass, dt)
                .map_err(|e| anyhow::anyhow!("--vdos-table: {e}"))?;
            let mut text = String::from("frequency,wavenumber,vdos");
            for k in &self.kinds {
                text.push_str(&format!(",vdos_{k}"));
            }
            text.push('\n');
            // 1 THz is 10¹² / c cm⁻¹, c = 29,979,245,800 cm/s.
            const CM_PER_THZ: f64 = 1e12 / 29_979_245_800.0;
            for (k, nu) in g.frequency.iter().enumerate() {
                text.push_str(&format!(
                    "{},{},{:.8e}",
                    crate::scene::compact(*nu, 8),
                    crate::scene::compact(nu * CM_PER_THZ, 8),
                    g.total[k]
                ));
                for column in &g.kinds {
                    text.push_str(&format!(",{:.8e}", column[k]));
                }
                text.push('\n');
            }
            file.write(&text)?;
            done.push(file);
        }
        Ok(done)
    }
}

/// Each atom's kind (its type, else its element: [`texmap_md_io::rdf::atom_kind`]) as an index
/// into `kinds`, which is first filled with `md`'s kinds sorted by name when empty (the first
/// frame sets a table's columns). An atom of a kind not in `kinds` is returned as the error.
fn kinds_of(
    md: &MdFrame,
    kinds: &mut Vec<texmap_md_io::Label>,
) -> std::result::Result<Vec<usize>, (usize, texmap_md_io::Label)> {
    let of: Vec<texmap_md_io::Label> = (0..md.n_atoms())
        .map(|i| texmap_md_io::rdf::atom_kind(md, i))
        .collect();
    if kinds.is_empty() {
        *kinds = of.clone();
        kinds.sort_by(|a, b| a.as_str().cmp(b.as_str()));
        kinds.dedup();
    }
    of.iter()
        .enumerate()
        .map(|(i, k)| kinds.iter().position(|s| s == k).ok_or((i, *k)))
        .collect()
}

/// The error of [`kinds_of`] for `flag`'s table at frame `f`.
fn new_kind(
    flag: &str,
    f: usize,
    (i, k): (usize, texmap_md_io::Label),
    kinds: &[texmap_md_io::Label],
) -> anyhow::Error {
    let known: Vec<String> = kinds.iter().map(|k| k.to_string()).collect();
    anyhow::anyhow!(
        "{flag}: frame {f}'s atom {i} is of kind {k}, which the first frame did not have ({}): the columns are the first frame's kinds",
        known.join(", ")
    )
}

/// `--profile-table`: the frames' density profiles summed, to be written as their mean.
struct ProfileMean {
    /// The cell edge (0, 1, 2) and its name as the table's first column.
    axis: usize,
    name: String,
    bins: usize,
    /// The kinds of the columns, sorted by name (the first frame's).
    kinds: Vec<texmap_md_io::Label>,
    /// Per bin: position, number, mass, charge, then each kind.
    sums: Vec<Vec<f64>>,
    charges: bool,
    frames: usize,
}

impl ProfileMean {
    fn add(&mut self, f: usize, md: &MdFrame) -> Result<()> {
        let kind = kinds_of(md, &mut self.kinds)
            .map_err(|e| new_kind("--profile-table", f, e, &self.kinds))?;
        let p = texmap_md_io::profile::density_profile(
            md,
            self.axis,
            self.bins,
            &kind,
            self.kinds.len(),
        )
        .map_err(|e| anyhow::anyhow!("--profile-table: {e}"))?;
        if self.frames == 0 {
            self.charges = p.charge.is_some();
            self.sums = vec![vec![0.0; 4 + self.kinds.len()]; self.bins];
        } else if self.charges != p.charge.is_some() {
            bail!(
                "--profile-table: frame {f} has charges where the first frame had none, or none where it had them"
            );
        }
        for (b, row) in self.sums.iter_mut().enumerate() {
            row[0] += p.position[b];
            row[1] += p.number[b];
            row[2] += p.mass[b];
            row[3] += p.charge.as_ref().map_or(0.0, |c| c[b]);
            for (v, k) in row[4..].iter_mut().zip(&p.kinds) {
                *v += k[b];
            }
        }
        self.frames += 1;
        Ok(())
    }

    fn csv(&self) -> String {
        let mut text = format!("{},number,mass", self.name);
        if self.charges {
            text.push_str(",charge");
        }
        for k in &self.kinds {
            text.push_str(&format!(",number_{k}"));
        }
        text.push('\n');
        let n = self.frames.max(1) as f64;
        for row in &self.sums {
            text.push_str(&format!(
                "{:.4},{:.8},{:.8}",
                row[0] / n,
                row[1] / n,
                row[2] / n
            ));
            if self.charges {
                text.push_str(&format!(",{:.8}", row[3] / n));
            }
            for v in &row[4..] {
                text.push_str(&format!(",{:.8}", v / n));
            }
            text.push('\n');
        }
        text
    }
}

/// `--rdf-table`: the frames' g(r) summed, to be written as their mean.
#[derive(Default)]
struct RdfMean {
    r: Vec<f64>,
    /// The kind pairs of the partial functions (`Si-O`), the first frame's.
    kinds: Vec<String>,
    /// Per bin: the total, then each partial.
    sums: Vec<Vec<f64>>,
    frames: usize,
}

impl RdfMean {
    fn add(&mut self, f: usize, g: &texmap_md_io::rdf::Rdf) -> Result<()> {
        let kinds: Vec<String> = g
            .partial
            .iter()
            .map(|p| format!("{}-{}", p.kinds[0], p.kinds[1]))
            .collect();
        if self.frames == 0 {
            self.r = g.r.clone();
            self.kinds = kinds;
            self.sums = vec![vec![0.0; 1 + g.partial.len()]; g.r.len()];
        } else if kinds != self.kinds {
            bail!(
                "--rdf-partial: frame {f}'s kinds of atoms ({}) are not the first frame's ({}): a mean of partial g(r) needs the same pairs in every frame",
                kinds.join(", "),
                self.kinds.join(", ")
            );
        }
        for (k, row) in self.sums.iter_mut().enumerate() {
            row[0] += g.total[k];
            for (v, p) in row[1..].iter_mut().zip(&g.partial) {
                *v += p.g[k];
            }
        }
        self.frames += 1;
        Ok(())
    }

    fn csv(&self) -> String {
        let mut text = String::from("r,g");
        for k in &self.kinds {
            text.push_str(&format!(",g_{k}"));
        }
        text.push('\n');
        let n = self.frames.max(1) as f64;
        for (r, row) in self.r.iter().zip(&self.sums) {
            text.push_str(&format!("{r:.6}"));
            for v in row {
                text.push_str(&format!(",{:.6}", v / n));
            }
            text.push('\n');
        }
        text
    }
}

impl AnalysisTables {
    /// The tables `analysis` asks for, their headers written (`whole`: see [`per_frame_table`]).
    pub(crate) fn create(analysis: &AnalysisArgs, whole: bool) -> Result<AnalysisTables> {
        Ok(AnalysisTables {
            defect: per_frame_table(
                &analysis.defect_table,
                "--defect-table",
                "frame,vacancies,interstitials",
                whole,
            )?,
            grain: per_frame_table(
                &analysis.grain_table,
                "--grain-table",
                "frame,grain,atoms,crystalline,structure,qx,qy,qz,qw",
                whole,
            )?,
            msd: per_frame_table(&analysis.msd_table, "--msd-table", "", whole)?
                .map(|t| (t, Vec::new())),
            rmsd: per_frame_table(
                &analysis.rmsd_table,
                "--rmsd-table",
                "frame,time,rmsd",
                whole,
            )?,
            cluster: per_frame_table(
                &analysis.cluster_table,
                "--cluster-table",
                "frame,cluster,atoms,x,y,z,rg",
                whole,
            )?,
            profile: whole_run_table(
                &analysis.profile_table,
                "--profile-table",
                "every part would write its own mean",
                whole,
            )?
            .map(|t| {
                (
                    t,
                    ProfileMean {
                        axis: match analysis.profile_axis.as_str() {
                            "x" | "a" => 0,
                            "y" | "b" => 1,
                            _ => 2,
                        },
                        name: analysis.profile_axis.clone(),
                        bins: analysis.profile_bins as usize,
                        kinds: Vec::new(),
                        sums: Vec::new(),
                        charges: false,
                        frames: 0,
                    },
                )
            }),
            dihedral: per_frame_table(
                &analysis.dihedral_table,
                "--dihedral-table",
                "frame,time,chain,resid,resname,phi,psi,omega",
                whole,
            )?,
            ramachandran: RamachandranPlot::create(analysis, whole)?,
            rmsf: whole_run_table(
                &analysis.rmsf_table,
                "--rmsf-table",
                "the mean position needs every frame in one run",
                whole,
            )?
            .map(|t| (t, texmap_md_io::rmsf::Fluctuation::new(), Vec::new())),
            contacts: ContactsTable::create(analysis, whole)?,
            saltbridges: SaltBridgeTables::create(analysis, whole)?,
            pca: PcaTables::create(analysis, whole)?,
            dssp: DsspTables::create(analysis, whole)?,
            rmsd_matrix: RmsdMatrix::create(analysis, whole)?,
            residue_map: ResidueMap::create(analysis, whole)?,
            order: OrderTable::create(analysis, whole)?,
            membrane: MembraneTable::create(analysis, whole)?,
            hbond: per_frame_table(
                &analysis.hbond_table,
                "--hbond-table",
                "frame,donor,hydrogen,acceptor,donor_atom,hydrogen_atom,acceptor_atom,distance,angle",
                whole,
            )?,
            hbond_occupancy: whole_run_table(
                &analysis.hbond_occupancy,
                "--hbond-occupancy",
                "the occupancy counts every frame",
                whole,
            )?
            .map(|t| (t, HbondOccupancy::default())),
            hbond_lifetime: SurvivalTable::create(
                &analysis.hbond_lifetime,
                "--hbond-lifetime",
                (analysis.hbond_lifetime_max, analysis.hbond_intermittency),
                whole,
                None,
            )?,
            measure: match per_frame_table(
                &analysis.measure_table,
                "--measure-table",
                "frame,measure,kind,value,atoms,spec",
                whole,
            )? {
                Some(_) if analysis.measures.is_empty() => {
                    return usage(
                        "--measure-table lists the --measure values: add a measurement, as --measure 'index 0; index 5'",
                    );
                }
                Some(t) => Some((t, analysis.measures.clone())),
                None => None,
            },
            survival: SurvivalTable::create(
                &analysis.survival_table,
                "--survival-table",
                (analysis.survival_max, analysis.survival_intermittency),
                whole,
                analysis
                    .survival_select
                    .as_deref()
                    .map(|s| crate::scene::parse_selection("--survival-select", s))
                    .transpose()?,
            )?,
            density: match whole_run_table(
                &analysis.density_map,
                "--density-map",
                "the mean over the frames needs every frame in one run",
                whole,
            )? {
                Some(file) => Some(DensityTable {
                    file,
                    select: crate::scene::parse_selection(
                        "--density-select",
                        &analysis.density_select,
                    )?,
                    text: analysis.density_select.clone(),
                    delta: analysis.density_delta,
                    padding: analysis.density_padding,
                    map: None,
                    first: 0,
                    positions: 0,
                    units: texmap_md_io::density::UNITS
                        .iter()
                        .find(|(name, _)| *name == analysis.density_units)
                        .map(|&(name, factor)| (name.to_string(), factor))
                        .unwrap_or(("A^-3".into(), 1.0)),
                }),
                None => None,
            },
            msd_lags: whole_run_table(
                &analysis.msd_lags,
                "--msd-lags",
                "the average over every time origin needs every frame in one run",
                whole,
            )?
            .map(|file| MsdLags {
                file,
                all: texmap_md_io::msd::AllOrigins::new(
                    analysis.msd_memory.saturating_mul(1 << 20),
                ),
                times: Vec::new(),
                kinds: Vec::new(),
                kind: Vec::new(),
                fit: analysis.msd_fit,
            }),
            sasa: per_frame_table(
                &analysis.sasa_table,
                "--sasa-table",
                "frame,time,sasa",
                whole,
            )?,
            gyration: match per_frame_table(
                &analysis.gyration_table,
                "--gyration-table",
                "frame,time,rg,rg_x,rg_y,rg_z,asphericity",
                whole,
            )? {
                Some(t) => {
                    let sel = crate::scene::parse_selection(
                        "--gyration-select",
                        &analysis.gyration_select,
                    )?;
                    Some((t, sel, !analysis.gyration_unweighted))
                }
                None => None,
            },
            sasa_residues: per_frame_table(
                &analysis.sasa_residue_table,
                "--sasa-residue-table",
                "frame,time,chain,resid,resname,sasa",
                whole,
            )?,
            velocities: {
                let why = "the average over every time origin needs every frame in one run";
                let vacf = whole_run_table(&analysis.vacf_table, "--vacf-table", why, whole)?;
                let vdos = whole_run_table(&analysis.vdos_table, "--vdos-table", why, whole)?;
                (vacf.is_some() || vdos.is_some()).then(|| VelocityTables {
                    vacf,
                    vdos,
                    all: texmap_md_io::vacf::Velocities::new(
                        analysis.msd_memory.saturating_mul(1 << 20),
                    ),
                    times: Vec::new(),
                    kinds: Vec::new(),
                    kind: Vec::new(),
                    mass: Ok(Vec::new()),
                    integrate: analysis.vacf_integrate,
                })
            },
            rdf: whole_run_table(
                &analysis.rdf_table,
                "--rdf-table",
                "every part would write its own mean",
                whole,
            )?
            .map(|t| (t, RdfMean::default())),
        })
    }

    /// Frame `f`'s rows, from what `plan` found in it (`md`, as prepared).
    pub(crate) fn write(
        &mut self,
        f: usize,
        plan: &texmap_md_scene::MolPlan,
        md: &MdFrame,
    ) -> Result<()> {
        let time = md
            .time
            .map(|t| crate::scene::compact(t, 6))
            .unwrap_or_default();
        if let Some(t) = &mut self.cluster
            && let Some(c) = plan.last_clusters()
        {
            let mut rows = String::new();
            for (k, (size, (p, rg))) in c
                .sizes
                .iter()
                .zip(c.centers.iter().zip(&c.gyration))
                .enumerate()
            {
                rows.push_str(&format!(
                    "{f},{k},{size},{:.4},{:.4},{:.4},{rg:.4}\n",
                    p[0], p[1], p[2]
                ));
            }
            t.write(&rows)?;
        }
        if let Some(t) = &mut self.rmsd
            && let Some(rmsd) = plan.last_fit_rmsd()
        {
            t.write(&format!("{f},{time},{rmsd:.6}\n"))?;
        }
        if let Some((t, kinds)) = &mut self.msd
            && let Some(d2) = md.property(texmap_md_scene::MSD)
        {
            let first = kinds.is_empty();
            let of = kinds_of(md, kinds).map_err(|e| new_kind("--msd-table", f, e, kinds))?;
            if first {
                let mut header = String::from("frame,time,msd");
                for k in kinds.iter() {
                    header.push_str(&format!(",msd_{k}"));
                }
                t.write(&format!("{header}\n"))?;
            }
            let mean = |pick: &dyn Fn(usize) -> bool| {
                let (sum, count) = d2
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| pick(*i))
                    .fold((0.0f64, 0usize), |(s, c), (_, v)| (s + *v as f64, c + 1));
                if count == 0 {
                    String::new()
                } else {
                    format!("{:.6}", sum / count as f64)
                }
            };
            let mut row = format!("{f},{time},{}", mean(&|_| true));
            for k in 0..kinds.len() {
                row.push(',');
                row.push_str(&mean(&|i| of.get(i) == Some(&k)));
            }
            t.write(&format!("{row}\n"))?;
        }
        if let Some(t) = &mut self.defect
            && let Some((vacancies, interstitials)) = plan.last_defects()
        {
            t.write(&format!("{f},{vacancies},{interstitials}\n"))?;
        }
        if let Some(t) = &mut self.grain
            && let Some(grains) = plan.last_grains()
        {
            let mut rows = String::new();
            for (g, grain) in grains.iter().enumerate() {
                let [x, y, z, w] = grain.orientation;
                rows.push_str(&format!(
                    "{f},{g},{},{},{},{x:.6},{y:.6},{z:.6},{w:.6}\n",
                    grain.size,
                    grain.crystalline,
                    grain.structure.name()
                ));
            }
            t.write(&rows)?;
        }
        if let Some((_, mean)) = &mut self.rdf
            && let Some(g) = plan.last_rdf()
        {
            mean.add(f, g)?;
        }
        if let Some(lags) = &mut self.msd_lags
            && let Some(unwrapped) = plan.last_unwrapped()
        {
            lags.add(f, unwrapped, md)?;
        }
        if let Some(v) = &mut self.velocities {
            v.add(f, md)?;
        }
        if let Some((t, sel, by_mass)) = &mut self.gyration {
            t.write(&gyration_row(f, &time, md, sel, *by_mass)?)?;
        }
        if let Some(area) = md.property(texmap_md_scene::SASA) {
            let measured = || area.iter().filter(|a| a.is_finite()).map(|a| f64::from(*a));
            if let Some(t) = &mut self.sasa {
                t.write(&format!("{f},{time},{:.3}\n", measured().sum::<f64>()))?;
            }
            if let Some(t) = &mut self.sasa_residues {
                t.write(&residue_sums(f, &time, md, area))?;
            }
        }
        if let Some(t) = &mut self.dihedral {
            let angle = |a: Option<f64>| a.map(|a| format!("{a:.3}")).unwrap_or_default();
            let label = |v: &[texmap_md_io::Label], i: usize| {
                v.get(i).map(|l| l.to_string()).unwrap_or_default()
            };
            let mut rows = String::new();
            for r in texmap_md_io::dihedrals::backbone_dihedrals(md) {
                let i = r.atoms.start;
                rows.push_str(&format!(
                    "{f},{time},{},{},{},{},{},{}\n",
                    label(&md.chains, i),
                    md.res_ids.get(i).map(|n| n.to_string()).unwrap_or_default(),
                    label(&md.res_names, i),
                    angle(r.phi),
                    angle(r.psi),
                    angle(r.omega)
                ));
            }
            t.write(&rows)?;
        }
        if let Some(r) = &mut self.ramachandran {
            r.add(f, md)?;
        }
        if let Some((_, mean)) = &mut self.profile {
            mean.add(f, md)?;
        }
        if let Some((_, fluctuation, rows)) = &mut self.rmsf {
            if fluctuation.frames() == 0 {
                *rows = (0..md.n_atoms()).map(|i| atom_columns(md, i)).collect();
            }
            fluctuation
                .add(&md.positions)
                .map_err(|e| anyhow::anyhow!("--rmsf-table: frame {f}: {e}"))?;
        }
        if let Some(d) = &mut self.density {
            d.add(f, md)?;
        }
        if let Some(c) = &mut self.contacts {
            c.add(f, &time, md)?;
        }
        if let Some(b) = &mut self.saltbridges {
            b.add(f, &time, md)?;
        }
        if let Some(t) = &mut self.survival {
            t.add_selected(f, md)?;
        }
        if let Some(p) = &mut self.pca {
            p.add(f, md)?;
        }
        if let Some(d) = &mut self.dssp {
            d.add(f, &time, md)?;
        }
        if let Some(r) = &mut self.residue_map {
            r.add(f, md)?;
        }
        if let Some(o) = &mut self.order {
            o.add(f, plan, md)?;
        }
        if let Some(m) = &mut self.membrane {
            m.add(f, &time, md)?;
        }
        if let Some(r) = &mut self.rmsd_matrix {
            r.add(f, md)?;
        }
        if let Some(t) = &mut self.hbond {
            t.write(&hbond_rows(f, plan.last_hbonds(), md))?;
        }
        if let Some((_, o)) = &mut self.hbond_occupancy {
            o.add(plan.last_hbonds(), md);
        }
        if let Some(l) = &mut self.hbond_lifetime {
            l.add_hbonds(plan.last_hbonds(), md.time);
        }
        if let Some((t, specs)) = &mut self.measure {
            let mut rows = String::new();
            for (m, (got, spec)) in plan
                .last_measurements()
                .iter()
                .zip(specs.iter())
                .enumerate()
            {
                let kind = ["distance", "angle", "dihedral"][got.atoms.len() - 2];
                let atoms: Vec<String> = got.atoms.iter().map(|i| i.to_string()).collect();
                let spec = spec.replace('"', "\"\"");
                rows += &format!(
                    "{f},{m},{kind},{:.6},{},\"{spec}\"\n",
                    got.value,
                    atoms.join(" ")
                );
            }
            t.write(&rows)?;
        }
        Ok(())
    }

    /// Every table moved into place (`--rdf-table`'s mean written first).
    pub(crate) fn commit(self) -> Result<()> {
        let rdf = self
            .rdf
            .map(|(mut t, mean)| t.write(&mean.csv()).map(|()| t));
        let msd = self.msd.map(|(t, _)| t);
        let msd_lags = self.msd_lags.map(MsdLags::finish).transpose()?;
        let velocities = self
            .velocities
            .map(VelocityTables::finish)
            .transpose()?
            .unwrap_or_default();
        let profile = self
            .profile
            .map(|(mut t, mean)| t.write(&mean.csv()).map(|()| t))
            .transpose()?;
        let rmsf = self
            .rmsf
            .map(|(mut t, fluctuation, rows)| {
                let mut text = String::from("atom,id,name,resname,resid,chain,rmsf\n");
                for (row, r) in rows.iter().zip(fluctuation.rmsf()) {
                    text.push_str(&format!("{row},{r:.6}\n"));
                }
                t.write(&text).map(|()| t)
            })
            .transpose()?;
        let density = self.density.map(DensityTable::finish).transpose()?;
        let survival = self.survival.map(SurvivalTable::finish).transpose()?;
        let pca = self
            .pca
            .map(PcaTables::finish)
            .transpose()?
            .unwrap_or_default();
        let dssp = self
            .dssp
            .map(DsspTables::finish)
            .transpose()?
            .unwrap_or_default();
        let rmsd_matrix = self
            .rmsd_matrix
            .map(RmsdMatrix::finish)
            .transpose()?
            .unwrap_or_default();
        let hbond_lifetime = self.hbond_lifetime.map(SurvivalTable::finish).transpose()?;
        let saltbridges = self
            .saltbridges
            .map(SaltBridgeTables::finish)
            .transpose()?
            .unwrap_or_default();
        let hbond_occupancy = self
            .hbond_occupancy
            .map(|(mut t, o)| t.write(&o.csv()).map(|()| t))
            .transpose()?;
        let residue_map = self
            .residue_map
            .map(ResidueMap::finish)
            .transpose()?
            .unwrap_or_default();
        if let Some(r) = &self.ramachandran {
            r.finish()?;
        }
        let order = self.order.map(OrderTable::finish).transpose()?;
        for t in [
            self.hbond,
            hbond_lifetime,
            hbond_occupancy,
            order,
            self.membrane.map(|m| m.file),
            self.measure.map(|(t, _)| t),
            survival,
            self.contacts.map(|c| c.file),
            density,
            self.dihedral,
            self.sasa,
            self.sasa_residues,
            self.gyration.map(|(t, _, _)| t),
            msd_lags,
            profile,
            rmsf,
            self.defect,
            self.grain,
            self.rmsd,
            self.cluster,
            msd,
            rdf.transpose()?,
        ]
        .into_iter()
        .flatten()
        .chain(velocities)
        .chain(pca)
        .chain(dssp)
        .chain(rmsd_matrix)
        .chain(residue_map)
        .chain(saltbridges)
        {
            t.commit()?;
        }
        Ok(())
    }
}

/// `--order-table`: lipid tail order parameters over the run; the carbons and their bonds are
/// found at the first frame.
struct OrderTable {
    file: crate::output::AtomicFile,
    chart: Option<PathBuf>,
    select: texmap_md_io::select::Selection,
    method: texmap_md_io::order::Method,
    normal: usize,
    order: Option<texmap_md_io::order::OrderParameters>,
}

impl OrderTable {
    fn create(analysis: &AnalysisArgs, whole: bool) -> Result<Option<OrderTable>> {
        let Some(file) = whole_run_table(
            &analysis.order_table,
            "--order-table",
            "the order parameters average every frame",
            whole,
        )?
        else {
            return Ok(None);
        };
        let select = analysis.order_select.as_deref().unwrap_or_default();
        Ok(Some(OrderTable {
            file,
            chart: chart_file(
                &analysis.order_chart,
                "--order-chart",
                "the order parameters average every frame",
                whole,
            )?,
            select: crate::scene::parse_selection("--order-select", select)?,
            method: match analysis.order_method.as_str() {
                "united-atom" => texmap_md_io::order::Method::UnitedAtom,
                "bonds" => texmap_md_io::order::Method::Bonds,
                _ => texmap_md_io::order::Method::Hydrogens,
            },
            normal: match analysis.order_normal.as_str() {
                "x" => 0,
                "y" => 1,
                _ => 2,
            },
            order: None,
        }))
    }

    fn add(&mut self, f: usize, plan: &texmap_md_scene::MolPlan, md: &MdFrame) -> Result<()> {
        if self.order.is_none() {
            let picked = self
                .select
                .evaluate(md)
                .map_err(|e| anyhow::anyhow!("--order-select: frame {f}: {e}"))?;
            let mut bonds: Vec<[u32; 2]> =
                plan.topology().map(|t| t.bonds.clone()).unwrap_or_default();
            bonds.extend_from_slice(&md.bonds);
            if bonds.is_empty() {
                bonds = texmap_md_io::bonds::bonds_by_distance(md, true).pairs;
            }
            self.order = Some(
                texmap_md_io::order::OrderParameters::new(
                    md,
                    &picked,
                    &bonds,
                    self.method,
                    self.normal,
                )
                .map_err(|e| anyhow::anyhow!("--order-table: frame {f}: {e}"))?,
            );
        }
        if let Some(order) = &mut self.order {
            order
                .add(&md.positions, md.cell.as_ref())
                .map_err(|e| anyhow::anyhow!("--order-table: frame {f}: {e}"))?;
        }
        Ok(())
    }

    fn finish(mut self) -> Result<crate::output::AtomicFile> {
        let Some(order) = self.order.take() else {
            bail!("--order-table: no frame was read");
        };
        let mut text = String::from("resname,atom,chain,position,sites,vectors,s,minus_s,sem\n");
        let sem = order.standard_error();
        let mean = order.mean();
        for ((g, s), e) in order.groups().iter().zip(&mean).zip(sem) {
            let e = if e.is_finite() {
                format!("{e:.6}")
            } else {
                String::new()
            };
            text.push_str(&format!(
                "{},{},{},{},{},{},{s:.6},{:.6},{e}\n",
                g.residue, g.name, g.chain, g.position, g.sites, g.vectors, -s
            ));
        }
        self.file.write(&text)?;
        if let Some(path) = &self.chart {
            // A line per lipid kind and chain, in order of first appearance, by position.
            let mut series: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
            for (g, s) in order.groups().iter().zip(&mean) {
                let name = format!("{} chain {}", g.residue, g.chain);
                let k = match series.iter().position(|(n, _)| *n == name) {
                    Some(k) => k,
                    None => {
                        series.push((name, Vec::new()));
                        series.len() - 1
                    }
                };
                series[k].1.push((g.position as f64, -s));
            }
            for (_, points) in &mut series {
                points.sort_by(|a, b| a.0.total_cmp(&b.0));
            }
            let y = match self.method {
                texmap_md_io::order::Method::Bonds => "−S (bond order)",
                _ => "−S_CD",
            };
            let size = texmap_study::chart::CHART_SIZE;
            write_chart(path, size, |t| {
                texmap_study::chart::lines(["", "position along the chain", y], &series, size, t)
            })?;
        }
        Ok(self.file)
    }
}

/// `--membrane-table`: the leaflets and each head's tail atom, found at the first frame.
struct MembraneTable {
    file: crate::output::AtomicFile,
    select: texmap_md_io::select::Selection,
    cutoff: f64,
    normal: usize,
    leaflets: Vec<Vec<usize>>,
    tails: std::collections::HashMap<usize, usize>,
    n_atoms: usize,
}

impl MembraneTable {
    fn create(analysis: &AnalysisArgs, whole: bool) -> Result<Option<MembraneTable>> {
        let Some(file) = per_frame_table(
            &analysis.membrane_table,
            "--membrane-table",
            "frame,time,upper,lower,thickness,area,apl_upper,apl_lower",
            whole,
        )?
        else {
            return Ok(None);
        };
        Ok(Some(MembraneTable {
            file,
            select: crate::scene::parse_selection("--membrane-select", &analysis.membrane_select)?,
            cutoff: analysis.membrane_cutoff,
            normal: match analysis.membrane_normal.as_str() {
                "x" => 0,
                "y" => 1,
                _ => 2,
            },
            leaflets: Vec::new(),
            tails: Default::default(),
            n_atoms: 0,
        }))
    }

    fn add(&mut self, f: usize, time: &str, md: &MdFrame) -> Result<()> {
        if self.leaflets.is_empty() {
            let heads = self
                .select
                .indices(md)
                .map_err(|e| anyhow::anyhow!("--membrane-select: frame {f}: {e}"))?;
            let found = texmap_md_io::membrane::leaflets(
                &md.positions,
                &heads,
                md.cell.as_ref(),
                self.cutoff,
            );
            if found.len() < 2 || found[1].len() < 2 {
                bail!(
                    "--membrane-table: frame {f}: the {} head atoms of --membrane-select form {} set(s) within --membrane-cutoff {} Å (the second largest has {} head(s)): no bilayer (a longer cutoff joins heads farther apart, a shorter one keeps the leaflets apart)",
                    heads.len(),
                    found.len(),
                    self.cutoff,
                    found.get(1).map_or(0, |l| l.len())
                );
            }
            // Each head's tail: the atom of its residue farthest from it (nearest images).
            let image = md
                .cell
                .as_ref()
                .and_then(texmap_md_io::pbc::NearestImage::new);
            let mut heads: Vec<usize> = found[..2].iter().flatten().copied().collect();
            heads.sort_unstable();
            for r in texmap_md_io::secondary::residue_ranges(md) {
                let first = heads.partition_point(|&h| h < r.start);
                let last = heads.partition_point(|&h| h < r.end);
                for h in &heads[first..last] {
                    let far = r.clone().max_by(|&a, &b| {
                        let d = |i: usize| {
                            let v: [f64; 3] = std::array::from_fn(|k| {
                                f64::from(md.positions[i][k] - md.positions[*h][k])
                            });
                            let v = image.as_ref().map_or(v, |m| m.apply(v));
                            v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
                        };
                        d(a).total_cmp(&d(b))
                    });
                    if let Some(t) = far.filter(|&t| t != *h) {
                        self.tails.insert(*h, t);
                    }
                }
            }
            self.leaflets = found;
            self.n_atoms = md.n_atoms();
        } else if md.n_atoms() != self.n_atoms {
            bail!(
                "--membrane-table: frame {f} has {} atoms and the first {}: every frame must hold the same atoms",
                md.n_atoms(),
                self.n_atoms
            );
        }
        let m = texmap_md_io::membrane::measure(
            &md.positions,
            &self.leaflets,
            md.cell.as_ref(),
            self.normal,
            |h| self.tails.get(&h).copied(),
        )
        .map_err(|e| anyhow::anyhow!("--membrane-table: frame {f}: {e}"))?;
        let num = |v: f64| {
            if v.is_finite() {
                format!("{v:.4}")
            } else {
                String::new()
            }
        };
        self.file.write(&format!(
            "{f},{time},{},{},{:.4},{},{},{}\n",
            m.lipids[0],
            m.lipids[1],
            m.thickness,
            num(m.area),
            num(m.area_per_lipid[0]),
            num(m.area_per_lipid[1])
        ))
    }
}

/// `--hbond-occupancy`: every bond seen, by donor, hydrogen and acceptor, and the frames.
#[derive(Default)]
struct HbondOccupancy {
    bonds: std::collections::BTreeMap<(u32, u32, u32), SeenBond>,
    frames: usize,
}

/// A bond's frames, its summed distance and angle, and its atoms' labels.
struct SeenBond {
    frames: usize,
    distance: f64,
    angle: f64,
    atoms: String,
}

impl HbondOccupancy {
    fn add(&mut self, bonds: &[texmap_md_io::hbonds::HBond], md: &MdFrame) {
        for b in bonds {
            let e = self
                .bonds
                .entry((b.donor, b.hydrogen, b.acceptor))
                .or_insert_with(|| SeenBond {
                    frames: 0,
                    distance: 0.0,
                    angle: 0.0,
                    atoms: [b.donor, b.hydrogen, b.acceptor]
                        .map(|i| hbond_atom(md, i))
                        .join(","),
                });
            e.frames += 1;
            e.distance += f64::from(b.distance);
            e.angle += f64::from(b.angle);
        }
        self.frames += 1;
    }

    /// The table, the most present bonds first (then by donor, hydrogen, acceptor).
    fn csv(&self) -> String {
        let mut rows: Vec<_> = self.bonds.iter().collect();
        rows.sort_by(|a, b| b.1.frames.cmp(&a.1.frames).then(a.0.cmp(b.0)));
        let mut text = String::from(
            "donor,hydrogen,acceptor,donor_atom,hydrogen_atom,acceptor_atom,frames,occupancy,distance,angle\n",
        );
        for ((d, h, a), b) in rows {
            let k = b.frames as f64;
            text.push_str(&format!(
                "{d},{h},{a},{},{},{:.6},{:.4},{:.3}\n",
                b.atoms,
                b.frames,
                k / self.frames.max(1) as f64,
                b.distance / k,
                b.angle / k
            ));
        }
        text
    }
}

/// Atom `i` of `md` as RESNAME RESID:NAME, quoted for CSV when it needs to be.
fn hbond_atom(md: &MdFrame, i: u32) -> String {
    let i = i as usize;
    let label = |v: &[texmap_md_io::Label]| v.get(i).map(|l| l.as_str().to_string());
    let res = label(&md.res_names).unwrap_or_default();
    let id = md.res_ids.get(i).map(|r| r.to_string()).unwrap_or_default();
    let name = label(&md.names).unwrap_or_else(|| format!("#{i}"));
    let text = format!("{res}{id}:{name}");
    // CSV quoting (RFC 4180) for names that hold a comma or a quote.
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text
    }
}

/// The `--hbond-table` rows of frame `f` (see the flag).
pub(crate) fn hbond_rows(f: usize, bonds: &[texmap_md_io::hbonds::HBond], md: &MdFrame) -> String {
    use std::fmt::Write;
    let atom = |i: u32| hbond_atom(md, i);
    let mut out = String::new();
    for b in bonds {
        let _ = writeln!(
            out,
            "{f},{},{},{},{},{},{},{:.4},{:.3}",
            b.donor,
            b.hydrogen,
            b.acceptor,
            atom(b.donor),
            atom(b.hydrogen),
            atom(b.acceptor),
            b.distance,
            b.angle
        );
    }
    out
}

/// Atom `i`'s mass for a mass-weighted analysis: the file's (a massless virtual site's 0
/// included) or its element's; `None` when it has neither (no element, no mass in the files).
fn mass_of(md: &MdFrame, i: usize) -> Option<f64> {
    let given = md
        .property("mass")
        .and_then(|m| m.get(i))
        .is_some_and(|m| m.is_finite());
    let m = texmap_md_io::atom_mass(md, i);
    (m > 0.0 || (given && m == 0.0)).then_some(m)
}

/// `--saltbridge-table` and `--saltbridge-occupancy`: the salt bridges of every frame among
/// `--saltbridge-select`'s atoms.
struct SaltBridgeTables {
    table: Option<crate::output::AtomicFile>,
    occupancy: Option<crate::output::AtomicFile>,
    select: texmap_md_io::select::Selection,
    cutoff: f32,
    histidine: bool,
    /// Every pair seen, by the acid's and the base's first atoms.
    seen: std::collections::BTreeMap<(usize, usize), SeenSaltBridge>,
    frames: usize,
}

/// A salt bridge's labels (acid, base, their chains, as CSV fields), frames present and summed
/// distances.
struct SeenSaltBridge {
    labels: String,
    frames: usize,
    distance: f64,
    min_distance: f64,
}

impl SaltBridgeTables {
    fn create(analysis: &AnalysisArgs, whole: bool) -> Result<Option<SaltBridgeTables>> {
        let table = per_frame_table(
            &analysis.saltbridge_table,
            "--saltbridge-table",
            "frame,time,acid,base,acid_chain,base_chain,distance,min_distance",
            whole,
        )?;
        let occupancy = whole_run_table(
            &analysis.saltbridge_occupancy,
            "--saltbridge-occupancy",
            "the occupancy counts every frame",
            whole,
        )?;
        if table.is_none() && occupancy.is_none() {
            return Ok(None);
        }
        let cutoff = analysis.saltbridge_cutoff;
        if !(cutoff > texmap_md_io::bonds::BOND_TOLERANCE
            && cutoff <= texmap_md_io::saltbridges::MAX_CUTOFF)
        {
            return usage(format!(
                "--saltbridge-cutoff {cutoff}: expected an oxygen-nitrogen distance above 0.45 and at most {} Å",
                texmap_md_io::saltbridges::MAX_CUTOFF
            ));
        }
        Ok(Some(SaltBridgeTables {
            table,
            occupancy,
            select: crate::scene::parse_selection(
                "--saltbridge-select",
                &analysis.saltbridge_select,
            )?,
            cutoff,
            histidine: analysis.saltbridge_his,
            seen: Default::default(),
            frames: 0,
        }))
    }

    fn add(&mut self, f: usize, time: &str, md: &MdFrame) -> Result<()> {
        use std::fmt::Write;
        let mut mask = vec![false; md.n_atoms()];
        for i in self
            .select
            .indices(md)
            .map_err(|e| anyhow::anyhow!("--saltbridge-select: frame {f}: {e}"))?
        {
            if let Some(m) = mask.get_mut(i) {
                *m = true;
            }
        }
        let groups = texmap_md_io::saltbridges::charged_groups(md, Some(&mask), self.histidine);
        if self.frames == 0 && (groups.acids.is_empty() || groups.bases.is_empty()) {
            eprintln!(
                "texmap: warning: frame {f}: --saltbridge-select keeps {} acidic (ASP, GLU) and {} basic (ARG, LYS{}) side chains, so there can be no salt bridges",
                groups.acids.len(),
                groups.bases.len(),
                if self.histidine { ", HIS" } else { "" }
            );
        }
        let found = texmap_md_io::saltbridges::salt_bridges(md, &groups, self.cutoff)
            .map_err(|e| anyhow::anyhow!("--saltbridge-table: frame {f}: {e}"))?;
        let residue = |i: usize| {
            let label = |v: &[texmap_md_io::Label]| {
                v.get(i).map(|l| l.as_str().to_string()).unwrap_or_default()
            };
            let id = md.res_ids.get(i).map(|r| r.to_string()).unwrap_or_default();
            (
                csv_field(&format!("{}{id}", label(&md.res_names))),
                csv_field(&label(&md.chains)),
            )
        };
        let mut rows = String::new();
        for b in &found {
            let (acid, base) = (groups.acids[b.acid].residue, groups.bases[b.base].residue);
            let e = self.seen.entry((acid, base)).or_insert_with(|| {
                let ((a, ac), (r, rc)) = (residue(acid), residue(base));
                SeenSaltBridge {
                    labels: format!("{a},{r},{ac},{rc}"),
                    frames: 0,
                    distance: 0.0,
                    min_distance: 0.0,
                }
            });
            e.frames += 1;
            e.distance += f64::from(b.distance);
            e.min_distance += f64::from(b.min_distance);
            let _ = writeln!(
                rows,
                "{f},{time},{},{:.4},{:.4}",
                e.labels, b.distance, b.min_distance
            );
        }
        if let Some(t) = &mut self.table {
            t.write(&rows)?;
        }
        self.frames += 1;
        Ok(())
    }

    /// The tables, the occupancy's rows written: the most present bridges first (then by the
    /// acid's and the base's atoms).
    fn finish(self) -> Result<Vec<crate::output::AtomicFile>> {
        let mut out: Vec<crate::output::AtomicFile> = self.table.into_iter().collect();
        if let Some(mut t) = self.occupancy {
            let mut rows: Vec<_> = self.seen.iter().collect();
            rows.sort_by(|a, b| b.1.frames.cmp(&a.1.frames).then(a.0.cmp(b.0)));
            let mut text = String::from(
                "acid,base,acid_chain,base_chain,frames,occupancy,distance,min_distance\n",
            );
            for (_, b) in rows {
                let k = b.frames as f64;
                text.push_str(&format!(
                    "{},{},{:.6},{:.4},{:.4}\n",
                    b.labels,
                    b.frames,
                    k / self.frames.max(1) as f64,
                    b.distance / k,
                    b.min_distance / k
                ));
            }
            t.write(&text)?;
            out.push(t);
        }
        Ok(out)
    }
}

/// `text` as a CSV field, quoted (RFC 4180) when it holds a comma or a quote.
fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

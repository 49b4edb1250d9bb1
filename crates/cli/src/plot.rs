//! `texmap plot`: a line chart of a table's columns, PNG or SVG — the RMSD, radius of
//! gyration, SASA or hydrogen-bond count over time that `texmap convert` writes as CSV, a
//! GROMACS `.xvg` file (what users otherwise open in xmgrace or matplotlib), a GROMACS energy
//! file (`.edr`, what `gmx energy` reads) or a LAMMPS log's thermo output.
//!
//! A CSV table has a header row of column names and comma-separated cells (RFC 4180 quotes
//! allowed); an empty cell is a gap in its line. An `.xvg` file's `#` lines are comments, its
//! `@` lines give the axis labels and the series' legends, and its rows are numbers separated
//! by spaces. An `.edr` file (by its extension or its first bytes) and a LAMMPS log (a file
//! whose first lines name `LAMMPS (`) are read by md-io's `energy` module: the `.edr` file's
//! columns are `Time` (ps) and its terms with their units, picked by name as `gmx energy`
//! names them (`--y Temperature,Pressure`; spaces may be written as `-`, as its menu shows
//! them) and drawn against the time; the log's columns are its thermo keywords, every run's
//! table joined, drawn against `Step`. Columns are chosen by name or by number from 1.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::Args;

use texmap_md_io::energy::{self, EnergyTable};

use crate::args::usage;

/// `texmap plot FILE --y COL -o OUT.png`.
#[derive(Args, Clone, Debug)]
pub struct PlotArgs {
    /// The table: CSV with a header row (every table texmap convert writes), a GROMACS .xvg
    /// file (gmx rms, gyrate, energy, ...), a GROMACS energy file (.edr: every term of gmx
    /// energy, with its unit) or a LAMMPS log (log.lammps, told by its first line 'LAMMPS (':
    /// the thermo output of every run, thermo_style multi too).
    pub file: PathBuf,
    /// The column along x, by name or number from 1 (by default Time for an .edr file, Step
    /// for a LAMMPS log; else 'time' when the rows' times increase, else the first column:
    /// frame, lag, residue).
    #[arg(long, value_name = "COL")]
    pub x: Option<String>,
    /// The columns drawn against it, comma-separated names or numbers (by default every other
    /// column of numbers but frame, time, Step and CPU; an .edr file's terms must be named):
    /// --y rmsd, --y helix,strand,coil, --y 2,3, --y Temperature,Pressure, --y Temp,PotEng.
    #[arg(long, value_name = "COL,...", value_delimiter = ',')]
    pub y: Vec<String>,
    /// Also draw each series' running mean over N rows (centred), in its own colour, for a
    /// noisy RMSD or energy.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(2..=100_000))]
    pub running_mean: Option<u32>,
    /// The chart's title (none by default).
    #[arg(long, default_value = "")]
    pub title: String,
    /// The x axis's label (the column's name, with its unit: 'Time (ps)'; or the .xvg file's).
    #[arg(long, value_name = "TEXT")]
    pub x_label: Option<String>,
    /// The y axis's label (the column's name when there is one, with an .edr term's unit:
    /// 'Temperature (K)'; the terms' shared unit; or the .xvg file's).
    #[arg(long, value_name = "TEXT")]
    pub y_label: Option<String>,
    /// The image size, WxH pixels.
    #[arg(long, default_value = "960x640")]
    pub size: String,
    /// The chart, PNG or SVG by the name.
    #[arg(short, long, value_name = "FILE.png|FILE.svg")]
    pub output: PathBuf,
}

/// A table read: column names, each column's numbers (NaN for an empty cell) or why it has
/// none (its first cell that is not a number), the axis labels an .xvg file gives, each
/// column's unit (empty when unknown) and the column x is by default.
struct Table {
    names: Vec<String>,
    columns: Vec<std::result::Result<Vec<f64>, String>>,
    x_label: Option<String>,
    y_label: Option<String>,
    units: Vec<String>,
    default_x: Option<usize>,
    /// An .edr file: its terms must be named with --y, as gmx energy asks for them.
    edr: bool,
}

impl Table {
    fn values(&self, k: usize) -> Result<&[f64]> {
        self.columns[k]
            .as_deref()
            .map_err(|e| anyhow::anyhow!("{e}: only numbers can be drawn"))
    }
}

pub fn plot(a: &PlotArgs) -> Result<()> {
    let size = crate::scene::parse_size(&a.size)?;
    if !a
        .output
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("svg") || e.eq_ignore_ascii_case("png"))
    {
        return usage(format!(
            "-o {}: expected a .png or .svg file",
            a.output.display()
        ));
    }
    let bytes = std::fs::read(&a.file)
        .with_context(|| format!("{}: cannot read the table", a.file.display()))?;
    let has_extension = |ext: &str| {
        a.file
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case(ext))
    };
    let name = a.file.display().to_string();
    let table = if has_extension("edr") || energy::is_edr(&bytes) {
        let t = energy::edr_from_reader(std::io::Cursor::new(&bytes), bytes.len() as u64, &name)?;
        energy_table(t, true)
    } else if energy::is_lammps_log(&bytes) {
        let t = energy::lammps_log_from_bytes(&bytes, &name)?;
        if t.truncated_rows > 0 {
            eprintln!(
                "texmap: warning: {name}: {} row(s) cut short at the end of the file dropped (a run still writing, or killed)",
                t.truncated_rows
            );
        }
        energy_table(t, false)
    } else {
        let text = String::from_utf8(bytes).map_err(|_| {
            anyhow::anyhow!(
                "{}: cannot read the table: not UTF-8 text (nor an .edr file or a LAMMPS log)",
                a.file.display()
            )
        })?;
        if has_extension("xvg") {
            read_xvg(&a.file, &text)?
        } else {
            read_csv(&a.file, &text)?
        }
    };
    let column = |spec: &str| -> Result<usize> {
        if let Some(k) = table.names.iter().position(|n| n == spec) {
            return Ok(k);
        }
        // gmx energy's menu writes a term's spaces as '-' (LJ-(SR), Kinetic-En.).
        if let Some(k) = table
            .names
            .iter()
            .position(|n| n.contains(' ') && n.replace(' ', "-") == spec)
        {
            return Ok(k);
        }
        match spec.parse::<usize>() {
            Ok(k) if (1..=table.names.len()).contains(&k) => Ok(k - 1),
            _ => usage(format!(
                "{}: no column '{spec}': the columns are {} (or their numbers from 1)",
                a.file.display(),
                table.names.join(", ")
            )),
        }
    };
    // By default x is the file's own (an .edr file's Time, a log's Step), else the time when
    // the rows have increasing times, else the first column.
    let timed = table.names.iter().position(|n| n == "time").filter(|&k| {
        table.columns[k]
            .as_ref()
            .is_ok_and(|t| t.windows(2).all(|w| w[1] > w[0]))
    });
    let x = match &a.x {
        Some(spec) => column(spec)?,
        None => table.default_x.or(timed).unwrap_or(0),
    };
    let ys: Vec<usize> = if a.y.is_empty() {
        if table.edr {
            return usage(format!(
                "{}: name the terms to draw with --y (e.g. --y Temperature,Pressure): the terms are {}",
                a.file.display(),
                table.names[1..].join(", ")
            ));
        }
        (0..table.names.len())
            .filter(|&k| {
                k != x
                    && table.columns[k].is_ok()
                    && !matches!(
                        table.names[k].as_str(),
                        "frame" | "time" | "Step" | "Time" | "CPU"
                    )
            })
            .collect()
    } else {
        a.y.iter()
            .map(|s| column(s.trim()))
            .collect::<Result<_>>()?
    };
    if ys.is_empty() {
        // Columns there are, but of text: say where the first stops being numbers.
        if let Some(k) = (0..table.names.len()).find(|&k| k != x && table.columns[k].is_err()) {
            table.values(k)?;
        }
        return usage(format!(
            "{}: one column only: nothing to draw against it",
            a.file.display()
        ));
    }
    let xs = table.values(x)?;
    let mut series: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for &k in &ys {
        let points: Vec<(f64, f64)> = xs
            .iter()
            .zip(table.values(k)?)
            .map(|(x, y)| (*x, *y))
            .collect();
        if points.iter().all(|p| !p.1.is_finite()) {
            bail!(
                "{}: column '{}' has no number to draw",
                a.file.display(),
                table.names[k]
            );
        }
        series.push((table.names[k].clone(), points));
    }
    if let Some(n) = a.running_mean {
        let n = n as usize;
        let means: Vec<(String, Vec<(f64, f64)>)> = series
            .iter()
            .map(|(name, p)| (format!("{name} (mean of {n})"), running_mean(p, n)))
            .collect();
        series.extend(means);
    }
    let x_label = a
        .x_label
        .clone()
        .or(table.x_label.clone())
        .unwrap_or_else(|| match table.units[x].as_str() {
            "" => table.names[x].clone(),
            unit => format!("{} ({unit})", table.names[x]),
        });
    let y_label = a
        .y_label
        .clone()
        .or(table.y_label.clone())
        .unwrap_or_else(|| {
            let unit = &table.units[ys[0]];
            let shared = ys.iter().all(|&k| table.units[k] == *unit);
            match (ys.len(), unit.is_empty() || !shared) {
                (1, true) => table.names[ys[0]].clone(),
                (1, false) => format!("{} ({unit})", table.names[ys[0]]),
                (_, false) => unit.clone(),
                (_, true) => String::new(),
            }
        });
    crate::tables::write_chart(&a.output, size, |t| {
        texmap_study::chart::lines([&a.title, &x_label, &y_label], &series, size, t)
    })?;
    crate::note!(
        "plotted {} series of {} rows to {}",
        series.len(),
        xs.len(),
        a.output.display()
    );
    Ok(())
}

/// An energy file's or log's table as plot's, x by default its `Time` (the .edr's first
/// column) or `Step`.
fn energy_table(t: EnergyTable, edr: bool) -> Table {
    let default_x = if edr { Some(0) } else { t.index("Step") };
    Table {
        columns: t.columns.into_iter().map(Ok).collect(),
        x_label: None,
        y_label: None,
        default_x,
        units: t.units,
        names: t.names,
        edr,
    }
}

/// The centred running mean over `n` rows (fewer at the ends), skipping gaps.
fn running_mean(p: &[(f64, f64)], n: usize) -> Vec<(f64, f64)> {
    let half = n / 2;
    (0..p.len())
        .map(|i| {
            let window = &p[i.saturating_sub(half)..(i + half + 1).min(p.len())];
            let values: Vec<f64> = window
                .iter()
                .map(|q| q.1)
                .filter(|v| v.is_finite())
                .collect();
            let mean = if values.is_empty() {
                f64::NAN
            } else {
                values.iter().sum::<f64>() / values.len() as f64
            };
            (p[i].0, mean)
        })
        .collect()
}

/// The cells of one CSV line, RFC 4180 quotes undone.
fn csv_cells(line: &str) -> Vec<String> {
    let mut cells = Vec::new();
    let mut cell = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                cell.push('"');
                chars.next();
            }
            '"' => quoted = !quoted,
            ',' if !quoted => cells.push(std::mem::take(&mut cell)),
            _ => cell.push(c),
        }
    }
    cells.push(cell);
    cells
}

/// A number, or NaN for an empty cell; the error names the place.
fn cell(path: &Path, line: usize, name: &str, text: &str) -> Result<f64> {
    let t = text.trim();
    if t.is_empty() {
        return Ok(f64::NAN);
    }
    t.parse::<f64>().map_err(|_| {
        anyhow::anyhow!(
            "{}: line {line}: column '{name}' holds '{t}', not a number",
            path.display()
        )
    })
}

fn read_csv(path: &Path, text: &str) -> Result<Table> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let Some((_, header)) = lines.next() else {
        bail!("{}: the table is empty", path.display());
    };
    let names: Vec<String> = csv_cells(header)
        .into_iter()
        .map(|n| n.trim().to_string())
        .collect();
    let mut raw: Vec<(usize, Vec<String>)> = Vec::new();
    for (k, line) in lines {
        let cells = csv_cells(line);
        if cells.len() != names.len() {
            bail!(
                "{}: line {}: {} cells, the header names {}",
                path.display(),
                k + 1,
                cells.len(),
                names.len()
            );
        }
        raw.push((k + 1, cells));
    }
    if raw.is_empty() {
        bail!("{}: the table has a header and no rows", path.display());
    }
    let columns = (0..names.len())
        .map(|c| {
            raw.iter()
                .map(|(line, cells)| cell(path, *line, &names[c], &cells[c]))
                .collect::<Result<Vec<f64>>>()
                .map_err(|e| e.to_string())
        })
        .collect();
    Ok(Table {
        units: vec![String::new(); names.len()],
        names,
        columns,
        x_label: None,
        y_label: None,
        default_x: None,
        edr: false,
    })
}

/// The text between the first pair of double quotes of an `@` line.
fn quoted(line: &str) -> Option<String> {
    let start = line.find('"')? + 1;
    let end = start + line[start..].find('"')?;
    Some(line[start..end].to_string())
}

fn read_xvg(path: &Path, text: &str) -> Result<Table> {
    let (mut x_label, mut y_label) = (None, None);
    let mut legends: Vec<(usize, String)> = Vec::new();
    let mut rows: Vec<Vec<f64>> = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') || t.starts_with('&') {
            continue;
        }
        if let Some(at) = t.strip_prefix('@') {
            let words: Vec<&str> = at.split_whitespace().collect();
            match words.as_slice() {
                ["xaxis", "label", ..] => x_label = quoted(t),
                ["yaxis", "label", ..] => y_label = quoted(t),
                [s, "legend", ..] if s.starts_with('s') => {
                    if let (Ok(i), Some(l)) = (s[1..].parse::<usize>(), quoted(t)) {
                        legends.push((i, l));
                    }
                }
                _ => {}
            }
            continue;
        }
        let row: Vec<f64> = t
            .split_whitespace()
            .map(|v| {
                v.parse::<f64>().map_err(|_| {
                    anyhow::anyhow!("{}: line {}: '{v}' is not a number", path.display(), k + 1)
                })
            })
            .collect::<Result<_>>()?;
        if let Some(first) = rows.first()
            && first.len() != row.len()
        {
            bail!(
                "{}: line {}: {} numbers, the first row {}",
                path.display(),
                k + 1,
                row.len(),
                first.len()
            );
        }
        rows.push(row);
    }
    let Some(width) = rows.first().map(Vec::len) else {
        bail!("{}: no rows of numbers", path.display());
    };
    let mut names: Vec<String> = (0..width)
        .map(|c| if c == 0 { "x".into() } else { format!("y{c}") })
        .collect();
    if let Some(l) = &x_label {
        names[0] = l.clone();
    }
    for (i, l) in legends {
        if i + 1 < width {
            names[i + 1] = l;
        }
    }
    let columns = (0..width)
        .map(|c| Ok(rows.iter().map(|r| r[c]).collect()))
        .collect();
    Ok(Table {
        units: vec![String::new(); names.len()],
        names,
        columns,
        x_label,
        y_label,
        default_x: None,
        edr: false,
    })
}

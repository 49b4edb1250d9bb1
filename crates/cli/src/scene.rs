//! The `render` flags turned into the `texmap-md-scene` library's calls: an md-io frame (atoms
//! in Å) becomes an impostor `SphereScene` styled as the flags ask, and a camera is chosen.
//! Files and flag texts (topology, selections, colours, vectors, keyframes) are read and parsed
//! here; the library's [`MolPlan`] and [`CameraPlan`] do the work, and their errors are
//! reworded to name the flags.

use anyhow::{Context, Result};
use glam::Vec3;
use texmap_core::camera::Camera;
use texmap_impostor::SphereScene;
use texmap_md_io::{Frame, Selection, Topology};
use texmap_md_scene::{
    BondSource, CameraPlan, CameraPlanError, MolError, MolOptions, MolPlan, MotionSpec, Pbc,
    RuleKind, SelectionRole, StyleError, StyleOptions, StyleWarning, ViewAxis,
};

use texmap_md_scene::Colormap;

use crate::args::{
    BondsArg, ColorBy, ColormapArg, DrawStyle, MolArgs, PathArgs, PbcArg, StyleArgs, ViewArgs,
    parse_color, usage,
};

pub use texmap_md_scene::{MAX_MATERIALS, SceneBuilder};

/// The library's style options for the `--color-by`, `--radius-scale`, `--type-radius` and
/// `--type-color` flags.
pub fn style_options(args: &StyleArgs) -> StyleOptions {
    StyleOptions {
        color_by: match args.color_by {
            ColorBy::Property => texmap_md_scene::ColorBy::Property,
            ColorBy::Element => texmap_md_scene::ColorBy::Element,
            ColorBy::Type => texmap_md_scene::ColorBy::Type,
            ColorBy::Chain => texmap_md_scene::ColorBy::Chain,
            ColorBy::Structure => texmap_md_scene::ColorBy::Structure,
            ColorBy::Cna => texmap_md_scene::ColorBy::Cna,
            ColorBy::Diamond => texmap_md_scene::ColorBy::Diamond,
            ColorBy::Cluster => texmap_md_scene::ColorBy::Cluster,
            ColorBy::Grain => texmap_md_scene::ColorBy::Grain,
            ColorBy::Ipf(axis) => texmap_md_scene::ColorBy::Ipf(axis),
            ColorBy::Scalar(_) => texmap_md_scene::ColorBy::Scalar,
        },
        scalar: texmap_md_scene::ScalarColor {
            source: match &args.color_by {
                ColorBy::Scalar(s) => s.clone(),
                _ => texmap_md_scene::ScalarSource::Index,
            },
            map: colormap(args.colormap),
            range: args.color_range,
        },
        radius_scale: args.radius_scale,
        type_radius: args
            .type_radius
            .iter()
            .map(|t| (t.name.clone(), t.radius))
            .collect(),
        type_color: args
            .type_color
            .iter()
            .map(|t| (t.name.clone(), t.rgb))
            .collect(),
    }
}

/// The library's colour map for a `--colormap` choice.
pub fn colormap(c: ColormapArg) -> Colormap {
    match c {
        ColormapArg::Viridis => Colormap::Viridis,
        ColormapArg::Plasma => Colormap::Plasma,
        ColormapArg::Coolwarm => Colormap::Coolwarm,
        ColormapArg::Turbo => Colormap::Turbo,
        ColormapArg::Gray => Colormap::Gray,
    }
}

/// The scene builder for the style flags; a refused style is a usage error naming the flag.
pub fn scene_builder(args: &StyleArgs) -> Result<SceneBuilder> {
    SceneBuilder::new(&style_options(args)).or_else(|e| match e {
        StyleError::BadRadiusScale { scale } => usage(format!(
            "--radius-scale {scale}: must be a finite number > 0"
        )),
        StyleError::NameTooLong { .. } => usage(e.to_string()),
        StyleError::Rule(e) => usage(format!("--type-radius/--type-color: {e}")),
    })
}

/// The colour bar of a numeric `--color-by`, unless `--no-color-bar`: drawn onto `image`.
pub fn draw_color_bar(
    builder: &SceneBuilder,
    args: &StyleArgs,
    image: &mut texmap_core::frame::Frame,
) {
    if args.no_color_bar || builder.color_by() != texmap_md_scene::ColorBy::Scalar {
        return;
    }
    let scalar = builder.scalar();
    let Some((min, max)) = scalar.range else {
        return;
    };
    let title = scalar.source.title();
    let (w, h) = (image.width() as usize, image.height() as usize);
    texmap_md_scene::draw_color_bar(
        image.color.as_flattened_mut(),
        w,
        h,
        &texmap_md_scene::ColorBar {
            map: scalar.map,
            min,
            max,
            title: &title,
        },
    );
}

/// One piece of a `--label` template.
#[derive(Clone, Debug, PartialEq)]
pub enum LabelPart {
    Text(String),
    /// `{time}`: the frame's time in ps.
    Time,
    /// `{ns}`: the frame's time in ns.
    Ns,
    /// `{step}`: the frame's MD step.
    Step,
    /// `{frame}`: the frame's index in the file.
    Frame,
    /// `{hbonds}`: the hydrogen bonds the hbonds style draws in the frame.
    HBonds,
    /// `{vacancies}`, `{interstitials}`: the `--wigner-seitz` counts of the frame.
    Vacancies,
    Interstitials,
    /// `{grains}`: the `--grains` count of the frame.
    Grains,
    /// `{title}`: the frame's title (an XYZ comment line, a GRO title, a PDB TITLE, a docked
    /// pose's `REMARK VINA RESULT`), empty when it has none.
    Title,
    /// `{KEY}` or `{KEY:.N}`: the value of `KEY=...` in the frame's comment, as extended XYZ
    /// writes a frame's scalars (ASE's `energy=`, and what our ASE trajectory and pw.x readers
    /// put there), a number with N decimals when `.N` is given.
    Key {
        name: String,
        decimals: Option<usize>,
    },
}

/// A `{KEY}` or `{KEY:.N}` placeholder's key and decimals, when `text` is one: a key starts
/// with a letter or `_` and holds letters, digits, `_`, `-` and `.`; N is at most 12.
fn comment_key(text: &str) -> Option<(&str, Option<usize>)> {
    let (name, decimals) = match text.split_once(":.") {
        Some((name, n)) => (name, Some(n.parse::<usize>().ok().filter(|n| *n <= 12)?)),
        None => (text, None),
    };
    Frame::is_comment_key(name.as_bytes()).then_some((name, decimals))
}

/// A `{placeholder}` template split into text and placeholders, each placeholder one of
/// `names` (given as its index there); `flag` and `hint` name the option and its placeholders
/// in the usage errors for unbalanced braces or an unknown placeholder.
fn template<'a>(
    flag: &str,
    text: &'a str,
    names: &[&str],
    hint: &str,
) -> Result<Vec<Result<&'a str, usize>>> {
    let mut parts = Vec::new();
    let mut rest = text;
    while let Some(open) = rest.find(['{', '}']) {
        if rest[open..].starts_with('}') {
            return usage(format!("{flag} {text:?}: '}}' without a '{{'"));
        }
        let Some(close) = rest[open..].find('}') else {
            return usage(format!("{flag} {text:?}: '{{' without a '}}'"));
        };
        if open > 0 {
            parts.push(Ok(&rest[..open]));
        }
        let name = &rest[open + 1..open + close];
        match names.iter().position(|n| *n == name) {
            Some(k) => parts.push(Err(k)),
            None => {
                return usage(format!(
                    "{flag} {text:?}: {{{name}}} is not a placeholder; use {hint}"
                ));
            }
        }
        rest = &rest[open + close + 1..];
    }
    if !rest.is_empty() {
        parts.push(Ok(rest));
    }
    Ok(parts)
}

/// `--label`'s template, parsed before any frame is read: braces balanced, every placeholder
/// one of the names below or a comment key (`{energy}`, `{energy:.3}`), which each frame must
/// then have.
pub fn parse_label(text: &str) -> Result<Vec<LabelPart>> {
    const NAMES: [&str; 9] = [
        "time",
        "ns",
        "step",
        "frame",
        "hbonds",
        "title",
        "vacancies",
        "interstitials",
        "grains",
    ];
    let hint = "{time} (ps), {ns}, {step}, {frame}, {hbonds}, {vacancies}, {interstitials}, {grains}, {title}, \
                or {KEY} / {KEY:.N} for a KEY=value of the frame's comment (extended XYZ: {energy:.3})";
    // The comment keys the template names, as further names after the fixed ones.
    let mut names: Vec<&str> = NAMES.to_vec();
    let mut rest = text;
    while let Some(open) = rest.find('{') {
        let Some(close) = rest[open..].find('}') else {
            break;
        };
        let name = &rest[open + 1..open + close];
        if !names.contains(&name) && comment_key(name).is_some() {
            names.push(name);
        }
        rest = &rest[open + close + 1..];
    }
    Ok(template("--label", text, &names, hint)?
        .into_iter()
        .map(|p| match p {
            Ok(t) => LabelPart::Text(t.to_string()),
            Err(0) => LabelPart::Time,
            Err(1) => LabelPart::Ns,
            Err(2) => LabelPart::Step,
            Err(3) => LabelPart::Frame,
            Err(4) => LabelPart::HBonds,
            Err(5) => LabelPart::Title,
            Err(6) => LabelPart::Vacancies,
            Err(7) => LabelPart::Interstitials,
            Err(8) => LabelPart::Grains,
            Err(k) => {
                let (name, decimals) = comment_key(names[k]).unwrap_or((names[k], None));
                LabelPart::Key {
                    name: name.to_string(),
                    decimals,
                }
            }
        })
        .collect())
}

/// The per-atom fields an `--atom-label` template may name, in the order of [`AtomLabel`]'s
/// placeholders.
const ATOM_FIELDS: [&str; 10] = [
    "name", "resname", "resid", "chain", "segid", "element", "type", "index", "serial", "id",
];

/// One `--atom-label SEL=TEXT`: the atoms it labels and the template of each one's text.
#[derive(Clone, Debug)]
pub struct AtomLabel {
    spec: String,
    select: Selection,
    /// Text, or a placeholder as its index in [`ATOM_FIELDS`].
    parts: Vec<Result<String, usize>>,
}

/// Parses `--atom-label 'SEL=TEXT'` before any frame is read.
pub fn parse_atom_label(spec: &str) -> Result<AtomLabel> {
    let (sel, text) = sel_value("--atom-label", spec)?;
    let hint = "{name} {resname} {resid} {chain} {segid} {element} {type} {index} (from 0) \
                {serial} (from 1) or {id} (as the file numbers atoms)";
    let parts = template("--atom-label", text, &ATOM_FIELDS, hint)?
        .into_iter()
        .map(|p| p.map(str::to_string))
        .collect();
    Ok(AtomLabel {
        spec: spec.to_string(),
        select: parse_selection("--atom-label", sel)?,
        parts,
    })
}

/// Atom `i`'s label text; an error names the field the frame lacks.
fn atom_label_text(label: &AtomLabel, frame: &Frame, i: usize, at: &str) -> Result<String> {
    let mut out = String::new();
    for part in &label.parts {
        let field = match part {
            Ok(text) => {
                out.push_str(text);
                continue;
            }
            Err(k) => *k,
        };
        let text = |v: &[texmap_md_io::Label]| v.get(i).map(|l| l.as_str().to_string());
        let value = match field {
            0 => text(&frame.names),
            1 => text(&frame.res_names),
            2 => frame.res_ids.get(i).map(i64::to_string),
            3 => text(&frame.chains),
            4 => text(&frame.segments),
            5 => frame.elements.get(i).map(|e| e.symbol().to_string()),
            6 => text(&frame.types),
            7 => Some(i.to_string()),
            8 => Some((i + 1).to_string()),
            _ => frame.ids.get(i).map(i64::to_string),
        };
        let Some(value) = value else {
            anyhow::bail!(
                "--atom-label {:?}: {at} has no {} column for {{{}}} (give --topology FILE for names, residues and chains)",
                label.spec,
                ATOM_FIELDS[field],
                ATOM_FIELDS[field]
            );
        };
        out.push_str(&value);
    }
    Ok(out)
}

/// Draws every `--atom-label` onto `image` (the frame drawn with `camera`): each selected atom's
/// text just above its projected centre, the farthest first so nearer labels stay on top.
/// `at` names the frame for errors. Returns the `--atom-label` options that select no atom.
pub fn draw_atom_labels<'a>(
    labels: &'a [AtomLabel],
    frame: &Frame,
    camera: &Camera,
    image: &mut texmap_core::frame::Frame,
    at: &str,
) -> Result<Vec<&'a str>> {
    let mut placed: Vec<(f32, [f32; 2], String)> = Vec::new();
    let mut empty = Vec::new();
    for label in labels {
        let mask = label
            .select
            .evaluate(frame)
            .map_err(|e| crate::args::UsageError(format!("--atom-label {:?}: {e}", label.spec)))?;
        if !mask.contains(&true) {
            empty.push(label.spec.as_str());
        }
        for (i, _) in mask.iter().enumerate().filter(|(_, m)| **m) {
            let p = Vec3::from_array(frame.positions[i]);
            if let Some((xy, depth)) = camera.project(p) {
                placed.push((depth, xy.to_array(), atom_label_text(label, frame, i, at)?));
            }
        }
    }
    // Far to near; ties in the order given (a stable sort), so the result is deterministic.
    placed.sort_by(|a, b| b.0.total_cmp(&a.0));
    let (w, h) = (image.width() as usize, image.height() as usize);
    for (_, xy, text) in &placed {
        texmap_md_scene::draw_atom_label(image.color.as_flattened_mut(), w, h, *xy, text);
    }
    Ok(empty)
}

/// A number with up to `decimals` decimals, trailing zeros dropped: 2.5, 1250, 0.125.
pub(crate) fn compact(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// The `--label` text of frame `index` of `file`. Errors when it asks for a time or step the
/// frame does not carry.
/// The caption of frame `index` of `file`; `hbonds` is the count of hydrogen bonds drawn (the
/// caller refuses `{hbonds}` without an hbonds representation), `defects` the vacancies and
/// interstitials (the caller refuses them without `--wigner-seitz`), `grains` the grain count
/// (refused without `--grains`).
pub fn label_text(
    parts: &[LabelPart],
    index: usize,
    frame: &Frame,
    file: &str,
    hbonds: usize,
    defects: Option<(usize, usize)>,
    grains: Option<usize>,
) -> Result<String> {
    let missing = |what: &str, placeholder: &str| {
        anyhow::anyhow!(
            "--label {{{placeholder}}}: frame {index} of {file} has no {what} (XTC, TRR, DCD, AMBER NetCDF, GRO with t= or step=, extended XYZ with Time= and LAMMPS dumps carry them; PDB and plain XYZ do not: use {{frame}})"
        )
    };
    let mut out = String::new();
    for p in parts {
        match p {
            LabelPart::Text(t) => out.push_str(t),
            LabelPart::Time => out.push_str(&compact(
                frame.time.ok_or_else(|| missing("time", "time"))?,
                3,
            )),
            LabelPart::Ns => out.push_str(&compact(
                frame.time.ok_or_else(|| missing("time", "ns"))? / 1000.0,
                3,
            )),
            LabelPart::Step => {
                let step = frame.step.ok_or_else(|| missing("step number", "step"))?;
                out.push_str(&step.to_string())
            }
            LabelPart::Frame => out.push_str(&index.to_string()),
            LabelPart::HBonds => out.push_str(&hbonds.to_string()),
            LabelPart::Vacancies => out.push_str(&defects.map_or(0, |d| d.0).to_string()),
            LabelPart::Interstitials => out.push_str(&defects.map_or(0, |d| d.1).to_string()),
            LabelPart::Grains => out.push_str(&grains.unwrap_or(0).to_string()),
            LabelPart::Title => out.push_str(frame.comment.lines().next().unwrap_or("").trim()),
            LabelPart::Key { name, decimals } => {
                let Some(value) = frame.comment_value(name) else {
                    let keys: Vec<&str> = frame.comment_pairs().map(|(k, _)| k).collect();
                    let has = if keys.is_empty() {
                        "no KEY=value pairs".to_string()
                    } else {
                        format!("the keys {}", keys.join(", "))
                    };
                    // Most often a mistyped placeholder: a usage error (exit 2).
                    return crate::args::usage(format!(
                        "--label {{{name}}}: frame {index} of {file} has no {name}= in its comment (it has {has}); the fixed placeholders are {{time}}, {{ns}}, {{step}}, {{frame}}, {{hbonds}}, {{vacancies}}, {{interstitials}}, {{grains}} and {{title}}"
                    ));
                };
                match decimals {
                    None => out.push_str(value),
                    Some(n) => {
                        let v: f64 = value.trim().parse().map_err(|_| {
                            anyhow::anyhow!(
                                "--label {{{name}:.{n}}}: frame {index} of {file} has {name}={value:?}, not a number"
                            )
                        })?;
                        out.push_str(&format!("{v:.n$}"));
                    }
                }
            }
        }
    }
    Ok(out)
}

/// One line of warning about the style flags.
pub fn warning_text(w: &StyleWarning) -> String {
    match w {
        StyleWarning::NoMatch { kind, name } => {
            let flag = match kind {
                RuleKind::Radius => "--type-radius",
                RuleKind::Color => "--type-color",
            };
            format!("{flag} {name}: no atom of the first frame has this type, name or element")
        }
        StyleWarning::ColorsOutOfRange { count } => format!(
            "{count} colour-column values of the first frame are outside [0, 1] and were clamped (colours are fractions of 1, not 0-255)"
        ),
        StyleWarning::NoChains => "--color-by chain: the first frame has no chain or segment identifiers (PDB, mmCIF and PSF files carry them); element colours are used".to_string(),
        StyleWarning::NoStructure => "--color-by structure: no residue of the first frame has a protein backbone (atoms N, CA, C and O with residue names and numbers: PDB, mmCIF, GRO, PSF, prmtop); element colours are used".to_string(),
        StyleWarning::NoScalar { what, available } => {
            let has = if available.is_empty() {
                "it has no per-atom property".to_string()
            } else {
                format!("its properties: {}", available.join(", "))
            };
            format!(
                "--color-by {what}: the first frame has no such number ({has}; speed needs velocities, coordination --coordination R); --color-by takes property, element, type, chain, structure, bfactor, occupancy, charge (from a topology), speed, residue, index, coordination or a property name"
            )
        }
    }
}

/// Reads a `--topology` file (its format told by the name).
pub fn open_topology(path: &std::path::Path) -> Result<Topology> {
    if path.is_dir() {
        anyhow::bail!("{}: is a directory, not a topology file", path.display());
    }
    if !path.exists() {
        anyhow::bail!("{}: no such file", path.display());
    }
    let defines = TOP_DEFINES.get().cloned().unwrap_or_default();
    if !defines.is_empty() {
        let name = path.to_string_lossy().to_ascii_lowercase();
        let name = name.strip_suffix(".gz").unwrap_or(&name);
        if !(name.ends_with(".top") || name.ends_with(".itp")) {
            return crate::args::usage(format!(
                "--define {}: defines preprocess a GROMACS topology (.top, .itp); {} is not one",
                defines[0],
                path.display()
            ));
        }
    }
    let options = texmap_md_io::GromacsTopOptions {
        defines,
        ..Default::default()
    };
    Ok(Topology::open_with(path, &options)?)
}

/// `--define`'s names, for every GROMACS topology the command opens (one command per process).
static TOP_DEFINES: std::sync::OnceLock<Vec<String>> = std::sync::OnceLock::new();

/// Keeps `--define`'s names for [`open_topology`].
pub(crate) fn set_defines(defines: &[String]) {
    if !defines.is_empty() {
        let _ = TOP_DEFINES.set(defines.to_vec());
    }
}

/// The groups of `--index FILE.ndx`, for every selection's `group` keyword: read once, before
/// any selection is parsed (one command per process).
static INDEX_GROUPS: std::sync::OnceLock<texmap_md_io::ndx::IndexGroups> =
    std::sync::OnceLock::new();

/// Reads `--index`'s file, when given, for [`parse_selection`].
pub(crate) fn load_index(path: Option<&std::path::Path>) -> Result<()> {
    if let Some(path) = path {
        let groups = texmap_md_io::ndx::IndexGroups::read(path)?;
        if groups.is_empty() {
            anyhow::bail!("{}: no '[ name ]' group in this index file", path.display());
        }
        let _ = INDEX_GROUPS.set(groups);
    }
    Ok(())
}

/// The `--index` groups, if any.
pub(crate) fn index_groups() -> Option<&'static texmap_md_io::ndx::IndexGroups> {
    INDEX_GROUPS.get()
}

/// A parsed selection (with the `--index` groups), or a usage error pointing at the bad
/// token's column.
pub(crate) fn parse_selection(flag: &str, text: &str) -> Result<Selection> {
    Selection::parse_with(text, index_groups())
        .map_err(|e| crate::args::UsageError(format!("{flag}: {e}")).into())
}

/// Splits `SEL=VALUE` at its last '='.
fn sel_value<'a>(flag: &str, s: &'a str) -> Result<(&'a str, &'a str)> {
    match s.rsplit_once('=') {
        Some((sel, v)) if !sel.trim().is_empty() && !v.trim().is_empty() => {
            Ok((sel.trim(), v.trim()))
        }
        _ => {
            let example = match flag {
                "--rep" => "protein=tube",
                "--radius" => "name CA=2",
                _ => "resname SOL=#4080ff",
            };
            usage(format!(
                "{flag} {s:?}: expected SELECTION=VALUE, e.g. {flag} '{example}'"
            ))
        }
    }
}

/// The library's bond source for `--bonds`.
impl From<BondsArg> for BondSource {
    fn from(b: BondsArg) -> BondSource {
        match b {
            BondsArg::Auto => BondSource::Auto,
            BondsArg::Topology => BondSource::Topology,
            BondsArg::None => BondSource::None,
        }
    }
}

/// The library's draw style for `--style`.
impl From<DrawStyle> for texmap_md_scene::DrawStyle {
    fn from(d: DrawStyle) -> texmap_md_scene::DrawStyle {
        match d {
            DrawStyle::Spacefill => texmap_md_scene::DrawStyle::Spacefill,
            DrawStyle::BallStick => texmap_md_scene::DrawStyle::BallStick,
            DrawStyle::Licorice => texmap_md_scene::DrawStyle::Licorice,
            DrawStyle::Tube => texmap_md_scene::DrawStyle::Tube,
            DrawStyle::Cartoon => texmap_md_scene::DrawStyle::Cartoon,
            DrawStyle::Surface => texmap_md_scene::DrawStyle::Surface,
            DrawStyle::HBonds => texmap_md_scene::DrawStyle::HBonds,
            DrawStyle::Polyhedra => texmap_md_scene::DrawStyle::Polyhedra,
            DrawStyle::Arrows => texmap_md_scene::DrawStyle::Arrows,
            DrawStyle::Trails => texmap_md_scene::DrawStyle::Trails,
            DrawStyle::Ellipsoids => texmap_md_scene::DrawStyle::Ellipsoids,
        }
    }
}

/// The library's periodic treatment for `--pbc`.
impl From<PbcArg> for Pbc {
    fn from(p: PbcArg) -> Pbc {
        match p {
            PbcArg::None => Pbc::None,
            PbcArg::Wrap => Pbc::Wrap,
            PbcArg::Unwrap => Pbc::Unwrap,
        }
    }
}

/// The surface style's options from `--surface-spacing` and `--surface-scale` (usage errors
/// out of range).
pub fn surface_options(args: &MolArgs) -> Result<texmap_md_scene::surface::SurfaceOptions> {
    let o = texmap_md_scene::surface::SurfaceOptions {
        spacing: args.surface_spacing,
        radius_scale: args.surface_scale,
        ..Default::default()
    };
    if !(o.spacing.is_finite() && o.spacing >= 0.05 && o.spacing <= 10.0) {
        return usage(format!(
            "--surface-spacing {}: expected a grid spacing from 0.05 to 10 Å",
            o.spacing
        ));
    }
    if !(o.radius_scale.is_finite() && o.radius_scale >= 0.1 && o.radius_scale <= 10.0) {
        return usage(format!(
            "--surface-scale {}: expected a radius scale from 0.1 to 10",
            o.radius_scale
        ));
    }
    Ok(o)
}

/// What `render` does to a frame between reading and drawing ([`MolPlan`]) for the
/// [`MolArgs`] and the `--topology` file's `topology` (read by the caller, whose trajectory
/// may need its atom count): the selections and colours parsed.
pub fn mol_plan(args: &MolArgs, style: &StyleArgs, topology: Option<Topology>) -> Result<MolPlan> {
    if args.trail_length == Some(0) {
        return Err(crate::args::UsageError(
            "--trail-length 0: expected at least 1 frame (the current one)".into(),
        )
        .into());
    }
    if matches!(style.color_by, ColorBy::Cluster) && args.analysis.clusters.is_none() {
        return Err(crate::args::UsageError(
            "--color-by cluster: give --clusters R (the neighbour cutoff in Å) to find them".into(),
        )
        .into());
    }
    let scalar_is = |name: &str| matches!(&style.color_by, ColorBy::Scalar(texmap_md_scene::ScalarSource::Property(p)) if p == name);
    if args.analysis.strain.is_none()
        && let Some(p) = ["shear_strain", "volumetric_strain", "d2min"]
            .into_iter()
            .find(|p| scalar_is(p))
    {
        return usage(format!(
            "--color-by {p}: give --strain R (the neighbour cutoff in Å, 3.0 for copper) to compute it"
        ));
    }
    let grains = args.analysis.grains.is_some() || matches!(style.color_by, ColorBy::Grain);
    if !grains
        && (args.analysis.grain_keep_orphans
            || args.analysis.grain_separate_faults
            || args.analysis.grain_table.is_some()
            || args.analysis.grain_min_size != 100)
    {
        return usage(
            "--grain-min-size, --grain-keep-orphans, --grain-separate-faults and --grain-table are about the grains: add --grains",
        );
    }
    if args.analysis.centrosymmetry_matching
        && args.analysis.centrosymmetry.is_none()
        && !scalar_is("centrosymmetry")
    {
        return usage(
            "--centrosymmetry-matching: give --centrosymmetry N (or --color-by centrosymmetry)",
        );
    }
    let bins = args.analysis.rdf_bins;
    if !(1..=texmap_md_io::rdf::MAX_BINS).contains(&bins) {
        return usage(format!(
            "--rdf-bins {bins}: expected 1 to {}",
            texmap_md_io::rdf::MAX_BINS
        ));
    }
    if let Some(n) = args.analysis.centrosymmetry {
        let mode = if args.analysis.centrosymmetry_matching {
            texmap_md_io::centrosymmetry::CspMode::Matching
        } else {
            texmap_md_io::centrosymmetry::CspMode::Conventional
        };
        if let Err(e) = texmap_md_io::centrosymmetry::check(n, mode) {
            return usage(format!("--centrosymmetry {n}: {e}"));
        }
    }
    let optional = |flag, text: &Option<String>| {
        text.as_deref()
            .map(|t| parse_selection(flag, t))
            .transpose()
    };
    let select = optional("--select", &args.select)?;
    let mut colors = Vec::new();
    for c in &args.color_rules {
        let (sel, v) = sel_value("--color", c)?;
        let rgb = parse_color(v).map_err(|e| crate::args::UsageError(format!("--color: {e}")))?;
        colors.push((
            parse_selection("--color", sel)?,
            rgb.map(|x| x as f32 / 255.0),
        ));
    }
    let mut radii = Vec::new();
    for r in &args.radius_rules {
        let (sel, v) = sel_value("--radius", r)?;
        let radius = match v.parse::<f32>() {
            Ok(x) if x.is_finite() && x > 0.0 => x,
            _ => return usage(format!("--radius {r:?}: {v:?} is not a radius > 0 in Å")),
        };
        radii.push((parse_selection("--radius", sel)?, radius));
    }
    let align = match optional("--align", &args.analysis.align)? {
        Some(select) => Some(texmap_md_scene::Alignment {
            select,
            reference: args
                .analysis
                .align_to
                .as_deref()
                .map(read_reference)
                .transpose()?,
            mass_weighted: args.analysis.align_mass,
        }),
        None => None,
    };
    let mut reps = Vec::new();
    for r in &args.reps {
        let (sel, spec) = sel_value("--rep", r)?;
        let (style, color) = match spec.split_once(':') {
            Some((style, color)) => (style.trim(), Some(rep_color(r, color.trim())?)),
            None => (spec, None),
        };
        let draw = <DrawStyle as clap::ValueEnum>::from_str(style, true).map_err(|_| {
            crate::args::UsageError(format!(
                "--rep {r:?}: {style:?} is not a style; use spacefill, ball-stick, licorice, tube, cartoon, surface, hbonds, polyhedra, arrows, trails or ellipsoids (VMD's and PyMOL's names work too: vdw, spheres, cpk, sticks, trace, newcartoon, quicksurf)"
            ))
        })?;
        reps.push(texmap_md_scene::Representation {
            select: Some(parse_selection("--rep", sel)?),
            draw: draw.into(),
            color,
        });
    }
    MolPlan::new(MolOptions {
        topology,
        select,
        align,
        reps,
        colors,
        radii,
        bonds: args.bonds.into(),
        draw: args.draw.into(),
        pbc: args.analysis.pbc.into(),
        replicate: args.analysis.replicate,
        coordination: args.analysis.coordination,
        clusters: match args.analysis.clusters {
            Some(cutoff) => Some(texmap_md_scene::ClusterOptions {
                cutoff,
                atoms: args
                    .analysis
                    .cluster_atoms
                    .as_deref()
                    .map(|t| parse_selection("--cluster-atoms", t))
                    .transpose()?,
            }),
            None => None,
        },
        sasa: match (&args.analysis.sasa, scalar_is("sasa")) {
            (Some(sel), _) => Some(texmap_md_scene::SasaOptions {
                atoms: match sel.trim() {
                    "all" => None,
                    t => Some(parse_selection("--sasa", t)?),
                },
                probe: args.analysis.sasa_probe,
            }),
            (None, true) => Some(texmap_md_scene::SasaOptions {
                atoms: None,
                probe: texmap_md_io::sasa::PROBE,
            }),
            (None, false) => None,
        },
        centrosymmetry: match args.analysis.centrosymmetry {
            Some(n) => Some(n),
            None if scalar_is("centrosymmetry") => Some(12),
            None => None,
        }
        .map(|neighbours| texmap_md_scene::CentroOptions {
            neighbours,
            mode: if args.analysis.centrosymmetry_matching {
                texmap_md_io::centrosymmetry::CspMode::Matching
            } else {
                texmap_md_io::centrosymmetry::CspMode::Conventional
            },
        }),
        strain: args.analysis.strain,
        freeze: args.analysis.freeze.clone(),
        voronoi: args.analysis.voronoi,
        orientations: args.analysis.orientations
            || [
                "lattice_rmsd",
                "orientation_x",
                "orientation_y",
                "orientation_z",
                "orientation_w",
            ]
            .into_iter()
            .any(scalar_is),
        grains: grains.then(|| grain_options(args)),
        msd: args.analysis.msd
            || args.analysis.msd_table.is_some()
            || args.analysis.msd_lags.is_some()
            || scalar_is("msd"),
        rdf: args.analysis.rdf.map(|cutoff| texmap_md_scene::RdfOptions {
            cutoff,
            bins: args.analysis.rdf_bins,
            partial: args.analysis.rdf_partial,
        }),
        wigner_seitz: args.analysis.wigner_seitz.map(|w| match w {
            crate::args::WignerSeitzArg::Sites => texmap_md_scene::WsOutput::Sites,
            crate::args::WignerSeitzArg::Atoms => texmap_md_scene::WsOutput::Atoms,
        }),
        computes: args
            .analysis
            .computes
            .iter()
            .map(|c| {
                let (name, formula) = c.split_once('=').ok_or_else(|| {
                    crate::args::UsageError(format!(
                        "--compute {c:?}: expected NAME=FORMULA, e.g. 'speed=sqrt(vx^2+vy^2+vz^2)'"
                    ))
                })?;
                let name = name.trim();
                if name.is_empty() || !name.chars().all(|ch| ch.is_alphanumeric() || ch == '_') {
                    return Err(crate::args::UsageError(format!(
                        "--compute {c:?}: the name {name:?} must be letters, digits and '_'"
                    )));
                }
                let parsed = texmap_md_io::expr::Expression::parse(formula).map_err(|e| {
                    crate::args::UsageError(format!("--compute {name}={formula}: {e}"))
                })?;
                Ok((name.to_string(), parsed))
            })
            .collect::<Result<Vec<_>, _>>()?,
        radius_from: args.radius_from.clone(),
        slice: args.slice.map(|[x, y, z, d, w]| texmap_md_scene::Slice {
            normal: [x, y, z],
            distance: d,
            width: w,
            invert: args.slice_invert,
        }),
        hbonds: texmap_md_io::hbonds::Criteria {
            distance: args.analysis.hbond_distance,
            angle: args.analysis.hbond_angle,
        },
        hbond_select: None,
        arrows: texmap_md_scene::arrows::ArrowOptions {
            source: match args.arrows.as_str() {
                "velocity" | "velocities" => texmap_md_scene::arrows::ArrowSource::Velocity,
                "displacement" | "displacements" => {
                    texmap_md_scene::arrows::ArrowSource::Displacement
                }
                stem => texmap_md_scene::arrows::ArrowSource::Property(stem.to_string()),
            },
            scale: args.arrow_scale,
            radius: args.arrow_radius,
        },
        ellipsoids: texmap_md_scene::ellipsoids::EllipsoidOptions {
            shape: args.ellipsoid_shape,
        },
        trail_length: args.trail_length,
        bond_orders: args.bond_orders,
        displacement: args.analysis.displacements || scalar_is("displacement"),
        measures: args
            .analysis
            .measures
            .iter()
            .map(|m| {
                texmap_md_scene::measure::Measure::parse_with(m, index_groups())
                    .map_err(|e| crate::args::UsageError(format!("--measure {e}")))
            })
            .collect::<Result<Vec<_>, _>>()?,
    })
    .map_err(mol_error)
}

/// The grain options of `--grains`, `--grain-min-size` and `--grain-keep-orphans`.
fn grain_options(args: &MolArgs) -> texmap_md_io::grains::GrainOptions {
    texmap_md_io::grains::GrainOptions {
        threshold_deg: args
            .analysis
            .grains
            .unwrap_or(texmap_md_io::grains::GrainOptions::default().threshold_deg),
        min_size: args.analysis.grain_min_size,
        adopt_orphans: !args.analysis.grain_keep_orphans,
        join_stacking_faults: !args.analysis.grain_separate_faults,
    }
}

/// The `:COLOUR` of `--rep SEL=STYLE:COLOUR`: a colouring method without a number, or one
/// colour.
fn rep_color(rep: &str, text: &str) -> Result<texmap_md_scene::RepColor> {
    use texmap_md_scene::RepColor;
    if text.starts_with('#') || text.contains(',') {
        let rgb = parse_color(text)
            .map_err(|e| crate::args::UsageError(format!("--rep {rep:?}: {e}")))?;
        return Ok(RepColor::Fixed(rgb.map(|x| x as f32 / 255.0)));
    }
    let by = match crate::args::parse_color_by(text) {
        Ok(ColorBy::Property) => texmap_md_scene::ColorBy::Property,
        Ok(ColorBy::Element) => texmap_md_scene::ColorBy::Element,
        Ok(ColorBy::Type) => texmap_md_scene::ColorBy::Type,
        Ok(ColorBy::Chain) => texmap_md_scene::ColorBy::Chain,
        Ok(ColorBy::Structure) => texmap_md_scene::ColorBy::Structure,
        Ok(ColorBy::Cna) => texmap_md_scene::ColorBy::Cna,
        Ok(ColorBy::Diamond) => texmap_md_scene::ColorBy::Diamond,
        Ok(ColorBy::Cluster) => texmap_md_scene::ColorBy::Cluster,
        Ok(ColorBy::Grain) => texmap_md_scene::ColorBy::Grain,
        Ok(ColorBy::Ipf(axis)) => texmap_md_scene::ColorBy::Ipf(axis),
        _ => {
            return usage(format!(
                "--rep {rep:?}: {text:?} is not a representation's colouring; use element, type, \
                 chain, structure, cna, diamond, cluster, grain, ipf, property, #rrggbb or R,G,B (a colouring by a number is the \
                 scene's: --color-by {text}, and the representations without :COLOUR take it)"
            ));
        }
    };
    Ok(RepColor::By(by))
}

/// The first frame of `--align-to FILE`, any format a trajectory may have.
fn read_reference(path: &std::path::Path) -> Result<Frame> {
    let mut traj = crate::commands::open_trajectory(path, None)
        .with_context(|| format!("--align-to {}", path.display()))?;
    let mut frame = Frame::new();
    if !traj.read_next(&mut frame)? {
        anyhow::bail!("--align-to {}: the file holds no frame", path.display());
    }
    Ok(frame)
}

/// The per-atom properties the analyses add, and the flag that adds each.
pub(crate) const ANALYSIS_PROPERTIES: [(&str, &str); 23] = [
    ("coordination", "--coordination R"),
    ("sasa", "--sasa"),
    ("msd", "--msd"),
    ("cluster", "--clusters R"),
    ("centrosymmetry", "--centrosymmetry N"),
    ("shear_strain", "--strain R"),
    ("volumetric_strain", "--strain R"),
    ("d2min", "--strain R"),
    ("site_occupancy", "--wigner-seitz"),
    ("site", "--wigner-seitz"),
    ("voronoi_volume", "--voronoi"),
    ("voronoi_faces", "--voronoi"),
    ("voronoi_n3", "--voronoi"),
    ("voronoi_n4", "--voronoi"),
    ("voronoi_n5", "--voronoi"),
    ("voronoi_n6", "--voronoi"),
    ("orientation_x", "--orientations"),
    ("orientation_y", "--orientations"),
    ("orientation_z", "--orientations"),
    ("orientation_w", "--orientations"),
    ("lattice_rmsd", "--orientations"),
    ("grain", "--grains"),
    ("displacement", "--displacements"),
];

/// A [`MolError`] as the usage error naming the flag.
pub fn mol_error(e: MolError) -> anyhow::Error {
    let text = match e {
        MolError::NoTopology => "--bonds topology needs bonds listed in a file: --topology FILE (PDB with CONECT records, PSF, prmtop, or a LAMMPS data file with a Bonds section), or an SDF/MOL2 input".to_string(),
        MolError::TopologyWithoutBonds { topology } => format!(
            "--bonds topology: {topology} has no bonds (use --bonds auto for bonds by distance)"
        ),
        MolError::BadRadius { radius, .. } => format!("--radius: {radius} is not a radius > 0 in Å"),
        MolError::Selection { role, mut error } => {
            let flag = match role {
                SelectionRole::Select => "--select",
                SelectionRole::Color => "--color",
                SelectionRole::Radius => "--radius",
                SelectionRole::Align => "--align",
                SelectionRole::Cluster => "--cluster-atoms",
                SelectionRole::Sasa => "--sasa",
                SelectionRole::HBonds => "--hbonds",
            };
            // A property an analysis computes: name the flag that computes it.
            if let Some((_, hint)) = ANALYSIS_PROPERTIES
                .iter()
                .find(|(p, _)| error.message.starts_with(&format!("this frame has no property '{p}'")))
            {
                error.message.push_str(&format!("; {hint} computes it"));
            }
            format!("{flag}: {error}")
        }
        MolError::Align { atoms, why } if atoms >= 3 => {
            // Bad coordinates in a frame: a runtime failure, not a usage error.
            return anyhow::anyhow!("--align: the selection's {atoms} atoms: {why}");
        }
        MolError::Align { atoms, why } => {
            format!("--align: the selection picks {atoms} atom(s) of the first frame: {why}")
        }
        MolError::Coordination(e) => return anyhow::anyhow!("--coordination: {e}"),
        MolError::Clusters(e) => return anyhow::anyhow!("--clusters: {e}"),
        MolError::Sasa(texmap_md_io::sasa::SasaError::BadProbe(p)) => {
            format!("--sasa-probe {p}: expected a radius from 0 to 10 Å")
        }
        MolError::Sasa(e) => return anyhow::anyhow!("--sasa: {e}"),
        MolError::Centrosymmetry(e) => format!("--centrosymmetry: {e}"),
        MolError::Strain(e) => return anyhow::anyhow!("--strain: {e}"),
        MolError::WignerSeitz(e) => return anyhow::anyhow!("--wigner-seitz: {e}"),
        MolError::Voronoi(e) => return anyhow::anyhow!("--voronoi: {e}"),
        MolError::Rdf(e) => return anyhow::anyhow!("--rdf: {e}"),
        MolError::Msd(e) => return anyhow::anyhow!("--msd: {e}"),
        MolError::Compute { name, error } => {
            // The formula parsed; the frame lacks a name it uses: the input's, not usage.
            return anyhow::anyhow!("--compute {name}: {error}");
        }
        MolError::NoRadiusProperty { .. } => return anyhow::anyhow!("--radius-from: {e}"),
        MolError::NoFreezeProperty { .. } | MolError::FreezeAtoms { .. } => {
            return anyhow::anyhow!("--freeze: {e}");
        }
        MolError::BadSlice => format!("--slice: {e}"),
        MolError::Replicate(e) => {
            // A frame without a cell, or too many atoms for the copies: the input's limit.
            return anyhow::anyhow!("--replicate: {e}");
        }
        MolError::AlignMismatch { .. } => {
            // The trajectory and the --align-to structure disagree: bad input, not usage.
            return anyhow::anyhow!("--align-to: {e}");
        }
        MolError::HBonds(texmap_md_io::hbonds::HBondError::CellTooSmall { .. }) => {
            // The frame's cell, not the options: bad input.
            return anyhow::anyhow!("--rep ...=hbonds: {e}");
        }
        MolError::HBonds(texmap_md_io::hbonds::HBondError::BadDistance(d)) => {
            format!("--hbond-distance {d}: expected a donor-acceptor distance above 0.45 and at most 6 Å")
        }
        MolError::Arrows(texmap_md_scene::arrows::ArrowError::BadOption { what, value }) => {
            format!("--arrow-{what} {value}: expected a finite number > 0")
        }
        MolError::TrailAtoms { .. } => return anyhow::anyhow!("--rep ...=trails: {e}"),
        MolError::Ellipsoids(texmap_md_scene::ellipsoids::EllipsoidError::BadOption { .. }) => {
            format!("--ellipsoid-shape: {e}")
        }
        MolError::Ellipsoids(e) => {
            // The frame lacks shapes or holds bad ones: the input's limit.
            return anyhow::anyhow!("--rep ...=ellipsoids: {e}");
        }
        MolError::Measure(e) => return anyhow::anyhow!("--measure {e}"),
        MolError::Arrows(e) => {
            // The frame lacks the vectors asked for: the input's limit.
            return anyhow::anyhow!("--rep ...=arrows: {e}");
        }
        MolError::HBonds(texmap_md_io::hbonds::HBondError::BadAngle(a)) => {
            format!("--hbond-angle {a}: expected an angle from 0 to 180 degrees")
        }
    };
    crate::args::UsageError(text).into()
}

/// The once-per-run warnings for `--rep`s whose selection picks none of `frame`'s atoms (a
/// residue named `NA+` in the file, `NA` on the command line), with the names of the
/// frame's residues when the selection names residues.
pub fn empty_rep_warnings(args: &MolArgs, frame: &Frame, f: usize) -> Vec<String> {
    let mut out = Vec::new();
    for r in &args.reps {
        let Ok((sel, _)) = sel_value("--rep", r) else {
            continue;
        };
        let Ok(selection) = Selection::parse_with(sel, index_groups()) else {
            continue;
        };
        if selection
            .evaluate(frame)
            .is_ok_and(|pick| !pick.contains(&true))
        {
            let mut hint = String::new();
            if sel.contains("resname") && !frame.res_names.is_empty() {
                let mut names: Vec<String> =
                    frame.res_names.iter().map(|l| l.to_string()).collect();
                names.sort();
                names.dedup();
                let shown: Vec<&str> = names.iter().take(30).map(String::as_str).collect();
                hint = format!(
                    " (the residue names are {}{})",
                    shown.join(" "),
                    if names.len() > 30 { " …" } else { "" }
                );
            }
            out.push(format!(
                "--rep {r:?} selects none of frame {f}'s atoms, so it draws nothing{hint}"
            ));
        }
    }
    out
}

/// The once-per-run hint for a protein chain the periodic box cuts (`--pbc none` or `wrap`):
/// consecutive CA atoms of one chain farther apart as written than through the box's faces.
pub fn split_chain_warning(frame: &Frame, f: usize) -> Option<String> {
    let cell = frame.cell.as_ref()?;
    let is_ca = |i: usize| frame.names.get(i).is_some_and(|n| *n == "CA");
    let chain = |i: usize| frame.chains.get(i);
    let mut cuts = 0;
    let mut prev: Option<usize> = None;
    for i in (0..frame.n_atoms()).filter(|&i| is_ca(i)) {
        if let Some(p) = prev
            && chain(p) == chain(i)
            && frame
                .res_ids
                .get(i)
                .zip(frame.res_ids.get(p))
                .is_some_and(|(a, b)| *a == b + 1)
        {
            let d: [f64; 3] = std::array::from_fn(|k| {
                frame.positions[i][k] as f64 - frame.positions[p][k] as f64
            });
            let m = texmap_md_io::pbc::minimum_image(cell, d);
            let len = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if len(d) > len(m) + 1.0 {
                cuts += 1;
            }
        }
        prev = Some(i);
    }
    (cuts > 0).then(|| {
        format!(
            "frame {f}: a protein chain crosses a face of the periodic box {cuts} time(s), so it is drawn in pieces; --pbc unwrap makes bonded molecules whole (VMD's pbc join)"
        )
    })
}

/// The once-per-run warning for atoms that have nothing to be told apart by.
pub fn unnamed_warning(plan: &MolPlan, frame: &Frame, file: &str) -> Option<String> {
    plan.atoms_unnamed(frame).then(|| {
        format!(
            "{file} has no atom names, types or elements (coordinates only): every atom is drawn in the unknown-element colour; give --topology FILE (PDB, PDBx/mmCIF, GRO or LAMMPS data file of the same atoms) for names, elements, residues and bonds"
        )
    })
}

fn parse_vec3(s: &str, what: &str) -> Result<Vec3> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return usage(format!(
            "{what} {s:?}: expected three comma-separated numbers X,Y,Z"
        ));
    }
    let mut v = [0f32; 3];
    for (k, p) in parts.iter().enumerate() {
        v[k] = match p.parse::<f32>() {
            Ok(x) if x.is_finite() => x,
            _ => return usage(format!("{what} {s:?}: {p:?} is not a finite number")),
        };
    }
    Ok(Vec3::from(v))
}

/// Parse `WxH`.
pub fn parse_size(s: &str) -> Result<(u32, u32)> {
    let bad = || {
        usage(format!(
            "size {s:?}: expected WxH with 1 ≤ W, H ≤ 16384, e.g. 1280x720"
        ))
    };
    let Some((w, h)) = s.split_once(['x', 'X']) else {
        return bad();
    };
    match (w.trim().parse::<u32>(), h.trim().parse::<u32>()) {
        (Ok(w), Ok(h))
            if (1..=texmap_core::camera::MAX_IMAGE_SIDE).contains(&w)
                && (1..=texmap_core::camera::MAX_IMAGE_SIDE).contains(&h) =>
        {
            Ok((w, h))
        }
        _ => bad(),
    }
}

/// Parse `--size` for `texmap render`: pixels `WxH`, or print units (`8.5cmx6cm`, `85mmx60mm`,
/// `3.3inx2.4in`) at `dpi`, each side rounded to the nearest pixel.
pub fn parse_print_size(s: &str, dpi: Option<f32>) -> Result<(u32, u32)> {
    let unit = |t: &str| -> Option<(f64, f64)> {
        let t = t.trim();
        for (suffix, inches) in [("cm", 1.0 / 2.54), ("mm", 1.0 / 25.4), ("in", 1.0)] {
            if let Some(v) = t.strip_suffix(suffix) {
                return v.trim().parse::<f64>().ok().map(|v| (v, inches));
            }
        }
        None
    };
    let Some((w, h)) = s.split_once(['x', 'X']) else {
        return parse_size(s);
    };
    let (Some((w, wu)), Some((h, hu))) = (unit(w), unit(h)) else {
        return parse_size(s);
    };
    let Some(dpi) = dpi else {
        return usage(format!(
            "--size {s:?}: a size in cm, mm or in needs --dpi (e.g. --dpi 300) to be made pixels"
        ));
    };
    let px = |v: f64, per_inch: f64| (v * per_inch * dpi as f64).round();
    let (pw, ph) = (px(w, wu), px(h, hu));
    let max = texmap_core::camera::MAX_IMAGE_SIDE as f64;
    if !(pw >= 1.0 && ph >= 1.0 && pw <= max && ph <= max) {
        return usage(format!(
            "--size {s:?} at --dpi {dpi}: {pw}x{ph} pixels; expected 1 to {max} a side"
        ));
    }
    Ok((pw as u32, ph as u32))
}

/// Parse `R,G,B` (0–255) into an opaque sRGB colour.
pub fn parse_background(s: &str) -> Result<[u8; 4]> {
    if s.trim().eq_ignore_ascii_case("transparent") {
        return Ok([0, 0, 0, 0]);
    }
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let parsed: Vec<Option<u8>> = parts.iter().map(|p| p.parse::<u8>().ok()).collect();
    match parsed.as_slice() {
        [Some(r), Some(g), Some(b)] => Ok([*r, *g, *b, 255]),
        _ => usage(format!(
            "--background {s:?}: expected R,G,B with each 0-255, or transparent"
        )),
    }
}

/// The automatic camera's position for `--view`.
fn view_axis(view: &str) -> Result<ViewAxis> {
    match ViewAxis::parse(view) {
        Some(axis) => Ok(axis),
        None => usage(format!(
            "--view {view:?}: expected auto, x, y, z, -x, -y or -z (the axis the camera sits on)"
        )),
    }
}

/// The camera for a render of `size` pixels and the point it looks at: exactly
/// `--eye/--target/--up` when given, else fitted to what the first frame draws
/// ([`texmap_md_scene::fit_camera`]).
pub fn camera_for(
    args: &ViewArgs,
    (w, h): (u32, u32),
    first: &Frame,
    scene: &SphereScene,
) -> Result<(Camera, Vec3)> {
    let hfov = if args.ortho { None } else { Some(args.fov) };
    if let Some(f) = hfov
        && !(f.is_finite() && f > 0.0 && f < 180.0)
    {
        return usage(format!(
            "--fov {f}: must be strictly between 0 and 180 degrees"
        ));
    }
    match (&args.eye, &args.target, &args.up) {
        (Some(e), Some(t), Some(u)) => {
            let (e, t, u) = (
                parse_vec3(e, "--eye")?,
                parse_vec3(t, "--target")?,
                parse_vec3(u, "--up")?,
            );
            let cam = match hfov {
                Some(f) => Camera::perspective_look_at(e, t, u, f, w, h),
                // Orthographic with an explicit camera: frame the scene's extent.
                None => Camera::orthographic_look_at(
                    e,
                    t,
                    u,
                    texmap_md_scene::camera::ortho_extent(scene),
                    w,
                    h,
                ),
            };
            return cam
                .map(|c| (c, t))
                .map_err(|e| crate::args::UsageError(format!("camera: {e}")).into());
        }
        (None, None, None) => {}
        _ => return usage("--eye, --target and --up go together: give all three or none"),
    }
    let axis = view_axis(&args.view)?;
    texmap_md_scene::fit_camera(first, scene, axis, hfov, w, h).context("automatic camera")
}

/// The camera of every frame of a render ([`CameraPlan`]) of `count` frames of `size` pixels
/// whose first frame is `first` (drawn as `scene`): the first camera from the view flags,
/// moved along `--orbit`/`--orbit-turns`/`--keyframes` and with the centre of `--follow`'s atoms.
pub fn camera_plan(
    view: &ViewArgs,
    size: (u32, u32),
    path: &PathArgs,
    first: &Frame,
    scene: &SphereScene,
    count: usize,
) -> Result<CameraPlan> {
    let (template, target) = camera_for(view, size, first, scene)?;
    let motion = match (path.orbit, path.orbit_turns, &path.keyframes) {
        (Some(d), None, None) => MotionSpec::Orbit {
            degrees_per_frame: d,
        },
        (None, Some(t), None) => MotionSpec::OrbitTurns { turns: t },
        (None, None, Some(file)) => MotionSpec::Keyframes(
            std::fs::read_to_string(file)
                .with_context(|| format!("--keyframes {}", file.display()))?,
        ),
        (None, None, None) => MotionSpec::Still,
        _ => return usage("--orbit, --orbit-turns and --keyframes exclude one another"),
    };
    let follow = path
        .follow
        .as_deref()
        .map(|t| parse_selection("--follow", t))
        .transpose()?;
    CameraPlan::new(template, target, motion, follow, first, count)
        .map_err(|e| camera_error(e, path))
}

/// A [`CameraPlanError`] as the error naming the flag (usage errors for the flags' values).
pub fn camera_error(e: CameraPlanError, path: &PathArgs) -> anyhow::Error {
    let usage = |text: String| crate::args::UsageError(text).into();
    match e {
        CameraPlanError::OrbitNotFinite { degrees } => usage(format!(
            "--orbit {degrees}: must be a finite number of degrees"
        )),
        CameraPlanError::OrbitTurnsNotFinite { turns } => {
            usage(format!("--orbit-turns {turns}: must be a finite number"))
        }
        CameraPlanError::Keyframes(e) => {
            let file = path
                .keyframes
                .as_deref()
                .unwrap_or(std::path::Path::new(""));
            anyhow::anyhow!("{}: {e}", file.display())
        }
        CameraPlanError::Follow(e) => usage(format!("--follow: {e}")),
        CameraPlanError::FollowNoneFirst { selection } => usage(format!(
            "--follow {selection:?} selects none of the first frame's atoms"
        )),
        CameraPlanError::FollowNone { selection } => {
            anyhow::anyhow!("--follow {selection:?} selects none of this frame's atoms")
        }
        e @ CameraPlanError::Camera { .. } => anyhow::anyhow!("{e}"),
    }
}

/// The quality pass a render asked for (`--quality`, `--aa`, `--ao`, ...), or `None` when no
/// quality flag was given (the plain impostor image). Fog is filled in per frame
/// ([`texmap_quality::Fog::for_scene`]), as the camera may move.
pub fn quality_options(
    q: &crate::args::QualityArgs,
    background: [u8; 4],
) -> Result<Option<texmap_quality::QualityOptions>> {
    use crate::args::QualityPreset;
    use texmap_quality::{Background, Outline, QualityOptions};
    let any = q.quality.is_some()
        || q.aa.is_some()
        || q.ao.is_some()
        || q.ao_distance.is_some()
        || q.shadows
        || q.soft_shadows.is_some()
        || q.fog
        || q.outline.is_some();
    if !any {
        return Ok(None);
    }
    let mut o = match q.quality.unwrap_or(QualityPreset::Draft) {
        QualityPreset::Draft => QualityOptions::draft(),
        QualityPreset::Good => QualityOptions::good(),
        QualityPreset::Publication => QualityOptions::publication(),
    };
    if let Some(n) = q.aa {
        o.aa = n;
    }
    if let Some(n) = q.ao {
        o.ao_samples = n;
    }
    if q.ao_distance.is_some() {
        o.ao_distance = q.ao_distance;
    }
    o.shadows |= q.shadows;
    if let Some(samples) = q.soft_shadows {
        o.soft_shadows = Some(texmap_quality::SoftShadows {
            samples,
            light_size_deg: q
                .light_size
                .unwrap_or(texmap_quality::DEFAULT_LIGHT_SIZE_DEG),
        });
    }
    if let Some(px) = q.outline {
        o.outline = Some(Outline {
            width_px: px,
            color: [0, 0, 0],
        });
    }
    o.background = if background[3] == 0 {
        Background::Transparent
    } else {
        Background::Color([background[0], background[1], background[2]])
    };
    o.validate()
        .map_err(|e| crate::args::UsageError(format!("quality options: {e}")))?;
    Ok(Some(o))
}

/// What `--isosurface` draws: one mesh whose kinds index `colors` (the +LEVEL and −LEVEL
/// sides, or with `--isosurface-color-by` the colour map's bins and a grey for vertices off the
/// other grid), their opacity, and the colour bar of a mapped surface.
pub struct Isosurfaces {
    pub mesh: texmap_md_scene::surface::MolMesh,
    pub colors: Vec<[u8; 3]>,
    pub opacity: f32,
    pub bar: Option<IsoBar>,
}

/// A mapped isosurface's colour bar: the map, the values at its two ends, the title.
pub type IsoBar = (Colormap, f32, f32, String);

/// Colour-map bands of an `--isosurface-color-by` surface (`isosurface::bands`: the triangles
/// cut where the value crosses from one band to the next).
pub const ISO_BINS: usize = 64;

impl Isosurfaces {
    /// The mesh with its kinds moved past a scene's `base` materials, and the materials to
    /// append to them.
    pub fn for_scene(
        &self,
        base: usize,
    ) -> (
        texmap_md_scene::surface::MolMesh,
        Vec<texmap_core::shade::Material>,
    ) {
        let mut mesh = self.mesh.clone();
        for k in &mut mesh.kinds {
            *k += base as u16;
        }
        (mesh, band_materials(&self.colors))
    }

    /// Draws the colour bar of a mapped surface onto `image` (unless `off`).
    pub fn draw_color_bar(&self, off: bool, image: &mut texmap_core::frame::Frame) {
        if let Some(bar) = &self.bar
            && !off
        {
            draw_volume_bar(bar, image);
        }
    }
}

/// The plastic materials of sRGB colours (a mapped surface's bands).
fn band_materials(colors: &[[u8; 3]]) -> Vec<texmap_core::shade::Material> {
    colors
        .iter()
        .map(|c| {
            let v = texmap_core::color::srgb8_to_linear_rgb([c[0], c[1], c[2], 255]);
            texmap_core::shade::Material::plastic(v)
        })
        .collect()
}

/// Draws a mapped surface's colour bar onto `image`.
pub fn draw_volume_bar(bar: &IsoBar, image: &mut texmap_core::frame::Frame) {
    let (map, min, max, title) = bar;
    let (w, h) = (image.width() as usize, image.height() as usize);
    texmap_md_scene::draw_color_bar(
        image.color.as_flattened_mut(),
        w,
        h,
        &texmap_md_scene::ColorBar {
            map: *map,
            min: *min,
            max: *max,
            title,
        },
    );
}

/// `--surface-color-by`: the molecular surface coloured by a volume's values at its vertices.
pub struct SurfaceColoring {
    volume: texmap_md_io::volume::Volume,
    path: std::path::PathBuf,
    map: Colormap,
    /// The colour map's ends: `--volume-range`, else set at the first frame coloured.
    range: Option<(f32, f32)>,
    off_grid_warned: bool,
}

/// `--surface-color-by`'s volume (its first data set), read once; `None` without the flag.
pub fn surface_coloring(m: &MolArgs) -> Result<Option<SurfaceColoring>> {
    let Some(path) = &m.surface_color_by else {
        return Ok(None);
    };
    let range = m.volume_range.as_deref().map(parse_iso_range).transpose()?;
    let (_, mut sets) = texmap_md_io::volume::read_volumes(path).with_context(|| {
        format!(
            "--surface-color-by reads volumetric data from {} (an OpenDX file such as APBS's, a CCP4/MRC map, a Gaussian cube file, an XSF file, or a VASP CHGCAR, PARCHG, LOCPOT or ELFCAR)",
            path.display()
        )
    })?;
    if sets.is_empty() {
        return usage(format!(
            "--surface-color-by {}: the file holds no data set",
            path.display()
        ));
    }
    Ok(Some(SurfaceColoring {
        volume: sets.swap_remove(0),
        path: path.clone(),
        map: colormap(m.volume_colormap),
        range,
        off_grid_warned: false,
    }))
}

impl SurfaceColoring {
    /// `surface` cut into colour bands of the volume's values at its vertices, its kinds past
    /// `materials`, to which the bands' materials are appended. Warns once when part of the
    /// surface lies outside the grid (drawn grey).
    pub fn apply(
        &mut self,
        surface: &texmap_md_scene::surface::MolMesh,
        materials: &mut Vec<texmap_core::shade::Material>,
        m: &MolArgs,
    ) -> Result<texmap_md_scene::surface::MolMesh> {
        let values: Vec<f64> = surface
            .positions
            .iter()
            .map(|p| {
                self.volume
                    .interpolate(p.as_dvec3().to_array())
                    .unwrap_or(f64::NAN)
            })
            .collect();
        let what = format!("--surface-color-by {}", self.path.display());
        let range = match self.range {
            Some(r) => r,
            None => *self.range.insert(volume_range(&values, m, &what)?),
        };
        let off = values.iter().filter(|v| v.is_nan()).count();
        if off > 0 && !self.off_grid_warned {
            self.off_grid_warned = true;
            eprintln!(
                "texmap: warning: {off} of the surface's {} vertices lie outside {}'s grid: their triangles are drawn grey",
                values.len(),
                self.path.display()
            );
        }
        let mut colors = Vec::new();
        let mut mesh = banded(surface, &values, range, self.map, &mut colors);
        let base = materials.len() as u16;
        for k in &mut mesh.kinds {
            *k += base;
        }
        materials.extend(band_materials(&colors));
        Ok(mesh)
    }

    /// The colour bar (once a frame was coloured), titled by the file's name.
    pub fn bar(&self) -> Option<IsoBar> {
        let (lo, hi) = self.range?;
        Some((self.map, lo, hi, crate::args::strip_gz_stem(&self.path)))
    }
}

/// Parses `--volume-range LO:HI` (finite, LO ≠ HI; HI < LO reverses the map).
fn parse_iso_range(s: &str) -> Result<(f32, f32)> {
    let bad = || {
        usage(format!(
            "--volume-range {s:?}: expected LO:HI, two different numbers (e.g. -0.05:0.05, or 0.05:-0.05 to reverse the map)"
        ))
    };
    let Some((a, b)) = s.split_once(':') else {
        return bad();
    };
    match (a.trim().parse::<f32>(), b.trim().parse::<f32>()) {
        (Ok(lo), Ok(hi)) if lo.is_finite() && hi.is_finite() && lo != hi => Ok((lo, hi)),
        _ => bad(),
    }
}

/// The range `--volume-range` gives, or the values' own: ±the largest magnitude for values of
/// both signs, else their span (NaN values, off the grid, left out). `what` names the layer in
/// the error for no values at all.
fn volume_range(values: &[f64], m: &MolArgs, what: &str) -> Result<(f32, f32)> {
    if let Some(r) = &m.volume_range {
        return parse_iso_range(r);
    }
    let (min, max) = values
        .iter()
        .filter(|v| !v.is_nan())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if min > max {
        return usage(format!(
            "{what}: no point of it lies inside the data's grid"
        ));
    }
    Ok(if min < 0.0 && max > 0.0 {
        let r = min.abs().max(max) as f32;
        (-r, r)
    } else if min == max {
        (min as f32 - 1.0, max as f32 + 1.0)
    } else {
        (min as f32, max as f32)
    })
}

/// `mesh` (kinds ignored) cut into the [`ISO_BINS`] colour bands of `values` over `range`,
/// its kinds from `base` (the grey of values off the grid: `base + ISO_BINS`); the bands'
/// colours and grey appended to `colors`.
fn banded(
    mesh: &texmap_md_scene::surface::MolMesh,
    values: &[f64],
    range: (f32, f32),
    map: Colormap,
    colors: &mut Vec<[u8; 3]>,
) -> texmap_md_scene::surface::MolMesh {
    let base = colors.len() as u16;
    colors.extend((0..ISO_BINS).map(|b| {
        let c = map.srgb((b as f32 + 0.5) / ISO_BINS as f32);
        c.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
    }));
    colors.push([128, 128, 128]);
    texmap_md_scene::isosurface::bands(
        mesh,
        values,
        (range.0 as f64, range.1 as f64),
        ISO_BINS as u16,
        base,
        base + ISO_BINS as u16,
    )
}

/// Parses `--volume-slice AXIS:F` (a, b or c; F from 0 to 1) into (axis, F).
fn parse_volume_slice(s: &str) -> Result<(usize, f64)> {
    let bad = || {
        usage(format!(
            "--volume-slice {s:?}: expected AXIS:F, the grid axis a, b or c and the position along it from 0 to 1 (e.g. c:0.5)"
        ))
    };
    let Some((axis, f)) = s.split_once(':') else {
        return bad();
    };
    let axis = match axis.trim() {
        "a" | "A" => 0,
        "b" | "B" => 1,
        "c" | "C" => 2,
        _ => return bad(),
    };
    match f.trim().parse::<f64>() {
        Ok(f) if (0.0..=1.0).contains(&f) => Ok((axis, f)),
        _ => bad(),
    }
}

/// What `--isosurface` and `--volume-slice` draw of volumetric data (with `--volume`,
/// `--volume-set`, `--isosurface-sign`, the colours, `--isosurface-color-by`,
/// `--volume-colormap`, `--volume-range`, `--isosurface-opacity` and a periodic volume's
/// `--replicate`); `None` without either. Usage errors for options out of range and for a
/// level the data never reaches.
pub fn isosurfaces(file: &std::path::Path, m: &MolArgs) -> Result<Option<Isosurfaces>> {
    use crate::args::IsoSignArg;
    use texmap_md_scene::isosurface::{Side, isosurface, slice};
    if m.isosurface.is_none() && m.volume_slices.is_empty() {
        if let Some(v) = &m.volume {
            return usage(format!(
                "--volume {}: give --isosurface LEVEL or --volume-slice AXIS:F to draw its data",
                v.display()
            ));
        }
        return Ok(None);
    }
    if m.isosurface_color_by.is_some() && !m.volume_slices.is_empty() {
        return usage(
            "--isosurface-color-by and --volume-slice would share one colour bar (--volume-colormap, --volume-range): draw them in two renders",
        );
    }
    let slices = m
        .volume_slices
        .iter()
        .map(|s| parse_volume_slice(s))
        .collect::<Result<Vec<_>>>()?;
    let opacity = m.isosurface_opacity;
    if !(opacity.is_finite() && (0.05..=1.0).contains(&opacity)) {
        return usage(format!(
            "--isosurface-opacity {opacity}: expected an opacity from 0.05 to 1"
        ));
    }
    let color = |flag: &str, v: &str| parse_color(v).or_else(|e| usage(format!("{flag}: {e}")));
    let sign_colors = [
        color("--isosurface-color", &m.isosurface_color)?,
        color("--isosurface-negative-color", &m.isosurface_negative_color)?,
    ];
    let path = m.volume.as_deref().unwrap_or(file);
    let (_, sets) = texmap_md_io::volume::read_volumes(path).with_context(|| {
        format!(
            "--isosurface and --volume-slice read volumetric data from {} (a Gaussian cube file, an XSF file, an OpenDX file, a CCP4/MRC map, or a VASP CHGCAR, PARCHG, LOCPOT or ELFCAR; another file's with --volume)",
            path.display()
        )
    })?;
    let names: Vec<String> = sets
        .iter()
        .enumerate()
        .map(|(i, v)| format!("{} {}", i + 1, v.name))
        .collect();
    let Some(vol) = m.volume_set.checked_sub(1).and_then(|i| sets.get(i)) else {
        return usage(format!(
            "--volume-set {}: {} holds {} data set(s): {}",
            m.volume_set,
            path.display(),
            sets.len(),
            names.join(", ")
        ));
    };
    let map = colormap(m.volume_colormap);
    let mut mesh = texmap_md_scene::surface::MolMesh::default();
    let mut colors = Vec::new();
    let mut bar = None;
    if let Some(level) = m.isosurface {
        if !level.is_finite() {
            return usage(format!("--isosurface {level}: expected a finite number"));
        }
        let (lo, hi) = vol.range().unwrap_or((0.0, 0.0));
        let mut sides = Vec::new();
        match m.isosurface_sign {
            IsoSignArg::Both => {
                sides.push((level, Side::Above, 0));
                if level > 0.0 && lo < -level {
                    sides.push((-level, Side::Below, 1));
                }
            }
            IsoSignArg::Positive => sides.push((level, Side::Above, 0)),
            IsoSignArg::Negative => sides.push((-level, Side::Below, 1)),
        }
        let mut iso = texmap_md_scene::surface::MolMesh::default();
        for (l, side, kind) in sides {
            iso.append(&isosurface(vol, l, side, kind)?);
        }
        if iso.triangles.is_empty() {
            return usage(format!(
                "--isosurface {level}: {} of {} runs from {lo} to {hi}, so no surface lies at that level",
                vol.name,
                path.display()
            ));
        }
        match &m.isosurface_color_by {
            None => {
                colors.extend(sign_colors);
                mesh.append(&iso);
            }
            Some(by_path) => {
                let (_, by) = texmap_md_io::volume::read_volumes(by_path).with_context(|| {
                    format!(
                        "--isosurface-color-by reads volumetric data from {} (a Gaussian cube file, an XSF file, an OpenDX file, a CCP4/MRC map, or a VASP CHGCAR, PARCHG, LOCPOT or ELFCAR)",
                        by_path.display()
                    )
                })?;
                let values: Vec<f64> = iso
                    .positions
                    .iter()
                    .map(|p| {
                        by[0]
                            .interpolate(p.as_dvec3().to_array())
                            .unwrap_or(f64::NAN)
                    })
                    .collect();
                let off = values.iter().filter(|v| v.is_nan()).count();
                if off > 0 {
                    crate::note!(
                        "{off} of the isosurface's {} vertices lie outside {}'s grid: their triangles are drawn grey",
                        values.len(),
                        by_path.display()
                    );
                }
                let what = format!("--isosurface-color-by {}", by_path.display());
                let range = volume_range(&values, m, &what)?;
                mesh.append(&banded(&iso, &values, range, map, &mut colors));
                // The bar's title: the file's name (a cube's comment line is often a long
                // title card).
                bar = Some((map, range.0, range.1, crate::args::strip_gz_stem(by_path)));
            }
        }
    }
    if !slices.is_empty() {
        let (mut planes, mut values) = (texmap_md_scene::surface::MolMesh::default(), Vec::new());
        for (axis, f) in slices {
            let (plane, v) = slice(vol, axis, f, 0)?;
            planes.append(&plane);
            values.extend(v);
        }
        let range = volume_range(&values, m, "--volume-slice")?;
        mesh.append(&banded(&planes, &values, range, map, &mut colors));
        bar = Some((map, range.0, range.1, crate::args::strip_gz_stem(path)));
    }
    // A periodic volume follows the atoms' periodic images (md-io's replicate::images).
    if let (true, Some(n)) = (vol.periodic, m.analysis.replicate) {
        let cell: [Vec3; 3] = std::array::from_fn(|a| {
            Vec3::from(vol.steps[a].map(|v| v as f32)) * vol.dims[a] as f32
        });
        let one = mesh.clone();
        mesh = texmap_md_scene::surface::MolMesh::default();
        let images = texmap_md_io::replicate::images;
        for i in images(n[0]) {
            for j in images(n[1]) {
                for k in images(n[2]) {
                    let mut copy = one.clone();
                    let shift = cell[0] * i as f32 + cell[1] * j as f32 + cell[2] * k as f32;
                    for p in &mut copy.positions {
                        *p += shift;
                    }
                    mesh.append(&copy);
                }
            }
        }
    }
    Ok(Some(Isosurfaces {
        mesh,
        colors,
        opacity,
        bar,
    }))
}

/// The axes of `--axes-tripod` as `camera` sees them: x, y, z or the cell's a, b, c (x, y, z
/// without a cell), each a unit direction in eye space, red, green and blue.
pub fn tripod_axes(
    which: crate::args::TripodArg,
    cell: Option<&texmap_md_io::UnitCell>,
    camera: &texmap_core::camera::Camera,
) -> Vec<texmap_md_scene::TripodAxis> {
    let colors = [[220, 40, 40], [30, 150, 30], [40, 80, 230]];
    let (dirs, labels) = match (which, cell) {
        (crate::args::TripodArg::Cell, Some(cell)) => {
            (cell.matrix().map(|r| r.map(|v| v as f32)), ['a', 'b', 'c'])
        }
        _ => (
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            ['x', 'y', 'z'],
        ),
    };
    (0..3)
        .map(|k| {
            let d = glam::Vec3::from(dirs[k]).normalize_or_zero();
            texmap_md_scene::TripodAxis {
                eye: camera.dir_to_eye(d).to_array(),
                label: labels[k],
                color: colors[k],
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_colours_parse_or_fail_clearly() {
        assert_eq!(parse_size("640x480").unwrap(), (640, 480));
        for bad in ["640", "0x10", "10x", "axb", "20000x10"] {
            let e = parse_size(bad).unwrap_err();
            assert!(
                e.downcast_ref::<crate::args::UsageError>().is_some(),
                "{bad}"
            );
        }
        assert_eq!(parse_background("1,2,3").unwrap(), [1, 2, 3, 255]);
        assert!(parse_background("1,2").is_err());
        assert!(parse_background("1,2,300").is_err());
        assert_eq!(
            parse_vec3("1,-2.5,3", "x").unwrap(),
            Vec3::new(1.0, -2.5, 3.0)
        );
        assert!(parse_vec3("1,nan,3", "x").is_err());
    }

    #[test]
    fn the_automatic_view_is_the_study_scenes_view() {
        assert_eq!(
            texmap_md_scene::AUTO_VIEW_DIRECTION,
            texmap_study::scenes::VIEW_DIRECTION
        );
    }
}

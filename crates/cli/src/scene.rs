//! Glue: an md-io frame (atoms in Å) becomes an impostor `SphereScene`, and a camera is chosen.

use std::collections::HashMap;

use anyhow::{Context, Result};
use glam::Vec3;
use texmap_core::camera::Camera;
use texmap_core::camera_path::{Keyframes, Pose};
use texmap_core::color::{hsv_to_rgb, srgb_to_linear};
use texmap_core::shade::Material;
use texmap_impostor::SphereScene;
use texmap_md_io::{
    Appearance, AtomStyle, Element, Frame, Label, Selection, Selector, Topology, atom_element,
};

use crate::args::{
    BondsArg, ColorBy, DrawStyle, MolArgs, PathArgs, PbcArg, StyleArgs, ViewArgs, parse_color,
    usage,
};

/// Most materials a scene gets: every method handles this many cheaply (the LUT and template
/// methods build tables per material). Colours past the first `MAX_MATERIALS` distinct ones
/// (after 8-bit quantisation) are drawn with the nearest of those.
pub const MAX_MATERIALS: usize = 256;

/// Reusable conversion from md-io frames to sphere scenes: one material per distinct colour,
/// kept stable across frames so per-material tables survive from frame to frame.
pub struct SceneBuilder {
    style: AtomStyle,
    color_by: ColorBy,
    pub(crate) radius_scale: f32,
    /// The NAMEs of --type-radius / --type-color, for the no-match warning.
    names: Vec<(&'static str, String)>,
    palette: Vec<[u8; 3]>,
    /// 8-bit colour -> material (exact, or the nearest palette entry once the palette is full).
    kinds: HashMap<[u8; 3], u16>,
    /// Distinct colours drawn with a nearest palette entry.
    merged: usize,
    types: Vec<Label>,
    radii: Vec<f32>,
    colors: Vec<[f32; 3]>,
}

/// A distinct, evenly spaced hue per type index (golden-angle hues).
fn type_color(i: usize) -> [f32; 3] {
    let c = hsv_to_rgb(Vec3::new((i as f32 * 137.507_77) % 360.0, 0.65, 0.95));
    [c.x, c.y, c.z]
}

/// The selectors a NAME of --type-radius / --type-color stands for: the type and the atom name
/// NAME, and the element whose symbol NAME is (any case), if any.
fn selectors(name: &str) -> Result<Vec<Selector>> {
    let Some(label) = Label::new(name) else {
        return usage(format!(
            "NAME {name:?} is longer than {} bytes",
            Label::CAPACITY
        ));
    };
    let mut v = vec![Selector::Type(label), Selector::Name(label)];
    if let Some(e) = Element::from_symbol(name) {
        v.push(Selector::Element(e));
    }
    Ok(v)
}

/// The md-io style for the CLI flags: one rule per selector, later flags replacing earlier
/// ones field by field (so `--type-radius O=1 --type-color O=#f00` sets both).
pub fn style_from(args: &StyleArgs) -> Result<AtomStyle> {
    let mut rules: Vec<(Selector, Appearance)> = Vec::new();
    let mut merge = |sel: Selector, look: Appearance| match rules.iter_mut().find(|r| r.0 == sel) {
        Some(r) => {
            r.1.radius = look.radius.or(r.1.radius);
            r.1.color = look.color.or(r.1.color);
        }
        None => rules.push((sel, look)),
    };
    for t in &args.type_radius {
        for sel in selectors(&t.name)? {
            merge(
                sel,
                Appearance {
                    radius: Some(t.radius),
                    color: None,
                },
            );
        }
    }
    for t in &args.type_color {
        for sel in selectors(&t.name)? {
            merge(
                sel,
                Appearance {
                    radius: None,
                    color: Some(t.rgb.map(|c| c as f32 / 255.0)),
                },
            );
        }
    }
    let mut style = AtomStyle::new();
    for (sel, look) in rules {
        style
            .set(sel, look)
            .map_err(|e| crate::args::UsageError(format!("--type-radius/--type-color: {e}")))?;
    }
    Ok(style)
}

impl SceneBuilder {
    pub fn new(args: &StyleArgs) -> Result<SceneBuilder> {
        let s = args.radius_scale;
        if !(s.is_finite() && s > 0.0) {
            return usage(format!("--radius-scale {s}: must be a finite number > 0"));
        }
        let names = args
            .type_radius
            .iter()
            .map(|t| ("--type-radius", t.name.clone()))
            .chain(
                args.type_color
                    .iter()
                    .map(|t| ("--type-color", t.name.clone())),
            )
            .collect();
        Ok(SceneBuilder {
            style: style_from(args)?,
            color_by: args.color_by,
            radius_scale: s,
            names,
            palette: Vec::new(),
            kinds: HashMap::new(),
            merged: 0,
            types: Vec::new(),
            radii: Vec::new(),
            colors: Vec::new(),
        })
    }

    /// The material of an sRGB colour in [0, 1] (quantised to 8 bits per channel).
    pub(crate) fn kind_of(&mut self, srgb: [f32; 3]) -> u16 {
        let key = srgb.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
        if let Some(k) = self.kinds.get(&key) {
            return *k;
        }
        let k = if self.palette.len() < MAX_MATERIALS {
            // A new material for a new colour.
            self.palette.push(key);
            (self.palette.len() - 1) as u16
        } else {
            // Palette full: the nearest entry (squared 8-bit distance, lowest index on ties).
            self.merged += 1;
            let d2 =
                |p: &[u8; 3]| -> i32 { (0..3).map(|c| (p[c] as i32 - key[c] as i32).pow(2)).sum() };
            let mut best = 0;
            for (i, p) in self.palette.iter().enumerate() {
                if d2(p) < d2(&self.palette[best]) {
                    best = i;
                }
            }
            best as u16
        };
        self.kinds.insert(key, k);
        k
    }

    /// Distinct colours so far drawn with the nearest of the first [`MAX_MATERIALS`].
    pub fn merged_colors(&self) -> usize {
        self.merged
    }

    /// Warnings worth one line each about `frame` (the first one rendered): a --type-radius or
    /// --type-color NAME that selects no atom; colour-column values outside [0, 1].
    pub fn warnings(&self, frame: &Frame) -> Vec<String> {
        let mut out = Vec::new();
        for (flag, name) in &self.names {
            let element = Element::from_symbol(name);
            let hit = frame.types.iter().any(|t| t.as_str() == name)
                || frame.names.iter().any(|n| n.as_str() == name)
                || element
                    .is_some_and(|e| (0..frame.n_atoms()).any(|i| atom_element(frame, i) == e));
            if !hit {
                out.push(format!(
                    "{flag} {name}: no atom of the first frame has this type, name or element"
                ));
            }
        }
        if self.color_by == ColorBy::Property {
            let outside = frame
                .colors
                .iter()
                .flatten()
                .filter(|v| !(0.0..=1.0).contains(*v))
                .count();
            if outside > 0 {
                out.push(format!(
                    "{outside} colour-column values of the first frame are outside [0, 1] and were clamped (colours are fractions of 1, not 0-255)"
                ));
            }
        }
        out
    }

    /// Fill `scene` (cleared first) from `frame` (whose colour column is dropped unless colouring
    /// by property). Atoms with non-finite coordinates are kept as they are: the renderers skip
    /// and count them.
    pub fn build(&mut self, frame: &mut Frame, scene: &mut SphereScene) {
        if self.color_by != ColorBy::Property {
            // Element and type colouring ignore colour columns in the file.
            frame.colors.clear();
        }
        // Radius and colour per atom: file column > --type-* rule > element table.
        self.style.apply(frame, &mut self.radii, &mut self.colors);
        scene.centers.clear();
        scene.radii.clear();
        scene.kinds.clear();
        scene.bonds.clear();
        // Atoms with types but no colours, names or elements (a LAMMPS dump with numeric
        // types) are coloured by type by default, as OVITO does.
        let by_type = self.color_by == ColorBy::Type
            || (self.color_by == ColorBy::Property
                && frame.colors.is_empty()
                && frame.names.is_empty()
                && !frame.types.is_empty()
                && frame.elements.iter().all(|e| e.is_unknown()));
        for i in 0..frame.n_atoms() {
            let p = frame.positions[i];
            let color = match by_type {
                true => match self.style.rules_for(frame, i).color {
                    Some(c) => c,
                    None => {
                        // One palette colour per type (or name), in order of appearance.
                        let label = frame
                            .types
                            .get(i)
                            .or(frame.names.get(i))
                            .copied()
                            .unwrap_or_default();
                        let idx = match self.types.iter().position(|t| *t == label) {
                            Some(j) => j,
                            None => {
                                self.types.push(label);
                                self.types.len() - 1
                            }
                        };
                        type_color(idx)
                    }
                },
                false => self.colors[i],
            };
            let kind = self.kind_of(color);
            scene.push(Vec3::from(p), self.radii[i] * self.radius_scale, kind);
        }
        self.refresh_materials(scene);
    }

    /// One material per palette colour (after [`SceneBuilder::kind_of`] added some).
    pub(crate) fn refresh_materials(&self, scene: &mut SphereScene) {
        scene.materials = self
            .palette
            .iter()
            .map(|c| {
                Material::plastic(Vec3::new(
                    srgb_to_linear(c[0] as f32 / 255.0),
                    srgb_to_linear(c[1] as f32 / 255.0),
                    srgb_to_linear(c[2] as f32 / 255.0),
                ))
            })
            .collect();
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
    Ok(Topology::open(path)?)
}

/// A parsed selection, or a usage error pointing at the bad token's column.
fn parse_selection(flag: &str, text: &str) -> Result<Selection> {
    Selection::parse(text).map_err(|e| crate::args::UsageError(format!("{flag}: {e}")).into())
}

/// Splits `SEL=VALUE` at its last '='.
fn sel_value<'a>(flag: &str, s: &'a str) -> Result<(&'a str, &'a str)> {
    match s.rsplit_once('=') {
        Some((sel, v)) if !sel.trim().is_empty() && !v.trim().is_empty() => {
            Ok((sel.trim(), v.trim()))
        }
        _ => usage(format!(
            "{flag} {s:?}: expected SELECTION=VALUE, e.g. {flag} 'resname SOL=#4080ff'"
        )),
    }
}

/// What `render` does to a frame between reading and drawing: topology, periodic boundaries,
/// selection, per-selection looks and bonds (the [`MolArgs`]).
pub struct MolPlan {
    pub topology: Option<Topology>,
    select: Option<Selection>,
    colors: Vec<(Selection, [f32; 3])>,
    radii: Vec<(Selection, f32)>,
    bonds: BondsArg,
    draw: DrawStyle,
    pbc: PbcArg,
    /// Scratch: selected atoms' new indices, bond pairs.
    map: Vec<u32>,
    pairs: Vec<[u32; 2]>,
    /// The bonds of the last frame drawn (before the selection).
    pub last_bond_count: usize,
}

impl MolPlan {
    pub fn new(args: &MolArgs) -> Result<MolPlan> {
        let topology = args.topology.as_deref().map(open_topology).transpose()?;
        let select = args
            .select
            .as_deref()
            .map(|t| parse_selection("--select", t))
            .transpose()?;
        let mut colors = Vec::new();
        for c in &args.color_rules {
            let (sel, v) = sel_value("--color", c)?;
            let rgb =
                parse_color(v).map_err(|e| crate::args::UsageError(format!("--color: {e}")))?;
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
        if args.bonds == BondsArg::Topology
            && args.draw != DrawStyle::Spacefill
            && topology.as_ref().is_none_or(|t| t.bonds.is_empty())
        {
            return usage(match &topology {
                None => "--bonds topology needs --topology FILE (PDB with CONECT records, or a LAMMPS data file with a Bonds section)".to_string(),
                Some(t) => format!("--bonds topology: {} has no bonds (use --bonds auto for bonds by distance)", t.name()),
            });
        }
        Ok(MolPlan {
            topology,
            select,
            colors,
            radii,
            bonds: args.bonds,
            draw: args.draw,
            pbc: args.pbc,
            map: Vec::new(),
            pairs: Vec::new(),
            last_bond_count: 0,
        })
    }

    /// Whether bonds are drawn at all.
    pub fn draws_bonds(&self) -> bool {
        self.draw != DrawStyle::Spacefill && self.bonds != BondsArg::None
    }

    /// The topology's labels on `frame` (number `index` of `trajectory`).
    pub fn label(&self, frame: &mut Frame, trajectory: &str, index: usize) -> Result<()> {
        if let Some(t) = &self.topology {
            t.apply(frame, trajectory, index)?;
        }
        Ok(())
    }

    /// The bonds of `frame` as `--bonds` asks (before periodic handling).
    fn find_bonds(&mut self, frame: &Frame, need: bool) {
        self.pairs.clear();
        if !need {
            return;
        }
        match (self.bonds, &self.topology) {
            (BondsArg::None, _) => {}
            (BondsArg::Topology, Some(t)) => self.pairs.extend_from_slice(&t.bonds),
            (BondsArg::Topology, None) => {}
            (BondsArg::Auto, Some(t)) if !t.bonds.is_empty() => {
                self.pairs.extend_from_slice(&t.bonds)
            }
            (BondsArg::Auto, _) => {
                self.pairs = texmap_md_io::bonds::bonds_by_distance(frame, true).pairs;
            }
        }
    }

    /// Periodic boundaries, then the scene: selected atoms only, per-selection colours and
    /// radii, bonds between drawn atoms (never across the box).
    pub fn build(
        &mut self,
        builder: &mut SceneBuilder,
        frame: &mut Frame,
        scene: &mut SphereScene,
    ) -> Result<()> {
        let unwrap = self.pbc == PbcArg::Unwrap && frame.cell.is_some();
        self.find_bonds(frame, self.draws_bonds() || unwrap);
        match self.pbc {
            PbcArg::None => {}
            PbcArg::Wrap => texmap_md_io::pbc::wrap(frame),
            PbcArg::Unwrap => {
                if unwrap && self.bonds == BondsArg::None {
                    // Molecules need bonds to be made whole even when none are drawn.
                    self.pairs = texmap_md_io::bonds::bonds_by_distance(frame, true).pairs;
                }
                texmap_md_io::pbc::unwrap(frame, &self.pairs);
            }
        }
        texmap_md_io::pbc::drop_crossing(&mut self.pairs, &frame.positions, frame.cell.as_ref());
        self.last_bond_count = self.pairs.len();
        // Every atom, styled; then the per-selection rules, in order.
        builder.build(frame, scene);
        for (sel, rgb) in &self.colors {
            let mask = sel
                .evaluate(frame)
                .map_err(|e| crate::args::UsageError(format!("--color: {e}")))?;
            let kind = builder.kind_of(*rgb);
            for (i, m) in mask.iter().enumerate() {
                if *m {
                    scene.kinds[i] = kind;
                }
            }
        }
        builder.refresh_materials(scene);
        let scale = builder.radius_scale;
        for (sel, r) in &self.radii {
            let mask = sel
                .evaluate(frame)
                .map_err(|e| crate::args::UsageError(format!("--radius: {e}")))?;
            for (i, m) in mask.iter().enumerate() {
                if *m {
                    scene.radii[i] = r * scale;
                }
            }
        }
        match self.draw {
            DrawStyle::Spacefill => {}
            DrawStyle::BallStick => {
                for r in &mut scene.radii {
                    *r *= texmap_study::scenes::BALL_AND_STICK_RADIUS_SCALE;
                }
                scene.bond_radius = texmap_study::scenes::BALL_AND_STICK_BOND_RADIUS;
            }
            DrawStyle::Licorice => {
                for r in &mut scene.radii {
                    *r = LICORICE_RADIUS;
                }
                scene.bond_radius = LICORICE_RADIUS;
            }
        }
        // The selection: keep selected atoms, renumber the bonds between them.
        let mask = match &self.select {
            Some(sel) => Some(
                sel.evaluate(frame)
                    .map_err(|e| crate::args::UsageError(format!("--select: {e}")))?,
            ),
            None => None,
        };
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
        if self.draws_bonds() {
            for b in &self.pairs {
                let (i, j) = if self.map.is_empty() {
                    (b[0], b[1])
                } else {
                    (self.map[b[0] as usize], self.map[b[1] as usize])
                };
                if i != u32::MAX && j != u32::MAX {
                    scene.bonds.push([i, j]);
                }
            }
        }
        Ok(())
    }

    /// The once-per-run warning for atoms that have nothing to be told apart by.
    pub fn unnamed_warning(&self, frame: &Frame, file: &str) -> Option<String> {
        let nothing = frame.names.is_empty()
            && frame.types.is_empty()
            && (0..frame.n_atoms()).all(|i| atom_element(frame, i).is_unknown());
        (self.topology.is_none() && nothing && frame.n_atoms() > 0).then(|| {
            format!(
                "{file} has no atom names, types or elements (coordinates only): every atom is drawn in the unknown-element colour; give --topology FILE (PDB, GRO or LAMMPS data file of the same atoms) for names, elements, residues and bonds"
            )
        })
    }
}

/// Atom and stick radius of `--style licorice` (Å), as VMD's Licorice default (0.3).
pub const LICORICE_RADIUS: f32 = 0.3;

/// The 8 corners of a periodic cell, corner `c` at fractional coordinates of its bits (x, y, z).
pub fn cell_corners(cell: &texmap_md_io::UnitCell) -> [Vec3; 8] {
    std::array::from_fn(|c| {
        let p = cell.to_cartesian([(c & 1) as f64, ((c >> 1) & 1) as f64, ((c >> 2) & 1) as f64]);
        Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32)
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

/// The view direction (from the camera toward the target) for `--view`.
fn view_direction(view: &str) -> Result<(Vec3, Vec3)> {
    Ok(match view {
        "auto" => (-texmap_study::scenes::VIEW_DIRECTION.normalize(), Vec3::Y),
        "x" => (-Vec3::X, Vec3::Z),
        "-x" => (Vec3::X, Vec3::Z),
        "y" => (-Vec3::Y, Vec3::Z),
        "-y" => (Vec3::Y, Vec3::Z),
        "z" => (-Vec3::Z, Vec3::Y),
        "-z" => (Vec3::Z, Vec3::Y),
        other => {
            return usage(format!(
                "--view {other:?}: expected auto, x, y, z, -x, -y or -z (the axis the camera sits on)"
            ));
        }
    })
}

/// The camera for a render and the point it looks at: exactly `--eye/--target/--up` when given,
/// else fitted to what the first frame draws (the selected atoms' bounding box's sphere).
pub fn camera_for(args: &ViewArgs, first: &Frame, scene: &SphereScene) -> Result<(Camera, Vec3)> {
    let (w, h) = parse_size(&args.size)?;
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
                None => {
                    // Orthographic with an explicit camera: frame the scene's extent.
                    let extent = scene
                        .bounds()
                        .map(|(lo, hi)| (hi - lo).length())
                        .unwrap_or(1.0);
                    Camera::orthographic_look_at(e, t, u, extent, w, h)
                }
            };
            return cam
                .map(|c| (c, t))
                .map_err(|e| crate::args::UsageError(format!("camera: {e}")).into());
        }
        (None, None, None) => {}
        _ => return usage("--eye, --target and --up go together: give all three or none"),
    }
    let (dir, up) = view_direction(&args.view)?;
    // Frame what is drawn: the scene's spheres (the selected atoms, and the box outline when
    // it is drawn); the periodic box only when no atom is drawn.
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    if let Some((a, b)) = scene.bounds() {
        lo = a;
        hi = b;
    } else if let Some(cell) = &first.cell {
        for p in cell_corners(cell) {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    let (center, radius) = if lo.x <= hi.x {
        ((lo + hi) * 0.5, (hi - lo).length() * 0.5)
    } else {
        (Vec3::ZERO, 1.0)
    };
    Camera::fit_sphere(center, radius.max(1e-3), dir, up, hfov, w, h, 1.05)
        .map(|c| (c, center))
        .context("automatic camera")
}

/// How the camera moves over the frames of a render.
enum Motion {
    Still,
    Orbit { degrees_per_frame: f32 },
    Keys(Keyframes),
}

/// The camera of every frame of a render: the first frame's camera (fitted or given), moved
/// along `--orbit`/`--orbit-turns`/`--keyframes` and with the centre of `--follow`'s atoms.
/// A frame's camera depends only on its position in the render and its own atoms, so the parts
/// of a sharded render draw exactly what one process would.
pub struct CameraPlan {
    template: Camera,
    pose: Pose,
    motion: Motion,
    /// The --follow selection and its atoms' centre in the first frame.
    follow: Option<(Selection, Vec3)>,
}

/// The mean position of the atoms `sel` selects, or None when it selects none.
fn centre_of(sel: &Selection, frame: &Frame) -> Result<Option<Vec3>> {
    let idx = sel
        .indices(frame)
        .map_err(|e| crate::args::UsageError(format!("--follow: {e}")))?;
    if idx.is_empty() {
        return Ok(None);
    }
    // f64 sum: a million atoms far from the origin keep their centre to well below an atom.
    let mut sum = [0f64; 3];
    for &i in &idx {
        for (s, p) in sum.iter_mut().zip(frame.positions[i]) {
            *s += p as f64;
        }
    }
    let n = idx.len() as f64;
    Ok(Some(Vec3::new(
        (sum[0] / n) as f32,
        (sum[1] / n) as f32,
        (sum[2] / n) as f32,
    )))
}

impl CameraPlan {
    /// The plan for a render of `count` frames whose first frame is `first` (drawn as `scene`).
    pub fn new(
        view: &ViewArgs,
        path: &PathArgs,
        first: &Frame,
        scene: &SphereScene,
        count: usize,
    ) -> Result<CameraPlan> {
        let (template, target) = camera_for(view, first, scene)?;
        let pose = Pose::of_camera(&template, target);
        let motion = match (path.orbit, path.orbit_turns, &path.keyframes) {
            (Some(d), None, None) => {
                if !d.is_finite() {
                    return usage(format!("--orbit {d}: must be a finite number of degrees"));
                }
                Motion::Orbit {
                    degrees_per_frame: d,
                }
            }
            (None, Some(t), None) => {
                if !t.is_finite() {
                    return usage(format!("--orbit-turns {t}: must be a finite number"));
                }
                Motion::Orbit {
                    degrees_per_frame: 360.0 * t / count.max(1) as f32,
                }
            }
            (None, None, Some(file)) => {
                let text = std::fs::read_to_string(file)
                    .with_context(|| format!("--keyframes {}", file.display()))?;
                let keys = Keyframes::parse(&text, &pose)
                    .map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?;
                Motion::Keys(keys)
            }
            (None, None, None) => Motion::Still,
            _ => return usage("--orbit, --orbit-turns and --keyframes exclude one another"),
        };
        let follow = match &path.follow {
            None => None,
            Some(text) => {
                let sel = parse_selection("--follow", text)?;
                let Some(c) = centre_of(&sel, first)? else {
                    return usage(format!(
                        "--follow {text:?} selects none of the first frame's atoms"
                    ));
                };
                Some((sel, c))
            }
        };
        Ok(CameraPlan {
            template,
            pose,
            motion,
            follow,
        })
    }

    /// The camera of the `k`-th rendered frame (0-based), whose atoms are `frame` (after the
    /// periodic-boundary treatment).
    pub fn camera(&self, k: usize, frame: &Frame) -> Result<Camera> {
        let mut pose = match &self.motion {
            Motion::Still => self.pose,
            Motion::Orbit { degrees_per_frame } => {
                // Reduced in f64 so that frame 100,000 turns as exactly as frame 1.
                let deg = (k as f64 * *degrees_per_frame as f64) % 360.0;
                self.pose.orbit(deg as f32)
            }
            Motion::Keys(keys) => keys.at(k as f32),
        };
        if let Some((sel, c0)) = &self.follow {
            let Some(c) = centre_of(sel, frame)? else {
                anyhow::bail!(
                    "--follow {:?} selects none of this frame's atoms",
                    sel.text()
                );
            };
            pose = pose.translated(c - *c0);
        }
        if matches!(self.motion, Motion::Still) && self.follow.is_none() {
            return Ok(self.template.clone());
        }
        pose.camera(&self.template)
            .map_err(|e| anyhow::anyhow!("camera of rendered frame {k}: {e}"))
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

    fn style_args(radius: &[(&str, f32)], color: &[(&str, [u8; 3])]) -> StyleArgs {
        StyleArgs {
            color_by: ColorBy::Property,
            radius_scale: 1.0,
            type_radius: radius
                .iter()
                .map(|(n, r)| crate::args::TypeRadius {
                    name: n.to_string(),
                    radius: *r,
                })
                .collect(),
            type_color: color
                .iter()
                .map(|(n, c)| crate::args::TypeColor {
                    name: n.to_string(),
                    rgb: *c,
                })
                .collect(),
        }
    }

    #[test]
    fn type_flags_merge_per_selector_and_match_type_name_or_element() {
        // "O" as radius and "o" as colour: both reach the oxygen element rule.
        let st = style_from(&style_args(&[("O", 1.0)], &[("o", [255, 0, 0])])).unwrap();
        let mut f = Frame::new();
        f.positions = vec![[0.0; 3]; 2];
        f.names = ["OW", "O"].map(|s| Label::new(s).unwrap()).to_vec();
        let look = st.rules_for(&f, 0);
        assert_eq!(look.radius, Some(1.0), "element rule radius for OW");
        assert_eq!(
            look.color,
            Some([1.0, 0.0, 0.0]),
            "element rule colour for OW"
        );
        // Atom named exactly "O": the name rule (radius only) then the element rule (colour).
        assert_eq!(st.rules_for(&f, 1).radius, Some(1.0));
        assert_eq!(st.rules_for(&f, 1).color, Some([1.0, 0.0, 0.0]));
    }

    #[test]
    fn palette_is_capped_and_overflow_colours_take_the_nearest() {
        let mut b = SceneBuilder::new(&style_args(&[], &[])).unwrap();
        // MAX_MATERIALS distinct greys 0..=255 fill the palette exactly.
        for g in 0..MAX_MATERIALS {
            let v = g as f32 / 255.0;
            assert_eq!(b.kind_of([v, v, v]) as usize, g);
        }
        assert_eq!(b.merged_colors(), 0);
        // Pure red is nearest (squared 8-bit distance, computed here by brute force) to the grey
        // g minimising (255 − g)² + 2g²: g = 85.
        let best = (0..256i32)
            .min_by_key(|g| (255 - g).pow(2) + 2 * g * g)
            .unwrap();
        assert_eq!(best, 85);
        assert_eq!(b.kind_of([1.0, 0.0, 0.0]) as usize, best as usize);
        assert_eq!(b.merged_colors(), 1);
        // Asked again: same material, counted once.
        assert_eq!(b.kind_of([1.0, 0.0, 0.0]) as usize, best as usize);
        assert_eq!(b.merged_colors(), 1);
        // The palette never grows past the cap, so u16 kinds cannot wrap.
        for i in 0..5000u32 {
            let c = [(i % 97) as f32 / 96.0, (i % 89) as f32 / 88.0, 0.5];
            assert!((b.kind_of(c) as usize) < MAX_MATERIALS);
        }
        assert_eq!(b.palette.len(), MAX_MATERIALS);
    }
}

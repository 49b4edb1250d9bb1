//! Frames styled into sphere scenes: [`style_from`] turns per-name radius and colour rules into
//! an md-io [`AtomStyle`], and a [`SceneBuilder`] fills a [`SphereScene`] from each frame with
//! it, one material per distinct colour ([`Palette`]).
//!
//! Per atom, the radius and colour come from the frame's own columns, then the rules, then the
//! element tables ([`AtomStyle`]); colouring by type gives every type (or atom name) without a
//! rule its own colour ([`type_color`]), in order of first appearance. Atoms with types but no
//! colours, names or elements (a LAMMPS dump with numeric types) are coloured by type by
//! default, as OVITO does.

use glam::Vec3;
use texmap_impostor::SphereScene;
use texmap_md_io::{Appearance, AtomStyle, Element, Frame, Label, Selector, atom_element};

use crate::palette::{Palette, type_color};
use crate::scalar::{ScalarColor, fit_range, scalar_color};

/// Where an atom's colour comes from (before the rules of [`style_from`], which always win
/// over the element table).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorBy {
    /// The frame's per-atom colour column where it has one, else the rules, else the element.
    Property,
    /// The rules, else the element; colour columns are ignored.
    Element,
    /// The rules, else one distinct colour per atom type (or name).
    Type,
    /// The rules, else one distinct colour per chain (or, without chains, per segment), in
    /// order of appearance; atoms of a frame with neither take the element colours.
    Chain,
    /// The rules, else [`StyleOptions::scalar`]'s number per atom through its colour map
    /// (module [`crate::scalar`]); atoms of a frame without the number take the element colours.
    Scalar,
    /// The rules, else the secondary structure of the atom's residue, assigned per frame
    /// ([`texmap_md_io::secondary`]), in VMD's Structure colours ([`STRUCTURE_COLORS`]); atoms
    /// outside protein residues (water, ligands, ions) take the element colours.
    Structure,
    /// The rules, else the crystal structure type adaptive common neighbour analysis gives the
    /// atom ([`texmap_md_io::cna`]), assigned per frame, in OVITO's colours ([`CNA_COLORS`]).
    Cna,
    /// The rules, else one distinct colour per cluster (the per-atom property
    /// [`crate::plan::CLUSTER`], [`crate::MolOptions::clusters`]): the palette colour of the
    /// cluster's id, the largest first; atoms in no cluster take the element colours.
    Cluster,
    /// The rules, else the diamond structure type ([`texmap_md_io::cna::classify_diamond`]),
    /// assigned per frame, in OVITO's colours ([`DIAMOND_COLORS`]).
    Diamond,
    /// The rules, else one distinct colour per grain (the per-atom property
    /// [`crate::plan::GRAIN`], [`crate::MolOptions::grains`]), the largest first; atoms in no
    /// grain take the element colours.
    Grain,
    /// The rules, else the inverse pole figure colour of the atom's lattice orientation along
    /// a sample axis ([`texmap_md_io::orientation::ipf_colour`]: for cubic crystals [001] red,
    /// [101] green, [111] blue), computed per frame, each channel rounded to eighths so that a
    /// polycrystal fits the scene's materials; atoms that are not FCC, HCP or BCC take
    /// [`CNA_COLORS`]' "other".
    Ipf(IpfAxis),
}

/// The sample direction an inverse pole figure ([`ColorBy::Ipf`]) looks along, as EBSD maps'
/// IPF-X, IPF-Y and IPF-Z.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IpfAxis {
    X,
    Y,
    Z,
}

impl IpfAxis {
    /// The unit vector.
    pub fn vector(self) -> [f64; 3] {
        match self {
            IpfAxis::X => [1.0, 0.0, 0.0],
            IpfAxis::Y => [0.0, 1.0, 0.0],
            IpfAxis::Z => [0.0, 0.0, 1.0],
        }
    }
}

/// The colours of [`ColorBy::Cna`], OVITO's: other near-white, FCC green, HCP red, BCC blue,
/// icosahedral yellow; sRGB in [0, 1], indexed by [`texmap_md_io::cna::StructureType`] as
/// `usize` (OVITO's type codes).
pub const CNA_COLORS: [[f32; 3]; 5] = [
    [0.95, 0.95, 0.95],
    [0.4, 1.0, 0.4],
    [1.0, 0.4, 0.4],
    [0.4, 0.4, 1.0],
    [0.95, 0.8, 0.2],
];

/// The colours of [`ColorBy::Diamond`], OVITO's: other near-white, cubic diamond blue and its
/// first and second neighbours cyan and light green, hexagonal diamond orange and its
/// neighbours yellow and yellow-green; sRGB in [0, 1], indexed by
/// [`texmap_md_io::cna::DiamondType`] as `usize`.
pub const DIAMOND_COLORS: [[f32; 3]; 7] = [
    [0.95, 0.95, 0.95],
    [19.0 / 255.0, 160.0 / 255.0, 254.0 / 255.0],
    [0.0, 254.0 / 255.0, 245.0 / 255.0],
    [126.0 / 255.0, 254.0 / 255.0, 181.0 / 255.0],
    [254.0 / 255.0, 137.0 / 255.0, 0.0],
    [254.0 / 255.0, 220.0 / 255.0, 0.0],
    [204.0 / 255.0, 229.0 / 255.0, 81.0 / 255.0],
];

/// The colours of [`ColorBy::Structure`], VMD's: coil white, helix purple (VMD's alpha-helix
/// colour), strand yellow (VMD's extended-beta colour); sRGB in [0, 1], indexed by
/// [`texmap_md_io::secondary::Structure`] as `usize`.
pub const STRUCTURE_COLORS: [[f32; 3]; 3] = [[1.0, 1.0, 1.0], [0.65, 0.0, 0.65], [1.0, 1.0, 0.0]];

/// Which kind of rule a [`StyleWarning`] or [`StyleError`] is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RuleKind {
    Radius,
    Color,
}

/// How a [`SceneBuilder`] styles atoms.
#[derive(Clone, Debug, PartialEq)]
pub struct StyleOptions {
    pub color_by: ColorBy,
    /// Factor on every radius (finite, > 0).
    pub radius_scale: f32,
    /// `(NAME, radius in Å)`: the atoms whose type, atom name or element symbol is NAME.
    pub type_radius: Vec<(String, f32)>,
    /// `(NAME, 8-bit sRGB colour)`, NAME as for `type_radius`.
    pub type_color: Vec<(String, [u8; 3])>,
    /// What [`ColorBy::Scalar`] colours by.
    pub scalar: ScalarColor,
}

impl Default for StyleOptions {
    fn default() -> Self {
        StyleOptions {
            color_by: ColorBy::Property,
            radius_scale: 1.0,
            type_radius: Vec::new(),
            type_color: Vec::new(),
            scalar: ScalarColor::default(),
        }
    }
}

/// Why a style was refused.
#[derive(Debug)]
pub enum StyleError {
    /// A rule's NAME is longer than an md-io [`Label`] holds.
    NameTooLong { name: String },
    /// md-io refused a rule (a radius that is not finite and > 0, or a colour outside [0, 1]).
    Rule(texmap_md_io::Error),
    /// The radius scale is not a finite number > 0.
    BadRadiusScale { scale: f32 },
}

impl std::fmt::Display for StyleError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StyleError::NameTooLong { name } => {
                write!(f, "NAME {name:?} is longer than {} bytes", Label::CAPACITY)
            }
            StyleError::Rule(e) => write!(f, "{e}"),
            StyleError::BadRadiusScale { scale } => {
                write!(f, "radius scale {scale}: must be a finite number > 0")
            }
        }
    }
}

impl std::error::Error for StyleError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            StyleError::Rule(e) => Some(e),
            _ => None,
        }
    }
}

/// Something worth telling the user about a style and the first frame it meets.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum StyleWarning {
    /// A rule's NAME matches no atom's type, name or element.
    NoMatch { kind: RuleKind, name: String },
    /// Colour-column values outside [0, 1] (clamped).
    ColorsOutOfRange { count: usize },
    /// Colouring by chain, but the frame has neither chain nor segment identifiers: the
    /// element colours are used.
    NoChains,
    /// Colouring by a number the frame does not have (a property by another name, speed
    /// without velocities); `available` lists the frame's properties.
    NoScalar {
        what: String,
        available: Vec<String>,
    },
    /// Colouring by secondary structure, but no residue of the frame has a protein backbone
    /// (N, CA, C, O with residue names and numbers): the element colours are used.
    NoStructure,
}

/// The selectors a rule NAME stands for: the type and the atom name NAME, and the element whose
/// symbol NAME is (any case), if any.
fn selectors(name: &str) -> Result<Vec<Selector>, StyleError> {
    let Some(label) = Label::new(name) else {
        return Err(StyleError::NameTooLong {
            name: name.to_string(),
        });
    };
    let mut v = vec![Selector::Type(label), Selector::Name(label)];
    if let Some(e) = Element::from_symbol(name) {
        v.push(Selector::Element(e));
    }
    Ok(v)
}

/// The md-io style for per-name rules: one rule per selector, later rules replacing earlier
/// ones field by field (so a radius rule and a colour rule for `O` set both), the radius rules
/// taken before the colour rules.
pub fn style_from(
    type_radius: &[(String, f32)],
    type_color: &[(String, [u8; 3])],
) -> Result<AtomStyle, StyleError> {
    let mut rules: Vec<(Selector, Appearance)> = Vec::new();
    let mut merge = |sel: Selector, look: Appearance| match rules.iter_mut().find(|r| r.0 == sel) {
        Some(r) => {
            r.1.radius = look.radius.or(r.1.radius);
            r.1.color = look.color.or(r.1.color);
        }
        None => rules.push((sel, look)),
    };
    for (name, radius) in type_radius {
        for sel in selectors(name)? {
            let look = Appearance {
                radius: Some(*radius),
                color: None,
            };
            merge(sel, look);
        }
    }
    for (name, rgb) in type_color {
        for sel in selectors(name)? {
            let look = Appearance {
                radius: None,
                color: Some(rgb.map(|c| c as f32 / 255.0)),
            };
            merge(sel, look);
        }
    }
    let mut style = AtomStyle::new();
    for (sel, look) in rules {
        style.set(sel, look).map_err(StyleError::Rule)?;
    }
    Ok(style)
}

/// Reusable conversion from md-io frames to sphere scenes: one material per distinct colour,
/// kept stable across frames so per-material tables survive from frame to frame.
#[derive(Clone, Debug)]
pub struct SceneBuilder {
    style: AtomStyle,
    color_by: ColorBy,
    radius_scale: f32,
    /// The rule NAMEs, for [`SceneBuilder::warnings`].
    names: Vec<(RuleKind, String)>,
    palette: Palette,
    /// The type or name labels met so far, and the chain (or segment) labels: label k of a
    /// list has palette colour k, so a chain keeps its colour whatever else is coloured.
    categories: [Vec<Label>; 2],
    radii: Vec<f32>,
    colors: Vec<[f32; 3]>,
    /// The scalar colouring and the per-atom values of the last frame.
    scalar: ScalarColor,
    values: Vec<f32>,
}

impl SceneBuilder {
    /// A builder styling atoms as `options` say.
    pub fn new(options: &StyleOptions) -> Result<SceneBuilder, StyleError> {
        let s = options.radius_scale;
        if !(s.is_finite() && s > 0.0) {
            return Err(StyleError::BadRadiusScale { scale: s });
        }
        let names = options
            .type_radius
            .iter()
            .map(|(n, _)| (RuleKind::Radius, n.clone()))
            .chain(
                options
                    .type_color
                    .iter()
                    .map(|(n, _)| (RuleKind::Color, n.clone())),
            )
            .collect();
        Ok(SceneBuilder {
            style: style_from(&options.type_radius, &options.type_color)?,
            color_by: options.color_by,
            radius_scale: s,
            names,
            palette: Palette::new(),
            categories: [Vec::new(), Vec::new()],
            radii: Vec::new(),
            colors: Vec::new(),
            scalar: options.scalar.clone(),
            values: Vec::new(),
        })
    }

    /// How atoms are coloured.
    pub fn color_by(&self) -> ColorBy {
        self.color_by
    }

    /// The scalar colouring (its range once fixed).
    pub fn scalar(&self) -> &ScalarColor {
        &self.scalar
    }

    /// Fixes the scalar range, when colouring by a scalar without one, to the finite values of
    /// `frame`'s atoms that `mask` selects (all atoms without a mask). Nothing when the frame
    /// lacks the values or none is finite: [`SceneBuilder::build`] then fits all atoms.
    pub fn fit_scalar_range(&mut self, frame: &Frame, mask: Option<&[bool]>) {
        if self.color_by != ColorBy::Scalar || self.scalar.range.is_some() {
            return;
        }
        if self.scalar.source.values(frame, &mut self.values) {
            self.scalar.range = fit_range(&self.values, mask);
        }
    }

    /// The factor on every radius.
    pub fn radius_scale(&self) -> f32 {
        self.radius_scale
    }

    /// The material of an sRGB colour in [0, 1] (see [`Palette::kind_of`]); call
    /// [`SceneBuilder::refresh_materials`] before drawing a scene that uses it.
    pub fn kind_of(&mut self, srgb: [f32; 3]) -> u16 {
        self.palette.kind_of(srgb)
    }

    /// Distinct colours so far drawn with the nearest of the first
    /// [`MAX_MATERIALS`](crate::MAX_MATERIALS).
    pub fn merged_colors(&self) -> usize {
        self.palette.merged_colors()
    }

    /// What is worth telling about `frame` (the first one drawn): rules whose NAME selects no
    /// atom, in rule order (radius rules first), then colour-column values outside [0, 1] when
    /// colouring by property, or no chains when colouring by chain.
    pub fn warnings(&self, frame: &Frame) -> Vec<StyleWarning> {
        let mut out = Vec::new();
        for (kind, name) in &self.names {
            let element = Element::from_symbol(name);
            let hit = frame.types.iter().any(|t| t.as_str() == name)
                || frame.names.iter().any(|n| n.as_str() == name)
                || element
                    .is_some_and(|e| (0..frame.n_atoms()).any(|i| atom_element(frame, i) == e));
            if !hit {
                out.push(StyleWarning::NoMatch {
                    kind: *kind,
                    name: name.clone(),
                });
            }
        }
        out.extend(self.color_warnings(frame, self.color_by));
        out
    }

    /// What is worth telling about colouring `frame` by `color_by` (the builder's own colouring
    /// or a representation's): colour-column values outside [0, 1] when colouring by property,
    /// no chains when colouring by chain, no protein backbone when colouring by structure, no
    /// such number when colouring by a scalar.
    pub fn color_warnings(&self, frame: &Frame, color_by: ColorBy) -> Vec<StyleWarning> {
        let mut out = Vec::new();
        if color_by == ColorBy::Property {
            let count = frame
                .colors
                .iter()
                .flatten()
                .filter(|v| !(0.0..=1.0).contains(*v))
                .count();
            if count > 0 {
                out.push(StyleWarning::ColorsOutOfRange { count });
            }
        }
        if color_by == ColorBy::Chain && frame.chains.is_empty() && frame.segments.is_empty() {
            out.push(StyleWarning::NoChains);
        }
        if color_by == ColorBy::Structure
            && texmap_md_io::secondary::assign(frame).residues().is_empty()
        {
            out.push(StyleWarning::NoStructure);
        }
        if color_by == ColorBy::Scalar && !self.scalar.source.values(frame, &mut Vec::new()) {
            out.push(StyleWarning::NoScalar {
                what: self.scalar.source.title(),
                available: frame.properties.iter().map(|p| p.name.clone()).collect(),
            });
        }
        out
    }

    /// Fill `scene` (cleared first, bonds included) from `frame`, whose colour column is
    /// dropped unless colouring by property. Atoms with non-finite coordinates are kept as they
    /// are: the renderers skip and count them.
    pub fn build(&mut self, frame: &mut Frame, scene: &mut SphereScene) {
        if self.color_by != ColorBy::Property {
            // Element and type colouring ignore colour columns in the file.
            frame.colors.clear();
        }
        // Radius and colour per atom: file column > rule > element table.
        self.style.apply(frame, &mut self.radii, &mut self.colors);
        scene.centers.clear();
        scene.radii.clear();
        scene.bonds.clear();
        let base = std::mem::take(&mut self.colors);
        self.kinds_into(frame, self.color_by, &base, &mut scene.kinds);
        self.colors = base;
        scene
            .centers
            .extend(frame.positions.iter().map(|&p| Vec3::from(p)));
        scene
            .radii
            .extend(self.radii.iter().map(|r| r * self.radius_scale));
        self.refresh_materials(scene);
    }

    /// The materials of `frame`'s atoms coloured by `color_by` rather than the builder's own
    /// colouring (a representation with its own colouring), in `kinds` (cleared first). The
    /// palette, the per-name rules and the category colours are the builder's, so one colour
    /// means one thing in every representation; [`ColorBy::Scalar`] is the builder's scalar.
    /// [`ColorBy::Property`] reads the frame's colour column, which [`SceneBuilder::build`]
    /// drops under any other colouring: keep a copy for it. Call
    /// [`SceneBuilder::refresh_materials`] before drawing.
    pub fn kinds_by(&mut self, frame: &Frame, color_by: ColorBy, kinds: &mut Vec<u16>) {
        let base: Vec<[f32; 3]> = (0..frame.n_atoms())
            .map(|i| match color_by {
                ColorBy::Property => self.style.resolve(frame, i).1,
                _ => self
                    .style
                    .rules_for(frame, i)
                    .color
                    .unwrap_or_else(|| atom_element(frame, i).color()),
            })
            .collect();
        self.kinds_into(frame, color_by, &base, kinds);
    }

    /// Every atom's material under `color_by`, into `kinds` (cleared first); `base` is each
    /// atom's colour without a colouring of its own (file column where it counts, rule,
    /// element).
    fn kinds_into(
        &mut self,
        frame: &Frame,
        color_by: ColorBy,
        base: &[[f32; 3]],
        kinds: &mut Vec<u16>,
    ) {
        kinds.clear();
        let by_type = color_by == ColorBy::Type
            || (color_by == ColorBy::Property
                && frame.colors.is_empty()
                && frame.names.is_empty()
                && !frame.types.is_empty()
                && frame.elements.iter().all(|e| e.is_unknown()));
        // The per-atom labels that pick a palette colour, if colouring by category.
        // The numbers that pick a map colour, if colouring by a scalar the frame has.
        let scalar =
            color_by == ColorBy::Scalar && self.scalar.source.values(frame, &mut self.values);
        if scalar && self.scalar.range.is_none() {
            self.scalar.range = fit_range(&self.values, None);
        }
        let range = self.scalar.range.unwrap_or((0.0, 1.0));
        let list = usize::from(color_by == ColorBy::Chain);
        let categories: Option<(&[Label], &[Label])> = match color_by {
            ColorBy::Chain if !frame.chains.is_empty() => Some((&frame.chains, &[])),
            ColorBy::Chain if !frame.segments.is_empty() => Some((&frame.segments, &[])),
            _ if by_type => Some((&frame.types, &frame.names)),
            _ => None,
        };
        let structure = if color_by == ColorBy::Structure {
            texmap_md_io::secondary::assign(frame).per_atom(frame.n_atoms())
        } else {
            Vec::new()
        };
        let crystal: Vec<[f32; 3]> = match color_by {
            ColorBy::Cna => texmap_md_io::cna::classify(frame)
                .into_iter()
                .map(|t| CNA_COLORS[t as usize])
                .collect(),
            ColorBy::Diamond => texmap_md_io::cna::classify_diamond(frame)
                .into_iter()
                .map(|t| DIAMOND_COLORS[t as usize])
                .collect(),
            _ => Vec::new(),
        };
        let cluster = match color_by {
            ColorBy::Cluster => frame.property(crate::plan::CLUSTER),
            ColorBy::Grain => frame.property(crate::plan::GRAIN),
            _ => None,
        }
        .filter(|v| v.len() == frame.n_atoms());
        let ipf: Vec<[f32; 3]> = match color_by {
            ColorBy::Ipf(axis) => ipf_colours(frame, axis),
            _ => Vec::new(),
        };
        for (i, &base_color) in base.iter().enumerate().take(frame.n_atoms()) {
            let color = match categories {
                Some((first, second)) => match self.style.rules_for(frame, i).color {
                    Some(c) => c,
                    None => {
                        // One palette colour per label, in order of appearance.
                        let label = first.get(i).or(second.get(i)).copied().unwrap_or_default();
                        let seen = &mut self.categories[list];
                        let idx = match seen.iter().position(|t| *t == label) {
                            Some(j) => j,
                            None => {
                                seen.push(label);
                                seen.len() - 1
                            }
                        };
                        type_color(idx)
                    }
                },
                None if scalar => match self.style.rules_for(frame, i).color {
                    Some(c) => c,
                    None => scalar_color(self.scalar.map, range, self.values[i]),
                },
                None if cluster.is_some() => match self.style.rules_for(frame, i).color {
                    Some(c) => c,
                    None => match cluster.map_or(-1.0, |v| v[i]) {
                        id if id >= 0.0 => type_color(id as usize),
                        _ => base_color,
                    },
                },
                None if !ipf.is_empty() => match self.style.rules_for(frame, i).color {
                    Some(c) => c,
                    None => ipf[i],
                },
                None if !crystal.is_empty() => match self.style.rules_for(frame, i).color {
                    Some(c) => c,
                    None => crystal[i],
                },
                None if !structure.is_empty() => {
                    match (structure[i], self.style.rules_for(frame, i).color) {
                        (_, Some(c)) => c,
                        (Some(ss), None) => STRUCTURE_COLORS[ss as usize],
                        (None, None) => base_color,
                    }
                }
                None => base_color,
            };
            kinds.push(self.palette.kind_of(color));
        }
    }

    /// One material per palette colour, in material order (after [`SceneBuilder::kind_of`]
    /// added some).
    pub fn refresh_materials(&self, scene: &mut SphereScene) {
        scene.materials = self.palette.materials();
    }
}

/// Every atom's inverse pole figure colour along `axis` ([`ColorBy::Ipf`]), each channel
/// rounded to eighths; "other" for atoms without a lattice orientation.
fn ipf_colours(frame: &Frame, axis: IpfAxis) -> Vec<[f32; 3]> {
    let types = texmap_md_io::cna::classify(frame);
    let fits = texmap_md_io::orientation::orientations(frame, &types);
    fits.iter()
        .map(|fit| match fit {
            Some(f) => {
                texmap_md_io::orientation::ipf_colour(f.orientation, f.symmetry, axis.vector())
                    .map(|c| (c * 7.0).round() / 7.0)
            }
            None => CNA_COLORS[0],
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(v: &[&str]) -> Vec<Label> {
        v.iter().map(|s| Label::new(s).unwrap()).collect()
    }

    #[test]
    fn rules_merge_per_selector_and_match_type_name_or_element() {
        // "O" as radius and "o" as colour: both reach the oxygen element rule.
        let st = style_from(&[("O".into(), 1.0)], &[("o".into(), [255, 0, 0])]).unwrap();
        let mut f = Frame::new();
        f.positions = vec![[0.0; 3]; 2];
        f.names = labels(&["OW", "O"]);
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
        let long = "X".repeat(Label::CAPACITY + 1);
        assert!(matches!(
            style_from(&[(long, 1.0)], &[]),
            Err(StyleError::NameTooLong { .. })
        ));
        assert!(matches!(
            style_from(&[("C".into(), -1.0)], &[]),
            Err(StyleError::Rule(_))
        ));
    }

    #[test]
    fn numeric_types_get_one_colour_each_and_scaled_radii() {
        // A LAMMPS-like frame: types only.
        let mut f = Frame::new();
        f.positions = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [3.0, 0.0, 0.0],
        ];
        f.types = labels(&["2", "1", "2", "7"]);
        let opts = StyleOptions {
            radius_scale: 0.5,
            type_radius: vec![("7".into(), 3.0)],
            ..StyleOptions::default()
        };
        let mut b = SceneBuilder::new(&opts).unwrap();
        let mut scene = SphereScene::default();
        b.build(&mut f, &mut scene);
        // Colours by type in order of appearance: "2", "1", "7".
        assert_eq!(scene.kinds, [0, 1, 0, 2]);
        let want: Vec<[u8; 3]> = (0..3)
            .map(|i| type_color(i).map(|c| (c * 255.0).round() as u8))
            .collect();
        assert_eq!(b.palette.colors(), want.as_slice());
        assert_eq!(scene.materials.len(), 3);
        // The rule's radius, scaled; the others the unknown element's, scaled.
        assert_eq!(scene.radii[3], 1.5);
        assert_eq!(scene.radii[0], Element::UNKNOWN_RADIUS * 0.5);
        assert_eq!(
            b.warnings(&f),
            [] as [StyleWarning; 0],
            "rule 7 matches a type"
        );
        let other = StyleOptions {
            type_color: vec![("Zz".into(), [1, 2, 3])],
            ..StyleOptions::default()
        };
        assert_eq!(
            SceneBuilder::new(&other).unwrap().warnings(&f),
            [StyleWarning::NoMatch {
                kind: RuleKind::Color,
                name: "Zz".into()
            }]
        );
        let bad = StyleOptions {
            radius_scale: f32::NAN,
            ..StyleOptions::default()
        };
        assert!(matches!(
            SceneBuilder::new(&bad),
            Err(StyleError::BadRadiusScale { .. })
        ));
    }

    #[test]
    fn chains_get_one_colour_each_then_segments_then_elements() {
        let mut f = Frame::new();
        f.positions = vec![[0.0; 3]; 5];
        f.names = labels(&["CA", "CA", "OW", "CA", "NA"]);
        f.chains = labels(&["B", "A", "W", "B", ""]);
        f.res_names = labels(&["ALA", "ALA", "SOL", "ALA", "NA"]);
        let opts = StyleOptions {
            color_by: ColorBy::Chain,
            type_color: vec![("NA".into(), [0, 0, 255])],
            ..StyleOptions::default()
        };
        let mut b = SceneBuilder::new(&opts).unwrap();
        let mut scene = SphereScene::default();
        b.build(&mut f, &mut scene);
        // Chains in order of appearance B, A, W; the rule wins over the blank chain.
        let want: Vec<[u8; 3]> = (0..3)
            .map(|i| type_color(i).map(|c| (c * 255.0).round() as u8))
            .chain([[0, 0, 255]])
            .collect();
        assert_eq!(scene.kinds, [0, 1, 2, 0, 3]);
        assert_eq!(b.palette.colors(), want.as_slice());
        assert!(b.warnings(&f).is_empty());
        // Segments stand in for chains; neither gives element colours and a warning.
        f.chains.clear();
        f.segments = labels(&["PROA", "PROA", "SOLV", "PROA", "IONS"]);
        let mut b = SceneBuilder::new(&opts).unwrap();
        b.build(&mut f, &mut scene);
        assert_eq!(scene.kinds, [0, 0, 1, 0, 2]);
        f.segments.clear();
        let mut b = SceneBuilder::new(&opts).unwrap();
        b.build(&mut f, &mut scene);
        assert_eq!(b.warnings(&f), [StyleWarning::NoChains]);
        let carbon = Element::from_symbol("C").unwrap().color();
        let carbon = carbon.map(|c| (c * 255.0).round() as u8);
        assert_eq!(b.palette.colors()[scene.kinds[0] as usize], carbon);
    }
}

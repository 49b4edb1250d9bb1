//! How an atom is drawn: [`atom_element`] (its element, given or guessed), [`atom_mass`] (the
//! file's mass, else the element's) and [`AtomStyle`],
//! the user's radius and colour overrides per type, name or element, over the file's own
//! columns and the element tables of [`crate::elements`].

use crate::elements::{Element, guess_element};
use crate::error::Error;
use crate::frame::{Frame, Label};

/// The element atom `i` of `frame` is drawn as: its `elements` entry when that is known, else
/// the element [`guess_element`] tells from its name (with its residue) or, without names, from
/// its type; [`Element::UNKNOWN`] when none does (or `i` is out of range).
pub fn atom_element(frame: &Frame, i: usize) -> Element {
    match frame.elements.get(i) {
        Some(e) if !e.is_unknown() => *e,
        _ => {
            let res = frame.res_names.get(i).map(|r| r.as_str());
            match (frame.names.get(i), frame.types.get(i)) {
                (Some(n), _) => guess_element(n, res, None),
                (None, Some(t)) => guess_element(t, None, None),
                (None, None) => Element::UNKNOWN,
            }
        }
    }
}

/// The mass of atom `i` of `frame` in u: the frame's `mass` property where it holds a finite
/// number (the masses a GROMACS .tpr, a LAMMPS data file, a HOOMD GSD or a DL_POLY file give:
/// united atoms, coarse-grained beads, heavy hydrogens, massless virtual sites), else the
/// standard atomic weight of [`atom_element`]'s element (0 for an unknown element).
///
/// ```
/// use texmap_md_io::{Frame, atom_mass};
/// let mut f = Frame::new();
/// f.positions = vec![[0.0; 3]; 2];
/// f.elements = vec![texmap_md_io::elements::Element::from_symbol("C").unwrap(); 2];
/// assert!((atom_mass(&f, 0) - 12.011).abs() < 1e-3);
/// f.properties.push(texmap_md_io::Property {
///     name: "mass".into(),
///     values: vec![14.027, f32::NAN], // a united-atom CH2, then no value
/// });
/// assert!((atom_mass(&f, 0) - 14.027).abs() < 1e-5);
/// assert!((atom_mass(&f, 1) - 12.011).abs() < 1e-3);
/// ```
pub fn atom_mass(frame: &Frame, i: usize) -> f64 {
    match frame.property("mass").and_then(|m| m.get(i)) {
        Some(m) if m.is_finite() => *m as f64,
        _ => atom_element(frame, i).mass(),
    }
}

/// What a user sets for a selection of atoms: radius (Å) and/or colour (sRGB in [0, 1]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Appearance {
    /// Radius in Å.
    pub radius: Option<f32>,
    /// Colour, sRGB-encoded in [0, 1].
    pub color: Option<[f32; 3]>,
}

/// Which atoms an [`AtomStyle`] rule applies to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Selector {
    /// Atoms whose type (LAMMPS `type`) is this.
    Type(Label),
    /// Atoms whose name is this.
    Name(Label),
    /// Atoms of this element.
    Element(Element),
}

/// Per-atom radius and colour for drawing a frame.
///
/// For each atom the first of these that exists wins (the OVITO order: file columns first):
/// 1. the frame's `radii` / `colors` column (from a `radius` / `color` column in the file);
/// 2. a rule for the atom's type, then for its name, then for its element (the latest rule set
///    for the same selector replaces the earlier one);
/// 3. the element table ([`Element::vdw_radius`] times [`AtomStyle::radius_scale`],
///    [`Element::color`]), the element being the frame's `elements` entry or else guessed from
///    the name (or type) by [`guess_element`];
/// 4. [`Element::UNKNOWN_RADIUS`] and [`Element::UNKNOWN_COLOR`].
///
/// Radius and colour are resolved independently (a rule may set only one of them).
///
/// A file colour is used as a colour for drawing: each channel is clamped to [0, 1] (files may
/// hold values outside it, and readers keep them as written); a file colour or radius that is not
/// finite (possible only in a frame built by hand, readers reject them) counts as absent.
#[derive(Clone, Debug, PartialEq)]
pub struct AtomStyle {
    rules: Vec<(Selector, Appearance)>,
    radius_scale: f32,
}

impl Default for AtomStyle {
    fn default() -> Self {
        AtomStyle::new()
    }
}

impl AtomStyle {
    /// No rules, table radii at scale 1.
    pub fn new() -> AtomStyle {
        AtomStyle {
            rules: Vec::new(),
            radius_scale: 1.0,
        }
    }

    /// Scale applied to table radii (not to file columns or rules), e.g. 0.3 for ball-and-stick.
    pub fn radius_scale(&self) -> f32 {
        self.radius_scale
    }

    /// Sets the scale applied to table radii; it must be finite and > 0.
    pub fn set_radius_scale(&mut self, s: f32) -> Result<(), Error> {
        if !(s.is_finite() && s > 0.0) {
            return Err(Error::InvalidValue {
                what: format!("radius scale must be finite and > 0, got {s}"),
            });
        }
        self.radius_scale = s;
        Ok(())
    }

    /// Sets (or replaces) the appearance of the atoms `sel` selects. A radius must be finite and
    /// > 0, colour channels finite and in [0, 1].
    pub fn set(&mut self, sel: Selector, look: Appearance) -> Result<(), Error> {
        if let Some(r) = look.radius
            && !(r.is_finite() && r > 0.0)
        {
            return Err(Error::InvalidValue {
                what: format!("radius must be finite and > 0, got {r}"),
            });
        }
        if let Some(c) = look.color
            && c.iter()
                .any(|v| !(v.is_finite() && (0.0..=1.0).contains(v)))
        {
            return Err(Error::InvalidValue {
                what: format!("colour channels must be in [0, 1], got {c:?}"),
            });
        }
        match self.rules.iter_mut().find(|(s, _)| *s == sel) {
            Some(slot) => slot.1 = look,
            None => self.rules.push((sel, look)),
        }
        Ok(())
    }

    fn rule(&self, sel: Selector) -> Option<&Appearance> {
        self.rules.iter().find(|(s, _)| *s == sel).map(|(_, a)| a)
    }

    /// The look the rules alone give atom `i` (step 2 of the type doc: the type rule, then the
    /// name rule, then the element rule, radius and colour each from the first rule that sets
    /// it), without file columns or tables; `None` fields where no rule applies.
    pub fn rules_for(&self, frame: &Frame, i: usize) -> Appearance {
        let sels = [
            frame.types.get(i).copied().map(Selector::Type),
            frame.names.get(i).copied().map(Selector::Name),
            Some(Selector::Element(atom_element(frame, i))),
        ];
        let mut look = Appearance::default();
        for sel in sels.into_iter().flatten() {
            if let Some(a) = self.rule(sel) {
                look.radius = look.radius.or(a.radius);
                look.color = look.color.or(a.color);
            }
        }
        look
    }

    /// Radius (Å) and colour (sRGB in [0, 1]) of atom `i` of `frame`, by the order in the type doc.
    /// `i` must be < `frame.n_atoms()`; an out-of-range `i` gets the unknown-element look.
    pub fn resolve(&self, frame: &Frame, i: usize) -> (f32, [f32; 3]) {
        // File columns: clamp colours into [0, 1]; non-finite entries count as absent.
        let mut radius = frame.radii.get(i).copied().filter(|r| r.is_finite());
        let mut color = frame
            .colors
            .get(i)
            .filter(|c| c.iter().all(|v| v.is_finite()))
            .map(|c| c.map(|v| v.clamp(0.0, 1.0)));
        // Rules: type, then name, then element.
        if radius.is_none() || color.is_none() {
            let look = self.rules_for(frame, i);
            radius = radius.or(look.radius);
            color = color.or(look.color);
        }
        // Table, with the unknown-element look built into the table accessors.
        match (radius, color) {
            (Some(r), Some(c)) => (r, c),
            (r, c) => {
                let element = atom_element(frame, i);
                (
                    r.unwrap_or_else(|| element.vdw_radius() * self.radius_scale),
                    c.unwrap_or_else(|| element.color()),
                )
            }
        }
    }

    /// Fills `radii` and `colors` (cleared first) with every atom's look, allocation-free once
    /// they have the capacity.
    pub fn apply(&self, frame: &Frame, radii: &mut Vec<f32>, colors: &mut Vec<[f32; 3]>) {
        radii.clear();
        colors.clear();
        for i in 0..frame.n_atoms() {
            let (r, c) = self.resolve(frame, i);
            radii.push(r);
            colors.push(c);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn el(s: &str) -> Element {
        Element::from_symbol(s).unwrap()
    }

    #[test]
    fn style_precedence_file_then_type_then_name_then_element_then_table() {
        let mut f = Frame::new();
        f.positions = vec![[0.0; 3]; 3];
        f.names = ["O", "H", "C"].map(|s| Label::new(s).unwrap()).to_vec();
        f.types = ["1", "2", "2"].map(|s| Label::new(s).unwrap()).to_vec();
        let mut st = AtomStyle::new();
        st.set(
            Selector::Element(el("O")),
            Appearance {
                radius: Some(9.0),
                color: Some([0.0, 0.0, 1.0]),
            },
        )
        .unwrap();
        st.set(
            Selector::Type(Label::new("1").unwrap()),
            Appearance {
                radius: Some(2.0),
                color: None,
            },
        )
        .unwrap();
        st.set(
            Selector::Name(Label::new("H").unwrap()),
            Appearance {
                radius: None,
                color: Some([1.0, 0.0, 0.0]),
            },
        )
        .unwrap();
        // Atom 0: type rule radius, element rule colour.
        assert_eq!(st.resolve(&f, 0), (2.0, [0.0, 0.0, 1.0]));
        // Atom 1: table radius for H, name rule colour.
        assert_eq!(st.resolve(&f, 1), (1.2, [1.0, 0.0, 0.0]));
        // The rules alone, without file columns: atom 0 has the type radius and element colour.
        assert_eq!(
            st.rules_for(&f, 0),
            Appearance {
                radius: Some(2.0),
                color: Some([0.0, 0.0, 1.0])
            }
        );
        assert_eq!(st.rules_for(&f, 2), Appearance::default());
        assert_eq!(atom_element(&f, 2), el("C"));
        assert_eq!(atom_element(&f, 9), Element::UNKNOWN);
        // Atom 2: table for C.
        assert_eq!(st.resolve(&f, 2), (1.77, el("C").color()));
        // File columns win over everything.
        f.radii = vec![0.5; 3];
        f.colors = vec![[0.5; 3]; 3];
        assert_eq!(st.resolve(&f, 0), (0.5, [0.5; 3]));
        // Out-of-range file colours are clamped for drawing; non-finite ones count as absent.
        f.colors[0] = [1.25, -0.5, 0.75];
        f.colors[1] = [f32::NAN, 0.0, 0.0];
        f.radii[1] = f32::INFINITY;
        assert_eq!(st.resolve(&f, 0), (0.5, [1.0, 0.0, 0.75]));
        assert_eq!(st.resolve(&f, 1), (1.2, [1.0, 0.0, 0.0]));
        assert!(
            st.set(
                Selector::Element(el("C")),
                Appearance {
                    radius: Some(-1.0),
                    color: None
                }
            )
            .is_err()
        );
        assert!(
            st.set(
                Selector::Element(el("C")),
                Appearance {
                    radius: None,
                    color: Some([2.0, 0.0, 0.0])
                }
            )
            .is_err()
        );
    }
}

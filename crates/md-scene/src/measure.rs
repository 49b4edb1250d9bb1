//! Measurements drawn in the picture, as PyMOL's `distance`, `angle` and `dihedral` show them:
//! dashed lines through two, three or four atoms and the value as a label.
//!
//! A [`Measure`] names its atoms by one selection each, every one of which must pick exactly
//! one atom in every frame. The atoms are chained through the nearest periodic images (each
//! from the one before it), so a measurement across a face of the box is the short one, and
//! the dashes are drawn along that chain (leaving the box where it does). The value:
//! - two atoms: the distance, Å;
//! - three: the angle at the middle atom, degrees in [0, 180];
//! - four: the dihedral (torsion) angle about the middle bond, degrees in (−180, 180], IUPAC's
//!   sign (positive clockwise seen along the middle bond from its first atom), as MDAnalysis's
//!   `calc_dihedrals` and PyMOL give it.
//!
//! The label sits at the middle of the dashed line (distance), at the vertex (angle) or at the
//! middle of the middle bond (dihedral).

use std::fmt;

use glam::DVec3;
use texmap_md_io::{Frame, Selection};

/// Dashes per measured segment.
pub const MEASURE_DASHES: usize = 6;
/// Radius (Å) of the dashes.
pub const MEASURE_RADIUS: f32 = 0.06;
/// The dashes' colour (sRGB): PyMOL's yellow.
pub const MEASURE_COLOR: [f32; 3] = [1.0, 1.0, 0.0];

/// One measurement: two to four atoms, each picked by a selection (the `spec` as written, for
/// messages).
#[derive(Clone, Debug)]
pub struct Measure {
    pub spec: String,
    pub atoms: Vec<Selection>,
}

/// A measurement in one frame: the chained positions (Å), the value and where its label goes.
#[derive(Clone, Debug, PartialEq)]
pub struct Measured {
    /// The atoms' indices in the frame, in the order of the selections.
    pub atoms: Vec<usize>,
    pub points: Vec<glam::Vec3>,
    /// Å for two atoms, degrees for three and four.
    pub value: f64,
    pub label_at: glam::Vec3,
}

impl Measured {
    /// The label: `2.85 Å`, `104.5°`.
    pub fn text(&self) -> String {
        if self.points.len() == 2 {
            format!("{:.2} Å", self.value)
        } else {
            format!("{:.1}°", self.value)
        }
    }
}

/// Why a measurement could not be made.
#[derive(Clone, Debug, PartialEq)]
pub enum MeasureError {
    /// Not two to four selections.
    Count { spec: String, count: usize },
    /// A selection picks no atom or several.
    NotOneAtom {
        spec: String,
        part: usize,
        picked: usize,
    },
    /// A selection could not be evaluated.
    Selection { spec: String, error: String },
    /// Two atoms of the chain coincide (no angle).
    Degenerate { spec: String },
}

impl fmt::Display for MeasureError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MeasureError::Count { spec, count } => write!(
                f,
                "{spec:?}: {count} selection(s); a measurement takes 2 (distance), 3 (angle) or 4 (dihedral), separated by ';'"
            ),
            MeasureError::NotOneAtom { spec, part, picked } => write!(
                f,
                "{spec:?}: selection {} picks {picked} atoms; each must pick exactly one",
                part + 1
            ),
            MeasureError::Selection { spec, error } => write!(f, "{spec:?}: {error}"),
            MeasureError::Degenerate { spec } => {
                write!(f, "{spec:?}: two of its atoms coincide, so it has no angle")
            }
        }
    }
}

impl std::error::Error for MeasureError {}

impl Measure {
    /// Parses `SEL; SEL[; SEL[; SEL]]`.
    pub fn parse(spec: &str) -> Result<Measure, MeasureError> {
        Measure::parse_with(spec, None)
    }

    /// Parses `SEL; SEL[; SEL[; SEL]]` with index groups for the selections' `group` keyword.
    pub fn parse_with(
        spec: &str,
        groups: Option<&texmap_md_io::ndx::IndexGroups>,
    ) -> Result<Measure, MeasureError> {
        let parts: Vec<&str> = spec.split(';').map(str::trim).collect();
        if !(2..=4).contains(&parts.len()) || parts.iter().any(|p| p.is_empty()) {
            return Err(MeasureError::Count {
                spec: spec.to_string(),
                count: parts.iter().filter(|p| !p.is_empty()).count(),
            });
        }
        let atoms = parts
            .iter()
            .map(|p| {
                Selection::parse_with(p, groups).map_err(|e| MeasureError::Selection {
                    spec: spec.to_string(),
                    error: e.to_string(),
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Measure {
            spec: spec.to_string(),
            atoms,
        })
    }

    /// The measurement in `frame`.
    pub fn measure(&self, frame: &Frame) -> Result<Measured, MeasureError> {
        let mut index = Vec::with_capacity(self.atoms.len());
        for (part, sel) in self.atoms.iter().enumerate() {
            let mask = sel.evaluate(frame).map_err(|e| MeasureError::Selection {
                spec: self.spec.clone(),
                error: e.to_string(),
            })?;
            let picked: Vec<usize> = (0..mask.len()).filter(|i| mask[*i]).collect();
            if picked.len() != 1 {
                return Err(MeasureError::NotOneAtom {
                    spec: self.spec.clone(),
                    part,
                    picked: picked.len(),
                });
            }
            index.push(picked[0]);
        }
        let at = |i: usize| DVec3::from_array(frame.positions[i].map(f64::from));
        let mut points = vec![at(index[0])];
        for w in index.windows(2) {
            let mut d = (at(w[1]) - at(w[0])).to_array();
            if let Some(cell) = &frame.cell {
                d = texmap_md_io::pbc::minimum_image(cell, d);
            }
            let prev = *points.last().expect("one point at least");
            points.push(prev + DVec3::from_array(d));
        }
        let degenerate = || MeasureError::Degenerate {
            spec: self.spec.clone(),
        };
        let (value, label_at) = match points.as_slice() {
            [a, b] => ((*b - *a).length(), (*a + *b) / 2.0),
            [a, b, c] => {
                let (u, v) = (*a - *b, *c - *b);
                if u.length() == 0.0 || v.length() == 0.0 {
                    return Err(degenerate());
                }
                let cos = u.dot(v) / (u.length() * v.length());
                (cos.clamp(-1.0, 1.0).acos().to_degrees(), *b)
            }
            [a, b, c, d] => {
                let (b1, b2, b3) = (*b - *a, *c - *b, *d - *c);
                let (n1, n2) = (b1.cross(b2), b2.cross(b3));
                if n1.length() == 0.0 || n2.length() == 0.0 {
                    return Err(degenerate());
                }
                let y = b2.length() * b1.dot(n2);
                let angle = y.atan2(n1.dot(n2)).to_degrees();
                // atan2 gives [−180, 180]: −180 is 180.
                let angle = if angle == -180.0 { 180.0 } else { angle };
                (angle, (*b + *c) / 2.0)
            }
            _ => unreachable!("2 to 4 atoms, checked in parse"),
        };
        Ok(Measured {
            atoms: index,
            points: points.iter().map(|p| p.as_vec3()).collect(),
            value,
            label_at: label_at.as_vec3(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use texmap_md_io::UnitCell;

    fn frame(p: &[[f32; 3]]) -> Frame {
        let mut f = Frame::new();
        f.positions = p.to_vec();
        f.ids = (1..=p.len() as i64).collect();
        f
    }

    #[test]
    fn distance_angle_and_dihedral_of_known_geometry() {
        // A water molecule: O-H 0.9572 Å, H-O-H 104.52°.
        let half = (104.52f64 / 2.0).to_radians();
        let (s, c) = (0.9572 * half.sin(), 0.9572 * half.cos());
        let f = frame(&[
            [0.0, 0.0, 0.0],
            [s as f32, c as f32, 0.0],
            [-s as f32, c as f32, 0.0],
        ]);
        let m = Measure::parse("index 0; index 1")
            .unwrap()
            .measure(&f)
            .unwrap();
        assert!((m.value - 0.9572).abs() < 1e-6, "{}", m.value);
        assert_eq!(m.text(), "0.96 Å");
        let m = Measure::parse("index 1; index 0; index 2")
            .unwrap()
            .measure(&f)
            .unwrap();
        assert!((m.value - 104.52).abs() < 1e-4, "{}", m.value);
        assert_eq!(m.text(), "104.5°");
        assert_eq!(m.label_at, glam::Vec3::ZERO);
        // A chain with a known torsion.
        for want in [60.0f64, -60.0, 180.0, 0.0, 120.0] {
            let t = want.to_radians();
            // b at the origin, c on +z, a in the xz plane at x = 1, d turned by t about z
            // (MDAnalysis's calc_dihedrals gives these points 60.0° for t = 60°).
            let a = [1.0, 0.0, -0.5];
            let d = [t.cos() as f32, t.sin() as f32, 2.0];
            let f = frame(&[a, [0.0, 0.0, 0.0], [0.0, 0.0, 1.5], d]);
            let m = Measure::parse("index 0; index 1; index 2; index 3")
                .unwrap()
                .measure(&f)
                .unwrap();
            assert!((m.value - want).abs() < 1e-4, "{want}: {}", m.value);
        }
    }

    #[test]
    fn across_the_box_the_short_way_and_bad_specs() {
        let mut f = frame(&[[0.5, 5.0, 5.0], [9.5, 5.0, 5.0]]);
        f.cell = Some(UnitCell::orthorhombic(10.0, 10.0, 10.0).unwrap());
        let m = Measure::parse("index 0; index 1")
            .unwrap()
            .measure(&f)
            .unwrap();
        assert!((m.value - 1.0).abs() < 1e-5);
        assert_eq!(m.points[1], glam::Vec3::new(-0.5, 5.0, 5.0));
        assert!(matches!(
            Measure::parse("index 0"),
            Err(MeasureError::Count { count: 1, .. })
        ));
        assert!(matches!(
            Measure::parse("index 0; index 1; index 0; index 1; index 0"),
            Err(MeasureError::Count { count: 5, .. })
        ));
        let e = Measure::parse("index 0; all")
            .unwrap()
            .measure(&f)
            .unwrap_err();
        assert!(
            matches!(
                e,
                MeasureError::NotOneAtom {
                    part: 1,
                    picked: 2,
                    ..
                }
            ),
            "{e}"
        );
        let e = Measure::parse("index 0; index 0; index 1")
            .unwrap()
            .measure(&f)
            .unwrap_err();
        assert!(matches!(e, MeasureError::Degenerate { .. }));
    }
}

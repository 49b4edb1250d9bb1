//! Colour by a number per atom (OVITO's colour coding, VMD's Beta/Velocity/ResID colouring,
//! PyMOL's `spectrum`): a [`ScalarSource`] gives each atom a value, a fixed range maps it to
//! [0, 1] and a [`Colormap`] to a colour.
//!
//! The range is fixed once, from the first frame drawn (the finite values of the drawn atoms)
//! unless given, so a colour means the same value in every frame of a movie. Values are
//! quantised to [`SCALAR_LEVELS`] steps, so a map takes at most that many of a scene's
//! materials; values outside the range take the end colours, and NaN (a LAMMPS `nan`) takes
//! [`NAN_COLOR`].

use texmap_md_io::Frame;

use crate::colormap::Colormap;

/// Steps of a scalar colouring (materials it may take).
pub const SCALAR_LEVELS: usize = 128;

/// The colour of an atom whose value is NaN: a neutral grey, sRGB.
pub const NAN_COLOR: [f32; 3] = [0.5, 0.5, 0.5];

/// Where an atom's number comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum ScalarSource {
    /// A property of the frame by name: `bfactor`, `occupancy`, a LAMMPS column (`c_pe`, `q`),
    /// an extended-XYZ array ([`Frame::property`]).
    Property(String),
    /// The speed |v| in Å/ps (velocities from GRO, TRR, NetCDF, LAMMPS, extended XYZ).
    Speed,
    /// The residue's position among the frame's residues (a change of residue number, name or
    /// chain starts the next): 0 for the first, 1, 2, ... (PyMOL's `spectrum count`).
    Residue,
    /// The atom index 0, 1, 2, ...
    Index,
}

impl ScalarSource {
    /// A short name for legends and messages (ASCII).
    pub fn title(&self) -> String {
        match self {
            ScalarSource::Property(n) => n.clone(),
            ScalarSource::Speed => "speed (A/ps)".into(),
            ScalarSource::Residue => "residue".into(),
            ScalarSource::Index => "atom index".into(),
        }
    }

    /// Fills `out` with one value per atom of `frame`; false (and `out` empty) when the frame
    /// lacks the source (no such property, no velocities).
    pub fn values(&self, frame: &Frame, out: &mut Vec<f32>) -> bool {
        out.clear();
        let n = frame.n_atoms();
        match self {
            ScalarSource::Property(name) => match frame.property(name) {
                Some(v) if v.len() == n => out.extend_from_slice(v),
                _ => return false,
            },
            ScalarSource::Speed => {
                if frame.velocities.len() != n {
                    return false;
                }
                out.extend(
                    frame
                        .velocities
                        .iter()
                        .map(|v| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()),
                );
            }
            ScalarSource::Residue => {
                let mut k = 0u32;
                for i in 0..n {
                    if i > 0 && new_residue(frame, i) {
                        k += 1;
                    }
                    out.push(k as f32);
                }
            }
            ScalarSource::Index => out.extend((0..n).map(|i| i as f32)),
        }
        true
    }
}

/// Whether atom `i` (> 0) starts a residue: its residue number, name or chain differs from
/// atom `i - 1`'s. A frame without residue columns has one residue per atom.
fn new_residue(frame: &Frame, i: usize) -> bool {
    if frame.res_ids.is_empty() && frame.res_names.is_empty() {
        return true;
    }
    let id = |k: usize| frame.res_ids.get(k);
    let name = |k: usize| frame.res_names.get(k);
    let chain = |k: usize| frame.chains.get(k);
    id(i) != id(i - 1) || name(i) != name(i - 1) || chain(i) != chain(i - 1)
}

/// A scalar colouring: source, map and (optionally) a fixed range.
#[derive(Clone, Debug, PartialEq)]
pub struct ScalarColor {
    pub source: ScalarSource,
    pub map: Colormap,
    /// `(low, high)`: values at or below `low` take the map's first colour, at or above `high`
    /// its last. `None`: fitted to the first frame drawn.
    pub range: Option<(f32, f32)>,
}

impl Default for ScalarColor {
    fn default() -> Self {
        ScalarColor {
            source: ScalarSource::Index,
            map: Colormap::Viridis,
            range: None,
        }
    }
}

/// The smallest and largest finite value among `values` whose `mask` entry is true (every
/// value without a mask); `None` when there is none.
pub fn fit_range(values: &[f32], mask: Option<&[bool]>) -> Option<(f32, f32)> {
    let mut lo = f32::INFINITY;
    let mut hi = f32::NEG_INFINITY;
    for (i, v) in values.iter().enumerate() {
        if mask.is_some_and(|m| !m.get(i).copied().unwrap_or(false)) || !v.is_finite() {
            continue;
        }
        lo = lo.min(*v);
        hi = hi.max(*v);
    }
    (lo <= hi).then_some((lo, hi))
}

/// The colour of `value` on `map` over `range`, quantised to [`SCALAR_LEVELS`] steps; a range
/// of one value maps everything to the middle of the map.
pub fn scalar_color(map: Colormap, range: (f32, f32), value: f32) -> [f32; 3] {
    if value.is_nan() {
        return NAN_COLOR;
    }
    let (lo, hi) = range;
    if hi <= lo || lo.is_nan() || hi.is_nan() {
        return map.srgb(0.5); // the legend's one colour for a range of one value
    }
    let t = ((value - lo) / (hi - lo)).clamp(0.0, 1.0);
    let steps = (SCALAR_LEVELS - 1) as f32;
    map.srgb((t * steps).round() / steps)
}

#[cfg(test)]
mod tests {
    use super::*;
    use texmap_md_io::Label;

    #[test]
    fn sources_range_and_colours() {
        let mut f = Frame::new();
        f.positions = vec![[0.0; 3]; 5];
        f.res_ids = vec![1, 1, 2, 2, 1];
        f.res_names = ["ALA", "ALA", "GLY", "GLY", "ALA"]
            .iter()
            .map(|s| Label::new(s).unwrap())
            .collect();
        f.velocities = vec![
            [3.0, 4.0, 0.0],
            [0.0; 3],
            [0.0, 0.0, 1.0],
            [1.0; 3],
            [0.0; 3],
        ];
        let mut v = Vec::new();
        assert!(ScalarSource::Residue.values(&f, &mut v));
        assert_eq!(
            v,
            [0.0, 0.0, 1.0, 1.0, 2.0],
            "a residue number change starts one"
        );
        assert!(ScalarSource::Speed.values(&f, &mut v));
        assert_eq!(v[0], 5.0);
        assert!(!ScalarSource::Property("bfactor".into()).values(&f, &mut v));
        assert!(v.is_empty());
        f.properties.push(texmap_md_io::Property {
            name: "bfactor".into(),
            values: vec![10.0, f32::NAN, 30.0, 50.0, 20.0],
        });
        assert!(ScalarSource::Property("bfactor".into()).values(&f, &mut v));
        assert_eq!(fit_range(&v, None), Some((10.0, 50.0)));
        let mask = [true, true, true, false, false];
        assert_eq!(fit_range(&v, Some(&mask)), Some((10.0, 30.0)));
        assert_eq!(fit_range(&[f32::NAN], None), None);
        let m = Colormap::Viridis;
        assert_eq!(scalar_color(m, (10.0, 50.0), 10.0), m.srgb(0.0));
        assert_eq!(scalar_color(m, (10.0, 50.0), 99.0), m.srgb(1.0));
        assert_eq!(scalar_color(m, (10.0, 50.0), f32::NAN), NAN_COLOR);
        assert_eq!(scalar_color(m, (7.0, 7.0), 7.0), m.srgb(0.5));
        // Quantised: at most SCALAR_LEVELS distinct colours over the range.
        let mut seen: Vec<[u32; 3]> = (0..10_000)
            .map(|k| scalar_color(m, (0.0, 1.0), k as f32 / 9999.0).map(f32::to_bits))
            .collect();
        seen.sort_unstable();
        seen.dedup();
        assert_eq!(seen.len(), SCALAR_LEVELS);
    }
}

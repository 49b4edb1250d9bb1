//! The fraction of native contacts Q(t), how much of a reference structure's contacts a frame
//! keeps: the folding coordinate of MDAnalysis's `analysis.contacts.Contacts`.
//!
//! The native contacts are the pairs (a, b), a from one group and b from another, at most
//! `radius` apart in the reference (every pair MDAnalysis's `contact_matrix` keeps: when the
//! groups overlap, an atom's pair with itself too, and both orders of a pair). A frame's Q is
//! then, over those pairs at their distances r in the frame (r0 in the reference):
//! - [`Method::HardCut`]: the share no longer than in the reference, r ≤ r0 (MDAnalysis's
//!   default, `hard_cut`: a pair that stretches at all is broken);
//! - [`Method::RadiusCut`]: the share with r ≤ `radius` (MDAnalysis's `radius_cut`);
//! - [`Method::SoftCut`]: the mean of 1 / (1 + exp(β (r − λ r0))), β = 5 Å⁻¹ and λ = 1.8 by
//!   default (Best, Hummer and Eaton 2013; MDAnalysis's `soft_cut`).
//!
//! Distances are taken to the nearest periodic image when the frame has a cell (MDAnalysis's
//! `pbc=True`), on f32 positions in f64.
//!
//! ```
//! use texmap_md_io::contacts::{Method, NativeContacts};
//! let reference = [[0.0f32, 0.0, 0.0], [3.0, 0.0, 0.0], [10.0, 0.0, 0.0]];
//! // Group a: atom 0; group b: atoms 1 and 2. Only (0, 1) is within 4.5 Å.
//! let native = NativeContacts::new(&reference, None, &[0], &[1, 2], 4.5).unwrap();
//! assert_eq!(native.pairs(), &[[0, 1]]);
//! let stretched = [[0.0f32, 0.0, 0.0], [5.0, 0.0, 0.0], [10.0, 0.0, 0.0]];
//! assert_eq!(native.q(&stretched, None, Method::RadiusCut), Ok(0.0));
//! assert_eq!(native.q(&reference, None, Method::HardCut), Ok(1.0));
//! // 3.2 Å: within the radius, but longer than the reference's 3 Å.
//! let longer = [[0.0f32, 0.0, 0.0], [3.2, 0.0, 0.0], [10.0, 0.0, 0.0]];
//! assert_eq!(native.q(&longer, None, Method::RadiusCut), Ok(1.0));
//! assert_eq!(native.q(&longer, None, Method::HardCut), Ok(0.0));
//! ```

use crate::frame::UnitCell;
use crate::pbc::NearestImage;

/// How a frame's pairs count towards Q (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Method {
    /// A pair counts when it is no longer than in the reference.
    HardCut,
    /// A pair counts when it is within the native radius.
    RadiusCut,
    /// Each pair counts 1 / (1 + exp(β (r − λ r0))).
    SoftCut { beta: f64, lambda: f64 },
}

impl Method {
    /// MDAnalysis's soft cut: β = 5 Å⁻¹, λ = 1.8.
    pub const SOFT: Method = Method::SoftCut {
        beta: 5.0,
        lambda: 1.8,
    };
}

/// Why the native contacts cannot be set up.
#[derive(Clone, Debug, PartialEq)]
pub enum ContactsError {
    /// One of the groups has no atoms.
    EmptyGroup,
    /// The two groups make more pairs than are searched (their product, the limit).
    TooManyPairs(u64, u64),
    /// The radius is not a finite number > 0.
    BadRadius(f64),
    /// An atom index past the positions.
    OutOfRange(usize),
}

impl std::fmt::Display for ContactsError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ContactsError::EmptyGroup => write!(f, "a group of contacts selects no atom"),
            ContactsError::TooManyPairs(n, most) => write!(
                f,
                "the two groups make {n} pairs, more than the {most} searched (select fewer atoms, e.g. heavy atoms or CA)"
            ),
            ContactsError::BadRadius(r) => write!(f, "a contact radius of {r} (expected > 0)"),
            ContactsError::OutOfRange(i) => write!(f, "atom {i} is past the frame's atoms"),
        }
    }
}

impl std::error::Error for ContactsError {}

/// A reference's native contacts and their distances.
#[derive(Clone, Debug)]
pub struct NativeContacts {
    pairs: Vec<[u32; 2]>,
    r0: Vec<f64>,
    radius: f64,
}

/// The distance between `p` and `q` (Å), through the nearest image when `image` is given.
fn distance(image: Option<&NearestImage>, p: [f32; 3], q: [f32; 3]) -> f64 {
    let d: [f64; 3] = std::array::from_fn(|k| q[k] as f64 - p[k] as f64);
    let d = match image {
        Some(image) => image.apply(d),
        None => d,
    };
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

impl NativeContacts {
    /// Most pairs the reference's search visits (|a| · |b|).
    pub const MAX_PAIRS: u64 = 1 << 31;

    /// The pairs of `a` × `b` within `radius` Å in `positions` (the reference; `cell` for the
    /// nearest images).
    pub fn new(
        positions: &[[f32; 3]],
        cell: Option<&UnitCell>,
        a: &[usize],
        b: &[usize],
        radius: f64,
    ) -> Result<NativeContacts, ContactsError> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(ContactsError::BadRadius(radius));
        }
        if a.is_empty() || b.is_empty() {
            return Err(ContactsError::EmptyGroup);
        }
        let n = a.len() as u64 * b.len() as u64;
        if n > Self::MAX_PAIRS {
            return Err(ContactsError::TooManyPairs(n, Self::MAX_PAIRS));
        }
        if let Some(&i) = a.iter().chain(b).find(|&&i| i >= positions.len()) {
            return Err(ContactsError::OutOfRange(i));
        }
        let image = cell.and_then(NearestImage::new);
        let (mut pairs, mut r0) = (Vec::new(), Vec::new());
        for &i in a {
            for &j in b {
                let r = distance(image.as_ref(), positions[i], positions[j]);
                if r <= radius {
                    pairs.push([i as u32, j as u32]);
                    r0.push(r);
                }
            }
        }
        Ok(NativeContacts { pairs, r0, radius })
    }

    /// The native pairs (reference atom indices), in `a`'s then `b`'s order.
    pub fn pairs(&self) -> &[[u32; 2]] {
        &self.pairs
    }

    /// The fraction of native contacts in `positions` (the frame's atoms in the reference's
    /// order); NaN without native contacts; an error when a pair's atom is past `positions`.
    pub fn q(
        &self,
        positions: &[[f32; 3]],
        cell: Option<&UnitCell>,
        method: Method,
    ) -> Result<f64, ContactsError> {
        if self.pairs.is_empty() {
            return Ok(f64::NAN);
        }
        if let Some(i) = self
            .pairs
            .iter()
            .flatten()
            .find(|&&i| i as usize >= positions.len())
        {
            return Err(ContactsError::OutOfRange(*i as usize));
        }
        let image = cell.and_then(NearestImage::new);
        let mut sum = 0.0;
        for (&[i, j], &r0) in self.pairs.iter().zip(&self.r0) {
            let r = distance(image.as_ref(), positions[i as usize], positions[j as usize]);
            sum += match method {
                Method::HardCut => f64::from(u8::from(r <= r0)),
                Method::RadiusCut => f64::from(u8::from(r <= self.radius)),
                Method::SoftCut { beta, lambda } => 1.0 / (1.0 + (beta * (r - lambda * r0)).exp()),
            };
        }
        Ok(sum / self.pairs.len() as f64)
    }
}

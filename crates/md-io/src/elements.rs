//! Element tables (van der Waals radius, CPK/Jmol colour, covalent radius) and the rule that maps
//! atom names to elements. How an atom is drawn (user overrides per type, name or element) is
//! [`crate::style`].
//!
//! # Tables
//! - Radii: S. Alvarez, "A cartography of the van der Waals territories", Dalton Trans. 42
//!   (2013) 8617, for every element it covers (H..Cf except Pm, Po..Ra). Where Alvarez gives
//!   none: M. Mantina et al., J. Phys. Chem. A 113 (2009) 5806 for Po, At, Rn, Fr, Ra, and 2.00 Å
//!   for Pm and Fm..Lr. Note Alvarez's radii are larger than Bondi's (1964) for metals (Na 2.50
//!   vs 2.27 Å) and for C (1.77 vs 1.70 Å).
//! - Colours: the Jmol CPK colours (8-bit sRGB), H..Lr.
//! - Masses: IUPAC 2016 standard atomic weights (conventional values: C 12.011, H 1.008), as
//!   ASE and MDAnalysis's mass guesser give them; for mass-weighted fits.
//! - Covalent radii: B. Cordero et al., "Covalent radii revisited", Dalton Trans. (2008) 2832,
//!   H..Cm (sp³ carbon 0.76 Å; the low-spin values for Mn, Fe, Co); Bk..Lr, which Cordero does
//!   not cover, 2.00 Å as ASE gives them. Used for bonds by distance ([`crate::bonds`]).
//!
//! All were generated from ASE 3.29 (`ase.data.vdw_alvarez`, `ase.data.colors.jmol_colors`,
//! `ase.data.covalent_radii`, `ase.data.atomic_masses`) by
//! `tests/data/gen_elements.py --rust`; `tests/elements.rs` checks every entry against the JSON
//! that script writes.
//!
//! # From an atom name to an element ([`guess_element`])
//! 1. An explicit element (PDB columns 77-78, an `element` column) wins when it is a symbol
//!    (case-insensitive: "CL", "Cl" and "cl" are chlorine).
//! 2. Leading digits are dropped ("1HB" → "HB") and the letters up to the first non-letter kept
//!    ("HG1" → "HG", "FE2+" → "FE"): call them L.
//! 3. In a standard biomolecular residue (the 20 amino acids and common protonation variants,
//!    nucleotides, water, ACE/NME caps) the element is L's first letter: "CA" is the α carbon,
//!    "HG1" a hydrogen, "OW" an oxygen.
//! 4. Otherwise, when L is exactly two letters that form a symbol, and either the name has no
//!    digits, or its second letter is lower case, or the residue name has the same letters (an
//!    ion named after itself), it is that element: "CA" alone or in residue
//!    "CA" is calcium, "Cl", "FE", "Fe2" are chlorine and iron; but "HO2" (a hydroxyl hydrogen)
//!    and "CD1" are hydrogen and carbon.
//! 5. Otherwise the first letter of L if it is a one-letter symbol (H B C N O F P S K V Y I W U),
//!    else the first two letters if they form a symbol, else [`Element::UNKNOWN`].
//!
//! Integer LAMMPS types ("1", "2") have no element: give them one with an `element` column or
//! style them by type with [`crate::AtomStyle`].

/// Standard atomic weights (IUPAC 2016, as ASE gives them) for Z = 1..=103, in u; for elements
/// without a stable isotope, the mass number of the longest-lived one.
const MASSES: [f64; 103] = [
    1.008,        // H
    4.002602,     // He
    6.94,         // Li
    9.0121831,    // Be
    10.81,        // B
    12.011,       // C
    14.007,       // N
    15.999,       // O
    18.998403163, // F
    20.1797,      // Ne
    22.98976928,  // Na
    24.305,       // Mg
    26.9815385,   // Al
    28.085,       // Si
    30.973761998, // P
    32.06,        // S
    35.45,        // Cl
    39.948,       // Ar
    39.0983,      // K
    40.078,       // Ca
    44.955908,    // Sc
    47.867,       // Ti
    50.9415,      // V
    51.9961,      // Cr
    54.938044,    // Mn
    55.845,       // Fe
    58.933194,    // Co
    58.6934,      // Ni
    63.546,       // Cu
    65.38,        // Zn
    69.723,       // Ga
    72.63,        // Ge
    74.921595,    // As
    78.971,       // Se
    79.904,       // Br
    83.798,       // Kr
    85.4678,      // Rb
    87.62,        // Sr
    88.90584,     // Y
    91.224,       // Zr
    92.90637,     // Nb
    95.95,        // Mo
    97.90721,     // Tc
    101.07,       // Ru
    102.9055,     // Rh
    106.42,       // Pd
    107.8682,     // Ag
    112.414,      // Cd
    114.818,      // In
    118.71,       // Sn
    121.76,       // Sb
    127.6,        // Te
    126.90447,    // I
    131.293,      // Xe
    132.90545196, // Cs
    137.327,      // Ba
    138.90547,    // La
    140.116,      // Ce
    140.90766,    // Pr
    144.242,      // Nd
    144.91276,    // Pm
    150.36,       // Sm
    151.964,      // Eu
    157.25,       // Gd
    158.92535,    // Tb
    162.5,        // Dy
    164.93033,    // Ho
    167.259,      // Er
    168.93422,    // Tm
    173.054,      // Yb
    174.9668,     // Lu
    178.49,       // Hf
    180.94788,    // Ta
    183.84,       // W
    186.207,      // Re
    190.23,       // Os
    192.217,      // Ir
    195.084,      // Pt
    196.966569,   // Au
    200.592,      // Hg
    204.38,       // Tl
    207.2,        // Pb
    208.9804,     // Bi
    208.98243,    // Po
    209.98715,    // At
    222.01758,    // Rn
    223.01974,    // Fr
    226.02541,    // Ra
    227.02775,    // Ac
    232.0377,     // Th
    231.03588,    // Pa
    238.02891,    // U
    237.04817,    // Np
    244.06421,    // Pu
    243.06138,    // Am
    247.07035,    // Cm
    247.07031,    // Bk
    251.07959,    // Cf
    252.083,      // Es
    257.09511,    // Fm
    258.09843,    // Md
    259.101,      // No
    262.11,       // Lr
];

/// (symbol, van der Waals radius in Å, Jmol colour as 8-bit sRGB, covalent radius in Å) for
/// Z = 1..=103.
const TABLE: [(&str, f32, [u8; 3], f32); 103] = [
    ("H", 1.20, [255, 255, 255], 0.31),
    ("He", 1.43, [217, 255, 255], 0.28),
    ("Li", 2.12, [204, 128, 255], 1.28),
    ("Be", 1.98, [194, 255, 0], 0.96),
    ("B", 1.91, [255, 181, 181], 0.84),
    ("C", 1.77, [144, 144, 144], 0.76),
    ("N", 1.66, [48, 80, 248], 0.71),
    ("O", 1.50, [255, 13, 13], 0.66),
    ("F", 1.46, [144, 224, 80], 0.57),
    ("Ne", 1.58, [179, 227, 245], 0.58),
    ("Na", 2.50, [171, 92, 242], 1.66),
    ("Mg", 2.51, [138, 255, 0], 1.41),
    ("Al", 2.25, [191, 166, 166], 1.21),
    ("Si", 2.19, [240, 200, 160], 1.11),
    ("P", 1.90, [255, 128, 0], 1.07),
    ("S", 1.89, [255, 255, 48], 1.05),
    ("Cl", 1.82, [31, 240, 31], 1.02),
    ("Ar", 1.83, [128, 209, 227], 1.06),
    ("K", 2.73, [143, 64, 212], 2.03),
    ("Ca", 2.62, [61, 255, 0], 1.76),
    ("Sc", 2.58, [230, 230, 230], 1.70),
    ("Ti", 2.46, [191, 194, 199], 1.60),
    ("V", 2.42, [166, 166, 171], 1.53),
    ("Cr", 2.45, [138, 153, 199], 1.39),
    ("Mn", 2.45, [156, 122, 199], 1.39),
    ("Fe", 2.44, [224, 102, 51], 1.32),
    ("Co", 2.40, [240, 144, 160], 1.26),
    ("Ni", 2.40, [80, 208, 80], 1.24),
    ("Cu", 2.38, [200, 128, 51], 1.32),
    ("Zn", 2.39, [125, 128, 176], 1.22),
    ("Ga", 2.32, [194, 143, 143], 1.22),
    ("Ge", 2.29, [102, 143, 143], 1.20),
    ("As", 1.88, [189, 128, 227], 1.19),
    ("Se", 1.82, [255, 161, 0], 1.20),
    ("Br", 1.86, [166, 41, 41], 1.20),
    ("Kr", 2.25, [92, 184, 209], 1.16),
    ("Rb", 3.21, [112, 46, 176], 2.20),
    ("Sr", 2.84, [0, 255, 0], 1.95),
    ("Y", 2.75, [148, 255, 255], 1.90),
    ("Zr", 2.52, [148, 224, 224], 1.75),
    ("Nb", 2.56, [115, 194, 201], 1.64),
    ("Mo", 2.45, [84, 181, 181], 1.54),
    ("Tc", 2.44, [59, 158, 158], 1.47),
    ("Ru", 2.46, [36, 143, 143], 1.46),
    ("Rh", 2.44, [10, 125, 140], 1.42),
    ("Pd", 2.15, [0, 105, 133], 1.39),
    ("Ag", 2.53, [192, 192, 192], 1.45),
    ("Cd", 2.49, [255, 217, 143], 1.44),
    ("In", 2.43, [166, 117, 115], 1.42),
    ("Sn", 2.42, [102, 128, 128], 1.39),
    ("Sb", 2.47, [158, 99, 181], 1.39),
    ("Te", 1.99, [212, 122, 0], 1.38),
    ("I", 2.04, [148, 0, 148], 1.39),
    ("Xe", 2.06, [66, 158, 176], 1.40),
    ("Cs", 3.48, [87, 23, 143], 2.44),
    ("Ba", 3.03, [0, 201, 0], 2.15),
    ("La", 2.98, [112, 212, 255], 2.07),
    ("Ce", 2.88, [255, 255, 199], 2.04),
    ("Pr", 2.92, [217, 255, 199], 2.03),
    ("Nd", 2.95, [199, 255, 199], 2.01),
    ("Pm", 2.00, [163, 255, 199], 1.99),
    ("Sm", 2.90, [143, 255, 199], 1.98),
    ("Eu", 2.87, [97, 255, 199], 1.98),
    ("Gd", 2.83, [69, 255, 199], 1.96),
    ("Tb", 2.79, [48, 255, 199], 1.94),
    ("Dy", 2.87, [31, 255, 199], 1.92),
    ("Ho", 2.81, [0, 255, 156], 1.92),
    ("Er", 2.83, [0, 230, 117], 1.89),
    ("Tm", 2.79, [0, 212, 82], 1.90),
    ("Yb", 2.80, [0, 191, 56], 1.87),
    ("Lu", 2.74, [0, 171, 36], 1.87),
    ("Hf", 2.63, [77, 194, 255], 1.75),
    ("Ta", 2.53, [77, 166, 255], 1.70),
    ("W", 2.57, [33, 148, 214], 1.62),
    ("Re", 2.49, [38, 125, 171], 1.51),
    ("Os", 2.48, [38, 102, 150], 1.44),
    ("Ir", 2.41, [23, 84, 135], 1.41),
    ("Pt", 2.29, [208, 208, 224], 1.36),
    ("Au", 2.32, [255, 209, 35], 1.36),
    ("Hg", 2.45, [184, 184, 208], 1.32),
    ("Tl", 2.47, [166, 84, 77], 1.45),
    ("Pb", 2.60, [87, 89, 97], 1.46),
    ("Bi", 2.54, [158, 79, 181], 1.48),
    ("Po", 1.97, [171, 92, 0], 1.40),
    ("At", 2.02, [117, 79, 69], 1.50),
    ("Rn", 2.20, [66, 130, 150], 1.50),
    ("Fr", 3.48, [66, 0, 102], 2.60),
    ("Ra", 2.83, [0, 125, 0], 2.21),
    ("Ac", 2.80, [112, 171, 250], 2.15),
    ("Th", 2.93, [0, 186, 255], 2.06),
    ("Pa", 2.88, [0, 161, 255], 2.00),
    ("U", 2.71, [0, 143, 255], 1.96),
    ("Np", 2.82, [0, 128, 255], 1.90),
    ("Pu", 2.81, [0, 107, 255], 1.87),
    ("Am", 2.83, [84, 92, 242], 1.80),
    ("Cm", 3.05, [120, 92, 227], 1.69),
    ("Bk", 3.40, [138, 79, 227], 2.00),
    ("Cf", 3.05, [161, 54, 212], 2.00),
    ("Es", 2.70, [179, 31, 212], 2.00),
    ("Fm", 2.00, [179, 31, 186], 2.00),
    ("Md", 2.00, [179, 13, 166], 2.00),
    ("No", 2.00, [189, 13, 135], 2.00),
    ("Lr", 2.00, [199, 0, 102], 2.00),
];

/// Index of a one- or two-letter symbol in [`SYMBOL_LUT`] (case-insensitive).
const fn symbol_slot(a: u8, b: Option<u8>) -> Option<usize> {
    let a = a.to_ascii_uppercase();
    if !a.is_ascii_uppercase() {
        return None;
    }
    let second = match b {
        None => 0,
        Some(b) => {
            let b = b.to_ascii_uppercase();
            if !b.is_ascii_uppercase() {
                return None;
            }
            (b - b'A') as usize + 1
        }
    };
    Some((a - b'A') as usize * 27 + second)
}

/// Symbol → atomic number in O(1): 26 first letters x (no second letter + 26 second letters).
const SYMBOL_LUT: [u8; 26 * 27] = {
    let mut lut = [0u8; 26 * 27];
    let mut z = 0;
    while z < TABLE.len() {
        let sym = TABLE[z].0.as_bytes();
        let b = if sym.len() == 2 { Some(sym[1]) } else { None };
        match symbol_slot(sym[0], b) {
            Some(slot) => lut[slot] = z as u8 + 1,
            None => panic!("element table symbol is not 1-2 letters"),
        }
        z += 1;
    }
    lut
};

/// A chemical element by atomic number; `Element::UNKNOWN` (0) when it could not be told.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Element(u8);

impl Element {
    /// No known element.
    pub const UNKNOWN: Element = Element(0);
    /// Radius used for unknown elements, in Å.
    pub const UNKNOWN_RADIUS: f32 = 1.5;
    /// Colour used for unknown elements (8-bit sRGB): a pink that no element has.
    pub const UNKNOWN_COLOR: [u8; 3] = [255, 20, 147];

    /// The element of atomic number `z` (1..=103), else `None`.
    pub fn from_z(z: u8) -> Option<Element> {
        (1..=TABLE.len() as u8).contains(&z).then_some(Element(z))
    }

    /// The element whose symbol is `s`, ignoring case and surrounding spaces ("fe", "FE", "Fe").
    #[inline]
    pub fn from_symbol(s: &str) -> Option<Element> {
        let s = s.trim().as_bytes();
        let slot = match *s {
            [a] => symbol_slot(a, None)?,
            [a, b] => symbol_slot(a, Some(b))?,
            _ => return None,
        };
        match SYMBOL_LUT[slot] {
            0 => None,
            z => Some(Element(z)),
        }
    }

    /// Atomic number (0 for unknown).
    pub fn z(self) -> u8 {
        self.0
    }

    /// True for [`Element::UNKNOWN`].
    pub fn is_unknown(self) -> bool {
        self.0 == 0
    }

    /// Chemical symbol ("X" for unknown).
    pub fn symbol(self) -> &'static str {
        match self.0 {
            0 => "X",
            z => TABLE[z as usize - 1].0,
        }
    }

    /// Van der Waals radius in Å (see the module doc for the sources).
    pub fn vdw_radius(self) -> f32 {
        match self.0 {
            0 => Element::UNKNOWN_RADIUS,
            z => TABLE[z as usize - 1].1,
        }
    }

    /// Covalent radius in Å (Cordero et al. 2008; see the module doc), for bonds by distance.
    /// The unknown element gets 0, so that it bonds to nothing.
    pub fn covalent_radius(self) -> f32 {
        match self.0 {
            0 => 0.0,
            z => TABLE[z as usize - 1].3,
        }
    }

    /// Standard atomic weight in u (see the module doc); 0 for the unknown element.
    pub fn mass(self) -> f64 {
        match self.0 {
            0 => 0.0,
            z => MASSES[z as usize - 1],
        }
    }

    /// Jmol CPK colour, 8-bit sRGB.
    pub fn color_srgb8(self) -> [u8; 3] {
        match self.0 {
            0 => Element::UNKNOWN_COLOR,
            z => TABLE[z as usize - 1].2,
        }
    }

    /// Jmol CPK colour as sRGB-encoded values in [0, 1] (the convention of file colour columns).
    pub fn color(self) -> [f32; 3] {
        self.color_srgb8().map(|c| c as f32 / 255.0)
    }
}

/// The element a type label names when it is a symbol written as one (`C`, `Ca`; not `CA`, an
/// aromatic carbon's type, nor `c`): LAMMPS type labels and HOOMD type names, which name
/// elements only sometimes, so no guessing from a name's first letters as [`guess_element`] does.
pub(crate) fn element_of_symbol(s: &[u8]) -> Option<Element> {
    let e = Element::from_symbol(std::str::from_utf8(s).ok()?)?;
    (e.symbol().as_bytes() == s).then_some(e)
}

/// Residues besides the protein's ([`crate::select::PROTEIN_RESIDUES`]) in which an atom
/// name's first letter is its element (rule 3 of the module doc): nucleotides, caps and
/// water.
const OTHER_BIO_RESIDUES: &[&str] = &[
    "SEC", "NMA", "NH2", "A", "C", "G", "U", "T", "DA", "DC", "DG", "DT", "DU", "RA", "RC", "RG",
    "RU", "ADE", "CYT", "GUA", "URA", "THY", "HOH", "WAT", "SOL", "TIP3", "TIP4", "TIP5", "SPC",
    "T3P", "T4P", "H2O",
];

/// True when `res` is a standard biomolecular residue (rule 3 of the module doc): every
/// residue `protein` selects ("CA" in a GROMOS LYSH is its α carbon, not calcium), nucleotides,
/// caps and water.
pub fn is_bio_residue(res: &str) -> bool {
    let r = res.trim();
    crate::select::PROTEIN_RESIDUES
        .iter()
        .chain(OTHER_BIO_RESIDUES)
        .any(|b| b.eq_ignore_ascii_case(r))
}

/// The element of an atom from its name, its residue (if the format has residues) and an
/// explicit element field (if the file has one), by the rule in the module doc.
pub fn guess_element(name: &str, residue: Option<&str>, explicit: Option<&str>) -> Element {
    // Rule 1: an explicit element column wins.
    if let Some(e) = explicit.and_then(Element::from_symbol) {
        return e;
    }
    // Rule 2: drop leading digits and keep the run of letters.
    let name = name.trim();
    let body = name.trim_start_matches(|c: char| c.is_ascii_digit());
    let n_letters = body.bytes().take_while(|b| b.is_ascii_alphabetic()).count();
    let letters = &body[..n_letters];
    if letters.is_empty() {
        return Element::UNKNOWN;
    }
    let first = Element::from_symbol(&letters[..1]);
    // Rule 3: biomolecular residues name atoms by element letter + position.
    if residue.is_some_and(is_bio_residue) {
        return first.unwrap_or(Element::UNKNOWN);
    }
    // Rule 4: an exact two-letter symbol ("CA" alone, "Cl", "Fe2").
    let two = if letters.len() >= 2 {
        Element::from_symbol(&letters[..2])
    } else {
        None
    };
    if let Some(e) = two {
        let has_digit = name.bytes().any(|b| b.is_ascii_digit());
        let second_lower = letters.as_bytes()[1].is_ascii_lowercase();
        // An ion names its residue after itself: "CA" in "CA", "FE2+" in "FE2".
        let res_letters = residue.map(|r| {
            let r = r.trim();
            &r[..r.bytes().take_while(|b| b.is_ascii_alphabetic()).count()]
        });
        let ion = res_letters.is_some_and(|r| r.eq_ignore_ascii_case(letters));
        if letters.len() == 2 && (!has_digit || second_lower || ion) {
            return e;
        }
        if second_lower && letters.len() > 2 {
            return e;
        }
    }
    // Rule 5: the first letter, else the first two.
    first.or(two).unwrap_or(Element::UNKNOWN)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn el(s: &str) -> Element {
        Element::from_symbol(s).unwrap()
    }

    #[test]
    fn type_labels_name_elements_only_as_symbols() {
        assert_eq!(element_of_symbol(b"Ca").map(|e| e.symbol()), Some("Ca"));
        assert_eq!(element_of_symbol(b"CA"), None);
        assert_eq!(element_of_symbol(b"c"), None);
        assert_eq!(element_of_symbol(b"CT"), None);
        assert_eq!(element_of_symbol(b"Colloid"), None);
    }

    #[test]
    fn symbols_round_trip() {
        for z in 1..=103u8 {
            let e = Element::from_z(z).unwrap();
            assert_eq!(Element::from_symbol(e.symbol()), Some(e));
            assert_eq!(Element::from_symbol(&e.symbol().to_uppercase()), Some(e));
        }
        assert_eq!(Element::from_z(0), None);
        assert_eq!(Element::from_z(104), None);
        assert_eq!(Element::from_symbol("Xx"), None);
    }

    #[test]
    fn name_rules_of_the_module_doc() {
        // Rule 1: explicit element column.
        assert_eq!(guess_element("CA", Some("ALA"), Some("CA")), el("Ca"));
        // Rule 3: biomolecular residues.
        assert_eq!(guess_element("CA", Some("ALA"), None), el("C"));
        assert_eq!(guess_element("1HB", Some("ALA"), None), el("H"));
        assert_eq!(guess_element("HG1", Some("THR"), None), el("H"));
        assert_eq!(guess_element("OW", Some("SOL"), None), el("O"));
        // Rule 4: exact two-letter symbols.
        assert_eq!(guess_element("CA", Some("CA"), None), el("Ca"));
        assert_eq!(guess_element("CA", None, None), el("Ca"));
        assert_eq!(guess_element("Cl", None, None), el("Cl"));
        assert_eq!(guess_element("FE2+", Some("FE2"), None), el("Fe"));
        assert_eq!(guess_element("Fe2", Some("LIG"), None), el("Fe"));
        assert_eq!(guess_element("HO2", Some("LIG"), None), el("H"));
        assert_eq!(guess_element("CD1", Some("LIG"), None), el("C"));
        // Rule 5: first letter, then two.
        assert_eq!(guess_element("C12", Some("LIG"), None), el("C"));
        assert_eq!(guess_element("Zn", None, None), el("Zn"));
        assert_eq!(guess_element("ZNA", None, None), el("Zn"));
        assert_eq!(guess_element("1", None, None), Element::UNKNOWN);
        assert_eq!(guess_element("", None, None), Element::UNKNOWN);
    }
}

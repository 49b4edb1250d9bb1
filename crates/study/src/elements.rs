//! The few chemical elements the study's scenes use, as a closed set: colours and van der Waals
//! radii come from `texmap-md-io`'s periodic table (Jmol CPK colours, Alvarez 2013 radii), the
//! one table `texmap render` also draws with, so the study and the command line draw an atom
//! alike; covalent radii for bonds by distance, masses for the MD integrator, and Seed 004's
//! particle radii are the study's own.
//!
//! # References
//! - The colour and radius table: `texmap_md_io::elements` (its module docs cite the sources).
//! - B. Cordero et al., "Covalent radii revisited", Dalton Trans. (2008) 2832 (covalent radii).
//! - Seed 004 (Kitayama et al.), the particle table of the silicate experiment.

use glam::Vec3;
use texmap_core::color::srgb8_to_linear;
use texmap_core::shade::Material;
use texmap_md_io::elements::Element as TableElement;

/// The elements used by the scenes (a closed set).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Element {
    H,
    He,
    C,
    N,
    O,
    Mg,
    Al,
    Si,
}

impl Element {
    /// Every element of the table, in table order.
    pub const ALL: [Element; 8] = [
        Element::H,
        Element::He,
        Element::C,
        Element::N,
        Element::O,
        Element::Mg,
        Element::Al,
        Element::Si,
    ];

    /// The chemical symbol.
    pub fn symbol(self) -> &'static str {
        match self {
            Element::H => "H",
            Element::He => "He",
            Element::C => "C",
            Element::N => "N",
            Element::O => "O",
            Element::Mg => "Mg",
            Element::Al => "Al",
            Element::Si => "Si",
        }
    }

    /// This element's entry in the periodic table of `texmap-md-io`.
    fn table(self) -> TableElement {
        // Every symbol of this closed set is in the table (tested below).
        TableElement::from_symbol(self.symbol()).unwrap_or(TableElement::UNKNOWN)
    }

    /// Jmol CPK colour, sRGB 8-bit.
    pub fn cpk_srgb(self) -> [u8; 3] {
        self.table().color_srgb8()
    }

    /// The CPK colour as linear RGB (what [`Material`] wants).
    pub fn cpk_linear(self) -> Vec3 {
        let [r, g, b] = self.cpk_srgb();
        Vec3::new(srgb8_to_linear(r), srgb8_to_linear(g), srgb8_to_linear(b))
    }

    /// Plastic material in the CPK colour, scaled to 0.8 so the white highlight stays visible on
    /// white hydrogen.
    pub fn material(self) -> Material {
        Material::plastic(self.cpk_linear() * 0.8)
    }

    /// Van der Waals radius in Å (Alvarez 2013, through `texmap-md-io`'s table).
    pub fn vdw_radius(self) -> f32 {
        self.table().vdw_radius()
    }

    /// Covalent (single-bond) radius in Å, Cordero et al. 2008.
    pub fn covalent_radius(self) -> f32 {
        match self {
            Element::H => 0.31,
            Element::He => 0.28,
            Element::C => 0.76,
            Element::N => 0.71,
            Element::O => 0.66,
            Element::Mg => 1.41,
            Element::Al => 1.21,
            Element::Si => 1.11,
        }
    }

    /// Atomic mass in u (used by the MD integrator).
    pub fn mass(self) -> f64 {
        match self {
            Element::H => 1.008,
            Element::He => 4.0026,
            Element::C => 12.011,
            Element::N => 14.007,
            Element::O => 15.999,
            Element::Mg => 24.305,
            Element::Al => 26.982,
            Element::Si => 28.085,
        }
    }
}

/// Seed 004's silicate system: `(element, count, radius)` per species, 1,115 particles in all.
/// The radii are the paper's display radii (Å), not van der Waals radii.
pub const SEED004_SPECIES: [(Element, usize, f32); 6] = [
    (Element::O, 409, 1.30),
    (Element::Si, 50, 1.00),
    (Element::Al, 6, 0.53),
    (Element::Mg, 50, 0.71),
    (Element::H, 500, 0.80),
    (Element::He, 100, 0.70),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seed004_table_has_1115_particles() {
        let n: usize = SEED004_SPECIES.iter().map(|s| s.1).sum();
        assert_eq!(n, 1115);
    }

    #[test]
    fn linear_colours_decode_the_srgb_table() {
        // Pure red channel 255 is linear 1; sRGB 144 (carbon grey) is linear ≈ 0.2789
        // (IEC 61966-2-1: ((144/255 + 0.055)/1.055)^2.4).
        let c = Element::C.cpk_linear();
        let expect = ((144.0f64 / 255.0 + 0.055) / 1.055).powf(2.4);
        assert!(
            (c.x as f64 - expect).abs() < 1e-5,
            "expected {expect}, got {}, tolerance 1e-5",
            c.x
        );
        assert!((Element::O.cpk_linear().x - 1.0).abs() < 1e-6);
        for e in Element::ALL {
            assert!(e.vdw_radius() > e.covalent_radius());
        }
    }

    #[test]
    fn every_element_is_in_the_periodic_table() {
        // The CLI and the study draw from the same table: carbon is Alvarez's 1.77 Å.
        for e in Element::ALL {
            assert!(!e.table().is_unknown(), "{} missing", e.symbol());
            assert_eq!(e.table().symbol(), e.symbol());
        }
        assert_eq!(Element::C.vdw_radius(), 1.77);
        assert_eq!(Element::Mg.vdw_radius(), 2.51);
    }
}

//! The input of every method: a set of spheres (structure of arrays) with their materials and
//! optional bonds.

use glam::Vec3;
use texmap_core::shade::Material;

/// A set of spheres and optional bonds (drawn as cylinders by every method).
///
/// Spheres are stored as structure-of-arrays so that transform and culling can run over lanes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SphereScene {
    pub centers: Vec<Vec3>,
    pub radii: Vec<f32>,
    /// Index into `materials` per sphere.
    pub kinds: Vec<u16>,
    /// One material per kind (element, type…); linear RGB.
    pub materials: Vec<Material>,
    /// Pairs of sphere indices joined by a cylinder of radius `bond_radius`.
    pub bonds: Vec<[u32; 2]>,
    pub bond_radius: f32,
    /// Per-bond radii, one per entry of `bonds`, when bonds differ (several draw styles in one
    /// scene); empty: every bond has `bond_radius`. A length other than `bonds.len()` makes
    /// every bond use `bond_radius`.
    pub bond_radii: Vec<f32>,
}

impl SphereScene {
    /// An empty scene with these materials (kinds index into them).
    pub fn new(materials: Vec<Material>) -> SphereScene {
        SphereScene {
            materials,
            bond_radius: 0.15,
            ..Default::default()
        }
    }

    /// The radius of bond `k`: `bond_radii[k]` when per-bond radii are given, else
    /// `bond_radius`.
    #[inline]
    pub fn bond_radius_of(&self, k: usize) -> f32 {
        if self.bond_radii.len() == self.bonds.len() {
            self.bond_radii[k]
        } else {
            self.bond_radius
        }
    }

    /// Add one sphere.
    pub fn push(&mut self, center: Vec3, radius: f32, kind: u16) {
        self.centers.push(center);
        self.radii.push(radius);
        self.kinds.push(kind);
    }

    /// Number of spheres.
    pub fn len(&self) -> usize {
        self.centers.len()
    }

    pub fn is_empty(&self) -> bool {
        self.centers.is_empty()
    }

    /// Whether sphere `i` can be drawn: finite centre, finite positive radius, known kind.
    #[inline]
    pub fn is_valid(&self, i: usize) -> bool {
        let r = self.radii[i];
        self.centers[i].is_finite()
            && r.is_finite()
            && r > 0.0
            && (self.kinds[i] as usize) < self.materials.len()
    }

    /// Axis-aligned bounds `(min, max)` of the valid spheres including their radii, or `None`
    /// when there is none.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        let mut any = false;
        for i in 0..self.len() {
            if self.is_valid(i) {
                let r = Vec3::splat(self.radii[i]);
                lo = lo.min(self.centers[i] - r);
                hi = hi.max(self.centers[i] + r);
                any = true;
            }
        }
        any.then_some((lo, hi))
    }
}

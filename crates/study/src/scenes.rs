//! The named scenes of the study, generated deterministically from a fixed seed.
//!
//! | scene | what | image |
//! |---|---|---|
//! | [`SceneId::S1`] | Seed 004's silicate system: 1,115 particles (409 O r 1.30, 50 Si r 1.00, 6 Al r 0.53, 50 Mg r 0.71, 500 H r 0.80, 100 He r 0.70) placed without overlap in a periodic box of side 30 Å | 500x500 |
//! | [`SceneId::S2`] | 100,000 spheres of radius 0.5 uniformly at random in a 100³ box, 4 materials | 1920x1080 |
//! | [`SceneId::S3`] | 1,000,000 spheres of radius 0.3 uniformly at random in a 200³ box, 4 materials | 1920x1080 |
//! | [`SceneId::Molecule`] | Seed 002's "molecule of about 300 atoms": an ideal α-helix of 30 alanines (Ala₃₀, 300 atoms with hydrogens), space-filling with CPK colours and Bondi radii, bonds by distance | 500x500 |
//! | [`SceneId::MoleculeBallStick`] | the same helix as ball and stick: atoms at [`BALL_AND_STICK_RADIUS_SCALE`] of their Bondi radii, its 299 bonds drawn (and traced by the reference) as cylinders of radius [`BALL_AND_STICK_BOND_RADIUS`] Å | 500x500 |
//!
//! **Cameras.** Every scene is seen in perspective from a fixed oblique direction
//! ([`VIEW_DIRECTION`]), looking at the centre of its box from [`EYE_DISTANCE_IN_BOX_LENGTHS`] = 2.4
//! box lengths. The horizontal field of view is chosen so that the sphere circumscribing the box
//! just fits the shorter image side: with the eye at distance `d` from the centre and the
//! circumscribed radius `ρ = (√3/2)·L`, the half-angle on the short side is `asin(ρ/d)`, which
//! gives 42.3° horizontally for the square images and 69.0° for 1920x1080 ([`framing_hfov_deg`]).
//! For the molecule the "box" is the cube whose circumscribed sphere is the molecule's bounding
//! sphere. Lighting is [`Lighting::default_for`] the camera.

use glam::{DVec3, Vec3};
use texmap_core::camera::{Camera, CameraError};
use texmap_core::shade::{Lighting, Material};
use texmap_impostor::SphereScene;

use crate::elements::{Element, SEED004_SPECIES};
use crate::rng::SplitMix64;

pub use texmap_md_scene::{BALL_AND_STICK_BOND_RADIUS, BALL_AND_STICK_RADIUS_SCALE};

/// The eye sits this many box lengths from the box centre.
pub const EYE_DISTANCE_IN_BOX_LENGTHS: f32 = 2.4;

/// Direction from the box centre toward the eye (unit after normalisation): oblique, from the
/// upper right front, so that no lattice-like alignment of the box faces the viewer.
pub const VIEW_DIRECTION: Vec3 = Vec3::new(0.45, 0.35, 1.0);

/// The seed every scene is generated from.
pub const SCENE_SEED: u64 = 0x7E57_4A90_0000_0004;

/// The named scenes (a closed set).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SceneId {
    S1,
    S2,
    S3,
    Molecule,
    /// The molecule as ball and stick: the one named scene whose bonds are drawn.
    MoleculeBallStick,
}

impl SceneId {
    pub const ALL: [SceneId; 5] = [
        SceneId::S1,
        SceneId::S2,
        SceneId::S3,
        SceneId::Molecule,
        SceneId::MoleculeBallStick,
    ];

    /// The name used in results files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SceneId::S1 => "s1",
            SceneId::S2 => "s2",
            SceneId::S3 => "s3",
            SceneId::Molecule => "molecule",
            SceneId::MoleculeBallStick => "molecule-bs",
        }
    }

    /// Parse [`SceneId::name`].
    pub fn from_name(s: &str) -> Option<SceneId> {
        SceneId::ALL.into_iter().find(|id| id.name() == s)
    }

    /// The scene's default image size.
    pub fn default_size(self) -> (u32, u32) {
        match self {
            SceneId::S1 | SceneId::Molecule | SceneId::MoleculeBallStick => (500, 500),
            SceneId::S2 | SceneId::S3 => (1920, 1080),
        }
    }
}

/// A scene ready to draw: spheres, camera and lighting.
#[derive(Clone, Debug)]
pub struct NamedScene {
    /// The name used in results files and directory names (`s1`, `s2`, …, or a file's stem).
    pub name: String,
    pub spheres: SphereScene,
    pub camera: Camera,
    pub lighting: Lighting,
    /// Draw (and let the reference trace) `spheres.bonds`: true for the ball-and-stick scene,
    /// false for the space-filling ones, whose bonds lie inside the atoms.
    pub draw_bonds: bool,
}

impl NamedScene {
    /// The scene's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// A scene of the caller's own (e.g. a trajectory frame) under a name of its choosing.
    pub fn custom(name: &str, spheres: SphereScene, camera: Camera) -> NamedScene {
        NamedScene {
            name: name.to_string(),
            lighting: Lighting::default_for(&camera),
            spheres,
            camera,
            draw_bonds: false,
        }
    }

    /// The same scene seen at another image size (same pose and field of view).
    pub fn with_size(&self, width: u32, height: u32) -> Result<NamedScene, CameraError> {
        let camera = self.camera.with_size(width, height)?;
        Ok(NamedScene {
            name: self.name.clone(),
            spheres: self.spheres.clone(),
            lighting: Lighting::default_for(&camera),
            camera,
            draw_bonds: self.draw_bonds,
        })
    }
}

/// The horizontal field of view (degrees) at which a sphere of radius `radius` at distance
/// `distance` from the eye just fits the shorter side of a `width` x `height` image.
///
/// Returns `None` unless `0 < radius < distance` and both sides are positive.
pub fn framing_hfov_deg(radius: f32, distance: f32, width: u32, height: u32) -> Option<f32> {
    if !(radius > 0.0 && distance > radius && width > 0 && height > 0) {
        return None;
    }
    // Half-angle subtended by the sphere, on the short side.
    let half = (radius as f64 / distance as f64).asin();
    let t_short = half.tan();
    // Convert to the horizontal half-angle through the aspect ratio (square pixels).
    let t_h = if width >= height {
        t_short * width as f64 / height as f64
    } else {
        t_short
    };
    Some((2.0 * t_h.atan()).to_degrees() as f32)
}

/// The study's camera for a cubic box of side `box_len` centred at `center`: eye at
/// [`EYE_DISTANCE_IN_BOX_LENGTHS`] box lengths along [`VIEW_DIRECTION`], field of view from
/// [`framing_hfov_deg`] for the box's circumscribed sphere.
pub fn box_camera(
    center: Vec3,
    box_len: f32,
    width: u32,
    height: u32,
) -> Result<Camera, CameraError> {
    let distance = EYE_DISTANCE_IN_BOX_LENGTHS * box_len;
    let radius = 0.5 * 3f32.sqrt() * box_len;
    let hfov =
        framing_hfov_deg(radius, distance, width, height).ok_or(CameraError::BadViewWidth {
            view_width: box_len,
        })?;
    let eye = center + VIEW_DIRECTION.normalize() * distance;
    Camera::perspective_look_at(eye, center, Vec3::Y, hfov, width, height)
}

/// Build a named scene at its default size.
pub fn build(id: SceneId) -> NamedScene {
    let (w, h) = id.default_size();
    build_sized(id, w, h).expect("default sizes are valid camera sizes")
}

/// Build a named scene at another image size.
pub fn build_sized(id: SceneId, width: u32, height: u32) -> Result<NamedScene, CameraError> {
    let (spheres, center, box_len) = match id {
        SceneId::S1 => {
            let sys = Seed004System::generate(SCENE_SEED);
            let c = Vec3::splat(sys.box_len as f32 * 0.5);
            let l = sys.box_len as f32;
            (sys.to_scene(&sys.positions), c, l)
        }
        SceneId::S2 => (
            random_spheres(100_000, 0.5, 100.0, SCENE_SEED ^ 2),
            Vec3::splat(50.0),
            100.0,
        ),
        SceneId::S3 => (
            random_spheres(1_000_000, 0.3, 200.0, SCENE_SEED ^ 3),
            Vec3::splat(100.0),
            200.0,
        ),
        SceneId::Molecule | SceneId::MoleculeBallStick => {
            let m = Molecule::alanine_helix(30);
            let s = if id == SceneId::Molecule {
                m.to_scene()
            } else {
                m.to_ball_and_stick(BALL_AND_STICK_RADIUS_SCALE, BALL_AND_STICK_BOND_RADIUS)
            };
            let (lo, hi) = s.bounds().expect("the molecule has atoms");
            let c = (lo + hi) * 0.5;
            // The cube whose circumscribed sphere is the bounding sphere of the atoms.
            let rho = (hi - lo).length() * 0.5;
            (s, c, rho * 2.0 / 3f32.sqrt())
        }
    };
    let camera = box_camera(center, box_len, width, height)?;
    Ok(NamedScene {
        name: id.name().to_string(),
        lighting: Lighting::default_for(&camera),
        spheres,
        camera,
        draw_bonds: id == SceneId::MoleculeBallStick,
    })
}

/// Four distinguishable plastic materials for the random scenes.
fn four_materials() -> Vec<Material> {
    [
        Vec3::new(0.75, 0.12, 0.10),
        Vec3::new(0.12, 0.35, 0.80),
        Vec3::new(0.85, 0.75, 0.20),
        Vec3::new(0.20, 0.65, 0.25),
    ]
    .into_iter()
    .map(Material::plastic)
    .collect()
}

/// `n` spheres of radius `r` with centres uniform in `[r, box_len − r]³` (overlaps allowed),
/// kinds uniform over four materials.
pub fn random_spheres(n: usize, r: f32, box_len: f32, seed: u64) -> SphereScene {
    let mut rng = SplitMix64::new(seed);
    let mut s = SphereScene::new(four_materials());
    s.centers.reserve(n);
    s.radii.reserve(n);
    s.kinds.reserve(n);
    let (lo, hi) = (r as f64, (box_len - r) as f64);
    for _ in 0..n {
        let p = Vec3::new(
            rng.range(lo, hi) as f32,
            rng.range(lo, hi) as f32,
            rng.range(lo, hi) as f32,
        );
        s.push(p, r, rng.below(4) as u16);
    }
    s
}

/// Seed 004's silicate system: 1,115 particles of six species in a periodic cubic box.
#[derive(Clone, Debug, PartialEq)]
pub struct Seed004System {
    /// Side of the periodic box (Å); positions lie in `[0, box_len)³`.
    pub box_len: f64,
    pub positions: Vec<DVec3>,
    /// Index into [`SEED004_SPECIES`] per particle.
    pub species: Vec<u8>,
}

impl Seed004System {
    /// The box side used by the study: "about 30" (Seed 004 does not state it).
    pub const BOX_LEN: f64 = 30.0;

    /// Place the 1,115 particles by random sequential addition: largest species first, each at
    /// a uniform random point whose minimum-image distance to every placed particle is at least
    /// the sum of the two display radii (spheres may touch, never overlap). The packing
    /// fraction is about 20%, far below the ~38% where random sequential addition jams, so a
    /// free spot is found within a few tries.
    pub fn generate(seed: u64) -> Seed004System {
        let l = Self::BOX_LEN;
        let mut rng = SplitMix64::new(seed);
        // Order species by decreasing radius so the big ones find room first.
        let mut order: Vec<usize> = (0..SEED004_SPECIES.len()).collect();
        order.sort_by(|&a, &b| SEED004_SPECIES[b].2.total_cmp(&SEED004_SPECIES[a].2));
        let mut positions: Vec<DVec3> = Vec::with_capacity(1115);
        let mut species: Vec<u8> = Vec::with_capacity(1115);
        for &s in &order {
            let (_, count, r) = SEED004_SPECIES[s];
            for _ in 0..count {
                // Draw candidates until one overlaps no placed particle; after many failures
                // take the last candidate (never reached at this density; keeps generation total).
                let mut p = DVec3::ZERO;
                for _attempt in 0..100_000 {
                    p = DVec3::new(rng.range(0.0, l), rng.range(0.0, l), rng.range(0.0, l));
                    let free = positions.iter().zip(&species).all(|(q, &sq)| {
                        let d = min_image(p - *q, l);
                        let contact = (r + SEED004_SPECIES[sq as usize].2) as f64;
                        d.length_squared() >= contact * contact
                    });
                    if free {
                        break;
                    }
                }
                positions.push(p);
                species.push(s as u8);
            }
        }
        Seed004System {
            box_len: l,
            positions,
            species,
        }
    }

    /// The display radius of particle `i`.
    pub fn radius(&self, i: usize) -> f32 {
        SEED004_SPECIES[self.species[i] as usize].2
    }

    /// A sphere scene of these particles at `positions` (one frame), one material per species.
    pub fn to_scene(&self, positions: &[DVec3]) -> SphereScene {
        let mats = SEED004_SPECIES.iter().map(|s| s.0.material()).collect();
        let mut scene = SphereScene::new(mats);
        for (i, p) in positions.iter().enumerate() {
            scene.push(p.as_vec3(), self.radius(i), self.species[i] as u16);
        }
        scene
    }
}

impl Seed004System {
    /// The S1 scene (camera and lighting of [`SceneId::S1`]) with the particles at an MD frame's
    /// positions (as [`crate::md::MdSystem::run`] yields them), for animations.
    pub fn frame_scene(
        &self,
        frame: &[Vec3],
        width: u32,
        height: u32,
    ) -> Result<NamedScene, CameraError> {
        let mats = SEED004_SPECIES.iter().map(|s| s.0.material()).collect();
        let mut spheres = SphereScene::new(mats);
        for (i, p) in frame.iter().enumerate().take(self.species.len()) {
            spheres.push(*p, self.radius(i), self.species[i] as u16);
        }
        let l = self.box_len as f32;
        let camera = box_camera(Vec3::splat(0.5 * l), l, width, height)?;
        Ok(NamedScene {
            name: SceneId::S1.name().to_string(),
            lighting: Lighting::default_for(&camera),
            spheres,
            camera,
            draw_bonds: false,
        })
    }
}

/// The minimum-image displacement in a periodic cube of side `l`.
#[inline]
pub(crate) fn min_image(d: DVec3, l: f64) -> DVec3 {
    d - (d / l).round() * l
}

/// A molecule: atoms, positions (Å) and bonds found by distance.
#[derive(Clone, Debug, PartialEq)]
pub struct Molecule {
    pub elements: Vec<Element>,
    pub positions: Vec<Vec3>,
    pub bonds: Vec<[u32; 2]>,
}

/// Ideal peptide geometry: standard bond lengths and angles (Engh & Huber 1991).
mod peptide {
    pub const N_CA: f64 = 1.458;
    pub const CA_C: f64 = 1.525;
    pub const C_N: f64 = 1.329;
    pub const C_O: f64 = 1.231;
    pub const N_H: f64 = 1.01;
    pub const C_H: f64 = 1.09;
    pub const CA_CB: f64 = 1.53;
    pub const ANG_N_CA_C: f64 = 111.2;
    pub const ANG_CA_C_N: f64 = 116.2;
    pub const ANG_C_N_CA: f64 = 121.7;
    pub const ANG_CA_C_O: f64 = 120.5;
    /// Right-handed α-helix backbone torsions (degrees).
    pub const PHI: f64 = -57.0;
    pub const PSI: f64 = -47.0;
    pub const OMEGA: f64 = 180.0;
    /// Half the tetrahedral angle's supplement: substituent directions lie 54.75° from the
    /// bisector of the two known bonds.
    pub const TETRA_HALF: f64 = 54.75;
}

/// Place atom D bonded to C from A, B, C given |CD|, angle BCD and torsion ABCD (degrees): the
/// natural-extension reference frame construction of chain geometry.
fn place(a: DVec3, b: DVec3, c: DVec3, bond: f64, angle_deg: f64, torsion_deg: f64) -> DVec3 {
    let (angle, torsion) = (angle_deg.to_radians(), torsion_deg.to_radians());
    // Local frame at C: x along B->C, z normal to the plane ABC, y completing it.
    let bc = (c - b).normalize();
    let n = (b - a).cross(bc).normalize();
    let m = n.cross(bc);
    let d = DVec3::new(
        -bond * angle.cos(),
        bond * angle.sin() * torsion.cos(),
        bond * angle.sin() * torsion.sin(),
    );
    c + bc * d.x + m * d.y + n * d.z
}

impl Molecule {
    /// An ideal right-handed α-helix of `residues` alanines (φ = −57°, ψ = −47°, trans
    /// peptides), with all hydrogens except the termini's extra ones: N, H, CA, HA, CB, 3 HB, C, O
    /// per residue, so 10 atoms a residue (300 for 30). Backbone by chain extension from ideal bond
    /// lengths and angles; CB/HA tetrahedral at CA; methyl hydrogens staggered. Bonds by distance:
    /// `d < 1.2 (r_cov,a + r_cov,b)`.
    pub fn alanine_helix(residues: usize) -> Molecule {
        use peptide::*;
        let mut el = Vec::with_capacity(residues * 10);
        let mut pos: Vec<DVec3> = Vec::with_capacity(residues * 10);
        // Backbone: N, CA, C of every residue, plus one extra N to orient the last carbonyl.
        let mut bb: Vec<[DVec3; 3]> = Vec::with_capacity(residues + 1);
        let n0 = DVec3::ZERO;
        let ca0 = DVec3::new(N_CA, 0.0, 0.0);
        let t = (180.0 - ANG_N_CA_C).to_radians();
        let c0 = ca0 + DVec3::new(CA_C * t.cos(), CA_C * t.sin(), 0.0);
        bb.push([n0, ca0, c0]);
        for i in 0..residues {
            let [n, ca, c] = bb[i];
            let n1 = place(n, ca, c, C_N, ANG_CA_C_N, PSI);
            let ca1 = place(ca, c, n1, N_CA, ANG_C_N_CA, OMEGA);
            let c1 = place(c, n1, ca1, CA_C, ANG_N_CA_C, PHI);
            bb.push([n1, ca1, c1]);
        }
        for i in 0..residues {
            let [n, ca, c] = bb[i];
            let n_next = bb[i + 1][0];
            // Amide hydrogen: in the peptide plane, opposite the bisector of C(prev)-N-CA.
            let h = if i == 0 {
                place(c, ca, n, N_H, 109.5, 180.0)
            } else {
                let cp = bb[i - 1][2];
                n + ((n - cp).normalize() + (n - ca).normalize()).normalize() * N_H
            };
            // CB and HA: the two remaining tetrahedral directions at CA.
            let u = ((ca - n).normalize() + (ca - c).normalize()).normalize();
            let w = (n - ca).cross(c - ca).normalize();
            let (ct, st) = (TETRA_HALF.to_radians().cos(), TETRA_HALF.to_radians().sin());
            let cb = ca + (u * ct + w * st) * CA_CB;
            let ha = ca + (u * ct - w * st) * C_H;
            // Methyl hydrogens: 109.5° at CB, staggered at 120° around the CA-CB axis.
            let axis = (cb - ca).normalize();
            let p = axis.cross(n - ca).normalize();
            let q = axis.cross(p);
            let tilt = (180.0f64 - 109.5).to_radians();
            // Carbonyl oxygen: in the plane CA-C-N(next), trans to N(next).
            let o = place(n_next, ca, c, C_O, ANG_CA_C_O, 180.0);
            el.extend([Element::N, Element::H, Element::C, Element::H, Element::C]);
            pos.extend([n, h, ca, ha, cb]);
            for k in 0..3 {
                let phi = (k as f64 * 120.0).to_radians();
                let d = axis * tilt.cos() + (p * phi.cos() + q * phi.sin()) * tilt.sin();
                el.push(Element::H);
                pos.push(cb + d * C_H);
            }
            el.extend([Element::C, Element::O]);
            pos.extend([c, o]);
        }
        // Lay the helix axis along world x, centred at the origin, so the study's oblique camera
        // sees it from the side. The axis is the difference of the centroids of two 5-turn
        // stretches of CA atoms (18 residues = 5 turns at 3.6 residues a turn).
        let ca_centroid = |r: std::ops::Range<usize>| {
            let n = r.len() as f64;
            r.map(|i| pos[i * 10 + 2]).sum::<DVec3>() / n
        };
        if residues >= 19 {
            let axis = (ca_centroid(residues - 18..residues) - ca_centroid(0..18)).normalize();
            let rot = glam::DQuat::from_rotation_arc(axis, DVec3::X);
            let centre = pos.iter().sum::<DVec3>() / pos.len() as f64;
            for p in &mut pos {
                *p = rot * (*p - centre);
            }
        }
        // Bonds by distance (O(N²) is fine for a few hundred atoms).
        let mut bonds = Vec::new();
        for i in 0..pos.len() {
            for j in i + 1..pos.len() {
                let lim = 1.2 * (el[i].covalent_radius() + el[j].covalent_radius()) as f64;
                if pos[i].distance_squared(pos[j]) < lim * lim {
                    bonds.push([i as u32, j as u32]);
                }
            }
        }
        Molecule {
            elements: el,
            positions: pos.into_iter().map(|p| p.as_vec3()).collect(),
            bonds,
        }
    }

    /// Space-filling spheres (Bondi radii, CPK colours), one material per element present, with
    /// the bonds kept for methods that draw them.
    pub fn to_scene(&self) -> SphereScene {
        let mut kinds: Vec<Element> = Vec::new();
        for e in &self.elements {
            if !kinds.contains(e) {
                kinds.push(*e);
            }
        }
        let mut s = SphereScene::new(kinds.iter().map(|e| e.material()).collect());
        for (e, p) in self.elements.iter().zip(&self.positions) {
            let k = kinds.iter().position(|x| x == e).unwrap_or(0);
            s.push(*p, e.vdw_radius(), k as u16);
        }
        s.bonds = self.bonds.clone();
        s
    }

    /// Ball and stick: [`Molecule::to_scene`] with every radius times `radius_scale` and bonds of
    /// radius `bond_radius`.
    pub fn to_ball_and_stick(&self, radius_scale: f32, bond_radius: f32) -> SphereScene {
        let mut s = self.to_scene();
        s.radii.iter_mut().for_each(|r| *r *= radius_scale);
        s.bond_radius = bond_radius;
        s
    }
}

/// `chains-100k`, the bond pass's large scene: 1,000 chains x 100 atoms (100,000 atoms r 0.4,
/// 99,000 bonds r 0.2), random walks of step 1.5 reflected into the box `[0, 100]³`, seen at
/// 1920x1080 by the box camera (as S2).
pub fn chains_100k() -> NamedScene {
    let mats = [
        Vec3::new(0.75, 0.12, 0.10),
        Vec3::new(0.12, 0.35, 0.80),
        Vec3::new(0.85, 0.75, 0.20),
    ]
    .map(Material::plastic)
    .to_vec();
    let mut s = SphereScene::new(mats);
    s.bond_radius = 0.2;
    // A small LCG: deterministic and dependency free.
    let mut state = 0x5eed_b0d5_u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    for _ in 0..1000 {
        let mut p = Vec3::new(next(), next(), next()) * 100.0;
        for k in 0..100 {
            let id = s.len() as u32;
            s.push(p, 0.4, (k % 3) as u16);
            if k > 0 {
                s.bonds.push([id - 1, id]);
            }
            // Next step: a random direction (rejection sampling in the unit ball).
            let dir = loop {
                let v = Vec3::new(next(), next(), next()) * 2.0 - Vec3::ONE;
                let l = v.length();
                if l > 0.1 && l <= 1.0 {
                    break v / l;
                }
            };
            p += dir * 1.5;
            // Reflect into the box.
            p = p.abs().map(|c| if c > 100.0 { 200.0 - c } else { c });
        }
    }
    let camera = box_camera(Vec3::splat(50.0), 100.0, 1920, 1080).expect("valid camera");
    NamedScene {
        name: "chains-100k".into(),
        lighting: Lighting::default_for(&camera),
        spheres: s,
        camera,
        draw_bonds: true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seed004_system_has_the_papers_composition_and_no_overlap() {
        let sys = Seed004System::generate(SCENE_SEED);
        assert_eq!(sys.positions.len(), 1115);
        for (k, &(_, count, _)) in SEED004_SPECIES.iter().enumerate() {
            let got = sys.species.iter().filter(|&&s| s as usize == k).count();
            assert_eq!(got, count, "species {k}");
        }
        // Brute-force check of every pair under the minimum image (independent of the placement
        // loop's early exit): no two spheres overlap by more than rounding.
        let mut worst = f64::INFINITY;
        for i in 0..sys.positions.len() {
            for j in i + 1..sys.positions.len() {
                let d = min_image(sys.positions[i] - sys.positions[j], sys.box_len).length();
                let contact = (sys.radius(i) + sys.radius(j)) as f64;
                worst = worst.min(d / contact);
            }
        }
        assert!(worst >= 1.0 - 1e-12, "closest pair at {worst} of contact");
        // Deterministic.
        assert_eq!(sys, Seed004System::generate(SCENE_SEED));
    }

    #[test]
    fn helix_has_300_atoms_a_tree_of_bonds_and_alpha_geometry() {
        let m = Molecule::alanine_helix(30);
        assert_eq!(m.elements.len(), 300);
        // 9 bonds inside each residue and one peptide bond between neighbours: 30·9 + 29.
        assert_eq!(m.bonds.len(), 30 * 9 + 29);
        // Trans peptides put consecutive CA atoms 3.80 Å apart (a classic constant).
        let ca = |i: usize| m.positions[i * 10 + 2];
        for i in 0..29 {
            let d = ca(i).distance(ca(i + 1));
            assert!(
                (d - 3.80).abs() < 0.03,
                "CA{i}-CA{}: expected 3.80, got {d}, tolerance 0.03",
                i + 1
            );
        }
        // α-helix signature: O(i) hydrogen-bonded to N(i+4) at about 2.9-3.1 Å, and a rise of
        // about 1.5 Å per residue (CA(i)→CA(i+3.6·k) spans are tested through i→i+18 = 5 turns).
        let o = |i: usize| m.positions[i * 10 + 9];
        let n = |i: usize| m.positions[i * 10];
        for i in 0..26 {
            let d = o(i).distance(n(i + 4));
            assert!((2.6..3.3).contains(&d), "O{i}..N{}: {d} Å", i + 4);
        }
        let rise = ca(0).distance(ca(18)) / 18.0;
        // The helix axis was laid along x: the 5-turn span CA(0)→CA(18) is along x.
        let along = (ca(18) - ca(0)).normalize();
        assert!(along.x.abs() > 0.99, "helix axis not along x: {along}");
        assert!(
            (rise - 1.5).abs() < 0.1,
            "rise per residue: expected 1.5, got {rise}, tolerance 0.1"
        );
    }

    #[test]
    fn framing_fov_matches_hand_values_and_scenes_build() {
        // Square image, sphere radius √3/2·L at 2.4 L: 2·asin(0.3608) = 42.30°.
        let f = framing_hfov_deg(0.5 * 3f32.sqrt(), 2.4, 500, 500).unwrap();
        assert!(
            (f - 42.30).abs() < 0.02,
            "expected 42.30, got {f}, tolerance 0.02"
        );
        let f = framing_hfov_deg(0.5 * 3f32.sqrt(), 2.4, 1920, 1080).unwrap();
        assert!(
            (f - 69.0).abs() < 0.1,
            "expected 69.0, got {f}, tolerance 0.1"
        );
        assert!(framing_hfov_deg(2.0, 1.0, 10, 10).is_none());
        let s1 = build(SceneId::S1);
        assert_eq!(s1.spheres.len(), 1115);
        // The box centre projects to the image centre.
        let (p, _) = s1.camera.project(Vec3::splat(15.0)).unwrap();
        assert!(
            (p.x - 250.0).abs() < 1e-2 && (p.y - 250.0).abs() < 1e-2,
            "{p:?}"
        );
        let m = build(SceneId::Molecule);
        assert_eq!(m.spheres.len(), 300);
        assert_eq!(m.spheres.bonds.len(), 299);
        assert!(!m.draw_bonds);
        let bs = build(SceneId::MoleculeBallStick);
        assert!(bs.draw_bonds && bs.spheres.bonds.len() == 299);
        // Every bond is thinner than both its atoms (hidden ends) and longer than their radii
        // together (a visible stick).
        for &[i, j] in &bs.spheres.bonds {
            let (ri, rj) = (bs.spheres.radii[i as usize], bs.spheres.radii[j as usize]);
            let l = (bs.spheres.centers[i as usize] - bs.spheres.centers[j as usize]).length();
            assert!(
                bs.spheres.bond_radius < ri.min(rj) && l > ri + rj,
                "bond {i}-{j}"
            );
        }
        assert_eq!(
            SceneId::from_name("molecule-bs"),
            Some(SceneId::MoleculeBallStick)
        );
        // Every atom of the molecule projects inside the image.
        for c in &m.spheres.centers {
            let (p, _) = m.camera.project(*c).unwrap();
            assert!(p.x > 0.0 && p.x < 500.0 && p.y > 0.0 && p.y < 500.0);
        }
    }
}

//! A small deterministic molecular-dynamics integrator for the demo: Seed 004's silicate
//! composition moved by Lennard-Jones forces with velocity Verlet in a periodic box.
//!
//! **Units.** Length in Å, mass in u (atomic mass units), energy in ε (the one LJ well depth shared
//! by all pairs), so time is in `τ = Å·√(u/ε)` and temperature in ε/k_B. The display radii of
//! Seed 004 set the pair sizes: `σ_ij = (r_i + r_j) / 2^{1/6}`, so that the potential minimum
//! `2^{1/6} σ_ij` is where the two displayed spheres touch.
//!
//! **Potential.** Shifted-force Lennard-Jones with a cut-off `r_c = 2.5 σ_ij`:
//! `V(r) = U(r) − U(r_c) − (r − r_c) U′(r_c)`, `U(r) = 4ε((σ/r)¹² − (σ/r)⁶)`, so that both the
//! energy and the force go to zero at `r_c` and velocity Verlet conserves energy to `O(dt²)`
//! without the spikes a truncated force gives.
//!
//! **Neighbour search.** A cell list rebuilt every step over `n³` cells with `n = ⌊L / r_c,max⌋ ≥ 3`
//! (O(N) work; buffers are allocated once). Every pair is visited exactly once (the lower index
//! owns it) in a fixed order, and Newton's third law is applied pair by pair, so the total
//! momentum is conserved to rounding.
//!
//! **Determinism.** Everything runs on one thread in a fixed order in f64; the same start and step
//! count give bit-identical positions on any machine with IEEE-754 arithmetic (no FMA contraction
//! is done by rustc without explicit `mul_add`).
//!
//! # References
//! - L. Verlet, Phys. Rev. 159 (1967) 98; W. Swope et al., J. Chem. Phys. 76 (1982) 637
//!   (velocity Verlet).
//! - M. P. Allen, D. J. Tildesley, *Computer Simulation of Liquids*, §5.3 (cell lists) and §5.2.3
//!   (shifted-force potential).
//! - Seed 004 (Kitayama et al.): 1,115 particles, 801 steps, the species table.

use glam::{DVec3, Vec3};

use crate::elements::SEED004_SPECIES;
use crate::rng::SplitMix64;
use crate::scenes::{Seed004System, min_image};

/// Why an MD run could not be set up.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum MdError {
    /// The time step is not finite and positive.
    BadTimeStep { dt: f64 },
    /// The temperature is not finite and non-negative.
    BadTemperature { temperature: f64 },
    /// The box is smaller than three cut-off lengths, so the cell list cannot work.
    BoxTooSmall { box_len: f64, cutoff: f64 },
    /// Positions and species differ in length, or a species index is unknown.
    BadSystem { particles: usize, species: usize },
}

impl std::fmt::Display for MdError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MdError::BadTimeStep { dt } => write!(f, "time step {dt} must be finite and positive"),
            MdError::BadTemperature { temperature } => {
                write!(
                    f,
                    "temperature {temperature} must be finite and non-negative"
                )
            }
            MdError::BoxTooSmall { box_len, cutoff } => write!(
                f,
                "box side {box_len} Å is less than 3 cut-offs of {cutoff} Å: the cell list needs 3 cells a side"
            ),
            MdError::BadSystem { particles, species } => write!(
                f,
                "{particles} positions but {species} species entries (or an unknown species index)"
            ),
        }
    }
}

impl std::error::Error for MdError {}

/// Run parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MdParams {
    /// Time step in τ.
    pub dt: f64,
    /// Initial temperature in ε/k_B (Maxwell–Boltzmann velocities, zero net momentum).
    pub temperature: f64,
    /// Seed for the initial velocities.
    pub seed: u64,
}

impl Default for MdParams {
    /// `dt = 0.005 τ`, `T = 1 ε/k_B`.
    fn default() -> MdParams {
        MdParams {
            dt: 0.005,
            temperature: 1.0,
            seed: 0x05EE_D004,
        }
    }
}

const N_SPECIES: usize = SEED004_SPECIES.len();
/// Cut-off in units of σ_ij.
const CUTOFF_SIGMAS: f64 = 2.5;

/// Per-pair-of-species constants of the shifted-force potential.
#[derive(Clone, Copy, Debug, Default)]
struct PairTable {
    sigma2: f64,
    rc2: f64,
    rc: f64,
    /// U(r_c).
    u_rc: f64,
    /// U′(r_c) (negative of the force magnitude at r_c).
    du_rc: f64,
}

/// The running system.
#[derive(Clone, Debug)]
pub struct MdSystem {
    box_len: f64,
    dt: f64,
    pos: Vec<DVec3>,
    vel: Vec<DVec3>,
    force: Vec<DVec3>,
    inv_mass: Vec<f64>,
    mass: Vec<f64>,
    species: Vec<u8>,
    pairs: [[PairTable; N_SPECIES]; N_SPECIES],
    cells_per_side: usize,
    /// Cell list: first particle of each cell and next particle in the same cell (`u32::MAX` ends).
    head: Vec<u32>,
    next: Vec<u32>,
    potential: f64,
    steps_done: u64,
}

impl MdSystem {
    /// Set up a run from a placed system (positions are wrapped into the box).
    pub fn new(system: &Seed004System, params: MdParams) -> Result<MdSystem, MdError> {
        if !(params.dt.is_finite() && params.dt > 0.0) {
            return Err(MdError::BadTimeStep { dt: params.dt });
        }
        if !(params.temperature.is_finite() && params.temperature >= 0.0) {
            return Err(MdError::BadTemperature {
                temperature: params.temperature,
            });
        }
        let n = system.positions.len();
        if system.species.len() != n || system.species.iter().any(|&s| s as usize >= N_SPECIES) {
            return Err(MdError::BadSystem {
                particles: n,
                species: system.species.len(),
            });
        }
        // Pair constants: σ_ij from the display radii, shifted-force terms at r_c.
        let mut pairs = [[PairTable::default(); N_SPECIES]; N_SPECIES];
        let mut rc_max = 0.0f64;
        for (a, row) in pairs.iter_mut().enumerate() {
            for (b, p) in row.iter_mut().enumerate() {
                let contact = (SEED004_SPECIES[a].2 + SEED004_SPECIES[b].2) as f64;
                let sigma = contact / 2f64.powf(1.0 / 6.0);
                let rc = CUTOFF_SIGMAS * sigma;
                let s6 = (sigma / rc).powi(6);
                *p = PairTable {
                    sigma2: sigma * sigma,
                    rc2: rc * rc,
                    rc,
                    u_rc: 4.0 * (s6 * s6 - s6),
                    du_rc: -24.0 * (2.0 * s6 * s6 - s6) / rc,
                };
                rc_max = rc_max.max(rc);
            }
        }
        let l = system.box_len;
        let cells_per_side = (l / rc_max).floor() as usize;
        if !(l.is_finite() && cells_per_side >= 3) {
            return Err(MdError::BoxTooSmall {
                box_len: l,
                cutoff: rc_max,
            });
        }
        let mass: Vec<f64> = system
            .species
            .iter()
            .map(|&s| SEED004_SPECIES[s as usize].0.mass())
            .collect();
        // Maxwell–Boltzmann velocities: each component normal with variance kT/m.
        let mut rng = SplitMix64::new(params.seed);
        let mut vel: Vec<DVec3> = mass
            .iter()
            .map(|&m| {
                let s = (params.temperature / m).sqrt();
                DVec3::new(rng.normal() * s, rng.normal() * s, rng.normal() * s)
            })
            .collect();
        // Remove the centre-of-mass velocity so the total momentum is zero.
        let total_m: f64 = mass.iter().sum();
        let p: DVec3 = vel.iter().zip(&mass).map(|(v, &m)| *v * m).sum();
        let v_cm = p / total_m;
        for v in &mut vel {
            *v -= v_cm;
        }
        let pos = system
            .positions
            .iter()
            .map(|p| *p - (*p / l).floor() * l)
            .collect();
        let mut md = MdSystem {
            box_len: l,
            dt: params.dt,
            pos,
            vel,
            force: vec![DVec3::ZERO; n],
            inv_mass: mass.iter().map(|m| 1.0 / m).collect(),
            mass,
            species: system.species.clone(),
            pairs,
            cells_per_side,
            head: vec![u32::MAX; cells_per_side.pow(3)],
            next: vec![u32::MAX; n],
            potential: 0.0,
            steps_done: 0,
        };
        md.compute_forces();
        Ok(md)
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.pos.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }

    /// Positions (Å) in `[0, L)³`.
    pub fn positions(&self) -> &[DVec3] {
        &self.pos
    }

    /// Velocities (Å/τ).
    pub fn velocities(&self) -> &[DVec3] {
        &self.vel
    }

    /// Steps taken so far.
    pub fn steps_done(&self) -> u64 {
        self.steps_done
    }

    /// Kinetic energy `Σ ½ m v²` (ε).
    pub fn kinetic_energy(&self) -> f64 {
        self.vel
            .iter()
            .zip(&self.mass)
            .map(|(v, &m)| 0.5 * m * v.length_squared())
            .sum()
    }

    /// Potential energy of the current positions (ε).
    pub fn potential_energy(&self) -> f64 {
        self.potential
    }

    /// Total momentum `Σ m v` (u·Å/τ).
    pub fn total_momentum(&self) -> DVec3 {
        self.vel.iter().zip(&self.mass).map(|(v, &m)| *v * m).sum()
    }

    /// Cell of a wrapped position.
    #[inline]
    fn cell_of(&self, p: DVec3) -> usize {
        let n = self.cells_per_side;
        let s = n as f64 / self.box_len;
        let c = |x: f64| ((x * s) as usize).min(n - 1);
        (c(p.z) * n + c(p.y)) * n + c(p.x)
    }

    /// Forces and potential energy for the current positions (cell list, each pair once).
    fn compute_forces(&mut self) {
        // Build the cell list (particles pushed in index order: fixed traversal order).
        self.head.fill(u32::MAX);
        for i in (0..self.pos.len()).rev() {
            let c = self.cell_of(self.pos[i]);
            self.next[i] = self.head[c];
            self.head[c] = i as u32;
        }
        for f in &mut self.force {
            *f = DVec3::ZERO;
        }
        let n = self.cells_per_side as isize;
        let l = self.box_len;
        let mut potential = 0.0;
        for cz in 0..n {
            for cy in 0..n {
                for cx in 0..n {
                    let c = ((cz * n + cy) * n + cx) as usize;
                    let mut i = self.head[c];
                    while i != u32::MAX {
                        let iu = i as usize;
                        let pi = self.pos[iu];
                        let si = self.species[iu] as usize;
                        // Visit the 27 neighbour cells (distinct because n ≥ 3).
                        for dz in -1..=1 {
                            for dy in -1..=1 {
                                for dx in -1..=1 {
                                    let nc = (((cz + dz).rem_euclid(n) * n
                                        + (cy + dy).rem_euclid(n))
                                        * n
                                        + (cx + dx).rem_euclid(n))
                                        as usize;
                                    let mut j = self.head[nc];
                                    while j != u32::MAX {
                                        // The lower index owns the pair: each pair once.
                                        if j > i {
                                            let ju = j as usize;
                                            let d = min_image(pi - self.pos[ju], l);
                                            let r2 = d.length_squared();
                                            let t = &self.pairs[si][self.species[ju] as usize];
                                            if r2 < t.rc2 {
                                                // Shifted-force LJ: V = U − U(rc) − (r − rc)U′(rc).
                                                let r = r2.sqrt();
                                                let s2 = t.sigma2 / r2;
                                                let s6 = s2 * s2 * s2;
                                                let u = 4.0 * (s6 * s6 - s6);
                                                potential += u - t.u_rc - (r - t.rc) * t.du_rc;
                                                // F = −dV/dr · d/r, with −dU/dr = 24(2s¹² − s⁶)/r.
                                                let fmag =
                                                    24.0 * (2.0 * s6 * s6 - s6) / r + t.du_rc;
                                                let f = d * (fmag / r);
                                                self.force[iu] += f;
                                                self.force[ju] -= f;
                                            }
                                        }
                                        j = self.next[j as usize];
                                    }
                                }
                            }
                        }
                        i = self.next[iu];
                    }
                }
            }
        }
        self.potential = potential;
    }

    /// One velocity-Verlet step: half kick, drift (wrapped), new forces, half kick.
    pub fn step(&mut self) {
        let dt = self.dt;
        let l = self.box_len;
        // Half kick and drift.
        for i in 0..self.pos.len() {
            self.vel[i] += self.force[i] * (0.5 * dt * self.inv_mass[i]);
            let p = self.pos[i] + self.vel[i] * dt;
            self.pos[i] = p - (p / l).floor() * l;
            // Rounding can put a coordinate exactly at L; fold it back to 0.
            self.pos[i] =
                DVec3::select(self.pos[i].cmpge(DVec3::splat(l)), DVec3::ZERO, self.pos[i]);
        }
        self.compute_forces();
        // Second half kick.
        for i in 0..self.pos.len() {
            self.vel[i] += self.force[i] * (0.5 * dt * self.inv_mass[i]);
        }
        self.steps_done += 1;
    }

    /// Run `steps` steps, returning the positions (as f32) before the first step and after every
    /// `every`-th step (`every` of 0 is taken as 1).
    pub fn run(&mut self, steps: usize, every: usize) -> Vec<Vec<Vec3>> {
        let every = every.max(1);
        let mut frames = vec![self.pos.iter().map(|p| p.as_vec3()).collect()];
        for s in 1..=steps {
            self.step();
            if s % every == 0 {
                frames.push(self.pos.iter().map(|p| p.as_vec3()).collect());
            }
        }
        frames
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::SCENE_SEED;

    fn start(dt: f64) -> MdSystem {
        let sys = Seed004System::generate(SCENE_SEED);
        MdSystem::new(
            &sys,
            MdParams {
                dt,
                ..MdParams::default()
            },
        )
        .unwrap()
    }

    /// Largest |E(t) − E(0)| over `steps` steps, in ε.
    fn worst_energy_error(dt: f64, steps: usize) -> (f64, f64) {
        let mut md = start(dt);
        let e0 = md.kinetic_energy() + md.potential_energy();
        let mut worst = 0.0f64;
        for _ in 0..steps {
            md.step();
            let e = md.kinetic_energy() + md.potential_energy();
            worst = worst.max((e - e0).abs());
        }
        (worst, md.kinetic_energy())
    }

    #[test]
    fn forces_are_minus_the_gradient_of_the_potential() {
        // Central finite differences of the potential (independent of the force code path)
        // against the analytic force on a few particles.
        let sys = Seed004System::generate(SCENE_SEED);
        let md = start(0.001);
        let h = 1e-5;
        for &i in &[0usize, 400, 700, 1114] {
            for axis in 0..3 {
                let energy_at = |delta: f64| {
                    let mut s = sys.clone();
                    s.positions[i][axis] += delta;
                    MdSystem::new(&s, MdParams::default())
                        .unwrap()
                        .potential_energy()
                };
                let numeric = -(energy_at(h) - energy_at(-h)) / (2.0 * h);
                let analytic = md.force[i][axis];
                let tol = 1e-5 * (1.0 + analytic.abs());
                assert!(
                    (numeric - analytic).abs() < tol,
                    "particle {i} axis {axis}: expected {numeric}, got {analytic}, tolerance {tol}"
                );
            }
        }
    }

    #[test]
    fn energy_is_conserved_and_the_error_scales_as_dt_squared() {
        // 1,115 particles at T = 1: kinetic energy ≈ 3/2 N kT ≈ 1,670 ε.
        let (e_small, ke) = worst_energy_error(0.001, 400);
        let (e_big, _) = worst_energy_error(0.002, 200);
        // Stated tolerance: over 0.4 τ at dt = 0.001 τ the total energy stays within 1e-4 of the
        // kinetic energy.
        let tol = 1e-4 * ke;
        assert!(
            e_small < tol,
            "energy error at dt=0.001: got {e_small} ε, tolerance {tol} ε"
        );
        // Velocity Verlet's energy error is O(dt²): doubling dt over the same time should multiply
        // it by about 4 (accept 2.5..6 for the fluctuating maximum).
        let ratio = e_big / e_small;
        assert!(
            (2.5..6.0).contains(&ratio),
            "error ratio for 2x dt: expected about 4, got {ratio} ({e_big} / {e_small})"
        );
    }

    #[test]
    fn momentum_is_conserved() {
        let mut md = start(0.005);
        let scale: f64 = md
            .velocities()
            .iter()
            .zip(&md.mass)
            .map(|(v, m)| v.length() * m)
            .sum();
        let p0 = md.total_momentum();
        assert!(p0.length() < 1e-12 * scale, "initial momentum {p0}");
        for _ in 0..200 {
            md.step();
        }
        let p = md.total_momentum().length();
        let tol = 1e-11 * scale;
        assert!(
            p < tol,
            "total momentum after 200 steps: got {p}, tolerance {tol}"
        );
    }

    #[test]
    fn runs_are_bit_reproducible_and_stay_in_the_box() {
        let mut a = start(0.005);
        let mut b = start(0.005);
        let fa = a.run(100, 50);
        let fb = b.run(100, 50);
        assert_eq!(fa.len(), 3);
        for (x, y) in a.positions().iter().zip(b.positions()) {
            assert_eq!(
                x.to_array().map(f64::to_bits),
                y.to_array().map(f64::to_bits)
            );
        }
        assert_eq!(fa, fb);
        for p in a.positions() {
            assert!(p.min_element() >= 0.0 && p.max_element() < 30.0, "{p}");
        }
        // A frame becomes the S1 scene with moved spheres; frame 0 is S1 itself.
        let sys = Seed004System::generate(SCENE_SEED);
        let s0 = sys.frame_scene(&fa[0], 500, 500).unwrap();
        let s1 = crate::scenes::build(crate::scenes::SceneId::S1);
        assert_eq!(s0.spheres, s1.spheres);
        assert_eq!(s0.camera, s1.camera);
        // The particles really moved.
        let moved = fa[0]
            .iter()
            .zip(&fa[2])
            .filter(|(p, q)| p.distance(**q) > 0.01)
            .count();
        assert!(moved > 1000, "{moved}");
    }

    #[test]
    fn bad_parameters_are_errors() {
        let sys = Seed004System::generate(SCENE_SEED);
        let bad_dt = MdParams {
            dt: 0.0,
            ..MdParams::default()
        };
        assert!(matches!(
            MdSystem::new(&sys, bad_dt),
            Err(MdError::BadTimeStep { .. })
        ));
        let mut small = sys.clone();
        small.box_len = 10.0;
        assert!(matches!(
            MdSystem::new(&small, MdParams::default()),
            Err(MdError::BoxTooSmall { .. })
        ));
    }
}

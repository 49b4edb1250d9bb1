//! What the benches share: a seeded generator, so each bench's input is the same on every run
//! and its peer script can be told the seed, and the adenylate kinase frame. Each bench uses
//! some of it.

/// A 64-bit linear congruential generator (Knuth's MMIX constants).
#[allow(dead_code)]
pub struct Lcg(pub u64);

#[allow(dead_code)]
impl Lcg {
    /// Uniform in [0, 1).
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Normal, by Box–Muller.
    pub fn normal(&mut self) -> f64 {
        let (u, v) = (1.0 - self.next(), self.next());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// Frame 0 of MDAnalysis's adenylate kinase in water (md-io's tests/data/hbonds: 47,681 atoms,
/// OPLS-AA names from its topology, triclinic box).
#[allow(dead_code)]
pub fn adk_frame() -> texmap::md_io::Frame {
    let dir = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/crates/md-io/tests/data/hbonds"
    );
    let top = texmap::md_io::Topology::open(format!("{dir}/adk_top.gro.gz")).unwrap();
    let mut traj = texmap::md_io::Trajectory::open(format!("{dir}/adk_0_9.xtc")).unwrap();
    let mut frame = texmap::md_io::Frame::new();
    assert!(traj.read_next(&mut frame).unwrap());
    top.apply(&mut frame, "adk_0_9.xtc", 0).unwrap();
    frame
}

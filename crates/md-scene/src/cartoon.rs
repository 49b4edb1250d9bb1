//! Protein cartoons, as VMD's NewCartoon and PyMOL's cartoon draw them: per chain, a
//! Catmull-Rom spline through the CA atoms (which it passes through exactly) swept by a cross
//! section that follows the residue's secondary structure (DSSP, [`texmap_md_io::secondary`]):
//! helices a wide flat ribbon, strands a flat band ending in an arrowhead, coil a thin tube.
//!
//! The ribbon's broad side follows each residue's CA→O direction, made perpendicular to the
//! spline and flipped where it turns by more than a right angle from the previous one (strands'
//! carbonyls alternate sides): a helix's ribbon then lies along its axis and a strand's in its
//! sheet, as in both programs. Every cross section is an ellipse of [`RING`] vertices, so
//! sections of different shapes join without a crack; normals are the ellipse's. An arrowhead
//! starts with a flat back face at the last strand residue and narrows to the coil at the next.
//! Each trace is closed by end caps, so the mesh is closed and wound outward.
//!
//! A trace breaks where the chain or segment changes, at a peptide bond DSSP finds broken, or
//! where a residue is not selected; a lone residue draws nothing. Each half interval takes the
//! material of its nearer CA atom, so colour rules and every colouring reach the cartoon.
//!
//! Nucleic acids, as VMD's NewCartoon draws them: a coil tube along the spline through each
//! strand's P atoms (broken where the chain changes or two are more than
//! [`crate::plan::MAX_P_GAP`] apart) and a rung per nucleotide from its P to the base atom at
//! the pairing edge (N1 of a purine, N3 of a pyrimidine; N1 when the residue has neither), so
//! the rungs of paired bases meet across the double helix.

use glam::Vec3;
use texmap_md_io::Frame;
use texmap_md_io::secondary::{self, Structure};
use texmap_md_io::select::NUCLEIC_RESIDUES;

use crate::surface::MolMesh;

/// Vertices per cross section.
pub const RING: usize = 12;
/// Spline samples per CA-CA interval.
pub const SUBDIVISIONS: usize = 8;
/// Coil tube radius (Å), the tube style's.
pub const COIL_RADIUS: f32 = crate::plan::TUBE_RADIUS;
/// Helix ribbon half width and half thickness (Å).
pub const HELIX: (f32, f32) = (1.1, 0.25);
/// Strand band half width and half thickness (Å).
pub const STRAND: (f32, f32) = (0.9, 0.25);
/// Half width of an arrowhead's base (Å).
pub const ARROW: f32 = 1.5;

/// One CA of a trace: where it is, its carbonyl O, its class and material.
#[derive(Clone, Copy, Debug)]
struct Residue {
    ca: Vec3,
    o: Vec3,
    class: Structure,
    kind: u16,
}

/// A point of the spline with its frame and cross section.
#[derive(Clone, Copy, Debug)]
struct Section {
    at: Vec3,
    /// Unit tangent, and the unit side (the section's broad axis) perpendicular to it.
    t: Vec3,
    side: Vec3,
    /// Half width (along `side`) and half thickness.
    a: f32,
    b: f32,
    kind: u16,
}

/// The cartoon of `frame`'s protein residues whose CA `selected` keeps (and nucleotides whose P
/// it keeps), positions from `centers` (the frame's, after the plan's alignment) and materials
/// from `kinds` (per atom), appended to `mesh`. Returns the residues drawn (in traces of two or
/// more).
pub fn append_cartoon(
    frame: &Frame,
    centers: &[Vec3],
    kinds: &[u16],
    selected: &[bool],
    mesh: &mut MolMesh,
) -> usize {
    let ss = secondary::assign(frame);
    let mut traces: Vec<Vec<Residue>> = Vec::new();
    let mut joined = false;
    for (r, &class) in ss.residues().iter().zip(ss.classes()) {
        let [_, ca, _, o] = r.backbone;
        if ca >= centers.len() || o >= centers.len() || !selected.get(ca).copied().unwrap_or(false)
        {
            joined = false;
            continue;
        }
        let res = Residue {
            ca: centers[ca],
            o: centers[o],
            class,
            kind: kinds.get(ca).copied().unwrap_or(0),
        };
        let near = traces
            .last()
            .and_then(|t| t.last())
            .is_some_and(|p| p.ca.distance(res.ca) <= crate::plan::MAX_CA_GAP);
        match traces.last_mut() {
            Some(t) if joined && !r.starts_piece && near => t.push(res),
            _ => traces.push(vec![res]),
        }
        joined = true;
    }
    sweep_traces(&traces, mesh) + append_nucleic(frame, centers, kinds, selected, mesh)
}

/// Sweeps every trace of two or more residues into `mesh`; returns the residues they hold.
fn sweep_traces(traces: &[Vec<Residue>], mesh: &mut MolMesh) -> usize {
    let mut drawn = 0;
    for trace in traces.iter().filter(|t| t.len() >= 2) {
        sweep(&sections(trace), mesh);
        drawn += trace.len();
    }
    drawn
}

/// The nucleic-acid part of [`append_cartoon`]: P traces and base rungs. Returns the
/// nucleotides drawn.
fn append_nucleic(
    frame: &Frame,
    centers: &[Vec3],
    kinds: &[u16],
    selected: &[bool],
    mesh: &mut MolMesh,
) -> usize {
    if frame.names.len() != frame.n_atoms() || centers.len() != frame.n_atoms() {
        return 0;
    }
    let label = |v: &[texmap_md_io::Label], i: usize| v.get(i).copied();
    let mut traces: Vec<Vec<Residue>> = Vec::new();
    let mut rungs: Vec<(Vec3, Vec3, u16)> = Vec::new();
    let mut last_p: Option<usize> = None;
    for range in secondary::residue_ranges(frame) {
        if !NUCLEIC_RESIDUES.contains(&frame.res_names[range.start].as_str()) {
            continue;
        }
        let find = |name: &str| range.clone().find(|&i| frame.names[i] == name);
        let Some(p) = find("P").filter(|&p| selected.get(p).copied().unwrap_or(false)) else {
            continue;
        };
        let res = Residue {
            ca: centers[p],
            o: centers[p],
            class: Structure::Coil,
            kind: kinds.get(p).copied().unwrap_or(0),
        };
        let joined = last_p.is_some_and(|q| {
            label(&frame.chains, p) == label(&frame.chains, q)
                && label(&frame.segments, p) == label(&frame.segments, q)
                && centers[p].distance(centers[q]) <= crate::plan::MAX_P_GAP
        });
        match traces.last_mut() {
            Some(t) if joined => t.push(res),
            _ => traces.push(vec![res]),
        }
        last_p = Some(p);
        let edge = if find("N9").is_some() { "N1" } else { "N3" };
        if let Some(b) = find(edge).or_else(|| find("N1")) {
            rungs.push((centers[p], centers[b], res.kind));
        }
    }
    let drawn = sweep_traces(&traces, mesh);
    for &(from, to, kind) in &rungs {
        let Some(t) = (to - from).try_normalize() else {
            continue;
        };
        let end = |at| Section {
            at,
            t,
            side: t.any_orthonormal_vector(),
            a: COIL_RADIUS,
            b: COIL_RADIUS,
            kind,
        };
        sweep(&[end(from), end(to)], mesh);
    }
    drawn
}

/// Point and derivative of the uniform Catmull-Rom spline through `p1` and `p2` at `t`.
pub(crate) fn catmull_rom(p0: Vec3, p1: Vec3, p2: Vec3, p3: Vec3, t: f32) -> (Vec3, Vec3) {
    let (t2, t3) = (t * t, t * t * t);
    let (c1, c2, c3) = (
        p2 - p0,
        2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3,
        3.0 * p1 - p0 - 3.0 * p2 + p3,
    );
    let at = 0.5 * (2.0 * p1 + c1 * t + c2 * t2 + c3 * t3);
    let d = 0.5 * (c1 + 2.0 * c2 * t + 3.0 * c3 * t2);
    (at, d)
}

/// The shape of a class: half width and half thickness.
fn shape(class: Structure) -> (f32, f32) {
    match class {
        Structure::Helix => HELIX,
        Structure::Strand => STRAND,
        Structure::Coil => (COIL_RADIUS, COIL_RADIUS),
    }
}

/// `v` made perpendicular to the unit `t` and unit (`fallback` when `v` lies along `t`).
fn across(v: Vec3, t: Vec3, fallback: Vec3) -> Vec3 {
    (v - t * v.dot(t))
        .try_normalize()
        .or_else(|| (fallback - t * fallback.dot(t)).try_normalize())
        .unwrap_or_else(|| t.any_orthonormal_vector())
}

/// The sections of one trace (two or more residues), start to end; an arrowhead's base is two
/// sections at one point.
fn sections(trace: &[Residue]) -> Vec<Section> {
    let n = trace.len();
    let p = |k: isize| -> Vec3 {
        match k {
            -1 => 2.0 * trace[0].ca - trace[1].ca,
            k if k as usize >= n => 2.0 * trace[n - 1].ca - trace[n - 2].ca,
            k => trace[k as usize].ca,
        }
    };
    // Each residue's side: CA→O across the chord through its neighbours, sign-continued.
    let mut sides: Vec<Vec3> = Vec::with_capacity(n);
    for (k, r) in trace.iter().enumerate() {
        let t = (p(k as isize + 1) - p(k as isize - 1)).normalize_or(Vec3::X);
        let prev = sides.last().copied();
        let mut s = across(r.o - r.ca, t, prev.unwrap_or(Vec3::Y));
        if prev.is_some_and(|q| q.dot(s) < 0.0) {
            s = -s;
        }
        sides.push(s);
    }
    let mut out = Vec::with_capacity((n - 1) * SUBDIVISIONS + 2);
    for i in 0..n - 1 {
        let ends_strand =
            trace[i].class == Structure::Strand && trace[i + 1].class != Structure::Strand;
        let (p0, p1, p2, p3) = (
            p(i as isize - 1),
            p(i as isize),
            p(i as isize + 1),
            p(i as isize + 2),
        );
        let last = i + 2 == n;
        for s in 0..SUBDIVISIONS + last as usize {
            let u = s as f32 / SUBDIVISIONS as f32;
            let (at, d) = catmull_rom(p0, p1, p2, p3, u);
            let t = d.normalize_or(p2 - p1).normalize_or(Vec3::X);
            let side = across(sides[i].lerp(sides[i + 1], u), t, sides[i]);
            let near = if u < 0.5 { i } else { i + 1 };
            let (a, b) = if ends_strand {
                // The arrowhead: from its base at residue i down to the next residue's shape.
                let (a1, b1) = shape(trace[i + 1].class);
                (ARROW + (a1 - ARROW) * u, STRAND.1 + (b1 - STRAND.1) * u)
            } else {
                shape(trace[near].class)
            };
            let section = Section {
                at,
                t,
                side,
                a,
                b,
                kind: trace[near].kind,
            };
            if ends_strand && s == 0 {
                // The band's own section first, then the base at the same point.
                out.push(Section {
                    a: STRAND.0,
                    b: STRAND.1,
                    kind: trace[i].kind,
                    ..section
                });
                out.push(Section {
                    kind: trace[i].kind,
                    ..section
                });
            } else {
                out.push(section);
            }
        }
    }
    out
}

/// Appends the swept tube through `sections` to `mesh`: rings joined by quads, a flat face
/// where two consecutive sections share a point (an arrowhead's base), and end caps.
fn sweep(sections: &[Section], mesh: &mut MolMesh) {
    let ring = |m: &mut MolMesh, s: &Section, flat: Option<Vec3>| -> u32 {
        let first = m.positions.len() as u32;
        let bv = s.t.cross(s.side);
        for j in 0..RING {
            let th = std::f32::consts::TAU * j as f32 / RING as f32;
            let (sin, cos) = th.sin_cos();
            m.positions
                .push(s.at + s.side * (s.a * cos) + bv * (s.b * sin));
            let n = flat.unwrap_or_else(|| (s.side * (cos / s.a) + bv * (sin / s.b)).normalize());
            m.normals.push(n);
        }
        first
    };
    let join = |m: &mut MolMesh, r0: u32, r1: u32, kind: u16| {
        for j in 0..RING as u32 {
            let k = (j + 1) % RING as u32;
            m.triangles.push([r0 + j, r0 + k, r1 + k]);
            m.triangles.push([r0 + j, r1 + k, r1 + j]);
            m.kinds.extend([kind, kind]);
        }
    };
    let cap = |m: &mut MolMesh, s: &Section, outward: Vec3| {
        let r = ring(m, s, Some(outward));
        let centre = m.positions.len() as u32;
        m.positions.push(s.at);
        m.normals.push(outward);
        for j in 0..RING as u32 {
            let k = (j + 1) % RING as u32;
            // Counter-clockwise seen along `outward`: the ring runs from side toward t × side.
            let tri = if outward.dot(s.t) > 0.0 {
                [centre, r + j, r + k]
            } else {
                [centre, r + k, r + j]
            };
            m.triangles.push(tri);
            m.kinds.push(s.kind);
        }
    };
    let (first, last) = (sections[0], sections[sections.len() - 1]);
    cap(mesh, &first, -first.t);
    let mut prev = ring(mesh, &first, None);
    for w in sections.windows(2) {
        let (s0, s1) = (w[0], w[1]);
        if s0.at == s1.at {
            // A flat face between two sections at one point, facing back along the spline.
            let back = -s1.t;
            let r0 = ring(mesh, &s0, Some(back));
            let r1 = ring(mesh, &s1, Some(back));
            join(mesh, r0, r1, s1.kind);
            prev = ring(mesh, &s1, None);
            continue;
        }
        let next = ring(mesh, &s1, None);
        join(mesh, prev, next, s0.kind);
        prev = next;
    }
    cap(mesh, &last, last.t);
}

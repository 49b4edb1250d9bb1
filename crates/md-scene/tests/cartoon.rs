//! Protein cartoons (`md_scene::cartoon`) on wwPDB 3GWI chain A (md-io's DSSP test data, whose
//! assignment equals MDAnalysis's): the mesh's shape against the CA trace and DSSP's classes.

use glam::Vec3;
use std::collections::HashMap;
use texmap_md_io::secondary::{self, Structure};
use texmap_md_io::{Frame, Trajectory};
use texmap_md_scene::cartoon::{ARROW, COIL_RADIUS, HELIX, STRAND, append_cartoon};
use texmap_md_scene::surface::MolMesh;

use crate::common;

fn read(name: &str) -> Frame {
    let path = format!(
        "{}/../md-io/tests/data/dssp/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    let mut t = Trajectory::open(&path).unwrap();
    let mut f = Frame::new();
    t.read_frame(0, &mut f).unwrap();
    f
}

/// 3GWI A's cartoon with each atom's kind its residue's class (0 coil, 1 helix, 2 strand; 3 for
/// atoms outside residues with a backbone).
fn cartoon(selected: &[bool]) -> (Frame, MolMesh, usize) {
    let f = read("3gwiA.pdb.gz");
    let centers: Vec<Vec3> = f.positions.iter().map(|p| Vec3::from(*p)).collect();
    let kinds: Vec<u16> = secondary::assign(&f)
        .per_atom(f.n_atoms())
        .iter()
        .map(|c| c.map_or(3, |c| c as u16))
        .collect();
    let mut m = MolMesh::default();
    let n = append_cartoon(&f, &centers, &kinds, selected, &mut m);
    (f, m, n)
}

#[test]
fn the_cartoon_is_closed_and_wraps_the_ca_trace() {
    let f = read("3gwiA.pdb.gz");
    let (_, m, drawn) = cartoon(&vec![true; f.n_atoms()]);
    let ss = secondary::assign(&f);
    assert!(drawn > 0 && drawn <= ss.residues().len());
    // Closed: with vertices merged by position, every directed edge has its reverse as often.
    let mut id: HashMap<[i64; 3], u32> = HashMap::new();
    let key = |p: Vec3| (p * 1e4).round().as_i64vec3().to_array();
    let merged: Vec<u32> = m
        .positions
        .iter()
        .map(|p| {
            let n = id.len() as u32;
            *id.entry(key(*p)).or_insert(n)
        })
        .collect();
    let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
    for t in &m.triangles {
        let t = t.map(|i| merged[i as usize]);
        for k in 0..3 {
            *edges.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            *edges.entry((t[(k + 1) % 3], t[k])).or_default() -= 1;
        }
    }
    assert!(edges.values().all(|&v| v == 0), "an edge without its twin");
    // Wound outward: the volume is positive, and about a tube of each shape's cross section
    // along the trace (between the coil's and the arrowhead's).
    let length: f32 = ss
        .residues()
        .windows(2)
        .filter(|w| !w[1].starts_piece)
        .map(|w| {
            f.positions[w[0].backbone[1]]
                .into_iter()
                .zip(f.positions[w[1].backbone[1]])
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f32>()
                .sqrt()
        })
        .sum();
    let pi = std::f32::consts::PI;
    let (lo, hi) = (
        pi * COIL_RADIUS * COIL_RADIUS * length,
        pi * ARROW * STRAND.1 * length,
    );
    let v = m.volume() as f32;
    assert!(v > lo && v < hi, "volume {v} outside {lo}..{hi}");
    // Every CA inside its section: no vertex nearer than the thinnest half thickness, one within
    // the widest half width (the end caps' centres are the end CAs: ends are left out).
    let res = ss.residues();
    for k in 1..res.len() - 1 {
        if res[k].starts_piece || res[k + 1].starts_piece {
            continue;
        }
        let ca = Vec3::from(f.positions[res[k].backbone[1]]);
        let d = m
            .positions
            .iter()
            .map(|p| p.distance(ca))
            .fold(f32::MAX, f32::min);
        assert!(
            d > 0.24 && d < ARROW + 0.01,
            "residue {}: nearest vertex {d}",
            res[k].res_id
        );
    }
}

#[test]
fn helices_are_ribbons_and_strands_are_bands_as_dssp_assigns_them() {
    let f = read("3gwiA.pdb.gz");
    let (_, m, _) = cartoon(&vec![true; f.n_atoms()]);
    let ss = secondary::assign(&f);
    let [coil, helix, strand] = ss.counts();
    assert!(
        coil > 0 && helix > 0 && strand > 0,
        "{coil} {helix} {strand}"
    );
    // The section at each CA lies in the plane across the spline's tangent there, the chord
    // through the neighbouring CAs (Catmull-Rom), and is as wide as its residue's class: a
    // strand's last residue is an arrowhead's base (both sections at its CA: the widest is the
    // base).
    let res = ss.residues();
    let ca = |k: usize| Vec3::from(f.positions[res[k].backbone[1]]);
    let mut checked = [0; 3];
    for k in 1..res.len() - 1 {
        if res[k].starts_piece || res[k + 1].starts_piece {
            continue;
        }
        let t = (ca(k + 1) - ca(k - 1)).normalize();
        let half_width = m
            .positions
            .iter()
            .map(|p| *p - ca(k))
            .filter(|d| d.dot(t).abs() < 1e-3 && d.length() < ARROW + 0.1)
            .map(|d| d.length())
            .fold(0.0f32, f32::max);
        let class = ss.classes()[k];
        let expected = match class {
            Structure::Helix => HELIX.0,
            Structure::Strand if ss.classes()[k + 1] != Structure::Strand => ARROW,
            Structure::Strand => STRAND.0,
            Structure::Coil => COIL_RADIUS,
        };
        assert!(
            (half_width - expected).abs() < 2e-3,
            "residue {} ({class:?}): half width {half_width}, expected {expected}",
            res[k].res_id
        );
        checked[class as usize] += 1;
    }
    assert!(checked.iter().all(|&n| n > 10), "{checked:?}");
}

#[test]
fn only_selected_residues_are_drawn_and_breaks_split_the_trace() {
    let f = read("3gwiA.pdb.gz");
    let all = cartoon(&vec![true; f.n_atoms()]).1;
    // Every other residue unselected: no two neighbours, so nothing to draw.
    let ss = secondary::assign(&f);
    let mut alternate = vec![false; f.n_atoms()];
    for r in ss.residues().iter().step_by(2) {
        alternate[r.backbone[1]] = true;
    }
    let (_, none, drawn) = cartoon(&alternate);
    assert_eq!((drawn, none.triangles.len()), (0, 0));
    // Half the residues: about half the triangles.
    let mut half = vec![false; f.n_atoms()];
    for r in &ss.residues()[..ss.residues().len() / 2] {
        half[r.backbone[1]] = true;
    }
    let (_, part, _) = cartoon(&half);
    let ratio = part.triangles.len() as f64 / all.triangles.len() as f64;
    assert!(ratio > 0.4 && ratio < 0.6, "{ratio}");
}

/// Supersampling (`Frame::downsample`, `texmap render --supersample`): the cartoon drawn at 4x
/// the size and box-filtered down against the reference ray tracer's own 4x4 stratified
/// samples per pixel of the same mesh; one sample per pixel is well short of it.
#[test]
fn a_supersampled_cartoon_meets_the_supersampled_reference() {
    use texmap_core::camera::Camera;
    use texmap_core::frame::Frame as Image;
    use texmap_core::metrics::psnr;
    use texmap_core::shade::{Lighting, Material};
    use texmap_md_scene::surface::draw_mesh;
    let f = read("3gwiA.pdb.gz");
    let (_, m, _) = cartoon(&vec![true; f.n_atoms()]);
    let centre = m.positions.iter().copied().sum::<Vec3>() / m.positions.len() as f32;
    let (w, h) = (240, 180);
    let cam = Camera::perspective_look_at(
        centre + Vec3::new(0.0, 10.0, 70.0),
        centre,
        Vec3::Y,
        40.0,
        w,
        h,
    )
    .unwrap();
    let lighting = Lighting::default_for(&cam);
    let materials: Vec<Material> = (0..4)
        .map(|k| Material::plastic(Vec3::new(0.9 - 0.2 * k as f32, 0.3 + 0.2 * k as f32, 0.5)))
        .collect();
    let bg = [0, 0, 0, 255];
    let draw = |ss: u32| {
        let big = cam.with_size(w * ss, h * ss).unwrap();
        let mut img = Image::new(w * ss, h * ss, bg);
        draw_mesh(&m, &materials, &big, &lighting, 1.0, &mut img).unwrap();
        img.downsample(ss).unwrap()
    };
    let reference = common::traced(&m, &materials, &cam, lighting, 4, bg);
    let (one, four) = (
        psnr(&draw(1), &reference).unwrap(),
        psnr(&draw(4), &reference).unwrap(),
    );
    eprintln!("against the 4x4 reference: 1 sample {one:.2} dB, 4x4 supersampled {four:.2} dB");
    assert!(
        four > 50.0 && four > one + 20.0,
        "1 sample {one} dB, supersampled {four} dB"
    );
}

/// Nucleic acids: the DNA "strand" of md-io's chains fixture (MDAnalysis-written for the
/// selection tests: P, C4' and N1 of six nucleotides at scattered places): a rung from every P
/// to its N1 (neither N9 nor N3 in this file: the N1 fallback), and a tube only between
/// phosphates close enough to be bonded neighbours (DA 5 and DC3 6, 6.9 Å apart; the others are
/// 11 to 27 Å from their neighbours).
#[test]
fn a_dna_strand_is_a_tube_through_its_phosphates_with_a_rung_to_each_base() {
    let path = format!(
        "{}/../md-io/tests/data/chains_mda.pdb",
        env!("CARGO_MANIFEST_DIR")
    );
    let mut f = Frame::new();
    Trajectory::open(&path)
        .unwrap()
        .read_frame(0, &mut f)
        .unwrap();
    let centers: Vec<Vec3> = f.positions.iter().map(|p| Vec3::from(*p)).collect();
    let dna: Vec<bool> = f
        .res_names
        .iter()
        .map(|r| r.as_str().starts_with('D'))
        .collect();
    let mut m = MolMesh::default();
    let n = append_cartoon(&f, &centers, &vec![0; f.n_atoms()], &dna, &mut m);
    assert_eq!(n, 2);
    // A rung's cap centres are its ends: a vertex on every P and every N1.
    for (i, name) in f.names.iter().enumerate() {
        if dna[i] && (name.as_str() == "P" || name.as_str() == "N1") {
            let d = m
                .positions
                .iter()
                .map(|p| p.distance(centers[i]))
                .fold(f32::MAX, f32::min);
            assert!(d < 1e-5, "atom {i} ({name}): nearest vertex {d}");
        }
    }
    let volume = m.volume();
    assert!(volume > 0.0, "volume {volume}");
    // Nothing for the protein's atoms: a DNA-only selection draws no ribbon.
    assert!(m.positions.iter().all(|p| {
        centers
            .iter()
            .zip(&dna)
            .filter(|(_, d)| **d)
            .any(|(c, _)| c.distance(*p) < 6.0)
    }));
}

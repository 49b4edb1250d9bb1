//! `MolOptions::align` against MDAnalysis 2.11's `AlignTraj`: a tumbling, diffusing, jiggling
//! copy of wwPDB 3GWI chain A (tests/data/align_3gwi.xtc with md-io's 3gwiA.pdb.gz as the
//! topology) superposed on its first frame on the backbone. Each frame's RMSD after the fit and
//! the superposed positions of every 10th atom are MDAnalysis's (tests/data/gen_align.py); and
//! the same trajectory fitted by mass onto a separate, moved structure
//! (`AlignTraj(weights="mass")`, tests/data/gen_align_to.py).

use std::path::{Path, PathBuf};

use texmap_md_io::{Frame, Selection, Topology, Trajectory};
use texmap_md_scene::{Alignment, MolOptions, MolPlan, SceneBuilder, SphereScene, StyleOptions};

fn here(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(name)
}

/// The numbers of `key` in the generator's JSON (one object, flat arrays of numbers), read
/// without a JSON dependency: every number after `"key":` up to the next key.
fn numbers(text: &str, key: &str) -> Vec<f64> {
    let at = text.find(&format!("\"{key}\":")).unwrap() + key.len() + 3;
    let rest = &text[at..];
    let end = rest.find("\"").unwrap_or(rest.len());
    rest[..end]
        .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'e'))
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().unwrap())
        .collect()
}

/// Every frame of align_3gwi.xtc through a plan with `alignment`, against the generator's JSON
/// `reference` (RMSD per frame, superposed positions of every 10th atom).
fn check_against_mdanalysis(reference: &str, alignment: Alignment) {
    let text = std::fs::read_to_string(here(reference)).unwrap();
    let rmsd = numbers(&text, "rmsd");
    let atoms: Vec<usize> = numbers(&text, "atoms")
        .iter()
        .map(|v| *v as usize)
        .collect();
    let positions = numbers(&text, "positions");
    assert_eq!(rmsd.len(), 6);
    assert_eq!(positions.len(), 6 * atoms.len() * 3);
    let topology = Topology::open(here("../md-io/tests/data/dssp/3gwiA.pdb.gz")).unwrap();
    let mut plan = MolPlan::new(MolOptions {
        topology: Some(topology),
        align: Some(alignment),
        ..MolOptions::default()
    })
    .unwrap();
    let mut builder = SceneBuilder::new(&StyleOptions::default()).unwrap();
    let mut traj = Trajectory::open(here("tests/data/align_3gwi.xtc")).unwrap();
    let mut frame = Frame::new();
    let mut scene = SphereScene::default();
    let mut worst = 0.0f64;
    for f in 0..6 {
        assert!(traj.read_next(&mut frame).unwrap());
        plan.label(&mut frame, "align_3gwi.xtc", f).unwrap();
        let before = frame.positions[0];
        plan.build(&mut builder, &mut frame, &mut scene).unwrap();
        let fit = plan.last_fit_rmsd().unwrap();
        assert!(
            (fit - rmsd[f]).abs() < 1e-4,
            "frame {f}: rmsd {fit} vs {}",
            rmsd[f]
        );
        for (k, &i) in atoms.iter().enumerate() {
            let c = scene.centers[i];
            for (a, got) in [c.x, c.y, c.z].into_iter().enumerate() {
                let want = positions[(f * atoms.len() + k) * 3 + a];
                worst = worst.max((got as f64 - want).abs());
            }
        }
        // Later frames really were moved (by up to 20 Å and a random turn).
        if f > 0 {
            let after = frame.positions[0];
            let moved: f32 = (0..3)
                .map(|k| (after[k] - before[k]).powi(2))
                .sum::<f32>()
                .sqrt();
            assert!(moved > 1.0, "frame {f}: moved {moved}");
        }
    }
    // Both fits start from the same XTC values; f32 positions of ~50 Å carry ~4e-6 Å.
    assert!(
        worst < 1e-3,
        "largest difference from MDAnalysis: {worst} Å"
    );
}

#[test]
fn frames_are_superposed_as_mdanalysis_aligntraj_superposes_them() {
    let backbone = Selection::parse("backbone").unwrap();
    check_against_mdanalysis(
        "tests/data/align_reference.json",
        Alignment::on_first_frame(backbone),
    );
}

fn target() -> Frame {
    let mut t = Trajectory::open(here("tests/data/align_target.pdb.gz")).unwrap();
    let mut frame = Frame::new();
    assert!(t.read_next(&mut frame).unwrap());
    frame
}

#[test]
fn mass_weighted_fits_onto_a_reference_structure_match_mdanalysis() {
    check_against_mdanalysis(
        "tests/data/align_to_reference.json",
        Alignment {
            select: Selection::parse("backbone").unwrap(),
            reference: Some(target()),
            mass_weighted: true,
        },
    );
}

#[test]
fn a_reference_with_other_atoms_is_refused_naming_the_difference() {
    let build = |reference: Frame| {
        first_frame(Alignment {
            select: Selection::parse("backbone").unwrap(),
            reference: Some(reference),
            mass_weighted: false,
        })
    };
    // The last residue's atoms renamed out of the backbone: the counts differ.
    let mut short = target();
    let last = *short.res_ids.last().unwrap();
    for i in 0..short.n_atoms() {
        if short.res_ids[i] == last {
            short.names[i] = texmap_md_io::Label::new("XX").unwrap();
        }
    }
    let e = build(short).unwrap_err().to_string();
    assert!(e.contains("but") && e.contains("of the reference"), "{e}");
    // Two backbone atoms of the first residue named the other's name.
    let mut swapped = target();
    let n = swapped
        .names
        .iter()
        .position(|n| n.as_str() == "N")
        .unwrap();
    let ca = swapped
        .names
        .iter()
        .position(|n| n.as_str() == "CA")
        .unwrap();
    swapped.names.swap(n, ca);
    let e = build(swapped).unwrap_err().to_string();
    assert!(
        e.contains("is N in the frame but CA in the reference"),
        "{e}"
    );
    // The unchanged structure is accepted.
    assert!(build(target()).is_ok());
}

/// The first frame of align_3gwi.xtc built with `alignment`.
fn first_frame(alignment: Alignment) -> Result<(), texmap_md_scene::MolError> {
    let topology = Topology::open(here("../md-io/tests/data/dssp/3gwiA.pdb.gz")).unwrap();
    let mut plan = MolPlan::new(MolOptions {
        topology: Some(topology),
        align: Some(alignment),
        ..MolOptions::default()
    })
    .unwrap();
    let mut builder = SceneBuilder::new(&StyleOptions::default()).unwrap();
    let mut traj = Trajectory::open(here("tests/data/align_3gwi.xtc")).unwrap();
    let mut frame = Frame::new();
    assert!(traj.read_next(&mut frame).unwrap());
    plan.label(&mut frame, "align_3gwi.xtc", 0).unwrap();
    plan.build(&mut builder, &mut frame, &mut SphereScene::default())
}

#[test]
fn an_alignment_of_fewer_than_three_atoms_is_refused() {
    let e = first_frame(Alignment::on_first_frame(
        Selection::parse("index 0 1").unwrap(),
    ))
    .unwrap_err();
    assert!(e.to_string().contains("picks 2 atom(s)"), "{e}");
}

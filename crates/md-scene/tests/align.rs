//! `MolOptions::align` against MDAnalysis 2.11's `AlignTraj`: a tumbling, diffusing, jiggling
//! copy of wwPDB 3GWI chain A (tests/data/align_3gwi.xtc with md-io's 3gwiA.pdb.gz as the
//! topology) superposed on its first frame on the backbone. Each frame's RMSD after the fit and
//! the superposed positions of every 10th atom are MDAnalysis's (tests/data/gen_align.py).

use std::path::{Path, PathBuf};

use texmap_md_io::{Frame, Selection, Topology, Trajectory};
use texmap_md_scene::{MolOptions, MolPlan, SceneBuilder, SphereScene, StyleOptions};

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

#[test]
fn frames_are_superposed_as_mdanalysis_aligntraj_superposes_them() {
    let text = std::fs::read_to_string(here("tests/data/align_reference.json")).unwrap();
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
        align: Some(Selection::parse("backbone").unwrap()),
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
fn an_alignment_of_fewer_than_three_atoms_is_refused() {
    let topology = Topology::open(here("../md-io/tests/data/dssp/3gwiA.pdb.gz")).unwrap();
    let mut plan = MolPlan::new(MolOptions {
        topology: Some(topology),
        align: Some(Selection::parse("index 0 1").unwrap()),
        ..MolOptions::default()
    })
    .unwrap();
    let mut builder = SceneBuilder::new(&StyleOptions::default()).unwrap();
    let mut traj = Trajectory::open(here("tests/data/align_3gwi.xtc")).unwrap();
    let mut frame = Frame::new();
    assert!(traj.read_next(&mut frame).unwrap());
    plan.label(&mut frame, "align_3gwi.xtc", 0).unwrap();
    let e = plan
        .build(&mut builder, &mut frame, &mut SphereScene::default())
        .unwrap_err();
    assert!(e.to_string().contains("picks 2 atom(s)"), "{e}");
}

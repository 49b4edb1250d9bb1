//! Principal component analysis against MDAnalysis 2.11's `analysis.pca.PCA` on the same
//! file (data/pca/gen_pca.py): a bending and twisting helix, 80 frames written by MDAnalysis
//! as XTC, read here by our XTC reader.

use std::path::PathBuf;

use serde_json::Value;
use texmap_md_io::pca::{Pca, cosine_content};
use texmap_md_io::select::Selection;
use texmap_md_io::{Frame, Trajectory};

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/pca")
}

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// The positions of the atoms `sel` picks in helix_pca.xtc (the topology from helix.pdb),
/// frame by frame, as the file holds them.
fn positions(sel: &str) -> Vec<Vec<[f32; 3]>> {
    let mut f = Frame::new();
    let mut pdb = Trajectory::open(dir().join("../dihedrals/helix.pdb")).unwrap();
    pdb.read_frame(0, &mut f).unwrap();
    let pick = Selection::parse(sel).unwrap().indices(&f).unwrap();
    let mut xtc = Trajectory::open(dir().join("helix_pca.xtc")).unwrap();
    let n = xtc.n_frames().unwrap();
    (0..n)
        .map(|k| {
            xtc.read_frame(k, &mut f).unwrap();
            pick.iter().map(|&i| f.positions[i]).collect()
        })
        .collect()
}

/// Every variance, the cumulated variance, the first three components (up to sign), every
/// frame's projection on them and their cosine content equal MDAnalysis's, on the CA atoms
/// (69 coordinates over 80 frames: the covariance matrix) and the backbone (276 coordinates:
/// the 80 x 80 matrix of the frames' products). Tolerances are relative to the largest
/// variance (1e-7): the two XTC decoders may round a coordinate's last f32 bit differently.
#[test]
fn equals_mdanalysis_on_both_paths() {
    let text = std::fs::read_to_string(dir().join("pca_reference.json")).unwrap();
    let reference: Value = serde_json::from_str(&text).unwrap();
    for sel in ["name CA", "backbone"] {
        let r = &reference[format!("raw {sel}")];
        let frames = positions(sel);
        assert_eq!(frames.len(), 80);
        assert_eq!(frames[0].len() as u64, r["atoms"].as_u64().unwrap());
        let mut pca = Pca::new(1 << 30);
        for p in &frames {
            pca.add(p).unwrap();
        }
        let c = pca.solve(3).unwrap();
        let want = floats(&r["variance"]);
        let top = want[0];
        // MDAnalysis lists 3N values; past the frames' rank they are rounding noise.
        assert_eq!(c.variance.len(), want.len().min(80));
        for (k, (got, want)) in c.variance.iter().zip(&want).enumerate() {
            assert!(
                (got - want).abs() < 1e-7 * top,
                "{sel}: variance {k}: {got} vs {want}"
            );
        }
        let cumulated = floats(&r["cumulated_variance"]);
        for k in [0, 1, 2, 10, 40] {
            assert!((c.cumulated(k) - cumulated[k]).abs() < 1e-7, "{sel}: {k}");
        }
        let mean = floats(&r["mean"]);
        for (got, want) in c.mean.iter().flatten().zip(&mean) {
            assert!((got - want).abs() < 1e-5, "{sel}: mean {got} vs {want}");
        }
        let projections = r["projections"].as_array().unwrap();
        for k in 0..3 {
            let v: Vec<f64> = c.vectors[k].iter().flatten().copied().collect();
            let w = floats(&r["components"][k]);
            let dot: f64 = v.iter().zip(&w).map(|(a, b)| a * b).sum();
            assert!(
                (dot.abs() - 1.0).abs() < 1e-7,
                "{sel}: component {k}: {dot}"
            );
            let sign = dot.signum();
            let ours: Vec<f64> = c.projections.iter().map(|p| p[k]).collect();
            for (f, (got, row)) in ours.iter().zip(projections).enumerate() {
                let want = sign * row[k].as_f64().unwrap();
                assert!(
                    (got - want).abs() < 1e-5 * top.sqrt(),
                    "{sel}: frame {f} on component {k}: {got} vs {want}"
                );
            }
            let cc = r["cosine_content"][k].as_f64().unwrap();
            assert!(
                (cosine_content(&ours, k) - cc).abs() < 1e-7,
                "{sel}: cosine content {k}: {} vs {cc}",
                cosine_content(&ours, k)
            );
        }
    }
}

/// The pairwise RMSD after superposition equals MDAnalysis's DistanceMatrix with rms.rmsd
/// (center=True, superposition=True) on every second frame's CA atoms (gen_rmsd_matrix.py).
#[test]
fn rmsd_matrix_equals_mdanalysis() {
    let text = std::fs::read_to_string(dir().join("rmsd_matrix_reference.json")).unwrap();
    let reference: Value = serde_json::from_str(&text).unwrap();
    let frames: Vec<Vec<[f32; 3]>> = positions("name CA").into_iter().step_by(2).collect();
    assert_eq!(frames.len() as u64, reference["frames"].as_u64().unwrap());
    let m = texmap_md_io::rmsd::rmsd_matrix(&frames, usize::MAX).unwrap();
    let want = floats(&reference["matrix"]);
    assert_eq!(m.len(), want.len());
    for (k, (got, want)) in m.iter().zip(&want).enumerate() {
        // Seven digits in the file; the XTC decoders may differ in a last f32 bit.
        assert!(
            (got - want).abs() < 1e-6 * want.max(1.0),
            "pair {k}: {got} vs {want}"
        );
    }
}

/// The free-energy landscape of MDAnalysis's PC1–PC2 projections equals NumPy's
/// `histogram2d` of them (edges, every bin's count) and `−RT ln(n / n_max)` at 300 K
/// (gen_landscape.py), at 12 and 5 bins a side.
#[test]
fn landscape_equals_numpy() {
    use texmap_md_io::pca::{GAS_CONSTANT, Landscape};
    let text = std::fs::read_to_string(dir().join("landscape_reference.json")).unwrap();
    let reference: Value = serde_json::from_str(&text).unwrap();
    let text = std::fs::read_to_string(dir().join("pca_reference.json")).unwrap();
    let pca: Value = serde_json::from_str(&text).unwrap();
    let points: Vec<(f64, f64)> = pca["aligned name CA"]["projections"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| (p[0].as_f64().unwrap(), p[1].as_f64().unwrap()))
        .collect();
    let kt = GAS_CONSTANT * reference["temperature"].as_f64().unwrap();
    for r in reference["landscapes"].as_array().unwrap() {
        let bins = r["bins"].as_u64().unwrap() as usize;
        let l = Landscape::new(&points, bins, kt).unwrap();
        let (xe, ye) = (floats(&r["x_edges"]), floats(&r["y_edges"]));
        assert_eq!((l.x.0, l.x.1), (xe[0], xe[bins]));
        assert_eq!((l.y.0, l.y.1), (ye[0], ye[bins]));
        let (cx, cy) = l.centre(2, 3);
        assert!((cx - 0.5 * (xe[2] + xe[3])).abs() < 1e-12);
        assert!((cy - 0.5 * (ye[3] + ye[4])).abs() < 1e-12);
        let counts = r["counts"].as_array().unwrap();
        let energy = r["free_energy"].as_array().unwrap();
        for i in 0..bins {
            for j in 0..bins {
                let k = j * bins + i;
                assert_eq!(
                    u64::from(l.counts[k]),
                    counts[i][j].as_u64().unwrap(),
                    "{bins} bins: ({i}, {j})"
                );
                match (l.free_energy[k], energy[i][j].as_f64()) {
                    (Some(g), Some(want)) => assert!((g - want).abs() < 1e-8, "{g} vs {want}"),
                    (None, None) => {}
                    other => panic!("{bins} bins: ({i}, {j}): {other:?}"),
                }
            }
        }
        assert_eq!(l.counts.iter().sum::<u32>(), 80);
    }
    // What it refuses: no points, a point not finite, no bins, no temperature.
    assert!(Landscape::new(&[], 10, kt).is_none());
    assert!(Landscape::new(&[(0.0, f64::NAN)], 10, kt).is_none());
    assert!(Landscape::new(&points, 0, kt).is_none());
    assert!(Landscape::new(&points, 10, 0.0).is_none());
    // One point: the range widened to ±0.5, ΔG 0 in its bin.
    let one = Landscape::new(&[(2.0, -1.0)], 4, kt).unwrap();
    assert_eq!((one.x, one.y), ((1.5, 2.5), (-1.5, -0.5)));
    assert_eq!(one.free_energy.iter().flatten().count(), 1);
}

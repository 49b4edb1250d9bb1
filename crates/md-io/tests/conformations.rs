//! Clustering of conformations against GROMACS 2022.5's `gmx cluster` on the same file
//! (data/conformations/gen_clusters.py): a helix that dwells in four shapes and moves between
//! them, 200 frames written by MDAnalysis as XTC and read here by our XTC reader, clustered on
//! the CA atoms with the gromos method at two cutoffs and with single linkage.

use std::collections::BTreeSet;
use std::path::PathBuf;

use serde_json::Value;
use texmap_md_io::conformations::{Method, cluster};
use texmap_md_io::select::Selection;
use texmap_md_io::{Frame, Trajectory};

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/conformations")
}

/// The CA atoms of states.xtc, frame by frame.
fn positions() -> Vec<Vec<[f32; 3]>> {
    let mut f = Frame::new();
    let mut pdb = Trajectory::open(dir().join("../dihedrals/helix.pdb")).unwrap();
    pdb.read_frame(0, &mut f).unwrap();
    let pick = Selection::parse("name CA").unwrap().indices(&f).unwrap();
    let mut xtc = Trajectory::open(dir().join("states.xtc")).unwrap();
    let n = xtc.n_frames().unwrap();
    (0..n)
        .map(|k| {
            xtc.read_frame(k, &mut f).unwrap();
            pick.iter().map(|&i| f.positions[i]).collect()
        })
        .collect()
}

fn frames_of(v: &Value) -> Vec<usize> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap() as usize)
        .collect()
}

/// Every cluster gmx found is one of ours with the same members, middle structure, mean RMSD
/// and middle RMSD (gmx prints them in nm to three decimals), and the clusters come in gmx's
/// order where that order is defined: gromos's by size (equal sizes may come either way,
/// gmx's sort being unstable), linkage's by first frame. Each frame's cluster number (gmx's
/// -clid) names the same set of frames.
#[test]
fn clusters_equal_gmx_cluster() {
    let text = std::fs::read_to_string(dir().join("clusters_reference.json")).unwrap();
    let reference: Value = serde_json::from_str(&text).unwrap();
    let frames = positions();
    assert_eq!(frames.len() as u64, reference["frames"].as_u64().unwrap());
    let m = texmap_md_io::rmsd::rmsd_matrix(&frames, usize::MAX).unwrap();
    let n = frames.len();
    for run in reference["runs"].as_array().unwrap() {
        let method = match run["method"].as_str().unwrap() {
            "gromos" => Method::Gromos,
            "linkage" => Method::Linkage,
            other => panic!("{other}"),
        };
        let cutoff = 10.0 * run["cutoff_nm"].as_f64().unwrap();
        let ours = cluster(&m, n, cutoff, method).unwrap();
        let theirs = run["clusters"].as_array().unwrap();
        let what = format!("{} at {cutoff} Å", method.name());
        assert_eq!(ours.clusters.len(), theirs.len(), "{what}: cluster count");
        assert!(theirs.len() >= 3, "{what}: the run has something to find");
        for (k, t) in theirs.iter().enumerate() {
            let members = frames_of(&t["members"]);
            let c = ours
                .clusters
                .iter()
                .find(|c| c.members == members)
                .unwrap_or_else(|| panic!("{what}: gmx's cluster {} is none of ours", k + 1));
            assert_eq!(
                c.members.len(),
                ours.clusters[k].members.len(),
                "{what}: cluster {} comes in gmx's order of sizes",
                k + 1
            );
            if method == Method::Linkage {
                assert_eq!(c, &ours.clusters[k], "{what}: numbered by first frame");
            }
            assert_eq!(c.middle as u64, t["middle"].as_u64().unwrap(), "{what}");
            for (key, ours) in [
                ("mean_rmsd_nm", c.mean_rmsd),
                ("middle_rmsd_nm", c.middle_rmsd),
            ] {
                match t[key].as_f64() {
                    Some(nm) => assert!(
                        (ours / 10.0 - nm).abs() <= 0.0005 + 1e-9,
                        "{what}: {key} {} vs {nm}",
                        ours / 10.0
                    ),
                    None => assert_eq!(ours, 0.0, "{what}: a lone frame"),
                }
            }
        }
        // gmx's per-frame numbers and ours name the same sets of frames.
        let clid = frames_of(&run["cluster_of_frame"]);
        let sets = |ids: &[usize]| -> BTreeSet<Vec<usize>> {
            let mut by: std::collections::BTreeMap<usize, Vec<usize>> = Default::default();
            for (f, &c) in ids.iter().enumerate() {
                by.entry(c).or_default().push(f);
            }
            by.into_values().collect()
        };
        assert_eq!(sets(&clid), sets(&ours.of_frame), "{what}: -clid");
    }
}

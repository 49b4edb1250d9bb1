//! Clusters (`texmap_md_io::coordination::clusters`) against OVITO 3.17's Cluster analysis
//! modifier (cutoff mode, sorted by size) on systems OVITO wrote (tests/data/clusters,
//! gen_clusters.py): a random gas below and above percolation in a periodic box (760 clusters;
//! one spanning the box) and copper in BCC iron (a precipitate and solutes, only the copper
//! clustered). The clusters must be OVITO's atom for atom: the same sizes in the same order, the
//! same atoms together; where sizes are unique, the same ids (OVITO leaves the order of equal sizes
//! undocumented; texmap puts the cluster holding the lower atom index first).

use std::collections::HashMap;
use std::path::Path;

use texmap_md_io::coordination::clusters;
use texmap_md_io::{Frame, Trajectory};

fn data(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/clusters")
        .join(name)
}

#[test]
fn every_cluster_is_ovitos() {
    let text = std::fs::read_to_string(data("clusters_reference.json")).unwrap();
    let cases: serde_json::Value = serde_json::from_str(&text).unwrap();
    for case in cases.as_array().unwrap() {
        let file = case["file"].as_str().unwrap();
        let cutoff = case["cutoff"].as_f64().unwrap() as f32;
        let mut frame = Frame::new();
        assert!(
            Trajectory::open(data(file))
                .unwrap()
                .read_next(&mut frame)
                .unwrap()
        );
        let only: Option<Vec<bool>> = case["only"].as_str().map(|el| {
            (0..frame.n_atoms())
                .map(|i| texmap_md_io::atom_element(&frame, i).symbol() == el)
                .collect()
        });
        let c = clusters(&frame, cutoff, only.as_deref()).unwrap();
        let want_ids: Vec<i64> = case["ids"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_i64().unwrap())
            .collect();
        let want_sizes: Vec<usize> = case["sizes"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_u64().unwrap() as usize)
            .collect();
        assert_eq!(c.sizes, want_sizes, "{file} at {cutoff} Å: sizes");
        // The same partition: each of our clusters is exactly one of OVITO's.
        let mut ours_to_theirs: HashMap<i32, i64> = HashMap::new();
        let mut theirs_to_ours: HashMap<i64, i32> = HashMap::new();
        for (i, (&a, &b)) in c.ids.iter().zip(&want_ids).enumerate() {
            assert_eq!(a < 0, b < 0, "{file}: atom {i} clustered by one only");
            assert_eq!(*ours_to_theirs.entry(a).or_insert(b), b, "{file}: atom {i}");
            assert_eq!(*theirs_to_ours.entry(b).or_insert(a), a, "{file}: atom {i}");
        }
        // Where a size is unique, the id is OVITO's too.
        let mut unique = 0;
        for (&a, &b) in &ours_to_theirs {
            if a >= 0
                && c.sizes
                    .iter()
                    .filter(|&&s| s == c.sizes[a as usize])
                    .count()
                    == 1
            {
                assert_eq!(
                    a as i64, b,
                    "{file}: cluster of {} atoms",
                    c.sizes[a as usize]
                );
                unique += 1;
            }
        }
        println!(
            "{file} at {cutoff} Å: {} clusters (largest {}), {unique} of unique size",
            c.sizes.len(),
            c.sizes[0]
        );
        assert_eq!(c.sizes.len() as u64, case["count"].as_u64().unwrap());
        // OVITO orders clusters of equal size in no documented way (ours: by lowest atom).
        assert!(unique >= 2);
    }
}

/// A cluster cut by the cell's faces is unwrapped whole: a chain of five atoms 2 Å apart along
/// x around the face x = 0 of a 20 Å cell (wrapped to 16, 18, 0, 2, 4) has its centre at the
/// face (x = 20, unwrapped from its first atom at 16) and a radius of gyration of √8 Å
/// (distances 4, 2, 0, 2, 4 from the centre); a lone atom's is 0 at itself.
#[test]
fn cluster_cut_by_the_faces_has_the_centre_and_gyration_of_the_whole() {
    let mut frame = Frame::new();
    frame.cell = Some(texmap_md_io::UnitCell::orthorhombic(20.0, 20.0, 20.0).unwrap());
    frame.positions = vec![
        [16.0, 5.0, 5.0],
        [18.0, 5.0, 5.0],
        [0.0, 5.0, 5.0],
        [2.0, 5.0, 5.0],
        [4.0, 5.0, 5.0],
        [10.0, 15.0, 15.0],
    ];
    let c = texmap_md_io::coordination::clusters(&frame, 2.5, None).unwrap();
    assert_eq!(c.sizes, [5, 1]);
    let [x, y, z] = c.centers[0];
    assert!((x - 20.0).abs() < 1e-12 && (y - 5.0).abs() < 1e-12 && (z - 5.0).abs() < 1e-12);
    assert!((c.gyration[0] - 8f64.sqrt()).abs() < 1e-12);
    assert_eq!(c.centers[1], [10.0, 15.0, 15.0]);
    assert_eq!(c.gyration[1], 0.0);
}

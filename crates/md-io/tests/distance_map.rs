//! Residue–residue maps against GROMACS 2022.5's `gmx mdmat` and MDAnalysis 2.11's
//! `distances.distance_array` (data/distance_map/gen_distance_map.py) on adenylate kinase in
//! water in a truncated octahedron: the protein's 214 residues over the file's frames.

use std::io::Read;
use std::path::PathBuf;

use serde_json::Value;
use texmap_md_io::distance_map::DistanceMap;
use texmap_md_io::select::Selection;
use texmap_md_io::{Frame, Topology, Trajectory};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn gunzip(name: &str) -> String {
    let mut text = String::new();
    flate2::read::GzDecoder::new(std::fs::File::open(data(name)).unwrap())
        .read_to_string(&mut text)
        .unwrap();
    text
}

/// The map of the protein's residues over every frame of adk_0_9.xtc.
fn protein_map(cutoff: f64) -> DistanceMap {
    let top = Topology::open(data("hbonds/adk_top.gro.gz")).unwrap();
    let mut traj = Trajectory::open(data("hbonds/adk_0_9.xtc")).unwrap();
    let mut frame = Frame::new();
    let mut map = None;
    let mut k = 0;
    while traj.read_next(&mut frame).unwrap() {
        top.apply(&mut frame, "adk_0_9.xtc", k).unwrap();
        let map = map.get_or_insert_with(|| {
            let protein = Selection::parse("protein")
                .unwrap()
                .evaluate(&frame)
                .unwrap();
            let groups: Vec<Vec<usize>> = texmap_md_io::secondary::residue_ranges(&frame)
                .into_iter()
                .map(|r| r.filter(|&i| protein[i]).collect::<Vec<usize>>())
                .filter(|g| !g.is_empty())
                .collect();
            DistanceMap::new(groups, cutoff).unwrap()
        });
        map.add(&frame.positions, frame.cell.as_ref()).unwrap();
        k += 1;
    }
    map.unwrap()
}

/// The mean smallest distances and the contact fractions at 4.5 Å equal MDAnalysis's
/// minimum-image distances; the mean equals gmx mdmat's within its discretisation (half a
/// level of 1.5 / 999 nm), and every pair past its 1.5 nm top level is past it here too.
#[test]
fn residue_maps_equal_gmx_mdmat_and_mdanalysis() {
    let reference: Value = serde_json::from_str(&gunzip("distance_map/reference.json.gz")).unwrap();
    let map = protein_map(reference["cutoff"].as_f64().unwrap());
    let n = map.residues();
    assert_eq!(n as u64, reference["residues"].as_u64().unwrap());
    assert_eq!(map.frames() as u64, reference["frames"].as_u64().unwrap());
    let (mean, contacts) = (map.mean(), map.contact_fraction());
    let want_mean = reference["mean"].as_array().unwrap();
    let want_contacts = reference["contact_fraction"].as_array().unwrap();
    let mut k = 0;
    for i in 0..n {
        assert_eq!((mean[i * n + i], contacts[i * n + i]), (0.0, 1.0));
        for j in i + 1..n {
            let (m, c) = (mean[i * n + j], contacts[i * n + j]);
            assert_eq!((m, c), (mean[j * n + i], contacts[j * n + i]));
            let w = want_mean[k].as_f64().unwrap();
            assert!((m - w).abs() < 1e-4, "({i}, {j}): {m} vs {w}");
            assert_eq!(c, want_contacts[k].as_f64().unwrap(), "({i}, {j}): {m} Å");
            k += 1;
        }
    }
    // gmx mdmat's XPM: a header line "214 214 1000 2", 1000 colour lines (in level order),
    // then the rows, two characters a cell.
    let xpm = gunzip("distance_map/mdmat_mean.xpm.gz");
    let lines: Vec<&str> = xpm
        .lines()
        .filter(|l| l.starts_with('"'))
        .map(|l| l.trim_end_matches(',').trim_matches('"'))
        .collect();
    let head: Vec<usize> = lines[0]
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect();
    assert_eq!(head, vec![n, n, 1000, 2]);
    let level: std::collections::HashMap<&str, usize> =
        (0..1000).map(|k| (&lines[1 + k][..2], k)).collect();
    let step = 15.0 / 999.0;
    let rows = &lines[1001..];
    assert_eq!(rows.len(), n);
    for (r, row) in rows.iter().enumerate() {
        // gmx writes the top row (the last residue) first; the map is symmetric anyway.
        let i = n - 1 - r;
        for j in 0..n {
            let k = level[&row[2 * j..2 * j + 2]];
            let ours = mean[i * n + j];
            if k == 999 {
                assert!(
                    ours >= 15.0 - step / 2.0,
                    "({i}, {j}): {ours} Å at gmx's top level"
                );
            } else {
                let theirs = k as f64 * step;
                assert!(
                    (ours - theirs).abs() <= step / 2.0 + 1e-4,
                    "({i}, {j}): {ours} Å against gmx's {theirs}"
                );
            }
        }
    }
}

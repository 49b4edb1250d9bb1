//! md-io's radial distribution functions against OVITO 3.17.2's Coordination analysis
//! (tests/data/rdf/gen_rdf.py): a triclinic Si/O mixture (two frames) and a small Ar/Kr cube whose
//! cutoff is more than a third of the cell (every pair tested), total and partial g(r).

use std::path::PathBuf;

use texmap_md_io::rdf::{RdfError, rdf};
use texmap_md_io::{Frame, Trajectory};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/rdf")
        .join(name)
}

fn frame_of(file: &str, k: usize) -> Frame {
    let mut t = Trajectory::open(data(file)).unwrap();
    let mut f = Frame::new();
    for _ in 0..=k {
        assert!(t.read_next(&mut f).unwrap());
    }
    f
}

/// g(r) of ours and OVITO's as pair counts per bin (g times the ideal gas's count in the shell):
/// equal, except that a pair whose distance lies within f32 rounding of a bin edge may fall on
/// the other side (OVITO reads positions as f64, md-io as f32): no bin differs by more than one
/// pair (2 counts: a pair counts from each end) and no pair is lost or gained up to any bin.
fn same_counts(
    ours: &[f64],
    theirs: &[serde_json::Value],
    ideal: impl Fn(usize) -> f64,
    what: &str,
) {
    assert_eq!(ours.len(), theirs.len(), "{what}");
    let (mut sum_a, mut sum_b) = (0i64, 0i64);
    let mut moved = 0;
    for (k, (a, b)) in ours.iter().zip(theirs).enumerate() {
        let b = b.as_f64().unwrap();
        let (ca, cb) = (a * ideal(k), b * ideal(k));
        assert!(
            (ca - ca.round()).abs() < 1e-6 && (cb - cb.round()).abs() < 1e-6,
            "{what} bin {k}: {ca} {cb}"
        );
        let (ca, cb) = (ca.round() as i64, cb.round() as i64);
        assert!(
            (ca - cb).abs() <= 2,
            "{what} bin {k}: {ca} pair ends vs OVITO's {cb}"
        );
        moved += (ca != cb) as usize;
        sum_a += ca;
        sum_b += cb;
        assert!(
            (sum_a - sum_b).abs() <= 2,
            "{what} up to bin {k}: {sum_a} vs {sum_b}"
        );
    }
    assert!(moved <= 4, "{what}: {moved} bins differ");
}

fn close(ours: &[f64], theirs: &[serde_json::Value], what: &str) {
    assert_eq!(ours.len(), theirs.len(), "{what}");
    for (k, (a, b)) in ours.iter().zip(theirs).enumerate() {
        let b = b.as_f64().unwrap();
        assert!(
            (a - b).abs() <= 1e-12 * b.abs().max(1.0),
            "{what} bin {k}: {a} vs OVITO {b}"
        );
    }
}

#[test]
fn total_and_partial_rdfs_are_ovitos() {
    let reference: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(data("rdf_reference.json")).unwrap())
            .unwrap();
    let mut checked = 0;
    for e in reference.as_array().unwrap() {
        let file = e["file"].as_str().unwrap();
        let k = e["frame"].as_u64().unwrap() as usize;
        let frame = frame_of(file, k);
        let cutoff = e["cutoff"].as_f64().unwrap() as f32;
        let bins = e["bins"].as_u64().unwrap() as usize;
        let g = rdf(&frame, cutoff, bins, true).unwrap();
        let what = format!("{file} frame {k}");
        close(&g.r, e["r"].as_array().unwrap(), &format!("{what} r"));
        let volume = frame.cell.unwrap().volume();
        let dr = cutoff as f64 / bins as f64;
        let shell = |k: usize| {
            let (r0, r1) = (k as f64 * dr, (k + 1) as f64 * dr);
            4.0 / 3.0 * std::f64::consts::PI * (r1.powi(3) - r0.powi(3))
        };
        let n = frame.n_atoms() as f64;
        same_counts(
            &g.total,
            e["total"].as_array().unwrap(),
            |k| shell(k) * n * n / volume,
            &format!("{what} total"),
        );
        let columns = e["columns"].as_array().unwrap();
        assert_eq!(g.partial.len(), columns.len(), "{what}");
        for (name, values) in columns.iter().zip(e["g"].as_array().unwrap()) {
            let name = name.as_str().unwrap();
            let (a, b) = name.split_once('-').unwrap();
            let p = g
                .partial
                .iter()
                .find(|p| {
                    let [x, y] = p.kinds.map(|l| l.as_str().to_string());
                    (x == a && y == b) || (x == b && y == a)
                })
                .unwrap_or_else(|| panic!("{what}: no partial {name}"));
            let (na, nb) = (p.atoms[0] as f64, p.atoms[1] as f64);
            let ordered = if a == b { 1.0 } else { 2.0 };
            same_counts(
                &p.g,
                values.as_array().unwrap(),
                |k| shell(k) * ordered * na * nb / volume,
                &format!("{what} {name}"),
            );
        }
        // The partials weighted by their pairs' share add up to the total.
        let n: usize = g
            .partial
            .iter()
            .filter(|p| p.kinds[0] == p.kinds[1])
            .map(|p| p.atoms[0])
            .sum();
        for bin in 0..bins {
            let sum: f64 = g
                .partial
                .iter()
                .map(|p| {
                    let w = (p.atoms[0] * p.atoms[1]) as f64 / (n * n) as f64;
                    let ordered = if p.kinds[0] == p.kinds[1] { 1.0 } else { 2.0 };
                    ordered * w * p.g[bin]
                })
                .sum();
            assert!(
                (sum - g.total[bin]).abs() <= 1e-9 * g.total[bin].max(1.0),
                "{what} bin {bin}"
            );
        }
        checked += 1;
    }
    assert_eq!(checked, 3);
}

#[test]
fn what_has_no_rdf_is_refused_with_the_reason() {
    let mut frame = frame_of("small.xyz", 0);
    // More than half the 15 Å cell.
    let e = rdf(&frame, 7.6, 10, false).unwrap_err();
    assert!(matches!(e, RdfError::CutoffTooLong { .. }), "{e}");
    assert!(e.to_string().contains("up to 7.50 Å"), "{e}");
    assert_eq!(
        rdf(&frame, 5.0, 0, false).unwrap_err(),
        RdfError::BadBins(0)
    );
    assert_eq!(
        rdf(&frame, 0.3, 10, false).unwrap_err(),
        RdfError::BadCutoff(0.3)
    );
    frame.cell = None;
    assert_eq!(rdf(&frame, 5.0, 10, false).unwrap_err(), RdfError::NoCell);
    frame.positions.truncate(1);
    frame.types.truncate(1);
    frame.names.truncate(1);
    frame.elements.truncate(1);
    frame.cell = frame_of("small.xyz", 0).cell;
    assert_eq!(
        rdf(&frame, 5.0, 10, false).unwrap_err(),
        RdfError::TooFewAtoms(1)
    );
}

//! Hydrogen bonds against MDAnalysis 2.11's HydrogenBondAnalysis on a solvated protein in a
//! triclinic box (adk_oplsaa: 47,681 atoms, rhombic dodecahedron), two frames; the reference,
//! topology and trajectory are written by `tests/data/gen_hbonds.py`. MDAnalysis takes its
//! donor–hydrogen bonds from the GROMACS TPR, which texmap does not read: here they come from
//! bonds by distance, so the comparison also checks that those find every polar hydrogen.

use std::collections::BTreeSet;
use std::io::Read;

use texmap_md_io::bonds::bonds_by_distance;
use texmap_md_io::hbonds::{Criteria, HBondError, donor_hydrogens, hydrogen_bonds};
use texmap_md_io::{Frame, Label, Topology, Trajectory, UnitCell};

fn data(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/hbonds")
        .join(name)
}

type Triple = (u32, u32, u32);

fn reference() -> (usize, Vec<BTreeSet<Triple>>) {
    let mut text = String::new();
    flate2::read::GzDecoder::new(std::fs::File::open(data("reference.json.gz")).unwrap())
        .read_to_string(&mut text)
        .unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let frames = v["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            let flat: Vec<u32> = f["dha"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_u64().unwrap() as u32)
                .collect();
            flat.chunks(3).map(|c| (c[0], c[1], c[2])).collect()
        })
        .collect();
    (v["n_atoms"].as_u64().unwrap() as usize, frames)
}

/// The D–A distance and D–H···A angle of a triple, for the report of a disagreement.
fn geometry(frame: &Frame, (d, h, a): Triple) -> (f64, f64) {
    let cell = frame.cell.unwrap();
    let p = |i: u32| frame.positions[i as usize].map(f64::from);
    let disp = |from: u32, to: u32| {
        let (f, t) = (p(from), p(to));
        texmap_md_io::pbc::minimum_image(&cell, std::array::from_fn(|k| t[k] - f[k]))
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let da = disp(d, a);
    let (hd, ha) = (disp(h, d), disp(h, a));
    let angle = (dot(hd, ha) / (dot(hd, hd) * dot(ha, ha)).sqrt())
        .acos()
        .to_degrees();
    (dot(da, da).sqrt(), angle)
}

#[test]
fn matches_mdanalysis_on_a_solvated_protein_in_a_triclinic_box() {
    let (n_atoms, want) = reference();
    let top = Topology::open(data("adk_top.gro.gz")).unwrap();
    let mut traj = Trajectory::open(data("adk_0_9.xtc")).unwrap();
    let mut frame = Frame::new();
    let mut k = 0;
    while traj.read_next(&mut frame).unwrap() {
        top.apply(&mut frame, "adk_0_9.xtc", k).unwrap();
        assert_eq!(frame.n_atoms(), n_atoms);
        let cell = frame.cell.expect("the XTC has a box");
        assert!(!cell.is_orthorhombic());
        let bonds = bonds_by_distance(&frame, true);
        let dh = donor_hydrogens(&frame, &bonds.pairs);
        let got: BTreeSet<Triple> = hydrogen_bonds(&frame, &dh, None, Criteria::default())
            .unwrap()
            .iter()
            .map(|b| (b.donor, b.hydrogen, b.acceptor))
            .collect();
        // A triple one side finds and the other does not must lie on a cutoff, where the
        // rounding of the f32 positions decides: frame 0 has one, a donor-acceptor pair 3.00 Å
        // apart in the file (the XTC's 0.01 Å grid), 3.0000005 Å between the f32 positions,
        // which MDAnalysis's f32 arithmetic keeps and ours drops.
        let mut report = Vec::new();
        for t in got.symmetric_difference(&want[k]) {
            let (dist, angle) = geometry(&frame, *t);
            let on_edge = (dist - 3.0).abs() < 1e-5 || (angle - 150.0).abs() < 1e-4;
            if !on_edge {
                report.push((*t, want[k].contains(t), dist, angle));
            }
        }
        assert!(
            report.is_empty(),
            "frame {k}: {} bonds, {} in MDAnalysis; disagreements (triple, in MDAnalysis, \
             distance, angle): {:?}",
            got.len(),
            want[k].len(),
            &report[..report.len().min(20)]
        );
        assert!(got.len() > 13_000, "frame {k}: {}", got.len());
        k += 1;
    }
    assert_eq!(k, want.len());
}

fn water_dimer(shift: f32) -> Frame {
    let mut frame = Frame::new();
    frame.names = ["OW", "HW1", "HW2", "OW", "HW1", "HW2"]
        .map(|n| Label::new(n).unwrap())
        .to_vec();
    // Donor O at the origin, its first H along +x toward the acceptor 2.9 Å away.
    frame.positions = vec![
        [0.0, 0.0, 0.0],
        [0.96, 0.0, 0.0],
        [-0.24, 0.93, 0.0],
        [2.9, 0.0, 0.0],
        [3.15, 0.93, 0.0],
        [3.15, -0.47, 0.81],
    ];
    for p in &mut frame.positions {
        p[0] += shift;
    }
    frame
}

#[test]
fn criteria_are_the_distance_and_angle_stated() {
    let frame = water_dimer(5.0);
    let dh = [[0, 1], [0, 2], [3, 4], [3, 5]];
    let at = |c: Criteria| hydrogen_bonds(&frame, &dh, None, c).unwrap().len();
    assert_eq!(at(Criteria::default()), 1);
    // 2.9 Å: out at a 2.85 Å cutoff, in at 2.95.
    assert_eq!(
        at(Criteria {
            distance: 2.85,
            ..Criteria::default()
        }),
        0
    );
    assert_eq!(
        at(Criteria {
            distance: 2.95,
            ..Criteria::default()
        }),
        1
    );
    // Bend the hydrogen 40° off the O···O line: the angle at H drops to about 124°.
    let mut bent = frame.clone();
    let t = 40f32.to_radians();
    bent.positions[1] = [5.0 + 0.96 * t.cos(), 0.96 * t.sin(), 0.0];
    let b = hydrogen_bonds(&bent, &dh, None, Criteria::default()).unwrap();
    assert!(b.is_empty());
    let b = hydrogen_bonds(
        &bent,
        &dh,
        None,
        Criteria {
            angle: 120.0,
            ..Criteria::default()
        },
    )
    .unwrap();
    assert_eq!(b.len(), 1);
    // The angle at H of the triangle O(0,0), H(0.96 cos t, 0.96 sin t), O(2.9, 0).
    let h = [0.96 * t.cos() as f64, 0.96 * t.sin() as f64];
    let (u, v) = ([-h[0], -h[1]], [2.9 - h[0], -h[1]]);
    let want = ((u[0] * v[0] + u[1] * v[1])
        / ((u[0] * u[0] + u[1] * u[1]) * (v[0] * v[0] + v[1] * v[1])).sqrt())
    .acos()
    .to_degrees();
    assert!(
        (b[0].angle as f64 - want).abs() < 1e-3,
        "{} {want}",
        b[0].angle
    );
}

#[test]
fn a_bond_across_the_box_is_found_by_its_nearest_image() {
    // The dimer straddling the face x = 0 of a 20 Å box: the acceptor at x = 1.4, the donor
    // at x = −1.5 written wrapped as 18.5.
    let mut frame = water_dimer(-1.5);
    for p in &mut frame.positions {
        if p[0] < 0.0 {
            p[0] += 20.0;
        }
    }
    let dh = [[0, 1], [0, 2], [3, 4], [3, 5]];
    let open = hydrogen_bonds(&frame, &dh, None, Criteria::default()).unwrap();
    assert!(open.is_empty(), "no bond without the box: {open:?}");
    frame.cell = Some(UnitCell::orthorhombic(20.0, 20.0, 20.0).unwrap());
    let b = hydrogen_bonds(&frame, &dh, None, Criteria::default()).unwrap();
    assert_eq!(b.len(), 1);
    assert_eq!((b[0].donor, b[0].hydrogen, b[0].acceptor), (0, 1, 3));
    assert!((b[0].distance - 2.9).abs() < 1e-4, "{}", b[0].distance);
}

#[test]
fn a_mask_keeps_only_bonds_within_it_and_bad_criteria_are_refused() {
    let frame = water_dimer(0.0);
    let dh = [[0, 1], [0, 2], [3, 4], [3, 5]];
    let c = Criteria::default();
    let without_acceptor = [true, true, true, false, true, true];
    assert!(
        hydrogen_bonds(&frame, &dh, Some(&without_acceptor), c)
            .unwrap()
            .is_empty()
    );
    let without_hydrogen = [true, false, true, true, true, true];
    assert!(
        hydrogen_bonds(&frame, &dh, Some(&without_hydrogen), c)
            .unwrap()
            .is_empty()
    );
    assert_eq!(
        hydrogen_bonds(&frame, &dh, Some(&[true; 6]), c)
            .unwrap()
            .len(),
        1
    );
    // The pairs in any order (and repeated) give the same bonds.
    let shuffled = [[3, 5], [0, 2], [3, 4], [0, 1], [0, 1]];
    assert_eq!(
        hydrogen_bonds(&frame, &shuffled, None, c).unwrap(),
        hydrogen_bonds(&frame, &dh, None, c).unwrap()
    );
    for d in [0.0, 0.45, -3.0, 6.5, f32::NAN, f32::INFINITY] {
        let e = hydrogen_bonds(
            &frame,
            &dh,
            None,
            Criteria {
                distance: d,
                angle: 150.0,
            },
        );
        assert!(matches!(e, Err(HBondError::BadDistance(_))), "{d}");
    }
    for a in [-1.0, 180.5, f32::NAN] {
        let e = hydrogen_bonds(
            &frame,
            &dh,
            None,
            Criteria {
                distance: 3.0,
                angle: a,
            },
        );
        assert!(matches!(e, Err(HBondError::BadAngle(_))), "{a}");
    }
    let mut small = frame.clone();
    small.cell = Some(UnitCell::orthorhombic(8.0, 8.0, 8.0).unwrap());
    let e = hydrogen_bonds(&small, &dh, None, c).unwrap_err();
    assert!(e.to_string().contains("--replicate"), "{e}");
}

/// `hbonds::lifetime` is MDAnalysis's hydrogen-bond lifetime autocorrelation
/// (lib.correlations' correct_intermittency and autocorrelation, gen_lifetime.py) on 80
/// synthetic bonds switching on and off over 200 frames, continuous and with gaps of up to 2
/// frames forgiven, at every lag to 30.
#[test]
fn lifetime_is_mdanalysis_autocorrelation() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/hbonds/lifetime_reference.json");
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let frames: Vec<Vec<[u32; 2]>> = r["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            f.as_array()
                .unwrap()
                .iter()
                .map(|p| [0, 1].map(|k| p[k].as_u64().unwrap() as u32))
                .collect()
        })
        .collect();
    for inter in [0usize, 2] {
        let want: Vec<f64> = r[format!("intermittency_{inter}")]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let got = texmap_md_io::hbonds::lifetime(&frames, 30, inter);
        assert_eq!(got.len(), want.len());
        for (tau, (g, w)) in got.iter().zip(&want).enumerate() {
            assert!(
                (g - w).abs() < 1e-12,
                "intermittency {inter}, lag {tau}: {g} vs {w}"
            );
        }
    }
    // Fewer frames than lags: the curve stops at the last frame; no frames, no curve.
    assert_eq!(texmap_md_io::hbonds::lifetime(&frames[..5], 30, 0).len(), 5);
    assert!(texmap_md_io::hbonds::lifetime(&[], 30, 0).is_empty());
}

// Salt bridges (`saltbridges`), here rather than in a test binary of their own.

fn saltbridge_reference() -> serde_json::Value {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/saltbridges/reference.json");
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Salt bridges by VMD's saltbr criterion against the same criterion computed with
/// MDAnalysis 2.11's `distance_array` and `minimize_vectors` (periodic minimum image) on the
/// solvated adenylate kinase (triclinic box, GROMACS's LYSH and HISB), two frames, at 3.2 Å
/// without histidines and 4.0 Å with (`tests/data/saltbridges/gen_saltbridges.py`): the same
/// pairs, both distances to 1e-3 Å; again with the system moved by half the box and wrapped.
#[test]
fn saltbridges_match_mdanalysis_distances_on_a_solvated_protein() {
    use texmap_md_io::saltbridges::{charged_groups, salt_bridges};
    let r = saltbridge_reference();
    let top = Topology::open(data("adk_top.gro.gz")).unwrap();
    let protein = texmap_md_io::select::Selection::parse("protein").unwrap();
    for (run, shifted) in r["runs"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|run| [(run, false), (run, true)])
    {
        let cutoff = run["cutoff"].as_f64().unwrap() as f32;
        let his = run["histidine"].as_bool().unwrap();
        let mut traj = Trajectory::open(data("adk_0_9.xtc")).unwrap();
        let mut frame = Frame::new();
        let mut k = 0;
        while traj.read_next(&mut frame).unwrap() {
            top.apply(&mut frame, "adk_0_9.xtc", k).unwrap();
            assert!(!frame.cell.unwrap().is_orthorhombic());
            let mut mask = vec![false; frame.n_atoms()];
            for i in protein.indices(&frame).unwrap() {
                mask[i] = true;
            }
            // Every other pass, the frame moved by half the box and wrapped, so that the
            // protein lies across the faces: the same bridges through the nearest images.
            if shifted {
                let m = frame.cell.unwrap().matrix();
                for q in &mut frame.positions {
                    for k in 0..3 {
                        q[k] += ((m[0][k] + m[1][k] + m[2][k]) / 2.0) as f32;
                    }
                }
                texmap_md_io::pbc::wrap(&mut frame);
            }
            let groups = charged_groups(&frame, Some(&mask), his);
            assert_eq!(groups.acids.len() as u64, run["acids"].as_u64().unwrap());
            assert_eq!(groups.bases.len() as u64, run["bases"].as_u64().unwrap());
            let got: Vec<(usize, usize, f32, f32)> = salt_bridges(&frame, &groups, cutoff)
                .unwrap()
                .iter()
                .map(|b| {
                    (
                        groups.acids[b.acid].residue,
                        groups.bases[b.base].residue,
                        b.distance,
                        b.min_distance,
                    )
                })
                .collect();
            let want: Vec<(usize, usize, f64, f64)> = run["frames"][k]
                .as_array()
                .unwrap()
                .iter()
                .map(|row| {
                    (
                        row[0].as_u64().unwrap() as usize,
                        row[1].as_u64().unwrap() as usize,
                        row[2].as_f64().unwrap(),
                        row[3].as_f64().unwrap(),
                    )
                })
                .collect();
            let got_pairs: Vec<(usize, usize)> = got.iter().map(|t| (t.0, t.1)).collect();
            let want_pairs: Vec<(usize, usize)> = want.iter().map(|t| (t.0, t.1)).collect();
            assert_eq!(
                got_pairs, want_pairs,
                "cutoff {cutoff}, frame {k}, shifted {shifted}"
            );
            assert!(got.len() >= 16, "{}", got.len());
            for (g, w) in got.iter().zip(&want) {
                assert!(
                    (f64::from(g.2) - w.2).abs() < 1e-3 && (f64::from(g.3) - w.3).abs() < 1e-3,
                    "cutoff {cutoff}, frame {k}, shifted {shifted}: {g:?} vs {w:?}"
                );
            }
            k += 1;
        }
        assert_eq!(k, 2);
    }
}

/// An aspartate (OD1, OD2) and an arginine (NH1, NH2, NE) with NH1 `gap` Å beyond OD1 along
/// x, starting at `x0`.
fn asp_arg(x0: f32, gap: f32) -> Frame {
    let mut frame = Frame::new();
    let l = |s: &str| Label::new(s).unwrap();
    frame.names = ["CG", "OD1", "OD2", "CZ", "NH1", "NH2", "NE"]
        .map(l)
        .to_vec();
    frame.res_names = ["ASP", "ASP", "ASP", "ARG", "ARG", "ARG", "ARG"]
        .map(l)
        .to_vec();
    frame.res_ids = vec![7, 7, 7, 9, 9, 9, 9];
    let o1 = x0 + 1.0;
    let n1 = o1 + gap;
    frame.positions = vec![
        [x0, 0.0, 0.0],
        [o1, 1.0, 0.0],
        [o1 - 0.5, 2.0, 0.0],
        [n1 + 1.0, 1.0, 1.0],
        [n1, 1.0, 0.0],
        [n1 + 1.5, 0.0, 1.2],
        [n1 + 1.6, 2.0, 1.6],
    ];
    frame
}

#[test]
fn a_salt_bridge_is_in_or_out_by_the_cutoff_and_found_across_the_box() {
    use texmap_md_io::saltbridges::{SaltBridgeError, charged_groups, salt_bridges};
    let frame = asp_arg(5.0, 3.3);
    let groups = charged_groups(&frame, None, false);
    assert_eq!(groups.acids[0].atoms, [1, 2]);
    assert_eq!(groups.bases[0].atoms, [4, 5, 6]);
    assert!(salt_bridges(&frame, &groups, 3.2).unwrap().is_empty());
    let b = salt_bridges(&frame, &groups, 3.5).unwrap();
    assert_eq!(b.len(), 1);
    assert!((b[0].min_distance - 3.3).abs() < 1e-5, "{b:?}");
    // The centroids: O (o1 - 0.25, 1.5, 0), N (n1 + 1.033.., 1, 0.933..).
    let p = &frame.positions;
    let c = |ids: &[usize]| -> [f64; 3] {
        std::array::from_fn(|k| {
            ids.iter().map(|&i| f64::from(p[i][k])).sum::<f64>() / ids.len() as f64
        })
    };
    let (o, n) = (c(&[1, 2]), c(&[4, 5, 6]));
    let want = ((0..3).map(|k| (o[k] - n[k]).powi(2)).sum::<f64>()).sqrt();
    assert!(
        (f64::from(b[0].distance) - want).abs() < 1e-5,
        "{b:?} {want}"
    );
    // A mask without the arginine's nitrogens: no base.
    let mask = [true, true, true, true, false, false, false];
    assert!(charged_groups(&frame, Some(&mask), false).bases.is_empty());

    // Across the face x = 0 of a 20 Å box: the aspartate at x −3..−1.5, written wrapped.
    let mut wrapped = asp_arg(-3.0, 3.0);
    for q in &mut wrapped.positions {
        if q[0] < 0.0 {
            q[0] += 20.0;
        }
    }
    let groups = charged_groups(&wrapped, None, false);
    assert!(salt_bridges(&wrapped, &groups, 3.2).unwrap().is_empty());
    wrapped.cell = Some(UnitCell::orthorhombic(20.0, 20.0, 20.0).unwrap());
    let b = salt_bridges(&wrapped, &groups, 3.2).unwrap();
    assert_eq!(b.len(), 1);
    assert!((b[0].min_distance - 3.0).abs() < 1e-4, "{b:?}");
    let unwrapped = asp_arg(-3.0, 3.0);
    let open = salt_bridges(&unwrapped, &groups, 3.2).unwrap();
    assert!(
        (b[0].distance - open[0].distance).abs() < 1e-4,
        "{b:?} {open:?}"
    );

    // Histidine only when asked; bad cutoffs and a small cell are refused.
    let mut his = asp_arg(5.0, 3.0);
    for (i, name) in ["CG", "ND1", "NE2", "CE1"].iter().enumerate() {
        his.names[3 + i] = Label::new(name).unwrap();
        his.res_names[3 + i] = Label::new("HSD").unwrap();
    }
    assert!(charged_groups(&his, None, false).bases.is_empty());
    let g = charged_groups(&his, None, true);
    assert_eq!(g.bases[0].atoms, [4, 5]);
    assert_eq!(salt_bridges(&his, &g, 3.2).unwrap().len(), 1);
    for c in [0.0, 0.45, -1.0, 8.5, f32::NAN] {
        assert!(matches!(
            salt_bridges(&frame, &groups, c),
            Err(SaltBridgeError::BadCutoff(_))
        ));
    }
    let mut small = frame.clone();
    small.cell = Some(UnitCell::orthorhombic(9.0, 9.0, 9.0).unwrap());
    let e = salt_bridges(&small, &groups, 3.2).unwrap_err();
    assert!(e.to_string().contains("--replicate"), "{e}");
}

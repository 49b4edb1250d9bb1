//! Lattice orientations (`texmap_md_io::orientation`) and grains (`texmap_md_io::grains`)
//! against OVITO 3.17's Polyhedral template matching and Grain segmentation modifiers on
//! polycrystals OVITO wrote (tests/data/grains, gen_grains.py): FCC aluminium, BCC iron and
//! HCP magnesium, each a periodic cube of Voronoi grains in random orientations with thermal
//! noise.

use texmap_md_io::Frame;
use texmap_md_io::cna::{StructureType, classify};
use texmap_md_io::grains::{GrainOptions, segment};
use texmap_md_io::orientation::{LatticeFit, Symmetry, disorientation, orientations};

use crate::support;
use support::ovito::*;

const DATA: Fixtures = Fixtures("grains");

fn quaternions(v: &serde_json::Value) -> Vec<[f64; 4]> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|q| {
            let q = numbers(q);
            [q[0], q[1], q[2], q[3]]
        })
        .collect()
}

/// A system: OVITO's results, the frame, its a-CNA types and lattice fits.
struct System {
    case: serde_json::Value,
    frame: Frame,
    types: Vec<StructureType>,
    fits: Vec<Option<LatticeFit>>,
}

fn systems() -> Vec<System> {
    let refs = DATA.json("grains_reference.json");
    let cases = refs["systems"].as_array().unwrap().clone();
    cases
        .into_iter()
        .map(|case| {
            let frame = DATA.frame(case["file"].as_str().unwrap());
            let types = classify(&frame);
            let fits = orientations(&frame, &types);
            System {
                case,
                frame,
                types,
                fits,
            }
        })
        .collect()
}

#[test]
fn disorientations_are_ovitos() {
    let refs = DATA.json("grains_reference.json");
    let pairs = &refs["pairs"];
    let (a, b) = (quaternions(&pairs["a"]), quaternions(&pairs["b"]));
    for (name, sym) in [
        ("cubic", Symmetry::Cubic),
        ("hexagonal", Symmetry::Hexagonal),
    ] {
        let expected = numbers(&pairs[name]);
        for i in 0..a.len() {
            let ours = disorientation(a[i], b[i], sym);
            assert!(
                (ours - expected[i]).abs() < 1e-9,
                "{name} pair {i}: {ours} against OVITO's {}",
                expected[i]
            );
        }
    }
}

#[test]
fn orientations_and_rmsd_are_ptms() {
    for System {
        case, types, fits, ..
    } in systems()
    {
        let file = case["file"].as_str().unwrap();
        let ptm_types = integers(&case["structure"]);
        let ptm_q = quaternions(&case["orientation"]);
        let ptm_rmsd = numbers(&case["rmsd"]);
        let (mut both, mut same_q, mut worst_angle, mut worst_rmsd) = (0, 0, 0f64, 0f64);
        for i in 0..types.len() {
            if types[i] == StructureType::Other || ptm_types[i] != types[i] as i64 {
                continue;
            }
            let fit = fits[i].expect("a crystalline atom has a fit");
            both += 1;
            let q = fit.orientation;
            let r = ptm_q[i];
            let dot: f64 = (0..4).map(|k| q[k] * r[k]).sum();
            if dot.abs() > 1.0 - 1e-6 {
                same_q += 1;
            }
            worst_angle = worst_angle.max(disorientation(q, r, fit.symmetry));
            worst_rmsd = worst_rmsd.max((fit.rmsd - ptm_rmsd[i]).abs());
        }
        println!(
            "{file}: {both} atoms crystalline in both, {same_q} with OVITO's quaternion, worst angle {worst_angle:.3e} rad, worst RMSD difference {worst_rmsd:.3e}"
        );
        assert!(
            both > types.len() / 3,
            "{file}: {both} of {} crystalline",
            types.len()
        );
        assert!(worst_angle < 1e-5, "{file}: {worst_angle}");
        assert!(worst_rmsd < 1e-6, "{file}: {worst_rmsd}");
        // OVITO stores quaternions in f32: the same one, in the same fundamental zone.
        assert_eq!(same_q, both, "{file}: quaternions other than OVITO's");
    }
}

#[test]
fn grains_are_ovitos() {
    for System {
        case,
        frame,
        types,
        fits,
    } in systems()
    {
        let file = case["file"].as_str().unwrap();
        let ours = segment(&frame, &types, &fits, &GrainOptions::default());
        let theirs = integers(&case["grain"]);
        let ovito_sizes = integers(&case["grain_size"]);
        let ovito_q = quaternions(&case["grain_orientation"]);
        println!(
            "{file}: ours {:?}, OVITO's {:?}",
            ours.grains
                .iter()
                .map(|g| (g.size, g.crystalline))
                .collect::<Vec<_>>(),
            ovito_sizes
        );
        assert_eq!(ours.grains.len(), ovito_sizes.len(), "{file}: grain count");
        // Which of OVITO's grains each of ours is: where most of its crystalline atoms are.
        let g = ours.grains.len();
        let mut votes = vec![vec![0usize; g]; g];
        for i in 0..theirs.len() {
            if fits[i].is_some() && ours.grain[i] >= 0 && theirs[i] >= 0 {
                votes[ours.grain[i] as usize][theirs[i] as usize] += 1;
            }
        }
        let map: Vec<usize> = votes
            .iter()
            .map(|v| (0..g).max_by_key(|&k| v[k]).unwrap())
            .collect();
        let (mut crystal, mut crystal_same, mut all_same) = (0, 0, 0);
        for i in 0..theirs.len() {
            let same = ours.grain[i] >= 0 && theirs[i] == map[ours.grain[i] as usize] as i64;
            if fits[i].is_some() {
                crystal += 1;
                crystal_same += same as usize;
            }
            all_same += same as usize;
        }
        println!(
            "{file}: map {map:?}; crystalline atoms in OVITO's grain {crystal_same} of {crystal}, all atoms {all_same} of {}",
            theirs.len()
        );
        // Numbered as OVITO numbers them; every crystalline atom in OVITO's grain; orphans
        // adopted as OVITO adopts them but at a few atoms where two grains are equally near.
        assert_eq!(map, (0..g).collect::<Vec<_>>(), "{file}: grain numbering");
        assert_eq!(
            crystal_same, crystal,
            "{file}: crystalline atoms in another grain"
        );
        assert!(
            all_same * 100 >= theirs.len() * 99,
            "{file}: {all_same} of {} atoms",
            theirs.len()
        );
        let symmetry = fits.iter().flatten().next().unwrap().symmetry;
        for (k, grain) in ours.grains.iter().enumerate() {
            let angle = disorientation(grain.orientation, ovito_q[k], symmetry);
            assert!(
                angle < 1e-3,
                "{file}: grain {k}'s mean orientation {angle} rad from OVITO's"
            );
            assert_eq!(
                grain.structure as i64,
                integers(&case["grain_structure"])[k],
                "{file}: grain {k}"
            );
        }
    }
}

#[test]
fn grains_do_not_depend_on_the_thread_count() {
    let frame = DATA.frame("fcc_poly.xyz");
    let run = || {
        let types = classify(&frame);
        let fits = orientations(&frame, &types);
        (
            fits.clone(),
            segment(&frame, &types, &fits, &GrainOptions::default()),
        )
    };
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(run);
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap()
        .install(run);
    assert!(one == two);
}

/// Stacking faults and twin boundaries (tests/data/grains/gen_faults.py): with the faults
/// joined, two intrinsic faults leave one grain and two twin boundaries two grains of OVITO's
/// FCC atoms (the boundary layers join a side, as OVITO's but not necessarily the same one);
/// with them separate, each fault's HCP layers are a grain, as OVITO finds.
#[test]
fn stacking_faults_join_their_grain_as_in_ovito() {
    let refs = DATA.json("faults_reference.json");
    for case in refs.as_array().unwrap() {
        let file = case["file"].as_str().unwrap();
        let frame = DATA.frame(file);
        let types = classify(&frame);
        let fits = orientations(&frame, &types);
        for (key, join) in [("faults_joined", true), ("faults_separate", false)] {
            let options = GrainOptions {
                join_stacking_faults: join,
                ..GrainOptions::default()
            };
            let ours = segment(&frame, &types, &fits, &options);
            let theirs = integers(&case[key]["grain"]);
            let sizes = integers(&case[key]["grain_size"]);
            let ovito_types = integers(&case[key]["structure"]);
            assert_eq!(ours.grains.len(), sizes.len(), "{file} {key}");
            // Our grains map one to one onto OVITO's on the atoms that must agree: all of
            // them, but for the twin boundary layers when joined.
            let mut map = vec![None; sizes.len()];
            let mut agree = 0;
            let mut checked = 0;
            for i in 0..theirs.len() {
                assert_eq!(
                    types[i] as i64, ovito_types[i],
                    "{file}: atom {i}'s structure"
                );
                if join && types[i] == StructureType::Hcp && file == "twins.xyz" {
                    continue;
                }
                let (g, t) = (ours.grain[i], theirs[i]);
                assert!(g >= 0 && t >= 0, "{file} {key}: atom {i} in no grain");
                let m = map[g as usize].get_or_insert(t);
                checked += 1;
                agree += (*m == t) as usize;
            }
            println!(
                "{file} {key}: {agree} of {checked} atoms in OVITO's grain, grains {:?} against {sizes:?}",
                ours.grains.iter().map(|g| g.size).collect::<Vec<_>>()
            );
            assert_eq!(agree, checked, "{file} {key}");
        }
    }
}

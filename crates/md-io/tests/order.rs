//! Lipid tail order parameters against GROMACS 2022.5's `gmx order` and an independent numpy
//! computation on the same file (data/order/gen_order.py): a model bilayer of 32 two-chain
//! lipids with ideal hydrogens, 12 frames written by MDAnalysis as GRO + XTC, shifted so that
//! lipids on the edges are split across the box; bonds found by distance as the CLI finds them.

use std::path::PathBuf;

use serde_json::Value;
use texmap_md_io::order::{Method, OrderParameters};
use texmap_md_io::select::Selection;
use texmap_md_io::{Frame, Trajectory};

fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/order")
}

/// The GRO's frame (names, cell), the XTC's frames' positions and cells, the bonds by distance.
fn system() -> (Frame, Vec<Frame>, Vec<[u32; 2]>) {
    let mut gro = Frame::new();
    Trajectory::open(dir().join("bilayer.gro"))
        .unwrap()
        .read_frame(0, &mut gro)
        .unwrap();
    let bonds = texmap_md_io::bonds::bonds_by_distance(&gro, true).pairs;
    let mut xtc = Trajectory::open(dir().join("bilayer.xtc")).unwrap();
    let frames = (0..xtc.n_frames().unwrap())
        .map(|k| {
            let mut f = Frame::new();
            xtc.read_frame(k, &mut f).unwrap();
            f
        })
        .collect();
    (gro, frames, bonds)
}

fn run(method: Method) -> (OrderParameters, Value) {
    let (gro, frames, bonds) = system();
    let text = std::fs::read_to_string(dir().join("reference.json")).unwrap();
    let reference: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(frames.len() as u64, reference["frames"].as_u64().unwrap());
    // 32 lipids, each a P and 2 x 14 carbons with 29 hydrogens per chain: 31 bonds per chain.
    assert_eq!(bonds.len(), 32 * 2 * (13 + 29));
    let picked = Selection::parse("name C2* C3*")
        .unwrap()
        .evaluate(&gro)
        .unwrap();
    let mut order = OrderParameters::new(&gro, &picked, &bonds, method, 2).unwrap();
    for f in &frames {
        order.add(&f.positions, f.cell.as_ref()).unwrap();
    }
    (order, reference)
}

/// Our value per group name against the reference's table, to `tolerance`.
fn check(order: &OrderParameters, values: &[f64], table: &Value, sign: f64, tolerance: f64) {
    let table = table.as_object().unwrap();
    assert_eq!(order.groups().len(), table.len(), "{:?}", order.groups());
    for (g, v) in order.groups().iter().zip(values) {
        assert_eq!(g.residue, "DPPC");
        assert_eq!(g.sites, 32, "{}", g.name);
        let want = sign * table[&g.name].as_f64().unwrap();
        assert!(
            (v - want).abs() < tolerance,
            "{}: {v} against {want}",
            g.name
        );
    }
}

#[test]
fn hydrogens_equal_numpy_carbon_by_carbon_with_the_spread_over_lipids() {
    let (order, reference) = run(Method::Hydrogens);
    let mean = order.mean();
    check(&order, &mean, &reference["hydrogens"], 1.0, 1e-9);
    check(
        &order,
        &order.standard_error(),
        &reference["sem"],
        1.0,
        1e-9,
    );
    // Carbons in chain order, two hydrogens each but the methyls' three.
    assert_eq!(order.groups()[0].name, "C21");
    assert_eq!(order.groups()[13].name, "C214");
    assert_eq!(order.groups()[13].vectors, 3);
    // Each carbon's chain and place along it, from the bonds.
    let place = |k: usize| (order.groups()[k].chain, order.groups()[k].position);
    assert_eq!(
        (place(0), place(13), place(14), place(27)),
        ((1, 1), (1, 14), (2, 1), (2, 14))
    );
    assert_eq!(order.groups()[12].vectors, 2);
    // The values vary along the chain (the test is not of a constant).
    assert!(mean[0] < -0.25 && mean[10].abs() < 0.1, "{mean:?}");
}

#[test]
fn united_atom_equals_gmx_order_and_numpy() {
    let (order, reference) = run(Method::UnitedAtom);
    let mean = order.mean();
    // The first and last carbon of each chain have one heavy neighbour: 12 per chain.
    check(&order, &mean, &reference["united_atom"], 1.0, 1e-9);
    // gmx order prints −S_CD, computed in single precision from whole lipids.
    check(&order, &mean, &reference["gmx_order"], -1.0, 3e-5);
    // The ideal hydrogens give the same values but for the XTC's 0.01 Å rounding.
    let (h, _) = run(Method::Hydrogens);
    let hm = h.mean();
    for (g, v) in order.groups().iter().zip(&mean) {
        let k = h.groups().iter().position(|x| x.name == g.name).unwrap();
        assert!(
            (hm[k] - v).abs() < 0.01,
            "{}: {} against {v}",
            g.name,
            hm[k]
        );
    }
}

#[test]
fn bonds_equal_numpy_and_lipids_split_across_the_box_count_whole() {
    let (order, reference) = run(Method::Bonds);
    check(&order, &order.mean(), &reference["bonds"], 1.0, 1e-9);
    assert_eq!(order.groups()[0].name, "C21-C22");
    // Some bonds of the file are split across the box: without the cell they would be long.
    let (_, frames, bonds) = system();
    let split = bonds
        .iter()
        .filter(|[i, j]| {
            let (p, q) = (
                frames[0].positions[*i as usize],
                frames[0].positions[*j as usize],
            );
            (0..3).map(|k| (p[k] - q[k]).powi(2)).sum::<f32>() > 100.0
        })
        .count();
    assert!(split > 10, "{split}");
}

/// The leaflets of the P atoms equal LeafletFinder's (cutoff 25 Å, pbc=True); the thickness,
/// through the tails across the box's bottom face (50 Å, where the water between the periodic
/// images is 30 Å), equals the mean P heights' difference in the frames before the shift to
/// the XTC's rounding; the areas per lipid are the box's over 16.
#[test]
fn leaflets_are_leaflet_finders_and_the_thickness_is_through_the_tails() {
    let (gro, frames, _) = system();
    let text = std::fs::read_to_string(dir().join("reference.json")).unwrap();
    let reference: Value = serde_json::from_str(&text).unwrap();
    let m = &reference["membrane"];
    let heads = Selection::parse("name P").unwrap().indices(&gro).unwrap();
    let found = texmap_md_io::membrane::leaflets(
        &frames[0].positions,
        &heads,
        frames[0].cell.as_ref(),
        m["cutoff"].as_f64().unwrap(),
    );
    let resids = |l: &[usize]| -> Vec<u64> { l.iter().map(|&i| gro.res_ids[i] as u64).collect() };
    let want: Vec<Vec<u64>> = m["leaflets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| {
            g.as_array()
                .unwrap()
                .iter()
                .map(|r| r.as_u64().unwrap())
                .collect()
        })
        .collect();
    assert_eq!(found.iter().map(|l| resids(l)).collect::<Vec<_>>(), want);
    // Each P's tail: the last methyl carbon of its sn-2 chain (87 atoms a lipid).
    let tail = |h: usize| Some(h + 1 + 13 * 3);
    let upper: Vec<u64> = m["upper_resids"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r.as_u64().unwrap())
        .collect();
    for (f, want) in frames.iter().zip(m["thickness"].as_array().unwrap()) {
        let b = texmap_md_io::membrane::measure(&f.positions, &found, f.cell.as_ref(), 2, tail)
            .unwrap();
        let want = want.as_f64().unwrap();
        assert!(
            (b.thickness - want).abs() < 0.005,
            "{} vs {want}",
            b.thickness
        );
        assert_eq!(b.area, m["area"].as_f64().unwrap());
        assert_eq!(b.area_per_lipid, [400.0, 400.0]);
        // The upper leaflet's heads sit near z = 5 after the shift, the lower's near 35.
        let top = found.iter().find(|l| resids(l) == upper).unwrap();
        assert!(
            (b.heights[0] - f.positions[top[0]][2] as f64).abs() < 3.0,
            "{b:?}"
        );
        // Through the water instead: 80 − 50.
        let near =
            texmap_md_io::membrane::measure(&f.positions, &found, f.cell.as_ref(), 2, |_| None)
                .unwrap();
        assert!((near.thickness - (80.0 - want)).abs() < 0.005, "{near:?}");
    }
}

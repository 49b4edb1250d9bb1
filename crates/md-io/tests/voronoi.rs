//! Voronoi analysis (`texmap_md_io::voronoi`) against OVITO 3.17's Voronoi analysis modifier
//! (voro++) on systems OVITO wrote (tests/data/voronoi, gen_voronoi.py): a noisy FCC crystal,
//! whose cells are near-degenerate rhombic dodecahedra with sliver faces at their octahedral
//! corners, and a dense disordered packing. Volumes must be OVITO's within f32 coordinates,
//! and face counts and Voronoi indices OVITO's atom for atom; the cells tile the periodic cell.

use texmap_md_io::Frame;
use texmap_md_io::voronoi::voronoi;

use crate::support;
use support::ovito::*;

const DATA: Fixtures = Fixtures("voronoi");

#[test]
fn every_cell_is_ovitos() {
    let cases = DATA.json("voronoi_reference.json");
    for case in cases.as_array().unwrap() {
        let file = case["file"].as_str().unwrap();
        let frame = DATA.frame(file);
        let v = voronoi(&frame).unwrap();
        let volumes = numbers(&case["volume"]);
        let (worst, at) = v
            .volume
            .iter()
            .zip(&volumes)
            .enumerate()
            .map(|(i, (&a, &b))| ((a as f64 - b).abs() / b, i))
            .fold((0.0, 0), |m, x| if x.0 > m.0 { x } else { m });
        let total: f64 = v.volume.iter().map(|&x| x as f64).sum();
        let cell = frame.cell.unwrap().volume();
        let faces_differ = v
            .faces
            .iter()
            .zip(case["faces"].as_array().unwrap())
            .filter(|(a, b)| **a as u64 != b.as_u64().unwrap())
            .count();
        let index_differ = v
            .index
            .iter()
            .zip(case["index"].as_array().unwrap())
            .filter(|(a, b)| {
                let b: Vec<u64> = b
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_u64().unwrap())
                    .collect();
                a.iter().map(|&x| x as u64).collect::<Vec<_>>() != b
            })
            .count();
        println!(
            "{file}: worst volume {worst:.1e} (atom {at}), sum {total:.3} of {cell:.3} Å³, \
             {faces_differ} face counts and {index_differ} indices differ of {}",
            v.faces.len()
        );
        assert!(
            worst < 1e-5,
            "{file}: atom {at}: {} vs {}",
            v.volume[at],
            volumes[at]
        );
        assert!((total - cell).abs() < 1e-5 * cell);
        assert_eq!(faces_differ, 0, "{file}");
        assert_eq!(index_differ, 0, "{file}");
    }
}

#[test]
fn open_frames_and_bad_atoms_are_refused() {
    let mut frame = Frame::new();
    frame.positions = vec![[0.0; 3], [1.0, 0.0, 0.0]];
    assert!(
        voronoi(&frame)
            .unwrap_err()
            .to_string()
            .contains("no cell periodic along all three edges")
    );
    frame.cell = Some(texmap_md_io::UnitCell::orthorhombic(5.0, 5.0, 5.0).unwrap());
    frame.positions[1][2] = f32::NAN;
    assert!(voronoi(&frame).unwrap_err().to_string().contains("atom 1"));
    frame.positions.pop();
    assert!(voronoi(&frame).is_err());
}

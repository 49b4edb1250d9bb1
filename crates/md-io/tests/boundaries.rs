//! Cells that are not periodic along every edge, as OVITO 3.17.2 writes and reads them
//! (tests/data/boundaries/, by gen_boundaries.py): a copper film periodic along x and y only,
//! its cell shrink-wrapped along z (a LAMMPS dump with `pp pp ff` and extended XYZ with
//! `pbc="T T F"`), and a copper nanoparticle in a box shrink-wrapped on all sides (`ff ff ff`).
//! Every atom's adaptive CNA type and coordination number must be OVITO's, which sees no image
//! across an open edge; taken as periodic, the film's surfaces would meet their own images.

use std::io::Cursor;
use std::path::Path;

use texmap_md_io::cna::classify;
use texmap_md_io::coordination::coordination;
use texmap_md_io::{Format, Frame, Trajectory, Writer};

fn data(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/boundaries")
        .join(name)
}

fn reference() -> serde_json::Value {
    let text = std::fs::read_to_string(data("boundaries_reference.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn read(name: &str) -> Frame {
    let mut t = Trajectory::open(data(name)).unwrap();
    let mut frame = Frame::new();
    assert!(t.read_next(&mut frame).unwrap(), "{name}");
    frame
}

/// The atoms whose CNA type differs from OVITO's `want` (digits per atom).
fn cna_differences(frame: &Frame, want: &str) -> Vec<(usize, u8, u8)> {
    classify(frame)
        .iter()
        .zip(want.bytes())
        .enumerate()
        .filter(|(_, (g, w))| **g as u8 != w - b'0')
        .map(|(i, (g, w))| (i, *g as u8, w - b'0'))
        .collect()
}

#[test]
fn open_edges_see_no_images_as_ovito() {
    let reference = reference();
    for name in ["slab.lammpstrj", "slab.xyz", "particle.lammpstrj"] {
        let want = &reference[name];
        let frame = read(name);
        assert_eq!(frame.n_atoms() as u64, want["atoms"].as_u64().unwrap());
        let pbc: Vec<bool> = want["pbc"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| b.as_bool().unwrap())
            .collect();
        let cell = frame.cell.expect("the file has a cell");
        assert_eq!(cell.periodic().to_vec(), pbc, "{name}");

        let wrong = cna_differences(&frame, want["types"].as_str().unwrap());
        assert!(wrong.is_empty(), "{name}: (atom, ours, OVITO's) {wrong:?}");
        let got = coordination(&frame, 3.0).unwrap();
        let want: Vec<u32> = want["coordination"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_u64().unwrap() as u32)
            .collect();
        let wrong: Vec<(usize, u32, u32)> = (0..got.len())
            .filter(|&i| got[i] != want[i])
            .map(|i| (i, got[i], want[i]))
            .take(10)
            .collect();
        assert!(wrong.is_empty(), "{name}: (atom, ours, OVITO's) {wrong:?}");
        // Surfaces: an atom there has fewer than 12 neighbours.
        assert!(got.iter().filter(|&&c| c < 12).count() > 100, "{name}");
    }
}

#[test]
fn taken_as_periodic_the_films_surfaces_meet_their_images() {
    let reference = reference();
    let mut frame = read("slab.lammpstrj");
    frame.cell = frame.cell.map(|c| c.with_periodic([true; 3]));
    // The bottom layer's image lands on the top layer: no surface atom is left with OVITO's
    // type, and every atom of the outer layers gains neighbours.
    let wrong = cna_differences(
        &frame,
        reference["slab.lammpstrj"]["types"].as_str().unwrap(),
    );
    assert!(wrong.len() >= 100, "{} atoms differ", wrong.len());
    let open = coordination(&read("slab.lammpstrj"), 3.0).unwrap();
    let closed = coordination(&frame, 3.0).unwrap();
    assert!(open.iter().zip(&closed).filter(|(o, c)| c > o).count() >= 288);
}

#[test]
fn writers_keep_the_open_edges_and_voronoi_refuses_them() {
    let frame = read("slab.lammpstrj");
    for format in [Format::LammpsDump, Format::Xyz] {
        let mut w = Writer::new(Cursor::new(Vec::new()), format, "out").unwrap();
        w.write_frame(&frame).unwrap();
        let bytes = w.finish().unwrap().into_inner();
        let text = String::from_utf8(bytes.clone()).unwrap();
        assert!(
            text.contains("pp pp ff") || text.contains("pbc=\"T T F\""),
            "{format:?}: {}",
            &text[..300]
        );
        let dir = tempfile::tempdir().unwrap();
        let ext = if format == Format::Xyz {
            "xyz"
        } else {
            "lammpstrj"
        };
        let path = dir.path().join(format!("back.{ext}"));
        std::fs::write(&path, bytes).unwrap();
        let mut t = Trajectory::open(&path).unwrap();
        let mut back = Frame::new();
        assert!(t.read_next(&mut back).unwrap());
        let cell = back.cell.unwrap();
        assert_eq!(cell.periodic(), [true, true, false], "{format:?}");
        let origin = frame.cell.unwrap().origin();
        for (got, want) in cell.origin().iter().zip(origin) {
            assert!((got - want).abs() < 1e-6, "{format:?}");
        }
    }
    let e = texmap_md_io::voronoi::voronoi(&frame).unwrap_err();
    assert!(e.to_string().contains("periodic along all three"), "{e}");
}

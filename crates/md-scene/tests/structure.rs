//! `ColorBy::Structure` end to end: a wwPDB chain from MDAnalysis's DSSP test set read by md-io,
//! every atom of a protein residue coloured with VMD's colour for the class MDAnalysis 2.11
//! assigns its residue (`md-io/tests/data/dssp/reference.json`, by gen_dssp.py there), a water
//! keeping its element colour, and a colour rule winning over the structure.

use std::path::Path;

use texmap_md_io::{Frame, Label, Trajectory};
use texmap_md_scene::{
    ColorBy, STRUCTURE_COLORS, SceneBuilder, SphereScene, StyleOptions, StyleWarning,
};

fn data(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../md-io/tests/data/dssp")
        .join(name)
}

/// The C3 string of `chain` in the reference; the file is the generator's fixed layout
/// (`"dssp": "..."` after the chain's key), read without a JSON dependency.
fn mdanalysis_codes(chain: &str) -> Vec<char> {
    let text = std::fs::read_to_string(data("reference.json")).unwrap();
    let at = text.find(&format!("\"{chain}\": {{")).unwrap();
    let rest = &text[at..];
    let s = rest.find("\"dssp\": \"").unwrap() + "\"dssp\": \"".len();
    let e = rest[s..].find('"').unwrap();
    rest[s..s + e].chars().collect()
}

fn srgb8(c: [f32; 3]) -> [u8; 3] {
    c.map(|v| (v * 255.0).round() as u8)
}

fn material(scene: &SphereScene, i: usize) -> [u8; 3] {
    let m = scene.materials[scene.kinds[i] as usize].base_color;
    [m.x, m.y, m.z].map(texmap_core::color::linear_to_srgb8_exact)
}

#[test]
fn residues_take_vmds_colour_for_mdanalysiss_class() {
    let mut t = Trajectory::open(data("3gwiA.pdb.gz")).unwrap();
    let mut frame = Frame::new();
    assert!(t.read_next(&mut frame).unwrap());
    // A water after the chain: not protein, so element-coloured.
    let n = frame.n_atoms();
    frame.positions.push([100.0, 0.0, 0.0]);
    frame.names.push(Label::new("OW").unwrap());
    frame.res_names.push(Label::new("HOH").unwrap());
    frame.res_ids.push(9999);
    for v in [&mut frame.chains, &mut frame.segments] {
        if !v.is_empty() {
            v.push(Label::default());
        }
    }
    frame
        .elements
        .push(texmap_md_io::Element::from_symbol("O").unwrap());
    for p in &mut frame.properties {
        p.values.push(0.0);
    }
    if !frame.ids.is_empty() {
        frame.ids.push(99999);
    }
    let codes = mdanalysis_codes("3gwiA.pdb.gz");
    let options = StyleOptions {
        color_by: ColorBy::Structure,
        ..StyleOptions::default()
    };
    let mut builder = SceneBuilder::new(&options).unwrap();
    let mut scene = SphereScene::default();
    builder.build(&mut frame, &mut scene);
    assert!(builder.warnings(&frame).is_empty());
    // Residues in file order are the reference's residues (each has a full backbone).
    let mut residue = -1i64;
    let mut k = usize::MAX;
    let mut seen = [0usize; 3];
    for i in 0..n {
        if frame.res_ids[i] != residue {
            residue = frame.res_ids[i];
            k = k.wrapping_add(1);
        }
        let class = match codes[k] {
            '-' => 0,
            'H' => 1,
            'E' => 2,
            c => panic!("unexpected code {c}"),
        };
        seen[class] += 1;
        assert_eq!(
            material(&scene, i),
            srgb8(STRUCTURE_COLORS[class]),
            "atom {i}"
        );
    }
    assert_eq!(k + 1, codes.len());
    assert!(seen.iter().all(|&c| c > 100), "{seen:?}");
    let oxygen = texmap_md_io::Element::from_symbol("O").unwrap().color();
    assert_eq!(material(&scene, n), srgb8(oxygen));

    // A colour rule wins over the structure.
    let options = StyleOptions {
        color_by: ColorBy::Structure,
        type_color: vec![("CA".into(), [0, 255, 0])],
        ..StyleOptions::default()
    };
    let mut builder = SceneBuilder::new(&options).unwrap();
    builder.build(&mut frame, &mut scene);
    for i in 0..n {
        if frame.names[i].as_str() == "CA" {
            assert_eq!(material(&scene, i), [0, 255, 0]);
        }
    }
}

#[test]
fn a_frame_without_backbones_warns_and_keeps_element_colours() {
    let mut frame = Frame::new();
    frame.positions = vec![[0.0; 3], [1.5, 0.0, 0.0]];
    frame.names = vec![Label::new("C1").unwrap(), Label::new("O1").unwrap()];
    frame.elements = ["C", "O"]
        .map(|s| texmap_md_io::Element::from_symbol(s).unwrap())
        .to_vec();
    let options = StyleOptions {
        color_by: ColorBy::Structure,
        ..StyleOptions::default()
    };
    let mut builder = SceneBuilder::new(&options).unwrap();
    let mut scene = SphereScene::default();
    builder.build(&mut frame, &mut scene);
    assert_eq!(builder.warnings(&frame), [StyleWarning::NoStructure]);
    for (i, e) in frame.elements.iter().enumerate() {
        assert_eq!(material(&scene, i), srgb8(e.color()));
    }
}

//! The element table against ASE's data (tests/data/elements.json, from gen_elements.py).

use texmap_md_io::Element;

#[test]
fn table_matches_ase_alvarez_radii_and_jmol_colours() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/elements.json");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let rows = v["elements"].as_array().unwrap();
    assert_eq!(rows.len(), 103);
    // Where Alvarez (2013) has no radius the module doc names the fallback.
    let fallback = [
        (61, 2.00),
        (84, 1.97),
        (85, 2.02),
        (86, 2.20),
        (87, 3.48),
        (88, 2.83),
    ];
    for row in rows {
        let z = row["z"].as_u64().unwrap() as u8;
        let e = Element::from_z(z).unwrap();
        assert_eq!(e.symbol(), row["symbol"].as_str().unwrap());
        let want = match row["alvarez"].as_f64() {
            Some(r) => r,
            None => fallback
                .iter()
                .find(|(fz, _)| *fz == z)
                .map_or(2.0, |f| f.1),
        };
        let got = e.vdw_radius() as f64;
        assert!(
            (want - got).abs() <= 1e-6,
            "{}: expected {want}, actual {got}, tolerance 1e-6",
            e.symbol()
        );
        let rgb: Vec<u8> = row["jmol"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_u64().unwrap() as u8)
            .collect();
        assert_eq!(e.color_srgb8().to_vec(), rgb, "{}", e.symbol());
        let cordero = row["cordero"].as_f64().unwrap();
        let got = e.covalent_radius() as f64;
        assert!(
            (cordero - got).abs() <= 1e-6,
            "{} covalent: expected {cordero}, actual {got}",
            e.symbol()
        );
        let mass = row["mass"].as_f64().unwrap();
        assert_eq!(e.mass(), mass, "{} mass", e.symbol());
    }
    assert_eq!(Element::UNKNOWN.mass(), 0.0);
}

//! GROMACS run input files (.tpr) of file versions 58 to 138 (GROMACS 4.0.7 to 2026), single
//! and double precision, against what GROMACS 2022.5 (`gmx editconf`, `gmx dump`) and
//! MDAnalysis 2.11 read from the same files (`data/tpr/gen_tpr.py`).

use std::io::Read;
use std::sync::Arc;

use serde_json::Value;
use texmap_md_io::{Error, Topology, read_tpr};

fn dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/tpr")
}

fn reference() -> serde_json::Map<String, Value> {
    let mut text = String::new();
    flate2::read::GzDecoder::new(std::fs::File::open(dir().join("reference.json.gz")).unwrap())
        .read_to_string(&mut text)
        .unwrap();
    serde_json::from_str::<Value>(&text)
        .unwrap()
        .as_object()
        .unwrap()
        .clone()
}

fn bytes(name: &str) -> Vec<u8> {
    let raw = std::fs::read(dir().join(name)).unwrap();
    if name.ends_with(".gz") {
        let mut out = Vec::new();
        flate2::read::GzDecoder::new(&raw[..])
            .read_to_end(&mut out)
            .unwrap();
        out
    } else {
        raw
    }
}

fn strings(v: &Value) -> Vec<String> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap().to_string())
        .collect()
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_f64().unwrap())
        .collect()
}

fn vectors(v: &Value) -> Vec<[f64; 3]> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let p = numbers(p);
            [p[0], p[1], p[2]]
        })
        .collect()
}

/// Within the 6 significant digits `gmx dump` prints (MDAnalysis's float32 copies are closer).
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 6e-6 * b.abs() + 1e-6
}

fn label_strings(v: &[texmap_md_io::Label]) -> Vec<String> {
    v.iter().map(|l| l.as_str().to_string()).collect()
}

#[test]
fn every_version_reads_as_gromacs_and_mdanalysis_read_it() {
    let reference = reference();
    assert_eq!(reference.len(), 18);
    for (name, r) in &reference {
        let file: Arc<str> = name.as_str().into();
        let t = read_tpr(&bytes(name), &file).unwrap_or_else(|e| panic!("{name}: {e}"));
        let top = &t.topology;
        let n = r["n_atoms"].as_u64().unwrap() as usize;
        assert_eq!(top.n_atoms(), n, "{name}");
        assert_eq!(label_strings(&top.names), strings(&r["names"]), "{name}");
        assert_eq!(label_strings(&top.types), strings(&r["types"]), "{name}");
        assert_eq!(
            label_strings(&top.res_names),
            strings(&r["resnames"]),
            "{name}"
        );
        let moltypes: Vec<String> = strings(&r["moltypes"])
            .iter()
            .map(|s| s.chars().take(15).collect())
            .collect();
        assert_eq!(label_strings(&top.segments), moltypes, "{name}");
        let molnums: Vec<u32> = numbers(&r["molnums"]).iter().map(|&m| m as u32).collect();
        assert_eq!(t.molecules, molnums, "{name}");
        // MDAnalysis keeps charges and masses as float32, as the file stores them (or a
        // double-precision file's values rounded to float32).
        for (k, (q, m)) in numbers(&r["charges"])
            .iter()
            .zip(numbers(&r["masses"]))
            .enumerate()
        {
            assert!(
                (top.charges[k] as f64 - q).abs() <= 1e-6 * q.abs().max(1.0),
                "{name} atom {k}: charge {} against {q}",
                top.charges[k]
            );
            assert!(
                (top.masses[k] as f64 - m).abs() <= 1e-6 * m.max(1.0),
                "{name} atom {k}: mass {} against {m}",
                top.masses[k]
            );
        }
        // Elements: MDAnalysis names those of the atomic numbers it knows.
        for (k, e) in strings(&r["elements"]).iter().enumerate() {
            if !e.is_empty() {
                assert_eq!(top.elements[k].symbol(), e, "{name} atom {k}");
            }
        }
        // Residue numbers as `gmx editconf` writes them, bonds as GROMACS's chemical bonds.
        let resids: Vec<i64> = numbers(&r["resids"]).iter().map(|&x| x as i64).collect();
        assert_eq!(top.res_ids, resids, "{name}");
        let bonds: Vec<[u32; 2]> = r["bonds"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| {
                let b = numbers(b);
                [b[0] as u32, b[1] as u32]
            })
            .collect();
        assert_eq!(top.bonds, bonds, "{name}");
        // Positions, velocities and box: gmx dump's, else MDAnalysis's.
        let (x, v, dims) = if r.get("positions").is_some() {
            (&r["positions"], &r["velocities"], None)
        } else {
            (
                &r["mda_positions"],
                &r["mda_velocities"],
                Some(numbers(&r["mda_dimensions"])),
            )
        };
        let x = vectors(x);
        assert_eq!(t.positions.len(), x.len(), "{name}");
        for (k, (a, b)) in t.positions.iter().zip(&x).enumerate() {
            let tol = if dims.is_some() { 1e-4 } else { 0.0 };
            assert!(
                (0..3).all(|d| close(a[d], b[d]) || (a[d] - b[d]).abs() <= tol),
                "{name} atom {k}: {a:?} against {b:?}"
            );
        }
        let v = vectors(v);
        assert_eq!(t.velocities.len(), v.len(), "{name}");
        for (k, (a, b)) in t.velocities.iter().zip(&v).enumerate() {
            assert!(
                (0..3).all(|d| close(a[d], b[d]) || (a[d] - b[d]).abs() <= 1e-4),
                "{name} atom {k}: velocity {a:?} against {b:?}"
            );
        }
        let cell = t.cell.expect("a box");
        match dims {
            None => {
                let b = vectors(&r["box"]);
                for (row, want) in cell.iter().zip(&b) {
                    assert!(
                        (0..3).all(|d| close(row[d], want[d])),
                        "{name}: box {cell:?}"
                    );
                }
            }
            Some(d) => {
                let len = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                for k in 0..3 {
                    assert!(
                        (len(cell[k]) - d[k]).abs() < 1e-3,
                        "{name}: box {cell:?} {d:?}"
                    );
                }
            }
        }
        assert_eq!(t.double, name.contains("double"), "{name}");
    }
}

#[test]
fn the_peptide_system_has_chains_waters_sites_and_ions() {
    // GROMACS 2022.5's own file: two chains, TIP4P water with SETTLE and a massless site.
    let t = Topology::open(dir().join("peptide.tpr.gz")).unwrap();
    let n = t.n_atoms();
    let chains = label_strings(&t.chains);
    let first_water = t
        .res_names
        .iter()
        .position(|r| r.as_str() == "SOL")
        .unwrap();
    assert!(chains[..first_water].iter().all(|c| c == "A" || c == "B"));
    assert_eq!(chains[0], "A");
    assert_eq!(chains[first_water - 1], "B");
    assert!(chains[first_water..].iter().all(String::is_empty));
    // Chain B keeps the residue numbers of the PDB (20-27); waters and ions follow the
    // highest of them, one number each.
    assert_eq!(t.res_ids[first_water - 1], 27);
    assert_eq!(t.res_ids[first_water], 28);
    // Each water: O bonded to both H (SETTLE), the virtual site MW to nothing, of no element.
    let mw = first_water + 3;
    assert_eq!(t.names[mw].as_str(), "MW");
    assert!(t.elements[mw].is_unknown());
    assert_eq!(t.masses[mw], 0.0);
    assert!(
        t.bonds
            .contains(&[first_water as u32, first_water as u32 + 1])
    );
    assert!(
        t.bonds
            .contains(&[first_water as u32, first_water as u32 + 2])
    );
    assert!(!t.bonds.iter().any(|b| b.contains(&(mw as u32))));
    // Ions: single atoms, unbonded, sodium and chlorine.
    let na = t.names.iter().position(|l| l.as_str() == "NA").unwrap();
    assert_eq!(t.elements[na].symbol(), "Na");
    assert!(!t.bonds.iter().any(|b| b.contains(&(na as u32))));
    assert_eq!(t.elements[n - 1].symbol(), "Cl");
    // The charges sum to the neutral system's zero.
    let q: f64 = t.charges.iter().map(|&q| q as f64).sum();
    assert!(q.abs() < 1e-4, "{q}");
}

#[test]
fn the_topology_selects_as_the_gro_gromacs_writes() {
    // `gmx editconf -f peptide.tpr -o peptide.gro`, written by GROMACS, read by our GRO
    // reader: the same names and residues.
    let t = Topology::open(dir().join("peptide.tpr.gz")).unwrap();
    let r = &reference()["peptide.tpr.gz"];
    let resids: Vec<i64> = numbers(&r["resids"]).iter().map(|&x| x as i64).collect();
    assert_eq!(t.res_ids, resids);
    let mut f = texmap_md_io::Frame::new();
    f.positions = vec![[0.0; 3]; t.n_atoms()];
    t.apply(&mut f, "run.xtc", 0).unwrap();
    let sel = texmap_md_io::select::Selection::parse("segid SOL and name OW").unwrap();
    let picked = sel.evaluate(&f).unwrap();
    let waters = t.res_names.iter().filter(|r| r.as_str() == "SOL").count() / 4;
    assert_eq!(picked.iter().filter(|&&b| b).count(), waters);
    assert_eq!(f.property("mass").unwrap()[0], t.masses[0]);
}

fn error(bytes: &[u8]) -> String {
    match read_tpr(bytes, &"bad.tpr".into()) {
        Ok(_) => panic!("read"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn damaged_files_are_errors_naming_the_byte() {
    for name in [
        "dummy_2022-rc1.tpr",
        "vsites_4.0.7.tpr",
        "dummy_2021_double.tpr",
    ] {
        let b = bytes(name);
        let whole = read_tpr(&b, &"bad.tpr".into()).unwrap();
        for cut in (0..b.len()).step_by(37) {
            match read_tpr(&b[..cut], &"bad.tpr".into()) {
                // Before GROMACS 2020 the header gives no size: a file cut in the run
                // parameters, which are not read, still gives the whole topology and frame.
                Ok(t) => {
                    assert!(name.contains("4.0.7"), "{name} cut at {cut} read");
                    assert_eq!(t.topology, whole.topology);
                    assert_eq!(t.positions, whole.positions);
                    assert_eq!(t.velocities, whole.velocities);
                }
                Err(e) => {
                    let e = e.to_string();
                    assert!(e.starts_with("bad.tpr: byte"), "{name} cut at {cut}: {e}");
                }
            }
        }
        // Every byte flipped in turn: an error or a topology, never a panic or a runaway
        // allocation.
        for k in (0..b.len()).step_by(3) {
            let mut d = b.clone();
            d[k] ^= 0x5a;
            let _ = read_tpr(&d, &"bad.tpr".into());
        }
    }
    assert!(error(b"not a tpr at all, some text").contains("VERSION"));
    // A count far past the file: the symbol table's size (21, at byte 200 of this file) set
    // to 2^31 - 1 is refused before anything is allocated for it.
    let mut d = bytes("dummy_2018.tpr");
    assert_eq!(d[200..204], 21u32.to_be_bytes());
    d[200..204].copy_from_slice(&i32::MAX.to_be_bytes());
    let e = error(&d);
    assert!(
        e.starts_with("bad.tpr: byte 200") && e.contains("symbols"),
        "{e}"
    );
    // Versions: before GROMACS 4.0, and a generation newer than any known.
    let mut d = bytes("dummy_2018.tpr");
    let v = d
        .windows(4)
        .position(|w| w == 112u32.to_be_bytes())
        .unwrap();
    d[v..v + 4].copy_from_slice(&40u32.to_be_bytes());
    assert!(error(&d).contains("before GROMACS 4.0"), "{}", error(&d));
    let mut d = bytes("dummy_2018.tpr");
    d[v + 4..v + 8].copy_from_slice(&31u32.to_be_bytes());
    assert!(error(&d).contains("generation"), "{}", error(&d));
    // Topology::open names the file and refuses a cut one.
    let path = std::env::temp_dir().join(format!("texmap-cut-{}.tpr", std::process::id()));
    std::fs::write(&path, &bytes("vsites_2021.tpr")[..9000]).unwrap();
    let e = Topology::open(&path).unwrap_err();
    std::fs::remove_file(&path).unwrap();
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
}

//! GROMACS topologies (.top with their #included .itp files) read as the run input files
//! (.tpr) GROMACS 2022.5's grompp made from them are read (tests/data/gromacs_top/gen_top.py:
//! amber99sb-ildn with TIP3P and two chains, charmm27 with TIP4P and `-DHEAVY_H`), against
//! MDAnalysis 2.11's ITPParser on the same files, and a hand-written topology for the
//! preprocessor (includes, defines, #ifdef blocks, continued lines) without GROMACS.

use std::io::{Cursor, Read};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use texmap_md_io::{
    Error, GromacsTopOptions, Label, Topology, TopologyFormat, read_gromacs_top, read_tpr,
};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/gromacs_top")
}

/// The topology of `system`'s topol.tpr.gz, as the .tpr reader reads it.
fn tpr(system: &str) -> Topology {
    let path = dir().join(system).join("topol.tpr.gz");
    let mut bytes = Vec::new();
    flate2::read::GzDecoder::new(std::fs::File::open(&path).unwrap())
        .read_to_end(&mut bytes)
        .unwrap();
    let name: Arc<str> = path.display().to_string().into();
    read_tpr(&bytes, &name).unwrap().topology
}

/// The first index where `a` and `b` differ, with both values, or `None`.
fn first_difference<T: PartialEq + std::fmt::Debug>(a: &[T], b: &[T]) -> Option<String> {
    if a.len() != b.len() {
        return Some(format!("{} values against {}", a.len(), b.len()));
    }
    let k = a.iter().zip(b).position(|(x, y)| x != y)?;
    Some(format!("atom {k}: {:?} against {:?}", a[k], b[k]))
}

/// Every column of the two topologies is the same (masses and charges as f32, bonds as sets:
/// both readers give them sorted, each once).
fn same(top: &Topology, tpr: &Topology, what: &str) {
    assert_eq!(top.n_atoms(), tpr.n_atoms(), "{what}: atom count");
    let labels: [(&str, &Vec<Label>, &Vec<Label>); 5] = [
        ("names", &top.names, &tpr.names),
        ("types", &top.types, &tpr.types),
        ("residue names", &top.res_names, &tpr.res_names),
        ("molecule types (segments)", &top.segments, &tpr.segments),
        ("chains", &top.chains, &tpr.chains),
    ];
    for (column, a, b) in labels {
        if let Some(d) = first_difference(a, b) {
            panic!("{what}: {column} differ at {d}");
        }
    }
    let checks = [
        (
            "residue numbers",
            first_difference(&top.res_ids, &tpr.res_ids),
        ),
        ("ids", first_difference(&top.ids, &tpr.ids)),
        ("elements", first_difference(&top.elements, &tpr.elements)),
        ("masses", first_difference(&top.masses, &tpr.masses)),
        ("charges", first_difference(&top.charges, &tpr.charges)),
        ("bonds", first_difference(&top.bonds, &tpr.bonds)),
    ];
    for (column, d) in checks {
        if let Some(d) = d {
            panic!("{what}: {column} differ at {d}");
        }
    }
}

/// What the .mdp of `system` defines (gen_top.py's grompp runs).
fn defines(system: &str) -> Vec<String> {
    let mdp = std::fs::read_to_string(dir().join(system).join("mdp.mdp")).unwrap();
    mdp.lines()
        .filter_map(|l| l.strip_prefix("define"))
        .flat_map(|l| {
            l.trim_start_matches([' ', '='])
                .split_whitespace()
                .map(str::to_string)
        })
        .collect()
}

#[test]
fn grompps_preprocessed_topologies_read_as_their_tpr() {
    for system in ["amber", "charmm"] {
        let t = Topology::open(dir().join(system).join("processed.top.gz")).unwrap();
        let want = tpr(system);
        same(&t, &want, system);
        // Not vacuous: a protein, water, bonds, masses and charges.
        assert!(t.n_atoms() > 1000 && t.bonds.len() > 500, "{system}");
        assert!(t.segments.iter().any(|s| s.as_str() == "SOL"), "{system}");
        assert!(t.masses.iter().all(|m| *m >= 0.0) && t.charges.iter().any(|q| *q < 0.0));
    }
    // The two chains of the amber system are their own molecule types and chains.
    let t = Topology::open(dir().join("amber/processed.top.gz")).unwrap();
    assert!(t.chains.iter().any(|c| c.as_str() == "A"));
    assert!(t.chains.iter().any(|c| c.as_str() == "B"));
    // charmm: TIP4P's virtual site has no mass and no element; HEAVY_H made water heavy.
    let t = Topology::open(dir().join("charmm/processed.top.gz")).unwrap();
    let mw = t.names.iter().position(|n| n.as_str() == "MW").unwrap();
    assert_eq!(t.masses[mw], 0.0);
    assert!(t.elements[mw].is_unknown());
    assert_eq!(t.masses[mw - 3], 9.9514_f32);
}

/// The original topol.top, its force field #included from GROMACS's data directory: read
/// only where GROMACS is installed.
#[test]
fn topologies_with_their_force_field_includes_read_as_their_tpr() {
    if !Path::new("/usr/share/gromacs/top").is_dir() && std::env::var_os("GMXLIB").is_none() {
        eprintln!("SKIPPED: no GROMACS data directory (/usr/share/gromacs/top or GMXLIB)");
        return;
    }
    for system in ["amber", "charmm"] {
        let top = dir().join(system).join("topol.top");
        let options = GromacsTopOptions {
            defines: defines(system),
            ..GromacsTopOptions::default()
        };
        assert!(!options.defines.is_empty());
        let t = read_gromacs_top(&top, &options).unwrap();
        same(&t, &tpr(system), system);
    }
    // POSRES only adds restraints: the topology is the same without it, through `open`.
    let t = Topology::open(dir().join("amber/topol.top")).unwrap();
    same(&t, &tpr("amber"), "amber without defines");
    // Without HEAVY_H, charmm's water keeps its standard masses: the define matters.
    let t = Topology::open(dir().join("charmm/topol.top")).unwrap();
    let want = tpr("charmm");
    let water: Vec<usize> = (0..t.n_atoms())
        .filter(|&i| t.segments[i].as_str() == "SOL" && t.masses[i] > 0.0)
        .collect();
    assert!(!water.is_empty());
    for &i in &water {
        assert_ne!(t.masses[i], want.masses[i], "atom {i}");
        assert!(t.masses[i] == 15.9994 || t.masses[i] == 1.008, "atom {i}");
    }
    assert_eq!(t.bonds, want.bonds);
    assert_eq!(t.names, want.names);
}

#[test]
fn mdanalysis_itpparser_reads_the_same() {
    let text = std::fs::read_to_string(dir().join("mda.json")).unwrap();
    let r: serde_json::Value = serde_json::from_str(&text).unwrap();
    for system in ["amber", "charmm"] {
        let m = &r[system];
        let t = Topology::open(dir().join(system).join("processed.top.gz")).unwrap();
        assert_eq!(
            t.n_atoms() as u64,
            m["n_atoms"].as_u64().unwrap(),
            "{system}"
        );
        assert_eq!(
            t.bonds.len() as u64,
            m["n_bonds"].as_u64().unwrap(),
            "{system}"
        );
        let strings = |key: &str| -> Vec<String> {
            m[key]
                .as_array()
                .unwrap()
                .iter()
                .map(|s| s.as_str().unwrap().to_string())
                .collect()
        };
        let n = strings("names").len();
        assert!(n > 50, "{system}");
        let ours = |v: &[Label]| -> Vec<String> {
            v[..n].iter().map(|l| l.as_str().to_string()).collect()
        };
        assert_eq!(ours(&t.names), strings("names"), "{system}");
        assert_eq!(ours(&t.types), strings("types"), "{system}");
        assert_eq!(ours(&t.res_names), strings("resnames"), "{system}");
        assert_eq!(ours(&t.segments), strings("moltypes"), "{system}");
        for (key, ours) in [("charges", &t.charges), ("masses", &t.masses)] {
            for (k, v) in m[key].as_array().unwrap().iter().enumerate() {
                let v = v.as_f64().unwrap();
                // Ours are f32, MDAnalysis's masses f64: within f32's rounding.
                assert!(
                    (ours[k] as f64 - v).abs() <= 1e-6 * v.abs().max(1.0),
                    "{system}: {key} of atom {k}: {} against {v}",
                    ours[k]
                );
            }
        }
        let bonds: Vec<[u32; 2]> = m["bonds"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| [b[0].as_u64().unwrap() as u32, b[1].as_u64().unwrap() as u32])
            .collect();
        let ours: Vec<[u32; 2]> = t
            .bonds
            .iter()
            .copied()
            .filter(|b| (b[1] as usize) < n)
            .collect();
        assert_eq!(ours, bonds, "{system}");
    }
}

fn hand(options: &GromacsTopOptions) -> Topology {
    read_gromacs_top(dir().join("hand/system.top"), options).unwrap()
}

fn with(defines: &[&str]) -> GromacsTopOptions {
    GromacsTopOptions {
        defines: defines.iter().map(|d| d.to_string()).collect(),
        ..GromacsTopOptions::default()
    }
}

fn strs(v: &[Label]) -> Vec<&str> {
    v.iter().map(Label::as_str).collect()
}

#[test]
fn a_hand_written_topology_reads_as_grompp_would_read_it() {
    let t = hand(&GromacsTopOptions::default());
    assert_eq!(t.n_atoms(), 16);
    let eth = ["C1", "C2", "D"];
    let sol = ["OW", "HW1", "HW2"];
    let names: Vec<&str> = [&eth[..], &eth, &sol, &sol, &sol, &["NA"]].concat();
    assert_eq!(strs(&t.names), names);
    let eth = ["opls_x", "CT", "DUM"];
    let sol = ["OW", "HW", "HW"];
    let types: Vec<&str> = [&eth[..], &eth, &sol, &sol, &sol, &["NA"]].concat();
    assert_eq!(strs(&t.types), types);
    // ETH has two residues and keeps its numbers; one-residue molecules are numbered on.
    assert_eq!(t.res_ids, [1, 1, 2, 1, 1, 2, 3, 3, 3, 4, 4, 4, 5, 5, 5, 6]);
    assert_eq!(&strs(&t.res_names)[..4], ["ETH", "ETH", "ETH2", "ETH"]);
    assert_eq!(t.n_residues(), 8);
    let seg: Vec<&str> = [&["ETH"; 6][..], &["SOL"; 9], &["NA"]].concat();
    assert_eq!(strs(&t.segments), seg);
    assert!(t.chains.is_empty());
    // The mass from a define, from the atom type, a massless site; the charge from a define.
    let eth_m = [20.5, 12.011, 0.0];
    let sol_m = [15.9994, 1.008, 1.008];
    let masses: Vec<f32> = [&eth_m[..], &eth_m, &sol_m, &sol_m, &sol_m, &[22.99]].concat();
    assert_eq!(t.masses, masses);
    let eth_q = [-0.18, 0.18, 0.0];
    let sol_q = [-0.834, 0.417, 0.417];
    let charges: Vec<f32> = [&eth_q[..], &eth_q, &sol_q, &sol_q, &sol_q, &[1.0]].concat();
    assert_eq!(t.charges, charges);
    let elements: Vec<&str> = t.elements.iter().map(|e| e.symbol()).collect();
    let eth_e = ["C", "C", "X"];
    let sol_e = ["O", "H", "H"];
    assert_eq!(
        elements,
        [&eth_e[..], &eth_e, &sol_e, &sol_e, &sol_e, &["Na"]].concat()
    );
    // The continued bond, not the harmonic potential; SETTLE as two O-H bonds.
    assert_eq!(
        t.bonds,
        [
            [0, 1],
            [3, 4],
            [6, 7],
            [6, 8],
            [9, 10],
            [9, 11],
            [12, 13],
            [12, 14]
        ]
    );
    assert_eq!(t.ids, (1..=16).collect::<Vec<i64>>());

    // HEAVY redefines HW; FLEXIBLE swaps SETTLE for one bond; a define with a value from the
    // API replaces the file's default (#ifndef CHARGE_C2).
    let t = hand(&with(&["-DHEAVY", "FLEXIBLE", "-DCHARGE_C2=0.25"]));
    assert_eq!(&t.masses[6..9], [15.9994, 4.032, 4.032]);
    assert_eq!(t.bonds, [[0, 1], [3, 4], [6, 7], [9, 10], [12, 13]]);
    assert_eq!(t.charges[1], 0.25);
    assert_eq!(t.charges[4], 0.25);
}

#[test]
fn the_routing_tells_a_gromacs_top_from_an_amber_one() {
    assert_eq!(
        TopologyFormat::from_path(Path::new("mol.itp")),
        Some(TopologyFormat::GromacsTop)
    );
    // A .top names AMBER's format; open_as reads it as what it holds.
    assert_eq!(
        TopologyFormat::from_path(Path::new("system.top")),
        Some(TopologyFormat::Prmtop)
    );
    let t = Topology::open(dir().join("hand/system.top")).unwrap();
    assert_eq!(t.n_atoms(), 16);
    let t = Topology::open_as(dir().join("hand/system.top"), TopologyFormat::Prmtop).unwrap();
    assert_eq!(t.n_atoms(), 16);
    // An AMBER prmtop named .top is still AMBER's.
    let tmp = std::env::temp_dir().join(format!("texmap_gmx_top_{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let amber = tmp.join("amber.top");
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/prmtop_parmed.prmtop"),
        &amber,
    )
    .unwrap();
    let a = Topology::open(&amber).unwrap();
    let b = Topology::open(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/prmtop_parmed.prmtop"),
    )
    .unwrap();
    assert_eq!(a.names, b.names);
    assert_eq!(a.bonds, b.bonds);
    std::fs::remove_dir_all(&tmp).unwrap();
}

/// Reads `text` as a topology named `name` (includes are looked for beside it).
fn read(text: &str, name: &str) -> Result<Topology, Error> {
    Topology::from_reader(Cursor::new(text), TopologyFormat::GromacsTop, name)
}

const HEAD: &str = "[ atomtypes ]\nOW 8 15.9994 0.0 A 0.3 0.6\nHW 1 1.008 0.0 A 0 0\n\
    [ moleculetype ]\nSOL 2\n[ atoms ]\n1 OW 1 SOL OW 1 -0.8\n2 HW 1 SOL HW1 1 0.4\n\
    3 HW 1 SOL HW2 1 0.4\n";

#[test]
fn damage_is_an_error_naming_file_and_line() {
    let ok = read(&format!("{HEAD}[ molecules ]\nSOL 2\n"), "e.top").unwrap();
    assert_eq!(ok.n_atoms(), 6);
    let cases: [(String, &str, &[&str]); 10] = [
        // A missing include: the including file and line, the paths looked at.
        (
            format!("{HEAD}#include \"nope.itp\"\n"),
            "e.top: line 10",
            &["nope.itp", "looked for", "/usr/share/gromacs/top/nope.itp"],
        ),
        (
            format!("{HEAD}[ molecules ]\nSOL 1\nWAT 2\n"),
            "e.top: line 12",
            &["WAT"],
        ),
        (
            "[ atomtypes ]\nOW 8 16 0 A 0 0\n[ moleculetype ]\nX 1\n[ atoms ]\n1 OW 1 X\n".into(),
            "e.top: line 6",
            &["an atom line"],
        ),
        (
            format!("{HEAD}[ bonds ]\n1 4 1\n"),
            "e.top: line 11",
            &["1 and 4", "3 atoms"],
        ),
        (
            format!("{HEAD}[ settles ]\n2 1 0.1 0.16\n"),
            "e.top: line 11",
            &["2 and 4"],
        ),
        (
            format!("{HEAD}#ifdef A\n[ molecules ]\n"),
            "e.top: line 10",
            &["#endif"],
        ),
        (format!("{HEAD}#endif\n"), "e.top: line 10", &["#ifdef"]),
        (format!("{HEAD}#if 1\n"), "e.top: line 10", &["#if 1"]),
        (
            format!("{HEAD}[ molecules ]\nSOL 1000000000\n"),
            "e.top: line 11",
            &["2^26"],
        ),
        (
            format!("{HEAD}[ atoms ]\n4 XX 1 SOL M 1 0\n"),
            "e.top: line 11",
            &["atom type", "XX"],
        ),
    ];
    for (text, at, words) in &cases {
        let e = read(text, "e.top").unwrap_err().to_string();
        assert!(e.starts_with(at), "{at}: {e}");
        for w in *words {
            assert!(e.contains(w), "{at}: {w}: {e}");
        }
    }
    // No [ molecules ]: about the whole file.
    let e = read(HEAD, "e.top").unwrap_err().to_string();
    assert!(e.contains("[ molecules ]"), "{e}");
    // An include cycle ends at the depth limit, naming the included file.
    let e = read_gromacs_top(dir().join("hand/cycle.itp"), &GromacsTopOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("cycle.itp: line 2") && e.contains("64 deep"),
        "{e}"
    );
    // An error inside an included file names that file and its line.
    let name = dir().join("hand/inline.top").display().to_string();
    let e = read("#include \"mol.itp\"\n[ molecules ]\nETH 1\n", &name)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("mol.itp: line 13") && e.contains("atom type"),
        "{e}"
    );
}

#[test]
fn damaged_topologies_never_panic() {
    let mut text = String::new();
    flate2::read::GzDecoder::new(
        std::fs::File::open(dir().join("amber/processed.top.gz")).unwrap(),
    )
    .read_to_string(&mut text)
    .unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 33) as usize
    };
    let name = "damaged.top";
    for round in 0..300 {
        let mut bytes = text.clone().into_bytes();
        match round % 3 {
            0 => {
                let cut: usize = lines[..next() % lines.len()]
                    .iter()
                    .map(|l| l.len() + 1)
                    .sum();
                bytes.truncate(cut);
            }
            1 => {
                for _ in 0..4 {
                    let k = next() % bytes.len();
                    bytes[k] ^= 1 << (next() % 8);
                }
            }
            _ => {
                let k = next() % bytes.len();
                bytes[k] = b"#[];\\ 0-9x\n"[next() % 11];
            }
        }
        let result = std::panic::catch_unwind(|| {
            Topology::from_reader(Cursor::new(&bytes), TopologyFormat::GromacsTop, name)
        });
        match result {
            Err(_) => panic!("round {round}: panic"),
            Ok(Ok(t)) => {
                let n = t.n_atoms();
                assert!(t.names.len() == n && t.masses.len() == n && t.res_ids.len() == n);
                assert!(t.bonds.iter().all(|b| b[0] < b[1] && (b[1] as usize) < n));
            }
            Ok(Err(e)) => {
                let s = e.to_string();
                assert!(s.starts_with(name), "round {round}: {s}");
                if let Error::Parse { at, .. } = &e {
                    assert!(
                        at.line.is_some() || s.contains("[ molecules ]"),
                        "round {round}: {s}"
                    );
                }
            }
        }
    }
}

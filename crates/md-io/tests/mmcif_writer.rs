//! Our PDBx/mmCIF writer: the repository's fixtures (a multi-chain protein with DNA, water and
//! ions; wwPDB entries; a three-model file with a triclinic cell; water boxes; a LAMMPS dump
//! without names) written and read back by our reader, a system past 100,000 atoms and 9,999
//! residues, labels that need CIF quotes, frames streamed as they come, and refused frames.
//! The independent check: gemmi 0.7 (the CCP4 / Global Phasing library) reads every written
//! file, through `python3 -c`, and must find the frames' atoms, models and cell; without
//! python3 or gemmi (`pip install gemmi`; CI installs it) those checks say SKIPPED.

use std::cell::RefCell;
use std::io::{Cursor, Seek, SeekFrom, Write};
use std::path::Path;
use std::process::Command;
use std::rc::Rc;

use serde_json::Value;
use support::fixtures::{data, stream};
use texmap_md_io::elements::guess_element;
use texmap_md_io::replicate::replicate;
use texmap_md_io::{Element, Error, Format, Frame, Label, Property, Topology, Trajectory, Writer};

use crate::support;

/// Writes `frames` as mmCIF to `path`.
fn write_file(path: &Path, frames: &[Frame]) {
    let mut w = Writer::create(path, Format::Mmcif).unwrap();
    for f in frames {
        w.write_frame(f).unwrap();
    }
    w.finish().unwrap();
}

fn label(s: &str) -> Label {
    Label::new(s).unwrap()
}

/// The element the writer gives atom `i` (the frame's, else the names' guess).
fn written_element(f: &Frame, i: usize) -> Element {
    match f.elements.get(i) {
        Some(e) if !e.is_unknown() => *e,
        _ => guess_element(
            f.names.get(i).map_or("", |l| l.as_str()),
            f.res_names.get(i).map(|l| l.as_str()),
            None,
        ),
    }
}

/// What our reader must give back for atom `i` of `f`: a label column the frame lacks reads
/// back as empty labels (the writer's `?`), a missing residue number as 0, a missing id as the
/// atom's number from 1.
fn label_or_empty(column: &[Label], i: usize) -> Label {
    column.get(i).copied().unwrap_or_default()
}

/// `back` is `written` read back: every atom's labels, element, id and position (same bits),
/// occupancy and B-factor (the reader's 1 and 0 where the frame had none), the first frame's
/// cell on every model, and nothing else among the properties.
fn assert_read_back(written: &[Frame], back: &[Frame], what: &str) {
    assert_eq!(back.len(), written.len(), "{what}: models");
    let cell = written[0].cell.map(|c| (c.lengths(), c.angles()));
    for (k, (a, b)) in written.iter().zip(back).enumerate() {
        let at = |i: usize| format!("{what}, frame {k}, atom {i}");
        let n = a.n_atoms();
        assert_eq!(b.n_atoms(), n, "{what}, frame {k}");
        for i in 0..n {
            assert_eq!(b.names[i], label_or_empty(&a.names, i), "{}", at(i));
            assert_eq!(b.res_names[i], label_or_empty(&a.res_names, i), "{}", at(i));
            assert_eq!(b.chains[i], label_or_empty(&a.chains, i), "{}", at(i));
            assert_eq!(
                b.res_ids[i],
                a.res_ids.get(i).copied().unwrap_or(0),
                "{}",
                at(i)
            );
            let id = a.ids.get(i).copied().unwrap_or(i as i64 + 1);
            assert_eq!(b.ids[i], id, "{}", at(i));
            assert_eq!(b.elements[i], written_element(a, i), "{}", at(i));
            let (p, q) = (a.positions[i], b.positions[i]);
            assert!(
                (0..3).all(|c| p[c].to_bits() == q[c].to_bits()),
                "{}: wrote {p:?}, read back {q:?}",
                at(i)
            );
        }
        for (name, missing) in [("occupancy", 1.0f32), ("bfactor", 0.0)] {
            let expected: Vec<u32> = match a.property(name) {
                Some(v) => v.iter().map(|x| x.to_bits()).collect(),
                None => vec![missing.to_bits(); n],
            };
            let got: Vec<u32> = b
                .property(name)
                .unwrap()
                .iter()
                .map(|x| x.to_bits())
                .collect();
            assert!(got == expected, "{what}, frame {k}: {name}");
        }
        assert!(
            b.properties
                .iter()
                .all(|p| p.name == "occupancy" || p.name == "bfactor"),
            "{what}: only occupancy and bfactor are written"
        );
        assert_eq!(
            b.cell.map(|c| (c.lengths(), c.angles())),
            cell,
            "{what}, frame {k}: the first frame's cell, exactly"
        );
    }
}

/// gemmi's reading of a file: the cell (a b c α β γ) and space group, the model numbers, and
/// per atom `[model, serial, chain, residue name, sequence number or null, name, element,
/// x, y, z, occupancy, B]`, one JSON value a line.
const GEMMI: &str = r#"
import json, sys
import gemmi
st = gemmi.read_structure(sys.argv[1])
c = st.cell
cell = [c.a, c.b, c.c, c.alpha, c.beta, c.gamma] if c.is_crystal() else None
print(json.dumps({"cell": cell, "sg": st.spacegroup_hm, "models": [m.num for m in st]}))
for m in st:
    for ch in m:
        for r in ch:
            for a in r:
                n = r.seqid.num
                print(json.dumps([m.num, a.serial, ch.name, r.name, n, a.name, a.element.name,
                                  a.pos.x, a.pos.y, a.pos.z, a.occ, a.b_iso]))
"#;

/// Runs gemmi on `path`: its output lines, or `None` (and a SKIPPED line) without python3 or
/// gemmi.
fn gemmi(path: &Path) -> Option<Vec<Value>> {
    let out = match Command::new("python3")
        .arg("-c")
        .arg(GEMMI)
        .arg(path)
        .output()
    {
        Ok(o) => o,
        Err(e) => {
            eprintln!("SKIPPED: reading by gemmi (python3: {e})");
            return None;
        }
    };
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        if err.contains("No module named 'gemmi'") {
            eprintln!("SKIPPED: reading by gemmi (pip install gemmi)");
            return None;
        }
        panic!("gemmi failed on {}: {err}", path.display());
    }
    let text = String::from_utf8(out.stdout).unwrap();
    Some(
        text.lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect(),
    )
}

/// `g` (gemmi's f64 of our decimal) is `x`: the shortest round-trip decimal of an f32 lies
/// within half an f32 ulp of it, and gemmi keeps at least f32 precision (f64 positions, f32
/// occupancies and B-factors).
fn same_f32(g: &Value, x: f32, what: &str) {
    let g = g.as_f64().unwrap();
    let half_ulp = (f32::from_bits(x.abs().to_bits() + 1) - x.abs()) as f64 / 2.0;
    assert!(
        (g - x as f64).abs() <= half_ulp,
        "{what}: gemmi read {g}, the frame has {x} (tolerance {half_ulp:e})"
    );
}

/// gemmi reads `path` as `written`: the model count and numbers, the cell of the first frame
/// (lengths and angles to 1e-12, the decimals being f64's shortest) with space group P 1, and
/// every atom, found by its serial: chain, residue name and number, name, element, position,
/// and occupancy and B-factor where the frame has them. False when skipped.
fn assert_gemmi_reads(path: &Path, written: &[Frame], what: &str) -> bool {
    let Some(lines) = gemmi(path) else {
        return false;
    };
    let head = &lines[0];
    let models: Vec<i64> = (head["models"].as_array().unwrap().iter())
        .map(|m| m.as_i64().unwrap())
        .collect();
    let expected: Vec<i64> = (1..=written.len() as i64).collect();
    assert_eq!(models, expected, "{what}: gemmi's models");
    match written.first().and_then(|f| f.cell) {
        Some(c) => {
            let g: Vec<f64> = (head["cell"].as_array().unwrap().iter())
                .map(|v| v.as_f64().unwrap())
                .collect();
            let [a, b, cc] = c.lengths();
            let [al, be, ga] = c.angles();
            for (x, y) in g.iter().zip([a, b, cc, al, be, ga]) {
                assert!((x - y).abs() <= 1e-12 * y, "{what}: gemmi's cell {g:?}");
            }
            assert_eq!(head["sg"], "P 1", "{what}");
        }
        None => assert!(head["cell"].is_null(), "{what}: no cell"),
    }
    let atoms = &lines[1..];
    let total: usize = written.iter().map(Frame::n_atoms).sum();
    assert_eq!(atoms.len(), total, "{what}: gemmi's atoms");
    for (k, f) in written.iter().enumerate() {
        // gemmi groups atoms by chain: find each by its serial.
        let ids: Vec<i64> = (0..f.n_atoms())
            .map(|i| f.ids.get(i).copied().unwrap_or(i as i64 + 1))
            .collect();
        let mut index = std::collections::HashMap::new();
        for (i, id) in ids.iter().enumerate() {
            assert!(index.insert(*id, i).is_none(), "{what}: serial {id} twice");
        }
        let mut seen = vec![false; f.n_atoms()];
        let occupancy = f.property("occupancy");
        let bfactor = f.property("bfactor");
        for a in atoms.iter().filter(|a| a[0].as_i64() == Some(k as i64 + 1)) {
            let i = index[&a[1].as_i64().unwrap()];
            let at = format!("{what}, model {}, atom {i}", k + 1);
            seen[i] = true;
            let s = |v: &Value| v.as_str().unwrap().to_string();
            assert_eq!(
                s(&a[2]),
                label_or_empty(&f.chains, i).as_str(),
                "{at}: chain"
            );
            assert_eq!(s(&a[3]), label_or_empty(&f.res_names, i).as_str(), "{at}");
            assert_eq!(a[4].as_i64(), f.res_ids.get(i).copied(), "{at}: seqid");
            assert_eq!(s(&a[5]), label_or_empty(&f.names, i).as_str(), "{at}: name");
            let e = written_element(f, i);
            let symbol = if e.is_unknown() { "X" } else { e.symbol() };
            assert!(
                s(&a[6]).eq_ignore_ascii_case(symbol),
                "{at}: {} {symbol}",
                a[6]
            );
            for c in 0..3 {
                same_f32(&a[7 + c], f.positions[i][c], &at);
            }
            if let Some(v) = occupancy {
                same_f32(&a[10], v[i], &format!("{at}: occupancy"));
            }
            if let Some(v) = bfactor {
                same_f32(&a[11], v[i], &format!("{at}: B"));
            }
        }
        assert!(seen.iter().all(|&s| s), "{what}: model {} whole", k + 1);
    }
    true
}

/// The fixtures' frames written as mmCIF read back the same through our reader (as a `.cif`
/// told by its content) and through gemmi.
#[test]
fn fixtures_read_back_as_written() {
    let dir = tempfile::tempdir().unwrap();
    let mut checked = 0;
    for (name, min_frames) in [
        ("chains_mda.pdb", 1),  // chains A B W D, protein, water, ions, DNA, segments
        ("1uqc.cif", 1),        // NMR DNA: O5' and the other primed names
        ("3jqh.cif", 1),        // X-ray: cell, occupancies, B-factors, alternate locations
        ("gemmi_multi.cif", 3), // three models, triclinic cell
        ("mda_multi.pdb", 3),
        ("select_mda.pdb", 1), // 30 alanines, 200 waters, ions
        ("topo_mda.gro", 1),   // peptide in a water box
        ("mda_vel.gro", 2),
        ("tinker/water_box.arc", 3), // water box, a cell per frame
        ("lmp_tri.lammpstrj", 2),    // no names, residues or chains
    ] {
        let source = stream(&mut Trajectory::open(data(name)).unwrap());
        assert!(
            source.len() >= min_frames,
            "{name}: {} frames",
            source.len()
        );
        let out = dir.path().join(format!("{}.cif", name.replace('/', "_")));
        write_file(&out, &source);
        let mut t = Trajectory::open(&out).unwrap();
        assert_eq!(t.format(), Format::Mmcif, "{name}");
        let back = stream(&mut t);
        assert_read_back(&source, &back, name);
        if assert_gemmi_reads(&out, &source, name) {
            checked += 1;
        }
    }
    eprintln!("gemmi read {checked} of the fixtures' files");
    // 1UQC's primed names are double-quoted as the wwPDB writes them.
    let text = std::fs::read_to_string(dir.path().join("1uqc.cif.cif")).unwrap();
    assert!(text.contains(" \"O5'\" . DC A "), "O5' quoted");
    assert!(
        text.starts_with("data_1uqc.cif\n"),
        "the block is named after the file"
    );
}

/// Adenylate kinase in water (MDAnalysis's adk_oplsaa: 47,681 atoms, 11,302 residues, a
/// rhombic dodecahedron) with the two frames of its XTC, tiled three times along the first
/// cell vector (143,043 atoms, residue numbers to 33,906, each copy its own chain of up to 15
/// characters, a B-factor per atom): read back bit for bit, and by gemmi.
#[test]
fn more_than_100000_atoms_and_9999_residues() {
    let top = Topology::open(data("hbonds/adk_top.gro.gz")).unwrap();
    let mut traj = Trajectory::open(data("hbonds/adk_0_9.xtc")).unwrap();
    let mut frames = stream(&mut traj);
    assert_eq!(frames.len(), 2);
    let chains = ["A", "ADK_COPY_2", "ADENYL_KINASE_3"].map(|c| Label::new(c).unwrap());
    for (k, f) in frames.iter_mut().enumerate() {
        top.apply(f, "adk_0_9.xtc", k).unwrap();
        let n = f.n_atoms();
        replicate(f, &mut Vec::new(), [3, 1, 1]).unwrap();
        f.chains = (0..3 * n).map(|i| chains[i / n]).collect();
        f.properties.push(Property {
            name: "bfactor".into(),
            values: (0..3 * n).map(|i| (i % 997) as f32 * 0.0625).collect(),
        });
    }
    let n = frames[0].n_atoms();
    assert_eq!(n, 143_043);
    assert_eq!(frames[0].res_ids.iter().max(), Some(&33_906));
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("adk.cif");
    write_file(&out, &frames);
    let back = stream(&mut Trajectory::open(&out).unwrap());
    assert_read_back(&frames, &back, "adk x3");
    assert_eq!(back[1].ids[n - 1], 143_043);
    assert_eq!(back[1].chains[n - 1], "ADENYL_KINASE_3");
    // Protein rows are ATOM with an unknown label_seq_id, ions and water HETATM without one.
    let text = std::fs::read_to_string(&out).unwrap();
    let row = |id: &str| {
        let is_row = |l: &&str| l.starts_with("ATOM ") || l.starts_with("HETATM ");
        let mut rows = text.lines().filter(is_row);
        let l = rows.find(|l| l.split(' ').nth(1) == Some(id)).unwrap();
        l.split(' ').take(10).collect::<Vec<_>>().join(" ")
    };
    assert_eq!(row("1"), "ATOM 1 N N . MET A ? ? ?");
    assert_eq!(
        row("143043"),
        "HETATM 143043 NA NA . NA+ ADENYL_KINASE_3 ? . ?"
    );
    if assert_gemmi_reads(&out, &frames, "adk x3") {
        eprintln!("gemmi read the {n}-atom file");
    }
}

/// Atom names, residue names and chains that CIF 1.1 needs quoted (a leading quote or
/// underscore, `#`, `$`, `;`, brackets, blanks, reserved words, `.` and `?` as real names) or
/// a text field for (both `' ` and `" `) read back as they were, by us and by gemmi.
#[test]
fn labels_needing_quotes_read_back() {
    let names = [
        "O5'", "'N1", "\"N2", "_X", "#1", "$1", ";1", "[1]", "]2", ".", "?", "data_x", "LOOP_",
        "save_1", "global_", "stop_", "C A", "C\tB", "a' b\" c", "b\" c'", "x'", "O\"",
    ];
    let residues = ["DA", "A B", "'R", "_R", "ALA", "?"];
    let chains = ["_A", "?", "A'", "B B", "C"];
    let n = names.len();
    let mut f = Frame::new();
    for (i, name) in names.iter().enumerate() {
        f.positions
            .push([i as f32 * 1.5, -0.1 * i as f32, 1.0 / (i as f32 + 3.0)]);
        f.names.push(label(name));
        f.res_names.push(label(residues[i % residues.len()]));
        f.chains.push(label(chains[i % chains.len()]));
        f.res_ids.push(i as i64 - 3);
    }
    f.elements = vec![Element::UNKNOWN; n];
    f.properties.push(Property {
        name: "occupancy".into(),
        values: (0..n).map(|i| 1.0 / (i as f32 + 1.0)).collect(),
    });
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("quotes.cif");
    let frames = [f.clone(), f];
    write_file(&out, &frames);
    let text = std::fs::read_to_string(&out).unwrap();
    for quoted in [
        "\"O5'\"",
        "\"'N1\"",
        "'\"N2'",
        "'_X'",
        "'.'",
        "'?'",
        "'C A'",
        "\n;a' b\" c\n;",
    ] {
        assert!(text.contains(quoted), "{quoted} in\n{text}");
    }
    let back = stream(&mut Trajectory::open(&out).unwrap());
    assert_read_back(&frames, &back, "quoted labels");
    assert_gemmi_reads(&out, &frames, "quoted labels");
}

/// A file without frames is a data block with an empty `_atom_site` loop: no frame, for us
/// and for gemmi.
#[test]
fn no_frames_is_an_empty_loop() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("empty.cif");
    write_file(&out, &[]);
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("data_empty\n"), "{text}");
    assert!(stream(&mut Trajectory::open(&out).unwrap()).is_empty());
    if let Some(lines) = gemmi(&out) {
        assert_eq!(lines.len(), 1);
        assert_eq!(lines[0]["models"], serde_json::json!([]));
    }
}

/// A byte sink whose contents the test sees while the writer still owns it.
#[derive(Clone, Default)]
struct Shared(Rc<RefCell<Cursor<Vec<u8>>>>);

impl Write for Shared {
    fn write(&mut self, b: &[u8]) -> std::io::Result<usize> {
        self.0.borrow_mut().write(b)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl Seek for Shared {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        self.0.borrow_mut().seek(pos)
    }
}

/// Each frame's rows are written when the frame is handed over, not kept for `finish`.
#[test]
fn frames_are_written_as_they_come() {
    let source = stream(&mut Trajectory::open(data("mda_multi.pdb")).unwrap());
    let sink = Shared::default();
    let mut w = Writer::new(sink.clone(), Format::Mmcif, "multi.cif").unwrap();
    let rows = |sink: &Shared| {
        let text = String::from_utf8(sink.0.borrow().get_ref().clone()).unwrap();
        (text.lines())
            .filter(|l| l.starts_with("ATOM ") || l.starts_with("HETATM "))
            .count()
    };
    let mut expected = 0;
    for f in &source {
        w.write_frame(f).unwrap();
        expected += f.n_atoms();
        assert_eq!(rows(&sink), expected);
    }
    w.finish().unwrap();
}

/// What would not read back is refused before anything of the frame is written, naming the
/// atom: a line break in a label, a non-finite occupancy or B-factor, a model with other atoms.
#[test]
fn unwritable_frames_are_refused_naming_the_atom() {
    let good = stream(&mut Trajectory::open(data("mda_multi.pdb")).unwrap())[0].clone();
    let mut broken_name = good.clone();
    broken_name.names[2] = label("C\nA");
    let mut broken_chain = good.clone();
    broken_chain.chains[4] = label("A\r");
    let mut nan_b = good.clone();
    nan_b.properties.retain(|p| p.name != "bfactor");
    nan_b.properties.push(Property {
        name: "bfactor".into(),
        values: (0..good.n_atoms())
            .map(|i| if i == 5 { f32::NAN } else { 1.0 })
            .collect(),
    });
    let mut fewer = good.clone();
    fewer.retain_atoms(
        &vec![true; good.n_atoms() - 1]
            .into_iter()
            .chain([false])
            .collect::<Vec<_>>(),
    );
    for (frame, second, what) in [
        (
            &broken_name,
            false,
            "atom 2's name \"C\\nA\" holds a control character",
        ),
        (
            &broken_chain,
            false,
            "atom 4's chain \"A\\r\" holds a control character",
        ),
        (&nan_b, false, "atom 5's bfactor is NaN"),
        (&fewer, true, "it has 10 atoms and the first model 11"),
    ] {
        let mut w = Writer::new(Cursor::new(Vec::new()), Format::Mmcif, "bad.cif").unwrap();
        if second {
            w.write_frame(&good).unwrap();
        }
        let e = w.write_frame(frame).unwrap_err();
        assert!(matches!(e, Error::InvalidFrame { .. }), "{e:?}");
        assert!(e.to_string().contains(what), "{e}");
        let text = String::from_utf8(w.finish().unwrap().into_inner()).unwrap();
        let rows = (text.lines())
            .filter(|l| l.starts_with("ATOM ") || l.starts_with("HETATM "))
            .count();
        let expected = if second { good.n_atoms() } else { 0 };
        assert_eq!(rows, expected, "nothing of the refused frame:\n{text}");
    }
}

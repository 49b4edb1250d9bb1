//! PDBx/mmCIF: our reader against gemmi 0.7.5's reading of the same files (gemmi's conversions
//! of three PDB fixtures, and two entries written by the wwPDB; tests/data/gen_mmcif.py writes
//! mmcif_reference.json), the .cif against the .pdb it came from through our two readers, and
//! hand-written files for the CIF syntax and for each error. (Selections on the .cif against
//! MDAnalysis: tests/select.rs.)
//!
//! BinaryCIF: the .cif fixtures encoded by two other programs, biotite 1.6.0 and Mol* 5.6.1's
//! cif2bcif (tests/data/bcif/gen_bcif.py), read into the frames the .cif gives, field by
//! field; biotite's own decoding of each .bcif (bcif_reference.json) as a second reference;
//! gzip. (Damaged BinaryCIF: `bcif_campaign` in tests/fuzz_campaign.rs.)

use std::io::Cursor;
use std::path::PathBuf;

use serde_json::Value;
use texmap_md_io::{
    Error, Format, Frame, Label, ReadOptions, Topology, TopologyFormat, Trajectory,
};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// Every frame of `traj`, and the warnings it gave.
fn stream<R: std::io::Read + std::io::Seek>(traj: &mut Trajectory<R>) -> Vec<Frame> {
    let mut out = Vec::new();
    let mut f = Frame::new();
    while traj.read_next(&mut f).unwrap() {
        out.push(f.clone());
    }
    out
}

/// Reads `text` as mmCIF named `name`: the frames, or the first error.
fn read(text: &str, name: &str, opts: ReadOptions) -> Result<(Vec<Frame>, Vec<String>), Error> {
    let mut t = Trajectory::from_reader_with(Cursor::new(text), Format::Mmcif, name, opts)?;
    let mut out = Vec::new();
    let mut f = Frame::new();
    while t.read_next(&mut f)? {
        out.push(f.clone());
    }
    let warnings = t.warnings().iter().map(|w| w.to_string()).collect();
    Ok((out, warnings))
}

fn strict(text: &str) -> Result<Vec<Frame>, Error> {
    read(text, "hand.cif", ReadOptions::new()).map(|(f, _)| f)
}

fn labels(l: &[Label]) -> Vec<&str> {
    l.iter().map(|x| x.as_str()).collect()
}

/// Coordinates: gemmi's f64 rounded to 1e-4 in the JSON against our f32 of the same decimal
/// (at most 3 decimals in these files, values < 1000 Å: f32 is within 3e-5 of it).
const XYZ_TOL: f64 = 1e-3;

#[test]
fn reads_what_gemmi_reads() {
    let reference: Value =
        serde_json::from_str(&std::fs::read_to_string(data("mmcif_reference.json")).unwrap())
            .unwrap();
    let files = reference.as_object().unwrap();
    assert_eq!(files.len(), 5);
    for (name, r) in files {
        let mut traj = Trajectory::open(data(name)).unwrap();
        assert_eq!(traj.format(), Format::Mmcif);
        let frames = stream(&mut traj);
        let models = r["models"].as_array().unwrap();
        assert_eq!(frames.len(), models.len(), "{name}: models");
        assert_eq!(traj.n_frames().unwrap(), models.len(), "{name}");
        let mut dropped = Vec::new();
        for (k, (f, m)) in frames.iter().zip(models).enumerate() {
            let atoms = m["atoms"].as_array().unwrap();
            assert_eq!(f.n_atoms(), atoms.len(), "{name} model {k}: atoms");
            for (i, a) in atoms.iter().enumerate() {
                let what = format!("{name} model {k} atom {i}");
                assert_eq!(f.names[i], a[0].as_str().unwrap(), "{what}: name");
                assert_eq!(f.res_names[i], a[1].as_str().unwrap(), "{what}: residue");
                assert_eq!(f.chains[i], a[3].as_str().unwrap(), "{what}: chain");
                assert_eq!(
                    f.res_ids[i],
                    a[2].as_i64().unwrap(),
                    "{what}: residue number"
                );
                let el = a[4].as_str().unwrap();
                assert!(
                    f.elements[i].symbol().eq_ignore_ascii_case(el),
                    "{what}: element {} against gemmi's {el}",
                    f.elements[i].symbol()
                );
                for c in 0..3 {
                    let (want, got) = (a[5 + c].as_f64().unwrap(), f.positions[i][c] as f64);
                    assert!(
                        (want - got).abs() <= XYZ_TOL,
                        "{what} axis {c}: expected {want}, actual {got}, tolerance {XYZ_TOL}"
                    );
                }
            }
            let rows = m["rows"].as_u64().unwrap() as usize;
            if rows > atoms.len() {
                dropped.push((k, rows - atoms.len()));
            }
        }
        match r["cell"].as_array() {
            Some(c) => {
                let cell = frames[0].cell.expect("a cell");
                let want: Vec<f64> = c.iter().map(|v| v.as_f64().unwrap()).collect();
                let got = [cell.lengths(), cell.angles()].concat();
                for (w, g) in want.iter().zip(&got) {
                    assert!(
                        (w - g).abs() <= 1e-9,
                        "{name}: cell {got:?}, gemmi {want:?}"
                    );
                }
            }
            // gemmi calls the 1 Å placeholder of NMR entries no crystal; we drop it.
            None => assert!(frames.iter().all(|f| f.cell.is_none()), "{name}"),
        }
        let title = r["title"].as_str().unwrap_or("");
        assert_eq!(frames[0].comment, title, "{name}: title");
        // Every frame that lost alternate locations says so once, with the count.
        let warnings: Vec<String> = traj.warnings().iter().map(|w| w.to_string()).collect();
        assert_eq!(warnings.len(), dropped.len(), "{name}: {warnings:?}");
        for ((k, n), w) in dropped.iter().zip(&warnings) {
            let head = format!("{}: frame {k}, line ", traj.name());
            assert!(w.starts_with(&head), "{w}");
            assert!(
                w.contains(&format!("'{n} rows of other alternate locations")),
                "{w}"
            );
        }
    }
}

#[test]
fn real_entries_exercise_altlocs_microheterogeneity_and_quotes() {
    // 3JQH: residue 4 is PRO (altloc A) or SER (B), residue 18 ARG/GLN/GLU: gemmi keeps 206
    // of 238 rows, PRO 4 and ARG 18 (checked atom by atom above); here the rule's visible parts.
    let mut t = Trajectory::open(data("3jqh.cif")).unwrap();
    let f = &stream(&mut t)[0];
    assert_eq!(f.n_atoms(), 206);
    assert_eq!(&labels(&f.res_names)[..7], ["PRO"; 7]);
    let ser_1 = f
        .res_names
        .iter()
        .zip(&f.res_ids)
        .any(|(r, id)| r == "SER" && *id == 1);
    assert!(!ser_1);
    // The warning points at the first dropped row: ATOM 8, SER B, on line 754.
    let w = t.warnings()[0].to_string();
    assert!(w.contains("frame 0, line 754,"), "{w}");
    // 1UQC: names in double quotes with a prime ("O5'"), an NMR placeholder cell, a text-field
    // title.
    let mut t = Trajectory::open(data("1uqc.cif")).unwrap();
    let f = &stream(&mut t)[0];
    assert_eq!(f.names[0], "O5'");
    assert_eq!(f.names[17], "H5''");
    assert!(f.cell.is_none());
    assert!(
        f.comment
            .starts_with("SELF-COMPLEMENTARY DNA 5'-D(CACGTG)2")
    );
    assert!(t.warnings().is_empty());
}

#[test]
fn cif_and_pdb_give_the_same_frames() {
    for (pdb, cif) in [
        ("mda_multi.pdb", "gemmi_multi.cif"),
        ("topo_mda.pdb", "gemmi_topo.cif"),
        ("select_mda.pdb", "gemmi_select.cif"),
    ] {
        let a = stream(&mut Trajectory::open(data(pdb)).unwrap());
        let b = stream(&mut Trajectory::open(data(cif)).unwrap());
        assert_eq!(a.len(), b.len(), "{cif}");
        for (k, (mut a, mut b)) in a.into_iter().zip(b).enumerate() {
            // gemmi numbers atoms on through the models (model 2 starts at 12), PDB serials
            // restart at 1: ids agree in model 1 only.
            if k > 0 {
                a.ids.clear();
                b.ids.clear();
            }
            assert_eq!(a, b, "{cif} frame {k}");
        }
    }
}

#[test]
fn topology_from_cif_equals_the_pdb_one_without_bonds() {
    let cif = Topology::open(data("gemmi_topo.cif")).unwrap();
    let pdb = Topology::open(data("topo_mda.pdb")).unwrap();
    assert_eq!(cif.n_atoms(), 66);
    assert_eq!(cif.names, pdb.names);
    assert_eq!(cif.res_names, pdb.res_names);
    assert_eq!(cif.res_ids, pdb.res_ids);
    assert_eq!(cif.elements, pdb.elements);
    assert_eq!(cif.ids, pdb.ids);
    assert!(cif.bonds.is_empty(), "bonds come from the distance finder");
    let bytes = std::fs::read(data("gemmi_topo.cif")).unwrap();
    let t = Topology::from_reader(Cursor::new(bytes), TopologyFormat::Mmcif, "t.cif").unwrap();
    assert_eq!(t.names, pdb.names);
    // The topology labels the XTC of the same atoms.
    let mut traj = Trajectory::open(data("topo_mda.xtc")).unwrap();
    let mut f = Frame::new();
    traj.read_next(&mut f).unwrap();
    cif.apply(&mut f, traj.name(), 0).unwrap();
    assert_eq!(f.names, pdb.names);
}

/// A header exercising the syntax: comments, a text field before the atoms whose lines look
/// like CIF, quotes holding blanks and quote characters, a loop holding a text field, `?`/`.`.
const HEADER: &str = "# written by hand
data_hand
_struct.title
;A title on
two lines
;
_cell.length_a 10.0(2)
_cell.length_b 11
_cell.length_c 12
loop_
_misc.a
_misc.b
'it's here' \"say \"hi\"now\"
;loop_
_atom_site.Cartn_x
data_fake
;
x#y
?   .
_misc_pair.text 'a # not a comment'
";

#[test]
fn syntax_quotes_text_fields_reordered_columns_and_missing_values() {
    // Columns in an unusual order; auth_* missing (`?`/`.`) falls back to label_*; a missing
    // type_symbol falls back to the name; names with blanks and quotes.
    let text = format!(
        "{HEADER}loop_
_atom_site.Cartn_z
_atom_site.auth_atom_id
_atom_site.label_comp_id
_atom_site.id
_atom_site.type_symbol
_atom_site.label_atom_id
_atom_site.auth_seq_id
_atom_site.label_seq_id
_atom_site.unknown_item
_atom_site.Cartn_y
_atom_site.Cartn_x
3.0 CA ALA 7 C CA 5 1 ; 2.0 1.0
6.0 ? ALA 8 ? CB . 2 'x y' 5.0 4.0
9.0 \"O5'\" DA 9 O 'C 1' 3 3 \"a'b\" 8.0 7.0
-1 'N''X' 'A A' . . N . . . 0 0
#
"
    );
    let f = &strict(&text).unwrap()[0];
    assert_eq!(f.positions[0], [1.0, 2.0, 3.0]);
    assert_eq!(f.positions[2], [7.0, 8.0, 9.0]);
    // No escapes in CIF 1.1: 'N''X' is N''X (its first quotes are not followed by a blank).
    assert_eq!(labels(&f.names), ["CA", "CB", "O5'", "N''X"]);
    assert_eq!(labels(&f.res_names), ["ALA", "ALA", "DA", "A A"]);
    assert_eq!(f.res_ids, [5, 2, 3, 0]);
    assert_eq!(f.ids, [7, 8, 9, 4]);
    let el: Vec<&str> = f.elements.iter().map(|e| e.symbol()).collect();
    assert_eq!(el, ["C", "C", "O", "N"]);
    assert_eq!(f.comment, "A title on two lines");
    let c = f.cell.unwrap();
    assert_eq!(c.lengths(), [10.0, 11.0, 12.0]);
    assert_eq!(c.angles(), [90.0; 3]);
}

const ATOM_LOOP: &str = "loop_
_atom_site.group_PDB
_atom_site.id
_atom_site.label_atom_id
_atom_site.label_alt_id
_atom_site.label_comp_id
_atom_site.auth_asym_id
_atom_site.auth_seq_id
_atom_site.Cartn_x
_atom_site.Cartn_y
_atom_site.Cartn_z
_atom_site.pdbx_PDB_model_num
";

#[test]
fn first_alternate_location_is_kept_with_a_warning() {
    let text = format!(
        "data_alt\n{ATOM_LOOP}\
ATOM 1 N  . SER A 1 0 0 0 1
ATOM 2 CB A SER A 1 1 0 0 1
ATOM 3 CB B SER A 1 9 9 9 1
ATOM 4 OG B SER A 1 2 0 0 1
ATOM 5 OG A SER A 1 8 8 8 1
ATOM 6 N  B THR A 2 3 0 0 1
ATOM 7 N  A ALA A 2 7 7 7 1
ATOM 8 N  . GLY A 3 4 0 0 1
"
    );
    let (frames, warnings) = read(&text, "alt.cif", ReadOptions::new()).unwrap();
    let f = &frames[0];
    // CB: A first; OG: B first (each atom's first); residue 2: THR first, ALA dropped.
    assert_eq!(f.ids, [1, 2, 4, 6, 8]);
    assert_eq!(f.positions[2], [2.0, 0.0, 0.0]);
    assert_eq!(labels(&f.res_names), ["SER", "SER", "SER", "THR", "GLY"]);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].starts_with("alt.cif: frame 0, line 16,"),
        "{}",
        warnings[0]
    );
    assert!(
        warnings[0].contains("'3 rows of other alternate locations"),
        "{}",
        warnings[0]
    );
}

#[test]
fn models_are_frames_with_random_access() {
    let text = format!(
        "data_nmr\n{ATOM_LOOP}\
ATOM 1 N . GLY A 1 1 0 0 1
ATOM 2 C . GLY A 1 2 0 0 1
ATOM 3 N . GLY A 1 1 1 0 2
ATOM 4 C . GLY A 1 2 1 0 2
ATOM 5 N . GLY A 1 1 2 0 5
ATOM 6 C . GLY A 1 2 2 0 5
#
loop_
_trailer.x
1 2 3
"
    );
    let frames = strict(&text).unwrap();
    assert_eq!(frames.len(), 3);
    assert_eq!(frames[2].positions[1], [2.0, 2.0, 0.0]);
    let mut t = Trajectory::from_reader(Cursor::new(&text), Format::Mmcif, "nmr.cif").unwrap();
    assert_eq!(t.n_frames().unwrap(), 3);
    let mut f = Frame::new();
    for k in [2, 0, 1, 2] {
        t.read_frame(k, &mut f).unwrap();
        assert_eq!(f, frames[k], "frame {k}");
    }
    assert!(!t.read_next(&mut f).unwrap());
}

#[test]
fn a_one_atom_file_in_pair_form_is_read() {
    let text = "data_ion\n_atom_site.group_PDB HETATM\n_atom_site.id 1\n_atom_site.type_symbol NA\n\
_atom_site.label_atom_id NA\n_atom_site.label_comp_id NA\n_atom_site.Cartn_x 1.5\n\
_atom_site.Cartn_y -2\n_atom_site.Cartn_z 3e1\n#\n_other.item 1\n";
    let frames = strict(text).unwrap();
    assert_eq!(frames.len(), 1);
    assert_eq!(frames[0].positions, [[1.5, -2.0, 30.0]]);
    assert_eq!(frames[0].elements[0].symbol(), "Na");
}

#[test]
fn an_atom_site_loop_without_rows_has_no_frame() {
    for end in ["", "#\nloop_\n_x.y\n1\n"] {
        let text = format!("data_empty\n{ATOM_LOOP}{end}");
        let mut t = Trajectory::from_reader(Cursor::new(&text), Format::Mmcif, "e.cif").unwrap();
        assert_eq!(t.n_frames().unwrap(), 0, "{text}");
        assert!(strict(&text).unwrap().is_empty());
    }
}

/// Expects an error whose message starts with `hand.cif: frame F, line L,` and contains `what`.
fn fails(text: &str, frame: usize, line: u64, what: &str) -> Error {
    let e = strict(text).unwrap_err();
    let s = e.to_string();
    let head = format!("hand.cif: frame {frame}, line {line}, byte ");
    assert!(s.starts_with(&head), "expected {head}…, got {s}");
    assert!(s.contains(what), "expected {what:?} in {s}");
    e
}

#[test]
fn damage_gives_located_errors() {
    let row = "ATOM 1 N . GLY A 1 1 0 0 1\n";
    let atoms = |rows: &str| format!("data_x\n{ATOM_LOOP}{rows}");
    // The loop starts on line 2, its rows on line 14.
    let no_y = atoms(row).replace("_atom_site.Cartn_y\n", "");
    fails(&no_y, 0, 2, "no _atom_site.Cartn_y");
    fails(
        &atoms("ATOM 1 N . GLY A 1 1 0x 0 1\n"),
        0,
        14,
        "Cartn_y, found '0x'",
    );
    fails(
        &atoms("ATOM 1 N . GLY A 1 1 ? 0 1\n"),
        0,
        14,
        "Cartn_y, found '?'",
    );
    let short = atoms(&format!(
        "{row}ATOM 2 C . GLY A 1 2 0 0\n#\nloop_\n_x.y\n1\n"
    ));
    fails(&short, 0, 15, "10 of 11 values");
    let bad_loop = format!("data_x\nloop_\n_a.b\n_a.c\n1 2 3\n{ATOM_LOOP}{row}");
    fails(&bad_loop, 0, 5, "1 of 2 values in the last row");
    fails(&atoms("ATOM 1 N . 'GLY A 1 1 0 0 1\n"), 0, 14, "closing '");
    let open_text = "data_x\n_struct.title\n;never closed\n";
    let e = fails(open_text, 0, 3, "to close the text field");
    assert!(matches!(e, Error::Truncated { .. }));
    fails("data_x\n_cell.length_a 10\n", 0, 3, "an _atom_site loop");
    fails(
        "data_x\n_a.b 1\ndata_y\n",
        0,
        3,
        "an _atom_site loop in the first data block",
    );
    fails("_a.b 1\n", 0, 1, "a data_ block header");
    fails(&atoms("ATOM 1 N . GLY A 1 1 0 0 1 extra\n"), 0, 14, "");
    // Models: another atom count (an error, a warning under allow_truncated), decreasing
    // numbers, a model that does not start its line.
    let counts = atoms(&format!(
        "{row}ATOM 2 C . GLY A 1 2 0 0 1\n{}",
        row.replace(" 1\n", " 2\n")
    ));
    fails(&counts, 1, 16, "as many _atom_site rows as model 1");
    let lenient = ReadOptions::new().allow_truncated(true);
    let (frames, warnings) = read(&counts, "hand.cif", lenient).unwrap();
    assert_eq!(frames.len(), 2);
    assert!(warnings[0].contains("model 1 has 2"), "{warnings:?}");
    let down = atoms(&format!("{}{row}", row.replace(" 1\n", " 2\n")));
    fails(&down, 0, 15, "model 1 after model 2");
    let joined = atoms("ATOM 1 N . GLY A 1 1 0 0 1 ATOM 2 N . GLY A 1 1 0 0 2\n");
    fails(&joined, 0, 14, "at the start of a line");
}

#[test]
fn files_are_told_by_extension_and_content() {
    let dir = tempfile::tempdir().unwrap();
    for ext in ["cif", "mmcif", "CIF"] {
        let p = dir.path().join(format!("x.{ext}"));
        std::fs::copy(data("gemmi_multi.cif"), &p).unwrap();
        assert_eq!(Trajectory::open(&p).unwrap().format(), Format::Mmcif);
        assert_eq!(Topology::open(&p).unwrap().n_atoms(), 11);
    }
    let p = dir.path().join("noext");
    std::fs::copy(data("1uqc.cif"), &p).unwrap();
    assert_eq!(Trajectory::open(&p).unwrap().format(), Format::Mmcif);
}

// ---------------------------------------------------------------------------------------------
// BinaryCIF

/// The BinaryCIF fixtures and the .cif each was made from.
const BCIF: [(&str, &str); 8] = [
    ("bcif/biotite_gemmi_multi.bcif", "gemmi_multi.cif"),
    ("bcif/biotite_3jqh.bcif", "3jqh.cif"),
    ("bcif/biotite_1uqc.bcif", "1uqc.cif"),
    ("bcif/biotite_gemmi_topo_plain.bcif", "gemmi_topo.cif"),
    ("bcif/biotite_gemmi_multi_encodings.bcif", "gemmi_multi.cif"),
    ("bcif/molstar_gemmi_multi.bcif", "gemmi_multi.cif"),
    ("bcif/molstar_3jqh.bcif", "3jqh.cif"),
    ("bcif/molstar_1uqc.bcif", "1uqc.cif"),
];

/// The file whose Cartn_z is IntervalQuantization-encoded: 2^16 steps over the column's range.
const QUANTISED: &str = "bcif/biotite_gemmi_multi_encodings.bcif";

/// Every frame of a file opened by path, its frame count and its warnings.
fn read_all(name: &str) -> (Trajectory, Vec<Frame>, Vec<String>) {
    let mut t = Trajectory::open(data(name)).unwrap();
    let frames = stream(&mut t);
    assert_eq!(t.n_frames().unwrap(), frames.len(), "{name}");
    let warnings = t.warnings().iter().map(|w| w.to_string()).collect();
    (t, frames, warnings)
}

/// The count in a dropped-alternate-locations warning.
fn dropped(w: &str) -> usize {
    let at = w.find(" rows of other alternate locations").unwrap();
    let head = &w[..at];
    head[head.rfind('\'').unwrap() + 1..].parse().unwrap()
}

/// Every field our reader gives from the .bcif is the one it gives from the .cif the .bcif was
/// made from: names, elements, residues, chains, ids, the occupancy and bfactor properties,
/// cell, title and the alternate-location warnings. Positions are the same f32 bit for bit
/// (the writers keep the decimals: FixedPoint of 10^3, Float64, Float32 of the same decimal:
/// see src/bcif.rs, # Numbers), except the IntervalQuantization column, within one step
/// (biotite 1.6's encoder takes the step at or above the value, not the nearest).
#[test]
fn bcif_gives_the_frames_of_its_cif() {
    for (bcif, cif) in BCIF {
        let (t, b, bw) = read_all(bcif);
        assert_eq!(t.format(), Format::Bcif, "{bcif}");
        let (_, c, cw) = read_all(cif);
        assert_eq!(b.len(), c.len(), "{bcif}: frames");
        // The quantised axis: a step, plus the f32 rounding of values below 256 Å.
        let z: Vec<f32> = c
            .iter()
            .flat_map(|f| f.positions.iter().map(|p| p[2]))
            .collect();
        let (lo, hi) = z
            .iter()
            .fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
        let tol = (hi - lo) as f64 / 65535.0 + 256.0 * f32::EPSILON as f64;
        for (k, (mut fb, fc)) in b.into_iter().zip(c).enumerate() {
            if bcif == QUANTISED {
                for (i, (pb, pc)) in fb.positions.iter_mut().zip(&fc.positions).enumerate() {
                    let (got, want) = (pb[2] as f64, pc[2] as f64);
                    assert!(
                        (got - want).abs() <= tol,
                        "{bcif} frame {k} atom {i} z: expected {want}, actual {got}, tolerance {tol}"
                    );
                    pb[2] = pc[2];
                }
            }
            assert_eq!(fb, fc, "{bcif} frame {k}");
        }
        // The same alternate locations dropped, each frame's warning naming the .bcif.
        assert_eq!(bw.len(), cw.len(), "{bcif}: {bw:?} {cw:?}");
        for (wb, wc) in bw.iter().zip(&cw) {
            assert!(wb.starts_with(&format!("{}: frame ", t.name())), "{wb}");
            assert!(
                wb.contains(", found '") && wb.contains("_atom_site row"),
                "{wb}"
            );
            assert_eq!(dropped(wb), dropped(wc), "{wb} / {wc}");
        }
    }
}

/// Our reading against biotite's decoding of each .bcif (its BinaryCIFFile, not its structure
/// parser): row count, model numbers, every atom name (files without alternate locations), the
/// first and last rows' coordinates, cell and title. Coordinates: our f32 is biotite's decoded
/// double (or float32) rounded to f32, bit for bit, the IntervalQuantization column too (both
/// compute min + k (max − min) / (numSteps − 1)).
#[test]
fn bcif_matches_biotites_decoding() {
    let reference: Value =
        serde_json::from_str(&std::fs::read_to_string(data("bcif/bcif_reference.json")).unwrap())
            .unwrap();
    let files = reference["files"].as_object().unwrap();
    assert_eq!(files.len(), BCIF.len());
    for (file, r) in files {
        let name = format!("bcif/{file}");
        let (_, frames, warnings) = read_all(&name);
        let models: Vec<i64> = (r["models"].as_array().unwrap().iter())
            .map(|m| m.as_i64().unwrap())
            .collect();
        let mut distinct = models.clone();
        distinct.dedup();
        assert_eq!(frames.len(), distinct.len(), "{name}: models");
        let kept: usize = frames.iter().map(|f| f.n_atoms()).sum();
        let lost: usize = warnings.iter().map(|w| dropped(w)).sum();
        assert_eq!(
            kept + lost,
            r["rows"].as_u64().unwrap() as usize,
            "{name}: rows"
        );
        if lost == 0 {
            let names: Vec<&str> = frames.iter().flat_map(|f| labels(&f.names)).collect();
            let want: Vec<&str> = (r["names"].as_array().unwrap().iter())
                .map(|n| n.as_str().unwrap())
                .collect();
            assert_eq!(names, want, "{name}: names");
        }
        let ends = [
            ("first", frames[0].positions[0]),
            ("last", *frames.last().unwrap().positions.last().unwrap()),
        ];
        for (which, got) in ends {
            for (axis, want) in r[which].as_array().unwrap().iter().enumerate() {
                let want = want.as_f64().unwrap() as f32;
                assert_eq!(got[axis], want, "{name} {which} row, axis {axis}");
            }
        }
        let cell: Vec<f64> = (r["cell"].as_array().unwrap().iter())
            .map(|v| v.as_f64().unwrap())
            .collect();
        match frames[0].cell {
            Some(c) => assert_eq!([c.lengths(), c.angles()].concat(), cell, "{name}: cell"),
            // The NMR placeholder is dropped, as from the .cif.
            None => assert_eq!(cell, [1.0, 1.0, 1.0, 90.0, 90.0, 90.0], "{name}"),
        }
        assert_eq!(
            frames[0].comment,
            r["title"].as_str().unwrap(),
            "{name}: title"
        );
    }
}

#[test]
fn bcif_gz_topologies_and_content_sniffing() {
    // gzip: the same frames as the plain file (cif2bcif's own gzip).
    let (t, gz, _) = read_all("bcif/molstar_3jqh.bcif.gz");
    assert_eq!(t.format(), Format::Bcif);
    let (_, plain, _) = read_all("bcif/molstar_3jqh.bcif");
    assert_eq!(gz, plain);
    // A topology, from the name (.bcif and .bcif.gz), equals the .cif's.
    let cif = Topology::open(data("gemmi_topo.cif")).unwrap();
    let bcif = Topology::open(data("bcif/biotite_gemmi_topo_plain.bcif")).unwrap();
    assert_eq!(
        TopologyFormat::from_path(&data("x.bcif.gz")),
        Some(TopologyFormat::Bcif)
    );
    assert_eq!(bcif.n_atoms(), 66);
    assert_eq!(
        (&bcif.names, &bcif.res_names, &bcif.res_ids),
        (&cif.names, &cif.res_names, &cif.res_ids)
    );
    assert_eq!(
        (&bcif.elements, &bcif.ids, &bcif.chains),
        (&cif.elements, &cif.ids, &cif.chains)
    );
    let gz = Topology::open(data("bcif/molstar_3jqh.bcif.gz")).unwrap();
    assert_eq!(gz.names, Topology::open(data("3jqh.cif")).unwrap().names);
    // It labels the XTC of the same atoms.
    let mut traj = Trajectory::open(data("topo_mda.xtc")).unwrap();
    let mut f = Frame::new();
    traj.read_next(&mut f).unwrap();
    bcif.apply(&mut f, traj.name(), 0).unwrap();
    assert_eq!(f.names, cif.names);
    // Told by content without the extension; a .bcif that is not one says what it expected.
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("noext");
    std::fs::copy(data("bcif/molstar_gemmi_multi.bcif"), &p).unwrap();
    assert_eq!(Trajectory::open(&p).unwrap().format(), Format::Bcif);
    let p = dir.path().join("text.bcif");
    std::fs::copy(data("gemmi_multi.cif"), &p).unwrap();
    let e = Trajectory::open(&p).err().unwrap().to_string();
    assert!(
        e.starts_with(&format!(
            "{}: byte 0: expected a BinaryCIF file",
            p.display()
        )),
        "{e}"
    );
    // Random access across models.
    let mut t = Trajectory::open(data("bcif/molstar_gemmi_multi.bcif")).unwrap();
    let all = stream(&mut t);
    for k in [2, 0, 1, 2] {
        t.read_frame(k, &mut f).unwrap();
        assert_eq!(f, all[k], "frame {k}");
    }
    assert!(!t.read_next(&mut f).unwrap());
}

//! Crystallographic CIF (`Format::CrystalCif`) against ASE 3.29 on real COD mineral files
//! (tests/data/crystal/reference.json, written by tests/data/gen_crystal_cif.py), and on
//! synthetic files with analytic answers: rock salt from its 192 operations, special
//! positions, P 1 without operations, and the errors.

use std::io::Cursor;
use std::path::PathBuf;
use texmap_md_io::{Error, Format, Frame, Trajectory, UnitCell};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn read_str(text: &str) -> Result<Vec<Frame>, Error> {
    let src = Cursor::new(text.as_bytes().to_vec());
    let mut t = Trajectory::from_reader(src, Format::CrystalCif, "x.cif")?;
    let mut frames = Vec::new();
    let mut f = Frame::new();
    while t.read_next(&mut f)? {
        assert_eq!(f.check(), Ok(()));
        frames.push(f.clone());
    }
    Ok(frames)
}

fn one(text: &str) -> Frame {
    let mut frames = read_str(text).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(frames.len(), 1);
    frames.remove(0)
}

fn err(text: &str) -> String {
    match read_str(text) {
        Ok(f) => panic!("read {} frames, expected an error", f.len()),
        Err(e) => e.to_string(),
    }
}

/// `a - b` through the cell with the minimum image (rows of `m` are the edges).
fn min_image(m: [[f64; 3]; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let c = UnitCell::from_matrix(m).unwrap();
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    // Fractions of d: solve d = f M by Cramer's rule.
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let f = [0, 1, 2].map(|k| {
        let mut r = m;
        r[k] = d;
        let v = det(r) / det(m);
        v - v.round()
    });
    let p = c.to_cartesian(f);
    (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt()
}

/// Matches every atom of `f` to an unused atom of the same element in `(elements,
/// positions)` within `tol` Å (minimum image through `cell`); panics naming the first that
/// has none.
fn match_as_sets(
    what: &str,
    f: &Frame,
    cell: [[f64; 3]; 3],
    elements: &[String],
    positions: &[[f64; 3]],
    tol: f64,
) {
    assert_eq!(f.n_atoms(), positions.len(), "{what}: atom count");
    let mut used = vec![false; positions.len()];
    for (i, p) in f.positions.iter().enumerate() {
        let p = p.map(f64::from);
        let sym = f.elements[i].symbol();
        let best = (0..positions.len())
            .filter(|&j| !used[j] && elements[j] == sym)
            .map(|j| (min_image(cell, p, positions[j]), j))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        match best {
            Some((d, j)) if d <= tol => used[j] = true,
            _ => panic!(
                "{what}: atom {i} ({sym} at {p:?}) has no unused {sym} within {tol} Å (nearest: \
                 {best:?})"
            ),
        }
    }
}

#[test]
fn cod_minerals_match_ase() {
    let text = std::fs::read_to_string(data("crystal/reference.json")).unwrap();
    let reference: serde_json::Value = serde_json::from_str(&text).unwrap();
    let files = reference.as_object().unwrap();
    assert_eq!(files.len(), 9);
    let mut atoms = 0;
    for (name, frames) in files {
        let mut t = Trajectory::open(data(&format!("crystal/{name}"))).unwrap();
        assert_eq!(t.format(), Format::CrystalCif, "{name}");
        let frames = frames.as_array().unwrap();
        assert_eq!(t.n_frames().unwrap(), frames.len(), "{name}");
        let mut f = Frame::new();
        for (k, r) in frames.iter().enumerate() {
            assert!(t.read_next(&mut f).unwrap(), "{name} frame {k}");
            let what = format!("{name} frame {k}");
            let v3 = |v: &serde_json::Value| -> [f64; 3] {
                let a = v.as_array().unwrap();
                [0, 1, 2].map(|i| a[i].as_f64().unwrap())
            };
            let cell: Vec<[f64; 3]> = r["cell"].as_array().unwrap().iter().map(v3).collect();
            let cell = [cell[0], cell[1], cell[2]];
            // Cells: the same lengths-and-angles formula in f64 (ASE's cellpar_to_cell, a
            // along x, b in the xy plane); 1e-9 Å allows for the order of the operations.
            let ours = f.cell.expect("a cell").matrix();
            for i in 0..3 {
                for j in 0..3 {
                    let (e, a) = (cell[i][j], ours[i][j]);
                    assert!(
                        (e - a).abs() <= 1e-9,
                        "{what}: cell[{i}][{j}] expected {e}, actual {a}, tolerance 1e-9"
                    );
                }
            }
            let elements: Vec<String> = (r["elements"].as_array().unwrap().iter())
                .map(|e| e.as_str().unwrap().to_string())
                .collect();
            let positions: Vec<[f64; 3]> =
                r["positions"].as_array().unwrap().iter().map(v3).collect();
            assert_eq!(
                r["n_atoms"].as_u64().unwrap() as usize,
                f.n_atoms(),
                "{what}"
            );
            // Positions: f32 output of f64 arithmetic (1e-5 Å at 10 Å) against ASE's f64;
            // 1e-3 Å leaves room for where each wraps a coordinate of 0 or 1.
            match_as_sets(&what, &f, cell, &elements, &positions, 1e-3);
            assert_eq!(f.ids, (1..=f.n_atoms() as i64).collect::<Vec<_>>());
            atoms += f.n_atoms();
        }
        assert!(
            !t.read_next(&mut f).unwrap(),
            "{name}: more frames than ASE"
        );
    }
    assert_eq!(atoms, 94);
}

#[test]
fn mmcif_files_still_open_as_mmcif_and_cod_heads_as_crystal() {
    for name in [
        "1uqc.cif",
        "3jqh.cif",
        "3jqh.cif.gz",
        "gemmi_multi.cif",
        "gemmi_topo.cif",
        "gemmi_select.cif",
    ] {
        let t = Trajectory::open(data(name)).unwrap();
        assert_eq!(t.format(), Format::Mmcif, "{name}");
    }
    // 512 bytes from a COD file's data block reach no atom site: the first tag decides.
    let cod = std::fs::read_to_string(data("crystal/cod_9001665.cif")).unwrap();
    let block = &cod.as_bytes()[cod.find("data_").unwrap()..];
    assert_eq!(Format::from_magic(&block[..512]), Some(Format::CrystalCif));
    let pdbx = std::fs::read(data("1uqc.cif")).unwrap();
    assert_eq!(Format::from_magic(&pdbx[..512]), Some(Format::Mmcif));
    assert_eq!(Format::cif_kind(b"data_x\n"), Format::Mmcif);
    assert_eq!(
        Format::cif_kind(b"data_x\n_entry.id x\nloop_\n_atom_site.id\n_atom_site.Cartn_x\n"),
        Format::Mmcif
    );
    // DDLm spelling of a core CIF: fractional sites, dotted names.
    assert_eq!(
        Format::cif_kind(
            b"data_x\n_cell.length_a 4\nloop_\n_atom_site.label\n_atom_site.fract_x\n"
        ),
        Format::CrystalCif
    );
    // Tags inside a text field do not count.
    assert_eq!(
        Format::cif_kind(b"data_x\n_struct.title\n;\n_atom_site_label\n;\n_atom_site.id 1\n"),
        Format::Mmcif
    );
    assert_eq!(
        Format::from_extension("cif-crystal"),
        Some(Format::CrystalCif)
    );
    assert_eq!(Format::CrystalCif.name(), "cif-crystal");
    assert!(Format::CrystalCif.is_text());
}

/// The 48 point operations of m-3m (signed permutations) times the 4 F centrings, written in
/// several notations.
fn fm3m_operations() -> Vec<String> {
    let perms = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut ops = Vec::new();
    for t in [[0, 0, 0], [0, 1, 1], [1, 0, 1], [1, 1, 0]] {
        for p in perms {
            for signs in 0..8 {
                let comp: Vec<String> = (0..3)
                    .map(|k| {
                        let sign = if signs >> k & 1 == 1 { "-" } else { "" };
                        let var = ["x", "y", "z"][p[k]];
                        match (t[k], (signs + k) % 2) {
                            (0, _) => format!("{sign}{var}"),
                            (_, 0) => {
                                format!("1/2{}{var}", if sign.is_empty() { "+" } else { "-" })
                            }
                            _ => format!("{sign}{var}+0.5"),
                        }
                    })
                    .collect();
                ops.push(comp.join(","));
            }
        }
    }
    ops
}

#[test]
fn rock_salt_from_its_192_operations() {
    let ops = fm3m_operations();
    assert_eq!(ops.len(), 192);
    let mut text = String::from(
        "data_NaCl\n_chemical_name_mineral Halite\n_symmetry_space_group_name_H-M 'F m -3 m'\n\
         _cell_length_a 5.6402(3)\n_cell_length_b 5.6402(3)\n_cell_length_c 5.6402(3)\n\
         _cell_angle_alpha 90\n_cell_angle_beta 90\n_cell_angle_gamma 90\n\
         loop_\n_symmetry_equiv_pos_site_id\n_symmetry_equiv_pos_as_xyz\n",
    );
    for (k, op) in ops.iter().enumerate() {
        // Quoted with blanks every other line.
        if k % 2 == 0 {
            text += &format!("{} {op}\n", k + 1);
        } else {
            text += &format!("{} '{}'\n", k + 1, op.replace(',', ", "));
        }
    }
    text += "loop_\n_atom_site_label\n_atom_site_type_symbol\n_atom_site_fract_x\n\
             _atom_site_fract_y\n_atom_site_fract_z\n_atom_site_occupancy\n\
             _atom_site_U_iso_or_equiv\nNa1 Na1+ 0 0 0 1 0.0100(2)\nCl1 Cl1- 0.5 0.5 0.5 1.0 ?\n";
    let f = one(&text);
    assert_eq!(f.n_atoms(), 8);
    assert_eq!(f.comment, "NaCl: Halite");
    let a = 5.6402;
    let fcc = [
        [0.0, 0.0, 0.0],
        [0.0, 0.5, 0.5],
        [0.5, 0.0, 0.5],
        [0.5, 0.5, 0.0],
    ];
    let mut elements = Vec::new();
    let mut positions = Vec::new();
    for (sym, shift) in [("Na", 0.0), ("Cl", 0.5)] {
        for p in fcc {
            elements.push(sym.to_string());
            positions.push(p.map(|v: f64| ((v + shift) % 1.0) * a));
        }
    }
    let cell = [[a, 0.0, 0.0], [0.0, a, 0.0], [0.0, 0.0, a]];
    match_as_sets("NaCl", &f, cell, &elements, &positions, 1e-5);
    // Site by site: the four Na first, with their site's label, type and properties.
    let names: Vec<&str> = f.names.iter().map(|n| n.as_str()).collect();
    assert_eq!(
        names,
        ["Na1", "Na1", "Na1", "Na1", "Cl1", "Cl1", "Cl1", "Cl1"]
    );
    assert_eq!(f.types[0], "Na1+");
    assert_eq!(f.types[7], "Cl1-");
    assert_eq!(f.property("occupancy"), Some(&[1.0f32; 8][..]));
    let b = f.property("bfactor").unwrap();
    let b_na = 8.0 * std::f32::consts::PI.powi(2) * 0.01;
    assert!(
        (b[0] - b_na).abs() < 1e-5,
        "expected {b_na}, actual {}, tolerance 1e-5",
        b[0]
    );
    assert_eq!(b[4], 0.0);
}

/// A P -1 cell (a = 5, b = 6, c = 7 Å, oblique) with the given sites after the operations.
fn p1bar(sites: &str) -> String {
    format!(
        "data_t\n_cell_length_a 5\n_cell_length_b 6\n_cell_length_c 7\n_cell_angle_alpha 80\n\
         _cell_angle_beta 95\n_cell_angle_gamma 110\n_symmetry_space_group_name_H-M 'P -1'\n\
         loop_\n_space_group_symop_operation_xyz\nx,y,z\n-x,-y,-z\n\
         loop_\n_atom_site_label\n_atom_site_fract_x\n_atom_site_fract_y\n_atom_site_fract_z\n\
         {sites}"
    )
}

#[test]
fn special_positions_are_merged_within_the_tolerance() {
    // On the inversion centre (1/2, 0, 1/2): one atom; a general site: two.
    let f = one(&p1bar("Fe1 0.5 0 0.5\nO1 0.1 0.2 0.3\n"));
    assert_eq!(f.n_atoms(), 3);
    assert_eq!(f.elements[0].symbol(), "Fe");
    // On the centre at 0 written as 1 and as -0.0: wrapped, still one atom.
    assert_eq!(one(&p1bar("Fe1 1.0 -0.0 0\n")).n_atoms(), 1);
    // 1e-4 off the centre (images 2e-4 apart, about 0.001 Å): one atom, the first image.
    let f = one(&p1bar("Fe1 0.5001 0 0.5\n"));
    assert_eq!(f.n_atoms(), 1);
    // 0.01 off (images about 0.1 Å apart): two atoms, a split site.
    assert_eq!(one(&p1bar("Fe1 0.51 0 0.5\n")).n_atoms(), 2);
    // Two sites on the same spot are two sites (each its own atoms: nothing is dropped).
    assert_eq!(one(&p1bar("Fe1 0.5 0 0.5\nMg1 0.5 0 0.5\n")).n_atoms(), 2);
}

#[test]
fn p1_without_operations_takes_the_sites_as_they_are() {
    let text = "data_p1\n_symmetry_space_group_name_H-M 'P 1'\n_cell_length_a 4\n\
                _cell_length_b 4\n_cell_length_c 4\nloop_\n_atom_site_label\n\
                _atom_site_fract_x\n_atom_site_fract_y\n_atom_site_fract_z\n\
                C1 0.25 0.5 0.75\nC2 1.25 0 0\n";
    let f = one(text);
    // Angles default to 90; fractions wrapped into the cell as any expanded site.
    assert_eq!(f.positions, [[1.0, 2.0, 3.0], [1.0, 0.0, 0.0]]);
    assert!(f.cell.unwrap().is_orthorhombic());
    assert_eq!(f.comment, "p1");
    // No space group at all, and a number 1: the same.
    assert_eq!(
        one(&text.replace("_symmetry_space_group_name_H-M 'P 1'", "")).n_atoms(),
        2
    );
    assert_eq!(
        one(&text.replace(
            "_symmetry_space_group_name_H-M 'P 1'",
            "_space_group_IT_number 1"
        ))
        .n_atoms(),
        2
    );
}

/// "line L, byte B:" of the first `needle` in `text` (`nth` 0) or a later one.
fn place(text: &str, needle: &str, nth: usize) -> String {
    let byte = text.match_indices(needle).nth(nth).expect(needle).0;
    let line = text[..byte].matches('\n').count() + 1;
    format!("line {line}, byte {byte}:")
}

#[test]
fn a_space_group_without_operations_is_an_error_naming_it() {
    let text = "data_x\n_cell_length_a 5\n_cell_length_b 6\n_cell_length_c 7\n\
                _cell_angle_beta 100\n_symmetry_space_group_name_H-M 'P 1 21/c 1'\nloop_\n\
                _atom_site_label\n_atom_site_fract_x\n_atom_site_fract_y\n_atom_site_fract_z\n\
                Fe1 0.1 0.2 0.3\n";
    let e = err(text);
    let at = place(text, "'P 1 21/c 1'", 0);
    assert!(
        e.starts_with(&format!("x.cif: frame 0, {at} expected a list of symmetry")),
        "{e}"
    );
    assert!(e.contains("\"P 1 21/c 1\" and no operations"), "{e}");
    let text = text.replace(
        "_symmetry_space_group_name_H-M 'P 1 21/c 1'",
        "_space_group_IT_number 14",
    );
    let e = err(&text);
    assert!(
        e.contains(&place(&text, "14\n", 0)) && e.contains("space group number \"14\""),
        "{e}"
    );
}

#[test]
fn operations_may_follow_the_atoms_in_any_dialect() {
    // DDLm names, Cartesian sites, operations after the atoms: P 2 along b.
    let text = "data_ddlm\n_cell.length_a 10\n_cell.length_b 10\n_cell.length_c 10\nloop_\n\
                _atom_site.label\n_atom_site.type_symbol\n_atom_site.Cartn_x\n\
                _atom_site.Cartn_y\n_atom_site.Cartn_z\nO1 O2- 1 2 3\nloop_\n\
                _space_group_symop.id\n_space_group_symop.operation_xyz\n1 x,y,z\n2 -x,y,-z\n";
    let f = one(text);
    assert_eq!(f.positions, [[1.0, 2.0, 3.0], [9.0, 2.0, 7.0]]);
    assert_eq!(f.elements[1].symbol(), "O");
    assert_eq!(f.types[1], "O2-");
    // `_space_group_symop_operation_xyz` wins over `_symmetry_equiv_pos_as_xyz`.
    let both = text.replace(
        "2 -x,y,-z\n",
        "2 -x,y,-z\nloop_\n_symmetry_equiv_pos_as_xyz\nx,y,z\n-x,-y,-z\n",
    );
    assert_eq!(one(&both).positions, [[1.0, 2.0, 3.0], [9.0, 2.0, 7.0]]);
}

#[test]
fn each_block_with_sites_is_a_frame() {
    let site = "loop_\n_atom_site_label\n_atom_site_fract_x\n_atom_site_fract_y\n\
                _atom_site_fract_z\n";
    let text = format!(
        "#\\#CIF_1.1\ndata_global\n_publ_contact_author_name 'A. Author'\n\
         data_I\n_cell_length_a 3\n_cell_length_b 3\n_cell_length_c 3\n{site}Cu1 0 0 0\n\
         data_II\n_cell_length_a 4\n_cell_length_b 4\n_cell_length_c 4\n{site}Ag1 0 0 0\n\
         Ag2 0.5 0.5 0.5\ndata_trailing_notes\n_journal_year 2024\n"
    );
    let frames = read_str(&text).unwrap();
    assert_eq!(frames.len(), 2);
    assert_eq!(frames[0].comment, "I");
    assert_eq!(frames[1].n_atoms(), 2);
    assert_eq!(frames[1].positions[1], [2.0, 2.0, 2.0]);
    assert_eq!(frames[1].elements[0].symbol(), "Ag");
    // Random access and the count agree with streaming.
    let mut t =
        Trajectory::from_reader(Cursor::new(text.into_bytes()), Format::CrystalCif, "m.cif")
            .unwrap();
    assert_eq!(t.n_frames().unwrap(), 2);
    let mut f = Frame::new();
    t.read_frame(1, &mut f).unwrap();
    assert_eq!(f, frames[1]);
    t.read_frame(0, &mut f).unwrap();
    assert_eq!(f, frames[0]);
}

#[test]
fn damage_is_an_error_naming_the_place() {
    let check = |text: &str, needle: &str, nth: usize, what: &str| {
        let e = err(text);
        let at = place(text, needle, nth);
        assert!(
            e.starts_with(&format!("x.cif: frame 0, {at} ")),
            "{e}\nnot at {at}"
        );
        assert!(e.contains(what), "{e}\ndoes not say {what:?}");
    };
    let good = p1bar("Fe1 0.1 0.2 0.3\n");
    // A bad operation token: its line and byte, the token itself.
    let bad = good.replace("-x,-y,-z", "-x,-q,-z");
    check(
        &bad,
        "-x,-q,-z",
        0,
        "a symmetry operation such as x,y,z or -y,x-y,z+1/3",
    );
    assert!(err(&bad).ends_with("found '-x,-q,-z'"));
    // A singular matrix is no operation.
    check(
        &good.replace("-x,-y,-z", "x,x,z"),
        "x,x,z",
        0,
        "found 'x,x,z'",
    );
    // A coordinate that is not a number.
    check(
        &p1bar("Fe1 0.1 zero 0.3\n"),
        "zero",
        0,
        "_atom_site_fract_y, found 'zero'",
    );
    // A loop row with too few values, before the next keyword ...
    let short = p1bar("Fe1 0.1 0.2 0.3\nO1 0.5 0.5\nloop_\n_x\n1\n");
    check(&short, "O1", 0, "3 of 4 values in this row");
    // ... or at the end of the data: a cut.
    let cut = p1bar("Fe1 0.1 0.2 0.3\nO1 0.5 0.5\n");
    check(&cut, "O1", 0, "1 more values of the loop row");
    // Unterminated quote and text field.
    check(&good.replace("'P -1'", "'P -1"), "'P -1", 0, "a closing '");
    let open = good.clone() + "_publ_section_title\n;\nA title\n";
    check(&open, ";", 0, "close the text field");
    // No atom sites; sites without coordinates; fractional sites without a cell.
    let text = "data_x\n_cell_length_a 5\n";
    let e = err(text);
    assert!(
        e.contains("line 3, byte 24:") && e.contains("a data block with atom sites"),
        "{e}"
    );
    let text = "data_x\n_cell_length_a 5\nloop_\n_atom_site_label\n_atom_site_fract_x\nC 0\n";
    check(text, "loop_", 0, "_atom_site_fract_x, _y and _z");
    let text = "data_x\nloop_\n_atom_site_label\n_atom_site_fract_x\n_atom_site_fract_y\n\
                _atom_site_fract_z\nC 0 0 0\n";
    check(text, "loop_", 0, "the atom sites are fractional");
    // A cell that is not a cell, a cell value that is not a number.
    let bent = good.replace("_cell_angle_gamma 110", "_cell_angle_gamma 190");
    check(&bent, "5\n", 0, "a _cell with lengths > 0");
    check(
        &good.replace("_cell_length_b 6", "_cell_length_b six"),
        "six",
        0,
        "found 'six'",
    );
    // More operations than any space group has: the 193rd.
    let many = good.replace("x,y,z\n", &"x,y,z\n".repeat(193));
    check(&many, "x,y,z", 192, "at most 192 symmetry operations");
    // A value without a tag, a loop without values.
    let text = "data_x\n_cell_length_a 5 6\n";
    check(text, "6", 0, "a tag or loop_ (a value without a tag)");
    let text = good.clone() + "loop_\n_a\n_b\ndata_y\n";
    check(&text, "loop_", 2, "values after the loop's tags");
    // Labels longer than a Label holds.
    check(
        &p1bar("Fe_a_very_long_label 0 0 0\n"),
        "Fe_a",
        0,
        "a site label of at most 15 bytes",
    );
}

#[test]
fn one_site_as_items() {
    let text = "data_cu\n_cell_length_a 3.615\n_cell_length_b 3.615\n_cell_length_c 3.615\n\
                loop_\n_symmetry_equiv_pos_as_xyz\nx,y,z\nx,y+1/2,z+1/2\nx+1/2,y,z+1/2\n\
                x+1/2,y+1/2,z\n_atom_site_label Cu1\n_atom_site_fract_x 0\n\
                _atom_site_fract_y 0\n_atom_site_fract_z 0\n_atom_site_occupancy 0.5\n";
    let f = one(text);
    assert_eq!(f.n_atoms(), 4);
    assert_eq!(f.property("occupancy"), Some(&[0.5f32; 4][..]));
    assert_eq!(f.names[3], "Cu1");
}

/// A crystallographic CIF given as a topology (`--topology cod.cif`) is read as one, not as
/// PDBx/mmCIF: its expanded cell's elements, in the order the reference program lists them.
#[test]
fn a_crystal_cif_is_a_topology_too() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/crystal");
    let reference: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(format!("{dir}/reference.json")).unwrap())
            .unwrap();
    for name in ["cod_1010930.cif", "cod_9004112.cif"] {
        let t = texmap_md_io::Topology::open(format!("{dir}/{name}"))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let want = &reference[name][0];
        let elements: Vec<&str> = want["elements"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e.as_str().unwrap())
            .collect();
        assert_eq!(
            t.n_atoms(),
            want["n_atoms"].as_u64().unwrap() as usize,
            "{name}"
        );
        let ours: Vec<&str> = t.elements.iter().map(|e| e.symbol()).collect();
        let (mut a, mut b) = (ours.clone(), elements.clone());
        a.sort_unstable();
        b.sort_unstable();
        assert_eq!(a, b, "{name}: the same elements");
        assert!(t.bonds.is_empty());
    }
}

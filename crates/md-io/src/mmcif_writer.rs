//! PDBx/mmCIF written ([`MmcifWriter`]): the format of the reader in src/mmcif.rs, which reads
//! every file written here back to the same frames (within what is written, below).
//!
//! # What is written
//! One data block, `data_<name>`, `<name>` being the output file's stem with every character
//! other than a letter, digit, `-`, `.` or `_` made `_` (at most 75 characters, CIF 1.1's limit
//! for a block name; `texmap` when nothing is left), holding:
//! - `_entry.id` (the block name);
//! - when the first frame has a cell: `_cell.length_a/b/c`, `_cell.angle_alpha/beta/gamma` and
//!   `_symmetry.space_group_name_H-M 'P 1'` (a frame lists every atom and knows no symmetry,
//!   so a crystal's own space group is not kept; the PDB writer's CRYST1 says P 1 too). A PDBx
//!   file holds one cell for all its models: later frames' cells are not written, and readers
//!   (ours, gemmi) give every model the first frame's. A trajectory whose box changes is
//!   written as DCD, XTC or extended XYZ;
//! - one `_atom_site` loop holding every frame as a model, 1, 2, 3, ... (`pdbx_PDB_model_num`),
//!   row after row. Each frame is written as it comes: nothing is kept from one frame to the
//!   next but its atom count. Every model must hold as many atoms as the first (PDBx allows
//!   models to differ; our reader, like MDAnalysis's, reads a trajectory of fixed atoms, so a
//!   frame of another count is an [`crate::Error::InvalidFrame`]).
//!
//! The `_atom_site` items, per atom:
//!
//! | item | value |
//! |---|---|
//! | `group_PDB` | `ATOM` for a residue that `protein` or `nucleic` selects ([`crate::select::PROTEIN_RESIDUES`], [`crate::select::NUCLEIC_RESIDUES`]), `HETATM` for any other (water, ions, ligands), as the wwPDB splits them |
//! | `id` | the frame's id, else the atom's number from 1 |
//! | `type_symbol` | the element in upper case (the wwPDB's spelling); for an atom without one, the element the names give ([`crate::elements::guess_element`], as the PDB writer does) |
//! | `label_atom_id`, `auth_atom_id` | the atom name |
//! | `label_alt_id` | `.`: one conformation per atom |
//! | `label_comp_id`, `auth_comp_id` | the residue name |
//! | `label_asym_id`, `auth_asym_id` | the chain |
//! | `label_entity_id` | `?`: the entities are not known |
//! | `label_seq_id` | `.` on HETATM rows (no polymer sequence: the dictionary's "inapplicable"), `?` on ATOM rows (the index into the entity's sequence is not known) |
//! | `pdbx_PDB_ins_code` | `?` |
//! | `Cartn_x`, `Cartn_y`, `Cartn_z` | the position, Å |
//! | `occupancy`, `B_iso_or_equiv` | the `occupancy` and `bfactor` properties, as in PDB's columns 55-66 |
//! | `auth_seq_id` | the residue number |
//! | `pdbx_PDB_model_num` | the frame's number from 1 |
//!
//! A value the frame lacks (no names, residues, chains, occupancy or B-factor), and an empty
//! label, is `?` (unknown). Readers fill such values with their own defaults: ours and gemmi
//! read a missing occupancy as 1, ours a missing B-factor as 0 and gemmi as 20.
//!
//! Numbers are written in Rust's shortest round-trip form (positions, occupancies and B-factors
//! as f32, the cell as f64), the rule of every text writer here (src/writer.rs), not the
//! wwPDB's 3 decimals: reading a file back gives the same bits, so converting a trajectory to
//! PDBx loses no precision, and ids, residue numbers and chain names have no width limit (no
//! hybrid-36 as in PDB past 99,999 atoms or 9,999 residues, no one-letter chains).
//!
//! Not written: bonds (no `_struct_conn` or `_chem_comp_bond`), segments (PDBx has no segment
//! item; our reader keeps chains only), atom types, velocities, radii, colours, properties
//! other than `occupancy` and `bfactor`, time, step and title, the cell's origin and open
//! edges, entities, sequences and secondary structure.
//!
//! # Quoting (CIF 1.1)
//! A value is written bare unless it holds a blank or a quote, starts with `_ # $ ' " [ ] ;`,
//! is a reserved word (`data_…`, `save_…`, `loop_`, `global_`, `stop_`, in any case) or is `.`
//! or `?` as a real value. Such a value is quoted: in double quotes when it holds an apostrophe
//! (`"O5'"`, as the wwPDB writes it), else in single quotes. A CIF quote closes only before a
//! blank, so a value may hold its own quote character anywhere but directly before a blank; a
//! value holding both `' ` and `" ` is a text field (a line `;value`, then a line starting with
//! `;`). A label with a control character other than a tab (a line break) cannot be a CIF
//! value: the frame is refused ([`crate::Error::InvalidFrame`]), naming the atom.
//!
//! # References
//! - S. R. Hall, F. H. Allen, I. D. Brown, "The Crystallographic Information File (CIF)", Acta
//!   Cryst. A47 (1991) 655; CIF 1.1 syntax specification (IUCr, 2003), paragraphs 2-22.
//! - wwPDB, PDBx/mmCIF dictionary (`mmcif_pdbx_v50.dic`), categories ATOM_SITE, CELL, SYMMETRY.

use std::io::{self, Write};

use crate::cif::{Kind, classify};
use crate::frame::{Frame, Label};
use crate::pdb::written_element;
use crate::select::{NUCLEIC_RESIDUES, PROTEIN_RESIDUES};

/// The `_atom_site` items, in the order of each row.
const ATOM_SITE: [&str; 20] = [
    "group_PDB",
    "id",
    "type_symbol",
    "label_atom_id",
    "label_alt_id",
    "label_comp_id",
    "label_asym_id",
    "label_entity_id",
    "label_seq_id",
    "pdbx_PDB_ins_code",
    "Cartn_x",
    "Cartn_y",
    "Cartn_z",
    "occupancy",
    "B_iso_or_equiv",
    "auth_seq_id",
    "auth_comp_id",
    "auth_asym_id",
    "auth_atom_id",
    "pdbx_PDB_model_num",
];

/// How a value is written so that a CIF 1.1 reader gives back its exact bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Form {
    Bare,
    Single,
    Double,
    /// `;value` on a line of its own, then a line starting with `;`.
    TextField,
}

/// The form of a non-empty value without control characters other than tabs (see the
/// module doc).
fn form(v: &[u8]) -> Form {
    let blank = |b: u8| matches!(b, b' ' | b'\t');
    let special_start = matches!(
        v.first(),
        Some(b'_' | b'#' | b'$' | b'\'' | b'"' | b'[' | b']' | b';')
    );
    let bare = !special_start
        && !v.iter().any(|&b| blank(b) || b == b'\'' || b == b'"')
        && !matches!(v, b"." | b"?")
        && classify(v) == Kind::Bare;
    if bare {
        return Form::Bare;
    }
    // A quote character followed by a blank would close a value quoted with it.
    let closes = |q: u8| v.windows(2).any(|w| w[0] == q && blank(w[1]));
    let (single, double) = (!closes(b'\''), !closes(b'"'));
    if v.contains(&b'\'') && double {
        Form::Double
    } else if single {
        Form::Single
    } else if double {
        Form::Double
    } else {
        Form::TextField
    }
}

/// Writes `v` as [`form`] says; an empty value is `?`.
fn write_value(w: &mut impl Write, v: &[u8]) -> io::Result<()> {
    if v.is_empty() {
        return w.write_all(b"?");
    }
    let (open, close): (&[u8], &[u8]) = match form(v) {
        Form::Bare => (b"", b""),
        Form::Single => (b"'", b"'"),
        Form::Double => (b"\"", b"\""),
        Form::TextField => (b"\n;", b"\n;"),
    };
    w.write_all(open)?;
    w.write_all(v)?;
    w.write_all(close)
}

/// Writes a label of the frame, `?` when the frame has no such column.
fn write_label(w: &mut impl Write, label: Option<&Label>) -> io::Result<()> {
    write_value(w, label.map_or(&b""[..], |l| l.as_bytes()))
}

/// The `data_` block name for a file called `name` (see the module doc).
fn block_name(name: &str) -> String {
    let stem = std::path::Path::new(name)
        .file_stem()
        .map(|s| s.to_string_lossy())
        .unwrap_or_default();
    let clean: String = stem
        .chars()
        .map(|c| match c {
            'a'..='z' | 'A'..='Z' | '0'..='9' | '-' | '.' | '_' => c,
            _ => '_',
        })
        .take(75)
        .collect();
    if clean.is_empty() {
        "texmap".into()
    } else {
        clean
    }
}

/// True for a residue `protein` or `nucleic` selects: an `ATOM` row.
fn is_polymer(res: &str) -> bool {
    PROTEIN_RESIDUES.contains(&res) || NUCLEIC_RESIDUES.contains(&res)
}

/// Writes frames as PDBx/mmCIF models (see the module doc).
pub(crate) struct MmcifWriter<W> {
    pub out: W,
    /// The data block's name.
    block: String,
    /// Models written, and the atom count of the first.
    models: usize,
    atoms: usize,
    /// The first frame's cell, the only one written.
    pub(crate) first_cell: Option<crate::UnitCell>,
}

impl<W: Write> MmcifWriter<W> {
    /// A writer of a file called `name` (its stem names the data block).
    pub fn new(out: W, name: &str) -> MmcifWriter<W> {
        MmcifWriter {
            out,
            block: block_name(name),
            models: 0,
            first_cell: None,
            atoms: 0,
        }
    }

    /// Why `frame` cannot be the next model, if it cannot.
    pub fn check(&self, frame: &Frame) -> Result<(), String> {
        if self.models > 0 && frame.n_atoms() != self.atoms {
            return Err(format!(
                "it has {} atoms and the first model {}: the models of a PDBx/mmCIF file \
                 written here hold the same atoms (write .xyz or .lammpstrj, whose frames may \
                 differ)",
                frame.n_atoms(),
                self.atoms
            ));
        }
        let columns = [
            ("name", &frame.names),
            ("residue name", &frame.res_names),
            ("chain", &frame.chains),
        ];
        for (what, labels) in columns {
            let bad = |l: &Label| l.chars().any(|c| c.is_control() && c != '\t');
            if let Some(i) = labels.iter().position(bad) {
                return Err(format!(
                    "atom {i}'s {what} {:?} holds a control character, which no CIF value can",
                    labels[i].as_str()
                ));
            }
        }
        for (name, item) in [("occupancy", "occupancy"), ("bfactor", "B_iso_or_equiv")] {
            let values = frame.property(name).unwrap_or_default();
            if let Some(i) = values.iter().position(|v| !v.is_finite()) {
                return Err(format!(
                    "atom {i}'s {name} is {}, not a number _atom_site.{item} can hold",
                    values[i]
                ));
            }
        }
        Ok(())
    }

    /// The block header, the cell of `frame` (the first) and the `_atom_site` loop's tags.
    fn header(&mut self, frame: Option<&Frame>) -> io::Result<()> {
        let w = &mut self.out;
        let block = self.block.as_bytes();
        writeln!(w, "data_{}\n#", self.block)?;
        w.write_all(b"_entry.id ")?;
        write_value(w, block)?;
        w.write_all(b"\n#\n")?;
        if let Some(cell) = frame.and_then(|f| f.cell.as_ref()) {
            let [a, b, c] = cell.lengths();
            let [alpha, beta, gamma] = cell.angles();
            w.write_all(b"_cell.entry_id ")?;
            write_value(w, block)?;
            writeln!(
                w,
                "\n_cell.length_a {a}\n_cell.length_b {b}\n_cell.length_c {c}"
            )?;
            writeln!(
                w,
                "_cell.angle_alpha {alpha}\n_cell.angle_beta {beta}\n_cell.angle_gamma {gamma}\n#"
            )?;
            w.write_all(b"_symmetry.entry_id ")?;
            write_value(w, block)?;
            w.write_all(b"\n_symmetry.space_group_name_H-M 'P 1'\n")?;
            w.write_all(b"_symmetry.Int_Tables_number 1\n#\n")?;
        }
        w.write_all(b"loop_\n")?;
        for item in ATOM_SITE {
            writeln!(w, "_atom_site.{item}")?;
        }
        Ok(())
    }

    pub fn write_frame(&mut self, frame: &Frame) -> io::Result<()> {
        if self.models == 0 {
            self.header(Some(frame))?;
            self.atoms = frame.n_atoms();
            self.first_cell = frame.cell;
        }
        self.models += 1;
        let model = self.models;
        let occupancy = frame.property("occupancy");
        let bfactor = frame.property("bfactor");
        let w = &mut self.out;
        for (i, p) in frame.positions.iter().enumerate() {
            let name = frame.names.get(i);
            let res = frame.res_names.get(i);
            let chain = frame.chains.get(i);
            let polymer = res.is_some_and(|r| is_polymer(r));
            let id = frame.ids.get(i).copied().unwrap_or(i as i64 + 1);
            let group = if polymer { "ATOM" } else { "HETATM" };
            write!(w, "{group} {id} ")?;
            let element = written_element(frame, i);
            if element.is_unknown() {
                w.write_all(b"?")?;
            } else {
                w.write_all(&element.symbol().as_bytes().to_ascii_uppercase())?;
            }
            w.write_all(b" ")?;
            write_label(w, name)?;
            w.write_all(b" . ")?;
            write_label(w, res)?;
            w.write_all(b" ")?;
            write_label(w, chain)?;
            // Entity, label_seq_id (see the module doc's table) and insertion code.
            w.write_all(if polymer { b" ? ? ? " } else { b" ? . ? " })?;
            write!(w, "{} {} {}", p[0], p[1], p[2])?;
            for values in [occupancy, bfactor] {
                match values {
                    Some(v) => write!(w, " {}", v[i])?,
                    None => w.write_all(b" ?")?,
                }
            }
            match frame.res_ids.get(i) {
                Some(seq) => write!(w, " {seq} ")?,
                None => w.write_all(b" ? ")?,
            }
            write_label(w, res)?;
            w.write_all(b" ")?;
            write_label(w, chain)?;
            w.write_all(b" ")?;
            write_label(w, name)?;
            writeln!(w, " {model}")?;
        }
        Ok(())
    }

    /// Ends the file; a file without frames still gets its header and an `_atom_site` loop
    /// without rows (read as no frame).
    pub fn finish(&mut self) -> io::Result<()> {
        if self.models == 0 {
            self.header(None)?;
        }
        self.out.write_all(b"#\n")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_quoted_as_cif_1_1_asks() {
        let cases: [(&[u8], Form); 17] = [
            (b"CA", Form::Bare),
            (b"HOH", Form::Bare),
            (b"C1*", Form::Bare),
            (b"a.b", Form::Bare),
            (b"O5'", Form::Double),
            (b"'N", Form::Double),
            (b"\"N", Form::Single),
            (b"_X", Form::Single),
            (b"#1", Form::Single),
            (b"$1", Form::Single),
            (b";1", Form::Single),
            (b"[1]", Form::Single),
            (b".", Form::Single),
            (b"?", Form::Single),
            (b"DATA_x", Form::Single),
            (b"a' b", Form::Double),
            (b"a' b\" c", Form::TextField),
        ];
        for (v, f) in cases {
            assert_eq!(form(v), f, "{}", String::from_utf8_lossy(v));
        }
        for word in ["loop_", "Global_", "stop_", "save_frame", "C A", "C\tA"] {
            assert_eq!(form(word.as_bytes()), Form::Single, "{word}");
        }
    }

    #[test]
    fn block_names_are_the_stem_made_safe() {
        assert_eq!(block_name("/tmp/run 1.cif"), "run_1");
        assert_eq!(block_name("out"), "out");
        assert_eq!(block_name("dir/.cif"), ".cif");
        assert_eq!(block_name(""), "texmap");
        assert_eq!(block_name(&"x".repeat(100)).len(), 75);
    }
}

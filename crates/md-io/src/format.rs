//! The closed set of file formats, told from a file's extension or its first bytes.

use std::path::Path;

/// A trajectory file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Format {
    /// XYZ, plain or extended (ASE/OVITO key=value comment line): `.xyz`, `.extxyz`.
    Xyz,
    /// Protein Data Bank, multi-MODEL: `.pdb`, `.ent`.
    Pdb,
    /// GROMACS .gro: `.gro`.
    Gro,
    /// LAMMPS text dump: `.lammpstrj`, `.lammpsdump`, `.dump`.
    LammpsDump,
    /// LAMMPS binary dump (`dump atom` / `dump custom` to a `.bin` file), read as the text dump
    /// of the same data is. `.bin` names many formats, so the content tells: the magic header
    /// (`DUMPCUSTOM`, `DUMPATOM`) or, from an older LAMMPS, a plausible first frame header; by
    /// name: `lammps-bin`.
    LammpsBin,
    /// CHARMM/NAMD DCD: `.dcd`.
    Dcd,
    /// GROMACS compressed XTC: `.xtc`.
    Xtc,
    /// GROMACS TRR: `.trr`.
    Trr,
    /// AMBER NetCDF trajectory or restart (NetCDF-3, classic or 64-bit offset): `.nc`, `.ncdf`,
    /// `.ncrst`, and a restart named `.rst7` or `.restrt` whose first bytes are NetCDF's.
    Netcdf,
    /// HOOMD-blue GSD trajectory (GSD file format 1.0 and 2.x, `hoomd` schema): `.gsd`.
    Gsd,
    /// PDBx/mmCIF, the Protein Data Bank's archive format; models are frames: `.cif`, `.mmcif`.
    Mmcif,
    /// BinaryCIF, PDBx/mmCIF's binary encoding (the RCSB PDB's and PDBe's `.bcif`, Mol*'s),
    /// read as PDBx/mmCIF is: `.bcif`, or a MessagePack map whose first key is `encoder`,
    /// `version` or `dataBlocks`.
    Bcif,
    /// MDL molfile / SD file (V2000 and V3000), records are frames, with bonds: `.sdf`,
    /// `.sd`, `.mol`.
    Sdf,
    /// Tripos MOL2, molecules are frames, with bonds and partial charges: `.mol2`.
    Mol2,
    /// VASP POSCAR / CONTCAR (one structure) and XDATCAR (MD trajectory): files named
    /// `POSCAR*`, `CONTCAR*`, `XDATCAR*`, or `.vasp`, `.poscar`.
    Vasp,
    /// Crystallographic CIF (COD, ICSD, Materials Project: DDL1 `_atom_site_fract_x`), the
    /// asymmetric unit expanded by the file's symmetry operations; data blocks are frames. A
    /// `.cif` file is this or PDBx/mmCIF by its tags ([`Format::cif_kind`]); by name:
    /// `cif-crystal`.
    CrystalCif,
    /// LAMMPS data file (`read_data` / `write_data`), one frame with its bonds: `.data`, `.lmp`,
    /// files named `data.*` (`data.peptide`, as in the LAMMPS examples), or by its header (an
    /// `N atoms` line after the title: `system.lammps`); by name: `lammps-data`.
    LammpsData,
    /// Gaussian cube file, one frame (the molecule; its grid values are checked, not kept: see
    /// [`crate::volume::read_volumes`]): `.cube`, `.cub`.
    Cube,
    /// AMBER ASCII trajectory (`10F8.3`, optional box lines), read with the topology's atom
    /// count ([`crate::ReadOptions::atoms`]): `.mdcrd`, `.trj`, a file named `mdcrd`, and a
    /// `.crd` whose second line is coordinates; by name: `mdcrd`.
    AmberTrj,
    /// AMBER ASCII restart / input coordinates (`6F12.7`, optional velocities and box), one
    /// frame: `.rst7`, `.inpcrd`, `.restrt`, files named `inpcrd` or `restrt`, and a `.crd`
    /// whose second line is the atom count; by name: `rst7`.
    AmberRestart,
    /// CHARMM coordinate file (card format, standard or `EXT`), one frame per title block
    /// (concatenated files are frames), with segment ids and the WMAIN weighting: `.cor`, and
    /// `.crd` when its first non-blank line is a `*` title (AMBER also writes `.crd`: see
    /// [`crate::Trajectory::open`]); by name: `charmm-crd`.
    CharmmCrd,
    /// PQR (PDB2PQR, APBS, MDAnalysis, ParmEd): whitespace-separated PDB-like atom records with
    /// the partial charge (e) and radius (Å) as the `charge` and `radius` properties;
    /// MODEL/ENDMDL models are frames: `.pqr`.
    Pqr,
    /// AutoDock PDBQT (Vina's docked poses, one MODEL each; Meeko's and Open Babel's receptors
    /// and ligands): PDB records with partial charges and AutoDock atom types: `.pdbqt`.
    Pdbqt,
    /// NAMD binary coordinates (a count, then x y z as 8-byte floats; either byte order), one
    /// frame: `.coor`; by name: `namdbin`.
    NamdBin,
    /// Tinker Cartesian coordinates and archives (index, name, x y z, type, bonded atoms; an
    /// optional box line per frame), with their bonds: `.txyz`, `.arc`, and a `.xyz` in Tinker's
    /// layout ([`Format::tinker_xyz`]); by name: `txyz`.
    Tinker,
    /// DL_POLY `CONFIG` / `REVCON` (one frame) and `HISTORY` (DL_POLY 4 and Classic), by
    /// DL_POLY's file names (any suffix); by name: `dlpoly`.
    DlPoly,
    /// XCrySDen XSF and animated AXSF (Quantum ESPRESSO pp.x, ASE, pymatgen, XCrySDen): each
    /// structure a frame, with its cell (CRYSTAL, SLAB, POLYMER) and forces as `fx fy fz`
    /// (eV/Å); its data grids are checked, not kept (see [`crate::volume::read_volumes`]):
    /// `.xsf`, `.axsf`.
    Xsf,
    /// GROMACS run input (`.tpr`, from `grompp`): its starting frame (positions, velocities,
    /// box) with the topology it compiles (names, types, residues, molecule types as segments,
    /// masses, charges and the force field's chemical bonds): see [`crate::read_tpr`]; by
    /// name: `tpr`.
    Tpr,
    /// Quantum ESPRESSO pw.x output: every ionic step of an scf, relax, vc-relax, md or vc-md
    /// run that has results a frame (as ASE counts them), with its cell, the species labels,
    /// forces (`fx fy fz`, eV/Å), energy and stress (in the comment, eV and eV/Å³), step and
    /// time: `.pwo`, or an `.out` whose first lines hold pw.x's `Program PWSCF` banner; by
    /// name: `espresso-out`.
    EspressoOut,
    /// Quantum ESPRESSO pw.x input: one frame from `ATOMIC_SPECIES`, `ATOMIC_POSITIONS` and the
    /// cell of `ibrav` 1, 2, 3, 4, 6, 8 with `celldm` or `A, B, C`, or of `CELL_PARAMETERS`
    /// (ibrav 0): `.pwi`, or an `.in` whose first line that is not a comment opens the
    /// `&CONTROL` or `&SYSTEM` namelist; by name: `espresso-in`.
    EspressoIn,
    /// VASP's `vasprun.xml`: every ionic step (`<calculation>`) a frame, as ASE counts them,
    /// with its cell, the elements of `<atominfo>`, forces (`fx fy fz`, eV/Å), energy, free
    /// energy and stress (in the comment, eV and eV/Å³, as ASE reports them), step and, in
    /// molecular dynamics, time: files named `vasprun*.xml`, or a `.xml` whose first element is
    /// `<modeling>`; by name: `vasp-xml`.
    VaspXml,
    /// VASP's `OUTCAR`: every ionic step (each `POSITION … TOTAL-FORCE` table with its energy)
    /// a frame, as ASE counts them, with its cell, the POTCARs' elements, forces (`fx fy fz`,
    /// eV/Å), energy, free energy and stress (in the comment), step and time: files named
    /// `OUTCAR*`, or a file whose first line is VASP's banner (`vasp.6.4.1 …`); by name:
    /// `vasp-out`.
    Outcar,
    /// ASE trajectories (ASE's ULM binary format: `ase.io.Trajectory`, its MD drivers and
    /// optimisers): numbers, positions, cell and pbc, momenta as velocities, the calculator's
    /// forces and energies: `.traj`; by name: `ase-traj`.
    AseTraj,
}

impl Format {
    /// Every format, in declaration order.
    pub const ALL: [Format; 33] = [
        Format::Xyz,
        Format::Pdb,
        Format::Gro,
        Format::LammpsDump,
        Format::Dcd,
        Format::Xtc,
        Format::Trr,
        Format::Netcdf,
        Format::Gsd,
        Format::Mmcif,
        Format::Sdf,
        Format::Mol2,
        Format::Vasp,
        Format::CrystalCif,
        Format::LammpsData,
        Format::Cube,
        Format::AmberTrj,
        Format::AmberRestart,
        Format::CharmmCrd,
        Format::Pqr,
        Format::Pdbqt,
        Format::NamdBin,
        Format::Tinker,
        Format::DlPoly,
        Format::Xsf,
        Format::Tpr,
        Format::AseTraj,
        Format::Bcif,
        Format::LammpsBin,
        Format::EspressoOut,
        Format::EspressoIn,
        Format::VaspXml,
        Format::Outcar,
    ];

    /// The format a file extension (case-insensitive, e.g. "xyz", "lammpstrj") or a format's
    /// [`Format::name`] names.
    pub fn from_extension(ext: &str) -> Option<Format> {
        let e = ext.to_ascii_lowercase();
        Some(match e.as_str() {
            "xyz" | "extxyz" => Format::Xyz,
            "pdb" | "ent" => Format::Pdb,
            "gro" => Format::Gro,
            "lammpstrj" | "lammpsdump" | "dump" | "lammps-dump" => Format::LammpsDump,
            "lammps-bin" => Format::LammpsBin,
            "dcd" => Format::Dcd,
            "xtc" => Format::Xtc,
            "trr" => Format::Trr,
            "nc" | "ncdf" | "ncrst" => Format::Netcdf,
            "gsd" => Format::Gsd,
            "cif" | "mmcif" => Format::Mmcif,
            "bcif" => Format::Bcif,
            "sdf" | "sd" | "mol" => Format::Sdf,
            "mol2" => Format::Mol2,
            "vasp" | "poscar" | "contcar" | "xdatcar" => Format::Vasp,
            "cif-crystal" => Format::CrystalCif,
            "data" | "lmp" | "lammps-data" => Format::LammpsData,
            "cube" | "cub" => Format::Cube,
            "mdcrd" | "trj" => Format::AmberTrj,
            "rst7" | "inpcrd" | "restrt" => Format::AmberRestart,
            "crd" | "cor" | "charmm-crd" => Format::CharmmCrd,
            "pqr" => Format::Pqr,
            "pdbqt" => Format::Pdbqt,
            "coor" | "namdbin" => Format::NamdBin,
            "txyz" | "arc" => Format::Tinker,
            "dlpoly" => Format::DlPoly,
            "xsf" | "axsf" => Format::Xsf,
            "tpr" => Format::Tpr,
            "traj" | "ase-traj" => Format::AseTraj,
            "pwo" | "espresso-out" => Format::EspressoOut,
            "pwi" | "espresso-in" => Format::EspressoIn,
            "vasp-xml" => Format::VaspXml,
            "vasp-out" | "outcar" => Format::Outcar,
            _ => return None,
        })
    }

    /// The format a path's extension names, else VASP's run outputs by their names (`OUTCAR`
    /// and any suffix: `OUTCAR.relax`; `vasprun*.xml`), else VASP for the names VASP gives its
    /// files (`POSCAR`, `CONTCAR`, `XDATCAR` and any suffix: `CONTCAR.2`; the volumetric `CHGCAR`,
    /// `CHG`, `PARCHG`, `LOCPOT`, `ELFCAR`, `AECCAR0/1/2` as
    /// [`crate::volume::VaspQuantity::from_file_name`] tells them: `run1.CHGCAR`,
    /// `PARCHG.0012.ALLK`, read as one frame, the structure), else a LAMMPS data file for
    /// a name starting `data.` (`data.peptide`); a final `.gz` is looked
    /// through (`run.xyz.gz` is XYZ, read decompressed by [`crate::Trajectory::open`]).
    pub fn from_path(path: &Path) -> Option<Format> {
        let inner = crate::gz::inner_path(path);
        let by_extension = inner
            .extension()
            .and_then(|e| e.to_str())
            .and_then(Format::from_extension);
        if by_extension.is_some() {
            return by_extension;
        }
        // VASP's fixed file names, with any suffix (`POSCAR_relaxed`, `CONTCAR.2`).
        let name = inner.file_name()?.to_str()?.as_bytes();
        let starts = |p: &[u8]| name.len() >= p.len() && name[..p.len()].eq_ignore_ascii_case(p);
        if starts(b"OUTCAR") {
            return Some(Format::Outcar);
        }
        let xml = name.len() >= 4 && name[name.len() - 4..].eq_ignore_ascii_case(b".xml");
        if starts(b"vasprun") && xml {
            return Some(Format::VaspXml);
        }
        let vasp = [&b"POSCAR"[..], b"CONTCAR", b"XDATCAR"]
            .iter()
            .any(|v| name.len() >= v.len() && name[..v.len()].eq_ignore_ascii_case(v));
        let volumetric = std::str::from_utf8(name)
            .ok()
            .and_then(crate::volume::VaspQuantity::from_file_name)
            .is_some();
        if vasp || volumetric {
            return Some(Format::Vasp);
        }
        // DL_POLY's file names, with any suffix (`HISTORY_run2`, `REVCON.1`).
        let dlpoly = [&b"CONFIG"[..], b"REVCON", b"CFGMIN", b"HISTORY"]
            .iter()
            .any(|v| name.starts_with(v));
        if dlpoly {
            return Some(Format::DlPoly);
        }
        // AMBER's default file names.
        if name.eq_ignore_ascii_case(b"mdcrd") {
            return Some(Format::AmberTrj);
        }
        if name.eq_ignore_ascii_case(b"inpcrd") || name.eq_ignore_ascii_case(b"restrt") {
            return Some(Format::AmberRestart);
        }
        // The LAMMPS examples' names: `data.peptide`, `data.lj`.
        (name.len() > 5 && name[..5].eq_ignore_ascii_case(b"data.")).then_some(Format::LammpsData)
    }

    /// The format the first bytes of a file show (give at least 256 bytes when the file has
    /// them). Binary formats are told by their magic numbers (a LAMMPS binary dump from an
    /// older LAMMPS, which has none, by its first frame header), text formats by their first
    /// lines: `data_` (CIF: PDBx/mmCIF or crystallographic, by [`Format::cif_kind`]), a
    /// MessagePack map keyed `encoder`, `version` or `dataBlocks` (BinaryCIF),
    /// `@<TRIPOS>` (MOL2) or an XSF keyword (`CRYSTAL`, `ATOMS`, `ANIMSTEPS`…) on the first
    /// line that is not a `#` comment, pw.x's `Program PWSCF` banner (Quantum ESPRESSO output)
    /// or a first `&CONTROL` / `&SYSTEM` namelist (its input), a `*` title on the first non-blank line (CHARMM CRD), `ITEM: TIMESTEP` (LAMMPS), a PDB record name, a fourth line ending in `V2000` or
    /// `V3000` (molfile, SD file), an integer first line (XYZ), an `N atoms` line after the title
    /// (LAMMPS data file), an integer second line (GRO).
    pub fn from_magic(head: &[u8]) -> Option<Format> {
        let be = |k: usize| {
            head.get(k..k + 4)
                .map(|b| i32::from_be_bytes([b[0], b[1], b[2], b[3]]))
        };
        let le = |k: usize| {
            head.get(k..k + 4)
                .map(|b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        };
        // DCD: a Fortran record of 84 bytes (either endianness) starting with "CORD".
        if (le(0) == Some(84) || be(0) == Some(84)) && head.get(4..8) == Some(b"CORD") {
            return Some(Format::Dcd);
        }
        // GROMACS .tpr: an XDR string "VERSION ..." first (two lengths, then the text).
        if head.get(8..15) == Some(b"VERSION") {
            return Some(Format::Tpr);
        }
        // ASE trajectory: the ULM magic.
        if head.get(..8) == Some(b"- of Ulm") {
            return Some(Format::AseTraj);
        }
        // NetCDF-3: "CDF" and the version byte 1 (classic) or 2 (64-bit offset).
        if matches!(head.get(..4), Some(b"CDF\x01" | b"CDF\x02")) {
            return Some(Format::Netcdf);
        }
        // BinaryCIF: a MessagePack map whose first key is one of the file's.
        if crate::bcif::is_bcif(head) {
            return Some(Format::Bcif);
        }
        // GSD: the little-endian magic number 0x65DF65DF65DF65DF.
        if head.get(..8) == Some(&crate::gsd::MAGIC.to_le_bytes()[..]) {
            return Some(Format::Gsd);
        }
        // XTC and TRR: big-endian magic numbers 1995 and 1993.
        match be(0) {
            Some(1995) => return Some(Format::Xtc),
            Some(1993) => return Some(Format::Trr),
            _ => {}
        }
        // LAMMPS binary dump: its magic header, or a first frame header that fits.
        if crate::lammps_bin::sniff(head) {
            return Some(Format::LammpsBin);
        }
        // CIF (PDBx/mmCIF or crystallographic): a data block header, after comments and blank
        // lines.
        let cif = head
            .split(|b| *b == b'\n')
            .map(crate::parse::trim)
            .find(|l| !l.is_empty() && l[0] != b'#');
        if cif.is_some_and(|l| l.len() >= 5 && l[..5].eq_ignore_ascii_case(b"data_")) {
            return Some(Format::cif_kind(head));
        }
        // CHARMM CRD: `*` title lines first, then the atom count.
        if looks_like_charmm_crd(head) {
            return Some(Format::CharmmCrd);
        }
        // MOL2: a Tripos record header, after comments and blank lines.
        if cif.is_some_and(|l| l.starts_with(b"@<TRIPOS>")) {
            return Some(Format::Mol2);
        }
        // XSF: an XCrySDen keyword, after comments and blank lines.
        if cif.is_some_and(is_xsf_start) {
            return Some(Format::Xsf);
        }
        // Quantum ESPRESSO: pw.x's banner, or an input's first namelist.
        if crate::espresso::is_output(head) {
            return Some(Format::EspressoOut);
        }
        if crate::espresso::is_input(head) {
            return Some(Format::EspressoIn);
        }
        // VASP's run outputs: an XML document rooted at `<modeling>`, VASP's banner.
        if crate::vasp_out::is_vasprun(head) {
            return Some(Format::VaspXml);
        }
        if crate::vasp_out::is_outcar(head) {
            return Some(Format::Outcar);
        }
        let mut lines = head.split(|b| *b == b'\n');
        let first = lines.next().unwrap_or(&[]);
        let t = crate::parse::trim(first);
        if t.starts_with(b"ITEM:") {
            return Some(Format::LammpsDump);
        }
        // Molfile: the fourth line is a counts line ending in its version.
        let counts = head.split(|b| *b == b'\n').nth(3).unwrap_or(&[]);
        let counts = crate::parse::trim(counts);
        if counts.ends_with(b"V2000") || counts.ends_with(b"V3000") {
            return Some(Format::Sdf);
        }
        const PDB_RECORDS: [&[u8]; 12] = [
            b"HEADER", b"TITLE ", b"CRYST1", b"ATOM  ", b"HETATM", b"MODEL ", b"REMARK", b"COMPND",
            b"SOURCE", b"AUTHOR", b"EXPDTA", b"KEYWDS",
        ];
        if PDB_RECORDS.iter().any(|r| first.starts_with(r)) {
            return Some(Format::Pdb);
        }
        let is_count = |l: &[u8]| {
            let t = crate::parse::trim(l);
            !t.is_empty() && crate::parse::parse_usize(t).is_some()
        };
        if looks_like_vasp(head) {
            return Some(Format::Vasp);
        }
        if is_count(first) {
            return Some(Format::Xyz);
        }
        if looks_like_lammps_data(head) {
            return Some(Format::LammpsData);
        }
        if let Some(amber) = Format::amber_kind(head) {
            return Some(amber);
        }
        if lines.next().is_some_and(is_count) {
            return Some(Format::Gro);
        }
        None
    }

    /// True when the first bytes of a `.xyz` file are in Tinker's layout: a count line, an
    /// optional box line (six numbers), then an atom line `index name x y z type [bonded ...]`
    /// (integers where Tinker has them). A plain XYZ file's second line is a free comment and
    /// its atom lines start with a name, so it does not have this shape.
    pub fn tinker_xyz(head: &[u8]) -> bool {
        use crate::parse::{fields, parse_f64, parse_i64};
        let mut lines = head.split(|b| *b == b'\n');
        let count = lines.next().and_then(|l| fields(l).next());
        if count.and_then(parse_i64).is_none_or(|n| n <= 0) {
            return false;
        }
        let atom = |l: &[u8]| {
            let f: Vec<&[u8]> = fields(l).collect();
            f.len() >= 6
                && parse_i64(f[0]).is_some()
                && parse_f64(f[1]).is_none()
                && f[2..5].iter().all(|x| parse_f64(x).is_some())
                && f[5..].iter().all(|x| parse_i64(x).is_some())
        };
        let Some(second) = lines.next() else {
            return false;
        };
        if atom(second) {
            return true;
        }
        let six_reals = fields(second).count() == 6
            && fields(second).all(|x| x.contains(&b'.') && parse_f64(x).is_some());
        six_reals && lines.next().is_some_and(atom)
    }

    /// Which AMBER ASCII file the first bytes show, if either: after the title, an atom count
    /// (and time) then `6F12.7` coordinates is a restart ([`Format::AmberRestart`]); a line of
    /// `10F8.3` coordinates is a trajectory ([`Format::AmberTrj`]). A `.crd` file is told by
    /// this ([`crate::Trajectory::open`]); `None` for anything else.
    pub fn amber_kind(head: &[u8]) -> Option<Format> {
        use crate::parse::{fields, parse_f64, parse_usize, span, trim};
        let mut lines = head.split(|b| *b == b'\n').skip(1);
        let second = lines.next()?;
        // Every fixed-width field of `line` a number with a decimal point; the field count.
        let numbers = |line: &[u8], width: usize| {
            let n = crate::amber::field_count(line, width);
            let ok = n > 0
                && (0..n).all(|k| {
                    let f = trim(span(line, k * width, (k + 1) * width));
                    f.contains(&b'.') && parse_f64(f).is_some()
                });
            ok.then_some(n)
        };
        let words: Vec<&[u8]> = fields(second).collect();
        if let Some(n) = words.first().and_then(|w| parse_usize(w)) {
            let time = words.len() == 1 || (words.len() == 2 && parse_f64(words[1]).is_some());
            let third = lines.next().unwrap_or(&[]);
            return (n > 0 && time && numbers(third, 12) == Some((3 * n).min(6)))
                .then_some(Format::AmberRestart);
        }
        matches!(numbers(second, 8), Some(3..=10)).then_some(Format::AmberTrj)
    }

    /// Which CIF a file is, from its first bytes (`head`; [`crate::Trajectory::open`] gives up
    /// to [`Format::CIF_HEAD`] of a `.cif` file): [`Format::CrystalCif`] or [`Format::Mmcif`].
    ///
    /// The tags decide, outside text fields: an `_atom_site_…` tag without a dot (DDL1:
    /// `_atom_site_label`, `_atom_site_fract_x`, `_atom_site_aniso_U_11`) is a crystallographic
    /// CIF; `_atom_site.…` tags (DDL2) are PDBx/mmCIF, unless they hold `fract_x` and no
    /// `Cartn_x` (a DDLm core CIF). Without an atom-site tag in `head` the first tag decides:
    /// dotted (`_entry.id`) is mmCIF, undotted (`_publ_author_name`, `_cell_length_a`) is a
    /// crystallographic CIF. Without any tag, mmCIF.
    pub fn cif_kind(head: &[u8]) -> Format {
        let (mut first, mut dotted, mut fract, mut cartn) = (None, false, false, false);
        let mut text_field = false;
        for line in head.split(|b| *b == b'\n') {
            if line.first() == Some(&b';') {
                text_field = !text_field;
                continue;
            }
            let t = crate::parse::trim(line);
            if text_field || t.first() != Some(&b'_') {
                continue;
            }
            let end = t
                .iter()
                .position(|b| matches!(b, b' ' | b'\t'))
                .unwrap_or(t.len());
            let tag = t[..end].to_ascii_lowercase();
            let dot = tag.contains(&b'.');
            first.get_or_insert(dot);
            if tag.starts_with(b"_atom_site_") && !dot {
                return Format::CrystalCif;
            }
            if let Some(item) = tag.strip_prefix(b"_atom_site.") {
                dotted = true;
                fract |= item == b"fract_x";
                cartn |= item == b"cartn_x";
            }
        }
        match (dotted, first) {
            (true, _) if fract && !cartn => Format::CrystalCif,
            (true, _) | (false, Some(true) | None) => Format::Mmcif,
            (false, Some(false)) => Format::CrystalCif,
        }
    }

    /// Whether a file whose first bytes are `head` is a CHARMM CRD: its first non-blank line
    /// starts with a `*` title (after any indentation). `None` when `head` holds no non-blank
    /// line. No other format read here starts so; an AMBER ASCII trajectory (also `.crd`) starts
    /// with a title line of any text, then numbers.
    pub fn is_charmm_crd(head: &[u8]) -> Option<bool> {
        head.split(|b| *b == b'\n')
            .map(crate::parse::trim)
            .find(|l| !l.is_empty())
            .map(|l| l[0] == b'*')
    }

    /// How much of a `.cif` file [`crate::Trajectory::open`] reads to tell its kind
    /// ([`Format::cif_kind`]): a COD file's atom sites come after kilobytes of bibliography.
    pub const CIF_HEAD: u64 = 64 * 1024;

    /// True for the text formats (line numbers in errors, line-scan frame index).
    pub fn is_text(self) -> bool {
        matches!(
            self,
            Format::Xyz
                | Format::Pdb
                | Format::Gro
                | Format::LammpsDump
                | Format::Mmcif
                | Format::Sdf
                | Format::Mol2
                | Format::Vasp
                | Format::CrystalCif
                | Format::LammpsData
                | Format::Cube
                | Format::AmberTrj
                | Format::AmberRestart
                | Format::CharmmCrd
                | Format::Pqr
                | Format::Pdbqt
                | Format::Tinker
                | Format::DlPoly
                | Format::Xsf
                | Format::EspressoOut
                | Format::EspressoIn
                | Format::VaspXml
                | Format::Outcar
        )
    }

    /// A short lower-case name ("xyz", "lammps-dump").
    pub fn name(self) -> &'static str {
        match self {
            Format::Xyz => "xyz",
            Format::Pdb => "pdb",
            Format::Gro => "gro",
            Format::LammpsDump => "lammps-dump",
            Format::LammpsBin => "lammps-bin",
            Format::Dcd => "dcd",
            Format::Xtc => "xtc",
            Format::Trr => "trr",
            Format::Netcdf => "ncdf",
            Format::Gsd => "gsd",
            Format::Mmcif => "mmcif",
            Format::Sdf => "sdf",
            Format::Mol2 => "mol2",
            Format::Vasp => "vasp",
            Format::CrystalCif => "cif-crystal",
            Format::LammpsData => "lammps-data",
            Format::Cube => "cube",
            Format::AmberTrj => "mdcrd",
            Format::AmberRestart => "rst7",
            Format::CharmmCrd => "charmm-crd",
            Format::Pqr => "pqr",
            Format::Pdbqt => "pdbqt",
            Format::NamdBin => "namdbin",
            Format::Tinker => "txyz",
            Format::DlPoly => "dlpoly",
            Format::Xsf => "xsf",
            Format::Tpr => "tpr",
            Format::AseTraj => "ase-traj",
            Format::Bcif => "bcif",
            Format::EspressoOut => "espresso-out",
            Format::EspressoIn => "espresso-in",
            Format::VaspXml => "vasp-xml",
            Format::Outcar => "vasp-out",
        }
    }
}

/// True when the first lines have a VASP header's shape: a comment, one or three scaling
/// numbers, three lattice lines of three numbers, then species names (words starting with a
/// letter) or atom counts (integers).
fn looks_like_vasp(head: &[u8]) -> bool {
    use crate::parse::{fields, parse_f64, parse_usize};
    let lines: Vec<&[u8]> = head
        .split(|b| *b == b'\n')
        .map(crate::parse::trim)
        .take(7)
        .collect();
    if lines.len() < 7 {
        return false;
    }
    let numbers = |l: &[u8]| fields(l).take_while(|f| parse_f64(f).is_some()).count();
    let scale = numbers(lines[1]);
    if !(scale == 1 || scale == 3) || fields(lines[1]).count() != scale {
        return false;
    }
    if lines[2..5].iter().any(|l| numbers(l) < 3) {
        return false;
    }
    let words: Vec<&[u8]> = fields(lines[5]).collect();
    !words.is_empty()
        && (words.iter().all(|w| parse_usize(w).is_some())
            || words.iter().all(|w| w[0].is_ascii_alphabetic()))
}

/// True when `line` (the first that is not blank or a `#` comment) starts an XSF file: one of
/// XCrySDen's leading keywords, in any case.
fn is_xsf_start(line: &[u8]) -> bool {
    const KEYWORDS: [&[u8]; 8] = [
        b"ANIMSTEPS",
        b"CRYSTAL",
        b"SLAB",
        b"POLYMER",
        b"MOLECULE",
        b"ATOMS",
        b"BEGIN_BLOCK_DATAGRID_3D",
        b"BEGIN_BLOCK_DATAGRID3D",
    ];
    let first = crate::parse::fields(line).next().unwrap_or(b"");
    KEYWORDS.iter().any(|k| first.eq_ignore_ascii_case(k))
}

/// True when the first non-blank lines are `*` titles followed by an atom-count line (`N` or
/// `N  EXT`), or by nothing more in `head`.
fn looks_like_charmm_crd(head: &[u8]) -> bool {
    use crate::parse::{fields, parse_usize, trim};
    if Format::is_charmm_crd(head) != Some(true) {
        return false;
    }
    let mut lines = head.split(|b| *b == b'\n').peekable();
    while lines.next_if(|l| trim(l).is_empty()).is_some() {}
    while lines.next_if(|l| trim(l).first() == Some(&b'*')).is_some() {}
    let Some(count) = lines.next() else {
        return true;
    };
    if lines.peek().is_none() {
        // A count line cut by the end of `head` (or a file without a final newline): the
        // titles decide.
        return true;
    }
    let f: Vec<&[u8]> = fields(count).collect();
    match f[..] {
        [n] => parse_usize(n).is_some(),
        [n, ext] => parse_usize(n).is_some() && ext.eq_ignore_ascii_case(b"EXT"),
        _ => false,
    }
}

/// True when a LAMMPS data file's header shows: after the title line, one of the first three
/// lines that are not blank or `#` comments is `N atoms` (what LAMMPS `write_data`, MDAnalysis,
/// ASE, OVITO and moltemplate write first).
fn looks_like_lammps_data(head: &[u8]) -> bool {
    use crate::parse::{fields, parse_usize};
    head.split(|b| *b == b'\n')
        .skip(1)
        .map(|l| crate::parse::trim(l.split(|b| *b == b'#').next().unwrap_or(&[])))
        .filter(|l| !l.is_empty())
        .take(3)
        .any(|l| {
            let f: Vec<&[u8]> = fields(l).collect();
            matches!(f[..], [n, b"atoms"] if parse_usize(n).is_some())
        })
}

impl std::fmt::Display for Format {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extensions() {
        assert_eq!(Format::from_path(Path::new("a/b.XYZ")), Some(Format::Xyz));
        assert_eq!(
            Format::from_path(Path::new("run.lammpstrj")),
            Some(Format::LammpsDump)
        );
        assert_eq!(Format::from_path(Path::new("x.trr")), Some(Format::Trr));
        assert_eq!(Format::from_path(Path::new("noext")), None);
        assert_eq!(
            Format::from_path(Path::new("1abc.pdb.GZ")),
            Some(Format::Pdb)
        );
        assert_eq!(Format::from_path(Path::new("run.gz")), None);
        // Every name `texmap info` prints is a name `--format` takes.
        for f in Format::ALL {
            assert_eq!(Format::from_extension(f.name()), Some(f), "{}", f.name());
        }
    }

    #[test]
    fn magic() {
        let mut dcd = 84i32.to_le_bytes().to_vec();
        dcd.extend_from_slice(b"CORD");
        assert_eq!(Format::from_magic(&dcd), Some(Format::Dcd));
        assert_eq!(
            Format::from_magic(&1995i32.to_be_bytes()),
            Some(Format::Xtc)
        );
        assert_eq!(
            Format::from_magic(&1993i32.to_be_bytes()),
            Some(Format::Trr)
        );
        assert_eq!(
            Format::from_magic(b"ITEM: TIMESTEP\n0\n"),
            Some(Format::LammpsDump)
        );
        assert_eq!(Format::from_magic(b"CRYST1   10.000"), Some(Format::Pdb));
        assert_eq!(
            Format::from_magic(b"3\ncomment\nC 0 0 0\n"),
            Some(Format::Xyz)
        );
        assert_eq!(
            Format::from_magic(b"Water\n   3\n    1SOL"),
            Some(Format::Gro)
        );
        assert_eq!(
            Format::from_magic(b"CDF\x02\0\0\0\x04"),
            Some(Format::Netcdf)
        );
        assert_eq!(
            Format::from_magic(&0x65DF_65DF_65DF_65DFu64.to_le_bytes()),
            Some(Format::Gsd)
        );
        assert_eq!(
            Format::from_path(Path::new("run.gsd.gz")),
            Some(Format::Gsd)
        );
        assert_eq!(
            Format::from_magic(b"# generated by PyMOL\n#\ndata_1ABC\n_entry.id 1ABC\n"),
            Some(Format::Mmcif)
        );
        assert_eq!(Format::from_magic(b"DATA_x\n"), Some(Format::Mmcif));
        assert_eq!(
            Format::from_path(Path::new("1abc.CIF")),
            Some(Format::Mmcif)
        );
        assert_eq!(Format::from_extension("mmcif"), Some(Format::Mmcif));
        assert_eq!(
            Format::from_path(Path::new("1abc.bcif.gz")),
            Some(Format::Bcif)
        );
        assert_eq!(
            Format::from_magic(b"\x83\xa7encoder\xa4x"),
            Some(Format::Bcif)
        );
        assert_eq!(Format::from_magic(b"hello\nworld\n"), None);
        assert_eq!(
            Format::from_magic(b"\n* TITLE\n*\n    1\n"),
            Some(Format::CharmmCrd)
        );
        assert_eq!(Format::is_charmm_crd(b" \n\n"), None);
        assert_eq!(
            Format::from_magic(b"* title\n\n 12 atoms\n"),
            Some(Format::LammpsData)
        );
        assert_eq!(
            Format::from_magic(b"* A\n* B\n     12345  EXT\n"),
            Some(Format::CharmmCrd)
        );
        assert_eq!(Format::is_charmm_crd(b"AMBER title\n  1.000"), Some(false));
        assert_eq!(
            Format::from_path(Path::new("a.cor")),
            Some(Format::CharmmCrd)
        );
        assert_eq!(
            Format::from_path(Path::new("a.CRD")),
            Some(Format::CharmmCrd)
        );
        assert_eq!(Format::from_path(Path::new("1abc.pqr")), Some(Format::Pqr));
        assert_eq!(Format::from_path(Path::new("md.AXSF")), Some(Format::Xsf));
        assert_eq!(
            Format::from_magic(b"# pw.x\n\n CRYSTAL\n PRIMVEC\n"),
            Some(Format::Xsf)
        );
        assert_eq!(
            Format::from_magic(b"ANIMSTEPS 3\nATOMS 1\n"),
            Some(Format::Xsf)
        );
    }
}

//! Damaged topology files (the MDAnalysis-written PDB with CONECT, LAMMPS data file and GRO,
//! ParmEd's PSF and prmtop and gemmi's mmCIF of tests/data, cut at every line end and at seeded
//! offsets, with seeded bit flips and byte replacements): never a panic, and every error names the file
//! and, for damage inside the file, the line or byte.

use std::io::Cursor;

use texmap_md_io::{Error, Topology, TopologyFormat};

fn data(name: &str) -> Vec<u8> {
    std::fs::read(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name),
    )
    .unwrap()
}

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        self.0 >> 33
    }
}

fn check(bytes: &[u8], format: TopologyFormat, what: &str) -> bool {
    let name = "damaged.top";
    match std::panic::catch_unwind(|| Topology::from_reader(Cursor::new(bytes), format, name)) {
        Err(_) => panic!("{what}: panic"),
        Ok(Ok(t)) => {
            let n = t.n_atoms();
            for v in [
                t.names.len(),
                t.types.len(),
                t.ids.len(),
                t.res_ids.len(),
                t.elements.len(),
            ] {
                assert!(v == 0 || v == n, "{what}: ragged topology");
            }
            assert!(
                t.bonds.iter().all(|b| b[0] < b[1] && (b[1] as usize) < n),
                "{what}"
            );
            true
        }
        Ok(Err(e)) => {
            let s = e.to_string();
            assert!(s.starts_with(name) || s.contains(name), "{what}: {s}");
            if let Error::Parse { at, .. } | Error::Truncated { at, .. } = &e {
                // A file with no atom at all is about the whole file, not a place in it.
                let whole = s.contains("end of file") || s.contains("none");
                assert!(
                    at.line.is_some() || at.byte.is_some() || whole,
                    "{what}: {s}"
                );
            }
            false
        }
    }
}

#[test]
fn damaged_topologies_give_located_errors_never_panics() {
    for (file, format) in [
        ("topo_mda.pdb", TopologyFormat::Pdb),
        ("topo_mda.data", TopologyFormat::LammpsData),
        ("topo_mda.gro", TopologyFormat::Gro),
        ("psf_parmed.psf", TopologyFormat::Psf),
        ("gemmi_topo.cif", TopologyFormat::Mmcif),
        ("prmtop_parmed.prmtop", TopologyFormat::Prmtop),
    ] {
        let good = data(file);
        assert!(check(&good, format, file));
        let mut rng = Lcg(17);
        let mut ok = 0;
        let mut errors = 0;
        let ends: Vec<usize> = (0..good.len()).filter(|&i| good[i] == b'\n').collect();
        for &e in &ends {
            let cut = &good[..e];
            if check(cut, format, &format!("{file} cut at {e}")) {
                ok += 1
            } else {
                errors += 1
            }
        }
        for k in 0..600 {
            let mut m = good.clone();
            let at = rng.next() as usize % m.len();
            if k % 2 == 0 {
                m[at] ^= 1 << (rng.next() % 8);
            } else {
                m[at] = b"09 -.eE\n#x"[rng.next() as usize % 10];
            }
            if check(&m, format, &format!("{file} byte {at} changed")) {
                ok += 1
            } else {
                errors += 1
            }
        }
        assert!(errors > 0 && ok > 0, "{file}: {ok} read, {errors} errors");
    }
}

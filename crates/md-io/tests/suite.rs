//! The md-io integration tests as one test binary (`cargo test -p texmap-md-io --test suite`;
//! one file's tests: `--test suite amber_ascii::`). One binary links texmap-md-io and its dependencies
//! once instead of once per file, which was most of the workspace's test build time. Each `.rs`
//! file in this directory is a module listed below ([`listed`] fails when one is not); the
//! helper modules they share are declared here once.

mod support {
    pub mod alloc;
    pub mod campaign;
    pub mod dft;
    pub mod fixtures;
    pub mod gsd_index;
    pub mod lammps_bin;
    pub mod ovito;
}

// The counting allocator serves every module: its counters are per thread, so a test that
// measures sees only its own allocations.
#[global_allocator]
static ALLOC: support::alloc::CountingAlloc = support::alloc::CountingAlloc;

#[path = "amber_ascii.rs"]
mod amber_ascii;
#[path = "asetraj.rs"]
mod asetraj;
#[path = "binary_damage.rs"]
mod binary_damage;
#[path = "binary_mdanalysis.rs"]
mod binary_mdanalysis;
#[path = "bonds.rs"]
mod bonds;
#[path = "boundaries.rs"]
mod boundaries;
#[path = "clusters.rs"]
mod clusters;
#[path = "cna.rs"]
mod cna;
#[path = "conformations.rs"]
mod conformations;
#[path = "coordination.rs"]
mod coordination;
#[path = "cp2k.rs"]
mod cp2k;
#[path = "crd_pqr.rs"]
mod crd_pqr;
#[path = "crystal_cif.rs"]
mod crystal_cif;
#[path = "diamond.rs"]
mod diamond;
#[path = "distance_map.rs"]
mod distance_map;
#[path = "dlpoly.rs"]
mod dlpoly;
#[path = "elements.rs"]
mod elements;
#[path = "energy.rs"]
mod energy;
#[path = "espresso.rs"]
mod espresso;
#[path = "expr.rs"]
mod expr;
#[path = "fuzz_campaign.rs"]
mod fuzz_campaign;
#[path = "grains.rs"]
mod grains;
#[path = "gromacs_top.rs"]
mod gromacs_top;
#[path = "gsd.rs"]
mod gsd;
#[path = "gsd_writer.rs"]
mod gsd_writer;
#[path = "gzip.rs"]
mod gzip;
#[path = "hbonds.rs"]
mod hbonds;
#[path = "hostile_headers.rs"]
mod hostile_headers;
#[path = "lammps_colors.rs"]
mod lammps_colors;
#[path = "lammps_data.rs"]
mod lammps_data;
#[path = "lammps_write.rs"]
mod lammps_write;
#[path = "mmcif.rs"]
mod mmcif;
#[path = "mmcif_writer.rs"]
mod mmcif_writer;
#[path = "molecules.rs"]
mod molecules;
#[path = "namdbin.rs"]
mod namdbin;
#[path = "netcdf.rs"]
mod netcdf;
#[path = "netcdf_writer.rs"]
mod netcdf_writer;
#[path = "order.rs"]
mod order;
#[path = "pca.rs"]
mod pca;
#[path = "pdbqt.rs"]
mod pdbqt;
#[path = "prmtop.rs"]
mod prmtop;
#[path = "properties.rs"]
mod properties;
#[path = "rdf.rs"]
mod rdf;
#[path = "replicate.rs"]
mod replicate;
#[path = "sasa.rs"]
mod sasa;
#[path = "secondary.rs"]
mod secondary;
#[path = "select.rs"]
mod select;
#[path = "sequence.rs"]
mod sequence;
#[path = "smooth.rs"]
mod smooth;
#[path = "strain.rs"]
mod strain;
#[path = "text_access.rs"]
mod text_access;
#[path = "text_cases.rs"]
mod text_cases;
#[path = "text_damage.rs"]
mod text_damage;
#[path = "text_programs.rs"]
mod text_programs;
#[path = "tinker.rs"]
mod tinker;
#[path = "topology.rs"]
mod topology;
#[path = "topology_damage.rs"]
mod topology_damage;
#[path = "tpr.rs"]
mod tpr;
#[path = "trr_writer.rs"]
mod trr_writer;
#[path = "vasp.rs"]
mod vasp;
#[path = "vasp_out.rs"]
mod vasp_out;
#[path = "vasp_writer.rs"]
mod vasp_writer;
#[path = "volume.rs"]
mod volume;
#[path = "voronoi.rs"]
mod voronoi;
#[path = "wigner_seitz.rs"]
mod wigner_seitz;
#[path = "writers.rs"]
mod writers;
#[path = "xsf.rs"]
mod xsf;

#[path = "../../../tests/support/listed.rs"]
mod listed;

/// Every `.rs` file in tests/ is a module of this binary.
#[test]
fn listed() {
    listed::every_file_is_a_module(env!("CARGO_MANIFEST_DIR"), include_str!("suite.rs"));
}

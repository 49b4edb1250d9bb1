"""Write CHARMM coordinate files (.crd) and PQR files with the programs that write them, and
what those programs read back from each (crd_pqr_reference.json.gz), for
crates/md-io/tests/crd_pqr.rs.

CHARMM CRD, by MDAnalysis's CRDWriter:
- mda_chains.crd: chains_mda.pdb (362 atoms: two alanine chains, waters, ions, a DNA strand)
  in the standard layout, with its segment ids (PROA, PROB, SOLV, IONS, DNA1) in the SEGID
  column (the chain ids dropped first: the writer prefers them) and seeded weights (WMAIN,
  MDAnalysis's tempfactors);
- mda_chains_ext.crd.gz: the same in the EXT layout (`extended=True`), gzipped (Python's gzip,
  level 9, no name, mtime 0);
- mda_two.crd: two single-frame files of topo_mda.pdb's 66 atoms concatenated, frame 0 of
  topo_mda.xtc in the standard layout and frame 3 in EXT, seeded weights. MDAnalysis reads one
  frame per CRD, so the reference holds its reading of each part alone.

PQR:
- pdb2pqr_amber.pqr: PDB2PQR `--ff=AMBER` of 3jqh_gemmi.pdb (PDB entry 3JQH, a 23-residue helix
  and waters; PDB2PQR adds hydrogens): fixed columns, no chain field (PDB2PQR's default);
- pdb2pqr_chains.pqr: PDB2PQR `--ff=CHARMM --keep-chain --whitespace` of a two-chain PDB this
  script makes from 3jqh_gemmi.pdb: residues 1-12 as chain A, and again as chain B moved 30 A
  along x and renumbered 1-5, 5A (an insertion code), 6-11;
- mda_chains.pqr: MDAnalysis's PQRWriter of its own reading of pdb2pqr_chains.pqr (the chain
  field written from the segment ids, A and B; the insertion code dropped);
- parmed_models.pqr: ParmEd's PQRFile.write of residues 1-4 of pdb2pqr_amber.pqr (read with
  ParmEd), chains A (residues 1-2) and B (3-4) set, a triclinic box, three models (the positions
  and two seeded displacements): CRYST1 and MODEL/ENDMDL records.

The reference: for each file, per frame, what MDAnalysis reads back (CRD: ids, names,
resnames, resids, resnums, segids, tempfactors, positions; PQR: ids, names, resnames, resids,
segids (the chain, or SYSTEM without one), charges, radii, positions), and for
parmed_models.pqr what ParmEd reads back (per model positions; names, residue names and numbers,
chains, charges, radii, box), gzipped. Positions are stored as the shortest decimals that give the same
float32 values.

Run from this directory with MDAnalysis 2.11.0, pdb2pqr 3.8.0 (with propka 3.5.1) and ParmEd
4.3.1: `pip install MDAnalysis==2.11.0 pdb2pqr==3.8.0 parmed==4.3.1 && python3 gen_crd_pqr.py`.
Seeded (numpy default_rng(7)); PDB2PQR's output is deterministic, so reruns give the same files.
"""
import gzip
import json
import os
import shutil
import subprocess
import tempfile
import warnings
from importlib.metadata import version

import MDAnalysis as mda
import numpy as np
import parmed
from MDAnalysis.coordinates.CRD import CRDWriter

warnings.filterwarnings("ignore")
rng = np.random.default_rng(7)


def f32(values):
    """float32 values as the shortest decimals that round-trip them."""
    return [float(np.format_float_positional(np.float32(v), unique=True)) for v in values]


def rows(xyz):
    return [f32(p) for p in np.asarray(xyz, dtype=np.float32)]


def strs(values):
    return [str(v) for v in values]


def ints(values):
    return [int(v) for v in values]


def crd_reading(path):
    """What MDAnalysis reads back from a CHARMM CRD."""
    u = mda.Universe(path, format="CRD", topology_format="CRD")
    a = u.atoms
    return {
        "ids": ints(a.ids),
        "names": strs(a.names),
        "resnames": strs(a.resnames),
        "resids": ints(a.resids),
        "resnums": ints(a.resnums),
        "segids": strs(a.segids),
        "tempfactors": f32(a.tempfactors),
        "positions": rows(a.positions),
    }


def pqr_reading(path):
    """What MDAnalysis reads back from a PQR."""
    u = mda.Universe(path)
    a = u.atoms
    return {
        "ids": ints(a.ids),
        "names": strs(a.names),
        "resnames": strs(a.resnames),
        "resids": ints(a.resids),
        "segids": strs(a.segids),
        "charges": f32(a.charges),
        "radii": f32(a.radii),
        "positions": rows(a.positions),
    }


def write_crd(atoms, path, extended):
    with CRDWriter(path, extended=extended) as w:
        w.write(atoms)


ref = {
    "programs": {
        "MDAnalysis": mda.__version__,
        "pdb2pqr": version("pdb2pqr"),
        "propka": version("propka"),
        "parmed": parmed.__version__,
    }
}

with tempfile.TemporaryDirectory() as tmp:
    # --- CHARMM CRD: chains_mda.pdb, standard and EXT.
    u = mda.Universe("chains_mda.pdb")
    u.del_TopologyAttr("chainIDs")
    u.atoms.tempfactors = np.round(rng.uniform(0.0, 50.0, u.atoms.n_atoms), 5)
    write_crd(u.atoms, "mda_chains.crd", extended=False)
    ref["mda_chains.crd"] = [crd_reading("mda_chains.crd")]
    ext = os.path.join(tmp, "mda_chains_ext.crd")
    write_crd(u.atoms, ext, extended=True)
    ref["mda_chains_ext.crd.gz"] = [crd_reading(ext)]
    with open(ext, "rb") as src, open("mda_chains_ext.crd.gz", "wb") as raw:
        with gzip.GzipFile(filename="", mode="wb", fileobj=raw, compresslevel=9, mtime=0) as z:
            shutil.copyfileobj(src, z)

    # --- CHARMM CRD: two frames of topo_mda, standard then EXT, concatenated.
    t = mda.Universe("topo_mda.pdb", "topo_mda.xtc")
    t.atoms.tempfactors = np.round(rng.uniform(0.0, 5.0, t.atoms.n_atoms), 5)
    parts = []
    for frame, extended in ((0, False), (3, True)):
        t.trajectory[frame]
        part = os.path.join(tmp, f"two_{frame}.crd")
        write_crd(t.atoms, part, extended)
        parts.append(part)
    ref["mda_two.crd"] = [crd_reading(p) for p in parts]
    with open("mda_two.crd", "wb") as out:
        for p in parts:
            with open(p, "rb") as src:
                out.write(src.read())

    # --- PQR: PDB2PQR, AMBER force field, fixed columns without chains.
    def pdb2pqr(args, pdb, out):
        work = os.path.join(tmp, "pdb2pqr")
        os.makedirs(work, exist_ok=True)
        shutil.copy(pdb, os.path.join(work, "in.pdb"))
        subprocess.run(["pdb2pqr", *args, "in.pdb", "out.pqr"], cwd=work, check=True,
                       capture_output=True)
        shutil.copy(os.path.join(work, "out.pqr"), out)

    pdb2pqr(["--ff=AMBER"], "3jqh_gemmi.pdb", "pdb2pqr_amber.pqr")
    ref["pdb2pqr_amber.pqr"] = [pqr_reading("pdb2pqr_amber.pqr")]

    # --- PQR: PDB2PQR, CHARMM force field, two chains, an insertion code, whitespace.
    atoms = [l for l in open("3jqh_gemmi.pdb") if l.startswith("ATOM") and int(l[22:26]) <= 12]
    lines, serial = [], 0
    for chain, shift in (("A", 0.0), ("B", 30.0)):
        for l in atoms:
            serial += 1
            seq, icode = int(l[22:26]), " "
            if chain == "B" and seq >= 6:
                seq, icode = (5, "A") if seq == 6 else (seq - 1, " ")
            x = float(l[30:38]) + shift
            lines.append(f"{l[:6]}{serial:5d}{l[11:21]}{chain}{seq:4d}{icode}{l[27:30]}"
                         f"{x:8.3f}{l[38:]}")
        lines.append("TER\n")
    lines.append("END\n")
    two = os.path.join(tmp, "two_chains.pdb")
    with open(two, "w") as f:
        f.writelines(lines)
    pdb2pqr(["--ff=CHARMM", "--keep-chain", "--whitespace"], two, "pdb2pqr_chains.pqr")
    ref["pdb2pqr_chains.pqr"] = [pqr_reading("pdb2pqr_chains.pqr")]

    # --- PQR: MDAnalysis's writer, from its reading of the two-chain file.
    mda.Universe("pdb2pqr_chains.pqr").atoms.write("mda_chains.pqr")
    ref["mda_chains.pqr"] = [pqr_reading("mda_chains.pqr")]

    # --- PQR: ParmEd, three models, chains and a box.
    s = parmed.load_file("pdb2pqr_amber.pqr")[":1-4"]
    for k, res in enumerate(s.residues):
        res.chain = "A" if k < 2 else "B"
    s.box = [30.0, 35.0, 40.0, 80.0, 95.0, 100.0]
    base = s.coordinates
    coords = np.stack([base] + [base + rng.normal(0.0, 0.5, base.shape) for _ in range(2)])
    parmed.formats.PQRFile.write(s, "parmed_models.pqr", coordinates=coords)
    back = parmed.load_file("parmed_models.pqr")
    ref["parmed_models.pqr"] = {
        "names": [a.name for a in back.atoms],
        "resnames": [a.residue.name for a in back.atoms],
        "resids": [int(a.residue.number) for a in back.atoms],
        "chains": [a.residue.chain for a in back.atoms],
        "charges": f32([a.charge for a in back.atoms]),
        "radii": f32([a.solvent_radius for a in back.atoms]),
        "box": [float(b) for b in back.box],
        "models": [rows(c) for c in back.get_coordinates()],
    }

with open("crd_pqr_reference.json.gz", "wb") as raw:
    with gzip.GzipFile(filename="", mode="wb", fileobj=raw, compresslevel=9, mtime=0) as z:
        z.write(json.dumps(ref, separators=(",", ":")).encode() + b"\n")

"""MDTraj 1.11.1's Shrake-Rupley areas, for tests/sasa.rs.

Run from this directory: python3 gen_sasa.py (mdtraj, numpy).

For three wwPDB protein chains of md-io's DSSP fixtures (../dssp/1ahsA, 2cviA, 3gwiA: heavy
atoms as deposited) and for MDAnalysis's solvated peptide (../select_mda.pdb, with its water
and ions, hydrogens included), sasa_reference.json holds every atom's solvent-accessible area in
A^2 (mdtraj.shrake_rupley, probe 0.14 nm, 960 points, mode 'atom', its default radii, times
100), the atoms' elements as MDTraj read them, and the per-residue sums (mode 'residue');
and the peptide's residues measured alone (its protein atoms sliced out: no water, no ions).
"""
import json
import os

import mdtraj as md
import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
files = ["../dssp/1ahsA.pdb.gz", "../dssp/2cviA.pdb.gz", "../dssp/3gwiA.pdb.gz", "../select_mda.pdb"]
out = {}
for name in files:
    t = md.load(os.path.join(here, name))
    atom = md.shrake_rupley(t, probe_radius=0.14, n_sphere_points=960, mode="atom")[0] * 100.0
    residue = md.shrake_rupley(t, probe_radius=0.14, n_sphere_points=960, mode="residue")[0] * 100.0
    out[os.path.basename(name)] = {
        "elements": [a.element.symbol for a in t.topology.atoms],
        "sasa": [round(float(x), 4) for x in atom],
        "residues": [round(float(x), 3) for x in residue],
        "total": float(atom.sum()),
    }
    print(name, t.n_atoms, round(float(atom.sum()), 2), sorted(set(out[os.path.basename(name)]["elements"])))
# The peptide alone (its water and ions neither measured nor burying it).
t = md.load(os.path.join(here, "../select_mda.pdb"))
protein = t.atom_slice(t.topology.select("protein"))
residue = md.shrake_rupley(protein, probe_radius=0.14, n_sphere_points=960, mode="residue")[0] * 100.0
out["select_mda.pdb protein"] = {
    "residues": [round(float(x), 3) for x in residue],
    "resids": [r.resSeq for r in protein.topology.residues],
    "total": float(residue.sum()),
}
print("protein alone", protein.n_atoms, round(float(residue.sum()), 2))
with open(os.path.join(here, "sasa_reference.json"), "w") as f:
    json.dump(out, f)
    f.write("\n")

"""MDAnalysis 2.11.0's Ramachandran angles: the reference for `--dihedral-table`
(crates/cli/tests/convert.rs).

Run from this directory: python3 gen_dihedrals.py

- helix.pdb + helix.dcd (written by MDAnalysis): the 23-residue protein of PDB 3JQH
  (../3jqh_gemmi.pdb, as gemmi wrote it) without its waters, over 12 frames, each the crystal
  structure with seeded Gaussian noise of 0.1 A per axis on every atom, so the angles move
  from frame to frame.
- ramachandran_reference.json: per frame, the phi and psi (degrees) of residues 2-22 (the
  termini have only one of the two), from MDAnalysis.analysis.dihedrals.Ramachandran, with
  their residue numbers; and the omega (CA-C-N'-CA') of residues 1-22 from
  Dihedral over each residue's omega_selection().
"""
import json

import numpy as np
import MDAnalysis as mda
from MDAnalysis.analysis.dihedrals import Dihedral, Ramachandran

rng = np.random.default_rng(20261206)
crystal = mda.Universe("../3jqh_gemmi.pdb")
protein = crystal.select_atoms("protein")
protein.write("helix.pdb")
base = protein.positions.copy()
with mda.Writer("helix.dcd", protein.n_atoms) as w:
    for f in range(12):
        protein.positions = base + rng.normal(0.0, 0.1, size=base.shape)
        w.write(protein)

u = mda.Universe("helix.pdb", "helix.dcd")
residues = u.select_atoms("protein").residues[1:-1]
r = Ramachandran(residues.atoms).run()
chain = u.select_atoms("protein").residues[:-1]
omega = Dihedral([res.omega_selection() for res in chain]).run()
json.dump({"resids": residues.resids.tolist(), "angles": r.results.angles.tolist(),
           "omega_resids": chain.resids.tolist(), "omega": omega.results.angles.tolist()},
          open("ramachandran_reference.json", "w"), indent=1)
print(len(residues), "residues,", r.results.angles.shape[0], "frames; frame 0 residue 2:",
      r.results.angles[0][0])

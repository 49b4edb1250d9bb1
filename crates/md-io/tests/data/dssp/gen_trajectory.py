"""MDAnalysis 2.11.0's DSSP over trajectories: the reference for `texmap convert --dssp-table`
and `--dssp-residue-table` (crates/cli/tests/convert.rs).

Run from this directory: python3 gen_trajectory.py

trajectory_reference.json, per system: the residue numbers MDAnalysis assigns and, per frame,
the C3 codes ('H', 'E', '-') of analysis.dssp.DSSP(u).run() joined into one string.
- "helix": ../dihedrals/helix.pdb + ../pca/helix_pca.xtc (see ../pca/gen_pca.py: a bending,
  twisting 23-residue helix with noise, 80 frames; its ends fray from frame to frame).
- "adk": ../hbonds/adk_top.gro.gz + ../hbonds/adk_0_9.xtc (MDAnalysis's adenylate kinase in
  water: helices and a sheet), the protein made whole by MDAnalysis's unwrap transformation
  (bonds guessed): the file's frame 0 cuts it across the box at three peptide bonds, where
  DSSP on the raw coordinates would be an artefact of the wrapping (texmap: --pbc unwrap).
"""
import json
import warnings

import MDAnalysis as mda
from MDAnalysis import transformations
from MDAnalysis.analysis.dssp import DSSP

warnings.simplefilter("ignore")
out = {}
for key, top, traj in [
    ("helix", "../dihedrals/helix.pdb", "../pca/helix_pca.xtc"),
    ("adk", "../hbonds/adk_top.gro.gz", "../hbonds/adk_0_9.xtc"),
]:
    u = mda.Universe(top, traj)
    if key == "adk":
        protein = u.select_atoms("protein")
        protein.guess_bonds()
        u.trajectory.add_transformations(transformations.unwrap(protein))
    d = DSSP(u).run()
    out[key] = {
        "resids": [int(r) for r in d.results.resids],
        "frames": ["".join(row) for row in d.results.dssp],
    }
    print(key, len(out[key]["frames"]), out[key]["frames"][0])
with open("trajectory_reference.json", "w") as f:
    json.dump(out, f)
    f.write("\n")

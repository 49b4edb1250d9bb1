"""OVITO's coordination numbers of the crystals of crystals.xyz.gz (see gen_cna.py), for
tests/coordination.rs.

coordination_reference.json: per frame and per cutoff (2.9 A, between the FCC and BCC first and
second shells; 3.2 A, OVITO's default; 4.0 A, past the second shells), the "Coordination"
property OVITO 3.17's CoordinationAnalysisModifier computes for every atom.

    pip install ovito==3.17.2
    python3 gen_coordination.py
"""
import json
import os

from ovito.io import import_file
from ovito.modifiers import CoordinationAnalysisModifier

here = os.path.dirname(os.path.abspath(__file__))
pipe = import_file(os.path.join(here, "crystals.xyz.gz"))
modifier = CoordinationAnalysisModifier(cutoff=3.2, number_of_bins=50)
pipe.modifiers.append(modifier)
cutoffs = [2.9, 3.2, 4.0]
frames = []
for f in range(pipe.source.num_frames):
    per_cutoff = {}
    for c in cutoffs:
        modifier.cutoff = c
        d = pipe.compute(f)
        per_cutoff[str(c)] = d.particles["Coordination"][...].tolist()
    frames.append(per_cutoff)
with open(os.path.join(here, "coordination_reference.json"), "w") as out:
    json.dump({"cutoffs": cutoffs, "frames": frames}, out)
    out.write("\n")

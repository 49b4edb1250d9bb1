"""FCC crystals with planar faults written by OVITO, and OVITO's grains of them, for
tests/grains.rs: what OVITO's Grain segmentation does with the HCP layers of a stacking fault
or a twin boundary (handle_stacking_faults, on by default).

Close-packed layers of copper (nearest-neighbour distance 2.556 A) stacked along z in a
periodic box: each layer a triangular lattice at position A, B or C, the next one step on
(A -> B -> C -> A) in the FCC stacking. Both files as extended XYZ by ovito.io.export_file,
thermal noise 0.03 A:

- faults.xyz: 19 layers and two intrinsic stacking faults (a position skipped after layers 4
  and 13): two FCC slabs of one orientation, each fault two HCP layers;
- twins.xyz: 18 layers, 9 stepping up and 9 down (...ABCABCBACBA...): two twins related by
  60 degrees about [111], each boundary one HCP layer.

faults_reference.json: per file, OVITO 3.17's PolyhedralTemplateMatchingModifier (defaults,
output_orientation) then GrainSegmentationModifier with handle_stacking_faults on (its
default) and off: every atom's "Grain" and the grain table's sizes.

    pip install ovito==3.17.2
    python3 gen_faults.py
"""
import json
import os
import sys

import numpy as np
from ovito.io import import_file
from ovito.modifiers import GrainSegmentationModifier, PolyhedralTemplateMatchingModifier

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(here))
import ovito_single  # noqa: E402

nn = 2.556
nx, ny = 12, 7  # atoms per row, rows (pairs) per layer: the cell is 12 nn by 7 * sqrt(3) nn
dz = nn * np.sqrt(2.0 / 3.0)
offsets = {0: np.array([0.0, 0.0]), 1: np.array([nn / 2, nn / (2 * np.sqrt(3))]),
           2: np.array([nn, nn / np.sqrt(3)])}


def layers(steps, noise, seed):
    """Positions of the layers whose stacking positions follow `steps` (+1 or -1 each)."""
    pos, out = 0, []
    for z, step in enumerate([0] + steps[:-1]):
        pos = (pos + step) % 3
        for i in range(nx):
            for j in range(2 * ny):
                x = i * nn + (j % 2) * nn / 2
                y = j * nn * np.sqrt(3) / 2
                out.append([x + offsets[pos][0], y + offsets[pos][1], z * dz])
    rng = np.random.default_rng(seed)
    p = np.array(out)
    L = np.array([nx * nn, ny * nn * np.sqrt(3), len(steps) * dz])
    return (p + rng.normal(0, noise, p.shape)) % L, L


cases = []
for name, steps, seed in [
    # A skipped step (+2) is an intrinsic stacking fault; the stack must close: sum = 0 mod 3.
    ("faults.xyz", [1] * 4 + [2] + [1] * 8 + [2] + [1] * 5, 21),
    ("twins.xyz", [1] * 9 + [-1] * 9, 22),
]:
    assert sum(steps) % 3 == 0
    p, L = layers(steps, 0.03, seed)
    ovito_single.write(os.path.join(here, name), np.diag(L), p, "Cu")
    case = {"file": name}
    for handle in [True, False]:
        pipe = import_file(os.path.join(here, name), columns=ovito_single.COLUMNS)
        pipe.modifiers.append(PolyhedralTemplateMatchingModifier(output_orientation=True))
        pipe.modifiers.append(GrainSegmentationModifier(handle_stacking_faults=handle))
        data = pipe.compute()
        key = "faults_joined" if handle else "faults_separate"
        case[key] = {"grain": data.particles["Grain"][...].tolist(),
                     "grain_size": data.tables["grains"]["Grain Size"][...].tolist(),
                     "structure": data.particles["Structure Type"][...].tolist()}
        print(name, key, case[key]["grain_size"])
    cases.append(case)
with open(os.path.join(here, "faults_reference.json"), "w") as out:
    json.dump(cases, out)
    out.write("\n")

"""Point defects in iron written by OVITO, and OVITO's Wigner-Seitz analysis of them, for
tests/wigner_seitz.rs.

ref.xyz: BCC iron (a = 2.87 A), 10^3 cells (2,000 sites), periodic, thermal noise of 0.05 A
(seed 9). cur.xyz: the same atoms after a damage event, with new noise: six Frenkel pairs (an
atom moved from its site to an octahedral interstitial position far away), one <110> split
dumbbell (two atoms 0.9 A either side of a site), a replacement sequence of four atoms along
[111] (each to the next site, the last to an interstitial position), two atoms sputtered away
(removed: the frame has 1,998 atoms), the box expanded by 1 % with the atoms (NPT), and every
atom wrapped into the box. Both as extended XYZ written by ovito.io.export_file.
ws_reference.json: OVITO 3.17's WignerSeitzAnalysisModifier with cur.xyz's frame against
ref.xyz (affine mapping to the reference): each site's "Occupancy" (sites mode), each atom's
"Site Index" (output_displaced), and OVITO's vacancy and interstitial counts.

    pip install ovito==3.17.2
    python3 gen_ws.py
"""
import json
import os
import sys

import numpy as np
from ovito.io import import_file
from ovito.modifiers import WignerSeitzAnalysisModifier
from ovito.pipeline import FileSource, ReferenceConfigurationModifier

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(here))
import ovito_single  # noqa: E402
COLUMNS = ovito_single.COLUMNS


def write(name, cell, positions):
    ovito_single.write(os.path.join(here, name), cell, positions, "Fe")


a, n = 2.87, 10
L = a * n
base = np.array([[0, 0, 0], [0.5, 0.5, 0.5]]) + 0.1
sites = np.array([(np.array([i, j, k]) + b) * a for i in range(n) for j in range(n)
                  for k in range(n) for b in base])
rng = np.random.default_rng(9)
ref = sites + rng.normal(0, 0.05, sites.shape)
write("ref.xyz", np.diag([L, L, L]), ref)

cur = sites.copy()
# Frenkel pairs: atom k to an octahedral position (half a lattice constant along x from a site
# far away).
movers = [17, 333, 871, 1204, 1500, 1999]
targets = [905, 1402, 77, 650, 222, 1111]
for k, t in zip(movers, targets):
    cur[k] = sites[t] + np.array([a / 2, 0, 0])
# A <110> dumbbell: site 444's atom and one extra from site 1600 split around site 444.
d = np.array([1, 1, 0]) / np.sqrt(2) * 0.9
cur[444] = sites[444] + d
cur[1600] = sites[444] - d
# A replacement sequence along [111]: site s -> s + a/2 (1,1,1), four times.
step = np.array([a / 2, a / 2, a / 2])
start = sites[1000]
chain = [int(np.argmin(np.linalg.norm(sites - (start + m * step), axis=1))) for m in range(4)]
for m, k in enumerate(chain):
    cur[k] = start + (m + 1) * step + (np.array([0.4, -0.3, 0.1]) if m == 3 else 0)
cur += rng.normal(0, 0.05, cur.shape)
# Two atoms sputtered away.
cur = np.delete(cur, [5, 1234], axis=0)
# NPT: the box and the atoms expanded by 1 %, then wrapped.
cur *= 1.01
L2 = L * 1.01
cur -= L2 * np.floor(cur / L2)
write("cur.xyz", np.diag([L2, L2, L2]), cur)

result = {}
for mode in ["sites", "atoms"]:
    pipe = import_file(os.path.join(here, "cur.xyz"), columns=COLUMNS)
    mod = WignerSeitzAnalysisModifier(
        affine_mapping=ReferenceConfigurationModifier.AffineMapping.ToReference,
        output_displaced=(mode == "atoms"))
    mod.reference = FileSource()
    mod.reference.load(os.path.join(here, "ref.xyz"), columns=COLUMNS)
    pipe.modifiers.append(mod)
    data = pipe.compute()
    if mode == "sites":
        result["occupancy"] = data.particles["Occupancy"][...].tolist()
        result["vacancies"] = int(data.attributes["WignerSeitz.vacancy_count"])
        result["interstitials"] = int(data.attributes["WignerSeitz.interstitial_count"])
    else:
        result["site"] = data.particles["Site Index"][...].tolist()
        result["atom_occupancy"] = data.particles["Occupancy"][...].tolist()
with open(os.path.join(here, "ws_reference.json"), "w") as out:
    json.dump(result, out)
    out.write("\n")

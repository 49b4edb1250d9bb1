"""OVITO's Slice modifier on the first crystal of crystals.xyz.gz (see gen_cna.py), for
md-scene's tests/analysis.rs.

slice_reference.json: per configuration (normal, distance, slab width, inverse), the indices of
the atoms OVITO 3.17's SliceModifier keeps, in order.

    pip install ovito==3.17.2
    python3 gen_slice.py
"""
import json
import os

import numpy as np
from ovito.io import import_file
from ovito.modifiers import SliceModifier

here = os.path.dirname(os.path.abspath(__file__))
pipe = import_file(os.path.join(here, "crystals.xyz.gz"))
original = np.array(pipe.compute(0).particles.positions)
modifier = SliceModifier()
pipe.modifiers.append(modifier)
configs = []
for normal, distance, width, inverse in [
    ((1, 1, 1), 12.0, 0.0, False),
    ((1, 1, 1), 12.0, 0.0, True),
    ((1, 1, 1), 20.0, 4.0, False),
    ((1, 1, 1), 20.0, 4.0, True),
    ((0, 0, 2), 10.0, 3.0, False),
    ((1, -2, 0.5), -3.0, 0.0, False),
]:
    modifier.normal = normal
    modifier.distance = distance
    modifier.slab_width = width
    modifier.inverse = inverse
    kept = np.array(pipe.compute(0).particles.positions)
    index = {tuple(p): i for i, p in enumerate(original)}
    configs.append({
        "normal": list(normal),
        "distance": distance,
        "width": width,
        "inverse": inverse,
        "kept": [index[tuple(p)] for p in kept],
    })
with open(os.path.join(here, "slice_reference.json"), "w") as out:
    json.dump({"configs": configs}, out)
    out.write("\n")

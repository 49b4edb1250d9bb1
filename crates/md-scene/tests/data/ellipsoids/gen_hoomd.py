"""A HOOMD-blue GSD file of ellipsoids, for the ellipsoids tests, and what OVITO reads from it.

- `hoomd_ellipsoids.gsd`: written by gsd 5.0.1 (`gsd.hoomd`): 40 particles of two types, `E`
  an ellipsoid (type_shapes `{"type": "Ellipsoid", "a": 1.5, "b": 0.6, "c": 0.4}`, semi-axes)
  and `S` a sphere (`{"type": "Sphere", "diameter": 1.0}`), random orientations, two frames
  (the second turns every particle; type_shapes in frame 0 only, as writers do).
- `hoomd_read.json`: per frame, OVITO 3.17.2's "Aspherical Shape" (semi-axes) and
  "Orientation" (x, y, z, w) of each particle after reading the GSD file.

Run: `pip install gsd==5.0.1 ovito==3.17.2; python3 gen_hoomd.py`.
"""
import json

import gsd.hoomd
import numpy as np
from ovito.io import import_file

rng = np.random.default_rng(5)
n, L = 40, 16.0
pos = rng.uniform(-L / 2 + 1, L / 2 - 1, (n, 3)).astype(np.float32)
types = (np.arange(n) % 2).astype(np.uint32)


def quats():
    q = rng.normal(size=(n, 4))
    return (q / np.linalg.norm(q, axis=1)[:, None]).astype(np.float32)  # w, x, y, z (HOOMD)


with gsd.hoomd.open("hoomd_ellipsoids.gsd", "w") as f:
    for k in range(2):
        s = gsd.hoomd.Frame()
        s.configuration.step = 1000 * k
        s.configuration.box = [L, L, L, 0, 0, 0]
        s.particles.N = n
        s.particles.position = pos + k * 0.5
        s.particles.orientation = quats()
        if k == 0:
            s.particles.types = ["E", "S"]
            s.particles.typeid = types
            s.particles.type_shapes = [
                {"type": "Ellipsoid", "a": 1.5, "b": 0.6, "c": 0.4},
                {"type": "Sphere", "diameter": 1.0},
            ]
        f.append(s)

pipeline = import_file("hoomd_ellipsoids.gsd")
frames = []
for k in range(pipeline.source.num_frames):
    d = pipeline.compute(k)
    shape = d.particles["Aspherical Shape"][...] if "Aspherical Shape" in d.particles else None
    frames.append({
        "semi_axes": shape.tolist() if shape is not None else None,
        "orientation_xyzw": d.particles["Orientation"][...].tolist(),
    })
with open("hoomd_read.json", "w") as f:
    json.dump(frames, f)
print([None if fr["semi_axes"] is None else fr["semi_axes"][:2] for fr in frames])

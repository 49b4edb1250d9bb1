"""Polycrystals written by OVITO, and OVITO's lattice orientations and grains of them, for
tests/grains.rs.

Each file is a periodic cube filled by the Voronoi construction: grains seeded at random
points (numpy seed per file), each a crystal turned by a random rotation, an atom kept where
its grain's seed is the nearest (nearest periodic image), one of any two atoms closer than 0.7
nearest-neighbour distances dropped, then thermal noise. As extended XYZ by
ovito.io.export_file:

- fcc_poly.xyz: aluminium, a = 4.05 A, 52 A cube, 6 grains, noise 0.04 A;
- bcc_poly.xyz: iron, a = 2.87 A, 40 A cube, 4 grains, noise 0.03 A;
- hcp_poly.xyz: magnesium, a = 3.21 A, c = 5.21 A, 46 A cube, 4 grains, noise 0.03 A.

grains_reference.json, per file, from OVITO 3.17's PolyhedralTemplateMatchingModifier
(defaults: FCC, HCP, BCC; output_orientation, output_rmsd) and GrainSegmentationModifier
(defaults): every atom's "Structure Type", "Orientation" (x, y, z, w) and "RMSD", its "Grain"
(-1: none), and the grain table's sizes, structure types and orientations. "pairs": random
orientation pairs with PolyhedralTemplateMatchingModifier.calculate_misorientation's
disorientation angle (radians) for cubic and hexagonal symmetry.

    pip install ovito==3.17.2
    python3 gen_grains.py
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


def random_rotation(rng):
    q = rng.normal(size=4)
    x, y, z, w = q / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def polycrystal(rng, L, grains, lattice, basis, nn, noise):
    """Atoms of `grains` Voronoi grains in a periodic cube of side L; `lattice` rows are the
    cell vectors, `basis` fractional sites, `nn` the nearest-neighbour distance."""
    seeds = rng.uniform(0, L, (grains, 3))
    reach = int(np.ceil(L / np.min(np.linalg.norm(lattice, axis=1)))) + 1
    idx = np.array([(i, j, k) for i in range(-reach, reach + 1)
                    for j in range(-reach, reach + 1) for k in range(-reach, reach + 1)], float)
    local = (idx[:, None, :] + basis[None, :, :]).reshape(-1, 3) @ lattice
    atoms = []
    for g in range(grains):
        p = local @ random_rotation(rng).T
        # One copy of each site: the cube of side L around the seed (nearest images).
        p = p[((p >= -L / 2) & (p < L / 2)).all(axis=1)]
        p = (p + seeds[g]) % L
        d = p[:, None, :] - seeds[None, :, :]
        d -= L * np.round(d / L)
        keep = np.argmin((d * d).sum(axis=2), axis=1) == g
        atoms.append(p[keep])
    atoms = np.concatenate(atoms)
    kept = []
    cell = int(L // nn)
    buckets = {}
    for i, p in enumerate(atoms):
        c = tuple((p // (L / cell)).astype(int) % cell)
        close = False
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for dz in (-1, 0, 1):
                    for j in buckets.get(((c[0] + dx) % cell, (c[1] + dy) % cell,
                                          (c[2] + dz) % cell), []):
                        d = atoms[j] - p
                        d -= L * np.round(d / L)
                        if d @ d < (0.7 * nn) ** 2:
                            close = True
        if not close:
            buckets.setdefault(c, []).append(i)
            kept.append(i)
    atoms = atoms[kept]
    return (atoms + rng.normal(0, noise, atoms.shape)) % L


fcc = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]])
bcc = np.array([[0, 0, 0], [0.5, 0.5, 0.5]])
a, c = 3.21, 5.21
hex_cell = np.array([[a, 0, 0], [-a / 2, a * np.sqrt(3) / 2, 0], [0, 0, c]])
hcp = np.array([[0, 0, 0], [1 / 3, 2 / 3, 0.5]])
systems = [
    ("fcc_poly.xyz", "Al", 52.0, 6, np.eye(3) * 4.05, fcc, 4.05 / np.sqrt(2), 0.04, 11),
    ("bcc_poly.xyz", "Fe", 40.0, 4, np.eye(3) * 2.87, bcc, 2.87 * np.sqrt(3) / 2, 0.03, 12),
    ("hcp_poly.xyz", "Mg", 46.0, 4, hex_cell, hcp, a, 0.03, 13),
]
cases = []
for name, element, L, grains, lattice, basis, nn, noise, seed in systems:
    rng = np.random.default_rng(seed)
    atoms = polycrystal(rng, L, grains, lattice, basis, nn, noise)
    ovito_single.write(os.path.join(here, name), np.diag([L, L, L]), atoms, element)
    pipe = import_file(os.path.join(here, name), columns=ovito_single.COLUMNS)
    pipe.modifiers.append(PolyhedralTemplateMatchingModifier(output_orientation=True,
                                                             output_rmsd=True))
    pipe.modifiers.append(GrainSegmentationModifier())
    data = pipe.compute()
    p = data.particles
    table = data.tables["grains"]
    cases.append({
        "file": name,
        "structure": p["Structure Type"][...].tolist(),
        "orientation": p["Orientation"][...].tolist(),
        "rmsd": p["RMSD"][...].tolist(),
        "grain": p["Grain"][...].tolist(),
        "grain_size": table["Grain Size"][...].tolist(),
        "grain_structure": table["Structure Type"][...].tolist(),
        "grain_orientation": table["Orientation"][...].tolist(),
    })
    print(name, len(atoms), "atoms,", len(table["Grain Size"]), "grains",
          table["Grain Size"][...].tolist())

rng = np.random.default_rng(14)
qa = rng.normal(size=(200, 4))
qa /= np.linalg.norm(qa, axis=1)[:, None]
qb = rng.normal(size=(200, 4))
qb /= np.linalg.norm(qb, axis=1)[:, None]
pairs = {"a": qa.tolist(), "b": qb.tolist()}
for sym in ["cubic", "hexagonal"]:
    pairs[sym] = PolyhedralTemplateMatchingModifier.calculate_misorientation(
        qa, qb, symmetry=sym).tolist()
with open(os.path.join(here, "grains_reference.json"), "w") as out:
    json.dump({"systems": cases, "pairs": pairs}, out)
    out.write("\n")

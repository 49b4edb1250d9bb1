"""Reference areas and volumes of a Gaussian molecular surface, for tests/surface.rs.

The density of md_scene::surface (one Gaussian per atom, sigma = r / sqrt(2 ln(1/iso)), so an
isolated atom's surface is its van der Waals sphere) is summed here with numpy on a fine grid
(each Gaussian to 6 sigma, where it is below 1e-7 of its peak) and the isosurface is extracted by
scikit-image's Lewiner marching cubes; areas by skimage's mesh_surface_area, volumes by the
divergence theorem. Atoms: wwPDB 2XCJ chain A's ATOM/HETATM records, radii from ASE's
vdw_alvarez table (the one texmap-md-io's elements come from).
"""
import json

import gzip
import numpy as np
import skimage
from ase.data import atomic_numbers, vdw_alvarez
from skimage.measure import marching_cubes, mesh_surface_area

ISO = 0.5
PDB = "../../../md-io/tests/data/dssp/2xcjA.pdb.gz"


def density(centers, radii, h, reach=6.0):
    k = np.sqrt(2.0 * np.log(1.0 / ISO))
    sigma = radii / k
    lo = (centers - reach * sigma[:, None]).min(axis=0) - 2 * h
    hi = (centers + reach * sigma[:, None]).max(axis=0) + 2 * h
    n = np.ceil((hi - lo) / h).astype(int) + 1
    rho = np.zeros(n[::-1])  # z, y, x
    axes = [lo[a] + h * np.arange(n[a]) for a in range(3)]
    for c, s in zip(centers, sigma):
        f = []
        sl = []
        for a in range(3):
            i0 = max(int(np.ceil((c[a] - reach * s - lo[a]) / h)), 0)
            i1 = min(int(np.floor((c[a] + reach * s - lo[a]) / h)), n[a] - 1)
            d = axes[a][i0 : i1 + 1] - c[a]
            f.append(np.exp(-d * d / (2 * s * s)))
            sl.append(slice(i0, i1 + 1))
        rho[sl[2], sl[1], sl[0]] += f[2][:, None, None] * f[1][None, :, None] * f[0][None, None, :]
    return rho, lo


def measure(centers, radii, h):
    rho, lo = density(centers, radii, h)
    verts, faces, _, _ = marching_cubes(rho, ISO, spacing=(h, h, h), method="lewiner")
    verts = verts[:, ::-1] + lo  # z, y, x -> x, y, z
    area = mesh_surface_area(verts, faces)
    a, b, c = verts[faces[:, 0]], verts[faces[:, 1]], verts[faces[:, 2]]
    volume = abs(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)
    return float(area), float(volume), len(faces)


rows = [l for l in gzip.open(PDB, "rt") if l.startswith(("ATOM", "HETATM"))]
centers = np.array([[float(l[30:38]), float(l[38:46]), float(l[46:54])] for l in rows])
elements = [(l[76:78].strip() or l[12:14].strip()).capitalize() for l in rows]
radii = np.array([vdw_alvarez.vdw_radii[atomic_numbers[e]] for e in elements])
out = {
    "source": "wwPDB 2XCJ chain A (ATOM/HETATM records), radii ase.data.vdw_alvarez, scikit-image %s marching cubes"
    % skimage.__version__,
    "isovalue": ISO,
    "centers": np.round(centers, 3).tolist(),
    "radii": radii.tolist(),
    "reference": [],
}
for h in (0.3, 0.2, 0.15):
    area, volume, faces = measure(np.round(centers, 3), radii, h)
    print(f"h {h}: area {area:.2f} volume {volume:.2f} triangles {faces}")
    out["reference"].append({"spacing": h, "area": area, "volume": volume, "triangles": faces})
with open("surface_reference.json", "w") as f:
    json.dump(out, f)

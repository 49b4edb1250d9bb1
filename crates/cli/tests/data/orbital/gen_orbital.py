"""Writes formaldehyde's HOMO as a Gaussian cube file with PySCF (RHF/6-31G), and what
scikit-image's marching cubes makes of it (the data read back by ASE's cube reader) at the
tests' level: the reference the CLI test compares texmap's isosurface with.

    python3 gen_orbital.py   # PySCF 2.14, ASE 3.29, scikit-image 0.26, numpy

Outputs (beside this script): h2co_homo.cube.gz (gzip of PySCF's cube), reference.json.
"""
import gzip, json, os, shutil
import numpy as np
from pyscf import gto, scf
from pyscf.tools import cubegen
from skimage import measure

here = os.path.dirname(os.path.abspath(__file__))
mol = gto.M(
    atom="""C 0.000 0.000 -0.529
            O 0.000 0.000  0.677
            H 0.000 0.935 -1.116
            H 0.000 -0.935 -1.116""",
    basis="6-31g",
    unit="Angstrom",
)
mf = scf.RHF(mol).run()
homo = mol.nelectron // 2 - 1
cube = os.path.join(here, "h2co_homo.cube")
cubegen.orbital(mol, cube, mf.mo_coeff[:, homo], nx=36, ny=34, nz=40, margin=3.5)
with open(cube, "rb") as f, gzip.open(cube + ".gz", "wb", compresslevel=9) as g:
    shutil.copyfileobj(f, g)

# Read the cube back with ASE's reader (another program's) and run marching cubes on each sign.
from ase.io.cube import read_cube
with open(cube) as f:
    got = read_cube(f)
os.remove(cube)
data = got["data"]  # (nx, ny, nz), z fastest
spacing = np.asarray(got["spacing"])  # rows: the axes' steps in Å
assert np.allclose(spacing, np.diag(np.diag(spacing)))
step = np.diag(spacing)
level = 0.05
out = {"level": level, "shape": list(data.shape), "min": float(data.min()), "max": float(data.max())}
for name, field in (("positive", data), ("negative", -data)):
    # Padded with a low value so that marching cubes would close a lobe at the grid's border
    # as texmap does (these lobes stay inside the grid).
    padded = np.pad(field, 1, constant_values=-1.0)
    verts, faces, _, _ = measure.marching_cubes(padded, level, spacing=tuple(step))
    area = measure.mesh_surface_area(verts, faces)
    tri = verts[faces]
    vol = abs(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0)
    out[name] = {"area": float(area), "volume": float(vol), "triangles": int(len(faces))}
bohr = 0.529177210903
out["atoms"] = [[a[0], *(np.array(a[1]) * bohr).tolist()] for a in mol._atom]
with open(os.path.join(here, "reference.json"), "w") as f:
    json.dump(out, f, indent=1)
print(json.dumps(out, indent=1))

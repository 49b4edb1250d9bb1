"""Formaldehyde's electron density and electrostatic potential as PySCF writes them to Gaussian
cube files (RHF/6-31G, cubegen.density and cubegen.mep on the same 30 x 30 x 32 grid), and the
exact potential PySCF evaluates at points between the grid points: what interpolating the
cube must approximate (md-io's Volume::interpolate, the ESP-coloured isosurface).

    python3 gen_esp.py   # PySCF 2.14, numpy

Outputs (beside this script): h2co_density.cube.gz, h2co_esp.cube.gz, esp_points.json.
"""
import gzip, json, os, shutil
import numpy as np
from pyscf import gto, scf
from pyscf.tools import cubegen

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
dm = mf.make_rdm1()
shape = dict(nx=30, ny=30, nz=32, margin=5.0)
for name, write in (("density", cubegen.density), ("esp", cubegen.mep)):
    path = os.path.join(here, f"h2co_{name}.cube")
    write(mol, path, dm, **shape)
    with open(path, "rb") as f, gzip.open(path + ".gz", "wb", compresslevel=9) as g:
        shutil.copyfileobj(f, g)
    os.remove(path)

# The exact potential at points between grid points (Bohr inside PySCF, Å in the file):
# nuclei minus electrons, as cubegen.mep computes it at the grid points.
c = cubegen.Cube(mol, **shape)
rng = np.random.default_rng(7)
lo, box = c.boxorig, np.diag(c.box)
pts = lo + box * (0.15 + 0.7 * rng.random((24, 3)))
from pyscf import df

fakemol = gto.fakemol_for_charges(pts)
vele = np.einsum("ijp,ij->p", df.incore.aux_e2(mol, fakemol), dm)
vnuc = sum(
    z / np.linalg.norm(pts - r, axis=1) for z, r in zip(mol.atom_charges(), mol.atom_coords())
)
esp = vnuc - vele
bohr = 0.529177210903
out = {
    "points_angstrom": (pts * bohr).tolist(),
    "esp_hartree_per_e": esp.tolist(),
}
with open(os.path.join(here, "esp_points.json"), "w") as f:
    json.dump(out, f, indent=1)
print(len(pts), "points; esp range", esp.min(), esp.max())

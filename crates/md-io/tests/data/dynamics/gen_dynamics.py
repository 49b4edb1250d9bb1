"""MDAnalysis 2.11.0's mean squared displacement and RMSD: references for `--msd-table` and
`--rmsd-table` (crates/cli/tests/convert.rs).

Run from this directory: python3 gen_dynamics.py

- walk.gro + walk.dcd (written by MDAnalysis): 300 atoms (200 named OW in residues SOL, 100
  named NA in residues NA) on Gaussian random walks (0.7 A per axis per frame) in a periodic
  18 A cube, 40 frames, every position wrapped into the box, so atoms cross the faces many times.
  msd_reference.json holds, per frame, the mean squared displacement from frame 0 of all atoms,
  of the OW and of the NA atoms, after MDAnalysis's NoJump transformation unwraps the walk.
- msd_lags_reference.json: MDAnalysis's EinsteinMSD (msd_type xyz, fft=False: the direct sum
  over every origin) of the same unwrapped walk for all atoms, the OW and the NA atoms, with
  its lag times, and the diffusion coefficient of each (numpy's least-squares line over lag
  times from 10 % to 90 % of the longest, slope / 6, in 10^-5 cm^2/s), as gmx msd fits it.
- rmsf_reference.json: MDAnalysis's rms.RMSF of every atom of topo_mda.xtc (with topo_mda.gro)
  after align.AlignTraj superposes all its frames on frame 0 by all atoms, unweighted.
- profile_reference.json: MDAnalysis's LinearDensity of the walk along z in 0.25 A bins (72
  across the 18 A box), grouping by atoms, averaged over the 40 frames: the mass density
  (g/cm^3) of all atoms and of the OW and NA atoms, with the bins' edges and the masses
  MDAnalysis guessed.
- rmsd_reference.json: MDAnalysis's rms.RMSD of md-io's topo_mda.xtc (with topo_mda.gro) on
  all atoms against frame 0, unweighted and mass-weighted (results.rmsd's third column).
"""
import json

import numpy as np
import MDAnalysis as mda
from MDAnalysis.analysis import align, rms
from MDAnalysis.analysis.msd import EinsteinMSD
from MDAnalysis.analysis.lineardensity import LinearDensity
from MDAnalysis.transformations import NoJump

rng = np.random.default_rng(61206)
n_ow, n_na, frames, box = 200, 100, 40, 18.0
n = n_ow + n_na
u = mda.Universe.empty(n, n_residues=n, atom_resindex=np.arange(n), trajectory=True)
u.add_TopologyAttr("name", ["OW"] * n_ow + ["NA"] * n_na)
u.add_TopologyAttr("resname", ["SOL"] * n_ow + ["NA"] * n_na)
u.add_TopologyAttr("resid", np.arange(1, n + 1))
u.dimensions = [box, box, box, 90, 90, 90]
true = rng.random((n, 3)) * box
u.atoms.positions = true % box
u.atoms.write("walk.gro")
with mda.Writer("walk.dcd", n) as w:
    for f in range(frames):
        u.atoms.positions = true % box
        u.dimensions = [box, box, box, 90, 90, 90]
        w.write(u.atoms)
        true = true + rng.normal(0.0, 0.7, size=(n, 3))

walk = mda.Universe("walk.gro", "walk.dcd")
walk.trajectory.add_transformations(NoJump())
ow = walk.select_atoms("name OW")
na = walk.select_atoms("name NA")
origin = None
rows = []
for ts in walk.trajectory:
    p = walk.atoms.positions.astype(np.float64)
    if origin is None:
        origin = p.copy()
    d2 = ((p - origin) ** 2).sum(axis=1)
    rows.append({"frame": ts.frame, "msd": d2.mean(), "msd_OW": d2[ow.indices].mean(),
                 "msd_NA": d2[na.indices].mean()})
json.dump(rows, open("msd_reference.json", "w"), indent=1)
print("msd at the last frame:", rows[-1])

lags = {}
for key, sel in [("msd", "all"), ("msd_OW", "name OW"), ("msd_NA", "name NA")]:
    walk = mda.Universe("walk.gro", "walk.dcd")
    walk.trajectory.add_transformations(NoJump())
    m = EinsteinMSD(walk, select=sel, msd_type="xyz", fft=False).run()
    curve = m.results.timeseries
    time = np.arange(m.n_frames) * walk.trajectory.dt
    window = (time >= 0.1 * time[-1]) & (time <= 0.9 * time[-1])
    slope = np.polyfit(time[window], curve[window], 1)[0]
    lags[key] = curve.tolist()
    lags["time"] = time.tolist()
    lags["D_" + key] = slope / 6.0 * 10.0
json.dump(lags, open("msd_lags_reference.json", "w"), indent=1)
print("D (1e-5 cm^2/s):", {k: v for k, v in lags.items() if k.startswith("D_")})

topo = mda.Universe("../topo_mda.gro", "../topo_mda.xtc")
plain = rms.RMSD(topo, select="all").run().results.rmsd[:, 2].tolist()
mass = rms.RMSD(topo, select="all", weights="mass").run().results.rmsd[:, 2].tolist()
json.dump({"rmsd": plain, "rmsd_mass": mass}, open("rmsd_reference.json", "w"), indent=1)
print("rmsd:", plain, mass)

mobile = mda.Universe("../topo_mda.gro", "../topo_mda.xtc")
reference = mda.Universe("../topo_mda.gro", "../topo_mda.xtc")
align.AlignTraj(mobile, reference, select="all", in_memory=True).run()
fluct = rms.RMSF(mobile.atoms).run().results.rmsf
json.dump({"rmsf": fluct.tolist()}, open("rmsf_reference.json", "w"), indent=1)
print("rmsf: atoms", len(fluct), "mean", fluct.mean(), "max", fluct.max())

profile = {}
for key, sel in [("mass", "all"), ("mass_OW", "name OW"), ("mass_NA", "name NA")]:
    walk = mda.Universe("walk.gro", "walk.dcd")
    walk.add_TopologyAttr("charges", np.zeros(walk.atoms.n_atoms))
    atoms = walk.select_atoms(sel)
    density = LinearDensity(atoms, grouping="atoms", binsize=0.25).run()
    profile[key] = density.results.z.mass_density.tolist()
    profile["edges"] = density.results.z.hist_bin_edges.tolist()
    profile["masses_" + key] = sorted(set(atoms.masses.tolist()))
json.dump(profile, open("profile_reference.json", "w"), indent=1)
print("profile: bins", len(profile["mass"]), "masses", profile["masses_mass"],
      "mean mass density", np.mean(profile["mass"]))

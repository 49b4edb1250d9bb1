"""GROMACS 2022.5's gmx cluster: the reference for md-io's `conformations` and
`texmap convert --clusters` (crates/md-io/tests/conformations.rs, crates/cli/tests/convert.rs).

Run from this directory (needs MDAnalysis, scipy and gmx on the PATH; Debian's `gromacs`
package): python3 gen_clusters.py

- states.xtc (written by MDAnalysis): the 185 atoms of ../dihedrals/helix.pdb (PDB 3JQH's
  23-residue helix) over 200 frames, 5 ps apart. The helix dwells in one of four shapes
  (straight; bent one way; bent across and twisted; twisted the other way) for 8 to 30 frames,
  then moves to the next over 3 frames; every frame adds seeded Gaussian noise of 0.3 A per
  axis on every atom, then turns and moves the whole molecule at random, so that only a
  superposition recovers the shape.
- ca.ndx: the 23 CA atoms, the group gmx cluster fits and measures.
- clusters_reference.json: for each run, what gmx cluster wrote
  (`gmx cluster -f states.xtc -s ../dihedrals/helix.pdb -n ca.ndx -method M -cutoff C`, the
  CA group for the fit and the output): every frame's cluster (-clid), and from cluster.log
  each cluster's size, middle structure (the member with the smallest mean RMSD to the
  others) and that mean, the cluster's mean RMSD, and its members, all as frame numbers.
- gmx_clid.xvg: the first run's -clid file as gmx wrote it (for `texmap plot`'s test).

The runs are chosen so that the answer does not hang on what gmx leaves open: the gromos method
finds the same clusters however it breaks a tie between the structures with the most
neighbours (gmx sorts them with an unstable sort: which one it takes is not defined), and no pair's RMSD (MDAnalysis's, in
double precision) lies within 0.0002 A of the cutoff (gmx computes in single precision): from
the cutoff wanted, the script takes the first in steps of 0.0005 nm that meets both (checked
with its own RMSD matrix and its own reading of the method, breaking the ties 32 ways). Only
the numbering of clusters of equal size is then gmx's choice.
"""
import json
import os
import re
import subprocess
import tempfile
import warnings

import numpy as np
import MDAnalysis as mda
from MDAnalysis.analysis import rms
from scipy.spatial.transform import Rotation

warnings.simplefilter("ignore")
HERE = os.path.dirname(os.path.abspath(__file__))
PDB = os.path.join(HERE, "..", "dihedrals", "helix.pdb")
XTC = os.path.join(HERE, "states.xtc")
NDX = os.path.join(HERE, "ca.ndx")
FRAMES = 200
DT = 5.0
# (method, the cutoff wanted in nm): each run takes the first cutoff from there up in steps of
# 0.0005 nm that meets the conditions below.
RUNS = [("gromos", 0.08), ("gromos", 0.1), ("linkage", 0.06)]
MARGIN = 2e-4
NOISE = 0.25


def write_trajectory():
    rng = np.random.default_rng(20261206)
    u = mda.Universe(PDB)
    atoms = u.atoms
    base = atoms.positions.astype(np.float64)
    centre = base.mean(axis=0)
    ca = u.select_atoms("name CA").positions.astype(np.float64)
    w, v = np.linalg.eigh(np.cov((ca - ca.mean(axis=0)).T))
    axis, across, other = v[:, -1], v[:, -2], v[:, -3]
    s = (base - centre) @ axis
    s /= np.abs(s).max()
    # (bend along `across`, bend along `other`, twist in radians at the ends)
    states = [(0.0, 0.0, 0.0), (7.0, 0.0, 0.0), (0.0, -6.0, 0.5), (0.0, 0.0, -0.9)]

    def shape(b1, b2, tw):
        p = base - centre
        p = p + b1 * (s ** 2)[:, None] * across[None, :] + b2 * (s ** 2)[:, None] * other[None, :]
        for i in range(len(p)):
            p[i] = Rotation.from_rotvec(tw * s[i] * axis).apply(p[i])
        return p

    # The sequence of shapes: dwell, then a 3-frame move to the next.
    params = []
    state = 0
    while len(params) < FRAMES:
        for _ in range(int(rng.integers(8, 31))):
            params.append(states[state])
        nxt = int(rng.choice([k for k in range(4) if k != state]))
        for t in (0.25, 0.5, 0.75):
            a, b = np.array(states[state]), np.array(states[nxt])
            params.append(tuple((1 - t) * a + t * b))
        state = nxt
    params = params[:FRAMES]
    with mda.Writer(XTC, atoms.n_atoms) as out:
        for f, (b1, b2, tw) in enumerate(params):
            p = shape(b1, b2, tw)
            p += rng.normal(0.0, NOISE, size=p.shape)
            p = Rotation.random(random_state=rng.integers(1 << 31)).apply(p)
            p += centre + rng.normal(0.0, 3.0, size=3)
            atoms.positions = p
            u.trajectory.ts.time = f * DT
            u.trajectory.ts.frame = f
            out.write(atoms)
    ids = u.select_atoms("name CA").indices
    with open(NDX, "w") as f:
        f.write("[ CA ]\n" + " ".join(str(i + 1) for i in ids) + "\n")


def matrix():
    u = mda.Universe(PDB, XTC)
    ca = u.select_atoms("name CA")
    xs = [ca.positions.astype(np.float64).copy() for _ in u.trajectory]
    n = len(xs)
    m = np.zeros((n, n))
    for i in range(n):
        for j in range(i + 1, n):
            m[i, j] = m[j, i] = rms.rmsd(xs[i], xs[j], center=True, superposition=True)
    return m


def gromos(m, cut, pick):
    """Our own reading of Daura et al.: the partition, as sets of frames; `pick` chooses among
    the structures that tie for the most neighbours."""
    left = np.ones(len(m), bool)
    near = m < cut
    parts = []
    while left.any():
        counts = (near & left[None, :]).sum(axis=1) * left
        top = np.flatnonzero(counts == counts.max())
        centre = pick(top)
        members = near[centre] & left
        parts.append(frozenset(np.flatnonzero(members).tolist()))
        left &= ~members
    return parts


def tie_free(m, cut):
    """Whether every way of breaking the ties (first, last, 30 random) gives one partition."""
    rng = np.random.default_rng(7)
    first = set(gromos(m, cut, lambda top: top[0]))
    picks = [lambda top: top[-1]] + [lambda top: rng.choice(top) for _ in range(30)]
    return all(set(gromos(m, cut, p)) == first for p in picks)


def run_gmx(method, cut_nm, keep_clid=None):
    with tempfile.TemporaryDirectory() as d:
        cmd = ["gmx", "-quiet", "cluster", "-f", XTC, "-s", PDB, "-n", NDX, "-method", method,
               "-cutoff", str(cut_nm), "-g", f"{d}/cl.log", "-clid", f"{d}/clid.xvg",
               "-o", f"{d}/rmsd-clust.xpm", "-dist", f"{d}/dist.xvg"]
        subprocess.run(cmd, input="0\n0\n", text=True, check=True, capture_output=True)
        clid = []
        for line in open(f"{d}/clid.xvg"):
            if line[0] in "#@":
                continue
            t, c = line.split()
            clid.append((round(float(t) / DT), int(c)))
        log = open(f"{d}/cl.log").read()
        if keep_clid:
            with open(f"{d}/clid.xvg") as src, open(keep_clid, "w") as dst:
                dst.write(src.read())
    assert [f for f, _ in clid] == list(range(FRAMES)), clid[:5]
    clusters = []
    for line in log[log.index("cl. |"):].splitlines()[1:]:
        parts = [p.strip() for p in line.split("|")]
        if len(parts) != 4:
            continue
        times = [float(x) for x in parts[3].split()]
        if parts[0]:
            stats = parts[1].split()
            mid = parts[2].split()
            clusters.append({
                "cluster": int(parts[0]),
                "size": int(stats[0]),
                "mean_rmsd_nm": float(stats[1]) if len(stats) > 1 else None,
                "middle": round(float(mid[0]) / DT),
                "middle_rmsd_nm": float(mid[1]) if len(mid) > 1 else None,
                "members": [],
            })
        clusters[-1]["members"] += [round(t / DT) for t in times]
    for c in clusters:
        assert len(c["members"]) == c["size"], c
    version = re.search(r"GROMACS - gmx.*?, (\S+)", subprocess.run(
        ["gmx", "--version"], capture_output=True, text=True).stdout)
    return [c for _, c in clid], clusters, version.group(1) if version else "?"


write_trajectory()
m = matrix()
print("RMSD range", m[np.triu_indices(len(m), 1)].min(), m.max())
out = {"frames": FRAMES, "dt_ps": DT, "select": "name CA", "runs": []}
for method, wanted in RUNS:
    for step in range(40):
        cut_nm = round(wanted + 0.0005 * step, 4)
        cut = 10 * cut_nm
        margin = np.abs(m[np.triu_indices(len(m), 1)] - cut).min()
        if margin > MARGIN and (method != "gromos" or tie_free(m, cut)):
            break
    else:
        raise SystemExit(f"{method}: no cutoff from {wanted} nm meets the conditions")
    keep = os.path.join(HERE, "gmx_clid.xvg") if not out["runs"] else None
    clid, clusters, version = run_gmx(method, cut_nm, keep)
    print(method, cut, "clusters", len(clusters), [c["size"] for c in clusters][:12], "margin", margin)
    out["runs"].append({"method": method, "cutoff_nm": cut_nm, "gmx": version,
                        "cluster_of_frame": clid, "clusters": clusters})
with open(os.path.join(HERE, "clusters_reference.json"), "w") as f:
    json.dump(out, f)
    f.write("\n")

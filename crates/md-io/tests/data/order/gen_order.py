"""Lipid tail order parameters: the reference for md-io's `order` and `texmap convert
--order-table` (crates/md-io/tests/order.rs, crates/cli/tests/convert.rs).

Run from this directory (needs MDAnalysis and numpy; gmx on the PATH for the GROMACS rows:
Debian's `gromacs` package): python3 gen_order.py

- bilayer.gro and bilayer.xtc (written by MDAnalysis): a model bilayer of 32 lipids (residue
  DPPC; 16 per leaflet, heads P at z = 15 and 65 A in an 80 x 80 x 80 A box) over 12 frames.
  Each lipid is a head atom P and two chains of 14 sp3 carbons, C21..C214 and C31..C314, with
  ideal tetrahedral angles, C-C 1.53 A, and two hydrogens per carbon (three on the last) at the
  ideal tetrahedral positions (H2nR/H2nS, H3nR/H3nS, H214T...). Every frame draws each chain
  anew: its first bond tilted up to 20 degrees from the normal, its torsions trans (70 %) or
  gauche +-60 (15 % each), each head moved along z by N(0, 1 A); no two atoms that are not
  bonded within the distance rule of md-io's bond guess (plus 0.2 A), bonded ones 0.2 A inside
  it. The system is shifted by (25, 25, 20) A and wrapped into the box, so lipids on the edges
  are split across it and the upper leaflet's heads sit near z = 5 with its tails across the
  bottom face (the bilayer is 50 A thick through its tails, 30 A through the water).
- reference.json: computed here, with numpy, from the coordinates as MDAnalysis reads them
  back from the XTC (so at the XTC's 0.01 A precision), for the normal z:
  - `hydrogens`: per carbon name, the mean over lipids, frames and the carbon's hydrogens of
    P2 = (3 cos^2 - 1) / 2 of the C-H vector to its nearest image;
  - `united_atom`: per carbon with two heavy neighbours, gmx order's construction
    (z along C(i-1) -> C(i+1), x normal to the three carbons' plane, y = z x x,
    S_CD = 2/3 S_xx + 1/3 S_yy);
  - `bonds`: per bond between two carbons (C21-C22 ...), P2 of the bond;
  - `sem`: for `hydrogens`, the standard error over the 32 lipids of their time averages;
  - `membrane`: MDAnalysis's LeafletFinder (P atoms, cutoff 25 A, pbc=True) on the shifted
    file: each leaflet's residue numbers; the residues of the upper leaflet (z = 65 before the
    shift); per frame the thickness, the mean P height of the upper leaflet minus the lower's
    in the frames before the shift; the box's xy area.
  - `gmx_order`: when gmx is installed, what `gmx order -d z` writes to its -od file (-S_CD)
    for the inner carbons of each chain, from an index group per chain position (its first
    and last group give no value) and a tpr built with grompp from a topology of massive
    points (order needs only the positions). gmx order takes plain differences (it expects
    `trjconv -pbc mol` first), so it reads the frames before the shift, every lipid whole:
    the same order parameters.
"""
import json
import os
import shutil
import subprocess
import tempfile

import numpy as np
import MDAnalysis as mda

RNG = np.random.default_rng(20261207)
BOX = 80.0
NC = 14
TET = np.arccos(-1.0 / 3.0)
CC, CH, PC = 1.53, 1.09, 1.60
FRAMES = 12
# The shift applied to every frame before it is wrapped into the box: lipids on the x and y
# edges and the upper leaflet's tails end up split across the faces.
SHIFT = np.array([25.0, 25.0, 20.0])


def unit(v):
    return v / np.linalg.norm(v)


def place(a, b, c, length, angle, torsion):
    """The atom d bonded to c with |cd| = length, angle bcd and torsion abcd (NeRF)."""
    bc = unit(c - b)
    n = unit(np.cross(b - a, bc))
    m = np.cross(n, bc)
    local = np.array([-length * np.cos(angle),
                      length * np.sin(angle) * np.cos(torsion),
                      length * np.sin(angle) * np.sin(torsion)])
    return c + local[0] * bc + local[1] * m + local[2] * n


def chain(start, down):
    """Carbons of one chain from `start` growing along `down` (+-z)."""
    tilt = np.radians(RNG.uniform(0, 20))
    phi = RNG.uniform(0, 2 * np.pi)
    d0 = np.array([np.sin(tilt) * np.cos(phi), np.sin(tilt) * np.sin(phi), down * np.cos(tilt)])
    c = [start + PC * d0]
    # A virtual atom beside the start sets the first torsion.
    helper = start + unit(np.cross(d0, [1.0, 0.3, 0.2]))
    c.append(place(helper, start, c[0], CC, TET, RNG.uniform(0, 2 * np.pi)))
    for i in range(2, NC):
        r = RNG.random()
        t = 180.0 if r < 0.7 else (60.0 if r < 0.85 else -60.0)
        a = start if i == 2 else c[i - 3]
        c.append(place(a, c[i - 2], c[i - 1], CC, TET, np.radians(t)))
    return np.array(c)


def hydrogens(c, start):
    """Ideal hydrogens of every carbon: two per inner carbon, three on the last."""
    out = []
    for i in range(NC):
        before = start if i == 0 else c[i - 1]
        if i + 1 < NC:
            u, v = unit(before - c[i]), unit(c[i + 1] - c[i])
            bis, perp = unit(u + v), unit(np.cross(u, v))
            h = TET / 2
            out.append([c[i] + CH * (-np.cos(h) * bis + s * np.sin(h) * perp) for s in (1, -1)])
        else:
            # A methyl: staggered about the last C-C bond.
            out.append([place(c[i - 2], c[i - 1], c[i], CH, TET, np.radians(t))
                        for t in (180.0, 60.0, -60.0)])
    return out


RADIUS = {"C": 0.76, "H": 0.31, "P": 1.07}


def chain_atoms(start, down):
    """A chain's atoms (carbon, its hydrogens, next carbon...), elements and bonds."""
    c = chain(start, down)
    hs = hydrogens(c, start)
    pos, el, bonds = [], [], []
    prev = None
    for i in range(NC):
        ci = len(pos)
        pos.append(c[i])
        el.append("C")
        if prev is not None:
            bonds.append((prev, ci))
        prev = ci
        for h in hs[i]:
            bonds.append((ci, len(pos)))
            pos.append(h)
            el.append("H")
    return np.array(pos), el, set(bonds)


def guessed_apart(p, e, q, f):
    """True when no pair of p's and q's atoms (nearest images) is within the bond rule (plus a
    margin for the XTC's rounding)."""
    d = nearest(p[:, None] - q[None])
    r = np.linalg.norm(d, axis=2)
    lim = np.array([[RADIUS[a] + RADIUS[b] + 0.45 + 0.2 for b in f] for a in e])
    return bool(np.all(r > lim))


def chain_fits(p, e, bonds):
    """The distance rule finds exactly the chain's own bonds, with 0.2 A to spare."""
    d = np.linalg.norm(p[:, None] - p[None], axis=2)
    for i in range(len(p)):
        for j in range(i + 1, len(p)):
            limit = RADIUS[e[i]] + RADIUS[e[j]] + 0.45
            if (i, j) in bonds:
                if d[i, j] > limit - 0.2:
                    return False
            elif d[i, j] < limit + 0.2:
                return False
    return True


def lipid_positions(heads):
    """All atoms of every lipid; the bonds the distance rule finds are exactly the chains'."""
    placed_p = [h for h, _ in heads]
    placed = [(np.array(placed_p), ["P"] * len(placed_p))]
    chains = []
    for head, down in heads:
        for _ in range(1000):
            pair = [chain_atoms(head + np.array([xoff, 0.0, 3.0 * down]), down)
                    for xoff in (-2.5, 2.5)]
            if all(chain_fits(*c) for c in pair) \
                    and guessed_apart(pair[0][0], pair[0][1], pair[1][0], pair[1][1]) \
                    and all(guessed_apart(p, e, q, f) for p, e, _ in pair for q, f in placed):
                for p, e, _ in pair:
                    placed.append((p, e))
                    chains.append(p)
                break
        else:
            # A neighbour took the room: draw the whole frame again.
            return None
    atoms = []
    for k, (head, _) in enumerate(heads):
        atoms.append(head)
        atoms.extend(chains[2 * k])
        atoms.extend(chains[2 * k + 1])
    return np.array(atoms)


def layout():
    heads = []
    for z, down in ((65.0, -1.0), (15.0, 1.0)):
        for ix in range(4):
            for iy in range(4):
                heads.append((np.array([10.0 + 20 * ix, 10.0 + 20 * iy, z]), down))
    return heads


def names():
    out = ["P"]
    for sn in (2, 3):
        for i in range(1, NC + 1):
            out.append(f"C{sn}{i}")
            tags = ("R", "S") if i < NC else ("R", "S", "T")
            out.extend(f"H{sn}{i}{t}" for t in tags)
    return out


def build():
    per = names()
    heads = layout()
    n_lip = len(heads)
    n = n_lip * len(per)
    u = mda.Universe.empty(n, n_residues=n_lip, atom_resindex=np.repeat(np.arange(n_lip), len(per)),
                           trajectory=True)
    u.add_TopologyAttr("names", per * n_lip)
    u.add_TopologyAttr("types", [p[0] for p in per] * n_lip)
    u.add_TopologyAttr("resnames", ["DPPC"] * n_lip)
    u.add_TopologyAttr("resids", np.arange(1, n_lip + 1))
    u.dimensions = [BOX, BOX, BOX, 90, 90, 90]
    frames, whole = [], []
    for _ in range(FRAMES):
        # Each head moved along the normal by N(0, 1 A), its chains with it.
        moved = [(h + np.array([0.0, 0.0, RNG.normal()]), d) for h, d in heads]
        p = None
        while p is None:
            p = lipid_positions(moved)
        whole.append(p.copy())
        p = (p + SHIFT) % BOX
        frames.append(p)
    write(u, frames, "bilayer")
    return per, n_lip, u, whole, heads


def write(u, frames, stem):
    u.atoms.positions = frames[0]
    u.atoms.write(stem + ".gro")
    with mda.Writer(stem + ".xtc", len(u.atoms)) as w:
        for p in frames:
            u.atoms.positions = p
            w.write(u.atoms)


def p2(c):
    return 1.5 * c * c - 0.5


def nearest(d):
    return d - BOX * np.round(d / BOX)


def reference(per, n_lip):
    u = mda.Universe("bilayer.gro", "bilayer.xtc")
    idx = {name: i for i, name in enumerate(per)}
    m = len(per)
    carbons = [f"C{sn}{i}" for sn in (2, 3) for i in range(1, NC + 1)]
    hyd = {c: [nm for nm in per if nm.startswith("H" + c[1:]) and len(nm) == len(c) + 1] for c in carbons}
    sums_h = {c: np.zeros(n_lip) for c in carbons}
    sums_ua = {c: 0.0 for c in carbons}
    sums_b = {}
    for ts in u.trajectory:
        x = u.atoms.positions.astype(np.float64)
        for c in carbons:
            ci = np.arange(n_lip) * m + idx[c]
            s = np.zeros(n_lip)
            for h in hyd[c]:
                d = nearest(x[np.arange(n_lip) * m + idx[h]] - x[ci])
                s += p2(d[:, 2] / np.linalg.norm(d, axis=1))
            sums_h[c] += s / len(hyd[c])
            sn, i = c[1], int(c[2:])
            prev = f"C{sn}{i - 1}"
            if i < NC:
                nxt = f"C{sn}{i + 1}"
                key = f"{c}-{nxt}"
                d = nearest(x[np.arange(n_lip) * m + idx[nxt]] - x[ci])
                sums_b[key] = sums_b.get(key, 0.0) + np.sum(p2(d[:, 2] / np.linalg.norm(d, axis=1)))
                if i == 1:
                    continue
                a = nearest(x[np.arange(n_lip) * m + idx[prev]] - x[ci])
                b = nearest(x[np.arange(n_lip) * m + idx[nxt]] - x[ci])
                # z along C(i-1) -> C(i+1) as the atoms lie (not the unit bonds' difference).
                z = b - a
                z /= np.linalg.norm(z, axis=1)[:, None]
                xx = np.cross(a, b)
                xx /= np.linalg.norm(xx, axis=1)[:, None]
                y = np.cross(z, xx)
                sums_ua[c] += np.sum(2 / 3 * p2(xx[:, 2]) + 1 / 3 * p2(y[:, 2]))
    f = len(u.trajectory)
    out = {
        "frames": f,
        "lipids": n_lip,
        "hydrogens": {c: float(np.mean(sums_h[c]) / f) for c in carbons},
        "sem": {c: float(np.std(sums_h[c] / f, ddof=1) / np.sqrt(n_lip)) for c in carbons},
        "united_atom": {c: sums_ua[c] / (n_lip * f) for c in carbons if 1 < int(c[2:]) < NC},
        "bonds": {k: v / (n_lip * f) for k, v in sums_b.items()},
    }
    # Ideal hydrogens: the two methods agree but for the XTC's rounding.
    for c, v in out["united_atom"].items():
        assert abs(v - out["hydrogens"][c]) < 0.01, (c, v, out["hydrogens"][c])
    return out


def membrane(per, n_lip, whole, heads):
    """LeafletFinder's leaflets of the P atoms in the shifted file, and per frame the
    thickness (upper minus lower mean P height) from the frames before the shift."""
    from MDAnalysis.analysis.leaflet import LeafletFinder
    u = mda.Universe("bilayer.gro", "bilayer.xtc")
    found = LeafletFinder(u, "name P", cutoff=25.0, pbc=True)
    groups = [sorted(int(r) for r in g.resids) for g in found.groups()]
    m = len(per)
    upper = [k for k, (_, d) in enumerate(heads) if d < 0]
    lower = [k for k, (_, d) in enumerate(heads) if d > 0]
    thickness = [float(np.mean(p[np.array(upper) * m, 2]) - np.mean(p[np.array(lower) * m, 2]))
                 for p in whole]
    return {
        "cutoff": 25.0,
        "leaflets": groups,
        "upper_resids": [k + 1 for k in upper],
        "thickness": thickness,
        "area": BOX * BOX,
    }


TOP = """[ defaults ]
1 1 no 1.0 1.0
[ atomtypes ]
P 30.97 0.0 A 0.0 0.0
C 12.011 0.0 A 0.0 0.0
H 1.008 0.0 A 0.0 0.0
[ moleculetype ]
DPPC 1
[ atoms ]
{atoms}
[ system ]
bilayer
[ molecules ]
DPPC {n}
"""

MDP = """integrator = md
nsteps = 0
cutoff-scheme = Verlet
pbc = xyz
coulombtype = cut-off
"""


def gmx_order(per, n_lip, u, whole):
    gmx = shutil.which("gmx")
    if gmx is None:
        return None
    m = len(per)
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        atoms = "\n".join(f"{i + 1} {nm[0]} 1 DPPC {nm} {i + 1} 0.0" for i, nm in enumerate(per))
        with open(os.path.join(tmp, "top.top"), "w") as f:
            f.write(TOP.format(atoms=atoms, n=n_lip))
        with open(os.path.join(tmp, "run.mdp"), "w") as f:
            f.write(MDP)
        here = os.getcwd()
        # The frames before the shift: every lipid whole (gmx order takes plain differences,
        # as after trjconv -pbc mol), the same order parameters as the shifted file's.
        os.chdir(tmp)
        write(u, whole, "whole")
        os.chdir(here)
        run = lambda *a, **k: subprocess.run([gmx, "-quiet", *a], cwd=tmp, check=True,
                                             capture_output=True, **k)
        run("grompp", "-f", "run.mdp", "-c", "whole.gro", "-p", "top.top",
            "-o", "topol.tpr", "-maxwarn", "5")
        for sn in (2, 3):
            with open(os.path.join(tmp, f"sn{sn}.ndx"), "w") as f:
                for i in range(1, NC + 1):
                    name = f"C{sn}{i}"
                    k = per.index(name)
                    f.write(f"[ {name} ]\n")
                    f.write(" ".join(str(l * m + k + 1) for l in range(n_lip)) + "\n")
            run("order", "-f", "whole.xtc", "-s", "topol.tpr", "-n",
                f"sn{sn}.ndx", "-d", "z", "-od", f"deuter{sn}.xvg", "-o", f"order{sn}.xvg",
                input=b"0\n" * NC)
            rows = [l.split() for l in open(os.path.join(tmp, f"deuter{sn}.xvg"))
                    if l.strip() and l[0] not in "#@"]
            for r in rows:
                # Row i is the carbon of group i + 1 (the first group gives none).
                out[f"C{sn}{int(float(r[0])) + 1}"] = float(r[1])
    return out


def main():
    per, n_lip, u, whole, heads = build()
    ref = reference(per, n_lip)
    ref["membrane"] = membrane(per, n_lip, whole, heads)
    g = gmx_order(per, n_lip, u, whole)
    if g is not None:
        ref["gmx_order"] = g
    with open("reference.json", "w") as f:
        json.dump(ref, f, indent=1, sort_keys=True)
        f.write("\n")


if __name__ == "__main__":
    main()

"""Fixtures and references for tests/tpr.rs: GROMACS run input files (.tpr) of many versions.

Files (all single .tpr files, some gzipped; the test reads them as written):

- peptide.tpr.gz: made here by GROMACS 2022.5 (file version 127): two 8-residue chains of
  PDB 2CVI (dssp/2cviA.pdb.gz, residues 1-8 as chain A and 20-27 as chain B) with
  amber99sb-ildn, pdb2gmx -chainsep id, TIP4P water (SETTLE and a virtual site) in a rhombic
  dodecahedron, Na+ and Cl- at 0.15 M, h-bond constraints and velocities (gen-vel);
- from MDAnalysisTests 2.11.0 (PyPI sdist, data/tprs): the all_bonded test molecule (every
  bonded interaction GROMACS has) as written by GROMACS 5.1 to 2026 (single and double
  precision), virtual sites by 4.0.7, 2021 and 2025, Linear_Angle (2019), the NNPot alanine
  dipeptide (2025) and lysozyme in water by 4.5 (2lyz_gmx_4.5.tpr, gzipped here).

reference.json.gz, per file:

- from GROMACS 2022.5 for the files it reads (version <= 127): residue numbers from
  `gmx editconf -f F -o F.gro`, bonds from `gmx editconf -f F -o F.pdb -conect` (GROMACS's
  chemical bonds, IS_CHEMBOND) plus each SETTLE's second O-H (CONECT takes a SETTLE's first
  two atoms only), read from `gmx dump`, and the positions, velocities and box printed by
  `gmx dump` (nm, 6 digits);
- for newer files, the residue numbers and bonds of the same system's file GROMACS 2022.5
  reads ("same_as"), and positions, velocities and box from MDAnalysis 2.11's TPRReader;
- from MDAnalysis 2.11 for every file: names, types, residue names, charges, masses,
  molecule types and molecule numbers, and the mass-weighted radius of gyration of every atom
  (and of the peptide's two chains) with the file's masses.

    pip install MDAnalysis==2.11.0      # and GROMACS 2022.5 (Debian: apt install gromacs)
    python3 gen_tpr.py PATH/TO/MDAnalysisTests/data [--peptide]
"""
import gzip
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import warnings

import MDAnalysis as mda

warnings.filterwarnings("ignore")
here = os.path.dirname(os.path.abspath(__file__))
data = sys.argv[1]

MDA = {
    "dummy_5.1.tpr": "tprs/all_bonded/dummy_5.1.tpr",
    "dummy_2016.tpr": "tprs/all_bonded/dummy_2016.tpr",
    "dummy_2018.tpr": "tprs/all_bonded/dummy_2018.tpr",
    "dummy_2020.tpr": "tprs/all_bonded/dummy_2020.tpr",
    "dummy_2020_double.tpr": "tprs/all_bonded/dummy_2020_double.tpr",
    "dummy_2021_double.tpr": "tprs/all_bonded/dummy_2021_double.tpr",
    "dummy_2022-rc1.tpr": "tprs/all_bonded/dummy_2022-rc1.tpr",
    "dummy_2023.tpr": "tprs/all_bonded/dummy_2023.tpr",
    "dummy_2024_4.tpr": "tprs/all_bonded/dummy_2024_4.tpr",
    "dummy_2025_0.tpr": "tprs/all_bonded/dummy_2025_0.tpr",
    "dummy_2026_0.tpr": "tprs/all_bonded/dummy_2026_0.tpr",
    "vsites_4.0.7.tpr": "tprs/virtual_sites/extra-interactions-4.0.7.tpr",
    "vsites_2021.tpr": "tprs/virtual_sites/extra-interactions-2021.tpr",
    "vsites_2025_0.tpr": "tprs/virtual_sites/extra-interactions-2025_0.tpr",
    "linear_angle_2019.tpr": "tprs/Linear_Angle.tpr",
    "ala_nnpot_2025_0.tpr": "tprs/ala_nnpot_gmx_2025_0.tpr",
    "2lyz_gmx_4.5.tpr.gz": "tprs/2lyz_gmx_4.5.tpr",
}
# Files GROMACS 2022.5 cannot read, and the file of the same system it can.
SAME_AS = {
    "dummy_2023.tpr": "dummy_2022-rc1.tpr",
    "dummy_2024_4.tpr": "dummy_2022-rc1.tpr",
    "dummy_2025_0.tpr": "dummy_2022-rc1.tpr",
    "dummy_2026_0.tpr": "dummy_2022-rc1.tpr",
    "vsites_2025_0.tpr": "vsites_2021.tpr",
    "ala_nnpot_2025_0.tpr": None,
}


def gmx(*args, stdin=None):
    r = subprocess.run(["gmx", "-quiet", "-nobackup", *args], input=stdin, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(r.stderr[-2000:])
    return r.stdout


def make_peptide(work):
    pdb = os.path.join(work, "pep.pdb")
    with gzip.open(os.path.join(here, "..", "dssp", "2cviA.pdb.gz"), "rt") as f, open(pdb, "w") as o:
        for line in f:
            if not line.startswith("ATOM"):
                continue
            r = int(line[22:26])
            if r <= 8:
                o.write(line)
            elif 20 <= r <= 27:
                o.write(line[:21] + "B" + line[22:])
        o.write("TER\nEND\n")
    with open(os.path.join(work, "min.mdp"), "w") as f:
        f.write("integrator = steep\nnsteps = 0\ncutoff-scheme = Verlet\ncoulombtype = PME\n"
                "rcoulomb = 0.9\nrvdw = 0.9\n")
    with open(os.path.join(work, "md.mdp"), "w") as f:
        f.write("integrator = md\nnsteps = 10\ndt = 0.002\ncutoff-scheme = Verlet\n"
                "coulombtype = PME\nrcoulomb = 0.9\nrvdw = 0.9\nconstraints = h-bonds\n"
                "tcoupl = v-rescale\ntc-grps = System\ntau-t = 0.1\nref-t = 300\n"
                "gen-vel = yes\ngen-temp = 300\ngen-seed = 7\n")
    os.chdir(work)
    gmx("pdb2gmx", "-f", "pep.pdb", "-o", "pep.gro", "-p", "topol.top", "-ff", "amber99sb-ildn",
        "-water", "tip4p", "-ignh", "-chainsep", "id")
    gmx("editconf", "-f", "pep.gro", "-o", "box.gro", "-c", "-d", "0.5", "-bt", "dodecahedron")
    gmx("solvate", "-cp", "box.gro", "-cs", "tip4p.gro", "-p", "topol.top", "-o", "solv.gro")
    gmx("grompp", "-f", "min.mdp", "-c", "solv.gro", "-p", "topol.top", "-o", "ions.tpr", "-maxwarn", "2")
    gmx("genion", "-s", "ions.tpr", "-o", "ions.gro", "-p", "topol.top", "-pname", "NA", "-nname", "CL",
        "-neutral", "-conc", "0.15", "-seed", "7", stdin="SOL\n")
    gmx("grompp", "-f", "md.mdp", "-c", "ions.gro", "-p", "topol.top", "-o", "peptide.tpr", "-maxwarn", "1")
    with open("peptide.tpr", "rb") as f, gzip.GzipFile(os.path.join(here, "peptide.tpr.gz"), "wb", 9, mtime=0) as g:
        g.write(f.read())


def plain(path, work):
    """The file as a plain .tpr in `work` (gmx does not read gzip)."""
    out = os.path.join(work, os.path.basename(path).removesuffix(".gz"))
    if path.endswith(".gz"):
        with gzip.open(path, "rb") as f, open(out, "wb") as o:
            o.write(f.read())
    else:
        shutil.copy(path, out)
    return out


def from_gmx(tpr, work):
    gro = os.path.join(work, "ref.gro")
    pdb = os.path.join(work, "ref.pdb")
    gmx("editconf", "-f", tpr, "-o", gro)
    gmx("editconf", "-f", tpr, "-o", pdb, "-conect")
    with open(gro) as f:
        lines = f.read().splitlines()
    n = int(lines[1])
    resids = [int(l[0:5]) for l in lines[2:2 + n]]
    bonds = set()
    with open(pdb) as f:
        for l in f:
            if l.startswith("CONECT"):
                a = int(l[6:11]) - 1
                for k in range(11, len(l.rstrip()), 5):
                    b = int(l[k:k + 5]) - 1
                    bonds.add((min(a, b), max(a, b)))
    dump = gmx("dump", "-s", tpr)
    # Molecule types: their atom counts and SETTLE entries; molecule blocks.
    natoms, settles, blocks = [], [], []
    section = None
    for line in dump.splitlines():
        s = line.strip()
        m = re.match(r"moltype \((\d+)\):", s)
        if m and line.startswith("   moltype"):
            natoms.append(None)
            settles.append([])
            section = None
            continue
        m = re.match(r"atom \((\d+)\):", s)
        if m and natoms and natoms[-1] is None:
            natoms[-1] = int(m.group(1))
        if s.endswith(":") and not s.startswith("atom") and line.startswith("      ") and not line.startswith("         "):
            section = s[:-1]
        m = re.match(r"\d+ type=\d+ \(SETTLE\)\s+(\d+)\s+(\d+)\s+(\d+)", s)
        if m and section == "Settle":
            settles[-1].append(tuple(int(x) for x in m.groups()))
        m = re.match(r"moltype\s+= (\d+)", s)
        if m:
            blocks.append([int(m.group(1)), None])
        m = re.match(r"#molecules\s+= (\d+)", s)
        if m:
            blocks[-1][1] = int(m.group(1))
    first = 0
    for t, nmol in blocks:
        for _ in range(nmol):
            for o, h1, h2 in settles[t]:
                bonds.add((first + o, first + h1))
                bonds.add((first + o, first + h2))
            first += natoms[t]
    vec = r"\{\s*([-+.\deE]+),\s*([-+.\deE]+),\s*([-+.\deE]+)\}"

    def block(name):
        out = []
        on = False
        for line in dump.splitlines():
            if re.match(rf"^{name} \(", line):
                on = True
                continue
            if on:
                m = re.search(rf"{name}\[\s*\d+\]={vec}", line)
                if not m:
                    break
                out.append([float(x) * 10 for x in m.groups()])
        return out

    return {
        "resids": resids,
        "bonds": sorted(bonds),
        "positions": block("x"),
        "velocities": block("v"),
        "box": block("box"),
    }


def from_mda(tpr):
    u = mda.Universe(tpr)
    a = u.atoms
    return {
        "n_atoms": len(a),
        "names": [str(x) for x in a.names],
        "types": [str(x) for x in a.types],
        "resnames": [str(x) for x in a.resnames],
        "charges": [float(x) for x in a.charges],
        "masses": [float(x) for x in a.masses],
        "moltypes": [str(x) for x in a.moltypes],
        "molnums": [int(x) for x in a.molnums],
        "elements": [str(x) for x in a.elements] if hasattr(a, "elements") else [],
        "mda_positions": a.positions.astype(float).tolist(),
        "mda_velocities": a.velocities.astype(float).tolist() if u.trajectory.ts.has_velocities else [],
        "mda_dimensions": [float(x) for x in u.dimensions] if u.dimensions is not None else [],
        # Mass-weighted radii of gyration with the file's masses (every atom; the protein).
        "rgyr_all": float(a.radius_of_gyration()),
        "rgyr_protein": float(u.select_atoms("moltype Protein_chain_A Protein_chain_B").radius_of_gyration())
        if "Protein_chain_A" in set(a.moltypes) else None,
    }


work = tempfile.mkdtemp()
if "--peptide" in sys.argv:
    make_peptide(os.path.join(work))
for name, src in MDA.items():
    dst = os.path.join(here, name)
    if name.endswith(".gz"):
        with open(os.path.join(data, src), "rb") as f, gzip.GzipFile(dst, "wb", 9, mtime=0) as g:
            g.write(f.read())
    else:
        shutil.copy(os.path.join(data, src), dst)

reference = {}
names = ["peptide.tpr.gz"] + list(MDA)
for name in names:
    tpr = plain(os.path.join(here, name), work)
    ref = from_mda(tpr)
    if name not in SAME_AS:
        ref.update(from_gmx(tpr, work))
    else:
        ref["same_as"] = SAME_AS[name]
    if "positions" in ref:
        # GROMACS printed these: MDAnalysis's copies are not needed.
        del ref["mda_positions"], ref["mda_velocities"], ref["mda_dimensions"]
    reference[name] = ref
for name, same in SAME_AS.items():
    ref = reference[name]
    if same is None:
        # No older file of this system: MDAnalysis's bonds, which hold only chemical bonds here.
        u = mda.Universe(plain(os.path.join(here, name), work))
        ref["bonds"] = sorted(tuple(sorted(int(i) for i in b.indices)) for b in u.bonds)
        ref["resids"] = [int(x) for x in u.atoms.resids]
        continue
    base = reference[same]
    for k in ["names", "types", "resnames", "charges", "masses", "moltypes", "molnums"]:
        assert ref[k] == base[k], (name, k)
    ref["resids"] = base["resids"]
    ref["bonds"] = base["bonds"]


def rounded(v):
    if isinstance(v, float):
        return float(f"{v:.7g}")
    if isinstance(v, list):
        return [rounded(x) for x in v]
    return v


reference = {k: {f: rounded(v) for f, v in r.items()} for k, r in reference.items()}
with gzip.GzipFile(os.path.join(here, "reference.json.gz"), "wb", 9, mtime=0) as f:
    f.write(json.dumps(reference, separators=(",", ":")).encode())
shutil.rmtree(work)

"""Fixtures for tests/gromacs_top.rs: GROMACS topologies (.top with #included .itp files)
and the run input files (.tpr) GROMACS 2022.5's grompp makes from them.

Two systems, both from PDB 2CVI (../dssp/2cviA.pdb.gz), hydrogens rebuilt by pdb2gmx:

- amber/: residues 1-4 as chain A and 20-23 as chain B, amber99sb-ildn, pdb2gmx -chainsep id
  (one .itp per chain, with its position restraints), TIP3P water, Na+/Cl- at 0.15 M;
  grompp with `define = -DPOSRES`;
- charmm/: residues 1-6, charmm27 (CMAP types, `\\` continued lines), TIP4P water (SETTLE,
  a virtual site of mass 0), Na+/Cl- (neutral); grompp with `define = -DHEAVY_H`, which
  redefines the water atom types' masses (O 9.9514 u, H 4.032 u) inside #ifdef blocks.

Per system: topol.top and the .itp files pdb2gmx wrote (they #include the force field from
the GROMACS data directory), conf.gro.gz (the solvated system), topol.tpr.gz (grompp's output),
processed.top.gz (grompp -pp: the topology preprocessed, no #include left, gzipped) and
mdp.mdp. The tests read each .top and compare with the .tpr read by the crate's .tpr reader
(itself checked against gmx dump and MDAnalysis in tests/tpr.rs).

mda.json: MDAnalysis 2.11's ITPParser on each processed.top: atom and bond counts, and the
names, types, residue names and numbers, charges, masses, molecule types and bonds of the atoms
up to the second water (every solute molecule and two waters), an independent reading.

    python3 gen_top.py        # GROMACS 2022.5 (Debian: apt install gromacs), MDAnalysis 2.11
"""
import gzip
import json
import os
import shutil
import subprocess
import tempfile
import warnings

warnings.filterwarnings("ignore")
here = os.path.dirname(os.path.abspath(__file__))


def gmx(*args, stdin=None, cwd=None):
    r = subprocess.run(["gmx", "-quiet", "-nobackup", *args], input=stdin, capture_output=True,
                       text=True, cwd=cwd)
    if r.returncode != 0:
        raise RuntimeError(r.stderr[-3000:])
    return r.stdout


def pdb(work, keep):
    out = os.path.join(work, "in.pdb")
    with gzip.open(os.path.join(here, "..", "dssp", "2cviA.pdb.gz"), "rt") as f, open(out, "w") as o:
        for line in f:
            if line.startswith("ATOM"):
                chain = keep(int(line[22:26]))
                if chain:
                    o.write(line[:21] + chain + line[22:])
        o.write("TER\nEND\n")


SYSTEMS = {
    "amber": dict(keep=lambda r: "A" if r <= 4 else ("B" if 20 <= r <= 23 else None),
                  ff="amber99sb-ildn", water="tip3p", solvent="spc216.gro",
                  define="-DPOSRES", extra=["-chainsep", "id"], ions=["-conc", "0.15"]),
    "charmm": dict(keep=lambda r: "A" if r <= 6 else None,
                   ff="charmm27", water="tip4p", solvent="tip4p.gro",
                   define="-DHEAVY_H", extra=[], ions=[]),
}


def make(name, s):
    out = os.path.join(here, name)
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    with tempfile.TemporaryDirectory() as work:
        pdb(work, s["keep"])
        with open(os.path.join(work, "mdp.mdp"), "w") as f:
            f.write(f"define = {s['define']}\nintegrator = steep\nnsteps = 0\n"
                    "cutoff-scheme = Verlet\ncoulombtype = PME\nrcoulomb = 0.6\nrvdw = 0.6\n")
        with open(os.path.join(work, "ions.mdp"), "w") as f:
            f.write("integrator = steep\nnsteps = 0\ncutoff-scheme = Verlet\ncoulombtype = PME\n"
                    "rcoulomb = 0.6\nrvdw = 0.6\n")
        gmx("pdb2gmx", "-f", "in.pdb", "-o", "pep.gro", "-p", "topol.top", "-ff", s["ff"],
            "-water", s["water"], "-ignh", *s["extra"], cwd=work)
        gmx("editconf", "-f", "pep.gro", "-o", "box.gro", "-c", "-d", "0.3", "-bt", "dodecahedron",
            cwd=work)
        gmx("solvate", "-cp", "box.gro", "-cs", s["solvent"], "-p", "topol.top", "-o", "solv.gro",
            cwd=work)
        gmx("grompp", "-f", "ions.mdp", "-c", "solv.gro", "-p", "topol.top", "-o", "ions.tpr",
            "-maxwarn", "2", cwd=work)
        gmx("genion", "-s", "ions.tpr", "-o", "conf.gro", "-p", "topol.top", "-pname", "NA",
            "-nname", "CL", "-neutral", *s["ions"], "-seed", "7", stdin="SOL\n", cwd=work)
        gmx("grompp", "-f", "mdp.mdp", "-c", "conf.gro", "-r", "conf.gro", "-p", "topol.top",
            "-o", "topol.tpr", "-pp", "processed.top", "-maxwarn", "1", cwd=work)
        for f in sorted(os.listdir(work)):
            if f.endswith(".itp") or f in ("topol.top", "mdp.mdp"):
                shutil.copy(os.path.join(work, f), out)
            if f in ("conf.gro", "topol.tpr", "processed.top"):
                with open(os.path.join(work, f), "rb") as i, \
                        gzip.GzipFile(os.path.join(out, f + ".gz"), "wb", 9, mtime=0) as g:
                    g.write(i.read())
        return mda_reading(os.path.join(work, "processed.top"))


def mda_reading(path):
    import MDAnalysis as mda
    u = mda.Universe(path, topology_format="ITP")
    # The atoms up to the second water: every solute molecule type and SOL twice.
    sol = [i for i, m in enumerate(u.atoms.moltypes) if m == "SOL"]
    n = sol[2 * (len(sol) // len(u.select_atoms("resname SOL").residues))] if sol else len(u.atoms)
    a = u.atoms[:n]
    return {
        "n_atoms": len(u.atoms),
        "n_bonds": len(u.bonds),
        "names": [str(x) for x in a.names],
        "types": [str(x) for x in a.types],
        "resnames": [str(x) for x in a.resnames],
        "resids": [int(x) for x in a.resids],
        "charges": [float(x) for x in a.charges],
        "masses": [float(x) for x in a.masses],
        "moltypes": [str(x) for x in a.moltypes],
        "bonds": sorted([sorted([int(b[0]), int(b[1])]) for b in u.bonds.indices if max(b) < n]),
    }


ref = {name: make(name, s) for name, s in SYSTEMS.items()}
with open(os.path.join(here, "mda.json"), "w") as f:
    json.dump(ref, f, separators=(",", ":"))
    f.write("\n")

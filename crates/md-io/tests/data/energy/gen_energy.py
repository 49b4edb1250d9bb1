"""GROMACS energy files and LAMMPS logs, with what their own tools read from them: the
reference for md-io's `energy` module and `texmap plot` (crates/md-io/tests/energy.rs,
crates/cli/tests/plot_energy.rs).

Run from this directory (Python 3.11): python3 gen_energy.py
Needs Debian 12's `gromacs` (gmx and gmx_d 2022.5), `lammps` and `python3-lammps`
(20220106, the 29 Sep 2021 release) and from PyPI pyedr 0.8.0 and lammps-logfile 1.1.4:

    apt-get install -y --no-install-recommends gromacs lammps python3-lammps
    pip install pyedr==0.8.0 lammps-logfile==1.1.4

GROMACS (every run: 176 SPC waters from `gmx solvate -cs spc216.gro -box 1.8`, OPLS-AA,
v-rescale at 300 K, C-rescale at 1 bar, PME, 2 fs steps, nstcalcenergy 1, nstenergy 5, so that
every frame but the first carries the sums, gmx mdrun -nt 1):
- water.edr: 50 steps, mixed precision (gmx); water_d.edr: the same run by gmx_d (double).
- blocks.edr: 20 steps with free energy (the waters' charges decoupled along three lambdas,
  dH/dl and the neighbours' energy differences written into the energy file,
  separate-dhdl-file = no, nstdhdl 2) and one water's H-H distance restrained (disre simple,
  nstdisreout 2): frames at odd multiples of 2 steps hold only the restraint and dH blocks
  (no energies), the others energies and blocks of double, int and float data.
- *_energy.xvg: `gmx energy` (gmx_d energy -dp for the double file) of five terms picked by
  name on stdin.
- edr_reference.json: pyedr's edr_to_dict (every term, the frames with energies) and
  get_unit_dictionary of each file.

LAMMPS (lmp, LJ melt of 256 atoms, boundary p p f):
- melt.log.lammps: four runs: the default thermo style twice (the same columns; the second
  repeats step 50), a custom style with other columns after one atom is kicked out of the box
  (`fix print` lines and a lost-atom WARNING inside its table), then thermo_style multi
  (a lost-atom WARNING before its first record).
- nostep.log.lammps: one run whose custom thermo has no step column.
- lammps_reference.json: per run (its column names in order and its columns), what LAMMPS's
  own python module reads (`lammps.formats.LogFile`, python3-lammps) and what lammps-logfile's
  `read_log` reads, per `run_num`. lammps-logfile does not recognise this LAMMPS version's multi records (their
  step lines start with 16 dashes, it looks for 12 and a space), and LogFile needs a `Step`
  header: the test takes each file's runs from the reader that sees them.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np
import pyedr
import lammps_logfile

sys.path.append("/usr/lib/python3/dist-packages")
from lammps.formats import LogFile  # noqa: E402  (Debian's python3-lammps)

HERE = os.path.dirname(os.path.abspath(__file__))

TOP = """#include "oplsaa.ff/forcefield.itp"
#include "oplsaa.ff/spc.itp"

[ system ]
SPC water

[ molecules ]
SOL 176
"""

# One water with three constraints instead of SETTLE (one SETTLE molecule type only) and a
# distance restraint between its hydrogens.
SOR = """[ moleculetype ]
SOR		2

[ atoms ]
     1  opls_116   1    SOR     OW      1      -0.82
     2  opls_117   1    SOR    HW1      1       0.41
     3  opls_117   1    SOR    HW2      1       0.41

[ constraints ]
1	2	1	0.1
1	3	1	0.1
2	3	1	0.16330

[ exclusions ]
1	2	3
2	1	3
3	1	2

[ distance_restraints ]
2 3 1 0 1 0.10 0.15 0.20 1.0
"""

TOP_BLOCKS = """#include "oplsaa.ff/forcefield.itp"
#include "sor.itp"
#include "oplsaa.ff/spc.itp"

[ system ]
SPC water, one restrained

[ molecules ]
SOR 1
SOL 175
"""

MDP = """integrator      = md
dt              = 0.002
nsteps          = {nsteps}
nstcalcenergy   = 1
nstenergy       = 5
nstlog          = 0
cutoff-scheme   = Verlet
coulombtype     = PME
rcoulomb        = 0.8
rvdw            = 0.8
tcoupl          = v-rescale
tc-grps         = System
tau-t           = 0.1
ref-t           = 300
pcoupl          = C-rescale
tau-p           = 1.0
ref-p           = 1.0
compressibility = 4.5e-5
gen-vel         = yes
gen-temp        = 300
gen-seed        = 7
ld-seed         = 7
"""

MDP_BLOCKS = """free-energy        = yes
init-lambda-state  = 1
fep-lambdas        = 0.0 0.5 1.0
couple-moltype     = SOL
couple-lambda0     = vdw-q
couple-lambda1     = vdw
couple-intramol    = no
nstdhdl            = 2
separate-dhdl-file = no
dhdl-derivatives   = yes
calc-lambda-neighbors = -1
disre              = simple
disre-weighting    = equal
nstdisreout        = 2
"""

# The terms gmx energy writes to each .xvg, picked by name as its menu spells them (spaces as -).
XVG_TERMS = ["Potential", "Temperature", "Pressure", "Density", "Lamb-System"]
XVG_TERMS_BLOCKS = ["Potential", "Temperature", "dVremain/dl", "Dis.-Rest.", "Pres-XY"]

MELT = """# LJ melt in four runs: the default thermo twice (the same columns), a custom thermo with
# other columns (fix print lines and a lost-atom WARNING inside its table), thermo multi
units           lj
atom_style      atomic
boundary        p p f
lattice         fcc 0.8442
region          box block 0 4 0 4 0 4
create_box      1 box
create_atoms    1 box
mass            1 1.0
velocity        all create 3.0 87287 loop geom
pair_style      lj/cut 2.5
pair_coeff      1 1 1.0 1.0 2.5
neighbor        0.3 bin
neigh_modify    every 20 delay 0 check no
fix             1 all nve
fix             w all wall/reflect zlo EDGE zhi EDGE
thermo          10
run             50
run             40
unfix           w
thermo_style    custom step temp pe ke etotal press vol
thermo_modify   norm yes lost warn
fix             p all print 25 "fix print at step $(step): pe $(pe)"
set             atom 1 vz -50.0
run             50
unfix           p
thermo_style    multi
thermo_modify   lost warn
run             30
"""

NOSTEP = """# LJ melt, a thermo table without a step column
units           lj
atom_style      atomic
lattice         fcc 0.8442
region          box block 0 3 0 3 0 3
create_box      1 box
create_atoms    1 box
mass            1 1.0
velocity        all create 2.0 4711 loop geom
pair_style      lj/cut 2.5
pair_coeff      1 1 1.0 1.0 2.5
fix             1 all nve
thermo_style    custom time temp pe etotal
thermo          5
run             25
"""


def run(cmd, cwd, stdin=None):
    r = subprocess.run(cmd, cwd=cwd, input=stdin, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{r.stdout}\n{r.stderr}")


def gromacs(tmp):
    run(["gmx", "solvate", "-cs", "spc216.gro", "-box", "1.8", "1.8", "1.8", "-o", "water.gro"], tmp)
    with open(os.path.join(tmp, "topol.top"), "w") as f:
        f.write(TOP)
    with open(os.path.join(tmp, "blocks.top"), "w") as f:
        f.write(TOP_BLOCKS)
    with open(os.path.join(tmp, "sor.itp"), "w") as f:
        f.write(SOR)
    with open(os.path.join(tmp, "md.mdp"), "w") as f:
        f.write(MDP.format(nsteps=50))
    with open(os.path.join(tmp, "blocks.mdp"), "w") as f:
        f.write(MDP.format(nsteps=20) + MDP_BLOCKS)
    for gmx, mdp, top, name in [
        ("gmx", "md.mdp", "topol.top", "water"),
        ("gmx_d", "md.mdp", "topol.top", "water_d"),
        ("gmx", "blocks.mdp", "blocks.top", "blocks"),
    ]:
        run([gmx, "grompp", "-f", mdp, "-c", "water.gro", "-p", top, "-o", f"{name}.tpr"], tmp)
        run([gmx, "mdrun", "-nt", "1", "-s", f"{name}.tpr", "-deffnm", name], tmp)
        terms = XVG_TERMS_BLOCKS if name == "blocks" else XVG_TERMS
        extra = ["-dp"] if gmx == "gmx_d" else []
        run([gmx, "energy", "-f", f"{name}.edr", "-o", f"{name}_energy.xvg"] + extra, tmp,
            stdin="\n".join(terms) + "\n\n")
        for out in [f"{name}.edr", f"{name}_energy.xvg"]:
            shutil.copy(os.path.join(tmp, out), os.path.join(HERE, out))
    reference = {}
    for name in ["water", "water_d", "blocks"]:
        path = os.path.join(HERE, f"{name}.edr")
        d = pyedr.edr_to_dict(path)
        reference[name] = {
            "names": list(d.keys()),
            "units": pyedr.get_unit_dictionary(path),
            "values": {k: [float(x) for x in np.asarray(v)] for k, v in d.items()},
        }
    with open(os.path.join(HERE, "edr_reference.json"), "w") as f:
        json.dump(reference, f, indent=0)
        f.write("\n")


def ordered(run):
    """A run's columns as {"names": [...], "columns": [[...], ...]}, keeping their order."""
    return {"names": list(run.keys()), "columns": [[float(x) for x in v] for v in run.values()]}


def lammps(tmp):
    reference = {}
    for name, script in [("melt", MELT), ("nostep", NOSTEP)]:
        with open(os.path.join(tmp, f"in.{name}"), "w") as f:
            f.write(script)
        log = f"{name}.log.lammps"
        run(["lmp", "-in", f"in.{name}", "-log", log, "-screen", "none"], tmp)
        shutil.copy(os.path.join(tmp, log), os.path.join(HERE, log))
        path = os.path.join(HERE, log)
        df = lammps_logfile.read_log(path)
        logfile_runs = []
        for k in sorted(set(df["run_num"])):
            part = df[df["run_num"] == k].drop(columns="run_num").dropna(axis=1, how="all")
            logfile_runs.append(ordered({c: part[c] for c in part.columns}))
        try:
            runs = [ordered(r) for r in LogFile(path).runs]
        except UnboundLocalError:
            # LogFile meets "Loop time" without having seen a "Step" header.
            runs = None
        reference[name] = {"lammps_LogFile": runs, "lammps_logfile_read_log": logfile_runs}
    with open(os.path.join(HERE, "lammps_reference.json"), "w") as f:
        json.dump(reference, f, indent=0)
        f.write("\n")


def main():
    with tempfile.TemporaryDirectory() as tmp:
        gromacs(tmp)
        lammps(tmp)


if __name__ == "__main__":
    main()

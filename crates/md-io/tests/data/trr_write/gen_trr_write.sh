#!/usr/bin/env bash
# The fixtures of crates/md-io/tests/trr_writer.rs.
#   md.trr           GROMACS 2022.5 (Debian gromacs 2022.5-2): 213 SPC waters from spc216.gro in a
#                    1.9 nm box, 20 steps of MD; positions every 10 steps, velocities every 20,
#                    forces every 5, so frames hold different blocks (steps 5 and 15 forces only).
#   written.trr      our writer's rewrite of md.trr's frames with positions
#                    (TEXMAP_BLESS=1 cargo test -p texmap-md-io --test suite trr_writer::).
#   gmx_check.txt    what `gmx check` counts in written.trr.
#   mdanalysis.json.gz  what MDAnalysis 2.11's TRRReader reads from written.trr.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
cd "$work"
cat > topol.top <<'TOP'
#include "oplsaa.ff/forcefield.itp"
#include "oplsaa.ff/spc.itp"

[ system ]
SPC water, for the TRR writer's fixtures

[ molecules ]
TOP
gmx -quiet solvate -cs spc216.gro -box 1.9 1.9 1.9 -o box.gro -p topol.top
cat > md.mdp <<'MDP'
integrator = md
dt = 0.002
nsteps = 20
nstxout = 10
nstvout = 20
nstfout = 5
nstxout-compressed = 0
nstenergy = 0
nstlog = 0
nstcalcenergy = 5
cutoff-scheme = Verlet
coulombtype = PME
rcoulomb = 0.85
rvdw = 0.85
tcoupl = v-rescale
tc-grps = System
tau-t = 0.1
ref-t = 300
gen-vel = yes
gen-temp = 300
gen-seed = 1993
MDP
gmx -quiet grompp -f md.mdp -c box.gro -p topol.top -o md.tpr
gmx -quiet mdrun -s md.tpr -deffnm md -nt 1
cp md.trr "$here/md.trr"
cd "$here"
TEXMAP_BLESS=1 cargo test -q -p texmap-md-io --test suite trr_writer::rewriting
gmx -quiet check -f written.trr 2>&1 | sed -n '/^Item/,/^Box/p' > gmx_check.txt
python3 gen_trr_write.py
rm -rf "$work"

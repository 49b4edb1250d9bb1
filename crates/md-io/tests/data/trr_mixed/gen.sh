#!/bin/sh
# A GROMACS TRR whose frames hold positions, velocities and forces at different strides
# (nstxout 10, nstvout 5, nstfout 2): 8 argon atoms, 20 steps of md.
# Run here with GROMACS (gmx) on PATH (2022.5 here); writes argon.trr and gmx_dump_blocks.txt
# (and removes grompp and mdrun's other output).
set -e
cat > argon.gro <<'G'
argon, 8 atoms
    8
    1AR      AR    1   0.200   0.200   0.200  0.1000 -0.2000  0.0500
    1AR      AR    2   0.600   0.200   0.200 -0.1000  0.1500  0.0000
    1AR      AR    3   0.200   0.600   0.200  0.0000  0.0000  0.1000
    1AR      AR    4   0.600   0.600   0.200  0.2000  0.1000 -0.1000
    1AR      AR    5   0.200   0.200   0.600 -0.2000  0.0000  0.0500
    1AR      AR    6   0.600   0.200   0.620  0.0500 -0.0500 -0.0500
    1AR      AR    7   0.200   0.600   0.600  0.0000  0.0500  0.0000
    1AR      AR    8   0.600   0.580   0.600 -0.0500 -0.0500 -0.0500
   0.80000   0.80000   0.80000
G
cat > argon.top <<'T'
[ defaults ]
1 1 no 1.0 1.0
[ atomtypes ]
AR 39.948 0.0 A 0.0062 9.7e-6
[ moleculetype ]
AR 1
[ atoms ]
1 AR 1 AR AR 1 0.0
[ system ]
argon
[ molecules ]
AR 8
T
cat > argon.mdp <<'M'
integrator = md
dt = 0.002
nsteps = 20
nstxout = 10
nstvout = 5
nstfout = 2
nstxout-compressed = 0
nstenergy = 0
nstlog = 0
cutoff-scheme = Verlet
rlist = 0.35
rvdw = 0.35
coulombtype = Cut-off
rcoulomb = 0.35
tcoupl = no
pcoupl = no
gen-vel = no
continuation = yes
M
gmx -quiet grompp -f argon.mdp -c argon.gro -p argon.top -o argon.tpr -maxwarn 2
gmx -quiet mdrun -nt 1 -deffnm argon -c confout.gro
rm -f argon.tpr argon.edr argon.log argon.cpt mdout.mdp confout.gro argon_prev.cpt argon.xtc
# The independent reference: which blocks GROMACS's own dump finds in each frame.
gmx -quiet dump -f argon.trr 2>/dev/null | grep -E "frame|natoms|^ *[xvf] \(" > gmx_dump_blocks.txt

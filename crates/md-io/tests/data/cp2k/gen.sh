#!/bin/sh
# CP2K outputs for the CP2K tests (crates/md-io/tests/cp2k.rs): run with CP2K 2023.1 (Debian's
# cp2k package, cp2k.psmp) in this directory, then gen_reference.py (ASE 3.29).
#   ar_npt: 108 Lennard-Jones argon atoms, flexible-cell NPT (NPT_F) for 40 steps of 5 fs:
#           positions every 4 steps (ar_npt-pos-1.xyz), the cell every step (ar_npt-1.cell),
#           the restart file of step 40 (ar_npt-1.restart: the cell and positions with all digits).
#   ar_opt: a 5-atom argon cluster relaxed by BFGS (ar_opt-pos-1.xyz: 'i = N, E = ...' lines).
set -e
cd "$(dirname "$0")"
export OMP_NUM_THREADS=1
cp2k.psmp -i ar_npt.inp -o ar_npt.out
cp2k.psmp -i ar_opt.inp -o ar_opt.out
rm -f ar_npt.out ar_opt.out ar_npt-1.ener ar_opt-1.restart ar_opt-1.restart.bak-* ar_npt-1.restart.bak-* ar_opt-BFGS.Hessian
python3 gen_reference.py

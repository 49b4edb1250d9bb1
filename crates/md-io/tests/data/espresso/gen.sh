#!/bin/sh
# Writes the Quantum ESPRESSO fixtures read by tests/espresso.rs and tests/fuzz_campaign.rs
# (espresso_campaign), with pw.x itself: Debian's `pw.x`, Quantum ESPRESSO 6.7MaX (package
# quantum-espresso 6.7-2+b1), norm-conserving Si.pz-vbc.UPF and ultrasoft Fe.pz-nd-rrkjus.UPF
# from /usr/share/espresso/pseudo.
#
# Each NAME.pwi is run on 1 MPI rank, 1 thread (`pw.x -in NAME.pwi > NAME.pwo`); the outputs
# are kept as pw.x wrote them. Small on purpose (ecutwfc 10-12 Ry, 2x2x2 k-points, Si2 cells,
# a few seconds each):
#   si_relax     relax, ibrav=2 with celldm(1), positions in alat (3 BFGS steps, then the final
#                coordinates block that ASE drops: it has no results of its own)
#   si_md        md, 4 steps of 20 a.u.: ibrav=0, CELL_PARAMETERS angstrom, positions in alat
#                (the first cell vector's length), species labels Si1 and Si2
#   si_vcrelax   vc-relax, ibrav=0, CELL_PARAMETERS bohr, crystal positions: the cell changes
#                every step, then the final scf at the relaxed structure (a frame in ASE)
#   si_vcmd      vc-md, 3 steps of Parrinello-Rahman cell dynamics (Beeman ions): the cell
#                grows every step; ibrav=2, positions in alat
#   si_vcmd_stopped  the same at 10 kbar with a light cell mass: the cell blows up and pw.x
#                stops in step 2's scf ("Error in routine electrons (1): charge is wrong"), a
#                run that ends mid-step, without JOB DONE.
#   ibrav0_alat  scf, CELL_PARAMETERS alat with celldm(1), positions in angstrom, stress
#   ibrav1_bohr  scf, simple cubic with celldm(1), positions in bohr
#   ibrav3_bcc   scf, bcc with A (angstrom), crystal positions, if_pos flags
#   ibrav4_hex   scf, hexagonal with celldm(1) and celldm(3), crystal positions written as
#                1/3 and 2/3, {crystal} braces, if_pos flags, forces and stress
#   ibrav6_tet   scf, simple tetragonal with A and C, (angstrom) positions, labels Si1 and Si2
#   ibrav8_ortho scf, simple orthorhombic with celldm(1..3), ATOMIC_POSITIONS without units
#                (alat, pw.x's deprecated default)
#   ibrav5_trig, ibravm5_trig111, ibravm3_bcc, ibrav7_bct, ibrav9_baseco, ibravm9_baseco,
#   ibrav91_aco, ibrav10_fco, ibrav11_bco, ibrav12_mono, ibravm12_mono, ibrav13_cmono,
#   ibravm13_cmono, ibrav14_tri
#                scf (1 k-point, conv_thr 1e-3: only the geometry matters) for every other
#                lattice pw.x 6.7 builds (m for a minus sign: ibravm5 is ibrav = -5), from
#                celldm(1..6) or from A, B, C, cosAB, cosAC, cosBC (ibravm5, ibravm3, ibravm9,
#                ibrav10, ibrav12, ibravm13, ibrav14), positions in crystal, alat, bohr or
#                angstrom units; each run's data file (tmp/PREFIX.save/data-file-schema.xml)
#                gives gen_reference.py pw.x's cell and positions with all their digits
#   fe_relax_mag relax of two Fe atoms (bcc, simple cubic cell) with nspin = 2 and
#                starting_magnetization(1) = 0.5: a "Magnetic moment per site" block after
#                each step's scf; nstep = 3 stops it before BFGS converges (exit status 3),
#                the last positions without results
# Then gen_reference.py writes reference.json: ASE's reading of every file, the geometry in
# the scf runs' data files, and the magnetic moments read by plain text matching.
#
# Run from anywhere: sh crates/md-io/tests/data/espresso/gen.sh
set -eu
cd "$(dirname "$0")"
export OMP_NUM_THREADS=1
for input in *.pwi; do
    # si_vcmd_stopped stops with pw.x's error (exit status 1), fe_relax_mag at nstep (exit
    # status 3): their outputs are the fixtures.
    pw.x -in "$input" > "${input%.pwi}.pwo" || [ "$input" = si_vcmd_stopped.pwi ] \
        || [ "$input" = fe_relax_mag.pwi ]
done
ls -l ./*.pwo
# The scf runs' data files (tmp/) are read by gen_reference.py, then removed.
python3 gen_reference.py
# vc-md also writes its cell dynamics' log files into the working directory: not kept.
rm -rf tmp vcmd.ave vcmd.avec vcmd.e vcmd.eal vcmd.p vcmd.tv vcstop.ave vcstop.avec vcstop.e \
    vcstop.eal vcstop.p vcstop.tv

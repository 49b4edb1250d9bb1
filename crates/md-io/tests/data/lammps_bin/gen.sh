#!/bin/sh
# Writes the LAMMPS binary dump fixtures read by tests/lammps.rs (the `binary` section) and
# tests/fuzz_campaign.rs (lammps_bin_campaign), with LAMMPS itself: Debian's `lmp`, LAMMPS
# 29 Sep 2021 - Update 2 (Debian package lammps 20220106.git7586adbb6a+ds1-2, Open MPI 4.1.4),
# which writes binary dumps in format revision 2 (magic header, units, time, column names).
#
# Each input dumps every frame twice, as text with every float at %.17g (the text then holds
# the binary's doubles exactly) and as binary (.bin): in.ortho an orthogonal box with boundary
# p f s, metal units, velocities, forces, image flags, per-atom computes (dump custom with
# x y z and with xs ys zs, dump atom scaled, dump atom with scale no and image yes); in.tri a
# triclinic box, real units and a per-frame atom count (dump_modify thresh, one frame empty).
# Both run on 1 MPI rank (*_np1: one chunk per frame) and, when mpirun exists, on 2 (*_np2:
# two chunks per frame; of those only custom_np2 and tri_np2 are kept, to keep the data small).
#
# Run from anywhere: sh crates/md-io/tests/data/lammps_bin/gen.sh
set -eu
cd "$(dirname "$0")"
lmp -h | grep -m1 'Large-scale Atomic/Molecular Massively Parallel Simulator'
for input in in.ortho in.tri; do
    lmp -in "$input" -var tag np1 -log none -screen none
done
if command -v mpirun >/dev/null; then
    for input in in.ortho in.tri; do
        mpirun --allow-run-as-root --oversubscribe -np 2 \
            lmp -in "$input" -var tag np2 -log none -screen none
    done
    for f in atom_np2 atom_image_np2 scaled_np2 tri_atom_np2; do
        rm -f "$f.bin" "$f.lammpstrj"
    done
fi
ls -l ./*.bin ./*.lammpstrj

#!/bin/sh
# Writes the gzip copies of four fixtures read by tests/gzip.rs, with the real gzip program
# (GNU gzip 1.12; -n leaves the name and time out of the header, so reruns give the same bytes).
#
# lmp_tri.lammpstrj.gz is two gzip members, as `cat a.gz b.gz` and bgzip make: the file cut at
# byte 10000 (inside an atom line of frame 2), each part compressed alone, the two concatenated.
set -eu
cd "$(dirname "$0")"
for f in topo_mda.pdb 3jqh.cif psf_parmed.psf; do
    gzip -9 -n -c "$f" > "$f.gz"
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
head -c 10000 lmp_tri.lammpstrj | gzip -9 -n -c > "$tmp/a.gz"
tail -c +10001 lmp_tri.lammpstrj | gzip -9 -n -c > "$tmp/b.gz"
cat "$tmp/a.gz" "$tmp/b.gz" > lmp_tri.lammpstrj.gz

# bzip2 (1.0.8): AMBER users compress their ASCII trajectories so; two streams, as pbzip2 and
# `cat a.bz2 b.bz2` make, split inside frame 2 of ParmEd's mdcrd. Topology: the prmtop.
head -c 4000 amber_ascii/box.mdcrd | bzip2 -9 -c > "$tmp/a.bz2"
tail -c +4001 amber_ascii/box.mdcrd | bzip2 -9 -c > "$tmp/b.bz2"
cat "$tmp/a.bz2" "$tmp/b.bz2" > amber_ascii/box.mdcrd.bz2
bzip2 -9 -c amber_ascii/truncoct.parm7 > amber_ascii/truncoct.parm7.bz2

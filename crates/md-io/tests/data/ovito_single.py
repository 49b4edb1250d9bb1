"""The writer the OVITO fixture scripts share (strain/, wigner_seitz/, voronoi/): a periodic
frame of one element as extended XYZ, written by ovito.io.export_file."""
import numpy as np
from ovito.data import DataCollection, ParticleType
from ovito.io import export_file

# The columns the fixtures are written and read back with.
COLUMNS = ["Particle Type", "Position.X", "Position.Y", "Position.Z"]


def write(path, cell, positions, element):
    """`positions` (N x 3) in the periodic `cell` (3 x 3 or 3 x 4 with the origin), all
    `element`, to `path`."""
    data = DataCollection()
    data.create_cell(cell, pbc=(True, True, True))
    particles = data.create_particles(count=len(positions))
    particles.create_property("Position", data=positions)
    t = particles.create_property("Particle Type", data=np.ones(len(positions), dtype=int))
    t.types.append(ParticleType(id=1, name=element))
    export_file(data, path, "xyz", columns=COLUMNS)

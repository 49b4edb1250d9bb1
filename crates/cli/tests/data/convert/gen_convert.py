"""OVITO's export of an analysed, cut-down polycrystal: the reference for `texmap convert`.

Run with OVITO 3.17.2 (pip install ovito==3.17.2) from this directory:

    python3 gen_convert.py

It loads ../../../../md-io/tests/data/grains/fcc_poly.xyz (7,881 aluminium atoms in 6 grains,
written by OVITO), applies adaptive common neighbour analysis and a coordination analysis with
a 3.2 A cutoff, deletes the FCC atoms (the grain boundaries stay) and exports what is left as a
LAMMPS dump and as extended XYZ with the structure type and coordination as columns:
ovito_defects.lammpstrj and ovito_defects.xyz.
"""

import ovito
import ovito.pipeline
from ovito.io import import_file, export_file
from ovito.modifiers import (
    CommonNeighborAnalysisModifier,
    CoordinationAnalysisModifier,
    ExpressionSelectionModifier,
    DeleteSelectedModifier,
)

SOURCE = "../../../../md-io/tests/data/grains/fcc_poly.xyz"

pipeline = import_file(SOURCE)
pipeline.modifiers.append(CommonNeighborAnalysisModifier())
pipeline.modifiers.append(CoordinationAnalysisModifier(cutoff=3.2, number_of_bins=50))
pipeline.modifiers.append(ExpressionSelectionModifier(expression="StructureType == 1"))
pipeline.modifiers.append(DeleteSelectedModifier())
data = pipeline.compute()
print("atoms left:", data.particles.count)

export_file(
    pipeline,
    "ovito_defects.lammpstrj",
    "lammps/dump",
    columns=[
        "Particle Type",
        "Position.X",
        "Position.Y",
        "Position.Z",
        "Structure Type",
        "Coordination",
    ],
)
export_file(
    pipeline,
    "ovito_defects.xyz",
    "xyz",
    columns=["Particle Type", "Position.X", "Position.Y", "Position.Z", "Structure Type", "Coordination"],
)

# Point defects: the atoms (those with occupancy 1 deleted) of a damaged BCC crystal (md-io's wigner_seitz fixture) whose
# Wigner-Seitz site holds other than one atom, with that occupancy, as extended XYZ.
from ovito.modifiers import WignerSeitzAnalysisModifier
from ovito.pipeline import FileSource

WS = "../../../../md-io/tests/data/wigner_seitz/"
ws = import_file(WS + "cur.xyz")
modifier = WignerSeitzAnalysisModifier(output_displaced=True, affine_mapping=ovito.pipeline.ReferenceConfigurationModifier.AffineMapping.ToReference)
modifier.reference = FileSource()
modifier.reference.load(WS + "ref.xyz")
ws.modifiers.append(modifier)
ws.modifiers.append(ExpressionSelectionModifier(expression="Occupancy == 1"))
ws.modifiers.append(DeleteSelectedModifier(operate_on={"particles"}))
print("defect atoms:", ws.compute().particles.count)
export_file(ws, "ovito_ws_defects.xyz", "xyz", columns=["Particle Type", "Position.X", "Position.Y", "Position.Z", "Occupancy"])

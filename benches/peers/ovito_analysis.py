"""The peer of benches/md_analysis.rs: OVITO's modifiers on the same atoms with the same
parameters, timed in the same minutes. Reads target/md_analysis_{ref,cur,poly}.xyz (written by
`cargo bench --bench md_analysis`) and prints the median of 10 evaluations per analysis, in ms,
file reading excluded (both configurations are loaded once; each evaluation is a new pipeline
over them, so OVITO's caches do not carry over).

    pip install ovito==3.17.2
    python3 benches/peers/ovito_analysis.py [threads]
"""
import os
import statistics
import sys
import time

threads = int(sys.argv[1]) if len(sys.argv) > 1 else 2
# Read by OVITO when it loads.
os.environ["OVITO_THREAD_COUNT"] = str(threads)

import ovito  # noqa: E402
from ovito.io import import_file  # noqa: E402
from ovito.modifiers import (AtomicStrainModifier, CentroSymmetryModifier,  # noqa: E402
                             CommonNeighborAnalysisModifier, CoordinationAnalysisModifier,
                             DeleteSelectedModifier, ExpressionSelectionModifier,
                             GrainSegmentationModifier, PolyhedralTemplateMatchingModifier,
                             VoronoiAnalysisModifier)
from ovito.io import export_file  # noqa: E402
from ovito.pipeline import Pipeline, StaticSource  # noqa: E402

here = os.path.dirname(os.path.abspath(__file__))
target = os.path.join(here, "..", "..", "target")

ref = os.path.join(target, "md_analysis_ref.xyz")
cur = os.path.join(target, "md_analysis_cur.xyz")
reference_data = import_file(ref).compute()
current_data = import_file(cur).compute()
poly_data = import_file(os.path.join(target, "md_analysis_poly.xyz")).compute()
print(f"{reference_data.particles.count} atoms, OVITO {ovito.version_string}, {threads} threads")


def timed(name, data, make_modifier, runs=10):
    times = []
    for _ in range(runs):
        pipe = Pipeline(source=StaticSource(data=data))
        made = make_modifier()
        for m in made if isinstance(made, list) else [made]:
            pipe.modifiers.append(m)
        t = time.perf_counter()
        pipe.compute()
        times.append((time.perf_counter() - t) * 1000)
    print(f"{name}: median {statistics.median(times):.1f} ms (min {min(times):.1f})")


def strain():
    m = AtomicStrainModifier(cutoff=3.0, output_nonaffine_squared_displacements=True)
    m.reference = StaticSource(data=reference_data)
    return m


timed("cna", reference_data, lambda: CommonNeighborAnalysisModifier())
timed("centrosymmetry_conventional", reference_data,
      lambda: CentroSymmetryModifier(num_neighbors=12, mode=CentroSymmetryModifier.Mode.Conventional))
timed("centrosymmetry_matching", reference_data,
      lambda: CentroSymmetryModifier(num_neighbors=12, mode=CentroSymmetryModifier.Mode.Matching))
timed("strain", current_data, strain)
timed("voronoi", reference_data, lambda: VoronoiAnalysisModifier(compute_indices=True))
timed("coordination", reference_data, lambda: CoordinationAnalysisModifier(cutoff=3.0))
timed("rdf_8A_200_bins", reference_data,
      lambda: CoordinationAnalysisModifier(cutoff=8.0, number_of_bins=200))
print(f"polycrystal: {poly_data.particles.count} atoms")
timed("orientations_poly", poly_data,
      lambda: PolyhedralTemplateMatchingModifier(output_orientation=True, output_rmsd=True))
timed("grains_poly", poly_data,
      lambda: [PolyhedralTemplateMatchingModifier(output_orientation=True),
               GrainSegmentationModifier()])


def export_defects(runs=10):
    """CNA, the FCC atoms deleted, the rest written as a LAMMPS dump with the structure type:
    what `texmap convert --select 'not cna fcc' --columns cna` does (the bench's
    export_defects_poly)."""
    out = os.path.join(target, "md_analysis_export_ovito.lammpstrj")
    times = []
    for _ in range(runs):
        pipe = Pipeline(source=StaticSource(data=poly_data))
        pipe.modifiers.append(CommonNeighborAnalysisModifier())
        pipe.modifiers.append(ExpressionSelectionModifier(expression="StructureType == 1"))
        pipe.modifiers.append(DeleteSelectedModifier())
        t = time.perf_counter()
        export_file(pipe, out, "lammps/dump",
                    columns=["Particle Type", "Position.X", "Position.Y",
                             "Position.Z", "Structure Type"])
        times.append((time.perf_counter() - t) * 1000)
    print(f"export_defects_poly: median {statistics.median(times):.1f} ms (min {min(times):.1f})")


export_defects()

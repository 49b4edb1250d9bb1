"""What MDAnalysis's TRRReader reads from written.trr (see gen_trr_write.sh)."""
import gzip
import json

import MDAnalysis
from MDAnalysis.coordinates.TRR import TRRReader

frames = []
for ts in TRRReader("written.trr"):
    frames.append({
        "step": int(ts.data["step"]),
        "time": float(ts.time),
        "dimensions": [float(x) for x in ts.dimensions],
        "positions": ts.positions.tolist() if ts.has_positions else None,
        "velocities": ts.velocities.tolist() if ts.has_velocities else None,
        "forces": ts.forces.tolist() if ts.has_forces else None,
    })
doc = {"program": f"MDAnalysis {MDAnalysis.__version__}", "frames": frames}
with gzip.GzipFile("mdanalysis.json.gz", "wb", mtime=0) as f:
    f.write(json.dumps(doc).encode())

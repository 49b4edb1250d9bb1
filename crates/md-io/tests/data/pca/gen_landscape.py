"""NumPy's free-energy landscape of MDAnalysis's PC1–PC2 projections: the reference for
md-io's `pca::Landscape` and `texmap convert --pca-landscape-table`
(crates/md-io/tests/pca.rs).

Run from this directory, after gen_pca.py: python3 gen_landscape.py

landscape_reference.json: the "aligned name CA" projections of pca_reference.json (frames
on PC1 and PC2, as MDAnalysis's PCA gave them), binned by numpy.histogram2d(pc1, pc2,
bins=B) for B = 12 and 5 (its range: each projection's lowest to highest value), and
dG = -R T ln(n / n_max) in kJ/mol at T = 300 K (R = 8.314462618e-3 kJ/(mol K)) for every bin
with a frame; counts[i][j] is bin i along PC1 and j along PC2 (NumPy's order).
"""
import json

import numpy as np

R = 8.314462618e-3
T = 300.0
ref = json.load(open("pca_reference.json"))["aligned name CA"]
proj = np.array(ref["projections"])
out = {"temperature": T, "landscapes": []}
for bins in (12, 5):
    h, xe, ye = np.histogram2d(proj[:, 0], proj[:, 1], bins=bins)
    with np.errstate(divide="ignore"):
        g = -R * T * np.log(h / h.max())
    out["landscapes"].append({
        "bins": bins,
        "x_edges": [float(v) for v in xe],
        "y_edges": [float(v) for v in ye],
        "counts": [[int(v) for v in row] for row in h],
        "free_energy": [[float(f"{v:.10g}") if np.isfinite(v) else None for v in row] for row in g],
    })
    print(bins, int(h.sum()), int((h > 0).sum()), float(np.nanmax(np.where(np.isfinite(g), g, np.nan))))
with open("landscape_reference.json", "w") as f:
    json.dump(out, f)
    f.write("\n")

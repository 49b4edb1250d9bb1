"""matplotlib's colormaps sampled for the colormap test, and the fit of the knot tables in
`crates/md-scene/src/colormap.rs`.

Run from this directory (see README.md for versions):
    python3 gen_colormaps.py                 # writes the JSON, prints the knot tables
    python3 gen_colormaps.py --alternatives  # also prints the errors of the rejected designs

Files:
- colormaps_matplotlib.json  for viridis, plasma, coolwarm, turbo and gray: the colour of
                             t = i/255, i = 0..=255, from `matplotlib.colormaps[name](t)`, as
                             8-bit sRGB codes floor(c * 255 + 0.5)
- stdout                     the knot tables for colormap.rs (paste them over the old ones
                             unchanged) and each map's measured error against the JSON; with
                             --alternatives, the worst code error of least-squares Chebyshev
                             polynomials per channel (degrees 6, 9, 12) and the fewest uniformly
                             spaced knots that stay within two codes

The fit: every map is a piecewise-linear curve through knots (t, r, g, b). Knot positions are
chosen greedily among the 256 sample positions: a segment grows while the straight line between
its end samples stays within TOL codes of every sample it spans. With the positions fixed
(rounded to 4 decimals), the knot colours are the least-squares fit to all 256 samples, rounded
to 4 decimals and clipped to [0, 1]; the error printed is that of the curve colormap.rs
evaluates, with those rounded numbers.
"""
import json
import os
import sys

import matplotlib
import numpy as np

NAMES = ["viridis", "plasma", "coolwarm", "turbo", "gray"]
# Greedy tolerance in 8-bit codes. 0.75 leaves the fitted curve within 0.62 codes of every
# sample, so the rounded codes differ by at most one.
TOL = 0.75

HERE = os.path.dirname(os.path.abspath(__file__))
t = np.linspace(0.0, 1.0, 256)


def code(c):
    """8-bit code as Rust's `(c * 255.0).round()` gives it for c >= 0."""
    return np.floor(c * 255.0 + 0.5).astype(int)


def greedy_knots(ref):
    """Sample indices of the knots: each segment as long as its chord stays within TOL."""
    knots = [0]
    a = 0
    while a < 255:
        b = a + 1
        while b < 255:
            seg = np.arange(a, b + 2)
            f = ((seg - a) / (b + 1 - a))[:, None]
            chord = (1.0 - f) * ref[a] + f * ref[b + 1]
            if np.abs(chord - ref[seg]).max() * 255.0 > TOL:
                break
            b += 1
        knots.append(b)
        a = b
    return np.array(knots)


def alternatives(name, ref):
    """The rejected designs: per-channel polynomials, and knots spaced uniformly."""
    worst = {}
    for degree in (6, 9, 12):
        v = np.polynomial.chebyshev.chebvander(2.0 * t - 1.0, degree)
        coef, *_ = np.linalg.lstsq(v, ref, rcond=None)
        worst[degree] = np.abs(code(v @ coef) - code(ref)).max()
    uniform = None
    for k in range(2, 257):
        a = hat_basis(np.linspace(0.0, 1.0, k))
        values, *_ = np.linalg.lstsq(a, ref, rcond=None)
        values = np.clip(np.round(values, 4), 0.0, 1.0)
        if np.abs(code(a @ values) - code(ref)).max() <= 2:
            uniform = k
            break
    print(f"// {name} alternatives: polynomial degree 6/9/12 worst "
          f"{worst[6]}/{worst[9]}/{worst[12]} codes; {uniform} uniform knots for <= 2 codes")


def hat_basis(kt):
    """Matrix A with A @ values = the piecewise-linear curve through knots kt at every t."""
    k = len(kt)
    seg = np.clip(np.searchsorted(kt, t, side="right") - 1, 0, k - 2)
    f = (t - kt[seg]) / (kt[seg + 1] - kt[seg])
    a = np.zeros((256, k))
    a[np.arange(256), seg] = 1.0 - f
    a[np.arange(256), seg + 1] += f
    return a


out = {
    "source": f"matplotlib {matplotlib.__version__}: matplotlib.colormaps[name](t)",
    "t": "i / 255 for i in 0..=255",
    "codes": "floor(c * 255 + 0.5) per channel r, g, b",
    "maps": {},
}
for name in NAMES:
    ref = np.asarray(matplotlib.colormaps[name](t))[:, :3]
    out["maps"][name] = code(ref).tolist()

    kt = np.round(greedy_knots(ref) / 255.0, 4)
    a = hat_basis(kt)
    values, *_ = np.linalg.lstsq(a, ref, rcond=None)
    values = np.clip(np.round(values, 4), 0.0, 1.0) + 0.0  # + 0.0: no "-0.0000"
    fit = a @ values
    worst_codes = np.abs(code(fit) - code(ref)).max()
    worst_float = np.abs(fit - ref).max() * 255.0
    print(f"// {name}: {len(kt)} knots, worst {worst_codes} code(s) "
          f"(curve within {worst_float:.2f} codes of matplotlib)")
    if "--alternatives" in sys.argv[1:]:
        alternatives(name, ref)
    print(f"const {name.upper()}: [[f32; 4]; {len(kt)}] = [")
    for ti, (r, g, b) in zip(kt, values):
        print(f"    [{ti:.4f}, {r:.4f}, {g:.4f}, {b:.4f}],")
    print("];")

with open(os.path.join(HERE, "colormaps_matplotlib.json"), "w") as f:
    f.write("{\n")
    f.write(f'  "source": {json.dumps(out["source"])},\n')
    f.write(f'  "t": {json.dumps(out["t"])},\n')
    f.write(f'  "codes": {json.dumps(out["codes"])},\n')
    f.write('  "maps": {\n')
    for i, name in enumerate(NAMES):
        rows = ", ".join(f"[{r}, {g}, {b}]" for r, g, b in out["maps"][name])
        comma = "," if i + 1 < len(NAMES) else ""
        f.write(f'    "{name}": [{rows}]{comma}\n')
    f.write("  }\n}\n")

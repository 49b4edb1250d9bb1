"""Velocity autocorrelation and vibrational density of states references for `--vacf-table`
and `--vdos-table` (crates/cli/tests/convert.rs), from a trajectory MDAnalysis 2.11.0 wrote.

Run from this directory: python3 gen_vacf.py (numpy, MDAnalysis, tidynamics).

- vel.gro + vel.trr (written by MDAnalysis, positions and velocities, 320 frames 0.01 ps
  apart): 36 atoms in a 30 A cube, integrated by BAOAB Langevin dynamics at 300 K with ten
  1 fs steps per frame: 8 atoms named OW (oxygen, 15.999 u) and 16 named HW (hydrogen,
  1.008 u), each on an isotropic spring about its own site (3 THz and 10 THz, friction 2/ps),
  and 12 free NA atoms (sodium, 22.990 u, friction 10/ps: D = kT / (m gamma) = 1.085 A^2/ps
  for the infinite run).
- vacf_reference.json, from the .trr read back by MDAnalysis (velocities in A/ps):
  - vacf: tidynamics.acf (the autocorrelation over every time origin, divided by the number
    of origins) of each atom's three velocity series, summed over the axes and averaged over
    all atoms and over the OW, HW and NA atoms, per lag;
  - d_green_kubo: one third of numpy's trapezoid integral of each column over lags 0 to 1.595
    ps (half the longest lag), in 10^-5 cm^2/s;
  - vdos: numpy's rfft of each velocity series zero-padded to n = 1024 (the power of two at or
    above twice the frames), |.|^2 summed over the axes and over all atoms weighted by
    MDAnalysis's masses, and over the atoms of each name unweighted, every column scaled to
    integrate to 3 over the frequencies k / (n dt), k = 0 .. n/2 (trapezoid); the frequencies
    in THz; each kind's peak frequency.
"""
import json

import numpy as np
import MDAnalysis as mda
from MDAnalysis.coordinates.memory import MemoryReader
import tidynamics

rng = np.random.default_rng(61207)
n_o, n_h, n_na = 8, 16, 12
n = n_o + n_h + n_na
frames, sub, dt_int, box = 320, 10, 0.001, 30.0
names = ["OW"] * n_o + ["HW"] * n_h + ["NA"] * n_na
mass = np.array([15.999] * n_o + [1.008] * n_h + [22.990] * n_na)
nu0 = np.array([3.0] * n_o + [10.0] * n_h + [0.0] * n_na)  # THz
gamma = np.array([2.0] * (n_o + n_h) + [10.0] * n_na)  # 1/ps
kt = 2.494339  # kJ/mol at 300 K; kJ/g = 1e6 m^2/s^2 = 100 A^2/ps^2
sigma2 = kt / mass * 100.0  # <v_x^2> in A^2/ps^2
omega2 = (2 * np.pi * nu0) ** 2
site = rng.random((n, 3)) * box
x = np.zeros((n, 3))
v = rng.normal(size=(n, 3)) * np.sqrt(sigma2)[:, None]
c1 = np.exp(-gamma * dt_int)[:, None]
c2 = np.sqrt((1 - c1[:, 0] ** 2) * sigma2)[:, None]
w2 = omega2[:, None]


def step(x, v):
    v = v - 0.5 * dt_int * w2 * x
    x = x + 0.5 * dt_int * v
    v = c1 * v + c2 * rng.normal(size=v.shape)
    x = x + 0.5 * dt_int * v
    v = v - 0.5 * dt_int * w2 * x
    return x, v


for _ in range(2000):  # equilibrate
    x, v = step(x, v)
pos, vel = [], []
for f in range(frames):
    pos.append(site + x)
    vel.append(v.copy())
    for _ in range(sub):
        x, v = step(x, v)
pos = np.array(pos, dtype=np.float32)
vel = np.array(vel, dtype=np.float32)

u = mda.Universe.empty(n, n_residues=n, atom_resindex=np.arange(n), trajectory=True)
u.add_TopologyAttr("name", names)
u.add_TopologyAttr("type", ["O"] * n_o + ["H"] * n_h + ["NA"] * n_na)
u.add_TopologyAttr("resname", ["SOL"] * (n_o + n_h) + ["NA"] * n_na)
u.add_TopologyAttr("resid", np.arange(1, n + 1))
u.add_TopologyAttr("masses", mass)
u.load_new(pos, format=MemoryReader, velocities=vel, dt=0.01,
           dimensions=np.array([[box, box, box, 90, 90, 90]] * frames))
u.atoms.write("vel.gro")
with mda.Writer("vel.trr", n) as w:
    for ts in u.trajectory:
        w.write(u.atoms)

r = mda.Universe("vel.gro", "vel.trr")
times = np.array([ts.time for ts in r.trajectory])
v = np.array([ts.velocities.copy() for ts in r.trajectory])  # (T, n, 3)
T = len(times)
dt = float(times[1] - times[0])
groups = {"all": np.arange(n)}
for name in ("HW", "NA", "OW"):
    groups[name] = np.where(np.array(names) == name)[0]
acf = np.array([[tidynamics.acf(v[:, i, a]) for a in range(3)] for i in range(n)]).sum(axis=1)
lag_t = np.arange(T) * dt
half = T // 2
vacf = {g: acf[idx].mean(axis=0) for g, idx in groups.items()}
d_gk = {g: float(np.trapezoid(c[: half + 1], lag_t[: half + 1]) / 3.0 * 10.0) for g, c in vacf.items()}

nfft = 1 << int(np.ceil(np.log2(2 * T)))
power = (np.abs(np.fft.rfft(v, n=nfft, axis=0)) ** 2).sum(axis=2)  # (bins, n)
freq = np.arange(nfft // 2 + 1) / (nfft * dt)
step_nu = freq[1]


def norm(p):
    area = step_nu * (p.sum() - 0.5 * (p[0] + p[-1]))
    return 3.0 * p / area


vdos = {"all": norm((power * r.atoms.masses[None, :]).sum(axis=1))}
for g in ("HW", "NA", "OW"):
    vdos[g] = norm(power[:, groups[g]].sum(axis=1))
peaks = {g: float(freq[1:][np.argmax(vdos[g][1:])]) for g in ("HW", "OW")}
print("dt", dt, "T", T, "nfft", nfft, "D_gk", d_gk, "peaks", peaks)
print("masses", sorted(set(r.atoms.masses.round(3))))
def g9(values):
    return [float(f"{x:.9g}") for x in values]


json.dump(
    {
        "source": "MDAnalysis 2.11.0 read vel.trr; tidynamics acf; numpy rfft (gen_vacf.py)",
        "dt": dt,
        "integrate_to": float(lag_t[half]),
        "lag_time": g9(lag_t),
        "vacf": {g: g9(c) for g, c in vacf.items()},
        "d_green_kubo": d_gk,
        "frequency": g9(freq),
        "vdos": {g: g9(c) for g, c in vdos.items()},
        "peak_thz": peaks,
    },
    open("vacf_reference.json", "w"),
)

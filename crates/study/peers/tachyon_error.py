"""Tachyon's default image against Tachyon's own converged image, beside ours against our reference.

The error that issue #19 asks about is each renderer's sampling error at its everyday setting:
OVITO's Tachyon at its defaults (antialiasing 12 samples, ambient occlusion 12 samples, shadows)
against Tachyon itself at 128 + 128 samples, and texmap's `good` preset against reftrace at 8x8
samples with 256 AO rays (the images `texmap compare --scene S1 --quality-axis` writes). Tachyon's
lighting and AO model differ from ours, so each is compared with its own converged image; our
reference is an independent renderer, so our figure also holds the method's own error.

Usage (OVITO from PyPI in a venv; Debian needs libvulkan1 and mesa-vulkan-drivers even for Tachyon):
  cargo run --release -p texmap-study --example quality_prof -- s1 --dump s1.xyz
  texmap compare --scene S1 --quality-axis --out q
  python tachyon_error.py s1.xyz 500 500 42.304066 q/s1_aa4-ao8-shadows.png \
      q/s1_reftrace-8x8-ao256-shadows.png
PSNR is texmap-core's: RGB channels of the 8-bit images (transparent pixels composited on black),
peak 255, over every pixel.
"""
import math
import re
import sys
import time

import numpy as np
from PIL import Image


def load(path):
    a = np.asarray(Image.open(path).convert("RGBA")).astype(np.float64)
    return np.round(a[..., :3] * a[..., 3:4] / 255.0)


def psnr(a, b):
    mse = ((load(a) - load(b)) ** 2).mean()
    return math.inf if mse == 0 else 10 * math.log10(255.0**2 / mse)


def tachyon(xyz, w, h, hfov, aa, ao, out):
    from ovito.io import import_file
    from ovito.vis import TachyonRenderer, Viewport

    header = open(xyz).readlines()[1]
    eye = tuple(map(float, re.search(r'eye="([^"]+)"', header).group(1).split()))
    d = tuple(map(float, re.search(r'dir="([^"]+)"', header).group(1).split()))
    pipeline = import_file(xyz, columns=["Particle Type", "Position.X", "Position.Y",
                                         "Position.Z", "Radius", "Color.R", "Color.G", "Color.B"])
    pipeline.add_to_scene()
    vfov = 2 * math.atan(math.tan(math.radians(hfov) / 2) * h / w)
    vp = Viewport(type=Viewport.Type.Perspective, camera_pos=eye, camera_dir=d, fov=vfov)
    r = TachyonRenderer(antialiasing_samples=aa, ambient_occlusion_samples=ao)
    t = time.time()
    vp.render_image(size=(w, h), filename=out, renderer=r, background=(0, 0, 0))
    pipeline.remove_from_scene()
    return time.time() - t


def main():
    xyz, w, h, hfov, ours, ref = sys.argv[1:7]
    w, h, hfov = int(w), int(h), float(hfov)
    t_def = tachyon(xyz, w, h, hfov, 12, 12, "tachyon_default.png")
    tachyon(xyz, w, h, hfov, 64, 64, "tachyon_64.png")
    tachyon(xyz, w, h, hfov, 128, 128, "tachyon_128.png")
    print(f"Tachyon default ({t_def:.2f} s) vs Tachyon 128+128: "
          f"{psnr('tachyon_default.png', 'tachyon_128.png'):.2f} dB")
    print(f"Tachyon 64+64 vs 128+128 (how converged the reference is): "
          f"{psnr('tachyon_64.png', 'tachyon_128.png'):.2f} dB")
    print(f"texmap {ours} vs {ref}: {psnr(ours, ref):.2f} dB")


if __name__ == "__main__":
    main()

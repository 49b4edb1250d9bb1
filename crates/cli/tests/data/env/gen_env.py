"""A small HDR latitude-longitude sky (a sun 8x brighter than white) written by OpenCV
(opencv-python-headless) as Radiance RGBE, sky.hdr: the format HDRI libraries such as Poly
Haven serve. sky_opencv.f32 holds what OpenCV decodes from it (rows top to bottom, RGB, little-
endian f32), which crates/cli/tests/envmap.rs writes as an EXR to render the same environment
both ways.

    pip install opencv-python-headless numpy
    python3 gen_env.py
"""
import os

import cv2
import numpy as np

h, w = 64, 128
y, x = np.mgrid[0:h, 0:w].astype(np.float32)
lat = (0.5 - (y + 0.5) / h) * np.pi
lon = ((x + 0.5) / w - 0.5) * 2 * np.pi
sky = np.stack([0.25 + 0.5 * np.clip(np.sin(lat), 0, 1)] * 3, axis=-1)
sky[..., 2] += 0.6 * np.clip(np.sin(lat), 0, 1)  # blue above
ground = lat < 0
sky[ground] = np.stack([0.30, 0.22, 0.12], axis=-1) * (1 + 0.3 * np.cos(4 * lon[ground]))[:, None]
# A sun far brighter than 1: the reason for HDR.
d = np.hypot(lat - 0.6, np.minimum(np.abs(lon - 0.8), 2 * np.pi - np.abs(lon - 0.8)))
sky += (8.0 * np.exp(-((d / 0.08) ** 2)))[..., None]
bgr = sky[..., ::-1].astype(np.float32)
assert cv2.imwrite("sky.hdr", bgr)
back = cv2.imread("sky.hdr", cv2.IMREAD_ANYDEPTH | cv2.IMREAD_COLOR)
assert back.dtype == np.float32 and back.shape == (h, w, 3)
back[..., ::-1].astype("<f4").tofile("sky_opencv.f32")
print(open("sky.hdr", "rb").read(11), os.path.getsize("sky.hdr"), float(back.max()))

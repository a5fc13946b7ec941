#!/usr/bin/env python3
"""Writes the example image pairs of examples/studies/same_different.* (8-bit grey PNGs, sRGB).

base.png        a smooth random texture (a stand-in for a render of a full model)
base_copy.png   the same pixels (an identical pair: the observer must be at chance)
fine.png        base with a faint fine checker (+-1 sRGB code, 2 px period, mean unchanged) in one
                corner: an "imperceptible" change (below threshold at its frequency)
blob.png        base plus a 2 deg wide bump of 25 % contrast: a deliberately perceptible change
Deterministic (seeded); run from this folder: python3 make_images.py
"""
import math
import random
import struct
import zlib

W = H = 128


def png(path, rows):
    raw = b"".join(b"\x00" + bytes(r) for r in rows)
    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
    data = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", W, H, 8, 0, 0, 0, 0))
            + chunk(b"sRGB", b"\x00") + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))
    with open(path, "wb") as f:
        f.write(data)


def to_code(lum):
    lum = min(1.0, max(0.0, lum))
    v = 12.92 * lum if lum <= 0.0031308 else 1.055 * lum ** (1 / 2.4) - 0.055
    return int(round(v * 255))


def from_code(c):
    v = c / 255.0
    return v / 12.92 if v <= 0.04045 else ((v + 0.055) / 1.055) ** 2.4


rnd = random.Random(14)
waves = [(rnd.uniform(1, 6), rnd.uniform(0, 2 * math.pi), rnd.uniform(0, 2 * math.pi), rnd.uniform(0.02, 0.05))
         for _ in range(8)]
base = []
for y in range(H):
    row = []
    for x in range(W):
        lum = 0.6
        for f, ang, ph, a in waves:
            u = (x * math.cos(ang) + y * math.sin(ang)) / W
            lum *= 1 + a * math.sin(2 * math.pi * f * u + ph)
        row.append(to_code(lum))
    base.append(row)
png("base.png", base)
png("base_copy.png", [list(r) for r in base])

fine = [list(r) for r in base]
for y in range(96, 128):
    for x in range(96, 128):
        fine[y][x] = max(0, min(255, fine[y][x] + (1 if (x + y) % 2 == 0 else -1)))
png("fine.png", fine)

blob = [list(r) for r in base]
for y in range(H):
    for x in range(W):
        r2 = ((x - 64) ** 2 + (y - 64) ** 2) / (16.0 ** 2)
        blob[y][x] = to_code(from_code(base[y][x]) * (1 + 0.25 * math.exp(-r2)))
png("blob.png", blob)

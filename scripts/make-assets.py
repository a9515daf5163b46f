#!/usr/bin/env python3
"""Writes lucent's own assets under assets/ with the Python standard library only (zlib + struct):

- assets/textures/checker.png: 256x256 8x8 checkerboard whose colour tells the texture coordinates
  (red grows with u to the right, blue grows with v upwards; uv (0,0) is the bottom-left corner,
  the image's last row), with a white dot in the top-left check.
- assets/textures/wood.png: 256x256 procedural wood boards (grain lines, seams), tiling seamlessly.
- assets/cube/cube.obj + cube.mtl: a unit cube, one quad per face with UVs spanning the texture
  and normals, material map_Kd ../textures/checker.png.
- assets/floor/floor.obj + floor.mtl: a 10x10 quad in the y = 0 plane with UVs 0..2 (the texture
  repeats twice each way), material map_Kd ../textures/wood.png.

Deterministic: running it again gives the same bytes. Usage: scripts/make-assets.py [root]
"""
import argparse
import math
import os
import struct
import zlib


def write_png(path, width, height, pixel):
    """8-bit RGB PNG; pixel(x, y) -> (r, g, b) in 0..255, y = 0 the top row."""
    raw = bytearray()
    for y in range(height):
        raw.append(0)  # filter: none
        for x in range(width):
            raw.extend(bytes(pixel(x, y)))

    def chunk(tag, data):
        c = struct.pack(">I", len(data)) + tag + data
        return c + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(bytes(raw), 9))
    png += chunk(b"IEND", b"")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(png)


def checker(x, y, size=256, n=8):
    cell = size // n
    cx, cy = x // cell, y // cell
    u = (cx + 0.5) / n               # u of the check's centre, left to right
    v = 1.0 - (cy + 0.5) / n         # v of the check's centre, bottom to top
    light = (cx + cy) % 2 == 0
    base = 0.85 if light else 0.35
    r = base * (0.35 + 0.65 * u)
    g = base * 0.55
    b = base * (0.35 + 0.65 * v)
    # a white dot in the top-left check (u small, v large) to see the image's orientation
    dx, dy = x - cell // 2, y - cell // 2
    if dx * dx + dy * dy <= (cell // 4) ** 2:
        r = g = b = 1.0
    return tuple(int(round(255 * c)) for c in (r, g, b))


def wood(x, y, size=256, planks=4):
    # boards running along the image's y axis, with grain lines that wobble along the board; every
    # term is periodic over the image, so the texture tiles seamlessly under repeat wrapping
    width = size // planks
    k = x // width
    lx = (x % width + 0.5) / width           # 0..1 across the board
    py = (y + 0.5) / size                    # 0..1 along the board
    phase = (k * 0.37) % 1.0
    wobble = (0.03 * math.sin(2 * math.pi * (py + phase))
              + 0.01 * math.sin(2 * math.pi * (3 * py + 2 * phase)))
    grain = 0.5 + 0.5 * math.sin(2 * math.pi * (5.0 + k) * (lx + wobble + phase))
    fine = 0.5 + 0.5 * math.sin(2 * math.pi * 9.0 * (lx + 0.5 * wobble))
    t = 0.6 * grain ** 4 + 0.15 * fine + 0.1 * ((k * 0.53) % 1.0)
    if x % width in (0, width - 1):
        t = 1.3                              # the seam between two boards
    light, dark = (0.78, 0.55, 0.32), (0.45, 0.26, 0.12)
    return tuple(max(0, min(255, int(round(255 * (l + (d - l) * t))))) for l, d in zip(light, dark))


CUBE_OBJ = """# scripts/make-assets.py: a unit cube centred at the origin, one quad per face
mtllib cube.mtl
v -0.5 -0.5 -0.5
v  0.5 -0.5 -0.5
v  0.5  0.5 -0.5
v -0.5  0.5 -0.5
v -0.5 -0.5  0.5
v  0.5 -0.5  0.5
v  0.5  0.5  0.5
v -0.5  0.5  0.5
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn  0  0  1
vn  0  0 -1
vn  1  0  0
vn -1  0  0
vn  0  1  0
vn  0 -1  0
g cube
usemtl checker
# counter-clockwise seen from outside; uv (0,0) at each face's bottom-left
f 5/1/1 6/2/1 7/3/1 8/4/1
f 2/1/2 1/2/2 4/3/2 3/4/2
f 6/1/3 2/2/3 3/3/3 7/4/3
f 1/1/4 5/2/4 8/3/4 4/4/4
f 8/1/5 7/2/5 3/3/5 4/4/5
f 1/1/6 2/2/6 6/3/6 5/4/6
"""

CUBE_MTL = """# lucent asset (scripts/make-assets.py)
newmtl checker
Kd 0.8 0.8 0.8
Ks 0 0 0
illum 1
map_Kd ../textures/checker.png
"""

FLOOR_OBJ = """# scripts/make-assets.py: a 10x10 floor at y = 0, its texture repeated twice each way
mtllib floor.mtl
v -5 0  5
v  5 0  5
v  5 0 -5
v -5 0 -5
vt 0 0
vt 2 0
vt 2 2
vt 0 2
vn 0 1 0
usemtl wood
f 1/1/1 2/2/1 3/3/1 4/4/1
"""

FLOOR_MTL = """# lucent asset (scripts/make-assets.py)
newmtl wood
Kd 0.6 0.45 0.3
illum 1
map_Kd ../textures/wood.png
"""


def main():
    default = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "assets")
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 usage="scripts/make-assets.py [root]")
    ap.add_argument("root", nargs="?", default=default,
                    help="the directory to write into (default: the checkout's assets/)")
    root = ap.parse_args().root
    write_png(os.path.join(root, "textures", "checker.png"), 256, 256, checker)
    write_png(os.path.join(root, "textures", "wood.png"), 256, 256, wood)
    for rel, text in (("cube/cube.obj", CUBE_OBJ), ("cube/cube.mtl", CUBE_MTL),
                      ("floor/floor.obj", FLOOR_OBJ), ("floor/floor.mtl", FLOOR_MTL)):
        path = os.path.join(root, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w", newline="\n") as f:
            f.write(text)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Writes DIR/env.pfm (a 512x256 sky: a blue gradient above the horizon, brown ground below, and a
3x3-texel sun of radiance 5e4) and DIR/scene.json (a floor and three spheres, diffuse, rough
conductor and plastic, lit by that map alone). A benchmark of the environment map's sampling:

    python3 bench/envmap/make_scene.py /tmp/envt
    build/lucent render /tmp/envt/scene.json -o out.exr --width 256 --height 144 --spp 128
"""
import json
import os
import struct
import sys


def main(out_dir):
    os.makedirs(out_dir, exist_ok=True)
    w, h = 512, 256
    rows = []
    for y in range(h):
        v = (y + 0.5) / h
        sky = (0.3 + 0.7 * (1 - v), 0.4 + 0.6 * (1 - v), 0.9) if v < 0.5 else (0.2, 0.18, 0.15)
        rows.append([sky] * w)
    for y in range(60, 63):
        for x in range(300, 303):
            rows[y][x] = (5e4, 4.5e4, 4e4)
    with open(os.path.join(out_dir, "env.pfm"), "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        for row in reversed(rows):  # PFM rows run bottom to top
            f.write(b"".join(struct.pack("<3f", *p) for p in row))
    scene = {
        "camera": {"position": [0, 2.2, 9], "look_at": [0, 1, 0], "up": [0, 1, 0], "fov": 38},
        "film": {"width": 128, "height": 72, "filter": {"type": "box", "radius": 0.5}},
        "integrator": {"type": "path", "max_depth": 6, "spp": 1024, "seed": 0},
        "materials": {
            "floor": {"type": "diffuse", "albedo": [0.55, 0.55, 0.55]},
            "diffuse": {"type": "diffuse", "albedo": [0.8, 0.25, 0.2]},
            "gold": {"type": "conductor", "specular": [1.0, 0.78, 0.34], "roughness": 0.25},
            "plastic": {"type": "plastic", "albedo": [0.1, 0.3, 0.8], "specular": [1, 1, 1],
                        "roughness": 0.08, "ior": 1.5}},
        "shapes": [
            {"type": "triangles", "material": "floor",
             "positions": [[-20, 0, -6], [20, 0, -6], [20, 0, 20], [-20, 0, 20]],
             "indices": [0, 3, 2, 0, 2, 1]},
            {"type": "sphere", "center": [-2.5, 1, 0], "radius": 1, "material": "diffuse"},
            {"type": "sphere", "center": [0, 1, 0], "radius": 1, "material": "gold"},
            {"type": "sphere", "center": [2.5, 1, 0], "radius": 1, "material": "plastic"}],
        "lights": [{"type": "environment", "file": "env.pfm", "scale": 1}]}
    with open(os.path.join(out_dir, "scene.json"), "w") as f:
        json.dump(scene, f, indent=1)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: make_scene.py OUT_DIR")
    main(sys.argv[1])

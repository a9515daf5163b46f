#!/usr/bin/env python3
"""Writes the scenes of BENCHMARKS.md, "Precision": the small scene of
tests/test_stability_scene.cpp (floor, two spheres, a standing triangle, a rotated box mesh, a
point light and a sphere lamp) scaled by s and translated by t (x -> s x + t on every axis; radii
scale by s, point intensities by s^2, so the expected image is the same), and the sphere light
over a plane of tests/test_precision.cpp translated by t. base-stored-T.json is the untranslated
scene as the device stores it at T: every coordinate (and the camera position) replaced by
float32(x + T) - T, so that rendering it near the origin shows what float storage alone changes.

usage: scripts/precision-scenes.py OUTDIR [WIDTH]"""
import argparse
import json
import math
import os
import struct


def base_scene(width):
    c, s = math.cos(math.pi / 6), math.sin(math.pi / 6)
    box = []
    for i in range(8):
        x = 0.25 if i & 1 else -0.25
        y = 0.5 if i & 2 else 0.0
        z = 0.25 if i & 4 else -0.25
        box.append([c * x + s * z, y, -s * x + c * z + 1.25])
    return {
        "camera": {"position": [0, 1.2, 5], "look_at": [0, 0.4, 0], "fov": 38},
        "film": {"width": width, "height": width},
        "integrator": {"type": "path", "max_depth": 4},
        "materials": {
            "floor": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]},
            "red": {"type": "diffuse", "albedo": [0.8, 0.25, 0.2]},
            "blue": {"type": "diffuse", "albedo": [0.2, 0.3, 0.8]},
            "green": {"type": "diffuse", "albedo": [0.3, 0.7, 0.3]},
            "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [6, 5, 4]}},
        "shapes": [
            {"type": "triangles", "material": "floor",
             "positions": [[-3, 0, -3], [3, 0, -3], [3, 0, 3], [-3, 0, 3]],
             "indices": [0, 2, 1, 0, 3, 2]},
            {"type": "sphere", "center": [-0.8, 0.6, 0], "radius": 0.6, "material": "red"},
            {"type": "sphere", "center": [0.9, 0.5, 0.4], "radius": 0.5, "material": "blue"},
            {"type": "triangles", "material": "blue",
             "positions": [[-2, 0, -1.5], [2, 0, -1.5], [0, 2, -1.8]], "indices": [0, 1, 2]},
            {"type": "triangles", "material": "green", "positions": box,
             "indices": [0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3,
                         0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5]},
            {"type": "sphere", "center": [1.2, 2.2, 1.0], "radius": 0.3, "material": "lamp"}],
        "lights": [{"type": "point", "position": [2, 4, 3], "intensity": [30, 28, 25]}]}


def sphere_light_over_plane(width):
    return {
        "camera": {"position": [0, -3, 1], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov": 40},
        "film": {"width": width, "height": width},
        "integrator": {"type": "path", "max_depth": 2},
        "materials": {"plane": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]},
                      "lamp": {"type": "diffuse", "albedo": [0, 0, 0], "emission": [4, 4, 4]}},
        "shapes": [
            {"type": "triangles", "material": "plane",
             "positions": [[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]],
             "indices": [0, 1, 2, 0, 2, 3]},
            {"type": "sphere", "center": [0.25, 0.125, 2], "radius": 0.5, "material": "lamp"}]}


def transformed(scene, s, t):
    f = lambda p: [s * v + t for v in p]
    scene["camera"]["position"] = f(scene["camera"]["position"])
    scene["camera"]["look_at"] = f(scene["camera"]["look_at"])
    for sh in scene["shapes"]:
        if sh["type"] == "sphere":
            sh["center"] = f(sh["center"])
            sh["radius"] *= s
        else:
            sh["positions"] = [f(p) for p in sh["positions"]]
    for l in scene.get("lights", []):
        l["position"] = f(l["position"])
        l["intensity"] = [v * s * s for v in l["intensity"]]
    return scene


def f32(v):
    return struct.unpack("f", struct.pack("f", v))[0]


def stored(scene, t):
    g = lambda p: [f32(v + t) - t for v in p]
    cam = scene["camera"]
    pos = g(cam["position"])
    cam["look_at"] = [a + (b - c) for a, b, c in zip(cam["look_at"], pos, cam["position"])]
    cam["position"] = pos
    for sh in scene["shapes"]:
        if sh["type"] == "sphere":
            sh["center"] = g(sh["center"])
            sh["radius"] = f32(sh["radius"])
        else:
            sh["positions"] = [g(p) for p in sh["positions"]]
    for l in scene.get("lights", []):
        l["position"] = g(l["position"])
    return scene


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 usage="scripts/precision-scenes.py OUTDIR [WIDTH]")
    ap.add_argument("outdir")
    ap.add_argument("width", nargs="?", type=int, default=48, help="film width and height (48)")
    args = ap.parse_args()
    if args.width < 1:
        ap.error("WIDTH must be a positive number of pixels, got %d" % args.width)
    out, width = args.outdir, args.width
    os.makedirs(out, exist_ok=True)
    variants = {"origin": (1, 0), "scale-1e-4": (1e-4, 0), "scale-1e6": (1e6, 0),
                "translate-1e4": (1, 1e4), "translate-1e5": (1, 1e5)}
    for name, (s, t) in variants.items():
        with open(os.path.join(out, "base-%s.json" % name), "w") as f:
            json.dump(transformed(base_scene(width), s, t), f)
    for t in (1e4, 1e5):
        with open(os.path.join(out, "base-stored-%s.json" % ("1e4" if t == 1e4 else "1e5")), "w") as f:
            json.dump(stored(base_scene(width), t), f)
    for name, t in {"origin": 0, "translate-1e4": 1e4, "translate-1e5": 1e5}.items():
        with open(os.path.join(out, "lamp-%s.json" % name), "w") as f:
            json.dump(transformed(sphere_light_over_plane(width), 1, t), f)


main()

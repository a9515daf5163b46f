"""Fixtures of lucent's Python suite: a small scene (as a dict of the JSON format) and sessions
with the environment's device and caches (CTest sets LUCENT_CACHE_DIR to the build's)."""
import copy
import os
import pathlib
import re

import numpy as np
import pytest

import lucent

SOURCE_DIR = pathlib.Path(os.environ.get("LUCENT_SOURCE_DIR",
                                         pathlib.Path(__file__).resolve().parents[2]))
SHARED_DIR = SOURCE_DIR.parent / "shared"

# The scene of tests/test_session.cpp: a sphere on a floor under a point light, 16x12.
SMALL = {
    "camera": {"position": [0, 1, 5], "look_at": [0, 0.5, 0], "fov": 40},
    "film": {"width": 16, "height": 12},
    "integrator": {"type": "path", "max_depth": 4, "spp": 4},
    "materials": {"w": {"type": "diffuse", "albedo": [0.7, 0.6, 0.5]},
                  "g": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
    "shapes": [{"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5, "material": "w"},
               {"type": "triangles", "material": "g",
                "positions": [[-5, 0, -5], [5, 0, -5], [5, 0, 5], [-5, 0, 5]],
                "indices": [0, 2, 1, 0, 3, 2]}],
    "lights": [{"type": "point", "position": [2, 4, 3], "intensity": [20, 20, 20]}],
}


@pytest.fixture
def small_dict():
    return copy.deepcopy(SMALL)


@pytest.fixture
def small_scene():
    return lucent.scene_from_dict(SMALL)


def add_degenerate_triangle(scene):
    """Appends a triangle whose vertices 0 and 4 (a copy of vertex 0) are equal: packing skips it
    with a warning ("skipped 1 degenerate or non-finite triangle")."""
    scene.positions = np.vstack([scene.positions, scene.positions[:1]])
    t = lucent.Triangle()
    t.v = (0, 4, 1)
    scene.triangles.append(t)


def session(**kwargs):
    """A session with the environment's defaults (device, kernel and cache directories)."""
    return lucent.Renderer(**{**lucent.environment(), **kwargs})


@pytest.fixture
def renderer():
    r = session()
    yield r
    r.close()


def header_fields(header, struct):
    """The data members of `struct` in include/lucent/<header>, parsed from the source: the
    bindings must expose every one of them."""
    text = (SOURCE_DIR / "include" / "lucent" / header).read_text()
    body = re.search(r"struct %s \{(.*?)\n\};" % struct, text, re.S).group(1)
    body = re.sub(r"//[^\n]*", "", body)
    body = re.sub(r"\([^;{]*\)[^;{]*\{[^{}]*\}", "();", body)  # inline member functions
    fields = []
    for statement in body.split(";"):
        statement = " ".join(statement.split())
        if not statement or "(" in statement or statement.startswith(("static", "using")):
            continue
        # "double a[3] = {0, 0, 0}, b[3] = {...}" -> declarators split outside braces
        depth, parts, current = 0, [], ""
        for ch in statement:
            depth += ch in "{"
            depth -= ch in "}"
            if ch == "," and depth == 0:
                parts.append(current)
                current = ""
            else:
                current += ch
        parts.append(current)
        for i, part in enumerate(parts):
            part = re.split(r"[={]", part)[0].strip()
            name = re.sub(r"\[.*\]", "", part).split()[-1]
            fields.append(name)
    return fields

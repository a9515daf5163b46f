#!/usr/bin/env python3
"""lucent scenes rendered by Mitsuba 3 (scripts/bench-mitsuba.sh drives this).

Two jobs, both from one lucent JSON scene:

  bench_mitsuba.py lucent-scene SCENE OUT.json --size W H --spp N --max-depth D
      writes a copy of SCENE for lucent with the film size, a box filter (radius 0.5, Mitsuba's
      default box), spp and max_depth overridden and mesh paths made absolute;

  bench_mitsuba.py render SCENE --size W H --spp N --max-depth D --threads T [--output X.exr]
      builds the same scene with Mitsuba's dict API and renders it with variant llvm_ad_rgb:
      one warm-up render (tracing, LLVM compilation or Dr.Jit's kernel cache), then one timed
      render. Prints the timed render's wall time and Mpaths/s, its CPU time (user + system of
      the process, every thread), Dr.Jit's kernel history (compile and execution time) and the
      linear image mean.

The subset of lucent's scene format translated (anything else is refused with a message):
the path integrator (no clamp, MIS on); camera position/look_at/up/fov (vertical; no roll, no
aperture); diffuse materials with an RGB albedo and optional emission; shapes sphere, mesh (OBJ
with its MTL's Kd/Ke unless "material" overrides; the transform steps
scale/rotate/translate/matrix) and triangles; lights point and environment (constant radiance).
Emissive shapes become one-sided area lights (lucent emits from the front side: the side of
(v1-v0)x(v2-v0), which is Mitsuba's face normal too).

Equivalences (checked on the image means, see BENCHMARKS.md "Throughput against Mitsuba 3"):
  - max_depth: lucent counts path segments (1: emitters seen directly, 2: direct light); so does
    Mitsuba's path integrator (max_depth 1: only directly visible emitters);
  - Russian roulette at each renderer's default (lucent: rr_depth of the scene, default 4,
    survival max(beta) capped at 1; Mitsuba: rr_depth 5, survival min(max(beta), 0.95));
  - meshes: OBJ quads split along the shorter diagonal (tinyobjloader's rule, which lucent uses);
    faces whose three or four corners repeat another face's (CornellBox-Original.obj's two
    "bottom" faces repeat a side face) are dropped, as bench/cycles/cornell_box.py does; flat
    shading unless the OBJ has normals (then per-vertex normals, as lucent);
  - the box filter: lucent's box of radius 0.5 samples the pixel uniformly; Mitsuba's "box"
    filter (radius 0.5) does the same.
"""
import argparse
import array
import json
import math
import os
import resource
import struct
import sys
import tempfile
import time


def fail(msg):
    sys.exit("bench_mitsuba.py: " + msg)


# ------------------------------------------------------------------------------------------------
# lucent scene reading
# ------------------------------------------------------------------------------------------------
def read_mtl(path):
    mats, cur = {}, None
    if not os.path.exists(path):
        return mats
    with open(path) as f:
        for line in f:
            w = line.split("#")[0].split()
            if not w:
                continue
            if w[0] == "newmtl":
                cur = w[1]
                mats[cur] = {"Kd": [0.0, 0.0, 0.0], "Ke": [0.0, 0.0, 0.0], "Ks": [0.0, 0.0, 0.0],
                             "illum": 2, "map_Kd": None}
            elif cur and w[0] in ("Kd", "Ke", "Ks") and len(w) >= 4:
                mats[cur][w[0]] = [float(x) for x in w[1:4]]
            elif cur and w[0] == "illum":
                mats[cur]["illum"] = int(w[1])
            elif cur and w[0] == "map_Kd":
                mats[cur]["map_Kd"] = w[-1]
    return mats


def read_obj(path):
    """Triangles of an OBJ file grouped by material name: {name: (positions, normals or None)},
    each a flat list of 3 corners per triangle. Quads are split along the shorter diagonal."""
    with open(path) as f:
        text = f.read()
    v, vn = [], []
    groups = {}
    mtllibs = []
    cur = ""
    seen = set()
    for line in text.splitlines():
        w = line.split("#")[0].split()
        if not w:
            continue
        if w[0] == "v":
            v.append((float(w[1]), float(w[2]), float(w[3])))
        elif w[0] == "vn":
            vn.append((float(w[1]), float(w[2]), float(w[3])))
        elif w[0] == "usemtl":
            cur = w[1]
        elif w[0] == "mtllib":
            mtllibs += w[1:]
        elif w[0] == "f":
            corners = []
            for c in w[1:]:
                parts = c.split("/")
                vi = int(parts[0])
                vi = vi - 1 if vi > 0 else len(v) + vi
                ni = None
                if len(parts) >= 3 and parts[2]:
                    ni = int(parts[2])
                    ni = ni - 1 if ni > 0 else len(vn) + ni
                corners.append((vi, ni))
            key = frozenset(v[vi] for vi, _ in corners)
            if key in seen:  # a twin of an earlier face (same corner positions)
                continue
            seen.add(key)
            if len(corners) == 4:
                p = [v[vi] for vi, _ in corners]
                d02 = sum((p[2][k] - p[0][k]) ** 2 for k in range(3))
                d13 = sum((p[3][k] - p[1][k]) ** 2 for k in range(3))
                tris = [(0, 1, 2), (0, 2, 3)] if d02 < d13 else [(0, 1, 3), (1, 2, 3)]
            else:
                tris = [(0, k, k + 1) for k in range(1, len(corners) - 1)]
            g = groups.setdefault(cur, ([], []))
            for t in tris:
                for k in t:
                    vi, ni = corners[k]
                    g[0].append(v[vi])
                    g[1].append(vn[ni] if ni is not None else None)
    out = {}
    for name, (pos, nor) in groups.items():
        out[name] = (pos, None if any(n is None for n in nor) else nor)
    return out, mtllibs


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def rotation(axis, degrees):
    n = math.sqrt(sum(x * x for x in axis))
    x, y, z = (v / n for v in axis)
    t = math.radians(degrees)
    c, s = math.cos(t), math.sin(t)
    return [[c + x * x * (1 - c), x * y * (1 - c) - z * s, x * z * (1 - c) + y * s, 0],
            [y * x * (1 - c) + z * s, c + y * y * (1 - c), y * z * (1 - c) - x * s, 0],
            [z * x * (1 - c) - y * s, z * y * (1 - c) + x * s, c + z * z * (1 - c), 0],
            [0, 0, 0, 1]]


def transform_matrix(steps):
    m = [[float(i == j) for j in range(4)] for i in range(4)]
    for step in steps or []:
        (kind, val), = step.items()
        t = [[float(i == j) for j in range(4)] for i in range(4)]
        if kind == "scale":
            sc = [val] * 3 if isinstance(val, (int, float)) else val
            for k in range(3):
                t[k][k] = float(sc[k])
        elif kind == "rotate":
            t = rotation(val["axis"], val["degrees"])
        elif kind == "translate":
            for k in range(3):
                t[k][3] = float(val[k])
        elif kind == "matrix":
            t = [[float(x) for x in row] for row in val]
        else:
            fail("unsupported transform step %s" % kind)
        m = matmul(t, m)
    return m


def det3(m):
    return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
            m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
            m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))


def inverse_transpose3(m):
    """Cofactor matrix of the 3x3 part (the inverse transpose up to a positive or negative
    scale; normals are normalised afterwards and their sign follows the determinant)."""
    c = [[0.0] * 3 for _ in range(3)]
    for i in range(3):
        for j in range(3):
            r = [k for k in range(3) if k != i]
            q = [k for k in range(3) if k != j]
            c[i][j] = (-1) ** (i + j) * (m[r[0]][q[0]] * m[r[1]][q[1]] - m[r[0]][q[1]] * m[r[1]][q[0]])
    d = det3(m)
    return [[x / d for x in row] for row in c]


def apply_transform(m, pos, nor):
    """Positions (and normals) through the affine m; corners 1 and 2 of each triangle swapped
    when m mirrors, so that the front side stays where the file put it (lucent's loader)."""
    p = [(m[0][0] * x + m[0][1] * y + m[0][2] * z + m[0][3],
          m[1][0] * x + m[1][1] * y + m[1][2] * z + m[1][3],
          m[2][0] * x + m[2][1] * y + m[2][2] * z + m[2][3]) for x, y, z in pos]
    n = None
    if nor is not None:
        it = inverse_transpose3(m)
        n = []
        for x, y, z in nor:
            v = [it[k][0] * x + it[k][1] * y + it[k][2] * z for k in range(3)]
            ln = math.sqrt(sum(c * c for c in v)) or 1.0
            n.append(tuple(c / ln for c in v))
    if det3(m) < 0:
        for k in range(0, len(p), 3):
            p[k + 1], p[k + 2] = p[k + 2], p[k + 1]
            if n is not None:
                n[k + 1], n[k + 2] = n[k + 2], n[k + 1]
    return p, n


def scene_triangles(scene, scene_dir):
    """Every triangle shape as (material dict, positions, normals or None): flat lists of
    corners, three per triangle; material dicts hold albedo and emission."""
    mats = scene.get("materials", {})

    def material(name):
        if name not in mats:
            fail("material %s is not in the scene" % name)
        m = mats[name]
        if m.get("type", "diffuse") != "diffuse" or isinstance(m.get("albedo"), dict):
            fail("material %s: only diffuse materials with an RGB albedo are translated" % name)
        return {"albedo": m.get("albedo", [0.8, 0.8, 0.8]), "emission": m.get("emission", [0, 0, 0])}

    out = []
    for i, sh in enumerate(scene.get("shapes", [])):
        kind = sh.get("type")
        if kind == "mesh":
            path = os.path.join(scene_dir, sh["file"])
            groups, mtllibs = read_obj(path)
            mtl = {}
            for lib in mtllibs:
                mtl.update(read_mtl(os.path.join(os.path.dirname(path), lib)))
            m4 = transform_matrix(sh.get("transform"))
            for name, (pos, nor) in groups.items():
                if "material" in sh:
                    mat = material(sh["material"])
                elif name in mtl:
                    e = mtl[name]
                    if e["map_Kd"] or (e["illum"] >= 2 and max(e["Ks"]) > 0) or e["illum"] in (4, 6, 7, 9):
                        fail("%s: MTL material %s is not a plain diffuse one" % (path, name))
                    mat = {"albedo": e["Kd"], "emission": e["Ke"]}
                else:
                    mat = {"albedo": [0.8, 0.8, 0.8], "emission": [0, 0, 0]}
                p, n = apply_transform(m4, pos, nor)
                out.append((mat, p, n))
        elif kind == "triangles":
            if "uvs" in sh:
                fail("shapes/%d: uvs are not translated" % i)
            idx = sh["indices"]
            pos = [tuple(sh["positions"][k]) for k in idx]
            nor = [tuple(sh["normals"][k]) for k in idx] if "normals" in sh else None
            p, n = apply_transform(transform_matrix(sh.get("transform")), pos, nor)
            out.append((material(sh["material"]), p, n))
        elif kind != "sphere":
            fail("shapes/%d: type %s is not translated" % (i, kind))
    return out, material


def check_camera(cam):
    for k in ("roll", "aperture"):
        if cam.get(k, 0) != 0:
            fail("camera %s is not translated" % k)


# ------------------------------------------------------------------------------------------------
# lucent-scene: the lucent side of the benchmark
# ------------------------------------------------------------------------------------------------
def write_lucent_scene(args):
    with open(args.scene) as f:
        scene = json.load(f)
    scene_dir = os.path.dirname(os.path.abspath(args.scene))
    film = scene.setdefault("film", {})
    film["width"], film["height"] = args.size
    film["filter"] = {"type": "box"}
    integ = scene.setdefault("integrator", {})
    integ["spp"] = args.spp
    integ["max_depth"] = args.max_depth
    if args.sampler:
        integ["sampler"] = args.sampler
    for sh in scene.get("shapes", []):
        if "file" in sh:
            sh["file"] = os.path.normpath(os.path.join(scene_dir, sh["file"]))
    for li in scene.get("lights", []):
        if "file" in li:
            li["file"] = os.path.normpath(os.path.join(scene_dir, li["file"]))
    for m in scene.get("materials", {}).values():
        if isinstance(m.get("albedo"), dict):
            m["albedo"]["texture"] = os.path.normpath(os.path.join(scene_dir, m["albedo"]["texture"]))
    with open(args.out, "w") as f:
        json.dump(scene, f, indent=1)


# ------------------------------------------------------------------------------------------------
# render: the Mitsuba side
# ------------------------------------------------------------------------------------------------
def write_ply(path, p, n):
    """Binary little-endian PLY of an unindexed triangle list (3 vertices per face)."""
    nv = len(p)
    with open(path, "wb") as f:
        head = ["ply", "format binary_little_endian 1.0", "element vertex %d" % nv,
                "property float x", "property float y", "property float z"]
        if n is not None:
            head += ["property float nx", "property float ny", "property float nz"]
        head += ["element face %d" % (nv // 3), "property list uchar int vertex_indices",
                 "end_header"]
        f.write(("\n".join(head) + "\n").encode())
        vert = array.array("f")
        for k in range(nv):
            vert.extend(p[k])
            if n is not None:
                vert.extend(n[k])
        if sys.byteorder != "little":
            vert.byteswap()
        f.write(vert.tobytes())
        face = struct.Struct("<B3i")
        f.write(b"".join(face.pack(3, k, k + 1, k + 2) for k in range(0, nv, 3)))


def mitsuba_scene(args, tmpdir):
    import mitsuba as mi
    with open(args.scene) as f:
        scene = json.load(f)
    scene_dir = os.path.dirname(os.path.abspath(args.scene))
    cam = scene.get("camera", {})
    check_camera(cam)
    # Mitsuba renders a path tracer without clamping: a scene asking lucent for anything else
    # would be compared against a different estimator
    integ = scene.get("integrator", {})
    if integ.get("type", "path") != "path":
        fail("integrator %s is not translated (only path)" % integ["type"])
    if integ.get("clamp", 0) or integ.get("mis", True) is False:
        fail("integrator clamp and mis false are not translated")
    w, h = args.size
    d = {"type": "scene"}
    d["integrator"] = {"type": "path", "max_depth": args.max_depth}
    d["sensor"] = {
        "type": "perspective",
        "fov": cam.get("fov", 45),  # (lucent's defaults: include/lucent/scene.hpp)
        "fov_axis": "y",
        "to_world": mi.ScalarTransform4f().look_at(origin=cam.get("position", [0, 0, 5]),
                                                   target=cam.get("look_at", [0, 0, 0]),
                                                   up=cam.get("up", [0, 1, 0])),
        "film": {"type": "hdrfilm", "width": w, "height": h, "rfilter": {"type": "box"},
                 "pixel_format": "rgb"},
        "sampler": {"type": "independent", "sample_count": args.spp, "seed": 0},
    }
    tris, material = scene_triangles(scene, scene_dir)

    def bsdf(mat):  # lucent's BSDFs see both sides of a surface (the normal faces the ray)
        return {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": {
            "type": "rgb", "value": list(mat["albedo"])}}}

    def emitter(mat):
        e = list(mat["emission"])
        return {"type": "area", "radiance": {"type": "rgb", "value": e}} if max(e) > 0 else None

    ntri = 0
    for k, (mat, p, n) in enumerate(tris):
        path = os.path.join(tmpdir, "mesh%d.ply" % k)
        write_ply(path, p, n)
        ntri += len(p) // 3
        sh = {"type": "ply", "filename": path, "face_normals": n is None, "bsdf": bsdf(mat)}
        if emitter(mat):
            sh["emitter"] = emitter(mat)
        d["mesh%d" % k] = sh
    nsph = 0
    for i, sh in enumerate(scene.get("shapes", [])):
        if sh.get("type") != "sphere":
            continue
        mat = material(sh["material"])
        s = {"type": "sphere", "center": sh["center"], "radius": sh["radius"], "bsdf": bsdf(mat)}
        if emitter(mat):
            s["emitter"] = emitter(mat)
        d["sphere%d" % i] = s
        nsph += 1
    for i, li in enumerate(scene.get("lights", [])):
        kind = li.get("type")
        if kind == "point":
            d["light%d" % i] = {"type": "point", "position": li["position"],
                                "intensity": {"type": "rgb", "value": li["intensity"]}}
        elif kind == "environment" and "file" not in li:
            d["light%d" % i] = {"type": "constant",
                                "radiance": {"type": "rgb", "value": li["radiance"]}}
        else:
            fail("lights/%d: type %s is not translated" % (i, kind))
    return d, ntri, nsph


def render(args):
    import drjit as dr
    dr.set_thread_count(args.threads)
    import mitsuba as mi
    mi.set_variant(args.variant)
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        d, ntri, nsph = mitsuba_scene(args, tmp)
        scene = mi.load_dict(d)
        t1 = time.perf_counter()
    w, h = args.size
    paths = w * h * args.spp
    print("mitsuba: %s %s, drjit %s, %d threads, %s: %d triangles, %d spheres, %dx%d, %d spp, "
          "max_depth %d; scene load %.3f s"
          % (args.variant, mi.__version__, dr.__version__, dr.thread_count(), args.scene, ntri, nsph,
             w, h, args.spp, args.max_depth, t1 - t0))

    dr.set_flag(dr.JitFlag.KernelHistory, True)
    cpu_s = 0.0

    def cpu():  # user + system CPU seconds of the process, every thread
        r = resource.getrusage(resource.RUSAGE_SELF)
        return r.ru_utime + r.ru_stime

    def one(seed):
        nonlocal cpu_s
        dr.kernel_history()  # clear
        ts, cs = time.perf_counter(), cpu()
        img = mi.render(scene, spp=args.spp, seed=seed)
        dr.eval(img)
        dr.sync_thread()
        te = time.perf_counter()
        cpu_s = cpu() - cs
        hist = dr.kernel_history()
        ex = sum(k.get("execution_time", 0.0) for k in hist) * 1e-3
        cg = sum(k.get("codegen_time", 0.0) + k.get("backend_time", 0.0) for k in hist) * 1e-3
        hits = sum(1 for k in hist if k.get("cache_hit") or k.get("cache_disk"))
        return img, te - ts, ex, cg, len(hist), hits

    for r in range(args.warmup):
        _, wall, ex, cg, nk, hits = one(0)
        print("mitsuba: warm-up render %.3f s (kernels %d, cached %d, compile %.3f s, execution "
              "%.3f s)" % (wall, nk, hits, cg, ex))
    img, wall, ex, cg, nk, hits = one(0)
    print("mitsuba: timed render %.3f s: %.4f Mpaths/s (kernels %d, cached %d, compile %.3f s, "
          "execution %.3f s: %.4f Mpaths/s)" % (wall, paths / wall * 1e-6, nk, hits, cg, ex,
                                                paths / ex * 1e-6 if ex > 0 else 0))
    print("mitsuba: render seconds %.4f" % wall)
    print("mitsuba: render CPU seconds %.4f (%.4f Mpaths per CPU second)" % (cpu_s, paths / cpu_s * 1e-6))
    flat = img.array  # height x width x 3, row-major
    idx = dr.arange(mi.UInt32, w * h) * 3
    m = [float(dr.mean(dr.gather(mi.Float, flat, idx + c))[0]) for c in range(3)]
    print("mitsuba: image mean (linear) R %.5f G %.5f B %.5f, average %.5f"
          % (m[0], m[1], m[2], sum(m) / 3))
    if args.output:
        mi.util.write_bitmap(args.output, img)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    for name in ("lucent-scene", "render"):
        p = sub.add_parser(name)
        p.add_argument("scene")
        if name == "lucent-scene":
            p.add_argument("out")
        p.add_argument("--size", type=int, nargs=2, default=[256, 256], metavar=("W", "H"))
        p.add_argument("--spp", type=int, default=64)
        p.add_argument("--max-depth", type=int, required=True)
        if name == "lucent-scene":
            p.add_argument("--sampler", choices=["sobol", "independent"],
                           help="lucent's sampler (default: the scene's; Mitsuba's is independent)")
        if name == "render":
            p.add_argument("--threads", type=int, default=2)
            p.add_argument("--variant", default="llvm_ad_rgb")
            p.add_argument("--warmup", type=int, default=1)
            p.add_argument("--output")
    args = ap.parse_args()
    if args.cmd == "lucent-scene":
        write_lucent_scene(args)
    else:
        render(args)


if __name__ == "__main__":
    main()

"""Benchmark (BENCHMARKS.md, "Python bindings"): what the binding costs against the `lucent`
command, and what a camera move costs a session.

    PYTHONPATH=build/python python3 python/bench_session.py --cli build/lucent [--reps 5]

1. The same scene and spp rendered by the CLI and by a Python process (load, session, render,
   write the EXR), alternated A B A B: the render time each reports (kernel passes) and each
   process's CPU time (user + sys, from getrusage of the child).
2. In one session, on the 100k-triangle dragon (../shared): set_scene, render, move the camera,
   set_scene, render: the time of each set_scene and the session's counters.
"""
import argparse
import os
import pathlib
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time

import lucent

ROOT = pathlib.Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"

PY_RENDER = """
import sys, lucent
scene = lucent.load_scene(sys.argv[1])
r = lucent.Renderer(**lucent.environment())
r.set_scene(scene)
r.render(int(sys.argv[2]))
res = r.result()
lucent.write_render_exr(sys.argv[3], res)
print(f"render {res.seconds:.4f}")
"""


def child(cmd):
    """Runs cmd; returns (its CPU seconds, its stdout + stderr)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run(cmd, check=True, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, out.stdout + out.stderr


def python_against_cli(cli, scene, spp, reps):
    runs = {"cli": [], "python": []}
    # removed at the end (mkdtemp left both images behind on every run)
    with tempfile.TemporaryDirectory() as tmpdir:
        tmp = pathlib.Path(tmpdir)
        for rep in range(reps + 1):  # the first pair warms the kernel caches and is dropped
            for who in ("cli", "python"):
                if who == "cli":
                    cpu, text = child([cli, "render", scene, "-o", str(tmp / "a.exr"), "--spp",
                                       str(spp)])
                    seconds = float(re.search(r"spp in ([0-9.]+) s", text).group(1))
                else:
                    cpu, text = child([sys.executable, "-c", PY_RENDER, scene, str(spp),
                                       str(tmp / "b.exr")])
                    seconds = float(re.search(r"render ([0-9.]+)", text).group(1))
                if rep > 0:
                    runs[who].append((seconds, cpu))
    print(f"\n{scene}, {spp} spp, {reps} alternated runs each (median; min-max)")
    for who, r in runs.items():
        s = [x[0] for x in r]
        c = [x[1] for x in r]
        print(f"  {who:7s} render {statistics.median(s):.3f} s ({min(s):.3f}-{max(s):.3f}), "
              f"process CPU {statistics.median(c):.2f} s ({min(c):.2f}-{max(c):.2f})")
    ratio = statistics.median([p[0] / c[0] for p, c in zip(runs["python"], runs["cli"])])
    ratio_cpu = statistics.median([p[1] / c[1] for p, c in zip(runs["python"], runs["cli"])])
    print(f"  python / cli: render time {ratio:.3f}, process CPU {ratio_cpu:.3f} "
          "(median of the pairs)")


def camera_move(spp):
    obj = SHARED / "assets" / "meshes" / "dragon.obj"
    if not obj.exists():
        print("\n(camera move: no ../shared/assets/meshes/dragon.obj, skipped)")
        return
    scene = lucent.scene_from_dict({
        "film": {"width": 320, "height": 240},
        "integrator": {"type": "path", "max_depth": 4},
        "materials": {"m": {"type": "plastic", "albedo": [0.6, 0.5, 0.4], "roughness": 0.2}},
        "shapes": [{"type": "mesh", "file": str(obj), "material": "m"}],
        "lights": [{"type": "environment", "radiance": [1, 1, 1]}],
    })
    lo, hi = scene.positions.min(axis=0), scene.positions.max(axis=0)
    centre, size = (lo + hi) / 2, float((hi - lo).max())
    scene.camera.look_at = centre
    scene.camera.position = centre + [0, 0.2 * size, 1.6 * size]
    r = lucent.Renderer(**lucent.environment())
    print(f"\ncamera move, one session: dragon ({len(scene.triangles)} triangles), "
          f"{scene.film.width}x{scene.film.height}, {spp} spp")
    for step in ("first", "moved"):
        t0 = time.perf_counter()
        r.set_scene(scene)
        t_set = time.perf_counter() - t0
        r.render(spp)
        s = r.stats
        print(f"  {step}: set_scene {t_set * 1e3:8.1f} ms, render {r.result().seconds:.3f} s; "
              f"bvh_builds {s.bvh_builds}, kernel builds {s.kernel_compiles + s.kernel_cache_loads}"
              f", kernel_reuses {s.kernel_reuses}, buffer_uploads {s.buffer_uploads}, "
              f"bytes_uploaded {s.bytes_uploaded}, bvh_seconds {s.bvh_seconds:.3f}")
        scene.camera.position.x += 0.1 * size


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cli", required=True)
    p.add_argument("--scene", default=str(ROOT / "scenes" / "cornell-box.json"))
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--reps", type=int, default=5)
    a = p.parse_args()
    if a.spp < 1 or a.reps < 1:  # (--reps 0 ended in statistics.median of nothing)
        p.error("--spp and --reps must be at least 1")
    print("load", open("/proc/loadavg").read().split()[:3], "device", lucent.list_devices()[0].name)
    python_against_cli(a.cli, a.scene, a.spp, a.reps)
    camera_move(16)
    print("load", open("/proc/loadavg").read().split()[:3])


if __name__ == "__main__":
    os.environ.setdefault("PYTHONDONTWRITEBYTECODE", "1")
    main()

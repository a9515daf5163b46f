"""A camera move by set_scene against one by set_camera, in one session, alternated.

The benchmark of BENCHMARKS.md, "Python bindings" (a camera move). set_scene is given the scene
again with its camera changed; set_camera the camera alone.

    PYTHONPATH=build/python python3 python/bench_camera_move.py /tmp/soup/soup.json [--rounds 6]

Each round moves the camera twice, once each way (the first way alternates between rounds), and
renders 1 spp after each move; it prints each call's wall time, the session's pack_seconds for
it, and the counters that say what it did. set_scene from Python includes the binding's copy of
the scene (Python threads may change it while the call runs), timed on its own as scene.copy().
"""
import argparse
import statistics
import sys
import time

import lucent


def timed(f):
    t0 = time.perf_counter()
    f()
    return time.perf_counter() - t0


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scene")
    p.add_argument("--rounds", type=int, default=6)
    a = p.parse_args()
    if a.rounds < 1:
        p.error("--rounds must be at least 1")
    print("load", open("/proc/loadavg").read().split()[:3], "device", lucent.list_devices()[0].name)
    try:
        scene = lucent.load_scene(a.scene)
    except lucent.Error as e:  # one line, not a traceback
        sys.exit(f"bench_camera_move.py: {e}")
    r = lucent.Renderer(**lucent.environment())
    t_first = timed(lambda: r.set_scene(scene))
    r.render(1)
    print(f"{a.scene}: {len(scene.triangles)} triangles, {scene.film.width}x{scene.film.height}; "
          f"first set_scene {t_first:.3f} s")
    times = {"set_scene": [], "set_camera": [], "scene.copy()": []}
    packs = {"set_scene": [], "set_camera": []}
    step = 0

    def move(way):
        nonlocal step
        step += 1
        camera = r.scene.camera
        camera.position = (camera.position[0] + 0.01 * (1 if step % 2 else -1),
                           camera.position[1], camera.position[2])
        before = r.stats
        if way == "set_scene":
            scene.camera = camera
            t = timed(lambda: r.set_scene(scene))
        else:
            t = timed(lambda: r.set_camera(camera))
        after = r.stats
        assert r.spp == 0, "the move dropped the accumulation"
        r.render(1)
        times[way].append(t)
        packs[way].append(after.pack_seconds - before.pack_seconds)
        return (after.scene_packs - before.scene_packs, after.camera_moves - before.camera_moves,
                after.bvh_builds - before.bvh_builds, after.buffer_uploads - before.buffer_uploads)

    for i in range(a.rounds):
        order = ("set_scene", "set_camera") if i % 2 == 0 else ("set_camera", "set_scene")
        counts = {way: move(way) for way in order}
        times["scene.copy()"].append(timed(scene.copy))
        print(f"  round {i + 1}: " + ", ".join(
            f"{way} {times[way][-1] * 1e3:.3f} ms (packs, moves, bvh, uploads {counts[way]})"
            for way in order))
    for way, t in times.items():
        extra = (f"; pack_seconds {statistics.median(packs[way]) * 1e3:.3f} ms"
                 if way in packs else "")
        print(f"{way:13s} median {statistics.median(t) * 1e3:9.3f} ms "
              f"({min(t) * 1e3:.3f}-{max(t) * 1e3:.3f}){extra}")
    print("load", open("/proc/loadavg").read().split()[:3])


if __name__ == "__main__":
    main()

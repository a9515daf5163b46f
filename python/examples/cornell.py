"""Render the Cornell box, move the camera, render again on the same session (no BVH or kernel
rebuild: the session's stats show it), and compare the two images.

    PYTHONPATH=build/python python3 python/examples/cornell.py [--spp 64] [--size 400] [--out DIR]

Needs the assets of ../shared (scenes/cornell-box.json refers to them).
"""
import argparse
import pathlib

import lucent

here = pathlib.Path(__file__).resolve().parent
parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--spp", type=int, default=64)
parser.add_argument("--size", type=int, default=0,
                    help="film width and height (default: the scene's)")
parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("."))
args = parser.parse_args()

scene = lucent.load_scene(here.parent.parent / "scenes" / "cornell-box.json")
if args.size:
    scene.film.width = scene.film.height = args.size

renderer = lucent.Renderer(**lucent.environment())  # LUCENT_DEVICE, LUCENT_CACHE_DIR, ...
renderer.set_scene(scene)
renderer.render(args.spp)
first = renderer.result()
print(f"first:  {first.spp} spp in {first.seconds:.2f} s on {first.device}")
print("       ", renderer.stats)

camera = scene.camera
camera.position.x += 0.3  # a new camera: only the launch parameters change
renderer.set_camera(camera)
renderer.render(args.spp)
second = renderer.result()
stats = renderer.stats
print(f"second: {second.spp} spp in {second.seconds:.2f} s")
print("       ", stats)
assert stats.bvh_builds == 1 and stats.kernel_compiles + stats.kernel_cache_loads == 1
assert stats.scene_packs == 1 and stats.camera_moves == 1, "the move packed nothing"

lucent.write_image(args.out / "cornell-1.png", first, film=scene.film)
lucent.write_image(args.out / "cornell-2.png", second, film=scene.film)
c = lucent.compare(first, second)
print(f"compare: {'same' if c.passed else 'different'} images: {c.failed_pixels} of "
      f"{c.width * c.height} pixels differ (max |z| {c.max_z:.1f}), RMSE {c.rmse:.4f}")

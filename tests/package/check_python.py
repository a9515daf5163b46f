"""Imports the installed lucent module (PYTHONPATH = the install prefix's module directory) and
renders with a session: a camera move rebuilds neither the BVH nor the kernel. Needs no numpy."""
import pathlib
import sys

import lucent

prefix = pathlib.Path(sys.argv[1]).resolve()
where = pathlib.Path(lucent.__file__).resolve()
assert prefix in where.parents, f"imported {where}, not the module installed under {prefix}"
assert lucent.__version__ == sys.argv[2], f"lucent.__version__ {lucent.__version__}, package {sys.argv[2]}"
scene = lucent.scene_from_dict({
    "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "fov": 40},
    "film": {"width": 16, "height": 16},
    "integrator": {"type": "direct", "spp": 2},
    "materials": {"white": {"type": "diffuse", "albedo": [0.8, 0.8, 0.8]}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white"}],
    "lights": [{"type": "point", "position": [0, 0, 4], "intensity": [10, 10, 10]}],
})
r = lucent.Renderer(**lucent.environment())
r.set_scene(scene)
r.render(2)
scene.camera.position.x += 0.5
r.set_scene(scene)
r.render(2)
s = r.stats
assert r.result().spp == 2 and s.bvh_builds == 1, s
assert s.kernel_compiles + s.kernel_cache_loads == 1, s
print(f"python: lucent {lucent.__version__} from {where}: {s}")

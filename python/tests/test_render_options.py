"""The render options from Python: samplers, clamping and adaptive sampling, caustics, the CPU
reference, and the image of the `lucent` command (a file of its own beside test_render.py: the two
take about 10 s each on cold kernel caches, and one CTest entry per file keeps each under 20 s)."""
import math
import pickle

import numpy as np
import pytest

import lucent
from conftest import session


def test_render_reference(small_scene):
    r = lucent.render_reference(small_scene, spp=2, threads=1)
    assert r.mean.shape == (12, 16, 3) and (r.samples == 2).all() and "reference" in r.device
    with pytest.raises(ValueError, match=r"spp must be an integer in \[0, 2\*\*30\], got -2"):
        lucent.render_reference(small_scene, spp=-2)
    with pytest.raises(ValueError, match=r"threads must be an integer in \[0, 2\*\*31 - 1\]"):
        lucent.render_reference(small_scene, threads=-1)
    with pytest.raises(ValueError, match=r"spp must be an integer in \[0, 2\*\*30\], got 1073741825"):
        lucent.render_reference(small_scene, spp=2 ** 30 + 1)
    with pytest.raises(ValueError, match=r"threads must be an integer in \[0, 2\*\*31 - 1\]"):
        lucent.render_reference(small_scene, threads=2 ** 64)
    small_scene.spheres[0].material = 7
    with pytest.raises(lucent.Error):
        lucent.render_reference(small_scene, spp=1)


def test_python_render_equals_the_cli_render(tmp_path, small_dict):
    """The binding adds nothing to the library's image: the `lucent` command and a session render
    the same samples, and the arrays are in row-major (H, W) order like the CLI's EXR."""
    import json
    import os
    import subprocess
    cli = os.environ.get("LUCENT_CLI")
    if not cli:
        pytest.skip("LUCENT_CLI is not set (CTest sets it)")
    path = tmp_path / "s.json"
    small_dict["film"]["width"] = 20  # not square: a transposition would show
    path.write_text(json.dumps(small_dict))
    subprocess.run([cli, "render", str(path), "-o", str(tmp_path / "cli.exr"), "--spp", "8",
                    "--quiet"], check=True)
    with session() as r:
        r.set_scene(lucent.load_scene(path))
        r.render(8)
        mine = r.result()
    theirs = lucent.read_render(tmp_path / "cli.exr")
    # equal up to the float summation order of passes (their split depends on timing)
    np.testing.assert_allclose(mine.mean, theirs.mean, rtol=1e-5, atol=1e-6)
    np.testing.assert_array_equal(mine.samples, theirs.samples)


def test_samplers_clamp_and_adaptive(renderer, small_scene):
    """The sampling knobs of the CLI (--sampler, --clamp, --target-error) from Python."""
    renderer.set_build_options(specialize=False)  # the full kernel, which other tests build too
    images = {}
    for name in lucent.SAMPLERS:
        small_scene.integrator.sampler = name
        renderer.set_scene(small_scene)
        renderer.render(4)
        images[name] = renderer.result().mean.copy()
    assert not np.array_equal(images["sobol"], images["independent"]), "other random numbers"
    with pytest.raises(ValueError):
        small_scene.integrator.sampler = "halton"

    # clamping only removes energy: never brighter than the unclamped render of the same samples
    small_scene.integrator.sampler = "independent"
    small_scene.integrator.clamp = 0.05
    renderer.set_scene(small_scene)
    renderer.render(4)
    clamped = renderer.result().mean
    assert clamped.mean() < images["independent"].mean()
    assert (clamped <= images["independent"] + 1e-6).all()

    small_scene.integrator.clamp = 0
    assert small_scene.integrator.dielectric_splits == 2  # the default
    small_scene.integrator.dielectric_splits = 0
    renderer.set_scene(small_scene)
    renderer.reset()
    renderer.render_adaptive(target_error=0.05, min_spp=8, max_spp=256)
    r = renderer.result()
    assert 0 < r.estimated_relmse <= 0.05 and r.target_error == 0.05
    assert r.samples.min() >= 8 and r.samples.max() <= 256
    # the calibration and the halves' estimate come through: gains within their clamp, the plan
    # at the target, and an a-posteriori estimate from the two halves' difference
    assert 1 / 64 <= r.model_gain_a <= 4 and 1 / 64 <= r.model_gain_b <= 4
    assert 0 < r.planned_relmse <= 0.05
    assert r.halves_relmse > 0
    # the shortfall warning says so exactly when the halves are above 1.5 times the target
    limit = 1.5 * 0.05 * (1 + 2 * math.sqrt(2 / (3 * r.width * r.height)))
    assert (r.target_shortfall != "") == (r.halves_relmse > limit)
    # a complete render: its plan done, spp all it planned
    assert not r.pilot_incomplete and not r.plan_incomplete and r.spp == r.planned_spp
    # stopped by a time limit in its pilot: still a target render, and it says so (it had
    # target_error 0 and no shortfall, like a finished uniform render); pickled with it
    renderer.reset()
    renderer.render_adaptive(target_error=0.05, min_spp=8, max_spp=256, max_seconds=1e-9)
    r = renderer.result()
    assert r.target_error == 0.05 and r.pilot_incomplete and r.plan_incomplete
    assert r.spp < r.planned_spp
    assert r.target_shortfall.startswith("the time limit stopped the render in its pilot")
    back = pickle.loads(pickle.dumps(r))
    assert (back.planned_spp, back.pilot_incomplete, back.plan_incomplete) == (
        r.planned_spp, True, True)
    with pytest.raises(ValueError):
        renderer.render_adaptive()  # neither a target nor a budget
    with pytest.raises(ValueError):
        renderer.render_adaptive(target_error=float("nan"))


def test_caustics_from_python(renderer, small_dict):
    """integrator.caustics: a point light's caustic through a mirror appears only with it, and
    what light tracing cannot do is refused with lucent.Error."""
    renderer.set_build_options(specialize=False)  # the full kernel, which other tests build too
    small_dict["materials"]["mirror"] = {"type": "mirror"}
    small_dict["shapes"].append({"type": "sphere", "center": [-1.5, 1, 0], "radius": 1,
                                 "material": "mirror"})
    small_dict["integrator"] = {"type": "path", "max_depth": 4, "sampler": "independent"}
    means = {}
    for caustics in (False, True):
        scene = lucent.scene_from_dict(small_dict)
        scene.integrator.caustics = caustics
        renderer.set_scene(scene)
        renderer.reset()
        renderer.render(16)
        means[caustics] = renderer.result().mean.mean()
    # the mirror sends the point light's light onto the floor: light tracing adds it
    assert means[True] > means[False] * 1.01
    # an adaptive render traces them too (each half its own light paths)
    renderer.reset()
    renderer.render_adaptive(target_error=0.05, min_spp=8, max_spp=64)
    assert renderer.result().mean.mean() > means[False] * 1.01

"""Images, compare() and converge() from Python, with known answers and their error paths."""
import math
import os
import re
import subprocess
import sys
import textwrap
from xml.etree import ElementTree

import numpy as np
import pytest

import lucent
from conftest import SMALL, add_degenerate_triangle, session


def constant(value, h=4, w=5):
    return np.full((h, w, 3), value, np.float32)


def test_write_and_read_linear_formats(tmp_path):
    img = np.random.default_rng(1).random((6, 7, 3), dtype=np.float32) * 4
    for ext in ("pfm", "exr"):
        path = tmp_path / f"a.{ext}"
        lucent.write_image(path, img)
        back = lucent.read_image(path)
        assert back.shape == (6, 7, 3) and back.dtype == np.float32
        np.testing.assert_allclose(back, img, rtol=1e-6)


def test_png_display_settings_known_answers(tmp_path):
    path = tmp_path / "a.png"
    # sRGB: 0.5 encodes to 188/255, which read_image decodes back to 0.5 (within 8-bit steps)
    lucent.write_image(path, constant(0.5))
    assert lucent.read_image(path) == pytest.approx(0.5, abs=4e-3)
    # linear transfer: 0.5 -> 128/255, decoded as sRGB 128 -> 0.2158
    lucent.write_image(path, constant(0.5), transfer="linear")
    assert lucent.read_image(path) == pytest.approx(0.2158, abs=2e-3)
    # one stop of exposure doubles 0.25 to 0.5
    lucent.write_image(path, constant(0.25), transfer="linear", exposure=1)
    assert lucent.read_image(path) == pytest.approx(0.2158, abs=2e-3)
    # gamma 1 is linear; a film's settings apply, keywords override them
    film = lucent.Film()
    film.transfer = "gamma"
    film.gamma = 1.0
    lucent.write_image(path, constant(0.5), film=film)
    assert lucent.read_image(path) == pytest.approx(0.2158, abs=2e-3)
    lucent.write_image(path, constant(0.5), film=film, transfer="srgb")
    assert lucent.read_image(path) == pytest.approx(0.5, abs=4e-3)
    # clamp against Reinhard: 3.0 saturates, 3 / (1 + 3) = 0.75 does not
    lucent.write_image(path, constant(3.0), transfer="linear")
    assert lucent.read_image(path) == pytest.approx(1.0)
    lucent.write_image(path, constant(3.0), transfer="linear", tonemap="reinhard")
    assert lucent.read_image(path) == pytest.approx(0.5225, abs=3e-3)  # sRGB decode of 191


def test_render_exr_keeps_variance_and_counts(tmp_path, small_scene):
    with session() as r:
        r.set_scene(small_scene)
        r.render(4)
        res = r.result()
    path = tmp_path / "r.exr"
    lucent.write_render_exr(path, res)
    back = lucent.read_render(path)
    np.testing.assert_array_equal(back.mean, res.mean)
    np.testing.assert_array_equal(back.variance, res.variance)
    np.testing.assert_array_equal(back.samples, res.samples)
    # the key of its random numbers, which converge checks a reference against
    assert (res.seed, res.sampler) == (small_scene.integrator.seed, "sobol")
    assert (back.seed, back.sampler) == (res.seed, res.sampler)
    lucent.write_render_exr(path, lucent.RenderResult(res.mean))  # from arrays: unknown
    assert lucent.read_render(path).sampler == ""
    lucent.write_image(tmp_path / "r.png", res)  # a result's mean
    plain = lucent.read_render(tmp_path / "r.png")
    assert plain.variance is None and plain.samples is None and plain.mean.shape == (12, 16, 3)


def test_result_from_arrays():
    r = lucent.RenderResult(constant(1.0), variance=constant(0.5), samples=np.full((4, 5), 3),
                            spp=3)
    assert r.spp == 3 and r.samples.dtype == np.uint32 and r.variance[0, 0, 0] == 0.5
    # the views are read-only: a negative variance or count written through one bypassed the
    # checks above (copies change, and a RenderResult of them checks them)
    for view in (r.mean, r.variance, r.samples):
        assert not view.flags.writeable
        with pytest.raises(ValueError, match="read-only"):
            view[0, 0] = -1
    copy = np.array(r.variance)
    copy[0, 0] = -1
    with pytest.raises(ValueError, match="variance: every value must be finite and >= 0"):
        lucent.RenderResult(r.mean, variance=copy, samples=r.samples)
    with pytest.raises(ValueError, match="variance: its shape differs"):
        lucent.RenderResult(constant(1.0), variance=constant(1.0, 2, 2))
    with pytest.raises(ValueError, match=r"samples: expected an array of shape \(H, W\)"):
        lucent.RenderResult(constant(1.0), samples=np.ones((5, 4)))


def test_reference_warnings_reach_python(small_scene, capfd):
    """render_reference's warnings (here: a scene without light) are Python warnings, or go to
    on_warning; they were printed to stderr, out of the caller's reach."""
    small_scene.lights = []
    for m in small_scene.materials:
        m.emission = (0, 0, 0)
    with pytest.warns(lucent.LucentWarning, match="no light"):
        lucent.render_reference(small_scene, spp=1)
    got = []
    lucent.render_reference(small_scene, spp=1, on_warning=got.append)
    assert len(got) == 1 and "no light" in got[0], got
    assert "no light" not in capfd.readouterr().err
    with pytest.raises(TypeError, match="on_warning"):
        lucent.render_reference(small_scene, spp=1, on_warning=3)


def test_compare_kernel_against_the_reference(small_scene):
    """The kernel and the independent reference integrator agree on the small scene (the
    z-test of `lucent compare`), and a 30% albedo change is detected (negative control)."""
    small_scene.integrator.seed = 3
    with session() as r:
        r.set_scene(small_scene)
        r.render(64)
        kernel = r.result()
        ref = lucent.render_reference(small_scene, spp=64)
        c = lucent.compare(kernel, ref)
        assert isinstance(c, lucent.CompareResult) and c.passed and bool(c), c.summary()
        assert c.statistical and c.tested == 16 * 12 * 3 and c.z.shape == (12, 16, 3)
        assert np.abs(c.z).max() == pytest.approx(c.max_z, rel=1e-5)
        assert len(c.mean_a) == 3 and "RMSE" in c.summary()
        small_scene.materials[1].albedo = (0.35, 0.35, 0.35)
        r.set_scene(small_scene)
        r.render(64)
        worse = lucent.compare(r.result(), ref)
        assert not worse.passed and not worse.mean_test_passed


def test_compare_arrays_without_variance():
    a = constant(1.0)
    c = lucent.compare(a, a)
    assert c.passed and not c.statistical and c.rmse == 0
    c = lucent.compare(a, constant(1.5))
    assert not c.passed and c.max_abs_error == pytest.approx(0.5)
    assert c.rmse == pytest.approx(0.5)
    # both epsilons 0: an exact comparison, which identical arrays pass (0/0 was NaN: FAIL)
    c = lucent.compare(a, a, abs_epsilon=0, rel_epsilon=0)
    assert c.passed and c.max_z == 0 and list(c.mean_z) == [0, 0, 0]
    b = constant(1.0)
    b[1, 2, 0] = np.nextafter(np.float32(1), np.float32(2))
    c = lucent.compare(a, b, abs_epsilon=0, rel_epsilon=0)
    assert not c.passed and c.failed_channels == 1 and c.max_z == math.inf
    # alpha in the command line's and the library's range (0.7 passed here, then the library
    # refused it as a lucent.Error)
    for bad in (0, 1e-13, 0.7, 1, math.nan):
        with pytest.raises(ValueError, match=r"alpha must be in \[1e-12, 0.5\]"):
            lucent.compare(a, a, alpha=bad)
    # the value as it reads back ("got 0.000000" of 1e-13, "got 1.000000" of 1.0000001)
    with pytest.raises(ValueError, match=r"alpha must be in \[1e-12, 0.5\], got 1e-13$"):
        lucent.compare(a, a, alpha=1e-13)
    with pytest.raises(ValueError, match=r"min_pass_fraction must be in \[0, 1\], got 1.0000001$"):
        lucent.compare(a, a, min_pass_fraction=1.0000001)
    assert lucent.compare(a, a, alpha=0.5).passed


def test_linear_files_take_no_display_settings_and_render_exr_is_exr(tmp_path):
    # display settings for a linear file were dropped without a word
    for ext in ("exr", "pfm"):
        for name, value in (("exposure", 2.0), ("tonemap", "aces"), ("gamma", 3.0),
                            ("transfer", "gamma")):
            with pytest.raises(ValueError, match=rf"^write_image: {name} is a display setting, "
                                                 rf"for \.png; \.{ext} holds linear values$"):
                lucent.write_image(tmp_path / f"a.{ext}", constant(1.0), **{name: value})
        assert not (tmp_path / f"a.{ext}").exists()
        lucent.write_image(tmp_path / f"a.{ext}", constant(1.0), film=lucent.Film())
    lucent.write_image(tmp_path / "a.png", constant(1.0), exposure=2.0)
    # write_render_exr wrote OpenEXR under any name (w.png)
    with pytest.raises(lucent.Error, match=r"w\.png: write_render_exr writes OpenEXR: use an "
                                           r"\.exr file$"):
        lucent.write_render_exr(tmp_path / "w.png", lucent.RenderResult(constant(0.5)))
    assert not (tmp_path / "w.png").exists()


def test_image_errors(tmp_path):
    with pytest.raises(lucent.Error, match=r"a\.tiff: unknown output format '\.tiff'"):
        lucent.write_image(tmp_path / "a.tiff", constant(1.0))
    # a name without an extension said "unknown output format '.'"
    with pytest.raises(lucent.Error, match="noext: no extension to name the output format"):
        lucent.write_image(tmp_path / "noext", constant(1.0))
    with pytest.raises(lucent.Error, match="nodir"):
        lucent.write_image(tmp_path / "nodir" / "a.png", constant(1.0))
    with pytest.raises(lucent.Error):
        lucent.read_image(tmp_path / "none.exr")
    with pytest.raises(lucent.Error):
        lucent.read_render(tmp_path / "none.exr")
    (tmp_path / "junk.exr").write_bytes(b"not an exr")
    with pytest.raises(lucent.Error, match=r"junk\.exr"):
        lucent.read_render(tmp_path / "junk.exr")
    with pytest.raises(ValueError,
                       match=r"image: expected an array of shape \(H, W, 3\), got \(4, 5\)"):
        lucent.write_image(tmp_path / "a.png", np.zeros((4, 5)))
    with pytest.raises(ValueError, match=r"got \(0, 5, 3\)"):
        lucent.write_image(tmp_path / "a.png", np.zeros((0, 5, 3)))
    with pytest.raises(TypeError):
        lucent.write_image(tmp_path / "a.png", "pixels")
    with pytest.raises(ValueError, match="unknown transfer 'log'"):
        lucent.write_image(tmp_path / "a.png", constant(1.0), transfer="log")
    with pytest.raises(ValueError, match="unknown tone map"):
        lucent.write_image(tmp_path / "a.png", constant(1.0), tonemap="hable")
    with pytest.raises(ValueError, match="gamma must be a finite number > 0"):
        lucent.write_image(tmp_path / "a.png", constant(1.0), gamma=0)
    with pytest.raises(TypeError):
        lucent.write_image(tmp_path / "a.png", constant(1.0), film="srgb")
    with pytest.raises(ValueError, match=r"b: expected an array of shape \(H, W, 3\)"):
        lucent.compare(constant(1.0), np.zeros(3))
    with pytest.raises(lucent.Error, match="size"):
        lucent.compare(constant(1.0), constant(1.0, 2, 2))
    for bad in ({"alpha": 0}, {"alpha": 1.5}, {"min_pass_fraction": 2}, {"abs_epsilon": -1}):
        with pytest.raises(ValueError):
            lucent.compare(constant(1.0), constant(1.0), **bad)
    # names that are not UTF-8 (surrogateescape) are shown as \xNN, not lost with the message
    with pytest.raises(lucent.Error, match=r"caf\\xe9\.png: cannot open image"):
        lucent.read_image(os.path.join(str(tmp_path), "caf\udce9.png"))
    with pytest.raises(lucent.Error, match=r"no\\xe8dir/a\.png: cannot write"):
        lucent.write_image(os.path.join(str(tmp_path), "no\udce8dir", "a.png"), constant(1.0))


def reference_of(scene, spp):
    """A reference integrator render of `scene` at another seed than its own (converge refuses a
    reference at the ladder's seed, whose samples are the rungs' own)."""
    other = lucent.scene_from_dict(SMALL)
    other.integrator.seed = (scene.integrator.seed + 7) % 2 ** 32
    assert other.integrator.seed != scene.integrator.seed
    return lucent.render_reference(other, spp=spp)


def test_converge(small_scene):
    reference = reference_of(small_scene, 64)
    points = []
    with session() as r:
        res = lucent.converge(small_scene, reference, settings=["default", "max_depth=1"],
                              spp_ladder=[1, 4, 16], renderer=r, on_point=points.append)
        # one session: the BVH once for both settings and every rung
        assert r.stats.bvh_builds == 1
    assert [(p.setting, p.spp) for p in res.points] == [
        ("default", 1), ("default", 4), ("default", 16),
        ("max_depth=1", 1), ("max_depth=1", 4), ("max_depth=1", 16)]
    assert [p.setting for p in points] == [p.setting for p in res.points]
    default, direct_only = res.fits
    assert default.points == 3 and default.slope_spp < -0.5 and not default.biased
    # max_depth 1 sees emitters only: the lit scene renders black, far from the reference
    assert direct_only.biased and res.points[-1].relmse > 10 * res.points[2].relmse
    # each fit's verdict, its first words
    assert re.fullmatch(r"<lucent\.ConvergeResult of 6 points: default: (unbiased|undetermined); "
                        r"max_depth=1: biased: error stops decreasing at ~relMSE \S+>",
                        repr(res)), repr(res)
    assert res.csv().startswith("setting,spp,seconds,samples_per_s,rmse,relmse")
    assert res.csv().count("\n") == 7
    assert res.svg("t").lstrip().startswith("<")
    # any title is valid XML: control characters and XML's non-characters as \xNN
    svg = res.svg("a\x01b\x1b\ufffe \u00e9 <&>")
    title = ElementTree.fromstring(svg.encode()).find("{http://www.w3.org/2000/svg}text")
    assert title is not None and title.text == "a\\x01b\\x1b\\xef\\xbf\\xbe \u00e9 <&>"
    plot = res.plot_image("t")
    assert plot.ndim == 3 and plot.shape[2] == 3


def test_converge_without_a_session(small_scene):
    """Without renderer=, converge renders in a session of its own: the same ladder, packing
    warnings as LucentWarning, and an on_point that raises stops it after that rung."""
    reference = reference_of(small_scene, 16)
    res = lucent.converge(small_scene, reference, spp_ladder=[1, 4])
    assert [(p.setting, p.spp) for p in res.points] == [("default", 1), ("default", 4)]
    assert res.points[1].relmse < res.points[0].relmse
    assert re.fullmatch(r"<lucent\.ConvergePoint default 1 spp, relMSE [0-9.]+>",
                        repr(res.points[0]))
    fit, = res.fits
    assert repr(fit) == "<lucent.ConvergeFit default: %s>" % fit.verdict
    seen = []

    def stop(point):
        seen.append(point.spp)
        raise RuntimeError("enough")
    with pytest.raises(RuntimeError, match="enough"):
        lucent.converge(small_scene, reference, spp_ladder=[1, 2, 4], on_point=stop)
    assert seen == [1]
    add_degenerate_triangle(small_scene)
    with pytest.warns(lucent.LucentWarning, match="degenerate"):
        lucent.converge(small_scene, reference, spp_ladder=[1])


def test_converge_by_time_and_errors(small_scene):
    # an empty list of settings ran ['default'] without a word, where an empty ladder is an error
    with pytest.raises(ValueError, match=r"^settings: an empty list \(give \['default'\]"):
        lucent.converge(small_scene, lucent.render_reference(small_scene, spp=4), settings=[])
    reference = reference_of(small_scene, 16)
    with session() as r:
        res = lucent.converge(small_scene, reference, time_ladder=[0.02, 0.05], renderer=r)
        # a rung renders until its wall time reaches the budget; its `seconds` counts the kernel
        # passes only (not the host's accumulation between them), so it can fall a little short
        assert len(res.points) == 2 and res.points[1].spp > res.points[0].spp
        assert 0.04 <= res.points[1].seconds
        with pytest.raises(lucent.Error, match="settings: .*max_depth"):
            lucent.converge(small_scene, reference, settings=["max_depth=0"], renderer=r)
        with pytest.raises(lucent.Error, match="given twice"):
            lucent.converge(small_scene, reference, settings=["default", "default"], renderer=r)
        # the same setting in another spelling rendered twice
        same = "'max-depth=2' is the same setting as 'max_depth=2'"
        with pytest.raises(lucent.Error, match=same):
            lucent.converge(small_scene, reference, settings=["max_depth=2", "max-depth=2"],
                            renderer=r)
        with pytest.raises(ValueError, match="not both"):
            lucent.converge(small_scene, reference, spp_ladder=[1], time_ladder=[1], renderer=r)
        # the command line's limits (a rung of 2^31 - 1 spp or 1e300 s ran until killed); every
        # value refused before anything renders
        for bad in (0, 2 ** 24 + 1, 2 ** 31 - 1, 2 ** 40, -1):
            with pytest.raises(ValueError, match=r"spp_ladder values must be an integer in "
                                                 r"\[1, 2\*\*24\], got " + str(bad)):
                lucent.converge(small_scene, reference, spp_ladder=[1, bad], renderer=r)
        with pytest.raises(TypeError, match="spp_ladder values must be an integer"):
            lucent.converge(small_scene, reference, spp_ladder=[1.5], renderer=r)
        for bad in (-1, 0, 1e7 * 1.0001, 1e300, math.inf, math.nan):
            with pytest.raises(ValueError, match=r"time_ladder values must be in \(0, 1e7\] "
                                                 r"seconds, got " + re.escape(repr(bad))):
                lucent.converge(small_scene, reference, time_ladder=[0.01, bad], renderer=r)
        with pytest.raises(lucent.Error, match="ladder is empty"):
            lucent.converge(small_scene, reference, spp_ladder=[], renderer=r)
        # an adaptive setting with no rung at its pilot rendered nothing, and was dropped
        with pytest.raises(lucent.Error, match=r"setting 'adaptive' has no rung at or above its "
                                               r"pilot of 64 spp \(the ladder's largest rung is 4\)"):
            lucent.converge(small_scene, reference, settings=["default", "adaptive"],
                            spp_ladder=[1, 4], renderer=r)
        with pytest.raises(lucent.Error,
                           match="the reference image is 5x4, the scene renders 16x12"):
            lucent.converge(small_scene, constant(1.0), spp_ladder=[1], renderer=r)
        # a render at the scene's own seed replays the rungs' samples and hides their error (the
        # library took it: relMSE 0.6x the noise of an unbiased ladder), as `lucent converge`
        with pytest.raises(lucent.Error, match=r"^the reference image was rendered with seed 0, "
                                               r"the ladder's: its samples include the rungs' own"):
            lucent.converge(small_scene, lucent.render_reference(small_scene, spp=4),
                            spp_ladder=[1], renderer=r)
        with pytest.raises(TypeError, match="on_point must be callable"):
            lucent.converge(small_scene, reference, on_point=1, renderer=r)
        # not pybind11's RuntimeError "Unable to cast Python instance to C++ type"
        with pytest.raises(TypeError, match=r"^renderer must be a lucent\.Renderer or None, got "
                                            r"<lucent\.Scene "):
            lucent.converge(small_scene, reference, spp_ladder=[1], renderer=small_scene)

        def stop(point):
            raise RuntimeError("enough")
        with pytest.raises(RuntimeError, match="enough"):
            lucent.converge(small_scene, reference, spp_ladder=[1, 2, 4], renderer=r,
                            on_point=stop)
        # the session renders normally afterwards (its cancel flag is its own again)
        r.set_scene(small_scene)
        assert r.render(2).samples_done == 2


def test_result_from_arrays_refuses_what_no_render_holds(tmp_path):
    # counts are whole and in [0, 2^32): -1 wrapped to 4294967295 and 2.9 became 2
    with pytest.raises(ValueError, match=r"samples: counts must be in \[0, 2\^32\), got -1"):
        lucent.RenderResult(constant(1.0), samples=np.full((4, 5), -1))
    # spp as any integer argument: a ValueError naming it and its range (pybind's "incompatible
    # constructor arguments" TypeError for 2**70 and -1)
    for bad in (2 ** 70, -1, 2 ** 32 + 1):
        with pytest.raises(ValueError, match=r"^spp must be an integer in \[0, 2\*\*32\]"):
            lucent.RenderResult(constant(1.0), spp=bad)
    assert lucent.RenderResult(constant(1.0), spp=7).spp == 7
    with pytest.raises(TypeError, match="samples: expected integer counts"):
        lucent.RenderResult(constant(1.0), samples=np.full((4, 5), 2.9))
    # unsigned counts are shown unsigned (2^63 was "got -9223372036854775808")
    with pytest.raises(ValueError, match=r"counts must be in \[0, 2\^32\), got 9223372036854775808$"):
        lucent.RenderResult(constant(1.0), samples=np.full((4, 5), 2 ** 63, np.uint64))
    with pytest.raises(ValueError, match=r"got 4294967296$"):
        lucent.RenderResult(constant(1.0), samples=np.full((4, 5), 2 ** 32, np.uint64))
    # a strided array of 64-bit counts is checked element by element (its buffer was read as if
    # contiguous: 2**40 in the last row passed and became 0, other strides read past the end)
    for dtype in (np.uint64, np.int64):
        wide = np.ones((4, 10), dtype)
        wide[3, 8] = 2 ** 40
        with pytest.raises(ValueError, match=r"got 1099511627776$"):
            lucent.RenderResult(constant(1.0), samples=wide[:, ::2])
        counts = np.arange(1, 21, dtype=dtype).reshape(4, 5)[::-1, ::-1]
        assert lucent.RenderResult(constant(1.0), samples=counts).samples.tolist() == counts.tolist()
    # a variance is per sample: without the counts compare() took one sample a pixel and
    # write_render_exr() dropped it
    with pytest.raises(ValueError, match=r"^variance: a variance needs the per-pixel sample counts "
                                         r"\(samples=\.\.\.\)$"):
        lucent.RenderResult(constant(1.0), variance=constant(4.0))
    # counts without a variance say nothing to compare(): a tolerance test, as for images
    counts = lucent.RenderResult(constant(1.0), samples=np.full((4, 5), 16))
    assert not lucent.compare(counts, constant(1.0)).statistical
    # and write_render_exr() writes their mean, as before (no statistics without a variance)
    lucent.write_render_exr(str(tmp_path / "counts.exr"), counts)
    assert lucent.read_render(str(tmp_path / "counts.exr")).variance is None
    # a variance is finite and >= 0
    for bad in (-1.0, math.nan, math.inf):
        with pytest.raises(ValueError, match="variance: every value must be finite and >= 0"):
            lucent.RenderResult(constant(1.0), variance=constant(bad))
    # strings are not numbers
    with pytest.raises(TypeError, match="mean: expected numbers"):
        lucent.RenderResult(np.full((2, 2, 3), "0.5"))
    # None is named (NumPy made it an array of dtype object, which the message named)
    with pytest.raises(TypeError, match="^mean: expected numbers, got None$"):
        lucent.RenderResult(None)
    with pytest.raises(TypeError, match="^image: expected numbers, got None$"):
        lucent.write_image(tmp_path / "n.png", None)


class OutOfMemory:
    """An array-like whose conversion runs out of memory (as a copy too large for memory does)."""
    def __array__(self, dtype=None):
        raise MemoryError("no memory for the copy")


def test_out_of_memory_is_raised_not_reported_as_a_wrong_shape(tmp_path):
    # array_t::ensure cleared NumPy's MemoryError: "expected an array of shape (H, W, 3)"
    for f in (lambda: lucent.write_image(tmp_path / "a.png", OutOfMemory()),
              lambda: lucent.RenderResult(OutOfMemory()),
              lambda: lucent.RenderResult(constant(1.0), variance=OutOfMemory(),
                                          samples=np.ones((4, 5), np.uint32)),
              lambda: lucent.RenderResult(constant(1.0), samples=OutOfMemory()),
              lambda: lucent.compare(constant(1.0), OutOfMemory())):
        with pytest.raises(MemoryError, match="no memory for the copy"):
            f()


OUT_OF_MEMORY_CHILD = textwrap.dedent("""
    import resource, sys
    import numpy as np
    import lucent
    # the address space in use and 1 GiB more: a 3 GiB copy cannot be made
    used = int(open("/proc/self/statm").read().split()[0]) * resource.getpagesize()
    resource.setrlimit(resource.RLIMIT_AS, (used + 2 ** 30, resource.getrlimit(resource.RLIMIT_AS)[1]))
    big = np.broadcast_to(np.float32(0.5), (16384, 16384, 3))  # 12 bytes of data
    for f in (lambda: lucent.write_image(sys.argv[1], big), lambda: lucent.RenderResult(big)):
        try:
            f()
        except Exception as e:
            print(type(e).__name__)
""")


@pytest.mark.skipif(not os.path.exists("/proc/self/statm"), reason="needs Linux's /proc")
def test_an_image_too_large_to_copy_raises_memory_error(tmp_path):
    env = dict(os.environ)
    if "ASAN_OPTIONS" in env:  # the sanitizer build: a failed allocation returns null, as libc's
        env["ASAN_OPTIONS"] += ":allocator_may_return_null=1"
    child = subprocess.run([sys.executable, "-c", OUT_OF_MEMORY_CHILD, str(tmp_path / "big.png")],
                           capture_output=True, text=True, timeout=60, env=env)
    assert child.stdout.split() == ["MemoryError", "MemoryError"], child.stdout + child.stderr


def test_display_settings_of_the_wrong_type_name_the_setting(tmp_path):
    with pytest.raises(TypeError, match="transfer: expected a string, got 3"):
        lucent.write_image(tmp_path / "a.png", constant(1.0), transfer=3)
    with pytest.raises(TypeError, match="gamma: expected a number, got 'x'"):
        lucent.write_image(tmp_path / "a.png", constant(1.0), gamma="x")
    lucent.write_image(tmp_path / "a.png", constant(1.0), gamma=np.float32(2.2), exposure=1,
                       transfer="gamma")
    # a gamma shapes the "gamma" transfer only, as a scene file's film says (it was dropped
    # without a word)
    for transfer in ("srgb", "linear"):
        with pytest.raises(ValueError, match=rf"^gamma: only used with transfer 'gamma' \(the "
                                             rf"transfer is {transfer}\)$"):
            lucent.write_image(tmp_path / "a.png", constant(1.0), gamma=2.0, transfer=transfer)


def test_non_finite_inputs_are_errors_not_results(small_scene):
    # as `lucent compare` and `lucent converge`: an input error naming the pixel, not a FAIL or
    # NaN errors
    a = constant(1.0)
    a[2, 3, 1] = math.nan
    with pytest.raises(lucent.Error, match=r"a: pixel \(3, 2\) channel G is not finite \(nan\)"):
        lucent.compare(a, constant(1.0))
    with pytest.raises(lucent.Error, match=r"b: pixel \(3, 2\) channel G is not finite"):
        lucent.compare(constant(1.0), a)
    ref = np.ones((small_scene.film.height, small_scene.film.width, 3), np.float32)
    ref[0, 0, 0] = math.inf
    with pytest.raises(lucent.Error, match=r"the reference image: pixel \(0, 0\) channel R is "
                                           r"not finite \(inf\)"):
        lucent.converge(small_scene, ref, spp_ladder=[1])


def test_paths_with_a_nul_and_path_like_directories(tmp_path):
    """A NUL in a file path was pybind's "incompatible function arguments" (cache_dir and the device
    selector said ValueError), and Renderer(cache_dir=Path) was refused where every other path
    argument took an os.PathLike."""
    img = np.ones((2, 2, 3), np.float32)
    for call in (lambda: lucent.write_image("a\x00.png", img), lambda: lucent.read_image("a\x00.png"),
                 lambda: lucent.load_scene(b"a\x00.json"),
                 lambda: lucent.read_part_info("a\x00.exr")):
        with pytest.raises(ValueError, match=r"^path: embedded null character in 'a\\x00\."):
            call()
    lucent.write_image(tmp_path / "p.pfm", img)
    assert lucent.read_image(tmp_path / "p.pfm").shape == (2, 2, 3)
    with lucent.Renderer(cache_dir=tmp_path / "cache") as r:
        assert r.options["cache_dir"] == str(tmp_path / "cache")
    scene = lucent.Scene()  # the scene's paths too, not the names that are no paths
    scene.path = tmp_path / "scene.json"
    assert scene.path == str(tmp_path / "scene.json")
    with pytest.raises(TypeError):
        lucent.Material("diffuse", tmp_path)


def test_a_keyboard_interrupt_in_a_converge_warning_stops_the_study(small_scene):
    """converge without a renderer gives its warnings on the calling thread, where Ctrl-C can
    land while warnings.warn runs: the study stops there, as for an exception of on_point (the
    ladder ran to its end before KeyboardInterrupt came out; the review's find)."""
    import time
    import warnings
    add_degenerate_triangle(small_scene)  # a packing warning at the first rung
    reference = reference_of(small_scene, 16)

    def interrupt(*args, **kwargs):
        raise KeyboardInterrupt

    t0 = time.monotonic()
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = interrupt
        with pytest.raises(KeyboardInterrupt):
            lucent.converge(small_scene, reference, spp_ladder=[1, 2 ** 22])
    assert time.monotonic() - t0 < 30


def test_compare_says_when_one_rare_sample_decides_the_image_mean_test():
    """CompareResult.mean_variance_dominated: one pixel-channel holds most of the image means'
    variance and its mean rests on about one sample (63 samples of 1 and one of 1e4 in A)."""
    n = 64
    mean = (63 + 1e4) / n
    var = (63 * (1 - mean) ** 2 + (1e4 - mean) ** 2) / (n - 1)
    a_mean, a_var = constant(1.0), constant(0.01)
    a_mean[3, 2, :], a_var[3, 2, :] = mean, var
    counts = np.full((4, 5), n, np.uint32)
    a = lucent.RenderResult(a_mean, a_var, counts)
    b = lucent.RenderResult(constant(1.0), constant(0.01), counts)
    c = lucent.compare(a, b)
    assert c.passed and c.mean_variance_dominated
    assert (c.mean_variance_x, c.mean_variance_y) == (2, 3) and c.mean_variance_share > 0.99
    assert abs(c.mean_variance_samples - 1) < 0.05
    assert "channel R holds 100.0% of the image means' variance, and its mean rests on about " \
           "1.0 samples" in c.summary()
    assert not lucent.compare(b, b).mean_variance_dominated

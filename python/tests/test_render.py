"""The render session from Python: NumPy results without copies, progressive accumulation, what a
change rebuilds (stats), AOVs, callbacks, the GIL, cancellation, and every error of the API."""
import gc
import inspect
import pathlib
import re
import subprocess
import sys
import threading
import time
import warnings
import weakref

import numpy as np
import pytest

import lucent
from conftest import SMALL, add_degenerate_triangle, header_fields, session


def kernel_builds(stats):
    return stats.kernel_compiles + stats.kernel_cache_loads


def test_result_arrays(renderer, small_scene):
    renderer.set_scene(small_scene)
    p = renderer.render(4)
    assert isinstance(p, lucent.RenderProgress) and p.samples_done == 4 and p.accumulated == 4
    r = renderer.result()
    assert r.mean.shape == (12, 16, 3) and r.mean.dtype == np.float32
    assert r.variance.shape == (12, 16, 3) and r.variance.dtype == np.float32
    assert r.samples.shape == (12, 16) and r.samples.dtype == np.uint32
    assert (r.samples == 4).all() and r.spp == 4 and renderer.spp == 4
    assert r.rays > 0 and r.seconds > 0 and not r.cancelled and r.nonfinite == 0
    assert "LC_HAS_SPHERES" in r.build_options and r.device == renderer.device.name
    assert (r.width, r.height) == (16, 12)
    # views of the result's own memory: no copy, kept alive by the arrays
    assert np.shares_memory(r.mean, r.mean) and r.mean.base is not None
    mean = r.mean
    del r
    assert np.isfinite(mean).all() and mean.max() > 0


def test_progressive_renders_add_up(small_scene):
    with session() as a, session() as b:
        a.set_scene(small_scene)
        b.set_scene(small_scene)
        a.render(3)
        a.render(5)
        b.render(8)
        ra, rb = a.result(), b.result()
        assert (ra.samples == rb.samples).all() and ra.spp == 8
        np.testing.assert_allclose(ra.mean, rb.mean, rtol=1e-5, atol=1e-6)


def test_camera_change_rebuilds_neither_bvh_nor_kernel(renderer, small_scene):
    renderer.set_scene(small_scene)
    renderer.render(2)
    before = renderer.result()
    s0 = renderer.stats
    assert (s0.bvh_builds, kernel_builds(s0), s0.scene_packs) == (1, 1, 1)
    small_scene.camera.position.x += 0.5
    renderer.set_scene(small_scene)
    assert renderer.spp == 0, "a new camera drops the accumulation"
    renderer.render(2)
    s1 = renderer.stats
    assert (s1.bvh_builds, kernel_builds(s1), s1.scene_packs) == (1, 1, 2)
    assert s1.kernel_reuses == s0.kernel_reuses + 1
    assert s1.buffer_uploads == s0.buffer_uploads, "no scene buffer changed"
    assert not np.array_equal(before.mean, renderer.result().mean)
    # a material's parameters: one buffer upload, nothing rebuilt
    small_scene.materials[0].albedo = (0.2, 0.9, 0.2)
    renderer.set_scene(small_scene)
    s2 = renderer.stats
    assert (s2.bvh_builds, kernel_builds(s2)) == (1, 1)
    assert s2.buffer_uploads == s1.buffer_uploads + 1


def test_set_camera_moves_the_camera_without_packing(renderer, small_scene):
    """set_camera renders what a fresh session of the moved scene renders, bit for bit, packs
    and uploads nothing (stats.camera_moves counts it), and refuses a bad camera with
    set_scene's message, keeping the session's camera and samples."""
    renderer.set_scene(small_scene)
    renderer.render(2)
    s0 = renderer.stats
    camera = renderer.scene.camera
    camera.position = (0.5, 1.2, 4.5)
    renderer.set_camera(camera)
    assert renderer.spp == 0, "a new camera drops the accumulation"
    s1 = renderer.stats
    assert s1.camera_moves == s0.camera_moves + 1
    assert (s1.scene_packs, s1.bvh_builds, kernel_builds(s1), s1.buffer_uploads,
            s1.bytes_uploaded) == (s0.scene_packs, s0.bvh_builds, kernel_builds(s0),
                                   s0.buffer_uploads, s0.bytes_uploaded)
    assert tuple(renderer.scene.camera.position) == (0.5, 1.2, 4.5)
    renderer.render(3)
    moved = renderer.result()
    small_scene.camera = camera
    with session() as fresh:
        fresh.set_scene(small_scene)
        fresh.render(3)
        expected = fresh.result()
    assert np.array_equal(moved.mean, expected.mean)
    assert np.array_equal(moved.variance, expected.variance)
    assert np.array_equal(moved.samples, expected.samples)

    bad = renderer.scene.camera
    bad.fov_degrees = 180
    bad_scene = renderer.scene
    bad_scene.camera = bad
    with session() as other:
        with pytest.raises(lucent.Error) as by_scene:
            other.set_scene(bad_scene)
    with pytest.raises(lucent.Error) as by_camera:
        renderer.set_camera(bad)
    assert str(by_camera.value) == str(by_scene.value)
    assert "/camera/fov: must be in (0, 180) degrees, got 180" in str(by_camera.value)
    assert renderer.scene.camera.fov_degrees == camera.fov_degrees and renderer.spp == 3
    with pytest.raises(TypeError):
        renderer.set_camera(small_scene)


def test_stats_count_calls_once_and_buffers_per_device(small_scene):
    """scene_packs and kernel_reuses count set_scene calls, once whatever the number of devices;
    kernel builds and buffer uploads count work on each device, and a first upload counts every
    buffer it writes (not 1), as a later one counts the buffers that changed."""
    with session() as one:
        one.set_scene(small_scene)
        buffers, bytes_ = one.stats.buffer_uploads, one.stats.bytes_uploaded
    assert buffers >= 6, "BVH nodes and leaves, triangles, spheres, materials, lights"
    index = lucent.select_device(lucent.environment()["device"]).index
    with session(device=f"{index},{index}") as two:
        assert len(two.devices) == 2
        two.set_scene(small_scene)
        s0 = two.stats
        assert (s0.scene_packs, kernel_builds(s0), s0.kernel_reuses) == (1, 2, 0)
        assert (s0.buffer_uploads, s0.bytes_uploaded) == (2 * buffers, 2 * bytes_)
        small_scene.camera.position.x += 0.5
        two.set_scene(small_scene)
        s1 = two.stats
        assert (s1.scene_packs, kernel_builds(s1), s1.kernel_reuses) == (2, 2, 1)
        assert s1.buffer_uploads == s0.buffer_uploads
        small_scene.materials[0].albedo = (0.2, 0.9, 0.2)
        two.set_scene(small_scene)
        s2 = two.stats
        assert s2.kernel_reuses == 2
        assert s2.buffer_uploads == s1.buffer_uploads + 2, "the materials buffer on each device"


def test_stats_expose_every_field(renderer, small_scene):
    renderer.set_scene(small_scene)
    renderer.render(1)
    st = renderer.stats
    fields = header_fields("session.hpp", "SessionStats")
    assert len(fields) >= 12
    assert sorted(st.as_dict()) == sorted(fields)
    for f in fields:
        assert getattr(st, f) == st.as_dict()[f] and f in repr(st)
    assert st.passes >= 1 and st.render_seconds > 0


@pytest.mark.parametrize("header, struct, cls", [
    ("render.hpp", "RenderResult", lucent.RenderResult),
    ("render.hpp", "RenderProgress", lucent.RenderProgress),
    ("compare.hpp", "CompareResult", lucent.CompareResult),
    ("converge.hpp", "ConvergePoint", lucent.ConvergePoint),
    ("converge.hpp", "ConvergeFit", lucent.ConvergeFit),
    ("converge.hpp", "ConvergeResult", lucent.ConvergeResult),
    ("device.hpp", "DeviceInfo", lucent.DeviceInfo),
])
def test_result_classes_expose_every_field(header, struct, cls):
    fields = header_fields(header, struct)
    assert fields
    for f in fields:
        assert hasattr(cls, f), f"{struct}.{f} is not exposed"


def test_aov_renders_by_integrator_name(renderer, small_scene):
    small_scene.integrator.type = "albedo"
    renderer.set_scene(small_scene)
    renderer.render(1)
    r = renderer.result()
    assert "LC_HAS_INTEGRATOR_AOV" in r.build_options
    # the centre pixel sees the sphere: its albedo, exactly
    np.testing.assert_allclose(r.mean[6, 8], [0.7, 0.6, 0.5], rtol=1e-6)
    small_scene.integrator.type = "depth"
    renderer.set_scene(small_scene)
    renderer.render(1)
    # distance from the camera (0, 1, 5) to the sphere's front, about 4.6
    assert 4.0 < renderer.result().mean[6, 8, 0] < 5.0


def test_render_for_reset_and_sample_ranges(renderer, small_scene):
    renderer.set_scene(small_scene)
    p = renderer.render_for(0.05)
    assert p.samples_done > 0 and renderer.spp == p.accumulated
    renderer.reset(4)
    assert renderer.spp == 0 and renderer.first_sample == 4
    renderer.render(4)
    high = renderer.result()
    renderer.reset()
    renderer.render(4)
    assert not np.array_equal(high.mean, renderer.result().mean), "other samples"
    p = renderer.render(1000000, seconds=0.05)
    assert 0 < p.samples_done < 1000000


def test_progress_callback(renderer, small_scene):
    renderer.set_scene(small_scene)
    seen = []
    renderer.render(16, progress=seen.append)
    assert seen and all(isinstance(p, lucent.RenderProgress) for p in seen)
    assert [p.accumulated for p in seen] == sorted(p.accumulated for p in seen)
    assert seen[-1].samples_done == 16 and seen[-1].samples_target == 16


def test_an_exception_in_the_progress_callback_stops_the_render(renderer, small_scene):
    renderer.set_scene(small_scene)
    calls = []

    def stop(p):
        calls.append(p)
        raise ZeroDivisionError("stop here")
    with pytest.raises(ZeroDivisionError, match="stop here"):
        renderer.render(1000000, progress=stop)
    assert len(calls) == 1, "stopped after the pass that raised"
    r = renderer.result()
    assert r.cancelled and 0 < r.spp < 1000000, "the accumulation keeps what was rendered"
    renderer.render(1)
    assert not renderer.result().cancelled


def test_the_gil_is_released_while_rendering(renderer, small_scene):
    renderer.set_scene(small_scene)
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(1)
            time.sleep(0.001)
    t = threading.Thread(target=count)
    t.start()
    try:
        before = len(ticks)
        renderer.render_for(0.3)
        during = len(ticks) - before
    finally:
        done.set()
        t.join()
    assert during > 10, "another Python thread ran during the render"


def test_cancel_from_another_thread(renderer, small_scene):
    renderer.set_scene(small_scene)
    timer = threading.Timer(0.2, renderer.cancel)
    timer.start()
    p = renderer.render(10 ** 9)
    timer.join()
    assert p.samples_done < 10 ** 9 and renderer.result().cancelled


def test_one_call_at_a_time(renderer, small_scene):
    renderer.set_scene(small_scene)
    errors = []
    started = threading.Event()

    def other():
        started.wait()
        try:
            renderer.render(1)
        except lucent.Error as e:
            errors.append(str(e))
    t = threading.Thread(target=other)
    t.start()

    def progress(p):
        started.set()
        t.join(timeout=10)  # the other thread tries while this render is in progress
    renderer.render(2, progress=progress)
    t.join()
    assert errors and "in use by another thread" in errors[0]


def test_warnings_of_packing(small_scene):
    add_degenerate_triangle(small_scene)
    got = []
    with session(on_warning=got.append) as r:
        r.set_scene(small_scene)
    assert len(got) == 1 and "skipped 1 degenerate or non-finite triangle" in got[0]
    with session() as r, pytest.warns(lucent.LucentWarning, match="degenerate"):
        r.set_scene(small_scene)


def test_a_warning_names_the_line_that_called_lucent(small_scene):
    """A LucentWarning is attributed to the line that called lucent (set_scene, load_scene), as a
    warning of a Python function is to its caller: it named the caller's caller (stacklevel 2 from
    C++, where no Python frame of lucent's is on the stack), or "sys:1" at a script's top level."""
    add_degenerate_triangle(small_scene)
    here = pathlib.Path(__file__).resolve()

    def set_it(r):
        line = inspect.currentframe().f_lineno + 1
        r.set_scene(small_scene)
        return line

    with session() as r, warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        line = set_it(r)
    assert [(pathlib.Path(w.filename).resolve(), w.lineno) for w in got] == [(here, line)]


# --- errors -------------------------------------------------------------------------------

def test_session_errors(renderer, small_scene):
    with pytest.raises(lucent.Error, match="no scene"):
        renderer.render(1)
    with pytest.raises(lucent.Error, match="no scene"):
        renderer.result()
    with pytest.raises(lucent.Error, match="no scene"):
        renderer.scene
    renderer.set_scene(small_scene)
    with pytest.raises(ValueError, match=r"spp must be an integer in \[0, 2\*\*32 - 1\]"):
        renderer.render(-1)
    with pytest.raises(ValueError, match="render: give spp > 0, seconds > 0 or both"):
        renderer.render(0)
    with pytest.raises(TypeError):
        renderer.render(1.5)
    with pytest.raises(TypeError):
        renderer.render("8")
    with pytest.raises(ValueError, match=r"seconds must be a finite number in \[0, 1e7\]"):
        renderer.render(1, seconds=-1)
    # the command line's limit, 1e7 s (render_for(1e8) ran until killed)
    for bad in (0, float("nan"), 1e8, float("inf")):
        with pytest.raises(ValueError, match=r"seconds must be a finite number in \(0, 1e7\]"):
            renderer.render_for(bad)
    with pytest.raises(ValueError, match=r"seconds must be a finite number in \[0, 1e7\]"):
        renderer.render(1, seconds=1.5e7)
    with pytest.raises(ValueError, match=r"max_seconds must be a finite number in \[0, 1e7\]"):
        renderer.render_adaptive(target_error=0.1, max_seconds=1e8)
    with pytest.raises(ValueError, match=r"first_sample must be an integer in \[0, 2\*\*32 - 1\]"):
        renderer.reset(-1)
    with pytest.raises(TypeError):
        renderer.set_scene({"film": {}})
    with pytest.raises(TypeError):
        renderer.render(1, 0, None, 3)
    with pytest.raises(TypeError, match="progress must be callable or None, got 3"):
        renderer.render(1, progress=3)
    huge = small_scene.copy()
    huge.film.width = huge.film.height = 1 << 20
    with pytest.raises(lucent.Error, match="1048576x1048576 film") as e:
        renderer.set_scene(huge)
    assert "\n" not in str(e.value)
    renderer.render(1)  # the session still renders its previous scene
    assert renderer.result().width == 16
    renderer.close()
    with pytest.raises(lucent.Error, match="closed"):
        renderer.render(1)
    # a with block too (__enter__ returned the closed renderer)
    with pytest.raises(lucent.Error, match="closed"):
        with renderer:
            pass


U32 = "the sampler's sample indices are 32-bit"
COUNT = "a pixel's sample count is 32-bit"


@pytest.mark.parametrize("call, message", [
    # integers out of range, whatever their size: ValueError naming the argument and its range
    # (2**32 passed the range, and the session refused it: a pixel's count holds 2**32 - 1)
    (lambda r: r.render(2 ** 32), r"^spp must be an integer in \[0, 2\*\*32 - 1\] \(%s\), got "
     r"4294967296$" % COUNT),
    (lambda r: r.render(2 ** 63), r"^spp must be an integer in \[0, 2\*\*32 - 1\] \(%s\), got "
     r"9223372036854775808$" % COUNT),
    (lambda r: r.render(2 ** 64), r"^spp must be .*, got 18446744073709551616$"),
    (lambda r: r.render(-2 ** 70), r"^spp must be .*, got -1180591620717411303424$"),
    (lambda r: r.render(0), r"^render: give spp > 0, seconds > 0 or both, got spp=0 and seconds=0$"),
    (lambda r: r.render(0, seconds=0), r"^render: give spp > 0, seconds > 0 or both"),
    (lambda r: r.reset(2 ** 32), r"^first_sample must be an integer in \[0, 2\*\*32 - 1\] "
     r"\(%s\), got 4294967296$" % U32),
    (lambda r: r.reset(2 ** 64), r"^first_sample must be an integer in \[0, 2\*\*32 - 1\]"),
    (lambda r: r.reset(-1), r"^first_sample must be an integer in \[0, 2\*\*32 - 1\] .*, got -1$"),
    # render_adaptive: never clamped, and its combinations are arguments too
    (lambda r: r.render_adaptive(budget_spp=8, max_spp=2 ** 40),
     r"^max_spp must be an integer in \[4, 2\*\*32 - 1\], got 1099511627776$"),
    (lambda r: r.render_adaptive(budget_spp=8, min_spp=2 ** 32),
     r"^min_spp must be an integer in \[4, 2\*\*32 - 1\], got 4294967296$"),
    (lambda r: r.render_adaptive(target_error=0.1, min_spp=3),
     r"^min_spp must be an integer in \[4, 2\*\*32 - 1\], got 3$"),
    (lambda r: r.render_adaptive(budget_spp=8, min_spp=0), r"^min_spp must be .*, got 0$"),
    (lambda r: r.render_adaptive(budget_spp=8, min_spp=5, max_spp=5),
     r"^max_spp must be at least min_spp's pilot \(min_spp rounded up to even, 6\), got "
     r"min_spp=5 and max_spp=5$"),
    (lambda r: r.render_adaptive(target_error=0.1, budget_spp=8),
     r"^render_adaptive: give one of target_error and budget_spp, a number > 0, got "
     r"target_error=0.1 and budget_spp=8$"),
    (lambda r: r.render_adaptive(), r"^render_adaptive: give one of target_error and budget_spp"),
    (lambda r: r.render_adaptive(budget_spp=float("inf")), r"^budget_spp must be a finite number"),
    (lambda r: r.render_adaptive(budget_spp=8, max_seconds=-1), r"^max_seconds must be a finite"),
    (lambda r: r.render(1, seconds=float("inf")), r"^seconds must be a finite number in \[0, 1e7\]"),
    (lambda r: r.render_for(float("nan")), r"^seconds must be a finite number in \(0, 1e7\]"),
])
def test_numeric_argument_errors_are_value_errors(renderer, small_scene, call, message):
    """Every out-of-range or invalid numeric argument of the session's methods raises ValueError
    with one message naming it and its range: not pybind11's TypeError for an int beyond a C
    integer, not lucent.Error for one the library refuses, never a silent clamp. The session is
    untouched."""
    renderer.set_scene(small_scene)
    renderer.render(2)
    before = renderer.result()
    with pytest.raises(ValueError, match=message) as e:
        call(renderer)
    assert not isinstance(e.value, lucent.Error)
    assert renderer.spp == 2 and renderer.first_sample == 0
    assert np.array_equal(renderer.result().mean, before.mean)


def test_integer_arguments_take_any_integer_and_refuse_the_rest(renderer, small_scene):
    """Python and NumPy integers are integers; a float or a str is a TypeError naming the
    argument (not pybind11's "incompatible function arguments"). A value in range works."""
    renderer.set_scene(small_scene)
    renderer.render(np.int64(2))
    renderer.reset(np.uint32(2 ** 32 - 1))
    assert renderer.first_sample == 2 ** 32 - 1
    renderer.render(1)  # the last sample index
    with pytest.raises(lucent.Error, match="go past 2\\^32"):  # the session's state, not spp
        renderer.render(1)
    renderer.reset()
    for call, name in [(lambda: renderer.render(1.5), "spp"), (lambda: renderer.render("8"), "spp"),
                       (lambda: renderer.reset(0.0), "first_sample"),
                       (lambda: renderer.render_adaptive(budget_spp=8, min_spp=8.0), "min_spp"),
                       (lambda: lucent.render_reference(small_scene, spp=1, threads="2"),
                        "threads")]:
        with pytest.raises(TypeError, match="^%s must be an integer, got " % name):
            call()
    assert "spp: int" in renderer.render.__doc__ and "first_sample: int = 0" in renderer.reset.__doc__


def test_reserved_host_bytes_counts_in_the_memory_check(small_scene):
    """What the application declares it holds beside the session is added to the estimate by
    which set_scene refuses a film too large for the host (here a petabyte: always refused)."""
    with session(reserved_host_bytes=2**50) as r:
        assert r.options["reserved_host_bytes"] == 2**50
        with pytest.raises(lucent.Error, match="the largest part is what the application keeps "
                           r"beside the session \(its outputs, as it declared them\)"):
            r.set_scene(small_scene)
    with session(reserved_host_bytes=1 << 20) as r:
        r.set_scene(small_scene)  # a mebibyte more: fine
    with pytest.raises(ValueError, match=r"^reserved_host_bytes must be an integer in \[0, "):
        session(reserved_host_bytes=-1)
    with pytest.raises(TypeError, match="^reserved_host_bytes must be an integer, got 1.5"):
        session(reserved_host_bytes=1.5)


def test_session_option_errors():
    with pytest.raises(lucent.Error, match="no such device"):
        session(device="no such device at all")
    with pytest.raises(lucent.Error, match="no such device"):
        lucent.select_device("no such device at all")
    with pytest.raises(ValueError, match="unknown precision 'quad'"):
        session(precision="quad")
    with pytest.raises(ValueError, match="pass_seconds must be a positive number"):
        session(pass_seconds=0)
    with pytest.raises(TypeError):
        session(fast_math="yes please", bogus=1)
    with pytest.raises(TypeError):
        lucent.Renderer("0")  # keyword arguments only
    with pytest.raises(TypeError, match="on_warning must be callable"):
        session(on_warning="stderr")
    with session() as r, pytest.raises(ValueError, match="unknown precision"):
        r.set_build_options(precision="half")



def test_a_nul_in_a_device_or_directory_is_refused_not_cut():
    # a file name ends at a NUL for the system, and a message at its first NUL: "device 'gpu"
    for kwargs, name in [({"device": "gpu\0 1"}, "device"), ({"kernel_dir": "k\0 1"}, "kernel_dir"),
                         ({"cache_dir": "c\0 1"}, "cache_dir")]:
        with pytest.raises(ValueError, match=r"%s: embedded null character in '.*\\x00 1'" % name):
            session(**kwargs)
    with pytest.raises(ValueError, match=r"selector: embedded null character in 'gpu\\x00 1'"):
        lucent.select_device("gpu\0 1")
    with pytest.raises(ValueError, match=r"cache_dir: embedded null character"):
        lucent.clear_cache("c\0 1")
    with pytest.raises(ValueError, match=r"unknown precision 'flo\\x00at'"):
        session(precision="flo\0at")


def test_reprs_say_what_they_hold(renderer, small_scene):
    renderer.set_scene(small_scene)
    d = renderer.device
    name = d.name
    assert repr(d) == "<lucent.DeviceInfo %d: %s (%s, %s)>" % (d.index, name, d.type, d.platform)
    # the session's devices: one here, the session's own
    assert [dev.name for dev in renderer.devices] == [name]
    p = renderer.render(4)
    assert re.fullmatch(r"<lucent\.RenderProgress samples_done=4 samples_target=4 accumulated=4 "
                        r"elapsed=\S+ time_limit=0 samples_per_second=\S+>", repr(p)), repr(p)
    share, = p.devices
    assert repr(share) == "<lucent.DeviceShare %s: 4 spp>" % name
    res = renderer.result()
    assert re.fullmatch(r"<lucent\.RenderResult 16x12, 4 spp, \S+ s, %s>" % re.escape(res.device),
                        repr(res)), repr(res)
    assert re.fullmatch(r"<lucent\.CompareResult passed, max \|z\| 0\.0+, RMSE 0\.0+>",
                        repr(lucent.compare(res.mean, res.mean)))
    assert repr(lucent.compare(res.mean, res.mean + 1)).startswith("<lucent.CompareResult FAILED")
    assert repr(renderer) == "<lucent.Renderer device=%r>" % d
    closed = session()
    closed.close()
    assert repr(closed) == "<lucent.Renderer (closed)>"


def test_a_renderer_in_a_cycle_through_its_on_warning_is_collected(small_scene):
    """A renderer whose on_warning refers back to it (a bound method of the object that holds
    it) was never collected: Python's garbage collector did not see the callable the renderer
    held, and the session, its buffers and its device stayed for the process's life."""

    class App:
        def __init__(self):
            self.renderer = session(on_warning=self.log)
            self.renderer.set_scene(small_scene)

        def log(self, message):
            pass

    app = App()
    alive = weakref.ref(app)
    del app
    gc.collect()
    assert alive() is None
    # one never initialised (cls.__new__) is visited and collected too
    bare = lucent.Renderer.__new__(lucent.Renderer)
    cycle = [bare]
    cycle.append(cycle)
    del bare, cycle
    gc.collect()


def test_flags_take_true_or_false_only(small_scene):
    """A bool argument took anything with a truth value: fast_math=0.5 turned fast math on,
    complete=None off, image_mean_test=0.3 on (the scene's bool fields refuse them already)."""
    img = np.ones((2, 2, 3), np.float32)
    calls = {
        "fast_math": lambda: lucent.Renderer(fast_math=0.5),
        "specialize": lambda: lucent.Renderer(specialize=None),
        "image_mean_test": lambda: lucent.compare(img, img, image_mean_test=0.3),
        "complete": lambda: lucent.merge_parts(["a.exr"], complete="yes"),
    }
    for name, call in calls.items():
        with pytest.raises(TypeError, match=r"^%s must be True or False, got " % name):
            call()
    with pytest.raises(TypeError, match=r"^fast_math must be True or False, got 2\.0$"):
        lucent.scene_info(small_scene, fast_math=2.0)
    with session() as r:
        with pytest.raises(TypeError, match=r"^specialize must be True or False, got 1$"):
            r.set_build_options(specialize=1)
        r.set_build_options(fast_math=np.bool_(True))  # a NumPy bool is a bool
        assert r.options["fast_math"] is True
    assert lucent.scene_info(small_scene, fast_math=True)["fast_math"] is True


def test_a_failed_calls_warning_callback_error_is_not_raised_by_the_next_call(small_scene):
    """A call that failed on its own error kept what its on_warning had raised, and the next call,
    which gave no warning, raised it."""
    bright = lucent.scene_from_dict(SMALL)
    bright.materials[0].albedo = (1.25, 0.5, 0.5)  # a warning, then the memory check fails
    seen = []

    def raiser(message):
        seen.append(message)
        raise RuntimeError("from on_warning")

    with session(on_warning=raiser, reserved_host_bytes=2 ** 62) as r:
        with pytest.raises(lucent.Error, match="host memory"):
            r.set_scene(bright)
        assert len(seen) == 1
        r.set_build_options(fast_math=True)  # raised "from on_warning"
        assert r.options["fast_math"] is True


def test_the_collector_meets_a_subclass_renderer_being_laid_out():
    """A Renderer is tracked by the garbage collector from its allocation on: a collection while
    pybind11 laid out a Python subclass's first instance read its null status pointer, and the
    interpreter crashed (SIGSEGV; the review's find, with gc.set_threshold(1))."""
    code = ("import gc, lucent\ngc.set_threshold(1)\n"
            "class S(lucent.Renderer):\n    pass\n"
            "s = S(**lucent.environment())\ndel s\ngc.collect()\n"
            "t = S.__new__(S)\ngc.collect()\nprint('collected')\n")
    child = subprocess.run([sys.executable, "-c", code], capture_output=True, timeout=120)
    assert child.returncode == 0, child.stderr.decode()
    assert child.stdout == b"collected\n"


def test_scene_info_gives_the_warnings_a_render_gives(small_scene):
    """scene_info says what a render of the scene says (as `lucent info` does): an albedo above 1,
    here; it gave only the packing's own warnings."""
    small_scene.materials[0].albedo = (1.5, 0.5, 0.5)
    got = []
    lucent.scene_info(small_scene, on_warning=got.append)
    assert any("is above 1" in str(w) for w in got), got

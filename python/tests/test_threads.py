"""A session used from several Python threads: one call at a time, close() against calls in
progress, and what other threads may read meanwhile. The threads are ordered by events set from
the session's own callbacks (a progress callback between passes, a warning callback inside
set_scene, a finaliser that runs inside close()), never by sleeps. A call from a callback of the
session's own call, on the same thread, is refused as a re-entry, not as another thread's. The
interpreter exits cleanly while a daemon thread is in a call (a child process)."""
import json
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import lucent
from conftest import SMALL, add_degenerate_triangle, session

IN_USE = "in use by another thread"
WAIT = 10  # seconds: a bound on every wait, never reached when the test passes


def run_in_thread(f):
    """Starts `f` on a thread; returns (thread, outcome): outcome["value"] or outcome["error"]."""
    outcome = {}

    def body():
        try:
            outcome["value"] = f()
        except BaseException as e:  # reported to the test's thread
            outcome["error"] = e
    t = threading.Thread(target=body)
    t.start()
    return t, outcome


def error_of(f):
    """The lucent.Error that f() raised, as text; None when it returned."""
    try:
        f()
    except lucent.Error as e:
        return str(e)
    return None


def test_close_is_refused_while_another_thread_renders(small_scene):
    """close() from another thread while a render is in progress raises (the render goes on);
    a progress callback reads every property of its session; after close() every call raises
    that the renderer is closed."""
    r = session()
    r.set_scene(small_scene)
    in_callback = threading.Event()
    seen = {}

    def other():
        in_callback.wait(WAIT)
        return error_of(r.close), error_of(r.__exit__)

    t, outcome = run_in_thread(other)

    def progress(p):
        if in_callback.is_set():
            return
        # between passes the session can be read, from its own callback too
        seen.update(spp=r.spp, accumulated=p.accumulated, first=r.first_sample,
                    passes=r.stats.passes, width=r.scene.film.width,
                    precision=r.options["precision"], device=r.device.name)
        in_callback.set()
        t.join(WAIT)  # the other thread closes while this render is in progress

    p = r.render(2, progress=progress)
    t.join()
    assert "error" not in outcome, outcome
    close_error, exit_error = outcome["value"]
    assert close_error and IN_USE in close_error
    assert exit_error and IN_USE in exit_error
    assert seen["spp"] == seen["accumulated"] > 0 and seen["first"] == 0
    assert seen["passes"] >= 1 and seen["width"] == 16 and seen["precision"] == "float"
    assert p.samples_done == 2 and r.spp == 2, "the render went on"
    r.render(1)  # the session is still open
    assert r.spp == 3
    r.close()
    for call in (lambda: r.render(1), lambda: r.set_scene(small_scene), lambda: r.result(),
                 lambda: r.reset(), lambda: r.spp, lambda: r.first_sample, lambda: r.stats,
                 lambda: r.scene, lambda: r.options, lambda: r.device, r.cancel):
        assert "the renderer is closed" in (error_of(call) or "returned")
    r.close()  # closing again does nothing


class FinalisedInsideClose:
    """An on_warning callable whose finaliser runs when the session drops it, inside close()
    (which destroys the session with the GIL released): it lets another thread call the
    renderer at that moment and waits for it."""

    def __init__(self, inside, done):
        self.inside, self.done = inside, done

    def __call__(self, message):
        pass

    def __del__(self):
        self.inside.set()
        self.done.wait(WAIT)


def test_calls_while_close_destroys_the_session_raise_closed(small_scene):
    inside_close, tried = threading.Event(), threading.Event()
    r = session(on_warning=FinalisedInsideClose(inside_close, tried))
    r.set_scene(small_scene)
    r.render(1)

    def other():
        try:
            inside_close.wait(WAIT)
            assert inside_close.is_set(), "the finaliser did not run inside close()"
            calls = {"render": lambda: r.render(1), "set_scene": lambda: r.set_scene(small_scene),
                     "result": r.result, "reset": r.reset, "spp": lambda: r.spp,
                     "first_sample": lambda: r.first_sample, "stats": lambda: r.stats,
                     "scene": lambda: r.scene, "options": lambda: r.options,
                     "device": lambda: r.device, "cancel": r.cancel}
            errors = {name: error_of(call) for name, call in calls.items()}
            errors["close"] = error_of(r.close) or "returned"
            return errors
        finally:
            tried.set()

    t, outcome = run_in_thread(other)
    r.close()
    t.join()
    assert inside_close.is_set() and tried.is_set()
    assert "error" not in outcome, outcome
    errors = outcome["value"]
    assert errors.pop("close") == "returned", "a second close() while closing does nothing"
    assert all(e and "the renderer is closed" in e for e in errors.values()), errors


def test_scene_and_options_are_refused_during_another_threads_set_scene(small_scene):
    """While set_scene runs (here: stopped in its warning callback), another thread's scene and
    options raise, as a second call would; spp, first_sample and stats give the values from
    before the call; device is fixed for the session's life."""
    armed, in_set_scene = threading.Event(), threading.Event()
    holder = {}

    def on_warning(message):
        if armed.is_set():
            in_set_scene.set()
            holder["thread"].join(WAIT)  # the other thread reads while set_scene is in progress

    with session(on_warning=on_warning) as r:
        r.set_scene(small_scene)
        r.reset(5)
        r.render(2)
        before = r.stats

        def other():
            in_set_scene.wait(WAIT)
            return {"scene": error_of(lambda: r.scene), "options": error_of(lambda: r.options),
                    "render": error_of(lambda: r.render(1)),
                    "counters": (r.spp, r.first_sample, r.stats.scene_packs),
                    "device": r.device.name}

        holder["thread"], outcome = run_in_thread(other)
        bad = small_scene.copy()
        add_degenerate_triangle(bad)  # packing warns once
        armed.set()
        r.set_scene(bad)
        holder["thread"].join()
        assert in_set_scene.is_set() and "error" not in outcome, outcome
        got = outcome["value"]
        assert IN_USE in (got["scene"] or "returned") and IN_USE in (got["options"] or "returned")
        assert IN_USE in (got["render"] or "returned")
        assert got["counters"] == (2, 5, before.scene_packs)
        assert got["device"] == r.device.name
        # once set_scene returned: the new scene, and the counters of the session
        assert len(r.scene.triangles) == len(small_scene.triangles) + 1
        assert r.stats.scene_packs == before.scene_packs + 1


def test_counters_are_read_from_another_thread_during_a_render(renderer, small_scene):
    """spp, first_sample and stats may be polled from another thread while a render runs: they
    give the values after the render's last pass, never a torn read or an error."""
    renderer.set_scene(small_scene)
    renderer.reset(3)
    first_pass = threading.Event()
    progress = []

    def on_progress(p):
        progress.append(p.accumulated)
        first_pass.set()

    def other():
        first_pass.wait(WAIT)
        reads = []
        for _ in range(50):
            stats = renderer.stats
            reads.append((renderer.spp, renderer.first_sample, stats.passes))
        renderer.cancel()  # ends the render
        return reads

    t, outcome = run_in_thread(other)
    p = renderer.render(10 ** 9, progress=on_progress)
    t.join()
    assert "error" not in outcome, outcome
    reads = outcome["value"]
    assert renderer.result().cancelled and p.samples_done < 10 ** 9
    assert all(first == 3 for _, first, _ in reads)
    spps = [spp for spp, _, _ in reads]
    assert spps == sorted(spps) and progress[0] <= spps[0] and spps[-1] <= renderer.spp
    assert all(passes >= 1 for _, _, passes in reads)


def reentry(verb, what, callback, call):
    """The message of `what` refused in `callback` of the session's own `call`."""
    return (f"cannot {verb} {what} from the {callback} of this renderer's own {call} (a session "
            f"runs one call at a time: {verb} it once {call} has returned)")


def session_calls(r, scene):
    """Every call of the session that a call in progress refuses, by name."""
    reference = np.zeros((12, 16, 3), np.float32)
    return {"render": lambda: r.render(1), "render_for": lambda: r.render_for(0.01),
            "render_adaptive": lambda: r.render_adaptive(budget_spp=4, min_spp=4),
            "set_scene": lambda: r.set_scene(scene), "set_build_options": r.set_build_options,
            "set_camera": lambda: r.set_camera(scene.camera),
            "reset": r.reset, "result": r.result, "close": r.close,
            "converge": lambda: lucent.converge(scene, reference, renderer=r, spp_ladder=[1])}


@pytest.mark.parametrize("call", ["render", "render_for", "render_adaptive"])
def test_calls_from_a_renders_own_progress_callback_say_so(renderer, small_scene, call):
    """From its own progress callback every call of the session is refused as a re-entry (it was
    "in use by another thread", which it is not); what is safe between passes works: spp,
    first_sample, stats, scene, options, device, result() (a live preview: it was refused),
    cancel()."""
    renderer.set_scene(small_scene)
    renderer.reset(5)
    calls = session_calls(renderer, small_scene)
    del calls["result"]
    errors, reads = {}, {}

    def progress(p):
        if errors:
            return
        errors.update({name: error_of(c) or "returned" for name, c in calls.items()})
        errors["__exit__"] = error_of(lambda: renderer.__exit__(None, None, None)) or "returned"
        reads.update(spp=renderer.spp, accumulated=p.accumulated, first=renderer.first_sample,
                     passes=renderer.stats.passes, width=renderer.scene.film.width,
                     precision=renderer.options["precision"], device=renderer.device.name)
        preview = renderer.result()
        reads.update(preview_spp=preview.spp, preview_shape=preview.mean.shape,
                     preview_n=int(preview.samples.sum()))
        renderer.cancel()  # ends this render after the pass

    run = {"render": lambda: renderer.render(10 ** 9, progress=progress),
           "render_for": lambda: renderer.render_for(60, progress=progress),
           "render_adaptive": lambda: renderer.render_adaptive(
               budget_spp=10 ** 6, min_spp=4, max_spp=10 ** 6, progress=progress)}[call]
    run()
    assert errors.pop("__exit__") == reentry("call", "close", "progress callback", call)
    for name, error in errors.items():
        assert error == reentry("call", name, "progress callback", call), name
    assert reads["spp"] == reads["accumulated"] > 0 and reads["first"] == 5
    assert reads["passes"] >= 1 and reads["width"] == 16 and reads["precision"] == "float"
    assert reads["device"] == renderer.device.name
    assert reads["preview_spp"] == reads["spp"] and reads["preview_shape"] == (12, 16, 3)
    assert reads["preview_n"] > 0
    assert renderer.result().cancelled, "cancel() from the callback stopped the render"
    renderer.reset()
    renderer.render(1)  # the session is open and works
    assert renderer.spp == 1


def test_calls_from_a_warning_callback_of_set_scene_say_so(small_scene):
    """A warning callback runs inside set_scene: every call and scene and options are refused
    there as re-entries of set_scene; spp and device work."""
    got = {}

    def on_warning(message):
        calls = session_calls(r, small_scene)
        got.update({name: error_of(c) or "returned" for name, c in calls.items()})
        got["scene"] = error_of(lambda: r.scene) or "returned"
        got["options"] = error_of(lambda: r.options) or "returned"
        got["reads"] = (r.spp, r.first_sample, r.device.name)

    with session(on_warning=on_warning) as r:
        bad = small_scene.copy()
        add_degenerate_triangle(bad)  # packing warns once
        r.set_scene(bad)
        assert got.pop("reads") == (0, 0, r.device.name)
        assert got.pop("scene") == reentry("read", "scene", "warning callback", "set_scene")
        assert got.pop("options") == reentry("read", "options", "warning callback", "set_scene")
        for name, error in got.items():
            assert error == reentry("call", name, "warning callback", "set_scene"), name
        assert len(r.scene.triangles) == len(small_scene.triangles) + 1


def test_calls_from_converges_own_on_point_callback_say_so(renderer, small_scene):
    """From on_point the study's session is read as from a progress callback: result() gives
    the rung's image (it was refused, where the library's on_point may read it), and a call
    that changes the session is refused."""
    renderer.set_scene(small_scene)
    got = []
    lucent.converge(small_scene, np.zeros((12, 16, 3), np.float32), renderer=renderer,
                    spp_ladder=[1, 2],
                    on_point=lambda p: got.append((p.spp, renderer.result().spp,
                                                   error_of(lambda: renderer.render(1)))))
    assert got == [(n, n, reentry("call", "render", "on_point callback", "converge"))
                   for n in (1, 2)]


@pytest.mark.parametrize("b_options", [{}, {"device": "0,0"}], ids=["one device", "two contexts"])
def test_a_reentry_through_another_sessions_callback_says_so(small_scene, b_options):
    """Session a's progress callback renders with session b, whose progress callback calls a: a
    re-entry of a's render on this thread, two callbacks down. With two contexts ("0,0"), b's
    passes, and its progress callback, run on threads of the session's own, which have the chain
    of callbacks of b.render's caller (they said "in use by another thread")."""
    got = {}
    with session() as a, session(**b_options) as b:
        a.set_scene(small_scene)
        b.set_scene(small_scene)

        def b_progress(p):
            got.setdefault("a", error_of(lambda: a.render(1)))
            got.setdefault("b", error_of(b.result))  # allowed: b's own progress callback
            got.setdefault("a.result", error_of(a.result))

        def a_progress(p):
            if "outer" not in got:
                got["outer"] = b.render(4, progress=b_progress).samples_done

        a.render(1, progress=a_progress)
        assert got == {"outer": 4, "a": reentry("call", "render", "progress callback", "render"),
                       "b": None, "a.result": None}
        assert a.spp == 1 and b.spp == 4


EXIT_CHILD = textwrap.dedent("""
    import json, sys, threading, time
    import numpy as np
    import lucent
    mode, scene, path = sys.argv[1], lucent.scene_from_dict(json.loads(sys.argv[2])), sys.argv[3]
    started = threading.Event()

    def body():
        if mode == "render":
            r = lucent.Renderer(**lucent.environment())
            r.set_scene(scene)
            r.render(10 ** 9, progress=lambda p: started.set())
        elif mode == "reference":
            scene.film.height = 100000  # many short rows: the reference stops after a row
            started.set()
            lucent.render_reference(scene, spp=64, threads=1)
        else:  # a call that releases the GIL, then takes it back
            image = np.zeros((300, 300, 3), np.float32)
            while True:
                lucent.write_image(path, image)
                started.set()
    class Finalizer:  # deleted as the interpreter finalizes: the daemon thread asks for the GIL
        def __del__(self):
            time.sleep(0.2)
    finalizer = Finalizer()
    threading.Thread(target=body, daemon=True).start()
    started.wait(30)
    time.sleep(0.2)  # well into the call (the test passes if not)
    print("exiting", flush=True)
""")


@pytest.mark.parametrize("mode", ["render", "reference", "write_image"])
def test_the_interpreter_exits_cleanly_while_a_daemon_thread_is_in_a_call(mode, tmp_path):
    # CPython ends a daemon thread that asks for the GIL during finalization with pthread_exit;
    # the unwinding met a joinable std::thread or a noexcept destructor and aborted the process
    start = time.monotonic()
    child = subprocess.run([sys.executable, "-c", EXIT_CHILD, mode, json.dumps(SMALL),
                            str(tmp_path / "image.png")],
                           capture_output=True, text=True, timeout=60)
    assert child.stdout.split() == ["exiting"], child.stdout + child.stderr
    assert "terminate" not in child.stderr and child.returncode == 0, child.stderr
    assert time.monotonic() - start < 20, "exit waits for the render's current pass only"


FIRST_ARRAYS_CHILD = textwrap.dedent("""
    import sys, threading, faulthandler
    import lucent
    faulthandler.dump_traceback_later(30, exit=True)
    barrier = threading.Barrier(4)
    def touch():
        barrier.wait()
        lucent.Scene().positions  # an (N, 3) array: pybind11 once imported NumPy here
    threads = [threading.Thread(target=touch) for _ in range(4)]
    for t in threads: t.start()
    for t in threads: t.join()
    print("ok")
""")


def test_first_arrays_made_by_several_threads_at_once_do_not_deadlock():
    # pybind11 imported NumPy on the first array, inside a static's initialisation: a thread in
    # that import waited for the GIL, which a second thread held while it waited for the static
    # (20 hangs in 20 runs); the module now imports NumPy when it is imported
    child = subprocess.run([sys.executable, "-c", FIRST_ARRAYS_CHILD], capture_output=True,
                           text=True, timeout=60)
    assert child.stdout.split() == ["ok"] and child.returncode == 0, child.stdout + child.stderr


def test_cancel_from_a_thread_that_saw_the_call_begin_stops_it(renderer, small_scene):
    """A cancel made once another thread's call is seen in progress (its reads refused) stops
    that call, however early: it was lost in about one try of six, when it came before the call
    reached the library, whose start drops an earlier cancel."""
    renderer.set_scene(small_scene)
    for attempt in range(20):
        def other():
            while True:
                try:
                    renderer.options  # refused once the render has begun
                except lucent.Error as e:
                    if "in use" in str(e):
                        renderer.cancel()
                        return

        t, outcome = run_in_thread(other)
        start = time.monotonic()
        renderer.render(0, seconds=30.0)
        seconds = time.monotonic() - start
        t.join()
        assert "error" not in outcome, outcome
        assert renderer.result().cancelled and seconds < 10, (attempt, seconds)


def test_callbacks_run_on_the_calling_thread_in_its_context(renderer, small_scene):
    """Progress callbacks and converge's on_point run on the thread that called, as Python code
    expects: they see its contextvars, threading.local values and
    current_thread() (they ran on a thread of the call's own, with an empty context)."""
    import contextvars
    var = contextvars.ContextVar("var", default="unset")
    local = threading.local()

    def seen(*_):
        return (threading.get_ident(), var.get(), getattr(local, "value", "unset"))

    def on(thread_name):
        var.set("set on " + thread_name)
        local.value = thread_name
        renderer.set_scene(small_scene)
        progress, points = [], []
        renderer.render(2, progress=lambda p: progress.append(seen()))
        reference = lucent.RenderResult(renderer.result().mean)
        lucent.converge(small_scene, reference, spp_ladder=[1], renderer=renderer,
                        on_point=lambda p: points.append(seen()))
        return progress, points, (threading.get_ident(), "set on " + thread_name, thread_name)

    results = [on("main")]
    t = threading.Thread(target=lambda: results.append(on("other")))
    t.start()
    t.join()
    assert len(results) == 2
    for progress, points, expected in results:
        assert progress and set(progress) == {expected}
        assert points and set(points) == {expected}


def test_a_signal_handler_during_the_threads_own_render_is_told_so(renderer, small_scene):
    """A signal handler runs on the thread whose render waits for its worker: a call from it
    was refused as "in use by another thread", which it is not."""
    import os
    import signal
    renderer.set_scene(small_scene)
    errors = []

    def handler(signum, frame):
        try:
            renderer.result()
        except lucent.Error as e:
            errors.append(str(e))
        renderer.cancel()

    previous = signal.signal(signal.SIGUSR1, handler)
    try:
        threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGUSR1)).start()
        renderer.render(10 ** 9)
    finally:
        signal.signal(signal.SIGUSR1, previous)
    assert errors == ["cannot call result from a signal handler that runs during this renderer's "
                      "own render on the same thread (a session runs one call at a time: call it "
                      "once render has returned)"]

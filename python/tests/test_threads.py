"""A session used from several Python threads: one call at a time, close() against calls in
progress, and what other threads may read meanwhile. The threads are ordered by events set from
the session's own callbacks (a progress callback between passes, a warning callback inside
set_scene, a finaliser that runs inside close()), never by sleeps."""
import threading

import lucent
from conftest import add_degenerate_triangle, session

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

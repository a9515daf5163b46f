"""Ctrl-C (SIGINT) during a render stops it cleanly after the current pass, keeps what was
rendered in the session and raises KeyboardInterrupt: a child Python process is interrupted."""
import json
import os
import signal
import subprocess
import sys
import textwrap

import pytest

from conftest import SMALL

CHILD = textwrap.dedent("""
    import json, sys
    import lucent
    mode = sys.argv[1]
    scene = lucent.scene_from_dict(json.loads(sys.argv[2]))
    r = lucent.Renderer(**lucent.environment())
    r.set_scene(scene)
    announced = []

    def progress(p):
        if not announced:
            announced.append(1)
            print("rendering", flush=True)
    try:
        if mode == "session":
            r.render(10 ** 9, progress=progress)
        elif mode == "converge":
            reference = lucent.RenderResult(r.result().mean)
            print("rendering", flush=True)
            lucent.converge(scene, reference, spp_ladder=[2 ** 24], renderer=r)
        else:
            # the reference stops after the rows under way: many short rows
            scene.film.height = 100000
            print("rendering", flush=True)
            lucent.render_reference(scene, spp=64)
        print("finished", flush=True)
    except KeyboardInterrupt:
        if mode == "session":
            res = r.result()
            print("interrupted", res.spp, res.cancelled, int(res.samples.min()), flush=True)
        else:
            print("interrupted", flush=True)
""")


@pytest.mark.parametrize("mode", ["session", "converge", "reference"])
def test_sigint_stops_the_render_and_raises_keyboard_interrupt(mode):
    env = dict(os.environ)
    child = subprocess.Popen([sys.executable, "-c", CHILD, mode, json.dumps(SMALL)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        line = child.stdout.readline()
        assert line.strip() == "rendering", line + child.stderr.read()
        # let the render run a little (the reference and converge announce before starting)
        try:
            child.wait(timeout=0.5)
        except subprocess.TimeoutExpired:
            pass
        child.send_signal(signal.SIGINT)
        out, err = child.communicate(timeout=60)
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    words = out.split()
    assert words and words[0] == "interrupted", out + err
    assert child.returncode == 0, err
    if mode == "session":
        spp, cancelled, min_samples = int(words[1]), words[2], int(words[3])
        assert 0 < spp < 10 ** 9 and cancelled == "True"
        assert min_samples > 0, "the accumulation keeps the passes rendered before Ctrl-C"


SET_SCENE_CHILD = textwrap.dedent("""
    import json, os, signal, sys, threading, time
    import lucent
    scene = lucent.scene_from_dict(json.loads(sys.argv[1]))
    for ms in range(5, 45, 5):
        r = lucent.Renderer(**lucent.environment())
        timer = threading.Timer(ms / 1000, lambda: os.kill(os.getpid(), signal.SIGINT))
        try:
            # (inside the try: on a loaded machine the signal came before start() returned)
            timer.start()
            r.set_scene(scene)
            # a Ctrl-C that comes after set_scene is raised here: in the wait for the timer's
            # thread, or at the next line once it has sent it (a fixed 0.2 s sleep did not
            # wait for a timer late on a loaded machine, and took 1.6 s in all)
            timer.join()
            time.sleep(0.01)
            print(ms, "late", flush=True)
        except KeyboardInterrupt:
            print(ms, "keyboard", flush=True)
        except lucent.Error as e:
            print(ms, "error", str(e).replace("\\n", " "), flush=True)
""")


def test_sigint_during_set_scene_raises_keyboard_interrupt():
    # PoCL's LLVM handles SIGINT while it builds a kernel (warm cache or not: it preprocesses the
    # source) and the build fails: set_scene raised lucent.Error "kernel build failed", and the
    # KeyboardInterrupt then came out in the caller's except block (the interruption tester's
    # find, 13 of 80 random trials). A failed call with a Ctrl-C pending raises KeyboardInterrupt.
    child = subprocess.run([sys.executable, "-c", SET_SCENE_CHILD, json.dumps(SMALL)],
                           capture_output=True, text=True, timeout=120, env=dict(os.environ))
    assert child.returncode == 0, child.stderr
    lines = child.stdout.splitlines()
    assert len(lines) == 8, child.stdout + child.stderr
    assert not [line for line in lines if " error " in line], child.stdout


LOCK_CHILD = textwrap.dedent("""
    import fcntl, json, os, signal, sys, threading, time
    import lucent
    scene = lucent.scene_from_dict(json.loads(sys.argv[1]))
    first, second = sys.argv[2], sys.argv[3]
    env = dict(lucent.environment())
    env["cache_dir"] = first
    lucent.Renderer(**env).set_scene(scene)  # the build lock's name: its key's
    lock = [n for n in os.listdir(first) if n.endswith(".lock")][0]
    fd = os.open(os.path.join(second, lock), os.O_RDWR | os.O_CREAT)
    fcntl.flock(fd, fcntl.LOCK_EX)  # another build of the kernel, in progress
    env["cache_dir"] = second
    r = lucent.Renderer(**env)
    threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
    t0 = time.monotonic()
    try:
        r.set_scene(scene)
        print("returned", time.monotonic() - t0, flush=True)
    except KeyboardInterrupt:
        print("keyboard", time.monotonic() - t0, flush=True)
""")


def test_sigint_stops_set_scene_waiting_for_another_build(tmp_path):
    # set_scene waits up to 600 s for another process's build of the same kernel (its lock); a
    # Ctrl-C there was ignored until that build ended, as it ran on the calling thread, where
    # Python's handler never ran (the concurrency tester's find: 14 s, the holder's time). It now
    # raises KeyboardInterrupt at once.
    if os.environ.get("LUCENT_CACHE_DIR") == "off":
        pytest.skip("LUCENT_CACHE_DIR=off: no build locks")
    first, second = tmp_path / "first", tmp_path / "second"
    first.mkdir()
    second.mkdir()
    child = subprocess.run(
        [sys.executable, "-c", LOCK_CHILD, json.dumps(SMALL), str(first), str(second)],
        capture_output=True, text=True, timeout=60, env=dict(os.environ))
    assert child.returncode == 0, child.stderr
    words = child.stdout.split()
    assert words and words[0] == "keyboard", child.stdout + child.stderr
    # (the signal at 1 s; the wait looks at the cancel flag every 20 ms, Python's loop every 50)
    assert float(words[1]) < 3, child.stdout


BLOCKED_CALLBACK_CHILD = textwrap.dedent("""
    import json, os, signal, sys, threading, time
    import lucent
    scene = lucent.scene_from_dict(json.loads(sys.argv[1]))
    r = lucent.Renderer(**lucent.environment())
    r.set_scene(scene)
    entered = threading.Event()

    def progress(p):
        entered.set()
        time.sleep(60)  # a callback that blocks (a deadlock, a dialog left open)

    def interrupt():
        entered.wait()
        time.sleep(0.2)
        os.kill(os.getpid(), signal.SIGINT)
    threading.Thread(target=interrupt, daemon=True).start()
    t0 = time.monotonic()
    try:
        r.render(10 ** 9, progress=progress)
    except KeyboardInterrupt:
        print("keyboard", round(time.monotonic() - t0, 1), r.result().spp > 0, flush=True)
""")


def test_sigint_interrupts_a_blocked_progress_callback():
    # The callback runs on the thread that called render, where Python handles the signal: it
    # raised in the callback at once. (It ran on the render's worker thread, where no signal
    # handler runs: Ctrl-C was seen between passes only, then render waited for the callback,
    # and further Ctrl-Cs went unseen until it returned: a blocked callback could not be stopped.)
    child = subprocess.run([sys.executable, "-c", BLOCKED_CALLBACK_CHILD, json.dumps(SMALL)],
                           capture_output=True, text=True, timeout=50, env=dict(os.environ))
    assert child.returncode == 0, child.stderr
    word, seconds, kept = child.stdout.split()
    assert word == "keyboard" and kept == "True", child.stdout
    assert float(seconds) < 30, child.stdout


SHORT_PASSES_CHILD = textwrap.dedent("""
    import json, os, signal, sys, threading, time
    import lucent
    scene = lucent.scene_from_dict(json.loads(sys.argv[1]))
    env = dict(lucent.environment())
    env["pass_seconds"] = 0.002
    r = lucent.Renderer(**env)
    r.set_scene(scene)
    seen = []

    first = []

    def interrupt():
        while len(seen) < 20:
            time.sleep(0.001)
        first.append(time.monotonic() - t0)  # 20 passes: short ones, under 50 ms each?
        os.kill(os.getpid(), signal.SIGINT)
    t0 = time.monotonic()
    threading.Thread(target=interrupt, daemon=True).start()
    try:
        r.render(10 ** 9, progress=seen.append)  # a C function: no signal interrupts it
    except KeyboardInterrupt:
        print("keyboard", round(time.monotonic() - t0, 1), round(first[0], 3), flush=True)
""")


def test_sigint_stops_a_render_of_short_passes_with_a_c_callback():
    # Passes of a few milliseconds post their callback more often than the calling thread's
    # 50 ms look at the signals: it looked only when none came, and Ctrl-C went unseen (the
    # review's find: still rendering after 60 s). It looks every 50 ms, callbacks or not.
    child = subprocess.run([sys.executable, "-c", SHORT_PASSES_CHILD, json.dumps(SMALL)],
                           capture_output=True, text=True, timeout=60, env=dict(os.environ))
    assert child.returncode == 0, child.stderr
    word, seconds, twenty = child.stdout.split()
    assert word == "keyboard" and float(seconds) < 30, child.stdout
    if float(twenty) > 20 * 0.05:  # (what the test needs: callbacks more often than 50 ms)
        pytest.skip("passes of %.0f ms here: too long to test this" % (1000 * float(twenty) / 20))

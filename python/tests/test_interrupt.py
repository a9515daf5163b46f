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

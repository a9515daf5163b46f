"""python/bench_session.py, the benchmark of BENCHMARKS.md "Python bindings": its scratch
directory is removed (tempfile.mkdtemp left the CLI's and Python's images behind on every run).
The two child processes are stand-ins here: nothing renders."""
import importlib.util
import pathlib
import tempfile

SOURCE = pathlib.Path(__file__).resolve().parents[1] / "bench_session.py"


def load_bench_session():
    spec = importlib.util.spec_from_file_location("bench_session", SOURCE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_python_against_cli_leaves_no_scratch_directory(tmp_path, monkeypatch, capsys):
    bench = load_bench_session()
    written = []

    def child(cmd):  # writes the image it is asked for, reports a render time
        out = cmd[cmd.index("-o") + 1] if "-o" in cmd else cmd[-1]
        pathlib.Path(out).write_bytes(b"image")
        written.append(out)
        return 0.5, "x.exr: 8x8, 1 spp in 0.250 s (...)\nrender 0.2500\n"

    monkeypatch.setattr(bench, "child", child)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    bench.python_against_cli("lucent", "scene.json", 1, 2)
    assert len(written) == 6  # a warm-up pair and two timed pairs
    assert all(pathlib.Path(w).is_relative_to(tmp_path) for w in written)
    assert list(tmp_path.iterdir()) == []
    assert "python / cli: render time 1.000" in capsys.readouterr().out

"""Session options and the kernel cache directory from Python: each test builds kernels of its own
(the full kernel with fast math and in double; a cache of its own), so they are an entry apart
from test_render.py (python.pytest.render took 16.8 s under the sanitizers with them)."""
import lucent
from conftest import session


def test_session_options_and_devices(small_scene):
    devices = lucent.list_devices()
    assert devices and all(isinstance(d, lucent.DeviceInfo) for d in devices)
    assert lucent.select_device("0").name == devices[0].name
    with session(device="0", fast_math=True, specialize=False) as r:
        assert r.device.name == devices[0].name
        assert r.options["fast_math"] and not r.options["specialize"]
        r.set_scene(small_scene)
        opts = r.result().build_options
        assert "-cl-fast-relaxed-math" in opts and "LC_HAS_CONDUCTOR" in opts
        # a setting not given stays (precision="float" alone turned fast math and the full
        # kernel off, and fast_math=True alone a double-precision session into a float one)
        r.set_build_options(precision="double")
        assert r.options["fast_math"] and not r.options["specialize"]
        r.set_build_options(fast_math=False)
        assert r.options["precision"] == "double" and not r.options["specialize"]
        r.set_build_options(precision="float")
        r.set_scene(small_scene)
        assert "-cl-fast-relaxed-math" not in r.result().build_options
        assert r.options == {**r.options, "precision": "float", "fast_math": False,
                             "specialize": False}
        assert r.scene.film.width == 16
    assert set(lucent.environment()) == {"device", "kernel_dir", "cache_dir"}


def test_kernel_cache_directory_is_an_option(tmp_path, small_scene, monkeypatch):
    # lucent's cache serves drivers without a cache of their own, not PoCL, even with its cache
    # off: PoCL gave programs made from one binary in two processes one directory, and one process
    # aborted when the other released its program (src/cl/program_cache.hpp)
    monkeypatch.setenv("POCL_KERNEL_CACHE", "0")
    with session(cache_dir=str(tmp_path)) as a:
        a.set_scene(small_scene)
        assert a.stats.kernel_compiles == 1
    device = lucent.select_device(lucent.environment()["device"])
    pocl = device.platform == "Portable Computing Language"
    with session(cache_dir=str(tmp_path)) as b:
        b.set_scene(small_scene)
        loads = (0, 1) if pocl else (1, 0)
        assert (b.stats.kernel_cache_loads, b.stats.kernel_compiles) == loads
    if pocl:  # an entry as another driver's session writes one, for what follows
        assert not list(tmp_path.glob("*.bin"))
        (tmp_path / "0123456789abcdef.bin").write_bytes(b"an entry")
    assert lucent.cache_dir(str(tmp_path)) == str(tmp_path)
    assert lucent.cache_dir("off") == ""
    # "" is the directory a Renderer() without cache_dir uses, whatever LUCENT_CACHE_DIR says
    # (it was that variable's: clear_cache() emptied another directory than the sessions')
    monkeypatch.setenv("LUCENT_CACHE_DIR", str(tmp_path / "env"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert lucent.cache_dir() == str(tmp_path / "xdg" / "lucent")
    assert lucent.cache_dir(lucent.environment()["cache_dir"]) == str(tmp_path / "env")
    info = lucent.cache_info(str(tmp_path))
    assert (info["directory"], info["programs"]) == (str(tmp_path), 1)
    assert info["bytes"] == sum(f.stat().st_size for f in tmp_path.glob("*.bin"))
    monkeypatch.setenv("LUCENT_CACHE_MAX_MB", "64")
    assert lucent.cache_info(str(tmp_path))["limit_bytes"] == 64 << 20
    assert lucent.clear_cache(str(tmp_path)) == 1
    assert lucent.cache_info(str(tmp_path))["programs"] == 0
    assert lucent.cache_info("off")["directory"] == ""

"""Pickling and copying: scenes, the values they hold and render results round-trip exactly (pickle
protocol 2, the highest protocol, copy.deepcopy, a multiprocessing worker), a round-tripped scene
renders the same image, and a corrupted state raises a ValueError naming the class and the key."""
import copy
import copyreg
import math
import multiprocessing
import pickle
import struct
import subprocess
import sys

import numpy as np
import pytest

import lucent
from conftest import header_fields, session

PROTOCOLS = [2, pickle.HIGHEST_PROTOCOL]
WORKER_WAIT = 120  # seconds: a bound on a worker's answer, never reached when the test passes


def pickled(obj, protocol):
    return pickle.loads(pickle.dumps(obj, protocol))


def round_trips():
    """(name, f): f(obj) returns a copy made through the pickled state."""
    return [(f"pickle-{p}", lambda o, p=p: pickled(o, p)) for p in PROTOCOLS] + [
        ("deepcopy", copy.deepcopy), ("copy", copy.copy)]


def same(a, b, path="state"):
    """a and b are equal to the bit: dicts (keys in order), lists, tuples, arrays (dtype, shape
    and bytes), floats (their bits: NaN and -0.0 included)."""
    assert type(a) is type(b), f"{path}: {type(a)} != {type(b)}"
    if isinstance(a, dict):
        assert list(a) == list(b), path
        for k in a:
            same(a[k], b[k], f"{path}/{k}")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            same(x, y, f"{path}/{i}")
    elif isinstance(a, np.ndarray):
        assert (a.dtype, a.shape) == (b.dtype, b.shape) and a.tobytes() == b.tobytes(), path
    elif isinstance(a, float):
        assert struct.pack("<d", a) == struct.pack("<d", b), f"{path}: {a!r} != {b!r}"
    else:
        assert a == b, f"{path}: {a!r} != {b!r}"


def texels(h, w, seed):
    """Random float32 texels with the values a lossy copy would change: NaN with a payload, -0.0,
    infinities, a subnormal, the largest float32."""
    rgba = np.random.default_rng(seed).random((h, w, 4), dtype=np.float32)
    special = np.array([np.nan, -0.0, np.inf, -np.inf, 1e-45, np.finfo(np.float32).max],
                       np.float32)
    special[0] = np.frombuffer(struct.pack("<I", 0x7FC01234), np.float32)[0]
    rgba.reshape(-1)[:special.size] = special
    return rgba


@pytest.fixture
def rich_scene(small_scene):
    """The small scene with every field away from its default: a thin lens, a gaussian filter,
    clamping, normals and uvs, a textured material, an emissive sphere, an environment map."""
    s = small_scene
    s.path = "rich/scene.json"
    s.camera.aperture, s.camera.roll_degrees, s.camera.focus_distance = 0.01, 2.5, 4.75
    s.film.filter.type, s.film.filter.radius = "gaussian", 1.25
    s.film.transfer, s.film.gamma, s.film.exposure, s.film.tonemap = "gamma", 2.4, -0.5, "aces"
    it = s.integrator
    it.seed, it.max_depth, it.rr_depth, it.spp = 4294967295, 5, 3, 2
    it.ao_distance, it.clamp, it.mis, it.caustics = 0.5, 40.0, False, True
    it.sampler, it.dielectric_splits = "independent", 1
    albedo = lucent.Texture()
    albedo.path = "albedo.png"
    albedo.rgba = np.clip(np.nan_to_num(texels(4, 5, 1), posinf=1, neginf=0), 0, 1)
    env = lucent.Texture()
    env.path = "sky.exr"
    env.rgba = texels(3, 6, 2)
    s.textures.append(albedo)
    s.textures.append(env)
    s.materials[0].albedo_texture = 0
    s.materials[0].albedo_wrap_v, s.materials[0].albedo_uv_scale = "mirror", (2, -0.5)
    s.materials[0].albedo_uv_offset = (0.25, 1 / 3)
    s.materials[1].type, s.materials[1].roughness, s.materials[1].ior = "conductor", 0.3, 1.7
    s.materials[1].specular = (0.9, 0.8, 0.1 + 1e-17)
    lamp = lucent.Material()
    lamp.name, lamp.emission = "lamp", (3, 2.5, 2)
    s.materials.append(lamp)
    s.spheres.append(lucent.Sphere((0.5, 1.5, -0.25), 1 / 3, material=2))
    s.normals = [[0, 1, 0], [0, 1, 0], [0, 1, 0], [0, 1, 0]]
    s.uvs = [[0, 0], [1, 0], [1, 1], [0, 1]]
    for t in s.triangles:
        t.n = t.v
        t.uv = t.v
    sky = lucent.Light()
    sky.type, sky.radiance, sky.texture = "environment_map", (0.5, 0.5, 0.5), 1
    s.lights.append(sky)
    s.shapes[1].file, s.shapes[1].libraries = "mesh.obj", ["lib/a.mtl", "b.mtl"]
    return s


def test_the_state_holds_every_field_of_the_structs(rich_scene):
    """The state's keys are the structs' fields, read from include/lucent/scene.hpp: a field
    added to a struct must be pickled too."""
    s = rich_scene
    state = s.__getstate__()
    assert list(state) == header_fields("scene.hpp", "Scene")
    for key, struct_name in [("camera", "Camera"), ("film", "Film"),
                             ("integrator", "Integrator")]:
        assert list(state[key]) == header_fields("scene.hpp", struct_name), key
    assert list(state["film"]["filter"]) == header_fields("scene.hpp", "Filter")
    for key, struct_name in [("materials", "Material"), ("lights", "Light"),
                             ("textures", "Texture"), ("shapes", "ShapeEntry")]:
        assert state[key] and all(list(e) == header_fields("scene.hpp", struct_name)
                                  for e in state[key]), key
    # spheres and triangles are columns, one array per field
    assert list(state["spheres"]) == header_fields("scene.hpp", "Sphere")
    assert list(state["triangles"]) == header_fields("scene.hpp", "Triangle")
    assert state["triangles"]["uv"].shape == (2, 3) and state["positions"].shape == (4, 3)


@pytest.mark.parametrize("name, round_trip", round_trips())
def test_a_scene_round_trips_exactly(rich_scene, name, round_trip):
    s = rich_scene
    before = s.__getstate__()
    c = round_trip(s)
    assert type(c) is lucent.Scene and c is not s
    same(before, c.__getstate__())
    same(before, s.__getstate__())  # the original is unchanged
    # the fields themselves, not only the states
    assert c.path == "rich/scene.json" and c.camera.roll_degrees == 2.5
    assert (c.film.filter.type, c.film.tonemap, c.integrator.seed) == ("gaussian", "aces",
                                                                       4294967295)
    assert c.integrator.caustics and not c.integrator.mis and c.integrator.sampler == "independent"
    assert c.materials[1].specular == (0.9, 0.8, 0.1 + 1e-17) and c.materials[2].emissive
    assert (c.materials[0].albedo_wrap_u, c.materials[0].albedo_wrap_v) == ("repeat", "mirror")
    assert c.materials[0].albedo_uv_scale == (2, -0.5)
    assert c.materials[0].albedo_uv_offset == (0.25, 1 / 3)
    assert c.spheres[1].radius == 1 / 3 and c.spheres[1].material == 2
    assert c.triangles[1].n == (0, 3, 2) and c.triangles[1].uv == (0, 3, 2)
    assert c.lights[1].type == "environment_map" and c.lights[1].texture == 1
    assert [e.type for e in c.shapes] == ["sphere", "triangles"]
    assert c.shapes[1].libraries == ["lib/a.mtl", "b.mtl"] and c.shapes[0].libraries == []
    assert np.array_equal(c.uvs, s.uvs) and np.array_equal(c.normals, s.normals)
    # texels to the bit (NaN payloads, -0.0, infinities, subnormals)
    for t, orig in zip(c.textures, s.textures):
        assert (t.width, t.height, t.path) == (orig.width, orig.height, orig.path)
        assert t.rgba.dtype == np.float32
        assert np.array_equal(t.rgba.view(np.uint32), orig.rgba.view(np.uint32))
    assert np.array_equal(c.textures[1].rgba.view(np.uint32), texels(3, 6, 2).view(np.uint32))
    # an independent copy
    c.materials[0].roughness = 0.9
    c.textures[0].rgba = np.zeros((1, 1, 4))
    assert s.materials[0].roughness == 0.1 and s.textures[0].width == 5


class TaggedScene(lucent.Scene):
    """A subclass with attributes of its own (module level: pickle names it)."""

    def __init__(self):
        super().__init__()
        self.notes = ["from the asset library"]


class TaggedCamera(lucent.Camera):
    pass


@pytest.mark.parametrize("name, round_trip", round_trips())
def test_a_subclass_keeps_its_class_and_attributes(name, round_trip):
    # copies and pickles of a Python subclass were of the base class (Scene's copy), or lost the
    # instance's attributes (every class's pickle)
    s = TaggedScene()
    s.film.width = 7
    c = round_trip(s)
    assert type(c) is TaggedScene and c.notes == ["from the asset library"] and c.film.width == 7
    assert (c.notes is s.notes) == (name == "copy")  # a shallow copy shares them
    cam = TaggedCamera()
    cam.fov_degrees = 12
    cam.label = "left"
    k = round_trip(cam)
    assert type(k) is TaggedCamera and k.label == "left" and k.fov_degrees == 12
    # attributes that refer back to the object refer to the copy (the attributes were restored
    # before the object was memoized: .me was lost, or a second copy; the third review's find)
    cam.me = cam
    s.me = s
    k, c = round_trip(cam), round_trip(s)
    if name == "copy":
        assert k.me is cam and c.me is s
    else:
        assert k.me is k and k.label == "left" and c.me is c and c.notes == s.notes
    # the base classes keep their form: copyreg's, the state alone
    assert pickle.loads(pickle.dumps(lucent.Camera())).__class__ is lucent.Camera
    assert lucent.Camera().__reduce_ex__(2)[0] is copyreg.__newobj__


@pytest.mark.parametrize("name, round_trip", round_trips())
def test_every_value_class_round_trips(rich_scene, name, round_trip):
    s = rich_scene
    values = [s.camera, s.film, s.film.filter, s.integrator, s.materials[1], s.spheres[1],
              s.triangles[1], s.lights[1], s.textures[1], s.shapes[1], lucent.Texture(),
              s.camera.position, lucent.Vec2((0.25, -1e300)), s.materials, s.spheres, s.triangles,
              s.lights, s.textures, s.shapes, lucent.Scene()]
    for v in values:
        c = round_trip(v)
        assert type(c) is type(v) and c is not v
        same(v.__getstate__(), c.__getstate__(), type(v).__name__)
    assert pickled(s.camera.position, 2) == (0, 1, 5)
    assert round_trip(lucent.Vec2((0.25, -1e300))) == (0.25, -1e300)
    assert [m.name for m in round_trip(s.materials)] == ["g", "w", "lamp"]
    assert round_trip(lucent.Texture()).rgba.shape == (0, 0, 4)


def test_a_round_tripped_scene_renders_the_same_image(rich_scene):
    """Bit-identical images at a fixed seed, each scene in a session of its own; the textures
    matter to the image (a zeroed one changes it), so their texels were carried over."""
    s = rich_scene
    s.integrator.caustics = False  # no light paths: a shorter render
    s.integrator.seed = 7
    s.textures[1].rgba = np.random.default_rng(3).random((3, 6, 4), dtype=np.float32)
    images = []
    changed = s.copy()
    changed.textures[0].rgba = np.zeros((4, 5, 4))
    for scene in (s, pickled(s, 2), pickled(s, pickle.HIGHEST_PROTOCOL), changed):
        with session(specialize=False) as r:
            r.set_scene(scene)
            r.render(2)
            result = r.result()
            assert result.nonfinite == 0 and result.spp == 2
            images.append(result.mean.copy())
    assert images[0].max() > 0
    assert images[1].tobytes() == images[0].tobytes()
    assert images[2].tobytes() == images[0].tobytes()
    assert images[3].tobytes() != images[0].tobytes()


def render_here(scene):
    """Renders `scene` in a session of its own (in a worker process, or here), with the full
    kernel: these tests are of the scene's round trip, and the full kernel is the program many
    tests share (a specialised one per scene cost CI a cold kernel build each)."""
    with session(specialize=False) as r:
        r.set_scene(scene)
        r.render(2)
        return r.result()


def test_a_worker_process_renders_a_scene_and_returns_its_result(rich_scene):
    """The scene goes to a spawned multiprocessing worker and its RenderResult comes back: the
    same image as a render here."""
    s = rich_scene
    s.integrator.caustics = False
    s.textures[1].rgba = np.random.default_rng(3).random((3, 6, 4), dtype=np.float32)
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        # a bound on the wait: a worker that cannot start leaves apply() waiting for ever
        there = pool.apply_async(render_here, (s,)).get(timeout=WORKER_WAIT)
    here = render_here(s)
    assert type(there) is lucent.RenderResult and (there.spp, there.width) == (2, 16)
    assert there.mean.tobytes() == here.mean.tobytes()
    assert np.array_equal(there.samples, here.samples)


def render_or_error(scene):
    try:
        return render_here(scene)
    except lucent.Error as e:
        return str(e)


def test_a_forked_worker_of_a_process_that_used_opencl_is_refused(small_scene):
    """A worker forked (Linux's default start method before Python 3.14) from a process that had
    used OpenCL (here: this test process's sessions) hung for ever in set_scene: the driver's
    threads do not survive a fork. Its first lucent call now raises lucent.Error saying so."""
    lucent.list_devices()  # (this process has used OpenCL)
    with multiprocessing.get_context("fork").Pool(1) as pool:
        there = pool.apply_async(render_or_error, (small_scene,)).get(timeout=WORKER_WAIT)
    assert isinstance(there, str) and there.startswith(
        "this process is a fork of one that had used OpenCL"), there
    assert 'multiprocessing.get_context("spawn")' in there


def test_setstate_on_an_object_that_exists_is_refused(rich_scene):
    # pybind11 skips a __setstate__ on an object its constructor made and returns None: the
    # scene stayed as it was without a word
    s, other = rich_scene, lucent.Scene()
    before = s.__getstate__()
    values = [(s, other), (lucent.Vec3((1, 2, 3)), lucent.Vec3((4, 5, 6))),
              (lucent.Camera(), s.camera), (lucent.RenderResult(np.zeros((1, 1, 3))),
                                            lucent.RenderResult(np.ones((2, 1, 3))))]
    for mine, theirs in values:
        name = type(mine).__name__
        with pytest.raises(TypeError, match=f"^{name}.__setstate__: this {name} exists already"):
            mine.__setstate__(theirs.__getstate__())
    same(before, s.__getstate__())
    # the object pickle makes is set, once
    fresh = lucent.Scene.__new__(lucent.Scene)
    fresh.__setstate__(before)
    same(before, fresh.__getstate__())
    with pytest.raises(TypeError, match="exists already"):
        fresh.__setstate__(other.__getstate__())
    # called on something else: the original's TypeError (read as an instance, it crashed)
    for stranger in (5, object(), lucent.Vec3((1, 2, 3))):
        with pytest.raises(TypeError) as e:
            lucent.Scene.__setstate__(stranger, before)
        assert "Vec3.__setstate__" not in str(e.value)


@pytest.mark.parametrize("name, round_trip", round_trips())
def test_a_render_result_round_trips_exactly(renderer, small_scene, name, round_trip):
    renderer.set_scene(small_scene)
    renderer.render(3)
    res = renderer.result()
    state = res.__getstate__()
    assert list(state) == header_fields("render.hpp", "RenderResult")
    c = round_trip(res)
    assert type(c) is lucent.RenderResult and c is not res
    same(state, c.__getstate__())
    assert c.mean.tobytes() == res.mean.tobytes() and c.variance.tobytes() == res.variance.tobytes()
    assert c.samples.dtype == np.uint32 and np.array_equal(c.samples, res.samples)
    assert (c.spp, c.rays, c.seconds, c.device, c.build_options, c.sampler) == (
        res.spp, res.rays, res.seconds, res.device, res.build_options, res.sampler)
    assert [(d.device, d.samples) for d in c.devices] == [(d.device, d.samples) for d in res.devices]
    assert lucent.compare(res, c).max_z == 0
    # a result made of arrays: no variance, no counts
    a = round_trip(lucent.RenderResult(np.full((2, 3, 3), 0.5), spp=7))
    assert a.variance is None and a.samples is None and a.spp == 7 and a.mean.shape == (2, 3, 3)


@pytest.mark.parametrize("name, round_trip", round_trips())
def test_a_caustics_result_keeps_its_light_mean_variance(renderer, small_dict, name, round_trip):
    """A render with caustics carries the image mean's light part (its variance from the light
    paths' totals, and its share of the variance layer), a render without none; both come back
    exactly, and compare() takes it from either."""
    small_dict["integrator"]["caustics"] = True
    small_dict["integrator"]["max_depth"] = 6
    small_dict["materials"]["w"] = {"type": "dielectric", "ior": 1.5}
    small_dict["lights"][0]["position"] = [0, 1.5, 0]  # over the glass sphere
    renderer.set_build_options(specialize=False)  # (the shared full kernel, as render_here)
    renderer.set_scene(lucent.scene_from_dict(small_dict))
    renderer.render(4)
    res = renderer.result()
    v = res.light_mean_variance
    assert list(v) == ["paths", "pixels"] and all(x > 0 for x in v["paths"] + v["pixels"])
    c = round_trip(res)
    assert c.light_mean_variance == v
    assert res.__getstate__()["light_mean_variance"] == v
    cmp = lucent.compare(res, c)
    assert cmp.light_paths_a and cmp.light_paths_b
    assert lucent.RenderResult(res.mean, res.variance, res.samples).light_mean_variance is None


@pytest.mark.parametrize("key, value, message", [
    ("mean", np.zeros((12, 16)), "/mean: expected a (N, N, 3) array of float32, got a (12, 16) "
                                 "array of float64"),
    ("variance", np.zeros((12, 15, 3), np.float32), "/variance: expected a (12, 16, 3) array"),
    ("samples", np.zeros((12, 16), np.int32), "/samples: expected a (12, 16) array of uint32, got "
                                              "a (12, 16) array of int32"),
    ("spp", -2, "/spp: integer out of range: -2"),
    ("spp", 2 ** 64, "/spp: integer out of range: 18446744073709551616"),
    ("devices", [{"device": "cpu"}], "/devices/0/samples: missing"),
    ("sampler", None, "/sampler: expected a str, got NoneType"),
    # a per-sample variance without the counts (the constructor refuses it too)
    ("samples", None, "/samples: a variance needs the per-pixel sample counts"),
    # the sizes of an image are 1 to the largest int (height -2**31 and 2 before)
    ("mean", np.empty((0, 0, 3), np.float32), "/mean: expected an (H, W, 3) image with 1 <= H, "
                                              "W <= 2147483647, got a (0, 0, 3) array"),
    ("mean", np.empty((2, 0, 3), np.float32), "/mean: expected an (H, W, 3) image with 1 <= H, "
                                              "W <= 2147483647, got a (2, 0, 3) array"),
    ("mean", np.empty((2 ** 31, 0, 3), np.float32), "got a (2147483648, 0, 3) array"),
    ("mean", np.empty((2 ** 32 + 2, 0, 3), np.float32), "got a (4294967298, 0, 3) array"),
    ("mean", np.empty((0, 2 ** 31, 3), np.float32), "got a (0, 2147483648, 3) array"),
    ("light_mean_variance", {"paths": (1.0, 2.0), "pixels": (0.0, 0.0, 0.0)},
     "/light_mean_variance/paths: expected a tuple of 3 finite numbers >= 0, got (1.0, 2.0)"),
    ("light_mean_variance", {"paths": (1.0, 2.0, 3.0), "pixels": (0.0, -1.0, 0.0)},
     "/light_mean_variance/pixels: expected a tuple of 3 finite numbers >= 0"),
    ("light_mean_variance", {"paths": (1.0, 2.0, 3.0)}, "/light_mean_variance/pixels: missing"),
    ("light_mean_variance", [1.0] * 6, "/light_mean_variance: expected a dict, got list"),
])
def test_a_corrupted_result_state_raises_value_error(renderer, small_scene, key, value, message):
    renderer.set_scene(small_scene)
    renderer.render(1)
    state = renderer.result().__getstate__()
    state[key] = value
    with pytest.raises(ValueError) as e:
        restore(lucent.RenderResult, state)
    assert str(e.value).startswith("cannot unpickle lucent.RenderResult: ")
    assert message in str(e.value)
    state = renderer.result().__getstate__()
    state["spp"] = 2 ** 64 - 1  # the largest uint64 is a count like the others
    assert restore(lucent.RenderResult, state).spp == 2 ** 64 - 1


@pytest.mark.parametrize("shape", [(0, 0, 3), (1, 0, 3), (0, 1, 3), (2 ** 31, 0, 3),
                                   (2 ** 32 + 2, 0, 3), (0, 2 ** 31, 3)])
def test_a_result_state_with_an_empty_or_huge_image_raises_value_error(shape):
    """An image has 1 to 2**31 - 1 rows and columns, as the constructor requires: a state of an
    array-made result (no variance, no counts) with an empty image was accepted, its sizes cast
    to int (a height of -2**31, or 2 for 2**32 + 2)."""
    state = lucent.RenderResult(np.zeros((2, 3, 3), np.float32)).__getstate__()
    assert state["variance"] is None and state["samples"] is None
    state["mean"] = np.empty(shape, np.float32)
    with pytest.raises(ValueError) as e:
        restore(lucent.RenderResult, state)
    assert str(e.value) == (
        "cannot unpickle lucent.RenderResult: /mean: expected an (H, W, 3) image with 1 <= H, W <= "
        f"2147483647, got a ({shape[0]}, {shape[1]}, 3) array")
    with pytest.raises(ValueError, match=r"expected an array of shape \(H, W, 3\)"):
        lucent.RenderResult(np.empty(shape, np.float32))


# Run in a child process: pickling with protocol 0 or 1 aborted the interpreter. Reads a list of
# values (pickled with the highest protocol) and writes back their pickles with protocols 0 and 1
# and the errors of values that do not pickle.
LISTS = ["ShapeList", "MaterialList", "SphereList", "TriangleList", "LightList", "TextureList"]
OLD_PROTOCOLS = f"LISTS = {LISTS!r}" + """
import pickle, sys
import numpy as np
import lucent
values = pickle.load(sys.stdin.buffer)
refused, reduced = [], []
scene = lucent.Scene()
scene.materials.append(lucent.Material())
# the iterators of the bound lists: pybind11 classes outside the module (pybind11_builtins)
iterators = [iter(scene.materials)] + [iter(getattr(lucent, name)()) for name in LISTS]
with lucent.Renderer(**lucent.environment()) as r:
    for obj in (r, lucent.compare(np.zeros((1, 1, 3)), np.zeros((1, 1, 3))), r.device, *iterators):
        for protocol in (0, 1):
            try:
                pickle.dumps(obj, protocol)
                refused.append("pickled")
            except TypeError as e:
                refused.append(str(e))
        try:  # obj.__reduce__(), called by hand, took the same path (object's)
            obj.__reduce__()
            reduced.append("reduced")
        except TypeError as e:
            reduced.append(str(e))
pickles = [[pickle.dumps(v, protocol) for protocol in (0, 1)] for v in values]
states = [v.__reduce__()[2] for v in values]
pickle.dump((pickles, refused, reduced, states), sys.stdout.buffer, 2)
"""


def test_protocols_0_and_1_pickle_or_refuse_and_never_abort(rich_scene):
    """Protocols 0 and 1 went through copyreg._reduce_ex, which calls pybind11's base type: an
    uncaught C++ exception, and the interpreter aborted ("instance allocation failed"), even for
    classes that do not pickle, and for the iterators of the bound lists."""
    s = rich_scene
    values = [s, s.camera, s.textures, lucent.Vec2((1, 2)), lucent.RenderResult(np.ones((2, 2, 3)))]
    child = subprocess.run([sys.executable, "-c", OLD_PROTOCOLS], capture_output=True,
                           input=pickle.dumps(values, pickle.HIGHEST_PROTOCOL), timeout=WORKER_WAIT)
    assert child.returncode == 0, child.stderr.decode()
    pickles, refused, reduced, states = pickle.loads(child.stdout)
    for v, by_protocol, state in zip(values, pickles, states):
        for data in by_protocol:
            same(v.__getstate__(), pickle.loads(data).__getstate__(), type(v).__name__)
        same(v.__getstate__(), state, type(v).__name__)
    assert reduced == refused[::2], (reduced, refused)
    renderer_refused = [r for r in refused[:2] if r.startswith("cannot pickle or copy a lucent.")]
    assert len(renderer_refused) == 2, refused
    assert refused[2:] == ["cannot pickle 'lucent.CompareResult' object"] * 2 + [
        "cannot pickle 'lucent.DeviceInfo' object"] * 2 + [
        "cannot pickle 'iterator' object"] * 2 * (1 + len(LISTS))
    # protocol 2 and above refuse them the same way
    for name in LISTS:
        with pytest.raises(TypeError, match="cannot pickle 'iterator' object"):
            pickle.dumps(iter(getattr(lucent, name)()), pickle.HIGHEST_PROTOCOL)


def restore(cls, state):
    """What unpickling does with `state`: a new object of cls given it by __setstate__."""
    obj = cls.__new__(cls)
    obj.__setstate__(state)
    return obj


def corrupt(state, path, value):
    """`state` with the item at `path` ("a/0/b") replaced by `value` (deleted when None)."""
    state = copy.deepcopy(state)
    *parents, last = path.split("/")
    d = state
    for k in parents:
        d = d[int(k)] if isinstance(d, list) else d[k]
    if value is None:
        del d[last]
    else:
        d[last] = value
    return state


@pytest.mark.parametrize("path, value, message", [
    ("camera", None, "lucent.Scene: /camera: missing"),
    ("camera/up", None, "lucent.Scene: /camera/up: missing"),
    ("colour", 1, "lucent.Scene: unknown key 'colour'"),
    ("camera/fov_degrees", "45", "lucent.Scene: /camera/fov_degrees: expected a number, got str"),
    ("camera/position", (1, 2), "/camera/position: expected a sequence of 3 numbers, got (1, 2)"),
    ("camera/aperture", 10 ** 400, "/camera/aperture: number out of range: 1000000"),
    ("film/width", 2.5, "/film/width: expected an integer, got float"),
    ("film/width", 2 ** 40, "/film/width: integer out of range: 1099511627776"),
    ("film/filter", [], "lucent.Scene: /film/filter: expected a dict, got list"),
    ("film/filter/type", "lanczos", "/film/filter/type: unknown filter type 'lanczos'"),
    ("integrator/seed", -1, "/integrator/seed: integer out of range: -1"),
    ("integrator/mis", 1, "/integrator/mis: expected a bool, got int"),
    ("materials", {}, "lucent.Scene: /materials: expected a list, got dict"),
    ("materials/1/type", "gold", "/materials/1/type: unknown material type 'gold'"),
    ("materials/0/name", None, "lucent.Scene: /materials/0/name: missing"),
    ("spheres/radius", np.zeros(3), "/spheres/radius: expected a (2,) array of float64, got a "
                                    "(3,) array of float64"),
    ("spheres/material", np.zeros(2), "/spheres/material: expected a (2,) array of int32, got a "
                                      "(2,) array of float64"),
    ("positions", [[0, 0, 0]], "/positions: expected a (N, 3) array of float64, got list"),
    ("uvs", np.zeros((4, 3)), "/uvs: expected a (N, 2) array of float64, got a (4, 3) array"),
    ("triangles/n", np.zeros((1, 3), np.int32), "/triangles/n: expected a (2, 3) array of int32"),
    ("triangles/v", None, "lucent.Scene: /triangles/v: missing"),
    ("textures/1/width", 7, "/textures/1/rgba: expected a (3, 7, 4) array of float32, got a "
                            "(3, 6, 4) array of float32"),
    ("textures/1/height", 0, "/textures/1/width: a texture of 6 x 0 texels"),
    ("textures/0/rgba", np.zeros((4, 5, 4)), "/textures/0/rgba: expected a (4, 5, 4) array of "
                                             "float32, got a (4, 5, 4) array of float64"),
    ("shapes/0/count", -1, "/shapes/0/count: integer out of range: -1"),
    ("shapes/1/libraries", "a.mtl", "/shapes/1/libraries: expected a list, got str"),
    ("shapes/1/libraries", ["a.mtl", 2], "/shapes/1/libraries/1: expected a str, got int"),
    # a lone surrogate is a str without UTF-8: pybind11's cast raised a RuntimeError
    ("path", "rich/\ud800.json", "/path: a str that is not valid Unicode (a lone surrogate)"),
    ("shapes/1/libraries", ["\ud800.mtl"],
     "/shapes/1/libraries/0: a str that is not valid Unicode (a lone surrogate)"),
    ("x\ud800", 1, "lucent.Scene: unknown key 'x\\ud800'"),
    ("lights/1/texture", True, "/lights/1/texture: expected an integer, got bool"),
])
def test_a_corrupted_scene_state_raises_value_error(rich_scene, path, value, message):
    state = corrupt(rich_scene.__getstate__(), path, value)
    with pytest.raises(ValueError) as e:
        restore(lucent.Scene, state)
    assert str(e.value).startswith("cannot unpickle lucent.Scene") and message in str(e.value)


@pytest.mark.parametrize("cls, state, message", [
    (lucent.Scene, None, "cannot unpickle lucent.Scene: expected a dict, got NoneType"),
    (lucent.Camera, {}, "cannot unpickle lucent.Camera: /position: missing"),
    (lucent.Material, {"name": "m"}, "cannot unpickle lucent.Material: /type: missing"),
    (lucent.Triangle, {"v": (0, 1), "n": (0, 0, 0), "uv": (0, 0, 0), "material": 0},
     "cannot unpickle lucent.Triangle: /v: expected a tuple of 3 integers, got (0, 1)"),
    (lucent.Texture, {"path": "", "width": 1, "height": 1, "rgba": b"\0" * 16},
     "cannot unpickle lucent.Texture: /rgba: expected a (1, 1, 4) array of float32, got bytes"),
    (lucent.Vec3, [1, 2, 3], "cannot unpickle lucent.Vec3: expected a tuple, got [1, 2, 3]"),
    (lucent.Vec2, (1, 2, 3), "cannot unpickle lucent.Vec2: expected a sequence of 2 numbers"),
    (lucent.MaterialList, [{}], "cannot unpickle lucent.MaterialList: /0/name: missing"),
    (lucent.SphereList, (), "cannot unpickle lucent.SphereList: expected a list, got tuple"),
])
def test_a_corrupted_value_state_raises_value_error(cls, state, message):
    with pytest.raises(ValueError) as e:
        restore(cls, state)
    assert message in str(e.value)


def test_a_corrupted_pickle_raises_not_crashes(rich_scene):
    data = pickle.dumps(rich_scene, pickle.HIGHEST_PROTOCOL)
    with pytest.raises(Exception):
        pickle.loads(data[:len(data) // 2])
    # a state that unpickles is a state like the others: the scene's numbers, unchecked
    state = rich_scene.__getstate__()
    state["camera"]["fov_degrees"] = math.inf
    state["triangles"]["v"] = np.full((2, 3), 99, np.int32)
    s = restore(lucent.Scene, state)
    assert s.camera.fov_degrees == math.inf and s.triangles[0].v == (99, 99, 99)
    with pytest.raises(lucent.Error, match="fov"):
        lucent.scene_info(s)  # a render validates it, as a scene changed field by field


def test_a_renderer_refuses_pickling_and_copying(renderer, small_scene):
    """A session lives on its device: pickling or copying it raises a TypeError that says so and
    what to send instead (before: "cannot pickle 'lucent.Renderer' object", no more)."""
    renderer.set_scene(small_scene)
    refused = r"^cannot pickle or copy a lucent\.Renderer: it is a session on a device .*pickle " \
              r"its scene and result\(\) instead"
    for attempt in (lambda: pickle.dumps(renderer, 2),
                    lambda: pickle.dumps({"session": renderer}, pickle.HIGHEST_PROTOCOL),
                    lambda: copy.copy(renderer), lambda: copy.deepcopy([renderer])):
        with pytest.raises(TypeError, match=refused):
            attempt()
    renderer.render(1)  # the session is untouched
    assert renderer.spp == 1
    # what the message suggests works
    scene, result = pickled(renderer.scene, 2), pickled(renderer.result(), 2)
    assert scene.film.width == 16 and result.spp == 1

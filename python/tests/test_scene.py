"""Scenes from Python: files and dicts through the one parser, every struct field readable and
writable, enums by their registry names, and every error of the scene API."""
import json
import math
import os
import pickle
import re
import subprocess
import warnings

import numpy as np
import pytest

import lucent
from conftest import SMALL, SOURCE_DIR, header_fields


def test_dict_and_file_give_the_same_scene(tmp_path, small_scene):
    path = tmp_path / "small.json"
    path.write_text(json.dumps(SMALL))
    from_file = lucent.load_scene(path)  # os.PathLike accepted
    for s in (from_file, small_scene):
        assert (s.film.width, s.film.height) == (16, 12)
        assert s.camera.position == (0, 1, 5)
        assert s.camera.fov_degrees == 40
        assert sorted(m.name for m in s.materials) == ["g", "w"]
        assert s.materials[s.find_material("w")].albedo == (0.7, 0.6, 0.5)
        assert len(s.spheres) == 1 and len(s.triangles) == 2
        assert [(e.type, e.first, e.count) for e in s.shapes] == [("sphere", 0, 1),
                                                                  ("triangles", 0, 2)]
        assert s.positions.shape == (4, 3)
        assert s.lights[0].type == "point" and s.lights[0].intensity == (20, 20, 20)
    assert from_file.path == str(path)
    assert small_scene.path.endswith("<dict>")


def test_registry_names():
    assert lucent.MATERIAL_TYPES[:3] == ("diffuse", "mirror", "dielectric")
    assert "rough_dielectric" in lucent.MATERIAL_TYPES
    assert lucent.INTEGRATORS == ("path", "whitted", "direct", "albedo", "normal", "depth", "ao",
                                  "primitive")
    assert lucent.FILTER_TYPES == ("box", "tent", "gaussian")
    assert lucent.SAMPLERS == ("sobol", "independent")
    assert lucent.LIGHT_TYPES[0] == "point" and "environment_map" in lucent.LIGHT_TYPES
    assert lucent.TRANSFERS == ("srgb", "gamma", "linear")
    assert lucent.TONEMAPS == ("clamp", "reinhard", "aces")
    assert lucent.TEXTURE_WRAPS == ("repeat", "clamp", "mirror")
    # the registry header is the source of the names: every scene-file name of it is exposed
    registry = (SOURCE_DIR / "kernels" / "shared" / "registry.h").read_text()
    for name in re.findall(r'X\(\w+, \w+, \d+, "(\w+)"', registry):
        assert name in (lucent.MATERIAL_TYPES + lucent.LIGHT_TYPES + lucent.INTEGRATORS +
                        lucent.FILTER_TYPES + lucent.SAMPLERS + ("sphere", "triangles")), name


@pytest.mark.parametrize("cls, header, struct", [
    (lucent.Camera, "scene.hpp", "Camera"), (lucent.Filter, "scene.hpp", "Filter"),
    (lucent.Film, "scene.hpp", "Film"), (lucent.Integrator, "scene.hpp", "Integrator"),
    (lucent.Material, "scene.hpp", "Material"), (lucent.Sphere, "scene.hpp", "Sphere"),
    (lucent.Triangle, "scene.hpp", "Triangle"), (lucent.Light, "scene.hpp", "Light"),
    (lucent.Texture, "scene.hpp", "Texture"), (lucent.Scene, "scene.hpp", "Scene"),
    (lucent.ShapeEntry, "scene.hpp", "ShapeEntry"),
])
def test_every_field_of_the_scene_structs_is_exposed(cls, header, struct):
    fields = header_fields(header, struct)
    assert fields, struct
    for f in fields:
        assert hasattr(cls(), f), f"{struct}.{f} is not exposed"


def test_fields_are_writable_in_place(small_scene):
    s = small_scene
    s.camera.position.x += 1
    s.camera.look_at = [0, 0, 0]
    s.camera.up = np.array([0, 0, 1.0])
    s.camera.aperture = 0.1
    assert s.camera.position == (1, 1, 5) and s.camera.up == (0, 0, 1)
    s.film.width = 8
    s.film.filter.type = "gaussian"
    s.film.filter.radius = 2
    s.film.transfer = "linear"
    s.film.tonemap = "aces"
    s.integrator.type = "albedo"
    s.integrator.seed = 7
    s.materials[0].type = "rough_dielectric"
    s.materials[0].roughness = 0.3
    s.spheres[0].radius = 2
    s.triangles[0].v = (0, 1, 2)
    s.lights[0].position[1] = 10
    assert (s.film.width, s.film.filter.type, s.film.filter.radius) == (8, "gaussian", 2)
    assert (s.film.transfer, s.film.tonemap) == ("linear", "aces")
    assert (s.integrator.type, s.integrator.seed) == ("albedo", 7)
    assert (s.materials[0].type, s.materials[0].roughness) == ("rough_dielectric", 0.3)
    assert s.spheres[0].radius == 2 and s.triangles[0].v == (0, 1, 2)
    assert s.lights[0].position == (2, 10, 3)
    assert list(s.camera.position) == [1, 1, 5] and np.asarray(s.camera.position).shape == (3,)


def test_lists_grow_and_copies_are_independent(small_scene):
    s = small_scene
    copy = s.copy()
    m = lucent.Material()
    m.name = "lamp"
    m.emission = (4, 4, 4)
    s.materials.append(m)
    s.spheres.append(lucent.Sphere((0, 2, 0), 0.25, material=2))
    assert s.find_material("lamp") == 2 and s.materials[2].emissive
    assert len(copy.materials) == 2 and len(copy.spheres) == 1
    s.positions = s.positions + [0, 1, 0]
    assert s.positions[0, 1] == 1 and copy.positions[0, 1] == 0
    with pytest.raises(ValueError):
        s.positions[0, 0] = 5  # a read-only copy: assign the attribute instead


def albedo_of_a_sphere(renderer, m):
    """A scene built in code, a sphere of material m filling the centre of the albedo AOV: the
    scene and the AOV's centre pixel."""
    s = lucent.Scene()
    s.film.width, s.film.height = 8, 8
    s.camera.position = (0, 0, 4)
    s.camera.look_at = (0, 0, 0)
    s.materials.append(m)
    s.spheres.append(lucent.Sphere((0, 0, 0), 1.5))
    s.integrator.type = "albedo"
    renderer.set_scene(s)
    renderer.render(1)
    return s, renderer.result().mean[4, 4]


def test_scene_built_in_code_renders(renderer):
    m = lucent.Material()
    m.albedo = (0.5, 0.25, 1.0)
    # the albedo AOV of a sphere filling the centre is the material's albedo
    _, centre = albedo_of_a_sphere(renderer, m)
    assert centre == pytest.approx([0.5, 0.25, 1.0], rel=1e-6)


def test_texture_mapping_from_python(renderer):
    """A material's texture mapping (the scene format's "wrap", "uv_scale", "uv_offset"): a 1x2
    texture, red over blue, on a sphere whose front (v = 0.5) reads v + 0.5 = 1: the top edge,
    red when clamped, and half red, half blue repeating (the edge's texels mix with the bottom
    row's)."""
    m = lucent.Material()
    assert (m.albedo_wrap_u, m.albedo_wrap_v) == ("repeat", "repeat")
    assert m.albedo_uv_scale == (1, 1) and m.albedo_uv_offset == (0, 0)
    m.albedo = (1, 1, 1)
    m.albedo_texture = 0
    m.albedo_uv_offset = (0, 0.5)
    s = lucent.Scene()
    s.film.width, s.film.height = 8, 8
    s.camera.position = (0, 0, 4)
    s.camera.look_at = (0, 0, 0)
    t = lucent.Texture()
    t.rgba = np.array([[[1, 0, 0, 1]], [[0, 0, 1, 1]]], np.float32)
    s.textures.append(t)
    s.materials.append(m)
    s.spheres.append(lucent.Sphere((0, 0, 0), 1.5))
    s.integrator.type = "albedo"

    def centre():
        renderer.set_scene(s)
        renderer.render(1)
        return renderer.result().mean[4, 4]

    assert centre()[2] > 0.2  # repeating: the bottom row's blue
    s.materials[0].albedo_wrap_v = "clamp"
    assert s.materials[0].albedo_wrap_v == "clamp"
    assert centre() == pytest.approx([1, 0, 0], abs=1e-5)
    with pytest.raises(ValueError, match="wrap"):
        s.materials[0].albedo_wrap_u = "border"
    s.materials[0].albedo_uv_scale = (0, 1)
    with pytest.raises(lucent.Error, match=r"/materials/0/albedo/uv_scale/0: must be between "):
        renderer.set_scene(s)


def test_diffuse_mirror_from_python(renderer, small_dict):
    renderer.set_build_options(specialize=False)  # the full kernel, which other tests build too
    # reflectance is Material.specular, as for mirror; the albedo AOV is albedo + reflectance
    m = lucent.Material()
    m.type = "diffuse_mirror"
    m.albedo = (0.1, 0.5, 0.9)
    m.specular = (0.9, 0.25, 0.0)
    s, centre = albedo_of_a_sphere(renderer, m)
    assert centre == pytest.approx([1.0, 0.75, 0.9], rel=1e-6)
    # more than it receives, in a channel: refused with the JSON path, from code and from a dict
    m.specular = (0.9, 0.6, 0.0)
    s.materials[0] = m
    with pytest.raises(lucent.Error, match=r"/materials/0/reflectance/1: albedo \+ reflectance "
                                           r"must be <= 1 in each channel .* = 1\.1 in green"):
        renderer.set_scene(s)
    small_dict["materials"]["w"] = {"type": "diffuse_mirror", "albedo": [0.5, 0.5, 0.5],
                                    "reflectance": [0.5, 0.5, 0.75]}
    with pytest.raises(lucent.Error) as e:
        lucent.scene_from_dict(small_dict)
    assert one_line(e).startswith("./<dict>: /materials/w/reflectance/2: albedo + reflectance "
                                  "must be <= 1 in each channel")


def test_texture_from_an_array(small_scene):
    t = lucent.Texture()
    t.rgba = np.ones((2, 3, 4), np.float32) * [0.1, 0.2, 0.3, 1]
    assert (t.width, t.height) == (3, 2) and t.rgba.shape == (2, 3, 4)
    small_scene.textures.append(t)
    small_scene.materials[0].albedo_texture = 0
    assert small_scene.textures[0].rgba[1, 2, 1] == pytest.approx(0.2)


def test_relative_files_are_relative_to_base_dir(tmp_path):
    (tmp_path / "tri.obj").write_text("mtllib tri.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    (tmp_path / "tri.mtl").write_text("newmtl a\nKd 0.5 0.5 0.5\n")
    d = {"shapes": [{"type": "mesh", "file": "tri.obj"}]}
    s = lucent.scene_from_dict(d, base_dir=tmp_path)
    assert len(s.triangles) == 1
    # the MTL library the OBJ read, relative to the OBJ file (an input of the scene)
    assert list(s.shapes[0].libraries) == [str(tmp_path / "tri.mtl")]
    with pytest.raises(lucent.Error, match=r"tri\.obj"):
        lucent.scene_from_dict(d)  # "." holds no tri.obj


def test_loader_warnings_go_to_the_callback_or_to_warnings(tmp_path):
    (tmp_path / "m.obj").write_text("mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    d = {"shapes": [{"type": "mesh", "file": "m.obj"}]}
    got = []
    lucent.scene_from_dict(d, base_dir=tmp_path, on_warning=got.append)
    assert len(got) == 1 and "missing.mtl" in got[0]
    with pytest.warns(lucent.LucentWarning, match="missing.mtl"):
        lucent.scene_from_dict(d, base_dir=tmp_path)

    def fail(message):
        raise KeyError("from the callback")
    with pytest.raises(KeyError, match="from the callback"):
        lucent.scene_from_dict(d, base_dir=tmp_path, on_warning=fail)


# --- errors -------------------------------------------------------------------------------

def one_line(e):
    text = str(e.value)
    assert "\n" not in text
    return text


def test_parser_errors_are_lucent_errors_with_the_json_path(small_dict):
    assert issubclass(lucent.Error, RuntimeError)
    small_dict["shapes"][0]["radius"] = -1
    with pytest.raises(lucent.Error) as e:
        lucent.scene_from_dict(small_dict)
    assert one_line(e) == "./<dict>: /shapes/0/radius: must be > 0, got -1"
    with pytest.raises(lucent.Error, match=r"^x/scene\.json: /camera/fvo: unknown key"):
        lucent.scene_from_dict({"camera": {"fvo": 3}}, base_dir="x", name="scene.json")
    with pytest.raises(lucent.Error, match="unknown material 'nope'"):
        lucent.scene_from_dict({"shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1,
                                           "material": "nope"}]})


@pytest.mark.parametrize("value, message", [
    (math.nan, "/camera/fov: must be a finite number, got nan"),
    (math.inf, "/camera/fov: must be a finite number, got inf"),
    # an int beyond 64 bits is the float its JSON text would be: the value's own range error
    (2 ** 70, "/camera/fov: must be in (0, 180) degrees, got 1.1805916207174113e+21"),
    (10 ** 400, "/camera/fov: integer out of range (not a finite double): an integer of about "
                "401 digits"),
    (object(), "/camera/fov: cannot be written as JSON"),
])
def test_dict_values_json_cannot_hold(value, message):
    with pytest.raises(lucent.Error, match=re.escape(message)):
        lucent.scene_from_dict({"camera": {"fov": value}})


def test_an_integer_too_long_to_print_is_named_by_its_digits():
    # past sys.get_int_max_str_digits (4300): str() raised its own ValueError, naming no place
    with pytest.raises(lucent.Error, match=re.escape(
            "/camera/fov: integer out of range (not a finite double): an integer of about 5001 "
            "digits")):
        lucent.scene_from_dict({"camera": {"fov": 10 ** 5000}})


def test_dict_paths_escape_slash_and_tilde_in_keys():
    # JSON pointers (RFC 6901): '~' as ~0, '/' as ~1; the key "a/b" was written as two levels
    with pytest.raises(lucent.Error) as e:
        lucent.scene_from_dict({"materials": {"a/b~": {"type": object()}}})
    assert one_line(e).startswith("./<dict>: /materials/a~1b~0/type: cannot be written as JSON")
    with pytest.raises(lucent.Error) as e:
        lucent.scene_from_dict({"materials": {"a/b": {"type": "dielectric", "ior": 0}}})
    assert one_line(e).startswith("./<dict>: /materials/a~1b/ior: must be in [")


def test_dict_keys_must_be_strings():
    with pytest.raises(lucent.Error, match="keys must be strings"):
        lucent.scene_from_dict({"camera": {1: 2}})
    with pytest.raises(TypeError):
        lucent.scene_from_dict([1, 2])


def test_dict_strings_with_a_lone_surrogate_are_errors_with_the_json_path(small_dict):
    # JSON text is UTF-8; a name from os.listdir ("w\udce8") raised "RuntimeError: Unable to
    # cast Python instance to C++ type"
    small_dict["shapes"][0]["material"] = "w\udce8"
    with pytest.raises(lucent.Error) as e:
        lucent.scene_from_dict(small_dict)
    assert str(e.value) == ("./<dict>: /shapes/0/material: a str that is not valid Unicode (a "
                            "lone surrogate): 'w\\udce8'")
    with pytest.raises(lucent.Error, match=r"^./<dict>: /materials: a key that is not valid "
                                           r"Unicode \(a lone surrogate\): 'g\\ud800'$"):
        lucent.scene_from_dict({"materials": {"g\ud800": {"type": "diffuse"}}})
    # the name is a file name for messages: any bytes
    with pytest.raises(lucent.Error, match=r"^./sc\\xe8ne\.json: /camera/fvo: unknown key"):
        lucent.scene_from_dict({"camera": {"fvo": 3}}, name="sc\udce8ne.json")


def test_numpy_values_in_dicts(small_dict):
    small_dict["camera"]["position"] = np.array([0.0, 1, 5])
    small_dict["film"]["width"] = np.int64(16)
    assert lucent.scene_from_dict(small_dict).camera.position == (0, 1, 5)


def test_load_scene_errors(tmp_path):
    with pytest.raises(lucent.Error, match="cannot open scene file"):
        lucent.load_scene(tmp_path / "none.json")
    with pytest.raises(lucent.Error, match="is a directory"):
        lucent.load_scene(tmp_path)
    bad = tmp_path / "bad.json"
    bad.write_text('{"film": {"width": 0}}')
    with pytest.raises(lucent.Error, match=r"bad\.json: /film/width"):
        lucent.load_scene(bad)
    with pytest.raises(TypeError):
        lucent.load_scene(3)


def test_error_messages_keep_bytes_that_are_not_utf8(tmp_path):
    # a file name from os.listdir may hold any byte (surrogateescape): the message is not lost
    with pytest.raises(lucent.Error) as e:
        lucent.load_scene(os.path.join(str(tmp_path), "sc\udce8ne.json"))
    assert str(e.value).endswith("sc\\xe8ne.json: cannot open scene file (No such file or directory)")
    assert e.value.args == (str(e.value),)


def test_text_from_files_that_is_not_utf8_reads_back_as_os_fsdecode_gives_it(tmp_path):
    # a Latin-1 file name and material name: they loaded, then every read raised
    # UnicodeDecodeError (scene.path, the names, repr, pickle)
    d = os.fsencode(tmp_path)
    (tmp_path / "m.mtl").write_bytes(b"newmtl caf\xe9\nKd 0.8 0.2 0.2\n")
    (tmp_path / "m.obj").write_bytes(b"mtllib m.mtl\nmtllib gon\xe9.mtl\nv -1 0 -1\nv 1 0 -1\n"
                                     b"v 0 0 1\nusemtl caf\xe9\nf 1 2 3\n")
    scene = dict(SMALL, shapes=[{"type": "mesh", "file": "m.obj"}], materials={})
    with open(os.path.join(d, b"sc\xe8ne.json"), "w") as f:
        json.dump(scene, f)
    name, = [n for n in os.listdir(tmp_path) if n.endswith(".json")]
    assert name == "sc\udce8ne.json"
    warnings = []
    s = lucent.load_scene(os.path.join(str(tmp_path), name), on_warning=warnings.append)
    assert s.path == os.path.join(str(tmp_path), name)
    assert os.fsencode(s.path) == os.path.join(d, b"sc\xe8ne.json")
    assert [m.name for m in s.materials] == ["m.obj:caf\udce9"]
    assert s.find_material("m.obj:caf\udce9") == 0
    assert s.shapes[0].file == os.path.join(str(tmp_path), "m.obj")
    assert s.shapes[0].libraries == [os.path.join(str(tmp_path), "m.mtl")]
    assert any("gon\\xe9.mtl" in w for w in warnings), warnings  # a message: backslashreplace
    assert "sc\\udce8ne.json" in repr(s)
    assert repr(s.materials[0]) == "<lucent.Material 'm.obj:caf\\udce9' diffuse>"
    # assigned text keeps its bytes too (str with surrogateescape, or bytes)
    s.materials[0].name = "x\udcff"
    assert s.materials[0].name == "x\udcff"
    s.materials[0].name = b"y\xfe"
    assert s.materials[0].name == "y\udcfe"
    s.shapes[0].libraries = ["a\udce4.mtl", b"b\xe4.mtl"]
    assert s.shapes[0].libraries == ["a\udce4.mtl", "b\udce4.mtl"]
    t = lucent.Texture()
    t.path = "t\udce9.png"
    t.rgba = np.ones((1, 1, 4))
    s.textures.append(t)
    with pytest.raises(TypeError):
        s.materials[0].name = "z\ud800"  # a lone surrogate that no byte gives
    # pickle keeps the bytes: to the bit
    data = pickle.dumps(s)
    back = pickle.loads(data)
    assert pickle.dumps(back) == data
    assert (back.path, back.materials[0].name, back.textures[0].path, back.shapes[0].libraries) == \
        (s.path, "y\udcfe", "t\udce9.png", ["a\udce4.mtl", "b\udce4.mtl"])
    assert lucent.scene_info(back)["triangles"] == 1


def test_bad_field_values():
    m = lucent.Material()
    with pytest.raises(ValueError,
                       match=r"unknown material type 'gold' \(expected one of diffuse, "):
        m.type = "gold"
    with pytest.raises(ValueError, match="unknown integrator 'bdpt'"):
        lucent.Integrator().type = "bdpt"
    with pytest.raises(ValueError, match="unknown filter type"):
        lucent.Filter().type = "lanczos"
    with pytest.raises(ValueError, match="unknown transfer"):
        lucent.Film().transfer = "pq"
    with pytest.raises(ValueError, match="unknown tone map"):
        lucent.Film().tonemap = "filmic"
    with pytest.raises(ValueError, match="unknown light type"):
        lucent.Light().type = "spot"
    with pytest.raises(ValueError, match="expected a sequence of 3 numbers"):
        m.albedo = (1, 2)
    with pytest.raises(ValueError, match="expected a sequence of 3 numbers"):
        m.albedo = "abc"
    with pytest.raises(TypeError):
        m.albedo = 0.5
    with pytest.raises(TypeError):
        m.albedo = ("a", "b", "c")
    # bytes are a sequence of integers: b"abc" was the albedo (97, 98, 99)
    for raw in (b"abc", bytearray(b"abc"), memoryview(b"abc")):
        with pytest.raises(TypeError, match="expected a sequence of 3 numbers"):
            m.albedo = raw
        with pytest.raises(TypeError, match="expected a sequence of 3 numbers"):
            lucent.Vec3(raw)
    # a memoryview of numbers is numbers; one of bytes (ctypes' "<B" too) or released is refused
    assert tuple(lucent.Vec3(memoryview(np.array([1.0, 2.0, 3.0])))) == (1, 2, 3)
    import ctypes
    released = memoryview(np.array([1.0, 2.0, 3.0]))
    released.release()
    for raw in (memoryview((ctypes.c_ubyte * 3)(1, 2, 3)), released):
        with pytest.raises(TypeError, match="expected a sequence of 3 numbers"):
            lucent.Vec3(raw)
    with pytest.raises(TypeError):
        lucent.Film().width = "wide"
    with pytest.raises(TypeError):
        m.type = 3
    # a type's name is a str: bytes were read as their text, None raised pybind's own message
    with pytest.raises(TypeError, match="^type must be a str, got bytes$"):
        lucent.Integrator().type = b"path"
    with pytest.raises(TypeError, match="^type must be a str, got NoneType$"):
        lucent.Integrator().type = None
    with pytest.raises(TypeError, match="^tonemap must be a str, got int$"):
        lucent.Film().tonemap = 1
    with pytest.raises(TypeError, match="^type must be a str, got bytes$"):
        lucent.Filter(b"box")
    with pytest.raises(TypeError, match="^type must be a str, got bytes$"):
        lucent.Material(b"diffuse")
    # and the other names given as arguments (the reviewer's find)
    with pytest.raises(TypeError, match="^precision must be a str, got bytes$"):
        lucent.Renderer(precision=b"float")
    with pytest.raises(TypeError, match="^device must be a str, got NoneType$"):
        lucent.Renderer(device=None)
    with pytest.raises(TypeError, match="^precision must be a str, got int$"):
        lucent.scene_info(lucent.Scene(), precision=3)
    with pytest.raises(TypeError, match="^selector must be a str, got bytes$"):
        lucent.select_device(b"0")
    with pytest.raises(ValueError, match="expected 3 indices"):
        lucent.Triangle().v = (1, 2)
    with pytest.raises(TypeError, match="expected 3 integer indices"):
        lucent.Triangle().v = (1, 2, 3.5)
    with pytest.raises(ValueError, match="expected a sequence of 3 numbers"):
        lucent.Sphere((0, 0), 1)
    with pytest.raises(IndexError):
        lucent.Vec3((1, 2, 3))[3]
    s = lucent.Scene()
    with pytest.raises(ValueError, match=r"positions: expected an array of shape \(N, 3\)"):
        s.positions = np.zeros((4, 2))
    with pytest.raises(ValueError, match=r"uvs: expected an array of shape \(N, 2\)"):
        s.uvs = [[1, 2, 3]]
    with pytest.raises(ValueError, match=r"rgba: expected an array of shape \(H, W, 4\)"):
        lucent.Texture().rgba = np.zeros((2, 2, 3))


def test_vectors_index_compare_and_show():
    v = lucent.Vec3((1, 2.5, -3))
    assert (v[0], v[1], v[2], v[-1], v[-3]) == (1, 2.5, -3, -3, 1)
    v[-1] = 4
    assert v.z == 4 and list(v) == [1, 2.5, 4] and len(v) == 3
    with pytest.raises(IndexError):
        v[-4]
    assert v == (1, 2.5, 4) and v == [1, 2.5, 4] and v == lucent.Vec3((1, 2.5, 4))
    assert v != (1, 2.5, 5) and v != (1, 2.5) and v != "abc" and v != 3 and v != (1j, 2.5, 4)
    assert repr(v) == "Vec3(1, 2.5, 4)"
    w = lucent.Vec2((0.25, -1))
    assert (w[0], w[-1]) == (0.25, -1) and repr(w) == "Vec2(0.25, -1)"


def test_scene_repr_counts_what_it_holds(small_scene):
    assert re.fullmatch(r"<lucent\.Scene '.*': 16x12, path, 2 materials, 1 spheres, 2 triangles, "
                        r"1 lights, 0 textures>", repr(small_scene)), repr(small_scene)


def test_every_scene_type_repr_shows_its_fields():
    scene = lucent.load_scene(SOURCE_DIR / "scenes" / "materials.json")
    assert repr(scene.camera) == ("<lucent.Camera position=Vec3(0, 2.2, 9), look_at=Vec3(0, 1, 0), "
                                  "up=Vec3(0, 1, 0), fov_degrees=38.0, roll_degrees=0.0, "
                                  "aperture=0.0, focus_distance=0.0>")
    assert repr(scene.film) == ("<lucent.Film width=640, height=360, filter=<lucent.Filter "
                                "type='gaussian', radius=1.5>, transfer='srgb', gamma=2.2, "
                                "exposure=0.3, tonemap='aces'>")
    assert repr(scene.integrator).startswith("<lucent.Integrator type='path', max_depth=10, ")
    assert repr(scene.spheres[0]) == "<lucent.Sphere center=Vec3(-4, 1, 0), radius=1.0, material=0>"
    assert repr(scene.lights[1]) == ("<lucent.Light type='environment', position=Vec3(0, 0, 0), "
                                     "intensity=Vec3(0, 0, 0), radiance=Vec3(0.05, 0.06, 0.08), "
                                     "texture=-1>")
    assert repr(scene.triangles[0]) == ("<lucent.Triangle v=(0, 3, 2), n=(-1, -1, -1), "
                                        "uv=(-1, -1, -1), material=1>")
    assert repr(scene.shapes[0]) == ("<lucent.ShapeEntry type='triangles', file='', first=0, "
                                     "count=2, libraries=[]>")
    assert repr(lucent.Texture()) == "<lucent.Texture path='', width=0, height=0>"
    # lists show their first 8 items and count the rest (a mesh holds millions)
    assert repr(lucent.TextureList()) == "<lucent.TextureList of 0: []>"
    assert repr(scene.materials).startswith(
        "<lucent.MaterialList of 9: [<lucent.Material 'diffuse' diffuse>, ")
    assert repr(scene.materials).endswith(", ... 1 more]>")
    many = lucent.TriangleList([lucent.Triangle()] * 100000)
    assert len(repr(many)) < 1000 and repr(many).endswith(", ... 99992 more]>")


def test_array_fields_refuse_what_is_not_numbers():
    with pytest.raises(TypeError, match="positions: expected numbers, got an array of dtype"):
        lucent.Scene().positions = [["a", "b", "c"]]


def test_scene_info_matches_the_cli(tmp_path, small_dict):
    small_dict["materials"]["lamp"] = {"type": "diffuse", "albedo": [0, 0, 0],
                                       "emission": [1, 1, 1]}
    small_dict["shapes"].append({"type": "sphere", "center": [1, 2, 0], "radius": 0.1,
                                 "material": "lamp"})
    scene = lucent.scene_from_dict(small_dict)
    info = lucent.scene_info(scene)
    assert (info["triangles"], info["spheres"], info["vertices"]) == (2, 2, 4)
    assert info["lights"]["point"] == 1 and info["lights"]["sphere"] == 1
    assert info["lights"]["triangle"] == 0 and info["skipped_triangles"] == 0
    assert info["bvh"]["primitives"] == 4 and info["bvh"]["nodes"] >= 1
    # counts are ints (texture_bytes was a float)
    assert all(type(info[k]) is int for k in ("triangles", "spheres", "vertices", "materials",
                                              "textures", "texture_bytes"))
    for define in ("LC_HAS_SPHERES", "LC_HAS_TRIANGLES", "LC_HAS_POINT_LIGHTS",
                   "LC_HAS_SPHERE_LIGHTS", "LC_HAS_DIFFUSE", "LC_HAS_INTEGRATOR_PATH"):
        assert define in info["feature_defines"], define
    assert "LC_HAS_MIRROR" not in info["feature_defines"]
    # what set_scene checks before rendering on a CPU device: the film's part is 80 bytes a pixel
    memory = info["host_memory"]
    film = small_dict["film"]
    film_part = next(p for p in memory["parts"] if p["what"].startswith("the accumulation"))
    assert film_part["bytes"] == film["width"] * film["height"] * 80
    assert memory["bytes"] == sum(p["bytes"] for p in memory["parts"]) > film_part["bytes"]
    assert memory["limit_bytes"] >= 0
    double = lucent.scene_info(scene, precision="double", fast_math=True, specialize=False)
    assert "-D LC_DOUBLE" in double["build_options"]
    assert "-cl-fast-relaxed-math" in double["build_options"]
    assert "LC_HAS_MIRROR" in double["feature_defines"]
    with pytest.raises(ValueError, match="unknown precision"):
        lucent.scene_info(scene, precision="single")
    cli = os.environ.get("LUCENT_CLI")
    if cli:  # the same build options as `lucent info` prints
        path = tmp_path / "s.json"
        path.write_text(json.dumps(small_dict))
        out = subprocess.run([cli, "info", str(path), "--precision", "double", "--fast-math",
                              "--no-specialize"], check=True, capture_output=True, text=True)
        line = next(x for x in out.stdout.splitlines() if "build options" in x)
        assert line.split("build options", 1)[1].strip() == double["build_options"]


def test_texture_arrays_are_copies_that_outlive_the_texture(small_scene):
    # a view of the texels dangled once the setter or the texture list reallocated them
    t = lucent.Texture()
    t.rgba = np.full((1, 1, 4), 0.5, np.float32)
    a = t.rgba
    t.rgba = np.full((64, 64, 4), 0.25, np.float32)
    assert a.shape == (1, 1, 4) and a[0, 0, 0] == 0.5
    assert not a.flags.writeable
    small_scene.textures.append(t)
    b = small_scene.textures[0].rgba
    small_scene.textures.clear()
    assert b[63, 63, 3] == 0.25
    with pytest.raises(TypeError, match="rgba: expected numbers"):
        t.rgba = np.full((1, 1, 4), "0.5")


def test_dict_that_contains_itself_is_an_error():
    # the conversion recursed until the C stack overflowed
    d = {"camera": {}}
    d["camera"]["fov"] = d
    with pytest.raises(lucent.Error, match="nested deeper than 64 levels"):
        lucent.scene_from_dict(d)


def textured_quad(small_scene):
    """small_scene with its floor textured (a 2x2 texture) through uvs set from Python."""
    s = small_scene
    t = lucent.Texture()
    t.rgba = np.full((2, 2, 4), 0.5, np.float32)
    s.textures.append(t)
    s.materials[1].albedo_texture = 0
    s.uvs = [[0, 0], [1, 0], [1, 1], [0, 1]]
    for k in range(len(s.triangles)):
        s.triangles[k].uv = s.triangles[k].v
    return s


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), 1e300])
def test_texture_coordinates_set_from_python_must_be_finite(renderer, small_scene, bad):
    # add_mesh and the OBJ loader refuse such uvs; set from Python they were rendered: the
    # reference's lookups were NaN (every sample of the floor dropped, a black floor), the
    # kernel's read the texel at uv 0
    s = textured_quad(small_scene)
    uvs = np.array(s.uvs)
    uvs[2] = [bad, 0.5]
    s.uvs = uvs
    match = r"/shapes/1 \(triangle 0\)/uv/1/0: must "
    with pytest.raises(lucent.Error, match=match):
        renderer.set_scene(s)
    with pytest.raises(lucent.Error, match=match):
        lucent.render_reference(s, spp=1)


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -0.25])
def test_texels_set_from_python_must_be_finite_and_non_negative(renderer, small_scene, bad):
    # texture files and SceneBuilder.add_texture refuse such texels; set from Python they were
    # rendered: a NaN texel made every sample that read it non-finite (a black floor), a
    # negative one negative light
    s = textured_quad(small_scene)
    rgba = np.array(s.textures[0].rgba)
    rgba[1, 0, 2] = bad
    s.textures[0].rgba = rgba
    with pytest.raises(lucent.Error, match=r"/textures/0/rgba/10: must be"):
        renderer.set_scene(s)
    with pytest.raises(lucent.Error, match=r"/textures/0/rgba/10: must be"):
        lucent.render_reference(s, spp=1)


def test_scene_info_validates_the_scene(small_scene):
    # it packed the scene unchecked: a material index set from Python read past the list
    small_scene.spheres[0].material = 1000000
    with pytest.raises(lucent.Error,
                       match="/shapes/0/material: must index one of the scene.s 2 materials"):
        lucent.scene_info(small_scene)


def test_memory_counts_of_huge_films_saturate_and_are_refused(small_scene):
    """A film of 2147352580x536903681 pixels (2^60 + 4) was counted as 3783 bytes: its byte counts
    wrapped 64 bits, set_scene passed the memory check and PoCL aborted the interpreter. Counts now
    stop at 2^64 - 1: the total is never below a part, and set_scene refuses the film."""
    for width, height in ((2147352580, 536903681), (1073741824, 1073741824),
                          (2147483647, 2147483647)):
        small_scene.film.width, small_scene.film.height = width, height
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", lucent.LucentWarning)  # the camera's float steps
            memory = lucent.scene_info(small_scene)["host_memory"]
            assert memory["bytes"] >= max(p["bytes"] for p in memory["parts"]) >= width * height
            r = lucent.Renderer()
            with pytest.raises(lucent.Error, match="rendering needs about .*: reduce the film size"):
                r.set_scene(small_scene)
    # an application's reservation near 2^64 no longer wraps the total below the limit
    small_scene.film.width, small_scene.film.height = 16, 12
    for reserved in (2 ** 63, 2 ** 64 - 100, 2 ** 64 - 1):
        with pytest.raises(lucent.Error, match="what the application keeps beside the session"):
            lucent.Renderer(reserved_host_bytes=reserved).set_scene(small_scene)


def test_indices_take_numpy_integers_and_refuse_the_rest():
    t = lucent.Triangle()
    t.v = np.array([0, 1, 2])
    assert t.v == (0, 1, 2)
    with pytest.raises(TypeError, match="expected 3 integer indices"):
        t.v = (True, 1, 2)
    with pytest.raises(ValueError, match="index 0 out of range"):
        t.v = (2 ** 40, 0, 0)
    # beyond 64 bits, or NumPy's unsigned: the same ValueError (it was RuntimeError "Unable to
    # cast Python instance to C++ type"), through the integer fields' int_value
    for big in (2 ** 64, -2 ** 63 - 1, np.uint64(2 ** 64 - 1)):
        with pytest.raises(ValueError, match=f"^index 1 out of range: {int(big)}$"):
            t.n = (0, big, 0)
    with pytest.raises(ValueError, match="^index 2 out of range: an integer too long to show$"):
        t.uv = (0, 0, 10 ** 5000)
    assert t.v == (0, 1, 2)  # unchanged by a refused assignment


def test_out_of_memory_in_array_fields_is_raised_not_reported_as_a_wrong_shape(small_scene):
    class OutOfMemory:  # a conversion that runs out of memory (a copy too large for memory)
        def __array__(self, dtype=None):
            raise MemoryError("no memory for the copy")
    with pytest.raises(MemoryError, match="no memory for the copy"):
        small_scene.positions = OutOfMemory()
    with pytest.raises(MemoryError, match="no memory for the copy"):
        lucent.Texture().rgba = OutOfMemory()


def test_array_fields_refuse_strings_that_look_like_numbers():
    with pytest.raises(TypeError, match="positions: expected numbers"):
        lucent.Scene().positions = [["1", "2", "3e400"]]


def with_normals(small_scene, normals):
    """small_scene with its floor's vertex normals set from Python (the floor faces +y)."""
    s = small_scene
    s.normals = normals
    for k in range(len(s.triangles)):
        s.triangles[k].n = s.triangles[k].v
    return s


@pytest.mark.parametrize("bad", [float("inf"), -float("inf"), 1e39])
def test_normals_set_from_python_must_fit_in_a_float(small_scene, bad):
    # add_mesh and the OBJ loader refuse non-finite normals and store unit ones; set from Python
    # an infinite normal, or one beyond float range, made the kernel's shading normal NaN: the
    # floor rendered black (mean 0.0035 instead of 0.055) with no non-finite sample counted
    normals = np.tile([0.0, 1.0, 0.0], (4, 1))
    normals[2, 1] = bad
    s = with_normals(small_scene, normals)
    with pytest.raises(lucent.Error, match=r"/shapes/1 \(triangle 0\)/n/1/1: must "):
        lucent.scene_info(s)
    s.normals = np.tile([0.0, 2.0, 0.0], (4, 1))  # any finite length: normalized when shading
    assert lucent.scene_info(s)["triangles"] == 2


@pytest.mark.parametrize("field, indices", [("n", (0, 1, -1)), ("n", (-2, -2, -2)),
                                            ("uv", (-1, 0, 1)), ("uv", (-1, -1, -3))])
def test_normal_and_uv_indices_are_three_or_none(small_scene, field, indices):
    # normals (uvs) are used when all three indices are given: some given and some not, or an
    # index below -1, ignored them without a word
    s = with_normals(small_scene, np.tile([0.0, 1.0, 0.0], (4, 1)))
    s.uvs = [[0, 0], [1, 0], [1, 1], [0, 1]]
    setattr(s.triangles[1], field, indices)
    what = "normals" if field == "n" else "uvs"
    with pytest.raises(lucent.Error,
                       match=r"/shapes/1 \(triangle 1\)/%s: must be three indices of the scene's "
                       r"%s or -1 for all three \(none\), got \(%d, %d, %d\)$"
                       % ((field, what) + indices)):
        lucent.scene_info(s)
    setattr(s.triangles[1], field, (-1, -1, -1))
    assert lucent.scene_info(s)["triangles"] == 2


@pytest.mark.parametrize("obj, field, lo, hi", [
    (lucent.Film(), "width", "-2**31", "2**31 - 1"),
    (lucent.Integrator(), "seed", "0", "2**32 - 1"),
    (lucent.Integrator(), "max_depth", "-2**31", "2**31 - 1"),
    (lucent.Material(), "albedo_texture", "-2**31", "2**31 - 1"),
    (lucent.Sphere(), "material", "-2**31", "2**31 - 1"),
    (lucent.Triangle(), "material", "-2**31", "2**31 - 1"),
    (lucent.Light(), "texture", "-2**31", "2**31 - 1"),
    (lucent.ShapeEntry(), "first", "0", "2**64 - 1"),
])
def test_integer_fields_out_of_range_are_value_errors_naming_the_field(obj, field, lo, hi):
    # as README says of every number out of its range: a ValueError naming it and its range.
    # These were pybind11's TypeError "incompatible function arguments", several lines naming
    # neither the field nor its range
    name = type(obj).__name__
    before = getattr(obj, field)
    for big in (2 ** 64, -2 ** 70, 10 ** 30):
        with pytest.raises(ValueError) as e:
            setattr(obj, field, big)
        assert str(e.value) == "%s.%s must be an integer in [%s, %s], got %d" % (name, field, lo,
                                                                                  hi, big)
    with pytest.raises(TypeError, match=r"^%s\.%s must be an integer, got 2\.0$" % (name, field)):
        setattr(obj, field, 2.0)
    with pytest.raises(TypeError, match="must be an integer, got True"):
        setattr(obj, field, True)
    assert getattr(obj, field) == before  # unchanged by a refused assignment
    setattr(obj, field, np.int16(3))
    assert getattr(obj, field) == 3


def test_sphere_material_argument_is_checked_as_the_field():
    with pytest.raises(ValueError, match=r"^Sphere\.material must be an integer in \[-2\*\*31, "):
        lucent.Sphere((0, 0, 0), 1, 2 ** 40)
    assert lucent.Sphere((0, 0, 0), 1, np.int64(2)).material == 2


def test_python_values_start_from_the_struct_defaults_not_the_types(small_scene):
    # README's Python section: setting a type changes nothing else (the scene format's per-type
    # defaults, a conductor's specular 0.9, a diffuse_mirror's reflectance 0.2, a gaussian's
    # radius 1.5, are not applied)
    m = lucent.Material()
    m.type = "conductor"
    assert m.specular == (1, 1, 1)
    f = lucent.Filter()
    f.type = "gaussian"
    assert f.radius == 0.5
    m.type = "diffuse_mirror"
    m.name = "dm"
    small_scene.materials[0] = m
    with pytest.raises(lucent.Error, match=r"/materials/dm/reflectance/0: albedo \+ reflectance "
                                           r"must be <= 1 .* 0\.8 \+ 1 = 1\.8 in red"):
        lucent.scene_info(small_scene)


@pytest.mark.parametrize("type_name", lucent.MATERIAL_TYPES)
def test_material_of_a_type_has_the_scene_formats_defaults(type_name):
    # Material(type) is the material a scene file gives for {"type": type_name} alone (it did not
    # exist: Material() has the struct's defaults whatever its type, see the test above)
    from_file = lucent.scene_from_dict({"materials": {"m": {"type": type_name}}}).materials[0]
    made = lucent.Material(type_name, "m")
    assert made.type == type_name and made.name == "m"
    for field in ("albedo", "specular", "emission"):
        assert tuple(getattr(made, field)) == tuple(getattr(from_file, field)), field
    for field in ("ior", "roughness", "albedo_texture"):
        assert getattr(made, field) == getattr(from_file, field), field
    with pytest.raises(ValueError, match="unknown material type 'bogus'"):
        lucent.Material("bogus")


@pytest.mark.parametrize("type_name", lucent.FILTER_TYPES)
def test_filter_of_a_type_has_the_scene_formats_radius(type_name):
    from_file = lucent.scene_from_dict({"film": {"filter": {"type": type_name}}}).film.filter
    made = lucent.Filter(type_name)
    assert made.type == type_name and made.radius == from_file.radius


@pytest.mark.parametrize("field", ["mis", "caustics"])
def test_bool_fields_take_only_bools(field):
    # pybind11's bool caster took anything with a truth value: mis = "no" turned MIS on
    i = lucent.Integrator()
    for v in (True, False, np.bool_(True)):
        setattr(i, field, v)
        assert getattr(i, field) == bool(v)
    for v in ("no", 0.5, None, 1):
        with pytest.raises(TypeError, match=rf"Integrator\.{field} must be True or False, got "):
            setattr(i, field, v)
    assert getattr(i, field) is True


def test_huge_arrays_are_refused_before_they_are_copied():
    # a broadcast view of 12 bytes standing for 10^9 positions was copied whole (24 GB of float64,
    # then the scene's vector): the kernel killed the process; MemoryError now, before any copy.
    # (10^10 rows here, 480 GB to copy: a host with more memory than that is skipped)
    if os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") > 400e9:
        pytest.skip("this host has more than 400 GB of memory")
    s = lucent.Scene()
    with pytest.raises(MemoryError, match=r"^positions: 30000000000 values need about"):
        s.positions = np.broadcast_to(np.zeros(3, "f4"), (10 ** 10, 3))
    assert s.positions.shape == (0, 3)
    t = lucent.Texture()
    with pytest.raises(MemoryError, match=r"^rgba: "):
        t.rgba = np.broadcast_to(np.zeros(4, "f4"), (10 ** 6, 10 ** 6, 4))
    # images given to compare, write_image, RenderResult and converge alike
    huge = np.broadcast_to(np.float32(1), (10 ** 5, 10 ** 5, 3))  # 240 GB to copy
    with pytest.raises(MemoryError, match=r"^image: 30000000000 values need about"):
        lucent.write_image("never.pfm", huge)
    with pytest.raises(MemoryError, match=r"^mean: 30000000000 values need about"):
        lucent.RenderResult(huge)
    with pytest.raises(MemoryError, match=r"^a: 30000000000 values need about"):
        lucent.compare(huge, huge)
    assert not os.path.exists("never.pfm")


def test_errors_and_warnings_are_one_line(tmp_path, small_dict):
    """A name with a newline or an escape sequence came through raw in lucent.Error and in
    warnings; they are one line, as the command line prints them."""
    small_dict["shapes"][0]["material"] = "a\nc\x1b[31m"
    with pytest.raises(lucent.Error) as e:
        lucent.scene_from_dict(small_dict)
    assert "\n" not in str(e.value) and "\x1b" not in str(e.value)
    assert "'a\\nc\\x1b[31m'" in str(e.value), str(e.value)
    path = tmp_path / "s.json"
    path.write_text(json.dumps(small_dict))
    with pytest.raises(lucent.Error) as f:
        lucent.load_scene(path)
    assert "'a\\nc\\x1b[31m'" in str(f.value) and "\n" not in str(f.value)


@pytest.mark.parametrize("value, shown", [(2 ** 63, "9223372036854775808"),
                                          (2 ** 64, "1.8446744073709552e+19"),
                                          (-2 ** 63 - 1, "-9.223372036854776e+18"),
                                          (-2 ** 63, "-9223372036854775808")])
def test_integers_beyond_64_bits_get_the_fields_range_error(tmp_path, value, shown):
    """An integer field given an integer beyond the signed 64 bits: its range, from a file and
    from a dict alike (a file said "must be an integer, got a number 1.8446744073709552e+19",
    a dict "integer out of range: 9223372036854775808")."""
    message = "/film/width: must be in [1, 16384], got " + shown
    with pytest.raises(lucent.Error, match=re.escape(message)):
        lucent.scene_from_dict({"film": {"width": value}})
    path = tmp_path / "s.json"
    path.write_text('{"film": {"width": %d}}' % value)
    with pytest.raises(lucent.Error, match=re.escape(message)):
        lucent.load_scene(path)

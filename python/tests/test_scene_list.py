"""The scene's lists (MaterialList, TriangleList, ...) behave as Python lists whose elements are
objects of their own: a reference to an element (`w = scene.materials[0]`, an iterator's item, a
member such as `w.albedo`) follows the element when the list changes, and outlives it when it
leaves the list. With pybind11's bind_vector such a reference pointed at freed memory once the
list reallocated: edits were lost, reads returned garbage, writes crashed the interpreter
(`free(): invalid pointer`), and `del lst[::-1]` erased out of bounds. The sanitizer build runs
these tests with AddressSanitizer, which reports any access to freed memory."""
import random

import numpy as np

import pytest

import lucent
from conftest import SMALL


def material(name):
    m = lucent.Material()
    m.name = name
    return m


def test_reference_follows_its_element_when_the_list_reallocates(small_scene):
    w = small_scene.materials[0]
    name = w.name
    albedo = w.albedo  # a member: a reference into the element too
    for i in range(100):  # several reallocations
        small_scene.materials.append(material(f"n{i}"))
    w.albedo = (1, 0, 0)
    assert small_scene.materials[0] is w
    assert w.name == name
    assert tuple(small_scene.materials[0].albedo) == (1, 0, 0)
    assert tuple(albedo) == (1, 0, 0)
    albedo.y = 0.25
    assert small_scene.materials[0].albedo.y == 0.25


def test_element_removed_from_the_list_lives_on_as_a_copy(small_scene):
    w = small_scene.materials[1]
    name = w.name
    small_scene.materials.clear()
    for i in range(50):
        small_scene.materials.append(material(f"n{i}"))
    assert w.name == name
    w.name = "a name long enough to need its own allocation " * 4  # crashed: free() on junk
    assert all(m.name.startswith("n") for m in small_scene.materials)
    assert all(m is not w for m in small_scene.materials)


def test_iterator_follows_the_list_by_index(small_scene):
    it = iter(small_scene.triangles)
    first = next(it)
    v = tuple(first.v)
    for _ in range(100):
        small_scene.triangles.append(lucent.Triangle())
    assert tuple(first.v) == v
    assert next(it) is small_scene.triangles[1]
    # items appended during an iteration are visited, and a list that shrinks ends it
    seen = 0
    for t in small_scene.triangles:
        seen += 1
        if seen == 1:
            small_scene.triangles.append(lucent.Triangle())
        if seen == 50:
            del small_scene.triangles[60:]
    assert seen == 60


def test_slices_delete_and_assign_as_in_a_python_list(small_scene):
    for i in range(4):
        small_scene.materials.append(material(f"n{i}"))
    names = [m.name for m in small_scene.materials]
    del small_scene.materials[::-1]  # erased out of bounds with bind_vector
    assert len(small_scene.materials) == 0
    small_scene.materials = [material(n) for n in names]  # a Python list converts
    assert [m.name for m in small_scene.materials] == names
    small_scene.materials = tuple(small_scene.materials)  # and a tuple, and itself
    assert [m.name for m in small_scene.materials] == names
    small_scene.materials[1:3] = [material("x")]  # a simple slice: any length
    assert [m.name for m in small_scene.materials] == [names[0], "x"] + names[3:]
    with pytest.raises(ValueError, match="extended slice of size 3"):
        small_scene.materials[::2] = [material("y")]
    with pytest.raises(IndexError, match="pop from empty list"):
        lucent.MaterialList().pop()
    with pytest.raises(IndexError):
        small_scene.materials[len(small_scene.materials)]
    small_scene.materials.insert(-100, material("first"))
    small_scene.materials.insert(100, material("last"))
    assert small_scene.materials[0].name == "first"
    assert small_scene.materials[-1].name == "last"
    small_scene.materials.extend(small_scene.materials)  # itself: read before it grows
    assert len(small_scene.materials) == 2 * (len(names) + 1)


def test_random_changes_match_a_python_list_and_keep_references():
    """Model check: random changes to a MaterialList and to a Python list of the same names, with
    references held to some elements. After each change the names agree, every held reference
    still names its element, is that element where the model has it, and is no element of the
    list once the model dropped it; an edit through a reference reaches the list exactly then."""
    rng = random.Random(2026)

    class Item:  # the model's element: an object of its own, like a list element
        def __init__(self, name):
            self.name = name

    lst, model = lucent.MaterialList(), []
    held = []  # (model item, the reference taken when it was in the list, its albedo)
    counter = 0

    def new_name():
        nonlocal counter
        counter += 1
        return f"m{counter}"

    def random_slice(n):
        a = rng.randint(-n - 2, n + 2)
        b = rng.randint(-n - 2, n + 2)
        step = rng.choice([None, 1, 2, 3, -1, -2, -3])
        return slice(rng.choice([None, a]), rng.choice([None, b]), step)

    for step in range(600):
        n = len(model)
        op = rng.choice(["append", "append", "extend", "extend_self", "insert", "pop", "del",
                         "del_slice", "set", "set_slice", "hold", "hold", "clear"]
                        if n else ["append", "extend", "insert", "hold"])
        if op == "append":
            name = new_name()
            lst.append(material(name))
            model.append(Item(name))
        elif op == "extend":
            names = [new_name() for _ in range(rng.randint(0, 4))]
            lst.extend([material(x) for x in names])
            model.extend(Item(x) for x in names)
        elif op == "extend_self" and n < 40:
            lst.extend(lst)
            model.extend([Item(x.name) for x in model])
        elif op == "insert":
            i, name = rng.randint(-n - 3, n + 3), new_name()
            lst.insert(i, material(name))
            model.insert(i, Item(name))
        elif op == "pop":
            i = rng.randint(-n, n - 1)
            assert lst.pop(i).name == model.pop(i).name
        elif op == "del":
            i = rng.randint(-n, n - 1)
            del lst[i]
            del model[i]
        elif op == "del_slice":
            s = random_slice(n)
            del lst[s]
            del model[s]
        elif op == "set":
            i, name = rng.randint(-n, n - 1), new_name()
            lst[i] = material(name)
            model[i] = Item(name)
        elif op == "set_slice":
            s = random_slice(n)
            size = len(range(*s.indices(n)))
            if s.step not in (None, 1):
                names = [new_name() for _ in range(size)]
            else:
                names = [new_name() for _ in range(rng.randint(0, 3))]
            lst[s] = [material(x) for x in names]
            model[s] = [Item(x) for x in names]
        elif op == "hold" and n:
            i = rng.randrange(n)
            ref = lst[i]
            held.append((model[i], ref, ref.albedo if rng.random() < 0.5 else None))
        elif op == "clear" and rng.random() < 0.2:
            lst.clear()
            model.clear()

        elements = list(lst)  # one pass over the list a step: its elements' identities
        assert [m.name for m in elements] == [x.name for x in model], f"step {step}: {op}"
        in_list = {id(m) for m in elements}
        at = {id(x): k for k, x in enumerate(model)}
        for item, ref, albedo in held:
            assert ref.name == item.name, f"step {step}: {op}"
            k = at.get(id(item))
            mark = float(step)
            if albedo is not None:
                albedo.x = mark
                assert ref.albedo.x == mark
            else:
                ref.albedo = (mark, 0, 0)
            if k is not None:
                assert lst[k] is ref, f"step {step}: {op}"
                assert lst[k].albedo.x == mark
            else:
                assert id(ref) not in in_list, f"step {step}: {op}"
        if len(held) > 30:
            del held[: len(held) - 30]
    assert counter > 300


def test_scene_renders_after_its_lists_changed_under_references():
    s = lucent.scene_from_dict(SMALL)
    w = s.materials[0]
    s.materials.append(material("extra"))
    s.spheres.append(lucent.Sphere((1, 0.5, 0), 0.25, material=2))
    w.albedo = (0.9, 0.1, 0.1)
    lucent.scene_info(s)  # validates: every index in range
    assert tuple(s.materials[0].albedo) == pytest.approx((0.9, 0.1, 0.1))


class Hostile:
    """A number whose conversion (__float__, __index__) runs Python code that empties a scene list
    and fills another scene's list of the same type, which takes the freed memory: a setter that
    took its element before converting its value wrote into the other scene (or freed memory)."""

    def __init__(self, value, victim, other, make):
        self.value, self.victim, self.other, self.make = value, victim, other, make

    def strike(self):
        if self.victim is not None:
            self.victim.clear()
            self.other.extend([self.make() for _ in range(8)])
            self.victim = None

    def __float__(self):
        self.strike()
        return float(self.value)

    def __index__(self):
        self.strike()
        return int(self.value)


class HostileArray(Hostile):
    def __array__(self, dtype=None, copy=None):
        self.strike()
        return np.full((2, 3, 4), self.value, dtype=np.float32)


class HostileSequence(Hostile):
    def __len__(self):
        return 3

    def __getitem__(self, i):
        if i >= 3:
            raise IndexError(i)
        self.strike()
        return self.value


def sphere():
    return lucent.Sphere((7, 7, 7), 2.0, 1)


def light():
    l = lucent.Light()
    l.position = (7, 7, 7)
    return l


def shape():
    e = lucent.ShapeEntry()
    e.first = 7
    e.libraries = ["x.mtl"]
    return e


# (list, a new element, the edit through a reference with a value that strikes, what the edited
# element then reads); the value is 5
EDITS = [
    ("spheres", sphere, lambda e, h: setattr(e, "radius", h), lambda e: e.radius),
    ("spheres", sphere, lambda e, h: setattr(e, "material", h), lambda e: e.material),
    ("spheres", sphere, lambda e, h: setattr(e, "center", (h, 0, 0)), lambda e: e.center.x),
    ("spheres", sphere, lambda e, h: setattr(e.center, "y", h), lambda e: e.center.y),
    ("spheres", sphere, lambda e, h: e.center.__setitem__(2, h), lambda e: e.center.z),
    ("materials", lambda: material("m"), lambda e, h: setattr(e, "ior", h), lambda e: e.ior),
    ("materials", lambda: material("m"), lambda e, h: setattr(e, "albedo_texture", h),
     lambda e: e.albedo_texture),
    ("materials", lambda: material("m"), lambda e, h: setattr(e, "albedo", (0, h, 0)),
     lambda e: e.albedo.y),
    ("triangles", lucent.Triangle, lambda e, h: setattr(e, "material", h), lambda e: e.material),
    ("lights", light, lambda e, h: setattr(e, "position", (0, 0, h)), lambda e: e.position.z),
    ("shapes", shape, lambda e, h: setattr(e, "first", h), lambda e: e.first),
]


@pytest.mark.parametrize("name,make,edit,read", EDITS)
def test_an_edit_whose_value_changes_the_list_reaches_the_element_it_named(name, make, edit,
                                                                           read):
    """The value is converted before the element is taken: the edit lands on the element, which
    the conversion removed from its list (a copy the reference keeps), and never in the other
    scene that reused the memory. The sanitizer build reports any write to freed memory."""
    scene, other = lucent.Scene(), lucent.Scene()
    victim = getattr(scene, name)
    victim.append(make())
    element = victim[0]
    edit(element, Hostile(5, victim, getattr(other, name), make))
    assert len(victim) == 0
    assert read(element) == 5
    fresh = make()
    for e in getattr(other, name):
        assert read(e) == read(fresh), "the edit went to another scene's element"


def test_sequence_and_array_values_are_converted_before_the_element_is_taken():
    scene, other = lucent.Scene(), lucent.Scene()
    scene.triangles.append(lucent.Triangle())
    t = scene.triangles[0]
    t.v = HostileSequence(4, scene.triangles, other.triangles, lucent.Triangle)
    assert t.v == (4, 4, 4) and len(scene.triangles) == 0
    assert all(e.v == lucent.Triangle().v for e in other.triangles)

    def texture():
        x = lucent.Texture()
        x.rgba = np.zeros((1, 1, 4), np.float32)
        return x

    scene.textures.append(texture())
    x = scene.textures[0]
    x.rgba = HostileArray(0.5, scene.textures, other.textures, texture)
    assert (x.height, x.width) == (2, 3) and float(x.rgba[1, 2, 3]) == 0.5
    assert all((e.height, e.width) == (1, 1) for e in other.textures)

    scene.shapes.append(shape())
    e = scene.shapes[0]
    e.libraries = HostileSequence("y.mtl", scene.shapes, other.shapes, shape)
    assert e.libraries == ["y.mtl"] * 3
    assert all(s.libraries == ["x.mtl"] for s in other.shapes)
    # a comparison reads the vector after converting the other side, and an index after
    # converting it (the other scene's elements differ, so that a stale read shows)
    def far_sphere():
        return lucent.Sphere((1, 1, 1), 2.0, 1)

    scene.spheres.append(sphere())
    c = scene.spheres[0].center
    assert c == (Hostile(7, scene.spheres, other.spheres, far_sphere), 7, 7)
    scene.spheres.append(sphere())
    c = scene.spheres[0].center
    assert c[Hostile(1, scene.spheres, other.spheres, far_sphere)] == 7


def test_insert_of_an_element_of_the_list_survives_an_index_that_clears_it():
    """insert(i, x) with x an element of the same list and an index whose __index__ clears the
    list: x was copied after the index, from freed memory (ASan: heap-use-after-free; a release
    build raised basic_string::_M_create for a material, inserted a garbage sphere)."""
    other = lucent.Scene()
    for make, lst_of, check in [
            (lambda i: material(chr(65 + i) * 200), lambda s: s.materials, lambda m: m.name),
            (lambda i: lucent.Sphere((i, 2 * i, 3 * i), 0.5 + i, 1), lambda s: s.spheres,
             lambda sp: (tuple(sp.center), sp.radius))]:
        s = lucent.Scene()
        lst = lst_of(s)
        for i in range(4):
            lst.append(make(i))
        expected = check(lst[2])
        lst.insert(Hostile(0, lst, lst_of(other), lambda: make(9)), lst[2])
        assert len(lst) == 1 and check(lst[0]) == expected


def test_slice_bounds_are_converted_before_the_list_is_measured():
    """A slice's bounds (__index__) can change the list: it is measured after them, as a Python
    list is. With the length read first, reads, deletions and assignments went past the end."""
    other = lucent.Scene()

    def filled():
        lst = lucent.MaterialList()
        lst.extend([material(f"n{i}") for i in range(6)])
        return lst

    def bound(lst):
        return Hostile(1, lst, other.materials, lambda: material("o"))

    lst = filled()
    assert len(lst[bound(lst):5]) == 0
    lst = filled()
    del lst[bound(lst):5:2]
    assert len(lst) == 0
    lst = filled()
    lst[bound(lst):5] = [material("a")]
    assert [m.name for m in lst] == ["a"]
    lst = filled()
    with pytest.raises(ValueError, match="extended slice of size 0"):
        lst[bound(lst):5:2] = [material("a")]


def test_items_of_another_type_name_the_item(small_scene):
    # extend and slice assignment with an item that is no Material raised pybind's RuntimeError
    # "Unable to cast Python instance to C++ type", naming none (the Python API tester's find)
    m = lucent.Material()
    before = len(small_scene.materials)
    with pytest.raises(TypeError, match=r"^extend: item 1: expected a Material, not int$"):
        small_scene.materials.extend([m, 3])
    with pytest.raises(TypeError, match=r"^extend: item 0: expected a Material, not str$"):
        small_scene.materials.extend("ab")
    with pytest.raises(TypeError, match=r"^slice assignment: item 1: expected a Material, not int$"):
        small_scene.materials[0:1] = [m, 3]
    assert len(small_scene.materials) == before


def test_indices_are_read_as_a_python_list_reads_them(small_scene):
    # an int past Py_ssize_t, a float or a value of another type raised pybind's "incompatible
    # function arguments" TypeError (the Python API tester's find); as a Python list: IndexError
    # for the first, TypeError naming the type for the others
    mats, v = small_scene.materials, lucent.Vec3((1, 2, 3))
    for index in (2 ** 70, -2 ** 70):
        with pytest.raises(IndexError, match="cannot fit 'int' into an index-sized integer"):
            mats[index]
        with pytest.raises(IndexError, match="cannot fit 'int' into an index-sized integer"):
            del mats[index]
        with pytest.raises(IndexError, match="cannot fit 'int' into an index-sized integer"):
            v[index]
    with pytest.raises(TypeError, match=r"^list indices must be integers or slices, not float$"):
        mats[1.5]
    with pytest.raises(TypeError, match=r"^list indices must be integers or slices, not str$"):
        mats["0"] = lucent.Material()
    with pytest.raises(TypeError, match=r"^vector indices must be integers, not NoneType$"):
        v[None]
    with pytest.raises(TypeError, match=r"^list assignment: expected a Material, not int$"):
        mats[0] = 5
    with pytest.raises(TypeError, match=r"^can only assign an iterable$"):
        mats[0:1] = 5
    # what a list takes: bool and numpy integers, negative indices, slices
    first = mats[0].name
    assert mats[False].name == first and mats[np.int64(0)].name == first
    assert mats[-len(mats)].name == first and v[-1] == 3
    mats[0:1] = [lucent.Material("mirror")]
    assert mats[0].type == "mirror"


def test_lists_name_what_is_wrong_as_a_python_list_does():
    """The list constructor and the scene's list properties named neither the list nor the item
    that is no element (pybind's RuntimeError "Unable to cast Python instance", and "(): incompatible
    function arguments"), and pop or insert at an index past Py_ssize_t said "incompatible function
    arguments" where a list raises OverflowError."""
    m = lucent.Material("mirror")
    with pytest.raises(TypeError, match=r"^MaterialList\(\): item 1: expected a Material, not int$"):
        lucent.MaterialList([m, 5])
    s = lucent.Scene()
    with pytest.raises(TypeError, match=r"^Scene.materials: item 1: expected a Material, not int$"):
        s.materials = [m, 5]
    with pytest.raises(TypeError, match=r"^Scene.materials: expected a list of Material, not int$"):
        s.materials = 5
    s.materials = (m, m)
    s.materials = s.materials
    assert len(s.materials) == 2
    items = lucent.MaterialList([m])
    for call in (lambda: items.pop(2 ** 70), lambda: items.insert(2 ** 70, m),
                 lambda: [m].pop(2 ** 70), lambda: [m].insert(2 ** 70, m)):  # (as a list's)
        with pytest.raises(OverflowError):
            call()
    with pytest.raises(TypeError, match=r"^the index must be an integer, not float$"):
        items.pop(1.5)
    items.insert(-(2 ** 40), m)  # as a list: before the first
    assert len(items) == 2 and items.pop(-1).type == "mirror"

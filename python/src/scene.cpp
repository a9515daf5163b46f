// Scenes in Python: the scene structs with every field readable and writable (enums by their
// scene-file names), scenes from files and from dicts of the JSON format (the same parser and
// its one-line errors).
#include <pybind11/pybind11.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>

#include "common.hpp"
#include "core/text.hpp"
#include "lucent/error.hpp"
#include "lucent/types.hpp"
#include "render/features.hpp"
#include "render/pack.hpp"
#include "render/resources.hpp"
#include "scene/json_guard.hpp"
#include "scene/loaders.hpp"
#include "scene/validate.hpp"
#include "scene_list.hpp"
#include "state.hpp"

PYBIND11_MAKE_OPAQUE(std::vector<lucent::Material>)
PYBIND11_MAKE_OPAQUE(std::vector<lucent::Sphere>)
PYBIND11_MAKE_OPAQUE(std::vector<lucent::Triangle>)
PYBIND11_MAKE_OPAQUE(std::vector<lucent::Light>)
PYBIND11_MAKE_OPAQUE(std::vector<lucent::Texture>)
PYBIND11_MAKE_OPAQUE(std::vector<lucent::ShapeEntry>)

namespace lucent::python {

namespace {

/// The fewest digits that read back as `v` (Vec3(0, 2.2, 9), not 2.2000000000000002), as
/// Python's repr of a float.
std::string format_number(double v) { return io::shortest_real(v); }

/// The object a setter assigns to (or a method reads), taken from `self` after the value (or an
/// index, or the other side of a comparison) was converted. Converting
/// can run Python code (__float__, __index__, a sequence's __getitem__, __array__), and that code
/// can change the scene list the object is an element of, which moves the element to a copy
/// (scene_list.hpp): a `C&` taken as the setter's first argument, before its value was converted,
/// pointed where the element had been, and the edit went into freed memory or another scene's
/// element. Every setter of the scene's classes takes `py::handle self` and calls this last.
template <class C>
C& assigned(py::handle self) {
  return self.cast<C&>();
}

/// A number member (what def_readwrite gives, with the object taken after the number).
template <class C, class D>
void number_property(py::class_<C>& c, const char* name, D C::*member, const char* doc = "") {
  c.def_property(
      name, [member](const C& o) { return o.*member; },
      [member](py::handle self, D v) { assigned<C>(self).*member = v; }, doc);
}

/// A vector member: reading gives the vector itself (`camera.position.x += 1` changes the
/// camera), assigning takes any sequence of numbers.
template <class C, class V>
void vec_property(py::class_<C>& c, const char* name, V C::*member, const char* doc = "") {
  c.def_property(name,
                 py::cpp_function([member](C& o) -> V& { return o.*member; },
                                  py::return_value_policy::reference_internal),
                 py::cpp_function([member](py::handle self, py::handle v) {
                   const V x = to_vec<V>(v);
                   assigned<C>(self).*member = x;
                 }),
                 doc);
}

/// Vec3 / Vec2: glm vectors with x, y, (z), indexing, iteration, comparison with sequences and
/// conversion from any sequence of numbers (function arguments accept tuples, lists, arrays).
template <class V>
py::class_<V> bind_vector_type(py::module_& m, const char* name) {
  constexpr int N = V::length();
  // (the vector read after the index is converted: assigned())
  auto get = [](py::handle self, py::handle index) {
    py::ssize_t i = list_detail::index_of(index, "vector indices must be integers");
    if (i < 0) i += N;
    if (i < 0 || i >= N) throw py::index_error(std::string("index out of range"));
    return assigned<V>(self)[static_cast<int>(i)];
  };
  py::class_<V> c(m, name);
  c.def(py::init([](py::sequence s) { return to_vec<V>(s); }), py::arg("values"));
  number_property(c, "x", &V::x);
  number_property(c, "y", &V::y);
  c.def("__len__", [](const V&) { return N; })
      .def("__getitem__", get)
      .def("__setitem__",
           [](py::handle self, py::handle index, double value) {
             py::ssize_t i = list_detail::index_of(index, "vector indices must be integers");
             if (i < 0) i += N;
             if (i < 0 || i >= N) throw py::index_error(std::string("index out of range"));
             assigned<V>(self)[static_cast<int>(i)] = value;
           })
      .def("__iter__",
           [](const V& v) {
             py::list l;
             for (int i = 0; i < N; ++i) l.append(v[i]);
             return py::iter(l);
           })
      .def("__eq__",
           [](py::handle self, py::object other) {
             if (py::isinstance<V>(other)) return assigned<V>(self) == other.cast<V>();
             if (!py::isinstance<py::sequence>(other) || py::isinstance<py::str>(other) ||
                 py::len(other) != static_cast<std::size_t>(N))
               return false;
             // the other side's numbers first (their conversion can move this vector, as a
             // setter's value can: assigned())
             py::sequence s = py::reinterpret_borrow<py::sequence>(other);
             V w;
             for (int i = 0; i < N; ++i) {
               py::object e = s[static_cast<std::size_t>(i)];
               // a number that is not real (complex) compares unequal rather than raising
               if (!PyNumber_Check(e.ptr()) || !py::hasattr(e, "__float__") ||
                   py::isinstance<py::str>(e))
                 return false;
               w[i] = py::float_(e).cast<double>();
             }
             return assigned<V>(self) == w;
           })
      .def(
          "__array__",
          [](const V& v, py::object dtype) {
            // V::length(), not N: clang 14 wants N captured to pass it to array_t
            py::array_t<double> a(static_cast<py::ssize_t>(V::length()));
            for (int i = 0; i < N; ++i) a.mutable_at(i) = v[i];
            return dtype.is_none() ? py::array(a) : py::array(a.attr("astype")(dtype));
          },
          py::arg("dtype") = py::none())
      .def("__repr__", [name](const V& v) {
        std::string s = std::string(name) + "(";
        for (int i = 0; i < N; ++i) s += (i ? ", " : "") + format_number(v[i]);
        return s + ")";
      });
  if constexpr (N == 3) number_property(c, "z", &V::z);
  c.attr("__hash__") = py::none();
  py::implicitly_convertible<py::sequence, V>();
  return c;
}

/// The magnitude of I's lowest value (2**31 for an int, 0 for an unsigned type).
template <class I>
constexpr std::uint64_t lowest_magnitude() {
  using L = std::numeric_limits<I>;
  return L::is_signed ? static_cast<std::uint64_t>(-(L::min() + 1)) + 1 : 0;
}

/// The integer `v` (int_value) as an I, or nothing when it is beyond I's range.
template <class I>
std::optional<I> narrowed(const IntValue& v) {
  if (!v.fits ||
      v.magnitude > (v.negative ? lowest_magnitude<I>()
                                : static_cast<std::uint64_t>(std::numeric_limits<I>::max())))
    return std::nullopt;
  return v.negative ? static_cast<I>(-static_cast<long long>(v.magnitude - 1) - 1)
                    : static_cast<I>(v.magnitude);
}

/// `arg` as an integer of type I: TypeError unless it is an integer (an int, a NumPy integer:
/// operator.index; not a bool, as for triangle indices), ValueError "<what> must be an integer
/// in [lo, hi], got <value>" for one outside I, of any size (never wrapped or clamped). A C++
/// integer member bound as is refused such a value with pybind11's TypeError "incompatible
/// function arguments", several lines that named neither the field nor its range.
template <class I>
I integer_value(const IntArg& arg, const std::string& what) {
  using L = std::numeric_limits<I>;
  const IntValue v = int_value(arg, what, /*allow_bool=*/false);
  if (const std::optional<I> x = narrowed<I>(v)) return *x;
  const std::uint64_t lowest = lowest_magnitude<I>();
  throw py::value_error(what + " must be an integer in [" +
                        (L::is_signed ? "-" + range_bound(lowest) : std::string("0")) + ", " +
                        range_bound(static_cast<std::uint64_t>(L::max())) + "], got " +
                        int_repr(v.index));
}

/// An integer member (integer_value's checks, naming the class and the member).
template <class C, class I>
void int_property(py::class_<C>& c, const char* name, I C::*member, const char* doc = "") {
  const std::string what = c.attr("__name__").template cast<std::string>() + "." + name;
  c.def_property(
      name, [member](const C& o) { return o.*member; },
      [member, what](py::handle self, const IntArg& v) {
        const I x = integer_value<I>(v, what);
        assigned<C>(self).*member = x;
      },
      doc);
}

/// A bool member that takes True, False or a NumPy bool only (TypeError "<Class>.<name> must be
/// True or False, got ..."): pybind11's caster took anything with a truth value, so
/// `integrator.mis = "no"` or `= 0.5` turned MIS on without a word.
template <class C>
void bool_property(py::class_<C>& c, const char* name, bool C::*member, const char* doc = "") {
  const std::string what = c.attr("__name__").template cast<std::string>() + "." + name;
  c.def_property(
      name, [member](const C& o) { return o.*member; },
      [member, what](py::handle self, py::object v) {
        assigned<C>(self).*member = flag_value(v, what);
      },
      doc);
}

/// A property holding text from files (FileText: a file name, a name in an MTL file); `Text`
/// PathText for a path, which takes an os.PathLike too.
template <class Text = FileText, class C>
void text_property(py::class_<C>& c, const char* name, std::string C::*member,
                   const char* doc = "") {
  c.def_property(
      name, [member](const C& o) { return FileText{o.*member}; },
      [member](py::handle self, const Text& v) { assigned<C>(self).*member = v.bytes; }, doc);
}

/// A property holding an enum by its registry name.
template <class C, class E>
void enum_property(py::class_<C>& c, const char* name, E C::*member) {
  c.def_property(
      name, [member](const C& o) { return std::string(enum_name(o.*member)); },
      [member, name](py::handle self, py::handle v) {
        const E x = parse_enum<E>(enum_text(v, name));
        assigned<C>(self).*member = x;
      });
}

/// int[3] members (triangle indices) as tuples.
template <class C>
void triple_property(py::class_<C>& c, const char* name, int (C::*member)[3]) {
  c.def_property(
      name,
      [member](const C& o) {
        return py::make_tuple((o.*member)[0], (o.*member)[1], (o.*member)[2]);
      },
      [member](py::handle self, py::sequence s) {
        if (s.size() != 3)
          throw py::value_error("expected 3 indices, got " + py::repr(s).cast<std::string>());
        int v[3];
        for (int i = 0; i < 3; ++i) {
          const std::string what = "index " + std::to_string(i);
          IntValue x;
          try {  // Python and NumPy integers (operator.index), not booleans
            x = int_value(IntArg{s[static_cast<std::size_t>(i)]}, what, /*allow_bool=*/false);
          } catch (const py::type_error&) {
            throw py::type_error("expected 3 integer indices, got " +
                                 py::repr(s).cast<std::string>());
          }
          const std::optional<int> n = narrowed<int>(x);
          if (!n) throw py::value_error(what + " out of range: " + int_repr(x.index));
          v[i] = *n;
        }
        C& o = assigned<C>(self);
        for (int i = 0; i < 3; ++i) (o.*member)[i] = v[i];
      });
}

/// A list of glm vectors as an (N, D) float64 array (a read-only copy).
template <class V>
py::array_t<double> vectors_array(const std::vector<V>& v) {
  return copy_rows(v.empty() ? nullptr : &v[0].x, v.size(), V::length());
}

/// An (N, D) array of numbers (or an empty sequence) as a list of glm vectors; TypeError or
/// ValueError naming `name` otherwise.
template <class V>
std::vector<V> vectors_from(py::handle value, const std::string& name) {
  constexpr int D = V::length();
  require_numbers(value, name, sizeof(double) + sizeof(typename V::value_type));
  auto a = array_or_null<CArray<double>>(value);
  if (!a)
    throw py::type_error(name + ": expected an array of shape (N, " + std::to_string(D) + ")");
  if (!(a.ndim() == 2 && a.shape(1) == D) && !(a.ndim() == 1 && a.shape(0) == 0))
    throw py::value_error(name + ": expected an array of shape (N, " + std::to_string(D) + ")");
  std::vector<V> out(static_cast<std::size_t>(a.ndim() == 2 ? a.shape(0) : 0));
  for (std::size_t i = 0; i < out.size(); ++i)
    for (int k = 0; k < D; ++k) out[i][k] = a.at(static_cast<py::ssize_t>(i), k);
  return out;
}

/// A list of glm vectors as an (N, D) float64 array: a read-only copy (assign the attribute to
/// change it).
template <class V>
void vector_array_property(py::class_<Scene>& c, const char* name, std::vector<V> Scene::*member) {
  constexpr int D = V::length();
  c.def_property(
      name, [member](const Scene& s) { return vectors_array(s.*member); },
      [member, name](py::handle self, py::handle value) {
        std::vector<V> x = vectors_from<V>(value, name);
        assigned<Scene>(self).*member = std::move(x);
      },
      (std::string(name) + ": an (N, " + std::to_string(D) +
       ") float64 array (a read-only copy; assign to change)")
          .c_str());
}

/// A texture's texels as an (H, W, 4) float32 array: a read-only copy (a view of t.rgba
/// dangled once the setter or the scene's texture list reallocated it: reading freed memory,
/// a crash).
py::array_t<float> texture_texels(const Texture& t) {
  py::array_t<float> a({py::ssize_t(t.height), py::ssize_t(t.width), py::ssize_t(4)});
  if (!t.rgba.empty())
    std::copy(t.rgba.begin(), t.rgba.end(), static_cast<float*>(a.mutable_data()));
  a.attr("flags").attr("writeable") = false;
  return a;
}

/// Sets a texture's texels, width and height from an (H, W, 4) array of numbers (H, W >= 1).
void set_texture_texels(py::handle self, py::handle value) {
  require_numbers(value, "rgba", 2 * sizeof(float));
  auto a = array_or_null<CArray<float>>(value);
  if (!a || a.ndim() != 3 || a.shape(2) != 4 || a.shape(0) < 1 || a.shape(1) < 1)
    throw py::value_error("rgba: expected an array of shape (H, W, 4)");
  // (a side past 2^31 wrapped to a negative width)
  if (a.shape(0) > std::numeric_limits<int>::max() || a.shape(1) > std::numeric_limits<int>::max())
    throw py::value_error("rgba: a side of " + std::to_string(std::max(a.shape(0), a.shape(1))) +
                          " texels is more than a texture can have");
  Texture& t = assigned<Texture>(self);  // after the conversion
  t.height = static_cast<int>(a.shape(0));
  t.width = static_cast<int>(a.shape(1));
  t.rgba.assign(a.data(), a.data() + a.size());
}

// ------------------------------------------------------------------------------------------
// Pickling (py::pickle; copy.copy and copy.deepcopy use it too). A value's state is plain Python
// data: a dict of its fields by their attribute names (numbers, strings, tuples, enums by their
// names, nested structs by their states), read back by StateReader (state.hpp). A scene's spheres
// and triangles are columns (NumPy arrays named by the fields), its vertex lists the (N, 3) /
// (N, 2) arrays of its attributes and a texture's texels its (H, W, 4) float32 array, so that a
// scene of millions of triangles pickles without a Python object per triangle. Indices are not
// checked against the lists, as when the fields are set from Python: a render validates the
// scene.
// ------------------------------------------------------------------------------------------

py::tuple vec_state(const glm::dvec3& v) { return py::make_tuple(v.x, v.y, v.z); }
py::tuple vec_state(const glm::dvec2& v) { return py::make_tuple(v.x, v.y); }
py::tuple triple_state(const int (&v)[3]) { return py::make_tuple(v[0], v[1], v[2]); }

/// Each pickled class's state (`state`) and the value a state gives back (`from`, ValueError
/// naming `where` for a bad state).
template <class T>
struct Pickled;

template <>
struct Pickled<Camera> {
  static py::dict state(const Camera& c) {
    py::dict d;
    d["position"] = vec_state(c.position);
    d["look_at"] = vec_state(c.look_at);
    d["up"] = vec_state(c.up);
    d["fov_degrees"] = c.fov_degrees;
    d["roll_degrees"] = c.roll_degrees;
    d["aperture"] = c.aperture;
    d["focus_distance"] = c.focus_distance;
    return d;
  }
  static Camera from(py::handle state, const std::string& where) {
    StateReader r(state, where);
    Camera c;
    c.position = r.vec<glm::dvec3>("position");
    c.look_at = r.vec<glm::dvec3>("look_at");
    c.up = r.vec<glm::dvec3>("up");
    c.fov_degrees = r.number("fov_degrees");
    c.roll_degrees = r.number("roll_degrees");
    c.aperture = r.number("aperture");
    c.focus_distance = r.number("focus_distance");
    r.finish();
    return c;
  }
};

template <>
struct Pickled<Filter> {
  static py::dict state(const Filter& f) {
    py::dict d;
    d["type"] = enum_name(f.type);
    d["radius"] = f.radius;
    return d;
  }
  static Filter from(py::handle state, const std::string& where) {
    StateReader r(state, where);
    Filter f;
    f.type = r.name<FilterType>("type");
    f.radius = r.number("radius");
    r.finish();
    return f;
  }
};

template <>
struct Pickled<Film> {
  static py::dict state(const Film& f) {
    py::dict d;
    d["width"] = f.width;
    d["height"] = f.height;
    d["filter"] = Pickled<Filter>::state(f.filter);
    d["transfer"] = enum_name(f.transfer);
    d["gamma"] = f.gamma;
    d["exposure"] = f.exposure;
    d["tonemap"] = enum_name(f.tonemap);
    return d;
  }
  static Film from(py::handle state, const std::string& where) {
    StateReader r(state, where);
    Film f;
    f.width = r.integer<int>("width");
    f.height = r.integer<int>("height");
    f.filter = r.nested("filter", &Pickled<Filter>::from);
    f.transfer = r.name<Transfer>("transfer");
    f.gamma = r.number("gamma");
    f.exposure = r.number("exposure");
    f.tonemap = r.name<ToneMap>("tonemap");
    r.finish();
    return f;
  }
};

template <>
struct Pickled<Integrator> {
  static py::dict state(const Integrator& i) {
    py::dict d;
    d["type"] = enum_name(i.type);
    d["max_depth"] = i.max_depth;
    d["rr_depth"] = i.rr_depth;
    d["spp"] = i.spp;
    d["seed"] = i.seed;
    d["ao_distance"] = i.ao_distance;
    d["mis"] = i.mis;
    d["sampler"] = enum_name(i.sampler);
    d["clamp"] = i.clamp;
    d["caustics"] = i.caustics;
    d["dielectric_splits"] = i.dielectric_splits;
    return d;
  }
  static Integrator from(py::handle state, const std::string& where) {
    StateReader r(state, where);
    Integrator i;
    i.type = r.name<IntegratorType>("type");
    i.max_depth = r.integer<int>("max_depth");
    i.rr_depth = r.integer<int>("rr_depth");
    i.spp = r.integer<int>("spp");
    i.seed = r.integer<std::uint32_t>("seed");
    i.ao_distance = r.number("ao_distance");
    i.mis = r.boolean("mis");
    i.sampler = r.name<SamplerType>("sampler");
    i.clamp = r.number("clamp");
    i.caustics = r.boolean("caustics");
    i.dielectric_splits = r.integer<int>("dielectric_splits");
    r.finish();
    return i;
  }
};

template <>
struct Pickled<Material> {
  static py::dict state(const Material& m) {
    py::dict d;
    d["name"] = file_text(m.name);
    d["type"] = enum_name(m.type);
    d["albedo"] = vec_state(m.albedo);
    d["albedo_texture"] = m.albedo_texture;
    d["albedo_wrap_u"] = enum_name(m.albedo_wrap_u);
    d["albedo_wrap_v"] = enum_name(m.albedo_wrap_v);
    d["albedo_uv_scale"] = vec_state(m.albedo_uv_scale);
    d["albedo_uv_offset"] = vec_state(m.albedo_uv_offset);
    d["emission"] = vec_state(m.emission);
    d["specular"] = vec_state(m.specular);
    d["ior"] = m.ior;
    d["roughness"] = m.roughness;
    return d;
  }
  static Material from(py::handle state, const std::string& where) {
    StateReader r(state, where);
    Material m;
    m.name = r.text("name");
    m.type = r.name<MaterialType>("type");
    m.albedo = r.vec<glm::dvec3>("albedo");
    m.albedo_texture = r.integer<int>("albedo_texture");
    m.albedo_wrap_u = r.name<TextureWrap>("albedo_wrap_u");
    m.albedo_wrap_v = r.name<TextureWrap>("albedo_wrap_v");
    m.albedo_uv_scale = r.vec<glm::dvec2>("albedo_uv_scale");
    m.albedo_uv_offset = r.vec<glm::dvec2>("albedo_uv_offset");
    m.emission = r.vec<glm::dvec3>("emission");
    m.specular = r.vec<glm::dvec3>("specular");
    m.ior = r.number("ior");
    m.roughness = r.number("roughness");
    r.finish();
    return m;
  }
};

template <>
struct Pickled<Sphere> {
  static py::dict state(const Sphere& s) {
    py::dict d;
    d["center"] = vec_state(s.center);
    d["radius"] = s.radius;
    d["material"] = s.material;
    return d;
  }
  static Sphere from(py::handle state, const std::string& where) {
    StateReader r(state, where);
    Sphere s;
    s.center = r.vec<glm::dvec3>("center");
    s.radius = r.number("radius");
    s.material = r.integer<int>("material");
    r.finish();
    return s;
  }
};

template <>
struct Pickled<Triangle> {
  static py::dict state(const Triangle& t) {
    py::dict d;
    d["v"] = triple_state(t.v);
    d["n"] = triple_state(t.n);
    d["uv"] = triple_state(t.uv);
    d["material"] = t.material;
    return d;
  }
  static Triangle from(py::handle state, const std::string& where) {
    StateReader r(state, where);
    Triangle t;
    r.triple("v", t.v);
    r.triple("n", t.n);
    r.triple("uv", t.uv);
    t.material = r.integer<int>("material");
    r.finish();
    return t;
  }
};

template <>
struct Pickled<Light> {
  static py::dict state(const Light& l) {
    py::dict d;
    d["type"] = enum_name(l.type);
    d["position"] = vec_state(l.position);
    d["intensity"] = vec_state(l.intensity);
    d["radiance"] = vec_state(l.radiance);
    d["texture"] = l.texture;
    return d;
  }
  static Light from(py::handle state, const std::string& where) {
    StateReader r(state, where);
    Light l;
    l.type = r.name<LightType>("type");
    l.position = r.vec<glm::dvec3>("position");
    l.intensity = r.vec<glm::dvec3>("intensity");
    l.radiance = r.vec<glm::dvec3>("radiance");
    l.texture = r.integer<int>("texture");
    r.finish();
    return l;
  }
};

template <>
struct Pickled<Texture> {
  static py::dict state(const Texture& t) {
    py::dict d;
    d["path"] = file_text(t.path);
    d["width"] = t.width;
    d["height"] = t.height;
    d["rgba"] = texture_texels(t);
    return d;
  }
  static Texture from(py::handle state, const std::string& where) {
    StateReader r(state, where);
    Texture t;
    t.path = r.text("path");
    t.width = r.integer<int>("width");
    t.height = r.integer<int>("height");
    // a texture has texels (the rgba setter's H, W >= 1), or none: Texture() is 0 x 0
    if (t.width < 0 || t.height < 0 || (t.width == 0) != (t.height == 0))
      r.fail("width", "a texture of " + std::to_string(t.width) + " x " + std::to_string(t.height) +
                          " texels");
    py::array_t<float> rgba = r.array<float>("rgba", {t.height, t.width, 4});
    t.rgba.assign(rgba.data(), rgba.data() + rgba.size());
    r.finish();
    return t;
  }
};

template <>
struct Pickled<ShapeEntry> {
  static py::dict state(const ShapeEntry& e) {
    py::dict d;
    d["type"] = enum_name(e.type);
    d["file"] = file_text(e.file);
    d["first"] = e.first;
    d["count"] = e.count;
    py::list libraries;
    for (const std::string& l : e.libraries) libraries.append(file_text(l));
    d["libraries"] = libraries;
    return d;
  }
  static ShapeEntry from(py::handle state, const std::string& where) {
    StateReader r(state, where);
    ShapeEntry e;
    e.type = r.name<ShapeType>("type");
    e.file = r.text("file");
    e.first = r.integer<std::size_t>("first");
    e.count = r.integer<std::size_t>("count");
    e.libraries = r.list<std::string>("libraries", [](py::handle v, const std::string& at) {
      std::string text;
      if (!py::isinstance<py::str>(v))
        throw py::value_error("cannot unpickle " + at + ": expected a str, got " +
                              py::type::handle_of(v).attr("__name__").cast<std::string>());
      if (!file_bytes(v, text))
        throw py::value_error("cannot unpickle " + at +
                              ": a str that is not valid Unicode (a lone surrogate)");
      return text;
    });
    r.finish();
    return e;
  }
};

/// The bound lists (MaterialList, ...): a list of their elements' states.
template <class T>
struct Pickled<std::vector<T>> {
  static py::list state(const std::vector<T>& v) {
    py::list l;
    for (const T& e : v) l.append(Pickled<T>::state(e));
    return l;
  }
  static std::vector<T> from(py::handle state, const std::string& where) {
    return read_list<T>(state, where, &Pickled<T>::from);
  }
};

/// Vec3 and Vec2: a tuple of their numbers.
template <int N>
struct Pickled<glm::vec<N, double>> {
  using V = glm::vec<N, double>;
  static py::tuple state(const V& v) {
    py::list l;
    for (int i = 0; i < N; ++i) l.append(v[i]);
    return py::tuple(l);
  }
  static V from(py::handle state, const std::string& where) {
    if (!py::isinstance<py::tuple>(state))
      throw py::value_error("cannot unpickle " + where + ": expected a tuple, got " +
                            py::repr(state).cast<std::string>());
    try {
      return to_vec<V>(state);
    } catch (const py::builtin_exception& e) {
      throw py::value_error("cannot unpickle " + where + ": " + e.what());
    }
  }
};

template <>
struct Pickled<Scene> {
  static py::dict state(const Scene& s) {
    const auto n_spheres = static_cast<py::ssize_t>(s.spheres.size());
    py::array_t<double> center({n_spheres, py::ssize_t(3)}), radius(n_spheres);
    py::array_t<int> sphere_material(n_spheres);
    for (py::ssize_t i = 0; i < n_spheres; ++i) {
      const Sphere& sp = s.spheres[static_cast<std::size_t>(i)];
      for (int k = 0; k < 3; ++k) center.mutable_at(i, k) = sp.center[k];
      radius.mutable_at(i) = sp.radius;
      sphere_material.mutable_at(i) = sp.material;
    }
    py::dict spheres;
    spheres["center"] = center;
    spheres["radius"] = radius;
    spheres["material"] = sphere_material;

    const auto n_triangles = static_cast<py::ssize_t>(s.triangles.size());
    py::array_t<int> v({n_triangles, py::ssize_t(3)}), n({n_triangles, py::ssize_t(3)}),
        uv({n_triangles, py::ssize_t(3)}), triangle_material(n_triangles);
    for (py::ssize_t i = 0; i < n_triangles; ++i) {
      const Triangle& t = s.triangles[static_cast<std::size_t>(i)];
      for (int k = 0; k < 3; ++k) {
        v.mutable_at(i, k) = t.v[k];
        n.mutable_at(i, k) = t.n[k];
        uv.mutable_at(i, k) = t.uv[k];
      }
      triangle_material.mutable_at(i) = t.material;
    }
    py::dict triangles;
    triangles["v"] = v;
    triangles["n"] = n;
    triangles["uv"] = uv;
    triangles["material"] = triangle_material;

    py::dict d;
    d["path"] = file_text(s.path);
    d["camera"] = Pickled<Camera>::state(s.camera);
    d["film"] = Pickled<Film>::state(s.film);
    d["integrator"] = Pickled<Integrator>::state(s.integrator);
    d["materials"] = Pickled<std::vector<Material>>::state(s.materials);
    d["spheres"] = spheres;
    d["positions"] = vectors_array(s.positions);
    d["normals"] = vectors_array(s.normals);
    d["uvs"] = vectors_array(s.uvs);
    d["triangles"] = triangles;
    d["lights"] = Pickled<std::vector<Light>>::state(s.lights);
    d["textures"] = Pickled<std::vector<Texture>>::state(s.textures);
    d["shapes"] = Pickled<std::vector<ShapeEntry>>::state(s.shapes);
    return d;
  }

  static Scene from(py::handle state, const std::string& where) {
    StateReader r(state, where);
    Scene s;
    s.path = r.text("path");
    s.camera = r.nested("camera", &Pickled<Camera>::from);
    s.film = r.nested("film", &Pickled<Film>::from);
    s.integrator = r.nested("integrator", &Pickled<Integrator>::from);
    s.materials = r.list<Material>("materials", &Pickled<Material>::from);
    {
      StateReader c(r.get("spheres"), r.path("spheres"));
      auto center = c.array<double>("center", {-1, 3});
      const py::ssize_t count = center.shape(0);
      auto radius = c.array<double>("radius", {count});
      auto material = c.array<int>("material", {count});
      c.finish();
      s.spheres.resize(static_cast<std::size_t>(count));
      for (py::ssize_t i = 0; i < count; ++i) {
        Sphere& sp = s.spheres[static_cast<std::size_t>(i)];
        sp.center = {center.at(i, 0), center.at(i, 1), center.at(i, 2)};
        sp.radius = radius.at(i);
        sp.material = material.at(i);
      }
    }
    s.positions = vertices<glm::dvec3>(r, "positions");
    s.normals = vertices<glm::dvec3>(r, "normals");
    s.uvs = vertices<glm::dvec2>(r, "uvs");
    {
      StateReader c(r.get("triangles"), r.path("triangles"));
      auto v = c.array<int>("v", {-1, 3});
      const py::ssize_t count = v.shape(0);
      auto n = c.array<int>("n", {count, 3});
      auto uv = c.array<int>("uv", {count, 3});
      auto material = c.array<int>("material", {count});
      c.finish();
      s.triangles.resize(static_cast<std::size_t>(count));
      for (py::ssize_t i = 0; i < count; ++i) {
        Triangle& t = s.triangles[static_cast<std::size_t>(i)];
        for (int k = 0; k < 3; ++k) {
          t.v[k] = v.at(i, k);
          t.n[k] = n.at(i, k);
          t.uv[k] = uv.at(i, k);
        }
        t.material = material.at(i);
      }
    }
    s.lights = r.list<Light>("lights", &Pickled<Light>::from);
    s.textures = r.list<Texture>("textures", &Pickled<Texture>::from);
    s.shapes = r.list<ShapeEntry>("shapes", &Pickled<ShapeEntry>::from);
    r.finish();
    return s;
  }

 private:
  /// An (N, D) float64 array as a list of vectors.
  template <class V>
  static std::vector<V> vertices(StateReader& r, const char* key) {
    constexpr int D = V::length();
    auto a = r.array<double>(key, {-1, D});
    std::vector<V> out(static_cast<std::size_t>(a.shape(0)));
    for (std::size_t i = 0; i < out.size(); ++i)
      for (int k = 0; k < D; ++k) out[i][k] = a.at(static_cast<py::ssize_t>(i), k);
    return out;
  }
};

/// Pickling for a bound class: its state (Pickled<T>), read back with errors naming the class.
template <class T, class... Options>
void def_pickle(py::class_<T, Options...>& c) {
  const std::string where = "lucent." + c.attr("__name__").template cast<std::string>();
  c.def(py::pickle([](const T& v) -> py::object { return Pickled<T>::state(v); },
                   [where](const py::object& state) { return Pickled<T>::from(state, where); }));
}

/// Python value -> JSON, with the JSON path of the first value JSON cannot hold.
nlohmann::json to_json(py::handle o, const std::string& path, const std::string& label,
                       int depth = 0) {
  auto fail = [&](const std::string& what) -> nlohmann::json {
    throw Error(label + ": " + (path.empty() ? "/" : path) + ": " + what);
  };
  // as deep as a scene file may nest (json_guard.hpp); a dict that contains itself recursed
  // until the C stack overflowed
  if (depth > scene_detail::kMaxJsonDepth)
    return fail("nested deeper than " + std::to_string(scene_detail::kMaxJsonDepth) +
                " levels (a value that contains itself?)");
  if (o.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(o)) return o.cast<bool>();
  if (py::isinstance<py::int_>(o)) {
    // as the JSON text of the number would be parsed: up to 2^64 - 1 an integer, beyond it a
    // float, whose range error the reader gives as for a file (it said "integer out of range:
    // 9223372036854775808", where a file said "must be in [1, 16384], got ...")
    py::int_ i = py::reinterpret_borrow<py::int_>(o);
    const int bits = i.attr("bit_length")().cast<int>();
    if (bits <= 63) return o.cast<long long>();
    if (bits == 64 && o.attr("__gt__")(py::int_(0)).cast<bool>())
      return o.cast<unsigned long long>();
    if (bits == 64 &&
        o.attr("__eq__")(py::int_(std::numeric_limits<long long>::min())).cast<bool>())
      return std::numeric_limits<long long>::min();  // (-2^63: a long long, as a file's)
    try {
      return py::float_(py::reinterpret_borrow<py::object>(o)).cast<double>();
    } catch (py::error_already_set&) {  // (beyond a double: OverflowError)
      // its digits named by their count (a line of 401 digits; past sys.get_int_max_str_digits,
      // 4300, str() raised its own ValueError naming no place)
      return fail("integer out of range (not a finite double): an integer of about " +
                  std::to_string(static_cast<int>(bits * 0.30102999566398120) + 1) + " digits");
    }
  }
  if (py::isinstance<py::float_>(o)) {
    double d = o.cast<double>();
    if (!std::isfinite(d)) return fail("must be a finite number, got " + format_number(d));
    return d;
  }
  // JSON text is UTF-8: a lone surrogate (a file name from os.listdir, "w\udce8") has none
  const auto not_unicode = [](py::handle s) {
    return "that is not valid Unicode (a lone surrogate): " + py::repr(s).cast<std::string>();
  };
  if (py::isinstance<py::str>(o)) {
    std::string text;
    if (!utf8_text(o, text)) return fail("a str " + not_unicode(o));
    return text;
  }
  if (py::isinstance<py::dict>(o)) {
    nlohmann::json j = nlohmann::json::object();
    try {  // (a part built when an exception leaves is freed without allocating: release_json)
      for (auto item : py::reinterpret_borrow<py::dict>(o)) {
        if (!py::isinstance<py::str>(item.first))
          return fail("keys must be strings, got " + py::repr(item.first).cast<std::string>());
        std::string key;
        if (!utf8_text(item.first, key)) return fail("a key " + not_unicode(item.first));
        j[key] =
            to_json(item.second, path + "/" + scene_detail::pointer_key(key), label, depth + 1);
      }
    } catch (...) {
      scene_detail::release_json(j);
      throw;
    }
    return j;
  }
  if (py::hasattr(o, "tolist") && !py::isinstance<py::str>(o))  // NumPy arrays and scalars
    return to_json(o.attr("tolist")(), path, label, depth + 1);
  if (py::isinstance<py::list>(o) || py::isinstance<py::tuple>(o) ||
      py::isinstance<glm::dvec3>(o) || py::isinstance<glm::dvec2>(o)) {
    nlohmann::json j = nlohmann::json::array();
    std::size_t i = 0;
    try {
      for (auto item : o)
        j.push_back(to_json(item, path + "/" + std::to_string(i++), label, depth + 1));
    } catch (...) {
      scene_detail::release_json(j);
      throw;
    }
    return j;
  }
  return fail("cannot be written as JSON: " + py::repr(o).cast<std::string>());
}

/// Runs `load` without the GIL, its warnings sent to `on_warning` (warnings.warn when None).
template <class F>
auto with_warnings(py::object on_warning, F&& load) {
  check_callable(on_warning, "on_warning");
  auto errors = std::make_shared<CallbackErrors>();
  WarningSink sink = python_warning_sink(SharedObject(std::move(on_warning)), errors);
  std::optional<decltype(load())> out;
  {
    ReleaseGil release;
    scene_detail::ScopedWarningSink scoped(sink);
    out.emplace(load());
  }
  errors->rethrow();
  return std::move(*out);
}

/// What `lucent info` prints, as a dict: the packed scene's counts, its BVH and the kernel's
/// feature defines and build options for these settings. Needs no device.
py::dict scene_info(const Scene& scene, const TextArg& precision, const FlagArg& fast_math_arg,
                    const FlagArg& specialize_arg, py::object on_warning) {
  RenderOptions options;
  options.precision = parse_enum<Precision>(text_argument(precision, "precision"));
  options.fast_math = flag_argument(fast_math_arg, "fast_math");
  options.specialize = flag_argument(specialize_arg, "specialize");
  const bool specialize = options.specialize;
  Scene copy = scene;
  auto packed = with_warnings(std::move(on_warning), [&] {
    scene_detail::validate_scene(copy);  // fields set from Python may index past the lists
    render_detail::check_packing_host_memory(copy, 2);  // (the caller's scene and this copy)
    render_detail::PackedScene p = render_detail::pack_scene(copy);
    // what a render of it says, as `lucent info` does
    for (const std::string& note : scene_detail::energy_gain_notes(copy)) scene_detail::warn(note);
    for (const std::string& note :
         render_detail::packing_notes(copy, p, options.precision == Precision::Float))
      scene_detail::warn(note);
    return p;
  });
  py::dict lights;
  for (const auto& [type, name] : enum_names<LightType>().entries) lights[name] = 0;
  for (const lc_light& l : packed.lights) {
    py::str name(enum_name(static_cast<LightType>(l.type)));
    lights[name] = lights[name].cast<int>() + 1;
  }
  const bvh::BuildStats& b = packed.bvh_stats;
  py::dict bvh;
  bvh["seconds"] = b.seconds;
  bvh["primitives"] = b.primitives;
  bvh["binary_nodes"] = b.binary_nodes;
  bvh["nodes"] = b.nodes;
  bvh["width"] = LC_BVH_WIDTH;
  bvh["bytes"] = packed.nodes.size() * sizeof(lc_bvh_node);
  bvh["leaves"] = b.leaves;
  bvh["mean_leaf_size"] = b.mean_leaf_size;
  bvh["max_leaf_size"] = b.max_leaf_size;
  bvh["binary_max_depth"] = b.binary_max_depth;
  bvh["max_depth"] = b.max_depth;
  bvh["sah_cost"] = b.sah_cost;
  std::uint64_t texel_bytes = 0;  // (a count, an int as the others: it was a float)
  for (const Texture& t : copy.textures) texel_bytes += std::uint64_t(t.width) * t.height * 16;
  std::string defines = render_detail::feature_defines(copy, packed, specialize);
  py::list define_list;
  std::istringstream words(defines);
  for (std::string w; words >> w;)
    if (w != "-D") define_list.append(w);
  py::dict d;
  d["triangles"] = copy.triangles.size();
  d["skipped_triangles"] = packed.skipped_triangles;
  d["spheres"] = copy.spheres.size();
  d["vertices"] = copy.positions.size();
  d["materials"] = copy.materials.size();
  d["textures"] = copy.textures.size();
  d["texture_bytes"] = texel_bytes;
  d["lights"] = lights;
  d["bvh"] = bvh;
  d["feature_defines"] = define_list;
  d["precision"] = precision_name(options.precision);
  d["fast_math"] = options.fast_math;
  d["build_options"] = render_detail::build_options(copy, packed, options);
  // what a session's set_scene checks before rendering on a CPU device (the scene held twice:
  // the application's and the session's copy), as `lucent info` prints it
  py::list parts;
  const std::vector<render_detail::MemoryPart> estimate =
      render_detail::estimate_host_memory(copy, {render_detail::DeviceLimits::cpu()});
  for (const render_detail::MemoryPart& p : estimate) {
    py::dict part;
    part["what"] = p.what;
    part["bytes"] = p.bytes;
    parts.append(part);
  }
  py::dict memory;
  memory["bytes"] = render_detail::total_bytes(estimate);
  memory["limit_bytes"] = render_detail::host_memory_allowed();
  memory["parts"] = parts;
  d["host_memory"] = memory;
  return d;
}

/// `<lucent.Name field=repr, ...>` for C: each field read through its Python property, so the
/// repr shows what reading it gives (Vec3(0, 0, 5), 'box').
template <class C>
void fields_repr(py::class_<C>& c, std::vector<const char*> fields) {
  c.def("__repr__", [name = py::str(c.attr("__name__")).cast<std::string>(),
                     fields = std::move(fields)](py::handle self) {
    std::string s = "<lucent." + name;
    for (std::size_t i = 0; i < fields.size(); ++i)
      s += std::string(i ? ", " : " ") + fields[i] + "=" +
           py::repr(self.attr(fields[i])).cast<std::string>();
    return s + ">";
  });
}

/// copy.copy (memo nullptr) or copy.deepcopy of a Scene: the C++ copy, of the object's own class
/// with its attributes (shallow or deep) for a Python subclass.
py::object copy_of_scene(py::handle self, py::dict* memo) {
  if (reinterpret_cast<PyObject*>(Py_TYPE(self.ptr())) == py::type::of<Scene>().ptr())
    return py::cast(Scene(self.cast<const Scene&>()));
  py::handle cls = py::type::handle_of(self);
  py::object obj = cls.attr("__new__")(cls);
  obj.attr("__setstate__")(self.attr("__getstate__")());
  py::object attributes = py::getattr(self, "__dict__", py::none());
  if (!attributes.is_none()) {
    if (memo) {
      // the copy first, so that attributes referring back to the object refer to it (a second
      // copy was made: the review's find)
      (*memo)[py::int_(reinterpret_cast<std::uintptr_t>(self.ptr()))] = obj;
      attributes = py::module_::import("copy").attr("deepcopy")(attributes, *memo);
    }
    obj.attr("__dict__").attr("update")(attributes);
  }
  return obj;
}

std::string scene_repr(const Scene& s) {
  return "<lucent.Scene " + py::repr(file_text(s.path)).cast<std::string>() + ": " +
         std::to_string(s.film.width) + "x" + std::to_string(s.film.height) + ", " +
         enum_name(s.integrator.type) + ", " + std::to_string(s.materials.size()) + " materials, " +
         std::to_string(s.spheres.size()) + " spheres, " + std::to_string(s.triangles.size()) +
         " triangles, " + std::to_string(s.lights.size()) + " lights, " +
         std::to_string(s.textures.size()) + " textures>";
}

}  // namespace

void bind_scene(py::module_& m) {
  auto vec3 = bind_vector_type<glm::dvec3>(m, "Vec3");
  auto vec2 = bind_vector_type<glm::dvec2>(m, "Vec2");
  def_pickle(vec3);
  def_pickle(vec2);

  py::class_<Camera> camera(m, "Camera", "Pinhole or thin-lens camera (README, \"camera\").");
  camera.def(py::init<>());
  number_property(camera, "fov_degrees", &Camera::fov_degrees, "vertical field of view");
  number_property(camera, "roll_degrees", &Camera::roll_degrees);
  number_property(camera, "aperture", &Camera::aperture, "thin-lens radius (0: pinhole)");
  number_property(camera, "focus_distance", &Camera::focus_distance, "0: the distance to look_at");
  vec_property(camera, "position", &Camera::position);
  vec_property(camera, "look_at", &Camera::look_at);
  vec_property(camera, "up", &Camera::up);
  def_pickle(camera);

  py::class_<Filter> filter(
      m, "Filter",
      "Pixel filter: type (FILTER_TYPES) and radius in pixels. Filter() is a box of 0.5, and "
      "setting type keeps the radius; Filter(type) has the type's default radius, as a scene "
      "file gives it (tent and gaussian 1.5).");
  filter.def(py::init<>())
      .def(py::init([](py::handle type) {
             Filter f;
             f.type = parse_enum<FilterType>(enum_text(type, "type"));
             f.radius = lucent::default_filter_radius(f.type);
             return f;
           }),
           py::arg("type"));
  number_property(filter, "radius", &Filter::radius);
  enum_property(filter, "type", &Filter::type);
  def_pickle(filter);

  py::class_<Film> film(m, "Film", "Image size, pixel filter and display settings.");
  film.def(py::init<>()).def_readwrite("filter", &Film::filter);
  number_property(film, "gamma", &Film::gamma);
  number_property(film, "exposure", &Film::exposure);
  int_property(film, "width", &Film::width);
  int_property(film, "height", &Film::height);
  enum_property(film, "transfer", &Film::transfer);
  enum_property(film, "tonemap", &Film::tonemap);
  def_pickle(film);

  py::class_<Integrator> integrator(m, "Integrator",
                                    "type: an integrator or AOV name (INTEGRATORS).");
  integrator.def(py::init<>());
  number_property(integrator, "ao_distance", &Integrator::ao_distance);
  number_property(integrator, "clamp", &Integrator::clamp,
                  "the largest sample contribution (0: off); biased, lower variance");
  bool_property(integrator, "mis", &Integrator::mis);
  bool_property(integrator, "caustics", &Integrator::caustics,
                "path: caustic paths by light tracing (pinhole and thin-lens cameras)");
  int_property(integrator, "max_depth", &Integrator::max_depth);
  int_property(integrator, "rr_depth", &Integrator::rr_depth);
  int_property(integrator, "spp", &Integrator::spp);
  int_property(integrator, "seed", &Integrator::seed);
  int_property(integrator, "dielectric_splits", &Integrator::dielectric_splits,
               "path: smooth-glass vertices per camera path at which both lobes are "
               "followed (0 .. 4; default 2; 0: off)");
  enum_property(integrator, "type", &Integrator::type);
  enum_property(integrator, "sampler", &Integrator::sampler);
  def_pickle(integrator);

  py::class_<Material> material(
      m, "Material",
      "type: MATERIAL_TYPES; README, \"materials\". specular is the scene format's reflectance "
      "(mirror, diffuse_mirror) and tint (dielectric, rough_dielectric). Material(type, name='') "
      "has the type's defaults of the scene format (a conductor's specular 0.9, a "
      "diffuse_mirror's reflectance 0.2); Material() has albedo 0.8, specular 1, ior 1.5, "
      "roughness 0.1, and setting its type changes nothing else.");
  material.def(py::init<>())
      .def(py::init([](py::handle type, const FileText& name) {
             return material_of_type(parse_enum<MaterialType>(enum_text(type, "type")), name.bytes);
           }),
           py::arg("type"), py::arg("name") = FileText{})
      .def_property_readonly("emissive", &Material::emissive)
      .def("__repr__", [](const Material& mt) {
        return "<lucent.Material " + py::repr(file_text(mt.name)).cast<std::string>() + " " +
               enum_name(mt.type) + ">";
      });
  number_property(material, "ior", &Material::ior);
  number_property(material, "roughness", &Material::roughness);
  int_property(material, "albedo_texture", &Material::albedo_texture,
               "index into Scene.textures or -1");
  // how the albedo texture covers the surface: read at uv * albedo_uv_scale + albedo_uv_offset,
  // wrapped in u and v by TEXTURE_WRAPS (the scene format's "wrap", "uv_scale", "uv_offset")
  enum_property(material, "albedo_wrap_u", &Material::albedo_wrap_u);
  enum_property(material, "albedo_wrap_v", &Material::albedo_wrap_v);
  vec_property(material, "albedo_uv_scale", &Material::albedo_uv_scale,
               "the albedo texture is read at uv * albedo_uv_scale + albedo_uv_offset");
  vec_property(material, "albedo_uv_offset", &Material::albedo_uv_offset);
  text_property(material, "name", &Material::name);
  vec_property(material, "albedo", &Material::albedo);
  vec_property(material, "emission", &Material::emission);
  vec_property(material, "specular", &Material::specular);
  enum_property(material, "type", &Material::type);
  def_pickle(material);

  py::class_<Sphere> sphere(m, "Sphere");
  sphere.def(py::init<>())
      .def(py::init([](py::handle center, double radius, const IntArg& material) {
             return Sphere{to_vec<glm::dvec3>(center), radius,
                           integer_value<int>(material, "Sphere.material")};
           }),
           py::arg("center"), py::arg("radius"), py::arg("material") = 0);
  number_property(sphere, "radius", &Sphere::radius);
  int_property(sphere, "material", &Sphere::material, "index into Scene.materials");
  vec_property(sphere, "center", &Sphere::center);
  def_pickle(sphere);

  py::class_<Triangle> triangle(m, "Triangle",
                                "Indices into Scene.positions (v), .normals (n) and .uvs (uv); "
                                "n or uv (-1, -1, -1): absent.");
  triangle.def(py::init<>());
  int_property(triangle, "material", &Triangle::material);
  triple_property(triangle, "v", &Triangle::v);
  triple_property(triangle, "n", &Triangle::n);
  triple_property(triangle, "uv", &Triangle::uv);
  def_pickle(triangle);

  py::class_<Light> light(m, "Light", "An explicit light: point, environment or environment_map.");
  light.def(py::init<>());
  int_property(light, "texture", &Light::texture, "environment map: index into Scene.textures");
  vec_property(light, "position", &Light::position);
  vec_property(light, "intensity", &Light::intensity, "point: W/sr");
  vec_property(light, "radiance", &Light::radiance, "environment radiance, or the map's scale");
  enum_property(light, "type", &Light::type);
  def_pickle(light);

  py::class_<Texture> texture(m, "Texture",
                              "A linear RGBA image: rgba is an (H, W, 4) float32 array.");
  texture.def(py::init<>())
      .def_readonly("width", &Texture::width)
      .def_readonly("height", &Texture::height)
      .def_property(
          "rgba", &texture_texels, &set_texture_texels,
          "(H, W, 4) float32, linear, row 0 at the top: a read-only copy (assign an array to "
          "change it)");
  text_property<PathText>(texture, "path", &Texture::path);
  def_pickle(texture);

  py::class_<ShapeEntry> shape_entry(
      m, "ShapeEntry",
      "One entry of the scene's shape list as given (for messages and statistics): type, the "
      "OBJ file of a mesh, its first sphere or triangle and their count, and the MTL libraries "
      "the OBJ file named that exist (inputs of the scene).");
  int_property(shape_entry, "first", &ShapeEntry::first);
  int_property(shape_entry, "count", &ShapeEntry::count);
  shape_entry.def(py::init<>())
      .def_property(
          "libraries",
          [](const ShapeEntry& e) {
            std::vector<FileText> out;
            for (const std::string& l : e.libraries) out.push_back({l});
            return out;
          },
          [](py::handle self, const std::vector<PathText>& libraries) {
            ShapeEntry& e = assigned<ShapeEntry>(self);
            e.libraries.clear();
            for (const PathText& l : libraries) e.libraries.push_back(l.bytes);
          });
  text_property<PathText>(shape_entry, "file", &ShapeEntry::file);
  enum_property(shape_entry, "type", &ShapeEntry::type);
  def_pickle(shape_entry);

  auto shape_list = bind_scene_list<ShapeEntry>(m, "ShapeList");
  auto material_list = bind_scene_list<Material>(m, "MaterialList");
  auto sphere_list = bind_scene_list<Sphere>(m, "SphereList");
  auto triangle_list = bind_scene_list<Triangle>(m, "TriangleList");
  auto light_list = bind_scene_list<Light>(m, "LightList");
  auto texture_list = bind_scene_list<Texture>(m, "TextureList");
  def_pickle(shape_list);
  def_pickle(material_list);
  def_pickle(sphere_list);
  def_pickle(triangle_list);
  def_pickle(light_list);
  def_pickle(texture_list);

  py::class_<Scene> scene(m, "Scene",
                          "A scene: camera, film, integrator and lists of materials, spheres, "
                          "triangles, lights and textures (a reference to a list's element "
                          "follows the element when the list changes, as in a Python list).");
  scene.def(py::init<>())
      .def_readwrite("camera", &Scene::camera)
      .def_readwrite("film", &Scene::film)
      .def_readwrite("integrator", &Scene::integrator);
  text_property<PathText>(scene, "path", &Scene::path,
                          "the file the scene came from, for messages");
  list_property(scene, "materials", &Scene::materials);
  list_property(scene, "spheres", &Scene::spheres);
  list_property(scene, "triangles", &Scene::triangles);
  list_property(scene, "lights", &Scene::lights);
  list_property(scene, "textures", &Scene::textures);
  list_property(scene, "shapes", &Scene::shapes, "the shape list as given (ShapeEntry)");
  scene
      .def(
          "find_material",
          [](const Scene& s, const FileText& name) { return s.find_material(name.bytes); },
          py::arg("name"), "Index of the material named `name`, or -1.")
      .def("copy", [](const Scene& s) { return Scene(s); })
      // (a Python subclass's copy is of its class, with its attributes: it was a Scene)
      .def("__copy__", [](py::object self) { return copy_of_scene(self, nullptr); })
      .def("__deepcopy__",
           [](py::object self, py::dict memo) { return copy_of_scene(self, &memo); })
      .def("__repr__", &scene_repr);
  def_pickle(scene);
  vector_array_property(scene, "positions", &Scene::positions);
  vector_array_property(scene, "normals", &Scene::normals);
  vector_array_property(scene, "uvs", &Scene::uvs);

  fields_repr(camera, {"position", "look_at", "up", "fov_degrees", "roll_degrees", "aperture",
                       "focus_distance"});
  fields_repr(filter, {"type", "radius"});
  fields_repr(film, {"width", "height", "filter", "transfer", "gamma", "exposure", "tonemap"});
  fields_repr(integrator, {"type", "max_depth", "rr_depth", "spp", "seed", "sampler", "mis",
                           "clamp", "caustics", "dielectric_splits", "ao_distance"});
  fields_repr(sphere, {"center", "radius", "material"});
  fields_repr(triangle, {"v", "n", "uv", "material"});
  fields_repr(light, {"type", "position", "intensity", "radiance", "texture"});
  fields_repr(texture, {"path", "width", "height"});
  fields_repr(shape_entry, {"type", "file", "first", "count", "libraries"});

  m.def(
      "load_scene",
      [](const std::filesystem::path& path, py::object on_warning) {
        std::string p = path.string();
        return with_warnings(std::move(on_warning), [&] { return load_scene(p); });
      },
      py::arg("path"), py::arg("on_warning") = py::none(),
      "Loads a JSON scene. Warnings (a missing MTL file, ...) go to on_warning(message), or "
      "warnings.warn(message, LucentWarning) when None.");
  m.def("scene_info", &scene_info, py::arg("scene"), py::kw_only(), py::arg("precision") = "float",
        py::arg("fast_math") = false, py::arg("specialize") = true,
        py::arg("on_warning") = py::none(),
        "What `lucent info` prints, as a dict: counts (triangles, skipped_triangles, lights by "
        "type, ...), the BVH's statistics, the kernel's feature defines and full build options "
        "for these settings, and host_memory: what set_scene estimates for a CPU device (bytes, "
        "parts) and the limit it checks against (limit_bytes; 0: unknown). Packs the scene and "
        "builds its BVH; needs no device.");
  m.def(
      "scene_from_dict",
      [](py::dict d, const std::filesystem::path& base_dir, const FileText& name,
         py::object on_warning) {
        std::string label = (base_dir / name.bytes).string();
        // (the document freed without allocating: scene_detail::release_json)
        nlohmann::json document = to_json(d, "", label);
        std::string text;
        {
          const scene_detail::JsonRelease release(document);
          text = document.dump();
        }
        return with_warnings(std::move(on_warning), [&] { return parse_scene(text, label); });
      },
      py::arg("d"), py::arg("base_dir") = ".", py::arg("name") = "<dict>",
      py::arg("on_warning") = py::none(),
      "A scene from a dict of the JSON scene format, through the same parser and errors as "
      "load_scene (messages name base_dir/name and the JSON path). Relative file names are "
      "relative to base_dir.");
}

}  // namespace lucent::python

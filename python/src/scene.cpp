// Scenes in Python: the scene structs with every field readable and writable (enums by their
// scene-file names), scenes from files and from dicts of the JSON format (the same parser and
// its one-line errors).
#include <pybind11/stl_bind.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "common.hpp"
#include "lucent/error.hpp"
#include "render/features.hpp"
#include "render/pack.hpp"
#include "scene/json_guard.hpp"
#include "scene/loaders.hpp"
#include "scene/validate.hpp"

PYBIND11_MAKE_OPAQUE(std::vector<lucent::Material>)
PYBIND11_MAKE_OPAQUE(std::vector<lucent::Sphere>)
PYBIND11_MAKE_OPAQUE(std::vector<lucent::Triangle>)
PYBIND11_MAKE_OPAQUE(std::vector<lucent::Light>)
PYBIND11_MAKE_OPAQUE(std::vector<lucent::Texture>)
PYBIND11_MAKE_OPAQUE(std::vector<lucent::ShapeEntry>)

namespace lucent::python {

namespace {

std::string format_number(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

/// A glm vector from a Vec3/Vec2 or a sequence of N numbers (tuple, list, NumPy array), with
/// clear errors: ValueError for a wrong length, TypeError for anything else.
template <class V>
V to_vec(py::handle o) {
  constexpr int N = V::length();
  if (py::isinstance<V>(o)) return o.cast<V>();
  if (!py::isinstance<py::sequence>(o) || py::isinstance<py::str>(o)) {
    if (py::isinstance<py::str>(o))
      throw py::value_error("expected a sequence of " + std::to_string(N) + " numbers, got " +
                            py::repr(o).cast<std::string>());
    throw py::type_error("expected a sequence of " + std::to_string(N) + " numbers, got " +
                         py::repr(o).cast<std::string>());
  }
  py::sequence s = py::reinterpret_borrow<py::sequence>(o);
  if (s.size() != static_cast<std::size_t>(N))
    throw py::value_error("expected a sequence of " + std::to_string(N) + " numbers, got " +
                          py::repr(o).cast<std::string>());
  V v;
  for (int i = 0; i < N; ++i) {
    py::object e = s[static_cast<std::size_t>(i)];
    double d = PyFloat_AsDouble(e.ptr());
    if (d == -1.0 && PyErr_Occurred()) {
      PyErr_Clear();
      throw py::type_error("expected a sequence of " + std::to_string(N) + " numbers, got " +
                           py::repr(o).cast<std::string>());
    }
    v[i] = d;
  }
  return v;
}

/// A vector member: reading gives the vector itself (`camera.position.x += 1` changes the
/// camera), assigning takes any sequence of numbers.
template <class C, class V>
void vec_property(py::class_<C>& c, const char* name, V C::*member, const char* doc = "") {
  c.def_property(name,
                 py::cpp_function([member](C& o) -> V& { return o.*member; },
                                  py::return_value_policy::reference_internal),
                 py::cpp_function([member](C& o, py::handle v) { o.*member = to_vec<V>(v); }), doc);
}

/// Vec3 / Vec2: glm vectors with x, y, (z), indexing, iteration, comparison with sequences and
/// conversion from any sequence of numbers (function arguments accept tuples, lists, arrays).
template <class V>
void bind_vector_type(py::module_& m, const char* name) {
  constexpr int N = V::length();
  auto get = [](const V& v, py::ssize_t i) {
    if (i < 0) i += N;
    if (i < 0 || i >= N) throw py::index_error(std::string("index out of range"));
    return v[static_cast<int>(i)];
  };
  py::class_<V> c(m, name);
  c.def(py::init([](py::sequence s) { return to_vec<V>(s); }), py::arg("values"))
      .def_readwrite("x", &V::x)
      .def_readwrite("y", &V::y)
      .def("__len__", [](const V&) { return N; })
      .def("__getitem__", get)
      .def("__setitem__",
           [](V& v, py::ssize_t i, double value) {
             if (i < 0) i += N;
             if (i < 0 || i >= N) throw py::index_error(std::string("index out of range"));
             v[static_cast<int>(i)] = value;
           })
      .def("__iter__",
           [](const V& v) {
             py::list l;
             for (int i = 0; i < N; ++i) l.append(v[i]);
             return py::iter(l);
           })
      .def("__eq__",
           [](const V& v, py::object other) {
             if (py::isinstance<V>(other)) return v == other.cast<V>();
             if (!py::isinstance<py::sequence>(other) || py::isinstance<py::str>(other) ||
                 py::len(other) != static_cast<std::size_t>(N))
               return false;
             py::sequence s = py::reinterpret_borrow<py::sequence>(other);
             for (int i = 0; i < N; ++i) {
               py::object e = s[static_cast<std::size_t>(i)];
               // a number that is not real (complex) compares unequal rather than raising
               if (!PyNumber_Check(e.ptr()) || !py::hasattr(e, "__float__") ||
                   py::isinstance<py::str>(e))
                 return false;
               if (py::float_(e).cast<double>() != v[i]) return false;
             }
             return true;
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
  if constexpr (N == 3) c.def_readwrite("z", &V::z);
  c.attr("__hash__") = py::none();
  py::implicitly_convertible<py::sequence, V>();
}

/// A property holding an enum by its registry name.
template <class C, class E>
void enum_property(py::class_<C>& c, const char* name, E C::*member) {
  c.def_property(
      name, [member](const C& o) { return std::string(enum_name(o.*member)); },
      [member](C& o, const std::string& v) { o.*member = parse_enum<E>(v); });
}

/// int[3] members (triangle indices) as tuples.
template <class C>
void triple_property(py::class_<C>& c, const char* name, int (C::*member)[3]) {
  c.def_property(
      name,
      [member](const C& o) {
        return py::make_tuple((o.*member)[0], (o.*member)[1], (o.*member)[2]);
      },
      [member](C& o, py::sequence s) {
        if (s.size() != 3)
          throw py::value_error("expected 3 indices, got " + py::repr(s).cast<std::string>());
        int v[3];
        for (int i = 0; i < 3; ++i) {
          py::object e = s[static_cast<std::size_t>(i)];
          // Python and NumPy integers (operator.index), not booleans
          if (py::isinstance<py::bool_>(e) || !py::hasattr(e, "__index__"))
            throw py::type_error("expected 3 integer indices, got " +
                                 py::repr(s).cast<std::string>());
          const long long x = py::reinterpret_steal<py::int_>(PyNumber_Index(e.ptr()))
                                  .cast<long long>();  // overflow raises
          if (x < std::numeric_limits<int>::min() || x > std::numeric_limits<int>::max())
            throw py::value_error("index " + std::to_string(i) +
                                  " out of range: " + std::to_string(x));
          v[i] = static_cast<int>(x);
        }
        for (int i = 0; i < 3; ++i) (o.*member)[i] = v[i];
      });
}

/// A list of glm vectors as an (N, D) float64 array: a read-only copy (assign the attribute to
/// change it).
template <class V>
void vector_array_property(py::class_<Scene>& c, const char* name, std::vector<V> Scene::*member) {
  constexpr int D = V::length();
  c.def_property(
      name,
      [member](const Scene& s) {
        const std::vector<V>& v = s.*member;
        return copy_rows(v.empty() ? nullptr : &v[0].x, v.size(), D);
      },
      [member, name](Scene& s, py::handle value) {
        require_numbers(value, name);
        auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
        if (!a)
          throw py::type_error(std::string(name) + ": expected an array of shape (N, " +
                               std::to_string(D) + ")");
        if (!(a.ndim() == 2 && a.shape(1) == D) && !(a.ndim() == 1 && a.shape(0) == 0))
          throw py::value_error(std::string(name) + ": expected an array of shape (N, " +
                                std::to_string(D) + ")");
        std::vector<V> out(static_cast<std::size_t>(a.ndim() == 2 ? a.shape(0) : 0));
        for (std::size_t i = 0; i < out.size(); ++i)
          for (int k = 0; k < D; ++k) out[i][k] = a.at(static_cast<py::ssize_t>(i), k);
        s.*member = std::move(out);
      },
      (std::string(name) + ": an (N, " + std::to_string(D) +
       ") float64 array (a read-only copy; assign to change)")
          .c_str());
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
    py::int_ i = py::reinterpret_borrow<py::int_>(o);
    if (i.attr("bit_length")().cast<int>() > 63)
      return fail("integer out of range: " + py::str(o).cast<std::string>());
    return o.cast<long long>();
  }
  if (py::isinstance<py::float_>(o)) {
    double d = o.cast<double>();
    if (!std::isfinite(d)) return fail("must be a finite number, got " + format_number(d));
    return d;
  }
  if (py::isinstance<py::str>(o)) return o.cast<std::string>();
  if (py::isinstance<py::dict>(o)) {
    nlohmann::json j = nlohmann::json::object();
    for (auto item : py::reinterpret_borrow<py::dict>(o)) {
      if (!py::isinstance<py::str>(item.first))
        return fail("keys must be strings, got " + py::repr(item.first).cast<std::string>());
      std::string key = item.first.cast<std::string>();
      j[key] = to_json(item.second, path + "/" + key, label, depth + 1);
    }
    return j;
  }
  if (py::hasattr(o, "tolist") && !py::isinstance<py::str>(o))  // NumPy arrays and scalars
    return to_json(o.attr("tolist")(), path, label, depth + 1);
  if (py::isinstance<py::list>(o) || py::isinstance<py::tuple>(o) ||
      py::isinstance<glm::dvec3>(o) || py::isinstance<glm::dvec2>(o)) {
    nlohmann::json j = nlohmann::json::array();
    std::size_t i = 0;
    for (auto item : o)
      j.push_back(to_json(item, path + "/" + std::to_string(i++), label, depth + 1));
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
    py::gil_scoped_release release;
    scene_detail::ScopedWarningSink scoped(sink);
    out.emplace(load());
  }
  errors->rethrow();
  return std::move(*out);
}

/// What `lucent info` prints, as a dict: the packed scene's counts, its BVH and the kernel's
/// feature defines and build options for these settings. Needs no device.
py::dict scene_info(const Scene& scene, const std::string& precision, bool fast_math,
                    bool specialize, py::object on_warning) {
  RenderOptions options;
  options.precision = parse_enum<Precision>(precision);
  options.fast_math = fast_math;
  options.specialize = specialize;
  Scene copy = scene;
  auto packed = with_warnings(std::move(on_warning), [&] {
    scene_detail::validate_scene(copy);  // fields set from Python may index past the lists
    return render_detail::pack_scene(copy);
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
  double texel_bytes = 0;
  for (const Texture& t : copy.textures) texel_bytes += double(t.width) * t.height * 16;
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
  d["fast_math"] = fast_math;
  d["build_options"] = render_detail::build_options(copy, packed, options);
  return d;
}

std::string scene_repr(const Scene& s) {
  return "<lucent.Scene '" + s.path + "': " + std::to_string(s.film.width) + "x" +
         std::to_string(s.film.height) + ", " + enum_name(s.integrator.type) + ", " +
         std::to_string(s.materials.size()) + " materials, " + std::to_string(s.spheres.size()) +
         " spheres, " + std::to_string(s.triangles.size()) + " triangles, " +
         std::to_string(s.lights.size()) + " lights, " + std::to_string(s.textures.size()) +
         " textures>";
}

}  // namespace

void bind_scene(py::module_& m) {
  bind_vector_type<glm::dvec3>(m, "Vec3");
  bind_vector_type<glm::dvec2>(m, "Vec2");

  py::class_<Camera> camera(m, "Camera", "Pinhole or thin-lens camera (README, \"camera\").");
  camera.def(py::init<>())
      .def_readwrite("fov_degrees", &Camera::fov_degrees, "vertical field of view")
      .def_readwrite("roll_degrees", &Camera::roll_degrees)
      .def_readwrite("aperture", &Camera::aperture, "thin-lens radius (0: pinhole)")
      .def_readwrite("focus_distance", &Camera::focus_distance, "0: the distance to look_at");
  vec_property(camera, "position", &Camera::position);
  vec_property(camera, "look_at", &Camera::look_at);
  vec_property(camera, "up", &Camera::up);

  py::class_<Filter> filter(m, "Filter", "Pixel filter: type (FILTER_TYPES) and radius in pixels.");
  filter.def(py::init<>()).def_readwrite("radius", &Filter::radius);
  enum_property(filter, "type", &Filter::type);

  py::class_<Film> film(m, "Film", "Image size, pixel filter and display settings.");
  film.def(py::init<>())
      .def_readwrite("width", &Film::width)
      .def_readwrite("height", &Film::height)
      .def_readwrite("filter", &Film::filter)
      .def_readwrite("gamma", &Film::gamma)
      .def_readwrite("exposure", &Film::exposure);
  enum_property(film, "transfer", &Film::transfer);
  enum_property(film, "tonemap", &Film::tonemap);

  py::class_<Integrator> integrator(m, "Integrator",
                                    "type: an integrator or AOV name (INTEGRATORS).");
  integrator.def(py::init<>())
      .def_readwrite("max_depth", &Integrator::max_depth)
      .def_readwrite("rr_depth", &Integrator::rr_depth)
      .def_readwrite("spp", &Integrator::spp)
      .def_readwrite("seed", &Integrator::seed)
      .def_readwrite("ao_distance", &Integrator::ao_distance)
      .def_readwrite("mis", &Integrator::mis)
      .def_readwrite("clamp", &Integrator::clamp,
                     "the largest sample contribution (0: off); biased, lower variance")
      .def_readwrite("caustics", &Integrator::caustics,
                     "path: caustic paths by light tracing (pinhole and thin-lens cameras)")
      .def_readwrite("dielectric_splits", &Integrator::dielectric_splits,
                     "path: smooth-glass vertices per camera path at which both lobes are "
                     "followed (0 .. 4; default 2; 0: off)");
  enum_property(integrator, "type", &Integrator::type);
  enum_property(integrator, "sampler", &Integrator::sampler);

  py::class_<Material> material(m, "Material", "type: MATERIAL_TYPES; README, \"materials\".");
  material.def(py::init<>())
      .def_readwrite("name", &Material::name)
      .def_readwrite("albedo_texture", &Material::albedo_texture, "index into Scene.textures or -1")
      .def_readwrite("ior", &Material::ior)
      .def_readwrite("roughness", &Material::roughness)
      .def_property_readonly("emissive", &Material::emissive)
      .def("__repr__", [](const Material& mt) {
        return "<lucent.Material '" + mt.name + "' " + enum_name(mt.type) + ">";
      });
  vec_property(material, "albedo", &Material::albedo);
  vec_property(material, "emission", &Material::emission);
  vec_property(material, "specular", &Material::specular);
  enum_property(material, "type", &Material::type);

  py::class_<Sphere> sphere(m, "Sphere");
  sphere.def(py::init<>())
      .def(py::init([](py::handle center, double radius, int material) {
             return Sphere{to_vec<glm::dvec3>(center), radius, material};
           }),
           py::arg("center"), py::arg("radius"), py::arg("material") = 0)
      .def_readwrite("radius", &Sphere::radius)
      .def_readwrite("material", &Sphere::material, "index into Scene.materials");
  vec_property(sphere, "center", &Sphere::center);

  py::class_<Triangle> triangle(m, "Triangle",
                                "Indices into Scene.positions (v), .normals (n) and .uvs (uv); "
                                "-1: absent.");
  triangle.def(py::init<>()).def_readwrite("material", &Triangle::material);
  triple_property(triangle, "v", &Triangle::v);
  triple_property(triangle, "n", &Triangle::n);
  triple_property(triangle, "uv", &Triangle::uv);

  py::class_<Light> light(m, "Light", "An explicit light: point, environment or environment_map.");
  light.def(py::init<>())
      .def_readwrite("texture", &Light::texture, "environment map: index into Scene.textures");
  vec_property(light, "position", &Light::position);
  vec_property(light, "intensity", &Light::intensity, "point: W/sr");
  vec_property(light, "radiance", &Light::radiance, "environment radiance, or the map's scale");
  enum_property(light, "type", &Light::type);

  py::class_<Texture>(m, "Texture", "A linear RGBA image: rgba is an (H, W, 4) float32 array.")
      .def(py::init<>())
      .def_readwrite("path", &Texture::path)
      .def_readonly("width", &Texture::width)
      .def_readonly("height", &Texture::height)
      .def_property(
          "rgba",
          [](const Texture& t) {
            // a copy: a view of t.rgba dangled once the setter or the scene's texture list
            // reallocated it (reading freed memory, a crash)
            py::array_t<float> a({py::ssize_t(t.height), py::ssize_t(t.width), py::ssize_t(4)});
            if (!t.rgba.empty())
              std::copy(t.rgba.begin(), t.rgba.end(), static_cast<float*>(a.mutable_data()));
            a.attr("flags").attr("writeable") = false;
            return a;
          },
          [](Texture& t, py::handle value) {
            require_numbers(value, "rgba");
            auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(value);
            if (!a || a.ndim() != 3 || a.shape(2) != 4 || a.shape(0) < 1 || a.shape(1) < 1)
              throw py::value_error("rgba: expected an array of shape (H, W, 4)");
            t.height = static_cast<int>(a.shape(0));
            t.width = static_cast<int>(a.shape(1));
            t.rgba.assign(a.data(), a.data() + a.size());
          },
          "(H, W, 4) float32, linear, row 0 at the top: a read-only copy (assign an array to "
          "change it)");

  py::class_<ShapeEntry> shape_entry(
      m, "ShapeEntry",
      "One entry of the scene's shape list as given (for messages and statistics): type, the "
      "OBJ file of a mesh, its first sphere or triangle and their count, and the MTL libraries "
      "the OBJ file named that exist (inputs of the scene).");
  shape_entry.def(py::init<>())
      .def_readwrite("file", &ShapeEntry::file)
      .def_readwrite("first", &ShapeEntry::first)
      .def_readwrite("count", &ShapeEntry::count)
      .def_readwrite("libraries", &ShapeEntry::libraries);
  enum_property(shape_entry, "type", &ShapeEntry::type);

  py::bind_vector<std::vector<ShapeEntry>>(m, "ShapeList");
  py::bind_vector<std::vector<Material>>(m, "MaterialList");
  py::bind_vector<std::vector<Sphere>>(m, "SphereList");
  py::bind_vector<std::vector<Triangle>>(m, "TriangleList");
  py::bind_vector<std::vector<Light>>(m, "LightList");
  py::bind_vector<std::vector<Texture>>(m, "TextureList");

  py::class_<Scene> scene(m, "Scene",
                          "A scene: camera, film, integrator and lists of materials, spheres, "
                          "triangles, lights and textures (a reference to a list element stays "
                          "valid while the list is not resized).");
  scene.def(py::init<>())
      .def_readwrite("path", &Scene::path, "the file the scene came from, for messages")
      .def_readwrite("camera", &Scene::camera)
      .def_readwrite("film", &Scene::film)
      .def_readwrite("integrator", &Scene::integrator)
      .def_readwrite("materials", &Scene::materials)
      .def_readwrite("spheres", &Scene::spheres)
      .def_readwrite("triangles", &Scene::triangles)
      .def_readwrite("lights", &Scene::lights)
      .def_readwrite("textures", &Scene::textures)
      .def_readwrite("shapes", &Scene::shapes, "the shape list as given (ShapeEntry)")
      .def("find_material", &Scene::find_material, py::arg("name"),
           "Index of the material named `name`, or -1.")
      .def("copy", [](const Scene& s) { return Scene(s); })
      .def("__copy__", [](const Scene& s) { return Scene(s); })
      .def("__deepcopy__", [](const Scene& s, py::dict) { return Scene(s); })
      .def("__repr__", &scene_repr);
  vector_array_property(scene, "positions", &Scene::positions);
  vector_array_property(scene, "normals", &Scene::normals);
  vector_array_property(scene, "uvs", &Scene::uvs);

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
        "for these settings. Packs the scene and builds its BVH; needs no device.");
  m.def(
      "scene_from_dict",
      [](py::dict d, const std::filesystem::path& base_dir, const std::string& name,
         py::object on_warning) {
        std::string label = (base_dir / name).string();
        std::string text = to_json(d, "", label).dump();
        return with_warnings(std::move(on_warning), [&] { return parse_scene(text, label); });
      },
      py::arg("d"), py::arg("base_dir") = ".", py::arg("name") = "<dict>",
      py::arg("on_warning") = py::none(),
      "A scene from a dict of the JSON scene format, through the same parser and errors as "
      "load_scene (messages name base_dir/name and the JSON path). Relative file names are "
      "relative to base_dir.");
}

}  // namespace lucent::python

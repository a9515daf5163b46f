#pragma once
// The names of lucent's types (materials, lights, shapes, integrators and AOVs, pixel filters,
// samplers), generated from the registries (lucent/registry.h; kernels/shared/registry.h in the
// source tree): the name of each enum value, the lookup of a name, the list of valid names. Every
// name table of the library, the scene loader and the command line comes from here, so that a
// type added to a registry is known everywhere at once.
//
//   lucent::type_name(lucent::IntegratorType::Ao)            -> "ao"
//   lucent::find_type<lucent::MaterialType>("mirror")        -> MaterialType::Mirror (optional)
//   lucent::parse_type<lucent::FilterType>("sinc")           -> throws lucent::Error:
//       "unknown filter 'sinc' (expected one of: box, tent, gaussian)"
//   lucent::type_names<lucent::LightType>()                  -> "point, sphere, triangle, ..."
#include <cstddef>
#include <optional>
#include <string>

#include "lucent/error.hpp"
#include "lucent/scene.hpp"

namespace lucent {

/// One registry entry as the host sees it: the enum value, its name in scene files, on the
/// command line and in `lucent info`, and the kernel feature define that compiles it in.
template <class E>
struct TypeEntry {
  E value;
  const char* name;
  const char* feature;
};

/// The entries of one registry, in registry order: TypeList<E>::entries, and `what` names the
/// concept in messages ("material type", "integrator", ...).
template <class E>
struct TypeList;

#define LUCENT_TYPE_ENTRY(Enum, ID, Name, value, name, feature, ...) \
  TypeEntry<Enum>{Enum::Name, name, #feature},
#define LUCENT_MATERIAL_ENTRY(...) LUCENT_TYPE_ENTRY(MaterialType, __VA_ARGS__)
#define LUCENT_LIGHT_ENTRY(...) LUCENT_TYPE_ENTRY(LightType, __VA_ARGS__)
#define LUCENT_SHAPE_ENTRY(...) LUCENT_TYPE_ENTRY(ShapeType, __VA_ARGS__)
#define LUCENT_INTEGRATOR_ENTRY(...) LUCENT_TYPE_ENTRY(IntegratorType, __VA_ARGS__)
#define LUCENT_FILTER_ENTRY(...) LUCENT_TYPE_ENTRY(FilterType, __VA_ARGS__)
#define LUCENT_SAMPLER_ENTRY(...) LUCENT_TYPE_ENTRY(SamplerType, __VA_ARGS__)

template <>
struct TypeList<MaterialType> {
  static constexpr const char* what = "material type";
  static constexpr TypeEntry<MaterialType> entries[] = {LC_MATERIAL_TYPES(LUCENT_MATERIAL_ENTRY)};
};
template <>
struct TypeList<LightType> {
  static constexpr const char* what = "light type";
  static constexpr TypeEntry<LightType> entries[] = {LC_LIGHT_TYPES(LUCENT_LIGHT_ENTRY)};
};
template <>
struct TypeList<ShapeType> {
  static constexpr const char* what = "shape type";
  static constexpr TypeEntry<ShapeType> entries[] = {LC_SHAPE_TYPES(LUCENT_SHAPE_ENTRY)};
};
/// The integrators, then the AOVs (one enum, IntegratorType).
template <>
struct TypeList<IntegratorType> {
  static constexpr const char* what = "integrator";
  static constexpr TypeEntry<IntegratorType> entries[] = {
      LC_INTEGRATOR_TYPES(LUCENT_INTEGRATOR_ENTRY) LC_AOV_TYPES(LUCENT_INTEGRATOR_ENTRY)};
};
template <>
struct TypeList<FilterType> {
  static constexpr const char* what = "filter";
  static constexpr TypeEntry<FilterType> entries[] = {LC_FILTER_TYPES(LUCENT_FILTER_ENTRY)};
};
template <>
struct TypeList<SamplerType> {
  static constexpr const char* what = "sampler";
  static constexpr TypeEntry<SamplerType> entries[] = {LC_SAMPLER_TYPES(LUCENT_SAMPLER_ENTRY)};
};

#undef LUCENT_MATERIAL_ENTRY
#undef LUCENT_LIGHT_ENTRY
#undef LUCENT_SHAPE_ENTRY
#undef LUCENT_INTEGRATOR_ENTRY
#undef LUCENT_FILTER_ENTRY
#undef LUCENT_SAMPLER_ENTRY
#undef LUCENT_TYPE_ENTRY

/// The registry entry of `value`, or nullptr for a value no entry has (a cast integer).
template <class E>
constexpr const TypeEntry<E>* find_entry(E value) {
  for (const TypeEntry<E>& e : TypeList<E>::entries)
    if (e.value == value) return &e;
  return nullptr;
}

/// The name of `value` ("diffuse", "path", ...); "unknown" for a value no entry has.
template <class E>
constexpr const char* type_name(E value) {
  const TypeEntry<E>* e = find_entry(value);
  return e ? e->name : "unknown";
}

/// The kernel feature define of `value` ("LC_HAS_MIRROR", ...); "" for a value no entry has.
template <class E>
constexpr const char* type_feature(E value) {
  const TypeEntry<E>* e = find_entry(value);
  return e ? e->feature : "";
}

/// The value named `name` (exact, case-sensitive), if any.
template <class E>
std::optional<E> find_type(const std::string& name) {
  for (const TypeEntry<E>& e : TypeList<E>::entries)
    if (name == e.name) return e.value;
  return std::nullopt;
}

/// The valid names, in registry order, joined by `separator` ("box, tent, gaussian").
template <class E>
std::string type_names(const char* separator = ", ") {
  std::string out;
  for (const TypeEntry<E>& e : TypeList<E>::entries) {
    if (!out.empty()) out += separator;
    out += e.name;
  }
  return out;
}

/// The value named `name`; throws lucent::Error "unknown <what> '<name>' (expected one of:
/// <names>)".
template <class E>
E parse_type(const std::string& name) {
  if (std::optional<E> v = find_type<E>(name)) return *v;
  throw Error(std::string("unknown ") + TypeList<E>::what + " '" + name +
              "' (expected one of: " + type_names<E>() + ")");
}

/// True for the AOVs (first-hit outputs: albedo, normal, ...), false for the integrators.
constexpr bool is_aov(IntegratorType t) {
#define LUCENT_IS_AOV(ID, Name, ...) t == IntegratorType::Name ||
  return LC_AOV_TYPES(LUCENT_IS_AOV) false;
#undef LUCENT_IS_AOV
}

/// The pixel filter's default radius in pixels (the registry's last column): box 0.5, tent and
/// gaussian 1.5.
constexpr double default_filter_radius(FilterType t) {
#define LUCENT_FILTER_RADIUS(ID, Name, value, name, feature, file, radius) \
  t == FilterType::Name ? radius:
  return LC_FILTER_TYPES(LUCENT_FILTER_RADIUS) 0.5;
#undef LUCENT_FILTER_RADIUS
}

/// The light types that are emissive shapes (sphere, triangle): made from shapes whose material
/// has an emission, never written in a scene's "lights". A light type is a shape light when a
/// shape type has the same file (kernels/geom/<file>.cl and kernels/light/<file>.cl).
namespace detail {
constexpr bool same_name(const char* a, const char* b) {
  while (*a && *a == *b) {  // (no comma operator: clang's -Wcomma in a consumer's build)
    ++a;
    ++b;
  }
  return *a == *b;
}
}  // namespace detail

constexpr bool is_shape_light(LightType t) {
  const char* light_file = "";
#define LUCENT_LIGHT_FILE(ID, Name, value, name, feature, file, ...) \
  if (t == LightType::Name) light_file = #file;
  LC_LIGHT_TYPES(LUCENT_LIGHT_FILE)
#undef LUCENT_LIGHT_FILE
  bool shape = false;
#define LUCENT_SHAPE_FILE(ID, Name, value, name, feature, file) \
  shape = shape || detail::same_name(light_file, #file);
  LC_SHAPE_TYPES(LUCENT_SHAPE_FILE)
#undef LUCENT_SHAPE_FILE
  return shape;
}

}  // namespace lucent

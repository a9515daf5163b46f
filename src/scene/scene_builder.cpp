// SceneBuilder (lucent/scene_builder.hpp): the one way into a checked Scene, for scenes built in
// code and for the JSON loader alike. Each call checks its element (scene/validate.hpp) at the
// element's place, then adds it.
#include "lucent/scene_builder.hpp"

#include <cmath>
#include <utility>

#include "lucent/error.hpp"
#include "scene/loaders.hpp"
#include "scene/material_type.hpp"
#include "scene/validate.hpp"

namespace lucent {

using scene_detail::Reporter;

int Scene::find_material(const std::string& name) const {
  for (size_t i = 0; i < materials.size(); ++i)
    if (materials[i].name == name) return static_cast<int>(i);
  return -1;
}

Material material_of_type(MaterialType type, std::string name) {
  Material m;
  m.name = std::move(name);
  m.type = type;
  for (const scene_detail::MaterialParam& param : scene_detail::material_type_def(type).params) {
    if (param.colour) m.*param.colour = param.default_colour;
    if (param.number) m.*param.number = param.default_number;
  }
  return m;
}

Light point_light(const glm::dvec3& position, const glm::dvec3& intensity) {
  Light l;
  l.type = LightType::Point;
  l.position = position;
  l.intensity = intensity;
  return l;
}

Light environment_light(const glm::dvec3& radiance) {
  Light l;
  l.type = LightType::Environment;
  l.radiance = radiance;
  return l;
}

Light environment_map(int texture, double scale) {
  Light l;
  l.type = LightType::EnvironmentMap;
  l.texture = texture;
  l.radiance = glm::dvec3(scale);
  return l;
}

SceneBuilder::SceneBuilder(std::string name) { scene_.path = std::move(name); }

void SceneBuilder::set_camera(const Camera& camera) {
  scene_detail::validate_camera(camera, Reporter(scene_.path, "/camera"));
  scene_.camera = camera;
}

void SceneBuilder::set_film(const Film& film) {
  scene_detail::validate_film(film, Reporter(scene_.path, "/film"));
  scene_.film = film;
}

void SceneBuilder::set_integrator(const Integrator& integrator) {
  scene_detail::validate_integrator(integrator, Reporter(scene_.path, "/integrator"));
  scene_.integrator = integrator;
}

int SceneBuilder::add_texture(Texture texture) {
  scene_detail::validate_texture(
      texture, Reporter(scene_.path, "/textures/" + std::to_string(scene_.textures.size())));
  scene_.textures.push_back(std::move(texture));
  return static_cast<int>(scene_.textures.size() - 1);
}

int SceneBuilder::load_texture(const std::string& file) {
  return scene_detail::load_texture(scene_, file, &obj_materials_);
}

int SceneBuilder::add_material(const Material& material) {
  const Reporter at = Reporter(scene_.path, "/materials").at(material.name);
  scene_detail::validate_material(material, scene_.textures, at);
  if (material_names_.count(material.name))
    at.fail("there is already a material named '" + material.name + "'");
  const int index = static_cast<int>(scene_.materials.size());
  material_names_.emplace(material.name, index);  // first: may throw, before the list changes
  try {
    scene_.materials.push_back(material);
  } catch (...) {
    material_names_.erase(material.name);
    throw;
  }
  return index;
}

int SceneBuilder::material_index(const std::string& name, const std::string& pointer) const {
  const auto it = material_names_.find(name);
  if (it == material_names_.end())
    Reporter(scene_.path, pointer).fail("unknown material '" + name + "'");
  return it->second;
}

std::string SceneBuilder::shape_place() const {
  return "/shapes/" + std::to_string(scene_.shapes.size());
}

void SceneBuilder::add_sphere(const SphereShape& sphere) {
  const std::string p = shape_place();
  Sphere s;
  s.material = material_index(sphere.material, p + "/material");
  scene_detail::validate_sphere(sphere, Reporter(scene_.path, p));
  s.center = sphere.center;
  s.radius = sphere.radius;
  scene_.shapes.push_back({ShapeType::Sphere, "", scene_.spheres.size(), 1, {}});
  scene_.spheres.push_back(s);
}

void SceneBuilder::add_mesh(const MeshShape& mesh) {
  const std::string p = shape_place();
  const int material = material_index(mesh.material, p + "/material");
  scene_detail::validate_mesh(mesh, Reporter(scene_.path, p));

  const glm::dmat4& xf = mesh.transform;
  const glm::dmat3 nxf = scene_detail::normal_transform(glm::dmat3(xf));
  const bool mirrored = scene_detail::unit_determinant(glm::dmat3(xf)) < 0;
  const int base = static_cast<int>(scene_.positions.size());
  const int nbase = static_cast<int>(scene_.normals.size());
  const int uvbase = static_cast<int>(scene_.uvs.size());
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const glm::dvec3 w = glm::dvec3(xf * glm::dvec4(mesh.positions[i], 1.0));
    const double m = scene_detail::max_abs(w);
    if (!(m <= limits::kMaxCoordinate))
      Reporter(scene_.path, p + "/positions/" + std::to_string(i))
          .fail(scene_detail::beyond_geometry_range(
              std::string(mesh.transform == glm::dmat4(1.0) ? "its largest coordinate, "
                                                            : "its largest coordinate after the "
                                                              "transform, ") +
              scene_detail::format_number(m) + ","));
    scene_.positions.push_back(w);
  }
  for (const glm::dvec3& n : mesh.normals) scene_.normals.push_back(scene_detail::unit(nxf * n));
  for (const glm::dvec2& uv : mesh.uvs) scene_.uvs.push_back(uv);
  ShapeEntry entry{ShapeType::Triangle, "", scene_.triangles.size(), mesh.indices.size() / 3, {}};
  for (std::size_t i = 0; i < mesh.indices.size(); i += 3) {
    Triangle tri;
    tri.material = material;
    for (int k = 0; k < 3; ++k) {
      int v = mesh.indices[i + k];
      tri.v[k] = base + v;
      tri.n[k] = mesh.normals.empty() ? -1 : nbase + v;
      tri.uv[k] = mesh.uvs.empty() ? -1 : uvbase + v;
    }
    if (mirrored) {  // keep the front side where the transformed normals point
      std::swap(tri.v[1], tri.v[2]);
      std::swap(tri.n[1], tri.n[2]);
      std::swap(tri.uv[1], tri.uv[2]);
    }
    scene_.triangles.push_back(tri);
  }
  scene_.shapes.push_back(entry);
}

void SceneBuilder::add_obj(const ObjShape& obj) {
  const std::string p = shape_place();
  Reporter at(scene_.path, p);
  const int material = obj.material.empty() ? -1 : material_index(obj.material, p + "/material");
  scene_detail::check_affine(at.at("transform"), obj.transform);
  ShapeEntry entry{ShapeType::Triangle, obj.file, scene_.triangles.size(), 0, {}};
  // a failed load leaves the scene as it was
  const std::size_t materials = scene_.materials.size(), positions = scene_.positions.size(),
                    normals = scene_.normals.size(), uvs = scene_.uvs.size(),
                    triangles = scene_.triangles.size(), textures = scene_.textures.size();
  const scene_detail::ObjMaterials obj_materials = obj_materials_;
  auto roll_back = [&] {
    obj_materials_ = obj_materials;
    for (std::size_t i = materials; i < scene_.materials.size(); ++i) {
      const auto it = material_names_.find(scene_.materials[i].name);
      if (it != material_names_.end() && it->second == static_cast<int>(i))
        material_names_.erase(it);
    }
    scene_.materials.resize(materials);
    scene_.positions.resize(positions);
    scene_.normals.resize(normals);
    scene_.uvs.resize(uvs);
    scene_.triangles.resize(triangles);
    scene_.textures.resize(textures);
  };
  try {
    entry.libraries = scene_detail::load_obj(scene_, obj.file, obj.transform, material,
                                             &obj_materials_, &material_names_);
  } catch (const Error& e) {
    roll_back();
    at.at("file").fail(e.what());  // "<scene>: /shapes/2/file: <obj>:<line>: ..."
  } catch (...) {                  // std::bad_alloc: the builder as it was too
    roll_back();
    throw;
  }
  entry.count = scene_.triangles.size() - entry.first;
  scene_.shapes.push_back(entry);
}

void SceneBuilder::add_light(const Light& light) {
  Reporter at(scene_.path, "/lights/" + std::to_string(scene_.lights.size()));
  scene_detail::validate_light(light, scene_.textures.size(), at);
  if (light.type != LightType::Point)
    for (const Light& other : scene_.lights)
      if (other.type != LightType::Point) at.fail("only one environment light is allowed");
  scene_.lights.push_back(light);
}

Scene SceneBuilder::build() {
  Scene out = std::move(scene_);
  scene_ = Scene{};
  obj_materials_.clear();
  material_names_.clear();
  scene_.path = out.path;
  return out;
}

}  // namespace lucent

// The JSON scene's "shapes": spheres, inline triangle lists and OBJ meshes, with their
// transforms. Each entry becomes one SceneBuilder call (add_sphere, add_mesh, add_obj), which
// checks it at the entry's place ("/shapes/<i>").
#include <glm/gtc/matrix_transform.hpp>

#include "scene/json_sections.hpp"

namespace lucent::scene_detail {

namespace {

/// A list of steps ({"scale"}, {"rotate"}, {"translate"}, {"matrix"}) applied in order.
glm::dmat4 parse_transform(const JsonReader& r, const json& j, const std::string& p) {
  if (!j.is_array()) r.fail(p, "must be an array of transform steps, got " + json_type_name(j));
  glm::dmat4 m(1.0);
  for (size_t i = 0; i < j.size(); ++i) {
    const std::string sp = p + "/" + std::to_string(i);
    const json& step = j[i];
    r.check_object(step, sp);
    if (step.size() != 1)
      r.fail(sp, "each step must hold exactly one of scale, rotate, translate, matrix");
    glm::dmat4 s(1.0);
    if (step.contains("scale")) {
      const json& v = step["scale"];
      glm::dvec3 k =
          v.is_array() ? r.vec3(v, sp + "/scale") : glm::dvec3(r.number(v, sp + "/scale"));
      for (int a = 0; a < 3; ++a)
        if (k[a] == 0) r.fail(sp + "/scale", "must not be zero");
      s = glm::scale(glm::dmat4(1.0), k);
    } else if (step.contains("rotate")) {
      const json& rj = step["rotate"];
      r.check_keys(rj, sp + "/rotate", {"axis", "degrees"});
      glm::dvec3 axis = r.vec3(r.require(rj, sp + "/rotate", "axis"), sp + "/rotate/axis");
      check_nonzero(r.at(sp + "/rotate/axis"), axis);
      double deg = r.number(r.require(rj, sp + "/rotate", "degrees"), sp + "/rotate/degrees");
      s = glm::rotate(glm::dmat4(1.0), glm::radians(deg), unit(axis));
    } else if (step.contains("translate")) {
      s = glm::translate(glm::dmat4(1.0), r.vec3(step["translate"], sp + "/translate"));
    } else if (step.contains("matrix")) {
      const json& mj = step["matrix"];
      const std::string mp = sp + "/matrix";
      if (!mj.is_array() || mj.size() != 4) r.fail(mp, "must be 4 rows of 4 numbers");
      for (int row = 0; row < 4; ++row) {
        const json& rowj = mj[row];
        const std::string rp = mp + "/" + std::to_string(row);
        if (!rowj.is_array() || rowj.size() != 4) r.fail(rp, "must be a row of 4 numbers");
        for (int c = 0; c < 4; ++c) s[c][row] = r.number(rowj[c], rp + "/" + std::to_string(c));
      }
      check_affine(r.at(mp), s);
    } else {
      r.fail(sp + "/" + pointer_key(step.begin().key()),
             "unknown transform step (allowed: scale, rotate, translate, matrix)");
    }
    m = s * m;  // steps apply in order
  }
  return m;
}

glm::dmat4 optional_transform(const JsonReader& r, const json& j, const std::string& p) {
  return j.contains("transform") ? parse_transform(r, j["transform"], p + "/transform")
                                 : glm::dmat4(1.0);
}

MeshShape parse_triangles(const JsonReader& r, const json& j, const std::string& p) {
  MeshShape mesh;
  mesh.material = r.string(r.require(j, p, "material"), p + "/material");
  mesh.transform = optional_transform(r, j, p);
  const json& pos = r.require(j, p, "positions");
  if (!pos.is_array()) r.fail(p + "/positions", "must be a non-empty array of [x, y, z]");
  for (size_t i = 0; i < pos.size(); ++i)
    mesh.positions.push_back(r.vec3(pos[i], p + "/positions/" + std::to_string(i)));
  const json& idx = r.require(j, p, "indices");
  // before the indices: a short list is one error, not one per index (an empty one is refused
  // with the mesh, after its positions: validate_mesh)
  if (!idx.is_array() || idx.size() % 3 != 0)
    r.fail(p + "/indices", "must be a non-empty array whose length is a multiple of 3");
  for (size_t i = 0; i < idx.size(); ++i)
    mesh.indices.push_back(static_cast<int>(
        r.integer(idx[i], p + "/indices/" + std::to_string(i), rules::vertex_index(pos.size()))));
  for (const char* key : {"normals", "uvs"}) {
    if (!j.contains(key)) continue;
    const json& a = j[key];
    const std::string ap = p + "/" + key;
    r.check_array(a, ap);
    for (size_t i = 0; i < a.size(); ++i) {
      const std::string ep = ap + "/" + std::to_string(i);
      if (key[0] == 'n')
        mesh.normals.push_back(r.vec3(a[i], ep));
      else
        mesh.uvs.push_back(r.vec2(a[i], ep));
    }
  }
  return mesh;
}

void parse_shape(const JsonReader& r, const json& j, const std::string& p, SceneBuilder& b) {
  r.check_object(j, p);
  // the registry's shape types, and "mesh": an OBJ file (its faces become triangles)
  const std::string name = r.string(r.require(j, p, "type"), p + "/type");
  if (name == "mesh") {
    r.check_keys(j, p, {"type", "file", "material", "transform"});
    ObjShape obj;
    obj.file = r.file_path(r.require(j, p, "file"), p + "/file");
    if (j.contains("material")) {
      // ObjShape's empty material means "the OBJ file's own": "" in a file would silently mean
      // that too, where every other shape refuses it as an unknown material
      obj.material = r.string(j["material"], p + "/material");
      if (obj.material.empty())
        r.fail(p + "/material",
               "must name a material, got an empty string (leave it out to use the OBJ file's "
               "materials)");
    }
    obj.transform = optional_transform(r, j, p);
    b.add_obj(obj);
    return;
  }
  std::optional<ShapeType> type = find_type<ShapeType>(name);
  if (!type)
    r.fail(p + "/type",
           "unknown value '" + name + "' (expected one of: " + type_names<ShapeType>() + ", mesh)");
  switch (*type) {
    case ShapeType::Sphere: {
      r.check_keys(j, p, {"type", "center", "radius", "material"});
      SphereShape s;
      s.center = r.vec3(r.require(j, p, "center"), p + "/center");
      s.radius = r.number(r.require(j, p, "radius"), p + "/radius");
      s.material = r.string(r.require(j, p, "material"), p + "/material");
      b.add_sphere(s);
      break;
    }
    case ShapeType::Triangle:
      r.check_keys(j, p,
                   {"type", "positions", "indices", "normals", "uvs", "material", "transform"});
      b.add_mesh(parse_triangles(r, j, p));
      break;
  }
}

}  // namespace

void parse_shapes(const JsonReader& r, const json& j, SceneBuilder& b) {
  r.check_array(j, "/shapes");
  for (size_t i = 0; i < j.size(); ++i) parse_shape(r, j[i], "/shapes/" + std::to_string(i), b);
}

}  // namespace lucent::scene_detail

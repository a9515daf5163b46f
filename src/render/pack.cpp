#include "render/pack.hpp"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "lucent/error.hpp"
#include "scene/loaders.hpp"

namespace lucent::render_detail {

namespace {

void put3(float* dst, const glm::dvec3& v) {
  dst[0] = static_cast<float>(v.x);
  dst[1] = static_cast<float>(v.y);
  dst[2] = static_cast<float>(v.z);
}

double luminance(const glm::dvec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

lc_uint material_type(MaterialType t) {
  switch (t) {
    case MaterialType::Mirror: return LC_MAT_MIRROR;
    case MaterialType::Dielectric: return LC_MAT_DIELECTRIC;
    case MaterialType::Conductor: return LC_MAT_CONDUCTOR;
    case MaterialType::Plastic: return LC_MAT_PLASTIC;
    default: return LC_MAT_DIFFUSE;
  }
}

lc_uint integrator_type(IntegratorType t) {
  switch (t) {
    case IntegratorType::Whitted: return LC_INTEGRATOR_WHITTED;
    case IntegratorType::Direct: return LC_INTEGRATOR_DIRECT;
    case IntegratorType::Albedo: return LC_INTEGRATOR_ALBEDO;
    case IntegratorType::Normal: return LC_INTEGRATOR_NORMAL;
    case IntegratorType::Depth: return LC_INTEGRATOR_DEPTH;
    case IntegratorType::Ao: return LC_INTEGRATOR_AO;
    case IntegratorType::Primitive: return LC_INTEGRATOR_PRIMITIVE;
    default: return LC_INTEGRATOR_PATH;
  }
}

lc_uint filter_type(FilterType t) {
  switch (t) {
    case FilterType::Tent: return LC_FILTER_TENT;
    case FilterType::Gaussian: return LC_FILTER_GAUSSIAN;
    default: return LC_FILTER_BOX;
  }
}

bool finite3(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace

lc_camera pack_camera(const Camera& c, int width, int height) {
  lc_camera cam{};
  glm::dvec3 fwd = glm::normalize(c.look_at - c.position);
  glm::dvec3 right = glm::normalize(glm::cross(fwd, c.up));
  glm::dvec3 up = glm::cross(right, fwd);
  if (c.roll_degrees != 0) {
    // counter-clockwise as seen looking along forward: right turns towards up
    double a = glm::radians(c.roll_degrees);
    glm::dvec3 r2 = std::cos(a) * right + std::sin(a) * up;
    up = -std::sin(a) * right + std::cos(a) * up;
    right = r2;
  }
  put3(cam.position, c.position);
  put3(cam.right, right);
  put3(cam.up, up);
  put3(cam.forward, fwd);
  cam.tan_half_fov = static_cast<float>(std::tan(glm::radians(c.fov_degrees) * 0.5));
  cam.aspect = static_cast<float>(width) / static_cast<float>(height);
  cam.lens_radius = static_cast<float>(c.aperture);
  cam.focus_distance = static_cast<float>(
      c.focus_distance > 0 ? c.focus_distance : glm::length(c.look_at - c.position));
  return cam;
}

PackedScene pack_scene(const Scene& scene) {
  PackedScene p;
  lc_params& P = p.params;
  P.camera = pack_camera(scene.camera, scene.film.width, scene.film.height);
  P.width = static_cast<lc_uint>(scene.film.width);
  P.height = static_cast<lc_uint>(scene.film.height);
  P.seed = scene.integrator.seed;
  P.max_depth = static_cast<lc_uint>(scene.integrator.max_depth);
  P.rr_depth = static_cast<lc_uint>(scene.integrator.rr_depth);
  P.integrator = integrator_type(scene.integrator.type);
  P.filter = filter_type(scene.film.filter.type);
  P.filter_radius = static_cast<float>(scene.film.filter.radius);
  P.env_light = -1;
  P.flags = scene.integrator.mis ? 0u : LC_FLAG_NO_MIS;
  P.ao_distance = scene.integrator.ao_distance > 0 ? static_cast<float>(scene.integrator.ao_distance)
                                                   : INFINITY;

  if (scene.materials.empty() && (!scene.spheres.empty() || !scene.triangles.empty()))
    throw Error(scene.path + ": shapes need at least one material");
  for (const Material& m : scene.materials) {
    lc_material d{};
    put3(d.albedo, m.albedo);
    d.albedo_tex = m.albedo_texture;
    put3(d.emission, m.emission);
    d.type = material_type(m.type);
    put3(d.specular, m.specular);
    d.ior = static_cast<float>(m.ior);
    d.roughness = static_cast<float>(m.roughness);
    p.materials.push_back(d);
  }

  std::vector<double> power;
  auto add_light = [&](lc_light l, double pw) {
    p.lights.push_back(l);
    power.push_back(std::max(0.0, pw));
    return static_cast<lc_uint>(p.lights.size() - 1);
  };

  for (const Sphere& s : scene.spheres) {
    lc_sphere d{};
    put3(d.center, s.center);
    d.radius = static_cast<float>(s.radius);
    d.material = static_cast<lc_uint>(s.material);
    d.light = LC_INVALID;
    const Material& m = scene.materials[s.material];
    if (m.emissive()) {
      lc_light l{};
      l.type = LC_LIGHT_SPHERE;
      put3(l.position, s.center);
      put3(l.intensity, m.emission);
      l.prim = static_cast<lc_uint>(p.spheres.size());
      l.area = static_cast<float>(4 * M_PI * s.radius * s.radius);
      l.texture = -1;
      d.light = add_light(l, luminance(m.emission) * M_PI * l.area);
    }
    p.spheres.push_back(d);
  }

  for (size_t i = 0; i < scene.triangles.size(); ++i) {
    const Triangle& t = scene.triangles[i];
    glm::dvec3 v[3] = {scene.positions[t.v[0]], scene.positions[t.v[1]], scene.positions[t.v[2]]};
    double area = 0.5 * glm::length(glm::cross(v[1] - v[0], v[2] - v[0]));
    if (!finite3(v[0]) || !finite3(v[1]) || !finite3(v[2]) || !(area > 0) || !std::isfinite(area)) {
      ++p.skipped_triangles;
      continue;
    }
    lc_triangle d{};
    put3(d.v0, v[0]);
    put3(d.v1, v[1]);
    put3(d.v2, v[2]);
    d.material = static_cast<lc_uint>(t.material);
    d.light = LC_INVALID;
    lc_triangle_attr a{};
    bool has_n = t.n[0] >= 0 && t.n[1] >= 0 && t.n[2] >= 0;
    bool has_uv = t.uv[0] >= 0 && t.uv[1] >= 0 && t.uv[2] >= 0;
    for (int k = 0; k < 3; ++k) {
      if (has_n) put3(a.n + 3 * k, scene.normals[t.n[k]]);
      if (has_uv) {
        a.uv[2 * k] = static_cast<float>(scene.uvs[t.uv[k]].x);
        a.uv[2 * k + 1] = static_cast<float>(scene.uvs[t.uv[k]].y);
      }
    }
    d.flags = (has_n ? LC_TRI_HAS_NORMALS : 0u) | (has_uv ? LC_TRI_HAS_UVS : 0u);
    a.source_index = static_cast<lc_uint>(i);
    const Material& m = scene.materials[t.material];
    if (m.emissive()) {
      lc_light l{};
      l.type = LC_LIGHT_TRIANGLE;
      put3(l.intensity, m.emission);
      l.prim = static_cast<lc_uint>(p.triangles.size());
      l.area = static_cast<float>(area);
      l.texture = -1;
      d.light = add_light(l, luminance(m.emission) * M_PI * area);
    }
    p.triangles.push_back(d);
    p.tri_attrs.push_back(a);
  }
  if (p.skipped_triangles > 0)
    scene_detail::warn(scene.path + ": skipped " + std::to_string(p.skipped_triangles) +
                       " degenerate or non-finite triangle(s)");

  p.bvh = bvh::build(p.triangles, p.spheres);

  // Radius of the region that matters, for the power of environment lights: the scene's
  // bounding radius, but no more than the camera's distance to what it looks at (a ground sphere
  // of radius 1000 would otherwise make the sky outweigh every point light a thousandfold).
  // Selection probabilities change only the variance, never the expected value.
  double radius = 1;
  if (!p.bvh.nodes.empty()) {
    const float *lo = p.bvh.bmin, *hi = p.bvh.bmax;
    glm::dvec3 d(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    radius = std::max(1e-6, 0.5 * glm::length(d));
  }
  double view = glm::length(scene.camera.look_at - scene.camera.position);
  if (view > 0 && std::isfinite(view)) radius = std::min(radius, view);
  for (const Light& l : scene.lights) {
    lc_light d{};
    d.texture = -1;
    d.prim = LC_INVALID;
    if (l.type == LightType::Point) {
      d.type = LC_LIGHT_POINT;
      put3(d.position, l.position);
      put3(d.intensity, l.intensity);
      add_light(d, luminance(l.intensity) * 4 * M_PI);
    } else {
      d.type = l.type == LightType::Environment ? LC_LIGHT_ENV : LC_LIGHT_ENV_MAP;
      put3(d.intensity, l.radiance);
      d.texture = l.texture;
      if (l.type == LightType::Environment) put3(P.env_radiance, l.radiance);
      P.env_light = static_cast<lc_int>(add_light(d, luminance(l.radiance) * M_PI * 4 * M_PI * radius * radius));
    }
  }
  double total = 0;
  for (double w : power) total += w;
  double acc = 0;
  for (size_t i = 0; i < p.lights.size(); ++i) {
    // 90% by power, 10% uniform: a defensive mixture, so that no light starves when one
    // power estimate dwarfs the others (an environment behind a 1000-unit floor sphere)
    double uniform = 1.0 / p.lights.size();
    double pdf = total > 0 ? 0.9 * power[i] / total + 0.1 * uniform : uniform;
    p.lights[i].pdf_select = static_cast<float>(pdf);
    acc += pdf;
    p.light_cdf.push_back(static_cast<float>(acc));
  }
  if (!p.light_cdf.empty()) p.light_cdf.back() = 1.0f;

  // environment maps: a CDF over texels (luminance x sin(theta)) after the light CDF
  for (lc_light& l : p.lights) {
    if (l.type != LC_LIGHT_ENV_MAP) continue;
    const Texture& t = scene.textures.at(static_cast<size_t>(l.texture));
    l.prim = static_cast<lc_uint>(p.light_cdf.size());
    std::vector<double> w(static_cast<size_t>(t.width) * t.height);
    double total_w = 0;
    for (int y = 0; y < t.height; ++y) {
      double sin_t = std::sin(M_PI * (y + 0.5) / t.height);
      for (int x = 0; x < t.width; ++x) {
        const float* px = &t.rgba[(static_cast<size_t>(y) * t.width + x) * 4];
        double lum = std::max(0.0, luminance({px[0], px[1], px[2]}));
        w[static_cast<size_t>(y) * t.width + x] = lum * sin_t;
        total_w += lum * sin_t;
      }
    }
    double run = 0;
    p.light_cdf.push_back(0.0f);
    for (double v : w) {
      run += total_w > 0 ? v / total_w : 1.0 / w.size();
      p.light_cdf.push_back(static_cast<float>(run));
    }
    p.light_cdf.back() = 1.0f;
  }

  for (const Texture& t : scene.textures) {
    lc_texture d{};
    d.offset = static_cast<lc_uint>(p.texels.size());
    d.width = static_cast<lc_uint>(t.width);
    d.height = static_cast<lc_uint>(t.height);
    p.textures.push_back(d);
    for (size_t i = 0; i + 3 < t.rgba.size(); i += 4)
      p.texels.push_back({t.rgba[i], t.rgba[i + 1], t.rgba[i + 2], t.rgba[i + 3]});
  }

  P.num_triangles = static_cast<lc_uint>(p.triangles.size());
  P.num_spheres = static_cast<lc_uint>(p.spheres.size());
  P.num_lights = static_cast<lc_uint>(p.lights.size());
  P.num_nodes = static_cast<lc_uint>(p.bvh.nodes.size());
  return p;
}

std::vector<std::string> scene_features(const Scene& scene, const PackedScene& packed) {
  std::vector<std::string> f;
  auto add = [&](bool on, const char* name) {
    if (on) f.push_back(name);
  };
  // materials some primitive uses (a declared but unused material costs nothing)
  std::vector<char> used(scene.materials.size(), 0);
  for (const lc_sphere& sp : packed.spheres) used[sp.material] = 1;
  for (const lc_triangle& t : packed.triangles) used[t.material] = 1;
  auto has_mat = [&](MaterialType t) {
    for (size_t i = 0; i < scene.materials.size(); ++i)
      if (used[i] && scene.materials[i].type == t) return true;
    return false;
  };
  auto has_light = [&](lc_uint type) {
    for (const lc_light& l : packed.lights)
      if (l.type == type) return true;
    return false;
  };
  bool textured = false;
  for (size_t i = 0; i < scene.materials.size(); ++i)
    textured = textured || (used[i] && scene.materials[i].albedo_texture >= 0);
  bool smooth = false, uvs = false;
  for (const lc_triangle& t : packed.triangles) {
    smooth = smooth || (t.flags & LC_TRI_HAS_NORMALS);
    uvs = uvs || (t.flags & LC_TRI_HAS_UVS);
  }
  IntegratorType it = scene.integrator.type;
  bool aov = it == IntegratorType::Albedo || it == IntegratorType::Normal ||
             it == IntegratorType::Depth || it == IntegratorType::Ao || it == IntegratorType::Primitive;
  add(!packed.spheres.empty(), "LC_HAS_SPHERES");
  add(!packed.triangles.empty(), "LC_HAS_TRIANGLES");
  add(smooth, "LC_HAS_SMOOTH_NORMALS");
  add(uvs && textured, "LC_HAS_UVS");
  add(textured, "LC_HAS_TEXTURES");
  add(has_mat(MaterialType::Mirror), "LC_HAS_MIRROR");
  add(has_mat(MaterialType::Dielectric), "LC_HAS_DIELECTRIC");
  add(has_mat(MaterialType::Conductor), "LC_HAS_CONDUCTOR");
  add(has_mat(MaterialType::Plastic), "LC_HAS_PLASTIC");
  add(has_light(LC_LIGHT_POINT), "LC_HAS_POINT_LIGHTS");
  add(has_light(LC_LIGHT_SPHERE), "LC_HAS_SPHERE_LIGHTS");
  add(has_light(LC_LIGHT_TRIANGLE), "LC_HAS_TRIANGLE_LIGHTS");
  add(has_light(LC_LIGHT_ENV), "LC_HAS_ENV");
  add(has_light(LC_LIGHT_ENV_MAP), "LC_HAS_ENV_MAP");
  add(scene.camera.aperture > 0, "LC_HAS_THIN_LENS");
  add(scene.film.filter.type == FilterType::Tent, "LC_HAS_FILTER_TENT");
  add(scene.film.filter.type == FilterType::Gaussian, "LC_HAS_FILTER_GAUSSIAN");
  add(it == IntegratorType::Path, "LC_HAS_INTEGRATOR_PATH");
  add(it == IntegratorType::Whitted, "LC_HAS_INTEGRATOR_WHITTED");
  add(it == IntegratorType::Direct, "LC_HAS_INTEGRATOR_DIRECT");
  add(aov, "LC_HAS_INTEGRATOR_AOV");
  return f;
}

const std::vector<std::string>& all_features() {
  static const std::vector<std::string> all = {
      "LC_HAS_SPHERES", "LC_HAS_TRIANGLES", "LC_HAS_SMOOTH_NORMALS", "LC_HAS_UVS", "LC_HAS_TEXTURES",
      "LC_HAS_MIRROR", "LC_HAS_DIELECTRIC", "LC_HAS_CONDUCTOR", "LC_HAS_PLASTIC",
      "LC_HAS_POINT_LIGHTS", "LC_HAS_SPHERE_LIGHTS", "LC_HAS_TRIANGLE_LIGHTS", "LC_HAS_ENV",
      "LC_HAS_ENV_MAP", "LC_HAS_THIN_LENS", "LC_HAS_FILTER_TENT", "LC_HAS_FILTER_GAUSSIAN",
      "LC_HAS_INTEGRATOR_PATH", "LC_HAS_INTEGRATOR_WHITTED", "LC_HAS_INTEGRATOR_DIRECT",
      "LC_HAS_INTEGRATOR_AOV"};
  return all;
}

std::string feature_defines(const Scene& scene, const PackedScene& packed, bool specialize) {
  std::string d;
  for (const std::string& f : specialize ? scene_features(scene, packed) : all_features()) d += " -D " + f;
  return d;
}

std::string build_options(const Scene& scene, const PackedScene& packed,
                          const RenderOptions& options) {
  std::string o = "-cl-std=CL1.2" + feature_defines(scene, packed, options.specialize);
  if (options.precision == Precision::Double) o += " -D LC_DOUBLE";
  if (options.fast_math) o += " -cl-fast-relaxed-math";
  return o;
}

void check_precision_support(const DeviceInfo& device, Precision precision) {
  if (precision == Precision::Double && !device.fp64)
    throw Error("--precision double: device '" + device.name +
                "' has no double-precision floating point (cl_khr_fp64); use --precision float "
                "or pick another device with --device");
}

}  // namespace lucent::render_detail

namespace lucent {

const char* precision_name(Precision p) { return p == Precision::Double ? "double" : "float"; }

Precision parse_precision(const std::string& text, const std::string& what) {
  if (text == "float") return Precision::Float;
  if (text == "double") return Precision::Double;
  throw Error(what + ": unknown precision '" + text + "' (expected float or double)");
}

}  // namespace lucent

// `lucent info SCENE`: what the scene holds (shapes, materials, textures, lights), the BVH built
// over it and the kernel feature defines it would be compiled with. Needs no OpenCL device.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "bvh/bvh.hpp"
#include "cl/kernel_source.hpp"
#include "lucent/scene.hpp"
#include "lucent/session.hpp"
#include "render/features.hpp"
#include "render/pack.hpp"

namespace lucent::cli {

namespace {

struct InfoArgs {
  std::string scene;
  std::string precision = "float";
  bool fast_math = false;
  bool no_specialize = false;
};

InfoArgs& args() {
  static InfoArgs a;
  return a;
}

std::string format_bytes(double b) {
  char buf[32];
  if (b >= 1024.0 * 1024 * 1024)
    std::snprintf(buf, sizeof buf, "%.2f GiB", b / (1024.0 * 1024 * 1024));
  else if (b >= 1024.0 * 1024)
    std::snprintf(buf, sizeof buf, "%.2f MiB", b / (1024.0 * 1024));
  else if (b >= 1024.0)
    std::snprintf(buf, sizeof buf, "%.2f KiB", b / 1024.0);
  else
    std::snprintf(buf, sizeof buf, "%.0f B", b);
  return buf;
}

const char* material_name(MaterialType t) {
  switch (t) {
    case MaterialType::Mirror:
      return "mirror";
    case MaterialType::Dielectric:
      return "dielectric";
    case MaterialType::Conductor:
      return "conductor";
    case MaterialType::Plastic:
      return "plastic";
    default:
      return "diffuse";
  }
}

const char* integrator_name(IntegratorType t) {
  switch (t) {
    case IntegratorType::Whitted:
      return "whitted";
    case IntegratorType::Direct:
      return "direct";
    case IntegratorType::Albedo:
      return "albedo";
    case IntegratorType::Normal:
      return "normal";
    case IntegratorType::Depth:
      return "depth";
    case IntegratorType::Ao:
      return "ao";
    case IntegratorType::Primitive:
      return "primitive";
    default:
      return "path";
  }
}

/// Shape entries of the scene file by type ("sphere", "triangles", "mesh"): the loaded Scene
/// merges meshes and triangle lists into one triangle list. The file was validated already.
std::map<std::string, int> shape_entries(const std::string& path) {
  std::map<std::string, int> out;
  std::ifstream f(path, std::ios::binary);
  nlohmann::json root = nlohmann::json::parse(f, nullptr, false);
  if (!root.is_object() || !root.contains("shapes") || !root["shapes"].is_array()) return out;
  for (const auto& s : root["shapes"])
    if (s.is_object() && s.contains("type") && s["type"].is_string())
      ++out[s["type"].get<std::string>()];
  return out;
}

}  // namespace

CLI::App* add_info_command(CLI::App& app) {
  CLI::App* cmd =
      app.add_subcommand("info", "Print scene statistics, its BVH and the kernel feature defines");
  cmd->add_option("scene", args().scene, "Scene file (JSON)")->required();
  cmd->add_option("--precision", args().precision,
                  "Show the build options for this precision: float (default) or double")
      ->check(CLI::IsMember({"float", "double"}));
  cmd->add_flag("--fast-math", args().fast_math,
                "Show the build options with -cl-fast-relaxed-math");
  cmd->add_flag("--no-specialize", args().no_specialize,
                "Show the build options of the full kernel");
  return cmd;
}

int run_info_command() {
  const std::string& path = args().scene;
  Scene scene = load_scene(path);
  render_detail::PackedScene packed = render_detail::pack_scene(scene);
  std::map<std::string, int> entries = shape_entries(path);

  std::printf("scene         %s\n", path.c_str());
  std::printf("film          %dx%d\n", scene.film.width, scene.film.height);
  std::printf("integrator    %s, max_depth %d, spp %d, seed %u\n",
              integrator_name(scene.integrator.type), scene.integrator.max_depth,
              scene.integrator.spp, static_cast<unsigned>(scene.integrator.seed));

  std::printf("\nshapes\n");
  std::printf("  spheres             %zu\n", scene.spheres.size());
  std::printf("  triangle lists      %d\n", entries["triangles"]);
  std::printf("  meshes              %d\n", entries["mesh"]);
  std::printf("  triangles           %zu", scene.triangles.size());
  if (packed.skipped_triangles > 0)
    std::printf(" (%zu degenerate or non-finite, skipped)", packed.skipped_triangles);
  std::printf("\n  vertices            %zu (normals %zu, uvs %zu)\n", scene.positions.size(),
              scene.normals.size(), scene.uvs.size());

  std::printf("\nmaterials     %zu\n", scene.materials.size());
  std::map<std::string, int> by_type;
  int emissive = 0;
  for (const Material& m : scene.materials) {
    ++by_type[material_name(m.type)];
    if (m.emissive()) ++emissive;
  }
  for (const auto& [name, n] : by_type) std::printf("  %-19s %d\n", name.c_str(), n);
  std::printf("  %-19s %d\n", "emissive", emissive);

  double texel_bytes = 0;
  for (const Texture& t : scene.textures) texel_bytes += double(t.width) * t.height * 16;
  std::printf("\ntextures      %zu (%s on the device)\n", scene.textures.size(),
              format_bytes(texel_bytes).c_str());
  for (const Texture& t : scene.textures)
    std::printf("  %dx%d  %-10s  %s\n", t.width, t.height,
                format_bytes(double(t.width) * t.height * 16).c_str(), t.path.c_str());

  std::size_t count[5] = {0, 0, 0, 0, 0};
  for (const lc_light& l : packed.lights)
    if (l.type < 5) ++count[l.type];
  std::printf("\nlights        %zu\n", packed.lights.size());
  std::printf("  point               %zu\n", count[LC_LIGHT_POINT]);
  std::printf("  emissive spheres    %zu\n", count[LC_LIGHT_SPHERE]);
  std::printf("  emissive triangles  %zu\n", count[LC_LIGHT_TRIANGLE]);
  std::printf("  environment         %zu\n", count[LC_LIGHT_ENV]);
  std::printf("  environment map     %zu\n", count[LC_LIGHT_ENV_MAP]);

  const bvh::BuildStats& s = packed.bvh_stats;
  std::printf("\nBVH\n");
  std::printf("  build time          %.3f ms\n", s.seconds * 1e3);
  std::printf("  primitives          %zu\n", s.primitives);
  std::printf("  nodes               %zu binary, collapsed into %zu %d-wide (%s)\n", s.binary_nodes,
              s.nodes, LC_BVH_WIDTH,
              format_bytes(double(packed.nodes.size()) * sizeof(lc_bvh_node)).c_str());
  std::printf("  leaves              %zu\n", s.leaves);
  std::printf("  leaf size           mean %.2f, max %zu\n", s.mean_leaf_size, s.max_leaf_size);
  std::printf("  max depth           %zu binary, %zu wide\n", s.binary_max_depth, s.max_depth);
  std::printf("  SAH cost            %.3f\n", s.sah_cost);

  std::string defines = render_detail::feature_defines(scene, packed);
  if (!defines.empty() && defines[0] == ' ') defines.erase(0, 1);
  RenderOptions options;
  options.precision = parse_precision(args().precision);
  options.fast_math = args().fast_math;
  options.specialize = !args().no_specialize;
  std::printf("\nkernel\n");
  std::string kernel_dir = SessionOptions::from_environment().kernel_dir;
  std::printf("  sources             %s\n", kernel_dir.empty() ? "embedded" : kernel_dir.c_str());
  std::printf("  feature defines     %s\n", defines.empty() ? "(none)" : defines.c_str());
  std::printf(
      "  precision           %s%s\n", precision_name(options.precision),
      options.precision == Precision::Double ? " (rays and geometry in double; needs fp64)" : "");
  std::printf("  math                %s\n",
              options.fast_math ? "fast (-cl-fast-relaxed-math)" : "IEEE");
  std::printf("  build options       %s\n",
              render_detail::build_options(scene, packed, options).c_str());
  return 0;
}

}  // namespace lucent::cli

// `lucent info SCENE`: what the scene holds (shapes, materials, textures, lights), the BVH built
// over it and the kernel feature defines it would be compiled with. Needs no OpenCL device.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <map>
#include <string>

#include "bvh/bvh.hpp"
#include "cl/context.hpp"
#include "cl/kernel_source.hpp"
#include "cli/commands.hpp"
#include "lucent/scene.hpp"
#include "lucent/session.hpp"
#include "lucent/types.hpp"
#include "render/features.hpp"
#include "render/integrator_knobs.hpp"
#include "render/pack.hpp"
#include "render/resources.hpp"
#include "scene/validate.hpp"

namespace lucent::cli {

namespace {

struct InfoArgs {
  std::string scene;
  std::string integrator;
  std::string precision = "float";
  bool fast_math = false;
  bool no_specialize = false;
  SamplingArgs sampling;
};

InfoArgs& info_args() {
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

/// Counts by registry entry, printed one line per entry (zeros included) under a section.
template <class E>
void print_counts(const std::map<E, std::size_t>& counts) {
  for (const TypeEntry<E>& e : TypeList<E>::entries) {
    auto it = counts.find(e.value);
    std::printf("  %-19s %zu\n", e.name, it == counts.end() ? std::size_t(0) : it->second);
  }
}

/// The estimate `lucent render` checks before rendering on PoCL's CPU device (its buffers are host
/// memory), part by part, against what lucent allows itself (render/resources.hpp); the output's
/// write comes on top (docs/reliability.md, "Resources").
void print_memory(const Scene& scene) {
  // (one description: lucent render gives its scene to the session)
  std::vector<render_detail::MemoryPart> parts =
      render_detail::estimate_host_memory(scene, {render_detail::DeviceLimits::cpu()}, 1);
  std::stable_sort(parts.begin(), parts.end(),
                   [](const auto& a, const auto& b) { return a.bytes > b.bytes; });
  const std::uint64_t total = render_detail::total_bytes(parts);
  std::string what;
  const std::uint64_t limit = render_detail::host_memory_allowed(&what);
  std::printf("\nhost memory   %s estimated for a render on a CPU device",
              format_bytes(total).c_str());
  if (limit > 0)
    std::printf(" (lucent allows itself %s: 80%% of %s)", format_bytes(limit).c_str(),
                what.c_str());
  std::printf("\n");
  for (const render_detail::MemoryPart& p : parts)
    if (p.bytes > 0) std::printf("  %-10s  %s\n", format_bytes(p.bytes).c_str(), p.what.c_str());
}

}  // namespace

CLI::App* add_info_command(CLI::App& app) {
  CLI::App* cmd =
      app.add_subcommand("info", "Print scene statistics, its BVH and the kernel feature defines");
  cmd->add_option("scene", info_args().scene, "Scene file (JSON)")->required()->check(non_empty());
  cmd->add_option("--integrator", info_args().integrator,
                  "Show the scene with this integrator (as render --integrator): " +
                      type_names<IntegratorType>())
      ->check(non_empty());
  cmd->add_option("--precision", info_args().precision,
                  "Show the build options for this precision: float (default) or double")
      ->check(CLI::IsMember({"float", "double"}));
  cmd->add_flag("--fast-math", info_args().fast_math,
                "Show the build options with -cl-fast-relaxed-math");
  cmd->add_flag("--no-specialize", info_args().no_specialize,
                "Show the build options of the full kernel");
  add_sampling_options(cmd, info_args().sampling, false);
  return cmd;
}

int run_info_command() {
  const std::string& path = info_args().scene;
  Scene scene = load_scene(path);
  if (!info_args().integrator.empty())
    scene.integrator.type = parse_integrator(info_args().integrator);
  apply_sampling_options(info_args().sampling, scene);
  render_detail::check_packing_host_memory(scene);
  render_detail::PackedScene packed = render_detail::pack_scene(scene);
  // what a render of it says (an albedo above 1, float's rounding, settings that change nothing)
  for (const std::string& note : scene_detail::energy_gain_notes(scene)) scene_detail::warn(note);
  for (const std::string& note : render_detail::packing_notes(
           scene, packed, parse_precision(info_args().precision) == Precision::Float))
    scene_detail::warn(note);

  std::printf("scene         %s\n", one_line(path).c_str());
  std::printf("film          %dx%d\n", scene.film.width, scene.film.height);
  std::printf("integrator    %s, max_depth %d, spp %d, seed %u\n", type_name(scene.integrator.type),
              scene.integrator.max_depth, scene.integrator.spp,
              static_cast<unsigned>(scene.integrator.seed));
  std::printf("filter        %s, radius %g\n", type_name(scene.film.filter.type),
              scene.film.filter.radius);
  std::printf("sampler       %s\n", type_name(scene.integrator.sampler));
  // what the 8-bit outputs apply (README, "film")
  const Film& film = scene.film;
  std::printf("display       %s", transfer_name(film.transfer));
  if (film.transfer == Transfer::Gamma) std::printf(" %g", film.gamma);
  std::printf(", exposure %g, tonemap %s\n", film.exposure, tonemap_name(film.tonemap));
  // what the render does with the path integrator's knobs, not only what the scene says: a
  // setting the render leaves unused says why (the kernel's features decide, as for the render)
  using render_detail::IntegratorKnob;
  const std::vector<std::string> features = render_detail::scene_features(scene, packed);
  auto has = [&features](const char* f) {
    return std::find(features.begin(), features.end(), f) != features.end();
  };
  auto why_unused = [&scene](IntegratorKnob knob, const char* otherwise) {
    const char* why = render_detail::knob_ignored(scene.integrator.type, knob);
    return std::string(why ? why : otherwise);
  };
  std::string clamp = "off", caustics = "off",
              splits = std::to_string(scene.integrator.dielectric_splits);
  if (scene.integrator.clamp > 0) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", scene.integrator.clamp);
    clamp = buf;
    if (!has("LC_HAS_CLAMP")) clamp += " (unused: " + why_unused(IntegratorKnob::Clamp, "") + ")";
  }
  if (scene.integrator.caustics)
    caustics = has("LC_HAS_CAUSTICS")
                   ? "on"
                   : "off (asked for; " +
                         why_unused(IntegratorKnob::Caustics,
                                    "no mirror or smooth glass surface in the scene") +
                         ")";
  if (scene.integrator.dielectric_splits > 0 && !has("LC_HAS_SPLITTING"))
    splits +=
        " (unused: " + why_unused(IntegratorKnob::Splits, "no smooth glass in the scene") + ")";
  std::printf("clamp         %s\n", clamp.c_str());
  std::printf("caustics      %s\n", caustics.c_str());
  std::printf("glass splits  %s\n", splits.c_str());

  // the shape list as written: its entries by type (OBJ files apart), then the primitives
  std::map<ShapeType, std::size_t> by_shape;
  std::size_t meshes = 0;
  for (const ShapeEntry& e : scene.shapes) ++(e.file.empty() ? by_shape[e.type] : meshes);
  std::printf("\nshapes        %zu\n", scene.shapes.size());
  print_counts(by_shape);
  std::printf("  %-19s %zu\n", "mesh", meshes);
  std::printf("\nprimitives\n");
  std::printf("  spheres             %zu\n", scene.spheres.size());
  std::printf("  triangles           %zu", scene.triangles.size());
  if (packed.skipped_triangles > 0)
    std::printf(" (%zu degenerate or non-finite, skipped)", packed.skipped_triangles);
  std::printf("\n  vertices            %zu (normals %zu, uvs %zu)\n", scene.positions.size(),
              scene.normals.size(), scene.uvs.size());

  std::printf("\nmaterials     %zu\n", scene.materials.size());
  std::map<MaterialType, std::size_t> by_type;
  std::size_t emissive = 0;
  for (const Material& m : scene.materials) {
    ++by_type[m.type];
    if (m.emissive()) ++emissive;
  }
  print_counts(by_type);
  std::printf("  %-19s %zu\n", "emissive", emissive);

  double texel_bytes = 0;
  for (const Texture& t : scene.textures) texel_bytes += double(t.width) * t.height * 16;
  std::printf("\ntextures      %zu (%s on the device)\n", scene.textures.size(),
              format_bytes(texel_bytes).c_str());
  for (const Texture& t : scene.textures)
    std::printf("  %dx%d  %-10s  %s\n", t.width, t.height,
                format_bytes(double(t.width) * t.height * 16).c_str(), one_line(t.path).c_str());

  // the packed lights: the scene's lights and one per emissive sphere or triangle
  std::map<LightType, std::size_t> lights;
  for (const lc_light& l : packed.lights) ++lights[static_cast<LightType>(l.type)];
  std::printf("\nlights        %zu\n", packed.lights.size());
  print_counts(lights);

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

  RenderOptions options;
  options.precision = parse_precision(info_args().precision);
  options.fast_math = info_args().fast_math;
  options.specialize = !info_args().no_specialize;
  // (--no-specialize: every feature, as the build options below and Python's scene_info say)
  std::string defines = render_detail::feature_defines(scene, packed, options.specialize);
  if (!defines.empty() && defines[0] == ' ') defines.erase(0, 1);
  print_memory(scene);
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
  // what each device's build adds, from render_detail::device_defines itself (info opens no
  // device): PoCL's CPU device (which has fp64 and 64-bit atomics), another device with both,
  // one with fp64 only and one without
  DeviceInfo pocl_cpu;
  pocl_cpu.type = "CPU";
  pocl_cpu.platform = cl_util::kPoclPlatform;
  pocl_cpu.fp64 = pocl_cpu.int64_atomics = true;
  DeviceInfo with_atomics;
  with_atomics.type = "GPU";
  with_atomics.fp64 = with_atomics.int64_atomics = true;
  DeviceInfo with_fp64;
  with_fp64.type = "GPU";
  with_fp64.fp64 = true;
  const DeviceInfo without_fp64;
  auto device_options = [](const DeviceInfo& d) {
    std::string s = render_detail::device_defines(d);
    return s.empty() ? std::string("none") : s.substr(1);
  };
  std::printf(
      "  device options      %s on PoCL's CPU device, %s on other devices with fp64 and 64-bit "
      "atomics, %s on those with fp64 only, %s on others\n",
      device_options(pocl_cpu).c_str(), device_options(with_atomics).c_str(),
      device_options(with_fp64).c_str(), device_options(without_fp64).c_str());
  return 0;
}

}  // namespace lucent::cli

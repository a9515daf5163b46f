#include "cl/kernel_source.hpp"

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include "lucent/error.hpp"
#include "render/features.hpp"
#include "shared/registry.h"

namespace lucent::detail {

namespace {

void expand(const std::string& path, const std::string& kernel_dir, std::set<std::string>& seen,
            std::ostringstream& out) {
  if (!seen.insert(path).second) return;  // each file once (all headers are guarded anyway)
  std::istringstream in(read_kernel_file(path, kernel_dir));
  out << "#line 1 \"kernels/" << path << "\"\n";
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    std::string::size_type p = line.find_first_not_of(" \t");
    if (p != std::string::npos && line.compare(p, 8, "#include") == 0) {
      if (line.find('<', p + 8) != std::string::npos) {  // <system> headers: host-only branches
        out << line << '\n';
        continue;
      }
      auto q1 = line.find('"', p + 8);
      auto q2 = q1 == std::string::npos ? q1 : line.find('"', q1 + 1);
      if (q1 == std::string::npos || q2 == std::string::npos)
        throw Error("kernels/" + path + ":" + std::to_string(number) +
                    ": only #include \"file\" is supported in kernel sources");
      expand(line.substr(q1 + 1, q2 - q1 - 1), kernel_dir, seen, out);
      out << "#line " << number + 1 << " \"kernels/" << path << "\"\n";
      continue;
    }
    out << line << '\n';
  }
}

// The kernel files generated from the registries (kernels/shared/registry.h): the per-type file
// lists that bsdf/bsdf.cl, light/light.cl, geom/interaction.cl and integrator/integrator.cl
// include, LC_ENABLED's 0 for every feature (shared/registry.h), and every feature define (for
// probe kernels that test every type).
bool generated_kernel_file(const std::string& path, std::string& text) {
  std::ostringstream out;
  out << "/* generated from kernels/shared/registry.h by src/cl/kernel_source.cpp */\n";
#define LUCENT_INCLUDE_TYPE(dir) \
  [&](const char* file) { out << "#include \"" dir "/" << file << ".cl\"\n"; }
  if (path == "generated/materials.cl") {
    auto add = LUCENT_INCLUDE_TYPE("bsdf");
#define X(ID, Name, value, name, feature, file, params) add(#file);
    LC_MATERIAL_TYPES(X)
#undef X
  } else if (path == "generated/lights.cl") {
    auto add = LUCENT_INCLUDE_TYPE("light");
#define X(ID, Name, value, name, feature, file, params) add(#file);
    LC_LIGHT_TYPES(X)
#undef X
  } else if (path == "generated/shapes.cl") {
    auto add = LUCENT_INCLUDE_TYPE("geom");
#define X(ID, Name, value, name, feature, file) add(#file);
    LC_SHAPE_TYPES(X)
#undef X
  } else if (path == "generated/integrators.cl") {
    auto add = LUCENT_INCLUDE_TYPE("integrator");
#define X(ID, Name, value, name, feature, file) add(#file);
    LC_INTEGRATOR_TYPES(X)
#undef X
  } else if (path == "generated/features_off.cl") {
    // LC_ENABLED's value for a feature that is not defined (shared/registry.h)
    for (const std::string& f : render_detail::all_features())
      out << "#define LC_ON_" << f << " 0\n";
  } else if (path == "generated/all_features.cl") {
    for (const std::string& f : render_detail::all_features())
      out << "#ifndef " << f << "\n#define " << f << " 1\n#endif\n";
  } else {
    return false;
  }
#undef LUCENT_INCLUDE_TYPE
  text = out.str();
  return true;
}

}  // namespace

std::string read_kernel_file(const std::string& path, const std::string& kernel_dir) {
  std::string generated;
  if (path.rfind("generated/", 0) == 0) {
    if (generated_kernel_file(path, generated)) return generated;
    throw Error("kernels/" + path + ": no such generated kernel source");
  }
  if (!kernel_dir.empty()) {
    std::string full = kernel_dir + "/" + path;
    std::ifstream f(full, std::ios::binary);
    if (!f) throw Error(full + ": cannot read kernel source (kernel directory " + kernel_dir + ")");
    std::ostringstream ss;
    ss << f.rdbuf();
    return ss.str();
  }
  for (int i = 0; i < kEmbeddedKernelFileCount; ++i)
    if (path == kEmbeddedKernelFiles[i].path) return kEmbeddedKernelFiles[i].content;
  throw Error("kernels/" + path + ": no such embedded kernel source");
}

std::string assemble_kernel_source(const std::string& path, const std::string& kernel_dir) {
  std::set<std::string> seen;
  std::ostringstream out;
  expand(path, kernel_dir, seen, out);
  return out.str();
}

}  // namespace lucent::detail

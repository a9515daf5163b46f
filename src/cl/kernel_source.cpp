#include "cl/kernel_source.hpp"

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <set>
#include <sstream>

#include "core/file_io.hpp"
#include "lucent/error.hpp"
#include "render/features.hpp"
#include "shared/registry.h"

namespace lucent::detail {

namespace {

// `included_from`: "<file>:<line>" of the #include that names `path` ("" for the main file), so
// that a file that cannot be read is reported with the place that wants it.
void expand(const std::string& path, const std::string& kernel_dir, std::set<std::string>& seen,
            std::ostringstream& out, const std::string& included_from = "") {
  if (!seen.insert(path).second) return;  // each file once (all headers are guarded anyway)
  std::string text;
  try {
    text = read_kernel_file(path, kernel_dir);
  } catch (const Error& e) {
    if (included_from.empty()) throw;
    throw Error(included_from + ": #include \"" + path + "\": " + e.what());
  }
  std::istringstream in(text);
  // the place of a line for messages: the file in the kernel directory when sources come from one
  // (the generated files never do)
  const bool own = !kernel_dir.empty() && path.rfind("generated/", 0) != 0;
  const std::string file = (own ? kernel_dir : std::string("kernels")) + "/" + path;
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
        throw Error(file + ":" + std::to_string(number) +
                    ": only #include \"file\" is supported in kernel sources");
      expand(line.substr(q1 + 1, q2 - q1 - 1), kernel_dir, seen, out,
             file + ":" + std::to_string(number));
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
    const std::string full = kernel_dir + "/" + path;
    const std::string where = " (kernel directory " + kernel_dir + ")";
    std::error_code ec;
    if (!std::filesystem::exists(full, ec))
      throw Error(full + ": cannot read kernel source" + where);
    // bounded, regular files only, text: a directory there read as an empty file (the build
    // then failed on names it lacked, elsewhere), a FIFO hung the render and /dev/zero ate memory
    io::ReadSpec spec;
    spec.what = "kernel source";
    spec.max_bytes = 16u << 20;
    spec.text = true;
    try {
      return io::read_file(full, spec);
    } catch (const Error& e) {
      throw Error(e.what() + where);
    }
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

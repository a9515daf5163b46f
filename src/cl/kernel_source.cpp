#include "cl/kernel_source.hpp"

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include "lucent/error.hpp"

namespace lucent::detail {

namespace {

const char* kernel_dir_override() {
  const char* dir = std::getenv("LUCENT_KERNEL_DIR");
  return (dir && *dir) ? dir : nullptr;
}

void expand(const std::string& path, std::set<std::string>& seen, std::ostringstream& out) {
  if (!seen.insert(path).second) return;  // each file once (all headers are guarded anyway)
  std::istringstream in(read_kernel_file(path));
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
      expand(line.substr(q1 + 1, q2 - q1 - 1), seen, out);
      out << "#line " << number + 1 << " \"kernels/" << path << "\"\n";
      continue;
    }
    out << line << '\n';
  }
}

}  // namespace

std::string read_kernel_file(const std::string& path) {
  if (const char* dir = kernel_dir_override()) {
    std::string full = std::string(dir) + "/" + path;
    std::ifstream f(full, std::ios::binary);
    if (!f) throw Error(full + ": cannot read kernel source (LUCENT_KERNEL_DIR is set)");
    std::ostringstream ss;
    ss << f.rdbuf();
    return ss.str();
  }
  for (int i = 0; i < kEmbeddedKernelFileCount; ++i)
    if (path == kEmbeddedKernelFiles[i].path) return kEmbeddedKernelFiles[i].content;
  throw Error("kernels/" + path + ": no such embedded kernel source");
}

std::string assemble_kernel_source(const std::string& path) {
  std::set<std::string> seen;
  std::ostringstream out;
  expand(path, seen, out);
  return out.str();
}

std::string kernel_source_origin() {
  const char* dir = kernel_dir_override();
  return dir ? std::string(dir) : std::string("embedded");
}

}  // namespace lucent::detail

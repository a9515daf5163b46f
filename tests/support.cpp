#include "support.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace lucent::test {

namespace fs = std::filesystem;

namespace {
std::string read_all(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

struct TempRoot {
  std::string path;
  TempRoot() {
    path = std::string(LUCENT_BINARY_DIR) + "/test_tmp/" + std::to_string(::getpid());
    fs::create_directories(path);
  }
  ~TempRoot() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

TempRoot& temp_root() {
  static TempRoot root;
  return root;
}
}  // namespace

std::string temp_dir() {
  static std::atomic<int> counter{0};
  std::string dir = temp_root().path + "/" + std::to_string(counter++);
  fs::create_directories(dir);
  return dir;
}

CommandResult run_cli(const std::string& args, const std::string& env) {
  std::string dir = temp_dir();
  std::string out = dir + "/stdout", err = dir + "/stderr";
  std::string cmd = (env.empty() ? "" : env + " ") + std::string("'") + LUCENT_CLI_PATH + "' " +
                    args + " </dev/null >'" + out + "' 2>'" + err + "'";
  int raw = std::system(cmd.c_str());
  CommandResult r;
  if (WIFEXITED(raw))
    r.status = WEXITSTATUS(raw);
  else if (WIFSIGNALED(raw))
    r.status = 128 + WTERMSIG(raw);
  r.out = read_all(out);
  r.err = read_all(err);
  return r;
}

void write_file(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
}

std::string source_path(const std::string& rel) { return std::string(LUCENT_SOURCE_DIR) + "/" + rel; }

std::string shared_asset(const std::string& rel) {
  std::string p = std::string(LUCENT_SHARED_DIR) + "/assets/" + rel;
  return fs::exists(p) ? p : std::string();
}

RenderResult render_json(const std::string& json, int spp) {
  Scene scene = parse_scene(json, temp_dir() + "/scene.json");
  RenderOptions opt;
  opt.spp = spp;
  return render(scene, opt);
}

int count_lines(const std::string& s) {
  std::istringstream in(s);
  std::string line;
  int n = 0;
  while (std::getline(in, line))
    if (!line.empty()) ++n;
  return n;
}

}  // namespace lucent::test

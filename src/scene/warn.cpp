#include <cstdio>

#include "scene/loaders.hpp"

namespace lucent::scene_detail {

namespace {
void stderr_sink(const std::string& message) { std::fprintf(stderr, "lucent: warning: %s\n", message.c_str()); }
void (*g_sink)(const std::string&) = stderr_sink;
}  // namespace

void warn(const std::string& message) { g_sink(message); }
void set_warning_sink(void (*sink)(const std::string&)) { g_sink = sink ? sink : stderr_sink; }

}  // namespace lucent::scene_detail

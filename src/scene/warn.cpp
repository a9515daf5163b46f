#include <cstdio>
#include <utility>

#include "core/text.hpp"
#include "scene/loaders.hpp"

namespace lucent::scene_detail {

namespace {
void stderr_sink(const std::string& message) {
  std::fprintf(stderr, "lucent: warning: %s\n", io::one_line(message).c_str());
}
void (*g_sink)(const std::string&) = stderr_sink;
thread_local const std::function<void(const std::string&)>* t_sink = nullptr;
}  // namespace

void warn(const std::string& message) {
  if (t_sink && *t_sink)
    (*t_sink)(message);
  else
    g_sink(message);
}
void set_warning_sink(void (*sink)(const std::string&)) { g_sink = sink ? sink : stderr_sink; }

ScopedWarningSink::ScopedWarningSink(const std::function<void(const std::string&)>& sink)
    : previous_(t_sink) {
  if (sink) t_sink = &sink;
}
ScopedWarningSink::~ScopedWarningSink() { t_sink = previous_; }

}  // namespace lucent::scene_detail

namespace lucent {

// (the public scope: its own copy of the sink, which a caller's temporary lambda may be)
ScopedWarningSink::ScopedWarningSink(WarningSink sink)
    : sink_(std::move(sink)), previous_(scene_detail::t_sink) {
  if (sink_) scene_detail::t_sink = &sink_;
}
ScopedWarningSink::~ScopedWarningSink() { scene_detail::t_sink = previous_; }

}  // namespace lucent

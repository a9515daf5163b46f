#pragma once
// Where the library's warnings go: a scene that loads but may not render as meant (a
// focus_distance without an aperture, an OBJ's missing MTL file or texture), a render's notes
// (a scene without lights, degenerate triangles skipped). By default each is printed on stderr
// as "lucent: warning: <message>".
#include <functional>
#include <string>

namespace lucent {

/// Receives warnings (one line each, without the "lucent: warning: " prefix).
using WarningSink = std::function<void(const std::string&)>;

/// While alive, the warnings given on the calling thread go to `sink` instead of stderr: those of
/// load_scene, parse_scene, SceneBuilder (add_obj's OBJ and MTL files), render_reference and a
/// session's or a one-shot render's calls, unless their own options name a sink
/// (SessionOptions::on_warning, RenderOptions::on_warning, ReferenceOptions::on_warning), which
/// takes precedence. A sink that does nothing silences them. Scopes nest (the innermost one's
/// sink receives them) and must end in reverse order, on the thread that made them, as local
/// variables do. A null sink changes nothing.
///
///   std::vector<std::string> warnings;
///   {
///     lucent::ScopedWarningSink sink([&](const std::string& w) { warnings.push_back(w); });
///     scene = lucent::load_scene("scene.json");
///   }
class ScopedWarningSink {
 public:
  explicit ScopedWarningSink(WarningSink sink);
  ~ScopedWarningSink();
  ScopedWarningSink(const ScopedWarningSink&) = delete;
  ScopedWarningSink& operator=(const ScopedWarningSink&) = delete;

 private:
  WarningSink sink_;
  const WarningSink* previous_;
};

}  // namespace lucent

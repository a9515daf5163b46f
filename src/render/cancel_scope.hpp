#pragma once
// Several calls of one session as one operation for Renderer::cancel(): run_convergence's ladder
// (src/render/converge.cpp) renders rung after rung on one session, and a call clears the cancel
// asked for before it began, so a cancel between two rungs was forgotten and the ladder went on.
#include <atomic>
#include <functional>

#include "lucent/session.hpp"

namespace lucent::render_detail {

/// While alive, the calls of `renderer` are one operation for Renderer::cancel(): a cancel asked
/// for during any of them or between two of them stays asked for (no call clears it as it
/// starts), so that every call after it stops at once, and cancelled() tells the caller to stop
/// calling. A cancel asked for before the scope began is dropped, as a call's start drops it.
/// Created and destroyed on the thread that makes the calls; scopes may nest.
class CancelScope {
 public:
  /// Begins the operation `call` ("run_convergence"), whose cancel flag is `flag` while it lives
  /// (null: the session's own). Throws lucent::Error naming `call`, changing nothing, while a call
  /// of the session is in progress (another thread's render, or this call made from a render's
  /// on_progress): run_convergence there had already cleared the render's pending cancel and
  /// replaced its cancel flag when its first set_build_options was refused, so that the render
  /// ran its full time.
  CancelScope(Renderer& renderer, const char* call, const std::atomic<bool>* flag = nullptr);
  ~CancelScope();
  CancelScope(const CancelScope&) = delete;
  CancelScope& operator=(const CancelScope&) = delete;

  /// cancel() was called since the scope began, or the session's cancel flag is raised.
  bool cancelled() const;

  /// Runs `f` (a callback of the operation: run_convergence's on_point), holding the session as a
  /// call does: a call that changes it (set_scene, render, reset, ...) is refused from `f`,
  /// naming `what` ("run_convergence's on_point": a study whose on_point set another scene
  /// measured that scene's error against the reference, without a word); reads and cancel() work.
  void hold(const char* what, const std::function<void()>& f);

 private:
  Renderer& renderer_;
  const std::atomic<bool>* flag_before_ = nullptr;  ///< the session's flag, given back at the end
  bool flag_replaced_ = false;
};

}  // namespace lucent::render_detail

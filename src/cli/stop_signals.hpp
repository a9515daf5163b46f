#pragma once
// SIGINT, SIGTERM and SIGHUP for `lucent` and `lucent-mpi`: the first stops the work after the
// current pass (a handler sets a flag), and a second one of any of the three ends the process at
// once. A signal the process was started with ignored (nohup's SIGHUP, SIGINT of a script's
// background job) stays ignored: lucent stopped on them, against the shell's convention.
#include <signal.h>

#include <csignal>

namespace lucent::cli {

inline constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP};

/// A stop signal's name in messages ("interrupted by SIGTERM ..."): SIGTERM, SIGHUP, else
/// "SIGINT (Ctrl-C)".
inline const char* signal_name(int sig) {
  return sig == SIGTERM ? "SIGTERM" : sig == SIGHUP ? "SIGHUP" : "SIGINT (Ctrl-C)";
}

namespace stop_detail {
/// Which of kStopSignals the process started with ignored (set before any handler is installed,
/// read in the handlers).
inline volatile std::sig_atomic_t ignored[3] = {0, 0, 0};
}  // namespace stop_detail

/// Installs `handler` for each stop signal that is not ignored; returns nothing to restore: see
/// StopSignalScope for a command that gives them back.
inline void install_stop_handler(void (*handler)(int)) {
  for (int i = 0; i < 3; ++i) {
    struct sigaction now {};
    ::sigaction(kStopSignals[i], nullptr, &now);
    stop_detail::ignored[i] = now.sa_handler == SIG_IGN;
    if (!stop_detail::ignored[i]) std::signal(kStopSignals[i], handler);
  }
}

/// In a handler, after the first stop signal: each stop signal that was not ignored back to its
/// default, so that a second one, of any of the three, ends the process (only the one received
/// was: SIGTERM then SIGHUP was a second graceful stop, named SIGHUP). Async-signal-safe.
inline void stop_signals_to_default() {
  for (int i = 0; i < 3; ++i)
    if (!stop_detail::ignored[i]) std::signal(kStopSignals[i], SIG_DFL);
}

/// install_stop_handler() while alive; the dispositions before it afterwards (converge gives
/// them back when its outputs are written, also when it throws).
class StopSignalScope {
 public:
  explicit StopSignalScope(void (*handler)(int)) {
    for (int i = 0; i < 3; ++i) ::sigaction(kStopSignals[i], nullptr, &before_[i]);
    install_stop_handler(handler);
  }
  ~StopSignalScope() {
    for (int i = 0; i < 3; ++i) ::sigaction(kStopSignals[i], &before_[i], nullptr);
  }
  StopSignalScope(const StopSignalScope&) = delete;
  StopSignalScope& operator=(const StopSignalScope&) = delete;

 private:
  struct sigaction before_[3]{};
};

}  // namespace lucent::cli

#pragma once
// SIGINT, SIGTERM and SIGHUP for `lucent` and `lucent-mpi`: the first stops the work after the
// current pass (a handler sets a flag). A second one ends the process at once: the same signal
// at any time, another of the three from a second after the first. Another one within that
// second is part of the same stop: LSF's bkill sends SIGINT and SIGTERM together (then SIGKILL
// after its grace period), systemd SIGTERM then SIGHUP, and either killed the render with
// nothing written. (Before 30 Nov 2026 only the same signal ended it, at any time, and SIGTERM
// then SIGHUP was a second graceful stop named SIGHUP.)
//
// A signal the process was started with ignored (nohup's SIGHUP, SIGINT of a script's background
// job) stays ignored, and blocked: lucent stopped on them, against the shell's convention, and
// PoCL's LLVM, which installs handlers of its own while it builds, failed a kernel build on one.
#include <pthread.h>
#include <signal.h>
#include <time.h>

#include <atomic>

namespace lucent::cli {

inline constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP};

/// A stop signal's name in messages ("interrupted by SIGTERM ..."): SIGTERM, SIGHUP, else
/// "SIGINT (Ctrl-C)".
inline const char* signal_name(int sig) {
  return sig == SIGTERM ? "SIGTERM" : sig == SIGHUP ? "SIGHUP" : "SIGINT (Ctrl-C)";
}

namespace stop_detail {
/// The first stop signal received (0: none yet) and when (CLOCK_MONOTONIC, ns): read and written
/// by the handlers of any thread (lock-free atomics are async-signal-safe).
inline std::atomic<int> first_signal{0};
inline std::atomic<long long> first_ns{0};
/// A later signal of another kind within this of the first is part of the same stop.
inline constexpr long long kSameStopNs = 1000000000;

inline long long monotonic_ns() {
  timespec t{};
  ::clock_gettime(CLOCK_MONOTONIC, &t);  // async-signal-safe
  return static_cast<long long>(t.tv_sec) * 1000000000 + t.tv_nsec;
}

inline void default_action(int sig) {
  struct sigaction d {};
  d.sa_handler = SIG_DFL;
  sigemptyset(&d.sa_mask);
  ::sigaction(sig, &d, nullptr);
}

/// The three stop signals as a set.
inline sigset_t stop_set() {
  sigset_t s;
  sigemptyset(&s);
  for (int sig : kStopSignals) sigaddset(&s, sig);
  return s;
}
}  // namespace stop_detail

/// For a command's handler, first: true for the first stop signal (the handler then records its
/// stop); for a later one false, having ended the process (the same signal again: its default
/// action is back; another one a second or more after the first) or let it pass (another one
/// within that second). Async-signal-safe.
inline bool first_stop_signal(int sig) {
  using namespace stop_detail;
  const long long now = monotonic_ns();
  int none = 0;
  if (first_signal.compare_exchange_strong(none, sig)) {
    first_ns.store(now);
    default_action(sig);  // the same signal again ends the process
    return true;
  }
  if (now - first_ns.load() >= kSameStopNs) {
    default_action(sig);
    ::raise(sig);  // pending until this handler returns (the signal is blocked in it)
  }
  return false;
}

/// Installs `handler` for each stop signal the process was not started with ignored; those stay
/// ignored and are blocked in this thread (and so in the threads it starts after this). The
/// three are blocked while the dispositions are read and set (a signal between two of them saw
/// the others' half-made state), and each handler runs with all three blocked.
inline void install_stop_handler(void (*handler)(int)) {
  const sigset_t all = stop_detail::stop_set();
  sigset_t before;
  ::pthread_sigmask(SIG_BLOCK, &all, &before);
  bool ignored[3];
  for (int i = 0; i < 3; ++i) {
    struct sigaction now {};
    ::sigaction(kStopSignals[i], nullptr, &now);
    ignored[i] = now.sa_handler == SIG_IGN;
  }
  sigset_t keep_blocked;
  sigemptyset(&keep_blocked);
  for (int i = 0; i < 3; ++i) {
    if (ignored[i]) {
      sigaddset(&keep_blocked, kStopSignals[i]);
      continue;
    }
    struct sigaction a {};
    a.sa_handler = handler;
    a.sa_mask = all;
    ::sigaction(kStopSignals[i], &a, nullptr);
  }
  ::pthread_sigmask(SIG_SETMASK, &before, nullptr);
  ::pthread_sigmask(SIG_BLOCK, &keep_blocked, nullptr);
}

/// install_stop_handler() while alive (the first stop signal's record cleared); the dispositions
/// and this thread's mask before it afterwards. converge gives them back once its outputs are
/// written, also when it throws.
class StopSignalScope {
 public:
  explicit StopSignalScope(void (*handler)(int)) {
    const sigset_t all = stop_detail::stop_set();
    ::pthread_sigmask(SIG_BLOCK, &all, &mask_);
    for (int i = 0; i < 3; ++i) ::sigaction(kStopSignals[i], nullptr, &before_[i]);
    stop_detail::first_signal.store(0);
    ::pthread_sigmask(SIG_SETMASK, &mask_, nullptr);
    install_stop_handler(handler);
  }
  ~StopSignalScope() {
    const sigset_t all = stop_detail::stop_set();
    ::pthread_sigmask(SIG_BLOCK, &all, nullptr);
    for (int i = 0; i < 3; ++i) ::sigaction(kStopSignals[i], &before_[i], nullptr);
    ::pthread_sigmask(SIG_SETMASK, &mask_, nullptr);
  }
  StopSignalScope(const StopSignalScope&) = delete;
  StopSignalScope& operator=(const StopSignalScope&) = delete;

 private:
  struct sigaction before_[3]{};
  sigset_t mask_{};
};

namespace stop_detail {
/// The stop signal run_with_stops_deferred() recorded (0: none).
inline std::atomic<int> deferred_signal{0};
inline void record_deferred_stop(int sig) {
  if (first_stop_signal(sig)) deferred_signal.store(sig);
}
}  // namespace stop_detail

/// Runs `work`, a command's last step (merge's and compare's writing of their output), with a
/// stop signal recorded instead of acted on: the output is written in full, as render's is, where
/// the signal's default action killed the process in the write and left a hidden temporary file
/// beside the output. A second signal ends the process at once (first_stop_signal). Before this
/// step the signals keep their default action: a command killed while it reads has written
/// nothing. Returns the first stop signal received during `work` (0: none); an exception of
/// `work` passes through, the signal then lost.
template <class Work>
int run_with_stops_deferred(Work&& work) {
  stop_detail::deferred_signal.store(0);
  StopSignalScope scope(stop_detail::record_deferred_stop);
  work();
  return stop_detail::deferred_signal.load();
}

}  // namespace lucent::cli

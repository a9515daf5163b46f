#pragma once
// SIGINT, SIGTERM and SIGHUP for `lucent` and `lucent-mpi`: the first stops the work after the
// current pass (a handler sets a flag). Any of the three within a second of the first is part of
// the same stop; one from a second after the first ends the process at once. Signals come
// together: GNU timeout sends its SIGTERM to the process and then to its process group (the same
// signal twice, microseconds apart), LSF's bkill SIGINT and SIGTERM, systemd SIGTERM then SIGHUP;
// each of these killed the render with nothing written while the same signal again ended it at
// any time (until 30 Nov 2026; before that day another signal was a second graceful stop).
//
// A signal the process was started with ignored (nohup's SIGHUP, SIGINT of a script's background
// job) stays ignored, and blocked: lucent stopped on them, against the shell's convention, and
// PoCL's LLVM, whose handlers were then in place (the library gives the process's back), failed a
// kernel build on one.
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
/// When the first stop signal came (CLOCK_MONOTONIC, ns; 0: none yet), and which it was: read
/// and written by the handlers of any thread (lock-free atomics are async-signal-safe). The time
/// decides: a handler that saw the signal set but not yet its time (two signals on two threads
/// at once, as GNU timeout sends them) took 0 for it and ended the process.
inline std::atomic<long long> first_ns{0};
inline std::atomic<int> first_signal{0};
/// The stop signals (bit i: kStopSignals[i]) the process was started with ignored.
inline std::atomic<unsigned> ignored_at_start{0};
/// A later stop signal within this of the first is part of the same stop.
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

/// What a stop signal is to the stop under way.
enum class StopSignal {
  First,     ///< the first: the handler records the stop
  SameStop,  ///< within a second of the first: part of its stop
  EndNow,    ///< a second or more after the first: the process ends at once
};

/// Classifies a stop signal `sig` received at `now_ns` (CLOCK_MONOTONIC), recording the first.
/// Async-signal-safe.
inline StopSignal classify_stop_signal(int sig, long long now_ns) {
  using namespace stop_detail;
  long long first = 0;
  if (first_ns.compare_exchange_strong(first, now_ns)) {
    first_signal.store(sig);
    return StopSignal::First;
  }
  return now_ns - first >= kSameStopNs ? StopSignal::EndNow : StopSignal::SameStop;
}

/// For a command's handler, first: true for the first stop signal (the handler then records its
/// stop); for a later one false, having ended the process (a second or more after the first) or
/// let it pass (within that second). Async-signal-safe.
inline bool first_stop_signal(int sig) {
  switch (classify_stop_signal(sig, stop_detail::monotonic_ns())) {
    case StopSignal::First:
      return true;
    case StopSignal::EndNow:
      stop_detail::default_action(sig);
      ::raise(sig);  // pending until this handler returns (the signal is blocked in it)
      return false;
    case StopSignal::SameStop:
      break;
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
  unsigned ignored_bits = 0;
  for (int i = 0; i < 3; ++i) {
    if (ignored[i]) {
      sigaddset(&keep_blocked, kStopSignals[i]);
      ignored_bits |= 1u << i;
      continue;
    }
    struct sigaction a {};
    a.sa_handler = handler;
    a.sa_mask = all;
    ::sigaction(kStopSignals[i], &a, nullptr);
  }
  stop_detail::ignored_at_start.store(ignored_bits);
  ::pthread_sigmask(SIG_SETMASK, &before, nullptr);
  ::pthread_sigmask(SIG_BLOCK, &keep_blocked, nullptr);
}

/// Takes the stop signals back from a handler installed over `handler` (after
/// install_stop_handler): PoCL's LLVM installs its own when PoCL initialises and keeps it (the
/// library gives the process's back then, cl_util's KeepStopHandlers; this is the CLI's second
/// line) (SA_RESETHAND: the default action comes back as it is entered, before it gives the signal
/// to the handler it replaced). A second signal microseconds after the first, as GNU timeout sends
/// (to the process, then to its group), found the default action there and killed the process
/// with nothing written. Called after each kernel build; a signal the process was started with
/// ignored is ignored again.
inline void reclaim_stop_handler(void (*handler)(int)) {
  const sigset_t all = stop_detail::stop_set();
  sigset_t before;
  ::pthread_sigmask(SIG_BLOCK, &all, &before);
  const unsigned ignored = stop_detail::ignored_at_start.load();
  for (int i = 0; i < 3; ++i) {
    struct sigaction now {};
    ::sigaction(kStopSignals[i], nullptr, &now);
    const bool info = (now.sa_flags & SA_SIGINFO) != 0;
    struct sigaction a {};
    a.sa_mask = all;
    if (ignored & (1u << i)) {
      if (!info && now.sa_handler == SIG_IGN) continue;
      a.sa_handler = SIG_IGN;
    } else {
      // (the default action: a later signal's EndNow, which must stay)
      if (!info && (now.sa_handler == handler || now.sa_handler == SIG_DFL)) continue;
      a.sa_handler = handler;
    }
    ::sigaction(kStopSignals[i], &a, nullptr);
  }
  ::pthread_sigmask(SIG_SETMASK, &before, nullptr);
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
    stop_detail::first_ns.store(0);
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
/// beside the output. A second signal from a second after the first ends the process at once
/// (first_stop_signal). Before this
/// step the signals keep their default action: a command killed while it reads has written
/// nothing. Returns the first stop signal received during `work` (0: none); an exception of
/// `work` passes through, the signal then lost.
template <class Work>
int run_with_stops_deferred(Work&& work) {
  stop_detail::deferred_signal.store(0);
  {
    StopSignalScope scope(stop_detail::record_deferred_stop);
    work();
  }
  // (read once the handlers are given back: one that came in between was recorded, and lost)
  return stop_detail::deferred_signal.load();
}

}  // namespace lucent::cli

// Rendering from Python: the session (lucent.Renderer), its results as NumPy arrays without
// copies, its statistics, and the reference integrator. Renders release the GIL; the progress
// callback and Python's signal handlers run between passes, so Ctrl-C stops a render after the
// current pass, keeps what it had accumulated and raises KeyboardInterrupt.
#include <cmath>
#include <limits>
#include <mutex>
#include <optional>
#include <thread>

#include "common.hpp"
#include "core/file_io.hpp"
#include "lucent/converge.hpp"
#include "lucent/error.hpp"
#include "lucent/limits.hpp"
#include "lucent/parts.hpp"
#include "lucent/reference.hpp"
#include "lucent/session.hpp"
#include "scene/loaders.hpp"
#include "state.hpp"

namespace lucent::python {

namespace {

// Every field of SessionStats, for attributes, as_dict() and repr().
#define LUCENT_PY_SESSION_STATS(X) \
  X(scene_packs)                   \
  X(bvh_builds)                    \
  X(kernel_compiles)               \
  X(kernel_cache_loads)            \
  X(kernel_reuses)                 \
  X(camera_moves)                  \
  X(buffer_uploads)                \
  X(bytes_uploaded) X(passes) X(pack_seconds) X(bvh_seconds) X(build_seconds) X(render_seconds)

#define LUCENT_PY_PROGRESS(X) \
  X(samples_done) X(samples_target) X(accumulated) X(elapsed) X(time_limit) X(samples_per_second)

template <class T>
std::string format_field(const T& v) {
  if constexpr (std::is_floating_point_v<T>) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
  } else {
    return std::to_string(v);
  }
}

// Several devices in one session (RenderResult::devices, RenderProgress::devices,
// Renderer::devices()) are exposed when the library has them.
template <class T, class = void>
struct has_device_shares : std::false_type {};
template <class T>
struct has_device_shares<T, std::void_t<decltype(std::declval<T&>().devices)>> : std::true_type {};
template <class T, class = void>
struct has_devices_method : std::false_type {};
template <class T>
struct has_devices_method<T, std::void_t<decltype(std::declval<const T&>().devices())>>
    : std::true_type {};

/// `devices`: each device's part (a list of DeviceShare), when T has it.
template <class T>
void bind_device_shares(py::module_& m, py::class_<T>& c) {
  if constexpr (has_device_shares<T>::value) {
    using Share = typename decltype(std::declval<T&>().devices)::value_type;
    if (!py::hasattr(m, "DeviceShare"))
      py::class_<Share>(m, "DeviceShare", "One device's part of a render.")
          .def_readonly("device", &Share::device)
          .def_readonly("samples", &Share::samples)
          .def_readonly("seconds", &Share::seconds)
          .def("__repr__", [](const Share& d) {
            return "<lucent.DeviceShare " + d.device + ": " + std::to_string(d.samples) + " spp>";
          });
    c.def_readonly("devices", &T::devices, "each device's part (several devices in a session)");
  }
}

/// A session as Python holds it: the Renderer, the sink of its warnings, and a guard against
/// two Python threads using it at once. Calls (set_scene, render, result, ...) run one at a time:
/// a second one, from another thread or from a callback of the first, raises (saying which of
/// the two it is). While a call runs:
/// - cancel() and device (fixed for the session's life) work from any thread;
/// - spp, first_sample and stats give the values the call began with, updated after each pass
///   of render(), render_for() and render_adaptive() (a copy that the rendering thread writes
///   under a mutex: the session's own counters change during passes, without the GIL);
/// - scene, options and result() raise, except while the call is stopped in its progress
///   callback (between passes: nothing in the session changes then), from any thread;
/// - close() raises; once close() began, everything raises that the renderer is closed.
/// `busy_`, `closed_` and `paused_` change with the GIL held, and are read with it: holding the
/// GIL, a thread that sees no call in progress (or one paused in its callback) reads the session
/// before any other thread can start a call (or resume the render).
class PyRenderer {
 public:
  PyRenderer(const TextArg& device_arg, const PathText& kernel_dir, const PathText& cache_dir,
             const TextArg& precision, const FlagArg& fast_math, const FlagArg& specialize,
             double pass_seconds, const IntArg& reserved_host_bytes, py::object on_warning)
      : warning_errors_(std::make_shared<CallbackErrors>()) {
    check_callable(on_warning, "on_warning");
    const std::string device = text_argument(device_arg, "device");
    refuse_nul(device, "device");
    refuse_nul(kernel_dir.bytes, "kernel_dir");
    refuse_nul(cache_dir.bytes, "cache_dir");
    if (!(pass_seconds > 0) || !std::isfinite(pass_seconds))
      throw py::value_error("pass_seconds must be a positive number of seconds, got " +
                            format_field(pass_seconds));
    SessionOptions o;
    o.device = device;
    o.kernel_dir = kernel_dir.bytes;
    o.cache_dir = cache_dir.bytes;
    o.precision = parse_enum<Precision>(text_argument(precision, "precision"));
    o.fast_math = flag_argument(fast_math, "fast_math");
    o.specialize = flag_argument(specialize, "specialize");
    o.pass_seconds = pass_seconds;
    o.reserved_host_bytes = int_argument(reserved_host_bytes, "reserved_host_bytes", 0,
                                         std::numeric_limits<std::uint64_t>::max());
    on_warning_ = SharedObject(std::move(on_warning));
    sink_ = python_warning_sink(on_warning_, warning_errors_);
    o.on_warning = [this](const std::string& message) {
      // a call_interruptible's worker thread has no Python frame: warnings.warn named "sys:1";
      // the warning is given on the caller's thread once the call returns (flush_warnings)
      if (deferring_.load() && std::this_thread::get_id() != caller_thread_) {
        std::lock_guard<std::mutex> lock(deferred_mutex_);
        deferred_warnings_.push_back(message);
        return;
      }
      give_warning(message);
    };
    caller_chain_ = t_callbacks;  // the warnings of the construction are its caller's callbacks
    ReleaseGil release;
    renderer_.emplace(std::move(o));
    renderer_->set_cancel_flag(&stop_);
    caller_chain_ = nullptr;
  }

  /// The session, for what does not change while a call runs (device(), cancel()). The GIL is
  /// held. Raises once close() began (the session may be being destroyed without the GIL).
  Renderer& get() {
    if (closed_) throw Error("the renderer is closed");
    return *renderer_;
  }

  /// The session, for reading what a call changes (`what`: scene, options): refused while a
  /// call runs, unless it is paused in its progress callback.
  const Renderer& read(const char* what) {
    Renderer& r = get();
    if (busy_ && !paused_)
      throw Error(refusal("read", what,
                          "its scene and options can be read between calls, or from a progress "
                          "callback"));
    return r;
  }

  /// What spp, first_sample and stats read.
  struct Counters {
    std::uint64_t spp = 0, first_sample = 0;
    SessionStats stats;
  };
  /// The session's counters; while a call runs, those it began with or the last pass's.
  Counters counters() {
    Renderer& r = get();
    if (!busy_) return {r.spp(), r.first_sample(), r.stats()};
    std::lock_guard<std::mutex> lock(counters_mutex_);
    return counters_;
  }

  /// Runs `f(renderer)` with the GIL released, one call at a time (`what`: its name, for
  /// messages); then raises what a warning callback raised.
  /// A lucent::Error raised while Ctrl-C came is KeyboardInterrupt: PoCL's LLVM, while its
  /// handlers were in place (the library gives the process's back), failed a kernel build on
  /// SIGINT, and set_scene raised lucent.Error "kernel build failed", the KeyboardInterrupt then
  /// coming out in the caller's except block.
  /// (The signals are looked at once the call is no longer busy: a Python handler may use the
  /// session.)
  template <class F>
  auto call(const char* what, F&& f) {
    using Result = decltype(f(get()));
    std::exception_ptr failed;
    std::conditional_t<std::is_void_v<Result>, bool, std::optional<Result>> out{};
    {
      Busy busy(*this, what);
      Renderer& r = get();
      try {
        ReleaseGil release;
        if constexpr (std::is_void_v<Result>)
          f(r);
        else
          out.emplace(f(r));
      } catch (const Error&) {
        failed = std::current_exception();
      } catch (...) {
        warning_errors_->clear();  // (as below: the failure is raised)
        throw;
      }
      // a failed call raises its own error; what its on_warning raised goes with it (it was
      // kept, and raised by the next call, which had given no warning)
      if (failed)
        warning_errors_->clear();
      else
        warning_errors_->rethrow();
    }
    if (failed) {
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      std::rethrow_exception(failed);
    }
    if constexpr (!std::is_void_v<Result>) return std::move(*out);
  }

  /// Runs `f(renderer, stop)`, one call at a time, on a worker thread while this one runs
  /// Python's signal handlers (run_interruptible): KeyboardInterrupt raises `stop`, the
  /// session's cancel flag, and a render in progress ends after its current pass.
  /// The warnings of the call's worker thread are given on this thread when it returns, so that
  /// warnings.warn names the line that made the call.
  template <class F>
  void call_interruptible(const char* what, F&& f) {
    Busy busy(*this, what);
    Renderer& r = get();
    stop_ = false;
    deferring_ = true;
    try {
      run_interruptible(
          [&] {
            caller_queue_ = t_caller_queue;
            f(r, stop_);
          },
          stop_);
    } catch (...) {
      flush_warnings();
      warning_errors_->clear();  // (as call's: the failure is raised, not a later call's)
      throw;
    }
    flush_warnings();
    warning_errors_->rethrow();
  }

  /// Gives the warnings deferred by a call_interruptible (the GIL held, the call still busy).
  void flush_warnings() {
    deferring_ = false;
    std::vector<std::string> messages;
    {
      std::lock_guard<std::mutex> lock(deferred_mutex_);
      messages.swap(deferred_warnings_);
    }
    for (const std::string& m : messages) give_warning(m);
  }

  /// A warning to the session's sink, as a callback of the call in progress.
  void give_warning(const std::string& message) {
    WithChain chain(caller_chain_);  // on a device thread, the chain of the call's caller
    InCallback frame(this, "warning callback");
    sink_(message);
  }

  /// A render call: `progress(p)` runs after each pass (on the calling thread, with the GIL);
  /// an exception it raises, or Ctrl-C, stops the render after the current pass and is raised
  /// once the render returned. The accumulation keeps what was rendered.
  /// `what`: render or render_for, for messages.
  RenderProgress render(const char* what, std::uint64_t spp, double seconds, py::object progress) {
    return run_with_progress(what, std::move(progress),
                             [&](Renderer& r, const ProgressFn& on_progress) {
                               return r.render(spp, seconds, on_progress);
                             });
  }

  RenderProgress render_adaptive(const AdaptiveOptions& options, py::object progress) {
    return run_with_progress("render_adaptive", std::move(progress),
                             [&](Renderer& r, const ProgressFn& on_progress) {
                               return r.render_adaptive(options, on_progress);
                             });
  }

  using ProgressFn = std::function<void(const RenderProgress&)>;
  /// Runs `f(renderer, on_progress)` interruptibly, with `progress` (a callable or None) called
  /// under the GIL after each pass.
  template <class F>
  RenderProgress run_with_progress(const char* what, py::object progress, F&& f) {
    check_callable(progress, "progress");
    CallbackErrors errors;
    const bool has_progress = !progress.is_none();
    // after each pass, with the session's lock held (nothing in the session changes meanwhile)
    ProgressFn on_progress = [&](const RenderProgress& p) {
      save_counters();
      if (!has_progress) return;
      // on the thread that called render (from the worker, or a device thread of a session
      // with several devices), with its chain of callbacks
      run_with_gil(caller_queue_, [&] {
        InCallback frame(this, "progress callback");
        paused_ = true;  // scene and options can be read until the callback returns
        if (!errors.run([&] { progress(p); })) stop_ = true;
        paused_ = false;
      });
    };
    RenderProgress out;
    call_interruptible(what, [&](Renderer& r, std::atomic<bool>&) { out = f(r, on_progress); });
    errors.rethrow();
    return out;
  }

  /// While alive (the GIL held), the call in progress is paused in a callback of its own between
  /// two passes or rungs (converge's on_point): result(), scene and options can be read there,
  /// as in a progress callback (the library holds the session, so nothing in it changes).
  struct PausedInCallback {
    PyRenderer* r;
    explicit PausedInCallback(PyRenderer* renderer) : r(renderer) {
      if (r) r->paused_ = true;
    }
    ~PausedInCallback() {
      if (r) r->paused_ = false;
    }
    PausedInCallback(const PausedInCallback&) = delete;
    PausedInCallback& operator=(const PausedInCallback&) = delete;
  };

  /// The accumulation: a call of its own, or, while a render is paused in its progress callback
  /// (between passes, nothing in the session changes: Renderer::result() is safe there), read
  /// with the GIL held, as scene and options are (a notebook's live preview was refused).
  RenderResult result() {
    if (busy_ && paused_) return get().result();
    return call("result", [](Renderer& rr) { return rr.result(); });
  }

  /// Stops a render in progress after its current pass. Renderer::cancel() alone was lost when
  /// it came after another thread saw this session busy but before the call reached the library
  /// (whose start drops an earlier cancel): the call's own stop flag is raised too. It is
  /// lowered when a call starts, with the GIL held, before any thread can see it busy.
  void cancel() {
    Renderer& r = get();
    r.cancel();
    if (busy_) stop_ = true;
  }

  /// The Python objects the renderer holds, for the type's tp_traverse and tp_clear.
  int visit_references(visitproc visit, void* arg) const {
    Py_VISIT(on_warning_.ptr());
    return 0;
  }
  void clear_references() { on_warning_.clear(); }

  /// Destroys the session (with the GIL released: a device may take a while to let go). Refused
  /// while a call runs; claims the session first, so that no call starts meanwhile. Closing a
  /// closed renderer does nothing.
  void close() {
    if (closed_) return;
    if (busy_.exchange(true))
      throw Error(refusal("call", "close", "close it once that call has returned"));
    closed_ = true;  // from here on every call raises, before touching renderer_
    {
      ReleaseGil release;
      renderer_.reset();
      sink_ = nullptr;  // (the on_warning callable goes with the session)
    }
    on_warning_ = SharedObject();  // (with the GIL: the garbage collector reads it under it)
    busy_ = false;
  }

  /// The files the session's scene reads, made absolute when set_scene took it (with the GIL):
  /// write_part refuses them whatever the current directory is since (after an os.chdir the
  /// scene's relative names meant other files, and a part was written over its environment map).
  std::vector<std::string> inputs_at_set_scene;

 private:
  /// Marks the session in use for a call named `what` (the GIL held); a second call gets an
  /// error.
  struct Busy {
    Busy(PyRenderer& r, const char* what) : session(r) {
      if (r.closed_) throw Error("the renderer is closed");
      if (r.busy_.exchange(true))
        throw Error(r.refusal("call", what, "a session renders one call at a time"));
      r.call_ = what;
      r.caller_chain_ = t_callbacks;
      r.caller_thread_ = std::this_thread::get_id();
      try {
        r.save_counters();  // what other threads read during the call
      } catch (...) {
        r.caller_chain_ = nullptr;
        r.busy_ = false;
        throw;
      }
    }
    ~Busy() {
      session.caller_chain_ = nullptr;
      session.busy_ = false;
    }
    PyRenderer& session;
  };

  /// Why `what` (a call, or a property to read: `verb`) is refused while a call is in progress
  /// (the GIL held): made from a callback of that call on this thread, it would re-enter it;
  /// otherwise another thread's call is in progress (`hint`: what to do then).
  std::string refusal(const char* verb, const char* what, const char* hint) const {
    if (const CallbackFrame* f = callback_of(this))
      return std::string("cannot ") + verb + " " + what + " from the " + f->callback +
             " of this renderer's own " + call_ + " (a session runs one call at a time: " + verb +
             " it once " + call_ + " has returned)";
    // this thread's call, waiting for its worker, runs Python's signal handlers
    if (std::this_thread::get_id() == caller_thread_)
      return std::string("cannot ") + verb + " " + what +
             " from a signal handler that runs during this renderer's own " + call_ +
             " on the same thread (a session runs one call at a time: " + verb + " it once " +
             call_ + " has returned)";
    return std::string("the renderer is in use by another thread (") + hint + ")";
  }

  /// Copies the session's counters for other threads; called where nothing changes them (a call
  /// starting, with the GIL; a render between passes, under its lock).
  void save_counters() {
    const Renderer& r = *renderer_;
    Counters c{r.spp(), r.first_sample(), r.stats()};
    std::lock_guard<std::mutex> lock(counters_mutex_);
    counters_ = c;
  }

  std::optional<Renderer> renderer_;
  std::shared_ptr<CallbackErrors> warning_errors_;
  /// on_warning, which sink_ holds too: visited and cleared by Python's garbage collector, so
  /// that a renderer whose on_warning refers back to it (a bound method of the object that
  /// holds the renderer) is collected; such a cycle kept the session, its buffers and its device
  /// for the process's life (118 MiB a 1024x1024 session).
  SharedObject on_warning_;
  WarningSink sink_;  ///< the session's warnings to Python (on_warning, or warnings.warn)
  /// A call_interruptible's worker thread's warnings, given when it returns (flush_warnings).
  std::atomic<bool> deferring_{false};
  std::thread::id caller_thread_;
  std::mutex deferred_mutex_;
  std::vector<std::string> deferred_warnings_;
  std::atomic<bool> busy_{false};  ///< a call (or close()) is in progress
  bool closed_ = false;            ///< close() began (GIL)
  bool paused_ = false;            ///< the call in progress is in its progress callback (GIL)
  const char* call_ = "";          ///< the name of the call in progress, for messages (GIL)
  /// The chain of callbacks of the thread that made the call in progress (or constructs the
  /// session), for its callbacks on threads of the library. Set with the GIL before the call
  /// starts the threads that read it, unchanged until it returned.
  const CallbackFrame* caller_chain_ = nullptr;
  /// The queue of the call_interruptible in progress, for its callbacks on threads of the
  /// library (set by its worker before the call starts them).
  CallerQueue* caller_queue_ = nullptr;
  std::atomic<bool> stop_{false};  ///< the session's cancel flag
  std::mutex counters_mutex_;
  Counters counters_;  ///< the counters while a call runs (counters_mutex_)
};

/// The C++ object of a bound instance, or null before its __init__ has made it (cls.__new__).
/// (Also while pybind11 lays the instance out: a GC type is tracked from its allocation on, and
/// the layout of a Python subclass's first instance makes objects, which may collect, before it
/// exists: its status pointer was null, and the collector crashed, the review's find.)
template <class T>
T* constructed(PyObject* self) {
  auto* inst = reinterpret_cast<py::detail::instance*>(self);
  if (!inst->simple_layout && !inst->nonsimple.values_and_holders) return nullptr;
  py::detail::value_and_holder v_h = inst->get_value_and_holder(nullptr, false);
  return v_h && v_h.holder_constructed() ? v_h.value_ptr<T>() : nullptr;
}

/// A py::custom_type_setup that makes T's instances known to Python's garbage collector
/// through T's visit_references and clear_references: a cycle through the Python objects a T
/// holds is collected.
template <class T>
void collected_by_python(PyHeapTypeObject* heap_type) {
  PyTypeObject* type = &heap_type->ht_type;
  type->tp_flags |= Py_TPFLAGS_HAVE_GC;
  type->tp_traverse = [](PyObject* self, visitproc visit, void* arg) {
    Py_VISIT(Py_TYPE(self));  // (a heap type's instances visit it)
    const T* t = constructed<T>(self);
    return t ? t->visit_references(visit, arg) : 0;
  };
  type->tp_clear = [](PyObject* self) {
    if (T* t = constructed<T>(self)) t->clear_references();
    return 0;
  };
  // untracked before the C++ object goes: a collection during its destructor (another
  // thread's, while the destructor waits for the device) visited a half-destroyed object
  type->tp_dealloc = [](PyObject* self) {
    PyObject_GC_UnTrack(self);
    reinterpret_cast<PyTypeObject*>(py::detail::get_internals().instance_base)->tp_dealloc(self);
  };
}

/// Renderer.devices: every device of the session, when the library has several per session.
template <class R>
void bind_session_devices(py::class_<PyRenderer>& c) {
  if constexpr (has_devices_method<R>::value)
    c.def_property_readonly("devices",
                            [](PyRenderer& r) { return static_cast<const R&>(r.get()).devices(); });
}

// The sampler's sample indices are 32-bit: a render adds at most 2**32 samples per pixel, and
// reset() starts below 2**32.
constexpr std::uint64_t kSampleIndices = std::uint64_t(1) << 32;
constexpr const char* kSampleNote = " (the sampler's sample indices are 32-bit)";
constexpr const char* kCountNote = " (a pixel's sample count is 32-bit)";
constexpr std::uint64_t kMaxAdaptiveSpp = std::numeric_limits<std::uint32_t>::max();

/// A time limit: as checked_seconds, and at most the command line's 1e7 s (--time; a render_for
/// of 1e8 s ran until killed).
double checked_time_limit(double s, const char* what) {
  static_assert(limits::kMaxSeconds == 1e7, "the message says 1e7");
  if (!(s >= 0) || !(s <= limits::kMaxSeconds))
    throw py::value_error(std::string(what) + " must be a finite number in [0, 1e7] seconds, got " +
                          format_field(s));
  return s;
}

double checked_seconds(double s, const char* what) {
  if (!(s >= 0) || !std::isfinite(s))
    throw py::value_error(std::string(what) + " must be a finite number >= 0, got " +
                          format_field(s));
  return s;
}

std::vector<ConvergeSetting> parse_settings(const std::vector<std::string>& names) {
  // (an empty list ran ['default'] without a word, where an empty ladder is an error)
  if (names.empty())
    throw py::value_error("settings: an empty list (give ['default'] for the scene's own)");
  for (const std::string& n : names) refuse_nul(n, "settings");
  try {
    return parse_converge_settings(names);
  } catch (const Error& e) {
    throw Error(std::string("settings: ") + e.what());
  }
}

std::string result_repr(const RenderResult& r) {
  return "<lucent.RenderResult " + std::to_string(r.mean.width) + "x" +
         std::to_string(r.mean.height) + ", " + std::to_string(r.spp) + " spp, " +
         format_field(r.seconds) + " s" + (r.cancelled ? ", cancelled" : "") + ", " + r.device +
         ">";
}

/// An image's pixels as an (H, W, 3) float32 array (a copy), for a pickled state.
py::array_t<float> image_copy(const Image& image) {
  py::array_t<float> a({py::ssize_t(image.height), py::ssize_t(image.width), py::ssize_t(3)});
  std::copy(image.rgb.begin(), image.rgb.end(), a.mutable_data());
  return a;
}

/// RenderResult::light_mean_variance as Python sees it: None, or {"paths": (R, G, B), "pixels":
/// (R, G, B)}.
py::object light_mean_variance_object(const std::optional<LightMeanVariance>& v) {
  if (!v) return py::none();
  py::dict d;
  d["paths"] = py::make_tuple(v->paths[0], v->paths[1], v->paths[2]);
  d["pixels"] = py::make_tuple(v->pixels[0], v->pixels[1], v->pixels[2]);
  return d;
}

/// The same back from a pickled state (None, or that dict of finite numbers >= 0).
std::optional<LightMeanVariance> light_mean_variance_from(py::handle v, const std::string& where) {
  if (v.is_none()) return std::nullopt;
  StateReader s(v, where);
  LightMeanVariance m;
  auto three = [&](const char* key, double(&out)[3]) {
    py::object t = s.get(key);
    bool ok = py::isinstance<py::tuple>(t) && py::len(t) == 3;
    for (int c = 0; ok && c < 3; ++c) {
      py::object x = t[py::int_(c)];
      ok = !py::isinstance<py::bool_>(x) &&
           (py::isinstance<py::float_>(x) || py::isinstance<py::int_>(x));
      if (ok) out[c] = x.cast<double>();
      ok = ok && std::isfinite(out[c]) && out[c] >= 0;
    }
    if (!ok)
      s.fail(key,
             "expected a tuple of 3 finite numbers >= 0, got " + py::repr(t).cast<std::string>());
  };
  three("paths", m.paths);
  three("pixels", m.pixels);
  s.finish();
  return m;
}

/// A RenderResult's pickled state: its fields by attribute name, the images and counts as NumPy
/// arrays (variance and samples None when the result has none), read back strictly (state.hpp).
py::dict result_state(const RenderResult& r) {
  py::dict d;
  d["mean"] = image_copy(r.mean);
  d["variance"] = r.variance.rgb.empty() ? py::object(py::none()) : image_copy(r.variance);
  if (r.samples.empty()) {
    d["samples"] = py::none();
  } else {
    py::array_t<std::uint32_t> n({py::ssize_t(r.mean.height), py::ssize_t(r.mean.width)});
    std::copy(r.samples.begin(), r.samples.end(), n.mutable_data());
    d["samples"] = n;
  }
  d["spp"] = r.spp;
  d["nonfinite"] = r.nonfinite;
  d["rays"] = r.rays;
  d["seconds"] = r.seconds;
  d["build_seconds"] = r.build_seconds;
  d["program_cache_hit"] = r.program_cache_hit;
  d["build_options"] = file_text(r.build_options);
  d["cancelled"] = r.cancelled;
  d["device"] = r.device;
  if constexpr (has_device_shares<RenderResult>::value) {
    py::list devices;
    for (const auto& share : r.devices) {
      py::dict s;
      s["device"] = share.device;
      s["samples"] = share.samples;
      s["seconds"] = share.seconds;
      devices.append(s);
    }
    d["devices"] = devices;
  }
  d["estimated_relmse"] = r.estimated_relmse;
  d["target_error"] = r.target_error;
  d["halves_relmse"] = r.halves_relmse;
  d["model_gain_a"] = r.model_gain_a;
  d["model_gain_b"] = r.model_gain_b;
  d["planned_relmse"] = r.planned_relmse;
  d["planned_spp"] = r.planned_spp;
  d["pilot_incomplete"] = r.pilot_incomplete;
  d["plan_incomplete"] = r.plan_incomplete;
  d["seed"] = r.seed;
  d["sampler"] = r.sampler;
  d["light_mean_variance"] = light_mean_variance_object(r.light_mean_variance);
  return d;
}

RenderResult result_from_state(const py::object& state) {
  StateReader s(state, "lucent.RenderResult");
  RenderResult r;
  auto image = [&](const char* key, py::ssize_t h, py::ssize_t w) {
    py::array_t<float> a = s.array<float>(key, {h, w, 3});
    // as image_from_array: an image has a row and a column, and its sizes are ints
    constexpr py::ssize_t most = std::numeric_limits<int>::max();
    if (a.shape(0) < 1 || a.shape(0) > most || a.shape(1) < 1 || a.shape(1) > most)
      s.fail(key, "expected an (H, W, 3) image with 1 <= H, W <= " + std::to_string(most) +
                      ", got a (" + std::to_string(a.shape(0)) + ", " + std::to_string(a.shape(1)) +
                      ", 3) array");
    Image img;
    img.height = static_cast<int>(a.shape(0));
    img.width = static_cast<int>(a.shape(1));
    img.rgb.assign(a.data(), a.data() + a.size());
    return img;
  };
  r.mean = image("mean", -1, -1);
  if (!s.get("variance").is_none()) r.variance = image("variance", r.mean.height, r.mean.width);
  if (!s.get("samples").is_none()) {
    py::array_t<std::uint32_t> n = s.array<std::uint32_t>("samples", {r.mean.height, r.mean.width});
    r.samples.assign(n.data(), n.data() + n.size());
  }
  if (!r.variance.rgb.empty() && r.samples.empty())  // as the constructor
    s.fail("samples", "a variance needs the per-pixel sample counts");
  r.spp = s.integer<std::uint64_t>("spp");
  r.nonfinite = s.integer<std::uint64_t>("nonfinite");
  r.rays = s.integer<std::uint64_t>("rays");
  r.seconds = s.number("seconds");
  r.build_seconds = s.number("build_seconds");
  r.program_cache_hit = s.boolean("program_cache_hit");
  r.build_options = s.text("build_options");
  r.cancelled = s.boolean("cancelled");
  r.device = s.text("device");
  if constexpr (has_device_shares<RenderResult>::value) {
    using Share = typename decltype(r.devices)::value_type;
    r.devices = s.list<Share>("devices", [](py::handle item, const std::string& where) {
      StateReader d(item, where);
      Share share;
      share.device = d.text("device");
      share.samples = d.integer<decltype(share.samples)>("samples");
      share.seconds = d.number("seconds");
      d.finish();
      return share;
    });
  }
  r.estimated_relmse = s.number("estimated_relmse");
  r.target_error = s.number("target_error");
  r.halves_relmse = s.number("halves_relmse");
  r.model_gain_a = s.number("model_gain_a");
  r.model_gain_b = s.number("model_gain_b");
  r.planned_relmse = s.number("planned_relmse");
  r.planned_spp = s.integer<std::uint64_t>("planned_spp");
  r.pilot_incomplete = s.boolean("pilot_incomplete");
  r.plan_incomplete = s.boolean("plan_incomplete");
  r.seed = s.integer<std::uint32_t>("seed");
  r.sampler = s.text("sampler");
  r.light_mean_variance = s.nested("light_mean_variance", &light_mean_variance_from);
  s.finish();
  return r;
}

}  // namespace

void bind_render(py::module_& m) {
  py::class_<RenderProgress> progress(m, "RenderProgress",
                                      "Where a render call stands (after each pass).");
  progress
#define LUCENT_PY_FIELD(f) .def_readonly(#f, &RenderProgress::f)
      LUCENT_PY_PROGRESS(LUCENT_PY_FIELD)
#undef LUCENT_PY_FIELD
          .def("__repr__", [](const RenderProgress& p) {
            std::string s = "<lucent.RenderProgress";
#define LUCENT_PY_FIELD(f) s += " " #f "=" + format_field(p.f);
            LUCENT_PY_PROGRESS(LUCENT_PY_FIELD)
#undef LUCENT_PY_FIELD
            return s + ">";
          });

  bind_device_shares(m, progress);

  py::class_<SessionStats>(m, "SessionStats",
                           "What a session has built and done (lucent::SessionStats).")
#define LUCENT_PY_FIELD(f) .def_readonly(#f, &SessionStats::f)
      LUCENT_PY_SESSION_STATS(LUCENT_PY_FIELD)
#undef LUCENT_PY_FIELD
          .def("as_dict",
               [](const SessionStats& s) {
                 py::dict d;
#define LUCENT_PY_FIELD(f) d[#f] = s.f;
                 LUCENT_PY_SESSION_STATS(LUCENT_PY_FIELD)
#undef LUCENT_PY_FIELD
                 return d;
               })
          .def("__repr__", [](const SessionStats& s) {
            std::string out = "<lucent.SessionStats";
#define LUCENT_PY_FIELD(f) out += " " #f "=" + format_field(s.f);
            LUCENT_PY_SESSION_STATS(LUCENT_PY_FIELD)
#undef LUCENT_PY_FIELD
            return out + ">";
          });

  py::class_<RenderResult> result(
      m, "RenderResult",
      "An accumulation: mean and variance (H, W, 3) float32 and samples (H, W) uint32 are "
      "read-only NumPy views of this object's memory (no copy; to change them, copy them and make "
      "a RenderResult of the copies, which checks them); variance and samples are None for images "
      "that carry none.");
  bind_device_shares(m, result);
  result
      .def(
          py::init([](py::handle mean, py::handle variance, py::handle samples,
                      const IntArg& spp_arg) {
            // (an spp of 2^70 or -1 was pybind's "incompatible constructor arguments" TypeError)
            const std::uint64_t spp = int_argument(spp_arg, "spp", 0, kSampleIndices, kSampleNote);
            RenderResult r;
            r.mean = image_from_array(mean, "mean");
            if (!variance.is_none()) {
              r.variance = image_from_array(variance, "variance");
              if (r.variance.width != r.mean.width || r.variance.height != r.mean.height)
                throw py::value_error("variance: its shape differs from the mean's");
              for (float v : r.variance.rgb)
                if (!(v >= 0) || !std::isfinite(v))
                  throw py::value_error("variance: every value must be finite and >= 0, got " +
                                        std::to_string(v));
            }
            if (!samples.is_none()) {
              // whole counts in [0, 2^32): forcecast wrapped -1 to 4294967295 and cut 2.9 to 2
              py::array given = array_or_null<py::array>(samples);
              if (!given || given.ndim() != 2 || given.shape(0) != r.mean.height ||
                  given.shape(1) != r.mean.width)
                throw py::value_error("samples: expected an array of shape (H, W) like the mean's");
              const char kind = given.dtype().kind();
              if (kind != 'i' && kind != 'u')
                throw py::type_error("samples: expected integer counts, got an array of dtype " +
                                     py::str(given.dtype()).cast<std::string>());
              // unsigned counts as unsigned: 2^63 as int64 was "got -9223372036854775808"
              const auto check = [](auto wide) {
                for (py::ssize_t k = 0; k < wide.size(); ++k)
                  if (wide.data()[k] < 0 || wide.data()[k] > UINT32_MAX)
                    throw py::value_error("samples: counts must be in [0, 2^32), got " +
                                          std::to_string(wide.data()[k]));
              };
              if (kind == 'u')
                check(CArray<std::uint64_t>(given));
              else
                check(CArray<std::int64_t>(given));
              auto a = array_or_null<CArray<std::uint32_t>>(samples);
              if (!a || a.ndim() != 2 || a.shape(0) != r.mean.height || a.shape(1) != r.mean.width)
                throw py::value_error("samples: expected an array of shape (H, W) like the mean's");
              r.samples.assign(a.data(), a.data() + a.size());
            }
            // a variance is per sample: compare() divides it by the counts (without them it
            // took one sample a pixel) and write_render_exr() writes both or neither
            if (!r.variance.rgb.empty() && r.samples.empty())
              throw py::value_error(
                  "variance: a variance needs the per-pixel sample counts (samples=...)");
            r.spp = spp;
            return r;
          }),
          py::arg("mean"), py::arg("variance") = py::none(), py::arg("samples") = py::none(),
          py::arg("spp") = 0)
      .def_property_readonly(
          "mean",
          [](py::object self) {
            const RenderResult& r = self.cast<const RenderResult&>();
            return readonly_view(r.mean.rgb, {r.mean.height, r.mean.width, 3}, self);
          })
      .def_property_readonly(
          "variance",
          [](py::object self) -> py::object {
            const RenderResult& r = self.cast<const RenderResult&>();
            if (r.variance.rgb.empty()) return py::none();
            return readonly_view(r.variance.rgb, {r.variance.height, r.variance.width, 3}, self);
          })
      .def_property_readonly("samples",
                             [](py::object self) -> py::object {
                               const RenderResult& r = self.cast<const RenderResult&>();
                               if (r.samples.empty()) return py::none();
                               return readonly_view(r.samples, {r.mean.height, r.mean.width}, self);
                             })
      .def_property_readonly("width", [](const RenderResult& r) { return r.mean.width; })
      .def_property_readonly("height", [](const RenderResult& r) { return r.mean.height; })
      .def_readonly("spp", &RenderResult::spp)
      .def_readonly("nonfinite", &RenderResult::nonfinite)
      .def_readonly("estimated_relmse", &RenderResult::estimated_relmse,
                    "an adaptive render's estimate of its relMSE (0: not adaptive)")
      .def_readonly("halves_relmse", &RenderResult::halves_relmse,
                    "an adaptive render's relMSE from its halves' difference (0: not adaptive)")
      .def_readonly("model_gain_a", &RenderResult::model_gain_a,
                    "a target render's calibration gain of half A's error model (0: none)")
      .def_readonly("model_gain_b", &RenderResult::model_gain_b,
                    "a target render's calibration gain of half B's error model (0: none)")
      .def_readonly("planned_relmse", &RenderResult::planned_relmse,
                    "the relMSE the last call's calibrated plans predicted (0: none, or a budget "
                    "call)")
      .def_readonly("target_error", &RenderResult::target_error,
                    "the relMSE an adaptive render aimed at (0: not adaptive)")
      .def_readonly("planned_spp", &RenderResult::planned_spp,
                    "an adaptive render's planned samples per pixel, calibration included (the "
                    "pilot's while the pilot is not complete; 0: not adaptive)")
      .def_readonly("pilot_incomplete", &RenderResult::pilot_incomplete,
                    "a time limit or a cancel stopped an adaptive render in its pilot (no plan "
                    "made, nothing estimated)")
      .def_readonly("plan_incomplete", &RenderResult::plan_incomplete,
                    "a time limit or a cancel stopped an adaptive render before every planned "
                    "sample was rendered")
      .def_property_readonly("target_shortfall", &lucent::target_shortfall,
                             "a target render's warning when a time limit stopped it in its pilot "
                             "or its halves' relMSE is above 1.5 times the target ('' otherwise)")
      .def_readonly("seed", &RenderResult::seed,
                    "the seed of the render's random numbers (meaningful when sampler is set)")
      .def_readonly("sampler", &RenderResult::sampler,
                    "the render's sampler ('sobol', 'independent'); '' when unknown (an image "
                    "that did not say); write_render_exr stores both")
      .def_property_readonly(
          "light_mean_variance",
          [](const RenderResult& r) { return light_mean_variance_object(r.light_mean_variance); },
          "integrator.caustics: the image mean's light part, {'paths': (R, G, B), 'pixels': (R, G, "
          "B)}: its variance from the light paths' totals, and its share of the variance layer "
          "summed over the pixels, each over the pixel count squared (compare's image-mean test "
          "uses both); None without caustics or when unknown")
      .def_readonly("rays", &RenderResult::rays)
      .def_readonly("seconds", &RenderResult::seconds)
      .def_readonly("build_seconds", &RenderResult::build_seconds)
      .def_readonly("program_cache_hit", &RenderResult::program_cache_hit)
      .def_property_readonly("build_options",
                             [](const RenderResult& r) { return FileText{r.build_options}; })
      .def_readonly("cancelled", &RenderResult::cancelled)
      .def_readonly("device", &RenderResult::device)
      .def(py::pickle([](const RenderResult& r) -> py::object { return result_state(r); },
                      &result_from_state))
      .def("__repr__", &result_repr);

  py::class_<PyRenderer> renderer(
      m, "Renderer", py::custom_type_setup(collected_by_python<PyRenderer>),
      "A render session: one device and one scene, rendered progressively. set_scene() packs "
      "the scene and builds only what changed (a camera move rebuilds neither the BVH nor the "
      "kernel, and set_camera() packs nothing again: see stats). Environment variables are not "
      "read: pass **lucent.environment() for "
      "the `lucent` command's defaults.");
  bind_session_devices<Renderer>(renderer);
  renderer
      .def(py::init<const TextArg&, const PathText&, const PathText&, const TextArg&,
                    const FlagArg&, const FlagArg&, double, const IntArg&, py::object>(),
           py::kw_only(), py::arg("device") = "", py::arg("kernel_dir") = "",
           py::arg("cache_dir") = "", py::arg("precision") = "float", py::arg("fast_math") = false,
           py::arg("specialize") = true, py::arg("pass_seconds") = 0.25,
           py::arg("reserved_host_bytes") = 0, py::arg("on_warning") = py::none(),
           "device: an index from list_devices() or a name substring (\"\": the first GPU, else "
           "the first CPU); kernel_dir: \"\" for the embedded kernels; cache_dir: \"\" for the "
           "default, \"off\" for none; precision: \"float\" or \"double\"; reserved_host_bytes: "
           "host memory the application holds beside the session (its outputs, other results), "
           "added to the estimate by which set_scene() refuses a film too large; "
           "on_warning(message): "
           "warnings of scene packing (None: warnings.warn with LucentWarning).")
      .def_property_readonly(
          "device", [](PyRenderer& r) { return r.get().device(); },
          "The session's (first) device (any thread, at any time until close()).")
      .def("__repr__",
           [](py::handle self) -> std::string {
             // (never raises: a closed renderer says so)
             PyRenderer* r = constructed<PyRenderer>(self.ptr());
             if (!r) return "<lucent.Renderer (not initialised)>";
             try {
               return "<lucent.Renderer device=" +
                      py::repr(py::cast(r->get().device())).cast<std::string>() + ">";
             } catch (const Error&) {
               return "<lucent.Renderer (closed)>";
             }
           })
      .def_property_readonly(
          "options",
          [](PyRenderer& r) {
            // a copy: making the dict may let other threads run
            const SessionOptions o = r.read("options").options();
            py::dict d;
            d["device"] = o.device;
            d["kernel_dir"] = file_text(o.kernel_dir);
            d["cache_dir"] = file_text(o.cache_dir);
            d["precision"] = precision_name(o.precision);
            d["fast_math"] = o.fast_math;
            d["specialize"] = o.specialize;
            d["pass_seconds"] = o.pass_seconds;
            d["reserved_host_bytes"] = o.reserved_host_bytes;
            return d;
          },
          "The session's options, as a dict. Like scene, raises while "
          "another thread's call runs.")
      .def(
          "set_build_options",
          [](PyRenderer& r, const TextArg& precision, const FlagArg& fast_math_arg,
             const FlagArg& specialize_arg) {
            // a setting not given (None) stays the session's: set_build_options(fast_math=True)
            // turned a double-precision session into a float one without a word
            std::optional<Precision> p;
            std::optional<bool> fast_math, specialize;
            if (!precision.value.is_none())
              p = parse_enum<Precision>(text_argument(precision, "precision"));
            if (!fast_math_arg.value.is_none())
              fast_math = flag_argument(fast_math_arg, "fast_math");
            if (!specialize_arg.value.is_none())
              specialize = flag_argument(specialize_arg, "specialize");
            r.call_interruptible("set_build_options", [&](Renderer& rr, std::atomic<bool>&) {
              const SessionOptions& o = rr.options();
              rr.set_build_options(p.value_or(o.precision), fast_math.value_or(o.fast_math),
                                   specialize.value_or(o.specialize));
            });
          },
          py::kw_only(), py::arg("precision") = py::none(), py::arg("fast_math") = py::none(),
          py::arg("specialize") = py::none(),
          "Build settings for the next set_scene/render; a setting not given (None) stays as it "
          "is.")
      .def(
          "set_scene",
          [](PyRenderer& r, const Scene& scene) {
            Scene copy = scene;  // Python threads may change `scene` while the GIL is released
            std::vector<std::string> inputs;
            for (const std::string& in : scene_detail::scene_inputs(copy.path, copy)) {
              std::error_code ec;
              const std::filesystem::path absolute = std::filesystem::absolute(in, ec);
              if (!ec && !in.empty()) inputs.push_back(absolute.string());
            }
            // interruptible: Ctrl-C stops a wait for another process's build of the kernel
            // (up to 600 s; it was ignored there)
            r.call_interruptible("set_scene",
                                 [&](Renderer& rr, std::atomic<bool>&) { rr.set_scene(copy); });
            r.inputs_at_set_scene = std::move(inputs);
          },
          py::arg("scene"),
          "Makes a copy of `scene` the session's scene; keeps the BVH, the kernel and the "
          "accumulation when it can (see Renderer).")
      .def(
          "set_camera",
          [](PyRenderer& r, const Camera& camera) {
            const Camera copy = camera;  // (as set_scene's copy of its scene)
            r.call_interruptible("set_camera",
                                 [&](Renderer& rr, std::atomic<bool>&) { rr.set_camera(copy); });
          },
          py::arg("camera"),
          "Moves the camera of the session's scene: what set_scene() of the scene with `camera` "
          "does (the same image, errors and warnings), without packing the scene again "
          "(stats.camera_moves). The film, integrator and the rest stay the scene's.")
      .def_property_readonly(
          "scene", [](PyRenderer& r) { return Scene(r.read("scene").scene()); },
          "A copy of the session's scene. Raises lucent.Error while another thread's call "
          "(set_scene, render, ...) runs, except from a render's progress callback (between "
          "passes, from any thread).")
      .def(
          "render",
          [](PyRenderer& r, const IntArg& spp_arg, double seconds, py::object progress) {
            // (2**32 passed here, and the session refused it: a pixel's count holds 2**32 - 1)
            const std::uint64_t spp =
                int_argument(spp_arg, "spp", 0, kSampleIndices - 1, kCountNote);
            seconds = checked_time_limit(seconds, "seconds");
            if (spp == 0 && seconds == 0)
              throw py::value_error(
                  "render: give spp > 0, seconds > 0 or both, got spp=0 and "
                  "seconds=0");
            return r.render("render", spp, seconds, std::move(progress));
          },
          py::arg("spp"), py::arg("seconds") = 0.0, py::arg("progress") = py::none(),
          "Adds `spp` samples per pixel, or samples for `seconds` when that comes first (0: no "
          "limit of that kind). progress(RenderProgress) is called after each pass. Ctrl-C stops "
          "after the current pass (the accumulation keeps it) and raises KeyboardInterrupt.")
      .def(
          "render_adaptive",
          [](PyRenderer& r, double target_error, double budget_spp, const IntArg& min_spp,
             const IntArg& max_spp, double max_seconds, py::object progress) {
            AdaptiveOptions o;
            o.target_error = checked_seconds(target_error, "target_error");
            o.budget_spp = checked_seconds(budget_spp, "budget_spp");
            if ((o.target_error > 0) == (o.budget_spp > 0))
              throw py::value_error(
                  "render_adaptive: give one of target_error and budget_spp, a number > 0, got "
                  "target_error=" +
                  format_field(o.target_error) + " and budget_spp=" + format_field(o.budget_spp));
            o.min_spp =
                static_cast<std::uint32_t>(int_argument(min_spp, "min_spp", 4, kMaxAdaptiveSpp));
            o.max_spp =
                static_cast<std::uint32_t>(int_argument(max_spp, "max_spp", 4, kMaxAdaptiveSpp));
            // the pilot is two halves of (min_spp + 1) / 2 samples (Renderer::render_adaptive)
            const std::uint64_t pilot = 2 * ((std::uint64_t(o.min_spp) + 1) / 2);
            if (o.max_spp < pilot)
              throw py::value_error(
                  "max_spp must be at least min_spp's pilot (min_spp rounded up "
                  "to even, " +
                  std::to_string(pilot) + "), got min_spp=" + std::to_string(o.min_spp) +
                  " and max_spp=" + std::to_string(o.max_spp));
            o.max_seconds = checked_time_limit(max_seconds, "max_seconds");
            return r.render_adaptive(o, std::move(progress));
          },
          py::arg("target_error") = 0.0, py::arg("budget_spp") = 0.0, py::arg("min_spp") = 64,
          py::arg("max_spp") = 16384, py::arg("max_seconds") = 0.0,
          py::arg("progress") = py::none(),
          "Adaptive sampling (the CLI's --target-error): a pilot of min_spp samples per pixel, "
          "then more where the error is high, until the estimated relMSE is at most target_error "
          "(or the samples average budget_spp per pixel), at most max_spp per pixel, within "
          "max_seconds (0: no limit). Unbiased; result().estimated_relmse says what it reached. "
          "Ends the uniform accumulation: call reset() before a uniform render.")
      .def(
          "render_for",
          [](PyRenderer& r, double seconds, py::object progress) {
            if (!(seconds > 0) || !(seconds <= limits::kMaxSeconds))
              throw py::value_error("seconds must be a finite number in (0, 1e7], got " +
                                    format_field(seconds));
            return r.render("render_for", 0, seconds, std::move(progress));
          },
          py::arg("seconds"), py::arg("progress") = py::none(),
          "Adds samples for about `seconds` (at least one pass).")
      .def(
          "reset",
          [](PyRenderer& r, const IntArg& first_sample) {
            const std::uint64_t first =
                int_argument(first_sample, "first_sample", 0, kSampleIndices - 1, kSampleNote);
            r.call("reset", [&](Renderer& rr) { rr.reset(first); });
          },
          py::arg("first_sample") = 0,
          "Drops the accumulation; the next sample index is first_sample.")
      .def(
          "write_part",
          [](PyRenderer& r, const std::filesystem::path& path, py::object requested,
             const TextArg& compression_arg) {
            const std::string compression = text_argument(compression_arg, "compression");
            const std::string p = path.string();
            PartCompression c = PartCompression::zip;
            if (compression == "piz")
              c = PartCompression::piz;
            else if (compression != "zip")
              throw py::value_error("compression must be 'zip' or 'piz', got '" + compression +
                                    "'");
            if (io::lower_extension(p) != ".exr")
              throw Error(p + ": write_part writes a part file: use an .exr name");
            std::optional<SampleRange> asked;
            if (!requested.is_none())
              asked = range_argument(requested, "requested", kSampleIndices, kSampleNote);
            r.call("write_part", [&](Renderer& rr) {
              const Scene& scene = rr.scene();  // (raises without a scene)
              // not over the scene or a file it reads (a part written over scene.json), by the
              // names set_scene resolved too
              std::vector<std::string> inputs = scene_detail::scene_inputs(scene.path, scene);
              inputs.insert(inputs.end(), r.inputs_at_set_scene.begin(),
                            r.inputs_at_set_scene.end());
              io::check_output_path(p, inputs);
              if (rr.spp() == 0)
                throw Error(p + ": the session holds no samples to write (render first)");
              const SampleRange rendered{rr.first_sample(), rr.first_sample() + rr.spp()};
              write_render_part(p, make_part(rr, asked.value_or(rendered), scene.path), c);
            });
          },
          py::arg("path"), py::kw_only(), py::arg("requested") = py::none(),
          py::arg("compression") = "zip",
          "Writes the accumulation, samples [first_sample, first_sample + spp), as a part file "
          "(.exr, docs/parts.md): parts of disjoint ranges of one scene merge into the image of "
          "their union, exactly (merge_parts, `lucent merge`). requested=(begin, end): the range "
          "the render was asked for, recorded as `lucent render --samples A:B` does, so that a "
          "render cut short (a time limit, cancel()) leaves the rest missing in merge_parts; by "
          "default the samples rendered. compression: 'zip' (the default) or 'piz' (written in "
          "half the time, read in twice it). Refused for a session without samples, an "
          "adaptive render, light-traced caustics, a requested range that does not hold the "
          "samples, and a path that is the scene or one of its files.")
      .def(
          "result", [](PyRenderer& r) { return r.result(); },
          "The accumulation so far (a RenderResult; its arrays are this call's own). Also from a "
          "render's progress callback (between passes: a live preview).")
      .def_property_readonly(
          "spp", [](PyRenderer& r) { return r.counters().spp; },
          "Samples per pixel accumulated. spp, first_sample and stats can be read from any "
          "thread: while a call runs, they give the values it began with, updated after each "
          "pass of render(), render_for() and render_adaptive().")
      .def_property_readonly(
          "first_sample", [](PyRenderer& r) { return r.counters().first_sample; },
          "Index of the accumulation's first sample (reset's argument).")
      .def_property_readonly(
          "stats", [](PyRenderer& r) { return r.counters().stats; },
          "What the session has built and done (a SessionStats).")
      .def(
          "cancel", [](PyRenderer& r) { r.cancel(); },
          "Stops a render in progress (in another thread) after its current pass.")
      .def("close", &PyRenderer::close,
           "Releases the device; every later call raises lucent.Error (closing again does "
           "nothing). Raises lucent.Error while a call runs: another thread's, or the one whose "
           "callback (progress, on_warning, converge's on_point) calls close().")
      .def(
          "__reduce_ex__",
          [](const PyRenderer&, py::handle) -> py::object {
            // pickle, copy.copy and copy.deepcopy ask for this first
            throw py::type_error(
                "cannot pickle or copy a lucent.Renderer: it is a session on a device (its "
                "kernel, buffers and accumulation live there); pickle its scene and result() "
                "instead and make a Renderer where they are used");
          },
          py::arg("protocol"))
      .def("__enter__",
           [](py::object self) {
             self.cast<PyRenderer&>().get();  // (a closed renderer entered a with block)
             return self;
           })
      .def("__exit__", [](PyRenderer& r, py::args) { r.close(); });

  m.def(
      "render_reference",
      [](const Scene& scene, const IntArg& spp, const IntArg& threads_arg, py::object on_warning) {
        const int threads = static_cast<int>(
            int_argument(threads_arg, "threads", 0, std::numeric_limits<int>::max()));
        check_callable(on_warning, "on_warning");
        Scene copy = scene;
        std::atomic<bool> cancel{false};
        ReferenceOptions o;
        o.spp = static_cast<int>(int_argument(spp, "spp", 0, std::uint64_t(1) << 30));
        o.threads = threads;
        o.cancel = &cancel;
        // its warnings (no light, energy notes) to Python, as converge's: they went to stderr
        auto warning_errors = std::make_shared<CallbackErrors>();
        CallerQueue* queue = nullptr;  // (the call's: warnings come from its worker thread)
        o.on_warning = python_warning_sink(SharedObject(std::move(on_warning)), warning_errors,
                                           &queue, &cancel);
        RenderResult out;
        run_interruptible(
            [&] {
              queue = t_caller_queue;
              out = render_reference(copy, o);
            },
            cancel);
        warning_errors->rethrow();
        return out;
      },
      py::arg("scene"), py::arg("spp") = 0, py::arg("threads") = 0,
      py::arg("on_warning") = py::none(),
      "Renders with the scalar double-precision reference integrator (spp 0: the scene's; "
      "threads 0: all cores). Ctrl-C stops it and raises KeyboardInterrupt. Its warnings go to "
      "on_warning(message), or warnings.warn(message, LucentWarning) when None.");

  py::class_<ConvergePoint>(m, "ConvergePoint", "One rung of a convergence ladder.")
      .def_readonly("setting", &ConvergePoint::setting)
      .def_readonly("spp", &ConvergePoint::spp)
      .def_readonly("seconds", &ConvergePoint::seconds)
      .def_readonly("samples_per_second", &ConvergePoint::samples_per_second)
      .def_readonly("rays_per_second", &ConvergePoint::rays_per_second)
      .def_readonly("rmse", &ConvergePoint::rmse)
      .def_readonly("relmse", &ConvergePoint::relmse)
      .def_readonly("noise_relmse", &ConvergePoint::noise_relmse)
      .def_readonly("reference_noise_relmse", &ConvergePoint::reference_noise_relmse)
      .def_readonly("excess_standard_error", &ConvergePoint::excess_standard_error)
      .def_readonly("estimated_relmse", &ConvergePoint::estimated_relmse)
      .def_readonly("halves_relmse", &ConvergePoint::halves_relmse)
      .def("__repr__", [](const ConvergePoint& p) {
        return "<lucent.ConvergePoint " + p.setting + " " + std::to_string(p.spp) +
               " spp, relMSE " + std::to_string(p.relmse) + ">";
      });
  py::class_<ConvergeFit>(m, "ConvergeFit", "The fitted error curve of one setting.")
      .def_readonly("setting", &ConvergeFit::setting)
      .def_readonly("points", &ConvergeFit::points)
      .def_readonly("slope_time", &ConvergeFit::slope_time)
      .def_readonly("slope_spp", &ConvergeFit::slope_spp)
      .def_readonly("tail_slope_spp", &ConvergeFit::tail_slope_spp)
      .def_readonly("excess_ratio", &ConvergeFit::excess_ratio)
      .def_readonly("biased", &ConvergeFit::biased)
      .def_readonly("bias_relmse", &ConvergeFit::bias_relmse)
      .def_readonly("floor_seconds", &ConvergeFit::floor_seconds)
      .def_readonly("verdict", &ConvergeFit::verdict)
      .def("__repr__", [](const ConvergeFit& f) {
        return "<lucent.ConvergeFit " + f.setting + ": " + f.verdict + ">";
      });
  py::class_<ConvergeResult>(m, "ConvergeResult", "Points (setting by setting) and fits.")
      .def_readonly("points", &ConvergeResult::points)
      .def_readonly("fits", &ConvergeResult::fits)
      .def("__repr__",
           [](const ConvergeResult& r) {
             // `<lucent.ConvergeResult of 8 points: default: unbiased; clamp=1: biased>`
             std::string s =
                 "<lucent.ConvergeResult of " + std::to_string(r.points.size()) + " points";
             // (each verdict's first words: its reasons follow " (" or "; ")
             for (std::size_t i = 0; i < r.fits.size(); ++i) {
               const std::string& v = r.fits[i].verdict;
               s += (i ? "; " : ": ") + r.fits[i].setting + ": " +
                    v.substr(0, std::min(v.find(" ("), v.find(';')));
             }
             return s + ">";
           })
      .def("csv", &convergence_csv, "setting,spp,seconds,samples_per_s,rmse,relmse,... rows")
      .def("svg", &convergence_svg, py::arg("title") = "relMSE against render time",
           "Log-log plot of relMSE against time, as SVG text.")
      .def(
          "plot_image",
          [](const ConvergeResult& r, const std::string& title) {
            return image_array(convergence_image(r, title));
          },
          py::arg("title") = "relMSE against render time",
          "The same plot as an (H, W, 3) linear float32 image (write_image it as a PNG).");

  m.def(
      "converge",
      [](const Scene& scene, py::handle reference, const std::vector<std::string>& settings,
         std::optional<std::vector<IntArg>> spp_ladder,
         std::optional<std::vector<double>> time_ladder, py::object renderer, py::object on_point) {
        check_callable(on_point, "on_point");
        if (!renderer.is_none() && !py::isinstance<PyRenderer>(renderer))
          throw py::type_error("renderer must be a lucent.Renderer or None, got " +
                               py::repr(renderer).cast<std::string>());
        if (spp_ladder && time_ladder)
          throw py::value_error("give spp_ladder or time_ladder, not both");
        ConvergeOptions o;
        o.settings = parse_settings(settings);
        // the command line's limits (lucent converge --spp-ladder, --time-ladder)
        if (time_ladder)
          o.time_ladder = *time_ladder;
        else if (spp_ladder)
          for (const IntArg& s : *spp_ladder)
            o.spp_ladder.push_back(
                static_cast<int>(int_argument(s, "spp_ladder values", 1, limits::kMaxSpp, "")));
        else
          o.spp_ladder = default_spp_ladder(64);
        static_assert(limits::kMaxSeconds == 1e7, "the message below says (0, 1e7]");
        for (double t : o.time_ladder)
          if (!(t > 0 && t <= limits::kMaxSeconds))
            throw py::value_error("time_ladder values must be in (0, 1e7] seconds, got " +
                                  py::repr(py::float_(t)).cast<std::string>());
        RenderResult ref = render_result_from(reference, "reference");
        Scene copy = scene;
        CallbackErrors errors;
        std::atomic<bool>* stop = nullptr;
        // on_point is a callback of the session's converge call when it renders in one
        PyRenderer* session = renderer.is_none() ? nullptr : &renderer.cast<PyRenderer&>();
        if (!on_point.is_none())
          o.on_point = [&](const ConvergePoint& p) {
            // (on the thread that called converge)
            run_with_gil(t_caller_queue, [&] {
              InCallback frame(session, "on_point callback");
              // result() reads there, as run_convergence's on_point may (it was refused)
              PyRenderer::PausedInCallback paused(session);
              if (!errors.run([&] { on_point(p); })) *stop = true;
            });
          };
        ConvergeResult out;
        if (renderer.is_none()) {
          auto warning_errors = std::make_shared<CallbackErrors>();
          std::atomic<bool> cancel{false};
          CallerQueue* queue = nullptr;  // (the call's, for warnings from its device threads)
          o.render.on_warning =
              python_warning_sink(SharedObject(py::none()), warning_errors, &queue, &cancel);
          stop = &cancel;
          o.render.cancel = &cancel;
          run_interruptible(
              [&] {
                queue = t_caller_queue;
                out = run_convergence(copy, ref, o);
              },
              cancel);
          warning_errors->rethrow();
        } else {
          // the session given renders every rung, with its own cancel flag
          renderer.cast<PyRenderer&>().call_interruptible(
              "converge", [&](Renderer& r, std::atomic<bool>& cancel) {
                stop = &cancel;
                o.render.cancel = &cancel;
                o.renderer = &r;
                out = run_convergence(copy, ref, o);
              });
        }
        errors.rethrow();
        return out;
      },
      py::arg("scene"), py::arg("reference"), py::kw_only(),
      py::arg("settings") = std::vector<std::string>{"default"}, py::arg("spp_ladder") = py::none(),
      py::arg("time_ladder") = py::none(), py::arg("renderer") = py::none(),
      py::arg("on_point") = py::none(),
      "Renders a ladder of spp (default 1, 2, 4, ..., 64) or seconds for each setting "
      "(\"default\", \"fast-math\", \"max_depth=2+no-mis\", ...: see `lucent converge`) and "
      "measures each rung's error against `reference` (a RenderResult or an array); returns a "
      "ConvergeResult. renderer: a Renderer to render with (default: a new session with the "
      "default options). on_point(ConvergePoint): called after each rung, on the calling thread "
      "(an exception it raises stops the study and is raised). Ctrl-C stops after the current "
      "pass and raises KeyboardInterrupt.");
}

}  // namespace lucent::python

// The `lucent` Python module: errors, enum names, devices, the environment's defaults, and the
// helpers shared by the other parts (scene.cpp, render.cpp, image.cpp).
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <future>
#include <mutex>
#include <set>
#include <thread>
#ifdef __GLIBCXX__
#include <cxxabi.h>  // abi::__forced_unwind
#endif

#include "cl/program_cache.hpp"
#include "common.hpp"
#include "core/text.hpp"
#include "lucent/device.hpp"
#include "lucent/error.hpp"
#include "lucent/session.hpp"
#include "lucent/version.hpp"
#include "render/resources.hpp"

namespace lucent::python {

#define LUCENT_PY_NAME(ID, Name, value, name, ...) {Enum::Name, name},

template <>
const EnumNames<MaterialType>& enum_names<MaterialType>() {
  using Enum = MaterialType;
  static const EnumNames<Enum> t{"material type", {LC_MATERIAL_TYPES(LUCENT_PY_NAME)}};
  return t;
}
template <>
const EnumNames<LightType>& enum_names<LightType>() {
  using Enum = LightType;
  static const EnumNames<Enum> t{"light type", {LC_LIGHT_TYPES(LUCENT_PY_NAME)}};
  return t;
}
template <>
const EnumNames<IntegratorType>& enum_names<IntegratorType>() {
  using Enum = IntegratorType;
  static const EnumNames<Enum> t{
      "integrator", {LC_INTEGRATOR_TYPES(LUCENT_PY_NAME) LC_AOV_TYPES(LUCENT_PY_NAME)}};
  return t;
}
template <>
const EnumNames<FilterType>& enum_names<FilterType>() {
  using Enum = FilterType;
  static const EnumNames<Enum> t{"filter type", {LC_FILTER_TYPES(LUCENT_PY_NAME)}};
  return t;
}
template <>
const EnumNames<ShapeType>& enum_names<ShapeType>() {
  using Enum = ShapeType;
  static const EnumNames<Enum> t{"shape type", {LC_SHAPE_TYPES(LUCENT_PY_NAME)}};
  return t;
}
template <>
const EnumNames<SamplerType>& enum_names<SamplerType>() {
  using Enum = SamplerType;
  static const EnumNames<Enum> t{"sampler", {LC_SAMPLER_TYPES(LUCENT_PY_NAME)}};
  return t;
}
#undef LUCENT_PY_NAME

// Not in the registries: the film's display settings (scene-file names) and the precision.
template <>
const EnumNames<Transfer>& enum_names<Transfer>() {
  static const EnumNames<Transfer> t{
      "transfer",
      {{Transfer::Srgb, "srgb"}, {Transfer::Gamma, "gamma"}, {Transfer::Linear, "linear"}}};
  return t;
}
template <>
const EnumNames<ToneMap>& enum_names<ToneMap>() {
  static const EnumNames<ToneMap> t{
      "tone map",
      {{ToneMap::Clamp, "clamp"}, {ToneMap::Reinhard, "reinhard"}, {ToneMap::Aces, "aces"}}};
  return t;
}
template <>
const EnumNames<TextureWrap>& enum_names<TextureWrap>() {
  static const EnumNames<TextureWrap> t{
      "wrap mode",
      {{TextureWrap::Repeat, texture_wrap_name(TextureWrap::Repeat)},
       {TextureWrap::Clamp, texture_wrap_name(TextureWrap::Clamp)},
       {TextureWrap::Mirror, texture_wrap_name(TextureWrap::Mirror)}}};
  return t;
}
template <>
const EnumNames<Precision>& enum_names<Precision>() {
  static const EnumNames<Precision> t{"precision",
                                      {{Precision::Float, "float"}, {Precision::Double, "double"}}};
  return t;
}

std::string visible_nul(const std::string& text) {
  std::string out;
  for (char c : text) out += c == '\0' ? std::string("\\x00") : std::string(1, c);
  return out;
}

std::string range_bound(std::uint64_t n) {
  for (int k = 16; k <= 64; ++k) {
    const std::uint64_t p = k < 64 ? std::uint64_t(1) << k : 0;  // 2**64 wraps to 0
    if (k < 64 && n == p) return "2**" + std::to_string(k);
    if (n == p - 1) return "2**" + std::to_string(k) + " - 1";
  }
  return std::to_string(n);
}

std::string int_repr(py::handle value) {
  try {
    return py::repr(value).cast<std::string>();
  } catch (py::error_already_set&) {  // an int past sys.get_int_max_str_digits()
    return "an integer too long to show";
  }
}

IntValue int_value(const IntArg& arg, const std::string& what, bool allow_bool) {
  py::handle v = arg.value;
  IntValue out;
  if (allow_bool || !py::isinstance<py::bool_>(v))
    out.index = py::reinterpret_steal<py::object>(PyNumber_Index(v.ptr()));
  if (!out.index) {
    PyErr_Clear();
    throw py::type_error(what + " must be an integer, got " + int_repr(v));
  }
  int overflow = 0;
  const long long x = PyLong_AsLongLongAndOverflow(out.index.ptr(), &overflow);
  if (x == -1 && PyErr_Occurred()) throw py::error_already_set();
  if (overflow == 0) {
    out.fits = true;
    out.negative = x < 0;
    out.magnitude =
        x < 0 ? static_cast<std::uint64_t>(-(x + 1)) + 1 : static_cast<std::uint64_t>(x);
  } else if (overflow > 0) {  // 2**63 and more: within 64 bits?
    const unsigned long long u = PyLong_AsUnsignedLongLong(out.index.ptr());
    if (PyErr_Occurred()) {
      PyErr_Clear();
    } else {
      out.fits = true;
      out.magnitude = u;
    }
  }
  return out;
}

std::uint64_t int_argument(const IntArg& arg, const char* what, std::uint64_t lo, std::uint64_t hi,
                           const char* note) {
  const IntValue v = int_value(arg, what, /*allow_bool=*/true);
  if (!v.fits || v.negative || v.magnitude < lo || v.magnitude > hi)
    throw py::value_error(std::string(what) + " must be an integer in [" + range_bound(lo) + ", " +
                          range_bound(hi) + "]" + note + ", got " + int_repr(v.index));
  return v.magnitude;
}

SampleRange range_argument(py::handle arg, const char* what, std::uint64_t top, const char* note) {
  const py::tuple t =
      py::isinstance<py::tuple>(arg) ? py::reinterpret_borrow<py::tuple>(arg) : py::tuple();
  if (t.size() != 2)
    throw py::type_error(std::string(what) + " must be a tuple (begin, end), got " +
                         py::repr(arg).cast<std::string>());
  const std::string name(what);
  const SampleRange r{int_argument(IntArg{t[0]}, (name + " begin").c_str(), 0, top - 1, note),
                      int_argument(IntArg{t[1]}, (name + " end").c_str(), 1, top, note)};
  if (r.begin >= r.end)
    throw py::value_error(name + " must be (begin, end) with begin < end, got (" +
                          std::to_string(r.begin) + ", " + std::to_string(r.end) + ")");
  return r;
}

void refuse_nul(const std::string& text, const char* what) {
  if (text.find('\0') != std::string::npos)
    throw py::value_error(std::string(what) + ": embedded null character in '" + visible_nul(text) +
                          "'");
}

py::str message_text(const std::string& raw) {
  // one line, as the command line prints it: a name with a newline or an escape sequence (a
  // material "a\nb") came through raw in lucent.Error and in warnings
  const std::string message = io::one_line(raw);
  PyObject* text = PyUnicode_DecodeUTF8(message.data(), static_cast<Py_ssize_t>(message.size()),
                                        "backslashreplace");
  if (!text) throw py::error_already_set();
  return py::reinterpret_steal<py::str>(text);
}

py::array_t<float> image_array(Image&& image) {
  auto* owner = new std::vector<float>(std::move(image.rgb));
  py::capsule capsule(owner, [](void* v) { delete static_cast<std::vector<float>*>(v); });
  return py::array_t<float>({image.height, image.width, 3}, owner->data(), capsule);
}

py::array_t<double> copy_rows(const double* first, std::size_t n, py::ssize_t cols) {
  py::array_t<double> a({static_cast<py::ssize_t>(n), cols});
  if (n > 0) std::copy(first, first + n * cols, a.mutable_data());
  a.attr("flags").attr("writeable") = false;
  return a;
}

void require_numbers(py::handle object, const std::string& what, std::uint64_t bytes_per_value) {
  // (NumPy makes an array of dtype object of None: "got an array of dtype object" named no None)
  if (object.is_none()) throw py::type_error(what + ": expected numbers, got None");
  py::array a = array_or_null<py::array>(object);
  if (!a) return;  // not convertible at all: the caller's conversion says so
  const char kind = a.dtype().kind();
  if (kind != 'b' && kind != 'i' && kind != 'u' && kind != 'f')
    throw py::type_error(what + ": expected numbers, got an array of dtype " +
                         py::str(a.dtype()).cast<std::string>());
  std::string limit_what;
  const std::uint64_t limit =
      bytes_per_value > 0 ? render_detail::host_memory_allowed(&limit_what) : 0;
  const double need = double(a.size()) * double(bytes_per_value);
  if (limit == 0 || need <= double(limit)) return;
  char buf[200];
  std::snprintf(buf, sizeof buf,
                ": %lld values need about %.1f GiB to copy, more than the %.1f GiB lucent allows "
                "itself (80%% of ",
                static_cast<long long>(a.size()), need / double(1ull << 30),
                double(limit) / double(1ull << 30));
  PyErr_SetString(PyExc_MemoryError, (what + buf + limit_what + ")").c_str());
  throw py::error_already_set();
}

Image image_from_array(py::handle object, const char* what) {
  // (the image's own copy, and the float32 conversion's unless the array is one already: a
  // broadcast view of one value standing for 40000x40000 pixels was copied whole, 17.9 GiB)
  const bool no_conversion =
      py::isinstance<py::array_t<float>>(object) &&
      (py::reinterpret_borrow<py::array>(object).flags() & py::array::c_style);
  require_numbers(object, what, (no_conversion ? 1 : 2) * sizeof(float));
  auto a = array_or_null<CArray<float>>(object);
  if (!a) throw py::type_error(std::string(what) + ": expected an array of shape (H, W, 3)");
  if (a.ndim() != 3 || a.shape(2) != 3 || a.shape(0) < 1 || a.shape(1) < 1) {
    std::string shape;
    for (py::ssize_t i = 0; i < a.ndim(); ++i)
      shape += (i ? ", " : "") + std::to_string(a.shape(i));
    throw py::value_error(std::string(what) + ": expected an array of shape (H, W, 3), got (" +
                          shape + (a.ndim() == 1 ? ",)" : ")"));
  }
  Image img;
  img.height = static_cast<int>(a.shape(0));
  img.width = static_cast<int>(a.shape(1));
  img.rgb.assign(a.data(), a.data() + a.size());
  return img;
}

RenderResult render_result_from(py::handle object, const char* what) {
  if (py::isinstance<RenderResult>(object)) return object.cast<RenderResult>();
  RenderResult r;
  r.mean = image_from_array(object, what);
  return r;
}

SharedObject::SharedObject(py::object o)
    : object_(new py::object(std::move(o)), [](py::object* p) {
        AcquireGil gil;
        delete p;
      }) {}

WarningSink python_warning_sink(SharedObject callback, std::shared_ptr<CallbackErrors> errors,
                                CallerQueue* const* queue, std::atomic<bool>* stop) {
  return [callback, errors, queue, stop](const std::string& message) {
    // (on the thread that made the call, when a thread of a call of run_interruptible gives it)
    run_with_gil(queue && *queue ? *queue : t_caller_queue, [&] {
      errors->run([&] {
        try {
          if (callback) {
            callback.get()(message_text(message));
          } else {
            // stacklevel 1: the innermost Python frame, the line that called into lucent (warn
            // is called from C++, not from a Python function of lucent's: 2 named the caller's
            // caller)
            py::module_ lucent = py::module_::import("lucent");
            py::module_::import("warnings")
                .attr("warn")(message_text(message), lucent.attr("LucentWarning"), 1);
          }
        } catch (py::error_already_set& e) {
          // Ctrl-C while it ran on the calling thread: the call stops, as for a progress
          // callback (converge ran its whole ladder before raising it)
          if (stop && e.matches(PyExc_KeyboardInterrupt)) stop->store(true);
          throw;
        }
      });
    });
  };
}

namespace {

[[noreturn]] void park_thread() {
  for (;;) std::this_thread::sleep_for(std::chrono::hours(1));
}

/// The calls of run_interruptible in progress, by their cancel flags: interpreter exit cancels
/// them and waits for them to end. Never destroyed: threads may still use it while the process
/// exits.
struct Calls {
  std::mutex mutex;
  std::condition_variable ended;
  std::multiset<std::atomic<bool>*> cancels;
  bool exiting = false;  ///< a call that begins now is cancelled at once
};
Calls& calls() {
  static Calls* c = new Calls;
  return *c;
}

/// Registers a call of run_interruptible while it lives.
class InProgress {
 public:
  explicit InProgress(std::atomic<bool>& cancel) : cancel_(cancel) {
    Calls& c = calls();
    std::lock_guard<std::mutex> lock(c.mutex);
    if (c.exiting) cancel.store(true);
    c.cancels.insert(&cancel);
  }
  ~InProgress() {
    Calls& c = calls();
    std::lock_guard<std::mutex> lock(c.mutex);
    c.cancels.erase(c.cancels.find(&cancel_));
    if (c.cancels.empty()) c.ended.notify_all();
  }
  InProgress(const InProgress&) = delete;
  InProgress& operator=(const InProgress&) = delete;

 private:
  std::atomic<bool>& cancel_;
};

/// How long interpreter exit waits for the calls it cancelled: a render stops after its current
/// pass (0.25 s by default), the reference renderer after its current row, which may take long
/// with a large spp: the process then exits without waiting further (the threads of the call
/// park when they ask for the GIL).
constexpr std::chrono::seconds kExitWait{5};

/// Runs at interpreter exit (atexit: after the non-daemon threads ended, before the interpreter
/// finalizes, while daemon threads still run): cancels the calls in progress and waits for them
/// to end, so that their threads return to Python rather than park, and no render runs on while
/// the process exits.
void end_calls_at_exit() {
  ReleaseGil release;  // the calls' threads take the GIL to return
  Calls& c = calls();
  std::unique_lock<std::mutex> lock(c.mutex);
  c.exiting = true;
  for (std::atomic<bool>* cancel : c.cancels) cancel->store(true);
  c.ended.wait_for(lock, kExitWait, [&] { return c.cancels.empty(); });
}

}  // namespace

void restore_gil(PyThreadState* state, std::atomic<bool>* cancel) noexcept {
#ifdef __GLIBCXX__
  try {
    PyEval_RestoreThread(state);
  } catch (abi::__forced_unwind&) {
    // the unwinding must end here (this function is noexcept): the thread never returns
    if (cancel) cancel->store(true);
    park_thread();
  }
#else
  (void)cancel;
  PyEval_RestoreThread(state);
#endif
}

ReleaseGil::ReleaseGil() {
  // as py::gil_scoped_release: pybind11's internals exist before a thread of ours asks for them
  py::detail::get_internals();
  state_ = PyEval_SaveThread();
}

AcquireGil::AcquireGil() {
#ifdef __GLIBCXX__
  try {
    gil_.emplace();
  } catch (abi::__forced_unwind&) {
    park_thread();
  }
#else
  gil_.emplace();
#endif
}

/// The callbacks of one call of run_interruptible: its worker (or a thread of the library that
/// works for it) posts one at a time and waits; the thread that made the call runs them between
/// its looks at Python's signals.
class CallerQueue {
 public:
  /// What the calling thread found when wait() returned.
  enum class Event { Timeout, Job, Finished };

  /// Posts `job` and waits until the calling thread has run it; rethrows its exception.
  void post(const std::function<void()>& job) {
    std::lock_guard<std::mutex> one_at_a_time(post_mutex_);
    std::unique_lock<std::mutex> lock(mutex_);
    job_ = &job;
    error_ = nullptr;
    wake_.notify_all();
    ran_.wait(lock, [&] { return job_ == nullptr; });
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  }

  /// The work has ended (its worker, as it returns): the calling thread stops waiting.
  void finish() {
    std::lock_guard<std::mutex> lock(mutex_);
    finished_ = true;
    wake_.notify_all();
  }

  /// (the calling thread) Waits up to `timeout` for a job or the work's end.
  Event wait(std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    wake_.wait_for(lock, timeout, [&] { return job_ || finished_; });
    return job_ ? Event::Job : finished_ ? Event::Finished : Event::Timeout;
  }

  /// (the calling thread, the GIL held) Runs the job posted and wakes its poster.
  void run_job() {
    const std::function<void()>* job;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job = job_;
    }
    std::exception_ptr error;
    try {
      (*job)();
    } catch (...) {
      error = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(mutex_);
    error_ = error;
    job_ = nullptr;
    ran_.notify_all();
  }

 private:
  std::mutex post_mutex_;  ///< one poster at a time
  std::mutex mutex_;
  std::condition_variable wake_;  ///< the calling thread: a job, or the end
  std::condition_variable ran_;   ///< the poster: its job ran
  const std::function<void()>* job_ = nullptr;
  std::exception_ptr error_;
  bool finished_ = false;
};

void run_with_gil(CallerQueue* queue, const std::function<void()>& f) {
  if (queue) {
    queue->post(f);
    return;
  }
  AcquireGil gil;
  f();
}

void run_interruptible(const std::function<void()>& work, std::atomic<bool>& cancel) {
  InProgress in_progress(cancel);  // ends once this thread holds the GIL again
  std::exception_ptr interrupt;
  std::exception_ptr failure;
  {
    ReleaseGil release;
    const CallbackFrame* callbacks = t_callbacks;  // valid while this thread waits
    CallerQueue queue;
    std::packaged_task<void()> task([&] {
      t_callbacks = callbacks;
      t_caller_queue = &queue;
      struct Finish {
        CallerQueue& queue;
        ~Finish() { queue.finish(); }
      } finish{queue};
      work();
    });
    std::future<void> done = task.get_future();
    std::thread worker(std::move(task));
    constexpr auto kSignalsEvery = std::chrono::milliseconds(50);
    auto signals_seen = std::chrono::steady_clock::now();
    for (;;) {
      const CallerQueue::Event event = queue.wait(kSignalsEvery);
      if (event == CallerQueue::Event::Finished) break;
      const auto now = std::chrono::steady_clock::now();
      // Python's signals every 50 ms, jobs or not: a callback that no signal interrupts (a C
      // function such as list.append) posted every few milliseconds by short passes kept this
      // thread from ever looking, and Ctrl-C went unseen (the review's find)
      const bool look = !interrupt && (event == CallerQueue::Event::Timeout ||
                                       now - signals_seen >= kSignalsEvery);
      if (event != CallerQueue::Event::Job && !look) continue;
      // at interpreter exit the thread parks here with the work cancelled (the worker stays
      // joinable)
      restore_gil(release.state(), &cancel);
      if (event == CallerQueue::Event::Job) queue.run_job();  // (after an interruption too)
      if (look) {
        signals_seen = now;
        if (PyErr_CheckSignals() != 0) {
          interrupt = std::make_exception_ptr(py::error_already_set());
          cancel.store(true);
        }
      }
      PyEval_SaveThread();
    }
    worker.join();
    try {
      done.get();
    } catch (...) {
      failure = std::current_exception();
    }
  }
  if (interrupt) std::rethrow_exception(interrupt);
  // a failure with Ctrl-C pending is the interruption: PoCL's LLVM fails a kernel build on SIGINT
  // (converge's next setting, a render's first build) before this thread's next look at the
  // signals, and lucent.Error came out instead of KeyboardInterrupt
  if (failure) {
    try {
      std::rethrow_exception(failure);
    } catch (const lucent::Error&) {
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      throw;
    }
  }
}

namespace {

/// The cache directory of a session whose cache_dir option is `dir` ("" when disabled): "" is
/// the default directory, as for Renderer(), which reads no environment variable unless asked
/// (it read LUCENT_CACHE_DIR, so clear_cache() emptied another directory than the sessions'
/// and removed none of their entries). The lucent command's: lucent.environment()["cache_dir"].
FileText resolved_cache_dir(const PathText& given) {
  const std::string& d = given.bytes;
  refuse_nul(d, "cache_dir");
  if (d == "off") return {};
  return {d.empty() ? cl_util::default_program_cache_dir() : d};
}

/// Gives every class of the module without a __reduce_ex__ of its own one for every pickle
/// protocol, and the same __reduce__. Protocols 0 and 1 otherwise reduce an object through
/// copyreg._reduce_ex, which calls pybind11's base type on it: a C++ exception that nothing
/// catches, and the interpreter aborts ("instance allocation failed: new instance has no
/// pybind11-registered base types", pybind11 issue 3745); object.__reduce__(), called by hand,
/// took the same path. A class with py::pickle reduces as protocol 2 does (copyreg.__newobj__,
/// then __setstate__ with its state), in any protocol; the others raise the TypeError that
/// protocol 2 raises for them. The iterators of the bound lists (ShapeList, ...: a pybind11
/// 'iterator' class each, in pybind11_builtins, not in the module) raise it too.
void reduce_in_every_protocol(py::module_& m) {
  // a Python subclass's state is ("lucent.subclass", the class's state, its __dict__), which
  // each bound class's __setstate__ reads (the attributes after the object exists: pickle and
  // deepcopy have memoized it, so attributes that refer back to it do so); any other state goes
  // to the class's own __setstate__, as before (old pickles load). On an object that exists
  // already (made by its constructor, or set before) pybind11 skips the call and returns None:
  // `scene.__setstate__(other.__getstate__())` left the scene as it was without a word; it is
  // refused
  // (an object of `cls` only: another one, 5 or object(), is the original's to refuse with its
  // TypeError; read as a pybind11 instance it crashed the interpreter)
  m.def("_constructed", [](py::handle self, py::handle cls) {
    if (!PyType_Check(cls.ptr()) ||
        !PyObject_TypeCheck(self.ptr(), reinterpret_cast<PyTypeObject*>(cls.ptr())))
      return false;
    auto* type = py::detail::get_type_info(reinterpret_cast<PyTypeObject*>(cls.ptr()));
    if (!type) return false;
    auto* inst = reinterpret_cast<py::detail::instance*>(self.ptr());
    return inst->get_value_and_holder(type).holder_constructed();
  });
  py::exec(R"py(
def _subclass_setstate(original, constructed, cls):
    def __setstate__(self, state):
        if constructed(self, cls):
            name = cls.__name__
            raise TypeError(f"{name}.__setstate__: this {name} exists already; its state is set "
                            "only on the object that pickle or copy makes (pickle.loads, "
                            "copy.copy)")
        if type(state) is tuple and len(state) == 3 and state[0] == "lucent.subclass":
            original(self, state[1])
            self.__dict__.update(state[2])
        else:
            original(self, state)
    __setstate__.__doc__ = original.__doc__
    return __setstate__
)py",
           m.attr("__dict__"));
  const py::object subclass_setstate = m.attr("_subclass_setstate");
  const py::object constructed = m.attr("_constructed");
  py::delattr(m, "_subclass_setstate");
  py::delattr(m, "_constructed");
  const py::object newobj = py::module_::import("copyreg").attr("__newobj__");
  const auto is_bound = [](py::handle cls) {
    return PyType_Check(cls.ptr()) &&
           py::detail::get_type_info(reinterpret_cast<PyTypeObject*>(cls.ptr()));
  };
  // __reduce_ex__(protocol) and __reduce__() of `cls`, both `reduce`
  const auto set_reduce = [](py::handle cls, const std::function<py::object(py::handle)>& reduce) {
    cls.attr("__reduce_ex__") =
        py::cpp_function([reduce](py::handle self, int) { return reduce(self); },
                         py::is_method(cls), py::arg("protocol"));
    cls.attr("__reduce__") = py::cpp_function(reduce, py::is_method(cls));
  };
  for (auto item : py::reinterpret_borrow<py::dict>(m.attr("__dict__"))) {
    py::handle cls = item.second;
    if (!is_bound(cls) || !cls.attr("__dict__").contains("__iter__")) continue;
    py::object empty;
    try {
      empty = cls();  // the lists; Vec3 and Vec2 need values (and iterate as Python lists)
    } catch (py::error_already_set&) {
      continue;
    }
    py::object iterator = py::type::of(py::iter(empty));
    if (!is_bound(iterator) || iterator.attr("__dict__").contains("__reduce_ex__")) continue;
    set_reduce(iterator, [](py::handle) -> py::object {
      throw py::type_error("cannot pickle 'iterator' object");
    });
  }
  for (auto item : py::reinterpret_borrow<py::dict>(m.attr("__dict__"))) {
    py::handle cls = item.second;
    if (!is_bound(cls)) continue;  // not a bound class (lucent.Error)
    if (cls.attr("__dict__").contains("__reduce_ex__")) {
      // one that says itself (Renderer): its __reduce__ says the same
      if (!cls.attr("__dict__").contains("__reduce__")) {
        const py::object own = cls.attr("__reduce_ex__");
        cls.attr("__reduce__") =
            py::cpp_function([own](py::handle self) { return own(self, 2); }, py::is_method(cls));
      }
    } else if (py::hasattr(cls, "__setstate__")) {
      // a Python subclass's attributes (its __dict__) come back too (the state alone lost them)
      cls.attr("__setstate__") = subclass_setstate(cls.attr("__setstate__"), constructed, cls);
      set_reduce(cls, [newobj](py::handle self) -> py::object {
        py::object state = self.attr("__getstate__")();
        const py::object attributes = py::getattr(self, "__dict__", py::none());
        if (!attributes.is_none() && py::len(attributes) > 0)
          state = py::make_tuple("lucent.subclass", state, attributes);
        return py::make_tuple(newobj, py::make_tuple(py::type::handle_of(self)), state);
      });
    } else {
      const std::string name = cls.attr("__name__").cast<std::string>();
      set_reduce(cls, [name](py::handle) -> py::object {
        throw py::type_error("cannot pickle 'lucent." + name + "' object");
      });
    }
  }
}

py::dict environment() {
  SessionOptions o = SessionOptions::from_environment();
  py::dict d;
  d["device"] = o.device;
  d["kernel_dir"] = file_text(o.kernel_dir);
  d["cache_dir"] = file_text(o.cache_dir);
  return d;
}

}  // namespace

}  // namespace lucent::python

PYBIND11_MODULE(lucent, m) {
  using namespace lucent;
  using namespace lucent::python;
  m.doc() =
      "lucent: a physically based OpenCL path tracer. Scenes (load_scene, scene_from_dict, "
      "Scene), render sessions (Renderer), images (write_image, read_render, compare) and "
      "convergence studies (converge). Every failure raises lucent.Error with lucent's one-line "
      "message.";
  m.attr("__version__") = kVersion;
  // NumPy imported now, with the import lock alone: pybind11 imported it on the first array,
  // inside a function-local static's initialisation, so that two threads making their first
  // arrays at once deadlocked (one in the guard holding the GIL, the other importing NumPy
  // waiting for the GIL; pybind11 PR 4877)
  py::module_::import("numpy");
  (void)py::detail::npy_api::get();

  static py::exception<Error> error(m, "Error", PyExc_RuntimeError);
  error.doc() =
      "A failure reported by lucent: one line naming the file and the place, or the call.";
  // PyErr_SetString (pybind11's translators) decodes the message as strict UTF-8: a message
  // naming a file whose name is not UTF-8 became an exception without a message
  py::register_exception_translator([](std::exception_ptr p) {
    const auto raise = [](PyObject* type, const std::exception& e) {
      PyErr_SetObject(type, message_text(e.what()).ptr());
    };
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      raise(error.ptr(), e);
    } catch (const py::value_error& e) {
      raise(PyExc_ValueError, e);
    } catch (const py::type_error& e) {
      raise(PyExc_TypeError, e);
    } catch (const py::index_error& e) {
      raise(PyExc_IndexError, e);
    }
  });
  py::object warning = py::reinterpret_steal<py::object>(
      PyErr_NewExceptionWithDoc("lucent.LucentWarning",
                                "A warning of scene loading or packing (skipped triangles, a "
                                "missing MTL file, ...).",
                                PyExc_UserWarning, nullptr));
  if (!warning) throw py::error_already_set();
  m.attr("LucentWarning") = warning;

  m.attr("MATERIAL_TYPES") = enum_name_tuple<MaterialType>();
  m.attr("LIGHT_TYPES") = enum_name_tuple<LightType>();
  m.attr("INTEGRATORS") = enum_name_tuple<IntegratorType>();
  m.attr("FILTER_TYPES") = enum_name_tuple<FilterType>();
  m.attr("SAMPLERS") = enum_name_tuple<SamplerType>();
  m.attr("TRANSFERS") = enum_name_tuple<Transfer>();
  m.attr("TONEMAPS") = enum_name_tuple<ToneMap>();
  m.attr("TEXTURE_WRAPS") = enum_name_tuple<TextureWrap>();

  py::class_<DeviceInfo>(m, "DeviceInfo", "An OpenCL device, as `lucent devices` lists it.")
      .def_readonly("index", &DeviceInfo::index)
      .def_readonly("platform", &DeviceInfo::platform)
      .def_readonly("name", &DeviceInfo::name)
      .def_readonly("type", &DeviceInfo::type)
      .def_readonly("vendor", &DeviceInfo::vendor)
      .def_readonly("driver_version", &DeviceInfo::driver_version)
      .def_readonly("opencl_c_version", &DeviceInfo::opencl_c_version)
      .def_readonly("compute_units", &DeviceInfo::compute_units)
      .def_readonly("global_memory", &DeviceInfo::global_memory)
      .def_readonly("fp64", &DeviceInfo::fp64)
      .def_readonly("int64_atomics", &DeviceInfo::int64_atomics)
      .def("__repr__", [](const DeviceInfo& d) {
        return "<lucent.DeviceInfo " + std::to_string(d.index) + ": " + d.name + " (" + d.type +
               ", " + d.platform + ")>";
      });
  m.def("list_devices", &list_devices, "Every OpenCL device of every platform.");
  m.def(
      "select_device",
      [](const TextArg& selector_arg, const TextArg& origin_arg) {
        const std::string selector = text_argument(selector_arg, "selector"),
                          origin = text_argument(origin_arg, "origin");
        refuse_nul(selector, "selector");
        refuse_nul(origin, "origin");
        return select_device(selector, origin);
      },
      py::arg("selector") = "", py::arg("origin") = "device",
      "The device a selector picks (an index or a case-insensitive substring of the name; \"\": "
      "the first GPU, else the first CPU device).");
  m.def("environment", &environment,
        "The `lucent` command's session defaults from LUCENT_DEVICE, LUCENT_KERNEL_DIR and "
        "LUCENT_CACHE_DIR, as keyword arguments for Renderer: Renderer(**lucent.environment()).");
  m.def("cache_dir", &resolved_cache_dir, py::arg("cache_dir") = "",
        "The kernel binary cache directory a session with this cache_dir uses (\"\": the "
        "default, as Renderer(); the lucent command's: lucent.environment()[\"cache_dir\"]), or "
        "\"\" when disabled (\"off\").");
  m.def(
      "clear_cache",
      [](const PathText& dir) {
        return cl_util::clear_program_cache(resolved_cache_dir(dir).bytes);
      },
      py::arg("cache_dir") = "",
      "Removes every cached kernel program from that directory (only the files the cache "
      "wrote); returns how many.");
  m.def(
      "cache_info",
      [](const PathText& dir) {
        const FileText resolved = resolved_cache_dir(dir);
        const cl_util::ProgramCacheUsage usage = cl_util::program_cache_usage(resolved.bytes);
        py::dict d;
        d["directory"] = file_text(resolved.bytes);
        d["programs"] = usage.programs;
        d["bytes"] = usage.bytes;
        d["limit_bytes"] = cl_util::program_cache_max_bytes();
        return d;
      },
      py::arg("cache_dir") = "",
      "What `lucent cache info` prints, as a dict: the directory (\"\" when disabled), the "
      "number of cached programs, their size in bytes, and the limit the cache keeps them under "
      "(LUCENT_CACHE_MAX_MB; 0: none).");

  bind_scene(m);
  bind_render(m);
  bind_image(m);
  reduce_in_every_protocol(m);
  py::module_::import("atexit").attr("register")(py::cpp_function(&end_calls_at_exit));
}

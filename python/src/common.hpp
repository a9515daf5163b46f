#pragma once
// Shared pieces of the Python module: enum names from the registries, vectors from sequences,
// arrays that own or view C++ vectors, images from arrays, and calling Python back from a render
// that released the GIL.
#include <pybind11/eval.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "lucent/image.hpp"
#include "lucent/parts.hpp"
#include "lucent/render.hpp"
#include "lucent/scene.hpp"

namespace py = pybind11;

namespace lucent::python {

/// Text that may come from files or the file system (file names, the names in OBJ and MTL
/// files, directories): bytes that need not be UTF-8. Python sees them as os.fsdecode does (a
/// byte that is not UTF-8 as a lone surrogate U+DC80..U+DCFF, errors="surrogateescape"), and a
/// str (or bytes) given back becomes the same bytes; a str with another lone surrogate is
/// refused (TypeError). A plain std::string raised UnicodeDecodeError on reading such text.
struct FileText {
  std::string bytes;
};

/// The bytes of the str `v` as FileText takes them (UTF-8, surrogateescape: a file name from
/// os.listdir), or false when it has none (another lone surrogate, "\ud800").
inline bool file_bytes(py::handle v, std::string& out) {
  py::object bytes = py::reinterpret_steal<py::object>(
      PyUnicode_AsEncodedString(v.ptr(), "utf-8", "surrogateescape"));
  if (!bytes) {
    PyErr_Clear();
    return false;
  }
  out.assign(PyBytes_AS_STRING(bytes.ptr()),
             static_cast<std::size_t>(PyBytes_GET_SIZE(bytes.ptr())));
  return true;
}

}  // namespace lucent::python

namespace pybind11::detail {
template <>
struct type_caster<lucent::python::FileText> {
  PYBIND11_TYPE_CASTER(lucent::python::FileText, const_name("str"));
  bool load(handle src, bool) {
    if (PyBytes_Check(src.ptr())) {
      value.bytes.assign(PyBytes_AS_STRING(src.ptr()),
                         static_cast<std::size_t>(PyBytes_GET_SIZE(src.ptr())));
      return true;
    }
    return PyUnicode_Check(src.ptr()) && lucent::python::file_bytes(src, value.bytes);
  }
  static handle cast(const lucent::python::FileText& text, return_value_policy, handle) {
    return PyUnicode_DecodeUTF8(text.bytes.data(), static_cast<Py_ssize_t>(text.bytes.size()),
                                "surrogateescape");
  }
};
}  // namespace pybind11::detail

namespace lucent::python {
/// A path (cache_dir, kernel_dir, Texture.path, Scene.path, ShapeEntry.file and .libraries):
/// FileText, or an os.PathLike as os.fspath gives it (Renderer(cache_dir=Path(...)) was
/// pybind's "incompatible function arguments", where every file path argument took one). Names
/// that are not paths (a material's) stay FileText.
struct PathText : FileText {};
}  // namespace lucent::python

namespace pybind11::detail {
template <>
struct type_caster<lucent::python::PathText> {
  PYBIND11_TYPE_CASTER(lucent::python::PathText, const_name("os.PathLike"));
  bool load(handle src, bool convert) {
    object text = reinterpret_borrow<object>(src);
    if (!PyBytes_Check(src.ptr()) && !PyUnicode_Check(src.ptr()) &&
        PyObject_HasAttrString(src.ptr(), "__fspath__")) {
      text = reinterpret_steal<object>(PyOS_FSPath(src.ptr()));
      if (!text) {
        PyErr_Clear();
        return false;
      }
    }
    type_caster<lucent::python::FileText> file;
    if (!file.load(text, convert)) return false;
    value.bytes = std::move(static_cast<lucent::python::FileText&>(file).bytes);
    return true;
  }
  static handle cast(const lucent::python::PathText& text, return_value_policy p, handle h) {
    return type_caster<lucent::python::FileText>::cast(text, p, h);
  }
};
}  // namespace pybind11::detail

namespace lucent::python {
void refuse_nul(const std::string& text, const char* what);
}  // namespace lucent::python

namespace pybind11::detail {
/// A file path (write_image, read_image, load_scene, ...): a str, bytes or os.PathLike, as
/// pybind11's own caster takes them, but a NUL in it is ValueError "path: embedded null character
/// in ..." (pybind11's said "incompatible function arguments", naming neither, where cache_dir
/// and the device selector said the former).
template <>
struct type_caster<std::filesystem::path> {
  PYBIND11_TYPE_CASTER(std::filesystem::path, const_name("os.PathLike"));
  bool load(handle src, bool) {
    object text = reinterpret_steal<object>(PyOS_FSPath(src.ptr()));
    if (!text) {
      PyErr_Clear();
      return false;
    }
    std::string bytes;
    if (PyBytes_Check(text.ptr()))
      bytes.assign(PyBytes_AS_STRING(text.ptr()),
                   static_cast<std::size_t>(PyBytes_GET_SIZE(text.ptr())));
    else if (!lucent::python::file_bytes(text, bytes))
      return false;
    lucent::python::refuse_nul(bytes, "path");
    value = bytes;
    return true;
  }
  static handle cast(const std::filesystem::path& path, return_value_policy, handle) {
    const std::string& bytes = path.native();
    object text = reinterpret_steal<object>(PyUnicode_DecodeUTF8(
        bytes.data(), static_cast<Py_ssize_t>(bytes.size()), "surrogateescape"));
    if (!text) return nullptr;
    return module_::import("pathlib").attr("Path")(text).release();
  }
};
}  // namespace pybind11::detail

namespace lucent::python {

/// An integer argument as given: any Python object, for int_argument() to check. A C++ integer
/// parameter made pybind11 refuse an int beyond its type (2**63 for a long long) with a TypeError
/// "incompatible function arguments" that names neither the argument nor its range, and let each
/// binding check the rest its own way; the signature still says "int".
struct IntArg {
  py::object value;
};

}  // namespace lucent::python

namespace pybind11::detail {
template <>
struct type_caster<lucent::python::IntArg> {
  PYBIND11_TYPE_CASTER(lucent::python::IntArg, const_name("int"));
  bool load(handle src, bool) {
    value.value = reinterpret_borrow<object>(src);
    return true;
  }
  static handle cast(const lucent::python::IntArg& arg, return_value_policy, handle) {
    return arg.value.inc_ref();
  }
};
}  // namespace pybind11::detail

namespace lucent::python {

/// A text argument as given (a type's or a mode's name: "float", "zip", a device selector), for
/// text_argument() to check: a std::string parameter took bytes as their text, and None or a
/// number raised pybind11's "incompatible function arguments"; the signature still says "str".
struct TextArg {
  py::object value;
};

}  // namespace lucent::python

namespace pybind11::detail {
template <>
struct type_caster<lucent::python::TextArg> {
  PYBIND11_TYPE_CASTER(lucent::python::TextArg, const_name("str"));
  bool load(handle src, bool) {
    value.value = reinterpret_borrow<object>(src);
    return true;
  }
  static handle cast(const lucent::python::TextArg& arg, return_value_policy, handle) {
    return arg.value.inc_ref();
  }
};
}  // namespace pybind11::detail

namespace lucent::python {

/// A True/False argument as given, for flag_argument() to check: a bool parameter took anything
/// with a truth value (fast_math=0.5 turned fast math on, complete=None off), as the scene's bool
/// fields did before bool_property; the signature still says "bool".
struct FlagArg {
  py::object value;
};

}  // namespace lucent::python

namespace pybind11::detail {
template <>
struct type_caster<lucent::python::FlagArg> {
  PYBIND11_TYPE_CASTER(lucent::python::FlagArg, const_name("bool"));
  bool load(handle src, bool) {
    value.value = reinterpret_borrow<object>(src);
    return true;
  }
  static handle cast(const lucent::python::FlagArg& arg, return_value_policy, handle) {
    return arg.value.inc_ref();
  }
};
}  // namespace pybind11::detail

namespace lucent::python {

/// `v` as a bool: True, False or a NumPy bool, else TypeError "<what> must be True or False,
/// got 0.5".
inline bool flag_value(py::handle v, const std::string& what) {
  const std::string type = Py_TYPE(v.ptr())->tp_name;
  if (!py::isinstance<py::bool_>(v) && type != "numpy.bool_" && type != "numpy.bool")
    throw py::type_error(what + " must be True or False, got " + py::repr(v).cast<std::string>());
  return v.cast<bool>();
}
inline bool flag_argument(const FlagArg& a, const char* what) { return flag_value(a.value, what); }

/// `v` as text: a str, else TypeError "<what> must be a str, got bytes".
inline std::string enum_text(py::handle v, const char* what) {
  if (!py::isinstance<py::str>(v))
    throw py::type_error(std::string(what) + " must be a str, got " +
                         std::string(Py_TYPE(v.ptr())->tp_name));
  return v.cast<std::string>();
}
inline std::string text_argument(const TextArg& a, const char* what) {
  return enum_text(a.value, what);
}

/// `bytes` as a str (FileText).
inline py::str file_text(const std::string& bytes) {
  return py::reinterpret_steal<py::str>(py::cast(FileText{bytes}).release());
}

// ------------------------------------------------------------------------------------------
// Enums by name: the registries' scene-file names (kernels/shared/registry.h), so that Python
// code reads and writes `material.type = "mirror"` as a scene file would.
// ------------------------------------------------------------------------------------------

template <class E>
struct EnumNames {
  const char* what;  ///< "material type", for messages
  std::vector<std::pair<E, const char*>> entries;
};

template <class E>
const EnumNames<E>& enum_names();
template <>
const EnumNames<MaterialType>& enum_names<MaterialType>();
template <>
const EnumNames<LightType>& enum_names<LightType>();
template <>
const EnumNames<IntegratorType>& enum_names<IntegratorType>();
template <>
const EnumNames<FilterType>& enum_names<FilterType>();
template <>
const EnumNames<ShapeType>& enum_names<ShapeType>();
template <>
const EnumNames<SamplerType>& enum_names<SamplerType>();
template <>
const EnumNames<Transfer>& enum_names<Transfer>();
template <>
const EnumNames<ToneMap>& enum_names<ToneMap>();
template <>
const EnumNames<TextureWrap>& enum_names<TextureWrap>();
template <>
const EnumNames<Precision>& enum_names<Precision>();

/// The registry name of `value`.
template <class E>
const char* enum_name(E value) {
  for (const auto& [v, name] : enum_names<E>().entries)
    if (v == value) return name;
  return "?";
}

// ------------------------------------------------------------------------------------------
// Text in messages
// ------------------------------------------------------------------------------------------

/// `text` with each NUL written \x00: an exception's message is a C string (what()), and would
/// end at the first NUL.
std::string visible_nul(const std::string& text);

/// ValueError naming `what` when `text` holds a NUL: lucent takes it as a C string (a file name,
/// a device selector), which would end there.
void refuse_nul(const std::string& text, const char* what);

/// A message as a str: UTF-8, with each byte that is not (from a file name or a file's contents)
/// written \xNN, as errors="backslashreplace" does.
py::str message_text(const std::string& message);

/// The value named `name`; ValueError naming the valid names otherwise.
template <class E>
E parse_enum(const std::string& name) {
  const EnumNames<E>& t = enum_names<E>();
  std::string valid;
  for (const auto& [v, n] : t.entries) {
    if (name == n) return v;
    valid += (valid.empty() ? "" : ", ") + std::string(n);
  }
  throw py::value_error("unknown " + std::string(t.what) + " '" + visible_nul(name) +
                        "' (expected one of " + valid + ")");
}

/// The names, in registry order (module attributes such as lucent.MATERIAL_TYPES).
template <class E>
py::tuple enum_name_tuple() {
  py::list out;
  for (const auto& entry : enum_names<E>().entries) out.append(entry.second);
  return py::tuple(out);
}

// ------------------------------------------------------------------------------------------
// Vectors and arrays
// ------------------------------------------------------------------------------------------

/// A glm vector from a Vec3/Vec2 or a sequence of N numbers (tuple, list, NumPy array; not bytes),
/// with clear errors: ValueError for a wrong length or a str, TypeError for anything else.
template <class V>
V to_vec(py::handle o) {
  constexpr int N = V::length();
  if (py::isinstance<V>(o)) return o.cast<V>();
  // bytes are a sequence of integers: Vec3(b"abc") was (97, 98, 99)
  // (a memoryview of bytes too, ctypes' "<B" included; one of other numbers is numbers, and a
  // released one is refused here rather than by the error of its format)
  bool bytes_like = py::isinstance<py::bytes>(o) || PyByteArray_Check(o.ptr());
  if (PyMemoryView_Check(o.ptr())) {
    try {
      std::string format = py::str(o.attr("format"));
      if (!format.empty() && std::string("@=<>!").find(format[0]) != std::string::npos)
        format.erase(0, 1);
      bytes_like = format == "B" || format == "b" || format == "c";
    } catch (py::error_already_set&) {
      bytes_like = true;
    }
  }
  if (!py::isinstance<py::sequence>(o) || py::isinstance<py::str>(o) || bytes_like) {
    if (py::isinstance<py::str>(o))
      throw py::value_error("expected a sequence of " + std::to_string(N) + " numbers, got " +
                            py::repr(o).cast<std::string>());
    throw py::type_error("expected a sequence of " + std::to_string(N) + " numbers, got " +
                         py::repr(o).cast<std::string>());
  }
  py::sequence s = py::reinterpret_borrow<py::sequence>(o);
  if (s.size() != static_cast<std::size_t>(N))
    throw py::value_error("expected a sequence of " + std::to_string(N) + " numbers, got " +
                          py::repr(o).cast<std::string>());
  V v;
  for (int i = 0; i < N; ++i) {
    py::object e = s[static_cast<std::size_t>(i)];
    double d = PyFloat_AsDouble(e.ptr());
    if (d == -1.0 && PyErr_Occurred()) {
      PyErr_Clear();
      throw py::type_error("expected a sequence of " + std::to_string(N) + " numbers, got " +
                           py::repr(o).cast<std::string>());
    }
    v[i] = d;
  }
  return v;
}

/// An integer argument's value (int_value): its sign and magnitude, `fits` false beyond 64 bits
/// (either sign); `index` is the int itself (operator.index of the argument), for messages.
struct IntValue {
  bool fits = false, negative = false;
  std::uint64_t magnitude = 0;
  py::object index;
};

/// `arg` as an int (what operator.index takes: an int, a NumPy integer; a bool only when
/// `allow_bool`): TypeError "<what> must be an integer, got <repr>" otherwise. The one
/// conversion of int_argument, of the scene structs' integer fields and of triangle indices.
IntValue int_value(const IntArg& arg, const std::string& what, bool allow_bool);

/// repr() of an int for messages ("an integer too long to show" past
/// sys.get_int_max_str_digits()).
std::string int_repr(py::handle value);

/// `arg` as an integer in [lo, hi], the one check of the integer arguments of the session's
/// methods (and render_reference's): TypeError naming `what` unless it is an integer (an int, a
/// NumPy integer: what operator.index takes, not a float or a str); ValueError
/// "<what> must be an integer in [lo, hi]<note>, got <value>" for any integer outside, negative
/// or beyond 64 bits alike (never clamped).
std::uint64_t int_argument(const IntArg& arg, const char* what, std::uint64_t lo, std::uint64_t hi,
                           const char* note = "");

/// A sample range given as a tuple (begin, end), [begin, end) with begin < end <= `top`:
/// TypeError "<what> must be a tuple (begin, end), got ..." for anything else than a 2-tuple,
/// ValueError naming "<what> begin" or "<what> end" (int_argument) or the order.
SampleRange range_argument(py::handle arg, const char* what, std::uint64_t top,
                           const char* note = "");

/// `n` as messages write a range's bound: 2**k or 2**k - 1 from 2**16 on, else in decimal.
std::string range_bound(std::uint64_t n);

/// A NumPy array over `data` (C order, `shape`), kept valid by `owner` (the Python object that
/// holds the vector): no copy.
template <class T>
py::array_t<T> view(const std::vector<T>& data, std::vector<py::ssize_t> shape, py::handle owner) {
  return py::array_t<T>(std::move(shape), data.data(), owner);
}

/// view(), read-only: for values the object checked when it was made (a RenderResult's variance
/// and counts), which a write through a view would bypass.
template <class T>
py::array_t<T> readonly_view(const std::vector<T>& data, std::vector<py::ssize_t> shape,
                             py::handle owner) {
  py::array_t<T> a = view(data, std::move(shape), owner);
  a.attr("flags").attr("writeable") = false;
  return a;
}

/// `object` as an array of type A (py::array, or py::array_t with its flags: converted as NumPy
/// converts), or a null array when NumPy cannot convert it (the caller says what it expected).
/// A MemoryError (a copy too large for memory) is raised: A::ensure cleared it, and the caller
/// reported a wrong shape or type.
template <class A>
A array_or_null(py::handle object) {
  try {
    return A(py::reinterpret_borrow<py::object>(object));
  } catch (py::error_already_set& e) {
    if (e.matches(PyExc_MemoryError)) throw;
    return py::reinterpret_steal<A>(py::handle());
  }
}

/// A C-contiguous array of T converted from `object` (array_or_null).
template <class T>
using CArray = py::array_t<T, py::array::c_style | py::array::forcecast>;

/// An (H, W, 3) float32 array that owns the image's pixels (moved into a capsule: no copy).
py::array_t<float> image_array(Image&& image);

/// A read-only NumPy array holding a copy of `n` rows of `cols` doubles starting at `first`.
py::array_t<double> copy_rows(const double* first, std::size_t n, py::ssize_t cols);

/// An (H, W, 3) float array (any real dtype, converted) as an Image; ValueError naming `what`
/// when the shape is not (H, W, 3) with H, W >= 1.
Image image_from_array(py::handle array, const char* what);
/// Raises TypeError unless `object` converts to an array of booleans, integers or floats (NumPy
/// would otherwise convert strings such as "3e400" to numbers). With `bytes_per_value` (the
/// conversion's copy and the scene's own, per value): MemoryError naming `what` when the values
/// would take more than lucent allows itself (render_detail::host_memory_allowed): a broadcast
/// view of 12 bytes standing for 10^9 positions was copied whole, and the kernel killed the
/// process.
void require_numbers(py::handle object, const std::string& what, std::uint64_t bytes_per_value = 0);

/// The image of a RenderResult or of an (H, W, 3) array.
RenderResult render_result_from(py::handle object, const char* what);

// ------------------------------------------------------------------------------------------
// Calling Python from C++ code that runs without the GIL
// ------------------------------------------------------------------------------------------

/// At interpreter exit, CPython ends a thread other than the main one that asks for the GIL (a
/// daemon thread returning from a call that released it, a thread of the library calling Python
/// back) with pthread_exit: an unwinding of the thread's C++ frames that aborts the process
/// ("terminate called without an active exception") at the first destructor, noexcept function
/// or joinable std::thread it meets. These take the GIL as pybind11's gil_scoped_release and
/// gil_scoped_acquire do, but park such a thread instead: it sleeps until the process exits (as
/// Python 3.14 does with such threads).

/// Takes the GIL back with `state` (PyEval_RestoreThread), or parks this thread at interpreter
/// exit after setting `*cancel` (when given: the work the thread waits for then stops).
void restore_gil(PyThreadState* state, std::atomic<bool>* cancel = nullptr) noexcept;

/// Releases the GIL while it lives (py::gil_scoped_release), then takes it back with
/// restore_gil.
class ReleaseGil {
 public:
  ReleaseGil();
  ~ReleaseGil() { restore_gil(state_); }
  ReleaseGil(const ReleaseGil&) = delete;
  ReleaseGil& operator=(const ReleaseGil&) = delete;
  PyThreadState* state() const { return state_; }

 private:
  PyThreadState* state_;
};

/// Holds the GIL while it lives, on any thread (py::gil_scoped_acquire); parks this thread at
/// interpreter exit.
class AcquireGil {
 public:
  AcquireGil();
  AcquireGil(const AcquireGil&) = delete;
  AcquireGil& operator=(const AcquireGil&) = delete;

 private:
  std::optional<py::gil_scoped_acquire> gil_;
};

/// TypeError unless `f` is None or callable.
inline void check_callable(const py::object& f, const char* what) {
  if (!f.is_none() && !PyCallable_Check(f.ptr()))
    throw py::type_error(std::string(what) + " must be callable or None, got " +
                         py::repr(f).cast<std::string>());
}

/// A Python object that may be copied and destroyed without the GIL (the std::function objects
/// of lucent's options are copied by the library, with the GIL released).
class SharedObject {
 public:
  SharedObject() = default;
  explicit SharedObject(py::object o);
  py::object get() const { return object_ ? *object_ : py::none(); }
  explicit operator bool() const { return object_ && !object_->is_none(); }
  /// For a holder's tp_traverse (the GIL held): the object, or null.
  PyObject* ptr() const { return object_ ? object_->ptr() : nullptr; }
  /// For a holder's tp_clear (the GIL held): None from now on, in every copy.
  void clear() {
    if (object_) *object_ = py::none();
  }

 private:
  std::shared_ptr<py::object> object_;
};

/// The first exception a callback raised while lucent ran without the GIL; rethrown by
/// rethrow() once lucent returned (it never crosses the library).
class CallbackErrors {
 public:
  bool failed() const { return static_cast<bool>(error_); }
  /// Runs `f` (with the GIL held by the caller); keeps its exception. Returns false when `f`
  /// threw or an earlier call did.
  template <class F>
  bool run(F&& f) {
    if (error_) return false;
    try {
      f();
      return true;
    } catch (...) {
      error_ = std::current_exception();
      return false;
    }
  }
  void rethrow() {
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
  }
  /// Forgets the exception kept (the call failed on its own error, which is raised instead).
  void clear() { error_ = nullptr; }

 private:
  std::exception_ptr error_;
};

class CallerQueue;

/// A warning sink that calls `callback(message)`, or warnings.warn(message, LucentWarning)
/// when `callback` is None. Exceptions go to `errors`. With `queue` (the address where a call of
/// run_interruptible stores its queue), on the thread that made that call from any thread of
/// the call (a device thread of a session with several devices too), else from its worker
/// (t_caller_queue); with `stop`, a KeyboardInterrupt raised in it (Ctrl-C on the calling
/// thread while it runs) sets `*stop`, as an exception of a progress callback stops a render.
WarningSink python_warning_sink(SharedObject callback, std::shared_ptr<CallbackErrors> errors,
                                CallerQueue* const* queue = nullptr,
                                std::atomic<bool>* stop = nullptr);

/// A callback of a session's call in progress (the progress callback of a render, a warning
/// callback, converge's on_point), in the chain of those running on this thread, innermost
/// first: a call on the same session from one of them, or from anything they call, would
/// re-enter the call in progress. The session refuses it saying so, not that another thread
/// uses the session.
struct CallbackFrame {
  const void* session;
  const char* callback;  ///< "progress callback", for messages
  const CallbackFrame* outer;
};

/// The chain of this thread (run_interruptible's worker inherits its caller's: the caller waits
/// for it).
inline thread_local const CallbackFrame* t_callbacks = nullptr;

/// Adds a callback of `session`'s call to this thread's chain while it lives.
class InCallback {
 public:
  InCallback(const void* session, const char* callback) : frame_{session, callback, t_callbacks} {
    t_callbacks = &frame_;
  }
  ~InCallback() { t_callbacks = frame_.outer; }
  InCallback(const InCallback&) = delete;
  InCallback& operator=(const InCallback&) = delete;

 private:
  CallbackFrame frame_;
};

/// Gives this thread, while it lives, the chain of the thread that made a call (`chain`,
/// captured when the call began): a callback of the call that runs on a thread of the library
/// (a session with several devices runs its passes on threads of its own, which start with an
/// empty chain) is then in the chain of the call that it belongs to. Does nothing when `chain`
/// is nullptr (the call was made outside every callback: this thread's chain stays).
class WithChain {
 public:
  explicit WithChain(const CallbackFrame* chain) : saved_(t_callbacks) {
    if (chain) t_callbacks = chain;
  }
  ~WithChain() { t_callbacks = saved_; }
  WithChain(const WithChain&) = delete;
  WithChain& operator=(const WithChain&) = delete;

 private:
  const CallbackFrame* saved_;
};

/// The innermost callback of `session`'s call in this thread's chain, or nullptr.
inline const CallbackFrame* callback_of(const void* session) {
  for (const CallbackFrame* f = t_callbacks; f; f = f->outer)
    if (f->session == session) return f;
  return nullptr;
}

/// The callbacks of a call of run_interruptible, waiting to run on the thread that made the call
/// (defined in module.cpp).
class CallerQueue;

/// The queue of the call of run_interruptible that this thread (its worker) works for, or
/// nullptr.
inline thread_local CallerQueue* t_caller_queue = nullptr;

/// Runs `f` with the GIL held, and returns when it has run: on the thread that made the call of
/// run_interruptible whose queue is `queue`, or on this thread when `queue` is nullptr. A
/// callback then runs on the thread that called lucent, as Python code expects: Ctrl-C
/// interrupts it (a second Ctrl-C was lost while a progress callback blocked: it ran on the
/// worker, where no signal handler runs), and it sees that thread's contextvars, threading.local
/// values and current_thread() (it saw a thread of its own). An exception of `f` is rethrown
/// here.
void run_with_gil(CallerQueue* queue, const std::function<void()>& f);

/// Runs `work` on a worker thread with the GIL released while this thread checks Python's
/// signals every 50 ms and runs the work's callbacks (run_with_gil with t_caller_queue, which
/// the worker has): on KeyboardInterrupt (or any exception of a signal handler) `cancel` is
/// set, the work is awaited (it stops early on the flag) and the exception is raised. The worker
/// has this thread's chain of callbacks. Interpreter exit sets `cancel` too, and waits a while
/// for the call to end (a daemon thread's render would otherwise run on while the process tears
/// down the libraries it uses).
void run_interruptible(const std::function<void()>& work, std::atomic<bool>& cancel);

/// Module parts.
void bind_scene(py::module_& m);
void bind_render(py::module_& m);
void bind_image(py::module_& m);

}  // namespace lucent::python

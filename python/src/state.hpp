#pragma once
// Reading pickled states back (py::pickle's __setstate__): a state is plain Python data, a dict of
// a value's fields by their attribute names, and the reader is strict: a missing, unknown or
// ill-typed key raises ValueError naming the class and the key ("cannot unpickle lucent.Scene:
// /materials/1/type: unknown material type 'gold' ..."), never a crash or a value half read.
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "common.hpp"

namespace lucent::python {

/// The path of `key` in the value at `where`, for messages: "lucent.Scene" and "camera" give
/// "lucent.Scene: /camera", "lucent.Scene: /materials" and 0 "lucent.Scene: /materials/0".
template <class K>
inline std::string state_path(const std::string& where, const K& key) {
  std::ostringstream s;
  s << where << (where.find(':') == std::string::npos ? ": /" : "/") << key;
  return s.str();
}

/// A list of states (`where`: its path, for messages), each read by `from_state(state, where)`.
template <class T, class F>
std::vector<T> read_list(py::handle state, const std::string& where, F&& from_state) {
  if (!py::isinstance<py::list>(state))
    throw py::value_error("cannot unpickle " + where + ": expected a list, got " +
                          py::type::handle_of(state).attr("__name__").cast<std::string>());
  std::vector<T> out;
  for (py::handle item : state) out.push_back(from_state(item, state_path(where, out.size())));
  return out;
}

/// The UTF-8 text of the str `v`, or false when it has none (a lone surrogate, "\ud800").
inline bool utf8_text(py::handle v, std::string& out) {
  Py_ssize_t n = 0;
  const char* p = PyUnicode_AsUTF8AndSize(v.ptr(), &n);
  if (!p) {
    PyErr_Clear();
    return false;
  }
  out.assign(p, static_cast<std::size_t>(n));
  return true;
}

/// A state being read; `where` names the class and the path of the value ("lucent.Scene:
/// /materials/0"), for messages.
class StateReader {
 public:
  StateReader(py::handle state, std::string where) : where_(std::move(where)) {
    if (!py::isinstance<py::dict>(state)) fail("", "expected a dict, got " + type_name(state));
    dict_ = py::reinterpret_borrow<py::dict>(state);
  }

  /// The value of `key`; ValueError when it is missing.
  py::object get(const char* key) {
    py::str k(key);
    if (!dict_.contains(k)) fail(key, "missing");
    read_.insert(key);
    return dict_[k];
  }

  double number(const char* key) {
    py::object v = get(key);
    if (py::isinstance<py::bool_>(v) ||
        !(py::isinstance<py::float_>(v) || py::isinstance<py::int_>(v)))
      fail(key, "expected a number, got " + type_name(v));
    const double d = PyFloat_AsDouble(v.ptr());
    if (d == -1.0 && PyErr_Occurred()) {
      PyErr_Clear();  // an integer beyond double's range
      fail(key, "number out of range: " + py::repr(v).cast<std::string>());
    }
    return d;
  }

  template <class I>
  I integer(const char* key) {
    return as_integer<I>(get(key), key);
  }

  bool boolean(const char* key) {
    py::object v = get(key);
    if (!py::isinstance<py::bool_>(v)) fail(key, "expected a bool, got " + type_name(v));
    return v.cast<bool>();
  }

  std::string text(const char* key) {
    py::object v = get(key);
    if (!py::isinstance<py::str>(v)) fail(key, "expected a str, got " + type_name(v));
    std::string text;
    if (!file_bytes(v, text)) fail(key, "a str that is not valid Unicode (a lone surrogate)");
    return text;
  }

  template <class V>
  V vec(const char* key) {
    py::object v = get(key);
    try {
      return to_vec<V>(v);
    } catch (const py::builtin_exception& e) {
      fail(key, e.what());
    }
  }

  /// An enum by its registry name.
  template <class E>
  E name(const char* key) {
    std::string v = text(key);
    try {
      return parse_enum<E>(v);
    } catch (const py::builtin_exception& e) {
      fail(key, e.what());
    }
  }

  /// int[3] (triangle indices) from a tuple of 3 integers.
  void triple(const char* key, int (&out)[3]) {
    py::object v = get(key);
    if (!py::isinstance<py::tuple>(v) || py::len(v) != 3)
      fail(key, "expected a tuple of 3 integers, got " + py::repr(v).cast<std::string>());
    for (int i = 0; i < 3; ++i) out[i] = as_integer<int>(v[py::int_(i)], key);
  }

  /// A nested value, read by `from_state(state, where)`.
  template <class F>
  auto nested(const char* key, F&& from_state) {
    return from_state(get(key), path(key));
  }

  /// A list of values, each read by `from_state(state, where)`.
  template <class T, class F>
  std::vector<T> list(const char* key, F&& from_state) {
    return read_list<T>(get(key), path(key), from_state);
  }

  /// A NumPy array of T's kind and size (in any byte order) of `shape` (-1: any size),
  /// returned C-contiguous in the native byte order.
  template <class T>
  py::array_t<T> array(const char* key, const std::vector<py::ssize_t>& shape) {
    py::object v = get(key);
    const py::dtype want = py::dtype::of<T>();
    auto shape_text = [](const std::vector<py::ssize_t>& shape) {
      std::string t = "(";
      for (std::size_t i = 0; i < shape.size(); ++i)
        t += (i ? ", " : "") + (shape[i] < 0 ? std::string("N") : std::to_string(shape[i]));
      return t + (shape.size() == 1 ? ",)" : ")");
    };
    const std::string expected =
        "expected a " + shape_text(shape) + " array of " + want.attr("name").cast<std::string>();
    if (!py::isinstance<py::array>(v)) fail(key, expected + ", got " + type_name(v));
    py::array a = py::reinterpret_borrow<py::array>(v);
    const std::vector<py::ssize_t> got(a.shape(), a.shape() + a.ndim());
    bool ok = a.dtype().kind() == want.kind() && a.dtype().itemsize() == want.itemsize() &&
              got.size() == shape.size();
    for (std::size_t i = 0; ok && i < shape.size(); ++i) ok = shape[i] < 0 || got[i] == shape[i];
    if (!ok)
      fail(key, expected + ", got a " + shape_text(got) + " array of " +
                    a.dtype().attr("name").cast<std::string>());
    return CArray<T>(a);  // raises MemoryError (ensure() gave a null array)
  }

  /// Raises for a key that no getter read (a state of another version of the module).
  void finish() const {
    for (auto item : dict_) {
      std::string key;
      if (!py::isinstance<py::str>(item.first) || !utf8_text(item.first, key) || !read_.count(key))
        fail("", "unknown key " + py::repr(item.first).cast<std::string>());
    }
  }

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw py::value_error("cannot unpickle " + path(key) + ": " + what);
  }

  /// The path of `key`, for messages.
  std::string path(const std::string& key) const {
    return key.empty() ? where_ : state_path(where_, key);
  }

 private:
  static std::string type_name(py::handle v) {
    return py::type::handle_of(v).attr("__name__").cast<std::string>();
  }

  template <class I>
  I as_integer(py::handle v, const char* key) const {
    if (py::isinstance<py::bool_>(v) || !py::isinstance<py::int_>(v))
      fail(key, "expected an integer, got " + type_name(v));
    int overflow = 0;
    const long long x = PyLong_AsLongLongAndOverflow(v.ptr(), &overflow);
    if (x == -1 && PyErr_Occurred()) throw py::error_already_set();
    if (overflow > 0 && !std::numeric_limits<I>::is_signed) {  // 2^63 .. 2^64 - 1: unsigned
      const unsigned long long u = PyLong_AsUnsignedLongLong(v.ptr());
      if (PyErr_Occurred())
        PyErr_Clear();  // at least 2^64
      else if (u <= static_cast<unsigned long long>(std::numeric_limits<I>::max()))
        return static_cast<I>(u);
    }
    const bool in_range =
        overflow == 0 &&
        (x < 0 ? std::numeric_limits<I>::is_signed &&
                     x >= static_cast<long long>(std::numeric_limits<I>::min())
               : static_cast<unsigned long long>(x) <=
                     static_cast<unsigned long long>(std::numeric_limits<I>::max()));
    if (!in_range) fail(key, "integer out of range: " + py::repr(v).cast<std::string>());
    return static_cast<I>(x);
  }

  std::string where_;
  py::dict dict_;
  std::set<std::string> read_;
};

}  // namespace lucent::python

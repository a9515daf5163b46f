// The scene's lists (MaterialList, SphereList, TriangleList, LightList, TextureList, ShapeList):
// Python sequences over a Scene's std::vector members whose elements are references into the
// vector, so that `scene.materials[0].albedo = (1, 0, 0)` edits the scene.
//
// A change of a list's length moves its elements in memory (the vector reallocates, inserts or
// erases). With pybind11's bind_vector every Python reference to an element (`w =
// scene.materials[0]`, an iterator, `a = w.albedo`) then pointed at freed memory: edits were lost,
// reads returned garbage, a write could corrupt the heap, and `del lst[::-1]` (pybind11 2.10's
// slice deletion with a negative step) erased out of bounds. Here every change moves those
// references with their elements, as a Python list's elements are objects of their own:
//  - an element that stays in the list: its references follow it to its new place;
//  - an element that leaves it (pop, del, clear, a replaced element, a list assigned over it):
//    its references move to a copy that they keep alive, as an object removed from a Python list
//    lives on while it is referenced.
// pybind11 keeps every Python object that wraps a C++ value in its table of registered instances,
// keyed by the value's address; that is how the references are found and moved (pybind11 2.x
// internals: registered_instances, value_and_holder, register_instance, deregister_instance,
// add_patient).
#pragma once

#include <pybind11/pybind11.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace lucent::python {

namespace py = pybind11;

namespace list_detail {

/// A Python object that wraps a value inside element `index` of a list, `offset` bytes into it
/// (0: the element itself; more: a member such as a material's albedo).
struct Reference {
  py::detail::instance* instance;
  const py::detail::type_info* type;
  void* value;
  std::size_t index;
  std::size_t offset;
};

template <class T>
std::vector<Reference> references(std::vector<T>& v) {
  std::vector<Reference> out;
  if (v.empty()) return out;
  const auto begin = reinterpret_cast<std::uintptr_t>(v.data());
  const auto end = begin + v.size() * sizeof(T);
  for (const auto& entry : py::detail::get_internals().registered_instances) {
    const auto at = reinterpret_cast<std::uintptr_t>(entry.first);
    if (at < begin || at >= end) continue;
    for (const py::detail::value_and_holder& vh : py::detail::values_and_holders(entry.second))
      if (vh.value_ptr() == entry.first)
        out.push_back({entry.second, vh.type, vh.value_ptr(), (at - begin) / sizeof(T),
                       (at - begin) % sizeof(T)});
  }
  return out;
}

/// Runs `op` on `v` (which must leave `v` as it was when it throws), then moves the references to
/// v's elements: `new_index(i)` is where element i is after the change, or -1 if it left the list.
template <class T, class Op, class NewIndex>
void change(std::vector<T>& v, Op&& op, NewIndex&& new_index) {
  std::vector<Reference> refs = references(v);
  if (refs.empty()) {
    op(v);
    return;
  }
  std::map<std::size_t, py::capsule> left;  // a copy of each referenced element that leaves
  for (const Reference& r : refs)
    if (new_index(r.index) < 0 && !left.count(r.index))
      left.emplace(r.index,
                   py::capsule(new T(v[r.index]), [](void* p) { delete static_cast<T*>(p); }));
  for (const Reference& r : refs) py::detail::deregister_instance(r.instance, r.value, r.type);
  auto place = [&](const Reference& r, void* value) {
    r.instance->get_value_and_holder(r.type).value_ptr() = value;
    py::detail::register_instance(r.instance, value, r.type);
  };
  try {
    op(v);
  } catch (...) {
    for (const Reference& r : refs) place(r, r.value);
    throw;
  }
  for (const Reference& r : refs) {
    const std::ptrdiff_t k = new_index(r.index);
    if (k >= 0) {
      place(r, reinterpret_cast<char*>(v.data() + k) + r.offset);
    } else {
      const py::capsule& copy = left.at(r.index);
      place(r, static_cast<char*>(copy.get_pointer()) + r.offset);
      py::detail::add_patient(reinterpret_cast<PyObject*>(r.instance), copy.ptr());
    }
  }
}

/// Index i of a sequence of n, negative counting from the end; IndexError outside.
inline std::size_t wrap_index(py::ssize_t i, std::size_t n, const char* what) {
  if (i < 0) i += static_cast<py::ssize_t>(n);
  if (i < 0 || static_cast<std::size_t>(i) >= n) throw py::index_error(what);
  return static_cast<std::size_t>(i);
}

/// An index as a Python list reads it (operator.index), before the list's length is read (its
/// __index__ may change the list): IndexError for an integer past Py_ssize_t and TypeError
/// naming the type of anything else, "<indices_must>, not float" (pybind's "incompatible
/// function arguments" TypeError said neither).
/// `overflow`: the exception of an integer past Py_ssize_t (a subscript's IndexError; pop and
/// insert raise OverflowError, as a list's do).
inline py::ssize_t index_of(py::handle i, const char* indices_must,
                            PyObject* overflow = PyExc_IndexError) {
  if (!PyIndex_Check(i.ptr()))
    throw py::type_error(std::string(indices_must) + ", not " + Py_TYPE(i.ptr())->tp_name);
  const Py_ssize_t n = PyNumber_AsSsize_t(i.ptr(), overflow);
  if (n == -1 && PyErr_Occurred()) throw py::error_already_set();
  return n;
}
inline constexpr const char* kListIndices = "list indices must be integers or slices";
/// (a list's insert and pop say "'float' object cannot be interpreted as an integer")
inline constexpr const char* kIndexMust = "the index must be an integer";

/// The Python name of the bound type T ("Material"), for messages.
template <class T>
std::string bound_name() {
  return py::str(py::type::of<T>().attr("__name__"));
}

/// `value` as T: TypeError "<what>: expected a Material, not float".
template <class T>
T value_of(py::handle value, const char* what) {
  try {
    return value.cast<T>();
  } catch (const py::cast_error&) {
    throw py::type_error(std::string(what) + ": expected a " + list_detail::bound_name<T>() +
                         ", not " + Py_TYPE(value.ptr())->tp_name);
  }
}

/// The items of `items` as T, read first (`items` may be the list itself): TypeError naming the
/// first that is no T (pybind's cast said RuntimeError "Unable to cast Python instance to C++
/// type", with no word of which item).
template <class T>
std::vector<T> values_of(const py::iterable& items, const char* what) {
  std::vector<T> values;
  for (py::handle h : items) {
    try {
      values.push_back(h.cast<T>());
    } catch (const py::cast_error&) {
      throw py::type_error(std::string(what) + ": item " + std::to_string(values.size()) +
                           ": expected a " + list_detail::bound_name<T>() + ", not " +
                           Py_TYPE(h.ptr())->tp_name);
    }
  }
  return values;
}

/// What a slice selects in a list: its first index and step, and the indices in its order.
struct Selection {
  py::ssize_t start = 0, step = 1;
  std::vector<std::size_t> indices;
};

/// The elements slice `s` selects in `v`. Its bounds are converted first (__index__, which can run
/// Python code that changes v), then fitted to v's length at that point, as a Python list does
/// (PySlice_Unpack, then PySlice_AdjustIndices): a length read before the conversion gave indices
/// past the end of a list that the conversion shortened.
template <class T>
Selection slice_indices(const py::slice& s, const std::vector<T>& v) {
  Selection out;
  py::ssize_t stop = 0;
  if (PySlice_Unpack(s.ptr(), &out.start, &stop, &out.step) < 0) throw py::error_already_set();
  const py::ssize_t length =
      PySlice_AdjustIndices(static_cast<py::ssize_t>(v.size()), &out.start, &stop, out.step);
  out.indices.resize(static_cast<std::size_t>(length));
  for (py::ssize_t k = 0; k < length; ++k)
    out.indices[k] = static_cast<std::size_t>(out.start + k * out.step);
  return out;
}

/// v without the elements whose flag is set; new_index for change().
template <class T>
void erase_flagged(std::vector<T>& v, const std::vector<char>& gone) {
  std::vector<T> kept;
  kept.reserve(v.size());  // may throw, before v changes; the moves below do not
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!gone[i]) kept.push_back(std::move(v[i]));
  v.swap(kept);
}

inline std::vector<std::ptrdiff_t> index_after_erase(const std::vector<char>& gone) {
  std::vector<std::ptrdiff_t> to(gone.size());
  std::ptrdiff_t next = 0;
  for (std::size_t i = 0; i < gone.size(); ++i) to[i] = gone[i] ? -1 : next++;
  return to;
}

/// Erases the flagged elements, moving the references to all of them (change()).
template <class T>
void erase(std::vector<T>& v, const std::vector<char>& gone) {
  const std::vector<std::ptrdiff_t> to = index_after_erase(gone);
  change(
      v, [&](std::vector<T>& x) { erase_flagged(x, gone); }, [&](std::size_t j) { return to[j]; });
}

template <class T>
struct Iterator {
  py::object list;
  std::size_t next = 0;
};

}  // namespace list_detail

/// Assigns `value` to the list member `v` (Scene.materials = ...): every element of the old
/// list leaves it.
template <class T>
void assign_list(std::vector<T>& v, const std::vector<T>& value) {
  std::vector<T> copy = value;  // `value` may be v itself
  list_detail::change(
      v, [&](std::vector<T>& x) { x.swap(copy); }, [](std::size_t) { return std::ptrdiff_t(-1); });
}

/// Binds std::vector<T> as the Python sequence `name`: len, indexing and slices (reading a slice
/// gives a new list, not attached to the scene), assignment and deletion of items and slices,
/// append, extend, insert, pop, clear and iteration, with a Python list's semantics. A Python list
/// or tuple of elements converts to it (`scene.materials = [m1, m2]`).
template <class T>
py::class_<std::vector<T>> bind_scene_list(py::module_& m, const char* name) {
  using V = std::vector<T>;
  using list_detail::change;
  using list_detail::Iterator;
  const auto same = [](std::size_t i) { return static_cast<std::ptrdiff_t>(i); };
  py::class_<V> c(m, name);
  c.def(py::init<>())
      .def(py::init<const V&>())
      .def(py::init([label = std::string(name) + "()"](const py::iterable& items) {
        // (an item that is no T was pybind's RuntimeError "Unable to cast Python instance")
        return list_detail::values_of<T>(items, label.c_str());
      }))
      .def("__len__", &V::size)
      .def("__bool__", [](const V& v) { return !v.empty(); })
      // `<lucent.MaterialList of 3: [<lucent.Material 'white' diffuse>, ...]>`, the first 8
      // items (a mesh's TriangleList holds millions)
      .def("__repr__",
           [name = std::string(name)](const V& v) {
             constexpr std::size_t kShown = 8;
             std::string s = "<lucent." + name + " of " + std::to_string(v.size()) + ": [";
             for (std::size_t i = 0; i < v.size() && i < kShown; ++i)
               s += (i ? ", " : "") + py::repr(py::cast(v[i])).template cast<std::string>();
             if (v.size() > kShown) s += ", ... " + std::to_string(v.size() - kShown) + " more";
             return s + "]>";
           })
      // (the slices' overloads first: the others take any index, as a Python list does)
      .def("__getitem__",
           [](const V& v, const py::slice& s) {
             V out;
             for (std::size_t i : list_detail::slice_indices(s, v).indices) out.push_back(v[i]);
             return out;
           })
      .def(
          "__getitem__",
          [](V& v, py::handle i) -> T& {
            const py::ssize_t n = list_detail::index_of(i, list_detail::kListIndices);
            return v[list_detail::wrap_index(n, v.size(), "list index out of range")];
          },
          py::return_value_policy::reference_internal)
      .def(
          "__setitem__",
          [](V& v, const py::slice& s, const py::iterable& items) {
            V values = list_detail::values_of<T>(items, "slice assignment");
            const list_detail::Selection sel = list_detail::slice_indices(s, v);
            const std::vector<std::size_t>& at = sel.indices;
            if (sel.step != 1) {  // an extended slice: one value per selected element
              if (values.size() != at.size())
                throw py::value_error("attempt to assign sequence of size " +
                                      std::to_string(values.size()) +
                                      " to extended slice of size " + std::to_string(at.size()));
              std::vector<char> replaced(v.size(), 0);
              for (std::size_t i : at) replaced[i] = 1;
              change(
                  v,
                  [&](V& x) {
                    for (std::size_t k = 0; k < at.size(); ++k) x[at[k]] = std::move(values[k]);
                  },
                  [&](std::size_t j) { return replaced[j] ? -1 : static_cast<std::ptrdiff_t>(j); });
              return;
            }
            // [start, start + length) replaced by the values, whatever their number
            const std::size_t first = static_cast<std::size_t>(sel.start), count = at.size();
            const std::ptrdiff_t shift =
                static_cast<std::ptrdiff_t>(values.size()) - static_cast<std::ptrdiff_t>(count);
            change(
                v,
                [&](V& x) {
                  V out;
                  out.reserve(x.size() - count + values.size());
                  // reserved: the moves below do not throw, so x stays whole if reserve does
                  for (std::size_t j = 0; j < first; ++j) out.push_back(std::move(x[j]));
                  for (T& e : values) out.push_back(std::move(e));
                  for (std::size_t j = first + count; j < x.size(); ++j)
                    out.push_back(std::move(x[j]));
                  x.swap(out);
                },
                [&](std::size_t j) -> std::ptrdiff_t {
                  if (j < first) return static_cast<std::ptrdiff_t>(j);
                  if (j < first + count) return -1;
                  return static_cast<std::ptrdiff_t>(j) + shift;
                });
          })
      .def("__setitem__",
           [](V& v, py::handle i, py::handle value) {
             if (py::isinstance<py::slice>(i)) throw py::type_error("can only assign an iterable");
             const py::ssize_t n = list_detail::index_of(i, list_detail::kListIndices);
             // `value` may be an element of v: a copy
             T copy = list_detail::value_of<T>(value, "list assignment");
             const std::size_t k =
                 list_detail::wrap_index(n, v.size(), "list assignment index out of range");
             change(
                 v, [&](V& x) { x[k] = std::move(copy); },
                 [k](std::size_t j) { return j == k ? -1 : static_cast<std::ptrdiff_t>(j); });
           })
      .def("__delitem__",
           [](V& v, const py::slice& s) {
             const list_detail::Selection sel = list_detail::slice_indices(s, v);
             std::vector<char> gone(v.size(), 0);
             for (std::size_t i : sel.indices) gone[i] = 1;
             list_detail::erase(v, gone);
           })
      .def("__delitem__",
           [](V& v, py::handle i) {
             const py::ssize_t n = list_detail::index_of(i, list_detail::kListIndices);
             const std::size_t k =
                 list_detail::wrap_index(n, v.size(), "list assignment index out of range");
             std::vector<char> gone(v.size(), 0);
             gone[k] = 1;
             list_detail::erase(v, gone);
           })
      .def(
          "append",
          [same](V& v, const T& value) {
            T copy = value;
            change(
                v, [&](V& x) { x.push_back(std::move(copy)); }, same);
          },
          py::arg("x"), "Adds an item at the end.")
      .def(
          "extend",
          [same](V& v, const py::iterable& items) {
            V values = list_detail::values_of<T>(items, "extend");  // (`items` may be this list)
            change(
                v,
                [&](V& x) {
                  x.reserve(x.size() + values.size());
                  for (T& e : values) x.push_back(std::move(e));
                },
                same);
          },
          py::arg("items"), "Adds the items at the end.")
      .def(
          "insert",
          [](V& v, py::handle index, const T& value) {
            // copied first: `value` may be an element of this list, and the index's __index__
            // may change the list (clear() freed the element, which was then copied: ASan's
            // heap-use-after-free, a garbage sphere inserted without a word)
            T copy = value;
            // as list.insert: an index beyond either end inserts at that end (one past
            // Py_ssize_t: OverflowError, as a list's, where pybind's TypeError said "incompatible")
            py::ssize_t i =
                list_detail::index_of(index, list_detail::kIndexMust, PyExc_OverflowError);
            const py::ssize_t n = static_cast<py::ssize_t>(v.size());
            if (i < 0) i = std::max<py::ssize_t>(0, i + n);
            const std::size_t k = static_cast<std::size_t>(std::min(i, n));
            change(
                v,
                [&](V& x) {
                  x.insert(x.begin() + static_cast<std::ptrdiff_t>(k), std::move(copy));
                },
                [k](std::size_t j) { return static_cast<std::ptrdiff_t>(j < k ? j : j + 1); });
          },
          py::arg("i"), py::arg("x"), "Inserts an item before index i.")
      .def(
          "pop",
          [](V& v, py::handle index) {
            const py::ssize_t i =
                list_detail::index_of(index, list_detail::kIndexMust, PyExc_OverflowError);
            if (v.empty()) throw py::index_error("pop from empty list");
            const std::size_t k = list_detail::wrap_index(i, v.size(), "pop index out of range");
            T out = v[k];
            std::vector<char> gone(v.size(), 0);
            gone[k] = 1;
            list_detail::erase(v, gone);
            return out;
          },
          py::arg("i") = -1, "Removes the item at index i (the last by default) and returns it.")
      .def(
          "clear",
          [](V& v) {
            change(
                v, [](V& x) { V().swap(x); }, [](std::size_t) { return std::ptrdiff_t(-1); });
          },
          "Removes every item.")
      .def(
          "__iter__", [](py::object self) { return Iterator<T>{std::move(self)}; },
          "Iterates by index, as over a Python list: items appended meanwhile are visited, and a "
          "list that shrinks ends the iteration.");
  py::class_<Iterator<T>>(c, "Iterator")
      .def("__iter__", [](py::object self) { return self; })
      .def("__next__", [](Iterator<T>& it) -> py::object {
        V& v = it.list.template cast<V&>();
        if (it.next >= v.size()) throw py::stop_iteration();
        return py::cast(v[it.next++], py::return_value_policy::reference_internal, it.list);
      });
  py::implicitly_convertible<py::list, V>();
  py::implicitly_convertible<py::tuple, V>();
  return c;
}

/// Scene.materials and the other lists: reading gives the list itself (edits reach the scene),
/// assigning takes a list of the kind or a Python list or tuple of elements.
template <class C, class T>
void list_property(py::class_<C>& c, const char* name, std::vector<T> C::*member,
                   const char* doc = "") {
  c.def_property(
      name,
      py::cpp_function([member](C& o) -> std::vector<T>& { return o.*member; },
                       py::return_value_policy::reference_internal),
      // (a value of another kind, or an item that is no T, was pybind's "(): incompatible
      // function arguments" TypeError, which named neither the list nor the item)
      py::cpp_function([member, what = c.attr("__name__").template cast<std::string>() + "." +
                                       name](C& o, py::handle value) {
        if (py::isinstance<std::vector<T>>(value)) {
          assign_list(o.*member, value.cast<std::vector<T>>());
          return;
        }
        if (!py::isinstance<py::iterable>(value) || py::isinstance<py::str>(value) ||
            py::isinstance<py::bytes>(value))
          throw py::type_error(what + ": expected a list of " + list_detail::bound_name<T>() +
                               ", not " + std::string(Py_TYPE(value.ptr())->tp_name));
        assign_list(o.*member, list_detail::values_of<T>(
                                   py::reinterpret_borrow<py::iterable>(value), what.c_str()));
      }),
      doc);
}

}  // namespace lucent::python

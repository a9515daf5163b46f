#include "scene/json_guard.hpp"

#include <cstddef>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <vector>

#include "core/file_io.hpp"
#include "core/host_memory.hpp"
#include "lucent/error.hpp"
#include "scene/validate.hpp"

namespace lucent::scene_detail {

namespace {

using nlohmann::json;

// An iterator over the text that remembers the last character the parser read, so that the
// SAX callbacks below know where they are (nlohmann's SAX interface gives no position).
struct TrackingIterator {
  using iterator_category = std::input_iterator_tag;
  using value_type = char;
  using difference_type = std::ptrdiff_t;
  using pointer = const char*;
  using reference = const char&;

  const char* p = nullptr;
  const char** last = nullptr;

  reference operator*() const {
    *last = p;
    return *p;
  }
  TrackingIterator& operator++() {
    ++p;
    return *this;
  }
  TrackingIterator operator++(int) {
    TrackingIterator t = *this;
    ++p;
    return t;
  }
  bool operator==(const TrackingIterator& o) const { return p == o.p; }
  bool operator!=(const TrackingIterator& o) const { return p != o.p; }
};

class StructureCheck : public nlohmann::json_sax<json> {
 public:
  StructureCheck(const std::string& text, const std::string& path, const char** last)
      : text_(text), path_(path), last_(last) {}

  /// What the text holds, for json_load_bytes.
  std::uint64_t values = 0, containers = 0, string_bytes = 0, members = 0;

  bool null() override { return value(); }
  bool boolean(bool) override { return value(); }
  bool number_integer(number_integer_t) override { return value(); }
  bool number_unsigned(number_unsigned_t) override { return value(); }
  bool number_float(number_float_t, const string_t&) override { return value(); }
  bool string(string_t& s) override {
    string_bytes += s.size();
    return value();
  }
  bool binary(binary_t&) override { return value(); }
  bool start_object(std::size_t) override { return open(true); }
  bool start_array(std::size_t) override { return open(false); }
  bool end_object() override { return close(); }
  bool end_array() override { return close(); }

  bool key(string_t& k) override {
    string_bytes += k.size();
    ++members;
    Frame& f = frames_.back();
    const std::size_t at = key_start();
    auto [it, fresh] = f.keys.emplace(k, at);
    f.key = k;
    if (!fresh) {
      const bool material = frames_.size() == 2 && frames_[0].key == "materials";
      fail(at, pointer(),
           std::string(material ? "duplicate material name '" + k + "'" : "duplicate key") +
               " (first at " + line_col_at(text_, it->second) + ")");
    }
    return true;
  }

  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override {
    return false;  // syntax errors: the parser reports them with their place
  }

 private:
  struct Frame {
    bool object = false;
    long index = -1;                          ///< arrays: the current element
    std::string key;                          ///< objects: the current key
    std::map<std::string, std::size_t> keys;  ///< objects: each key and where it first appears
  };

  std::size_t here() const { return static_cast<std::size_t>(*last_ - text_.data()); }

  // The key's opening quote: the last character read is its closing quote.
  std::size_t key_start() const {
    std::size_t i = here();
    while (i > 0) {
      --i;
      if (text_[i] != '"') continue;
      std::size_t slashes = 0;
      while (i > slashes && text_[i - 1 - slashes] == '\\') ++slashes;
      if (slashes % 2 == 0) return i;
    }
    return here();
  }

  std::string pointer() const {
    std::string p;
    for (const Frame& f : frames_)
      p += "/" + (f.object ? pointer_key(f.key) : std::to_string(f.index));
    return p.empty() ? "/" : p;
  }

  [[noreturn]] void fail(std::size_t at, const std::string& ptr, const std::string& what) const {
    throw Error(path_ + ":" + line_col_at(text_, at) + ": " + ptr + ": " + what);
  }

  bool value() {
    ++values;
    if (!frames_.empty() && !frames_.back().object) ++frames_.back().index;
    return true;
  }

  bool open(bool object) {
    value();
    ++containers;
    if (static_cast<int>(frames_.size()) >= kMaxJsonDepth)
      fail(here(), pointer(),
           "nested deeper than " + std::to_string(kMaxJsonDepth) +
               " levels (a scene needs 7: is this a scene file?)");
    frames_.push_back(Frame{object, -1, {}, {}});
    return true;
  }

  bool close() {
    frames_.pop_back();
    return true;
  }

  const std::string& text_;
  const std::string& path_;
  const char** last_;
  std::vector<Frame> frames_;
};

}  // namespace

std::string line_col_at(const std::string& text, std::size_t offset) {
  std::size_t line = 1, col = 1;
  for (std::size_t i = 0; i < offset && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return std::to_string(line) + ":" + std::to_string(col);
}

std::string read_scene_text(const std::string& path) {
  io::ReadSpec spec;
  spec.what = "scene file";
  spec.max_bytes = kMaxSceneBytes;
  spec.allow_pipe = true;
  spec.text = true;
  return io::read_file(path, spec);
}

std::uint64_t json_load_bytes(std::uint64_t text_bytes, std::uint64_t values,
                              std::uint64_t containers, std::uint64_t string_bytes,
                              std::uint64_t members) {
  // a value: its slot, twice over while its array grows (32), and what a number becomes in the
  // scene (a double of a position, an index of a triangle, with their arrays' growth: 16); a
  // container: its std::vector or std::map and the allocations' overhead; a string or key: its
  // characters beside the std::string counted in its slot; an object's member: its std::map node
  // and key (10^6 sphere objects peaked at 1.3 times the count without them)
  return sys::bytes_add(
      sys::bytes_add(text_bytes, sys::bytes_mul(values, 48)),
      sys::bytes_add(sys::bytes_add(sys::bytes_mul(containers, 64), 2 * string_bytes),
                     sys::bytes_mul(members, 64)));
}

void check_json_structure(const std::string& text, const std::string& path) {
  const char* last = text.data();
  StructureCheck check(text, path, &last);
  TrackingIterator first{text.data(), &last}, end{text.data() + text.size(), &last};
  json::sax_parse(first, end, &check);
  std::string what;
  const std::uint64_t limit = sys::host_memory_allowed(&what);
  const std::uint64_t need = json_load_bytes(text.size(), check.values, check.containers,
                                             check.string_bytes, check.members);
  if (limit > 0 && need > limit)
    throw Error(path + ": loading this scene's " + std::to_string(check.values) +
                " JSON values needs about " + sys::format_bytes(need) +
                " of host memory, more than the limit of " + sys::format_bytes(limit) +
                " (80% of " + what + "): reduce the scene's inline arrays");
}

void release_json(json& document) {
  // post-order: a container's elements are emptied first, then removed from the back one by one
  // (pop_back and erase free and never allocate), so that each destructor meets an empty
  // container or a scalar (depth is at most kMaxJsonDepth: check_json_structure)
  if (document.is_array()) {
    json::array_t& a = document.get_ref<json::array_t&>();
    while (!a.empty()) {
      release_json(a.back());
      a.pop_back();
    }
  } else if (document.is_object()) {
    json::object_t& o = document.get_ref<json::object_t&>();
    while (!o.empty()) {
      release_json(o.begin()->second);
      o.erase(o.begin());
    }
  }
  document = nullptr;
}

}  // namespace lucent::scene_detail

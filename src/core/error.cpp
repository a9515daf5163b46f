// lucent::Error's one-line message (include/lucent/error.hpp).
#include "lucent/error.hpp"

#include "core/text.hpp"

namespace lucent {

std::string Error::shown(const std::string& message) { return io::one_line(message); }

}  // namespace lucent

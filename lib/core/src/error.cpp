#include "articula/core/error.hpp"

#include <sstream>

namespace articula {

namespace {
std::string describe(const std::string& parameter, const std::string& expected, double found) {
  std::ostringstream s;
  s.precision(17);
  s << "invalid parameter '" << parameter << "': expected " << expected << ", found " << found;
  return s.str();
}
}  // namespace

InvalidParameter::InvalidParameter(const std::string& p, const std::string& expected, double found)
    : InputError(describe(p, expected, found)), parameter(p) {}

}  // namespace articula

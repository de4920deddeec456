#include "support/programs.hpp"

#include <cstdlib>

namespace demcal::test {

std::string missing_program(const std::string& name, const std::string& package,
                            const std::string& consequence) {
  return name + " is not installed (apt-get install " + package + "): " + consequence;
}

bool programs_required() {
  const char* v = std::getenv("DEMCAL_REQUIRE_PROGRAMS");
  return v && *v && std::string(v) != "0";
}

}  // namespace demcal::test

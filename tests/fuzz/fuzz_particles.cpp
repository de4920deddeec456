// libFuzzer target: the particle-file reader must turn any input into an
// Assembly or one InputError, never crash, hang or leak.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "demcal/scene/packing.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    demcal::Assembly a = demcal::read_particles(in, "fuzz.csv");
    (void)a;
  } catch (const demcal::InputError&) {
  }
  return 0;
}

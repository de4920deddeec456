// libFuzzer target: the particle-file readers (2D disks and 3D spheres, one
// input given to both) must turn any input into an assembly or one
// InputError, never crash, hang or leak.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "demcal/scene/packing.hpp"
#include "demcal/scene/sphere_packing.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    std::istringstream in(text);
    demcal::Assembly a = demcal::read_particles(in, "fuzz.csv");
    (void)a;
  } catch (const demcal::InputError&) {
  }
  try {
    std::istringstream in(text);
    demcal::SphereAssembly a = demcal::read_spheres(in, "fuzz.csv");
    (void)a;
  } catch (const demcal::InputError&) {
  }
  return 0;
}

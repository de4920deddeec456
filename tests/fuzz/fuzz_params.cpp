// libFuzzer target: the params.json reader (what `demcal upscale` and
// `demcal export` trust) must turn any input into a checked tree or one
// InputError, never crash, hang or leak. A tree it accepts must hold the
// REV block and the success it promises: reading them again cannot fail.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "demcal/upscaling/params_file.hpp"
#include "demcal/upscaling/upscaling.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  nlohmann::json params;
  try {
    params = demcal::parse_params_text(text, "fuzz.json");
  } catch (const demcal::InputError&) {
    return 0;
  }
  try {
    (void)demcal::rev_params_from_json(params, "fuzz.json");
    (void)demcal::calibration_succeeded(params, "fuzz.json");
  } catch (const demcal::InputError&) {
    std::abort();  // accepted, yet its rev block or its success does not read
  }
  return 0;
}

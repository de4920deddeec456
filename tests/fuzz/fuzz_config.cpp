// libFuzzer target: the config parser must turn any input into a SceneConfig
// or one InputError, never crash, hang or leak.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "demcal/scene/config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    demcal::SceneConfig c = demcal::parse_config_text(text, "fuzz.json");
    (void)demcal::to_json(c);
  } catch (const demcal::InputError&) {
  }
  return 0;
}

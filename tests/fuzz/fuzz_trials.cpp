// libFuzzer target: the trials.jsonl reader (--resume) must turn any input
// into trial records or one InputError, never crash, hang or leak. What it
// keeps (whole_bytes) is a prefix of whole lines that reads back to the
// same trials with nothing cut.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "demcal/search/calibration.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  size_t whole = 0;
  size_t count = 0;
  try {
    count = demcal::read_trials_text(text, "fuzz.jsonl", &whole).size();
  } catch (const demcal::InputError&) {
    return 0;
  }
  if (whole > size || (whole > 0 && whole < size && text[whole - 1] != '\n')) std::abort();
  size_t again_whole = 0;
  size_t again = 0;
  try {
    again = demcal::read_trials_text(text.substr(0, whole), "fuzz.jsonl", &again_whole).size();
  } catch (const demcal::InputError&) {
    std::abort();  // the kept prefix must read
  }
  if (again != count || again_whole != whole) std::abort();
  return 0;
}

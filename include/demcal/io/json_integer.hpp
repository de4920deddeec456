// A whole number read from a JSON value without a cast that can overflow:
// nlohmann's get<int>() on a float converts with static_cast, undefined
// behaviour for 5e110 (the trials.jsonl fuzzer found it in a record's id).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace demcal {

/// `v` as an integer in [min, max]: a JSON integer, or a float that is a
/// whole number of at most 2^53 (beyond it a double is not the number
/// written). Throws std::invalid_argument for a non-number and
/// std::out_of_range for anything else outside.
inline int64_t json_integer(const nlohmann::json& v,
                            int64_t min = std::numeric_limits<int64_t>::min(),
                            int64_t max = std::numeric_limits<int64_t>::max()) {
  if (!v.is_number()) throw std::invalid_argument("not a number: " + v.dump());
  if (v.is_number_unsigned()) {
    const uint64_t u = v.get<uint64_t>();
    if (max >= 0 && u <= static_cast<uint64_t>(max) &&
        (min <= 0 || u >= static_cast<uint64_t>(min)))
      return static_cast<int64_t>(u);
  } else if (v.is_number_integer()) {
    const int64_t i = v.get<int64_t>();
    if (i >= min && i <= max) return i;
  } else {
    const double d = v.get<double>();
    constexpr double kExact = 9007199254740992.0;  // 2^53
    if (std::isfinite(d) && std::floor(d) == d && std::abs(d) <= kExact) {
      const auto i = static_cast<int64_t>(d);  // exact, no overflow
      if (i >= min && i <= max) return i;
    }
  }
  throw std::out_of_range("not a whole number between " + std::to_string(min) + " and " +
                          std::to_string(max) + ": " + v.dump());
}

}  // namespace demcal

// A whole number read from a JSON value without a cast that can overflow:
// nlohmann's get<int>() on a float converts with static_cast, undefined
// behaviour for 5e110 (the trials.jsonl fuzzer found it in a record's id).
// Every count read from a file a user gives (config, params.json,
// trials.jsonl, a scaling study's results, a series.csv) goes through here.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "demcal/io/input_error.hpp"
#include "demcal/io/quoted_json.hpp"

namespace demcal {

inline std::out_of_range out_of_range_error(int64_t min, int64_t max, const std::string& shown) {
  return std::out_of_range("must be between " + std::to_string(min) + " and " +
                           std::to_string(max) + ", got " + quoted_value(shown));
}

/// `d` as an integer in [min, max] when it is a whole number of at most
/// 2^53 (beyond it a double is not the number written), never through a
/// cast that can overflow; else std::out_of_range, the message showing the
/// value as `shown` (how the file wrote it).
inline int64_t whole_number(double d, int64_t min, int64_t max, const std::string& shown) {
  if (!std::isfinite(d) || std::floor(d) != d)
    throw std::out_of_range("must be a whole number, got " + quoted_value(shown));
  constexpr double kExact = 9007199254740992.0;  // 2^53
  if (std::abs(d) > kExact)
    throw std::out_of_range("must be written as an integer (" + quoted_value(shown) +
                            " in exponent form is beyond 2^53, where a double is not exact)");
  const auto i = static_cast<int64_t>(d);  // |d| <= 2^53: exact, no overflow
  if (i < min || i > max) throw out_of_range_error(min, max, shown);
  return i;
}

/// `v` as an integer in [min, max]: a JSON integer, or a float that is a
/// whole number (whole_number). Throws std::invalid_argument for a
/// non-number and std::out_of_range for anything else outside; the message
/// says which ("must be ..., got VALUE", the value quoted and cut).
inline int64_t json_integer(const nlohmann::json& v,
                            int64_t min = std::numeric_limits<int64_t>::min(),
                            int64_t max = std::numeric_limits<int64_t>::max()) {
  if (!v.is_number()) throw std::invalid_argument("must be a whole number, got " + quoted_json(v));
  if (v.is_number_float()) return whole_number(v.get<double>(), min, max, v.dump());
  const bool in_range = v.is_number_unsigned()
                            ? max >= 0 && v.get<uint64_t>() <= static_cast<uint64_t>(max) &&
                                  (min <= 0 || v.get<uint64_t>() >= static_cast<uint64_t>(min))
                            : v.get<int64_t>() >= min && v.get<int64_t>() <= max;
  if (!in_range) throw out_of_range_error(min, max, v.dump());
  return v.is_number_unsigned() ? static_cast<int64_t>(v.get<uint64_t>()) : v.get<int64_t>();
}

/// json_integer for a value read from `file`: a value that is no count in
/// [min, max] is an InputError naming the file and `field` (exit status 2).
inline int64_t json_integer(const nlohmann::json& v, int64_t min, int64_t max,
                            const std::string& file, const std::string& field) {
  try {
    return json_integer(v, min, max);
  } catch (const std::logic_error& e) {  // invalid_argument, out_of_range
    throw InputError(file, field, e.what());
  }
}

}  // namespace demcal

// A JSON record without its wall times: what differs between two runs of
// the same computation (scaling studies, resumed or not).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace demcal::test {

/// `j` without its wall times (every key ending in "wall_time_s", at any
/// depth).
inline nlohmann::json without_timing(nlohmann::json j) {
  if (j.is_object()) {
    nlohmann::json out = nlohmann::json::object();
    for (auto& [key, value] : j.items()) {
      const std::string suffix = "wall_time_s";
      if (key.size() >= suffix.size() &&
          key.compare(key.size() - suffix.size(), suffix.size(), suffix) == 0)
        continue;
      out[key] = without_timing(value);
    }
    return out;
  }
  if (j.is_array())
    for (auto& v : j) v = without_timing(v);
  return j;
}

}  // namespace demcal::test

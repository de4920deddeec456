// A JSON value from a user's file, named in an error message by its type and
// its text: `got string "yes"`, `got number "5"` (not `got ""yes""`: a
// string's JSON text carries its own quotes).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "demcal/io/input_error.hpp"

namespace demcal {

inline std::string quoted_json(const nlohmann::json& v) {
  return std::string(v.type_name()) + " " +
         quoted_value(v.is_string() ? v.get<std::string>() : v.dump());
}

}  // namespace demcal

// The one error type for bad input: every command catches it, prints its
// message (file, key, what is wrong) and exits with status 2.
#pragma once

#include <stdexcept>
#include <string>

namespace demcal {

/// Bad user input: a config, a particle file, a parameter file. Carries the
/// file and the field (key or line) so the message names both.
class InputError : public std::runtime_error {
 public:
  InputError(const std::string& file, const std::string& field, const std::string& what)
      : std::runtime_error(file + ": " + (field.empty() ? "" : field + ": ") + what),
        file_(file),
        field_(field) {}
  const std::string& file() const { return file_; }
  const std::string& field() const { return field_; }

 private:
  std::string file_, field_;
};

}  // namespace demcal

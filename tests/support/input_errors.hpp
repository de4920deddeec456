// Test support: catching the one InputError a bad input must give.
#pragma once

#include <gtest/gtest.h>

#include <exception>
#include <functional>
#include <optional>

#include "demcal/io/input_error.hpp"

namespace demcal::test {

/// The InputError `f` throws, or nothing; then the test has failed already
/// (another exception, or none, is a failure of its own).
inline std::optional<InputError> input_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return std::nullopt;
  }
  ADD_FAILURE() << "expected InputError, nothing thrown";
  return std::nullopt;
}

}  // namespace demcal::test

// Test support: catching the one InputError a bad input must give.
#pragma once

#include <gtest/gtest.h>

#include <exception>
#include <functional>
#include <optional>
#include <string>

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

/// `f` fails with one InputError naming `file` and `field`, whose message
/// contains `words`.
inline void expect_input_error(const std::function<void()>& f, const std::string& file,
                               const std::string& field, const std::string& words) {
  const auto e = input_error(f);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->file(), file);
  EXPECT_EQ(e->field(), field) << e->what();
  EXPECT_NE(std::string(e->what()).find(words), std::string::npos) << e->what();
}

}  // namespace demcal::test

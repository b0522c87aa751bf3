// Shared by the framework tests: the error a call throws, and a readable
// "contains" check.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "framework/error.h"

namespace swarmsim::testing {

// The message of the swarmsim::Error thrown by `f`, or "" if none.
template <typename F>
std::string ErrorOf(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace swarmsim::testing

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << (haystack)

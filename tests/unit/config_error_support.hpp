// The ConfigError a config read throws, for tests that check what it names.
#pragma once

#include <gtest/gtest.h>

#include "common/core/config_error.hpp"

namespace masa::test {

// The ConfigError that `f` throws; a test failure (and an empty error) when it throws none.
template <typename F>
ConfigError configErrorOf(F f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e;
  }
  ADD_FAILURE() << "no ConfigError";
  return ConfigError("", "", "");
}

}  // namespace masa::test

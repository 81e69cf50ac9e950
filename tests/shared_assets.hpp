// The shared third-party characters (../shared/assets) live outside the project: a test
// that needs one skips on a clone without them, but fails under CI (CI=true), where they
// must be present.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string_view>

namespace drape::test {

inline bool under_ci() {
    const char* ci = std::getenv("CI");
    return ci != nullptr && std::string_view(ci) == "true";
}

}  // namespace drape::test

/// In a test body: skip (or, under CI, fail) when `path` is absent.
#define DRAPE_REQUIRE_SHARED(path)                                                                \
    do {                                                                                          \
        if (!std::filesystem::exists(path)) {                                                     \
            if (::drape::test::under_ci()) FAIL() << (path) << " is absent under CI";             \
            GTEST_SKIP() << (path) << " is absent (the shared third-party characters are optional)"; \
        }                                                                                         \
    } while (false)

// See test_paths.hpp.
#include "tests/test_paths.hpp"

#include <cstdlib>

namespace drape::test {

std::filesystem::path source_dir() { return DRAPE_SOURCE_DIR; }
std::filesystem::path binary_dir() { return DRAPE_BINARY_DIR; }
std::filesystem::path shared_assets() { return DRAPE_SHARED_ASSETS; }
const char* version() { return DRAPE_VERSION; }
const char* machine_flags() { return DRAPE_MACHINE_FLAGS; }

namespace {

// Worlds built by the tests keep their fitted bodies in build/body-cache (systems/character/body_cache.hpp):
// each test binary fits a character once, not once per test. A DRAPE_BODY_CACHE already set
// is kept.
[[maybe_unused]] const bool body_cache_set = [] {
    return ::setenv("DRAPE_BODY_CACHE", (binary_dir() / "body-cache").c_str(), /*overwrite=*/0) == 0;
}();

}  // namespace

}  // namespace drape::test

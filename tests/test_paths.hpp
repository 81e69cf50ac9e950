// Where tests find the project's sources, its build and the shared third-party characters
// (../shared/assets, outside the project; absent is allowed), and the build's version and
// machine flags. These are compiled into tests/test_paths.cpp alone, so that no other test
// file depends on where the checkout is (a compiler cache then serves a clone in another
// folder). Linked into every test binary,
// it also points DRAPE_BODY_CACHE at build/body-cache, so that worlds the tests build fit
// each character once per test binary (systems/character/body_cache.hpp).
#pragma once

#include <filesystem>

namespace drape::test {

std::filesystem::path source_dir();     ///< The project's source tree.
std::filesystem::path binary_dir();     ///< The build tree (the drape executable, test outputs).
std::filesystem::path shared_assets();  ///< ../shared/assets beside the project.
const char* version();                  ///< The project's version (CMake's PROJECT_VERSION).
const char* machine_flags();            ///< The build's machine flags (-march=...), for a failure to print.

}  // namespace drape::test

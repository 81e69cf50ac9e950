// Tests that assert a figure of a long garment simulation (strain, penetration, rise, the
// coverage of a fit over a walk) carry the CTest label `figures`; tests/CMakeLists.txt lists
// them, each with its reason. Such a figure depends on the build's rounding (a walking
// garment is chaotic), and it is the release build, which users run, that must show it.
//
// Where CTest sets DRAPE_TEST_FIGURES=short for them (the sanitizer build), a labelled test
// runs its short form: a few dozen frames, the first case where it loops over several, and
// asserts that it runs clean (no sanitizer report, nothing non-finite, no error) instead of
// its figures. Run by hand, or anywhere else, every test runs in full.
#pragma once

#include <algorithm>
#include <cstdlib>
#include <span>
#include <string_view>

namespace drape::test {

/// Whether this run is a labelled test's short form (DRAPE_TEST_FIGURES=short).
inline bool short_form() {
    const char* figures = std::getenv("DRAPE_TEST_FIGURES");
    return figures != nullptr && std::string_view(figures) == "short";
}

/// Whether the figures are asserted (not the short form).
inline bool full_form() { return !short_form(); }

/// Frames the short form runs where the full test runs `full`.
inline constexpr int short_frames = 36;

/// `full` frames, or short_frames in the short form.
inline int frames(int full) { return short_form() ? std::min(full, short_frames) : full; }

/// The cases a test loops over, or the first of them in the short form.
template <class T>
std::span<T> cases(std::span<T> all) {
    return short_form() && !all.empty() ? all.first(1) : all;
}
template <class T, std::size_t N>
std::span<T> cases(T (&all)[N]) {
    return cases(std::span<T>(all));
}

}  // namespace drape::test

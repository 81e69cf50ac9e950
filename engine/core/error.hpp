// Errors at Drape's boundaries: files, scene descriptions, assimp, EGL/GL, user parameters.
//
// A boundary returns `Result<T>` (std::expected). The message is one line that names the
// file or field and says what was wrong, so a user can act on it without a debugger.
#pragma once

#include <expected>
#include <string>
#include <utility>

namespace drape {

/// One clear error: where (file, field) and why.
struct Error {
    std::string message;  ///< One line, e.g. "scene.json:3:14: garments[0].particles: must be > 0".
};

template <class T>
using Result = std::expected<T, Error>;

/// Shorthand for returning an error: `return fail("file.glb: no skeleton");`
[[nodiscard]] inline std::unexpected<Error> fail(std::string message) {
    return std::unexpected<Error>(Error{std::move(message)});
}

}  // namespace drape

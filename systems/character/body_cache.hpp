// Fitted bodies kept on disk between runs. Fitting a character's ellipsoids and landmarks
// (fit_character_body) takes a moment: up to a second or two for a humanoid in the release
// build, tens of seconds under the sanitizers. build_world keeps each body it fits in a
// cache folder when one is given (WorldOptions::body_cache, or the DRAPE_BODY_CACHE
// environment variable; the tests use build/body-cache) and reads it back the next time.
//
// A cached body is the very body a fit would give: it is used only when it was fitted by
// the same program (the running executable: its path, size and modification time), from
// the same character file (its bytes, and the size and time of every file beside it, such
// as a .gltf's buffers), with the same fit options and the same number of threads. Anything
// else fits again. The files are written whole (a temporary file renamed), so runs in
// parallel share a folder safely; a file that cannot be read or written is only a missed
// cache.
#pragma once

#include <filesystem>
#include <optional>

#include "drape/systems/character/character_body.hpp"

namespace drape {

/// What identifies a fit: the program, the character's files, the options and the number
/// of threads the fit may use (TBB's, where it is called). None when the program or the
/// file cannot be identified.
struct BodyCacheKey {
    std::string text;  ///< Everything the fit depends on, compared on reading.
    std::string name;  ///< File name in the cache folder (the file's stem and a hash of text).
};
[[nodiscard]] std::optional<BodyCacheKey> body_cache_key(const std::filesystem::path& character_file, const FitOptions& options);

/// The cached body for `key` in `folder`, if there is one.
[[nodiscard]] std::optional<CharacterBody> read_cached_body(const std::filesystem::path& folder, const BodyCacheKey& key);

/// Keeps `body` in `folder` (created when missing). False when it could not be written.
bool write_cached_body(const std::filesystem::path& folder, const BodyCacheKey& key, const CharacterBody& body);

/// fit_character_body() through the cache folder `folder`: `character` was imported by this
/// program from `file` with the default import options; its body is read from `folder`
/// when the folder holds it, else fitted and kept there. An empty folder: fitted.
[[nodiscard]] Result<CharacterBody> fit_character_body(const CharacterAsset& character, const std::filesystem::path& file,
                                                       const FitOptions& options, const std::filesystem::path& folder);

/// The folder DRAPE_BODY_CACHE names; empty when it is not set.
[[nodiscard]] std::filesystem::path body_cache_from_environment();

}  // namespace drape

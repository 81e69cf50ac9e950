// Fitting a character's body: see character_body.hpp.
#include "drape/systems/character/character_body.hpp"

#include "drape/systems/character/body_landmarks.hpp"

namespace drape {

Result<CharacterBody> fit_character_body(const CharacterAsset& character, const FitOptions& options) {
    const std::string at = character.source.string() + ": ";
    if (auto ok = validate(options); !ok) return fail(at + ok.error().message);
    if (!character.skeleton || !character.mesh) return fail(at + "no skeleton or mesh to fit a body to");
    CharacterBody body;
    body.hip_bone = find_hip_bone(*character.skeleton);
    // A first look at the whole character finds its topology; the body is what is fitted.
    if (auto first = find_body_landmarks(character)) body.left_out = find_non_body_meshes(character, *first);
    const CharacterAsset fitted = body_only(character, body.left_out);
    body.ellipsoids = fit_ellipsoids(*fitted.skeleton, *fitted.mesh, fitted.height_m, options, fitted.clips, fitted.meshes, &body.legs);
    if (auto landmarks = find_body_landmarks(fitted)) body.landmarks = std::move(*landmarks);
    else body.landmarks_error = landmarks.error().message;
    return body;
}

}  // namespace drape

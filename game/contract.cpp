// The quality contract and its verdict: see contract.hpp.
#include "drape/game/contract.hpp"

#include <cmath>
#include <cstdio>

namespace drape {

namespace {

std::string format(const char* pattern, double value) {
    char text[64];
    std::snprintf(text, sizeof text, pattern, value);
    return text;
}

std::string percent(double strain) { return format("%.1f %%", strain * 100); }
std::string millimetres(double metres) { return format("%.1f mm", metres * 1000); }

// Broken when over the limit or not a number.
bool over(double value, double limit) { return !(value <= limit); }

}  // namespace

std::vector<std::string> contract_breaches(const GarmentStats& s, const QualityContract& c) {
    std::vector<std::string> out;
    if (s.nonfinite > 0) out.push_back(std::to_string(s.nonfinite) + " non-finite value(s)");
    if (over(s.strain_p99, c.strain_p99)) out.push_back("strain p99 " + percent(s.strain_p99) + " > " + format("%g %%", c.strain_p99 * 100));
    if (over(s.strain_max, c.strain_max)) out.push_back("strain max " + percent(s.strain_max) + " > " + format("%g %%", c.strain_max * 100));
    if (over(s.penetration_after_frame_m, c.penetration_after_frame_m))
        out.push_back("penetration after the frame " + millimetres(s.penetration_after_frame_m) + " > " +
                      format("%g mm", c.penetration_after_frame_m * 1000));
    if (!(s.compression_min >= c.compression_min))
        out.push_back("shortest spring " + percent(s.compression_min) + " of its rest length < " + format("%g %%", c.compression_min * 100));
    if (over(s.below_ground_m, c.penetration_after_frame_m))
        out.push_back("below the floor " + millimetres(s.below_ground_m) + " > " + format("%g mm", c.penetration_after_frame_m * 1000));
    if (over(s.rise_above_pins_m, c.rise_above_pins_m))
        out.push_back("rise above the pins " + format("%.1f cm", s.rise_above_pins_m * 100) + " > " +
                      format("%g cm", c.rise_above_pins_m * 100));
    return out;
}

std::string garment_verdict(std::string_view name, const GarmentStats& s, const QualityContract& c) {
    std::string line = std::string(name) + ": strain p99 " + percent(s.strain_p99) + ", max " + percent(s.strain_max) +
                       ", penetration " + millimetres(s.penetration_after_frame_m) + ": ";
    const std::vector<std::string> breaches = contract_breaches(s, c);
    if (breaches.empty()) return line + "within the contract";
    line += "outside the contract: ";
    for (std::size_t i = 0; i < breaches.size(); ++i) line += (i > 0 ? ", " : "") + breaches[i];
    return line;
}

std::vector<std::string> garment_names(const SceneDescription& scene) {
    std::vector<std::string> out;
    for (std::size_t i = 0; i < scene.garments.size(); ++i) {
        const GarmentDescription& g = scene.garments[i];
        std::string name = g.file.empty() ? garment_type_name(g.type) : g.file.stem().string() + (g.mesh.empty() ? "" : ":" + g.mesh);
        if (scene.garments.size() > 1) {
            name = "garments[" + std::to_string(i) + "] " + name;
            if (g.character >= 0 && static_cast<std::size_t>(g.character) < scene.characters.size())
                name += " on " + scene.characters[static_cast<std::size_t>(g.character)].file.stem().string();
        }
        out.push_back(std::move(name));
    }
    return out;
}

}  // namespace drape

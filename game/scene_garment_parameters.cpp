// Garment parameters as a scene names them; see scene_garment_parameters.hpp.
#include "drape/game/scene_garment_parameters.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

namespace drape {

namespace {

// A grid of about `particles` with the default grid's proportions; lines a multiple of the stride.
void grid_for(int particles, int default_lines, int default_rows, int stride, int& lines, int& rows) {
    const double aspect = double(default_rows) / double(default_lines);
    const int s = std::max(1, stride);
    lines = std::max(s * 2, static_cast<int>(std::lround(std::sqrt(particles / aspect) / s)) * s);
    rows = std::max(2, static_cast<int>(std::lround(double(particles) / lines)));
    rows = std::min(rows, max_garment_particles / lines);  // rounding must not pass the builders' limit
}

TubeParams defaults_of(GarmentType type) { return type == GarmentType::skirt ? TubeParams::skirt() : TubeParams::dress(); }

}  // namespace

const ParameterSpec& particles_parameter() {
    static const ParameterSpec spec{
        "particles", ParameterKind::integer, ParameterRange{16, double(max_garment_particles), false, false}, "",
        "target particle count: chooses `warp_lines` and `particles_per_line` in the default grid's proportions "
        "(give either this or those two; a scene-file convenience, not a builder field)"};
    return spec;
}

std::vector<const ParameterSpec*> scene_garment_parameters() {
    std::vector<const ParameterSpec*> out{&particles_parameter()};
    for (const GarmentParameterSpec& spec : garment_parameters()) out.push_back(&spec);
    return out;
}

Result<TubeParams> tube_params(const GarmentDescription& garment) {
    const TubeParams defaults = defaults_of(garment.type);
    TubeParams p = defaults;
    if (!garment.material.empty()) {
        auto material = material_preset(garment.material);
        if (!material) return std::unexpected(material.error());
        p.material = *material;
    }
    std::optional<int> particles;
    for (const GarmentParameter& q : garment.parameters) {
        if (q.name == particles_parameter().name) {
            particles = static_cast<int>(std::lround(q.value));
            continue;
        }
        const GarmentParameterSpec* spec = find_garment_parameter(q.name);
        if (spec == nullptr) return fail(q.name + ": unknown garment parameter (docs/scenes.md lists them)");
        spec->set(p, q.value);
    }
    // After the others: the grid keeps lines a multiple of the stride the scene chose.
    if (particles) grid_for(*particles, defaults.warp_lines, defaults.particles_per_line, p.weft_stride, p.warp_lines, p.particles_per_line);
    p.model = garment.model;
    p.integrator = garment.integrator;
    p.collision = garment.collision;
    p.pin_weights = garment.pin_weights;
    if (garment.color) p.color = *garment.color;
    return p;
}

std::string garment_parameters_markdown() {
    const TubeParams skirt = TubeParams::skirt(), dress = TubeParams::dress();
    std::string out = "| parameter | range | skirt | dress | file | meaning |\n|---|---|---|---|---|---|\n";
    auto row = [&](const ParameterSpec& spec, double skirt_default, double dress_default, bool file) {
        out += "| `";
        out += spec.name;
        out += "` | " + spec.range_text() + " | " + parameter_number_text(skirt_default) + " | " +
               parameter_number_text(dress_default) + " | " + (file ? "yes" : "") + " | ";
        out += spec.description;
        out += " |\n";
    };
    row(particles_parameter(), double(skirt.warp_lines) * skirt.particles_per_line, double(dress.warp_lines) * dress.particles_per_line,
        false);
    for (const GarmentParameterSpec& spec : garment_parameters())
        row(spec, spec.get(skirt), spec.get(dress), spec.takes_file_garments());
    return out;
}

}  // namespace drape

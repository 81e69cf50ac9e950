// Scene descriptions; see scene_description.hpp.
#include "drape/game/scene_description.hpp"

namespace drape {

std::string SourceLocation::str() const {
    if (file.empty()) return {};
    if (line <= 0) return file;
    return file + ":" + std::to_string(line) + ":" + std::to_string(column);
}

std::string located(const SourceLocation& where, std::string_view field, std::string_view reason) {
    std::string out = where.str();
    if (!out.empty()) out += ": ";
    if (!field.empty()) {
        out += field;
        out += ": ";
    }
    out += reason;
    return out;
}

Quat CharacterDescription::rotation() const {
    constexpr Real to_rad = Real(3.14159265358979323846 / 180.0);
    return Quat(Eigen::AngleAxis<Real>(rotation_deg.y() * to_rad, Vec3::UnitY()) *
                Eigen::AngleAxis<Real>(rotation_deg.x() * to_rad, Vec3::UnitX()) *
                Eigen::AngleAxis<Real>(rotation_deg.z() * to_rad, Vec3::UnitZ()));
}

const char* garment_type_name(GarmentType t) noexcept { return t == GarmentType::skirt ? "skirt" : "dress"; }
const char* cloth_model_name(ClothModel m) noexcept { return m == ClothModel::simplified ? "simplified" : "classic"; }
const char* cloth_integrator_name(ClothIntegrator i) noexcept { return i == ClothIntegrator::paper ? "paper" : "shipped"; }
const char* collision_mode_name(CollisionMode m) noexcept {
    return m == CollisionMode::candidate_lists ? "lists" : "brute_force";
}

}  // namespace drape

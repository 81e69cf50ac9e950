// Scene files: JSON -> SceneDescription with errors that point at the line, column and
// field (docs/scenes.md).
//
// nlohmann-json checks the syntax (and reports a byte offset that becomes line:column);
// it does not keep positions of values, so a small scanner walks the (already valid) text
// once and records, for every field path ("garments[0].particles"), where its key and its
// value start. The reader then walks the JSON tree field by field; an internal exception
// carries the first error out to the boundary, where it becomes a Result.
#include "drape/game/scene_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include <nlohmann/json.hpp>

#include "drape/game/scene_garment_parameters.hpp"
#include "drape/systems/cloth/garment_parameters.hpp"

namespace drape {

using Json = nlohmann::json;

std::pair<int, int> line_column(std::string_view text, std::size_t offset) {
    offset = std::min(offset, text.size());
    int line = 1;
    std::size_t line_start = 0;
    for (std::size_t i = 0; i < offset; ++i)
        if (text[i] == '\n') {
            ++line;
            line_start = i + 1;
        }
    return {line, static_cast<int>(offset - line_start) + 1};
}

namespace {

constexpr int max_nesting = 64;
constexpr std::size_t max_list = 256;   // characters, garments, collider overrides per scene
constexpr double max_coordinate_m = 1e4;

/// Joins text without `"literal" + std::string` temporaries (GCC 12 warns falsely on those).
template <class... Parts>
std::string cat(const Parts&... parts) {
    std::string s;
    (s.append(std::string_view(parts)), ...);
    return s;
}

struct SceneError {
    std::string message;
};

// ---------------------------------------------------------------------------------------
// Positions of keys and values by field path.
struct FieldPosition {
    std::size_t key = std::string::npos;  ///< Opening quote of the key (npos for array elements and the root).
    std::size_t value = 0;                ///< First byte of the value.
};
using Positions = std::unordered_map<std::string, FieldPosition>;

std::string member_path(const std::string& parent, std::string_view key) {
    return parent.empty() ? std::string(key) : parent + "." + std::string(key);
}
std::string element_path(const std::string& parent, std::size_t index) {
    return parent + "[" + std::to_string(index) + "]";
}

// Walks text nlohmann already accepted (comments allowed), recording positions. Also
// finds what nlohmann silently accepts but a scene must not contain: duplicate keys and
// absurd nesting.
class PositionScanner {
public:
    explicit PositionScanner(std::string_view text) : m_text(text) {}

    struct Problem {
        std::size_t offset;
        std::string field, reason;
    };

    std::optional<Problem> scan(Positions& out) {
        m_out = &out;
        value("", FieldPosition{}, 0);
        return m_problem;
    }

private:
    [[nodiscard]] char peek() const { return m_i < m_text.size() ? m_text[m_i] : '\0'; }

    void whitespace() {
        while (m_i < m_text.size()) {
            const char c = m_text[m_i];
            if (c == ' ' || c == '\t' || c == '\n' || c == '\r') {
                ++m_i;
            } else if (c == '/' && m_i + 1 < m_text.size() && m_text[m_i + 1] == '/') {
                while (m_i < m_text.size() && m_text[m_i] != '\n') ++m_i;
            } else if (c == '/' && m_i + 1 < m_text.size() && m_text[m_i + 1] == '*') {
                const std::size_t end = m_text.find("*/", m_i + 2);
                m_i = end == std::string_view::npos ? m_text.size() : end + 2;
            } else {
                return;
            }
        }
    }

    std::string string() {
        std::string s;
        ++m_i;  // opening quote
        while (m_i < m_text.size() && m_text[m_i] != '"') {
            char c = m_text[m_i++];
            if (c == '\\' && m_i < m_text.size()) {
                c = m_text[m_i++];
                switch (c) {
                    case 'n': s += '\n'; break;
                    case 't': s += '\t'; break;
                    case 'r': s += '\r'; break;
                    case 'b': s += '\b'; break;
                    case 'f': s += '\f'; break;
                    case 'u':  // kept escaped: such a key then has no position (the parent's is used)
                        s += "\\u";
                        break;
                    default: s += c;
                }
            } else {
                s += c;
            }
        }
        ++m_i;  // closing quote
        return s;
    }

    void value(const std::string& path, FieldPosition position, int depth) {
        if (m_problem) return;
        whitespace();
        position.value = m_i;
        m_out->emplace(path, position);
        if (depth > max_nesting) {
            m_problem = Problem{m_i, path, cat("nested deeper than ", std::to_string(max_nesting), " levels")};
            return;
        }
        const char c = peek();
        if (c == '{') {
            ++m_i;
            std::unordered_set<std::string> seen;
            whitespace();
            if (peek() == '}') {
                ++m_i;
                return;
            }
            while (m_i < m_text.size() && !m_problem) {
                whitespace();
                const std::size_t key_at = m_i;
                const std::string key = string();
                const std::string child = member_path(path, key);
                if (!seen.insert(key).second) {
                    m_problem = Problem{key_at, child, "duplicate field (each field may appear once)"};
                    return;
                }
                whitespace();
                ++m_i;  // ':'
                value(child, FieldPosition{key_at, 0}, depth + 1);
                whitespace();
                if (peek() == ',') {
                    ++m_i;
                    continue;
                }
                ++m_i;  // '}'
                return;
            }
        } else if (c == '[') {
            ++m_i;
            whitespace();
            if (peek() == ']') {
                ++m_i;
                return;
            }
            for (std::size_t index = 0; m_i < m_text.size() && !m_problem; ++index) {
                value(element_path(path, index), FieldPosition{}, depth + 1);
                whitespace();
                if (peek() == ',') {
                    ++m_i;
                    continue;
                }
                ++m_i;  // ']'
                return;
            }
        } else if (c == '"') {
            string();
        } else {  // number, true, false, null
            while (m_i < m_text.size() && std::string_view(",]} \t\r\n/").find(m_text[m_i]) == std::string_view::npos) ++m_i;
        }
    }

    std::string_view m_text;
    std::size_t m_i = 0;
    Positions* m_out = nullptr;
    std::optional<Problem> m_problem;
};

// ---------------------------------------------------------------------------------------
// Reading fields with errors at their place.
class Reader {
public:
    Reader(std::string label, std::string_view text, Positions positions, std::filesystem::path base_dir)
        : m_label(std::move(label)), m_text(text), m_positions(std::move(positions)), m_base(std::move(base_dir)) {}

    [[nodiscard]] SourceLocation where(const std::string& path, bool at_key = false) const {
        if (m_label.empty()) return {};
        // The field itself, else its closest recorded parent (e.g. keys with \u escapes).
        std::string p = path;
        while (true) {
            if (auto it = m_positions.find(p); it != m_positions.end()) {
                const std::size_t offset = at_key && it->second.key != std::string::npos ? it->second.key : it->second.value;
                const auto [line, column] = line_column(m_text, offset);
                return SourceLocation{m_label, line, column};
            }
            const std::size_t cut = p.find_last_of(".[");
            if (cut == std::string::npos || p.empty()) break;
            p.resize(cut);
        }
        return SourceLocation{m_label, 0, 0};
    }

    [[noreturn]] void fail_at(const std::string& path, std::string_view reason, bool at_key = false) const {
        // A key may hold any character: keep the message on one printable line.
        std::string field;
        for (const char c : path) {
            if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
                char escaped[8];
                std::snprintf(escaped, sizeof escaped, "\\x%02x", static_cast<unsigned char>(c));
                field += escaped;
            } else {
                field += c;
            }
        }
        throw SceneError{located(where(path, at_key), field, reason)};
    }

    [[nodiscard]] const std::filesystem::path& base_dir() const { return m_base; }

private:
    std::string m_label;
    std::string_view m_text;
    Positions m_positions;
    std::filesystem::path m_base;
};

std::string shown(const Json& j) {
    std::string s = j.dump();
    if (s.size() > 40) s = s.substr(0, 37) + "...";
    return s;
}

std::string typed(const Json& j) { return cat(j.type_name(), " ", shown(j)); }

std::string number_text(double v) {
    std::ostringstream out;
    out << v;
    return out.str();
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diagonal = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diagonal = up;
        }
    }
    return row[b.size()];
}

// The fields of one JSON object: each read marks its name as known; finish() rejects
// the fields nobody asked for.
class Fields {
public:
    Fields(const Reader& reader, const Json& j, std::string path) : m_reader(reader), m_json(j), m_path(std::move(path)) {
        if (!j.is_object())
            m_reader.fail_at(m_path, cat("must be an object ({...}), got ", typed(j)));
    }

    /// The field's value, or null when absent.
    const Json* get(std::string_view name) {
        m_known.emplace_back(name);
        const auto it = m_json.find(std::string(name));
        return it == m_json.end() ? nullptr : &*it;
    }
    const Json& require(std::string_view name) {
        const Json* j = get(name);
        if (j == nullptr) m_reader.fail_at(path(name), "missing (a required field)");
        return *j;
    }
    /// Marks extra names as known (fields read elsewhere).
    void know(std::string_view name) { m_known.emplace_back(name); }
    [[nodiscard]] std::string path(std::string_view name) const { return member_path(m_path, name); }

    void finish() const {
        for (const auto& [key, value] : m_json.items()) {
            if (std::find(m_known.begin(), m_known.end(), key) != m_known.end()) continue;
            std::string reason = "unknown field";
            std::string best;
            std::size_t best_distance = 3;  // suggest only close names
            for (const std::string& k : m_known)
                if (const std::size_t d = edit_distance(key, k); d < best_distance) {
                    best_distance = d;
                    best = k;
                }
            if (!best.empty()) reason += cat(" (did you mean \"", best, "\"?)");
            reason += "; known fields: ";
            for (std::size_t i = 0; i < m_known.size(); ++i) reason += (i ? ", " : "") + m_known[i];
            m_reader.fail_at(member_path(m_path, key), reason, true);
        }
    }

private:
    const Reader& m_reader;
    const Json& m_json;
    std::string m_path;
    std::vector<std::string> m_known;
};

enum class Bound { closed, open };

double read_real(const Reader& r, const std::string& path, const Json& j, double lo, double hi,
                 Bound lower = Bound::closed) {
    const std::string range = cat(lower == Bound::open ? "(" : "[", number_text(lo), ", ", number_text(hi), "]");
    if (!j.is_number()) r.fail_at(path, cat("must be a number in ", range, ", got ", typed(j)));
    const double v = j.get<double>();
    if (!std::isfinite(v)) r.fail_at(path, cat("must be a finite number, got ", shown(j)));
    if (v > hi || v < lo || (lower == Bound::open && v == lo))
        r.fail_at(path, cat("must be a number in ", range, ", got ", shown(j)));
    return v;
}

int read_int(const Reader& r, const std::string& path, const Json& j, long long lo, long long hi) {
    const std::string range = cat("[", std::to_string(lo), ", ", std::to_string(hi), "]");
    if (!j.is_number_integer()) {
        const std::string what = j.is_number() ? "number" : j.type_name();
        r.fail_at(path, cat("must be an integer in ", range, ", got ", what, " ", shown(j)));
    }
    const double v = j.get<double>();  // exact for any sane value; unsigned 64-bit giants stay out of range
    if (v < static_cast<double>(lo) || v > static_cast<double>(hi))
        r.fail_at(path, cat("must be an integer in ", range, ", got ", shown(j)));
    return static_cast<int>(j.get<long long>());
}

// A garment parameter against its spec (the same range validate(TubeParams) checks). A
// real is also checked as the Real the builder will hold, so that nothing the file
// passes is refused later for rounding (1e-50 is 0 as a float).
double read_parameter(const Reader& r, const std::string& path, const Json& j, const ParameterSpec& spec) {
    const std::string range = spec.range.text();
    if (spec.kind == ParameterKind::integer) {
        if (!j.is_number_integer()) {
            const std::string what = j.is_number() ? "number" : j.type_name();
            r.fail_at(path, cat("must be an integer in ", range, ", got ", what, " ", shown(j)));
        }
        const double v = j.get<double>();  // exact for any sane value; unsigned 64-bit giants stay out of range
        if (!spec.range.contains(v)) r.fail_at(path, cat("must be an integer in ", range, ", got ", shown(j)));
        return v;
    }
    if (!j.is_number()) r.fail_at(path, cat("must be a number in ", range, ", got ", typed(j)));
    const double v = j.get<double>();
    if (!std::isfinite(v)) r.fail_at(path, cat("must be a finite number, got ", shown(j)));
    const bool fits_real = std::abs(v) <= double(std::numeric_limits<Real>::max()) && spec.range.contains(double(static_cast<Real>(v)));
    if (!spec.range.contains(v) || !fits_real) r.fail_at(path, cat("must be a number in ", range, ", got ", shown(j)));
    return v;
}

bool read_bool(const Reader& r, const std::string& path, const Json& j) {
    if (!j.is_boolean()) r.fail_at(path, cat("must be true or false, got ", typed(j)));
    return j.get<bool>();
}

std::string read_string(const Reader& r, const std::string& path, const Json& j, bool allow_empty = true) {
    if (!j.is_string()) r.fail_at(path, cat("must be a string, got ", typed(j)));
    std::string s = j.get<std::string>();
    if (!allow_empty && s.empty()) r.fail_at(path, "must not be empty");
    return s;
}

Vec3 read_vec3(const Reader& r, const std::string& path, const Json& j, double lo, double hi, Bound lower = Bound::closed) {
    if (!j.is_array() || j.size() != 3)
        r.fail_at(path, cat("must be an array of 3 numbers [x, y, z], got ", typed(j)));
    Vec3 v;
    for (int i = 0; i < 3; ++i) v[i] = static_cast<Real>(read_real(r, element_path(path, i), j[i], lo, hi, lower));
    return v;
}

template <class E>
E read_choice(const Reader& r, const std::string& path, const Json& j, std::initializer_list<std::pair<std::string_view, E>> choices) {
    std::string names;
    for (const auto& [name, value] : choices) names += cat(names.empty() ? "\"" : ", \"", name, "\"");
    if (!j.is_string()) r.fail_at(path, cat("must be one of ", names, ", got ", typed(j)));
    const std::string s = j.get<std::string>();
    for (const auto& [name, value] : choices)
        if (s == name) return value;
    r.fail_at(path, cat("must be one of ", names, ", got ", shown(j)));
}

const Json& read_array(const Reader& r, const std::string& path, const Json& j) {
    if (!j.is_array()) r.fail_at(path, cat("must be an array ([...]), got ", typed(j)));
    if (j.size() > max_list) r.fail_at(path, cat("more than ", std::to_string(max_list), " entries (", std::to_string(j.size()), ")"));
    return j;
}

// ---------------------------------------------------------------------------------------
// Sections.
CharacterDescription read_character(const Reader& r, const std::string& path, const Json& j) {
    Fields f(r, j, path);
    CharacterDescription c;
    const std::string file_path = f.path("file");
    const std::string file = read_string(r, file_path, f.require("file"), false);
    c.file = file;
    if (c.file.is_relative() && !r.base_dir().empty()) c.file = r.base_dir() / c.file;
    c.file = c.file.lexically_normal();
    c.where = r.where(file_path);
    std::error_code ec;
    const auto status = std::filesystem::status(c.file, ec);
    if (!std::filesystem::exists(status)) r.fail_at(file_path, cat("no such file: ", c.file.string()));
    if (!std::filesystem::is_regular_file(status)) r.fail_at(file_path, cat("not a regular file: ", c.file.string()));
    if (const Json* clip = f.get("clip")) {
        if (clip->is_number_integer())
            c.clip = std::to_string(read_int(r, f.path("clip"), *clip, 0, 100000));
        else if (clip->is_string())
            c.clip = clip->get<std::string>();
        else
            r.fail_at(f.path("clip"), cat("must be a clip name (string) or index (integer >= 0), got ", typed(*clip)));
    }
    if (const Json* v = f.get("scale")) c.scale = static_cast<Real>(read_real(r, f.path("scale"), *v, 0, 1000, Bound::open));
    if (const Json* v = f.get("position_m")) c.position_m = read_vec3(r, f.path("position_m"), *v, -max_coordinate_m, max_coordinate_m);
    if (const Json* v = f.get("rotation_deg")) c.rotation_deg = read_vec3(r, f.path("rotation_deg"), *v, -3600, 3600);
    if (const Json* v = f.get("speed")) c.speed = read_real(r, f.path("speed"), *v, 0, 100);
    if (const Json* v = f.get("in_place")) c.in_place = read_bool(r, f.path("in_place"), *v);
    if (const Json* v = f.get("start_s")) c.start_s = read_real(r, f.path("start_s"), *v, 0, 100000);
    if (const Json* v = f.get("hide_modelled_garments")) c.hide_modelled_garments = read_bool(r, f.path("hide_modelled_garments"), *v);
    if (const Json* v = f.get("thicken_thin_trunk_m")) c.thicken_thin_trunk_m = read_real(r, f.path("thicken_thin_trunk_m"), *v, 0, 0.1);
    if (const Json* v = f.get("motion")) {
        const std::string motion_path = f.path("motion");
        c.motion = read_string(r, motion_path, *v, false);
        if (c.motion.is_relative() && !r.base_dir().empty()) c.motion = r.base_dir() / c.motion;
        c.motion = c.motion.lexically_normal();
        std::error_code ec;
        if (!std::filesystem::is_regular_file(c.motion, ec)) r.fail_at(motion_path, cat("no such file: ", c.motion.string()));
        if (c.motion.extension() != ".bvh" && c.motion.extension() != ".BVH")
            r.fail_at(motion_path, cat("must be a .bvh file, got ", c.motion.string()));
        if (f.get("clip")) r.fail_at(motion_path, "give either clip or motion, not both");
    }
    if (const Json* v = f.get("motion_bones")) {
        if (!v->is_object()) r.fail_at(f.path("motion_bones"), cat("must be an object of joint names to bone names, got ", typed(*v)));
        else
            for (const auto& [joint, bone] : v->items()) {
                if (!bone.is_string()) r.fail_at(f.path("motion_bones") + "." + joint, cat("must be a bone name (string), got ", typed(bone)));
                else c.motion_bones.emplace_back(joint, bone.get<std::string>());
            }
    }
    f.finish();
    return c;
}

GarmentDescription read_garment(const Reader& r, const std::string& path, const Json& j, std::size_t characters) {
    Fields f(r, j, path);
    GarmentDescription g;
    g.where = r.where(path);
    if (const Json* v = f.get("type"))
        g.type = read_choice<GarmentType>(r, f.path("type"), *v, {{"skirt", GarmentType::skirt}, {"dress", GarmentType::dress}});
    if (const Json* v = f.get("character"))
        g.character = read_int(r, f.path("character"), *v, 0, static_cast<long long>(characters) - 1);
    if (const Json* v = f.get("model"))
        g.model = read_choice<ClothModel>(r, f.path("model"), *v,
                                          {{"simplified", ClothModel::simplified}, {"classic", ClothModel::classic}});
    if (const Json* v = f.get("integrator"))
        g.integrator = read_choice<ClothIntegrator>(r, f.path("integrator"), *v,
                                                    {{"shipped", ClothIntegrator::shipped}, {"paper", ClothIntegrator::paper}});
    if (const Json* v = f.get("warp_solve"))
        g.warp_solve = read_choice<WarpSolve>(r, f.path("warp_solve"), *v, {{"rounds", WarpSolve::rounds}, {"lines", WarpSolve::lines}});
    if (const Json* v = f.get("pin_weights"))
        g.pin_weights = read_choice<PinWeights>(r, f.path("pin_weights"), *v,
                                                {{"nearest_vertex", PinWeights::nearest_vertex}, {"skin_surface", PinWeights::skin_surface}});
    if (const Json* v = f.get("collision"))
        g.collision = read_choice<CollisionMode>(r, f.path("collision"), *v,
                                                 {{"lists", CollisionMode::candidate_lists}, {"brute_force", CollisionMode::brute_force}});
    if (const Json* v = f.get("color")) g.color = read_vec3(r, f.path("color"), *v, 0, 1);
    if (const Json* v = f.get("material")) {
        std::string names;
        for (const MaterialPreset& preset : material_presets()) names += cat(names.empty() ? "\"" : ", \"", preset.name, "\"");
        if (!v->is_string() || !material_preset(v->get<std::string>()))
            r.fail_at(f.path("material"), cat("must be one of ", names, ", got ", v->is_string() ? shown(*v) : typed(*v)));
        g.material = v->get<std::string>();
    }
    for (const ParameterSpec* spec : scene_garment_parameters()) {
        const Json* v = f.get(spec->name);
        if (v == nullptr) continue;
        g.parameters.push_back({std::string(spec->name), read_parameter(r, f.path(spec->name), *v, *spec)});  // in table order
    }
    // A garment from a file: its mesh, where it is held, its grid's spacing.
    if (const Json* v = f.get("file")) {
        g.file = read_string(r, f.path("file"), *v, false);
        if (g.file.is_relative() && !r.base_dir().empty()) g.file = r.base_dir() / g.file;
        if (j.contains("type")) r.fail_at(f.path("type"), "give either type (a built-in garment) or file, not both", true);
    }
    if (const Json* v = f.get("mesh")) g.mesh = read_string(r, f.path("mesh"), *v, false);
    if (const Json* v = f.get("pins"))
        g.pins = read_choice<PinSource>(r, f.path("pins"), *v, {{"file", PinSource::file}, {"painted", PinSource::painted}, {"auto", PinSource::automatic}});
    if (const Json* v = f.get("spacing_m")) g.spacing_m = read_real(r, f.path("spacing_m"), *v, 0, 1);
    if (const Json* v = f.get("modelled_on"))
        g.modelled_on = read_choice<GarmentPose>(r, f.path("modelled_on"), *v,
                                                 {{"posed", GarmentPose::current}, {"bind", GarmentPose::bind}});
    for (const char* key : {"mesh", "pins", "spacing_m", "modelled_on"})
        if (g.file.empty() && j.contains(key)) r.fail_at(f.path(key), "applies to a garment from a file (give \"file\")", true);
    // Before a skirt and a dress shared one set of names, the ring height had one per type.
    for (const auto& [former, now] : {std::pair{"waist_height_fraction", "ring_height_fraction"}, {"waist_height_m", "ring_height_m"},
                                      {"shoulder_height_fraction", "ring_height_fraction"}, {"shoulder_height_m", "ring_height_m"}})
        if (j.contains(former))
            r.fail_at(f.path(former), cat("renamed ", now, " (the ring is the waist of a skirt, the shoulders of a dress)"), true);
    f.finish();
    // The grid size, however it was given.
    auto param = [&](std::string_view name) -> const GarmentParameter* {
        for (const GarmentParameter& p : g.parameters)
            if (p.name == name) return &p;
        return nullptr;
    };
    if (param("particles") && (param("warp_lines") || param("particles_per_line")))
        r.fail_at(f.path("particles"), "give either particles or warp_lines and particles_per_line, not both");
    if (const GarmentParameter *w = param("warp_lines"), *m = param("particles_per_line"); w && m && w->value * m->value > max_scene_particles)
        r.fail_at(f.path("warp_lines"), cat("warp_lines x particles_per_line must be at most ", std::to_string(max_scene_particles),
                                            " particles, got ", std::to_string(static_cast<long long>(w->value) * static_cast<long long>(m->value))));
    return g;
}

ColliderOverride read_collider(const Reader& r, const std::string& path, const Json& j, std::size_t characters) {
    Fields f(r, j, path);
    ColliderOverride c;
    if (const Json* v = f.get("character"))
        c.character = read_int(r, f.path("character"), *v, 0, static_cast<long long>(characters) - 1);
    c.bone = read_string(r, f.path("bone"), f.require("bone"), false);
    c.where = r.where(f.path("bone"));
    if (const Json* v = f.get("remove")) c.remove = read_bool(r, f.path("remove"), *v);
    if (const Json* v = f.get("center_m")) c.center_m = read_vec3(r, f.path("center_m"), *v, -10, 10);
    if (const Json* v = f.get("radii_m")) c.radii_m = read_vec3(r, f.path("radii_m"), *v, 0, 10, Bound::open);
    if (const Json* v = f.get("rotation_deg")) c.rotation_deg = read_vec3(r, f.path("rotation_deg"), *v, -3600, 3600);
    if (const Json* v = f.get("give_m")) c.give_m = static_cast<Real>(read_real(r, f.path("give_m"), *v, 0, 0.5));
    if (c.remove && (c.center_m || c.radii_m || c.rotation_deg || c.give_m))
        r.fail_at(f.path("remove"), "an override either removes the bone's ellipsoid or reshapes it, not both");
    if (!c.remove && !c.center_m && !c.radii_m && !c.rotation_deg && !c.give_m)
        r.fail_at(path, "sets nothing: give center_m, radii_m, rotation_deg or give_m, or \"remove\": true");
    f.finish();
    return c;
}

SolverDescription read_solver(const Reader& r, const Json& j) {
    Fields f(r, j, "solver");
    SolverDescription s;
    if (const Json* v = f.get("fixed_dt_s")) s.fixed_dt_s = read_real(r, f.path("fixed_dt_s"), *v, 0, 1, Bound::open);
    if (const Json* v = f.get("max_steps_per_frame")) s.max_steps_per_frame = read_int(r, f.path("max_steps_per_frame"), *v, 1, 1000);
    if (const Json* v = f.get("time_scale")) s.time_scale = read_real(r, f.path("time_scale"), *v, 0, 1000);
    if (const Json* v = f.get("substeps")) {
        if (v->is_string() && v->get<std::string>() == "auto")
            s.substeps = 0;
        else if (v->is_number_integer())
            s.substeps = read_int(r, f.path("substeps"), *v, 1, 1000);
        else
            r.fail_at(f.path("substeps"), cat("must be \"auto\" or an integer in [1, 1000], got ", shown(*v)));
    }
    if (const Json* v = f.get("max_surface_travel_m"))
        s.max_surface_travel_m = read_real(r, f.path("max_surface_travel_m"), *v, 0, 1, Bound::open);
    if (const Json* v = f.get("max_substeps")) s.max_substeps = read_int(r, f.path("max_substeps"), *v, 1, 1000);
    if (const Json* v = f.get("max_frame_dt_s")) s.max_frame_dt_s = read_real(r, f.path("max_frame_dt_s"), *v, 0, 10, Bound::open);
    if (const Json* v = f.get("teleport_threshold_m"))
        s.teleport_threshold_m = read_real(r, f.path("teleport_threshold_m"), *v, 0, max_coordinate_m, Bound::open);
    if (const Json* v = f.get("threads")) s.threads = read_int(r, f.path("threads"), *v, 0, 1024);
    if (const Json* v = f.get("settle_s")) s.settle_s = read_real(r, f.path("settle_s"), *v, 0, 10);
    f.finish();
    return s;
}

CameraDescription read_camera(const Reader& r, const Json& j) {
    Fields f(r, j, "camera");
    CameraDescription c;
    if (const Json* v = f.get("follow")) c.follow = read_bool(r, f.path("follow"), *v);
    if (const Json* v = f.get("target_m")) c.target_m = read_vec3(r, f.path("target_m"), *v, -max_coordinate_m, max_coordinate_m);
    if (const Json* v = f.get("distance_m")) c.distance_m = static_cast<Real>(read_real(r, f.path("distance_m"), *v, 0.3, 50));
    if (const Json* v = f.get("yaw_deg")) c.yaw_deg = static_cast<Real>(read_real(r, f.path("yaw_deg"), *v, -3600, 3600));
    if (const Json* v = f.get("pitch_deg")) c.pitch_deg = static_cast<Real>(read_real(r, f.path("pitch_deg"), *v, -89, 89));
    if (const Json* v = f.get("fov_deg")) c.fov_deg = static_cast<Real>(read_real(r, f.path("fov_deg"), *v, 5, 150));
    f.finish();
    return c;
}

SceneDescription read_scene(const Reader& r, const Json& j) {
    Fields f(r, j, "");
    SceneDescription scene;
    if (const Json* v = f.get("description")) scene.description = read_string(r, "description", *v);
    const Json& characters = read_array(r, "characters", f.require("characters"));
    if (characters.empty()) r.fail_at("characters", "must list at least one character");
    for (std::size_t i = 0; i < characters.size(); ++i)
        scene.characters.push_back(read_character(r, element_path("characters", i), characters[i]));
    if (const Json* v = f.get("garments")) {
        const Json& garments = read_array(r, "garments", *v);
        for (std::size_t i = 0; i < garments.size(); ++i)
            scene.garments.push_back(read_garment(r, element_path("garments", i), garments[i], scene.characters.size()));
    }
    if (const Json* v = f.get("colliders")) {
        const Json& colliders = read_array(r, "colliders", *v);
        for (std::size_t i = 0; i < colliders.size(); ++i)
            scene.colliders.push_back(read_collider(r, element_path("colliders", i), colliders[i], scene.characters.size()));
    }
    if (const Json* v = f.get("ground")) scene.ground = read_bool(r, "ground", *v);
    if (const Json* v = f.get("solver")) scene.solver = read_solver(r, *v);
    if (const Json* v = f.get("camera")) scene.camera = read_camera(r, *v);
    f.finish();
    return scene;
}

// "[json.exception.parse_error.101] parse error at line 3, column 5: syntax error ..." -> "syntax error ..."
std::string parse_error_reason(const Json::parse_error& e) {
    std::string what = e.what();
    if (const std::size_t column = what.find("column "); column != std::string::npos)
        if (const std::size_t colon = what.find(": ", column); colon != std::string::npos) return what.substr(colon + 2);
    return what;
}

using OrderedJson = nlohmann::ordered_json;  // written files keep a readable field order

OrderedJson vec(const Vec3& v) { return OrderedJson::array({v.x(), v.y(), v.z()}); }

}  // namespace

Result<SceneDescription> parse_scene(std::string_view text, std::string_view label, const std::filesystem::path& base_dir) {
    const std::string name(label);
    Json j;
    try {
        j = Json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/true, /*ignore_comments=*/true);
    } catch (const Json::parse_error& e) {
        // e.byte is 1-based: the position of the character that broke the syntax.
        const auto [line, column] = line_column(text, e.byte > 0 ? e.byte - 1 : 0);
        const SourceLocation where = name.empty() ? SourceLocation{} : SourceLocation{name, line, column};
        return fail(located(where, "", parse_error_reason(e)));
    } catch (const Json::exception& e) {
        // Number overflow ("1e400") carries no position: find the literal it quotes.
        const std::string what = e.what();
        std::size_t offset = 0;
        if (const std::size_t open = what.find(" '"); open != std::string::npos)
            if (const std::size_t close = what.find('\'', open + 2); close != std::string::npos)
                if (const std::size_t at = text.find(std::string_view(what).substr(open + 2, close - open - 2)); at != std::string_view::npos)
                    offset = at;
        const auto [line, column] = line_column(text, offset);
        const SourceLocation where = name.empty() ? SourceLocation{} : SourceLocation{name, line, column};
        const std::size_t bracket = what.find("] ");
        return fail(located(where, "", (bracket == std::string::npos ? what : what.substr(bracket + 2)) +
                                           " (numbers must be finite and fit a double)"));
    }
    Positions positions;
    if (auto problem = PositionScanner(text).scan(positions)) {
        const auto [line, column] = line_column(text, problem->offset);
        const SourceLocation where = name.empty() ? SourceLocation{} : SourceLocation{name, line, column};
        return fail(located(where, problem->field, problem->reason));
    }
    try {
        const Reader reader(name, text, std::move(positions), base_dir);
        return read_scene(reader, j);
    } catch (const SceneError& e) {
        return fail(e.message);
    } catch (const Json::exception& e) {  // a conversion the checks above missed: still one line
        return fail(located(name.empty() ? SourceLocation{} : SourceLocation{name, 0, 0}, "", e.what()));
    }
}

Result<SceneDescription> load_scene_file(const std::filesystem::path& file) {
    std::error_code ec;
    if (!std::filesystem::exists(file, ec)) return fail(file.string() + ": no such scene file");
    if (std::filesystem::is_directory(file, ec)) return fail(file.string() + ": is a folder, not a scene file");
    std::ifstream in(file, std::ios::binary);
    if (!in) return fail(file.string() + ": cannot open for reading");
    std::ostringstream buffer;
    buffer << in.rdbuf();
    if (in.bad()) return fail(file.string() + ": read error");
    const std::string text = buffer.str();
    return parse_scene(text, file.string(), file.parent_path());
}

Result<void> validate(const SceneDescription& scene) {
    auto parsed = parse_scene(to_json(scene), "", {});
    if (!parsed) return std::unexpected(parsed.error());
    return {};
}

std::string to_json(const SceneDescription& scene) {
    OrderedJson j = OrderedJson::object();
    if (!scene.description.empty()) j["description"] = scene.description;
    OrderedJson characters = OrderedJson::array();
    for (const CharacterDescription& c : scene.characters) {
        OrderedJson o;
        o["file"] = c.file.string();
        if (!c.clip.empty()) {
            const bool index = std::all_of(c.clip.begin(), c.clip.end(), [](char ch) { return ch >= '0' && ch <= '9'; }) && c.clip.size() < 7;
            if (index)
                o["clip"] = std::stoi(c.clip);
            else
                o["clip"] = c.clip;
        }
        o["scale"] = c.scale;
        o["position_m"] = vec(c.position_m);
        o["rotation_deg"] = vec(c.rotation_deg);
        o["speed"] = c.speed;
        o["in_place"] = c.in_place;
        if (c.start_s != 0) o["start_s"] = c.start_s;
        if (!c.hide_modelled_garments) o["hide_modelled_garments"] = false;
        if (c.thicken_thin_trunk_m != default_thicken_thin_trunk_m) o["thicken_thin_trunk_m"] = c.thicken_thin_trunk_m;
        if (!c.motion.empty()) o["motion"] = c.motion.string();
        if (!c.motion_bones.empty()) {
            OrderedJson bones = OrderedJson::object();
            for (const auto& [joint, bone] : c.motion_bones) bones[joint] = bone;
            o["motion_bones"] = std::move(bones);
        }
        characters.push_back(std::move(o));
    }
    j["characters"] = std::move(characters);
    OrderedJson garments = OrderedJson::array();
    for (const GarmentDescription& g : scene.garments) {
        OrderedJson o;
        if (g.file.empty()) o["type"] = garment_type_name(g.type);
        else {
            o["file"] = g.file.string();
            if (!g.mesh.empty()) o["mesh"] = g.mesh;
            o["pins"] = g.pins == PinSource::painted ? "painted" : g.pins == PinSource::automatic ? "auto" : "file";
            if (g.spacing_m > 0) o["spacing_m"] = g.spacing_m;
            if (g.modelled_on == GarmentPose::bind) o["modelled_on"] = "bind";
        }
        o["character"] = g.character;
        o["model"] = cloth_model_name(g.model);
        if (g.integrator != ClothIntegrator::shipped) o["integrator"] = cloth_integrator_name(g.integrator);
        if (g.warp_solve != WarpSolve::rounds) o["warp_solve"] = "lines";
        if (g.pin_weights != PinWeights::nearest_vertex) o["pin_weights"] = "skin_surface";
        o["collision"] = collision_mode_name(g.collision);
        if (g.color) o["color"] = vec(*g.color);
        if (!g.material.empty()) o["material"] = g.material;
        for (const GarmentParameter& p : g.parameters) {
            const auto specs = scene_garment_parameters();
            const auto spec = std::find_if(specs.begin(), specs.end(), [&](const ParameterSpec* s) { return s->name == p.name; });
            if (spec != specs.end() && (*spec)->kind == ParameterKind::integer)
                o[p.name] = static_cast<long long>(std::llround(p.value));
            else
                o[p.name] = p.value;
        }
        garments.push_back(std::move(o));
    }
    j["garments"] = std::move(garments);
    if (!scene.colliders.empty()) {
        OrderedJson colliders = OrderedJson::array();
        for (const ColliderOverride& c : scene.colliders) {
            OrderedJson o;
            o["character"] = c.character;
            o["bone"] = c.bone;
            if (c.remove) o["remove"] = true;
            if (c.center_m) o["center_m"] = vec(*c.center_m);
            if (c.radii_m) o["radii_m"] = vec(*c.radii_m);
            if (c.rotation_deg) o["rotation_deg"] = vec(*c.rotation_deg);
            if (c.give_m) o["give_m"] = *c.give_m;
            colliders.push_back(std::move(o));
        }
        j["colliders"] = std::move(colliders);
    }
    j["ground"] = scene.ground;
    const SolverDescription& s = scene.solver;
    j["solver"] = {{"fixed_dt_s", s.fixed_dt_s},
                   {"max_steps_per_frame", s.max_steps_per_frame},
                   {"time_scale", s.time_scale},
                   {"substeps", s.substeps == 0 ? OrderedJson("auto") : OrderedJson(s.substeps)},
                   {"max_surface_travel_m", s.max_surface_travel_m},
                   {"max_substeps", s.max_substeps},
                   {"max_frame_dt_s", s.max_frame_dt_s},
                   {"teleport_threshold_m", s.teleport_threshold_m},
                   {"threads", s.threads},
                   {"settle_s", s.settle_s}};
    const CameraDescription& c = scene.camera;
    j["camera"] = {{"follow", c.follow},       {"target_m", vec(c.target_m)}, {"distance_m", c.distance_m},
                   {"yaw_deg", c.yaw_deg},     {"pitch_deg", c.pitch_deg},   {"fov_deg", c.fov_deg}};
    return j.dump(2) + "\n";
}

}  // namespace drape

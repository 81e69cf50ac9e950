// Fitted bodies kept on disk: see body_cache.hpp.
#include "drape/systems/character/body_cache.hpp"

#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

namespace drape {

namespace fs = std::filesystem;

namespace {

// A new field in any of these must be written and read below (and the format's version
// raised); the sizes (with Eigen's alignment on x86-64) catch one added without that.
static_assert(sizeof(FitOptions) == 104, "body_cache.cpp: add the new FitOptions field to the key");
static_assert(sizeof(EllipsoidShape) == 64, "body_cache.cpp: write and read the new EllipsoidShape field");
static_assert(sizeof(BodyPoint) == 28, "body_cache.cpp: write and read the new BodyPoint field");
static_assert(sizeof(BodySection) == 40, "body_cache.cpp: write and read the new BodySection field");
static_assert(sizeof(BodyLandmarks) == 432, "body_cache.cpp: write and read the new BodyLandmarks field");
static_assert(sizeof(CharacterBody) == 528, "body_cache.cpp: write and read the new CharacterBody field");
constexpr std::string_view magic = "drape fitted body 3\n";
constexpr std::size_t encoded_ellipsoid_bytes = 4 + 12 + 16 + 12 + 1 + 4;  // as body_fields() lists one

std::string number(double v) {
    char buffer[64];
    const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, v);
    return ec == std::errc() ? std::string(buffer, end) : "?";
}

std::int64_t mtime_ns(const fs::path& p, std::error_code& ec) {
    const auto t = fs::last_write_time(p, ec);
    return std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
}

std::optional<std::string> read_all(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    if (!in) return std::nullopt;
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) return std::nullopt;
    return bytes;
}

// Writes the fields body_fields() lists.
class Writer {
public:
    template <class T>
    void raw(const T& v) {
        static_assert(std::is_arithmetic_v<T> || std::is_enum_v<T>);
        out.append(reinterpret_cast<const char*>(&v), sizeof v);
    }
    template <class V, class F>
    void items(const V& v, std::size_t /*item_bytes*/, F&& each) {
        raw(static_cast<std::uint32_t>(v.size()));
        for (const auto& item : v) each(item);
    }
    template <class O, class F>
    void maybe(const O& o, F&& each) {
        raw(static_cast<std::uint8_t>(o.has_value()));
        if (o) each(*o);
    }
    void text(const std::string& s) {
        raw(static_cast<std::uint32_t>(s.size()));
        out += s;
    }
    std::string out;
};

// Reads them back; a file too short or too long for them is not a body.
class Reader {
public:
    explicit Reader(std::string_view in) : m_in(in) {}
    template <class T>
    void raw(T& v) {
        static_assert(std::is_arithmetic_v<T> || std::is_enum_v<T>);
        v = T{};
        if (m_in.size() < sizeof v) {
            m_ok = false;
            return;
        }
        std::memcpy(&v, m_in.data(), sizeof v);
        m_in.remove_prefix(sizeof v);
    }
    template <class V, class F>
    void items(V& v, std::size_t item_bytes, F&& each) {
        v.resize(count(item_bytes));
        for (auto& item : v) each(item);
    }
    template <class O, class F>
    void maybe(O& o, F&& each) {
        std::uint8_t present = 0;
        raw(present);
        if (present) each(o.emplace());
    }
    void text(std::string& s) {
        const std::uint32_t n = count(1);
        s.assign(m_in.substr(0, n));
        m_in.remove_prefix(n);
    }
    [[nodiscard]] bool done() const { return m_ok && m_in.empty(); }

private:
    std::uint32_t count(std::size_t item_bytes) {
        std::uint32_t n = 0;
        raw(n);
        if (std::size_t(n) * item_bytes > m_in.size()) {
            m_ok = false;
            return 0;
        }
        return n;
    }
    std::string_view m_in;
    bool m_ok = true;
};

template <class Io, class V>
void vec3(Io& io, V& v) {
    for (int i = 0; i < 3; ++i) io.raw(v[i]);
}

template <class Io, class P>
void point(Io& io, P& p) {
    io.raw(p.bone);
    vec3(io, p.rest_m);
    vec3(io, p.local_m);
}

template <class Io, class S>
void section(Io& io, S& s) {
    point(io, s.center);
    io.raw(s.half_width_m);
    io.raw(s.half_depth_m);
    io.raw(s.girth_m);
}

// A body's fields in the file's order, one list for writing and reading (Body is
// CharacterBody or const CharacterBody): a number or an enum as its bytes, a vector or a
// string as its size and its items, an optional as a flag and its value.
template <class Io, class Body>
void body_fields(Io& io, Body& body) {
    io.items(body.ellipsoids, encoded_ellipsoid_bytes, [&](auto& s) {
        io.raw(s.bone);
        vec3(io, s.center);
        for (int i = 0; i < 4; ++i) io.raw(s.rotation.coeffs()[i]);
        vec3(io, s.radii_m);
        io.raw(s.region);
        io.raw(s.give_m);
    });
    io.raw(body.hip_bone);
    io.raw(body.legs);
    io.maybe(body.landmarks, [&](auto& l) {
        vec3(io, l.up);
        vec3(io, l.forward);
        vec3(io, l.left);
        io.raw(l.floor_m);
        io.raw(l.top_m);
        io.raw(l.height_m);
        io.raw(l.pelvis_bone);
        io.items(l.spine, sizeof(int), [&](auto& bone) { io.raw(bone); });
        io.raw(l.chest_bone);
        io.raw(l.head_bone);
        for (auto* c : {&l.left_leg, &l.right_leg, &l.left_arm, &l.right_arm}) {
            io.raw(c->root);
            io.raw(c->middle);
            io.raw(c->end);
        }
        io.items(l.body_bones, sizeof(int), [&](auto& bone) { io.raw(bone); });
        io.raw(l.crotch_m);
        io.raw(l.underarm_m);
        point(io, l.arms_meet_trunk);
        section(io, l.waist);
        section(io, l.hips);
        section(io, l.chest);
        point(io, l.left_shoulder);
        point(io, l.right_shoulder);
        io.text(l.found_by);
        io.items(l.how_found, 2 * sizeof(std::uint32_t), [&](auto& how) {
            io.text(how.first);
            io.text(how.second);
        });
    });
    io.text(body.landmarks_error);
    io.items(body.left_out, sizeof(std::size_t) + 1 + sizeof(std::uint32_t), [&](auto& m) {
        io.raw(m.mesh);
        io.raw(m.garment);
        io.text(m.why);
    });
}

std::string encode(const CharacterBody& body) {
    Writer w;
    body_fields(w, body);
    return w.out;
}

std::optional<CharacterBody> decode(std::string_view bytes) {
    Reader r(bytes);
    CharacterBody body;
    body_fields(r, body);
    if (!r.done()) return std::nullopt;
    return body;
}

}  // namespace

std::optional<BodyCacheKey> body_cache_key(const fs::path& character_file, const FitOptions& options) {
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (ec) return std::nullopt;
    const auto exe_size = fs::file_size(exe, ec);
    if (ec) return std::nullopt;
    const auto exe_time = mtime_ns(exe, ec);
    if (ec) return std::nullopt;
    const fs::path file = fs::absolute(character_file, ec).lexically_normal();
    if (ec) return std::nullopt;
    const auto bytes = read_all(file);
    if (!bytes) return std::nullopt;

    std::ostringstream key;
    key << magic << "program " << exe.string() << ' ' << exe_size << ' ' << exe_time << '\n';
    key << "file " << file.string() << ' ' << bytes->size() << ' ' << std::hash<std::string_view>{}(*bytes) << '\n';
    // The files beside it (a .gltf's buffers, an .fbx's textures), by size and time.
    std::vector<std::string> beside;
    for (const fs::directory_entry& entry : fs::directory_iterator(file.parent_path(), ec)) {
        std::error_code entry_ec;
        if (!entry.is_regular_file(entry_ec) || entry.path() == file) continue;
        const auto size = entry.file_size(entry_ec);
        const auto time = mtime_ns(entry.path(), entry_ec);
        if (entry_ec) return std::nullopt;
        beside.push_back(entry.path().filename().string() + ' ' + std::to_string(size) + ' ' + std::to_string(time));
    }
    if (ec) return std::nullopt;
    std::sort(beside.begin(), beside.end());
    for (const std::string& b : beside) key << "beside " << b << '\n';
    key << "options " << number(options.min_cluster_fraction) << ' ' << number(options.min_cluster_size) << ' '
        << number(options.tolerance_m) << ' ' << number(options.bulge_limit_m) << ' ' << number(options.target_coverage) << ' '
        << number(options.sample_spacing) << ' ' << number(options.min_radius_m) << ' ' << options.max_ellipsoids << ' '
        << options.tight_extra_ellipsoids << ' ' << number(options.leg_reach_m) << ' ' << number(options.arm_reach_m) << ' ' << int(options.legs) << ' '
        << number(options.knee_radius_share) << ' ' << number(options.thicken_thin_trunk_m) << '\n';
    const std::size_t threads = std::min(static_cast<std::size_t>(tbb::this_task_arena::max_concurrency()),
                                         tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
    key << "threads " << threads << '\n';

    BodyCacheKey out;
    out.text = key.str();
    char name[32];
    const auto [end, to_ec] = std::to_chars(name, name + sizeof name, std::hash<std::string_view>{}(out.text), 16);
    out.name = file.stem().string() + '-' + std::string(name, to_ec == std::errc() ? end : name) + ".body";
    return out;
}

std::optional<CharacterBody> read_cached_body(const fs::path& folder, const BodyCacheKey& key) {
    const auto bytes = read_all(folder / key.name);
    if (!bytes || bytes->size() < key.text.size() || std::string_view(*bytes).substr(0, key.text.size()) != key.text)
        return std::nullopt;
    return decode(std::string_view(*bytes).substr(key.text.size()));
}

bool write_cached_body(const fs::path& folder, const BodyCacheKey& key, const CharacterBody& body) {
    std::error_code ec;
    fs::create_directories(folder, ec);
    if (ec) return false;
    const fs::path target = folder / key.name;
    const fs::path temporary = folder / (key.name + ".tmp" + std::to_string(::getpid()));
    {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        out << key.text << encode(body);
        if (!out.flush()) {
            fs::remove(temporary, ec);
            return false;
        }
    }
    fs::rename(temporary, target, ec);
    if (!ec) return true;
    fs::remove(temporary, ec);
    return false;
}

Result<CharacterBody> fit_character_body(const CharacterAsset& character, const fs::path& file, const FitOptions& options,
                                         const fs::path& folder) {
    std::optional<BodyCacheKey> key;
    if (!folder.empty()) key = body_cache_key(file, options);
    if (key) {
        if (auto body = read_cached_body(folder, *key)) return std::move(*body);
    }
    auto body = fit_character_body(character, options);
    if (body && key) (void)write_cached_body(folder, *key, *body);
    return body;
}

fs::path body_cache_from_environment() {
    const char* folder = std::getenv("DRAPE_BODY_CACHE");
    return folder != nullptr ? fs::path(folder) : fs::path();
}

}  // namespace drape

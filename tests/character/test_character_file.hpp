// Writes small, fully known glTF characters for tests: a column of vertex rings skinned to
// a two-bone chain ("Root" at the origin, "Child" one unit up), with one clip ("Bend")
// that bends the child and moves the root. Options inject the bad inputs the importer
// must reject. Files go to a fresh temporary directory, never into the project.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace drape::test {

struct TestCharacter {
    bool skin = true;                 ///< false: no skeleton
    bool animation = true;            ///< false: no clip
    bool nan_rotation_key = false;
    bool nan_weight = false;
    float weight_sum = 0.8f;          ///< Weights as written (the importer normalises).
    float child_rest_angle_rad = 0;   ///< Node pose of Child about Z; the bind pose stays straight.
    float travel_m = 0.5f;            ///< Root translation along +Z over the clip.
    int rings = 5;                    ///< Vertex rings from y = 0 to y = 2.
    int ring_vertices = 8;
    float radius_m = 0.2f;
    float child_offset_m = 1;         ///< Child's joint above Root's in the node (rest) pose; 0: a zero-length Root.
    bool zero_scale_child_bind = false;  ///< Child's inverse bind matrix scaled to zero.
    float end_bone_offset_m = -1;     ///< >= 0: an unweighted joint "ChildEnd" this far above Child (0: zero length).
    bool zero_scale_end_bind = false; ///< ChildEnd's inverse bind matrix scaled to zero.
};

/// A fresh temporary directory for one test.
inline std::filesystem::path temp_dir(const std::string& name) {
    std::random_device rd;
    const auto dir = std::filesystem::temp_directory_path() / ("drape_test_" + name + "_" + std::to_string(rd()));
    std::filesystem::create_directories(dir);
    return dir;
}

inline std::string base64(const std::vector<std::uint8_t>& data) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < data.size(); i += 3) {
        const std::uint32_t n = (std::uint32_t(data[i]) << 16) | (i + 1 < data.size() ? std::uint32_t(data[i + 1]) << 8 : 0) |
                                (i + 2 < data.size() ? std::uint32_t(data[i + 2]) : 0);
        out += table[(n >> 18) & 63];
        out += table[(n >> 12) & 63];
        out += i + 1 < data.size() ? table[(n >> 6) & 63] : '=';
        out += i + 2 < data.size() ? table[n & 63] : '=';
    }
    return out;
}

/// Vertex positions as written (model space, metres).
inline std::vector<float> test_positions(const TestCharacter& c) {
    std::vector<float> p;
    for (int r = 0; r < c.rings; ++r)
        for (int k = 0; k < c.ring_vertices; ++k) {
            const float a = 2 * float(M_PI) * float(k) / float(c.ring_vertices);
            p.insert(p.end(), {c.radius_m * std::cos(a), 2.0f * float(r) / float(c.rings - 1), c.radius_m * std::sin(a)});
        }
    return p;
}

inline void write_test_character(const TestCharacter& c, const std::filesystem::path& path) {
    std::vector<std::uint8_t> buffer;
    struct View { std::size_t offset, length; };
    std::vector<View> views;
    auto append = [&](const void* data, std::size_t bytes) {
        while (buffer.size() % 4) buffer.push_back(0);
        views.push_back({buffer.size(), bytes});
        const auto* b = static_cast<const std::uint8_t*>(data);
        buffer.insert(buffer.end(), b, b + bytes);
        return views.size() - 1;
    };
    const std::vector<float> positions = test_positions(c);
    const int n = c.rings * c.ring_vertices;
    std::vector<std::uint8_t> joints;
    std::vector<float> weights;
    for (int r = 0; r < c.rings; ++r) {
        const float y = 2.0f * float(r) / float(c.rings - 1);
        const float w1 = y < 0.99f ? 0.f : (y > 1.01f ? 1.f : 0.5f);
        for (int k = 0; k < c.ring_vertices; ++k) {
            joints.insert(joints.end(), {0, 1, 0, 0});
            weights.insert(weights.end(), {(1 - w1) * c.weight_sum, w1 * c.weight_sum, 0, 0});
        }
    }
    if (c.nan_weight) weights[4] = std::numeric_limits<float>::quiet_NaN();  // vertex 1's only weight
    std::vector<std::uint16_t> indices;
    for (int r = 0; r + 1 < c.rings; ++r)
        for (int k = 0; k < c.ring_vertices; ++k) {
            const auto a = std::uint16_t(r * c.ring_vertices + k), b = std::uint16_t(r * c.ring_vertices + (k + 1) % c.ring_vertices);
            const auto a2 = std::uint16_t(a + c.ring_vertices), b2 = std::uint16_t(b + c.ring_vertices);
            indices.insert(indices.end(), {a, a2, b, b, a2, b2});
        }
    // Inverse binds: Root at the origin, Child at y = 1 (straight bind pose), column-major.
    std::vector<float> ibm = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1};
    if (c.zero_scale_child_bind) std::fill(ibm.begin() + 16, ibm.begin() + 32, 0.0f);
    const bool end_bone = c.end_bone_offset_m >= 0;
    if (end_bone) {
        ibm.insert(ibm.end(), {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1 - c.end_bone_offset_m, 0, 1});
        if (c.zero_scale_end_bind) std::fill(ibm.end() - 16, ibm.end(), 0.0f);
    }
    const float times[3] = {0, 0.5f, 1};
    const float s45 = std::sin(float(M_PI) / 8), c45 = std::cos(float(M_PI) / 8);
    float rotations[12] = {0, 0, 0, 1, 0, 0, s45, c45, 0, 0, std::sin(float(M_PI) / 4), std::cos(float(M_PI) / 4)};
    if (c.nan_rotation_key) rotations[6] = std::numeric_limits<float>::quiet_NaN();
    const float translations[9] = {0, 0, 0, 0, 0, c.travel_m / 2, 0, 0, c.travel_m};

    const auto v_pos = append(positions.data(), positions.size() * 4);
    const auto v_joint = append(joints.data(), joints.size());
    const auto v_weight = append(weights.data(), weights.size() * 4);
    const auto v_index = append(indices.data(), indices.size() * 2);
    const auto v_ibm = append(ibm.data(), ibm.size() * 4);
    const auto v_time = append(times, sizeof times);
    const auto v_rot = append(rotations, sizeof rotations);
    const auto v_tr = append(translations, sizeof translations);

    std::string j = "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,2]}],";
    const float ra = c.child_rest_angle_rad / 2;
    j += "\"nodes\":[{\"name\":\"Root\",\"children\":[1]},{\"name\":\"Child\",\"translation\":[0," +
         std::to_string(c.child_offset_m) + ",0],\"rotation\":[0,0," + std::to_string(std::sin(ra)) + "," +
         std::to_string(std::cos(ra)) + "]" + (end_bone ? ",\"children\":[3]" : "") + "},";
    j += std::string("{\"name\":\"Body\",\"mesh\":0") + (c.skin ? ",\"skin\":0" : "") + "}";
    if (end_bone) j += ",{\"name\":\"ChildEnd\",\"translation\":[0," + std::to_string(c.end_bone_offset_m) + ",0]}";
    j += "],";
    if (c.skin) j += std::string("\"skins\":[{\"joints\":[0,1") + (end_bone ? ",3" : "") + "],\"inverseBindMatrices\":4}],";
    j += "\"meshes\":[{\"name\":\"Column\",\"primitives\":[{\"attributes\":{\"POSITION\":0";
    if (c.skin) j += ",\"JOINTS_0\":1,\"WEIGHTS_0\":2";
    j += "},\"indices\":3}]}],";
    if (c.animation)
        j += "\"animations\":[{\"name\":\"Bend\",\"channels\":[{\"sampler\":0,\"target\":{\"node\":1,\"path\":\"rotation\"}},"
             "{\"sampler\":1,\"target\":{\"node\":0,\"path\":\"translation\"}}],\"samplers\":[{\"input\":5,\"output\":6,"
             "\"interpolation\":\"LINEAR\"},{\"input\":5,\"output\":7,\"interpolation\":\"LINEAR\"}]}],";
    const std::string N = std::to_string(n);
    j += "\"accessors\":["
         "{\"bufferView\":" + std::to_string(v_pos) + ",\"componentType\":5126,\"count\":" + N +
         ",\"type\":\"VEC3\",\"min\":[" + std::to_string(-c.radius_m) + ",0," + std::to_string(-c.radius_m) + "],\"max\":[" +
         std::to_string(c.radius_m) + ",2," + std::to_string(c.radius_m) + "]},"
         "{\"bufferView\":" + std::to_string(v_joint) + ",\"componentType\":5121,\"count\":" + N + ",\"type\":\"VEC4\"},"
         "{\"bufferView\":" + std::to_string(v_weight) + ",\"componentType\":5126,\"count\":" + N + ",\"type\":\"VEC4\"},"
         "{\"bufferView\":" + std::to_string(v_index) + ",\"componentType\":5123,\"count\":" + std::to_string(indices.size()) + ",\"type\":\"SCALAR\"},"
         "{\"bufferView\":" + std::to_string(v_ibm) + ",\"componentType\":5126,\"count\":" + std::to_string(ibm.size() / 16) +
         ",\"type\":\"MAT4\"},"
         "{\"bufferView\":" + std::to_string(v_time) + ",\"componentType\":5126,\"count\":3,\"type\":\"SCALAR\",\"min\":[0],\"max\":[1]},"
         "{\"bufferView\":" + std::to_string(v_rot) + ",\"componentType\":5126,\"count\":3,\"type\":\"VEC4\"},"
         "{\"bufferView\":" + std::to_string(v_tr) + ",\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],";
    j += "\"bufferViews\":[";
    for (std::size_t i = 0; i < views.size(); ++i) {
        if (i) j += ",";
        j += "{\"buffer\":0,\"byteOffset\":" + std::to_string(views[i].offset) + ",\"byteLength\":" +
             std::to_string(views[i].length) + "}";
    }
    j += "],\"buffers\":[{\"byteLength\":" + std::to_string(buffer.size()) +
         ",\"uri\":\"data:application/octet-stream;base64," + base64(buffer) + "\"}]}";
    std::ofstream(path, std::ios::binary) << j;
}

}  // namespace drape::test

#include "drape/engine/assets/garment_file.hpp"

#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <system_error>

#include <stb/stb_image.h>  // compiled in Debian's libstb (Drape::stb)
#include <stb/stb_image_write.h>

namespace drape {
namespace {

namespace fs = std::filesystem;

std::string one_line(std::string s) {
    std::replace(s.begin(), s.end(), '\n', ' ');
    while (!s.empty() && (s.back() == ' ' || s.back() == '\r')) s.pop_back();
    return s;
}

// The first node (depth first) that draws mesh `index`, with its transform from the root.
bool find_mesh_node(const aiNode* node, unsigned index, const aiMatrix4x4& parent, aiMatrix4x4& out, const aiNode*& found) {
    const aiMatrix4x4 here = parent * node->mTransformation;
    for (unsigned k = 0; k < node->mNumMeshes; ++k)
        if (node->mMeshes[k] == index) {
            out = here;
            found = node;
            return true;
        }
    for (unsigned c = 0; c < node->mNumChildren; ++c)
        if (find_mesh_node(node->mChildren[c], index, here, out, found)) return true;
    return false;
}

// A mesh's name: the node's that draws it where that node draws several (the parts an
// exporter split one mesh into, one per material, are named after it together), else its
// own, else its node's, else "#index".
std::string mesh_label(const aiScene* scene, unsigned i) {
    aiMatrix4x4 m;
    const aiNode* node = nullptr;
    const bool drawn = find_mesh_node(scene->mRootNode, i, aiMatrix4x4(), m, node);
    if (drawn && node->mNumMeshes > 1 && node->mName.length > 0) return node->mName.C_Str();
    const std::string own = scene->mMeshes[i]->mName.C_Str();
    if (!own.empty()) return own;
    if (drawn && node->mName.length > 0) return node->mName.C_Str();
    return std::string("#").append(std::to_string(i));
}

// A texture's side, in pixels, beyond which a file is taken as bad rather than allocated.
constexpr int max_texture_side = 16384;

// Decodes a PNG or JPEG held in memory into RGBA8; the error says why.
Result<Image> decode_image(const unsigned char* bytes, std::size_t size) {
    if (size == 0 || size > std::size_t(std::numeric_limits<int>::max())) return fail("empty or oversized image data");
    int w = 0, h = 0, channels = 0;
    // PNG and JPEG only, as the docs promise (libstb reads more: BMP, TGA, GIF, PSD, ...).
    static constexpr unsigned char png[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'}, jpeg[] = {0xff, 0xd8, 0xff};
    const bool is_png = size >= sizeof png && std::memcmp(bytes, png, sizeof png) == 0;
    const bool is_jpeg = size >= sizeof jpeg && std::memcmp(bytes, jpeg, sizeof jpeg) == 0;
    if (!is_png && !is_jpeg) return fail("not a PNG or JPEG image (neither signature)");
    if (!stbi_info_from_memory(bytes, int(size), &w, &h, &channels)) return fail(std::string("not a PNG or JPEG image (") + stbi_failure_reason() + ")");
    if (w <= 0 || h <= 0 || w > max_texture_side || h > max_texture_side)
        return fail(std::to_string(w) + "x" + std::to_string(h) + " pixels (at most " + std::to_string(max_texture_side) + " a side)");
    unsigned char* pixels = stbi_load_from_memory(bytes, int(size), &w, &h, &channels, 4);
    if (pixels == nullptr) return fail(std::string("cannot be decoded (") + stbi_failure_reason() + ")");
    Image image;
    image.width = w;
    image.height = h;
    image.rgba.assign(pixels, pixels + std::size_t(w) * std::size_t(h) * 4);
    stbi_image_free(pixels);
    return image;
}

// The base-colour texture of material `material`, when it names one: embedded in the scene
// (compressed, or raw BGRA texels) or a file beside `path`. Errors name the texture.
Result<Image> read_base_color(const aiScene* scene, const aiMaterial* material, const fs::path& path) {
    aiString name;
    if (material == nullptr ||
        (material->GetTexture(aiTextureType_BASE_COLOR, 0, &name) != AI_SUCCESS && material->GetTexture(aiTextureType_DIFFUSE, 0, &name) != AI_SUCCESS))
        return Image{};
    const std::string label = std::string("base-colour texture '") + name.C_Str() + "'";
    if (const aiTexture* t = scene->GetEmbeddedTexture(name.C_Str())) {
        if (t->pcData == nullptr) return fail(label + ": no data");
        if (t->mHeight == 0) {
            auto image = decode_image(reinterpret_cast<const unsigned char*>(t->pcData), t->mWidth);
            if (!image) return fail(label + ": " + image.error().message);
            return image;
        }
        if (t->mWidth > unsigned(max_texture_side) || t->mHeight > unsigned(max_texture_side))
            return fail(label + ": " + std::to_string(t->mWidth) + "x" + std::to_string(t->mHeight) + " texels (at most " +
                        std::to_string(max_texture_side) + " a side)");
        Image image;
        image.width = int(t->mWidth);
        image.height = int(t->mHeight);
        image.rgba.resize(std::size_t(t->mWidth) * t->mHeight * 4);
        for (std::size_t i = 0; i < std::size_t(t->mWidth) * t->mHeight; ++i) {
            const aiTexel& texel = t->pcData[i];
            image.rgba[4 * i + 0] = texel.r;
            image.rgba[4 * i + 1] = texel.g;
            image.rgba[4 * i + 2] = texel.b;
            image.rgba[4 * i + 3] = texel.a;
        }
        return image;
    }
    const fs::path file = path.parent_path() / fs::path(name.C_Str());
    std::ifstream in(file, std::ios::binary);
    if (!in) return fail(label + ": no such file " + file.string());
    const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    auto image = decode_image(bytes.data(), bytes.size());
    if (!image) return fail(label + " (" + file.string() + "): " + image.error().message);
    return image;
}

// `image` as PNG bytes.
std::vector<unsigned char> encode_png(const Image& image) {
    std::vector<unsigned char> out;
    stbi_write_png_to_func(
        [](void* context, void* data, int size) {
            auto& bytes = *static_cast<std::vector<unsigned char>*>(context);
            bytes.insert(bytes.end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
        },
        &out, image.width, image.height, 4, image.rgba.data(), image.width * 4);
    return out;
}

}  // namespace

std::pair<fs::path, std::string> split_garment_reference(std::string_view reference) {
    const std::size_t colon = reference.rfind(':');
    if (colon == std::string_view::npos || colon + 1 >= reference.size()) return {fs::path(reference), std::string()};
    const std::string_view after = reference.substr(colon + 1);
    if (after.find('/') != std::string_view::npos || after.find('\\') != std::string_view::npos) return {fs::path(reference), std::string()};
    return {fs::path(reference.substr(0, colon)), std::string(after)};
}

Result<GarmentMeshAsset> import_garment_mesh(const fs::path& path, std::string_view mesh_name) {
    const std::string at = path.string();
    std::error_code ec;
    if (!fs::exists(path, ec)) return fail(at + ": no such file");
    if (!fs::is_regular_file(path, ec)) return fail(at + ": not a regular file");
    if (fs::file_size(path, ec) == 0) return fail(at + ": empty file");

    Assimp::Importer importer;
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const aiScene* scene = importer.ReadFile(at, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType |
                                                     aiProcess_ValidateDataStructure);
    if (scene == nullptr) {
        const std::string why = one_line(importer.GetErrorString());
        if (why.find("mNumMeshes is 0") != std::string::npos) return fail(at + ": no meshes");
        return fail(at + ": not a readable model (" + (why.empty() ? "unknown format" : why) + ")");
    }
    if (scene->mRootNode == nullptr || scene->mNumMeshes == 0) return fail(at + ": no meshes");

    // Meshes by name, each with its parts: an exporter splits a mesh with several materials
    // into one part per material under the same name (FBX, glTF primitives).
    std::vector<std::pair<std::string, std::vector<unsigned>>> named;
    for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
        if (!(scene->mMeshes[i]->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
        const std::string label = mesh_label(scene, i);
        const auto it = std::find_if(named.begin(), named.end(), [&](const auto& n) { return n.first == label; });
        if (it == named.end())
            named.push_back({label, {i}});
        else
            it->second.push_back(i);
    }
    std::string names;
    for (const auto& [label, parts] : named)
        names.append(names.empty() ? "" : ", ").append(label).append(parts.size() > 1 ? " (" + std::to_string(parts.size()) + " parts)" : "");
    std::size_t chosen = 0;
    if (mesh_name.empty()) {
        if (named.empty()) return fail(at + ": no mesh of triangles");
        if (named.size() > 1) return fail(at + ": " + std::to_string(named.size()) + " meshes (" + names + "): name one as " + at + ":MESH");
    } else {
        const auto it = std::find_if(named.begin(), named.end(), [&](const auto& n) { return n.first == mesh_name; });
        if (it == named.end())
            return fail(at + ": no mesh named '" + std::string(mesh_name) + "' (" + (names.empty() ? "no meshes of triangles" : "meshes: " + names) + ")");
        chosen = static_cast<std::size_t>(it - named.begin());
    }

    GarmentMeshAsset out;
    out.name = named[chosen].first;
    const std::string label = at + ":" + out.name;
    const std::vector<unsigned>& parts = named[chosen].second;
    // Every part with UVs, or none; painted pins where a part paints them (0 elsewhere).
    const auto with_uvs = std::count_if(parts.begin(), parts.end(), [&](unsigned i) { return scene->mMeshes[i]->HasTextureCoords(0); });
    if (with_uvs != 0 && with_uvs != static_cast<std::ptrdiff_t>(parts.size()))
        return fail(label + ": " + std::to_string(with_uvs) + " of its " + std::to_string(parts.size()) + " parts have UVs: all or none must");
    const bool painted = std::any_of(parts.begin(), parts.end(), [&](unsigned i) { return scene->mMeshes[i]->HasVertexColors(0); });
    unsigned total = 0;
    for (unsigned i : parts) total += scene->mMeshes[i]->mNumVertices;
    out.positions.resize(3, total);
    if (with_uvs) out.uvs.resize(2, total);
    if (painted) out.pin = VectorX::Zero(total);
    unsigned first = 0;
    for (unsigned i : parts) {
        const aiMesh* m = scene->mMeshes[i];
        aiMatrix4x4 to_model;
        const aiNode* node = nullptr;
        if (!find_mesh_node(scene->mRootNode, i, aiMatrix4x4(), to_model, node)) to_model = aiMatrix4x4();
        for (unsigned v = 0; v < m->mNumVertices; ++v) {
            const aiVector3D p = to_model * m->mVertices[v];
            out.positions.col(first + v) = Vec3(p.x, p.y, p.z);
            if (with_uvs) out.uvs.col(first + v) = Eigen::Vector2f(m->mTextureCoords[0][v].x, m->mTextureCoords[0][v].y);
            if (painted && m->HasVertexColors(0)) out.pin[first + v] = std::clamp(m->mColors[0][v].r, 0.0f, 1.0f);
        }
        for (unsigned f = 0; f < m->mNumFaces; ++f) {
            const aiFace& face = m->mFaces[f];
            if (face.mNumIndices != 3) continue;
            for (unsigned k = 0; k < 3; ++k) out.indices.push_back(first + face.mIndices[k]);
        }
        first += m->mNumVertices;
    }
    if (!out.positions.allFinite()) return fail(label + ": a vertex position is not a finite number");
    if (!out.uvs.allFinite()) return fail(label + ": a UV coordinate is not a finite number");
    if (!out.pin.allFinite()) return fail(label + ": a vertex colour is not a finite number");
    if (out.indices.empty()) return fail(label + ": no triangles");
    if (with_uvs) {
        auto texture = read_base_color(scene, scene->mMaterials[scene->mMeshes[parts.front()]->mMaterialIndex], path);
        if (!texture) return fail(label + ": " + texture.error().message);
        out.base_color = std::move(*texture);
    }
    return out;
}

Result<void> write_garment_mesh(const fs::path& path, const GarmentMeshAsset& mesh) {
    const std::string at = path.string();
    const std::string ext = path.extension().string();
    if (ext != ".gltf" && ext != ".glb") return fail(at + ": a garment is written as glTF: name the file .gltf or .glb");
    std::error_code ec;
    const fs::path bin = fs::path(path).replace_extension(".bin");
    if (fs::exists(path, ec)) return fail(at + ": exists (not overwritten)");
    if (ext == ".gltf" && fs::exists(bin, ec)) return fail(bin.string() + ": exists (not overwritten)");
    const auto n = static_cast<unsigned>(mesh.vertex_count());
    if (n == 0 || mesh.indices.empty() || mesh.indices.size() % 3 != 0) return fail(at + ": the garment mesh has no triangles");
    if (mesh.uvs.size() != 0 && mesh.uvs.cols() != mesh.positions.cols()) return fail(at + ": one UV per vertex is needed");
    if (mesh.pin.size() != 0 && mesh.pin.size() != mesh.positions.cols()) return fail(at + ": one pin value per vertex is needed");
    const bool textured = !mesh.base_color.empty();
    if (textured && mesh.uvs.size() == 0) return fail(at + ": a base-colour texture needs UVs to be mapped by");
    if (textured && mesh.base_color.rgba.size() != std::size_t(mesh.base_color.width) * std::size_t(mesh.base_color.height) * 4)
        return fail(at + ": the base-colour texture's pixels do not match its size");

    // Normals: area-weighted face normals at the vertices.
    Matrix3X normals = Matrix3X::Zero(3, n);
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const Vec3 a = mesh.positions.col(mesh.indices[t]), b = mesh.positions.col(mesh.indices[t + 1]), c = mesh.positions.col(mesh.indices[t + 2]);
        const Vec3 nf = (b - a).cross(c - a);
        for (std::size_t k = 0; k < 3; ++k) normals.col(mesh.indices[t + k]) += nf;
    }

    auto scene = std::make_unique<aiScene>();
    scene->mRootNode = new aiNode("Garment");
    scene->mRootNode->mNumMeshes = 1;
    scene->mRootNode->mMeshes = new unsigned[1]{0};
    scene->mNumMaterials = 1;
    scene->mMaterials = new aiMaterial*[1]{new aiMaterial()};
    const aiString material_name("cloth");
    scene->mMaterials[0]->AddProperty(&material_name, AI_MATKEY_NAME);
    if (textured) {
        const std::vector<unsigned char> png = encode_png(mesh.base_color);
        if (png.empty()) return fail(at + ": the base-colour texture could not be encoded as PNG");
        auto* texture = new aiTexture();
        texture->mWidth = static_cast<unsigned>(png.size());
        texture->mHeight = 0;
        std::strcpy(texture->achFormatHint, "png");
        texture->pcData = new aiTexel[(png.size() + sizeof(aiTexel) - 1) / sizeof(aiTexel)];
        std::memcpy(texture->pcData, png.data(), png.size());
        texture->mFilename = aiString("base_color.png");
        scene->mNumTextures = 1;
        scene->mTextures = new aiTexture*[1]{texture};
        const aiString embedded("*0");
        scene->mMaterials[0]->AddProperty(&embedded, AI_MATKEY_TEXTURE(aiTextureType_BASE_COLOR, 0));
        scene->mMaterials[0]->AddProperty(&embedded, AI_MATKEY_TEXTURE(aiTextureType_DIFFUSE, 0));
    }
    scene->mNumMeshes = 1;
    scene->mMeshes = new aiMesh*[1]{new aiMesh()};
    aiMesh& m = *scene->mMeshes[0];
    m.mName = mesh.name.empty() ? "Garment" : mesh.name.c_str();
    m.mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
    m.mMaterialIndex = 0;
    m.mNumVertices = n;
    m.mVertices = new aiVector3D[n];
    m.mNormals = new aiVector3D[n];
    for (unsigned v = 0; v < n; ++v) {
        m.mVertices[v] = aiVector3D(mesh.positions(0, v), mesh.positions(1, v), mesh.positions(2, v));
        const Real len = normals.col(v).norm();
        const Vec3 nv = len > 0 ? Vec3(normals.col(v) / len) : Vec3::UnitY();
        m.mNormals[v] = aiVector3D(nv.x(), nv.y(), nv.z());
    }
    if (mesh.uvs.size() != 0) {
        m.mTextureCoords[0] = new aiVector3D[n];
        m.mNumUVComponents[0] = 2;
        for (unsigned v = 0; v < n; ++v) m.mTextureCoords[0][v] = aiVector3D(mesh.uvs(0, v), mesh.uvs(1, v), 0);
    }
    if (mesh.pin.size() != 0) {
        m.mColors[0] = new aiColor4D[n];
        for (unsigned v = 0; v < n; ++v) m.mColors[0][v] = aiColor4D(mesh.pin[v], 0, 0, 1);
    }
    m.mNumFaces = static_cast<unsigned>(mesh.indices.size() / 3);
    m.mFaces = new aiFace[m.mNumFaces];
    for (unsigned f = 0; f < m.mNumFaces; ++f) {
        m.mFaces[f].mNumIndices = 3;
        m.mFaces[f].mIndices = new unsigned[3]{mesh.indices[3 * f], mesh.indices[3 * f + 1], mesh.indices[3 * f + 2]};
    }

    Assimp::Exporter exporter;
    if (exporter.Export(scene.get(), ext == ".glb" ? "glb2" : "gltf2", at) != aiReturn_SUCCESS)
        return fail(at + ": could not be written (" + one_line(exporter.GetErrorString()) + ")");
    return {};
}

}  // namespace drape

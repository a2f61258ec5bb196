#pragma once

// Internal to the glTF loader and exporter: the load context, typed JSON reads that fail with the
// element's path, and the pieces shared between load and export (extension names, texture infos).

#include "core/scene/scene.hpp"

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace tinygltf {
class Model;
}

namespace vitrine::scene::gltf {

using Json = nlohmann::json;

inline constexpr const char* kTextureTransform = "KHR_texture_transform";
inline constexpr const char* kEmissiveStrength = "KHR_materials_emissive_strength";
inline constexpr const char* kLightsPunctual = "KHR_lights_punctual";
inline constexpr const char* kMeshQuantization = "KHR_mesh_quantization";
inline constexpr const char* kUnlit = "KHR_materials_unlit";
inline constexpr const char* kTransmission = "KHR_materials_transmission";
inline constexpr const char* kIor = "KHR_materials_ior";
inline constexpr const char* kSpecular = "KHR_materials_specular";
inline constexpr const char* kClearcoat = "KHR_materials_clearcoat";
inline constexpr const char* kSheen = "KHR_materials_sheen";
inline constexpr const char* kVolume = "KHR_materials_volume";
inline constexpr const char* kSpecGloss = "KHR_materials_pbrSpecularGlossiness";
inline constexpr const char* kVariants = "KHR_materials_variants";
inline constexpr const char* kMeshopt = "EXT_meshopt_compression";

// Material extensions vitrine reads no part of, and what of the material each one's absence leaves out: the loader
// warns once per extension (naming the materials that use it) rather than with the generic extensionsUsed warning.
struct IgnoredMaterialExtension {
    const char* name;
    const char* ignored;
};
inline constexpr IgnoredMaterialExtension kIgnoredMaterialExtensions[] = {
    {"KHR_materials_iridescence", "the thin-film iridescence (iridescenceFactor, its ior, thickness and textures)"},
};
// Our key inside `extras` for what glTF has no place for (physical camera, rooms, camera paths).
inline constexpr const char* kExtrasKey = "vitrine";

// Everything the conversion steps share; fail() is how every step reports a bad file.
struct LoadContext {
    std::string file; // as the user named it
    std::filesystem::path baseDir;
    Json doc;
    bool glb = false;            // the file is a GLB container (else glTF JSON)
    std::vector<uint8_t> glbBin; // GLB binary chunk, empty for .gltf
    const tinygltf::Model* model = nullptr;
    Scene* scene = nullptr;
    std::vector<std::string>* warnings = nullptr;
    // What tinygltf is given when the file had to be rewritten for it (preflight()), else empty: the file's bytes.
    // Data URIs tinygltf cannot decode (not base64, or a media type it does not list) become base64, and the
    // `indices` of primitives whose index accessor has no bufferView are dropped (tinygltf refuses them; the
    // meshes step reads them from doc).
    std::vector<uint8_t> tinygltfInput;
    // Whether preflight() made integral floats of integer properties (1.0 for 1) integers in doc: tinygltf then reads
    // the rewritten doc too.
    bool integersRewritten = false;
    // Accessors whose `type` glTF does not define (index -> the type as written): accessorAt() refuses to read them.
    std::map<int, std::string> unknownAccessorTypes;
    // Scene texture made for glTF texture i with usage u, or -1 (see resolveTexture()).
    std::vector<std::array<int32_t, 3>> textureByUsage;
    // Scene texture loaded for glTF texture i, or -1 when it has no image vitrine could read (no source, or one that
    // did not decode): materials are drawn without it.
    std::vector<int32_t> sceneTexture;
    int32_t defaultMaterial = -1;
    // The KHR_materials_variants variant the caller asked for ("" = the primitives' default materials), and its index
    // into the file's variants once loadMaterials() has found it (-1: none asked for).
    std::string materialVariant;
    int32_t variantIndex = -1;
    size_t variantCount = 0; // the file's variants
    // Scene textures made by converting KHR_materials_pbrSpecularGlossiness textures (base colour, metallic-roughness),
    // by a key of their sources and factors, so that materials sharing them share the result.
    std::map<std::string, std::pair<int32_t, int32_t>> specGlossTextures;
    std::set<int32_t> specGlossSources; // the scene textures those were converted from

    // "FILE: ELEMENT: WHAT", plus " (at /json/pointer)" when ELEMENT starts with a path into the glTF JSON
    // (`accessors[0].bufferView` → /accessors/0/bufferView). warn() keeps each distinct warning once.
    [[noreturn]] void fail(const std::string& element, const std::string& what) const;
    std::string message(const std::string& element, const std::string& what) const; // the text fail() throws
    void warn(const std::string& element, const std::string& what) const;
};

// The JSON pointer of the glTF path `element` starts with (`meshes[0].primitives[1].indices (accessors[3])` →
// /meshes/0/primitives/1/indices), or "" when it does not start with a top-level glTF property.
std::string jsonPointer(const std::string& element);
// A data: URI (RFC 2397) decoded: base64 or percent-encoded payload. False with error set when malformed.
bool decodeDataUri(const std::string& uri, std::vector<uint8_t>& out, std::string& mediaType, std::string& error);

// Standard base64 with padding (RFC 4648), for data: URIs.
std::string base64Encode(const std::vector<uint8_t>& data);
// A relative URI's %XX escapes decoded (a file name beside the glTF).
std::string urlDecode(const std::string& s);

// `element.key`, or `key` at the top level (element empty).
std::string path(const std::string& element, const char* key);
// Typed reads of obj[key] that fail with `element.key` when the type is wrong; absent → def.
const Json* member(const Json& obj, const char* key);
double number(const LoadContext& ctx, const Json& obj, const char* key, double def, const std::string& element);
int64_t integer(const LoadContext& ctx, const Json& obj, const char* key, int64_t def, const std::string& element);
bool boolean(const LoadContext& ctx, const Json& obj, const char* key, bool def, const std::string& element);
std::string string(const LoadContext& ctx, const Json& obj, const char* key, const std::string& def,
                   const std::string& element);
// A fixed-length array of numbers into the first n components of def.
glm::vec4 numbers(const LoadContext& ctx, const Json& obj, const char* key, int n, glm::vec4 def,
                  const std::string& element);
// obj[key] as an object (nullptr when absent); fails when present but not an object.
const Json* object(const LoadContext& ctx, const Json& obj, const char* key, const std::string& element);
// The number of elements of the top-level array `name` (0 when absent).
size_t topLevelCount(const LoadContext& ctx, const char* name);
// Fails unless value is an integer index in [0, topLevelCount(target)).
uint32_t checkIndex(const LoadContext& ctx, const Json& value, const std::string& element, const char* target);

// EXT_meshopt_compression (gltf_meshopt.cpp): every compressed bufferView of ctx.doc decoded with libmeshoptimizer
// into one new buffer of the document edit() returns (a copy of ctx.doc, made on first call; the new buffer a data:
// URI), the views pointed at it and the extension dropped; fallback buffers that hold no data get a one-byte
// placeholder, since no view reads them any more. Fails naming the view's field on a bad field, a range outside its
// buffer or data that does not decode. Does nothing (and never calls edit) when no view is compressed.
void decodeMeshoptCompression(const LoadContext& ctx, const std::function<Json&()>& edit);
// True when the buffer is marked as EXT_meshopt_compression's fallback ({"fallback": true}), which may hold no data.
bool isMeshoptFallback(const Json& buffer);

// Step 1: read the file (UserError when it cannot be opened).
std::vector<uint8_t> readGltfFile(const LoadContext& ctx, const std::filesystem::path& file);
// Step 2: unwrap a GLB, parse the JSON, and check everything tinygltf would index or read without checking:
// required extensions, cross-references, byte ranges, external files. `file` decides, with the bytes, whether
// they are a GLB.
void preflight(LoadContext& ctx, const std::filesystem::path& file, const std::vector<uint8_t>& bytes);

// Accessors, fully bounds-checked. Values are converted to float (normalised integers per glTF) and
// returned as `components` floats per element; element names the use for messages.
struct AccessorValues {
    size_t count = 0;
    int components = 0;
    std::vector<float> data;
    glm::vec4 get(size_t i) const; // missing components are 0
};
AccessorValues readAccessor(const LoadContext& ctx, int accessor, const std::string& element,
                            std::initializer_list<int> allowedComponents, bool floatOnly = false);
std::vector<uint32_t> readIndices(const LoadContext& ctx, int accessor, const std::string& element);

// Steps of the conversion, in order.
void loadImagesAndTextures(LoadContext& ctx);
void loadMaterials(LoadContext& ctx);
void loadMeshes(LoadContext& ctx);
void loadNodesAndScene(LoadContext& ctx);

// The primitive's material: its KHR_materials_variants mapping for ctx.variantIndex when it has one, else `material`
// (its own, -1 when absent). Checks the mapping's indices.
int variantMaterial(const LoadContext& ctx, const Json& primitive, int material, const std::string& element);
// Reads the file's KHR_materials_variants list and finds ctx.materialVariant in it (UserError listing the variants
// when absent). Called by loadMaterials().
void readVariants(LoadContext& ctx);

// KHR_materials_pbrSpecularGlossiness (the object under that name in material `element`) converted into the layer's
// albedo, shininess and metallic; its textures become new scene textures converted texel by texel.
void readSpecularGlossiness(LoadContext& ctx, const Json& ext, const std::string& element, MaterialLayer& layer);
// Once every material is read: removes the scene textures (and their images) that only the conversions read, so that
// neither the GPU nor an export carries them. Called by loadMaterials().
void dropSpecGlossSources(LoadContext& ctx);
// The conversion of one specular-glossiness sample (linear colours) into metallic-roughness. See gltf_specgloss.cpp.
struct MetalRough {
    glm::vec4 baseColor;
    float metallic;
    float roughness;
};
MetalRough specGlossToMetalRough(glm::vec4 diffuse, glm::vec3 specular, float glossiness);

// A glTF textureInfo (with KHR_texture_transform) as a TextureRef of the given usage.
TextureRef readTextureInfo(LoadContext& ctx, const Json& info, TextureUsage usage, const std::string& element);
// ... and back; textureIndex is the glTF texture index the scene texture was written as.
Json writeTextureInfo(const TextureRef& ref, int textureIndex);

const char* usageName(TextureUsage usage);

} // namespace vitrine::scene::gltf

#pragma once

// glTF 2.0 in and out. Loading goes through tinygltf behind checks of our own, so that a bad file is a
// UserError naming the file, the element (`meshes[3].primitives[0].attributes.NORMAL`) and what was
// expected, never a crash. Called by the scene nodes of the render graph and by `vitrine` tools.
//
// Supported on load: meshes (triangles, strips, fans; u8/u16/u32 indices; float or normalised-integer
// attributes, sparse accessors), NORMAL (flat normals generated when absent, as glTF asks), TANGENT
// (generated when absent, see tangents.hpp), TEXCOORD_0/1, COLOR_0 (rgb), `_AO` (vertex AO), the
// metallic-roughness material with all its textures, samplers, the node hierarchy, cameras, node
// animations (objects and cameras), KHR_texture_transform, KHR_materials_emissive_strength,
// KHR_lights_punctual (the first directional light becomes the sun; point and spot lights are kept with their
// nodes), KHR_materials_unlit, KHR_materials_transmission (the factor; its texture is ignored with a warning),
// KHR_materials_ior, KHR_materials_specular (strength and colour of the dielectric's Fresnel: material.hpp),
// KHR_materials_clearcoat (strength, roughness, their textures and the coat normal map: material.hpp),
// KHR_materials_sheen (colour, roughness and their textures: material.hpp), KHR_materials_volume (thickness, its
// texture and the attenuation: material.hpp),
// KHR_materials_pbrSpecularGlossiness (converted to metallic-roughness at load: factors, and
// textures texel by texel into new textures; gltf_specgloss.cpp), KHR_materials_variants (one variant chosen by name at
// load), KHR_mesh_quantization, EXT_meshopt_compression (decoded by libmeshoptimizer before tinygltf reads the file:
// gltf_meshopt.cpp), VITRINE_material_layers (VITRINE_material_layers.md) and the scene's reflection probes
// in VITRINE_reflection_probes (VITRINE_reflection_probes.md), morph targets (POSITION, NORMAL, TANGENT displacements;
// mesh or node `weights` make the rest pose, animated weights are an animation channel). Any other extension in
// extensionsRequired is refused by name; any other in extensionsUsed is ignored with a warning
// (KHR_materials_iridescence: one, naming what of which materials is lost). Skins (JOINTS_0/WEIGHTS_0, inverse bind
// matrices): the rest pose is skinned at load, animated joints re-skin on the CPU every frame (GpuScene::update).
// Point/line primitives are ignored with a warning. Accessors without a bufferView are zeros (plus their sparse
// substitutions), as glTF says, indices included. Data URIs may be base64 or percent-encoded (RFC 2397). Embedded
// (data: URI, GLB) and external buffers and images both work.
//
// How glTF maps onto the scene model:
// - A metallic-roughness material is a one-layer stack: shininess = 1 − roughnessFactor × texel.g,
//   metallic = metallicFactor × texel.b, cavity = the occlusion texture (1 + strength × (texel.r − 1)).
// - Texture usage, hence colour space, comes from the slots that use it: baseColor and emissive are
//   sRGB, everything else linear. A glTF texture used both ways becomes two scene textures.
// - Every camera node yields a camera path named after the node: one key for a still camera, samples
//   at 30 Hz over its animations otherwise. Paths written by exportGlb() come back exactly.
// - Node matrices are decomposed into translation/rotation/scale (shear is lost).

#include "core/base/error.hpp"
#include "core/scene/scene.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace vitrine::scene {

inline constexpr const char* kLayersExtension = "VITRINE_material_layers";
inline constexpr const char* kProbesExtension = "VITRINE_reflection_probes";

// What the loaders throw when their materialVariant is not a KHR_materials_variants variant of the file (the message
// lists the file's variants), so that a caller can point at where the name came from.
class UnknownMaterialVariant : public UserError {
public:
    using UserError::UserError;
};

// Loads a .gltf (JSON, external or data: URI buffers) or a .glb (recognised by its magic, whatever the
// file is called). The result is finalized and valid (Scene::validate() passes).
Scene loadGltf(const std::filesystem::path& file);
// Same, and collects what was ignored (unsupported features, extra attributes) into warnings. materialVariant: the
// KHR_materials_variants variant whose materials the primitives get ("" = their default materials); a name the file
// does not define is a UserError listing the file's variants.
Scene loadGltf(const std::filesystem::path& file, std::vector<std::string>& warnings,
               const std::string& materialVariant = "");
// The bytes of a file already read, as if loaded from `file` (its name for messages and the GLB check, its
// folder for external files). For the fuzzer and for callers that hold the file in memory.
Scene loadGltfFromMemory(const std::vector<uint8_t>& bytes, const std::filesystem::path& file,
                         std::vector<std::string>& warnings, const std::string& materialVariant = "");

// Loads for a user, as the scene.gltf node and `vitrine export-scene` do: each distinct warning (an unsupported
// extension in extensionsUsed, point and line primitives, unused attributes, tinygltf's own warnings, ...) is printed once
// on stderr through logWarning(), as "warning: FILE: ELEMENT: WHAT (at /json/pointer)". strict: warnings are errors;
// a UserError lists them all and nothing is printed.
Scene loadGltfReporting(const std::filesystem::path& file, bool strict, const std::string& materialVariant = "");

// Writes the scene as one self-contained .glb that the Khronos glTF-Validator reports without errors or warnings:
// geometry (one interleaved vertex buffer view; TANGENT only where the material has a normal map, TEXCOORD_0 only
// where a texture samples it or TEXCOORD_1 is written), materials as plain metallic-roughness plus
// VITRINE_material_layers where the core material cannot express the layer stack exactly, textures as embedded PNG, cameras, camera paths as animated camera
// nodes (a one-key path LINEAR, as CUBICSPLINE needs two keys), the sun as a KHR_lights_punctual directional light
// whose color × intensity is Sun::color × Sun::illuminance, reflection probes in VITRINE_reflection_probes, rooms and
// exact physical parameters in `extras`. loadGltf() of the result gives back a scene with the same contentHash() as
// dropUnusedAttributes() of the input. UserError when the file cannot be written.
void exportGlb(const Scene& scene, const std::filesystem::path& file);

// What exportGlb() does not write, set to what loadGltf() makes of its absence: per primitive, uv0 = (0, 0) unless a
// texture of its material samples TEXCOORD_0 or TEXCOORD_1 is written (lightmap UVs), and tangents generated (tangents.hpp) unless its material has a normal
// map. Neither changes a rendered pixel: the shaders read uv0 only through textures and tangents only for normal maps.
void dropUnusedAttributes(Scene& scene);

} // namespace vitrine::scene

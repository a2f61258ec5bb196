#pragma once

#include "core/image/image.hpp"

#include <glm/glm.hpp>

// Test-only nodes registered inside test_gpu (test_nodes.cpp):
//   test.octahedral   -> "result" 256x64: left half octEncode of a grid of directions, right
//                        half octDecode of a grid of codes (common/octahedral.glsl)
//   test.furnace      -> "albedo" 16x16: r = GGX-Smith directional albedo with F = 1
//                        (NoV = (x + 0.5) / 16, roughness = (y + 0.5) / 16; 64x64 stratified
//                        visible-normal samples), g = Lambert furnace (cosine-weighted samples)
//   test.cube_unfold  <- "cube" (storage read) -> "faces" (6N x N): layer f at x offset f N
//   test.cube_sample  <- "cube" (samplerCube)  -> "faces": textureLod at cubeTexelDirection
//   test.probe_cubes  -> "cubes": a probe cube-map array, constant per probe or the texel coordinates per face
//   test.brdf_lut     -> "lut" 32x32: (A, B) = (kLutA0 + kLutA1 NoV, kLutB roughness)
//   test.gltf_probes  -> scene.gltf's outputs, with reflection probes from its `probes` param
namespace vitrine::test {

inline constexpr int kOctGrid = 128;
inline constexpr int kFurnaceSamplesPerAxis = 64;
inline constexpr double kLutA0 = 0.25, kLutA1 = 0.5, kLutB = 0.2;

// Texel (x, y) of layer `face` in an unfolded cube.
inline glm::dvec3 cubeTexel(const Image& faces, int face, int x, int y) {
    const float* p = faces.at(face * faces.height + x, y);
    return {p[0], p[1], p[2]};
}

} // namespace vitrine::test

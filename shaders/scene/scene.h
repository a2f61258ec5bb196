// The GPU copy of a scene (core/scene/gpu_scene.hpp), shared by C++ and GLSL. Every struct is made of
// 16-byte members only, so std430 and C++ agree without padding rules.
#ifndef SCENE_SCENE_H
#define SCENE_SCENE_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif

// A texture reference of one material parameter: uv' = (dot(row0.xyz, (uv, 1)), dot(row1.xyz, (uv, 1))).
struct GpuTexRef {
    ivec4 info; // x: texture index into the scene's texture array (-1: none), y: uv set, z: channel
    vec4 row0;
    vec4 row1;
};

// Layer bits in GpuLayer::bits.x (scene::LayerParamBits).
#define VITRINE_LAYER_ALBEDO 1u
#define VITRINE_LAYER_NORMAL 2u
#define VITRINE_LAYER_SHININESS 4u
#define VITRINE_LAYER_METALLIC 8u
#define VITRINE_LAYER_CAVITY 16u

// Reference slots in GpuLayer::refs.
#define VITRINE_REF_ALBEDO 0
#define VITRINE_REF_NORMAL 1
#define VITRINE_REF_SHININESS 2
#define VITRINE_REF_METALLIC 3
#define VITRINE_REF_CAVITY 4
#define VITRINE_REF_MASK 5

// The texel pool's per-texture bits (GpuScene::geometrySet() binding 2, w), for ray tracers' texture sampling.
#define VITRINE_TEXEL_SRGB 1u    // colour: decode sRGB per texel before filtering, as an _SRGB image view does
#define VITRINE_TEXEL_NEAREST 2u // magnification filter nearest (else linear)
#define VITRINE_TEXEL_REPEAT 0u  // wrap modes, 2 bits each
#define VITRINE_TEXEL_CLAMP 1u
#define VITRINE_TEXEL_MIRROR 2u
#define VITRINE_TEXEL_WRAP_U_SHIFT 2u
#define VITRINE_TEXEL_WRAP_V_SHIFT 4u

struct GpuLayer {
    vec4 albedo;   // factor (linear rgb, a = coverage)
    vec4 scalars0; // normal scale, shininess factor, shininess atZero, metallic factor
    vec4 scalars1; // metallic atZero, cavity factor, cavity atZero, mask factor
    uvec4 bits;    // x: overrides (VITRINE_LAYER_*)
    GpuTexRef refs[6];
};

struct GpuMaterial {
    uvec4 info;    // x: first layer, y: layer count, z: alpha mode (0 opaque, 1 mask, 2 blend), w: double sided
    vec4 emissive; // rgb: factor x strength (linear), a: alpha cutoff
    GpuTexRef emissiveRef;
    // x: transmission, y: dielectric F0 from the IOR, z: unlit (1/0), w: KHR_materials_volume's thicknessFactor (0:
    // thin-walled, as without the extension)
    vec4 optics;
    // KHR_materials_specular (1, 1, 1, 1 without it): rgb: specularColorFactor (linear), a: specularFactor; the
    // textures multiply them (specularRef's alpha, specularColorRef's sRGB colour). scene.glsl materialSpecular.
    vec4 specular;
    GpuTexRef specularRef;
    GpuTexRef specularColorRef;
    // KHR_materials_clearcoat (0 without it): x: clearcoatFactor, y: clearcoatRoughnessFactor, z: the coat normal
    // map's scale, w: 0. The textures multiply x (clearcoatRef's red) and y (clearcoatRoughnessRef's green);
    // clearcoatNormalRef is a tangent-space normal map as a layer's. scene.glsl materialClearcoat.
    vec4 clearcoat;
    GpuTexRef clearcoatRef;
    GpuTexRef clearcoatRoughnessRef;
    GpuTexRef clearcoatNormalRef;
    // KHR_materials_sheen (0 without it): rgb: sheenColorFactor (linear), a: sheenRoughnessFactor. The textures
    // multiply them (sheenColorRef's sRGB colour, sheenRoughnessRef's alpha). scene.glsl materialSheen.
    vec4 sheen;
    GpuTexRef sheenColorRef;
    GpuTexRef sheenRoughnessRef;
    // KHR_materials_volume ((1, 1, 1, 0) without it): rgb: attenuationColor (linear), a: attenuationDistance, 0 for
    // +inf (the Sample Viewer's convention). thicknessRef's green multiplies optics.w. scene.glsl materialThickness.
    vec4 volume;
    GpuTexRef thicknessRef;
};

struct GpuInstance {
    mat4 world;
    mat4 prevWorld;    // last frame's (equal to world on the first frame and for static instances)
    mat4 normalMatrix; // inverse transpose of world's upper 3x3
    // x: 1 when the instance's mesh is deformed on the CPU every frame (animated joints or morph weights): its
    // vertices' last-frame positions are scenePrevPositions[gl_VertexIndex] (velocity); 0: they are the vertex's own.
    vec4 flags;
};

// One frame's camera. Jitter (sub-pixel, for temporal AA) is in `viewProj` only: velocity is computed from
// the unjittered matrices so it is exact and jitter-free.
struct GpuCamera {
    mat4 view;
    mat4 proj;                // jittered
    mat4 viewProj;            // jittered
    mat4 invViewProj;         // of the jittered viewProj: reconstructs world positions from depth
    mat4 viewProjNoJitter;    // this frame, unjittered
    mat4 prevViewProjNoJitter; // last frame, unjittered
    vec4 position;            // world, w = 1
    vec4 params;              // x: near, y: far (0 = infinite), z: width, w: height (pixels)
    vec4 jitter;              // xy: this frame's jitter in pixels, zw: last frame's
    vec4 time;                // x: seconds, y: frame index, z: ev100 (physical camera), w: per-vertex jitter
                              // threshold in pixels per frame (0: the jitter is the frustum's, in viewProj)
};

// Push constants of every scene draw. Compute passes that read the scene with push constants of their own
// (ray tracers: a stage has one push-constant block) define VITRINE_SCENE_NO_DRAW_PUSH.
#if defined(__cplusplus) || !defined(VITRINE_SCENE_NO_DRAW_PUSH)
VITRINE_PUSH_BEGIN(SceneDrawPush)
    mat4 viewProj;  // the pass's own view-projection (shadow cascades); G-buffer passes use the camera's
    uint instance;  // index into the instance buffer
    uint material;  // index into the material buffer
    uint flags;
    uint pad;
    vec4 lightmap;  // where the instance's lightmap lies in the atlas: atlas uv = uv1 * xy + zw
VITRINE_PUSH_END(draw)
#endif

#ifdef __cplusplus
static_assert(sizeof(GpuTexRef) == 48);
static_assert(sizeof(GpuLayer) == 64 + 6 * 48);
static_assert(sizeof(GpuMaterial) == 32 + 48 + 16 + 16 + 2 * 48 + 16 + 3 * 48 + 16 + 2 * 48 + 16 + 48);
static_assert(sizeof(GpuInstance) == 3 * 64 + 16);
static_assert(sizeof(GpuCamera) == 6 * 64 + 4 * 16);
static_assert(sizeof(SceneDrawPush) == 96);
}
#endif
#endif

// The scene's descriptor set (core/scene/gpu_scene.cpp, createDescriptors) and layered-material
// evaluation (MUSEUM_SPEC §2). Include after #version; define VITRINE_SCENE_SET (default 0) and
// VITRINE_SCENE_TEXTURES (the scene's texture count) before including, and VITRINE_SCENE_FRAGMENT in
// fragment shaders (for uvGradients()). Compute shaders whose invocations evaluate different materials
// (ray tracers) define VITRINE_SCENE_DIVERGENT_TEXTURES (see sceneTexture()) and pass zero gradients (LOD 0).
#ifndef SCENE_SCENE_GLSL
#define SCENE_SCENE_GLSL
#extension GL_GOOGLE_include_directive : require
#include "scene/scene.h"

#ifndef VITRINE_SCENE_SET
#define VITRINE_SCENE_SET 0
#endif
#ifndef VITRINE_SCENE_TEXTURES
#define VITRINE_SCENE_TEXTURES 1
#endif

layout(set = VITRINE_SCENE_SET, binding = 0, std140) uniform SceneCamera { GpuCamera camera; };
layout(set = VITRINE_SCENE_SET, binding = 1, std430) readonly buffer SceneInstances { GpuInstance instances[]; };
layout(set = VITRINE_SCENE_SET, binding = 2, std430) readonly buffer SceneMaterials { GpuMaterial materials[]; };
layout(set = VITRINE_SCENE_SET, binding = 3, std430) readonly buffer SceneLayers { GpuLayer layers[]; };
layout(set = VITRINE_SCENE_SET, binding = 4) uniform sampler2D sceneTextures[VITRINE_SCENE_TEXTURES];
// Last frame's positions (object space, w = 1) of the vertices of deformed meshes, by vertex index (GpuInstance::flags.x).
layout(set = VITRINE_SCENE_SET, binding = 5, std430) readonly buffer ScenePrevPositions { vec4 scenePrevPositions[]; };

vec2 refUv(GpuTexRef r, vec2 uv0, vec2 uv1) {
    vec3 uv = vec3(r.info.y == 0 ? uv0 : uv1, 1.0);
    return vec2(dot(r.row0.xyz, uv), dot(r.row1.xyz, uv));
}

// Screen-space derivatives of both UV sets, taken once at the top of the fragment shader in uniform
// control flow. Sampling then uses explicit gradients: implicit ones inside the material loop depend on
// helper invocations executing the buffer loads that drive it, which lavapipe does not guarantee (it
// showed as wrong mip levels along triangle edges).
struct UvGradients {
    vec4 uv0; // xy: d/dx, zw: d/dy
    vec4 uv1;
};

#ifdef VITRINE_SCENE_FRAGMENT
UvGradients uvGradients(vec2 uv0, vec2 uv1) {
    UvGradients g;
    g.uv0 = vec4(dFdx(uv0), dFdy(uv0));
    g.uv1 = vec4(dFdx(uv1), dFdy(uv1));
    return g;
}
#endif

// The scene texture `index`. In a draw the index is the same for every invocation (dynamically uniform).
#ifdef VITRINE_SCENE_TEXEL_POOL
// The texel pool (GpuScene::geometrySet() bindings 2 and 3): level 0 of every texture in one buffer, which
// invocations may index with different textures. Sampled as the samplers do at LOD 0 (zero gradients, so
// the magnification filter): bilinear or nearest, the sampler's wrap modes, sRGB decoded before filtering.
layout(set = VITRINE_GEOMETRY_SET, binding = 2, std430) readonly buffer SceneTexelTable { uvec4 sceneTexelTable[]; };
layout(set = VITRINE_GEOMETRY_SET, binding = 3, std430) readonly buffer SceneTexels { uint sceneTexels[]; };

// i modulo m in [0, m) (GLSL's % is undefined for negative operands).
int texelModulo(int i, int m) {
    int t = i - m * int(floor(float(i) / float(m)));
    return t < 0 ? t + m : (t >= m ? t - m : t);
}

int texelWrap(int i, int size, uint mode) {
    if (mode == VITRINE_TEXEL_CLAMP) return clamp(i, 0, size - 1);
    if (mode == VITRINE_TEXEL_MIRROR) {
        int t = texelModulo(i, 2 * size);
        return t >= size ? 2 * size - 1 - t : t;
    }
    return texelModulo(i, size);
}

vec4 texelPoolFetch(uvec4 tex, int x, int y) {
    vec4 c = unpackUnorm4x8(sceneTexels[tex.x + uint(y) * tex.y + uint(x)]);
    if ((tex.w & VITRINE_TEXEL_SRGB) != 0u) {
        vec3 lo = c.rgb / 12.92, hi = pow((c.rgb + 0.055) / 1.055, vec3(2.4));
        c.rgb = mix(hi, lo, lessThanEqual(c.rgb, vec3(0.04045)));
    }
    return c;
}

vec4 texelPoolSample(int index, vec2 uv) {
    uvec4 tex = sceneTexelTable[index];
    ivec2 size = ivec2(tex.yz);
    uint wrapU = (tex.w >> VITRINE_TEXEL_WRAP_U_SHIFT) & 3u, wrapV = (tex.w >> VITRINE_TEXEL_WRAP_V_SHIFT) & 3u;
    vec2 st = uv * vec2(size);
    if ((tex.w & VITRINE_TEXEL_NEAREST) != 0u) {
        ivec2 i = ivec2(floor(st));
        return texelPoolFetch(tex, texelWrap(i.x, size.x, wrapU), texelWrap(i.y, size.y, wrapV));
    }
    st -= 0.5;
    vec2 f = fract(st);
    ivec2 i0 = ivec2(floor(st));
    int x0 = texelWrap(i0.x, size.x, wrapU), x1 = texelWrap(i0.x + 1, size.x, wrapU);
    int y0 = texelWrap(i0.y, size.y, wrapV), y1 = texelWrap(i0.y + 1, size.y, wrapV);
    vec4 top = mix(texelPoolFetch(tex, x0, y0), texelPoolFetch(tex, x1, y0), f.x);
    vec4 bottom = mix(texelPoolFetch(tex, x0, y1), texelPoolFetch(tex, x1, y1), f.x);
    return mix(top, bottom, f.y);
}
#endif

// A ray tracer's invocations hit different materials, and without descriptor indexing (lavapipe has no
// shaderSampledImageArrayNonUniformIndexing) an array of samplers may only be indexed with a dynamically
// uniform value: VITRINE_SCENE_DIVERGENT_TEXTURES walks the array with a loop index, which is uniform
// (one sample per scene texture); VITRINE_SCENE_TEXEL_POOL samples the texel pool instead, at LOD 0 only.
vec4 sceneTexture(int index, vec2 uv, vec2 ddx, vec2 ddy) {
#if defined(VITRINE_SCENE_TEXEL_POOL)
    return texelPoolSample(index, uv);
#elif defined(VITRINE_SCENE_DIVERGENT_TEXTURES)
    vec4 texel = vec4(0.0);
    for (int t = 0; t < VITRINE_SCENE_TEXTURES; ++t)
        if (t == index) texel = textureGrad(sceneTextures[t], uv, ddx, ddy);
    return texel;
#else
    return textureGrad(sceneTextures[index], uv, ddx, ddy);
#endif
}

// The texel a reference points at; 1 without a texture (so "factor x texel" is the factor).
vec4 sampleRef(GpuTexRef r, vec2 uv0, vec2 uv1, UvGradients g) {
    if (r.info.x < 0) return vec4(1.0);
    vec4 d = r.info.y == 0 ? g.uv0 : g.uv1;
    mat2 m = mat2(r.row0.x, r.row1.x, r.row0.y, r.row1.y); // the transform's linear part (columns)
    return sceneTexture(r.info.x, refUv(r, uv0, uv1), m * d.xy, m * d.zw);
}

float channelOf(vec4 t, int c) { return c == 0 ? t.r : c == 1 ? t.g : c == 2 ? t.b : t.a; }

// KHR_materials_specular at a surface point: rgb the specular colour, a the strength (1, 1 without the
// extension); common/brdf.glsl dielectricSpecular turns them into the dielectric's F0 and F90.
vec4 materialSpecular(GpuMaterial m, vec2 uv0, vec2 uv1, UvGradients g) {
    vec4 s = m.specular;
    if (m.specularRef.info.x >= 0) s.a *= sampleRef(m.specularRef, uv0, uv1, g).a;
    if (m.specularColorRef.info.x >= 0) s.rgb *= sampleRef(m.specularColorRef, uv0, uv1, g).rgb;
    return s;
}

// KHR_materials_clearcoat at a surface point: x the coat's strength (clearcoatFactor x clearcoatTexture.r), y its
// perceptual roughness (clearcoatRoughnessFactor x clearcoatRoughnessTexture.g); (0, 0) without the extension.
vec2 materialClearcoat(GpuMaterial m, vec2 uv0, vec2 uv1, UvGradients g) {
    vec2 c = m.clearcoat.xy;
    if (m.clearcoatRef.info.x >= 0) c.x *= sampleRef(m.clearcoatRef, uv0, uv1, g).r;
    if (m.clearcoatRoughnessRef.info.x >= 0) c.y *= sampleRef(m.clearcoatRoughnessRef, uv0, uv1, g).g;
    return clamp(c, 0.0, 1.0);
}

// The coat's tangent-space normal: clearcoatNormalTexture scaled as a layer's normal map, else (0, 0, 1), the
// interpolated vertex normal (the spec: no normal mapping of the coat without its own map).
vec3 materialClearcoatNormal(GpuMaterial m, vec2 uv0, vec2 uv1, UvGradients g) {
    if (m.clearcoatNormalRef.info.x < 0) return vec3(0.0, 0.0, 1.0);
    vec3 n = sampleRef(m.clearcoatNormalRef, uv0, uv1, g).xyz * 2.0 - 1.0;
    n.xy *= m.clearcoat.z;
    return n;
}

// KHR_materials_sheen at a surface point: rgb the sheen colour (sheenColorFactor x sheenColorTexture), a its
// perceptual roughness (sheenRoughnessFactor x sheenRoughnessTexture.a); 0 without the extension.
vec4 materialSheen(GpuMaterial m, vec2 uv0, vec2 uv1, UvGradients g) {
    vec4 s = m.sheen;
    if (m.sheenColorRef.info.x >= 0) s.rgb *= sampleRef(m.sheenColorRef, uv0, uv1, g).rgb;
    if (m.sheenRoughnessRef.info.x >= 0) s.a *= sampleRef(m.sheenRoughnessRef, uv0, uv1, g).a;
    return clamp(s, 0.0, 1.0);
}

// KHR_materials_volume's thickness at a surface point, in the mesh's own units: thicknessFactor x
// thicknessTexture.g; 0 (thin-walled) without the extension.
float materialThickness(GpuMaterial m, vec2 uv0, vec2 uv1, UvGradients g) {
    float t = m.optics.w;
    if (m.thicknessRef.info.x >= 0) t *= sampleRef(m.thicknessRef, uv0, uv1, g).g;
    return max(t, 0.0);
}

// The blended parameters of a surface point. `normal` is tangent space and NOT normalised (only its direction
// counts). `normalLength` is what Toksvig reads: the length of the mean of the unit normals the sampled
// footprint of the normal map covers (1 on level 0 and where the normals agree), which the normal-map mip chain
// keeps in alpha as a = sqrt(1 - length) (core/scene/gpu_scene.cpp, shaders/scene/toksvig_mip.comp). It is not
// the length of the decoded vector: 8-bit bytes put a flat normal's length anywhere in 1 +- 0.008, which Toksvig
// would read as roughness 0.35 on a polished surface.
struct LayeredSurface {
    vec4 albedo; // linear rgb, a = coverage
    vec3 normal;
    float normalLength;
    float shininess;
    float metallic;
    float cavity;
};

// Layer 0 sets every parameter; each layer above blends the parameters it overrides over the result
// below with its own mask weight: p = mix(below, layer, weight), each parameter independently.
LayeredSurface evaluateLayers(GpuMaterial m, vec2 uv0, vec2 uv1, UvGradients g) {
    LayeredSurface s;
    s.albedo = vec4(1.0);
    s.normal = vec3(0.0, 0.0, 1.0);
    s.normalLength = 1.0;
    s.shininess = 0.5;
    s.metallic = 0.0;
    s.cavity = 1.0;
    uint first = m.info.x, count = m.info.y;
    for (uint i = 0; i < count; ++i) {
        GpuLayer l = layers[first + i];
        float w = 1.0;
        if (i > 0) {
            GpuTexRef mr = l.refs[VITRINE_REF_MASK];
            float t = mr.info.x < 0 ? 1.0 : channelOf(sampleRef(mr, uv0, uv1, g), mr.info.z);
            w = clamp(l.scalars1.w * t, 0.0, 1.0);
        }
        uint bits = l.bits.x;
        if ((bits & VITRINE_LAYER_ALBEDO) != 0u)
            s.albedo = mix(s.albedo, l.albedo * sampleRef(l.refs[VITRINE_REF_ALBEDO], uv0, uv1, g), w);
        if ((bits & VITRINE_LAYER_NORMAL) != 0u) {
            vec3 n = vec3(0.0, 0.0, 1.0);
            float len = 1.0;
            GpuTexRef nr = l.refs[VITRINE_REF_NORMAL];
            if (nr.info.x >= 0) {
                vec4 t = sampleRef(nr, uv0, uv1, g);
                n = t.xyz * 2.0 - 1.0;
                n.xy *= l.scalars0.x;
                // 1 - length grows as the slopes' variance, so as the square of the normal scale.
                len = clamp(1.0 - t.a * t.a * l.scalars0.x * l.scalars0.x, 0.0, 1.0);
            }
            s.normal = mix(s.normal, n, w);
            s.normalLength = mix(s.normalLength, len, w);
        }
        if ((bits & VITRINE_LAYER_SHININESS) != 0u) {
            GpuTexRef r = l.refs[VITRINE_REF_SHININESS];
            float t = r.info.x < 0 ? 1.0 : channelOf(sampleRef(r, uv0, uv1, g), r.info.z);
            s.shininess = mix(s.shininess, mix(l.scalars0.z, l.scalars0.y, t), w);
        }
        if ((bits & VITRINE_LAYER_METALLIC) != 0u) {
            GpuTexRef r = l.refs[VITRINE_REF_METALLIC];
            float t = r.info.x < 0 ? 1.0 : channelOf(sampleRef(r, uv0, uv1, g), r.info.z);
            s.metallic = mix(s.metallic, mix(l.scalars1.x, l.scalars0.w, t), w);
        }
        if ((bits & VITRINE_LAYER_CAVITY) != 0u) {
            GpuTexRef r = l.refs[VITRINE_REF_CAVITY];
            float t = r.info.x < 0 ? 1.0 : channelOf(sampleRef(r, uv0, uv1, g), r.info.z);
            s.cavity = mix(s.cavity, mix(l.scalars1.z, l.scalars1.y, t), w);
        }
    }
    return s;
}

// The shading normal (world) from the interpolated vertex normal and tangent (w: bitangent sign) and a tangent-space
// normal from evaluateLayers() (not unit length), flipped for back faces: gbuffer.layered's tangent frame, for
// forward passes.
vec3 shadingNormal(vec3 vertexNormal, vec4 tangent, vec3 tangentSpaceNormal, bool frontFacing) {
    vec3 n = normalize(vertexNormal);
    vec3 t = tangent.xyz - n * dot(n, tangent.xyz);
    t = dot(t, t) > 1e-12 ? normalize(t) : vec3(1.0, 0.0, 0.0);
    vec3 b = cross(n, t) * (tangent.w < 0.0 ? -1.0 : 1.0);
    float len = length(tangentSpaceNormal);
    vec3 nts = len > 1e-6 ? tangentSpaceNormal / len : vec3(0.0, 0.0, 1.0);
    vec3 N = normalize(t * nts.x + b * nts.y + n * nts.z);
    return frontFacing ? N : -N;
}

#endif

// A ray hit turned into a shading point for the path tracer (render.pathtrace) and bake.lightmap:
// position, geometric and shading normals (normal map applied), and the layered material evaluated by
// the same evaluateLayers() as gbuffer.layered, at LOD 0 (no ray cones: the top mip, so no Toksvig).
//
// Include after #version with VITRINE_SCENE_SET, VITRINE_SCENE_TEXTURES and VITRINE_BVH_SET defined, and
// VITRINE_GEOMETRY_SET: the set holding the scene's vertex buffer (binding 0, scene::Vertex as 18 floats)
// and index buffer (binding 1), GpuScene::vertexBuffer()/indexBuffer().
#ifndef PATHTRACE_SURFACE_GLSL
#define PATHTRACE_SURFACE_GLSL
#extension GL_GOOGLE_include_directive : require
#define VITRINE_SCENE_DIVERGENT_TEXTURES
#define VITRINE_SCENE_NO_DRAW_PUSH
#include "accel/bvh.glsl"
#include "common/brdf.glsl"
#include "scene/scene.glsl"

layout(set = VITRINE_GEOMETRY_SET, binding = 0, std430) readonly buffer SceneVertices { float sceneVertices[]; };
layout(set = VITRINE_GEOMETRY_SET, binding = 1, std430) readonly buffer SceneIndices { uint sceneIndices[]; };

const uint kVertexFloats = 18u; // position 3, normal 3, tangent 4, uv0 2, uv1 2, colour 4

struct PathSurface {
    vec3 position;
    vec3 geometricNormal; // faces the ray's origin
    vec3 normal;          // shading normal (normal map), on the same side as geometricNormal
    vec3 baseColor;       // layers x vertex colour
    float metallic;
    float roughness;
    float cavity;
    vec3 emissive;   // cd/m^2, before the node's emissive scale
    vec4 dielectric; // the dielectric's Fresnel F0 (rgb) and F90 (a): common/brdf.glsl dielectricSpecular
    vec2 coat;       // KHR_materials_clearcoat: strength, perceptual roughness (0, 0 without it)
    vec4 sheen;      // KHR_materials_sheen: colour (rgb), perceptual roughness (a); 0 without it
    vec3 coatNormal; // the coat's shading normal (its own normal map, else the vertex normal); `normal` without a coat
#ifdef PATHTRACE_SEE_THROUGH_SURFACE
    // What lets light pass (render.pathtrace's `transparent`: render/pathtrace.comp; the bake does not see through):
    float coverage;     // 0 where an alpha mask cuts the surface away, a blended surface's alpha, else 1
    float transmission; // KHR_materials_transmission's factor (0: opaque)
    // KHR_materials_volume's boundary (pathtrace/volume.glsl): a transmissive material with a thicknessFactor > 0.
    // The path refracts there and pays Beer's law for its way inside (render/pathtrace.comp).
    bool boundary;
    bool inside; // the boundary seen from inside its volume (its back face)
    float ior;   // KHR_materials_ior of a transmissive surface
    uint material; // the volume's material: which media a path is in, and their attenuation (pathtrace/media.glsl)
    float eta;     // the IOR on the ray's side over the IOR across: against air here, meetBoundary's in a medium
    vec4 specular; // KHR_materials_specular's colour (rgb) and strength (a), for an interface's Fresnel
    // What thin-walled glass lets through is tinted by: 1, but for a KHR_materials_volume on faces that bound nothing
    // (VITRINE_BVH_PRIMITIVE_OPEN_VOLUME) Beer's law over the refracted path through its thickness, as
    // forward.transparent tints it.
    vec3 attenuation;
#endif
};

vec3 vertexVec3(uint v, uint offset) {
    uint b = v * kVertexFloats + offset;
    return vec3(sceneVertices[b], sceneVertices[b + 1u], sceneVertices[b + 2u]);
}
vec4 vertexVec4(uint v, uint offset) {
    uint b = v * kVertexFloats + offset;
    return vec4(sceneVertices[b], sceneVertices[b + 1u], sceneVertices[b + 2u], sceneVertices[b + 3u]);
}
vec2 vertexVec2(uint v, uint offset) {
    uint b = v * kVertexFloats + offset;
    return vec2(sceneVertices[b], sceneVertices[b + 1u]);
}

// The IOR of a dielectric whose F0 is f0 = ((ior - 1) / (ior + 1))^2 (GpuMaterial optics.y).
float iorFromF0(float f0) {
    float r = sqrt(clamp(f0, 0.0, 0.98));
    return (1.0 + r) / (1.0 - r);
}

// Whether a material bounds a volume (pathtrace/volume.glsl): transmission and a thicknessFactor > 0.
bool materialBoundsVolume(GpuMaterial m) { return m.optics.x > 0.0 && m.optics.w > 0.0; }

// Whether a triangle bounds a volume: its material does and its mesh's faces of that material are closed (a volume
// material on faces that bound nothing is thin-walled glass: core/scene/closed_mesh.hpp).
bool boundsVolume(GpuMaterial m, GpuBvhPrimitive prim) {
    return materialBoundsVolume(m) && (prim.flags & VITRINE_BVH_PRIMITIVE_OPEN_VOLUME) == 0u;
}

// Whether the rasteriser would cull what the ray hit: the back of a triangle whose material is single sided
// (gbuffer.layered culls those; the BVH reports both sides). The front is counter-clockwise in world space.
bool pathCulled(BvhHit hit, vec3 direction) {
    GpuBvhTriangleRef ref = bvhRefs[hit.triangle];
    GpuBvhPrimitive prim = bvhPrimitives[ref.primitive];
    // A volume's back faces are where paths leave it: never culled.
    if (materials[ref.material].info.w != 0u || boundsVolume(materials[ref.material], prim)) return false;
    uint base = prim.firstIndex + 3u * ref.triangle;
    mat3 world = mat3(instances[hit.instance].world);
    vec3 p0 = world * vertexVec3(sceneIndices[base] + prim.vertexOffset, 0u);
    vec3 p1 = world * vertexVec3(sceneIndices[base + 1u] + prim.vertexOffset, 0u);
    vec3 p2 = world * vertexVec3(sceneIndices[base + 2u] + prim.vertexOffset, 0u);
    return dot(cross(p1 - p0, p2 - p0), direction) > 0.0;
}

// The closest surface the rasteriser would draw: back faces of single-sided materials are passed through, as
// gbuffer.layered culls them (shadow rays stop at either side, as shadow.directional draws both). The one rule of
// render.pathtrace and of bake.lightmap's bounces, both integrators (the CPU one: pathtrace_cpu.cpp traceVisible).
bool pathTraceVisible(vec3 origin, vec3 dir, out BvhHit hit) {
    float tmin = 0.0;
    for (int skip = 0; skip < 4; ++skip) {
        if (!bvhTraceClosest(origin, dir, tmin, 3.4e38, hit)) return false;
        if (!pathCulled(hit, dir)) return true;
        tmin = hit.t;
    }
    return false;
}

PathSurface pathSurface(BvhHit hit, vec3 origin, vec3 direction) {
    GpuBvhTriangleRef ref = bvhRefs[hit.triangle];
    GpuBvhPrimitive prim = bvhPrimitives[ref.primitive];
    uint i0 = sceneIndices[prim.firstIndex + 3u * ref.triangle] + prim.vertexOffset;
    uint i1 = sceneIndices[prim.firstIndex + 3u * ref.triangle + 1u] + prim.vertexOffset;
    uint i2 = sceneIndices[prim.firstIndex + 3u * ref.triangle + 2u] + prim.vertexOffset;
    vec3 bary = vec3(1.0 - hit.barycentrics.x - hit.barycentrics.y, hit.barycentrics);
    GpuInstance inst = instances[hit.instance];
    mat3 world = mat3(inst.world);
    mat3 normalMatrix = mat3(inst.normalMatrix);

    PathSurface s;
    s.position = origin + hit.t * direction;
    vec3 p0 = vertexVec3(i0, 0u), p1 = vertexVec3(i1, 0u), p2 = vertexVec3(i2, 0u);
    vec3 ng = normalize(normalMatrix * cross(p1 - p0, p2 - p0));
    bool backFace = dot(ng, direction) > 0.0;
    if (backFace) ng = -ng;
    s.geometricNormal = ng;

    vec3 n = normalMatrix * (bary.x * vertexVec3(i0, 3u) + bary.y * vertexVec3(i1, 3u) + bary.z * vertexVec3(i2, 3u));
    vec4 tangent = bary.x * vertexVec4(i0, 6u) + bary.y * vertexVec4(i1, 6u) + bary.z * vertexVec4(i2, 6u);
    vec2 uv0 = bary.x * vertexVec2(i0, 10u) + bary.y * vertexVec2(i1, 10u) + bary.z * vertexVec2(i2, 10u);
    vec2 uv1 = bary.x * vertexVec2(i0, 12u) + bary.y * vertexVec2(i1, 12u) + bary.z * vertexVec2(i2, 12u);
    vec4 color = bary.x * vertexVec4(i0, 14u) + bary.y * vertexVec4(i1, 14u) + bary.z * vertexVec4(i2, 14u);

    GpuMaterial m = materials[ref.material];
    UvGradients lod0;
    lod0.uv0 = vec4(0.0);
    lod0.uv1 = vec4(0.0);
    LayeredSurface l = evaluateLayers(m, uv0, uv1, lod0);

    // The G-buffer's tangent frame and normal mapping (gbuffer/layered.frag), flipped for back faces.
    n = dot(n, n) > 1e-20 ? normalize(n) : ng;
    vec3 t = world * tangent.xyz;
    t = t - n * dot(n, t);
    t = dot(t, t) > 1e-12 ? normalize(t) : vec3(1.0, 0.0, 0.0);
    vec3 b = cross(n, t) * (tangent.w < 0.0 ? -1.0 : 1.0);
    float len = length(l.normal);
    vec3 nts = len > 1e-6 ? l.normal / len : vec3(0.0, 0.0, 1.0);
    vec3 N = normalize(t * nts.x + b * nts.y + n * nts.z);
    if (backFace) N = -N;
    // A shading normal that faces away from the viewer (interpolation or a steep normal map) would
    // see no light at all; bend it back to the visible side.
    float NoV = dot(N, -direction);
    if (NoV < 0.01) N = normalize(N - direction * (0.01 - NoV));
    s.normal = N;
    s.coat = m.optics.z > 0.5 ? vec2(0.0) : materialClearcoat(m, uv0, uv1, lod0);
    s.coatNormal = N;
    s.sheen = m.optics.z > 0.5 ? vec4(0.0) : materialSheen(m, uv0, uv1, lod0);
    if (s.coat.x > 0.0) { // the same frame about the coat's own tangent-space normal
        vec3 c = materialClearcoatNormal(m, uv0, uv1, lod0);
        vec3 cts = length(c) > 1e-6 ? normalize(c) : vec3(0.0, 0.0, 1.0);
        vec3 C = normalize(t * cts.x + b * cts.y + n * cts.z);
        if (backFace) C = -C;
        float CoV = dot(C, -direction);
        if (CoV < 0.01) C = normalize(C - direction * (0.01 - CoV));
        s.coatNormal = C;
    }

    s.baseColor = l.albedo.rgb * color.rgb;
    s.metallic = clamp(l.metallic, 0.0, 1.0);
    s.roughness = roughnessFromShininess(clamp(l.shininess, 0.0, 1.0));
    s.cavity = clamp(l.cavity, 0.0, 1.0);
    // KHR_materials_specular over the fixed dielectric F0 of specularF0 (the tracer, like the G-buffer path, does
    // not read KHR_materials_ior).
    vec4 specular = materialSpecular(m, uv0, uv1, lod0);
    s.dielectric = dielectricSpecular(0.04, specular);
#ifdef PATHTRACE_SEE_THROUGH_SURFACE
    // As forward.transparent draws them: a mask's cut-off and a blend's alpha (the layers' alpha, not the vertex
    // colour's), and for transmission the dielectric's F0 from KHR_materials_ior; KHR_materials_volume's boundary.
    s.coverage = m.info.z == 1u ? (l.albedo.a < m.emissive.a ? 0.0 : 1.0) : m.info.z == 2u ? clamp(l.albedo.a, 0.0, 1.0) : 1.0;
    s.transmission = m.optics.x;
    s.boundary = boundsVolume(m, prim);
    s.inside = s.boundary && backFace;
    s.ior = iorFromF0(m.optics.y);
    s.material = ref.material;
    s.eta = s.inside ? s.ior : 1.0 / s.ior;
    s.specular = specular;
    s.attenuation = vec3(1.0);
    if (materialBoundsVolume(m) && !s.boundary && m.volume.a > 0.0) {
        vec3 modelScale = vec3(length(world[0]), length(world[1]), length(world[2]));
        vec3 crossing = normalize(refract(direction, N, 1.0 / s.ior)) * materialThickness(m, uv0, uv1, lod0) * modelScale;
        s.attenuation = pow(m.volume.rgb, vec3(length(crossing) / m.volume.a));
    }
    if (s.transmission > 0.0) s.dielectric = dielectricSpecular(m.optics.y, s.specular);
#endif
    s.emissive = m.emissive.rgb;
    if (m.emissiveRef.info.x >= 0) s.emissive *= sampleRef(m.emissiveRef, uv0, uv1, lod0).rgb;
    // KHR_materials_unlit, as gbuffer/unlit.glsl: the colour is emitted and nothing is reflected (cavity 0).
    if (m.optics.z > 0.5) {
        s.emissive = s.baseColor;
        s.baseColor = vec3(0.0);
        s.metallic = 0.0;
        s.cavity = 0.0;
    }
    return s;
}

#endif

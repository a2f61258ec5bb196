#version 460
#extension GL_GOOGLE_include_directive : require
#include "scene/scene.glsl"

// Lightmap texel G-buffer (core/bake/lightmap_raster.cpp): each lightmapped triangle drawn at its lightmap
// UVs, mapped into its instance's atlas region (draw.lightmap; draw.pad = region).
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 4) in vec2 inUv1;

layout(location = 0) out vec3 vWorld;
layout(location = 1) out vec3 vNormal;

void main() {
    GpuInstance inst = instances[draw.instance];
    vWorld = (inst.world * vec4(inPosition, 1.0)).xyz;
    vNormal = mat3(inst.normalMatrix) * inNormal;
    vec4 so = draw.lightmap;
    vec2 atlas = inUv1 * so.xy + so.zw; // 0..1 over the atlas
    gl_Position = vec4(atlas * 2.0 - 1.0, 0.5, 1.0);
}

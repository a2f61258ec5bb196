#version 460
#extension GL_GOOGLE_include_directive : require
#include "scene/scene.glsl"
#include "scene/jitter.glsl"

layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inTangent;
layout(location = 3) in vec2 inUv0;
layout(location = 4) in vec2 inUv1;
layout(location = 5) in vec4 inColor;

layout(location = 0) out vec3 vNormal;
layout(location = 1) out vec4 vTangent;
layout(location = 2) out vec2 vUv0;
layout(location = 3) out vec2 vUv1;
layout(location = 4) out vec4 vColor;
layout(location = 5) out vec4 vClip;     // this frame, unjittered
layout(location = 6) out vec4 vPrevClip; // last frame, unjittered
layout(location = 7) out float vViewDepth;

void main() {
    GpuInstance inst = instances[draw.instance];
    vec4 world = inst.world * vec4(inPosition, 1.0);
    // A re-skinned or re-morphed vertex was elsewhere last frame (GpuScene::update()).
    vec3 prevPosition = inst.flags.x != 0.0 ? scenePrevPositions[gl_VertexIndex].xyz : inPosition;
    vec4 prevWorld = inst.prevWorld * vec4(prevPosition, 1.0);
    mat3 nm = mat3(inst.normalMatrix);
    vNormal = nm * inNormal;
    vTangent = vec4(mat3(inst.world) * inTangent.xyz, inTangent.w);
    vUv0 = inUv0;
    vUv1 = inUv1;
    vColor = inColor;
    vClip = camera.viewProjNoJitter * world;
    vPrevClip = camera.prevViewProjNoJitter * prevWorld;
    vViewDepth = -(camera.view * world).z;
    gl_Position = jitteredClip(world, vClip, vPrevClip);
}

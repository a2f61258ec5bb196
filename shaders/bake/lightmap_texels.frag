#version 460
#extension GL_GOOGLE_include_directive : require
#include "scene/scene.glsl"

layout(location = 0) in vec3 vWorld;
layout(location = 1) in vec3 vNormal;

layout(location = 0) out vec4 outPosition; // world position, w: region index + 1
layout(location = 1) out vec4 outNormal;   // unit world normal

void main() {
    outPosition = vec4(vWorld, float(draw.pad + 1u));
    outNormal = vec4(normalize(vNormal), 0.0);
}

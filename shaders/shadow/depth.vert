#version 460
#extension GL_GOOGLE_include_directive : require
#include "scene/scene.glsl"

// Depth-only scene draw for shadow.directional: the cascade's matrix comes in draw.viewProj.
layout(location = 0) in vec3 inPosition;

void main() {
    gl_Position = draw.viewProj * (instances[draw.instance].world * vec4(inPosition, 1.0));
}

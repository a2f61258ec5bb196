#ifndef VITRINE_CUBEMAP_GLSL
#define VITRINE_CUBEMAP_GLSL

// Cube-map texel geometry in Vulkan's convention (what samplerCube does); CPU mirror:
// core/shading/cubemap.hpp. Layers are +X, -X, +Y, -Y, +Z, -Z; on a face of size N, texel
// (x, y) (y = row, 0 at the top) has face coordinates u = 2 (x + 0.5) / N - 1, v likewise.

// Unnormalised direction through face coordinates (u, v) in [-1, 1]^2.
vec3 cubeDirection(uint face, vec2 uv) {
    switch (face) {
    case 0u: return vec3(1.0, -uv.y, -uv.x);
    case 1u: return vec3(-1.0, -uv.y, uv.x);
    case 2u: return vec3(uv.x, 1.0, uv.y);
    case 3u: return vec3(uv.x, -1.0, -uv.y);
    case 4u: return vec3(uv.x, -uv.y, 1.0);
    default: return vec3(-uv.x, -uv.y, -1.0);
    }
}

vec3 cubeTexelDirection(uint face, ivec2 texel, int size) {
    return normalize(cubeDirection(face, (vec2(texel) + 0.5) * (2.0 / float(size)) - 1.0));
}

// The face a direction falls on and its face coordinates (inverse of cubeDirection).
uint cubeFace(vec3 d, out vec2 uv) {
    vec3 a = abs(d);
    if (a.x >= a.y && a.x >= a.z) {
        uv = d.x > 0.0 ? vec2(-d.z, -d.y) / a.x : vec2(d.z, -d.y) / a.x;
        return d.x > 0.0 ? 0u : 1u;
    }
    if (a.y >= a.z) {
        uv = d.y > 0.0 ? vec2(d.x, d.z) / a.y : vec2(d.x, -d.z) / a.y;
        return d.y > 0.0 ? 2u : 3u;
    }
    uv = d.z > 0.0 ? vec2(d.x, -d.y) / a.z : vec2(-d.x, -d.y) / a.z;
    return d.z > 0.0 ? 4u : 5u;
}

// Solid angle of the rectangle from the face centre to (x, y) on the unit-distance face.
float cubeCornerArea(float x, float y) { return atan(x * y, sqrt(x * x + y * y + 1.0)); }

// Exact solid angle (sr) of a texel; the 6 N^2 texels sum to 4 pi.
float cubeTexelSolidAngle(ivec2 texel, int size) {
    float s = 2.0 / float(size);
    float x0 = float(texel.x) * s - 1.0, x1 = x0 + s;
    float y0 = float(texel.y) * s - 1.0, y1 = y0 + s;
    return cubeCornerArea(x0, y0) - cubeCornerArea(x0, y1) - cubeCornerArea(x1, y0) + cubeCornerArea(x1, y1);
}

#endif

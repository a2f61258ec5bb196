#version 460
#extension GL_GOOGLE_include_directive : require
#include "ibl/localized.h"
// ibl.localized's proxies: the influence volume of probe gl_InstanceIndex, generated from gl_VertexIndex (no vertex
// buffer), triangles counter-clockwise seen from outside. A box is its 12 triangles along its rotated axes; a
// sphere is a 16 x 8 latitude-longitude mesh whose vertices lie at 1.1 radii so that every face stays outside the
// sphere (its cells span at most ~0.28 rad: cos 0.28 = 0.96 > 1 / 1.1). The fragment shader rejects what lies
// outside the exact volume.
layout(set = 0, binding = 0) uniform Uniforms { LocalizedUniforms u; };
layout(location = 0) flat out int vProbe;

const int kSphereLon = 16;
const int kSphereLat = 8;
const float kSphereScale = 1.1;
const vec2 kQuad[6] = vec2[6](vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, -1), vec2(1, 1), vec2(-1, 1));

void main() {
    LocalizedProbe pr = u.probes[gl_InstanceIndex];
    vec3 local;
    if (pr.center.w > 0.5) {
        int cell = gl_VertexIndex / 6;
        vec2 q = kQuad[gl_VertexIndex % 6] * 0.5 + 0.5; // x along latitude (theta), y along longitude (phi)
        float theta = (float(cell % kSphereLat) + q.x) * (3.14159265 / float(kSphereLat));
        float phi = (float(cell / kSphereLat) + q.y) * (6.28318531 / float(kSphereLon));
        local = vec3(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta)) * kSphereScale;
    } else {
        int face = gl_VertexIndex / 6;
        int axis = face >> 1;
        float s = (face & 1) == 0 ? 1.0 : -1.0;
        vec3 e[3] = vec3[3](vec3(1, 0, 0), vec3(0, 1, 0), vec3(0, 0, 1));
        // t1 x t2 = the outward normal s * e[axis], so the quad's order is counter-clockwise from outside.
        vec3 t1 = s > 0.0 ? e[(axis + 1) % 3] : e[(axis + 2) % 3];
        vec3 t2 = s > 0.0 ? e[(axis + 2) % 3] : e[(axis + 1) % 3];
        vec2 c = kQuad[gl_VertexIndex % 6];
        local = s * e[axis] + c.x * t1 + c.y * t2;
    }
    vec3 world = pr.center.xyz;
    if (pr.center.w > 0.5) world += local * pr.axisX.w;
    else world += pr.axisX.xyz * (local.x * pr.axisX.w) + pr.axisY.xyz * (local.y * pr.axisY.w) + pr.axisZ.xyz * (local.z * pr.axisZ.w);
    gl_Position = u.viewProj * vec4(world, 1.0);
    vProbe = gl_InstanceIndex;
}

#version 460
#extension GL_GOOGLE_include_directive : require
#include "post/lens.h"
#include "camera/exposure.glsl"

// Lens imperfections on the finished HDR image, each switchable: radial distortion (Brown's model in its two radial
// terms), lateral chromatic aberration (a radial scale per channel), natural vignetting (cos^4 law) and mechanical
// vignetting (the entrance pupil clipped by the lens barrel: the overlap of two discs, cat's-eye bokeh's cause).
// The output is the image the sensor sees: for each output pixel the ideal radius is found by inverting the
// distortion polynomial (Newton), per channel after undoing that channel's CA scale, and the input is sampled there.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_color;
layout(binding = 1) writeonly uniform image2D out_color;

const float kPi = 3.14159265358979;

// The ideal radius r with r (1 + k1 r^2 + k2 r^4) = rd.
float undistort(float rd) {
    float r = rd;
    for (int i = 0; i < 8; ++i) {
        float r2 = r * r;
        float f = r * (1.0 + pc.k1 * r2 + pc.k2 * r2 * r2) - rd;
        float df = 1.0 + 3.0 * pc.k1 * r2 + 5.0 * pc.k2 * r2 * r2;
        r -= f / max(df, 1e-3);
    }
    return r;
}

// The ideal-image position whose light lands at sensor offset `d` (pixels from the centre) in a channel whose
// image is scaled by `scale`.
vec2 sourceOffset(vec2 d, float scale) {
    vec2 dn = d / (pc.halfDiagonal * scale);
    float rd = length(dn);
    if ((pc.flags & LENS_DISTORTION) != 0u && rd > 0.0) dn *= undistort(rd) / rd;
    return dn * pc.halfDiagonal;
}

// Area of the intersection of discs of radius a and b whose centres are d apart.
float discOverlap(float a, float b, float d) {
    if (d >= a + b) return 0.0;
    if (d <= abs(a - b)) return kPi * min(a, b) * min(a, b);
    float ca = clamp((d * d + a * a - b * b) / (2.0 * d * a), -1.0, 1.0);
    float cb = clamp((d * d + b * b - a * a) / (2.0 * d * b), -1.0, 1.0);
    float k = (-d + a + b) * (d + a - b) * (d - a + b) * (d + a + b);
    return a * a * acos(ca) + b * b * acos(cb) - 0.5 * sqrt(max(k, 0.0));
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_color);
    if (any(greaterThanEqual(p, size))) return;
    vec2 d = vec2(p) + 0.5 - pc.centre;
    vec2 invSize = 1.0 / vec2(size);
    vec4 g = textureLod(in_color, (pc.centre + sourceOffset(d, 1.0)) * invSize, 0.0);
    vec3 c = g.rgb;
    if ((pc.flags & LENS_CA) != 0u) {
        c.r = textureLod(in_color, (pc.centre + sourceOffset(d, pc.caRed)) * invSize, 0.0).r;
        c.b = textureLod(in_color, (pc.centre + sourceOffset(d, pc.caBlue)) * invSize, 0.0).b;
    }
    float v = 1.0;
    if ((pc.flags & LENS_NATURAL_VIGNETTING) != 0u) {
        float t = length(d) * pc.mmPerPixel / pc.focalMm; // tan of the field angle
        float cos2 = 1.0 / (1.0 + t * t);
        v *= cos2 * cos2;
    }
    if ((pc.flags & LENS_MECHANICAL_VIGNETTING) != 0u) {
        float pupil = pc.pupil, mechanical = pc.mechanical;
#ifdef CAMERA_EXPOSURE
        // The camera's aperture, on the GPU: pc.pupil is the wide-open f-number and pc.mechanical 1 then.
        pupil = clamp(pc.pupil / max(cameraExposure.fNumber, 1e-3), 1e-3, 1.0);
        mechanical *= cameraExposure.mechanicalVignetting;
#endif
        float offset = mechanical * length(d) / pc.halfDiagonal;
        v *= discOverlap(pupil, 1.0, offset) / (kPi * pupil * pupil);
    }
    imageStore(out_color, p, vec4(c * v, g.a));
}

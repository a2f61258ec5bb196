#version 460
#extension GL_GOOGLE_include_directive : require
#include "camera/meter.h"

// One 16x16 tile of the metered image -> its histogram: tiles[tile * METER_BINS + bin] = (Σw, Σw·log2 Y).
layout(local_size_x = METER_TILE, local_size_y = METER_TILE) in;
layout(binding = 0) uniform sampler2D in_color;
layout(set = 1, binding = 0) writeonly buffer Tiles { vec2 tiles[]; };

shared uint sWeight[METER_BINS];
shared uint sPosition[METER_BINS];

void main() {
    uint lid = gl_LocalInvocationIndex;
    if (lid < METER_BINS) {
        sWeight[lid] = 0u;
        sPosition[lid] = 0u;
    }
    barrier();

    const float binWidth = (METER_MAX_LOG2 - METER_MIN_LOG2) / float(METER_BINS);
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = textureSize(in_color, 0);
    if (all(lessThan(p, size))) {
        vec3 c = max(texelFetch(in_color, p, 0).rgb, vec3(0.0));
        float y = dot(c, vec3(0.2126, 0.7152, 0.0722));
        float l = clamp(log2(max(y, 1e-30)), METER_MIN_LOG2, METER_MAX_LOG2);
        float t = (l - METER_MIN_LOG2) / binWidth;
        uint bin = min(uint(t), uint(METER_BINS - 1));
        float inBin = clamp(t - float(bin), 0.0, 1.0);
        // Centre weighting: a Gaussian around the image centre, blended with uniform (average) metering.
        vec2 d = (vec2(p) + 0.5 - 0.5 * vec2(size)) / (0.5 * float(size.y));
        float w = (1.0 - pc.centreWeight) + pc.centreWeight * exp(-dot(d, d) / (2.0 * pc.centreSigma * pc.centreSigma));
        atomicAdd(sWeight[bin], uint(w * METER_FIXED_ONE + 0.5));
        atomicAdd(sPosition[bin], uint(w * inBin * METER_FIXED_ONE + 0.5));
    }
    barrier();

    if (lid < METER_BINS) {
        uint tile = gl_WorkGroupID.y * pc.tilesX + gl_WorkGroupID.x;
        float w = float(sWeight[lid]) / METER_FIXED_ONE;
        float wt = float(sPosition[lid]) / METER_FIXED_ONE;
        // Σ w log2 Y = Σ w (binStart + t·binWidth) = binStart Σw + binWidth Σ w t.
        float binStart = METER_MIN_LOG2 + float(lid) * binWidth;
        tiles[tile * METER_BINS + lid] = vec2(w, binStart * w + binWidth * wt);
    }
}

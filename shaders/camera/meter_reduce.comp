#version 460
#extension GL_GOOGLE_include_directive : require
#include "camera/meter.h"

// Workgroup b sums bin b over every tile: result[b] = Σ_tiles tiles[tile * METER_BINS + b].
layout(local_size_x = METER_REDUCE_GROUP) in;
layout(set = 1, binding = 0) readonly buffer Tiles { vec2 tiles[]; };
layout(set = 1, binding = 1) writeonly buffer Result { vec2 result[]; };

shared vec2 sSum[METER_REDUCE_GROUP];

void main() {
    uint bin = gl_WorkGroupID.x;
    uint lid = gl_LocalInvocationIndex;
    vec2 s = vec2(0.0);
    for (uint t = lid; t < pc.tileCount; t += METER_REDUCE_GROUP) s += tiles[t * METER_BINS + bin];
    sSum[lid] = s;
    barrier();
    for (uint k = METER_REDUCE_GROUP / 2; k > 0u; k >>= 1) {
        if (lid < k) sSum[lid] += sSum[lid + k];
        barrier();
    }
    if (lid == 0u) result[bin] = sSum[0];
}

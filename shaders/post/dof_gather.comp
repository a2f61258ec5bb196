#version 460
#extension GL_GOOGLE_include_directive : require
#include "post/dof.h"
#include "post/aperture.glsl"
#include "post/dof_layers.glsl"
#include "camera/exposure.glsl"

// The aperture's roundness and area: the camera's at its f-number, on the GPU, or the push constants'.
#ifdef CAMERA_EXPOSURE
#define DOF_ROUNDNESS cameraExposure.apertureRoundness
#define DOF_APERTURE_AREA cameraExposure.apertureArea
#else
#define DOF_ROUNDNESS pc.roundness
#define DOF_APERTURE_AREA pc.apertureArea
#endif

// post.dof pass 3: the layers, gathered and composited, plus the scattered sprites.
// The frame's signed CoC range [-span, span] is cut into `layers` layers (Kawase 2008/2012: the demo used up to 15;
// shaders/post/dof_layers.glsl), layer i blurred with the CoC at its centre. At full resolution (no shrink buffer, so no shrink-buffer
// artefacts (Kawase 2009) where the CoC jumps: every tap reads its own pixel's colour and CoC), each pixel
// gathers, for every layer present in the 16x16 tiles around it, the taps of an aperture-shaped kernel of the
// layer's CoC (up to a radius of 2.5 pixels every pixel of the footprint weighted by its coverage; beyond, 24-64
// taps, one per 2 pixels of the kernel, on a Vogel spiral over the disc pushed out to the aperture's boundary, each weighted by the boundary's square so
// the density is uniform over the shape) that belong to that layer: their mean colour with the
// fraction of the kernel they cover as alpha. Layers are composited far to near (nearer layers cover farther
// ones, so a sharp object is never smeared over its blurred background and a blurred near object spreads over
// what is behind it), then divided by the total coverage: the background behind a sharp edge is extended from its
// own pixels rather than darkened. A gather kernel is the bokeh point-reflected: behind the focus plane taps come
// from the reflected aperture (the far bokeh shows the aperture upright), in front from the aperture itself (the
// near bokeh is inverted, as through a real lens). Sprites add their colour spread evenly over the aperture shape
// of their own CoC (edges antialiased over a pixel) to their layer, and are hidden by nearer layers like it.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, r32f) readonly uniform image2D out_coc;
layout(binding = 1, rgba32f) readonly uniform image2D out_prepared;
layout(binding = 2, r32ui) readonly uniform uimage2D out_tiles;
layout(binding = 3, r32ui) readonly uniform uimage2D out_sprite_count;
layout(binding = 4, rgba32f) readonly uniform image2D out_sprites;
layout(binding = 5) writeonly uniform image2D out_color;

float boundary(float theta) { return apertureBoundary(pc.blades, DOF_ROUNDNESS, pc.rotation, theta); }

shared vec4 sSprite[64];
shared vec3 sColor[64];
shared uint sCount;
shared vec4 sTap[64]; // this layer's taps: offset (pixels, y down), weight
shared uint sMask;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_color);
    bool inImage = all(lessThan(p, size));
    p = min(p, size - 1); // threads outside the image still take part in the sprite binning's barriers

    float span = layerSpan(imageLoad(out_sprite_count, ivec2(1, 0)).r);
    ivec2 tiles = imageSize(out_tiles);
    int reach = int(ceil((0.5 * span + 1.0) / float(DOF_TILE)));
    ivec2 tile = p / DOF_TILE;
    // The layers this pixel needs: those present in a tile within their own kernel's reach.
    uint mask = 0u;
    for (int ty = -reach; ty <= reach; ++ty)
        for (int tx = -reach; tx <= reach; ++tx) {
            ivec2 t = tile + ivec2(tx, ty);
            if (any(lessThan(t, ivec2(0))) || any(greaterThanEqual(t, tiles))) continue;
            vec2 lo = vec2(t * DOF_TILE), hi = lo + float(DOF_TILE);
            float dist = length(max(max(lo - (vec2(p) + 0.5), (vec2(p) + 0.5) - hi), vec2(0.0)));
            uint reachable = 0u;
            for (uint l = 0u; l < pc.layers; ++l)
                if (0.5 * abs(layerCoc(l, span)) + 1.0 >= dist) reachable |= 1u << l;
            mask |= imageLoad(out_tiles, t).r & reachable;
        }

    // Sprites, binned per 8x8 group: 64 at a time are loaded by the group's threads, those whose square reaches the
    // group's pixels kept in shared memory, and every pixel tests only these.
    vec3 spriteAdd[DOF_MAX_LAYERS];
    for (int i = 0; i < DOF_MAX_LAYERS; ++i) spriteAdd[i] = vec3(0.0);
    uint count = min(imageLoad(out_sprite_count, ivec2(0, 0)).r, pc.maxSprites);
    vec2 centre = vec2(p) + 0.5;
    vec2 groupMin = vec2(gl_WorkGroupID.xy * gl_WorkGroupSize.xy), groupMax = groupMin + vec2(gl_WorkGroupSize.xy);
    for (uint base = 0u; base < count; base += 64u) {
        if (gl_LocalInvocationIndex == 0u) sCount = 0u;
        barrier();
        uint s = base + gl_LocalInvocationIndex;
        if (s < count) {
            vec4 a = imageLoad(out_sprites, ivec2(2 * s, 0));
            float r = 0.5 * abs(a.z) + 1.0;
            if (all(greaterThanEqual(a.xy + r, groupMin)) && all(lessThanEqual(a.xy - r, groupMax))) {
                uint k = atomicAdd(sCount, 1u);
                sSprite[k] = a;
                sColor[k] = imageLoad(out_sprites, ivec2(2 * s + 1, 0)).rgb;
            }
        }
        barrier();
        for (uint k = 0u; k < sCount; ++k) {
            vec4 a = sSprite[k];
            vec2 d = centre - a.xy;
            float r = 0.5 * abs(a.z);
            float dist = length(d);
            if (dist > r + 1.0) continue;
            vec2 up = vec2(d.x, -d.y) * (a.z < 0.0 ? -1.0 : 1.0); // y up; the near bokeh inverted
            float edge = r * boundary(atan(up.y, up.x));
            float cover = clamp(edge - dist + 0.5, 0.0, 1.0);
            if (cover > 0.0) spriteAdd[layerOf(a.z, span)] += sColor[k] * cover / (DOF_APERTURE_AREA * r * r);
        }
        barrier();
    }
    // The kernel's taps depend on the layer only, not on the pixel: the group's threads compute them once per layer
    // present anywhere in the group (one tap a thread, at most 64) into shared memory, and every pixel reads them.
    if (gl_LocalInvocationIndex == 0u) sMask = 0u;
    barrier();
    atomicOr(sMask, mask);
    barrier();
    uint groupMask = sMask;

    uint own = layerOf(imageLoad(out_coc, p).r, span);
    vec3 acc = vec3(0.0), accSprites = vec3(0.0);
    float transmittance = 1.0;
    for (int l = int(pc.layers) - 1; l >= 0; --l) {
        if ((groupMask & (1u << uint(l))) == 0u) continue; // uniform over the group: the barriers below stay uniform
        float centreCoc = layerCoc(uint(l), span);
        float r = 0.5 * abs(centreCoc);
        // A gather kernel is the bokeh point-reflected: behind the focus plane the taps come from the reflected aperture.
        float flip = centreCoc > 0.0 ? -1.0 : 1.0;
        int reachPx = int(ceil(r + 0.5));
        int side = 2 * reachPx + 1;
        int taps = r <= 2.5 ? side * side : clamp(int(DOF_APERTURE_AREA * r * r * 0.5), 24, 64);
        if (r >= 1.0) {
            barrier(); // the previous layer's taps are read
            int i = int(gl_LocalInvocationIndex);
            if (i < taps) {
                if (r <= 2.5) {
                    // Small kernels: every pixel of the footprint, weighted by how much of it the aperture covers (its
                    // edge antialiased over a pixel), so the few taps do not alias.
                    int x = i % side - reachPx, y = i / side - reachPx;
                    vec2 up = flip * vec2(x, -y); // the offset in the aperture's frame (y up)
                    float dist = length(up);
                    float w = clamp(r * boundary(atan(up.y, up.x)) - dist + 0.5, 0.0, 1.0);
                    sTap[i] = vec4(x, y, w, 0.0);
                } else {
                    // 24-64 taps on a Vogel spiral over the disc pushed out to the aperture's boundary, each weighted
                    // by the boundary's square so the density is uniform over the shape.
                    float theta = float(i) * 2.39996323;
                    float b = boundary(theta);
                    vec2 o = flip * sqrt((float(i) + 0.5) / float(taps)) * b * r * vec2(cos(theta), sin(theta));
                    float w = b * b;
                    sTap[i] = vec4(o.x, -o.y, w, 0.0);
                }
            }
            barrier();
        }
        if (!inImage || (mask & (1u << uint(l))) == 0u) continue;
        vec3 sum = vec3(0.0);
        float alpha = 0.0;
        if (r < 1.0) {
            if (own == uint(l)) {
                sum = imageLoad(out_prepared, p).rgb;
                alpha = 1.0;
            }
        } else {
            float weightSum = 0.0, inside = 0.0;
            for (int i = 0; i < taps; ++i) {
                vec4 tap = sTap[i];
                if (tap.z <= 0.0) continue;
                ivec2 q = r <= 2.5 ? p + ivec2(tap.xy) : ivec2(floor(centre + tap.xy));
                vec4 t = imageLoad(out_prepared, clamp(q, ivec2(0), size - 1)); // colour, layer
                weightSum += tap.z;
                if (t.a == float(l)) {
                    sum += tap.z * t.rgb;
                    inside += tap.z;
                }
            }
            sum /= weightSum;
            alpha = inside / weightSum;
        }
        acc = sum + (1.0 - alpha) * acc;
        accSprites = spriteAdd[l] + (1.0 - alpha) * accSprites;
        transmittance *= 1.0 - alpha;
    }
    if (!inImage) return;
    float coverage = 1.0 - transmittance;
    vec3 gathered = coverage > 1e-4 ? acc / coverage : imageLoad(out_prepared, p).rgb;
    imageStore(out_color, p, vec4(gathered + accSprites, 1.0));
}

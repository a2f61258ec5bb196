#version 460
#extension GL_GOOGLE_include_directive : require
#include "ssr/hiz.h"
#include "common/brdf.glsl"
#include "common/mip_atlas.glsl"
#include "common/octahedral.glsl"
#include "pathtrace/sampling.glsl"

// Hi-Z screen-space cone-traced reflections [Uludag14] as the Museum demo used them (MUSEUM_SPEC §5): per
// pixel 1-4 rays by roughness, each a GGX visible normal [Heitz18] reflected; each ray marched through the
// min/max Hi-Z pyramid in screen space (x, y in pixels, reverse-Z depth: a straight line there) with at most
// max_taps fetches; at the hit the colour pyramid is read at the level of the ray's cone footprint (times
// cone_scale). The confidence of a hit is the product of a screen-edge fade, a back-face test, a thickness test and a
// ray-length fade; a ray that leaves the screen, runs out of taps or misses has none. No spatial filter. The output is
// premultiplied, (radiance x confidence, confidence), so that whatever filters it next (the temporal accumulation's
// running mean, the composite's bilinear upsampling) is linear: a pixel that found nothing is (0, 0) and lowers the
// confidence of its neighbours' mix without darkening its colour.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_normal;
layout(binding = 1) uniform sampler2D in_depth;
layout(binding = 2, rg32f) readonly uniform image2D in_hiz;
layout(binding = 3) uniform sampler2D in_color;
layout(binding = 4) uniform sampler2D in_velocity;
layout(binding = 5) writeonly uniform image2D out_reflection;
layout(binding = 6) uniform Uniforms { SsrUniforms u; };

// Reverse-Z hardware depth <-> view depth (m) through the projection's z and w rows.
float viewDepthOf(float z) { return (u.depthParams.y - z * u.depthParams.w) / (u.depthParams.x - z * u.depthParams.z); }
float depthOfView(float d) {
    return (u.depthParams.y - u.depthParams.x * d) / (u.depthParams.w - u.depthParams.z * d);
}
vec3 unproject(vec2 uv, float z) {
    vec4 w = u.invViewProj * vec4(uv * 2.0 - 1.0, z, 1.0);
    return w.xyz / w.w;
}
vec3 project(vec3 world) {
    vec4 c = u.viewProj * vec4(world, 1.0);
    return vec3(c.xy / c.w * 0.5 + 0.5, c.z / c.w);
}

// The depth `thickness` metres behind a surface of depth z: surfaces are slabs that thick.
float behind(float z) { return z <= 0.0 ? 0.0 : depthOfView(viewDepthOf(z) + u.params.x); }

// Reverse-Z depth of the surface at level-0 pixel position x (not a centre): bilinear between the four nearest
// texel centres, exact on a plane (its reverse-Z depth is affine in screen space).
float surfaceDepthAt(vec2 x) {
    vec2 f = x - 0.5;
    ivec2 i = ivec2(floor(f));
    vec2 w = f - vec2(i);
    ivec2 last = u.size.xy - 1;
    float d00 = texelFetch(in_depth, clamp(i, ivec2(0), last), 0).r;
    float d10 = texelFetch(in_depth, clamp(i + ivec2(1, 0), ivec2(0), last), 0).r;
    float d01 = texelFetch(in_depth, clamp(i + ivec2(0, 1), ivec2(0), last), 0).r;
    float d11 = texelFetch(in_depth, clamp(i + ivec2(1, 1), ivec2(0), last), 0).r;
    return mix(mix(d00, d10, w.x), mix(d01, d11, w.x), w.y);
}

// Ray parameter where the screen-space ray o + d t leaves Hi-Z cell `cell` of `level`.
float cellExit(vec3 o, vec3 d, int level, ivec2 cell) {
    vec2 lo, hi;
    mipCellBounds(u.size.xy, level, cell, lo, hi);
    vec2 tt = vec2(1e30);
    for (int a = 0; a < 2; ++a) {
        if (d[a] > 0.0) tt[a] = (hi[a] - o[a]) / d[a];
        else if (d[a] < 0.0) tt[a] = (lo[a] - o[a]) / d[a];
    }
    return min(tt.x, tt.y);
}

// Radiance along world ray (origin, r) from a surface of normal n and its confidence (a).
vec4 traceRay(vec3 origin, vec3 n, vec3 o, vec3 r, float coneTan) {
    // End point: max_distance along r, or short of the near plane when the ray comes towards the camera.
    float len = u.params.y;
    float towards = dot(r, u.cameraFwd.xyz);
    float depth0 = dot(origin - u.cameraPos.xyz, u.cameraFwd.xyz);
    if (towards < 0.0) len = min(len, (depth0 - 2.0 * u.cameraPos.w) / -towards);
    if (len <= 0.0) return vec4(0.0);
    vec2 size = vec2(u.size.xy);
    vec3 e = project(origin + r * len);
    vec3 op = vec3(o.xy * size, o.z);
    vec3 dp = vec3(e.xy * size, e.z) - op;
    // Clip to the screen: past tEnd the ray has left it.
    float tEnd = 1.0;
    for (int a = 0; a < 2; ++a) {
        if (dp[a] > 0.0) tEnd = min(tEnd, (size[a] - op[a]) / dp[a]);
        else if (dp[a] < 0.0) tEnd = min(tEnd, -op[a] / dp[a]);
    }
    float nudge = 0.01 / max(max(abs(dp.x), abs(dp.y)), 1e-6); // a hundredth of a pixel
    float t = cellExit(op, dp, 0, ivec2(op.xy)) + nudge;       // start outside the origin's own texel
    int level = 0;
    bool found = false;
    vec2 range = vec2(0.0);
    for (uint i = 0u; i < u.config.x && t < tEnd; ++i) {
        vec3 pt = op + dp * t;
        ivec2 cell = clamp(ivec2(floor(pt.xy)) >> level, ivec2(0), mipSize(u.size.xy, level) - 1);
        float tExit = min(cellExit(op, dp, level, cell), tEnd);
        range = imageLoad(in_hiz, mipOffset(u.size.xy, level) + cell).rg; // (farthest, nearest)
        float zBehind = behind(range.x);
        float za = op.z + dp.z * t, zb = op.z + dp.z * tExit;
        if (min(za, zb) > range.y || max(za, zb) < zBehind) {
            // The ray passes in front of (or behind) everything in the cell: skip it, coarser next.
            t = tExit + nudge;
            level = min(level + 1, u.size.z - 1);
            continue;
        }
        // Move to where the ray enters the cell's depth slab, then refine (or stop at level 0).
        if (dp.z < 0.0 && za > range.y) t = max(t, (range.y - op.z) / dp.z);
        else if (dp.z > 0.0 && za < zBehind) t = max(t, (zBehind - op.z) / dp.z);
        if (level == 0) {
            // A level-0 texel holds one depth: a ray leaving a surface at a low angle lies within the slab behind a
            // neighbouring texel's depth while it stays in front of the surface itself. A candidate on the ray's own
            // surface (its texel on the origin's tangent plane) that faces away from the ray is such a self-hit:
            // march on. Other back faces stay hits, for the back-face test below.
            ivec2 tc = clamp(ivec2(floor((op + dp * t).xy)), ivec2(0), u.size.xy - 1);
            if (dot(octDecode(texelFetch(in_normal, tc, 0).xy), r) >= 0.0) {
                vec3 s = unproject((vec2(tc) + 0.5) / size, texelFetch(in_depth, tc, 0).r) - origin;
                if (abs(dot(s, n)) < 0.05 * length(s)) {
                    t = tExit + nudge;
                    continue;
                }
            }
            found = true;
            break;
        }
        --level;
    }
    if (!found) return vec4(0.0);

    // A level-0 texel holds one depth, so the hit is only known to a pixel or two: bisect (4 steps, 1/4 px) the
    // ray's depth minus the interpolated surface depth over two pixels either side, where it changes sign.
    float tPixel = 100.0 * nudge;
    float ta = max(t - 2.0 * tPixel, 0.0), tb = min(t + 2.0 * tPixel, tEnd);
    bool refined = op.z + dp.z * ta > surfaceDepthAt((op + dp * ta).xy) &&
                   op.z + dp.z * tb <= surfaceDepthAt((op + dp * tb).xy);
    if (refined) {
        for (int k = 0; k < 4; ++k) {
            float tm = 0.5 * (ta + tb);
            if (op.z + dp.z * tm > surfaceDepthAt((op + dp * tm).xy)) ta = tm;
            else tb = tm;
        }
        t = 0.5 * (ta + tb);
    }

    vec3 ph = op + dp * t;
    // A march that went through NaN (measured: a handful of rays per frame at the museum's lower screen edge) has
    // no hit: its colour coordinates and cone footprint would be NaN, and the pyramid read at NaN coordinates is
    // undefined (it read the atlas's unwritten corner: images that differed from run to run).
    if (any(isnan(ph)) || any(isinf(ph))) return vec4(0.0);
    vec2 uvHit = ph.xy / size;
    ivec2 texel = clamp(ivec2(floor(ph.xy)), ivec2(0), u.size.xy - 1);
    float hitDepth = viewDepthOf(ph.z);
    float surfaceDepth = refined ? hitDepth : viewDepthOf(range.y); // a refined hit crosses the surface
    // Thickness: how far behind the surface the ray was found (0 where it crosses it). The front half of the slab
    // counts fully (a level-0 texel holds one depth, so a ray crossing a slanted surface is found a little behind
    // it); confidence fades over the back half.
    float fThickness = clamp(2.0 - 2.0 * max(hitDepth - surfaceDepth, 0.0) / u.params.x, 0.0, 1.0);
    // Back faces: the G-buffer's normal faces the camera; a ray arriving along it hit the surface's back.
    float fBackFace = dot(octDecode(texelFetch(in_normal, texel, 0).xy), r) < 0.0 ? 1.0 : 0.0;
    vec2 edge = min(uvHit, 1.0 - uvHit);
    float fEdge = clamp(min(edge.x, edge.y) / u.params.z, 0.0, 1.0);
    float dist = length(unproject(uvHit, ph.z) - origin);
    // A hit on the far plane (reverse-Z depth 0: the sky, or a ray that left the scene) unprojects to infinity: it is
    // no hit. (Its distance, cone footprint and colour coordinates would be NaN, and the pyramid read at NaN
    // coordinates is undefined: run-to-run differences in the frame.)
    if (isnan(dist) || isinf(dist)) return vec4(0.0);
    float fLength = clamp((u.params.y - dist) / (0.25 * u.params.y), 0.0, 1.0);
    float confidence = fThickness * fBackFace * fEdge * fLength;

    // Cone tracing: the lobe's footprint at the hit, in pixels across, times cone_scale picks the pyramid level.
    float pixels = u.cone.x * 2.0 * dist * coneTan * u.cameraFwd.w * 0.5 * size.y / max(hitDepth, 1e-4);
    float lod = log2(max(pixels, 1.0));
    vec2 uvColor = uvHit;
    if ((u.config.z & SSR_VELOCITY) != 0u) uvColor -= texelFetch(in_velocity, texel, 0).xy / size;
    vec3 radiance = mipSample(in_color, u.size.xy, u.size.w, uvColor, lod).rgb;
    return vec4(radiance, confidence);
}

void main() {
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    ivec2 outSize = imageSize(out_reflection);
    if (any(greaterThanEqual(q, outSize))) return;
    ivec2 p = min(q * u.size.xy / outSize, u.size.xy - 1); // the full-resolution pixel this one stands for
    float z = texelFetch(in_depth, p, 0).r;
    vec4 g = texelFetch(in_normal, p, 0);
    float roughness = roughnessFromShininess(g.w);
    float roughnessFade = clamp((u.params.w - roughness) / (0.25 * u.params.w), 0.0, 1.0);
    if (z <= 0.0 || roughnessFade <= 0.0) {
        imageStore(out_reflection, q, vec4(0.0));
        return;
    }
    vec2 uv = (vec2(p) + 0.5) / vec2(u.size.xy);
    vec3 world = unproject(uv, z);
    vec3 n = octDecode(g.xy);
    vec3 v = normalize(u.cameraPos.xyz - world);
    mat3 frame = basisAround(n);
    vec3 vLocal = transpose(frame) * v;
    float alpha = ggxAlpha(roughness);
    // 1 ray for mirrors, up to max_rays as the lobe widens; each covers 1/rays of the lobe's solid angle, whose
    // half-angle is about atan(1.29 alpha) (twice the GGX half-vector lobe's half-maximum, 0.64 alpha).
    int rays = clamp(int(ceil(roughness * 5.0)), 1, int(u.config.y));
    float coneTan = 1.29 * alpha / sqrt(float(rays));
    uint seed = rngSeed(uvec2(q), u.config.w, 0u);
    vec3 radiance = vec3(0.0);
    float confidence = 0.0;
    for (int i = 0; i < rays; ++i) {
        // Shininess 1 is a mirror: GGX at the smallest alpha still has tails that throw a few percent of rays
        // pixels off, so it reflects about the normal exactly. The G-buffer's Toksvig filter stores a mirror's
        // roughness as sqrt(kMinGgxAlpha), not 0 (toksvigRoughness() with an unfiltered normal), so a mirror is
        // any alpha at the floor, with 5 % of slack for the 8-bit roughness channel's rounding.
        bool mirror = alpha <= 1.05 * kMinGgxAlpha;
        vec3 h = mirror ? n : frame * sampleGgxVndf(vLocal, alpha, rngNext2(seed));
        vec3 r = reflect(-v, h);
        if (dot(r, n) <= 0.0) continue; // below the surface: no light from there
        vec4 hit = traceRay(world, n, vec3(uv, z), r, coneTan);
        radiance += hit.rgb * hit.a;
        confidence += hit.a;
    }
    // The rays' confidence-weighted mean radiance, times the pixel's confidence (their mean, faded by roughness).
    float c = confidence / float(rays) * roughnessFade;
    radiance = confidence > 0.0 ? min(radiance / confidence, vec3(60000.0)) * c : vec3(0.0);
    imageStore(out_reflection, q, vec4(radiance, c));
}

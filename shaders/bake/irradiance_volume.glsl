// Reading bake.lightmap's irradiance volume (layout in nodes/bake/lightmap.cpp): the SH9 radiance around a
// world point, trilinear between the 8 probes of its grid cell, skipping probes inside geometry. For
// lighting.deferred and any pass that lights what has no lightmap.
#ifndef BAKE_IRRADIANCE_VOLUME_GLSL
#define BAKE_IRRADIANCE_VOLUME_GLSL

// originSpacing: xyz probe (0, 0, 0), w spacing (m); counts: probes per axis. The point is moved a quarter
// of a cell along the normal first, so a surface reads the probes in front of it rather than behind it.
// False when no valid probe is near (sh is then zero).
bool volumeSh(sampler2D volume, vec4 originSpacing, uvec3 counts, vec3 p, vec3 n, out vec3 sh[9]) {
    for (int k = 0; k < 9; ++k) sh[k] = vec3(0.0);
    if (any(equal(counts, uvec3(0u)))) return false;
    ivec3 last = ivec3(counts) - 1;
    vec3 g = clamp((p + n * (0.25 * originSpacing.w) - originSpacing.xyz) / originSpacing.w, vec3(0.0), vec3(last));
    ivec3 i0 = min(ivec3(floor(g)), last);
    vec3 f = g - vec3(i0);
    float total = 0.0;
    for (int c = 0; c < 8; ++c) {
        ivec3 o = ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1);
        ivec3 q = min(i0 + o, last);
        vec3 t = mix(1.0 - f, f, vec3(o));
        ivec2 base = ivec2(9 * q.x, q.y + int(counts.y) * q.z);
        float w = t.x * t.y * t.z * texelFetch(volume, base, 0).a;
        if (w <= 0.0) continue;
        for (int k = 0; k < 9; ++k) sh[k] += w * texelFetch(volume, base + ivec2(k, 0), 0).rgb;
        total += w;
    }
    if (total < 1e-4) return false;
    for (int k = 0; k < 9; ++k) sh[k] /= total;
    return true;
}

#endif

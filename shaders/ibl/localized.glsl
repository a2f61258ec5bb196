// ibl.localized's per-probe maths, shared by its volume passes (shaders/ibl/localized.frag) so that the weight and
// the lookup direction exist once. Needs `u` (LocalizedUniforms) declared before inclusion.
#ifndef IBL_LOCALIZED_GLSL
#define IBL_LOCALIZED_GLSL

// World position of pixel `pixel` (centre) at hardware depth z (reverse Z), through the jittered inverse
// view-projection the G-buffer was rasterised with (as lighting.deferred reconstructs it).
vec3 localizedWorld(vec2 pixel, vec2 size, float z) {
    vec2 uv = pixel / size;
    vec4 wh = u.invViewProj * vec4(uv * 2.0 - 1.0, max(z, 1e-7), 1.0);
    return wh.xyz / wh.w;
}

// Signed distance from `world` to the border of the probe's influence volume, positive inside (m): the box's
// nearest face (along its rotated axes) or the sphere's surface.
float probeBorderDistance(LocalizedProbe pr, vec3 world) {
    vec3 d = world - pr.center.xyz;
    if (pr.center.w > 0.5) return pr.axisX.w - length(d);
    vec3 local = vec3(dot(d, pr.axisX.xyz), dot(d, pr.axisY.xyz), dot(d, pr.axisZ.xyz));
    vec3 inside = vec3(pr.axisX.w, pr.axisY.w, pr.axisZ.w) - abs(local);
    return min(inside.x, min(inside.y, inside.z));
}

// The probe's blend weight at border distance d > 0: the fade ramp (0 on the border, 1 from `fade` metres inside)
// times 16^priority (relative to the scene's highest, so one probe's w <= 1) times the node's weight scale.
float probeWeight(LocalizedProbe pr, float d) {
    float fade = pr.capture.w > 0.0 ? clamp(d / pr.capture.w, 0.0, 1.0) : 1.0;
    return fade * exp2(4.0 * pr.weight.y) * pr.weight.x; // 16^p = 2^(4p), exact
}

// The direction a rough lobe is looked up along [Lagarde14, 4.9.3]: the GGX lobe's mass leans from the mirror
// direction r towards the normal n as roughness grows (most at grazing angles, where r skims the surface), so the
// prefiltered cube is read between them: mix(n, r, s (sqrt(s) + a)) with a = roughness^2 (GGX alpha), s = 1 - a.
vec3 specularDominantDirection(vec3 n, vec3 r, float roughness) {
    float a = roughness * roughness;
    float s = 1.0 - a;
    return normalize(mix(n, r, s * (sqrt(s) + a)));
}

// Parallax correction [Lagarde12]: the lookup direction from the capture point towards where the reflected ray
// from `world` along `r` leaves the probe's proxy: its projection box, else the influence volume (box: slabs in
// the box's frame; sphere: the far root). Exact for a mirror whose surroundings lie on the proxy's boundary.
vec3 parallaxDirection(LocalizedProbe pr, vec3 world, vec3 r) {
    vec3 d = world - pr.proxyCenter.xyz;
    float t;
    if (pr.center.w > 0.5) {
        float b = dot(d, r);
        float c = dot(d, d) - pr.proxyHalf.x * pr.proxyHalf.x;
        t = -b + sqrt(max(b * b - c, 0.0));
    } else {
        vec3 h = pr.proxyHalf.xyz;
        vec3 local = vec3(dot(d, pr.axisX.xyz), dot(d, pr.axisY.xyz), dot(d, pr.axisZ.xyz));
        // A point of the influence volume outside the projection box (a window's reveal, a skylight's well) starts
        // from the box's nearest point: from outside, the ray could leave the box behind it.
        vec3 p = clamp(local, -h, h);
        world += mat3(pr.axisX.xyz, pr.axisY.xyz, pr.axisZ.xyz) * (p - local);
        vec3 rl = vec3(dot(r, pr.axisX.xyz), dot(r, pr.axisY.xyz), dot(r, pr.axisZ.xyz));
        vec3 inv = 1.0 / rl; // +-inf on an axis the ray is parallel to: that slab never bounds t
        vec3 tExit = max((h - p) * inv, (-h - p) * inv);
        t = max(min(tExit.x, min(tExit.y, tExit.z)), 0.0);
    }
    return world + r * t - pr.capture.xyz;
}

#endif

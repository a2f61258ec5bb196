#version 460
// One level of a Toksvig normal-map mip chain (MUSEUM_SPEC §2, [Toksvig04]): the texel of level m+1 holds
//   rgb: the plain average of the 2x2 decoded tangent-space normals of level m, re-encoded WITHOUT renormalising
//        (its direction is what the G-buffer shades with);
//   a:   sqrt(1 - L), L how much the normals under the texel agree, which the G-buffer turns into roughness
//        (shaders/scene/scene.glsl, normalLength).
// L is the agreement of the CORE of the normals, not of all of them: L = max over the four children of their L,
// times the length of the mean of the children's unit directions. On level 1 that is the length of the mean of
// the four unit normals (Toksvig's |Na|). Above it, a child whose own normals disagree (a texel holding a narrow
// groove, such as the museum floor's grout) does not widen its parent beyond its most coherent sibling, while
// children that point different ways (broad bumps at this scale) still do. Plain Toksvig (the mean of all the
// unit normals) turns a few steep texels into a wider lobe for the whole footprint: on the polished floor the
// grout averaged into every mid-distance pixel blurred the reflected colonnade (README "Fidelity"); the truth is
// a sharp lobe with a few normals tilted out of it. Level 0's alpha is 0 (core/scene/gpu_scene.cpp): its normals
// are unit whatever length their bytes decode to. Keeping L apart from the bytes is the point: an 8-bit flat
// normal decodes to a length anywhere in 1 +- 0.008 (z = 254 instead of 255), and Toksvig reads 1 - L = 0.008 on
// a polished surface (roughness 0.05) as roughness 0.35. The square root spends alpha's 8 bits where Toksvig is
// sensitive: the first step is 1 - L = 1.5e-5.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba8) readonly uniform image2D src;
layout(binding = 1, rgba8) writeonly uniform image2D dst;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(dst);
    if (any(greaterThanEqual(p, size))) return;
    ivec2 srcSize = imageSize(src);
    vec3 sum = vec3(0.0), directions = vec3(0.0);
    float core = 0.0; // the L of the most coherent child
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 2; ++x) {
            vec4 t = imageLoad(src, min(2 * p + ivec2(x, y), srcSize - 1));
            vec3 n = t.xyz * 2.0 - 1.0;
            sum += n;
            float len = length(n);
            if (len > 1e-6) directions += n / len;
            core = max(core, 1.0 - t.w * t.w);
        }
    vec3 avg = sum * 0.25;
    float shortening = clamp(1.0 - core * length(directions * 0.25), 0.0, 1.0);
    imageStore(dst, p, vec4(avg * 0.5 + 0.5, sqrt(shortening)));
}

#version 460
// One level of a Toksvig normal-map mip chain (MUSEUM_SPEC §2, [Toksvig04]): the texel of level m+1 is
// the plain average of the 2x2 decoded tangent-space normals of level m, re-encoded WITHOUT
// renormalising. |average| < 1 where the normals disagree; the G-buffer pass turns that into roughness.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba8) readonly uniform image2D src;
layout(binding = 1, rgba8) writeonly uniform image2D dst;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(dst);
    if (any(greaterThanEqual(p, size))) return;
    ivec2 srcSize = imageSize(src);
    vec4 sum = vec4(0.0);
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 2; ++x) {
            vec4 t = imageLoad(src, min(2 * p + ivec2(x, y), srcSize - 1));
            sum += vec4(t.xyz * 2.0 - 1.0, t.w);
        }
    vec4 avg = sum * 0.25;
    imageStore(dst, p, vec4(avg.xyz * 0.5 + 0.5, avg.w));
}

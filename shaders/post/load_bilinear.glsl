// Bilinear read of a storage image (a node's own output cannot be sampled in its later dispatches), zero outside:
// define BILINEAR_SOURCE as the image2D to read before including this.
vec3 loadBilinear(vec2 pos) {
    ivec2 size = imageSize(BILINEAR_SOURCE);
    vec2 q = pos - 0.5;
    ivec2 i = ivec2(floor(q));
    vec2 f = q - vec2(i);
    vec3 sum = vec3(0.0);
    for (int k = 0; k < 4; ++k) {
        ivec2 o = ivec2(k & 1, k >> 1);
        ivec2 t = i + o;
        if (any(lessThan(t, ivec2(0))) || any(greaterThanEqual(t, size))) continue;
        float w = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
        sum += w * imageLoad(BILINEAR_SOURCE, t).rgb;
    }
    return sum;
}

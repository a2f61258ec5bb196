// The bright pass post.flare and post.streaks share: the part of the colour above a display-referred threshold,
// box-averaged over factor x factor input texels into one texel of a smaller image. HDR radiance in, HDR out:
// a pixel of luminance L keeps the fraction max(0, L e - threshold) / (L e) of its colour (e: the exposure scale).
#include "common/color.glsl"
#include "camera/exposure.glsl"

// The exposure scale: the push constant's, times the camera's on the GPU when camera_state is connected (the push
// constant is 1 then).
float brightPassExposure(float pushed) {
#ifdef CAMERA_EXPOSURE
    return pushed * cameraExposure.exposure;
#else
    return pushed;
#endif
}

vec3 brightPass(sampler2D image, ivec2 texel, int factor, float exposure, float threshold) {
    ivec2 size = textureSize(image, 0);
    ivec2 lo = texel * factor, hi = min(lo + factor, size);
    vec3 sum = vec3(0.0);
    for (int y = lo.y; y < hi.y; ++y)
        for (int x = lo.x; x < hi.x; ++x) {
            vec3 c = max(texelFetch(image, ivec2(x, y), 0).rgb, vec3(0.0));
            float l = luminance(c) * exposure;
            sum += l > threshold ? c * ((l - threshold) / l) : vec3(0.0);
        }
    return sum / float(factor * factor);
}

// What post.motion_blur's three passes share: the clamped half-velocity of a pixel (McGuire12's V[X]).
#include "post/motion_blur.h"
#include "camera/exposure.glsl"

// Velocity (pixels per frame) scaled to the half-length the shutter sweeps, clamped to maxRadius.
vec2 halfVelocity(vec2 v) {
#ifdef CAMERA_EXPOSURE
    vec2 h = v * (pc.halfScale * cameraExposure.shutterSeconds); // shutter_driven by the camera: pc.halfScale is 0.5 fps
#else
    vec2 h = v * pc.halfScale;
#endif
    float len = length(h);
    return len > pc.maxRadius ? h * (pc.maxRadius / len) : h;
}

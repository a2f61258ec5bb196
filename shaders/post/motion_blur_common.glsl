// What post.motion_blur's three passes share: the clamped half-velocity of a pixel (McGuire12's V[X]).
#include "post/motion_blur.h"

// Velocity (pixels per frame) scaled to the half-length the shutter sweeps, clamped to maxRadius.
vec2 halfVelocity(vec2 v) {
    vec2 h = v * pc.halfScale;
    float len = length(h);
    return len > pc.maxRadius ? h * (pc.maxRadius / len) : h;
}

#ifndef VITRINE_SCENE_JITTER_GLSL
#define VITRINE_SCENE_JITTER_GLSL
// The clip position of a scene vertex with the frame's sub-pixel jitter (MUSEUM_SPEC §6), for every pass that
// rasterises the camera's view. Frustum jitter (camera.time.w == 0): the jittered viewProj. Per-vertex jitter:
// the unjittered position shifted by the jitter scaled by max(0, 1 - speed / threshold), speed being the vertex's
// screen motion in pixels since the last frame, so static geometry is supersampled and moving geometry does not
// wobble. clip / prevClip: this frame's and last frame's unjittered clip positions.
vec4 jitteredClip(vec4 world, vec4 clip, vec4 prevClip) {
    float threshold = camera.time.w;
    if (threshold <= 0.0) return camera.viewProj * world;
    float scale = 0.0;
    if (clip.w > 0.0 && prevClip.w > 0.0) {
        vec2 motion = (clip.xy / clip.w - prevClip.xy / prevClip.w) * 0.5 * camera.params.zw;
        scale = max(1.0 - length(motion) / threshold, 0.0);
    }
    vec2 shiftNdc = 2.0 * camera.jitter.xy / camera.params.zw;
    return vec4(clip.xy + shiftNdc * scale * clip.w, clip.zw);
}
#endif

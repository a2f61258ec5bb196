#ifndef POST_DOF_LAYERS_GLSL
#define POST_DOF_LAYERS_GLSL
// post.dof's layers: `layers` layers evenly over the signed CoC range [-span, span] of this frame, span the largest
// |CoC| present (the coc pass's atomic max, texel 1 of out_sprite_count), so the layers are as fine as the frame
// allows: layer i has CoC -span + 2 span i / (layers - 1), and a pixel belongs to the nearest.
float layerSpan(uint bits) { return max(uintBitsToFloat(bits), 1e-3); }

uint layerOf(float coc, float span) {
    float t = (coc / span * 0.5 + 0.5) * float(pc.layers - 1u);
    return uint(clamp(floor(t + 0.5), 0.0, float(pc.layers - 1u)));
}

float layerCoc(uint layer, float span) { return -span + 2.0 * span * float(layer) / float(pc.layers - 1u); }
#endif

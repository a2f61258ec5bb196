#version 460
// The opaque pass's HDR colour, copied under the transparent surfaces (forward.transparent).
layout(set = 0, binding = 4) uniform sampler2D in_color;
layout(location = 0, index = 0) out vec4 outColor;
layout(location = 0, index = 1) out vec4 outTransmit;

void main() {
    outColor = texelFetch(in_color, ivec2(gl_FragCoord.xy), 0);
    outTransmit = vec4(0.0); // replaces what the attachment held
}

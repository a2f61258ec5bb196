#version 460
// reference.substitute: color - technique + twin (a term of the lit colour replaced by its ray-traced twin's).
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_color;
layout(binding = 1) uniform sampler2D in_technique;
layout(binding = 2) uniform sampler2D in_twin;
layout(binding = 3) writeonly uniform image2D out_color;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(out_color)))) return;
    vec4 color = texelFetch(in_color, p, 0);
    vec3 rgb = color.rgb - texelFetch(in_technique, p, 0).rgb + texelFetch(in_twin, p, 0).rgb;
    imageStore(out_color, p, vec4(min(max(rgb, vec3(0.0)), vec3(60000.0)), color.a));
}

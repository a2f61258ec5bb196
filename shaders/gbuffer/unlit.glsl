// KHR_materials_unlit in the G-buffer: the colour (base × vertex colour) goes to the emissive channel, and the
// base colour and cavity are zeroed so that no light term (sun, point and spot lights, sky, lightmaps: all
// scale with base colour or cavity) adds to it.
#ifndef GBUFFER_UNLIT_GLSL
#define GBUFFER_UNLIT_GLSL

void applyUnlit(GpuMaterial m, inout vec4 base, inout vec4 material, inout vec3 emissive) {
    if (m.optics.z < 0.5) return;
    emissive = base.rgb;
    base = vec4(0.0);
    material.w = 0.0;
}

#endif

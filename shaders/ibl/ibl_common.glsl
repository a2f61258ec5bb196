// Conventions shared by ibl.capture (which writes the prefiltered cube-map array and the BRDF LUT) and
// ibl.localized (which reads them). Split-sum IBL [Karis13]: indirect specular = L(r, roughness) * (f0 * A + B).
#ifndef IBL_COMMON_GLSL
#define IBL_COMMON_GLSL

// Mip m of a prefiltered cube with `mipCount` levels is the radiance convolved with the GGX lobe of perceptual
// roughness m / (mipCount - 1) (the G-buffer's roughness = 1 - shininess, see common/brdf.glsl): mip 0 is the
// mirror, the last mip roughness 1 (ibl.capture gives each mip that roughness, nodes/ibl/capture.cpp). The mip a
// roughness reads:
float iblMipForRoughness(float roughness, float mipCount) { return clamp(roughness, 0.0, 1.0) * max(mipCount - 1.0, 0.0); }

// The BRDF LUT: texel (u, v) = (NoV, perceptual roughness) holds (A, B) in .rg so that the directional albedo of
// the GGX/Smith/Schlick specular lobe is f0 * A + B. Sample at texel centres: uv = (NoV, roughness) mapped with
// iblLutUv.
vec2 iblLutUv(float NoV, float roughness, vec2 lutSize) {
    vec2 t = clamp(vec2(NoV, roughness), 0.0, 1.0);
    return (t * (lutSize - 1.0) + 0.5) / lutSize;
}

#endif

// KHR_materials_sheen in the G-buffer, where it has no room of its own (an approximation, see below). A sheen takes
// the clear coat's slot (gbuffer/clearcoat_pack.glsl) when the pixel has no coat, marking it by a negative sign:
//     emissive.a = -(1 + lightmapped + 2 (32 q5(red) + q5(green))),   q5(x) = floor(31 x + 0.5)
// (at most 2048 in magnitude, exact in fp16), and the base colour alpha in material.x, which no lighting node
// reads (coverage was tested when the G-buffer was written), gives way to the blue and the roughness:
//     material.x = (16 q4(blue) + q4(roughness)) / 255,   q4(x) = floor(15 x + 0.5)
// So lighting.deferred sees the sheen colour to 5-5-4 bits and its roughness to 4 bits (steps of 1/15); a pixel
// with both a coat and a sheen keeps the coat and loses the sheen. forward.transparent and the path tracers read
// the material itself and have neither limit.
#ifndef GBUFFER_SHEEN_PACK_GLSL
#define GBUFFER_SHEEN_PACK_GLSL

// Whether a sheen can take the slot: emissive.a (packClearcoatAlpha's) says no coat strength.
bool sheenFits(float emissiveAlpha) { return emissiveAlpha < 64.0; }

// Rewrites emissive.a and material.x for `sheen` (rgb colour, a roughness); call only when sheenFits.
void packSheen(vec4 sheen, bool lightmapped, inout float emissiveAlpha, inout float materialX) {
    vec4 s = clamp(sheen, 0.0, 1.0);
    vec2 rg = floor(s.rg * 31.0 + 0.5);
    vec2 ba = floor(s.ba * 15.0 + 0.5);
    emissiveAlpha = -(1.0 + (lightmapped ? 1.0 : 0.0) + 2.0 * (32.0 * rg.x + rg.y));
    materialX = (16.0 * ba.x + ba.y) / 255.0;
}

// For emissive.a < 0: the sheen (rgb colour, a roughness), and `lightmapped` the flag.
vec4 unpackSheen(float emissiveAlpha, float materialX, out bool lightmapped) {
    float x = -emissiveAlpha - 1.0;
    float code = floor(x * 0.5);
    lightmapped = x - 2.0 * code > 0.5;
    float qr = floor(code / 32.0);
    float k = floor(materialX * 255.0 + 0.5);
    float qb = floor(k / 16.0);
    return vec4(qr / 31.0, (code - 32.0 * qr) / 31.0, qb / 15.0, (k - 16.0 * qb) / 15.0);
}

#endif

// Sampling for the path tracer (render.pathtrace) and, later, bake.lightmap: random numbers, frames,
// cosine-weighted hemisphere, GGX visible normals, the BRDF's lobe mixture, the environment map's
// luminance CDF (sky.env_cdf) and the power heuristic. Pure functions: the includer binds the textures.
#ifndef PATHTRACE_SAMPLING_GLSL
#define PATHTRACE_SAMPLING_GLSL
#extension GL_GOOGLE_include_directive : require
#include "common/brdf.glsl"
#include "common/color.glsl"
#include "common/cubemap.glsl"

// PCG (O'Neill 2014): one 32-bit state per path, seeded by hashing pixel, frame and sample.
uint pcgHash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}
uint rngSeed(uvec2 pixel, uint frame, uint sampleIndex) {
    return pcgHash(pixel.x ^ pcgHash(pixel.y ^ pcgHash(frame ^ pcgHash(sampleIndex))));
}
float rngNext(inout uint state) {
    state = state * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return float(((word >> 22u) ^ word) >> 8u) * (1.0 / 16777216.0); // [0, 1)
}
vec2 rngNext2(inout uint state) { return vec2(rngNext(state), rngNext(state)); }

// An orthonormal basis around unit n (Duff et al. 2017).
mat3 basisAround(vec3 n) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float b = n.x * n.y * a;
    vec3 t = vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    vec3 bt = vec3(b, s + n.y * n.y * a, -n.y);
    return mat3(t, bt, n);
}

// Cosine-weighted direction around +z; pdf = z / pi.
vec3 sampleCosine(vec2 u) {
    float r = sqrt(u.x), phi = 2.0 * kPi * u.y;
    return vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u.x)));
}

vec3 sampleUniformSphere(vec2 u) {
    float z = 1.0 - 2.0 * u.x, r = sqrt(max(0.0, 1.0 - z * z)), phi = 2.0 * kPi * u.y;
    return vec3(r * cos(phi), r * sin(phi), z);
}

// A GGX normal from the distribution of normals visible from v (local frame, +z the surface normal)
// [Heitz 2018, "Sampling the GGX distribution of visible normals", JCGT 7(4)].
vec3 sampleGgxVndf(vec3 v, float alpha, vec2 u) {
    vec3 vh = normalize(vec3(alpha * v.x, alpha * v.y, v.z));
    float lensq = vh.x * vh.x + vh.y * vh.y;
    vec3 t1 = lensq > 0.0 ? vec3(-vh.y, vh.x, 0.0) * inversesqrt(lensq) : vec3(1.0, 0.0, 0.0);
    vec3 t2 = cross(vh, t1);
    float r = sqrt(u.x), phi = 2.0 * kPi * u.y;
    float p1 = r * cos(phi), p2 = r * sin(phi);
    float s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * p2;
    vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return normalize(vec3(alpha * nh.x, alpha * nh.y, max(0.0, nh.z)));
}

// Density of l = reflect(-v, h) for h from sampleGgxVndf: D_v(h) / (4 VoH) = G1(v) D(h) / (4 NoV), with
// Smith's G1(v) = 2 NoV / (NoV + sqrt(a^2 + (1 - a^2) NoV^2)).
float ggxVndfPdf(float NoV, float NoH, float alpha) {
    float a2 = alpha * alpha;
    return ggxD(NoH, alpha) / (2.0 * (NoV + sqrt(a2 + (1.0 - a2) * NoV * NoV)));
}

// The BRDF of common/brdf.glsl, sampled as a mixture of its two lobes: GGX visible normals with
// probability specularProbability, else cosine-weighted for Lambert. The pdf of a direction is the
// mixture's (both lobes can produce every direction), so brdfCosine / pdf is the weight.
// KHR_materials_clearcoat adds a third lobe, the coat's GGX about its own normal, chosen first with probability
// coatProbability (0 without a coat: the two-lobe mixture as before, to the bit).
// KHR_materials_sheen adds one more under the coat: cosine-weighted about n (the sheen is a low, broad lobe),
// chosen with probability sheenProbability once the coat was not (0 without a sheen: the mixture as before). Every
// lobe's density is in brdfPdf, and the weight is the whole layered BRDF over it: unbiased.
struct BrdfLobes {
    vec3 baseColor;
    float metallic;
    float roughness;
    float specularProbability;
    float coatProbability;
    float coatRoughness;
    vec3 coatNormal;
    float sheenProbability;
};

// dielectric: the surface's dielectric Fresnel (dielectricSpecular; (0.04, 0.04, 0.04, 1) without
// KHR_materials_specular).
BrdfLobes brdfLobes(vec3 baseColor, float metallic, float roughness, vec4 dielectric, float NoV) {
    BrdfLobes b;
    b.baseColor = baseColor;
    b.metallic = metallic;
    b.roughness = roughness;
    vec3 f0 = specularF0With(baseColor, metallic, 0.04, dielectric);
    float s = luminance(schlickFresnelF90(f0, specularF90(metallic, dielectric), NoV));
    float d = luminance(diffuseAlbedo(baseColor, metallic));
    b.specularProbability = max(s / max(s + d, 1e-6), 0.1); // 1 for metals: no diffuse lobe
    b.coatProbability = 0.0;
    b.coatRoughness = 0.0;
    b.sheenProbability = 0.0;
    return b;
}

// The coat's lobe in the mixture, chosen in proportion to its Fresnel-weighted strength c Fc(nc.v) against the base's
// share (1 - c Fc) (s + d) of brdfLobes' estimates.
void addClearcoatLobe(inout BrdfLobes b, vec2 coat, vec3 nc, vec3 v) {
    b.coatNormal = nc;
    b.coatRoughness = coat.y;
    if (coat.x <= 0.0) return;
    float w = coat.x * clearcoatFresnel(clamp(dot(nc, v), 0.0, 1.0));
    vec3 f0 = specularF0(b.baseColor, b.metallic);
    float base = luminance(schlickFresnel(f0, clamp(dot(nc, v), 0.0, 1.0))) +
                 luminance(diffuseAlbedo(b.baseColor, b.metallic));
    b.coatProbability = clamp(w / max(w + (1.0 - w) * base, 1e-6), 0.05, 0.95);
}

// The sheen's lobe in the mixture, chosen in proportion to its albedo max(sc) E(n.v) against the base's share
// (1 - max(sc) E) (s + d), clamped to [0.05, 0.95] as the coat's.
void addSheenLobe(inout BrdfLobes b, vec4 sheen, float NoV) {
    if (!hasSheen(sheen)) return;
    float w = max(max(sheen.r, sheen.g), sheen.b) * sheenAlbedo(NoV, sheen.a);
    float base = luminance(schlickFresnel(specularF0(b.baseColor, b.metallic), NoV)) +
                 luminance(diffuseAlbedo(b.baseColor, b.metallic));
    b.sheenProbability = clamp(w / max(w + max(1.0 - w, 0.0) * base, 1e-6), 0.05, 0.95);
}

float baseBrdfPdf(BrdfLobes b, vec3 n, vec3 v, vec3 l) {
    float NoL = dot(n, l), NoV = dot(n, v);
    if (NoL <= 0.0 || NoV <= 0.0) return 0.0;
    vec3 h = normalize(v + l);
    float spec = ggxVndfPdf(NoV, clamp(dot(n, h), 0.0, 1.0), ggxAlpha(b.roughness));
    return b.specularProbability * spec + (1.0 - b.specularProbability) * NoL / kPi;
}

// The base's lobes and the sheen's (cosine about n).
float sheenBrdfPdf(BrdfLobes b, vec3 n, vec3 v, vec3 l) {
    float base = baseBrdfPdf(b, n, v, l);
    if (b.sheenProbability <= 0.0) return base;
    float NoL = dot(n, l);
    float sheen = NoL > 0.0 && dot(n, v) > 0.0 ? NoL / kPi : 0.0;
    return b.sheenProbability * sheen + (1.0 - b.sheenProbability) * base;
}

float brdfPdf(BrdfLobes b, vec3 n, vec3 v, vec3 l) {
    float base = sheenBrdfPdf(b, n, v, l);
    if (b.coatProbability <= 0.0) return base;
    vec3 nc = b.coatNormal;
    float NcoL = dot(nc, l), NcoV = dot(nc, v);
    float coat = 0.0;
    if (NcoL > 0.0 && NcoV > 0.0)
        coat = ggxVndfPdf(NcoV, clamp(dot(nc, normalize(v + l)), 0.0, 1.0), ggxAlpha(b.coatRoughness));
    return b.coatProbability * coat + (1.0 - b.coatProbability) * base;
}

// A direction from the mixture (world space); false when it fell below the surface.
bool sampleBrdf(BrdfLobes b, vec3 n, vec3 v, vec3 u, out vec3 l) {
    if (b.coatProbability > 0.0) {
        if (u.x < b.coatProbability) { // the coat's lobe, about its own normal
            mat3 cf = basisAround(b.coatNormal);
            vec3 h = cf * sampleGgxVndf(transpose(cf) * v, ggxAlpha(b.coatRoughness), u.yz);
            l = reflect(-v, h);
            return dot(n, l) > 0.0;
        }
        u.x = (u.x - b.coatProbability) / (1.0 - b.coatProbability);
    }
    mat3 frame = basisAround(n);
    if (b.sheenProbability > 0.0) {
        if (u.x < b.sheenProbability) { // the sheen's lobe
            l = frame * sampleCosine(u.yz);
            return dot(n, l) > 0.0;
        }
        u.x = (u.x - b.sheenProbability) / (1.0 - b.sheenProbability);
    }
    if (u.x < b.specularProbability) {
        vec3 vl = transpose(frame) * v;
        vec3 h = frame * sampleGgxVndf(vl, ggxAlpha(b.roughness), u.yz);
        l = reflect(-v, h);
    } else {
        l = frame * sampleCosine(u.yz);
    }
    return dot(n, l) > 0.0;
}

// Veach's power heuristic (beta = 2) for the technique with density a against one with density b.
float powerHeuristic(float a, float b) {
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0 ? a2 / (a2 + b2) : 0.0;
}

// Environment sampling from sky.env_cdf's table (layout in shaders/sky/env_cdf.comp): a texel by its
// luminance x solid angle, then a point uniform in the texel's face coordinates. A fraction
// kEnvUniform of samples is uniform over the sphere, so texels the table gives no weight (black in the
// map, but reached by bilinear filtering from a bright neighbour) still have a density.
const float kEnvUniform = 0.1;

float envCdf(sampler2D cdf, int x, int row) { return x < 0 || row < 0 ? 0.0 : texelFetch(cdf, ivec2(x, row), 0).r; }

// The table's total weight (0: a black environment, nothing to sample).
float envTotal(sampler2D cdf, int size) { return texelFetch(cdf, ivec2(0, 6 * size), 0).r; }

// Probability of texel (x, row) times the Jacobian from face coordinates to solid angle.
float envTexelPdf(sampler2D cdf, int size, int x, int row, vec2 uv) {
    float pRow = envCdf(cdf, size, row) - envCdf(cdf, size, row - 1);
    float pX = envCdf(cdf, x, row) - envCdf(cdf, x - 1, row);
    float texelArea = 4.0 / float(size * size);
    float r2 = 1.0 + dot(uv, uv);
    return pRow * pX / texelArea * r2 * sqrt(r2);
}

float envPdf(sampler2D cdf, int size, vec3 d) {
    vec2 uv;
    uint face = cubeFace(d, uv);
    ivec2 t = clamp(ivec2((uv * 0.5 + 0.5) * float(size)), ivec2(0), ivec2(size - 1));
    float p = envTexelPdf(cdf, size, t.x, int(face) * size + t.y, uv);
    return (1.0 - kEnvUniform) * p + kEnvUniform / (4.0 * kPi);
}

vec3 sampleEnv(sampler2D cdf, int size, vec3 u) {
    if (u.x < kEnvUniform) return sampleUniformSphere(u.yz);
    float ur = (u.x - kEnvUniform) / (1.0 - kEnvUniform);
    // The row: first whose cumulative weight exceeds ur (column `size` holds the rows' CDF).
    int lo = 0, hi = 6 * size - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (envCdf(cdf, size, mid) > ur) hi = mid;
        else lo = mid + 1;
    }
    int row = lo;
    float ux = u.y;
    lo = 0;
    hi = size - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (envCdf(cdf, mid, row) > ux) hi = mid;
        else lo = mid + 1;
    }
    // The position inside the texel reuses u.y's remainder within the chosen interval and u.z.
    float c0 = envCdf(cdf, lo - 1, row), c1 = envCdf(cdf, lo, row);
    float fx = c1 > c0 ? clamp((ux - c0) / (c1 - c0), 0.0, 0.999999) : 0.5;
    vec2 uv = (vec2(float(lo) + fx, float(row % size) + u.z) * 2.0) / float(size) - 1.0;
    return normalize(cubeDirection(uint(row / size), uv));
}

#endif

#ifndef VITRINE_SH_GLSL
#define VITRINE_SH_GLSL

// Real spherical harmonics up to band 2 (9 coefficients); CPU mirror: core/shading/sh.hpp.
// Order: Y00, Y1-1 (y), Y10 (z), Y11 (x), Y2-2 (xy), Y2-1 (yz), Y20 (3z^2 - 1), Y21 (xz),
// Y22 (x^2 - y^2), in world coordinates as they are (no axis is special).
// Stored coefficients are RADIANCE coefficients L_lm = integral of L(w) Y_lm(w) dw; irradiance
// applies the clamped-cosine convolution of [Ramamoorthi & Hanrahan 2001]:
// E(n) = sum A_l L_lm Y_lm(n), A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4.

void shBasis9(vec3 d, out float b[9]) {
    b[0] = 0.282094792;
    b[1] = 0.488602512 * d.y;
    b[2] = 0.488602512 * d.z;
    b[3] = 0.488602512 * d.x;
    b[4] = 1.092548431 * d.x * d.y;
    b[5] = 1.092548431 * d.y * d.z;
    b[6] = 0.315391565 * (3.0 * d.z * d.z - 1.0);
    b[7] = 1.092548431 * d.x * d.z;
    b[8] = 0.546274215 * (d.x * d.x - d.y * d.y);
}

// Radiance reconstructed from the coefficients (band-limited).
vec3 shRadiance(vec3 c[9], vec3 d) {
    float b[9];
    shBasis9(d, b);
    vec3 r = vec3(0.0);
    for (int i = 0; i < 9; ++i) r += c[i] * b[i];
    return r;
}

// Irradiance on a surface with unit normal n (lux when c is in cd/m^2).
vec3 shIrradiance(vec3 c[9], vec3 n) {
    float b[9];
    shBasis9(n, b);
    const float a0 = 3.14159265358979, a1 = 2.09439510239320, a2 = 0.785398163397448;
    vec3 e = a0 * c[0] * b[0];
    for (int i = 1; i < 4; ++i) e += a1 * c[i] * b[i];
    for (int i = 4; i < 9; ++i) e += a2 * c[i] * b[i];
    return e;
}

#endif

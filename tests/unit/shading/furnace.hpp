#pragma once

// Deterministic hemisphere quadratures for BRDF tests (CPU unit tests and the GPU furnace
// test's reference). Half-vector space, n = +Z, v in the XZ plane; theta_h is substituted by
// theta_h = atan(alpha tan(pi s / 2)), which spreads the midpoint rule in s over the GGX lobe
// at any roughness (no Monte Carlo, no importance sampling).

#include <cmath>

namespace vitrine::test {

inline constexpr double kQuadPi = 3.14159265358979323846;

// Integral over the hemisphere of f(cos theta_h, phi_h) d omega_h.
template <typename F> double integrateHalfVectors(double alpha, F&& f, int ns = 2048, int nphi = 256) {
    double sum = 0.0;
    for (int i = 0; i < ns; ++i) {
        double s = (i + 0.5) / ns, t = std::tan(0.5 * kQuadPi * s);
        double th = std::atan(alpha * t);
        double dth = alpha / (1.0 + alpha * alpha * t * t) * 0.5 * kQuadPi * (1.0 + t * t) / ns;
        for (int j = 0; j < nphi; ++j) {
            double phi = (j + 0.5) * kQuadPi / nphi; // [0, pi], mirrored
            sum += 2.0 * f(std::cos(th), phi) * std::sin(th) * dth * (kQuadPi / nphi);
        }
    }
    return sum;
}

// Integral of g(NoL, NoH, VoH) NoL over the light hemisphere, through d omega_l = 4 VoH d omega_h.
template <typename G> double integrateSpecular(double noV, double alpha, G&& g, int ns = 2048, int nphi = 256) {
    const double sinV = std::sqrt(std::max(0.0, 1.0 - noV * noV));
    return integrateHalfVectors(
        alpha,
        [&](double cosH, double phi) {
            double sinH = std::sqrt(std::max(0.0, 1.0 - cosH * cosH));
            double voH = sinV * sinH * std::cos(phi) + noV * cosH;
            double noL = 2.0 * voH * cosH - noV;
            if (voH <= 0.0 || noL <= 0.0) return 0.0;
            return g(noL, cosH, voH) * noL * 4.0 * voH;
        },
        ns, nphi);
}

// Directional albedo of the GGX lobe with F = 1 and height-correlated Smith masking in Heitz's
// form G2 = 1 / (1 + Lambda(v) + Lambda(l)), Lambda = (sqrt(1 + alpha^2 tan^2) - 1) / 2.
inline double specularAlbedo(double noV, double alpha, int ns = 2048, int nphi = 256) {
    auto lambda = [&](double c) { return 0.5 * (std::sqrt(1.0 + alpha * alpha * (1.0 - c * c) / (c * c)) - 1.0); };
    return integrateSpecular(
        noV, alpha,
        [&](double noL, double noH, double) {
            double a2 = alpha * alpha, d = noH * noH * (a2 - 1.0) + 1.0;
            double D = a2 / (kQuadPi * d * d);
            double G2 = 1.0 / (1.0 + lambda(noV) + lambda(noL));
            return D * G2 / (4.0 * noL * noV);
        },
        ns, nphi);
}

} // namespace vitrine::test

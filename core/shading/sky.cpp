#include "core/shading/sky.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace vitrine::shading {

namespace {

constexpr double kPi = std::numbers::pi;

// Piecewise Gaussian with different widths left and right of the peak.
double lobe(double x, double mu, double s1, double s2) {
    double t = (x - mu) / (x < mu ? s1 : s2);
    return std::exp(-0.5 * t * t);
}

// CIE 1931 2-degree colour matching functions, the multi-lobe fit of Wyman, Sloan and Shirley
// (JCGT 2013), wavelength in nm.
glm::dvec3 cieXyz(double nm) {
    return {1.056 * lobe(nm, 599.8, 37.9, 31.0) + 0.362 * lobe(nm, 442.0, 16.0, 26.7) -
                0.065 * lobe(nm, 501.1, 20.4, 26.2),
            0.821 * lobe(nm, 568.8, 46.9, 40.5) + 0.286 * lobe(nm, 530.9, 16.3, 31.1),
            1.217 * lobe(nm, 437.0, 11.8, 36.0) + 0.681 * lobe(nm, 459.0, 26.0, 13.8)};
}

// Planck spectral radiance, W / (m^2 sr um), wavelength in um.
double planck(double um, double kelvin) {
    return 1.191042e8 / (std::pow(um, 5.0) * (std::exp(14387.77 / (um * kelvin)) - 1.0));
}

} // namespace

glm::dvec3 sunDirection(double elevationDeg, double azimuthDeg) {
    double e = elevationDeg * kPi / 180.0, a = azimuthDeg * kPi / 180.0;
    return {std::cos(e) * std::sin(a), std::sin(e), -std::cos(e) * std::cos(a)};
}

glm::dvec3 xyzToRec709(glm::dvec3 c) {
    return {3.2404542 * c.x - 1.5371385 * c.y - 0.4985314 * c.z, -0.9692660 * c.x + 1.8760108 * c.y + 0.0415560 * c.z,
            0.0556434 * c.x - 0.2040259 * c.y + 1.0572252 * c.z};
}

double luminance709(glm::dvec3 rgb) {
    return 0.2126729 * rgb.x + 0.7151522 * rgb.y + 0.0721750 * rgb.z;
}

namespace {

// Radiance of the solar disk for turbidity T and sun zenith angle ts (see PreethamSky::sunRadiance()).
glm::dvec3 sunRadianceAt(double T, double ts) {
    // Slant-path transmittance of the extraterrestrial spectrum, 380-780 nm in 5 nm steps.
    const double m =
        1.0 / (std::cos(ts) + 0.15 * std::pow(std::max(93.885 - ts * 180.0 / kPi, 1e-3), -1.253)); // Kasten
    const double beta = 0.04608365822050 * T - 0.04586025928522;
    glm::dvec3 xyz(0.0);
    for (int i = 0; i <= 80; ++i) {
        const double nm = 380.0 + 5.0 * i, um = nm * 1e-3;
        const double rayleigh = std::exp(-0.008735 * std::pow(um, -4.08) * m);
        const double aerosol = std::exp(-beta * std::pow(um, -1.3) * m);
        const double dz = (nm - 600.0) / 45.0;
        const double ozone = std::exp(-0.12 * std::exp(-0.5 * dz * dz) * 0.35 * m);
        xyz += cieXyz(nm) * (planck(um, 5778.0) * rayleigh * aerosol * ozone * 0.005);
    }
    return glm::max(xyzToRec709(683.0 * xyz), glm::dvec3(0.0));
}

} // namespace

PreethamSky::PreethamSky(double turbidity, glm::dvec3 toSun, double groundAlbedo)
    : mTurbidity(turbidity), mToSun(glm::normalize(toSun)), mGroundAlbedo(groundAlbedo) {
    const double T = turbidity;
    mThetaS = std::acos(std::clamp(mToSun.y, -1.0, 1.0));
    // Perez coefficients A..E as linear functions of turbidity (Preetham's appendix).
    const double y[5][2] = {
        {0.1787, -1.4630}, {-0.3554, 0.4275}, {-0.0227, 5.3251}, {0.1206, -2.5771}, {-0.0670, 0.3703}};
    const double x[5][2] = {
        {-0.0193, -0.2592}, {-0.0665, 0.0008}, {-0.0004, 0.2125}, {-0.0641, -0.8989}, {-0.0033, 0.0452}};
    const double yc[5][2] = {
        {-0.0167, -0.2608}, {-0.0950, 0.0092}, {-0.0079, 0.2102}, {-0.0441, -1.6537}, {-0.0109, 0.0529}};
    for (int i = 0; i < 5; ++i) {
        mCoefY[i] = y[i][0] * T + y[i][1];
        mCoefX[i] = x[i][0] * T + x[i][1];
        mCoefYc[i] = yc[i][0] * T + yc[i][1];
    }
    const double ts = mThetaS;
    const double chi = (4.0 / 9.0 - T / 120.0) * (kPi - 2.0 * ts);
    const double yz = ((4.0453 * T - 4.9710) * std::tan(chi) - 0.2155 * T + 2.4192) * 1000.0; // kcd -> cd
    auto zenith = [&](const double m[3][4]) {
        double t[3] = {T * T, T, 1.0}, s[4] = {ts * ts * ts, ts * ts, ts, 1.0}, r = 0.0;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 4; ++j)
                r += t[i] * m[i][j] * s[j];
        return r;
    };
    const double mx[3][4] = {{0.00166, -0.00375, 0.00209, 0.0},
                             {-0.02903, 0.06377, -0.03202, 0.00394},
                             {0.11693, -0.21196, 0.06052, 0.25886}};
    const double my[3][4] = {{0.00275, -0.00610, 0.00317, 0.0},
                             {-0.04214, 0.08970, -0.04153, 0.00516},
                             {0.15346, -0.26756, 0.06670, 0.26688}};
    mZenithxyY = {zenith(mx), zenith(my), yz};

    mSunRadiance = sunRadianceAt(T, ts);

    // Horizontal irradiance from the sky dome: midpoint rule in (theta, phi).
    const int nt = 256, np = 512;
    glm::dvec3 e(0.0);
    for (int i = 0; i < nt; ++i) {
        double th = (i + 0.5) * (0.5 * kPi / nt);
        for (int j = 0; j < np; ++j) {
            double ph = (j + 0.5) * (2.0 * kPi / np);
            glm::dvec3 d(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
            e += skyRadiance(d) * (std::cos(th) * std::sin(th));
        }
    }
    mSkyIrradiance = e * ((0.5 * kPi / nt) * (2.0 * kPi / np));
}

double PreethamSky::zenithLuminance() const {
    return mZenithxyY.z;
}
glm::dvec2 PreethamSky::zenithChromaticity() const {
    return {mZenithxyY.x, mZenithxyY.y};
}

double PreethamSky::perez(const double c[5], double cosTheta, double gamma) const {
    double cg = std::cos(gamma);
    return (1.0 + c[0] * std::exp(c[1] / cosTheta)) * (1.0 + c[2] * std::exp(c[3] * gamma) + c[4] * cg * cg);
}

glm::dvec3 PreethamSky::skyRadiance(glm::dvec3 dir) const {
    const double cosTheta = std::max(dir.y, 1e-3);
    const double gamma = std::atan2(glm::length(glm::cross(dir, mToSun)), glm::dot(dir, mToSun));
    const double x = mZenithxyY.x * perez(mCoefX, cosTheta, gamma) / perez(mCoefX, 1.0, mThetaS);
    const double y = mZenithxyY.y * perez(mCoefYc, cosTheta, gamma) / perez(mCoefYc, 1.0, mThetaS);
    const double Y = mZenithxyY.z * perez(mCoefY, cosTheta, gamma) / perez(mCoefY, 1.0, mThetaS);
    return glm::max(xyzToRec709({x / y * Y, Y, (1.0 - x - y) / y * Y}), glm::dvec3(0.0));
}

glm::dvec3 PreethamSky::groundRadiance() const {
    return mGroundAlbedo / kPi * (mSkyIrradiance + sunIlluminance() * std::max(mToSun.y, 0.0));
}

glm::dvec3 PreethamSky::radiance(glm::dvec3 dir) const {
    return dir.y >= 0.0 ? skyRadiance(dir) : groundRadiance();
}

glm::dvec3 PreethamSky::sunRadiance() const {
    return mSunRadiance;
}

glm::dvec3 PreethamSky::sunIlluminance() const {
    double s = std::sin(kSunAngularRadius);
    return mSunRadiance * (kPi * s * s);
}

glm::dvec3 PreethamSky::sunIlluminance(double turbidity, glm::dvec3 toSun) {
    const double ts = std::acos(std::clamp(glm::normalize(toSun).y, -1.0, 1.0));
    double s = std::sin(kSunAngularRadius);
    return sunRadianceAt(turbidity, ts) * (kPi * s * s);
}

} // namespace vitrine::shading

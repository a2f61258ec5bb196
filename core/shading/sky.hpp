#pragma once

#include <glm/glm.hpp>

// The Preetham analytic daylight model [Preetham99] in absolute units, the CPU reference of
// shaders/sky/preetham.glsl (written separately, in double precision). Radiance is linear
// Rec.709 RGB whose luminance (0.2126 R + 0.7152 G + 0.0722 B) is in cd/m^2; illuminance is the
// same RGB integrated over solid angle, its luminance in lux.
//
// Coordinates: Y is up, right-handed. The sun's azimuth is measured in the XZ plane from -Z
// toward +X (compass-like, seen from above: 0 = -Z "north", 90 = +X "east"):
//     toSun = (cos(elev) sin(az), sin(elev), -cos(elev) cos(az)).
namespace vitrine::shading {

inline constexpr double kSunAngularRadius = 0.2665 * 3.14159265358979323846 / 180.0; // radians

glm::dvec3 sunDirection(double elevationDeg, double azimuthDeg);

// XYZ (Y in cd/m^2) to linear Rec.709 (D65 white).
glm::dvec3 xyzToRec709(glm::dvec3 xyz);
double luminance709(glm::dvec3 rgb);

class PreethamSky {
public:
    // turbidity in [1.7, 10]; toSun a unit vector at or above the horizon; groundAlbedo of the
    // Lambertian ground that fills the lower hemisphere.
    PreethamSky(double turbidity, glm::dvec3 toSun, double groundAlbedo);

    // Preetham's zenith luminance (cd/m^2) and chromaticity (x, y) for this turbidity and sun.
    double zenithLuminance() const;
    glm::dvec2 zenithChromaticity() const;

    // Perez sky radiance for a unit direction at or above the horizon (no sun disk).
    glm::dvec3 skyRadiance(glm::dvec3 dir) const;
    // The environment without the sun disk: the sky above the horizon, the lit ground below.
    glm::dvec3 radiance(glm::dvec3 dir) const;

    // Radiance of the solar disk seen from the ground: the extraterrestrial sun (5778 K
    // black body) attenuated along the slant path by Rayleigh scattering, aerosols (Angstrom's
    // law with Preetham's turbidity relation) and ozone (Chappuis band), integrated against
    // the CIE 1931 colour matching functions.
    glm::dvec3 sunRadiance() const;
    // Sun illuminance on a surface perpendicular to it: sunRadiance * pi sin^2(angular radius).
    glm::dvec3 sunIlluminance() const;
    // The same for a turbidity and sun direction without building the sky (whose constructor integrates the sky dome's
    // irradiance: most of its cost). Bit-identical to PreethamSky(turbidity, toSun, any).sunIlluminance().
    static glm::dvec3 sunIlluminance(double turbidity, glm::dvec3 toSun);
    // Irradiance from the Perez sky (without the sun) on a horizontal surface.
    glm::dvec3 skyIrradianceHorizontal() const { return mSkyIrradiance; }
    glm::dvec3 groundRadiance() const;

    double turbidity() const { return mTurbidity; }
    glm::dvec3 toSun() const { return mToSun; }

private:
    double perez(const double c[5], double cosTheta, double gamma) const;

    double mTurbidity;
    glm::dvec3 mToSun;
    double mThetaS; // sun zenith angle
    double mGroundAlbedo;
    double mCoefY[5], mCoefX[5], mCoefYc[5];
    glm::dvec3 mZenithxyY;
    glm::dvec3 mSkyIrradiance;
    glm::dvec3 mSunRadiance;
};

} // namespace vitrine::shading

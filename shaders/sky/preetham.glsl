#ifndef SKY_PREETHAM_GLSL
#define SKY_PREETHAM_GLSL

// Preetham, Shirley & Smits 1999, "A Practical Analytic Model for Daylight", in absolute
// units: radiance as linear Rec.709 RGB whose luminance is in cd/m^2. CPU reference (written
// separately): core/shading/sky.cpp. Y is up; toSun is the unit direction toward the sun.

const float kSkyPi = 3.14159265358979;

struct PerezCoefficients {
    float a[5]; // Perez A..E for luminance Y
    float x[5]; // for chromaticity x
    float y[5]; // for chromaticity y
};

PerezCoefficients perezCoefficients(float T) {
    PerezCoefficients c;
    c.a[0] = 0.1787 * T - 1.4630;
    c.a[1] = -0.3554 * T + 0.4275;
    c.a[2] = -0.0227 * T + 5.3251;
    c.a[3] = 0.1206 * T - 2.5771;
    c.a[4] = -0.0670 * T + 0.3703;
    c.x[0] = -0.0193 * T - 0.2592;
    c.x[1] = -0.0665 * T + 0.0008;
    c.x[2] = -0.0004 * T + 0.2125;
    c.x[3] = -0.0641 * T - 0.8989;
    c.x[4] = -0.0033 * T + 0.0452;
    c.y[0] = -0.0167 * T - 0.2608;
    c.y[1] = -0.0950 * T + 0.0092;
    c.y[2] = -0.0079 * T + 0.2102;
    c.y[3] = -0.0441 * T - 1.6537;
    c.y[4] = -0.0109 * T + 0.0529;
    return c;
}

// F(theta, gamma) = (1 + A e^(B / cos theta)) (1 + C e^(D gamma) + E cos^2 gamma)
float perezF(float c[5], float cosTheta, float gamma) {
    float cg = cos(gamma);
    return (1.0 + c[0] * exp(c[1] / cosTheta)) * (1.0 + c[2] * exp(c[3] * gamma) + c[4] * cg * cg);
}

// Zenith chromaticity x, y and luminance Y (cd/m^2) for turbidity T and sun zenith angle ts.
vec3 preethamZenith(float T, float ts) {
    float chi = (4.0 / 9.0 - T / 120.0) * (kSkyPi - 2.0 * ts);
    float Y = ((4.0453 * T - 4.9710) * tan(chi) - 0.2155 * T + 2.4192) * 1000.0;
    vec3 t = vec3(T * T, T, 1.0);
    vec4 s = vec4(ts * ts * ts, ts * ts, ts, 1.0);
    float x = dot(t, vec3(dot(vec4(0.00166, -0.00375, 0.00209, 0.0), s), dot(vec4(-0.02903, 0.06377, -0.03202, 0.00394), s),
                          dot(vec4(0.11693, -0.21196, 0.06052, 0.25886), s)));
    float y = dot(t, vec3(dot(vec4(0.00275, -0.00610, 0.00317, 0.0), s), dot(vec4(-0.04214, 0.08970, -0.04153, 0.00516), s),
                          dot(vec4(0.15346, -0.26756, 0.06670, 0.26688), s)));
    return vec3(x, y, Y);
}

vec3 xyzToRec709(vec3 c) {
    return vec3(3.2404542 * c.x - 1.5371385 * c.y - 0.4985314 * c.z, -0.9692660 * c.x + 1.8760108 * c.y + 0.0415560 * c.z,
                0.0556434 * c.x - 0.2040259 * c.y + 1.0572252 * c.z);
}

// Perez sky radiance in unit direction d (at or above the horizon), without the sun disk.
vec3 preethamSky(vec3 d, vec3 toSun, float T) {
    PerezCoefficients c = perezCoefficients(T);
    float ts = acos(clamp(toSun.y, -1.0, 1.0));
    vec3 z = preethamZenith(T, ts);
    float cosTheta = max(d.y, 1e-3);
    // atan of |cross| and dot keeps gamma accurate next to the sun, where acos is not.
    float gamma = atan(length(cross(d, toSun)), dot(d, toSun));
    float x = z.x * perezF(c.x, cosTheta, gamma) / perezF(c.x, 1.0, ts);
    float y = z.y * perezF(c.y, cosTheta, gamma) / perezF(c.y, 1.0, ts);
    float Y = z.z * perezF(c.a, cosTheta, gamma) / perezF(c.a, 1.0, ts);
    return max(xyzToRec709(vec3(x / y * Y, Y, (1.0 - x - y) / y * Y)), vec3(0.0));
}

// Asymmetric Gaussian lobe of the CIE 1931 colour-matching-function fit (Wyman, Sloan and
// Shirley, JCGT 2013).
float cmfLobe(float nm, float mu, float s1, float s2) {
    float t = (nm - mu) / (nm < mu ? s1 : s2);
    return exp(-0.5 * t * t);
}

// Radiance of the solar disk at the ground: a 5778 K black body (the extraterrestrial sun)
// through the slant path of relative air mass m (Kasten), attenuated by Rayleigh scattering,
// aerosols (Angstrom alpha = 1.3, beta from turbidity as in Preetham's appendix) and ozone
// (0.35 cm, Chappuis band as a Gaussian), 380-780 nm in 5 nm steps.
vec3 preethamSunRadiance(float T, float ts) {
    float m = 1.0 / (cos(ts) + 0.15 * pow(max(93.885 - degrees(ts), 1e-3), -1.253));
    float beta = 0.04608365822050 * T - 0.04586025928522;
    vec3 xyz = vec3(0.0);
    for (int i = 0; i <= 80; ++i) {
        float nm = 380.0 + 5.0 * float(i);
        float um = nm * 1e-3;
        float planck = 1.191042e8 / (pow(um, 5.0) * (exp(14387.77 / (um * 5778.0)) - 1.0));
        float dz = (nm - 600.0) / 45.0;
        float tau = exp(-m * (0.008735 * pow(um, -4.08) + beta * pow(um, -1.3) + 0.12 * 0.35 * exp(-0.5 * dz * dz)));
        vec3 cmf = vec3(1.056 * cmfLobe(nm, 599.8, 37.9, 31.0) + 0.362 * cmfLobe(nm, 442.0, 16.0, 26.7) -
                            0.065 * cmfLobe(nm, 501.1, 20.4, 26.2),
                        0.821 * cmfLobe(nm, 568.8, 46.9, 40.5) + 0.286 * cmfLobe(nm, 530.9, 16.3, 31.1),
                        1.217 * cmfLobe(nm, 437.0, 11.8, 36.0) + 0.681 * cmfLobe(nm, 459.0, 26.0, 13.8));
        xyz += cmf * (planck * tau * 0.005);
    }
    return max(xyzToRec709(683.0 * xyz), vec3(0.0));
}

// Illuminance on a surface facing a uniform disk of angular radius r: L pi sin^2 r.
float sunDiskFactor(float angularRadius) {
    float s = sin(angularRadius);
    return kSkyPi * s * s;
}

// One thread's share of the horizontal sky irradiance: `count` threads split a 32 (theta) x 64
// (phi) midpoint rule; thread i takes phi column i % 64 and every theta row j with
// j % (count / 64) == i / 64. Sum the shares of all threads.
vec3 preethamIrradianceShare(uint thread, uint count, vec3 toSun, float T) {
    const uint nt = 32u, np = 64u;
    uint rows = count / np;
    uint phiIndex = thread % np;
    vec3 e = vec3(0.0);
    for (uint j = thread / np; j < nt; j += rows) {
        float th = (float(j) + 0.5) * (0.5 * kSkyPi / float(nt));
        float ph = (float(phiIndex) + 0.5) * (2.0 * kSkyPi / float(np));
        vec3 d = vec3(sin(th) * cos(ph), cos(th), sin(th) * sin(ph));
        e += preethamSky(d, toSun, T) * (cos(th) * sin(th));
    }
    return e * ((0.5 * kSkyPi / float(nt)) * (2.0 * kSkyPi / float(np)));
}

#endif

#ifndef POST_APERTURE_GLSL
#define POST_APERTURE_GLSL
// The aperture's boundary: the GLSL twin of core/scene/aperture.cpp's apertureBoundary (regular polygon of `blades`
// straight blades with corners on the unit circle, rounded toward it by `roundness`; a circle below 3 blades).
// theta: direction angle counter-clockwise from +x with y up. Returns the boundary's distance from the centre.
float apertureBoundary(uint blades, float roundness, float rotation, float theta) {
    if (blades < 3u) return 1.0;
    float wedge = 6.28318530718 / float(blades);
    float phi = mod(theta - rotation, wedge);
    float polygon = cos(0.5 * wedge) / cos(phi - 0.5 * wedge);
    return polygon + roundness * (1.0 - polygon);
}
#endif

// Nested volumes in render.pathtrace: the KHR_materials_volume media a path is in, innermost last (a liquid inside a
// glass, an air bubble in a glass block, an insect in amber). A path that refracts into a volume pushes its material;
// one that leaves it removes it. The medium the path travels through is the last one entered (its attenuation is
// Beer's law over the segment), and a boundary refracts and reflects by the IORs on its two sides: the medium the path
// is in and the one across, so water in glass bends light by 1.5 / 1.33, not by 1.33 against air, and reflects by
// ((1.5 - 1.33) / (1.5 + 1.33))^2 = 0.0036 at normal incidence instead of 0.02. glTF gives volumes no priorities;
// where two overlap, the one entered last wins, and leaving the other inside it crosses no interface (an
// index-matched one: F0 0, no bending). Crossing into a rarer medium (water from glass, a bubble in glass) is
// drawn as the way out of a volume is, with Fresnel at the microfacet (pathtrace/volume.glsl crossBoundary), so light
// past the critical angle is reflected whole. A path that starts inside a volume (the camera in it) knows it only at
// the volume's boundary: its way there is not attenuated; reflected back there, it is in that volume from then on. At
// most PATHTRACE_MAX_MEDIA nested volumes; a path entering one more does not record it.
//
// nodes/render/pathtrace_cpu.cpp PathMedia is the CPU twin, line for line.
#ifndef PATHTRACE_MEDIA_GLSL
#define PATHTRACE_MEDIA_GLSL
#extension GL_GOOGLE_include_directive : require
#include "pathtrace/surface.glsl"

#define PATHTRACE_MAX_MEDIA 4

struct PathMedia {
    uint count;                         // volumes the path is in
    uint material[PATHTRACE_MAX_MEDIA]; // their materials, innermost (the last entered) last
};

PathMedia noMedia() {
    PathMedia media;
    media.count = 0u;
    for (int i = 0; i < PATHTRACE_MAX_MEDIA; ++i) media.material[i] = 0u;
    return media;
}

float mediumIor(uint material) { return iorFromF0(materials[material].optics.y); }

// The medium the path travels through: the innermost volume's attenuationColor (rgb) and attenuationDistance (a; 0:
// no attenuation, as in air).
vec4 currentMedium(PathMedia media) {
    return media.count > 0u ? materials[media.material[media.count - 1u]].volume : vec4(1.0, 1.0, 1.0, 0.0);
}

// Where the path's media hold `material`, innermost first; -1 where the path is not in it.
int findMedium(PathMedia media, uint material) {
    for (int i = int(media.count) - 1; i >= 0; --i)
        if (media.material[i] == material) return i;
    return -1;
}

// Boundary s met by a path in `media`: s.eta becomes the IOR on the path's side over the IOR across, and s.dielectric
// the interface's Fresnel F0 from those two IORs (KHR_materials_specular's colour and strength kept). Against air
// (the common case) both are the material's own.
void meetBoundary(inout PathSurface s, PathMedia media) {
    float outer = media.count > 0u ? mediumIor(media.material[media.count - 1u]) : 1.0;
    float here = outer, there = s.ior;
    bool air = media.count == 0u; // what lies beyond s's volume is no volume
    if (s.inside) {
        int at = findMedium(media, s.material);
        if (at < 0) { // the path started inside this volume: out of it into what surrounds the path
            here = s.ior;
            there = outer;
        } else if (at == int(media.count) - 1) { // out of the innermost volume into the one around it
            there = at > 0 ? mediumIor(media.material[at - 1]) : 1.0;
            air = at == 0;
        } else { // out of a volume overlapped by one entered later: the path stays in that one
            there = outer;
        }
    }
    s.eta = here / there;
    if (!air) { // F0 of the two media (against air, the material's own)
        float r = (here - there) / (here + there);
        s.dielectric = dielectricSpecular(r * r, s.specular);
    }
}

// A path met boundary s and crossed it (across: into its volume or out of it) or was reflected. The volume it enters,
// or that it is reflected back into without having been recorded in it (it started inside), is recorded if there is
// room; the one it leaves is removed.
void crossMedia(inout PathMedia media, PathSurface s, bool across) {
    int at = findMedium(media, s.material);
    if (across == s.inside) { // out of the volume, or reflected outside it
        if (!across || at < 0) return;
        for (int i = at; i + 1 < int(media.count); ++i) media.material[i] = media.material[i + 1];
        --media.count;
    } else if ((across || at < 0) && media.count < uint(PATHTRACE_MAX_MEDIA)) {
        media.material[media.count++] = s.material;
    }
}

#endif

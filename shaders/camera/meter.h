// camera.physical's metering: a centre-weighted histogram of log2 luminance, built per 16x16 tile
// (meter_tiles.comp) and summed over the tiles (meter_reduce.comp) into METER_BINS (Σw, Σw·log2 Y) pairs that the
// node reads back. Each bin keeps the weighted sum of log2 Y as well as the weight, so the mean of a bin is exact
// (a flat image meters exactly, not to the nearest bin centre).
#ifndef CAMERA_METER_H
#define CAMERA_METER_H
#include "../common/shared.h"

#define METER_BINS 64
#define METER_TILE 16
#define METER_REDUCE_GROUP 256
// Metered range of log2 luminance (cd/m²): 2^-10 (starlight) to 2^30 (beyond the sun's disk); outside it clamps.
#define METER_MIN_LOG2 (-10.0)
#define METER_MAX_LOG2 (30.0)
// Per-pixel weights and in-bin positions are summed per tile as 16.16 fixed point (shared-memory uint atomics):
// a 16x16 tile sums at most 256 · 65536 = 2^24, exact in the float the tile then writes.
#define METER_FIXED_ONE 65536.0

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
// One push-constant block per shader: expose.comp defines EXPOSE_SHADER before including this.
#if defined(__cplusplus) || !defined(EXPOSE_SHADER)
VITRINE_PUSH_BEGIN(MeterPush)
    float centreWeight; // 0: average metering; 1: the Gaussian alone
    float centreSigma;  // the Gaussian's σ, in units of half the image height
    uint tilesX;
    uint tileCount;
VITRINE_PUSH_END(pc)
#endif

// expose.comp's flags.
#define EXPOSE_METERED 1u  // the histogram holds this frame's metering
#define EXPOSE_RESET 2u    // frame 0: eye adaptation starts over
#define EXPOSE_MANUAL 4u   // manual mode: manualFNumber, manualShutter, iso
#define EXPOSE_AUTO_ISO 8u
#define EXPOSE_GROUP 64

// expose.comp: the histogram's trimmed mean -> eye adaptation -> program line -> CameraExposure.
#if defined(__cplusplus) || defined(EXPOSE_SHADER)
VITRINE_PUSH_BEGIN(ExposePush)
    uint flags;          // EXPOSE_*
    float meterLow;      // fractions of the histogram's weight ignored at the dark end ...
    float meterHigh;     // ... and above which metering stops
    float dt;            // seconds per frame
    float tau;           // adaptation time constant (s)
    float initialEv100;  // until the first metering, or always without metering
    float compensation;  // stops
    float shift;         // program shift (stops)
    float wideOpenFNumber;
    float minFNumber;
    float shortestShutter;
    float longestShutter;
    float focalLengthMm;
    float iso;           // manual ISO, or the program's (base) ISO
    float maxIso;
    float manualFNumber;
    float manualShutter;
    uint blades;         // aperture shape for the area (0: circle)
    float bladeRoundness;
    float bladeRotation;
    float mechanicalWideOpen; // mechanical vignetting wide open
    float pad0;
    float pad1;
    float pad2;
VITRINE_PUSH_END(pc)
#endif
#ifdef __cplusplus
static_assert(sizeof(MeterPush) == 16);
static_assert(sizeof(ExposePush) == 96);
}
#endif
#endif

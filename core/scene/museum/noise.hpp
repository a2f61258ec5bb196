#pragma once

// Deterministic random numbers and tileable noise for the museum's procedural textures: value noise,
// fbm and Worley (cellular) noise, all periodic over the unit square so that textures wrap seamlessly.
// Our own code rather than <random>: the standard distributions differ between library versions, and
// the museum must be the same everywhere for a given seed.

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace vitrine::scene::museum {

// splitmix64: tiny, fast, and good enough for content generation.
class Rng {
public:
    explicit Rng(uint64_t seed) : mState(seed) {}
    uint64_t next() {
        uint64_t z = (mState += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    float uniform() { return static_cast<float>(next() >> 40) * (1.0f / 16777216.0f); } // [0, 1)
    float uniform(float lo, float hi) { return lo + (hi - lo) * uniform(); }
    // An independent stream for a sub-task, so adding draws to one task does not reshuffle another.
    Rng fork(uint64_t salt) { return Rng(next() ^ (salt * 0xd1342543de82ef95ull)); }

private:
    uint64_t mState;
};

// Periodic value noise: random values on a period × period lattice, smoothly interpolated.
class ValueNoise {
public:
    ValueNoise(uint32_t period, Rng& rng);
    float sample(float u, float v) const; // u, v in tile units [0, 1), wraps; result in [0, 1]

private:
    uint32_t mPeriod;
    std::vector<float> mValues;
};

// Fractal sum of value-noise octaves, each doubling the frequency; periodic over the unit square.
class Fbm {
public:
    Fbm(uint32_t baseFrequency, int octaves, float gain, Rng& rng);
    float sample(float u, float v) const; // roughly [0, 1], mean 0.5

private:
    std::vector<ValueNoise> mOctaves;
    std::vector<float> mWeights;
};

// Periodic Worley noise on a cells × cells grid with one jittered feature point per cell.
class Worley {
public:
    Worley(uint32_t cells, Rng& rng);
    // f1, f2: distances to the nearest and second-nearest points in cell units; id: a random value of
    // the nearest point's cell in [0, 1).
    void sample(float u, float v, float& f1, float& f2, float& id) const;

private:
    uint32_t mCells;
    std::vector<glm::vec2> mPoints;
    std::vector<float> mIds;
};

inline float smoothstep(float e0, float e1, float x) {
    float t = glm::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

} // namespace vitrine::scene::museum

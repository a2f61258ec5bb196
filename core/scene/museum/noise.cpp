#include "core/scene/museum/noise.hpp"

#include <cmath>

namespace vitrine::scene::museum {

ValueNoise::ValueNoise(uint32_t period, Rng& rng) : mPeriod(period), mValues(size_t(period) * period) {
    // Powers of two let sample() wrap with a mask, which matters at millions of samples per texture.
    while (mPeriod & (mPeriod - 1))
        mPeriod &= mPeriod - 1;
    mValues.resize(size_t(mPeriod) * mPeriod);
    for (float& v : mValues)
        v = rng.uniform();
}

float ValueNoise::sample(float u, float v) const {
    float x = u * mPeriod, y = v * mPeriod;
    float fx = std::floor(x), fy = std::floor(y);
    float tx = x - fx, ty = y - fy;
    int32_t mask = static_cast<int32_t>(mPeriod) - 1, p = static_cast<int32_t>(mPeriod);
    int32_t x0 = static_cast<int32_t>(fx) & mask, y0 = static_cast<int32_t>(fy) & mask;
    int32_t x1 = (x0 + 1) & mask, y1 = (y0 + 1) & mask;
    float a = mValues[y0 * p + x0], b = mValues[y0 * p + x1];
    float c = mValues[y1 * p + x0], d = mValues[y1 * p + x1];
    float sx = tx * tx * (3.0f - 2.0f * tx), sy = ty * ty * (3.0f - 2.0f * ty);
    float top = a + (b - a) * sx, bottom = c + (d - c) * sx;
    return top + (bottom - top) * sy;
}

Fbm::Fbm(uint32_t baseFrequency, int octaves, float gain, Rng& rng) {
    float weight = 1.0f, total = 0.0f;
    for (int i = 0; i < octaves; ++i) {
        mOctaves.emplace_back(baseFrequency << i, rng);
        mWeights.push_back(weight);
        total += weight;
        weight *= gain;
    }
    for (float& w : mWeights)
        w /= total;
}

float Fbm::sample(float u, float v) const {
    float sum = 0.0f;
    for (size_t i = 0; i < mOctaves.size(); ++i)
        sum += mWeights[i] * mOctaves[i].sample(u, v);
    return sum;
}

Worley::Worley(uint32_t cells, Rng& rng) : mCells(cells), mPoints(size_t(cells) * cells), mIds(size_t(cells) * cells) {
    for (size_t i = 0; i < mPoints.size(); ++i) {
        mPoints[i] = glm::vec2(rng.uniform(0.1f, 0.9f), rng.uniform(0.1f, 0.9f));
        mIds[i] = rng.uniform();
    }
}

void Worley::sample(float u, float v, float& f1, float& f2, float& id) const {
    float x = u * mCells, y = v * mCells;
    int cx = static_cast<int>(std::floor(x)), cy = static_cast<int>(std::floor(y));
    int n = static_cast<int>(mCells);
    f1 = f2 = 1e9f;
    id = 0.0f;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            int gx = cx + dx, gy = cy + dy;
            size_t cell = size_t(((gy % n) + n) % n) * n + size_t(((gx % n) + n) % n);
            glm::vec2 p = glm::vec2(gx, gy) + mPoints[cell];
            float d = glm::length(p - glm::vec2(x, y));
            if (d < f1) {
                f2 = f1;
                f1 = d;
                id = mIds[cell];
            } else if (d < f2) {
                f2 = d;
            }
        }
    }
}

} // namespace vitrine::scene::museum

#include "core/shading/environment.hpp"

#include "core/shading/cubemap.hpp"
#include "core/shading/sky.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace vitrine::shading {

namespace {

constexpr double kPi = std::numbers::pi;

glm::dvec3 pixel(const float* rgba, int width, int x, int y) {
    const float* p = rgba + (static_cast<size_t>(y) * width + x) * 4;
    return {p[0], p[1], p[2]};
}

// Exact solid angle of an equirect pixel in row y.
double pixelSolidAngle(int y, int width, int height) {
    double top = kPi / 2 - kPi * y / height, bottom = kPi / 2 - kPi * (y + 1) / height;
    return (2.0 * kPi / width) * (std::sin(top) - std::sin(bottom));
}

// Bilinear lookup, wrapping in azimuth and clamping at the poles.
glm::dvec3 sampleEquirect(const float* rgba, int width, int height, glm::dvec3 d) {
    double az = std::atan2(d.x, -d.z), el = std::asin(std::clamp(d.y, -1.0, 1.0));
    double fx = (az + kPi) / (2.0 * kPi) * width - 0.5, fy = (kPi / 2 - el) / kPi * height - 0.5;
    int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
    double tx = fx - x0, ty = fy - y0;
    auto at = [&](int x, int y) {
        x = ((x % width) + width) % width;
        y = std::clamp(y, 0, height - 1);
        return pixel(rgba, width, x, y);
    };
    return glm::mix(glm::mix(at(x0, y0), at(x0 + 1, y0), tx), glm::mix(at(x0, y0 + 1), at(x0 + 1, y0 + 1), tx), ty);
}

} // namespace

glm::dvec3 equirectDirection(double u, double v) {
    double az = 2.0 * kPi * u - kPi, el = kPi / 2 - kPi * v;
    return {std::cos(el) * std::sin(az), std::sin(el), -std::cos(el) * std::cos(az)};
}

SunEstimate findSun(const float* rgba, int width, int height, std::vector<float>* withoutSun) {
    const size_t count = static_cast<size_t>(width) * height;
    std::vector<double> lum(count);
    size_t brightest = 0;
    for (size_t i = 0; i < count; ++i) {
        lum[i] = luminance709({rgba[i * 4], rgba[i * 4 + 1], rgba[i * 4 + 2]});
        if (lum[i] > lum[brightest]) brightest = i;
    }
    if (withoutSun) withoutSun->assign(rgba, rgba + count * 4);
    std::vector<double> sorted = lum;
    std::nth_element(sorted.begin(), sorted.begin() + count / 2, sorted.end());
    const double median = std::max(sorted[count / 2], 0.0), maximum = lum[brightest];

    SunEstimate sun;
    const int bx = static_cast<int>(brightest % width), by = static_cast<int>(brightest / width);
    sun.direction = equirectDirection((bx + 0.5) / width, (by + 0.5) / height);
    if (!(maximum > kSunMinContrast * median) || maximum <= 0.0) return sun;

    // Flood fill from the brightest pixel.
    const double threshold = std::max(kSunRegionFraction * maximum, kSunMinContrast * median);
    std::vector<uint8_t> state(count, 0); // 1: sun, 2: ring
    std::vector<size_t> stack = {brightest}, region, ring;
    state[brightest] = 1;
    while (!stack.empty()) {
        size_t i = stack.back();
        stack.pop_back();
        region.push_back(i);
        int x = static_cast<int>(i % width), y = static_cast<int>(i / width);
        const int nx[4] = {(x + 1) % width, (x + width - 1) % width, x, x}, ny[4] = {y, y, y - 1, y + 1};
        for (int k = 0; k < 4; ++k) {
            if (ny[k] < 0 || ny[k] >= height) continue;
            size_t j = static_cast<size_t>(ny[k]) * width + nx[k];
            if (state[j]) continue;
            state[j] = lum[j] > threshold ? 1 : 2;
            (state[j] == 1 ? stack : ring).push_back(j);
        }
    }
    glm::dvec3 fill(0.0);
    for (size_t j : ring)
        fill += pixel(rgba, width, static_cast<int>(j % width), static_cast<int>(j / width));
    if (!ring.empty()) fill /= static_cast<double>(ring.size());

    glm::dvec3 weighted(0.0);
    for (size_t i : region) {
        int x = static_cast<int>(i % width), y = static_cast<int>(i / width);
        double excess = lum[i] - luminance709(fill);
        weighted += equirectDirection((x + 0.5) / width, (y + 0.5) / height) *
                    (std::max(excess, 0.0) * pixelSolidAngle(y, width, height));
    }
    sun.found = true;
    sun.direction = glm::normalize(weighted);
    for (size_t i : region) {
        int x = static_cast<int>(i % width), y = static_cast<int>(i / width);
        glm::dvec3 d = equirectDirection((x + 0.5) / width, (y + 0.5) / height);
        double w = pixelSolidAngle(y, width, height) * std::max(glm::dot(d, sun.direction), 0.0);
        sun.illuminance += (pixel(rgba, width, x, y) - fill) * w;
        sun.solidAngle += pixelSolidAngle(y, width, height);
        if (withoutSun)
            for (int c = 0; c < 3; ++c)
                (*withoutSun)[i * 4 + c] = static_cast<float>(fill[c]);
    }
    sun.illuminance = glm::max(sun.illuminance, glm::dvec3(0.0));
    return sun;
}

EnvironmentBake bakeEquirect(const float* source, int width, int height, int faceSize, double intensity,
                             bool sunInCubemap) {
    std::vector<float> scaled(source, source + static_cast<size_t>(width) * height * 4);
    for (size_t i = 0; i < scaled.size(); ++i)
        if (i % 4 != 3) scaled[i] = static_cast<float>(scaled[i] * intensity);
    EnvironmentBake bake;
    bake.size = faceSize;
    std::vector<float> sunFree;
    bake.sun = findSun(scaled.data(), width, height, &sunFree);

    for (int y = 0; y < height; ++y) {
        double w = pixelSolidAngle(y, width, height);
        for (int x = 0; x < width; ++x)
            shAccumulate(bake.sh, equirectDirection((x + 0.5) / width, (y + 0.5) / height),
                         pixel(sunFree.data(), width, x, y), w);
    }

    // Each cube texel averages k x k bilinear samples, k about the number of equirect pixels
    // across the texel, so downsampling keeps the energy of small bright features.
    const float* cubeSource = sunInCubemap ? scaled.data() : sunFree.data();
    const int k = std::clamp(static_cast<int>(std::ceil(width / (4.0 * faceSize))), 1, 16);
    for (int face = 0; face < 6; ++face) {
        auto& out = bake.faces[face];
        out.assign(static_cast<size_t>(faceSize) * faceSize * 4, 1.0f);
        for (int y = 0; y < faceSize; ++y)
            for (int x = 0; x < faceSize; ++x) {
                glm::dvec3 sum(0.0);
                for (int sy = 0; sy < k; ++sy)
                    for (int sx = 0; sx < k; ++sx) {
                        double u = 2.0 * (x + (sx + 0.5) / k) / faceSize - 1.0,
                               v = 2.0 * (y + (sy + 0.5) / k) / faceSize - 1.0;
                        sum += sampleEquirect(cubeSource, width, height, glm::normalize(cubeDirection(face, u, v)));
                    }
                sum /= static_cast<double>(k * k);
                float* p = &out[(static_cast<size_t>(y) * faceSize + x) * 4];
                p[0] = static_cast<float>(sum.x);
                p[1] = static_cast<float>(sum.y);
                p[2] = static_cast<float>(sum.z);
            }
    }
    return bake;
}

} // namespace vitrine::shading

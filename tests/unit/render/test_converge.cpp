// convergeAccumulation (nodes/render/converge.cpp): the announced estimate of the samples and time a target needs; and
// convergeCached: a run stopped part way keeps a partial result that the next run resumes.
// A synthetic tracer whose noise falls exactly as 1/sqrt(samples) and whose first batch carries a one-off cost (as
// the real first batch carries pipeline creation and first touches of memory): the estimate must come once min_spp
// samples are in, and its time must not scale the first batch's cost up to the whole run.

#include "nodes/render/converge.hpp"
#include "nodes/render/pathtrace_cpu.hpp"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>

namespace vitrine {
namespace {

TEST(Converge, AnnouncesItsEstimateAtMinSppWithoutTheFirstBatchsCost) {
    ConvergeRun run;
    run.node = "test.converge";
    run.width = 8;
    run.height = 4;
    run.target = 0.05; // noise 1/sqrt(n): the target needs exactly 400 samples
    run.minSpp = 64;
    run.batch = 16;
    run.report = true;
    CpuAccumulation acc;
    double samples = 0.0;
    const auto start = std::chrono::steady_clock::now();
    testing::internal::CaptureStderr();
    const bool converged = convergeAccumulation(run, acc, [&](uint32_t spp, uint32_t, uint32_t b) {
                               std::this_thread::sleep_for(std::chrono::milliseconds(b == 0 ? 1500 : 20));
                               samples += spp;
                               for (glm::vec4& st : acc.stats)
                                   st = glm::vec4(float(samples), 1.0f, 0.0f, float(1.0 / std::sqrt(samples)));
                           }).converged;
    const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const std::string log = testing::internal::GetCapturedStderr();
    EXPECT_TRUE(converged) << log;
    EXPECT_GE(samples, 400.0) << log; // 400 or one batch more (1/sqrt(400) in float is a hair above 0.05)
    EXPECT_LE(samples, 416.0) << log;
    const size_t at = log.find("test.converge: ");
    ASSERT_NE(at, std::string::npos) << log;
    EXPECT_EQ(log.compare(at, 25, "test.converge: 64 spp in "), 0) << "announced before min_spp:\n" << log;
    const size_t needs = log.find("needs about 400 spp: about ", at);
    ASSERT_NE(needs, std::string::npos) << log;
    const double predicted = std::atof(log.c_str() + needs + 27);
    std::printf("predicted %.0f s, took %.2f s\n", predicted, took);
    // From the first batch's rate it would say about 9-10 s; the run takes about 2 s.
    EXPECT_LT(std::abs(predicted - took), 1.0) << log;
}

// A synthetic estimator whose batch b adds a value that depends on its seed only (as a tracer's batch does), folded in
// as the tracers fold batches in (mean and Welford's M2). Three scratch caches: one run straight through; a run asked
// to stop after its third batch, then a run that resumes it; and the cache's partial entry at each step.
struct SyntheticTracer {
    CpuAccumulation& acc;
    std::vector<uint32_t> batches; // what was traced, in order
    void operator()(uint32_t spp, uint32_t seed, uint32_t b) {
        batches.push_back(b);
        for (size_t i = 0; i < acc.color.size(); ++i) {
            // One value per batch and pixel, pseudo-random from the seed: 1 + a spread that shrinks nothing itself.
            uint32_t h = seed * 0x9E3779B1u + static_cast<uint32_t>(i) * 0x85EBCA77u;
            h ^= h >> 15;
            h *= 0x2C1B3C6Du;
            h ^= h >> 12;
            const float x = 1.0f + 0.5f * (static_cast<float>(h & 0xFFFFu) / 65535.0f - 0.5f);
            glm::vec4& st = acc.stats[i];
            const float nA = st.x, nB = static_cast<float>(spp), n = nA + nB;
            const float delta = x - st.y;
            st.y += delta * nB / n;
            st.z += delta * delta * nA * nB / n; // within the batch every sample is x: no spread of its own
            st.x = n;
            st.w = n > 1.0f ? std::sqrt(st.z / ((n - 1.0f) * n)) : 0.0f;
            acc.color[i] = glm::vec4(glm::vec3(st.y), 1.0f);
        }
    }
};

class ScratchCache {
public:
    explicit ScratchCache(const char* name) : mDir(std::filesystem::temp_directory_path() / name) {
        std::filesystem::remove_all(mDir);
        const char* old = std::getenv("VITRINE_CACHE_DIR");
        mHad = old != nullptr;
        if (old) mSaved = old;
        setenv("VITRINE_CACHE_DIR", mDir.c_str(), 1);
    }
    ~ScratchCache() {
        if (mHad)
            setenv("VITRINE_CACHE_DIR", mSaved.c_str(), 1);
        else
            unsetenv("VITRINE_CACHE_DIR");
        std::filesystem::remove_all(mDir);
    }
    std::filesystem::path path(const BakeKey& key) const { return BakeCache(mDir).pathOf(key); }

private:
    std::filesystem::path mDir;
    std::string mSaved;
    bool mHad = false;
};

ConvergeRun syntheticRun() {
    ConvergeRun run;
    run.node = "test.converge";
    run.width = 16;
    run.height = 8;
    run.target = 0.015; // the batches' spread (0.14) needs about 12 of them
    run.minSpp = 64;
    run.batch = 8;
    run.seed = 5;
    run.report = false;
    return run;
}

TEST(Converge, AStoppedRunKeepsItsPartialResultAndTheNextRunResumesItToTheSameResult) {
    const BakeKey key{"reference", 0x1234abcdull};
    CpuAccumulation straight;
    uint32_t straightBatches = 0;
    {
        ScratchCache cache("vitrine_test_converge_straight");
        SyntheticTracer tracer{straight, {}};
        ASSERT_TRUE(convergeCached(key, syntheticRun(), straight, std::ref(tracer)));
        straightBatches = static_cast<uint32_t>(tracer.batches.size());
        ASSERT_GT(straightBatches, 6u) << "the target should need several batches";
        EXPECT_TRUE(std::filesystem::exists(cache.path(key)));
        EXPECT_FALSE(std::filesystem::exists(cache.path(partialKey(key))));
    }
    ScratchCache cache("vitrine_test_converge_resumed");
    CpuAccumulation acc;
    {
        SyntheticTracer tracer{acc, {}};
        ConvergeRun run = syntheticRun();
        int asked = 0;
        run.stop = [&] { return ++asked >= 3; };
        testing::internal::CaptureStderr();
        EXPECT_FALSE(convergeCached(key, run, acc, std::ref(tracer)));
        const std::string log = testing::internal::GetCapturedStderr();
        EXPECT_EQ(tracer.batches, (std::vector<uint32_t>{0, 1, 2})) << log;
        EXPECT_NE(log.find("stopped (asked to stop) after 24 spp"), std::string::npos) << log;
        EXPECT_NE(log.find("kept the partial result"), std::string::npos) << log;
        EXPECT_FALSE(std::filesystem::exists(cache.path(key))) << "a stopped run must not look converged";
        EXPECT_TRUE(std::filesystem::exists(cache.path(partialKey(key))));
    }
    {
        CpuAccumulation fresh; // a new process: only the cache carries the partial result
        SyntheticTracer tracer{fresh, {}};
        ConvergeRun run = syntheticRun();
        run.report = true;
        bool resumedHook = false;
        ConvergeHooks hooks;
        hooks.resumed = [&](const CpuAccumulation& a) {
            resumedHook = true;
            EXPECT_FLOAT_EQ(a.stats[0].x, 24.0f);
        };
        testing::internal::CaptureStderr();
        EXPECT_TRUE(convergeCached(key, run, fresh, std::ref(tracer), hooks));
        const std::string log = testing::internal::GetCapturedStderr();
        EXPECT_TRUE(resumedHook);
        EXPECT_NE(log.find("resuming the partial result an earlier run stopped with (24 spp"), std::string::npos)
            << log;
        ASSERT_FALSE(tracer.batches.empty());
        EXPECT_EQ(tracer.batches.front(), 3u) << log;
        EXPECT_EQ(tracer.batches.size() + 3, straightBatches) << log;
        ASSERT_EQ(fresh.color.size(), straight.color.size());
        EXPECT_EQ(0, std::memcmp(fresh.color.data(), straight.color.data(), fresh.color.size() * sizeof(glm::vec4)));
        EXPECT_EQ(0, std::memcmp(fresh.stats.data(), straight.stats.data(), fresh.stats.size() * sizeof(glm::vec4)));
        EXPECT_TRUE(std::filesystem::exists(cache.path(key)));
        EXPECT_FALSE(std::filesystem::exists(cache.path(partialKey(key)))) << "the partial result outlived convergence";
    }
    {
        CpuAccumulation loaded;
        SyntheticTracer tracer{loaded, {}};
        EXPECT_TRUE(convergeCached(key, syntheticRun(), loaded, std::ref(tracer)));
        EXPECT_TRUE(tracer.batches.empty()) << "a converged result is loaded, not traced";
    }
}

// A partial result of another batch size (spp per batch) is not resumed: its batches' seeds would not line up.
TEST(Converge, APartialResultOfAnotherBatchSizeIsNotResumed) {
    ScratchCache cache("vitrine_test_converge_batch");
    const BakeKey key{"reference", 0x55ull};
    CpuAccumulation acc;
    {
        SyntheticTracer tracer{acc, {}};
        ConvergeRun run = syntheticRun();
        run.stop = [] { return true; };
        EXPECT_FALSE(convergeCached(key, run, acc, std::ref(tracer)));
    }
    CpuAccumulation other;
    SyntheticTracer tracer{other, {}};
    ConvergeRun run = syntheticRun();
    run.batch = 16;
    EXPECT_TRUE(convergeCached(key, run, other, std::ref(tracer)));
    ASSERT_FALSE(tracer.batches.empty());
    EXPECT_EQ(tracer.batches.front(), 0u);
}

} // namespace
} // namespace vitrine

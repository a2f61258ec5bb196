// convergeAccumulation (nodes/render/converge.cpp): the announced estimate of the samples and time a target needs.
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
        for (glm::vec4& st : acc.stats) st = glm::vec4(float(samples), 1.0f, 0.0f, float(1.0 / std::sqrt(samples)));
    });
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

} // namespace
} // namespace vitrine

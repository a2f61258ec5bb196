// `vitrine run` and `vitrine bench` as a user runs them, for what the hardening of issue #14 promises: --frames counts
// before validation, scene building is reported apart from compiling, Ctrl-C / SIGTERM stop a multi-frame run at a
// frame boundary with exit 130, a run killed while writing leaves the previous file intact, and a graph too large for
// the device's memory is a user error naming the sizes. The real binary on the machine's Vulkan device (lavapipe in
// CI), validation on, at small sizes.
#include "core/gpu/memory_budget.hpp"
#include "core/image/io.hpp"
#include "gpu_test.hpp"
#include "tests/gpu/cli.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace vitrine::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::string kSource = VITRINE_SOURCE_DIR;
const std::string kZoneplate = kSource + "/graphs/fxaa_zoneplate.json";
const std::string kTiny = "--set frame.width=32 --set frame.height=18";

std::vector<std::string> temporaryFiles(const fs::path& dir) {
    std::vector<std::string> found;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().filename().string().find(".tmp-") != std::string::npos) found.push_back(e.path().filename());
    return found;
}

std::string frameName(const std::string& stem, uint32_t frame, const std::string& ext) {
    char name[64];
    std::snprintf(name, sizeof name, "%s.%04u.%s", stem.c_str(), frame, ext.c_str());
    return name;
}

TEST(RunCli, FramesCountBeforeValidation) {
    const fs::path out = freshDir("run_frames");
    CliResult r = vitrine("run " + quote(kZoneplate) + " " + kTiny +
                          " --frames 3 --set 'frame.write=[0,2]' --validate --quiet --out " + quote(out.string()));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(fs::exists(out / "final.0000.png")) << r.output;
    EXPECT_TRUE(fs::exists(out / "final.0002.png")) << r.output;
    EXPECT_FALSE(fs::exists(out / "final.0001.png")) << r.output;
    EXPECT_TRUE(fs::exists(out / "frame.0002.exr")) << r.output;
}

// The device comes up on another thread while the graph compiles (a warm start's overlap): its errors still reach the
// user as before, and a graph's own error is reported first, alone.
TEST(RunCli, DeviceAndGraphErrorsSurviveTheOverlappedStart) {
    const fs::path out = freshDir("run_device_errors");
    CliResult unknownDevice = vitrine("run " + quote(kZoneplate) + " " + kTiny +
                                      " --device no-such-gpu --quiet --out " + quote(out.string()));
    EXPECT_EQ(unknownDevice.status, 1) << unknownDevice.output;
    EXPECT_NE(unknownDevice.output.find("--device no-such-gpu: no such Vulkan device"), std::string::npos)
        << unknownDevice.output;
    CliResult both = vitrine("run " + quote(kSource + "/graphs/no_such_graph.json") +
                             " --device no-such-gpu --quiet --out " + quote(out.string()));
    EXPECT_EQ(both.status, 1) << both.output;
    EXPECT_NE(both.output.find("no_such_graph.json: no such file"), std::string::npos) << both.output;
    EXPECT_EQ(both.output.find("no such Vulkan device"), std::string::npos) << both.output;
    CliResult fine =
        vitrine("run " + quote(kZoneplate) + " " + kTiny + " --validate --quiet --out " + quote((out / "ok").string()));
    EXPECT_EQ(fine.status, 0) << fine.output;
    EXPECT_TRUE(fs::exists(out / "ok" / "final.png")) << fine.output;
}

TEST(CompareCli, FramesCountBeforeValidation) {
    const fs::path out = freshDir("compare_frames");
    CliResult r =
        vitrine("compare " + quote(kZoneplate) + " " + quote(kSource + "/graphs/variants/no_fxaa.json") + " " + kTiny +
                " --frames 0:2 --set 'frame.write=[2]' --validate --quiet --out " + quote(out.string()));
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(fs::exists(out / "metrics.json")) << r.output;
}

// The scene node's setup (building or loading the scene) is reported as scene_build, not inside compile_ms.graph.
TEST(BenchCli, JsonFileReportsSceneBuildApartFromGraphCompile) {
    const fs::path dir = freshDir("bench_scene");
    const json graph = {
        {"format", "vitrine-graph/1"},
        {"frame", {{"width", 32}, {"height", 18}}},
        {"nodes",
         {{"scene", {{"type", "scene.gltf"}, {"params", {{"path", kSource + "/tests/data/gltf/quad.gltf"}}}}},
          {"gbuffer", {{"type", "gbuffer.layered"}, {"in", {{"scene", "scene.scene"}}}}}}},
        {"outputs", {{"normal", "gbuffer.normal"}}}};
    std::ofstream(dir / "graph.json") << graph.dump(2);
    // 2 + 1 warm-up frames: frame.write may name frame 2 although the file has one frame.
    CliResult r = vitrine("bench " + quote((dir / "graph.json").string()) +
                          " --frames 2 --warmup 1 --set 'frame.write=[2]' --validate --quiet --json " +
                          quote((dir / "bench.json").string()));
    ASSERT_EQ(r.status, 0) << r.output;
    const json bench = json::parse(readFile(dir / "bench.json"), nullptr, false);
    ASSERT_TRUE(bench.is_object()) << readFile(dir / "bench.json");
    const json& compile = bench["compile_ms"];
    ASSERT_TRUE(compile.contains("graph") && compile.contains("scene_build") && compile.contains("pipelines"))
        << compile;
    double sceneSetup = -1.0, gbufferSetup = -1.0;
    for (const json& p : bench["passes"]) {
        if (p["id"] == "scene") sceneSetup = p["setup_ms"].get<double>();
        if (p["id"] == "gbuffer") gbufferSetup = p["setup_ms"].get<double>();
    }
    EXPECT_GT(sceneSetup, 0.0) << bench["passes"];
    EXPECT_GE(gbufferSetup, 0.0) << bench["passes"];
    EXPECT_DOUBLE_EQ(compile["scene_build"].get<double>(), sceneSetup) << compile;
    EXPECT_GE(compile["graph"].get<double>(), gbufferSetup) << compile;
    EXPECT_NE(r.output.find("scene build"), std::string::npos) << r.output;
}

// Starts `vitrine ARGS` in the background with its output going to `log`; returns its pid.
pid_t spawnVitrine(const std::vector<std::string>& args, const fs::path& log) {
    pid_t pid = fork();
    if (pid == 0) {
        int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        dup2(fd, 1);
        dup2(fd, 2);
        std::vector<char*> argv = {const_cast<char*>(VITRINE_BINARY)};
        for (const auto& a : args)
            argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        execv(VITRINE_BINARY, argv.data());
        _exit(127);
    }
    return pid;
}

// Waits up to `seconds` for the child; -1 (and kills it) when it did not end.
int waitFor(pid_t pid, int seconds, int& status) {
    for (int i = 0; i < seconds * 20; ++i) {
        if (waitpid(pid, &status, WNOHANG) == pid) return 0;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    return -1;
}

class RunInterrupted : public testing::TestWithParam<int> {};

// A long run writing every frame is signalled once frame 3 is on disk. It must exit 130 after finishing the frame it
// was in: every frame before the stop has all its files (two PNGs and the EXR), none after it has any.
TEST_P(RunInterrupted, StopsAtAFrameBoundaryWithExit130) {
    const int signal = GetParam();
    const fs::path out = freshDir(std::string("run_interrupted_") + (signal == SIGINT ? "int" : "term"));
    std::string write = "frame.write=[";
    for (int f = 0; f < 400; ++f)
        write += (f ? "," : "") + std::to_string(f);
    write += "]";
    const pid_t pid =
        spawnVitrine({"run", kZoneplate, "--frames", "1000000", "--set", "frame.width=32", "--set", "frame.height=18",
                      "--set", write, "--set", "outputs.raw=pattern.color", "--quiet", "--out", out.string()},
                     out / "log.txt");
    ASSERT_GT(pid, 0);
    bool started = false;
    for (int i = 0; i < 1200 && !started; ++i) {
        started = fs::exists(out / "final.0003.png");
        if (!started) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    kill(pid, signal);
    int status = 0;
    ASSERT_EQ(waitFor(pid, 120, status), 0) << "still running 120 s after the signal; log:\n"
                                            << readFile(out / "log.txt");
    ASSERT_TRUE(started) << "frame 3 never appeared; log:\n" << readFile(out / "log.txt");
    const std::string log = readFile(out / "log.txt");
    ASSERT_TRUE(WIFEXITED(status)) << "ended by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0) << "\n" << log;
    EXPECT_EQ(WEXITSTATUS(status), 130) << log;
    std::smatch m;
    const std::string what = signal == SIGINT ? "interrupted \\(SIGINT\\)" : "terminated \\(SIGTERM\\)";
    ASSERT_TRUE(std::regex_search(log, m, std::regex(what + ": stopped after (\\d+) of 1000000 frames"))) << log;
    const uint32_t done = static_cast<uint32_t>(std::stoul(m[1]));
    EXPECT_GE(done, 4u) << log;
    EXPECT_LT(done, 1000000u) << log;
    for (uint32_t f = 0; f < std::min(done, 400u); ++f) {
        for (const std::string& name :
             {frameName("final", f, "png"), frameName("raw", f, "png"), frameName("frame", f, "exr")}) {
            ASSERT_TRUE(fs::exists(out / name)) << name << " missing although " << done << " frames finished";
            EXPECT_NO_THROW(loadImage(out / name)) << name;
        }
    }
    for (uint32_t f = done; f < 400; ++f)
        EXPECT_FALSE(fs::exists(out / frameName("final", f, "png")) || fs::exists(out / frameName("frame", f, "exr")))
            << "frame " << f << " has files but the run said it stopped after " << done;
    EXPECT_TRUE(temporaryFiles(out).empty()) << temporaryFiles(out).front();
}

// Ctrl-C while render.pathtrace converges to a target it cannot reach soon (the museum's reference at 32x18, target
// 0.1 %): the run stops after the batch it is in, exits 130 and keeps its samples in the bake cache as a partial
// result; the next run resumes from them (and, stopped by max_seconds this time, keeps the larger partial result).
TEST(RunConverging, CtrlCKeepsThePartialResultAndTheNextRunResumesIt) {
    const fs::path out = freshDir("run_converging_sigint");
    const fs::path cache = out / "cache";
    const char* old = std::getenv("VITRINE_CACHE_DIR");
    const std::string saved = old ? old : "";
    setenv("VITRINE_CACHE_DIR", cache.c_str(), 1);
    const std::vector<std::string> args = {"run",      kSource + "/graphs/variants/museum_reference.json",
                                           "--set",    "frame.width=32",
                                           "--set",    "frame.height=18",
                                           "--set",    "scene.params.texture_size=32",
                                           "--set",    "pathtrace.params.target_noise=0.001",
                                           "--verbose"};
    std::vector<std::string> first = args;
    first.insert(first.end(), {"--out", (out / "first").string()});
    const pid_t pid = spawnVitrine(first, out / "first.log");
    ASSERT_GT(pid, 0);
    bool tracing = false;
    for (int i = 0; i < 2400 && !tracing; ++i) {
        tracing = readFile(out / "first.log").find("render.pathtrace: batch 1:") != std::string::npos;
        if (!tracing) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    kill(pid, SIGINT);
    int status = 0;
    const bool ended = waitFor(pid, 120, status) == 0;
    const std::string log = readFile(out / "first.log");
    ASSERT_TRUE(tracing) << "never got to its second batch; log:\n" << log;
    ASSERT_TRUE(ended) << "still running 120 s after Ctrl-C; log:\n" << log;
    ASSERT_TRUE(WIFEXITED(status)) << log;
    EXPECT_EQ(WEXITSTATUS(status), 130) << log;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(log, m, std::regex("stopped \\(asked to stop\\) after (\\d+) spp"))) << log;
    const int stoppedAt = std::stoi(m[1]);
    EXPECT_NE(log.find("kept the partial result in the bake cache"), std::string::npos) << log;
    size_t partials = 0;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(cache / "bake" / "reference_partial", ec))
        partials += e.path().extension() == ".bin";
    EXPECT_EQ(partials, 1u) << log;

    std::vector<std::string> second = args;
    second.insert(second.end(), {"--set", "pathtrace.params.max_seconds=0.5", "--out", (out / "second").string()});
    const pid_t again = spawnVitrine(second, out / "second.log");
    ASSERT_GT(again, 0);
    ASSERT_EQ(waitFor(again, 300, status), 0) << readFile(out / "second.log");
    const std::string log2 = readFile(out / "second.log");
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << log2;
    EXPECT_NE(
        log2.find("resuming the partial result an earlier run stopped with (" + std::to_string(stoppedAt) + " spp"),
        std::string::npos)
        << log2;
    ASSERT_TRUE(std::regex_search(log2, m, std::regex("stopped \\(max_seconds ran out\\) after (\\d+) spp"))) << log2;
    EXPECT_GT(std::stoi(m[1]), stoppedAt) << log2;
    if (old)
        setenv("VITRINE_CACHE_DIR", saved.c_str(), 1);
    else
        unsetenv("VITRINE_CACHE_DIR");
}

INSTANTIATE_TEST_SUITE_P(Signals, RunInterrupted, testing::Values(SIGINT, SIGTERM),
                         [](const testing::TestParamInfo<int>& info) {
                             return std::string(info.param == SIGINT ? "Sigint" : "Sigterm");
                         });

class RunKilledWhileWriting : public testing::TestWithParam<std::string> {};

// A run whose writer dies halfway through a file (VITRINE_TEST_KILL_DURING_WRITE cuts the file being written to half
// and SIGKILLs the process) leaves the file of the previous run as it was; a run that completes replaces it.
TEST_P(RunKilledWhileWriting, LeavesThePreviousFileIntact) {
    const std::string file = GetParam();
    const fs::path out = freshDir("run_killed_" + file.substr(file.rfind('.') + 1));
    const std::string base =
        "run " + quote(kZoneplate) + " " + kTiny + " --validate --quiet --out " + quote(out.string());
    ASSERT_EQ(vitrine(base).status, 0);
    const std::string before = readFile(out / file);
    ASSERT_FALSE(before.empty());

    const std::string changed = base + " --set pattern.params.max_frequency=0.1";
    CliResult killed = vitrine(changed, "VITRINE_TEST_KILL_DURING_WRITE=" + file);
    EXPECT_EQ(killed.signal, SIGKILL) << killed.output;
    EXPECT_EQ(readFile(out / file), before) << file << " was changed by the killed run";
    EXPECT_NO_THROW(loadImage(out / file));
    EXPECT_FALSE(temporaryFiles(out).empty()) << "the killed run left no temporary file: did it write at all?";

    ASSERT_EQ(vitrine(changed).status, 0);
    EXPECT_NE(readFile(out / file), before) << "the changed graph renders the same " << file;
}

INSTANTIATE_TEST_SUITE_P(Outputs, RunKilledWhileWriting, testing::Values("final.png", "frame.0000.exr"),
                         [](const testing::TestParamInfo<std::string>& info) {
                             return info.param.substr(info.param.rfind('.') + 1);
                         });

// Enough 16384x16384 RGBA32F zone plates (4 GiB each) to exceed the largest heap of this device: the run must stop
// before allocating, with exit 1 naming the graph, the frame size and the sizes involved.
TEST(MemoryBudget, GraphTooLargeForTheDeviceIsAUserError) {
    const MemoryBudget budget = queryMemoryBudget(gpu().physicalDevice());
    VkDeviceSize largest = 0;
    for (const HeapBudget& h : budget.heaps)
        largest = std::max(largest, h.size);
    const VkDeviceSize perImage = 16384ull * 16384ull * 16ull;
    const size_t count = static_cast<size_t>(largest / perImage) + 1;
    json graph = {{"format", "vitrine-graph/1"}, {"frame", {{"width", 16384}, {"height", 16384}}}};
    for (size_t i = 0; i < count; ++i) {
        graph["nodes"]["zp" + std::to_string(i)] = {{"type", "pattern.zoneplate"}};
        graph["outputs"]["zp" + std::to_string(i)] = "zp" + std::to_string(i) + ".color";
    }
    const fs::path dir = freshDir("memory_budget_large");
    std::ofstream(dir / "huge.json") << graph.dump(2);
    const auto start = std::chrono::steady_clock::now();
    CliResult r = vitrine("run " + quote((dir / "huge.json").string()) + " --validate --quiet --out " +
                          quote((dir / "out").string()));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("huge.json: frame 16384x16384: "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(" GiB"), std::string::npos) << r.output;
    EXPECT_TRUE(r.output.find("per allocation") != std::string::npos ||
                r.output.find("the graph's textures need") != std::string::npos)
        << r.output;
    EXPECT_LT(seconds, 60.0) << "it should stop before rendering anything";
}

// VITRINE_MEMORY_BUDGET lowers what the heaps may hold: the 1024x1024 zone plate + FXAA needs 48 MiB (a 32 MiB
// transient heap for two overlapping RGBA32F textures, 16 MiB for the tone-mapped output).
TEST(MemoryBudget, LoweredBudgetStopsAGraphThatNeedsMore) {
    const fs::path out = freshDir("memory_budget_lowered");
    const std::string args = "run " + quote(kZoneplate) +
                             " --set frame.width=1024 --set frame.height=1024 --exr none " +
                             "--validate --quiet --out " + quote(out.string());
    CliResult low = vitrine(args, "VITRINE_MEMORY_BUDGET=40");
    EXPECT_EQ(low.status, 1) << low.output;
    EXPECT_NE(low.output.find("fxaa_zoneplate.json: frame 1024x1024: the graph's textures need 48.0 MiB"),
              std::string::npos)
        << low.output;
    EXPECT_NE(low.output.find("VITRINE_MEMORY_BUDGET allows 40.0 MiB"), std::string::npos) << low.output;
    EXPECT_FALSE(fs::exists(out / "final.png"));
    CliResult enough = vitrine(args, "VITRINE_MEMORY_BUDGET=48");
    EXPECT_EQ(enough.status, 0) << enough.output;
}

} // namespace
} // namespace vitrine::test

// The `vitrine` Python module (README "Python"): graphs loaded, edited and run from Python, outputs as NumPy arrays,
// `compare` returning the metrics of metrics.json. Everything goes through the code the command line runs: the
// loader and validator of `run`, the warm compiled graphs of `serve` (tools/vitrine/serve/warm_graphs.hpp), the
// frame/--set handling of render_output.hpp and `compare` itself (compare_command.cpp).
#include "core/base/error.hpp"
#include "core/base/log.hpp"
#include "core/gpu/context.hpp"
#include "core/graph/executor.hpp"
#include "core/graph/loader.hpp"
#include "core/graph/registry.hpp"
#include "core/image/io.hpp"
#include "core/shader/compiler.hpp"
#include "tools/vitrine/cli.hpp"
#include "tools/vitrine/render_output.hpp"
#include "tools/vitrine/serve/warm_graphs.hpp"
#include "tools/vitrine/version.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <regex>
#include <sstream>

namespace py = pybind11;
namespace fs = std::filesystem;

namespace vitrine::python {

namespace {

// Exception types, made at import (see PYBIND11_MODULE).
PyObject* gError = nullptr;         // vitrine.Error
PyObject* gUserError = nullptr;     // vitrine.UserError(vitrine.Error, ValueError)
PyObject* gInternalError = nullptr; // vitrine.InternalError(vitrine.Error, RuntimeError)

// The JSON pointer a user error names ("graphs/x.json: /nodes/fxaa/params/subpix: expected ..."): the first
// component "/", "/nodes...", "/frame...", "/outputs...", ... of the graph format (so an absolute file path is never
// taken for one). Empty when it names none (a missing file, a --set syntax error).
std::string pointerOf(const std::string& message) {
    static const std::regex pointer(
        R"((?:^|: )(/(?:(?:nodes|frame|outputs|extends|format|description|\$schema)(?:/[^\s:]*)?)?)(?=:|$))");
    std::smatch m;
    if (std::regex_search(message, m, pointer)) return m[1].str();
    return {};
}

void raiseUserError(const std::string& message) {
    py::object type = py::reinterpret_borrow<py::object>(gUserError);
    py::object error = type(message);
    const std::string pointer = pointerOf(message);
    error.attr("pointer") = pointer.empty() ? py::object(py::none()) : py::object(py::str(pointer));
    error.attr("message") = py::str(message);
    PyErr_SetObject(gUserError, error.ptr());
}

py::object toPython(const nlohmann::json& j) {
    return py::module_::import("json").attr("loads")(j.dump());
}

nlohmann::json fromPython(const py::handle& value) {
    return nlohmann::json::parse(py::module_::import("json").attr("dumps")(value).cast<std::string>());
}

// set={"frame.width": 320, "tonemap.params.exposure": 1.5}: `--set KEY=VALUE` assignments, the value as JSON.
std::vector<std::string> assignments(const py::object& set) {
    std::vector<std::string> out;
    if (set.is_none()) return out;
    if (!py::isinstance<py::dict>(set))
        throw py::type_error("set: expected a dict of {\"node.params.name\": value}, got " +
                             py::str(py::type::of(set)).cast<std::string>());
    for (auto [key, value] : set.cast<py::dict>()) {
        if (!py::isinstance<py::str>(key)) throw py::type_error("set: keys must be strings like \"frame.width\"");
        out.push_back(key.cast<std::string>() + "=" + fromPython(value).dump());
    }
    return out;
}

// A Vulkan device with its shader compiler and the compiled graphs kept warm on it (as `vitrine serve` keeps them).
class Device {
public:
    explicit Device(const std::string& device, bool validate, size_t warm) {
        mOptions.device = device;
        mOptions.validation = validate;
        py::gil_scoped_release release;
        mCtx = std::make_unique<Context>(mOptions);
        mShaders = std::make_unique<ShaderCompiler>();
        mWarm = std::make_unique<serve::WarmGraphs>(std::max<size_t>(warm, 1));
    }
    ~Device() { close(); }

    void close() {
        std::lock_guard lock(mMutex);
        mWarm.reset(); // executors before the context
        mShaders.reset();
        mCtx.reset();
    }
    Context& ctx() {
        if (!mCtx) throw UserError("vitrine.Device: the device was closed");
        return *mCtx;
    }
    std::string name() { return ctx().deviceInfo().name; }
    const ContextOptions& options() const { return mOptions; }
    size_t validationMessages() { return ctx().validationMessageCount(); }

    ContextOptions mOptions;
    std::unique_ptr<Context> mCtx;
    std::unique_ptr<ShaderCompiler> mShaders;
    std::unique_ptr<serve::WarmGraphs> mWarm;
    std::mutex mMutex; // one run at a time on a device (the GIL is released while it works)
};

std::shared_ptr<Device> gDefaultDevice;

std::shared_ptr<Device> defaultDevice() {
    if (!gDefaultDevice) {
        const char* env = std::getenv("VITRINE_DEVICE");
        gDefaultDevice = std::make_shared<Device>(env ? env : "", false, 4);
    }
    return gDefaultDevice;
}

// An image as a NumPy array that shares its memory (no copy): float32 (height, width, 4).
py::array_t<float> floatArray(std::shared_ptr<Image> image) {
    auto* owner = new std::shared_ptr<Image>(image);
    py::capsule capsule(owner, [](void* p) { delete static_cast<std::shared_ptr<Image>*>(p); });
    return py::array_t<float>({image->height, image->width, 4}, image->pixels.data(), capsule);
}

py::array_t<uint8_t> byteArray(std::vector<unsigned char> bytes, int width, int height) {
    auto* owner = new std::vector<unsigned char>(std::move(bytes));
    py::capsule capsule(owner, [](void* p) { delete static_cast<std::vector<unsigned char>*>(p); });
    return py::array_t<uint8_t>({height, width, 4}, owner->data(), capsule);
}

// What Graph.run() returns.
struct RunResult {
    std::map<std::string, std::shared_ptr<Image>> images; // every graph output at the last frame
    std::vector<std::string> passIds;
    std::vector<FrameTiming> timings; // this run's frames
    uint32_t frames = 0;
    bool reused = false;    // the compiled graph (pipelines, images, uploaded scenes) was kept from an earlier run
    double compileMs = 0.0; // compiling the graph and creating its executor (0 when reused)
    double runMs = 0.0;     // the frames, read-back included
    size_t validationMessages = 0;

    std::shared_ptr<Image> image(const std::string& name) const {
        auto it = images.find(name);
        if (it == images.end()) {
            std::string names;
            for (const auto& [n, _] : images)
                names += (names.empty() ? "" : ", ") + n;
            throw py::key_error("no output '" + name + "' (the graph's outputs: " + names + ")");
        }
        return it->second;
    }
};

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

class Graph {
public:
    static std::shared_ptr<Graph> load(const fs::path& file, const py::object& set, std::shared_ptr<Device> device) {
        auto g = std::make_shared<Graph>();
        g->mFile = file;
        g->mSets = assignments(set);
        g->mDevice = device ? std::move(device) : defaultDevice();
        g->mDesc = loadGraph(g->mFile, g->mSets); // validated now: errors at load, not at the first run
        return g;
    }

    // More --set assignments, validated at once; the graph is unchanged when they fail. A key set before is replaced
    // in place (not appended), so that setting a value back gives the same document as before, which the device
    // may still have compiled.
    void set(const py::object& set) {
        std::vector<std::string> sets = mSets;
        for (std::string& s : assignments(set)) {
            const std::string key = s.substr(0, s.find('=') + 1);
            auto same =
                std::find_if(sets.begin(), sets.end(), [&](const std::string& o) { return o.rfind(key, 0) == 0; });
            if (same != sets.end())
                *same = std::move(s);
            else
                sets.push_back(std::move(s));
        }
        mDesc = loadGraph(mFile, sets);
        mSets = std::move(sets);
    }

    py::dict nodes() const {
        py::dict out;
        for (const NodeDecl& n : mDesc.nodes) {
            py::dict node;
            node["type"] = n.schema ? n.schema->type : std::string();
            node["params"] = toPython(n.params);
            py::dict inputs;
            for (const auto& [port, ref] : n.inputs)
                inputs[py::str(port)] = ref.text();
            node["inputs"] = inputs;
            out[py::str(n.id)] = node;
        }
        return out;
    }

    py::dict outputs() const {
        py::dict out;
        for (const OutputDecl& o : mDesc.outputs)
            out[py::str(o.name)] = o.source.text();
        return out;
    }

    // The schema of a node type (`vitrine nodes --json` gives them all), or of the type of a node of this graph.
    py::object schema(const std::string& typeOrNode) const {
        std::string type = typeOrNode;
        if (int n = mDesc.findNode(typeOrNode); n >= 0 && mDesc.nodes[n].schema) type = mDesc.nodes[n].schema->type;
        const NodeSchema* s = NodeRegistry::global().find(type);
        if (!s) throw UserError("schema: no node type or node '" + typeOrNode + "' (" + mFile.string() + ")");
        return toPython(s->toJson());
    }

    RunResult run(uint32_t frames) {
        // The frame count as `vitrine run --frames N` puts it into the document (frame.frames, frame.write).
        cli::Args none;
        std::vector<std::string> sets = mSets;
        for (std::string& s : cli::setsWithFrames(none, frames))
            sets.push_back(std::move(s));
        serve::PreparedGraph prepared;
        prepared.desc = frames > 0 ? loadGraph(mFile, sets) : mDesc;
        RunResult result;
        std::shared_ptr<Device> device = mDevice;
        {
            py::gil_scoped_release release; // compiling (scene builds, bakes) and the GPU work run without the GIL
            std::lock_guard lock(device->mMutex);
            Context& ctx = device->ctx();
            const size_t before = ctx.validationMessageCount();
            const auto start = std::chrono::steady_clock::now();
            bool compiled = false;
            serve::WarmGraphs::Entry* entry = nullptr;
            try {
                entry = &device->mWarm->get(ctx, *device->mShaders, prepared, compiled);
                const auto compiledAt = std::chrono::steady_clock::now();
                Executor& executor = device->mWarm->executor(*entry);
                const size_t firstTiming = executor.timings().size();
                const uint32_t count = prepared.desc.frame.frames;
                RunOptions options;
                options.frames = count;
                options.write = {count - 1};
                options.progress = false;
                options.onOutput = [&](uint32_t, const std::string& name, const Image& image) {
                    result.images[name] = std::make_shared<Image>(image);
                };
                executor.run(options);
                const auto done = std::chrono::steady_clock::now();
                result.frames = count;
                result.reused = !compiled;
                result.compileMs =
                    compiled ? std::chrono::duration<double, std::milli>(compiledAt - start).count() : 0.0;
                result.runMs = std::chrono::duration<double, std::milli>(done - compiledAt).count();
                result.timings.assign(executor.timings().begin() + static_cast<std::ptrdiff_t>(firstTiming),
                                      executor.timings().end());
                for (const CompiledPass& p : device->mWarm->graph(*entry).passes)
                    result.passIds.push_back(p.id);
                result.validationMessages = ctx.validationMessageCount() - before;
            } catch (...) {
                if (entry) device->mWarm->drop(*entry);
                throw;
            }
        }
        return result;
    }

    py::object document() const { return toPython(mDesc.document); }
    const fs::path& file() const { return mFile; }
    std::shared_ptr<Device> device() const { return mDevice; }

private:
    fs::path mFile;
    std::vector<std::string> mSets;
    GraphDesc mDesc;
    std::shared_ptr<Device> mDevice;
};

// A path, or a NumPy array written to a float EXR in `temp` (a (H, W, 4) or (H, W, 3) float array, alpha 1 then).
std::string compareInput(const py::object& input, const std::string& key, const fs::path& temp) {
    if (py::isinstance<py::array>(input)) {
        py::array array = input.cast<py::array>();
        if (array.ndim() != 3 || (array.shape(2) != 3 && array.shape(2) != 4))
            throw UserError("compare " + key + ": expected an array of shape (height, width, 4) or (height, width, 3)");
        if (!array.dtype().is(py::dtype::of<float>()) && !array.dtype().is(py::dtype::of<double>()))
            throw UserError("compare " + key +
                            ": expected a float32 array of the output's values (r[\"final\"]); "
                            "compare a displayed uint8 image as a PNG file instead");
        const int h = static_cast<int>(array.shape(0)), w = static_cast<int>(array.shape(1));
        const int c = static_cast<int>(array.shape(2));
        Image image(w, h);
        auto f = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(array);
        if (!f) throw UserError("compare " + key + ": the array cannot be read as float32");
        const float* src = f.data();
        for (size_t i = 0; i < static_cast<size_t>(w) * h; ++i)
            for (int ch = 0; ch < 4; ++ch)
                image.pixels[i * 4 + ch] = ch < c ? src[i * c + ch] : 1.0f;
        const fs::path path = temp / (key + ".exr");
        writeExr(path, image, ExrPixelType::Float);
        return path.string();
    }
    if (py::isinstance<py::str>(input) || py::hasattr(input, "__fspath__"))
        return py::module_::import("os").attr("fspath")(input).cast<std::string>();
    throw py::type_error("compare " + key + ": expected a path (graph .json or image) or a NumPy array");
}

py::object compare(const py::object& a, const py::object& b, const py::object& reference, const py::object& out,
                   const py::object& set, const py::object& frame, const py::object& frames, const py::object& output,
                   bool hdr, const py::object& ppd, bool noiseFloor, bool force, std::shared_ptr<Device> device) {
    char pattern[] = "/tmp/vitrine-compare-XXXXXX";
    if (!mkdtemp(pattern)) throw InternalError("compare: cannot create a temporary folder in /tmp");
    const fs::path temp = pattern;
    struct Cleanup {
        fs::path dir;
        ~Cleanup() {
            std::error_code ec;
            fs::remove_all(dir, ec);
        }
    } cleanup{temp};

    cli::Args args;
    args.command = "compare";
    args.positional = {compareInput(a, "a", temp), compareInput(b, "b", temp)};
    if (!reference.is_none()) args.options["reference"] = {compareInput(reference, "reference", temp)};
    const fs::path outDir = out.is_none() ? temp / "out" : fs::path(py::str(out).cast<std::string>());
    args.options["out"] = {outDir.string()};
    for (std::string& s : assignments(set))
        args.options["set"].push_back(std::move(s));
    if (!frame.is_none()) args.options["frame"] = {std::to_string(frame.cast<uint32_t>())};
    if (!frames.is_none()) {
        auto range = frames.cast<std::pair<uint32_t, uint32_t>>();
        args.options["frames"] = {std::to_string(range.first) + ":" + std::to_string(range.second)};
    }
    if (!output.is_none()) args.options["output"] = {output.cast<std::string>()};
    if (hdr) args.options["hdr"] = {""};
    if (!ppd.is_none()) args.options["ppd"] = {py::str(ppd).cast<std::string>()};
    if (!noiseFloor) args.options["no-noise-floor"] = {""};
    if (force) args.options["force"] = {""};
    args.options["quiet"] = {""};
    args.options["no-summary"] = {""};
    const ContextOptions& options = (device ? device : defaultDevice())->options();
    if (!options.device.empty()) args.options["device"] = {options.device};
    if (options.validation) args.options["validate"] = {""};

    int status = 0;
    {
        py::gil_scoped_release release;
        status = cli::compareCommand(args);
    }
    if (status == 2) throw InternalError("compare: Vulkan validation messages while rendering (see stderr)");
    std::ifstream in(outDir / "metrics.json");
    std::stringstream text;
    text << in.rdbuf();
    return toPython(nlohmann::json::parse(text.str()));
}

py::dict readExr(const fs::path& path) {
    py::dict out;
    for (auto& [name, image] : readExrLayers(path))
        out[py::str(name)] = floatArray(std::make_shared<Image>(std::move(image)));
    return out;
}

} // namespace
} // namespace vitrine::python

PYBIND11_MODULE(vitrine, m) {
    using namespace vitrine;
    using namespace vitrine::python;
    m.doc() = "vitrine: load, edit and run render graphs; outputs as NumPy arrays; compare images (README \"Python\")";
    m.attr("__version__") = versionNumber();
    m.attr("commit") = versionCommit();
    // VITRINE_LOG=debug|info|warning|error (default warning), or vitrine.set_log_level() later.
    static const std::map<std::string, LogLevel> kLevels = {
        {"debug", LogLevel::Debug}, {"info", LogLevel::Info}, {"warning", LogLevel::Warning}, {"error", LogLevel::Error}};
    const char* envLevel = std::getenv("VITRINE_LOG");
    auto envIt = envLevel ? kLevels.find(envLevel) : kLevels.end();
    setLogLevel(envIt != kLevels.end() ? envIt->second : LogLevel::Warning);

    gError = PyErr_NewException("vitrine.Error", PyExc_Exception, nullptr);
    py::tuple userBases = py::make_tuple(py::handle(gError), py::handle(PyExc_ValueError));
    gUserError = PyErr_NewException("vitrine.UserError", userBases.ptr(), nullptr);
    py::tuple internalBases = py::make_tuple(py::handle(gError), py::handle(PyExc_RuntimeError));
    gInternalError = PyErr_NewException("vitrine.InternalError", internalBases.ptr(), nullptr);
    m.attr("Error") = py::handle(gError);
    m.attr("UserError") = py::handle(gUserError);
    m.attr("InternalError") = py::handle(gInternalError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const UserError& e) {
            raiseUserError(e.what());
        } catch (const InternalError& e) {
            PyErr_SetString(gInternalError, e.what());
        }
    });

    py::class_<Device, std::shared_ptr<Device>>(
        m, "Device",
        "A Vulkan device, chosen like --device: an index or part of its name "
        "('' = the best discrete GPU, else lavapipe). validate=True turns on the "
        "validation layers (messages counted in RunResult.validation_messages).")
        .def(py::init<const std::string&, bool, size_t>(), py::arg("device") = "", py::arg("validate") = false,
             py::arg("warm") = 4)
        .def_property_readonly("name", &Device::name)
        .def_property_readonly("validation_messages", &Device::validationMessages)
        .def("close", &Device::close, "Free the device and every graph kept warm on it.")
        .def("__repr__", [](Device& d) { return "<vitrine.Device '" + d.name() + "'>"; });

    m.def(
        "devices",
        [] {
            std::vector<py::dict> out;
            for (const auto& d : Context::listDevices()) {
                py::dict e;
                e["index"] = d.index;
                e["name"] = d.name;
                out.push_back(e);
            }
            return out;
        },
        "The Vulkan devices (as `vitrine devices`).");

    py::class_<RunResult>(m, "RunResult", "The outputs of the last frame of a run, and its timings.")
        .def(
            "__getitem__", [](const RunResult& r, const std::string& name) { return floatArray(r.image(name)); },
            "The output as scene-linear float32 (height, width, 4), sharing the result's memory (no copy).")
        .def(
            "display",
            [](const RunResult& r, const std::string& name) {
                std::shared_ptr<Image> image = r.image(name);
                return byteArray(displayBytes(*image), image->width, image->height);
            },
            py::arg("name"),
            "The output as the uint8 (height, width, 4) pixels `vitrine run` writes to NAME.png (sRGB display "
            "transform through the OCIO config).")
        .def("keys",
             [](const RunResult& r) {
                 std::vector<std::string> k;
                 for (const auto& [n, _] : r.images)
                     k.push_back(n);
                 return k;
             })
        .def("__contains__", [](const RunResult& r, const std::string& n) { return r.images.count(n) != 0; })
        .def("__len__", [](const RunResult& r) { return r.images.size(); })
        .def_property_readonly(
            "timings",
            [](const RunResult& r) {
                py::dict out;
                for (size_t p = 0; p < r.passIds.size(); ++p) {
                    std::vector<double> ms;
                    for (const FrameTiming& t : r.timings)
                        ms.push_back(t.passGpuMs.at(p));
                    out[py::str(r.passIds[p])] = median(ms);
                }
                return out;
            },
            "GPU milliseconds per node (timestamp queries; the median over the run's frames), as `vitrine bench`.")
        .def_property_readonly(
            "frame_timings",
            [](const RunResult& r) {
                std::vector<py::dict> out;
                for (const FrameTiming& t : r.timings) {
                    py::dict f, passes;
                    for (size_t p = 0; p < r.passIds.size(); ++p)
                        passes[py::str(r.passIds[p])] = t.passGpuMs.at(p);
                    f["gpu_ms"] = passes;
                    f["cpu_record_ms"] = t.cpuRecordMs;
                    f["cpu_wait_ms"] = t.cpuWaitMs;
                    f["frame_ms"] = t.frameMs;
                    out.push_back(f);
                }
                return out;
            },
            "Per frame: GPU ms per node, CPU record ms (less waits), CPU ms waiting for the GPU while recording, "
            "submit-to-completion ms.")
        .def_readonly("frames", &RunResult::frames)
        .def_readonly("reused", &RunResult::reused,
                      "The compiled graph was kept from an earlier run of the same document (nothing compiled).")
        .def_readonly("compile_ms", &RunResult::compileMs)
        .def_readonly("run_ms", &RunResult::runMs)
        .def_readonly("validation_messages", &RunResult::validationMessages)
        .def("__repr__", [](const RunResult& r) {
            std::string names;
            for (const auto& [n, i] : r.images)
                names +=
                    (names.empty() ? "" : ", ") + n + " " + std::to_string(i->width) + "x" + std::to_string(i->height);
            return "<vitrine.RunResult " + names + ", " + std::to_string(r.frames) + " frame(s)" +
                   (r.reused ? ", reused" : "") + ">";
        });

    py::class_<Graph, std::shared_ptr<Graph>>(m, "Graph",
                                              "A render graph file with --set assignments, run on a Device.")
        .def_static("load", &Graph::load, py::arg("path"), py::arg("set") = py::none(),
                    py::arg("device") = std::shared_ptr<Device>(),
                    "Load and validate a graph; set={'frame.width': 320, 'node.params.name': value} as --set.")
        .def("set", &Graph::set, py::arg("assignments"),
             "More --set assignments (a dict), validated at once; the graph is unchanged when they fail.")
        .def("run", &Graph::run, py::arg("frames") = 0,
             "Render `frames` frames (0: the graph's frame.frames) and return the outputs of the last one. A document "
             "run before on the same Device reuses its compiled graph; after set() the unchanged parts come from the "
             "caches (museum scene in memory, SPIR-V, bakes, pipeline cache).")
        .def("schema", &Graph::schema, py::arg("type_or_node"), "The schema of a node type, or of a node's type.")
        .def_property_readonly("nodes", &Graph::nodes)
        .def_property_readonly("outputs", &Graph::outputs)
        .def_property_readonly("document", &Graph::document)
        .def_property_readonly("file", &Graph::file)
        .def_property_readonly("device", &Graph::device);

    m.def("compare", &compare, py::arg("a"), py::arg("b"), py::arg("reference") = py::none(), py::kw_only(),
          py::arg("out") = py::none(), py::arg("set") = py::none(), py::arg("frame") = py::none(),
          py::arg("frames") = py::none(), py::arg("output") = py::none(), py::arg("hdr") = false,
          py::arg("ppd") = py::none(), py::arg("noise_floor") = true, py::arg("force") = false,
          py::arg("device") = std::shared_ptr<Device>(),
          "`vitrine compare A B [--reference R]`: A, B, R are graph or image paths or float32 arrays; returns the "
          "dict of metrics.json. out=DIR keeps the images, heat maps and report.html there.");
    m.def(
        "set_log_level",
        [](const std::string& level) {
            auto it = kLevels.find(level);
            if (it == kLevels.end())
                throw UserError("vitrine.set_log_level('" + level + "'): expected debug, info, warning or error");
            setLogLevel(it->second);
        },
        py::arg("level"), "What vitrine writes to stderr: 'debug', 'info', 'warning' (the default) or 'error'.");
    m.def("read_exr", &readExr, py::arg("path"), "The layers of an EXR file as float32 (height, width, 4) arrays.");

    // The default device goes before the interpreter does (its executors before the Vulkan instance).
    py::module_::import("atexit").attr("register")(py::cpp_function([] { vitrine::python::gDefaultDevice.reset(); }));
}

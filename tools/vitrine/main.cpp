// vitrine: run, validate, inspect and benchmark render graphs headless.
#include "core/base/error.hpp"
#include "core/base/heap.hpp"
#include "core/base/log.hpp"
#include "tools/vitrine/cli.hpp"
#include "tools/vitrine/interrupt.hpp"
#include "tools/vitrine/version.hpp"

#include <cstdio>
#include <exception>
#include <set>
#include <string_view>

namespace {

const char* kUsage = R"(usage: vitrine COMMAND [options]

commands:
  run GRAPH [--set K=V]... [--out DIR] [--frames N] [--exr half|float|none] [--overwrite]
      Render GRAPH headless; writes each output of the chosen frames as PNG (through the
      OCIO display transform) and all outputs of a frame as one multi-layer EXR. --frames N is
      frame.frames (and frame.write = [N-1]) before validation; later --set frame.* override it.
      --scene FILE (run, bench, compare): the graph's scene node becomes scene.gltf of FILE, e.g.
      `vitrine run graphs/gltf.json --scene model.glb` (output in out/model/; a scene.gltf
      node's key_light params are kept). The glTF loader's warnings
      (what vitrine ignores: unsupported extensions in extensionsUsed, skins, ...) go to stderr once each;
      --strict (run, bench, compare, validate, export-scene): they are errors (exit 1); without --scene it sets the
      param strict of every scene.gltf node of the graph.
  validate GRAPH [--set K=V]...     Load and compile GRAPH without rendering.
  nodes [--json [FILE]]             List node types with their ports and params; --json: the schemas as
                                    JSON on stdout (or in FILE).
  schema [--out FILE]               The graph format as a JSON Schema (draft 2020-12) generated from the
                                    node types, on stdout (or in FILE); graphs name it with "$schema".
  bench GRAPH [--frames N] [--warmup N] [--json FILE] [--set K=V]... [--bvh]
      Per-node GPU ms (median of timestamp queries), CPU record ms, compile ms, memory.
      --bvh: also the scene's ray-tracing BVH: build ms, nodes, memory, bake-cache load ms,
      and rays/s of primary (one per pixel) and incoherent (bounce) rays.
  graph GRAPH --dot                 The compiled graph (passes, resources, lifetimes) as Graphviz.
  compare A B [--reference R [--reference-half H | --no-noise-floor]] [--frame N | --frames A:B] [--regions F]
          [--set K=V]... [--output NAME] [--output-a NAME] [--output-b NAME] [--output-reference NAME]
          [--out DIR] [--force] [--hdr] [--ppd X] [--diff-scale S] [--no-summary]
      A, B, R: graphs (variants too) or images (EXR/PNG), same size. --output NAME: the graphs' output
      compared (default "final"), or that layer of an EXR; --output-a/-b/-reference NAME: that side's (e.g.
      one term of the frame, terms/specular_indirect, against its ray-traced twin's). Writes the images, |A-B|,
      FLIP error maps, metrics.json (PSNR, SSIM, FLIP; flicker and error per frame with
      --frames) and a self-contained report.html to DIR (default out/compare/A_vs_B).
      Files vitrine did not write there are not replaced without --force.
      With R also the noise floor: FLIP between R and a second half of it (R's graph with every
      render.pathtrace seed + 1, or --reference-half FILE); pairs within 1.5x of it are marked "within
      reference noise". --no-noise-floor: no second half. Every pair also gets the luminance ratio of
      16 px blocks (share within 15 %, mean |log2|) and its heat map (blocks_*.png). --regions F: the
      mean luminance ratio of each named region of F (e.g. graphs/regions/museum.regions.json) per pair,
      and regions.png showing them.
      --no-summary: print nothing on stdout (metrics.json has it all).
  golden check|accept [NAME]... [--out DIR] [--manifest FILE] [--set K=V]... [--from DIR]
      Image regression of tests/golden/manifest.json on this device class (lavapipe|gpu):
      `accept` (re)writes the golden EXRs, `check` compares with FLIP, per-pixel and block
      luminance tolerances and writes a heat map and report.html per failure into DIR
      (default golden-report). Exit 3: failed. --from DIR: compare DIR/NAME.exr (renders kept
      from another machine or code generation) instead of rendering; --keep DIR: also write each
      render to DIR/NAME.exr; --goldens DIR: the goldens from DIR; --class NAME: that class's
      tolerances (e.g. lavapipe-codegen).
      --skip-missing: exit 77 (skipped) when this device class has no goldens yet.
  export-scene museum|FILE OUT.glb [--seed N] [--texture-size N] [--force] [--strict]
      Write the procedural museum (or re-write a glTF file) as glTF binary for other tools.
  jitter [PATTERN]... [--out DIR] [--frames N]
      Plot the camera jitter patterns (halton, ordered, rotated, improved, stratified) as SVG:
      the first 16 samples numbered in order, later frames (sub-grid shifts) as dots.
  serve [DIR] [--port N] [--host ADDR] [--token T | --no-token] [--editor DIR] [--max-body BYTES] [--warm N]
        [--max-queue N]
      HTTP server for the graph editor: the editor at /, a JSON API under /api/ (nodes, graphs under DIR,
      validate, render previews, compare, progress events). One Vulkan device and the last N (--warm,
      default 4) compiled graphs stay warm between requests. Binds 127.0.0.1:8420 by default (--port 0: any
      free port; the URL is printed, with the access token every request needs: ?token=..., then a cookie;
      --token T picks it, --no-token drops it on the loopback). Answers only to the loopback names (or
      --host) and the server's own page (Host, Origin). Reads files under DIR only (default: the current
      directory) and writes only graph and variant .json files there (NAME.json.bak keeps what a PUT replaced).
      At most N GPU jobs wait (--max-queue, default 16); past that a render gets 503 with Retry-After.
  sweep FILE [--out DIR] [--jobs N] [--retry-failed] [--devices 0,1] [--list]
      Quality-versus-cost study (README "Sweeps"): every point of the vitrine-sweep/1 FILE (axes of --set
      values, variant files, frame ranges) rendered as its own process, --jobs at once, compared with the
      sweep's reference (FLIP, SSIM, PSNR as `compare`), timed per node (as `bench`); results in
      DIR/points/<id>/ (default out/sweep/<FILE's stem>), DIR/sweep.json, sweep.csv and report.html.
      Resumable: done points are skipped, failed ones too unless --retry-failed. Exit 3: some point failed.
      --point ID|INDEX: run one point in this process (what the driver and Slurm array tasks run).
  sweep FILE --slurm [--out DIR] [--partition P] [--time T] [--gpus-per-task N] [--sbatch-arg ARG]...
        [--retry-failed] [--no-wait]
      The same sweep as a Slurm job array (README "Sweeps on a Slurm cluster"): a reference job, one array task
      per point still to do (this vitrine binary, DIR on a folder every node sees), and a dependent job running
      --collect; squeue state shown while waiting. Options also from the sweep file's "slurm" block.
  sweep --collect DIR               Gather DIR/points/*/metrics.json into sweep.json, sweep.csv, report.html.
  cache ls                          The bake cache (BVHs, lightmaps, probes, ...): kind, size, age, total.
  cache rm NAME...|--all            Remove entries by the names `cache ls` prints (or a whole KIND); only
                                    files inside the bake cache folder. Cache folder: $VITRINE_CACHE_DIR,
                                    else $XDG_CACHE_HOME/vitrine, else ~/.cache/vitrine.
  devices                           List Vulkan devices.
  --version                         The version and the git commit vitrine was built from.

common options:
  --device INDEX|NAME   Vulkan device (default: best discrete GPU, else lavapipe)
  --validate            Enable Vulkan validation layers
  --quiet / --verbose   Less / more output on stderr

exit status: 0 done, 1 the input is wrong (message on stderr), 2 internal failure (or Vulkan
validation messages with --validate), 3 `golden check` found images beyond tolerance, 130 `run`
stopped by Ctrl-C / SIGTERM after finishing (and writing) the frame it was rendering.
)";

} // namespace

int main(int argc, char** argv) {
    using namespace vitrine;
    if (argc == 2 && (std::string_view(argv[1]) == "--version" || std::string_view(argv[1]) == "version")) {
        std::printf("vitrine %s (commit %s)\n", versionNumber(), versionCommit());
        return 0;
    }
    try {
        cli::Args args = cli::parse(argc, argv,
                                    {"set", "out", "frames", "device", "json", "warmup", "exr", "reference", "frame",
                                     "output", "output-a", "output-b", "output-reference", "ppd", "diff-scale", "reference-half", "regions", "manifest", "seed", "texture-size", "scene", "port", "host", "token", "editor", "max-body", "warm", "max-queue",
                                     "jobs", "point", "collect", "devices", "from", "keep", "goldens", "class",
                                     "partition", "time", "gpus-per-task", "sbatch-arg"},
                                    {{"nodes", {"json"}}});
        if (args.has("quiet")) setLogLevel(LogLevel::Warning);
        if (args.has("verbose")) setLogLevel(LogLevel::Debug);
        // Short runs keep freed memory and take huge pages (core/base/heap.hpp); the editor's long-lived server keeps
        // glibc's defaults, which give memory back between requests.
        if (args.command != "serve") {
            const HeapPolicy heap = tuneHeapForLargeBlocks();
            if (!heap.note.empty())
                logDebug("heap: " + heap.note);
            else
                logDebug("heap: freed memory kept, " + std::to_string(heap.reserved >> 20) +
                         " MiB reserved with huge pages");
        }
        if (args.command.empty() || args.command == "help" || args.has("help")) {
            std::fputs(kUsage, args.command.empty() ? stderr : stdout);
            return args.command.empty() ? 1 : 0;
        }
        if (args.command == "run") return cli::runCommand(args);
        if (args.command == "validate") return cli::validateCommand(args);
        if (args.command == "nodes") return cli::nodesCommand(args);
        if (args.command == "schema") return cli::schemaCommand(args);
        if (args.command == "bench") return cli::benchCommand(args);
        if (args.command == "graph") return cli::graphCommand(args);
        if (args.command == "devices") return cli::devicesCommand(args);
        if (args.command == "compare") {
            // Ctrl-C stops the render in progress (compareCommand then compares nothing). Only the command line
            // installs the handlers: the Python module, which calls compareCommand too, keeps Python's own.
            cli::InterruptHandlers interrupts;
            return cli::compareCommand(args);
        }
        if (args.command == "golden") return cli::goldenCommand(args);
        if (args.command == "export-scene") return cli::exportSceneCommand(args);
        if (args.command == "jitter") return cli::jitterCommand(args);
        if (args.command == "serve") return cli::serveCommand(args);
        if (args.command == "sweep") return cli::sweepCommand(args);
        if (args.command == "cache") return cli::cacheCommand(args);
        throw UserError("unknown command '" + args.command + "'; run `vitrine help`");
    } catch (const UserError& e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "internal error: %s\n", e.what());
        return 2;
    }
}

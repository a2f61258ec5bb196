#!/usr/bin/env python3
"""ctest gltf.validator: every glTF file vitrine writes passes the Khronos glTF-Validator with no cap on messages.

Exports `vitrine export-scene museum` (64-texel textures: the JSON is the same at any size), the showcase model and the
round trip (load, export) of every file in tests/data/gltf/corpus/ and tests/data/gltf/viewer/, of two of the latter
compressed by gltfpack -cc (EXT_meshopt_compression, KHR_mesh_quantization) and of quad.gltf and layered.gltf, then runs tools/gltf-validator/validate.mjs (npm gltf-validator, pinned by its package-lock.json,
installed by tools/install-deps.sh) on them and on those test files themselves with maxIssues 0. Fails on any error or
warning, and when the validator is not installed (never skipped). Infos are printed and counted, not failed: the
lightmap UVs (TEXCOORD_1) and the textures that only VITRINE_material_layers samples are used by vitrine, which the
validator cannot know.
Usage: check_validator.py VITRINE SOURCE_DIR OUT_DIR
"""
import glob
import os
import re
import shutil
import subprocess
import sys


def main():
    vitrine, src, out = sys.argv[1:4]
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    validator = os.path.join(src, "tools", "gltf-validator")
    if not os.path.isdir(os.path.join(validator, "node_modules", "gltf-validator")):
        sys.exit("gltf.validator: tools/gltf-validator/node_modules/gltf-validator is missing; run tools/install-deps.sh")
    corpus = sorted(glob.glob(os.path.join(src, "tests", "data", "gltf", "corpus", "*.gltf")))
    if not corpus:
        sys.exit("gltf.validator: no files in tests/data/gltf/corpus/")
    # ctest gltf.sample_viewer's files (tests/viewer/make_scenes.py), validated and round-tripped as the corpus is.
    viewer_files = sorted(glob.glob(os.path.join(src, "tests", "data", "gltf", "viewer", "*.gltf")))
    if not viewer_files:
        sys.exit("gltf.validator: no files in tests/data/gltf/viewer/")
    corpus += viewer_files
    # EXT_meshopt_compression files made by an independent encoder (Debian's gltfpack, installed by
    # tools/install-deps.sh), quantized and compressed with filters: validated, and loaded for the round trip.
    for f in [os.path.join(src, "tests", "data", "gltf", "viewer", n) for n in ("white_sphere.gltf", "metal_spheres.gltf")]:
        packed = os.path.join(out, "gltfpack_" + os.path.basename(f))
        r = subprocess.run(["gltfpack", "-i", f, "-o", packed, "-cc"], capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"gltf.validator: gltfpack on {f} failed ({r.returncode}; installed by tools/install-deps.sh):\n"
                     f"{r.stdout}{r.stderr}")
        corpus.append(packed)
    sources = [("museum", "museum"), (os.path.join(src, "data", "models", "showcase.gltf"), "showcase")]
    sources += [(os.path.join(src, "tests", "data", "gltf", n + ".gltf"), n) for n in ("quad", "layered")]
    sources += [(f, "corpus_" + os.path.splitext(os.path.basename(f))[0]) for f in corpus]
    written = []
    for source, name in sources:
        glb = os.path.join(out, name + ".glb")
        cmd = [vitrine, "export-scene", source, glb] + (["--texture-size", "64"] if source == "museum" else [])
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"gltf.validator: {' '.join(cmd)} failed ({r.returncode}):\n{r.stdout}{r.stderr}")
        written.append(glb)
    r = subprocess.run(["node", os.path.join(validator, "validate.mjs")] + corpus + written, capture_output=True,
                       text=True)
    print(r.stdout, end="")
    print(r.stderr, end="", file=sys.stderr)
    summaries = re.findall(r"^(\S+): (\d+) errors, (\d+) warnings, (\d+) infos", r.stdout, re.M)
    if len(summaries) != len(corpus) + len(written):
        sys.exit(f"gltf.validator: expected {len(corpus) + len(written)} summaries, got {len(summaries)}")
    bad = [s for s in summaries if s[1] != "0" or s[2] != "0"]
    if r.returncode != 0 or bad:
        sys.exit("gltf.validator: errors or warnings in: " + ", ".join(s[0] for s in bad))
    print(f"gltf.validator: {len(summaries)} files, 0 errors, 0 warnings")


main()

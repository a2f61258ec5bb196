"""ctest python.example: examples/fxaa_subpix_sweep.py runs at a tiny size and writes its plot;
examples/nested_volumes_scene.py writes a scene that `vitrine run --strict` path-traces (every volume closed, so no
warning). Neither replaces an existing file without --force. Environment as tests/python/test_vitrine.py."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np

SRC = Path(os.environ.get("VITRINE_SOURCE", Path(__file__).resolve().parents[2]))
EXAMPLE = SRC / "examples" / "fxaa_subpix_sweep.py"


def run(*args):
    return subprocess.run([sys.executable, str(EXAMPLE), *map(str, args)], capture_output=True, text=True)


def test_sweep_example_writes_png(tmp_path):
    out = tmp_path / "sweep.png"
    proc = run("--size", "32x18", "--steps", "3", "--out", out)
    assert proc.returncode == 0, proc.stderr
    lines = [l for l in proc.stdout.splitlines() if l.startswith("subpix")]
    assert [l.split(":")[0] for l in lines] == ["subpix 0.00", "subpix 0.50", "subpix 1.00"], proc.stdout
    # Every point has a finite FLIP in (0, 1): FXAA never makes the plate equal the supersampled one.
    flips = [float(l.split("FLIP mean ")[1].split(",")[0]) for l in lines]
    assert all(0.0 < f < 1.0 for f in flips), flips
    import matplotlib.image
    image = matplotlib.image.imread(str(out))
    assert image.ndim == 3 and image.shape[0] > 100 and image.shape[1] > 100
    assert np.ptp(image[..., :3]) > 0.5  # a plot, not a blank page

    before = out.read_bytes()
    proc = run("--size", "32x18", "--steps", "2", "--out", out)
    assert proc.returncode != 0 and "--force" in proc.stderr
    assert out.read_bytes() == before


def test_nested_volumes_scene_traces_without_warnings(tmp_path):
    script = SRC / "examples" / "nested_volumes_scene.py"
    scene = tmp_path / "nested.gltf"
    proc = subprocess.run([sys.executable, str(script), str(scene)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    vitrine = os.environ.get("VITRINE_BIN", str(SRC / "build" / "vitrine"))
    out = tmp_path / "out"
    proc = subprocess.run([vitrine, "run", str(SRC / "graphs" / "variants" / "gltf_reference.json"), "--scene",
                           str(scene), "--strict", "--set", "frame.width=16", "--set", "frame.height=16", "--set",
                           "pathtrace.params.target_noise=0", "--set", "pathtrace.params.spp=2", "--out", str(out)],
                          capture_output=True, text=True, cwd=SRC)
    assert proc.returncode == 0, proc.stderr
    assert "warning" not in proc.stderr, proc.stderr
    assert (out / "final.png").stat().st_size > 0

    before = scene.read_bytes()
    proc = subprocess.run([sys.executable, str(script), str(scene)], capture_output=True, text=True)
    assert proc.returncode != 0 and "--force" in proc.stderr
    assert scene.read_bytes() == before

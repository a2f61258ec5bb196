#!/usr/bin/env python3
"""A parameter sweep from Python: FXAA's `subpix` on the zone plate against the 16x16-supersampled plate.

One graph object is edited and re-run per value (the device, shaders and pipelines stay warm between runs); every
render is compared with the reference by vitrine.compare (the metrics of `vitrine compare`'s metrics.json), and the
result is plotted with matplotlib: FLIP and PSNR against subpix, FXAA's GPU time, and the renders at both ends.

    PYTHONPATH=build/python python3 examples/fxaa_subpix_sweep.py --out out/fxaa_subpix_sweep.png

--size WxH picks the frame size (default 320x180); --steps N the number of subpix values in [0, 1]. The PNG is not
replaced when it exists unless --force is given.
"""

import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt
import numpy as np

import vitrine

ROOT = Path(__file__).resolve().parent.parent


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/fxaa_subpix_sweep.png", help="the plot (PNG)")
    parser.add_argument("--size", default="320x180", help="frame size WxH")
    parser.add_argument("--steps", type=int, default=5, help="subpix values in [0, 1]")
    parser.add_argument("--device", default="", help="Vulkan device, as --device (index or part of the name)")
    parser.add_argument("--force", action="store_true", help="replace --out when it exists")
    args = parser.parse_args()

    out = Path(args.out)
    if out.exists() and not args.force:
        sys.exit(f"{out} exists; pass --force to replace it")
    try:
        width, height = (int(v) for v in args.size.lower().split("x"))
    except ValueError:
        sys.exit(f"--size: expected WxH, e.g. 320x180, got '{args.size}'")
    if args.steps < 2:
        sys.exit("--steps: expected at least 2")
    size = {"frame.width": width, "frame.height": height}

    device = vitrine.Device(args.device)
    reference = vitrine.Graph.load(ROOT / "graphs/variants/supersampled.json", set=size, device=device).run()["final"]
    graph = vitrine.Graph.load(ROOT / "graphs/fxaa_zoneplate.json", set=size, device=device)

    values = np.linspace(0.0, 1.0, args.steps)
    flip, psnr, gpu_ms, shown = [], [], [], []
    for subpix in values:
        graph.set({"fxaa.params.subpix": float(subpix)})
        result = graph.run(frames=1)
        pair = vitrine.compare(result["final"], reference)["pairs"][0]
        flip.append(pair["flip"]["mean"])
        psnr.append(pair["psnr"])
        gpu_ms.append(result.timings["fxaa"])
        shown.append(result.display("final"))
        print(f"subpix {subpix:.2f}: FLIP mean {flip[-1]:.4f}, PSNR {psnr[-1]:.2f} dB, fxaa {gpu_ms[-1]:.3f} ms")

    fig, axes = plt.subplots(2, 2, figsize=(10, 7))
    axes[0, 0].plot(values, flip, "o-")
    axes[0, 0].set(xlabel="fxaa.params.subpix", ylabel="FLIP mean vs supersampled (lower is better)")
    axes[0, 1].plot(values, psnr, "o-", color="tab:orange")
    axes[0, 1].set(xlabel="fxaa.params.subpix", ylabel="PSNR vs supersampled (dB)")
    axes[1, 0].imshow(np.concatenate([shown[0], shown[-1]], axis=1))
    axes[1, 0].set_title(f"subpix {values[0]:.2f} | {values[-1]:.2f}")
    axes[1, 0].axis("off")
    axes[1, 1].bar([f"{v:.2f}" for v in values], gpu_ms, color="tab:green")
    axes[1, 1].set(xlabel="fxaa.params.subpix", ylabel=f"fxaa GPU ms ({device.name})")
    fig.suptitle(f"FXAA subpix sweep, zone plate {width}x{height}")
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=80)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Writes a small glTF scene of nested KHR_materials_volume media for render.pathtrace (README "Nested volumes"):
a clear glass ball (IOR 1.5) on a checkered floor, holding a ball of blue water (IOR 1.33) and a small air bubble
(IOR 1), with its own camera. Python standard library only.

    python3 examples/nested_volumes_scene.py nested_volumes.gltf
    ./build/vitrine run graphs/variants/gltf_reference.json --scene nested_volumes.gltf \\
        --set frame.width=256 --set frame.height=256 --set pathtrace.params.target_noise=0 \\
        --set pathtrace.params.spp=128 --out out/nested

An existing file is not replaced unless --force is given."""
import argparse
import base64
import json
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))
from make_showcase_gltf import Builder, sphere  # noqa: E402  (the showcase's glTF writer and UV sphere)


def checkers(parity, size=0.5, count=8):
    """The floor's squares of one colour (parity 0 or 1), facing +y."""
    positions, normals, indices = [], [], []
    for i in range(-count, count):
        for k in range(-count, count):
            if (i + k) % 2 != parity:
                continue
            x0, z0, x1, z1 = i * size, k * size, (i + 1) * size, (k + 1) * size
            base = len(positions)
            positions += [(x0, 0.0, z0), (x1, 0.0, z0), (x1, 0.0, z1), (x0, 0.0, z1)]
            normals += [(0.0, 1.0, 0.0)] * 4
            indices += [base, base + 2, base + 1, base, base + 3, base + 2]
    return positions, normals, indices


def glass(name, ior, attenuation=None):
    volume = {"thicknessFactor": 0.5}
    if attenuation:
        volume.update({"attenuationColor": attenuation[0], "attenuationDistance": attenuation[1]})
    return {"name": name,
            "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 0},
            "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1}, "KHR_materials_ior": {"ior": ior},
                           "KHR_materials_volume": volume}}


def scene():
    b = Builder()
    dark = b.material({"name": "dark", "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.1, 0.12, 1],
                                                                "metallicFactor": 0, "roughnessFactor": 0.8}})
    light = b.material({"name": "light", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.7, 0.5, 1],
                                                                  "metallicFactor": 0, "roughnessFactor": 0.8}})
    meshes = [b.mesh("floor_dark", *checkers(0), dark), b.mesh("floor_light", *checkers(1), light),
              b.mesh("glass", *sphere(1.0), b.material(glass("glass", 1.5, ([0.95, 0.95, 0.85], 2.0)))),
              b.mesh("water", *sphere(0.6), b.material(glass("water", 1.33, ([0.3, 0.6, 0.95], 0.5)))),
              b.mesh("bubble", *sphere(0.15, 24, 12), b.material(glass("air", 1.0)))]
    # The water and the bubble lie inside the glass ball (centre y = 1, radius 1) and apart from each other.
    where = [None, None, [0, 1.0, 0], [0.25, 1.0, 0], [-0.6, 1.3, 0.3]]
    roots = [b.node({"mesh": m, **({"translation": t} if t else {})}) for m, t in zip(meshes, where)]
    roots.append(b.node({"camera": 0, "translation": [0, 1.6, 4.2], "rotation": [-0.0998, 0, 0, 0.995]}))
    return {"asset": {"version": "2.0", "generator": "vitrine examples/nested_volumes_scene.py"},
            "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"],
            "scene": 0, "scenes": [{"nodes": roots}], "nodes": b.nodes, "meshes": b.meshes,
            "materials": b.materials,
            "cameras": [{"type": "perspective",
                         "perspective": {"yfov": 0.6, "aspectRatio": 1.0, "znear": 0.05, "zfar": 100}}],
            "buffers": [{"byteLength": len(b.bin),
                         "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(b.bin)).decode()}],
            "bufferViews": b.views, "accessors": b.accessors}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", help="the .gltf file to write")
    parser.add_argument("--force", action="store_true", help="replace the file if it exists")
    args = parser.parse_args()
    if os.path.exists(args.out) and not args.force:
        sys.exit(f"nested_volumes_scene.py: {args.out} exists; pass --force to replace it")
    with open(args.out, "w") as f:
        json.dump(scene(), f)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()

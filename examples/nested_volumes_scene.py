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
import math
import os
import struct
import sys


def sphere(radius, segments=48, rings=24):
    """A UV sphere: positions, unit normals and counter-clockwise triangles seen from outside."""
    positions, normals, indices = [], [], []
    for j in range(rings + 1):
        theta = math.pi * j / rings
        for i in range(segments + 1):
            phi = 2.0 * math.pi * i / segments
            n = (math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi))
            positions.append(tuple(radius * c for c in n))
            normals.append(n)
    for j in range(rings):
        for i in range(segments):
            a = j * (segments + 1) + i
            b = a + segments + 1
            indices += [a, a + 1, b, a + 1, b + 1, b]
    return positions, normals, indices


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
    parts = [("floor_dark", checkers(0), 0), ("floor_light", checkers(1), 1), ("glass", sphere(1.0), 2),
             ("water", sphere(0.6), 3), ("bubble", sphere(0.15, 24, 12), 4)]
    data, views, accessors, meshes = b"", [], [], []
    for name, (positions, normals, indices), material in parts:
        attributes = {}
        for semantic, values in (("POSITION", positions), ("NORMAL", normals)):
            raw = b"".join(struct.pack("<3f", *v) for v in values)
            views.append({"buffer": 0, "byteOffset": len(data), "byteLength": len(raw)})
            data += raw
            accessor = {"bufferView": len(views) - 1, "componentType": 5126, "count": len(values), "type": "VEC3"}
            if semantic == "POSITION":
                accessor["min"] = [min(v[c] for v in values) for c in range(3)]
                accessor["max"] = [max(v[c] for v in values) for c in range(3)]
            accessors.append(accessor)
            attributes[semantic] = len(accessors) - 1
        raw = b"".join(struct.pack("<I", i) for i in indices)
        views.append({"buffer": 0, "byteOffset": len(data), "byteLength": len(raw)})
        data += raw
        accessors.append({"bufferView": len(views) - 1, "componentType": 5125, "count": len(indices), "type": "SCALAR"})
        meshes.append({"name": name, "primitives": [{"attributes": attributes, "indices": len(accessors) - 1,
                                                     "material": material}]})
    materials = [
        {"name": "dark", "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.1, 0.12, 1], "metallicFactor": 0,
                                                  "roughnessFactor": 0.8}},
        {"name": "light", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.7, 0.5, 1], "metallicFactor": 0,
                                                   "roughnessFactor": 0.8}},
        glass("glass", 1.5, ([0.95, 0.95, 0.85], 2.0)),
        glass("water", 1.33, ([0.3, 0.6, 0.95], 0.5)),
        glass("air", 1.0),
    ]
    # The water and the bubble lie inside the glass ball (centre y = 1, radius 1) and apart from each other.
    nodes = [{"mesh": 0}, {"mesh": 1}, {"mesh": 2, "translation": [0, 1.0, 0]},
             {"mesh": 3, "translation": [0.25, 1.0, 0]}, {"mesh": 4, "translation": [-0.6, 1.3, 0.3]},
             {"camera": 0, "translation": [0, 1.6, 4.2], "rotation": [-0.0998, 0, 0, 0.995]}]
    return {"asset": {"version": "2.0", "generator": "vitrine examples/nested_volumes_scene.py"},
            "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"],
            "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes, "meshes": meshes,
            "materials": materials,
            "cameras": [{"type": "perspective",
                         "perspective": {"yfov": 0.6, "aspectRatio": 1.0, "znear": 0.05, "zfar": 100}}],
            "buffers": [{"byteLength": len(data),
                         "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
            "bufferViews": views, "accessors": accessors}


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

#!/usr/bin/env python3
"""Writes data/models/showcase.gltf, the default model of graphs/gltf.json: a copper sphere on a plinth under a
glass case (KHR_materials_transmission + KHR_materials_ior, alpha BLEND as the fallback for viewers without them),
a blue half-transparent disc, an unlit label (KHR_materials_unlit), a point light (KHR_lights_punctual) and a
floor; no camera (scene.gltf frames it). Plain glTF 2.0 with one embedded base64 buffer, so any viewer opens it.

    python3 tools/make_showcase_gltf.py [OUT]
"""
import base64
import json
import math
import struct
import sys


class Builder:
    def __init__(self):
        self.bin = bytearray()
        self.views, self.accessors, self.meshes, self.nodes, self.materials = [], [], [], [], []

    def accessor(self, data, fmt, count, kind, component, target, minmax=None):
        while len(self.bin) % 4:
            self.bin.append(0)
        offset = len(self.bin)
        self.bin += struct.pack("<" + fmt * (len(data)), *data)
        self.views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(self.bin) - offset, "target": target})
        a = {"bufferView": len(self.views) - 1, "componentType": component, "count": count, "type": kind}
        if minmax:
            a["min"], a["max"] = minmax
        self.accessors.append(a)
        return len(self.accessors) - 1

    def mesh(self, name, positions, normals, indices, material):
        flat = [c for p in positions for c in p]
        lo = [min(p[i] for p in positions) for i in range(3)]
        hi = [max(p[i] for p in positions) for i in range(3)]
        pa = self.accessor(flat, "f", len(positions), "VEC3", 5126, 34962, (lo, hi))
        na = self.accessor([c for n in normals for c in n], "f", len(normals), "VEC3", 5126, 34962)
        ia = self.accessor(indices, "I", len(indices), "SCALAR", 5125, 34963)
        self.meshes.append({"name": name, "primitives": [
            {"attributes": {"POSITION": pa, "NORMAL": na}, "indices": ia, "material": material}]})
        return len(self.meshes) - 1

    def material(self, m):
        self.materials.append(m)
        return len(self.materials) - 1

    def node(self, n):
        self.nodes.append(n)
        return len(self.nodes) - 1


def box(hx, hy, hz):
    pos, nor, idx = [], [], []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            n = [0.0, 0.0, 0.0]
            n[axis] = sign
            u, v = (axis + 1) % 3, (axis + 2) % 3
            h = [hx, hy, hz]
            base = len(pos)
            for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = [0.0, 0.0, 0.0]
                p[axis] = sign * h[axis]
                p[u] = su * h[u]
                p[v] = sv * h[v]
                pos.append(p)
                nor.append(n)
            quad = [base, base + 1, base + 2, base, base + 2, base + 3]
            if sign < 0:  # counter-clockwise seen from outside
                quad = [base, base + 2, base + 1, base, base + 3, base + 2]
            idx += quad
    return pos, nor, idx


def sphere(r, seg=48, rings=24):
    pos, nor, idx = [], [], []
    for i in range(rings + 1):
        th = math.pi * i / rings
        for j in range(seg + 1):
            ph = 2 * math.pi * j / seg
            n = [math.sin(th) * math.cos(ph), math.cos(th), -math.sin(th) * math.sin(ph)]
            pos.append([r * c for c in n])
            nor.append(n)
    for i in range(rings):
        for j in range(seg):
            a, b = i * (seg + 1) + j, (i + 1) * (seg + 1) + j
            if i > 0:
                idx += [a, b, a + 1]
            if i < rings - 1:
                idx += [a + 1, b, b + 1]
    return pos, nor, idx


def disc(r, seg=48):
    pos, nor, idx = [[0.0, 0.0, 0.0]], [[0.0, 0.0, 1.0]], []
    for j in range(seg + 1):
        ph = 2 * math.pi * j / seg
        pos.append([r * math.cos(ph), r * math.sin(ph), 0.0])
        nor.append([0.0, 0.0, 1.0])
    for j in range(seg):
        idx += [0, j + 1, j + 2]
    return pos, nor, idx


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "data/models/showcase.gltf"
    b = Builder()
    floor = b.material({"name": "floor", "pbrMetallicRoughness": {
        "baseColorFactor": [0.45, 0.42, 0.38, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.8}})
    plinth = b.material({"name": "plinth", "pbrMetallicRoughness": {
        "baseColorFactor": [0.8, 0.78, 0.74, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.6}})
    copper = b.material({"name": "copper", "pbrMetallicRoughness": {
        "baseColorFactor": [0.95, 0.64, 0.54, 1.0], "metallicFactor": 1.0, "roughnessFactor": 0.25}})
    glass = b.material({"name": "glass", "alphaMode": "BLEND", "doubleSided": True,
                        "pbrMetallicRoughness": {"baseColorFactor": [0.92, 0.97, 0.95, 0.25], "metallicFactor": 0.0,
                                                 "roughnessFactor": 0.05},
                        "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                                       "KHR_materials_ior": {"ior": 1.5}}})
    tinted = b.material({"name": "blue film", "alphaMode": "BLEND", "doubleSided": True,
                         "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.3, 0.9, 0.5], "metallicFactor": 0.0,
                                                  "roughnessFactor": 0.4}})
    label = b.material({"name": "label", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.75, 0.2, 1.0]},
                        "extensions": {"KHR_materials_unlit": {}}})

    meshes = {
        "floor": b.mesh("floor", *box(1.1, 0.02, 1.1), floor),
        "plinth": b.mesh("plinth", *box(0.3, 0.4, 0.3), plinth),
        "sphere": b.mesh("sphere", *sphere(0.18), copper),
        "case": b.mesh("case", *box(0.29, 0.26, 0.29), glass),
        "disc": b.mesh("disc", *disc(0.3), tinted),
        "label": b.mesh("label", *box(0.2, 0.05, 0.005), label),
    }
    roots = [
        b.node({"name": "floor", "mesh": meshes["floor"], "translation": [0.0, -0.02, 0.0]}),
        b.node({"name": "plinth", "mesh": meshes["plinth"], "translation": [0.0, 0.4, 0.0]}),
        b.node({"name": "sphere", "mesh": meshes["sphere"], "translation": [0.0, 0.98, 0.0]}),
        b.node({"name": "case", "mesh": meshes["case"], "translation": [0.0, 1.06, 0.0]}),
        b.node({"name": "disc", "mesh": meshes["disc"], "translation": [0.75, 0.5, 0.3],
                "rotation": [0.0, -0.3826834, 0.0, 0.9238795]}),
        b.node({"name": "label", "mesh": meshes["label"], "translation": [0.0, 0.6, 0.31]}),
        b.node({"name": "lamp", "translation": [-0.6, 1.6, 0.8],
                "extensions": {"KHR_lights_punctual": {"light": 0}}}),
    ]
    doc = {
        "asset": {"version": "2.0", "generator": "vitrine tools/make_showcase_gltf.py"},
        "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_unlit",
                           "KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"name": "lamp", "type": "point", "color": [1.0, 0.85, 0.7], "intensity": 40000.0, "range": 10.0}]}},
        "scene": 0,
        "scenes": [{"name": "showcase", "nodes": roots}],
        "nodes": b.nodes,
        "meshes": b.meshes,
        "materials": b.materials,
        "accessors": b.accessors,
        "bufferViews": b.views,
        "buffers": [{"byteLength": len(b.bin),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(b.bin)).decode()}],
    }
    with open(out, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Writes the small glTF 2.0 test corpus next to this script (python3 standard library only; deterministic).

Each file is self-contained (buffers as base64 data: URIs), legal per the Khronos glTF-Validator (ctest gltf.validator
checks 0 errors and 0 warnings) and built so that a test can check a pixel or a vertex against a number worked out by
hand, written in the file's asset.extras.expect:
  camera_aspect.gltf   a perspective camera with aspectRatio 1.5 (yfov 0.8) looking down -Z at a small unlit marker
                       quad centred on view-space point P; tests/gpu/gltf_corpus_test.cpp renders it in a square
                       frame and finds the marker where the unstretched projection puts P.
  camera_ortho.gltf    the same with an orthographic camera (xmag 2, ymag 1).
  animation.gltf       node 0: translation LINEAR, rotation LINEAR (slerp), scale STEP; node 1: translation and
                       rotation CUBICSPLINE with non-zero tangents; tests/unit/scene/test_gltf_corpus.cpp samples them
                       between keys against the glTF 2.0 specification's formulas (Appendix C).
  morph_cube.gltf      a cube whose morph target moves its +X face 1 unit, at default weight 0.5; the rendered
                       silhouette (tests/gpu/gltf_corpus_test.cpp) and the loaded vertices sit half a unit out.
  morph_animated.gltf  the same at weight 0 with a LINEAR weights animation 0 -> 1 over 2 s: half a unit at t = 1.
  quantized.gltf       KHR_mesh_quantization: integer positions, normalised byte normals and short UVs
                       (tests/unit/scene/test_gltf_corpus.cpp checks the loaded vertices).
  skin_bend.gltf       a two-bone bend (joint 1 rotates 0 -> 90° about Z over 1 s) against CPU-skinned vertices
                       (unit test) and the rendered silhouette (GPU test).
Regenerate after editing: python3 tests/data/gltf/corpus/make_corpus.py
"""
import base64
import json
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
FLOAT, USHORT = 5126, 5123


class Builder:
    def __init__(self):
        self.bin = bytearray()
        self.doc = {"asset": {"version": "2.0", "generator": "vitrine tests/data/gltf/corpus/make_corpus.py"},
                    "bufferViews": [], "accessors": []}

    def view(self, data, target=None):
        while len(self.bin) % 4:
            self.bin.append(0)
        v = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if target:
            v["target"] = target
        self.bin += data
        self.doc["bufferViews"].append(v)
        return len(self.doc["bufferViews"]) - 1

    def floats(self, rows, type_, bounds=False, target=None):
        flat = [x for r in rows for x in (r if isinstance(r, (list, tuple)) else [r])]
        a = {"bufferView": self.view(struct.pack("<%df" % len(flat), *flat), target), "componentType": FLOAT,
             "count": len(rows), "type": type_}
        if bounds:
            n = len(flat) // len(rows)
            a["min"] = [min(flat[i::n]) for i in range(n)]
            a["max"] = [max(flat[i::n]) for i in range(n)]
        self.doc["accessors"].append(a)
        return len(self.doc["accessors"]) - 1

    def indices(self, idx):
        data = struct.pack("<%dH" % len(idx), *idx)
        self.doc["accessors"].append({"bufferView": self.view(data, 34963), "componentType": USHORT,
                                      "count": len(idx), "type": "SCALAR"})
        return len(self.doc["accessors"]) - 1

    def write(self, name):
        while len(self.bin) % 4:
            self.bin.append(0)
        self.doc["buffers"] = [{"byteLength": len(self.bin),
                                "uri": "data:application/octet-stream;base64," + base64.b64encode(self.bin).decode()}]
        with open(os.path.join(HERE, name), "w") as f:
            json.dump(self.doc, f, indent=1, sort_keys=True)
            f.write("\n")


def quad_mesh(b, center, half, material):
    """A square facing +Z (counter-clockwise seen from +Z) of half size `half` around `center`."""
    cx, cy, cz = center
    pos = [[cx - half, cy - half, cz], [cx + half, cy - half, cz], [cx + half, cy + half, cz], [cx - half, cy + half, cz]]
    nrm = [[0.0, 0.0, 1.0]] * 4
    prim = {"attributes": {"POSITION": b.floats(pos, "VEC3", True, 34962), "NORMAL": b.floats(nrm, "VEC3", False, 34962)},
            "indices": b.indices([0, 1, 2, 0, 2, 3]), "material": material}
    b.doc.setdefault("meshes", []).append({"name": "marker", "primitives": [prim]})
    return len(b.doc["meshes"]) - 1


def camera_file(name, camera, marker):
    b = Builder()
    b.doc["extensionsUsed"] = ["KHR_materials_unlit"]
    b.doc["materials"] = [{"name": "marker", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1],
                                                                      "metallicFactor": 0},
                           "extensions": {"KHR_materials_unlit": {}}}]
    mesh = quad_mesh(b, marker, 0.15, 0)
    b.doc["cameras"] = [camera]
    b.doc["nodes"] = [{"name": "camera", "camera": 0}, {"name": "marker", "mesh": mesh}]
    b.doc["scenes"] = [{"nodes": [0, 1]}]
    b.doc["scene"] = 0
    b.doc["asset"]["extras"] = {"expect": {"marker_view_space": marker}}
    b.write(name)


def animation_file():
    b = Builder()
    b.doc["nodes"] = [{"name": "linear_step"}, {"name": "cubic"}]
    b.doc["scenes"] = [{"nodes": [0, 1]}]
    b.doc["scene"] = 0
    times = b.floats([0.0, 1.0, 3.0], "SCALAR", True)
    t_lin = b.floats([[0, 0, 0], [2, 4, -2], [2, 0, 6]], "VEC3")
    half = math.sqrt(0.5)
    r_lin = b.floats([[0, 0, 0, 1], [0, half, 0, half], [half, 0, 0, half]], "VEC4")  # 0°, 90° about Y, 90° about X
    s_step = b.floats([[1, 1, 1], [2, 3, 4], [0.5, 0.5, 0.5]], "VEC3")
    ctimes = b.floats([0.0, 2.0], "SCALAR", True)
    # in-tangent, value, out-tangent per key (per second)
    t_cub = b.floats([[0, 0, 0], [0, 0, 0], [3, 0, 1], [1, 2, 0], [4, 1, -2], [0, 0, 0]], "VEC3")
    r_cub = b.floats([[0, 0, 0, 0], [0, 0, 0, 1], [0, 0.5, 0, 0], [0, 0.2, 0, 0], [0, half, 0, half], [0, 0, 0, 0]],
                     "VEC4")
    b.doc["animations"] = [{
        "name": "trs",
        "samplers": [{"input": times, "output": t_lin, "interpolation": "LINEAR"},
                     {"input": times, "output": r_lin, "interpolation": "LINEAR"},
                     {"input": times, "output": s_step, "interpolation": "STEP"},
                     {"input": ctimes, "output": t_cub, "interpolation": "CUBICSPLINE"},
                     {"input": ctimes, "output": r_cub, "interpolation": "CUBICSPLINE"}],
        "channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}},
                     {"sampler": 1, "target": {"node": 0, "path": "rotation"}},
                     {"sampler": 2, "target": {"node": 0, "path": "scale"}},
                     {"sampler": 3, "target": {"node": 1, "path": "translation"}},
                     {"sampler": 4, "target": {"node": 1, "path": "rotation"}}]}]
    b.write("animation.gltf")


def morph_cube_file(name, animated):
    """A unit cube (24 vertices, flat faces) whose one morph target moves the +X face by +1 in x (all 12 vertices at
    x = 0.5, so the faces around it stretch). Static: the mesh's
    weights are [0.5], so the rest pose has that face at x = 1.0. Animated: weights [0], a LINEAR weights animation
    from 0 at t = 0 to 1 at t = 2, so at t = 1 the face is at x = 1.0 too. An orthographic camera (xmag = ymag = 2)
    at z = 5 looks down -Z: in a square frame of W pixels the cube's middle row covers (1.0 + 0.5) / 4 × W pixels."""
    b = Builder()
    b.doc["extensionsUsed"] = ["KHR_materials_unlit"]
    b.doc["materials"] = [{"name": "white", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1],
                                                                     "metallicFactor": 0},
                           "extensions": {"KHR_materials_unlit": {}}}]
    pos, nrm, idx, delta = [], [], [], []
    for axis in range(3):
        for sign in (1, -1):
            n = [0.0, 0.0, 0.0]
            n[axis] = float(sign)
            u, v = (axis + 1) % 3, (axis + 2) % 3
            base = len(pos)
            for a, c in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = [0.0, 0.0, 0.0]
                p[axis] = 0.5 * sign
                p[u] = 0.5 * a
                p[v] = 0.5 * c
                pos.append(p)
                nrm.append(n)
                # every corner on the +X side moves, whichever face it belongs to (the side faces stretch)
                delta.append([1.0, 0.0, 0.0] if p[0] > 0 else [0.0, 0.0, 0.0])
            # counter-clockwise seen from outside
            idx += [base, base + 1, base + 2, base, base + 2, base + 3] if sign > 0 else \
                   [base, base + 2, base + 1, base, base + 3, base + 2]
    prim = {"attributes": {"POSITION": b.floats(pos, "VEC3", True, 34962), "NORMAL": b.floats(nrm, "VEC3", False, 34962)},
            "indices": b.indices(idx), "material": 0,
            "targets": [{"POSITION": b.floats(delta, "VEC3", True, 34962)}]}
    b.doc["meshes"] = [{"name": "cube", "primitives": [prim], "weights": [0.0 if animated else 0.5]}]
    b.doc["cameras"] = [{"type": "orthographic", "orthographic": {"xmag": 2.0, "ymag": 2.0, "znear": 0.1, "zfar": 20}}]
    b.doc["nodes"] = [{"name": "camera", "camera": 0, "translation": [0, 0, 5]}, {"name": "cube", "mesh": 0}]
    b.doc["scenes"] = [{"nodes": [0, 1]}]
    b.doc["scene"] = 0
    if animated:
        b.doc["animations"] = [{"name": "grow",
                                "samplers": [{"input": b.floats([0.0, 2.0], "SCALAR", True),
                                              "output": b.floats([0.0, 1.0], "SCALAR"), "interpolation": "LINEAR"}],
                                "channels": [{"sampler": 0, "target": {"node": 1, "path": "weights"}}]}]
    b.doc["asset"]["extras"] = {"expect": {"plus_x_face": 1.0, "at_time": 1.0 if animated else 0.0}}
    b.write(name)


def quantized_file():
    """KHR_mesh_quantization: one triangle with POSITION as SHORT integers (not normalised; the node scales by 0.01),
    NORMAL as normalised BYTE and TEXCOORD_0 as normalised UNSIGNED_SHORT, each element padded to 4 bytes as glTF
    asks. Loaded vertices: positions (100, 0, 0), (0, 200, 0), (0, 0, -300); normal (0, 0, 1) (127 / 127);
    uv (1, 0.5) for 65535 and 32768 (32768 / 65535)."""
    b = Builder()
    b.doc["extensionsUsed"] = ["KHR_mesh_quantization"]
    b.doc["extensionsRequired"] = ["KHR_mesh_quantization"]
    pos = struct.pack("<3hxx3hxx3hxx", 100, 0, 0, 0, 200, 0, 0, 0, -300)
    nrm = struct.pack("<3bx3bx3bx", 0, 0, 127, 0, 0, 127, 0, 0, 127)
    uv = struct.pack("<6H", 65535, 32768, 0, 0, 0, 65535)
    pv = b.view(pos, 34962)
    b.doc["bufferViews"][pv]["byteStride"] = 8
    nv = b.view(nrm, 34962)
    b.doc["bufferViews"][nv]["byteStride"] = 4
    uvv = b.view(uv, 34962)
    b.doc["accessors"] += [
        {"bufferView": pv, "componentType": 5122, "count": 3, "type": "VEC3", "min": [0, 0, -300], "max": [100, 200, 0]},
        {"bufferView": nv, "componentType": 5120, "normalized": True, "count": 3, "type": "VEC3"},
        {"bufferView": uvv, "componentType": 5123, "normalized": True, "count": 3, "type": "VEC2"}]
    first = len(b.doc["accessors"]) - 3
    b.doc["meshes"] = [{"primitives": [{"attributes": {"POSITION": first, "NORMAL": first + 1,
                                                       "TEXCOORD_0": first + 2}}]}]
    b.doc["nodes"] = [{"name": "quantized", "mesh": 0, "scale": [0.01, 0.01, 0.01]}]
    b.doc["scenes"] = [{"nodes": [0]}]
    b.doc["scene"] = 0
    b.write("quantized.gltf")


def skin_file():
    """A two-bone bend: a flat bar 0.2 wide along +Y from 0 to 2 (rows at y = 0, 0.5, 1, 1.5, 2), joint 0 at the
    origin, joint 1 its child at (0, 1, 0) (inverse bind matrix: translation by -1 in y). Rows below 1 follow joint 0,
    the row at 1 both half and half, rows above joint 1. Joint 1's rotation about +Z goes LINEAR from 0 at t = 0 to 90°
    at t = 1 (then holds): at t = 1 the tip (0, 2) is at (-1, 1). An orthographic camera (xmag = ymag = 2) at (0, 1, 5)
    looks down -Z."""
    b = Builder()
    b.doc["extensionsUsed"] = ["KHR_materials_unlit"]
    b.doc["materials"] = [{"name": "white", "doubleSided": True,
                           "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0},
                           "extensions": {"KHR_materials_unlit": {}}}]
    pos, nrm, joints, weights, idx = [], [], [], [], []
    for r, y in enumerate([0.0, 0.5, 1.0, 1.5, 2.0]):
        for x in (-0.1, 0.1):
            pos.append([x, y, 0.0])
            nrm.append([0.0, 0.0, 1.0])
            # a joint of weight 0 is 0, as the validator asks
            joints.append([0, 0, 0, 0] if y < 1 else [0, 1, 0, 0] if y == 1 else [1, 0, 0, 0])
            weights.append([1.0, 0.0, 0.0, 0.0] if y != 1 else [0.5, 0.5, 0.0, 0.0])
        if r:
            a = 2 * (r - 1)
            idx += [a, a + 1, a + 3, a, a + 3, a + 2]
    jdata = struct.pack("<%dB" % (4 * len(joints)), *[j for row in joints for j in row])
    b.doc["accessors"].append({"bufferView": b.view(jdata, 34962), "componentType": 5121, "count": len(joints),
                               "type": "VEC4"})
    jacc = len(b.doc["accessors"]) - 1
    prim = {"attributes": {"POSITION": b.floats(pos, "VEC3", True, 34962), "NORMAL": b.floats(nrm, "VEC3", False, 34962),
                           "JOINTS_0": jacc, "WEIGHTS_0": b.floats(weights, "VEC4", False, 34962)},
            "indices": b.indices(idx), "material": 0}
    b.doc["meshes"] = [{"name": "bar", "primitives": [prim]}]
    identity = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    down = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1]  # column-major translation (0, -1, 0)
    b.doc["skins"] = [{"name": "arm", "joints": [2, 3], "inverseBindMatrices": b.floats([identity, down], "MAT4")}]
    b.doc["cameras"] = [{"type": "orthographic", "orthographic": {"xmag": 2.0, "ymag": 2.0, "znear": 0.1, "zfar": 20}}]
    b.doc["nodes"] = [{"name": "camera", "camera": 0, "translation": [0, 1, 5]}, {"name": "bar", "mesh": 0, "skin": 0},
                      {"name": "joint0", "children": [3]}, {"name": "joint1", "translation": [0, 1, 0]}]
    b.doc["scenes"] = [{"nodes": [0, 1, 2]}]
    b.doc["scene"] = 0
    h = math.sqrt(0.5)
    b.doc["animations"] = [{"name": "bend",
                            "samplers": [{"input": b.floats([0.0, 1.0], "SCALAR", True),
                                          "output": b.floats([[0, 0, 0, 1], [0, 0, h, h]], "VEC4"),
                                          "interpolation": "LINEAR"}],
                            "channels": [{"sampler": 0, "target": {"node": 3, "path": "rotation"}}]}]
    b.write("skin_bend.gltf")


def main():
    # Perspective: the marker sits at 60 % of the half-height to the right and 40 % up at depth 5, so in a square
    # frame it lands at NDC (0.6, -0.4) (Vulkan y down) when the vertical field of view is kept, and at x = 0.4
    # when stretched by the authored 1.5.
    yfov, depth = 0.8, 5.0
    h = depth * math.tan(yfov / 2)
    camera_file("camera_aspect.gltf",
                {"type": "perspective", "perspective": {"yfov": yfov, "aspectRatio": 1.5, "znear": 0.1, "zfar": 100}},
                [0.6 * h, 0.4 * h, -depth])
    camera_file("camera_ortho.gltf",
                {"type": "orthographic", "orthographic": {"xmag": 2.0, "ymag": 1.0, "znear": 0.1, "zfar": 100}},
                [1.2, 0.5, -depth])
    animation_file()
    morph_cube_file("morph_cube.gltf", False)
    morph_cube_file("morph_animated.gltf", True)
    quantized_file()
    skin_file()


main()

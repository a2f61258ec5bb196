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
  spec_gloss.gltf      KHR_materials_pbrSpecularGlossiness: three factor-only materials (a grey dielectric, gold, a
                       grey half-metal) and a textured one (2x2 diffuse and specular-glossiness PNGs, nearest
                       sampling), each on a quad filling one quadrant of an orthographic view (xmag = ymag = 2 at
                       z = 5). asset.extras.expect holds the metallic-roughness values worked out by hand from the
                       conversion's quadratic (tests/unit/scene/test_gltf_corpus.cpp, tests/gpu/gltf_corpus_test.cpp).
  emissive_strength.gltf  two quads with emissiveFactor (1, 0.5, 0.25): the left one with
                       KHR_materials_emissive_strength 4, the right one without (G-buffer emissive 4x the right's).
  variants.gltf        KHR_materials_variants "red" and "blue" remapping the left quad's white material; the right quad
                       has no mapping and stays white whatever the variant.
  ignored_material_extensions.gltf  KHR_materials_iridescence (material 0) next to a plain _transmission (material
                       1): vitrine warns once, for the iridescence.
  specular.gltf        KHR_materials_specular: strength 0.4, strength 0, a tint alone, and a 2x2 texture read both as
                       specularTexture (alpha) and specularColorTexture (sRGB rgb), one quadrant each; the G-buffer's
                       material.y is 1 - strength (tests/gpu/gltf_materials_test.cpp).
  clearcoat.gltf       KHR_materials_clearcoat: a full smooth coat, a half coat of roughness 0.3, a factor 0, and a
                       coat textured by a 2x2 image (red: strength, green: roughness, with KHR_texture_transform) and a
                       coat normal map; the G-buffer's emissive alpha packs them (tests/gpu/gltf_materials_test.cpp).
  sheen.gltf           KHR_materials_sheen: spheres of velvet (red base, pink sheen, roughness 0.5), satin (blue, pale
                       blue sheen, 0.3) and a black sheen (none), and a quad whose sheen colour (sRGB rgb) and roughness
                       (alpha) come from a 2x2 image through KHR_texture_transform; the G-buffer packs them
                       (tests/gpu/gltf_materials_test.cpp). Rendered by graphs/gltf.json, the spheres' rims glow.
  volume.gltf          KHR_materials_volume on thin glass (_transmission 1) over a white backdrop: thickness 0.5 at
                       attenuationDistance 2 of colour (0.5, 0.8, 1); thickness 0 (thin-walled) with a colour; thickness
                       1 with no distance (infinite: no attenuation); and thicknessFactor 0.6 x the green of a 2x2
                       image through KHR_texture_transform at distance 0.5 of colour (0.2, 0.6, 0.9); the first on a
                       node of scale 2 (tests/unit/scene/test_gltf_materials.cpp reads them back).
Regenerate after editing: python3 tests/data/gltf/corpus/make_corpus.py
"""
import base64
import json
import math
import os
import struct
import zlib

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


def quad_mesh(b, center, half, material, uvs=False, name="marker", half_y=None):
    """A rectangle facing +Z (counter-clockwise seen from +Z) of half size `half` (`half_y` vertically) around
    `center`; uvs: TEXCOORD_0 with (0, 0) at the top-left corner, as glTF's UV origin is the image's top left."""
    cx, cy, cz = center
    hy = half if half_y is None else half_y
    pos = [[cx - half, cy - hy, cz], [cx + half, cy - hy, cz], [cx + half, cy + hy, cz], [cx - half, cy + hy, cz]]
    nrm = [[0.0, 0.0, 1.0]] * 4
    attributes = {"POSITION": b.floats(pos, "VEC3", True, 34962), "NORMAL": b.floats(nrm, "VEC3", False, 34962)}
    if uvs:
        attributes["TEXCOORD_0"] = b.floats([[0, 1], [1, 1], [1, 0], [0, 0]], "VEC2", False, 34962)
    prim = {"attributes": attributes, "indices": b.indices([0, 1, 2, 0, 2, 3]), "material": material}
    b.doc.setdefault("meshes", []).append({"name": name, "primitives": [prim]})
    return len(b.doc["meshes"]) - 1


def png_rgba(width, height, rgba):
    """An 8-bit RGBA PNG (no filtering) of rows of [r, g, b, a] texels, top row first."""
    raw = b"".join(b"\x00" + bytes(v for texel in rgba[y * width:(y + 1) * width] for v in texel)
                   for y in range(height))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def ortho_view(b, meshes):
    """An orthographic camera (xmag = ymag = 2) at z = 5 looking down -Z at one node per mesh."""
    b.doc["cameras"] = [{"type": "orthographic", "orthographic": {"xmag": 2.0, "ymag": 2.0, "znear": 0.1, "zfar": 20}}]
    b.doc["nodes"] = [{"name": "camera", "camera": 0, "translation": [0, 0, 5]}]
    b.doc["nodes"] += [{"name": b.doc["meshes"][m]["name"], "mesh": m} for m in meshes]
    b.doc["scenes"] = [{"nodes": list(range(len(b.doc["nodes"])))}]
    b.doc["scene"] = 0


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


def srgb_decode(v):
    c = v / 255.0
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def spec_gloss_file():
    """Quadrants (top-left, top-right, bottom-left, bottom-right): a grey dielectric, gold, a grey half-metal (factors
    only) and a textured material. Hand conversion (see core/scene/gltf_specgloss.cpp for the model): with
    D = brightness(diffuse) (1 - max(specular)) / 0.96 and S = brightness(specular) the metallic m is the larger root
    of 0.04 m^2 + (D + S - 0.08) m + (0.04 - S) = 0 (0 when S < 0.04); for grey colours the base colour is
    D / (1 - m) (m < 1), for m = 1 it is the specular colour; roughness = 1 - glossiness.
      grey dielectric: diffuse 0.5, specular 0.04, glossiness 0.8: S = 0.04, so c = 0 and m = 0; base = 0.5 x 0.96 /
        0.96 = 0.5; roughness 0.2.
      gold: diffuse 0, specular (1, 0.766, 0.336), glossiness 0.6: D = 0, and m = 1 solves 0.04 + (S - 0.08) +
        (0.04 - S) = 0: metallic 1, base = specular, roughness 0.4.
      grey half-metal: diffuse 0.3, specular 0.5, glossiness 0.5: D = 0.3 x 0.5 / 0.96 = 0.15625, b = 0.57625,
        c = -0.46, m = (-0.57625 + sqrt(0.57625^2 + 0.0736)) / 0.08 = 0.758345; base = 0.15625 / (1 - m) = 0.646584
        (and (0.5 - 0.04 (1 - m)) / m = 0.646584 from the specular side too); roughness 0.5.
    The textured quadrant's texels (diffuse sRGB rgb + linear alpha; specular sRGB rgb, glossiness linear alpha),
    left to right, top to bottom, and what they convert to (linear):
      (128 grey, spec 0, gloss 255): S = 0: m = 0, base = 0.215861 / 0.96 = 0.224856, roughness 0.
      (0 black, spec 255 white, gloss 0): D = 0, S = 1: m = 1, base = 1 (the specular), roughness 1.
      (255 red, spec 0, gloss 128): m = 0, base = (1 / 0.96 -> clamped 1, 0, 0), roughness 1 - 128/255.
      (255 white, spec 188 grey, gloss 64): specular 0.502886 linear: D = 0.497114 / 0.96 = 0.517827, S = 0.502886,
        m = 0.482173, base = D / (1 - m) = 1.000000 (so does the specular side), roughness 1 - 64/255."""
    b = Builder()
    b.doc["extensionsUsed"] = ["KHR_materials_pbrSpecularGlossiness"]
    sg = "KHR_materials_pbrSpecularGlossiness"
    b.doc["materials"] = [
        {"name": "grey_dielectric", "extensions": {sg: {"diffuseFactor": [0.5, 0.5, 0.5, 1.0],
                                                        "specularFactor": [0.04, 0.04, 0.04],
                                                        "glossinessFactor": 0.8}}},
        {"name": "gold", "extensions": {sg: {"diffuseFactor": [0.0, 0.0, 0.0, 1.0],
                                             "specularFactor": [1.0, 0.766, 0.336], "glossinessFactor": 0.6}}},
        {"name": "grey_half_metal", "extensions": {sg: {"diffuseFactor": [0.3, 0.3, 0.3, 1.0],
                                                        "specularFactor": [0.5, 0.5, 0.5], "glossinessFactor": 0.5}}},
        {"name": "textured", "extensions": {sg: {"diffuseTexture": {"index": 0},
                                                 "specularGlossinessTexture": {"index": 1}}}}]
    diffuse = png_rgba(2, 2, [[128, 128, 128, 255], [0, 0, 0, 255], [255, 0, 0, 255], [255, 255, 255, 255]])
    specgloss = png_rgba(2, 2, [[0, 0, 0, 255], [255, 255, 255, 0], [0, 0, 0, 128], [188, 188, 188, 64]])
    b.doc["images"] = [{"name": "diffuse", "mimeType": "image/png", "bufferView": b.view(diffuse)},
                       {"name": "specular_glossiness", "mimeType": "image/png", "bufferView": b.view(specgloss)}]
    b.doc["samplers"] = [{"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33071}]
    b.doc["textures"] = [{"sampler": 0, "source": 0}, {"sampler": 0, "source": 1}]
    meshes = [quad_mesh(b, c, 1.0, m, uvs=(m == 3), name=b.doc["materials"][m]["name"])
              for m, c in enumerate([[-1, 1, 0], [1, 1, 0], [-1, -1, 0], [1, -1, 0]])]
    ortho_view(b, meshes)
    grey = 0.646584
    dark = srgb_decode(128)
    b.doc["asset"]["extras"] = {"expect": {
        "quadrants": ["top_left", "top_right", "bottom_left", "bottom_right"],
        "base_color": [[0.5, 0.5, 0.5, 1.0], [1.0, 0.766, 0.336, 1.0], [grey, grey, grey, 1.0]],
        "metallic": [0.0, 1.0, 0.758345], "roughness": [0.2, 0.4, 0.5],
        "texels_base_color": [[dark / 0.96] * 3 + [1.0], [1.0, 1.0, 1.0, 1.0], [1.0, 0.0, 0.0, 1.0],
                              [1.0, 1.0, 1.0, 1.0]],
        "texels_metallic": [0.0, 1.0, 0.0, 0.482173],
        "texels_roughness": [0.0, 1.0, 1.0 - 128 / 255, 1.0 - 64 / 255]}}
    b.write("spec_gloss.gltf")


def emissive_strength_file():
    b = Builder()
    b.doc["extensionsUsed"] = ["KHR_materials_emissive_strength"]
    dark = {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0}
    b.doc["materials"] = [{"name": "strong", "pbrMetallicRoughness": dark, "emissiveFactor": [1.0, 0.5, 0.25],
                           "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}},
                          {"name": "plain", "pbrMetallicRoughness": dark, "emissiveFactor": [1.0, 0.5, 0.25]}]
    meshes = [quad_mesh(b, [-1, 0, 0], 1.0, 0, name="strong", half_y=2.0),
              quad_mesh(b, [1, 0, 0], 1.0, 1, name="plain", half_y=2.0)]
    ortho_view(b, meshes)
    b.doc["asset"]["extras"] = {"expect": {"left_emissive": [4.0, 2.0, 1.0], "right_emissive": [1.0, 0.5, 0.25]}}
    b.write("emissive_strength.gltf")


def variants_file():
    b = Builder()
    b.doc["extensionsUsed"] = ["KHR_materials_variants"]
    b.doc["extensions"] = {"KHR_materials_variants": {"variants": [{"name": "red"}, {"name": "blue"}]}}
    flat = lambda c: {"baseColorFactor": c, "metallicFactor": 0}  # noqa: E731
    b.doc["materials"] = [{"name": "white", "pbrMetallicRoughness": flat([1, 1, 1, 1])},
                          {"name": "red", "pbrMetallicRoughness": flat([1, 0, 0, 1])},
                          {"name": "blue", "pbrMetallicRoughness": flat([0, 0, 1, 1])}]
    meshes = [quad_mesh(b, [-1, 0, 0], 1.0, 0, name="mapped", half_y=2.0),
              quad_mesh(b, [1, 0, 0], 1.0, 0, name="unmapped", half_y=2.0)]
    b.doc["meshes"][meshes[0]]["primitives"][0]["extensions"] = {"KHR_materials_variants": {"mappings": [
        {"material": 1, "variants": [0]}, {"material": 2, "variants": [1]}]}}
    ortho_view(b, meshes)
    b.write("variants.gltf")


def ignored_material_extensions_file():
    b = Builder()
    names = ["KHR_materials_iridescence", "KHR_materials_transmission"]
    b.doc["extensionsUsed"] = names
    b.doc["materials"] = [
        {"name": "coated", "extensions": {
            "KHR_materials_iridescence": {"iridescenceFactor": 1.0, "iridescenceThicknessMaximum": 400.0}}},
        {"name": "glass", "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0},
         "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0}}}]
    meshes = [quad_mesh(b, [-1, 0, 0], 1.0, 0, name="coated"), quad_mesh(b, [1, 0, 0], 1.0, 1, name="glass")]
    ortho_view(b, meshes)
    b.write("ignored_material_extensions.gltf")


def specular_file():
    """Quadrants (top-left, top-right, bottom-left, bottom-right) of a grey rough dielectric with
    KHR_materials_specular: specularFactor 0.4, specularFactor 0, specularColorFactor (1, 0.5, 0.25) alone, and a 2x2
    texture (nearest) used as both specularTexture (its alpha: 255, 153, 51, 0) and specularColorTexture (its sRGB rgb).
    The G-buffer keeps the strength k as 1 - k in material.y: 0.6 (= 153/255, exact in UNORM8), 1, 0 and, per texel,
    1 - alpha/255 = 0, 0.4, 0.8, 1. The dielectric F0 for the forward pass and the tracers is
    k min(0.04 c, 1) and F90 = k."""
    b = Builder()
    b.doc["extensionsUsed"] = ["KHR_materials_specular"]
    sp = "KHR_materials_specular"
    grey = {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0, "roughnessFactor": 0.5}
    b.doc["materials"] = [
        {"name": "weak", "pbrMetallicRoughness": grey, "extensions": {sp: {"specularFactor": 0.4}}},
        {"name": "none", "pbrMetallicRoughness": grey, "extensions": {sp: {"specularFactor": 0.0}}},
        {"name": "tinted", "pbrMetallicRoughness": grey,
         "extensions": {sp: {"specularColorFactor": [1.0, 0.5, 0.25]}}},
        {"name": "textured", "pbrMetallicRoughness": grey,
         "extensions": {sp: {"specularTexture": {"index": 0}, "specularColorTexture": {"index": 0}}}}]
    image = png_rgba(2, 2, [[255, 255, 255, 255], [255, 128, 64, 153], [64, 128, 255, 51], [0, 0, 0, 0]])
    b.doc["images"] = [{"name": "specular", "mimeType": "image/png", "bufferView": b.view(image)}]
    b.doc["samplers"] = [{"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33071}]
    b.doc["textures"] = [{"sampler": 0, "source": 0}]
    meshes = [quad_mesh(b, c, 1.0, m, uvs=(m == 3), name=b.doc["materials"][m]["name"])
              for m, c in enumerate([[-1, 1, 0], [1, 1, 0], [-1, -1, 0], [1, -1, 0]])]
    ortho_view(b, meshes)
    b.doc["asset"]["extras"] = {"expect": {
        "quadrants": ["top_left", "top_right", "bottom_left", "bottom_right"],
        "strength": [0.4, 0.0, 1.0], "color": [[1, 1, 1], [1, 1, 1], [1.0, 0.5, 0.25]],
        "material_y": [0.6, 1.0, 0.0],
        "texels_material_y": [0.0, 0.4, 0.8, 1.0],
        "texels_color": [[1.0, 1.0, 1.0], [1.0, srgb_decode(128), srgb_decode(64)],
                         [srgb_decode(64), srgb_decode(128), 1.0], [0.0, 0.0, 0.0]]}}
    b.write("specular.gltf")


def clearcoat_file():
    """Quadrants (top-left, top-right, bottom-left, bottom-right) of a grey rough dielectric with
    KHR_materials_clearcoat: clearcoatFactor 1 with roughness 0; clearcoatFactor 0.5 with roughness 0.3; factor 0 (no
    coat); and a textured coat: clearcoatFactor 1 x the red channel and clearcoatRoughnessFactor 0.6 x the green
    channel of a 2x2 image (nearest), read through KHR_texture_transform (scale 1, offset 0: the identity, so the
    texels land on the quadrant's quarters as authored), plus a flat clearcoatNormalTexture of scale 0.5."""
    b = Builder()
    cc = "KHR_materials_clearcoat"
    b.doc["extensionsUsed"] = [cc, "KHR_texture_transform"]
    grey = {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0, "roughnessFactor": 0.5}
    tt = {"KHR_texture_transform": {"offset": [0, 0], "scale": [1, 1]}}
    b.doc["materials"] = [
        {"name": "full", "pbrMetallicRoughness": grey, "extensions": {cc: {"clearcoatFactor": 1.0}}},
        {"name": "half", "pbrMetallicRoughness": grey,
         "extensions": {cc: {"clearcoatFactor": 0.5, "clearcoatRoughnessFactor": 0.3}}},
        {"name": "zero", "pbrMetallicRoughness": grey, "extensions": {cc: {"clearcoatFactor": 0.0}}},
        {"name": "textured", "pbrMetallicRoughness": grey,
         "extensions": {cc: {"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.6,
                             "clearcoatTexture": {"index": 0, "extensions": tt},
                             "clearcoatRoughnessTexture": {"index": 0, "extensions": tt},
                             "clearcoatNormalTexture": {"index": 1, "scale": 0.5}}}}]
    # Red 255, 128, 64, 0 (strength 1, 0.502, 0.251, 0); green 0, 255, 128, 255 (roughness 0.6 x that).
    image = png_rgba(2, 2, [[255, 0, 0, 255], [128, 255, 0, 255], [64, 128, 0, 255], [0, 255, 0, 255]])
    flat = png_rgba(1, 1, [[128, 128, 255, 255]])
    b.doc["images"] = [{"name": "clearcoat", "mimeType": "image/png", "bufferView": b.view(image)},
                       {"name": "clearcoat_normal", "mimeType": "image/png", "bufferView": b.view(flat)}]
    b.doc["samplers"] = [{"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33071}]
    b.doc["textures"] = [{"sampler": 0, "source": 0}, {"sampler": 0, "source": 1}]
    meshes = [quad_mesh(b, c, 1.0, m, uvs=(m == 3), name=b.doc["materials"][m]["name"])
              for m, c in enumerate([[-1, 1, 0], [1, 1, 0], [-1, -1, 0], [1, -1, 0]])]
    # The coat normal map needs a tangent space (glTF: the file provides it when no base normal map is there).
    b.doc["meshes"][3]["primitives"][0]["attributes"]["TANGENT"] = b.floats([[1.0, 0.0, 0.0, 1.0]] * 4, "VEC4",
                                                                           False, 34962)
    ortho_view(b, meshes)
    b.doc["asset"]["extras"] = {"expect": {
        "quadrants": ["top_left", "top_right", "bottom_left", "bottom_right"],
        "clearcoat": [1.0, 0.5, 0.0, 1.0], "roughness": [0.0, 0.3, 0.0, 0.6],
        "texels_clearcoat": [1.0, 128 / 255, 64 / 255, 0.0],
        "texels_roughness": [0.0, 0.6, 0.6 * 128 / 255, 0.6]}}
    b.write("clearcoat.gltf")


def sphere_mesh(b, center, r, material, name, seg=48, rings=24):
    """A UV sphere (normals outward, counter-clockwise from outside) of radius r around center."""
    pos, nrm, idx = [], [], []
    for i in range(rings + 1):
        th = math.pi * i / rings
        for j in range(seg + 1):
            ph = 2 * math.pi * j / seg
            n = [math.sin(th) * math.cos(ph), math.cos(th), -math.sin(th) * math.sin(ph)]
            pos.append([center[k] + r * n[k] for k in range(3)])
            nrm.append(n)
    for i in range(rings):
        for j in range(seg):
            a, c = i * (seg + 1) + j, (i + 1) * (seg + 1) + j
            if i > 0:
                idx += [a, c, a + 1]
            if i < rings - 1:
                idx += [a + 1, c, c + 1]
    attributes = {"POSITION": b.floats(pos, "VEC3", True, 34962), "NORMAL": b.floats(nrm, "VEC3", False, 34962)}
    prim = {"attributes": attributes, "indices": b.indices(idx), "material": material}
    b.doc.setdefault("meshes", []).append({"name": name, "primitives": [prim]})
    return len(b.doc["meshes"]) - 1


def sheen_file():
    """Quadrants (top-left, top-right, bottom-left, bottom-right): spheres of radius 0.9 of velvet (dark red base,
    sheenColorFactor (0.9, 0.5, 0.6), roughness 0.5), satin (dark blue, (0.6, 0.7, 1.0), 0.3) and a black sheen
    ((0, 0, 0), 0.5: no sheen), and a grey quad whose sheen is sheenColorFactor 1 x the sRGB colour and
    sheenRoughnessFactor 0.8 x the alpha of a 2x2 image (nearest), read through KHR_texture_transform (the identity)."""
    b = Builder()
    sh = "KHR_materials_sheen"
    b.doc["extensionsUsed"] = [sh, "KHR_texture_transform"]
    tt = {"KHR_texture_transform": {"offset": [0, 0], "scale": [1, 1]}}

    def pbr(c):
        return {"baseColorFactor": c + [1], "metallicFactor": 0, "roughnessFactor": 0.8}
    b.doc["materials"] = [
        {"name": "velvet", "pbrMetallicRoughness": pbr([0.2, 0.01, 0.03]),
         "extensions": {sh: {"sheenColorFactor": [0.9, 0.5, 0.6], "sheenRoughnessFactor": 0.5}}},
        {"name": "satin", "pbrMetallicRoughness": pbr([0.02, 0.04, 0.2]),
         "extensions": {sh: {"sheenColorFactor": [0.6, 0.7, 1.0], "sheenRoughnessFactor": 0.3}}},
        {"name": "black", "pbrMetallicRoughness": pbr([0.5, 0.5, 0.5]),
         "extensions": {sh: {"sheenColorFactor": [0.0, 0.0, 0.0], "sheenRoughnessFactor": 0.5}}},
        {"name": "textured", "pbrMetallicRoughness": pbr([0.5, 0.5, 0.5]),
         "extensions": {sh: {"sheenColorFactor": [1.0, 1.0, 1.0], "sheenRoughnessFactor": 0.8,
                             "sheenColorTexture": {"index": 0, "extensions": tt},
                             "sheenRoughnessTexture": {"index": 0, "extensions": tt}}}}]
    # rgb (sRGB 255 and 0 decode exactly): red, green, blue, white; alpha 255, 128, 64, 0.
    image = png_rgba(2, 2, [[255, 0, 0, 255], [0, 255, 0, 128], [0, 0, 255, 64], [255, 255, 255, 0]])
    b.doc["images"] = [{"name": "sheen", "mimeType": "image/png", "bufferView": b.view(image)}]
    b.doc["samplers"] = [{"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33071}]
    b.doc["textures"] = [{"sampler": 0, "source": 0}]
    meshes = [sphere_mesh(b, c, 0.9, m, b.doc["materials"][m]["name"])
              for m, c in enumerate([[-1, 1, 0], [1, 1, 0], [-1, -1, 0]])]
    meshes.append(quad_mesh(b, [1, -1, 0], 1.0, 3, uvs=True, name="textured"))
    ortho_view(b, meshes)
    b.doc["asset"]["extras"] = {"expect": {
        "quadrants": ["top_left", "top_right", "bottom_left", "bottom_right"],
        "sheen_color": [[0.9, 0.5, 0.6], [0.6, 0.7, 1.0], [0.0, 0.0, 0.0], [1.0, 1.0, 1.0]],
        "roughness": [0.5, 0.3, 0.5, 0.8],
        "texels_color": [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]],
        "texels_roughness": [0.8, 0.8 * 128 / 255, 0.8 * 64 / 255, 0.0]}}
    b.write("sheen.gltf")


def volume_file():
    """Quadrants (top-left, top-right, bottom-left, bottom-right) of clear glass (transmissionFactor 1, white, smooth)
    with KHR_materials_volume, 0.5 in front of a white backdrop: thicknessFactor 0.5, attenuationDistance 2, colour
    (0.5, 0.8, 1.0), on a node of scale 2 (its quad authored at half size: d = 0.5 x 2 = 1, T = colour^0.5); thickness
    0 (thin-walled: the colour and distance change nothing); thickness 1 without attenuationDistance (+infinity: T = 1);
    and thicknessFactor 0.6 x the green channel of a 2x2 image (nearest; green 255, 128, 64, 0, the other channels
    different) through KHR_texture_transform (the identity), attenuationDistance 0.5, colour (0.2, 0.6, 0.9)."""
    b = Builder()
    vo, tr = "KHR_materials_volume", "KHR_materials_transmission"
    b.doc["extensionsUsed"] = [tr, vo, "KHR_texture_transform"]
    glass = {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 0}
    tt = {"KHR_texture_transform": {"offset": [0, 0], "scale": [1, 1]}}
    b.doc["materials"] = [
        {"name": "tinted", "pbrMetallicRoughness": glass, "extensions": {
            tr: {"transmissionFactor": 1.0},
            vo: {"thicknessFactor": 0.5, "attenuationDistance": 2.0, "attenuationColor": [0.5, 0.8, 1.0]}}},
        {"name": "thin", "pbrMetallicRoughness": glass, "extensions": {
            tr: {"transmissionFactor": 1.0},
            vo: {"thicknessFactor": 0.0, "attenuationDistance": 0.1, "attenuationColor": [0.2, 0.3, 0.4]}}},
        {"name": "clear", "pbrMetallicRoughness": glass, "extensions": {
            tr: {"transmissionFactor": 1.0}, vo: {"thicknessFactor": 1.0, "attenuationColor": [0.5, 0.5, 0.5]}}},
        {"name": "textured", "pbrMetallicRoughness": glass, "extensions": {
            tr: {"transmissionFactor": 1.0},
            vo: {"thicknessFactor": 0.6, "thicknessTexture": {"index": 0, "extensions": tt},
                 "attenuationDistance": 0.5, "attenuationColor": [0.2, 0.6, 0.9]}}},
        {"name": "backdrop", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0,
                                                      "roughnessFactor": 1}}]
    image = png_rgba(2, 2, [[0, 255, 0, 255], [255, 128, 255, 0], [128, 64, 0, 255], [255, 0, 255, 255]])
    b.doc["images"] = [{"name": "thickness", "mimeType": "image/png", "bufferView": b.view(image)}]
    b.doc["samplers"] = [{"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33071}]
    b.doc["textures"] = [{"sampler": 0, "source": 0}]
    meshes = [quad_mesh(b, [-0.5, 0.5, 0.25], 0.45, 0, name="tinted")]
    meshes += [quad_mesh(b, c, 0.9, m, uvs=(m == 3), name=b.doc["materials"][m]["name"])
               for m, c in [(1, [1, 1, 0.5]), (2, [-1, -1, 0.5]), (3, [1, -1, 0.5])]]
    meshes.append(quad_mesh(b, [0, 0, 0], 2.0, 4, name="backdrop"))
    ortho_view(b, meshes)
    b.doc["nodes"][1]["scale"] = [2, 2, 2]
    b.doc["asset"]["extras"] = {"expect": {
        "materials": ["tinted", "thin", "clear", "textured"],
        "thickness": [0.5, 0.0, 1.0, 0.6], "attenuation_distance": [2.0, 0.1, None, 0.5],
        "attenuation_color": [[0.5, 0.8, 1.0], [0.2, 0.3, 0.4], [0.5, 0.5, 0.5], [0.2, 0.6, 0.9]],
        "node_scale": [2.0, 1.0, 1.0, 1.0],
        "texels_thickness": [0.6, 0.6 * 128 / 255, 0.6 * 64 / 255, 0.0]}}
    b.write("volume.gltf")


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
    spec_gloss_file()
    emissive_strength_file()
    variants_file()
    ignored_material_extensions_file()
    specular_file()
    clearcoat_file()
    sheen_file()
    volume_file()


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Writes the glTF files of ctest gltf.sample_viewer to tests/data/gltf/viewer/ (python3 standard library only;
deterministic; the corpus's Builder from tests/data/gltf/corpus/make_corpus.py).

Every file carries what both renderers must share, so neither falls back on its own defaults:
  - a perspective camera (yfov 0.7, aspectRatio 1) on +Z looking down -Z at the origin (vitrine's scene.gltf and the
    Sample Viewer both render through the file's first camera);
  - one KHR_lights_punctual directional light of 100000 lux, white, in the direction of graphs/gltf.json's key light
    (key_light_elevation 35 deg above the horizon, key_light_azimuth 30 deg to the right of the way back to the
    camera): vitrine takes a file's directional light as its sun instead of adding the key light, at sky.hdri's
    sun_illuminance (100000 lux, the same number), the Sample Viewer lights with the file's light.
Files:
  white_sphere.gltf  a matte white sphere (base colour 0.8, metallic 0, roughness 1): diffuse, key light + studio IBL.
  metal_spheres.gltf three gold spheres (base colour (1, 0.766, 0.336), metallic 1), roughness 0.15, 0.45 and 0.8:
                     the prefiltered specular IBL at three blur levels.
  textured.gltf      a quad tilted 25 deg back, base colour texture 2x2 (red, green / blue, white; sRGB, nearest),
                     roughness 0.6: texture decoding, sRGB and UV orientation (a swapped channel or a flipped V shows).
  unlit.gltf         an orange KHR_materials_unlit quad (left) and a black quad with emissiveFactor (0.2, 0.5, 1.0)
                     (right): display-referred colours that must reach the PNG as authored.
  glass.gltf         textured.gltf's 2x2 texture on an upright quad behind two glass panes (KHR_materials_transmission
                     1, KHR_materials_ior 1.5, KHR_materials_volume thickness 0.8) across its vertical edges, turned
                     35 deg about the vertical: a smooth one at the top (the refraction offset moves the edge) and one
                     of roughness 0.6 at the bottom (the blur of the transmission framebuffer).
Regenerate after editing: python3 tests/viewer/make_scenes.py [OUT_DIR] (ctest data.viewer_scenes writes them to the
build tree and compares them byte for byte with the committed ones).
"""
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tests", "data", "gltf", "corpus"))
import make_corpus  # noqa: E402
from make_corpus import Builder, png_rgba, quad_mesh  # noqa: E402

OUT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "tests", "data", "gltf", "viewer")
KEY_ELEVATION, KEY_AZIMUTH = 35.0, 30.0  # graphs/gltf.json's scene.gltf key_light defaults
SUN_LUX = 100000.0                        # graphs/gltf.json's sky.hdri sun_illuminance


def quat_z_to(d):
    """The unit quaternion (x, y, z, w) turning +Z onto the unit vector d (a light shines down its node's -Z, so +Z
    points at the light)."""
    z = (0.0, 0.0, 1.0)
    axis = (z[1] * d[2] - z[2] * d[1], z[2] * d[0] - z[0] * d[2], z[0] * d[1] - z[1] * d[0])
    c = d[2]
    s = math.sqrt(sum(a * a for a in axis))
    if s < 1e-9:
        return [0.0, 0.0, 0.0, 1.0]
    half = math.atan2(s, c) / 2
    k = math.sin(half) / s
    return [axis[0] * k, axis[1] * k, axis[2] * k, math.cos(half)]


def to_key_light():
    """The direction to graphs/gltf.json's key light for a camera looking down -Z (nodes/scene/scene_node.cpp:
    heading (0, 0, -1), right (1, 0, 0); horizontal = -heading cos(az) + right sin(az))."""
    az, el = math.radians(KEY_AZIMUTH), math.radians(KEY_ELEVATION)
    return (math.sin(az) * math.cos(el), math.sin(el), math.cos(az) * math.cos(el))


def sphere_mesh(b, center, radius, material, name, rings=24, segments=48):
    pos, nrm, idx = [], [], []
    for i in range(rings + 1):
        theta = math.pi * i / rings
        for j in range(segments + 1):
            phi = 2 * math.pi * j / segments
            n = [math.sin(theta) * math.sin(phi), math.cos(theta), math.sin(theta) * math.cos(phi)]
            nrm.append(n)
            pos.append([center[k] + radius * n[k] for k in range(3)])
    for i in range(rings):
        for j in range(segments):
            a = i * (segments + 1) + j
            c = a + segments + 1
            idx += [a, c, a + 1, a + 1, c, c + 1]
    attributes = {"POSITION": b.floats(pos, "VEC3", True, 34962), "NORMAL": b.floats(nrm, "VEC3", False, 34962)}
    b.doc.setdefault("meshes", []).append({"name": name, "primitives": [
        {"attributes": attributes, "indices": b.indices(idx), "material": material}]})
    return len(b.doc["meshes"]) - 1


def finish(b, meshes, name, distance=3.6, mesh_rotation=None, transforms=None):
    """Adds the camera, the key light and a node per mesh (each turned by mesh_rotation, or given its entry of
    transforms: a dict of node fields), and writes the file."""
    b.doc["extensionsUsed"] = sorted(set(b.doc.get("extensionsUsed", []) + ["KHR_lights_punctual"]))
    b.doc.setdefault("extensions", {})["KHR_lights_punctual"] = {
        "lights": [{"name": "key", "type": "directional", "color": [1.0, 1.0, 1.0], "intensity": SUN_LUX}]}
    b.doc["cameras"] = [{"type": "perspective",
                         "perspective": {"yfov": 0.7, "aspectRatio": 1.0, "znear": 0.1, "zfar": 50.0}}]
    b.doc["nodes"] = [{"name": "camera", "camera": 0, "translation": [0.0, 0.0, distance]},
                      {"name": "key_light", "rotation": quat_z_to(to_key_light()),
                       "extensions": {"KHR_lights_punctual": {"light": 0}}}]
    for i, m in enumerate(meshes):
        node = {"name": b.doc["meshes"][m]["name"], "mesh": m}
        if mesh_rotation:
            node["rotation"] = mesh_rotation
        if transforms and transforms[i]:
            node.update(transforms[i])
        b.doc["nodes"].append(node)
    b.doc["scenes"] = [{"nodes": list(range(len(b.doc["nodes"])))}]
    b.doc["scene"] = 0
    b.doc["asset"]["generator"] = "vitrine tests/viewer/make_scenes.py"
    make_corpus.HERE = OUT
    b.write(name)


def white_sphere():
    b = Builder()
    b.doc["materials"] = [{"name": "white_matte", "pbrMetallicRoughness": {
        "baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}}]
    finish(b, [sphere_mesh(b, [0, 0, 0], 1.0, 0, "sphere")], "white_sphere.gltf")


def metal_spheres():
    b = Builder()
    rough = [0.15, 0.45, 0.8]
    b.doc["materials"] = [{"name": "gold_r%02d" % int(r * 100), "pbrMetallicRoughness": {
        "baseColorFactor": [1.0, 0.766, 0.336, 1.0], "metallicFactor": 1.0, "roughnessFactor": r}} for r in rough]
    meshes = [sphere_mesh(b, [x, 0, 0], 0.45, m, b.doc["materials"][m]["name"])
              for m, x in enumerate([-1.0, 0.0, 1.0])]
    finish(b, meshes, "metal_spheres.gltf", distance=5.0)


def textured():
    b = Builder()
    b.doc["materials"] = [{"name": "checker", "pbrMetallicRoughness": {
        "baseColorTexture": {"index": 0}, "metallicFactor": 0.0, "roughnessFactor": 0.6}}]
    image = png_rgba(2, 2, [[255, 0, 0, 255], [0, 255, 0, 255], [0, 0, 255, 255], [255, 255, 255, 255]])
    b.doc["images"] = [{"name": "checker", "mimeType": "image/png", "bufferView": b.view(image)}]
    b.doc["samplers"] = [{"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33071}]
    b.doc["textures"] = [{"sampler": 0, "source": 0}]
    tilt = math.radians(-25.0) / 2  # top edge leans away from the camera: it faces the key light more
    finish(b, [quad_mesh(b, [0, 0, 0], 1.1, 0, uvs=True, name="checker")], "textured.gltf",
           mesh_rotation=[math.sin(tilt), 0.0, 0.0, math.cos(tilt)])


def unlit():
    b = Builder()
    b.doc["extensionsUsed"] = ["KHR_materials_unlit"]
    b.doc["materials"] = [
        {"name": "orange_unlit", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.5, 0.1, 1.0]},
         "extensions": {"KHR_materials_unlit": {}}},
        {"name": "blue_emissive", "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0.0,
                                                           "roughnessFactor": 1.0},
         "emissiveFactor": [0.2, 0.5, 1.0]}]
    meshes = [quad_mesh(b, [-0.6, 0, 0], 0.5, 0, name="unlit", half_y=1.0),
              quad_mesh(b, [0.6, 0, 0], 0.5, 1, name="emissive", half_y=1.0)]
    finish(b, meshes, "unlit.gltf")


def glass():
    b = Builder()
    b.doc["extensionsUsed"] = ["KHR_materials_ior", "KHR_materials_transmission", "KHR_materials_volume"]
    glass_extensions = {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                        "KHR_materials_ior": {"ior": 1.5}, "KHR_materials_volume": {"thicknessFactor": 0.8}}
    b.doc["materials"] = [
        {"name": "checker", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0,
                                                     "roughnessFactor": 0.6}},
        {"name": "glass_smooth", "pbrMetallicRoughness": {"metallicFactor": 0.0, "roughnessFactor": 0.0},
         "extensions": glass_extensions},
        {"name": "glass_rough", "pbrMetallicRoughness": {"metallicFactor": 0.0, "roughnessFactor": 0.6},
         "extensions": glass_extensions}]
    image = png_rgba(2, 2, [[255, 0, 0, 255], [0, 255, 0, 255], [0, 0, 255, 255], [255, 255, 255, 255]])
    b.doc["images"] = [{"name": "checker", "mimeType": "image/png", "bufferView": b.view(image)}]
    b.doc["samplers"] = [{"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33071}]
    b.doc["textures"] = [{"sampler": 0, "source": 0}]
    meshes = [quad_mesh(b, [0, 0, -0.8], 1.3, 0, uvs=True, name="backdrop"),
              quad_mesh(b, [0, 0, 0], 0.5, 1, name="pane_smooth", half_y=0.4),
              quad_mesh(b, [0, 0, 0], 0.5, 2, name="pane_rough", half_y=0.4)]
    turn = math.radians(35.0) / 2
    panes = [{"translation": [0.0, y, 0.3], "rotation": [0.0, math.sin(turn), 0.0, math.cos(turn)]}
             for y in (0.55, -0.55)]
    finish(b, meshes, "glass.gltf", transforms=[None] + panes)


def main():
    os.makedirs(OUT, exist_ok=True)
    white_sphere()
    metal_spheres()
    textured()
    unlit()
    glass()


main()

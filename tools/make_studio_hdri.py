#!/usr/bin/env python3
"""Writes data/env/studio.hdr: the even, neutral studio environment of graphs/gltf.json (sky.hdri).

An equirectangular Radiance .hdr (256 x 128, flat RGBE scanlines), grey in every direction (R = G = B), in relative
units (the graph's sky.hdri `intensity` takes them to cd/m^2): 1.0 overhead, falling smoothly to 0.75 at the
horizon and to 0.4 straight down, with two broad soft "softbox" lobes (1.6x) high on either side of the +Z half that
the default view of scene.gltf looks from. No region is anywhere near 100x the median, so sky.hdri finds no sun in
it: the key light is the scene's sun (scene.gltf's key_light). Nothing is downloaded; run it again to regenerate:

    python3 tools/make_studio_hdri.py [OUT.hdr]
"""
import math
import os
import sys

WIDTH, HEIGHT = 256, 128


def radiance(d):
    x, y, z = d
    # Vertical gradient: smoothstep between the ground (0.4), the horizon (0.75) and the zenith (1.0).
    if y >= 0.0:
        t = y * y * (3.0 - 2.0 * y)
        base = 0.75 + 0.25 * t
    else:
        t = -y
        t = t * t * (3.0 - 2.0 * t)
        base = 0.75 - 0.35 * t
    # Two softboxes: broad cosine lobes 40 degrees up, 50 degrees either side of +Z.
    lobes = 0.0
    for side in (-1.0, 1.0):
        el, az = math.radians(40.0), math.radians(50.0) * side
        c = (math.cos(el) * math.sin(az), math.sin(el), math.cos(el) * math.cos(az))
        cos_angle = x * c[0] + y * c[1] + z * c[2]
        lobes += 0.6 * max(cos_angle, 0.0) ** 8
    return base + lobes


def direction(u, v):
    # sky.hdri's convention (core/shading/environment.cpp): the image centre looks down -Z, Y up.
    az = 2.0 * math.pi * u - math.pi
    el = math.pi / 2 - math.pi * v
    return (math.cos(el) * math.sin(az), math.sin(el), -math.cos(el) * math.cos(az))


def rgbe(value):
    if value < 1e-32:
        return bytes((0, 0, 0, 0))
    mantissa, exponent = math.frexp(value)
    m = int(mantissa * 256.0)
    return bytes((m, m, m, exponent + 128))


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(root, "data", "env", "studio.hdr")
    os.makedirs(os.path.dirname(out), exist_ok=True)
    rows = []
    for y in range(HEIGHT):
        row = bytearray()
        for x in range(WIDTH):
            row += rgbe(radiance(direction((x + 0.5) / WIDTH, (y + 0.5) / HEIGHT)))
        rows.append(bytes(row))
    header = b"#?RADIANCE\n# vitrine studio environment (tools/make_studio_hdri.py)\nFORMAT=32-bit_rle_rgbe\n\n"
    header += b"-Y %d +X %d\n" % (HEIGHT, WIDTH)
    with open(out, "wb") as f:
        f.write(header + b"".join(rows))
    print(out)


if __name__ == "__main__":
    main()

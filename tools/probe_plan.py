#!/usr/bin/env python3
"""Draws a floor plan (top view, x right, z down) of a scene's reflection probes as a PNG, to see where they are:
rooms as grey areas, each probe's influence volume as its outline (the box's 12 edges or the sphere's circle,
projected onto the floor) coloured by priority, the inside of its fade band as a thinner line, and its capture
point as a dot. Reads the probes of a .glb/.gltf (VITRINE_reflection_probes, core/scene/VITRINE_reflection_probes.md)
and/or a probe file ({"probes": [...]}); rooms come from the glTF scene's extras.vitrine.rooms.

    ./build/vitrine export-scene museum out/museum.glb
    python3 tools/probe_plan.py out/museum.glb --out out/museum_probes.png
    python3 tools/probe_plan.py out/museum.glb --probes my_probes.json --out out/plan.png   # the file's on top

Colours: priority 0 blue, 1 green, 2 red, others magenta; file probes (--probes) orange. Plain Python, no packages.
"""
import argparse
import json
import math
import struct
import sys
import zlib

COLOURS = {0: (40, 90, 220), 1: (20, 150, 60), 2: (210, 40, 40)}
OTHER, FILE_COLOUR, ROOM, BACKGROUND = (190, 40, 190), (240, 140, 0), (215, 215, 215), (255, 255, 255)


def gltf_json(path):
    data = open(path, "rb").read()
    if data[:4] == b"glTF":
        length = struct.unpack_from("<I", data, 12)[0]
        return json.loads(data[20:20 + length])
    return json.loads(data)


def rotate(q, v):
    x, y, z, w = q
    # v + 2 w (u × v) + 2 u × (u × v), u = (x, y, z)
    cx, cy, cz = y * v[2] - z * v[1], z * v[0] - x * v[2], x * v[1] - y * v[0]
    ccx, ccy, ccz = y * cz - z * cy, z * cx - x * cz, x * cy - y * cx
    return (v[0] + 2 * (w * cx + ccx), v[1] + 2 * (w * cy + ccy), v[2] + 2 * (w * cz + ccz))


class Canvas:
    def __init__(self, lo, hi, scale):
        self.lo, self.scale = lo, scale
        self.w, self.h = int((hi[0] - lo[0]) * scale) + 1, int((hi[1] - lo[1]) * scale) + 1
        self.px = bytearray(BACKGROUND * (self.w * self.h))

    def xy(self, x, z):
        return (x - self.lo[0]) * self.scale, (z - self.lo[1]) * self.scale

    def dot(self, x, y, colour, r=0):
        for j in range(-r, r + 1):
            for i in range(-r, r + 1):
                u, v = int(round(x)) + i, int(round(y)) + j
                if 0 <= u < self.w and 0 <= v < self.h and i * i + j * j <= r * r + r:
                    self.px[3 * (v * self.w + u):3 * (v * self.w + u) + 3] = bytes(colour)

    def line(self, a, b, colour, width=0):
        (x0, y0), (x1, y1) = self.xy(*a), self.xy(*b)
        n = int(max(abs(x1 - x0), abs(y1 - y0))) + 1
        for k in range(n + 1):
            t = k / n
            self.dot(x0 + (x1 - x0) * t, y0 + (y1 - y0) * t, colour, width)

    def rect(self, lo, hi, colour):
        (x0, y0), (x1, y1) = self.xy(*lo), self.xy(*hi)
        for v in range(max(0, int(y0)), min(self.h, int(y1) + 1)):
            for u in range(max(0, int(x0)), min(self.w, int(x1) + 1)):
                self.px[3 * (v * self.w + u):3 * (v * self.w + u) + 3] = bytes(colour)

    def png(self, path):
        raw = b"".join(b"\0" + bytes(self.px[3 * self.w * v:3 * self.w * (v + 1)]) for v in range(self.h))
        chunk = lambda kind, data: struct.pack(">I", len(data)) + kind + data + struct.pack(
            ">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
        header = struct.pack(">IIBBBBB", self.w, self.h, 8, 2, 0, 0, 0)
        with open(path, "wb") as f:
            f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 6)) +
                    chunk(b"IEND", b""))


def footprint(p, shrink=0.0):
    """Projected outline segments of the volume (shrunk by `shrink` metres), as ((x, z), (x, z)) pairs."""
    c = p.get("center", p["position"])
    if p.get("shape", "box") == "sphere":
        r = p["radius"] - shrink
        if r <= 0:
            return []
        pts = [(c[0] + r * math.cos(a * math.pi / 32), c[2] + r * math.sin(a * math.pi / 32)) for a in range(65)]
        return list(zip(pts, pts[1:]))
    h = [e - shrink for e in p["halfExtents"]]
    if min(h) <= 0:
        return []
    q = p.get("rotation", [0, 0, 0, 1])
    corner = lambda s: tuple(c[i] + rotate(q, (s[0] * h[0], s[1] * h[1], s[2] * h[2]))[i] for i in range(3))
    segs = []
    for axis in range(3):
        for a in (-1, 1):
            for b in (-1, 1):
                s0, s1 = [0, 0, 0], [0, 0, 0]
                others = [k for k in range(3) if k != axis]
                s0[others[0]] = s1[others[0]] = a
                s0[others[1]] = s1[others[1]] = b
                s0[axis], s1[axis] = -1, 1
                p0, p1 = corner(s0), corner(s1)
                segs.append(((p0[0], p0[2]), (p1[0], p1[2])))
    return segs


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", nargs="?", help=".glb or .gltf (rooms and probes)")
    ap.add_argument("--probes", help="a probe file drawn on top, in orange")
    ap.add_argument("--out", required=True, help="PNG to write")
    ap.add_argument("--scale", type=float, default=24.0, help="pixels per metre")
    args = ap.parse_args()
    rooms, probes = [], []
    if args.scene:
        scene = gltf_json(args.scene)["scenes"][0]
        rooms = scene.get("extras", {}).get("vitrine", {}).get("rooms", [])
        probes = [(p, None) for p in scene.get("extensions", {}).get("VITRINE_reflection_probes", {}).get("probes", [])]
    if args.probes:
        probes += [(p, FILE_COLOUR) for p in json.load(open(args.probes))["probes"]]
    if not probes and not rooms:
        sys.exit("probe_plan: nothing to draw (no rooms, no probes)")
    xs, zs = [], []
    for r in rooms:
        xs += [r["min"][0], r["max"][0]]
        zs += [r["min"][2], r["max"][2]]
    for p, _ in probes:
        for a, b in footprint(p):
            xs += [a[0], b[0]]
            zs += [a[1], b[1]]
    lo, hi = (min(xs) - 1, min(zs) - 1), (max(xs) + 1, max(zs) + 1)
    canvas = Canvas(lo, hi, args.scale)
    for r in rooms:
        canvas.rect((r["min"][0], r["min"][2]), (r["max"][0], r["max"][2]), ROOM)
    for p, colour in probes:
        colour = colour or COLOURS.get(p.get("priority", 0), OTHER)
        for a, b in footprint(p):
            canvas.line(a, b, colour, 1)
        light = tuple((c + 2 * 255) // 3 for c in colour)
        for a, b in footprint(p, p.get("fade", 0.5)):
            canvas.line(a, b, light, 0)
    for p, colour in probes:
        x, z = canvas.xy(p["position"][0], p["position"][2])
        canvas.dot(x, z, (0, 0, 0), 4)
        canvas.dot(x, z, colour or COLOURS.get(p.get("priority", 0), OTHER), 2)
    canvas.png(args.out)
    print(f"{args.out}: {len(rooms)} rooms, {len(probes)} probes, {canvas.w}x{canvas.h} px, x right, z down")


if __name__ == "__main__":
    main()

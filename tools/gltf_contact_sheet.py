#!/usr/bin/env python3
"""Render a folder of glTF models with graphs/gltf.json and tile the results into a contact sheet.

    python3 tools/gltf_contact_sheet.py MODELS_DIR --out OUT_DIR [--size 256] [--cols 4] [--vitrine build/vitrine]

MODELS_DIR holds one model per sub-folder (MODELS_DIR/Name/Name.gltf or .glb; else the first .gltf/.glb
in it), e.g. glTF-Sample-Assets' Models/<Name>/glTF-Embedded copied to MODELS_DIR/<Name>. Each model is
rendered one at a time (`vitrine run graphs/gltf.json --scene FILE --set frame.width=S --set frame.height=S
--out OUT_DIR/Name`); the script records the exit code, the `warning:` lines on stderr and the wall time in
OUT_DIR/results.json and results.md, and writes OUT_DIR/contact-sheet.png: one S x S tile per model with its
name (upper-cased, built-in 5x7 font) in a strip under it; a model that failed gets a dark red tile.
Pure Python (zlib + struct): no PIL or numpy needed. Run from the repository root.
"""
import argparse
import json
import os
import struct
import subprocess
import sys
import time
import zlib

# 5x7 glyphs, one string of 7 rows x 5 columns per character ('#' = ink).
FONT = {
    'A': ".###.#...##...#######...##...##...#", 'B': "####.#...##...#####.#...##...#####.",
    'C': ".###.#...##....#....#....#...#.###.", 'D': "####.#...##...##...##...##...#####.",
    'E': "######....#....####.#....#....#####", 'F': "######....#....####.#....#....#....",
    'G': ".###.#...##....#.####...##...#.####", 'H': "#...##...##...#######...##...##...#",
    'I': ".###...#....#....#....#....#...###.", 'J': "..###...#....#....#....##..#.##...",
    'K': "#...##..#.#.#..##...#.#..#..#.#...#", 'L': "#....#....#....#....#....#....#####",
    'M': "#...###.###.#.##...##...##...##...#", 'N': "#...###..##.#.##..###...##...##...#",
    'O': ".###.#...##...##...##...##...#.###.", 'P': "####.#...##...#####.#....#....#....",
    'Q': ".###.#...##...##...##.#.##..#..##.#", 'R': "####.#...##...#####.#.#..#..#.#...#",
    'S': ".#####....#.....###.....#....#####.", 'T': "#####..#....#....#....#....#....#..",
    'U': "#...##...##...##...##...##...#.###.", 'V': "#...##...##...##...##...#.#.#...#..",
    'W': "#...##...##...##.#.##.#.##.#.#.#.#.", 'X': "#...##...#.#.#...#...#.#.#...##...#",
    'Y': "#...##...#.#.#...#....#....#....#..", 'Z': "#####....#...#...#...#...#....#####",
    '0': ".###.#...##..###.#.###..##...#.###.", '1': "..#...##....#....#....#....#...###.",
    '2': ".###.#...#....#...#...#...#...#####", '3': "#####...#...#.....#....##...#.###.",
    '4': "...#...##..#.#.#..#.#####...#....#.", '5': "######....####.....#....##...#.###.",
    '6': "..##..#...#....####.#...##...#.###.", '7': "#####....#...#...#...#....#....#...",
    '8': ".###.#...##...#.###.#...##...#.###.", '9': ".###.#...##...#.####....#...#..##..",
    '-': "...............#####...............", '_': "..............................#####",
    '.': "..........................##...##..", ' ': "." * 35,
}


def read_png_rgb(path):
    """Decode an 8-bit RGB or RGBA non-interlaced PNG (what vitrine writes) to rows of RGB bytes."""
    data = open(path, 'rb').read()
    pos, idat = 8, b''
    while pos < len(data):
        n = struct.unpack('>I', data[pos:pos + 4])[0]
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + n]
        if kind == b'IHDR':
            w, h, depth, ctype, _, _, interlace = struct.unpack('>IIBBBBB', body)
            if depth != 8 or ctype not in (2, 6) or interlace:
                raise ValueError(f'{path}: only 8-bit RGB/RGBA non-interlaced PNGs are supported')
        elif kind == b'IDAT':
            idat += body
        pos += 12 + n
    bpp = 4 if ctype == 6 else 3
    raw = zlib.decompress(idat)
    stride = w * bpp
    rows, prev = [], bytearray(stride)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b = prev[x]
            c = prev[x - bpp] if x >= bpp else 0
            if f == 1:
                line[x] = (line[x] + a) & 255
            elif f == 2:
                line[x] = (line[x] + b) & 255
            elif f == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        prev = line
        rgb = bytearray(w * 3)
        for x in range(w):
            rgb[3 * x:3 * x + 3] = line[bpp * x:bpp * x + 3]
        rows.append(rgb)
    return w, h, rows


def write_png_rgb(path, w, rows):
    raw = b''.join(b'\x00' + bytes(r) for r in rows)
    def chunk(kind, body):
        return struct.pack('>I', len(body)) + kind + body + struct.pack('>I', zlib.crc32(kind + body) & 0xffffffff)
    with open(path, 'wb') as f:
        f.write(b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, len(rows), 8, 2, 0, 0, 0))
                + chunk(b'IDAT', zlib.compress(raw, 9)) + chunk(b'IEND', b''))


def draw_text(rows, x0, y0, text, scale=2, colour=(255, 255, 255)):
    for i, ch in enumerate(text.upper()):
        glyph = FONT.get(ch, FONT['.'])
        for gy in range(7):
            for gx in range(5):
                if glyph[gy * 5 + gx] != '#':
                    continue
                for sy in range(scale):
                    for sx in range(scale):
                        x = x0 + (i * 6 + gx) * scale + sx
                        y = y0 + gy * scale + sy
                        if 0 <= y < len(rows) and 0 <= x * 3 < len(rows[y]):
                            rows[y][3 * x:3 * x + 3] = bytes(colour)


def find_model(folder):
    name = os.path.basename(folder.rstrip('/'))
    for ext in ('.gltf', '.glb'):
        if os.path.isfile(os.path.join(folder, name + ext)):
            return os.path.join(folder, name + ext)
    for f in sorted(os.listdir(folder)):
        if f.endswith(('.gltf', '.glb')):
            return os.path.join(folder, f)
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument('models')
    ap.add_argument('--out', required=True)
    ap.add_argument('--size', type=int, default=256)
    ap.add_argument('--cols', type=int, default=4)
    ap.add_argument('--vitrine', default='build/vitrine')
    ap.add_argument('--graph', default='graphs/gltf.json')
    ap.add_argument('--no-render', action='store_true', help='reuse OUT/Name/final.png from an earlier run')
    args = ap.parse_args()

    os.makedirs(args.out, exist_ok=True)
    results = []
    for name in sorted(os.listdir(args.models)):
        folder = os.path.join(args.models, name)
        if not os.path.isdir(folder):
            continue
        model = find_model(folder)
        if model is None:
            continue
        out = os.path.join(args.out, name)
        entry = {'model': name, 'file': model}
        if not args.no_render:
            cmd = [args.vitrine, 'run', args.graph, '--scene', os.path.abspath(model),
                   '--set', f'frame.width={args.size}', '--set', f'frame.height={args.size}', '--out', out]
            t0 = time.time()
            proc = subprocess.run(cmd, capture_output=True, text=True)
            entry.update(rc=proc.returncode, wall_s=round(time.time() - t0, 1),
                         warnings=[l for l in proc.stderr.splitlines() if 'warning' in l.lower()],
                         errors=[] if proc.returncode == 0 else proc.stderr.strip().splitlines()[-3:])
            print(f"{name}: rc={proc.returncode} {entry['wall_s']} s, {len(entry['warnings'])} warning(s)",
                  file=sys.stderr)
        entry['png'] = os.path.join(out, 'final.png')
        results.append(entry)

    s, label_h = args.size, 24
    cols = max(1, min(args.cols, len(results)))
    nrows = (len(results) + cols - 1) // cols
    width = cols * s
    sheet = [bytearray(b'\x20' * (width * 3)) for _ in range(nrows * (s + label_h))]
    for i, e in enumerate(results):
        cx, cy = (i % cols) * s, (i // cols) * (s + label_h)
        tile = None
        if os.path.isfile(e['png']) and e.get('rc', 0) == 0:
            try:
                w, h, tile = read_png_rgb(e['png'])
                if (w, h) != (s, s):
                    tile = [tile[y * h // s][:] for y in range(s)]
                    tile = [bytearray(b''.join(bytes(r[3 * (x * w // s):3 * (x * w // s) + 3]) for x in range(s)))
                            for r in tile]
            except ValueError:
                tile = None
        for y in range(s):
            sheet[cy + y][3 * cx:3 * (cx + s)] = tile[y] if tile else b'\x60\x10\x10' * s
        scale = 2 if len(e['model']) * 12 <= s - 4 else 1
        label = e['model'][: max(1, (s - 4) // (6 * scale))]
        draw_text(sheet, cx + 4, cy + s + (5 if scale == 2 else 8), label, scale=scale)
    png = os.path.join(args.out, 'contact-sheet.png')
    write_png_rgb(png, width, sheet)

    with open(os.path.join(args.out, 'results.json'), 'w') as f:
        json.dump(results, f, indent=1)
    with open(os.path.join(args.out, 'results.md'), 'w') as f:
        f.write('| # | model | exit | warnings | wall (s) |\n|---|---|---|---|---|\n')
        for i, e in enumerate(results):
            f.write(f"| {i + 1} | {e['model']} | {e.get('rc', '')} | {len(e.get('warnings', []))} | "
                    f"{e.get('wall_s', '')} |\n")
    print(f'wrote {png} ({len(results)} tiles, {cols} per row)', file=sys.stderr)


if __name__ == '__main__':
    main()

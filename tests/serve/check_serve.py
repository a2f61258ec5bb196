#!/usr/bin/env python3
"""Tests of `vitrine serve` over HTTP, with the standard library only (no browser).

usage: check_serve.py VITRINE SOURCE_DIR

Starts the server on an ephemeral loopback port over a temporary copy of graphs/ (it never serves or writes the
source tree), and checks every API route's success and error cases: nodes equal `vitrine nodes --json`; the graph
list; GET -> PUT of a graph is byte-identical; path traversal refused (`../`, URL-encoded, absolute, a symlink out,
a graph whose image.load path, `extends` base or glTF buffer points outside the served directory); renders are PNGs
of the size asked for; validate reports the JSON pointer; compare returns the `vitrine compare` metrics and maps;
malformed JSON -> 400 with line and column; an oversize body -> 413; a graph that fails returns an error and the next
request works; a client that disconnects mid-render and two clients at once; progress as server-sent events;
with a --host other than the loopback default, requests without the token get 401. A second server instance
checks the token and the editor's static files. Ends with "N passed, M failed".
"""
import atexit
import hashlib
import http.client
import json
import os
import re
import shutil
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time
import traceback
import zlib

vitrine, source = sys.argv[1:3]
passed = 0
failed = []


def check(condition, what):
    global passed
    if condition:
        passed += 1
    else:
        failed.append(what)
        print("FAIL:", what, flush=True)


def js(payload):
    """The JSON of a reply body, {} when it is not JSON (a PNG where an error was expected)."""
    try:
        value = json.loads(payload)
        return value if isinstance(value, dict) else {}
    except ValueError:
        return {}


servers = []


@atexit.register
def stop_servers():
    for srv in servers:
        if srv.poll() is None:
            srv.kill()


def png_size(data):
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        return None
    return struct.unpack(">II", data[16:24])


def write_png(path, width, height, rgb):
    raw = b"".join(b"\x00" + bytes(rgb) * width for _ in range(height))

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def tree_digest(root):
    h = hashlib.sha256()
    for dirpath, dirs, files in sorted(os.walk(root)):
        dirs.sort()
        for name in sorted(files):
            path = os.path.join(dirpath, name)
            h.update(path.encode())
            with open(path, "rb") as f:
                h.update(f.read())
    return h.hexdigest()


class Server:
    def __init__(self, directory, *extra):
        self.proc = subprocess.Popen([vitrine, "serve", directory, "--port", "0", "--validate", *extra],
                                     stdout=subprocess.PIPE, text=True)
        servers.append(self.proc)
        self.url = None
        deadline = time.time() + 120
        while time.time() < deadline:
            line = self.proc.stdout.readline()
            if not line:
                break
            print("server:", line.rstrip(), flush=True)
            m = re.search(r"listening on http://([^/]+)/(\?token=(\w+))?", line)
            if m:
                self.host, port = m.group(1).rsplit(":", 1)
                self.port = int(port)
                self.token = m.group(3)
                self.url = m.group(0)
                break
        if not self.url:
            raise SystemExit("check_serve: the server did not start")
        threading.Thread(target=self.proc.stdout.read, daemon=True).start()

    def request(self, method, path, body=None, headers=None, timeout=600):
        conn = http.client.HTTPConnection(self.host, self.port, timeout=timeout)
        data = body if isinstance(body, (bytes, str)) or body is None else json.dumps(body)
        conn.request(method, path, body=data, headers=headers or {})
        r = conn.getresponse()
        payload = r.read()
        conn.close()
        return r, payload

    def json(self, method, path, body=None, headers=None):
        r, payload = self.request(method, path, body, headers)
        return r, js(payload)

    def stop(self):
        self.proc.send_signal(signal.SIGTERM)
        try:
            return self.proc.wait(timeout=120)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            return None


work = tempfile.mkdtemp(prefix="vitrine-serve-test-")
served = os.path.join(work, "served")
outside = os.path.join(work, "outside")
os.makedirs(outside)
shutil.copytree(os.path.join(source, "graphs"), os.path.join(served, "graphs"))
os.makedirs(os.path.join(served, "images"))
write_png(os.path.join(served, "images", "inside.png"), 12, 8, (200, 40, 40))
write_png(os.path.join(outside, "secret.png"), 12, 8, (10, 200, 10))
shutil.copy(os.path.join(source, "graphs", "fxaa_zoneplate.json"), os.path.join(outside, "graph.json"))
with open(os.path.join(outside, "x.bin"), "wb") as f:
    f.write(b"\0" * 64)
gdir = os.path.join(served, "graphs")


def write_graph(name, doc):
    with open(os.path.join(gdir, name), "w") as f:
        json.dump(doc, f)


def image_graph(path):
    return {"frame": {"width": 12, "height": 8},
            "nodes": {"img": {"type": "image.load", "params": {"path": path}},
                      "tonemap": {"type": "post.tonemap", "in": {"color": "img.color"}}},
            "outputs": {"final": "tonemap.color"}}


write_graph("image_inside.json", image_graph("../images/inside.png"))
write_graph("image_outside.json", image_graph(os.path.relpath(os.path.join(outside, "secret.png"), gdir)))
write_graph("image_absolute.json", image_graph(os.path.join(outside, "secret.png")))
write_graph("image_missing.json", image_graph("../images/missing.png"))
write_graph("bad_type.json", {"frame": {"width": 8, "height": 8},
                              "nodes": {"x": {"type": "no.such_node"}}, "outputs": {"final": "x.color"}})
write_graph("extends_outside.json", {"extends": os.path.relpath(os.path.join(outside, "graph.json"), gdir)})
os.symlink(os.path.join(outside, "graph.json"), os.path.join(gdir, "link_out.json"))
os.symlink(outside, os.path.join(served, "linkdir"))
os.makedirs(os.path.join(served, "scene"))
with open(os.path.join(served, "scene", "evil.gltf"), "w") as f:
    json.dump({"asset": {"version": "2.0"}, "buffers": [{"uri": "../../outside/x.bin", "byteLength": 64}]}, f)
outside_digest = tree_digest(outside)

with open(os.path.join(gdir, "fxaa_zoneplate.json"), "rb") as f:
    zoneplate_bytes = f.read()
zoneplate = json.loads(zoneplate_bytes)

def main():
    global server
    server = Server(served, "--max-body", "1000000", "--editor", os.path.join(work, "no-editor"))
    print("checking", server.url, flush=True)

    # Status, nodes, graphs list.
    r, body = server.json("GET", "/api/status")
    check(r.status == 200 and body.get("format") == "vitrine-serve/1", "GET /api/status")
    nodes_cli = subprocess.run([vitrine, "nodes", "--json"], check=True, capture_output=True).stdout
    r, payload = server.request("GET", "/api/nodes")
    check(r.status == 200 and payload == nodes_cli, "GET /api/nodes equals `vitrine nodes --json` byte for byte")
    r, payload = server.request("GET", "/api/schema")
    check(r.status == 200 and "$schema" in json.loads(payload), "GET /api/schema")
    r, body = server.json("GET", "/api/graphs")
    listed = {g["path"]: g for g in body.get("graphs", [])}
    check(r.status == 200 and listed.get("graphs/fxaa_zoneplate.json", {}).get("kind") == "graph",
          "GET /api/graphs lists graphs/fxaa_zoneplate.json as a graph")
    check(listed.get("graphs/variants/no_fxaa.json", {}).get("kind") == "variant",
          "GET /api/graphs lists graphs/variants/no_fxaa.json as a variant")
    check("graphs/vitrine-graph.schema.json" not in listed, "GET /api/graphs leaves out the schema")
    check("graphs/link_out.json" not in listed and not any(p.startswith("linkdir") for p in listed),
          "GET /api/graphs leaves out files behind symlinks out of DIR")

    r, body = server.json("GET", "/api/files?ext=png,.GLTF")
    files = body.get("files", [])
    check(r.status == 200 and "images/inside.png" in files and "scene/evil.gltf" in files and
          not any(f.endswith(".json") for f in files), f"GET /api/files?ext= lists those extensions ({files[:6]})")
    check(not any(f.startswith("linkdir") for f in files) and "graphs/link_out.json" not in files,
          "GET /api/files leaves out files behind symlinks out of DIR")
    r, body = server.json("GET", "/api/files")
    check(r.status == 200 and "graphs/fxaa_zoneplate.json" in body.get("files", []), "GET /api/files lists every file")

    # GET -> PUT round trip, byte-identical; new files; malformed bodies.
    r, payload = server.request("GET", "/api/graphs/graphs/fxaa_zoneplate.json")
    check(r.status == 200 and payload == zoneplate_bytes, "GET a graph returns its bytes")
    r, body = server.json("PUT", "/api/graphs/graphs/fxaa_zoneplate.json", payload)
    with open(os.path.join(gdir, "fxaa_zoneplate.json"), "rb") as f:
        check(r.status == 200 and f.read() == zoneplate_bytes, "PUT of what GET returned leaves the file byte-identical")
    r, payload2 = server.request("GET", "/api/graphs/graphs/fxaa_zoneplate.json")
    check(payload2 == zoneplate_bytes, "GET after PUT is byte-identical")
    r, body = server.json("PUT", "/api/graphs/graphs/new/copy.json", zoneplate_bytes)
    check(r.status == 201 and os.path.isfile(os.path.join(gdir, "new", "copy.json")), "PUT creates a new graph file")
    check(not [n for n in os.listdir(os.path.join(gdir, "new")) if n != "copy.json"], "PUT leaves no temporary file")
    r, body = server.json("PUT", "/api/graphs/graphs/fxaa_zoneplate.json", b'{"nodes": {,}}')
    with open(os.path.join(gdir, "fxaa_zoneplate.json"), "rb") as f:
        check(r.status == 400 and body.get("line") == 1 and body.get("column", 0) > 1 and f.read() == zoneplate_bytes,
              "PUT of malformed JSON: 400 with line and column, file unchanged")
    r, _ = server.request("GET", "/api/graphs/graphs/nope.json")
    check(r.status == 404, "GET of a missing graph: 404")

    # Path traversal, every way.
    for path in ["/api/graphs/../outside/graph.json", "/api/graphs/graphs/../../outside/graph.json",
                 "/api/graphs/%2e%2e/outside/graph.json", "/api/graphs/graphs%2f..%2f..%2foutside%2fgraph.json",
                 "/api/graphs//etc/passwd", "/api/graphs/%2fetc%2fpasswd", "/api/graphs/graphs/link_out.json",
                 "/api/graphs/linkdir/graph.json"]:
        r, body = server.json("GET", path)
        check(r.status in (400, 403) and "refused" in body.get("error", ""), f"GET {path} refused ({r.status})")
    for path in ["/api/graphs/../outside/new.json", "/api/graphs/%2e%2e/outside/graph.json",
                 "/api/graphs/linkdir/graph.json", "/api/graphs/linkdir/new.json", "/api/graphs/graphs/link_out.json",
                 "/api/graphs//tmp/x.json", "/api/graphs/graphs/x.txt"]:
        r, body = server.json("PUT", path, b"{}")
        check(r.status in (400, 403), f"PUT {path} refused ({r.status})")
    check(tree_digest(outside) == outside_digest, "nothing outside DIR was written")


    def render(body, **headers):
        return server.request("POST", "/api/render", json.dumps(body), headers)


    for name in ["image_outside.json", "image_absolute.json", "extends_outside.json", "link_out.json"]:
        r, payload = render({"graph": "graphs/" + name})
        body = js(payload)
        check(r.status == 403 and "refused" in body.get("error", ""), f"render {name} refused ({r.status}: {body})")
    r, payload = render({"graph": "graphs/image_outside.json"})
    check("/nodes/img/params/path" in js(payload).get("pointer", ""), "the refusal names the param's pointer")
    gltf_graph = {"frame": {"width": 16, "height": 16},
                  "nodes": {"scene": {"type": "scene.gltf", "params": {"path": "../scene/evil.gltf"}},
                            "gbuffer": {"type": "gbuffer.layered", "in": {"scene": "scene.scene"}}},
                  "outputs": {"final": "gbuffer.base_color"}}
    r, payload = render({"document": gltf_graph, "base": "graphs/inline.json"})
    check(r.status == 403 and "/buffers/0/uri" in js(payload).get("error", ""),
          "render of a glTF whose buffer URI leaves DIR refused")
    r, payload = render({"document": {"extends": "../../outside/graph.json"}, "base": "graphs/v.json"})
    check(r.status == 403, "inline document whose extends leaves DIR refused")
    r, payload = render({"graph": "graphs/image_inside.json"})
    check(r.status == 200 and png_size(payload) == (12, 8), "render of image.load inside DIR works (12x8)")

    # Renders: sizes, warm re-render, node outputs, variants, inline documents, async.
    r, png1 = render({"graph": "graphs/fxaa_zoneplate.json", "width": 160, "height": 90})
    check(r.status == 200 and r.getheader("Content-Type") == "image/png" and png_size(png1) == (160, 90),
          "render returns a 160x90 PNG")
    check(r.getheader("X-Vitrine-Validation-Messages") == "0", "no Vulkan validation messages")
    r, png2 = render({"graph": "graphs/fxaa_zoneplate.json", "width": 160, "height": 90})
    check(r.getheader("X-Vitrine-Warm") == "1" and png2 == png1, "the same render again is warm and identical")
    r, png3 = render({"graph": "graphs/fxaa_zoneplate.json", "width": 160, "height": 90, "output": "pattern.color"})
    check(r.status == 200 and png_size(png3) == (160, 90) and png3 != png1 and
          r.getheader("X-Vitrine-Output") == "preview", "render of a node output (pattern.color)")
    r, png4 = render({"graph": "graphs/variants/no_fxaa.json", "width": 160, "height": 90})
    check(r.status == 200 and png_size(png4) == (160, 90) and png4 != png1, "render of a variant")
    with open(os.path.join(gdir, "variants", "no_fxaa.json")) as f:
        variant = json.load(f)
    r, payload = render({"document": variant, "base": "graphs/variants/no_fxaa.json", "width": 160, "height": 90})
    check(r.status == 200 and payload == png4, "an inline variant (extends resolved from its base) renders as the file")
    doc = json.loads(zoneplate_bytes)
    doc["nodes"]["fxaa"]["params"] = {"subpix": 0.0}
    r, png5 = render({"document": doc, "base": "graphs/fxaa_zoneplate.json", "width": 160, "height": 90})
    check(r.status == 200 and png_size(png5) == (160, 90) and png5 != png1, "render of an edited inline document")
    r, png6 = render({"graph": "graphs/fxaa_zoneplate.json", "set": ["fxaa.params.subpix=0.0"], "width": 160,
                      "height": 90})
    check(png6 == png5, "\"set\" renders like the same edit inline")
    r, body = server.json("POST", "/api/render", {"graph": "graphs/fxaa_zoneplate.json", "width": 64, "height": 32,
                                                  "async": True})
    check(r.status == 202 and "image" in body, "async render answers 202 with an image id")
    for _ in range(600):
        r, payload = server.request("GET", "/api/images/" + body.get("image", "0"))
        if r.status != 202:
            break
        time.sleep(0.1)
    check(r.status == 200 and png_size(payload) == (64, 32), "async render's image is a 64x32 PNG")
    r, _ = server.request("GET", "/api/images/999999")
    check(r.status == 404, "unknown image: 404")

    def wait_image(url):
        for _ in range(1200):
            r, payload = server.request("GET", url)
            if r.status != 202:
                return r, payload
            time.sleep(0.1)
        return r, payload

    # Several outputs of one run at once (the editor's thumbnails): each the same PNG as rendering it alone.
    r, body = server.json("POST", "/api/render", {"graph": "graphs/fxaa_zoneplate.json", "width": 160, "height": 90,
                                                  "outputs": ["final", "pattern.color"]})
    urls = body.get("images", {}) if r.status == 200 else {}
    check(r.status == 200 and sorted(urls) == ["final", "pattern.color"], f"render of two outputs at once ({body})")
    if sorted(urls) == ["final", "pattern.color"]:
        _, final = server.request("GET", urls["final"])
        _, pattern = server.request("GET", urls["pattern.color"])
        check(final == png1 and pattern == png3, "each of several outputs equals its render alone")
    # "display": "thumbnail" exposes HDR values instead of clipping them to white; values up to 1 are left alone.
    bright = json.loads(zoneplate_bytes)
    bright["nodes"]["tonemap"]["params"] = {"operator": "reinhard", "inverse": True}  # [0, 1] -> [0, inf)
    hdr = {"document": bright, "base": "graphs/fxaa_zoneplate.json", "width": 160, "height": 90}
    r, clipped = render(hdr)
    r2, thumb = render(dict(hdr, display="thumbnail"))
    _, plain_thumb = render({"graph": "graphs/fxaa_zoneplate.json", "width": 160, "height": 90,
                             "display": "thumbnail"})
    check(r.status == 200 and r2.status == 200 and thumb != clipped and plain_thumb == png1,
          "display=thumbnail tone-maps an HDR output and leaves a display-range one as it is")
    r, body = server.json("POST", "/api/render", dict(hdr, display="fancy"))
    check(r.status == 400 and body.get("pointer") == "/display", "an unknown display: 400")
    r, body = server.json("POST", "/api/render", {"graph": "graphs/fxaa_zoneplate.json", "outputs": ["nope"]})
    check(r.status == 400 and body.get("pointer") == "/outputs/0", f"an unknown preview output: 400 ({body})")
    r, body = server.json("POST", "/api/render", {"graph": "graphs/fxaa_zoneplate.json", "outputs": []})
    check(r.status == 400 and body.get("pointer") == "/outputs", "an empty outputs list: 400")

    # A tagged render replaces the queued one with the same tag that has not started (a newer edit's previews).
    busy = {"graph": "graphs/fxaa_zoneplate.json", "width": 1280, "height": 720, "frames": 16, "async": True}
    r, blocker = server.json("POST", "/api/render", busy)
    first = {"graph": "graphs/fxaa_zoneplate.json", "width": 64, "height": 32, "async": True, "tag": "previews",
             "outputs": ["final", "pattern.color"]}
    r1, old = server.json("POST", "/api/render", first)
    r2, new = server.json("POST", "/api/render", dict(first, set=["fxaa.params.subpix=0.0"]))
    check(r1.status == 202 and r2.status == 202 and len(old.get("images", {})) == 2, "tagged async renders: 202")
    ra, body = server.json("GET", old.get("images", {}).get("final", "/api/images/0"))
    check(ra.status == 409 and body.get("superseded") is True, f"the superseded render's image: 409 ({ra.status})")
    rb, payload = wait_image(new.get("images", {}).get("pattern.color", "/api/images/0"))
    check(rb.status == 200 and png_size(payload) == (64, 32), "the newer tagged render is done")
    rc, _ = wait_image(blocker.get("url", "/api/images/0"))
    check(rc.status == 200, "the untagged render before them is done")

    # Validate.
    r, body = server.json("POST", "/api/validate", {"graph": "graphs/fxaa_zoneplate.json"})
    check(r.status == 200 and body.get("ok") is True and body.get("passes") == 3, "validate a good graph")
    r, body = server.json("POST", "/api/validate", {"graph": "graphs/bad_type.json"})
    check(body.get("ok") is False and body["errors"][0].get("pointer") == "/nodes/x/type" and
          body["errors"][0].get("file") == "graphs/bad_type.json", f"validate names file and pointer ({body})")
    bad = json.loads(zoneplate_bytes)
    bad["nodes"]["fxaa"]["params"] = {"subpix": "lots"}
    r, body = server.json("POST", "/api/validate", {"document": bad, "base": "graphs/fxaa_zoneplate.json"})
    check(body.get("ok") is False and body["errors"][0].get("pointer") == "/nodes/fxaa/params/subpix",
          f"validate points at a wrong param ({body})")
    # Every error at once, each with its pointer (the editor marks them all).
    bad["nodes"]["fxaa"]["params"] = {"subpix": "lots", "edge_threshold_min": -1}
    bad["nodes"]["fxaa"]["in"] = {"color": "pattern.nope"}
    r, body = server.json("POST", "/api/validate", {"document": bad, "base": "graphs/fxaa_zoneplate.json"})
    pointers = sorted(e.get("pointer") for e in body.get("errors", []))
    check(body.get("ok") is False and pointers == ["/nodes/fxaa/in/color", "/nodes/fxaa/params/edge_threshold_min",
                                                   "/nodes/fxaa/params/subpix"],
          f"validate reports every error with its pointer ({pointers})")
    r, body = server.json("POST", "/api/validate", {"graph": "graphs/image_outside.json"})
    check(body.get("ok") is False and "refused" in body["errors"][0]["error"], "validate reports a path outside DIR")

    # Compare.
    r, body = server.json("POST", "/api/compare", {"a": "graphs/fxaa_zoneplate.json", "b": "graphs/variants/no_fxaa.json",
                                                   "width": 160, "height": 90})
    pair = body.get("metrics", {}).get("pairs", [{}])[0]
    check(r.status == 200 and pair.get("flip", {}).get("mean", 0) > 0 and pair.get("psnr") is not None,
          f"compare A/B: FLIP mean {pair.get('flip', {}).get('mean')}, PSNR {pair.get('psnr')}")
    check(any(c.get("pointer", "").startswith("/nodes/") for c in body.get("metrics", {}).get("graphChanges", [])),
          "compare lists the graph changes")
    for key in ["a", "b", "diff", "flip"]:
        r, payload = server.request("GET", body.get("images", {}).get(key, "/api/images/0"))
        check(r.status == 200 and png_size(payload) == (160, 90), f"compare image {key} is a 160x90 PNG")
    r, body = server.json("POST", "/api/compare", {"a": "graphs/fxaa_zoneplate.json", "b": "graphs/fxaa_zoneplate.json",
                                                   "width": 80, "height": 45})
    check(r.status == 200 and body["metrics"]["pairs"][0]["psnr"] is None, "compare of a graph with itself: identical")
    r, body = server.json("POST", "/api/compare", {"a": "graphs/fxaa_zoneplate.json"})
    check(r.status == 400 and body.get("pointer") == "/b", "compare without B: 400 pointing at /b")

    # Malformed requests, oversize bodies.
    r, body = server.json("POST", "/api/render", b'{"graph": "graphs/fxaa_zoneplate.json",}')
    check(r.status == 400 and body.get("line") == 1 and body.get("column") and "pointer" in body,
          f"malformed JSON: 400 with line and column ({body})")
    r, body = server.json("POST", "/api/render", {"graph": 5})
    check(r.status == 400 and body.get("pointer") == "/graph", "a field of the wrong type: 400 with its pointer")
    r, body = server.json("POST", "/api/render", {"graph": "graphs/fxaa_zoneplate.json", "width": "wide"})
    check(r.status == 400 and body.get("pointer") == "/width", "a bad width: 400 with its pointer")
    r, body = server.json("POST", "/api/render", {"graph": "graphs/fxaa_zoneplate.json", "width": 100000})
    check(r.status == 400 and body.get("pointer") == "/width", "an oversize preview: 400")
    r, body = server.json("POST", "/api/render", b"[1, 2]")
    check(r.status == 400, "a body that is not an object: 400")
    r, _ = server.request("POST", "/api/render", b"{" + b" " * 2_000_000 + b"}")
    check(r.status == 413, f"a body over --max-body: 413 ({r.status})")
    r, body = server.json("GET", "/api/nope")
    check(r.status == 404, "unknown API route: 404")

    # Failing graphs return errors; the server goes on.
    r, body = server.json("POST", "/api/render", {"graph": "graphs/bad_type.json"})
    check(r.status == 422 and body.get("pointer") == "/nodes/x/type", "a graph failing validation: 422 with pointer")
    r, body = server.json("POST", "/api/render", {"graph": "graphs/image_missing.json"})
    check(r.status == 422 and "/nodes/img/params/path" in body.get("error", ""),
          f"a graph failing in a node's setup: 422 ({body.get('error')})")
    r, payload = render({"graph": "graphs/fxaa_zoneplate.json", "width": 160, "height": 90})
    check(r.status == 200 and payload == png1, "the next render after failures works")

    # Progress events (server-sent events), read while renders run.
    events = []


    def read_events():
        conn = http.client.HTTPConnection(server.host, server.port, timeout=600)
        conn.request("GET", "/api/events")
        resp = conn.getresponse()
        events.append(("status", resp.status, resp.getheader("Content-Type")))
        for line in resp:
            line = line.decode().rstrip("\n")
            if line.startswith("data: "):
                events.append(json.loads(line[6:]))
                if events[-1].get("stage") == "done" and events[-1].get("kind") == "render":
                    break
        conn.close()


    reader = threading.Thread(target=read_events)
    reader.start()
    time.sleep(0.5)
    render({"graph": "graphs/fxaa_zoneplate.json", "width": 96, "height": 54, "frames": 3})
    reader.join(timeout=120)
    stages = [e.get("stage") for e in events[1:] if isinstance(e, dict)]
    check(events and events[0][1] == 200 and events[0][2].startswith("text/event-stream"), "GET /api/events streams")
    check("compiling" in stages and stages.count("rendering") == 3 and "done" in stages,
          f"events: compiling, 3 frames rendering, done ({stages})")

    # A client that disconnects mid-render (seen rendering in the events), and one that drops its event stream.
    slow_events = []
    slow_frames = 24
    slow = json.dumps({"graph": "graphs/fxaa_zoneplate.json", "width": 1280, "height": 720,
                       "frames": slow_frames}).encode()
    s = socket.create_connection((server.host, server.port))
    left_at = []

    def watch_slow():
        # Sends the render, and closes its connection as soon as the first frame is reported (from this thread, so
        # that the job is still running even on a fast GPU).
        conn = http.client.HTTPConnection(server.host, server.port, timeout=600)
        conn.request("GET", "/api/events")
        stream = conn.getresponse()
        s.sendall(b"POST /api/render HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
                  b"Content-Length: " + str(len(slow)).encode() + b"\r\n\r\n" + slow)
        for line in stream:
            line = line.decode().rstrip("\n")
            if line.startswith("data: "):
                slow_events.append(json.loads(line[6:]))
                if slow_events[-1].get("stage") == "rendering" and not left_at:
                    s.close()
                    left_at.append(len(slow_events))
                if slow_events[-1].get("stage") in ("done", "error") and slow_events[-1].get("kind") == "render":
                    break
        conn.close()

    watcher = threading.Thread(target=watch_slow)
    watcher.start()
    watcher.join(timeout=300)
    e = socket.create_connection((server.host, server.port))
    e.sendall(b"GET /api/events HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
    time.sleep(0.2)
    e.close()
    slow_stages = [(ev.get("stage"), ev.get("done")) for ev in slow_events]
    check(left_at and ("rendering", slow_frames) in slow_stages[left_at[0]:] and slow_stages[-1][0] == "done",
          f"the client left after frame 1 of {slow_frames}; the job went on to the end "
          f"({slow_events[-1].get('ms', 0) if slow_events else 0:.0f} ms)")
    r, body = server.json("GET", "/api/status")
    check(r.status == 200 and server.proc.poll() is None, "the server answers after a client left mid-render")
    r, payload = render({"graph": "graphs/fxaa_zoneplate.json", "width": 160, "height": 90})
    check(r.status == 200 and payload == png1, "renders work after a client left mid-render")

    # Two clients at once get their own results.
    results = {}


    def client(key, body):
        results[key] = render(body)


    threads = [threading.Thread(target=client, args=("a", {"graph": "graphs/fxaa_zoneplate.json", "width": 160,
                                                             "height": 90})),
               threading.Thread(target=client, args=("b", {"graph": "graphs/variants/no_fxaa.json", "width": 120,
                                                             "height": 80}))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    check(results["a"][0].status == 200 and results["a"][1] == png1, "concurrent client A gets its own image")
    check(results["b"][0].status == 200 and png_size(results["b"][1]) == (120, 80),
          "concurrent client B gets its own image (120x80)")

    # Loopback-only names, other sites' pages, the placeholder page.
    r, _ = server.request("GET", "/api/status", headers={"Host": "evil.example:80"})
    check(r.status == 403, "a Host header that is not the loopback: 403 (DNS rebinding)")
    r, _ = server.request("POST", "/api/validate", b"{}", {"Origin": "http://evil.example"})
    check(r.status == 403, "a request from another site's page (Origin): 403")
    r, payload = server.request("GET", "/")
    check(r.status == 200 and b"npm --prefix editor" in payload, "GET / without a built editor: the placeholder page")
    check(server.stop() == 0, "the server stops cleanly on SIGTERM")
    check(tree_digest(outside) == outside_digest, "nothing outside DIR was written (end)")

    # --host other than the loopback default: a token on every request; the editor's static files.
    dist = os.path.join(work, "dist")
    os.makedirs(os.path.join(dist, "assets"))
    with open(os.path.join(dist, "index.html"), "w") as f:
        f.write("<!doctype html><title>editor</title>")
    with open(os.path.join(dist, "assets", "app.js"), "w") as f:
        f.write("console.log('editor');")
    server = Server(served, "--host", "127.0.0.2", "--editor", dist)
    check(server.token is not None and len(server.token) >= 32, "--host prints a URL with an access token")
    for path in ["/", "/assets/app.js", "/api/nodes", "/api/events", "/api/graphs/graphs/fxaa_zoneplate.json"]:
        r, _ = server.request("GET", path, timeout=10)
        check(r.status == 401, f"GET {path} without the token: 401")
    r, _ = server.request("GET", "/api/nodes?token=wrong")
    check(r.status == 401, "a wrong token: 401")
    r, payload = server.request("GET", "/?token=" + server.token)
    cookie = r.getheader("Set-Cookie", "")
    check(r.status == 200 and b"<title>editor</title>" in payload, "GET /?token=... serves the editor's index.html")
    check(cookie.startswith("vitrine_token=") and "HttpOnly" in cookie, "the token is kept as a cookie")
    r, payload = server.request("GET", "/assets/app.js", headers={"Cookie": cookie.split(";")[0]})
    check(r.status == 200 and r.getheader("Content-Type") == "text/javascript", "static files with the cookie")
    r, payload = server.request("GET", "/api/nodes", headers={"Authorization": "token " + server.token})
    check(r.status == 200 and payload == nodes_cli, "Authorization: token ... works")
    r, payload = server.request("POST", "/api/render", json.dumps({"graph": "graphs/fxaa_zoneplate.json", "width": 160,
                                                                    "height": 90}),
                                {"Authorization": "token " + server.token})
    check(r.status == 200 and payload == png1, "render with the token")
    r, _ = server.request("GET", "/..%2f..%2foutside%2fsecret.png", headers={"Authorization": "token " + server.token})
    check(r.status in (403, 404), "static files cannot leave the editor's directory")
    check(server.stop() == 0, "the token server stops cleanly")


try:
    main()
except Exception:
    traceback.print_exc()
    failed.append("the test script stopped on an exception")

shutil.rmtree(work, ignore_errors=True)
print(f"{passed} passed, {len(failed)} failed")
sys.exit(1 if failed else 0)

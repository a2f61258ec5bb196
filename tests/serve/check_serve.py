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
checks the token and the editor's static files, a third --no-token. Issue #27's checks run first
(security_checks: the loopback token, Host and Origin, headers, 415, chunked bodies past --max-body, where PUT
writes, ETag/If-Match, every path param of every node pointed out of DIR, event streams that must not starve the
API); VITRINE_SERVE_CHECKS=security runs only those. Ends with "N passed, M failed".
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
    def __init__(self, directory, *extra, stderr=None):
        self.proc = subprocess.Popen([vitrine, "serve", directory, "--port", "0", "--validate", *extra],
                                     stdout=subprocess.PIPE, stderr=stderr, text=True)
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

    def auth(self):
        """The header that carries the access token (none when the server printed none)."""
        return {"Authorization": "token " + self.token} if self.token else {}

    def request(self, method, path, body=None, headers=None, timeout=600, auth=True):
        """A request with the token (unless auth=False) and, when it has a body, Content-Type: application/json
        (unless headers name one)."""
        conn = http.client.HTTPConnection(self.host, self.port, timeout=timeout)
        data = body if isinstance(body, (bytes, str)) or body is None else json.dumps(body)
        sent = dict(self.auth()) if auth else {}
        if data is not None:
            sent["Content-Type"] = "application/json"
        sent.update(headers or {})
        conn.request(method, path, body=data, headers=sent)
        r = conn.getresponse()
        payload = r.read()
        conn.close()
        return r, payload

    def status_only(self, method, path, headers=None, auth=True, timeout=30):
        """The status and JSON body of a request that may stream (the event stream): the body is read only when the
        answer is not a stream."""
        conn = http.client.HTTPConnection(self.host, self.port, timeout=timeout)
        conn.request(method, path, headers=dict(self.auth() if auth else {}, **(headers or {})))
        r = conn.getresponse()
        body = {} if (r.getheader("Content-Type") or "").startswith("text/event-stream") else js(r.read())
        conn.close()
        return r, body

    def json(self, method, path, body=None, headers=None, auth=True):
        r, payload = self.request(method, path, body, headers, auth=auth)
        return r, js(payload)

    def raw(self, head, body_chunks=(), read_timeout=120):
        """Sends HEAD (request line and headers, without the final blank line; Host and the token are added) and
        BODY_CHUNKS from a thread over a raw socket, and reads the response while it sends: (status, headers, body)
        of the first response. Sending stops quietly when the server closes the connection."""
        s = socket.create_connection((self.host, self.port))
        s.settimeout(read_timeout)
        extra = f"Host: {self.host}:{self.port}\r\n"
        if self.token:
            extra += f"Authorization: token {self.token}\r\n"

        def send():
            try:
                s.sendall((head + extra + "\r\n").encode())
                for chunk in body_chunks:
                    s.sendall(chunk)
            except OSError:
                pass

        sender = threading.Thread(target=send, daemon=True)
        sender.start()
        data = b""
        try:
            while b"\r\n\r\n" not in data:
                more = s.recv(65536)
                if not more:
                    break
                data += more
            head_bytes, _, rest = data.partition(b"\r\n\r\n")
            lines = head_bytes.decode(errors="replace").split("\r\n")
            status = int(lines[0].split()[1]) if lines and len(lines[0].split()) > 1 else 0
            headers = {k.strip().lower(): v.strip() for k, _, v in (l.partition(":") for l in lines[1:])}
            length = int(headers.get("content-length", "0"))
            while len(rest) < length:
                more = s.recv(65536)
                if not more:
                    break
                rest += more
        except OSError:
            status, headers, rest = 0, {}, b""
        s.close()
        sender.join(timeout=30)
        return status, headers, rest[:int(headers.get("content-length", len(rest)) or 0)]

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
# Files an attack would like to read or write: a JSON file outside DIR with a marker that must never come back in
# an answer, a repository's .git/, node_modules/ and the editor's own sources inside DIR.
SECRET = "SECRET-7f3a9c-do-not-echo"
with open(os.path.join(outside, "secret.json"), "w") as f:
    json.dump({"format": SECRET, "name": SECRET, "token": SECRET}, f)
os.makedirs(os.path.join(served, ".git"))
with open(os.path.join(served, ".git", "config"), "w") as f:
    f.write("[core]\n")
os.makedirs(os.path.join(served, "node_modules", "pkg"))
os.makedirs(os.path.join(served, "editor", "src"))
with open(os.path.join(served, "editor", "package.json"), "w") as f:
    f.write('{"name": "vitrine-editor"}\n')
outside_digest = tree_digest(outside)

with open(os.path.join(gdir, "fxaa_zoneplate.json"), "rb") as f:
    zoneplate_bytes = f.read()
zoneplate = json.loads(zoneplate_bytes)

FILE_EXTENSIONS = re.compile(r"\.(json|cube|exr|hdr|png|jpe?g|glb|gltf|ocio|txt)\b", re.I)
FILE_NAMES = {"lens", "file", "path", "lut", "scene", "gltf", "probes", "filename"}


def path_param_checks(nodes):
    """Every param that names a file is a `path` kind (so that the served directory confines it)."""
    wrong = []
    for node in nodes:
        for p in node.get("params", []):
            if p.get("type") != "string":  # path already; numbers, enums and vectors name no file
                continue
            default = p.get("default")
            looks = (p["name"] in FILE_NAMES or
                     (isinstance(default, str) and FILE_EXTENSIONS.search(default)) or
                     FILE_EXTENSIONS.search(p.get("doc", "")))
            if looks:
                wrong.append(f"{node['type']}.{p['name']} ({p.get('type')})")
    check(not wrong, f"every param that names a file is a path kind (not: {wrong})")
    return [(node["type"], p["name"]) for node in nodes for p in node.get("params", []) if p.get("type") == "path"]


def security_checks(nodes):
    """Issue #27: DNS rebinding, cross-origin requests, path params out of DIR, chunked bodies past --max-body, PUT
    where it should not write, If-Match, security headers, Content-Type, the loopback token."""
    port = server.port
    secret_path = os.path.join(outside, "secret.json")

    # The loopback token (as Jupyter's): printed, required on every route, kept as an HttpOnly SameSite cookie.
    check(server.token is not None and len(server.token) >= 32, "a loopback server prints a URL with a token")
    for method, path, body in [("GET", "/api/status", None), ("GET", "/api/graphs", None), ("GET", "/api/events", None),
                               ("GET", "/api/graphs/graphs/fxaa_zoneplate.json", None),
                               ("PUT", "/api/graphs/graphs/token.json", zoneplate_bytes),
                               ("POST", "/api/validate", {"graph": "graphs/fxaa_zoneplate.json"})]:
        r, body = server.status_only(method, path, auth=False) if path == "/api/events" else \
            server.json(method, path, body, auth=False)
        check(r.status == 401 and "token" in body.get("error", ""), f"{method} {path} without the token: 401 ({r.status})")
    check(not os.path.exists(os.path.join(gdir, "token.json")), "a PUT without the token writes nothing")
    if server.token:
        r, _ = server.request("GET", "/api/status?token=" + server.token, auth=False)
        cookie = r.getheader("Set-Cookie", "")
        check(r.status == 200 and "HttpOnly" in cookie and "SameSite=Strict" in cookie,
              f"?token= answers with an HttpOnly SameSite=Strict cookie ({cookie})")
        r, _ = server.request("GET", "/api/status", headers={"Cookie": cookie.split(";")[0]}, auth=False)
        check(r.status == 200, "the cookie alone is enough")
        r, _ = server.request("GET", "/api/status", headers={"Cookie": "vitrine_token_%d=" % port + "0" * len(server.token)},
                              auth=False)
        check(r.status == 401, "a wrong cookie: 401")
        r, _ = server.request("GET", "/api/status", headers={"Cookie": "vitrine_token_%d=%s" % (port + 1, server.token)},
                              auth=False)
        check(r.status == 401, "another port's cookie: 401")

    # DNS rebinding: only the loopback names with this port are answered.
    for host in ["127.0.0.1.attacker.example:%d" % port, "127.0.0.1.attacker.example", "127.1.2.3:%d" % port,
                 "attacker.example:%d" % port, "127.0.0.1:%d" % (port + 1 if port < 65535 else 1), "localhost.:%d" % port]:
        r, body = server.json("GET", "/api/graphs", headers={"Host": host})
        check(r.status == 403 and "Host" in body.get("error", ""), f"Host {host}: 403 naming the Host ({r.status})")
    for host in ["127.0.0.1:%d" % port, "localhost:%d" % port, "[::1]:%d" % port]:
        r, _ = server.json("GET", "/api/status", headers={"Host": host})
        check(r.status == 200, f"Host {host}: answered ({r.status})")
    # Cross-origin requests: refused on what changes state and on the event stream.
    for origin in ["http://127.0.0.1.attacker.example:%d" % port, "http://attacker.example", "null",
                   "http://127.0.0.1:%d" % (port + 1)]:
        for method, path, body in [("PUT", "/api/graphs/graphs/cors.json", zoneplate_bytes),
                                   ("POST", "/api/validate", {"graph": "graphs/fxaa_zoneplate.json"}),
                                   ("POST", "/api/render", {"graph": "graphs/fxaa_zoneplate.json"}),
                                   ("DELETE", "/api/graphs/graphs/fxaa_zoneplate.json", None),
                                   ("GET", "/api/events", None)]:
            r, reply = server.status_only(method, path, headers={"Origin": origin}) if path == "/api/events" else \
                server.json(method, path, body, headers={"Origin": origin})
            check(r.status == 403 and "rigin" in reply.get("error", ""),
                  f"{method} {path} from Origin {origin}: 403 naming the origin ({r.status})")
    check(not os.path.exists(os.path.join(gdir, "cors.json")), "a cross-origin PUT writes nothing")
    r, body = server.json("POST", "/api/validate", {"graph": "graphs/fxaa_zoneplate.json"},
                          headers={"Origin": "http://127.0.0.1:%d" % port})
    check(r.status == 200 and body.get("ok") is True, "a POST from the server's own page (Origin) works")

    # Headers on every answer; no caching of the API.
    for method, path in [("GET", "/api/status"), ("GET", "/api/nope"), ("GET", "/"), ("GET", "/api/graphs/graphs/x.json")]:
        r, _ = server.request(method, path)
        csp = r.getheader("Content-Security-Policy", "")
        check("default-src 'self'" in csp and "frame-ancestors 'none'" in csp and "unsafe-eval" not in csp and
              "script-src 'self'" in csp and "http" not in csp, f"{path}: Content-Security-Policy ({csp})")
        check(r.getheader("X-Frame-Options") == "DENY" and r.getheader("X-Content-Type-Options") == "nosniff" and
              r.getheader("Referrer-Policy") == "no-referrer", f"{path}: X-Frame-Options, nosniff, Referrer-Policy")
        if path.startswith("/api/"):
            check(r.getheader("Cache-Control") == "no-store", f"{path}: Cache-Control: no-store")
    r, _ = server.request("GET", "/api/status", auth=False)
    check(r.getheader("Content-Security-Policy") and r.getheader("Cache-Control") == "no-store",
          "a 401 has the headers too")
    # A JSON body with another Content-Type (what an HTML form can send without a preflight): 415.
    for ctype in ["text/plain", "application/x-www-form-urlencoded", "multipart/form-data; boundary=x", None]:
        headers = {"Content-Type": ctype} if ctype else {}
        conn = http.client.HTTPConnection(server.host, server.port, timeout=60)
        sent = dict(server.auth(), **headers)
        conn.putrequest("POST", "/api/validate")
        for k, v in sent.items():
            conn.putheader(k, v)
        payload = json.dumps({"graph": "graphs/fxaa_zoneplate.json"}).encode()
        conn.putheader("Content-Length", str(len(payload)))
        conn.endheaders(payload)
        resp = conn.getresponse()
        body = js(resp.read())
        conn.close()
        check(resp.status == 415 and "Content-Type" in body.get("error", ""),
              f"POST with Content-Type {ctype}: 415 with a message ({resp.status})")
    r, body = server.json("PUT", "/api/graphs/graphs/ctype.json", zoneplate_bytes, headers={"Content-Type": "text/plain"})
    check(r.status == 415 and not os.path.exists(os.path.join(gdir, "ctype.json")), f"PUT as text/plain: 415 ({r.status})")
    r, body = server.json("POST", "/api/validate", b"{" + b" " * 2_000_000 + b"}", headers={"Content-Type": "text/plain"})
    check(r.status == 415, f"an oversize body with the wrong Content-Type: 415, not 413 ({r.status})")
    r, body = server.json("POST", "/api/validate", {"graph": "graphs/fxaa_zoneplate.json"},
                          headers={"Content-Type": "application/json; charset=utf-8"})
    check(r.status == 200, "application/json; charset=utf-8 is JSON")

    # Bodies past --max-body (1000000 here): 413 before anything is stored, chunked or not.
    big = b'{"nodes": {}, "pad": "' + b" " * 3_000_000 + b'"}'
    status, headers, body = server.raw("PUT /api/graphs/graphs/big_chunked.json HTTP/1.1\r\n"
                                       "Content-Type: application/json\r\nTransfer-Encoding: chunked\r\n",
                                       [b"%x\r\n%s\r\n" % (len(big[i:i + 65536]), big[i:i + 65536])
                                        for i in range(0, len(big), 65536)] + [b"0\r\n\r\n"])
    check(status == 413 and not os.path.exists(os.path.join(gdir, "big_chunked.json")),
          f"a chunked PUT past --max-body: 413, nothing written ({status})")
    status, headers, body = server.raw("POST /api/render HTTP/1.1\r\n"
                                       "Content-Type: application/json\r\nTransfer-Encoding: chunked\r\n",
                                       [b"%x\r\n%s\r\n" % (len(big[i:i + 65536]), big[i:i + 65536])
                                        for i in range(0, len(big), 65536)] + [b"0\r\n\r\n"])
    check(status == 413, f"a chunked POST past --max-body: 413 ({status})")
    r, body = server.json("PUT", "/api/graphs/graphs/big_plain.json", big)
    check(r.status == 413 and not os.path.exists(os.path.join(gdir, "big_plain.json")),
          f"a PUT past --max-body with Content-Length: 413, nothing written ({r.status})")
    status, headers, body = server.raw("PUT /api/graphs/graphs/small_chunked.json HTTP/1.1\r\n"
                                       "Content-Type: application/json\r\nTransfer-Encoding: chunked\r\n",
                                       [b"%x\r\n%s\r\n" % (len(zoneplate_bytes), zoneplate_bytes), b"0\r\n\r\n"])
    with open(os.path.join(gdir, "small_chunked.json"), "rb") if os.path.exists(
            os.path.join(gdir, "small_chunked.json")) else open(os.devnull, "rb") as f:
        check(status == 201 and f.read() == zoneplate_bytes, f"a chunked PUT under --max-body is written ({status})")
    r, _ = server.request("GET", "/api/status")
    check(r.status == 200, "the server answers after oversize bodies")

    # PUT writes graphs and variants only, never under dot-folders, node_modules or the editor's own sources.
    for path, body in [(".git/config.json", zoneplate_bytes), (".git/config", zoneplate_bytes),
                       (".hidden.json", zoneplate_bytes), ("graphs/.cache/x.json", zoneplate_bytes),
                       ("node_modules/pkg/package.json", zoneplate_bytes), ("editor/package.json", b'{"name": "x"}'),
                       ("editor/package.json", zoneplate_bytes), ("editor/src/graph.json", zoneplate_bytes),
                       ("graphs/notagraph.json", b'{"name": "x", "scripts": {"postinstall": "rm -rf ~"}}'),
                       ("graphs/wrongformat.json", b'{"format": "other/1", "nodes": {}}'),
                       ("graphs/array.json", b"[1, 2]")]:
        r, reply = server.json("PUT", "/api/graphs/" + path, body)
        check(r.status in (400, 403, 422) and reply.get("error"), f"PUT {path}: refused ({r.status}: {reply.get('error')})")
    check(not os.path.exists(os.path.join(served, ".git", "config.json")) and
          not os.path.exists(os.path.join(served, ".hidden.json")) and
          not os.path.exists(os.path.join(served, "node_modules", "pkg", "package.json")) and
          not os.path.exists(os.path.join(served, "editor", "src", "graph.json")) and
          not os.path.exists(os.path.join(gdir, "notagraph.json")), "refused PUTs wrote nothing")
    with open(os.path.join(served, "editor", "package.json")) as f:
        check(f.read() == '{"name": "vitrine-editor"}\n', "editor/package.json is unchanged")
    r, _ = server.json("PUT", "/api/graphs/graphs/variants/put_variant.json", {"extends": "../fxaa_zoneplate.json"})
    check(r.status == 201, f"PUT of a variant ({r.status})")

    # ETag on GET, If-Match on PUT (412 when the file changed since), NAME.json.bak of what a PUT replaced.
    target = "/api/graphs/graphs/etag.json"
    with open(os.path.join(gdir, "etag.json"), "wb") as f:
        f.write(zoneplate_bytes)
    r, first = server.request("GET", target)
    etag = r.getheader("ETag")
    check(r.status == 200 and etag and etag.startswith('"'), f"GET of a graph has an ETag ({etag})")
    edited = json.loads(first)
    edited["description"] = "edited in tab 1"
    edited_bytes = json.dumps(edited, indent=2).encode()
    r, _ = server.request("PUT", target, edited_bytes, headers={"If-Match": etag or '"none"'})
    new_etag = r.getheader("ETag")
    check(r.status == 200 and new_etag and new_etag != etag, f"PUT with the current ETag: 200 and a new ETag ({r.status})")
    with open(os.path.join(gdir, "etag.json.bak"), "rb") if os.path.exists(os.path.join(gdir, "etag.json.bak")) \
            else open(os.devnull, "rb") as f:
        check(f.read() == zoneplate_bytes, "the PUT kept what it replaced as etag.json.bak")
    r, _ = server.request("GET", target)
    check(r.getheader("ETag") == new_etag, "GET after PUT: the ETag the PUT answered")
    stale = dict(edited, description="edited in tab 2")
    r, body = server.json("PUT", target, stale, headers={"If-Match": etag or '"none"'})
    with open(os.path.join(gdir, "etag.json"), "rb") as f:
        check(r.status == 412 and f.read() == edited_bytes and body.get("error"),
              f"PUT with a stale If-Match: 412, the file unchanged ({r.status})")
    r, _ = server.request("PUT", "/api/graphs/graphs/etag_new.json", zoneplate_bytes, headers={"If-Match": '"abc"'})
    check(r.status == 412 and not os.path.exists(os.path.join(gdir, "etag_new.json")),
          f"If-Match on a file that does not exist: 412 ({r.status})")
    r, _ = server.request("PUT", target, edited_bytes, headers={"If-Match": "*"})
    check(r.status == 200, "If-Match: * on an existing file")

    # Every path param of every node (from the schemas, so new nodes are covered) pointed out of DIR: refused, and
    # neither the file's content nor where DIR lies on the machine comes back.
    escapes = {"..": os.path.relpath(secret_path, gdir), "absolute": secret_path,
               "URL-encoded ..": os.path.relpath(secret_path, gdir).replace("..", "%2e%2e"),
               "URL-encoded /": os.path.relpath(secret_path, gdir).replace("/", "%2f")}
    for node_type, param in path_param_checks(nodes):
        for how, value in escapes.items():
            doc = {"frame": {"width": 8, "height": 8}, "nodes": {"n": {"type": node_type, "params": {param: value}}},
                   "outputs": {"final": "n.color"}}
            for route in ["/api/render", "/api/validate"]:
                r, payload = server.request("POST", route, {"document": doc, "base": "graphs/probe.json"})
                text = payload.decode(errors="replace")
                body = js(payload)
                error = body.get("error", "") or " ".join(e.get("error", "") for e in body.get("errors", []))
                refused = (r.status == 403 if route == "/api/render" else body.get("ok") is False) and "refused" in error
                check(refused and SECRET not in text and work not in text and outside not in text,
                      f"{route} {node_type}.{param} = {how} path out of DIR: refused, nothing echoed "
                      f"({r.status}: {text[:300]})")
    # Event streams hold a server thread each: 16 open at once (16 tabs, or a script) must not starve the API.
    streams = []
    for _ in range(16):
        sk = socket.create_connection((server.host, server.port))
        sk.settimeout(10)
        sk.sendall(("GET /api/events HTTP/1.1\r\nHost: %s:%d\r\n%s\r\n" %
                    (server.host, server.port, "".join("%s: %s\r\n" % kv for kv in server.auth().items()))).encode())
        streams.append(sk)
    answers = []
    for sk in streams:
        try:
            answers.append(int(sk.recv(64).split()[1]))
        except (OSError, IndexError, ValueError):
            answers.append(0)
        if answers[-1] != 200:
            sk.close()
    try:
        r, _ = server.request("GET", "/api/status", timeout=10)
        status = r.status
    except OSError:
        status = 0
    check(status == 200, f"the API answers while 16 event streams are open ({status})")
    check(answers.count(200) >= 4 and 503 in answers and all(a in (200, 503) for a in answers),
          f"event streams past the limit get 503 ({answers})")
    for sk in streams:
        sk.close()

    # A working graph whose lens names a JSON file out of DIR: its setup used to read it and echo its "format".
    for value in [os.path.relpath(secret_path, gdir), secret_path]:
        for route in ["/api/validate", "/api/render"]:
            r, payload = server.request("POST", route, {"graph": "graphs/camera_checker.json",
                                                        "set": ["camera.params.lens=" + value], "width": 32, "height": 18})
            text = payload.decode(errors="replace")
            check("refused" in text and SECRET not in text and outside not in text,
                  f"{route} camera_checker.json with lens {value[:40]}...: refused, the file not echoed ({text[:200]})")
    check(tree_digest(outside) == outside_digest, "nothing outside DIR was written (security checks)")


def main():
    global server
    server = Server(served, "--max-body", "1000000", "--editor", os.path.join(served, "editor", "dist"))
    print("checking", server.url, flush=True)
    nodes = json.loads(subprocess.run([vitrine, "nodes", "--json"], check=True, capture_output=True).stdout)
    security_checks(nodes)
    if os.environ.get("VITRINE_SERVE_CHECKS") == "security":
        return

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
        conn.request("GET", "/api/events", headers=server.auth())
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
        conn.request("GET", "/api/events", headers=server.auth())
        stream = conn.getresponse()
        s.sendall(b"POST /api/render HTTP/1.1\r\nHost: 127.0.0.1:" + str(server.port).encode() +
                  b"\r\nContent-Type: application/json\r\nAuthorization: token " + (server.token or "").encode() +
                  b"\r\nContent-Length: " + str(len(slow)).encode() + b"\r\n\r\n" + slow)
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
    e.sendall(b"GET /api/events HTTP/1.1\r\nHost: 127.0.0.1:" + str(server.port).encode() +
              b"\r\nAuthorization: token " + (server.token or "").encode() + b"\r\n\r\n")
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
        r, _ = server.request("GET", path, timeout=10, auth=False)
        check(r.status == 401, f"GET {path} without the token: 401")
    r, _ = server.request("GET", "/api/nodes?token=wrong", auth=False)
    check(r.status == 401, "a wrong token: 401")
    r, payload = server.request("GET", "/?token=" + server.token, auth=False)
    cookie = r.getheader("Set-Cookie", "")
    check(r.status == 200 and b"<title>editor</title>" in payload, "GET /?token=... serves the editor's index.html")
    check(cookie.startswith("vitrine_token_%d=" % server.port) and "HttpOnly" in cookie,
          "the token is kept as a cookie named with the port (cookies do not tell ports apart)")
    r, payload = server.request("GET", "/assets/app.js", headers={"Cookie": cookie.split(";")[0]}, auth=False)
    check(r.status == 200 and r.getheader("Content-Type") == "text/javascript", "static files with the cookie")
    r, payload = server.request("GET", "/api/nodes", headers={"Authorization": "token " + server.token}, auth=False)
    check(r.status == 200 and payload == nodes_cli, "Authorization: token ... works")
    r, payload = server.request("POST", "/api/render", json.dumps({"graph": "graphs/fxaa_zoneplate.json", "width": 160,
                                                                    "height": 90}),
                                {"Authorization": "token " + server.token})
    check(r.status == 200 and payload == png1, "render with the token")
    r, _ = server.request("GET", "/..%2f..%2foutside%2fsecret.png", headers={"Authorization": "token " + server.token})
    check(r.status in (403, 404), "static files cannot leave the editor's directory")
    check(server.stop() == 0, "the token server stops cleanly")

    # --no-token: no token asked, with a warning on stderr; refused with a --host other than the loopback.
    server = Server(served, "--no-token", "--editor", dist, stderr=subprocess.PIPE)
    warning = []
    threading.Thread(target=lambda: warning.append(server.proc.stderr.read()), daemon=True).start()
    check(server.token is None, "--no-token prints a URL without a token")
    r, payload = server.request("GET", "/api/nodes", auth=False)
    check(r.status == 200 and payload == nodes_cli, "--no-token: the API answers without a token")
    r, _ = server.request("GET", "/api/status", headers={"Host": "127.0.0.1.attacker.example:%d" % server.port})
    check(r.status == 403, "--no-token: DNS rebinding still refused")
    check(server.stop() == 0, "the --no-token server stops cleanly")
    time.sleep(0.2)
    check(warning and "--no-token" in warning[0] and "token" in warning[0].lower(),
          f"--no-token warns on stderr ({(warning or [''])[0][-300:]!r})")
    refused = subprocess.run([vitrine, "serve", served, "--port", "0", "--host", "127.0.0.2", "--no-token"],
                             capture_output=True, text=True, timeout=120)
    check(refused.returncode != 0 and "--no-token" in refused.stderr,
          f"--no-token with a --host other than the loopback: refused ({refused.returncode})")


try:
    main()
except Exception:
    traceback.print_exc()
    failed.append("the test script stopped on an exception")

shutil.rmtree(work, ignore_errors=True)
print(f"{passed} passed, {len(failed)} failed")
sys.exit(1 if failed else 0)

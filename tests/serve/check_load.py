#!/usr/bin/env python3
"""`vitrine serve` under load (issue #27), with the standard library only.

usage: check_load.py VITRINE SOURCE_DIR [--bound-ms MS] [--max-ms MS]

Opens 32 event streams from 8 loopback addresses 127.0.0.2..9 (8 from the first, then the others in turn, so that
both the per-client and the global cap are met) and starts 32 renders at once (16 waiting for their PNG, 16 "async"), slow enough on lavapipe to fill
the GPU queue; while they run, it times GET /api/status and GET /api/nodes. Checks:
  - 4 streams from the address that tried 8, at most 4 from any, and 8 in all get 200; the others 503 with
    Retry-After;
  - status and nodes answer within --bound-ms (default 100) at the 95th percentile and within --max-ms (default 500)
    every time. Measured on lavapipe, 2 cores shared with other builds (load average 9): max 17-33 ms; with another
    lavapipe process baking beside it (load average 14): p95 28 ms, max 268 ms -- the CPU, not the server, so the
    maximum's bound is 5x the 95th percentile's. The server before the queue: max 8.1 s; with cpp-httplib's listen
    backlog of 5: max 1.0 s (a dropped SYN's retransmission);
  - every render gets either its PNG (a sync one at once, an async one at its /api/images URL) or 503 with
    Retry-After and "reason": "queue-full" -- none hangs or is lost; some are refused (the queue is bounded) and
    the server's own counts never pass its limits (waiting requests, queued jobs);
  - the server's resident memory after the load is within 256 MiB of what it was after one warm render;
  - closed streams free their slots (status shows 0 open within 15 s) and a render afterwards works;
  - --max-queue 0 is refused; with --max-queue 1, of 4 async renders sent at once some get 503, the others finish.
Prints the latencies (min, median, p95, max) and the RSS. Ends with "N passed, M failed".
"""
import atexit
import http.client
import json
import os
import re
import shutil
import socket
import statistics
import struct
import subprocess
import sys
import tempfile
import threading
import time

vitrine, source = sys.argv[1:3]
bound_ms = float(sys.argv[sys.argv.index("--bound-ms") + 1]) if "--bound-ms" in sys.argv else 100.0
max_ms = float(sys.argv[sys.argv.index("--max-ms") + 1]) if "--max-ms" in sys.argv else 500.0
passed = 0
failed = []

STREAM_CLIENTS = [f"127.0.0.{i}" for i in range(2, 10)]
# 32 streams: 8 from the first address (past its cap), then 24 from the other seven in turn.
STREAM_TRIES = [STREAM_CLIENTS[0]] * 8 + [STREAM_CLIENTS[1 + i % 7] for i in range(24)]
RENDERS_SYNC = 16
RENDERS_ASYNC = 16
MAX_STREAMS, MAX_PER_CLIENT, MAX_WAITING, MAX_QUEUED = 8, 4, 8, 16  # api.hpp, serve --max-queue default
RSS_GROWTH_MIB = 256


def check(condition, what):
    global passed
    if condition:
        passed += 1
    else:
        failed.append(what)
        print("FAIL:", what, flush=True)


def js(payload):
    try:
        value = json.loads(payload)
        return value if isinstance(value, dict) else {}
    except ValueError:
        return {}


def png_size(data):
    return struct.unpack(">II", data[16:24]) if data[:8] == b"\x89PNG\r\n\x1a\n" else None


def rss_mib(pid):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return 0.0


work = tempfile.mkdtemp(prefix="vitrine-serve-load-")
shutil.copytree(os.path.join(source, "graphs"), os.path.join(work, "graphs"))
proc = subprocess.Popen([vitrine, "serve", work, "--port", "0", "--validate"], stdout=subprocess.PIPE, text=True)


@atexit.register
def cleanup():
    if proc.poll() is None:
        proc.kill()
    shutil.rmtree(work, ignore_errors=True)


host = port = token = None
deadline = time.time() + 120
while time.time() < deadline:
    line = proc.stdout.readline()
    if not line:
        break
    print("server:", line.rstrip(), flush=True)
    m = re.search(r"listening on http://([^/]+):(\d+)/\?token=(\w+)", line)
    if m:
        host, port, token = m.group(1), int(m.group(2)), m.group(3)
        break
if not port:
    raise SystemExit("check_load: the server did not start")
threading.Thread(target=proc.stdout.read, daemon=True).start()
AUTH = {"Authorization": "token " + token}


def request(method, path, body=None, timeout=600, source_address=None):
    conn = http.client.HTTPConnection(host, port, timeout=timeout, source_address=source_address)
    headers = dict(AUTH)
    if body is not None:
        headers["Content-Type"] = "application/json"
        body = json.dumps(body)
    conn.request(method, path, body=body, headers=headers)
    r = conn.getresponse()
    payload = r.read()
    conn.close()
    return r, payload


def timed(path):
    t0 = time.perf_counter()
    try:
        r, payload = request("GET", path, timeout=30)
        ok = r.status == 200
        body = js(payload) if path == "/api/status" else None
    except OSError:
        ok, body = False, None
    return (time.perf_counter() - t0) * 1000.0, ok, body


SIZE = (640, 360)
render_spec = {"graph": "graphs/fxaa_zoneplate.json", "width": SIZE[0], "height": SIZE[1], "frames": 8}

# Warm: one render compiles the graph (later ones run frames only), then the baseline memory and latency.
r, payload = request("POST", "/api/render", render_spec)
check(r.status == 200 and png_size(payload) == SIZE, f"a warm-up render works ({r.status})")
ms = r.getheader("X-Vitrine-Ms")
r, payload = request("POST", "/api/render", render_spec)
print(f"one warm render of {SIZE[0]}x{SIZE[1]}x8 frames: {r.getheader('X-Vitrine-Ms')} ms (first: {ms} ms)",
      flush=True)
rss_before = rss_mib(proc.pid)
idle = [timed("/api/status")[0] for _ in range(20)]
print(f"status idle: median {statistics.median(idle):.1f} ms, max {max(idle):.1f} ms", flush=True)

# 32 event streams from 8 client addresses.
streams = []  # (address, socket, status, retry-after)
for address in STREAM_TRIES:
    s = socket.create_connection((host, port), timeout=10, source_address=(address, 0))
    s.sendall(f"GET /api/events HTTP/1.1\r\nHost: {host}:{port}\r\nAuthorization: token {token}\r\n\r\n".encode())
    head = b""
    try:
        while b"\r\n\r\n" not in head:
            more = s.recv(4096)
            if not more:
                break
            head += more
        status = int(head.split()[1])
    except (OSError, IndexError, ValueError):
        status = 0
    retry = re.search(rb"(?i)\r\nretry-after: *(\d+)", head)
    streams.append((address, s, status, int(retry.group(1)) if retry else None))
    if status != 200:
        s.close()
open_streams = [s for s in streams if s[2] == 200]
per_client = {a: sum(1 for s in open_streams if s[0] == a) for a in STREAM_CLIENTS}
print(f"event streams: {len(open_streams)} open of {len(streams)} tried; per client {per_client}", flush=True)
check(len(open_streams) == MAX_STREAMS, f"{MAX_STREAMS} event streams open in all ({len(open_streams)})")
check(per_client[STREAM_CLIENTS[0]] == MAX_PER_CLIENT and max(per_client.values()) <= MAX_PER_CLIENT,
      f"{MAX_PER_CLIENT} streams from a client that tried 8, at most {MAX_PER_CLIENT} from any ({per_client})")
check(all(s[2] == 503 and s[3] for s in streams if s[2] != 200),
      f"the other streams: 503 with Retry-After ({[(s[2], s[3]) for s in streams if s[2] != 200][:6]})")


def drain(sock):
    try:
        sock.settimeout(None)
        while sock.recv(65536):
            pass
    except OSError:
        pass


for s in open_streams:
    threading.Thread(target=drain, args=(s[1],), daemon=True).start()

# 32 renders at once, and status/nodes timed while they run.
results = {}


def sync_render(i):
    try:
        r, payload = request("POST", "/api/render", render_spec)
        results[("sync", i)] = (r.status, r.getheader("Retry-After"), png_size(payload), js(payload))
    except OSError as e:
        results[("sync", i)] = (0, None, None, {"error": str(e)})


def async_render(i):
    try:
        r, payload = request("POST", "/api/render", dict(render_spec, **{"async": True}))
        body = js(payload)
        if r.status != 202:
            results[("async", i)] = (r.status, r.getheader("Retry-After"), None, body)
            return
        for _ in range(6000):
            r, payload = request("GET", body.get("url", "/api/images/0"))
            if r.status != 202:
                break
            time.sleep(0.05)
        results[("async", i)] = (r.status, None, png_size(payload), js(payload))
    except OSError as e:
        results[("async", i)] = (0, None, None, {"error": str(e)})


workers = [threading.Thread(target=sync_render, args=(i,)) for i in range(RENDERS_SYNC)]
workers += [threading.Thread(target=async_render, args=(i,)) for i in range(RENDERS_ASYNC)]
start = time.perf_counter()
for w in workers:
    w.start()
status_ms, nodes_ms, samples = [], [], []
all_ok = True
nodes_cli = None
while any(w.is_alive() for w in workers) and time.perf_counter() - start < 600:
    t, ok, body = timed("/api/status")
    status_ms.append(t)
    all_ok = all_ok and ok
    if body:
        samples.append(body)
    t, ok, _ = timed("/api/nodes")
    nodes_ms.append(t)
    all_ok = all_ok and ok
    time.sleep(0.02)
for w in workers:
    w.join(timeout=60)
load_s = time.perf_counter() - start


def spread(values):
    values = sorted(values)
    return (f"min {values[0]:.1f}, median {statistics.median(values):.1f}, "
            f"p95 {values[int(0.95 * (len(values) - 1))]:.1f}, max {values[-1]:.1f} ms ({len(values)} requests)")


print(f"under load ({load_s:.1f} s): status {spread(status_ms)}", flush=True)
print(f"under load: nodes {spread(nodes_ms)}", flush=True)
check(all_ok, "status and nodes answered 200 throughout")
def p95(values):
    return sorted(values)[int(0.95 * (len(values) - 1))]


for name, values in [("status", status_ms), ("nodes", nodes_ms)]:
    check(p95(values) < bound_ms and max(values) < max_ms,
          f"{name} under load: 95 % within {bound_ms:.0f} ms and all within {max_ms:.0f} ms "
          f"(p95 {p95(values):.1f} ms, max {max(values):.1f} ms)")
busy = [s for s in samples if s.get("busy") or s.get("queued", 0) > 0]
check(len(busy) >= 3 and max(s.get("event_streams", 0) for s in samples) == MAX_STREAMS,
      f"the server was under load while timed ({len(busy)} of {len(samples)} samples busy)")
check(all(s.get("waiting_requests", 0) <= MAX_WAITING and s.get("queued", 0) <= MAX_QUEUED for s in samples),
      f"never more than {MAX_WAITING} requests waiting nor {MAX_QUEUED} jobs queued "
      f"(max {max(s.get('waiting_requests', 0) for s in samples)}, {max(s.get('queued', 0) for s in samples)})")

# None lost: each has its PNG or a 503 saying when to retry.
done = {k: v for k, v in results.items() if v[0] == 200}
refused = {k: v for k, v in results.items() if v[0] == 503}
other = {k: v for k, v in results.items() if v[0] not in (200, 503)}
print(f"renders: {len(done)} done, {len(refused)} refused (503), {len(other)} other; "
      f"sync done {sum(1 for k in done if k[0] == 'sync')}, async done {sum(1 for k in done if k[0] == 'async')}",
      flush=True)
check(len(results) == RENDERS_SYNC + RENDERS_ASYNC, f"every render answered ({len(results)})")
check(not other, f"every render got its image or 503 ({list(other.items())[:3]})")
check(all(v[2] == SIZE for v in done.values()), "every render done is a PNG of the size asked")
check(all(v[3].get("reason") == "queue-full" for v in refused.values()), "every 503 says queue-full")
check(all(v[1] and int(v[1]) >= 1 for v in refused.values()),
      f"every refused request has Retry-After ({[v[1] for v in refused.values()][:8]})")
check(refused and done, f"some renders were refused and some done ({len(refused)}, {len(done)})")
check(sum(1 for k in done if k[0] == "sync") >= 1, "sync renders get through while async ones queue")

rss_after = rss_mib(proc.pid)
print(f"RSS: {rss_before:.0f} MiB after one warm render, {rss_after:.0f} MiB after the load", flush=True)
check(rss_after - rss_before < RSS_GROWTH_MIB,
      f"resident memory within {RSS_GROWTH_MIB} MiB of before ({rss_before:.0f} -> {rss_after:.0f} MiB)")

# Streams closed by their clients free their slots (found at the next keep-alive writes).
for s in open_streams:
    s[1].close()
t0 = time.time()
open_now = None
while time.time() - t0 < 15:
    _, _, body = timed("/api/status")
    open_now = (body or {}).get("event_streams")
    if open_now == 0:
        break
    time.sleep(0.25)
print(f"closed streams freed in {time.time() - t0:.1f} s", flush=True)
check(open_now == 0, f"closed streams free their slots within 15 s ({open_now} still counted)")
s = socket.create_connection((host, port), timeout=10)
s.sendall(f"GET /api/events HTTP/1.1\r\nHost: {host}:{port}\r\nAuthorization: token {token}\r\n\r\n".encode())
check(s.recv(64).split()[1] == b"200", "a new event stream opens after the others closed")
s.close()
r, payload = request("POST", "/api/render", render_spec)
check(r.status == 200 and png_size(payload) == SIZE, f"a render after the load works ({r.status})")
proc.terminate()
check(proc.wait(timeout=120) == 0, "the server stops cleanly")

# --max-queue: out of range refused; 1 lets one job wait behind the running one.
bad = subprocess.run([vitrine, "serve", work, "--port", "0", "--max-queue", "0"], capture_output=True, text=True,
                     timeout=120)
check(bad.returncode != 0 and "--max-queue" in bad.stderr, f"--max-queue 0 refused ({bad.returncode}: {bad.stderr[-200:]})")
proc = subprocess.Popen([vitrine, "serve", work, "--port", "0", "--validate", "--max-queue", "1"],
                        stdout=subprocess.PIPE, text=True)
for line in proc.stdout:
    m = re.search(r"listening on http://([^/]+):(\d+)/\?token=(\w+)", line)
    if m:
        host, port, token = m.group(1), int(m.group(2)), m.group(3)
        AUTH = {"Authorization": "token " + token}
        break
threading.Thread(target=proc.stdout.read, daemon=True).start()
answers = [request("POST", "/api/render", dict(render_spec, **{"async": True})) for _ in range(4)]
statuses = [r.status for r, _ in answers]
accepted = [js(p).get("url") for r, p in answers if r.status == 202]
finished = []
for url in accepted:
    for _ in range(2400):
        r, payload = request("GET", url)
        if r.status != 202:
            break
        time.sleep(0.05)
    finished.append((r.status, png_size(payload)))
print(f"--max-queue 1, 4 async renders at once: {statuses}; accepted ones: {finished}", flush=True)
check(statuses.count(503) >= 1 and 202 in statuses and set(statuses) <= {202, 503},
      f"--max-queue 1: some of 4 renders at once refused ({statuses})")
check(all(f == (200, SIZE) for f in finished), f"--max-queue 1: every accepted render finished ({finished})")
proc.terminate()
check(proc.wait(timeout=120) == 0, "the --max-queue 1 server stops cleanly")
print(f"{passed} passed, {len(failed)} failed")
sys.exit(1 if failed else 0)

#!/usr/bin/env python3
"""`vitrine sweep` run locally on a small sweep, checked at the command-line level (standard library + Debian's
chromium only).

usage: check_sweep.py VITRINE SOURCE_DIR

The sweep is tests/sweep/fxaa_subpix.sweep.json (zone plate at 160x90: FXAA subpix 0, 0.5, 1 and the no_fxaa
variant, against the 16x16 supersampled plate) plus one point made to fail (subpix = 7, outside [0, 1]). Checks:
  - exit status 3 (a point failed); sweep.json and sweep.csv have every point; 4 done, the bad one failed with its
    error text (the pointer /nodes/fxaa/params/subpix) and exit code 1 recorded;
  - each done point's FLIP mean / weighted median, SSIM and PSNR equal what `vitrine compare` prints for the same
    pair (a variant file extending the zone plate with that subpix, vs the supersampled plate): an independent path;
  - a second run skips every point (metrics.json and error.json untouched, "0 to run"); --retry-failed reruns only
    the failed point; --collect rebuilds the same table;
  - report.html opens in headless chromium without console errors, has one plot per metric and axis plus the
    quality-versus-cost plot, and every image and link it names exists.
Ends with "N passed, M failed".
"""
import csv
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from html.parser import HTMLParser

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


def run(args, **kw):
    p = subprocess.run([vitrine] + args, capture_output=True, text=True, **kw)
    return p.returncode, p.stdout + p.stderr


work = tempfile.mkdtemp(prefix="vitrine-sweep-test-")
out = os.path.join(work, "out")
shipped = os.path.join(source, "tests", "sweep", "fxaa_subpix.sweep.json")
with open(shipped) as f:
    sweep = json.load(f)
base = os.path.dirname(shipped)
for key in ("graph", "reference"):
    sweep[key] = os.path.normpath(os.path.join(base, sweep[key]))
for p in sweep["points"]:
    p["variant"] = os.path.normpath(os.path.join(base, p["variant"]))
sweep["points"].append({"set": {"fxaa.params.subpix": 7}})  # outside [0, 1]: this point fails
sweep_file = os.path.join(work, "fxaa_subpix.sweep.json")
with open(sweep_file, "w") as f:
    json.dump(sweep, f, indent=2)
W, H = sweep["frame"]["width"], sweep["frame"]["height"]

# 1. The first run: every point, one failing.
rc, log = run(["sweep", sweep_file, "--out", out, "--jobs", "2"])
print(log)
check(rc == 3, f"exit status 3 when a point failed, got {rc}")
with open(os.path.join(out, "sweep.json")) as f:
    table = json.load(f)
points = {p["id"]: p for p in table["points"]}
check(sorted(points) == ["p0000", "p0001", "p0002", "p0003", "p0004"], f"every point in sweep.json: {sorted(points)}")
check(table["summary"] == {"done": 4, "failed": 1, "pending": 0}, f"summary {table['summary']}")
bad = points.get("p0004", {})
check(bad.get("status") == "failed" and bad.get("exit_code") == 1, f"p0004 failed with exit 1: {bad}")
check("/nodes/fxaa/params/subpix" in bad.get("error", "") and "[0.0, 1.0]" in bad.get("error", ""),
      f"p0004's error names the pointer and the range: {bad.get('error')}")
check(os.path.exists(os.path.join(out, "points", "p0004", "error.json"))
      and not os.path.exists(os.path.join(out, "points", "p0004", "metrics.json")), "p0004: error.json, no metrics.json")
with open(os.path.join(out, "sweep.csv")) as f:
    rows = list(csv.DictReader(f))
check([r["id"] for r in rows] == ["p0000", "p0001", "p0002", "p0003", "p0004"], "every point in sweep.csv")
check(all(r["status"] == "done" and r["flip"] for r in rows[:4]) and rows[4]["status"] == "failed", "csv statuses")
check(rows[4]["error"] == bad.get("error"), "csv has the error text")
for pid in ["p0000", "p0001", "p0002", "p0003"]:
    with open(os.path.join(out, "points", pid, "metrics.json")) as f:
        m = json.load(f)
    phases = m.get("phases_ms", {})
    check(all(k in phases for k in ("start_ms", "load_ms", "device_ms", "compile_ms", "pipelines_ms", "render_ms",
                                    "total_ms")), f"{pid}: phase timings {sorted(phases)}")
    check(m["metrics"].get("gpu_ms", 0) > 0 and set(m.get("gpu_ms_per_node", {})) >= {"pattern", "tonemap"},
          f"{pid}: GPU ms per node {m.get('gpu_ms_per_node')}")
    check(m["metrics"].get("device_bytes", 0) > 0 and m["metrics"].get("max_rss_bytes", 0) > 0, f"{pid}: memory")
    check(m["width"] == W and m["height"] == H, f"{pid}: rendered at {W}x{H}")

# 2. The metrics equal `vitrine compare` of the same pair.
ref = sweep["reference"]
variants = {}
for i, subpix in enumerate(sweep["axes"][0]["values"]):
    v = os.path.join(work, f"subpix_{subpix}.json")
    with open(v, "w") as f:
        json.dump({"extends": sweep["graph"], "nodes": {"fxaa": {"params": {"subpix": subpix}}}}, f)
    variants[f"p000{i}"] = v
variants["p0003"] = sweep["points"][0]["variant"]
for pid, graph in variants.items():
    cmp_out = os.path.join(work, "compare_" + pid)
    rc, log = run(["compare", graph, ref, "--set", f"frame.width={W}", "--set", f"frame.height={H}", "--out", cmp_out,
                   "--quiet"])
    check(rc == 0, f"compare for {pid}: {log}")
    if rc != 0:
        continue
    with open(os.path.join(cmp_out, "metrics.json")) as f:
        pair = json.load(f)["pairs"][0]
    m = points[pid]["metrics"]
    for name, want in (("flip", pair["flip"]["mean"]), ("flip_weighted_median", pair["flip"]["weightedMedian"]),
                       ("ssim", pair["ssim"]), ("psnr", pair["psnr"])):
        check(abs(m[name] - want) <= 1e-12 * max(1.0, abs(want)), f"{pid} {name}: sweep {m[name]!r} vs compare {want!r}")
    print(f"{pid} {points[pid]['label']}: FLIP {m['flip']:.5f} (compare {pair['flip']['mean']:.5f}), "
          f"SSIM {m['ssim']:.5f}, PSNR {m['psnr']:.3f}")
check(points["p0002"]["metrics"]["flip"] < points["p0003"]["metrics"]["flip"],
      "FXAA subpix 1 is closer to the supersampled plate than no AA (FLIP)")


# 3. Resume: nothing reruns; --retry-failed reruns only the failed point.
def stamps():
    s = {}
    for pid in points:
        for name in ("metrics.json", "error.json", "log.txt"):
            p = os.path.join(out, "points", pid, name)
            if os.path.exists(p):
                s[(pid, name)] = os.stat(p).st_mtime_ns
    return s


before = stamps()
rc, log = run(["sweep", sweep_file, "--out", out, "--jobs", "2"])
check(rc == 3, f"second run: exit 3 (the failure is still recorded), got {rc}")
check("4 done earlier (skipped), 1 failed earlier" in log and "0 to run" in log, f"second run skips all: {log}")
check(stamps() == before, "second run: no point's files changed")
rc, log = run(["sweep", sweep_file, "--out", out, "--jobs", "2", "--retry-failed"])
print(log)
check(rc == 3 and "1 to run" in log, f"--retry-failed runs one point: {log}")
after = stamps()
check(all(after[k] == before[k] for k in before if k[0] != "p0004"), "--retry-failed leaves done points alone")
check(after[("p0004", "error.json")] != before[("p0004", "error.json")], "--retry-failed reran p0004")

# A folder of another sweep is refused rather than "resumed" with the wrong results.
other = dict(sweep, axes=[{"name": "subpix", "set": "fxaa.params.subpix", "values": [0.25, 0.5, 1.0]}])
other_file = os.path.join(work, "other.sweep.json")
with open(other_file, "w") as f:
    json.dump(other, f)
rc, log = run(["sweep", other_file, "--out", out])
check(rc == 1 and "holds the results of another sweep: point p0000" in log, f"another sweep's folder refused: {log}")
check(stamps() == after, "the refused run changed nothing")

# 4. --collect rebuilds the same table.
with open(os.path.join(out, "sweep.csv")) as f:
    csv_before = f.read()
os.remove(os.path.join(out, "sweep.json"))
os.remove(os.path.join(out, "sweep.csv"))
rc, log = run(["sweep", "--collect", out])
check(rc == 0 and "4 done, 1 failed, 0 pending" in log, f"--collect: {log}")
with open(os.path.join(out, "sweep.csv")) as f:
    check(f.read() == csv_before, "--collect writes the same sweep.csv")


# 5. The report in headless chromium.
class Links(HTMLParser):
    def __init__(self):
        super().__init__()
        self.refs, self.plots = [], []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag in ("img", "a") and (a.get("src") or a.get("href")):
            self.refs.append(a.get("src") or a.get("href"))
        if tag == "svg" and "plot" in a.get("class", "").split():
            self.plots.append((a.get("data-metric"), a.get("data-axis")))


report = os.path.join(out, "report.html")
with open(report) as f:
    html = f.read()
links = Links()
links.feed(html)
metrics = sweep["metrics"]
want = {(m, "subpix") for m in metrics} | {("flip", "gpu_ms")}
check(set(links.plots) == want and len(links.plots) == len(want), f"one plot per metric and axis: {links.plots}")
local = [r for r in links.refs if not r.startswith("#")]
check(all(not re.match(r"^[a-z]+:", r) for r in local), f"no external links: {local}")
missing = [r for r in local if not os.path.exists(os.path.join(out, r))]
check(not missing and len(local) >= 4 * 3, f"every linked file exists ({len(local)}): missing {missing}")
check("<script" not in html, "no script in the report")

chromium = shutil.which("chromium") or "/usr/bin/chromium"
if not os.path.exists(chromium):
    check(False, "chromium not found: run tools/install-deps.sh (Debian's chromium package)")
else:
    profile = os.path.join(work, "chromium-profile")
    p = subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu", "--user-data-dir=" + profile,
                        "--enable-logging=stderr", "--v=0", "--dump-dom", "file://" + report],
                       capture_output=True, text=True, timeout=120)
    console = [l for l in p.stderr.splitlines() if "CONSOLE" in l or "Failed to load" in l or "ERR_FILE" in l]
    check(p.returncode == 0, f"chromium exit {p.returncode}: {p.stderr[-2000:]}")
    check(not console, f"no console errors: {console}")
    dom_plots = re.findall(r'<svg class="plot[^"]*" data-metric="([^"]+)" data-axis="([^"]+)"', p.stdout)
    check(set(dom_plots) == want, f"chromium's DOM has the plots: {dom_plots}")

print(f"{passed} passed, {len(failed)} failed")
if not failed:
    shutil.rmtree(work, ignore_errors=True)
sys.exit(1 if failed else 0)

#!/usr/bin/env python3
"""`vitrine sweep --slurm` on a real one-node Slurm cluster (tests/sweep/slurm_cluster.py), against the local run.

usage: check_slurm.py VITRINE SWEEP_FILE

Starts munged, slurmctld and slurmd from Debian's packages in a temporary folder, runs SWEEP_FILE once locally
(`vitrine sweep FILE --out local`) and once through Slurm (`--slurm`: a reference job, a job array of one task per
point, a dependent collect job), and checks that the two sweep.json tables have the same points, labels, values and
status and equal quality metrics (FLIP, SSIM, PSNR, flicker: the same renders on the same device, so equal up to the
JSON's float formatting, 1e-9 relative; timings and memory are measurements and are only checked to be there). Then:
a second --slurm on the same folder submits nothing but the collect job; --no-wait returns at once and the jobs still
finish; a bad "slurm" block names its JSON pointer; a partition Slurm does not have gives sbatch's own message; no
sbatch on PATH says what is missing. If the daemons do not start, the test fails with their logs (it never skips).
Ends with "N passed, M failed".
"""
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from slurm_cluster import SlurmCluster  # noqa: E402

vitrine = os.path.abspath(sys.argv[1])
sweep_file = os.path.abspath(sys.argv[2])
passed = 0
failed = []
MEASURED = ("gpu_ms", "max_rss_bytes")  # and every *_ms: timings and the process's peak memory differ run to run


def check(condition, what):
    global passed
    if condition:
        passed += 1
    else:
        failed.append(what)
        print("FAIL:", what, flush=True)


def run(args, env, timeout=900):
    t0 = time.monotonic()
    r = subprocess.run([vitrine] + args, env=env, capture_output=True, text=True, timeout=timeout)
    r.seconds = time.monotonic() - t0
    return r


def table(out):
    with open(os.path.join(out, "sweep.json")) as f:
        return json.load(f)


def same_number(a, b):
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        if math.isinf(a) or math.isinf(b):
            return a == b
        return abs(a - b) <= 1e-9 * max(1.0, abs(a), abs(b))
    return a == b


def quality_of(metrics):
    """The metrics that depend only on the renders (FLIP, SSIM, PSNR, flicker, device memory), not on timings,
    flattened: {"flip": .., "flicker.flip": ..}."""
    flat = {}

    def walk(prefix, value):
        if isinstance(value, dict):
            for k, v in value.items():
                walk(f"{prefix}.{k}" if prefix else k, v)
        else:
            flat[prefix] = value

    walk("", metrics)
    return {k: v for k, v in flat.items() if k.split(".")[0] not in MEASURED and not k.endswith("_ms")}


def compare_tables(local, slurm):
    lp = {p["id"]: p for p in local["points"]}
    sp = {p["id"]: p for p in slurm["points"]}
    check(sorted(lp) == sorted(sp), f"same point ids: local {sorted(lp)}, slurm {sorted(sp)}")
    check(local.get("summary") == slurm.get("summary"),
          f"same summary: local {local.get('summary')}, slurm {slurm.get('summary')}")
    compared = 0
    for pid in sorted(set(lp) & set(sp)):
        a, b = lp[pid], sp[pid]
        for key in ("label", "values", "status", "sets", "frames", "graph", "error", "exit_code"):
            check(a.get(key) == b.get(key), f"{pid}: {key} local {a.get(key)!r} vs slurm {b.get(key)!r}")
        qa, qb = quality_of(a.get("metrics", {})), quality_of(b.get("metrics", {}))
        check(sorted(qa) == sorted(qb), f"{pid}: same quality metrics: local {sorted(qa)}, slurm {sorted(qb)}")
        for k in sorted(set(qa) & set(qb)):
            check(same_number(qa[k], qb[k]), f"{pid}: {k} local {qa[k]} vs slurm {qb[k]}")
            compared += 1
        check(sorted(a.get("metrics", {})) == sorted(b.get("metrics", {})),
              f"{pid}: same metric names (timings included)")
    check(compared > 0, "some quality metric was compared")
    return compared


def main():
    work = tempfile.mkdtemp(prefix="vitrine-slurm-sweep-")
    try:
        with SlurmCluster() as cluster:
            env = cluster.env
            local = os.path.join(work, "local")
            r = run(["sweep", sweep_file, "--out", local], env)
            check(r.returncode == 0, f"local sweep exit status 0 (got {r.returncode}): {r.stderr[-3000:]}")
            print(f"local sweep: {r.seconds:.1f} s", flush=True)

            out = os.path.join(work, "slurm")
            r = run(["sweep", sweep_file, "--out", out, "--slurm"], env)
            check(r.returncode == 0,
                  f"--slurm exit status 0 (got {r.returncode}): {r.stdout[-2000:]}{r.stderr[-3000:]}")
            print(f"--slurm sweep: {r.seconds:.1f} s", flush=True)
            check("array job" in r.stdout and "collect job" in r.stdout, f"--slurm names its jobs: {r.stdout}")
            check("sweep.json" in r.stdout and "report.html" in r.stdout,
                  f"--slurm says where the table is: {r.stdout}")
            check("done" in r.stderr and "running" in r.stderr and "pending" in r.stderr,
                  f"--slurm shows progress from squeue: {r.stderr[-1500:]}")
            if os.path.exists(os.path.join(out, "sweep.json")) and os.path.exists(os.path.join(local, "sweep.json")):
                n = compare_tables(table(local), table(out))
                print(f"compared {n} quality metrics of {len(table(out)['points'])} points", flush=True)
            else:
                check(False, "both runs wrote sweep.json" + cluster.logs())
            check(os.path.exists(os.path.join(out, "report.html")), "the collect job wrote report.html")
            scripts = os.path.join(out, "slurm", "1")
            check(os.path.exists(os.path.join(scripts, "array.sh")), "the array script is kept in DIR/slurm/1/")
            with open(os.path.join(scripts, "array.sh")) as f:
                script = f.read()
            check(f"--array=0-{len(table(out)['points']) - 1}" in script, f"one array task per point:\n{script}")
            check(vitrine in script, "the array runs this same vitrine binary by its absolute path")

            # Resume: every point is done, so only the collect job goes.
            r = run(["sweep", sweep_file, "--out", out, "--slurm"], env)
            check(r.returncode == 0, f"second --slurm exit 0 (got {r.returncode}): {r.stderr[-2000:]}")
            check("0 to submit" in r.stdout and "no array" in r.stdout, f"second --slurm submits no array: {r.stdout}")

            # Another sweep's folder is refused before anything is submitted (resume would trust its results).
            with open(sweep_file) as f:
                other = json.load(f)
            other["axes"][0]["values"] = list(reversed(other["axes"][0]["values"]))
            here = os.path.dirname(os.path.abspath(sweep_file))  # its paths are relative to it; the copy is elsewhere
            for key in ("graph", "reference"):
                if isinstance(other.get(key), str):
                    other[key] = os.path.join(here, other[key])
            for point in other.get("points", []):
                if isinstance(point.get("variant"), str):
                    point["variant"] = os.path.join(here, point["variant"])
            for axis in other["axes"]:
                if isinstance(axis.get("variants"), list):
                    axis["variants"] = [os.path.join(here, v) for v in axis["variants"]]
            other_file = os.path.join(work, "other.sweep.json")
            with open(other_file, "w") as f:
                json.dump(other, f)
            r = run(["sweep", other_file, "--out", out, "--slurm"], env)
            check(r.returncode == 1 and "holds the results of another sweep" in r.stderr and
                  not os.path.exists(os.path.join(out, "slurm", "3")),
                  f"--slurm refuses another sweep's folder: {r.returncode} {r.stderr[-800:]}")

            # --no-wait: returns at once; the jobs finish on their own.
            out2 = os.path.join(work, "nowait")
            r = run(["sweep", sweep_file, "--out", out2, "--slurm", "--no-wait"], env)
            check(r.returncode == 0 and "not waiting" in r.stdout, f"--no-wait returns: {r.stdout}{r.stderr}")
            deadline = time.monotonic() + 600
            while time.monotonic() < deadline:
                q = subprocess.run(["squeue", "--me", "-h"], env=env, capture_output=True, text=True)
                if q.returncode == 0 and not q.stdout.strip():
                    break
                time.sleep(1)
            check(os.path.exists(os.path.join(out2, "sweep.json")), "after --no-wait the collect job wrote sweep.json")
            if os.path.exists(os.path.join(out2, "sweep.json")):
                check(table(out2)["summary"] == table(local)["summary"], "--no-wait table's summary = local")

            # Errors: a bad "slurm" block, in a copy of the sweep file whose graph paths are made absolute.
            with open(sweep_file) as f:
                doc = json.load(f)
            base = os.path.dirname(sweep_file)

            def absolute(node):  # graph, reference and variant paths are relative to the sweep file
                if isinstance(node, dict):
                    for k, v in node.items():
                        if k in ("graph", "reference", "variant") and isinstance(v, str):
                            node[k] = os.path.join(base, v)
                        elif k == "variants" and isinstance(v, list):
                            node[k] = [os.path.join(base, x) for x in v]
                        else:
                            absolute(v)
                elif isinstance(node, list):
                    for v in node:
                        absolute(v)

            absolute(doc)
            doc["slurm"] = {"partition": "debug", "gpus_per_task": "one"}
            bad = os.path.join(work, "bad.sweep.json")
            with open(bad, "w") as f:
                json.dump(doc, f)
            r = run(["sweep", bad, "--out", os.path.join(work, "bad"), "--slurm"], env)
            check(r.returncode == 1 and "/slurm/gpus_per_task" in r.stderr,
                  f"bad slurm block: exit 1 naming /slurm/gpus_per_task (got {r.returncode}: {r.stderr})")

            # A point that fails (subpix 2 is outside FXAA's range [0, 1]): recorded as failed in both runs alike, the
            # other point done; exit status 3 in both.
            del doc["slurm"]
            doc.pop("points", None)
            doc["axes"] = [{"name": "subpix", "set": "fxaa.params.subpix", "values": [0.5, 2.0]}]
            failing = os.path.join(work, "failing.sweep.json")
            with open(failing, "w") as f:
                json.dump(doc, f)
            rl = run(["sweep", failing, "--out", os.path.join(work, "failing-local")], env)
            rs = run(["sweep", failing, "--out", os.path.join(work, "failing-slurm"), "--slurm"], env)
            check(rl.returncode == 3 and rs.returncode == 3,
                  f"a failed point: exit 3 locally ({rl.returncode}) and with --slurm ({rs.returncode}): "
                  f"{rs.stderr[-2000:]}")
            tl, ts = table(os.path.join(work, "failing-local")), table(os.path.join(work, "failing-slurm"))
            statuses = [q["status"] for q in ts["points"]]
            check(statuses == ["done", "failed"], f"statuses {statuses}")
            compare_tables(tl, ts)

            # Tasks Slurm ends without a result (here: the array cancelled while it waits for the reference job) are
            # recorded as failed by the waiting command, with what happened, and the table shows them.
            cancelled = os.path.join(work, "cancelled")
            p = subprocess.Popen([vitrine, "sweep", failing, "--out", cancelled, "--slurm"], env=env,
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            jobs_file = os.path.join(cancelled, "slurm", "1", "jobs.json")
            deadline = time.monotonic() + 60
            while not os.path.exists(jobs_file) and time.monotonic() < deadline and p.poll() is None:
                time.sleep(0.05)
            with open(jobs_file) as f:
                array_job = json.load(f)["array"]
            subprocess.run(["scancel", array_job], env=env, check=True)
            out_c, err_c = p.communicate(timeout=300)
            check(p.returncode == 3, f"cancelled array: exit 3 (got {p.returncode}): {out_c}{err_c}")
            tc = table(cancelled)
            check([q["status"] for q in tc["points"]] == ["failed", "failed"],
                  f"cancelled tasks recorded as failed: {[q['status'] for q in tc['points']]}")
            check(all("ended without a result" in q.get("error", "") and "never started" in q.get("error", "")
                      for q in tc["points"]),
                  f"their error says what happened: {[q.get('error') for q in tc['points']]}")
            # ... and --retry-failed runs them.
            r = run(["sweep", failing, "--out", cancelled, "--slurm", "--retry-failed"], env)
            check(r.returncode == 3 and [q["status"] for q in table(cancelled)["points"]] == ["done", "failed"],
                  f"--retry-failed reruns cancelled points: {r.returncode} "
                  f"{[q['status'] for q in table(cancelled)['points']]}")

            r = run(["sweep", sweep_file, "--out", os.path.join(work, "nopart"), "--slurm", "--partition", "nosuch"],
                    env)
            check(r.returncode == 1 and "sbatch" in r.stderr and "partition" in r.stderr.lower(),
                  f"unknown partition: exit 1 with sbatch's message (got {r.returncode}: {r.stderr})")

            nopath = dict(env, PATH="/nonexistent")
            r = run(["sweep", sweep_file, "--out", os.path.join(work, "nosbatch"), "--slurm"], nopath)
            check(r.returncode == 1 and "sbatch" in r.stderr and "not found" in r.stderr,
                  f"no sbatch: exit 1 saying sbatch is not found (got {r.returncode}: {r.stderr})")

            leftover = subprocess.run(["squeue", "--me", "-h"], env=env, capture_output=True, text=True).stdout
            check(not leftover.strip(), f"no job left in the queue: {leftover}")
            strays_before_stop = cluster.stray_pids()
        check(not cluster.stray_pids(), f"no process of the cluster left (before stop: {strays_before_stop})")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print(f"{passed} passed, {len(failed)} failed", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""A one-node Slurm cluster in a temporary folder, for tests (Debian's slurmctld, slurmd, slurm-client, munge).

usage: slurm_cluster.py selftest            start, run a 4-task `sbatch --array --wait` job, check its files, stop
       slurm_cluster.py run -- CMD ARGS...  start, run CMD with SLURM_CONF set to the cluster's config, stop

or from Python: `with SlurmCluster() as cluster: subprocess.run(["sbatch", ...], env=cluster.env)`.

Everything lives in one temporary folder (mode 0711, its subfolders 0700 but munged's socket folder 0755): the munge
key, socket, pid, seed and log files, slurm.conf, the controller's state and slurmd's spool. The daemons run in the
foreground (munged -F, slurmctld -D, slurmd -D) as children of this process on free TCP ports, so each is stopped by
its own pid at the end (SIGTERM, then SIGKILL after a grace period); nothing is written under /etc, /run or /var.
Jobs still queued at the end are cancelled first, and any slurmstepd left behind is found by a marker variable only
our slurmd carries in its environment and killed by pid. If a daemon does not come up, SlurmClusterError carries the
daemons' logs: a test using this fails, it never skips.

What a container needed, solved within the folder's config: munged refuses a socket folder that other users cannot
reach (a mkdtemp folder is 0700), hence the modes above rather than --force; no systemd (daemons run in the
foreground, children of this process); no /run/munge or /var/log/slurm (every path points into the folder); no
cgroup hierarchy to delegate (proctrack/linuxproc, task/none, jobacct_gather/none: nothing touches cgroups); a host
name that may not resolve (SlurmctldHost and the node's NodeAddr are 127.0.0.1); no accounting database
(accounting_storage/none: `sacct` does not work on this cluster, `squeue` does).
"""
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

MARKER = "VITRINE_SLURM_TEST_CLUSTER"


class SlurmClusterError(RuntimeError):
    pass


def _free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _meminfo_mb():
    with open("/proc/meminfo") as f:
        for line in f:
            if line.startswith("MemTotal:"):
                return int(line.split()[1]) // 1024
    return 1024


class SlurmCluster:
    """Starts munged, slurmctld and slurmd on entry and stops them (by pid) on exit. `env` is os.environ plus
    SLURM_CONF for the client commands (sbatch, squeue, sinfo, scancel)."""

    def __init__(self, keep_dir=False, log=print):
        self.keep_dir = keep_dir
        self.log = log
        self.dir = None
        self.procs = {}
        self.env = None

    # -- set-up ---------------------------------------------------------------------------------------------------
    def __enter__(self):
        try:
            self.start()
        except BaseException:
            self.stop()
            raise
        return self

    def __exit__(self, *exc):
        self.stop()
        return False

    def start(self):
        for tool in ("munged", "munge", "unmunge", "slurmctld", "slurmd", "sbatch", "sinfo", "squeue", "scancel"):
            if shutil.which(tool) is None:
                raise SlurmClusterError(
                    f"'{tool}' not found: install Debian's munge, slurmctld, slurmd and slurm-client "
                    "(tools/install-deps.sh does)")
        self.dir = tempfile.mkdtemp(prefix="vitrine-slurm-")
        # munged wants its socket reachable by every user (execute on each directory above it, the socket's own
        # directory readable): the folder is 0711 and the socket's 0755; everything else stays 0700.
        os.chmod(self.dir, 0o711)
        d = self.dir
        self.hostname = socket.gethostname().split(".")[0]
        self.conf = os.path.join(d, "slurm.conf")
        self.munge_socket = os.path.join(d, "munge-socket", "munge.socket")
        os.makedirs(os.path.join(d, "munge-socket"), mode=0o755)
        os.chmod(os.path.join(d, "munge-socket"), 0o755)  # mode= is masked by the umask
        os.makedirs(os.path.join(d, "munge"), mode=0o700)
        os.makedirs(os.path.join(d, "state"), mode=0o700)
        os.makedirs(os.path.join(d, "spool"), mode=0o700)
        os.makedirs(os.path.join(d, "log"), mode=0o700)
        key = os.path.join(d, "munge", "munge.key")
        with open(os.open(key, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600), "wb") as f:
            f.write(os.urandom(1024))

        self.env = dict(os.environ)
        self.env["SLURM_CONF"] = self.conf
        daemon_env = dict(self.env)
        daemon_env[MARKER] = d

        munged = ["munged", "-F", "--socket", self.munge_socket, "--key-file", key,
                  "--pid-file", os.path.join(d, "munge", "munged.pid"),
                  "--log-file", os.path.join(d, "log", "munged.log"),
                  "--seed-file", os.path.join(d, "munge", "munged.seed")]
        self._spawn("munged", munged, daemon_env)
        self._wait_for(lambda: os.path.exists(self.munge_socket), 15, "munged's socket")
        probe = subprocess.run(f"munge -n -S '{self.munge_socket}' | unmunge -S '{self.munge_socket}'", shell=True,
                               capture_output=True, text=True)
        if probe.returncode != 0:
            raise SlurmClusterError("munge round trip failed: " + probe.stderr + self.logs())

        cpus = os.cpu_count() or 1
        memory = max(256, _meminfo_mb() - 512)
        with open(self.conf, "w") as f:
            f.write(f"""# written by tests/sweep/slurm_cluster.py
ClusterName=vitrinetest
SlurmctldHost={self.hostname}(127.0.0.1)
SlurmctldPort={_free_port()}
SlurmdPort={_free_port()}
SlurmUser={_user()}
SlurmdUser={_user()}
AuthType=auth/munge
AuthInfo=socket={self.munge_socket}
CredType=cred/munge
StateSaveLocation={d}/state
SlurmdSpoolDir={d}/spool
SlurmctldPidFile={d}/slurmctld.pid
SlurmdPidFile={d}/slurmd.pid
SlurmctldLogFile={d}/log/slurmctld.log
SlurmdLogFile={d}/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
MailProg=/bin/true
MinJobAge=120
KillWait=5
InactiveLimit=0
SlurmdParameters=config_overrides
NodeName={self.hostname} NodeAddr=127.0.0.1 CPUs={cpus} RealMemory={memory} State=UNKNOWN
PartitionName=debug Nodes={self.hostname} Default=YES MaxTime=INFINITE State=UP
""")
        self._spawn("slurmctld", ["slurmctld", "-D", "-c", "-f", self.conf], daemon_env)
        self._spawn("slurmd", ["slurmd", "-D", "-f", self.conf, "-N", self.hostname], daemon_env)

        def idle():
            r = subprocess.run(["sinfo", "-h", "-N", "-o", "%N %T"], env=self.env, capture_output=True, text=True)
            return r.returncode == 0 and "idle" in r.stdout

        self._wait_for(idle, 60, f"node {self.hostname} idle in sinfo")
        self.log(f"slurm cluster up in {d} (node {self.hostname}, {cpus} CPUs)")

    def _spawn(self, name, argv, env):
        out = open(os.path.join(self.dir, "log", name + ".stdout"), "w")
        self.procs[name] = subprocess.Popen(argv, env=env, stdout=out, stderr=subprocess.STDOUT,
                                            stdin=subprocess.DEVNULL, start_new_session=True)
        out.close()

    def _wait_for(self, ready, seconds, what):
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            for name, p in self.procs.items():
                if p.poll() is not None:
                    raise SlurmClusterError(f"{name} exited with status {p.returncode} while waiting for {what}"
                                            + self.logs())
            if ready():
                return
            time.sleep(0.25)
        raise SlurmClusterError(f"timed out after {seconds} s waiting for {what}" + self.logs())

    def logs(self):
        """Every daemon log of the folder, for error messages."""
        text = []
        logdir = os.path.join(self.dir or "", "log")
        if self.dir and os.path.isdir(logdir):
            for name in sorted(os.listdir(logdir)):
                with open(os.path.join(logdir, name), errors="replace") as f:
                    body = f.read()[-6000:]
                text.append(f"\n----- {logdir}/{name} -----\n{body}")
        return "".join(text)

    # -- tear-down ------------------------------------------------------------------------------------------------
    def stop(self):
        if self.env and self.procs.get("slurmctld") and self.procs["slurmctld"].poll() is None:
            subprocess.run(["scancel", "--full", "--quiet", "--partition", "debug"], env=self.env,
                           capture_output=True, timeout=30)
            deadline = time.monotonic() + 20
            while time.monotonic() < deadline:
                r = subprocess.run(["squeue", "-h", "-o", "%i"], env=self.env, capture_output=True, text=True)
                if r.returncode != 0 or not r.stdout.strip():
                    break
                time.sleep(0.5)
        for name in ("slurmd", "slurmctld", "munged"):
            p = self.procs.get(name)
            if p is None or p.poll() is not None:
                continue
            p.send_signal(signal.SIGTERM)
            try:
                p.wait(timeout=15)
            except subprocess.TimeoutExpired:
                self.log(f"{name} (pid {p.pid}) ignored SIGTERM for 15 s: killing it")
                p.kill()
                p.wait()
        for pid in self.stray_pids():
            self.log(f"killing leftover process {pid} of the test cluster")
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        self.procs = {}
        if self.dir and not self.keep_dir:
            shutil.rmtree(self.dir, ignore_errors=True)

    def stray_pids(self):
        """Processes (slurmstepd) forked from our slurmd that outlived it: they carry our marker variable."""
        if not self.dir:
            return []
        needle = f"{MARKER}={self.dir}".encode() + b"\0"
        found = []
        for entry in os.listdir("/proc"):
            if not entry.isdigit() or int(entry) == os.getpid():
                continue
            try:
                with open(f"/proc/{entry}/environ", "rb") as f:
                    if needle in f.read():
                        found.append(int(entry))
            except OSError:
                pass
        return found


def _user():
    import pwd
    return pwd.getpwuid(os.getuid()).pw_name


def selftest():
    with SlurmCluster() as cluster:
        outdir = os.path.join(cluster.dir, "out")
        os.mkdir(outdir)
        script = os.path.join(cluster.dir, "job.sh")
        with open(script, "w") as f:
            f.write("#!/bin/sh\necho \"task $SLURM_ARRAY_TASK_ID of $SLURM_ARRAY_JOB_ID\" > "
                    f"{outdir}/task-$SLURM_ARRAY_TASK_ID.txt\n")
        t0 = time.monotonic()
        r = subprocess.run(["sbatch", "--parsable", "--wait", "--array=0-3", "--output", f"{outdir}/slurm-%A_%a.out",
                            script], env=cluster.env, capture_output=True, text=True, timeout=120)
        if r.returncode != 0:
            raise SlurmClusterError(f"sbatch failed ({r.returncode}): {r.stderr}" + cluster.logs())
        job = r.stdout.strip().split(";")[0]
        for i in range(4):
            path = os.path.join(outdir, f"task-{i}.txt")
            if not os.path.exists(path):
                raise SlurmClusterError(f"array task {i} wrote no {path}" + cluster.logs())
            with open(path) as f:
                text = f.read().strip()
            if text != f"task {i} of {job}":
                raise SlurmClusterError(f"{path} says {text!r}, expected 'task {i} of {job}'")
        print(f"selftest: 4 array tasks of job {job} ran in {time.monotonic() - t0:.1f} s")
    return 0


def main(argv):
    if argv[1:2] == ["selftest"]:
        return selftest()
    if argv[1:3] == ["run", "--"] and len(argv) > 3:
        with SlurmCluster() as cluster:
            return subprocess.run(argv[3:], env=cluster.env).returncode
    print(__doc__.split("\n\n")[1], file=sys.stderr)
    return 2


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv))
    except SlurmClusterError as e:
        print(f"slurm_cluster: {e}", file=sys.stderr)
        sys.exit(1)

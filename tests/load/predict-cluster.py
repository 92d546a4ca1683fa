#!/usr/bin/env python3
"""One prediction job through one SQLite process and through PostgreSQL with one and with two
`kerf worker` processes behind a `kerf serve --job-workers 0`: wall time from upload
to done, the solver's own time, passes per second, CPU time of the kerf processes, and so the
overhead of claiming, heartbeats, splitting into parts and merging them against the one-process
run. On PostgreSQL the prediction is split into parts (`KERF_JOB_PART_S` core-seconds each,
default 8) that the workers run at once, and a finish step merges them; the script prints the
parts, their solve time and the finish step's. The machine's load average is printed with each
run (the machine may be shared).

Usage (release build, PostgreSQL from Debian's package; as root it runs as the postgres user):
    cargo build --release -p kerf-server
    KERF_PREDICT_PICK=0.29963 tests/load/predict-cluster.py target/release/kerf   # the patent's size
    tests/load/predict-cluster.py target/release/kerf sqlite 2   # only these runs
Without KERF_PREDICT_PICK the job is predict-job.py's 103 041-pass raster.
"""
import glob
import importlib.util
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request

HERE = os.path.dirname(os.path.abspath(__file__))


def load_job():
    spec = importlib.util.spec_from_file_location("predict_job", os.path.join(HERE, "predict-job.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.job()


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_up(base):
    for _ in range(600):
        try:
            urllib.request.urlopen(base + "/healthz", timeout=1)
            return
        except OSError:
            time.sleep(0.1)
    raise SystemExit(f"{base} did not come up")


def cpu_seconds(pid):
    fields = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


class Postgres:
    """A throw-away server in a temporary folder (as tests/src/postgres.rs starts one)."""

    def __init__(self):
        found = glob.glob("/usr/lib/postgresql/*/bin/initdb")
        self.bin = os.path.dirname(sorted(found)[-1]) if found else os.path.dirname(shutil.which("initdb"))
        self.folder = tempfile.mkdtemp(prefix="kerf-pg-")
        self.root = os.geteuid() == 0
        if self.root:
            shutil.chown(self.folder, "postgres", "postgres")
        self.port = free_port()
        data = os.path.join(self.folder, "data")
        self.run("initdb", "-D", data, "-U", "postgres", "--auth=trust", "--no-sync", "--no-instructions")
        options = f"-p {self.port} -k {self.folder} -c listen_addresses=127.0.0.1 -c max_connections=200"
        self.run("pg_ctl", "-D", data, "-l", os.path.join(self.folder, "log"), "-o", options, "-w", "start")
        self.url = f"postgres://postgres@127.0.0.1:{self.port}/postgres"

    def run(self, program, *arguments):
        command = [os.path.join(self.bin, program), *arguments]
        if self.root:
            command = ["runuser", "-u", "postgres", "--", *command]
        subprocess.run(command, check=True, stdout=subprocess.DEVNULL)

    def query(self, sql):
        command = [os.path.join(self.bin, "psql"), "-h", self.folder, "-p", str(self.port), "-U", "postgres",
                   "-At", "-F", " ", "-c", sql, "postgres"]
        if self.root:
            command = ["runuser", "-u", "postgres", "--", *command]
        return subprocess.run(command, check=True, capture_output=True, text=True).stdout.strip()

    def stop(self):
        self.run("pg_ctl", "-D", os.path.join(self.folder, "data"), "-m", "fast", "-w", "stop")
        shutil.rmtree(self.folder, ignore_errors=True)


def load():
    return open("/proc/loadavg").read().split()[0]


def measure(label, kerf, database, workers, body, postgres=None):
    port = free_port()
    base = f"http://127.0.0.1:{port}"
    env = dict(os.environ, RUST_LOG="warn")
    serve = [kerf, "serve", "--bind", f"127.0.0.1:{port}", "--database", database, "--max-body-bytes", "268435456"]
    if workers:
        serve += ["--job-workers", "0"]
    processes = [subprocess.Popen(serve, env=env)]
    for _ in range(workers):
        metrics = free_port()
        processes.append(subprocess.Popen(
            [kerf, "worker", "--database", database, "--metrics-bind", f"127.0.0.1:{metrics}"], env=env))
    try:
        wait_up(base)
        time.sleep(1)
        cpu = {p.pid: cpu_seconds(p.pid) for p in processes}
        load_before = load()
        started = time.time()
        request = urllib.request.Request(base + "/api/v1/jobs", data=body,
                                         headers={"content-type": "application/json"})
        submitted = json.load(urllib.request.urlopen(request))
        while True:
            job = json.load(urllib.request.urlopen(f"{base}/api/v1/jobs/{submitted['id']}"))
            if job["status"] not in ("queued", "running"):
                break
            time.sleep(0.25)
        wall = time.time() - started
        cpu = sum(cpu_seconds(p.pid) - cpu[p.pid] for p in processes)
        if job["status"] != "done":
            raise SystemExit(f"{label}: {job['status']}: {job.get('error')}")
        result = job["results"][0]["result"]
        passes, solve = result["summary"]["passes"], result["timings"]["solve_ms"] / 1000
        print(f"{label:34} {passes} passes: upload to done {wall:7.1f} s ({passes / wall:6.0f} passes/s), "
              f"kerf CPU {cpu:7.1f} s ({cpu / passes * 1e3:.2f} ms per pass), load {load_before} -> {load()}",
              flush=True)
        if not postgres:
            print(f"{'':34} solve {solve:.1f} s, outside the solver {wall - solve:.1f} s", flush=True)
        else:
            # Parts: their count, solve time (summed over workers) and the finish step's time.
            rows = postgres.query("SELECT kind, COUNT(*), SUM(solve_seconds), SUM(work), MAX(attempts) "
                                  "FROM job_chunks GROUP BY kind ORDER BY kind")
            parts_seconds = 0.0
            for row in rows.splitlines():
                kind, count, seconds, work, attempts = row.split()
                if kind == "part":
                    parts_seconds = float(seconds)
                    print(f"{'':34} {count} parts: solve {parts_seconds:.1f} s summed over the workers "
                          f"(estimated {float(work):.1f} core-s)", flush=True)
            print(f"{'':34} finish step (merge, correct, write the answer and program): "
                  f"{solve - parts_seconds:.1f} s", flush=True)
        return wall, cpu
    finally:
        for p in processes:
            p.terminate()
        for p in processes:
            p.wait()


def main():
    kerf = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else "target/release/kerf")
    # Which runs: any of sqlite, 1 and 2 (PostgreSQL with that many workers); all by default.
    runs = sys.argv[2:] or ["sqlite", "1", "2"]
    job = load_job()
    print(f"job: {job['name']}", flush=True)
    folder = tempfile.mkdtemp(prefix="kerf-measure-")
    try:
        body = json.dumps(job).encode()
        print(f"job file {len(body) / 1e6:.1f} MB", flush=True)
        alone = None
        if "sqlite" in runs:
            alone = measure("SQLite, one process", kerf, os.path.join(folder, "kerf.db"), 0, body)
        for workers in [int(run) for run in runs if run != "sqlite"]:
            postgres = Postgres()
            try:
                shared = measure(f"PostgreSQL, {workers} worker process(es)", kerf, postgres.url, workers, body,
                                 postgres)
            finally:
                postgres.stop()
            if alone:
                print(f"{'':34} against one SQLite process: wall {shared[0] - alone[0]:+.1f} s, "
                      f"CPU {shared[1] - alone[1]:+.1f} s ({(shared[1] / alone[1] - 1) * 100:+.1f} %)", flush=True)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()

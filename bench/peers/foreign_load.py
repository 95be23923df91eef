"""Runs a command and reports how busy the rest of the machine was while it ran: the
peer benchmark's check that an engine was timed on a quiet machine (a wrapper such as
/tmp/quiet.sh pauses known background jobs, not everything else that may start).

    /usr/bin/python3 bench/peers/foreign_load.py [--wait-quiet SECONDS CORES] CMD ARGS...

CMD's output passes through; then one JSON line follows on stdout:
  {"foreign_cores": F, "wall_s": W}
F = (CPU time the whole machine spent busy - CPU time of CMD and its children) / W, the
average number of cores other processes (or the hypervisor, as steal time) took. It is
null where /proc/stat is missing. Exit status: CMD's.

--wait-quiet SECONDS CORES first waits (at most SECONDS) for a half-second in which the
whole machine was busy on fewer than CORES cores, so that CMD starts in a quiet spell
rather than in the middle of someone else's job.
"""
from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import time

# /proc/stat's "cpu" fields that count as busy: user nice system idle iowait irq softirq steal.
BUSY_FIELDS = (0, 1, 2, 5, 6, 7)


def machine_busy_seconds():
    try:
        with open("/proc/stat") as f:
            fields = f.readline().split()
    except OSError:
        return None
    if not fields or fields[0] != "cpu":
        return None
    ticks = [int(v) for v in fields[1:]]
    return sum(ticks[i] for i in BUSY_FIELDS if i < len(ticks)) / os.sysconf("SC_CLK_TCK")


def children_cpu_seconds() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def wait_quiet(seconds: float, cores: float) -> None:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        busy0, t0 = machine_busy_seconds(), time.monotonic()
        if busy0 is None:
            return
        time.sleep(0.5)
        if (machine_busy_seconds() - busy0) / (time.monotonic() - t0) < cores:
            return


def main() -> int:
    cmd = sys.argv[1:]
    if cmd[:1] == ["--wait-quiet"]:
        if len(cmd) < 3:
            print("foreign_load.py: --wait-quiet needs SECONDS and CORES", file=sys.stderr)
            return 2
        wait_quiet(float(cmd[1]), float(cmd[2]))
        cmd = cmd[3:]
    if not cmd:
        print("foreign_load.py: usage: foreign_load.py [--wait-quiet SECONDS CORES] CMD ARGS...", file=sys.stderr)
        return 2
    busy0, own0, start = machine_busy_seconds(), children_cpu_seconds(), time.monotonic()
    try:
        code = subprocess.call(cmd)
    except OSError as e:
        print(f"foreign_load.py: cannot start {cmd[0]}: {e.strerror}", file=sys.stderr)
        return 127
    wall, busy1 = time.monotonic() - start, machine_busy_seconds()
    foreign = None
    if busy0 is not None and busy1 is not None and wall > 0:
        foreign = max(0.0, (busy1 - busy0) - (children_cpu_seconds() - own0)) / wall
    sys.stdout.flush()
    print(json.dumps({"foreign_cores": foreign, "wall_s": wall}), flush=True)
    return code


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Peak memory of `ampi run` on large photos, stage by stage.

Enlarges a photo to each size (the ffmpeg program, bicubic) into a temporary folder,
runs `ampi run` on it and samples, every 20 ms, the resident memory of ampi and of its
children (the ffmpeg process that encodes the MP4), attributing each sample to the stage
that was running. Prints, per size, every stage's peaks (ampi, encoder, the two together)
and the run's wall time. A 2 GB board needs the two together to fit.

  python3 scripts/peak_memory.py [--ampi build/ampi] [--photo FILE] [--sizes 3840x2160,7680x4320]
                                 [-- extra ampi run options]
"""
import argparse
import os
import subprocess
import sys
import tempfile
import threading
import time

SAMPLE_SECONDS = 0.02


def resident_mb(pid):
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024
    except OSError:
        pass
    return 0.0


def children(pid):
    try:
        with open(f"/proc/{pid}/task/{pid}/children") as f:
            return [int(p) for p in f.read().split()]
    except OSError:
        return []


def enlarge(photo, size, folder):
    out = os.path.join(folder, f"photo_{size}.jpg")
    width, height = size.split("x")
    subprocess.run(["ffmpeg", "-v", "error", "-y", "-i", photo, "-vf", f"scale={width}:{height}:flags=bicubic",
                    "-q:v", "2", out], check=True)
    return out


def run_sampled(command):
    """Runs command; returns (stage rows, wall seconds). A row: name, ms, ampi MB, encoder MB, sum MB."""
    start = time.monotonic()
    process = subprocess.Popen(command, stderr=subprocess.PIPE, text=True)
    events = []  # (time, stderr line)

    def read_stderr():
        for line in process.stderr:
            events.append((time.monotonic(), line.rstrip("\n")))

    reader = threading.Thread(target=read_stderr)
    reader.start()
    samples = []  # (time, ampi MB, encoder MB)
    while process.poll() is None:
        own = resident_mb(process.pid)
        encoder = sum(resident_mb(child) for child in children(process.pid))
        samples.append((time.monotonic(), own, encoder))
        time.sleep(SAMPLE_SECONDS)
    reader.join()
    wall = time.monotonic() - start
    if process.returncode != 0:
        sys.exit("ampi run failed:\n" + "\n".join(line for _, line in events))
    rows, begin = [], start
    for moment, line in events:
        parts = line.split()
        if not line.startswith("ampi:   ") or len(parts) < 3 or parts[-1] != "ms":
            continue
        # A stage shorter than the sampling period: the last sample before it ended.
        window = [s for s in samples if begin <= s[0] <= moment] or \
            [s for s in samples if s[0] <= moment][-1:] or [(0, 0.0, 0.0)]
        rows.append((" ".join(parts[1:-2]), parts[-2], max(s[1] for s in window), max(s[2] for s in window),
                     max(s[1] + s[2] for s in window)))
        begin = moment
    return rows, wall


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--ampi", default="build/ampi")
    parser.add_argument("--photo", default="../shared/data/photos/debian/Path.jpg")
    parser.add_argument("--sizes", default="3840x2160,7680x4320")
    parser.add_argument("extra", nargs="*", help="options passed on to ampi run (after --)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="ampi_peak_memory_") as folder:
        for size in args.sizes.split(","):
            photo = enlarge(args.photo, size, folder)
            out = os.path.join(folder, f"out_{size}")
            rows, wall = run_sampled([args.ampi, "run", photo, "-o", out, "--force", *args.extra])
            print(f"\n{size} ({os.path.basename(args.photo)} enlarged), wall {wall:.1f} s\n")
            print("| stage | ms | ampi (MB) | encoder (MB) | together (MB) |")
            print("|---|---:|---:|---:|---:|")
            for name, ms, own, encoder, together in rows:
                print(f"| {name} | {ms} | {own:.0f} | {encoder:.0f} | {together:.0f} |")
            print(f"| **peak** | | {max(r[2] for r in rows):.0f} | {max(r[3] for r in rows):.0f} | "
                  f"**{max(r[4] for r in rows):.0f}** |")


if __name__ == "__main__":
    main()

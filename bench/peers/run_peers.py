"""The peer benchmark: ampi's depth network beside ONNX Runtime, OpenCV DNN and PyTorch
running the same network on the same pixels with the same thread counts. Called by
bench/peers/run.sh (which installs and builds what it needs); writes bench/RESULTS.md.

For every network and size: the bundled example photo resized to the size is the input
of all four engines; each engine process loads the network once and, per thread count,
runs it --warmup times untimed and then N times timed (medians reported); each saves its
output, and every peer's output is compared with ampi's (largest absolute difference
relative to the range of ampi's output: the proof that they ran the same network).

--smoke runs a tiny case (64x64) and only checks the differences against --tolerance:
the ctest test peers_smoke. Any engine that is missing or fails stops the run with its
error (exit 1): a peer is never skipped. The one exception is written into the table:
OpenCV 4.6's ONNX importer cannot read the Depth Anything V2 export, so its cells of
those rows say so, with the importer's message.

Depth Anything V2 rows (--models vits, vitb or vitl) run a random-weight model made the
documented way (training/random_depth_anything.py, then import_depth_anything.py) at
--vit-sizes: the real checkpoint cannot be downloaded here, and the speed is the same.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import shlex
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from PIL import Image

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(REPO / "weights_format"))
from ampw import read_ampw  # noqa: E402

PEERS = ("onnxruntime", "opencv-dnn", "pytorch")
PEER_TITLES = {"onnxruntime": "ONNX Runtime", "opencv-dnn": "OpenCV DNN", "pytorch": "PyTorch"}
# The targets: ampi's latency at most this fraction of the peer's (lite, 1024x768, 2 threads).
TARGETS = {"onnxruntime": 0.8, "opencv-dnn": 0.5, "pytorch": 0.3}
TARGET_CASE = ("lite", (1024, 768), 2)
# Depth Anything V2's targets (ViT-S at 518x518, 2 threads); OpenCV DNN cannot run it.
VIT_TARGETS = {"onnxruntime": 0.8, "pytorch": 0.5}
VIT_TARGET_CASE = ("vits", (518, 518), 2)
VIT_VARIANTS = ("vits", "vitb", "vitl")
# Engines whose failure on a family is reported in the table instead of stopping the run.
MAY_FAIL = {"vit": ("opencv-dnn",)}


def parse_size(text: str):
    w, h = (int(v) for v in text.lower().split("x"))
    return w, h


def parse_sizes_runs(text: str):
    """'512x384:7,1024x768:5' -> [((512, 384), 7), ((1024, 768), 5)]."""
    out = []
    for item in text.split(","):
        size, _, runs = item.partition(":")
        out.append((parse_size(size), int(runs or 5)))
    return out


def fail(message: str):
    print(f"run_peers.py: {message}", file=sys.stderr)
    sys.exit(1)


class EngineFailed(RuntimeError):
    pass


# ---- inputs and exports -------------------------------------------------------------------

def make_inputs(photo: Path, size, multiple: int, folder: Path):
    """The photo resized to `size` as RGB floats in [0, 1]: H x W x 3 for ampi (which pads
    to its multiple itself) and 1 x 3 x Hp x Wp for the peers, padded the way ampi pads
    (bottom rows and right columns replicate the last ones)."""
    w, h = size
    rgb = np.asarray(Image.open(photo).convert("RGB").resize((w, h), Image.BILINEAR), np.float32) / 255.0
    hp, wp = -(-h // multiple) * multiple, -(-w // multiple) * multiple
    padded = np.pad(rgb, ((0, hp - h), (0, wp - w), (0, 0)), mode="edge")
    hwc, nchw = folder / f"input_{w}x{h}_hwc.npy", folder / f"input_{w}x{h}_nchw.npy"
    np.save(hwc, np.ascontiguousarray(rgb))
    np.save(nchw, np.ascontiguousarray(padded.transpose(2, 0, 1)[None]))
    return hwc, nchw, (wp, hp)


def export_onnx(weights: Path, padded_size, folder: Path) -> Path:
    """The network's ONNX export for one padded input size (re-made when older than the
    weights or the export code)."""
    wp, hp = padded_size
    onnx = folder / f"{weights.stem}_{wp}x{hp}.onnx"
    sources = [weights, HERE / "export_onnx.py", HERE / "peer_net.py"]
    if onnx.exists() and all(onnx.stat().st_mtime >= s.stat().st_mtime for s in sources):
        return onnx
    try:
        run_checked([sys.executable, str(HERE / "export_onnx.py"), str(weights), str(onnx), "--size", f"{wp}x{hp}"],
                    f"ONNX export of {weights.name} at {wp}x{hp}")
    except EngineFailed as e:
        fail(str(e))
    return onnx


def random_vit(variant: str, folder: Path) -> Path:
    """A random-weight Depth Anything V2 file of `variant`, made as a user makes one from
    a download (a checkpoint, then the importer); kept in `folder` for later runs."""
    ampw = folder / f"dav2_random_{variant}.ampw"
    if ampw.exists():
        return ampw
    pth = folder / f"dav2_random_{variant}.pth"
    try:
        run_checked([sys.executable, str(REPO / "training" / "random_depth_anything.py"), variant, str(pth)],
                    f"random {variant} checkpoint")
        run_checked([sys.executable, str(REPO / "training" / "import_depth_anything.py"), str(pth), str(ampw)],
                    f"import of the random {variant} checkpoint")
    except EngineFailed as e:
        fail(str(e))
    pth.unlink()
    return ampw


def weights_of(model: str, folder: Path) -> Path:
    if model in VIT_VARIANTS:
        return random_vit(model, folder)
    weights = REPO / "weights" / f"depth_{model}.ampw"
    if not weights.is_file():
        fail(f"{weights}: no such weight file")
    return weights


# ---- engines ------------------------------------------------------------------------------

def run_checked(cmd, what: str) -> str:
    """The command's stdout; EngineFailed (its first error line) when it fails."""
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, cwd=REPO)
    except OSError as e:
        raise EngineFailed(f"{what}: cannot start {cmd[0]}: {e.strerror}")
    if proc.returncode != 0:
        err = (proc.stderr or proc.stdout).strip().splitlines()
        raise EngineFailed(f"{what} failed (exit {proc.returncode}): {err[0] if err else 'no message'}"
                           f"\n  command: {' '.join(cmd)}")
    return proc.stdout


def engine_commands(args, weights: Path, onnx: Path, hwc: Path, nchw: Path, runs: int, save: Path):
    common = ["--threads", ",".join(map(str, args.threads)), "--runs", str(runs), "--warmup", str(args.warmup)]
    return {
        "ampi": [args.ampi, "bench", "network", "--weights", str(weights), "--input", str(hwc),
                 "--save", f"{save}_ampi"] + common,
        "onnxruntime": ["node", str(HERE / "ort_peer.js"), "--model", str(onnx), "--input", str(nchw),
                        "--save", f"{save}_onnxruntime"] + common,
        "opencv-dnn": [args.opencv_peer, "--model", str(onnx), "--input", str(nchw),
                       "--save", f"{save}_opencv-dnn"] + common,
        "pytorch": [sys.executable, str(HERE / "torch_peer.py"), "--weights", str(weights), "--input", str(nchw),
                    "--save", f"{save}_pytorch"] + common,
    }


def run_engine_once(name: str, cmd, args):
    """({threads: {"ms": [...], ...}}, foreign cores) from one run of the engine. `wrap`
    prefixes the command (e.g. a script that waits for a quiet machine): each engine process
    is wrapped on its own, so a long run never holds a machine-wide lock for more than one
    engine. Inside the wrapper, foreign_load.py measures how busy the rest of the machine was."""
    results, foreign = {}, None
    wait = ["--wait-quiet", str(args.wait_quiet), str(args.max_foreign)] if args.wait_quiet > 0 else []
    full = list(args.wrap) + [sys.executable, str(HERE / "foreign_load.py")] + wait + list(cmd)
    for line in run_checked(full, name).splitlines():
        if line.startswith("{"):
            record = json.loads(line)
            if "foreign_cores" in record:
                foreign = record["foreign_cores"]
            else:
                results[int(record["threads"])] = record
    return results, foreign


def run_engine(name: str, cmd, args) -> dict:
    """The engine's results; re-run (up to --retries times, after a pause) while other
    processes took more than --max-foreign cores on average, keeping the quietest run."""
    best = None
    for attempt in range(args.retries + 1):
        results, foreign = run_engine_once(name, cmd, args)
        if best is None or (foreign or 0.0) < best[1]:
            best = (results, foreign or 0.0, foreign)
        if foreign is None or foreign <= args.max_foreign:
            break
        print(f"    {name}: other processes took {foreign:.2f} cores meanwhile"
              + ("; again in 20 s" if attempt < args.retries else "; keeping the quietest run"),
              file=sys.stderr, flush=True)
        if attempt < args.retries:
            time.sleep(20)
    results, _, foreign = best
    for record in results.values():
        record["foreign_cores"] = foreign
    return results


def relative_difference(peer: np.ndarray, ampi: np.ndarray) -> float:
    h, w = ampi.shape
    if peer.shape[0] < h or peer.shape[1] < w:
        fail(f"a peer's output {peer.shape} is smaller than ampi's {ampi.shape}")
    span = float(ampi.max() - ampi.min())
    if not span > 0:
        fail("ampi's output is constant: the differences would prove nothing")
    return float(np.abs(peer[:h, :w].astype(np.float64) - ampi).max() / span)


def rounds_runs(runs: int, rounds: int) -> int:
    """Timed runs per engine process when `runs` are spread over `rounds` rounds."""
    return -(-runs // rounds)


def pool_timings(pooled: dict, results: dict):
    """Adds one round's results of an engine to its earlier rounds': the timings of each
    thread count joined, the busiest round's foreign load kept."""
    for threads, record in results.items():
        if threads not in pooled:
            pooled[threads] = dict(record, ms=list(record["ms"]))
            continue
        pooled[threads]["ms"] += record["ms"]
        loads = [f for f in (pooled[threads]["foreign_cores"], record["foreign_cores"]) if f is not None]
        pooled[threads]["foreign_cores"] = max(loads) if loads else None


def measure_case(args, model: str, weights: Path, size, runs: int, folder: Path, multiple: int) -> dict:
    """One network and size: --rounds rounds, each running every engine once in turn, so
    a slow spell of a shared machine falls on every engine rather than on whichever ran
    then; each engine's timings are pooled over the rounds. The outputs of the last round
    are compared. An engine of MAY_FAIL that fails is recorded in case["failed"] and not
    run again."""
    hwc, nchw, padded = make_inputs(args.photo, size, multiple, folder)
    onnx = export_onnx(weights, padded, folder)
    save = folder / f"out_{weights.stem}_{size[0]}x{size[1]}"
    case = {"model": model, "size": size, "padded": padded, "runs": rounds_runs(runs, args.rounds) * args.rounds,
            "engines": {}, "diff": {}, "range": {}, "failed": {}}
    may_fail = MAY_FAIL["vit"] if model in VIT_VARIANTS else ()
    commands = engine_commands(args, weights, onnx, hwc, nchw, rounds_runs(runs, args.rounds), save)
    for round_index in range(args.rounds):
        for name, cmd in commands.items():
            if name in case["failed"]:
                continue
            print(f"  {model} {size[0]}x{size[1]}: {name} (round {round_index + 1} of {args.rounds}) ...",
                  file=sys.stderr, flush=True)
            try:
                pool_timings(case["engines"].setdefault(name, {}), run_engine(name, cmd, args))
            except EngineFailed as e:
                if name not in may_fail:
                    fail(str(e))
                case["engines"].pop(name, None)
                case["failed"][name] = str(e).splitlines()[0]
    for t in args.threads:
        ampi = np.load(f"{save}_ampi.t{t}.npy").astype(np.float64)
        case["range"][t] = (float(ampi.min()), float(ampi.max()))
        for peer in PEERS:
            if peer not in case["failed"]:
                case["diff"].setdefault(peer, {})[t] = relative_difference(np.load(f"{save}_{peer}.t{t}.npy"), ampi)
    return case


def median_ms(case, engine, threads) -> float:
    return statistics.median(case["engines"][engine][threads]["ms"])


def failed(case, engine) -> bool:
    """Whether `engine` could not run this case (MAY_FAIL): its cells say n/a."""
    return engine in case.get("failed", {})


# ---- the table ----------------------------------------------------------------------------

def cpu_model() -> str:
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return platform.processor() or "unknown"


def git_commit() -> str:
    """HEAD, and whether tracked files differed from it (what the build then held)."""
    proc = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, cwd=REPO)
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                           capture_output=True, text=True, cwd=REPO).stdout.strip()
    return (proc.stdout.strip() or "unknown") + (" (tracked files modified in the tree)" if dirty else "")


def versions(cases) -> dict:
    first = cases[0]["engines"]
    t = next(iter(first["ampi"]))
    return {"isa": first["ampi"][t].get("isa", "?"), "ort": first["onnxruntime"][t].get("version", "?"),
            "torch": first["pytorch"][t].get("version", "?"),
            "torch_format": first["pytorch"][t].get("memory_format", "?")}


def opencv_version(opencv_peer: str) -> str:
    proc = subprocess.run([opencv_peer, "--version"], capture_output=True, text=True)
    return proc.stdout.strip() or "?"


def foreign_cores(case, engine):
    return next(iter(case["engines"][engine].values())).get("foreign_cores")


def busy(case, engine, args) -> bool:
    """Whether other processes took more than --max-foreign cores while `engine` ran."""
    foreign = foreign_cores(case, engine)
    return foreign is not None and foreign > args.max_foreign


def targets_section(cases, args) -> list:
    return (target_table(cases, args, TARGET_CASE, TARGETS)
            + target_table(cases, args, VIT_TARGET_CASE, VIT_TARGETS))


def target_table(cases, args, target_case, targets) -> list:
    model, size, threads = target_case
    case = next((c for c in cases if c["model"] == model and tuple(c["size"]) == size), None)
    if case is None and model in VIT_VARIANTS:
        return []  # no ViT in this run
    lines = [f"## Targets: ampi {model} at {size[0]}x{size[1]}, {threads} threads", ""]
    if case is None or threads not in case["engines"]["ampi"]:
        return lines + ["Not measured in this run (the target case was not among the sizes and threads).", ""]
    ampi = median_ms(case, "ampi", threads)
    lines += ["| peer | target (ampi / peer) | ampi (ms) | peer (ms) | measured ratio | |", "|---|---:|---:|---:|---:|---|"]
    for peer, target in targets.items():
        ms = median_ms(case, peer, threads)
        ratio = ampi / ms
        verdict = "**met**" if ratio <= target else "**not met**"
        if busy(case, "ampi", args) or busy(case, peer, args):
            verdict = "undecided: not timed on a quiet machine (see the check below)"
        lines.append(f"| {PEER_TITLES[peer]} | <= {target:.1f}x | {ampi:.1f} | {ms:.1f} | {ratio:.2f}x | {verdict} |")
    return lines + [""]


def latency_section(cases, args) -> list:
    threads_list = args.threads
    lines = ["## Latency (median ms) and ratios ampi / peer", "",
             f"A `*` marks a time taken while other processes took more than {args.max_foreign:.2f} "
             "cores (the quiet machine check below): not to be trusted.", "",
             "| network | size | threads | runs | ampi | ONNX Runtime | OpenCV DNN | PyTorch | "
             "ampi / ORT | ampi / OpenCV | ampi / PyTorch |",
             "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for case in cases:
        for t in threads_list:
            ampi = median_ms(case, "ampi", t)
            ran = [p for p in PEERS if not failed(case, p)]
            times = {p: median_ms(case, p, t) for p in ran}
            mark = {e: "*" if busy(case, e, args) else "" for e in ("ampi",) + tuple(ran)}
            w, h = case["size"]
            lines.append(f"| {case['model']} | {w}x{h} | {t} | {case['runs']} | {ampi:.1f}{mark['ampi']} | "
                         + " | ".join(f"{times[p]:.1f}{mark[p]}" if p in times else "n/a" for p in PEERS) + " | "
                         + " | ".join(f"{ampi / times[p]:.2f}" if p in times else "n/a" for p in PEERS) + " |")
    return lines + [""] + failure_notes(cases) + single_thread_note(cases, threads_list)


def failure_notes(cases) -> list:
    """Why an n/a: each engine that could not run a case, with its first error line."""
    notes = []
    for case in cases:
        for engine, error in case.get("failed", {}).items():
            notes.append(f"n/a: {PEER_TITLES[engine]} could not run {case['model']} ({error}).")
    return notes + [""] if notes else []


def single_thread_note(cases, threads_list) -> list:
    """A remark where a peer's one-thread time is far above twice its two-thread time (more
    than a second core can explain): a path the peer picks by thread count, worth knowing."""
    if 1 not in threads_list or 2 not in threads_list:
        return []
    notes = []
    for peer in PEERS:
        ratios = [median_ms(c, peer, 1) / median_ms(c, peer, 2) for c in cases if not failed(c, peer)]
        if ratios and max(ratios) > 3:
            notes.append(f"{PEER_TITLES[peer]}'s 1-thread median is {min(ratios):.1f}x to {max(ratios):.1f}x its "
                         "2-thread median here (bench/peers/README.md says why).")
    return notes + [""] if notes else []


def difference_section(cases, threads_list) -> list:
    lines = ["## Same network: largest output difference against ampi", "",
             "max |peer - ampi| / (max(ampi) - min(ampi)) over the whole disparity map, the largest",
             f"over thread counts {', '.join(map(str, threads_list))}.", "",
             "| network | size | ampi output range | ONNX Runtime | OpenCV DNN | PyTorch |", "|---|---|---|---:|---:|---:|"]
    for case in cases:
        w, h = case["size"]
        lo = min(case["range"][t][0] for t in threads_list)
        hi = max(case["range"][t][1] for t in threads_list)
        diffs = ["n/a" if failed(case, p) else f"{max(case['diff'][p].values()):.1e}" for p in PEERS]
        lines.append(f"| {case['model']} | {w}x{h} | {lo:.3f} .. {hi:.3f} | " + " | ".join(diffs) + " |")
    return lines + [""]


def quiet_section(cases, args) -> list:
    engines = ("ampi",) + PEERS
    lines = ["## Quiet machine check", "",
             "Average number of cores that other processes took while each engine process ran "
             "(bench/peers/foreign_load.py: busy time of the whole machine in /proc/stat minus the "
             f"engine's own CPU time). Each engine waited up to {args.wait_quiet:g} s for a quiet "
             f"half-second before starting and was re-run (up to {args.retries} times) while this "
             f"exceeded {args.max_foreign:.2f}; the quietest run of each round is kept, and the table "
             "gives the busiest round's. `n/a`: no /proc/stat.", "",
             "| network | size | ampi | ONNX Runtime | OpenCV DNN | PyTorch |", "|---|---|---:|---:|---:|---:|"]
    for case in cases:
        w, h = case["size"]
        cells = []
        for engine in engines:
            foreign = None if failed(case, engine) else foreign_cores(case, engine)
            cells.append("n/a" if foreign is None else f"{foreign:.2f}")
        lines.append(f"| {case['model']} | {w}x{h} | " + " | ".join(cells) + " |")
    return lines + [""]


def wrap_note(args) -> str:
    if not args.wrap:
        return ""
    return (f" and `--wrap {shlex.join(args.wrap)}`: each engine process ran through that wrapper, "
            "which waits for a quiet machine (one benchmark at a time, background jobs paused)")


# The settings a report states, kept with the raw timings so --report-from can re-make it.
REPORT_SETTINGS = ("models", "sizes", "vit_sizes", "threads", "warmup", "rounds", "wrap", "max_foreign", "retries", "wait_quiet", "commit")


def save_raw(args, cases, seconds: float):
    """Every timed run of every engine, for a closer look than the medians."""
    raw = args.work / "cases.json"
    settings = {k: getattr(args, k) for k in REPORT_SETTINGS}
    raw.write_text(json.dumps({"settings": settings, "seconds": seconds, "cases": cases}, indent=1))
    print(f"run_peers.py: raw timings in {raw}", file=sys.stderr)


def load_raw(args, path: Path):
    """The cases and duration of a run saved by save_raw; args takes that run's settings."""
    try:
        raw = json.loads(path.read_text())
        for k in REPORT_SETTINGS:
            setattr(args, k, raw["settings"][k])
        cases = raw["cases"]
    except (OSError, ValueError, KeyError, TypeError) as e:
        fail(f"{path}: not the raw timings of a run ({e})")
    for case in cases:  # JSON turned the thread counts into strings
        case["engines"] = {e: {int(t): r for t, r in by.items()} for e, by in case["engines"].items()}
        case["diff"] = {p: {int(t): d for t, d in by.items()} for p, by in case["diff"].items()}
        case.setdefault("failed", {})
        case["range"] = {int(t): tuple(r) for t, r in case["range"].items()}
    return cases, raw["seconds"]


def vit_sizes_note(args) -> str:
    """` --vit-sizes ...` when the run had Depth Anything V2 rows, else nothing."""
    if not any(m in VIT_VARIANTS for m in args.models.split(",")):
        return ""
    return f" --vit-sizes {args.vit_sizes}"


def write_results(args, cases, seconds: float):
    v = versions(cases)
    padded = [c for c in cases if tuple(c["padded"]) != tuple(c["size"])]
    pad_note = ""
    if padded:
        c = padded[0]
        pad_note = (f" Sizes that are not multiples of the network's multiple (e.g. {c['size'][0]}x{c['size'][1]}) "
                    f"run at {c['padded'][0]}x{c['padded'][1]}: ampi pads inside its timed run (edge replication), "
                    "the peers get the image padded the same way before timing (their export has that size), "
                    "and their outputs are cropped back for the comparison.")
    lines = [
        "# Peer benchmark: ampi's depth network beside ONNX Runtime, OpenCV DNN and PyTorch", "",
        "Made by `bash bench/peers/run.sh` (bench/peers/README.md) in one run of "
        f"{seconds / 60:.1f} minutes (wall clock, waits included) at commit {args.commit}, with "
        f"`--models {args.models} --sizes {args.sizes}{vit_sizes_note(args)} "
        f"--threads {','.join(map(str, args.threads))} "
        f"--warmup {args.warmup} --rounds {args.rounds}`{wrap_note(args)}; rerun it to refresh this file.", "",
        f"- Machine: {cpu_model()}, {os.cpu_count()} cores; ampi's kernels: {v['isa']}.",
        f"- Engines, all on the CPU, the same thread count each ({', then '.join(map(str, args.threads))}):",
        "  ampi (`ampi bench network`, DepthModel::run on its own kernels);",
        f"  ONNX Runtime {v['ort']} (npm's onnxruntime-node, CPU provider, all graph optimisations, "
        "intra-op threads = T, inter-op 1);",
        f"  OpenCV {opencv_version(args.opencv_peer)} DNN (Debian's, OpenCV backend, `cv::setNumThreads(T)`);",
        f"  PyTorch {v['torch']} (Debian's, eager, inference mode, {v['torch_format']} memory format, "
        "`torch.set_num_threads(T)`).",
        "- The same network for all: the weight file `weights/depth_*.ampw`; ONNX Runtime and OpenCV run "
        "its ONNX export with BatchNorm folded (bench/peers/export_onnx.py), PyTorch the same folded "
        "network rebuilt from the file (bench/peers/peer_net.py). Depth Anything V2 rows (vits, vitb, vitl) "
        "run a random-weight file made the way a user converts a download (training/random_depth_anything.py, "
        "then training/import_depth_anything.py; same speed as the real weights), PyTorch as our twin of "
        "the reference model (training/depth_anything.py) rebuilt from that file.",
        f"- Input: `{args.photo.relative_to(REPO) if args.photo.is_relative_to(REPO) else args.photo}` resized "
        "to each size, RGB in [0, 1], the same pixels for every engine; each engine times the network "
        "call alone (input normalisation included, loading excluded), wall clock, after "
        f"{args.warmup} untimed run(s) per process; the engines take turns in {args.rounds} round(s) per "
        "row (a process per engine and round, the timed runs split between the rounds), so a slow spell of "
        f"the machine falls on all of them; medians of all runs given per row.{pad_note}",
        "- Ratios below 1 mean ampi is faster.", "",
    ]
    lines += (targets_section(cases, args) + latency_section(cases, args) + difference_section(cases, args.threads)
              + quiet_section(cases, args))
    text = "\n".join(lines)
    Path(args.results).write_text(text)
    print(text)
    print(f"run_peers.py: wrote {args.results}", file=sys.stderr)


# ---- main ---------------------------------------------------------------------------------

def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--ampi", required=True, help="the ampi program")
    p.add_argument("--opencv-peer", required=True, help="the ampi_peer_opencv_dnn program")
    p.add_argument("--work", type=Path, default=REPO / "out" / "peers", help="inputs, exports, outputs")
    p.add_argument("--models", default="lite,heavy")
    p.add_argument("--sizes", default="512x384:9,1024x768:7,1920x1080:5",
                   help="WxH:RUNS,... (timed runs per thread count)")
    p.add_argument("--vit-sizes", default="518x518:3",
                   help="WxH:RUNS,... of the Depth Anything V2 models (vits, vitb, vitl in --models); "
                        "multiples of 14")
    p.add_argument("--threads", default="1,2")
    p.add_argument("--warmup", type=int, default=1)
    p.add_argument("--rounds", type=int, default=3,
                   help="rounds of all engines in turn per case; the timed runs are split between them")
    p.add_argument("--photo", type=Path, default=REPO / "examples" / "forest_path.jpg")
    p.add_argument("--results", default=str(REPO / "bench" / "RESULTS.md"))
    p.add_argument("--smoke", action="store_true", help="64x64 lite, 1 run, check differences only")
    p.add_argument("--tolerance", type=float, default=1e-3, help="largest relative difference --smoke accepts")
    p.add_argument("--max-foreign", type=float, default=0.1,
                   help="re-run an engine when other processes took more cores than this meanwhile")
    p.add_argument("--retries", type=int, default=5, help="re-runs of an engine on a busy machine")
    p.add_argument("--wait-quiet", type=float, default=30,
                   help="seconds each engine waits at most for a quiet half-second before it starts")
    p.add_argument("--report-from", type=Path, help="re-make the report from a run's raw timings "
                   "(WORK/cases.json) instead of measuring")
    p.add_argument("--wrap", type=shlex.split, default=[],
                   help="a command prefixed to each timed engine process, e.g. '/tmp/quiet.sh' "
                        "(waits for a lock and pauses background jobs while the engine runs)")
    args = p.parse_args(argv)
    if args.smoke:
        args.models, args.sizes, args.warmup, args.retries, args.wait_quiet, args.rounds = "lite", "64x64:1", 0, 0, 0, 1
    if args.rounds < 1:
        fail("--rounds must be at least 1")
    args.threads = [int(t) for t in args.threads.split(",")]
    args.work.mkdir(parents=True, exist_ok=True)
    if not args.photo.is_file():
        fail(f"{args.photo}: no such photo")

    if args.report_from:
        write_results(args, *load_raw(args, args.report_from))
        return
    start, args.commit = time.time(), git_commit()
    cases = []
    for model in args.models.split(","):
        weights = weights_of(model, args.work)
        multiple = int(read_ampw(str(weights))[0]["depth.multiple"])
        sizes = args.vit_sizes if model in VIT_VARIANTS else args.sizes
        for size, runs in parse_sizes_runs(sizes):
            cases.append(measure_case(args, model, weights, size, runs, args.work, multiple))

    if args.smoke:
        worst = max(max(c["diff"][p].values()) for c in cases for p in PEERS)
        for c in cases:
            for peer in PEERS:
                print(f"{c['model']} {c['size'][0]}x{c['size'][1]} {peer}: largest relative difference "
                      f"{max(c['diff'][peer].values()):.2e}")
        if worst > args.tolerance:
            fail(f"a peer's output differs from ampi's by {worst:.2e} of its range (tolerance {args.tolerance:.0e})")
        return
    save_raw(args, cases, time.time() - start)
    write_results(args, cases, time.time() - start)


if __name__ == "__main__":
    main()

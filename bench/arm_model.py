#!/usr/bin/python3
"""A model of ampi's NEON speed on ARM cores we do not have: the compiled inner loops of
the GEMM, depthwise and compositor kernels through llvm-mca's pipeline models of
Cortex-A76 (Raspberry Pi 5), Cortex-A55 and Neoverse-N1, and from them an estimate for
the lite network at 1024x768. Writes bench/RESULTS-arm-model.md:

    /usr/bin/python3 bench/arm_model.py [-o bench/RESULTS-arm-model.md]

How:
1. Each kernel's translation unit is compiled for aarch64 the way the cross build compiles
   it (aarch64-linux-gnu-g++ -O3, armv8-a), to assembly.
2. The hot loops are found in it: innermost loops (a label and the backward branch to
   it, with no loop inside) of the named function; among those with the steady state's
   FMA count (KERNELS), the one with the fewest instructions is the kernel's inner loop.
3. llvm-mca predicts cycles per iteration of that loop in steady state for each core, and
   the same for a block of independent FMAs gives each core's FMA bound (FMAs per cycle).
   The loop's bound is its FMA count over that rate; the ratio is the share of the FMA
   bound the loop reaches.
4. The network estimate: every convolution of weights/depth_lite.ampw at 1024x768, its
   multiply-adds at the predicted speed of the kernel that runs it (GEMM for 1x1 and
   full convolutions, depthwise for depthwise), on one core at the core's clock; the
   stem's 3x3 runs as Winograd's F(4x4, 3x3), its GEMM doing a quarter of the direct
   multiply-adds.

What it leaves out, so the figures are a model and not a measurement: memory (every load
hits L1; on a Raspberry Pi 5 the depthwise layers are bound by DRAM bandwidth), the
epilogues and edges of each kernel (only the inner loop is modelled), the element-wise
and resampling ops, threading, and llvm-mca's own simplifications (no branch
mispredictions, its published scheduling model of each core).
"""
from __future__ import annotations

import argparse
import re
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
from weights_format.ampw import read_ampw  # noqa: E402

COMPILER = "aarch64-linux-gnu-g++"
FLAGS = ["-std=c++17", "-O3", "-DNDEBUG", "-DAMPI_ARCH_ARM64=1", f"-I{ROOT}", "-S", "-o", "-"]

# Debian 12's newest LLVM: the first with a scheduling model of its own for Neoverse-N1
# (LLVM 16 and older model it, and Cortex-A76, with Cortex-A57's: one FMA pipe, not two).
MCA = "llvm-mca-19"

# core: (llvm-mca -mcpu, clock in GHz of a typical board or server, where it is found).
# LLVM 19 still gives Cortex-A76 Cortex-A57's model; Neoverse-N1 is Arm's server core
# built on Cortex-A76's microarchitecture, so its model stands in for the A76.
CORES = {
    "Cortex-A76": ("neoverse-n1", 2.4, "Raspberry Pi 5"),
    "Cortex-A55": ("cortex-a55", 1.8, "little cores of phones and RK3588 boards"),
    "Neoverse-N1": ("neoverse-n1", 3.0, "Ampere Altra, AWS Graviton2"),
}


@dataclass
class Kernel:
    name: str
    source: str       # translation unit, relative to the repository
    function: str     # a substring of the mangled names of the functions holding the loop
    fmas: int         # vector FMA instructions in one iteration of the steady-state loop (0: any)
    what: str


# The loop of each: among the innermost loops of the named functions, those doing the
# steady state's FMAs (the compiler also emits edge and tail loops, and a copy per
# activation), the one with the fewest instructions.
KERNELS = [
    Kernel("GEMM 8x8 tile", "kernels/arm/conv_gemm_neon.cpp", "10panel_tile", 8 * 2 * 4,  # rows x vectors x k steps
           "k loop of the 8-row x 8-column tile, 4 steps of k (1x1 and im2col convolutions)"),
    Kernel("depthwise 3x3 s1", "kernels/arm/conv_depthwise_neon.cpp", "FixedGeometryILi3ELi1E", 8 * 9,  # pixels x taps
           "8 output pixels x one channel vector x 9 taps, 3x3 stride 1"),
    Kernel("compositor", "render/composite_neon.cpp", "warp_over_row", 4 * 4 + 3,  # pixels x (bilinear 3, over 1) + coordinates
           "4 pixels of one layer warped (bilinear) and composited over the row"),
]

BRANCH = re.compile(r"^\s+(?:b(?:\.?[a-z]{2})?|cbn?z\s+\w+,|tbn?z\s+\w+,\s*#?\d+,)\s*(\.L\d+)\s*$")
LABEL = re.compile(r"^(\.L\d+):")
FUNCTION = re.compile(r"^([A-Za-z_][\w.$]*):")
VECTOR_FP = re.compile(r"^\s+(fmla|fmls|fmul|fadd|fsub|fmax|fmin|fdiv|fneg|frint\w*|fcvt\w*)\s+v\d+\.(4s|2d|8h)")
FMA = re.compile(r"^\s+fml[as]\s+v\d+\.4s")


def compile_to_asm(source: str) -> list[str]:
    out = subprocess.run([COMPILER, *FLAGS, str(ROOT / source)], check=True, capture_output=True, text=True)
    return out.stdout.splitlines()


def functions(lines: list[str]) -> dict[str, list[str]]:
    """Assembly lines by function (mangled label)."""
    result, current = {}, None
    for line in lines:
        m = FUNCTION.match(line)
        if m and not line.startswith("."):
            current = m.group(1)
            result[current] = []
        elif current:
            result[current].append(line)
    return result


def instructions(body: list[str]) -> list[str]:
    """The instructions of a block, without directives, labels and comments."""
    kept = []
    for line in body:
        text = line.split("//")[0].rstrip()
        if not text.strip() or text.lstrip().startswith(".") or LABEL.match(text):
            continue
        kept.append(text)
    return kept


def innermost_loops(body: list[str]) -> list[list[str]]:
    """Each loop (a label and a later branch back to it) with no other loop inside."""
    where = {m.group(1): i for i, line in enumerate(body) if (m := LABEL.match(line))}
    loops = [(where[m.group(1)], i) for i, line in enumerate(body)
             if (m := BRANCH.match(line)) and m.group(1) in where and where[m.group(1)] < i]
    inner = [(a, b) for a, b in loops if not any(a <= c and d <= b and (c, d) != (a, b) for c, d in loops)]
    return [instructions(body[a:b + 1]) for a, b in inner]


def count(pattern: re.Pattern, loop: list[str]) -> int:
    return sum(bool(pattern.match(i)) for i in loop)


def hot_loop(kernel: Kernel) -> list[str]:
    candidates = []
    for name, body in functions(compile_to_asm(kernel.source)).items():
        if kernel.function in name:
            candidates += [loop for loop in innermost_loops(body) if count(VECTOR_FP, loop)]
    if kernel.fmas:
        candidates = [loop for loop in candidates if count(FMA, loop) == kernel.fmas]
    if not candidates:
        raise SystemExit(f"{kernel.source}: no loop of {kernel.fmas or 'any number of'} FMAs in a function "
                         f"matching '{kernel.function}': has the kernel changed? (bench/arm_model.py, KERNELS)")
    return min(candidates, key=len)


def mca(loop: list[str], cpu: str, iterations: int = 300) -> tuple[float, float]:
    """(cycles per iteration in steady state, the resource floor): llvm-mca's simulated
    cycles, and the cycles per iteration its busiest unit (pipe or port) was kept busy,
    what the loop's instructions need whatever their dependencies."""
    with tempfile.NamedTemporaryFile("w", suffix=".s") as f:
        f.write("\n".join(loop) + "\n")
        f.flush()
        out = subprocess.run([MCA, "-mtriple=aarch64", f"-mcpu={cpu}", f"-iterations={iterations}",
                              "-resource-pressure", f.name], check=True, capture_output=True, text=True).stdout
    total = int(re.search(r"Total Cycles:\s+(\d+)", out).group(1))
    pressure = out.split("Resource pressure per iteration:")[1].splitlines()[2].split()
    return total / iterations, max(float(v) for v in pressure if v != "-")


def fma_per_cycle(cpu: str) -> float:
    """The core's FMA bound: independent 4-lane FMAs per cycle, in llvm-mca's model."""
    block = [f"\tfmla\tv{r}.4s, v28.4s, v29.4s" for r in range(24)]
    return len(block) / mca(block, cpu)[0]


def lite_layers(path: Path, height: int = 768, width: int = 1024):
    """(kind, multiply-adds) of every convolution of the lite network at height x width:
    kind 'gemm' (1x1 and full convolutions) or 'depthwise', from the weight file's tensors.
    A 3x3 convolution that Conv2d runs on its Winograd path (from 8 inputs, more than 4
    outputs; every convolution of lite has stride 1) counts the GEMM's multiply-adds of
    F(4x4, 3x3): 36 per 16 outputs where the direct sum takes 16 x 9 (its window and
    output transforms are left out, as the epilogues are)."""
    meta, tensors = read_ampw(str(path))
    # enc{L}, dec{L}: level L works at 1/2^L of the input; head1 at level 1
    layers = []
    for name, t in tensors.items():
        if not name.endswith(".weight") or t.ndim != 4:
            continue
        m = re.match(r"(enc|dec|head)(\d+)", name)
        level = int(m.group(2))
        if m.group(1) == "head" and level != 1:
            continue  # the coarse heads are trained, not run
        pixels = (height >> level) * (width >> level)
        out_c, kh, kw, in_c = t.shape
        kind = "depthwise" if ".dw." in name else "gemm"
        taps = kh * kw
        if kind == "gemm" and (kh, kw) == (3, 3) and in_c >= 8 and out_c > 4:
            taps = 36 / 16
        layers.append((kind, pixels * out_c * taps * in_c))
    return layers


def table(rows, header):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("-o", "--output", default=str(ROOT / "bench" / "RESULTS-arm-model.md"))
    args = ap.parse_args()
    if not shutil.which(MCA) or not shutil.which(COMPILER):
        raise SystemExit(f"bench/arm_model.py needs {MCA} and {COMPILER}: apt-get install llvm-19 g++-aarch64-linux-gnu")

    rates = {core: fma_per_cycle(cpu) for core, (cpu, _, _) in CORES.items()}
    loops = {k.name: hot_loop(k) for k in KERNELS}
    share = {}
    loop_rows = []
    for k in KERNELS:
        loop = loops[k.name]
        fmas, vector_fp = count(FMA, loop), count(VECTOR_FP, loop)
        row = [k.name, k.what, len(loop), fmas, vector_fp]
        for core, (cpu, _, _) in CORES.items():
            cycles, floor = mca(loop, cpu)
            bound = vector_fp / rates[core]
            share[k.name, core] = bound / cycles
            row.append(f"{cycles:.1f} / {bound:.1f} ({100 * bound / cycles:.0f}%), floor {floor:.1f}")
        loop_rows.append(row)

    layers = lite_layers(ROOT / "weights" / "depth_lite.ampw")
    kernel_of = {"gemm": "GEMM 8x8 tile", "depthwise": "depthwise 3x3 s1"}
    net_rows = []
    for core, (cpu, ghz, board) in CORES.items():
        peak = 4 * rates[core] * ghz  # GMAC/s of one core at the FMA bound
        ms = {kind: 0.0 for kind in kernel_of}
        for kind, macs in layers:
            ms[kind] += macs / (peak * share[kernel_of[kind], core]) / 1e6
        net_rows.append([core, board, f"{ghz:.1f}", f"{rates[core]:.1f}", f"{peak:.1f}",
                         f"{ms['gemm']:.0f}", f"{ms['depthwise']:.0f}", f"{ms['gemm'] + ms['depthwise']:.0f}"])
    gmacs = sum(m for _, m in layers) / 1e9

    text = f"""# ARM speed, modelled (no board measured)

Made by `/usr/bin/python3 bench/arm_model.py` ({COMPILER} -O3, armv8-a; llvm-mca
{subprocess.run([MCA, '--version'], capture_output=True, text=True).stdout.split('version')[1].split()[0]}; Cortex-A76 through the Neoverse-N1 model, see the script).
**This is a model, not a measurement**: llvm-mca's pipeline model of each core runs the
kernels' compiled inner loops with every load hitting L1. It leaves out memory (on a
Raspberry Pi 5 the depthwise layers are bound by DRAM bandwidth, not by the FMA units),
the kernels' epilogues and edges, the element-wise and resampling ops, threading, and
what the core models themselves simplify. Read it as an upper bound on speed and a
guide to which loops waste issue slots, not as timings.

## Inner loops against the FMA bound

Per iteration of the hot loop: llvm-mca's cycles / the FMA bound (vector FP
instructions over the core's independent-FMA rate) and the share of the bound reached;
then the resource floor, the cycles per iteration the busiest unit (a vector pipe, the
load or store ports) is kept busy in llvm-mca's simulation. A loop at its floor is
limited by what it issues, not by waiting on results.
FMA rates in llvm-mca's models: {', '.join(f'{c} {r:.1f}' for c, r in rates.items())} four-lane FMAs per cycle.

{table(loop_rows, ['kernel', 'loop', 'instructions', 'FMAs', 'vector FP', *[f'{c}: cycles / bound' for c in CORES]])}

Where the floor is far above the FMA bound the loop issues much besides arithmetic: the
compositor widens halves by bit shifts, masks them, computes each footprint's index in
integer lanes, converts, divides and stores, all on the same two vector pipes, so only
its floor can be reached. Cortex-A55 issues in order: its cycles are far above its
floors because it waits on every result.

## Lite at 1024x768, one core

{len(layers)} convolutions, {gmacs:.2f} G multiply-adds (the Winograd stem's GEMM counted, not the direct
sum it replaces); each at its kernel's modelled share of the core's FMA bound (4 lanes x
FMAs per cycle x clock). Clocks are those of the boards named.

{table(net_rows, ['core', 'found in', 'GHz', 'FMAs/cycle', 'GMAC/s peak', 'GEMM layers, ms', 'depthwise layers, ms', 'total, ms'])}
"""
    Path(args.output).write_text(text)
    print(text)


if __name__ == "__main__":
    main()

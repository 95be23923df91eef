"""Keeps glibc's malloc from handing large freed blocks back to the system, for the
trainers on the CPU.

glibc maps every block above its mmap threshold (128 KB at first, raised only as such
blocks are freed, at most to 32 MB) with a fresh mmap and unmaps it when freed, and gives
the top of the heap back once more than its trim threshold is free there. A training
step allocates and frees activations and gradients of tens of megabytes, so every step
paid page faults and the kernel zeroing those pages again: vmstat put a fifth to a third
of the CPU time in the system. With both thresholds out of reach the blocks stay in the
heap and are reused: lite on 2 threads, 4 scenes + 4 photos a step, 1.26 s a step before
and 0.67 after (training/BENCH_TRAIN.md). The cost: a process holds the largest heap it
ever needed until it ends."""
from __future__ import annotations

import ctypes

M_TRIM_THRESHOLD = -1  # mallopt parameters, malloc.h
M_MMAP_THRESHOLD = -3
NEVER = 1 << 30  # bytes: larger than any one block a step allocates


def keep_freed_blocks() -> bool:
    """Sets both thresholds; False where the C library is not glibc (nothing changes)."""
    try:
        libc = ctypes.CDLL("libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return False
    return bool(mallopt(M_MMAP_THRESHOLD, NEVER)) and bool(mallopt(M_TRIM_THRESHOLD, NEVER))

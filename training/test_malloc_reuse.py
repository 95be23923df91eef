"""training/malloc_reuse.py: a large freed block stays with the process for reuse, where
glibc's defaults hand it straight back to the system."""
import subprocess
import sys
import unittest
from pathlib import Path

HERE = Path(__file__).resolve().parent

# Resident memory (kB) after a 256 MB block is written and freed, in a fresh process.
PROBE = """
import sys
sys.path.insert(0, {here!r})
import numpy as np
import malloc_reuse
if {reuse}:
    assert malloc_reuse.keep_freed_blocks()
def resident_kb():
    return int(next(l for l in open('/proc/self/status') if l.startswith('VmRSS')).split()[1])
before = resident_kb()
block = np.ones(64 << 20, np.float32)
del block
print(resident_kb() - before)
"""


def kept_kb(reuse: bool) -> int:
    out = subprocess.run([sys.executable, "-c", PROBE.format(here=str(HERE), reuse=reuse)],
                         check=True, capture_output=True, text=True).stdout
    return int(out)


@unittest.skipUnless(sys.platform.startswith("linux"), "glibc's malloc")
class MallocReuseTest(unittest.TestCase):
    def test_freed_block_stays_resident_only_with_reuse(self):
        block_kb = 256 << 10
        self.assertLess(kept_kb(reuse=False), block_kb // 4)       # unmapped when freed
        self.assertGreater(kept_kb(reuse=True), 3 * block_kb // 4)  # kept in the heap


if __name__ == "__main__":
    unittest.main()

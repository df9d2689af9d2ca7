"""Cost of panel contact when no pair is active (issue 32 item 2): a Miura sheet of n x n
panels folded to its rigid state at Ext = 0.6 with and without ``contact=True``.

    python benchmarks/bench_contact.py [n ...]     (default 32: 1024 panels; 64: 4096)

Prints the time of each and their ratio (target <= 1.25x) and checks the two results agree.
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np

from holofold.geometry import miura_sheet
from holofold.mechanics import fold_pattern

SECTION = dict(panel_thickness=1e-3, crease_thickness=0.3e-3, crease_width=1e-3)


def run(n: int) -> None:
    folded = miura_sheet(n, n, a=0.02, b=0.02, gamma=math.radians(60), ext=0.6)
    t = time.perf_counter()
    off = fold_pattern(folded, 1.0, **SECTION)
    t_off = time.perf_counter() - t
    t = time.perf_counter()
    on = fold_pattern(folded, 1.0, contact=True, **SECTION)
    t_on = time.perf_counter() - t
    dev = float(np.abs(on.U[-1] - off.U[-1]).max() / np.abs(off.U[-1]).max())
    print(
        f"{n * n} panels: off {t_off:.2f} s, contact {t_on:.2f} s, ratio {t_on / t_off:.2f}x, "
        f"steps {len(off.fractions) - 1}, max |dU|/|U| {dev:.1e}"
    )


if __name__ == "__main__":
    for n in [int(a) for a in sys.argv[1:]] or [32]:
        run(n)

#!/usr/bin/python3
"""bridge_bounds_check.py - scripts/bridge_bounds.py's tolerance reference against a
brute-force computation.

    /usr/bin/python3 tests/host_sim/bridge_bounds_check.py   (repository root)

A synthetic field on a 0.1 m grid of cell centres: f falling with x and y, a one-point spike
(+50 dB) that is the best point, a wall with a doorway, a plateau (+5 dB, 0.4 m round)
beyond the doorway and a higher one (+100 dB) in a walled-off room. tolerant() must give
each point's worst f within 0.15 m and the legal point (its whole 0.25 m disc on the
grid), 4-connected to the best, whose worst is highest, all equal to a reference that
walks integer grid offsets through a dict: no scipy, no arrays.
"""
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "lib"))
sys.path.insert(0, os.path.join(HERE, "..", "..", "scripts"))
from checks import check, exit_status  # noqa: E402
from bridge_bounds import tolerant  # noqa: E402

STEP, TOL, CLEAR = 0.1, 0.15, 0.25


def field():
    cells = {}
    for j in range(30):
        for i in range(50):
            if i == 25 and j < 22 or i == 40:  # a wall with a doorway at the top; a sealed room
                continue
            x, y = 0.05 + i * STEP, 0.05 + j * STEP
            v = -x - 0.1 * y  # no two points alike: one answer
            if (i, j) == (10, 10):
                v += 50.0
            if np.hypot(x - 3.5, y - 2.5) <= 0.4:
                v += 5.0
            if i > 40:
                v += 100.0
            cells[(i, j)] = v
    return cells


def reference(cells, best):
    k_clr = int(CLEAR / STEP + 1e-9)  # the clearance disc holds the tolerance disc
    worst, legal = {}, set()
    for (i, j), v in cells.items():
        w, whole = v, True
        for di in range(-k_clr, k_clr + 1):
            for dj in range(-k_clr, k_clr + 1):
                d2 = (di * di + dj * dj) * STEP * STEP
                there = (i + di, j + dj) in cells
                if d2 <= TOL * TOL + 1e-12 and there:
                    w = min(w, cells[(i + di, j + dj)])
                if d2 <= CLEAR * CLEAR + 1e-12 and not there:
                    whole = False
        worst[(i, j)] = w
        if whole:
            legal.add((i, j))
    start = min(legal, key=lambda c: (0.05 + c[0] * STEP - best[0]) ** 2 +
                (0.05 + c[1] * STEP - best[1]) ** 2)
    part, todo = {start}, [start]
    while todo:
        i, j = todo.pop()
        for n in ((i + 1, j), (i - 1, j), (i, j + 1), (i, j - 1)):
            if n in legal and n not in part:
                part.add(n)
                todo.append(n)
    return worst, max(part, key=lambda c: worst[c])


def main():
    cells = field()
    keys = list(cells)
    xy = np.array([(0.05 + i * STEP, 0.05 + j * STEP) for i, j in keys])
    f = np.array([cells[k] for k in keys])
    best = tuple(xy[int(np.argmax(np.where(xy[:, 0] < 2.5, f, -1e9)))])
    worst, t = tolerant(xy, f, best)
    ref_worst, ref_t = reference(cells, best)
    diff = max(abs(worst[n] - ref_worst[k]) for n, k in enumerate(keys))
    check("worst f within 0.15 m equals the reference", diff < 1e-9, f"max diff {diff}")
    check("tolerance point equals the reference", keys[t] == ref_t, f"{keys[t]} != {ref_t}")
    check("the spike is the best point", best == (1.05, 1.05), str(best))
    check("tolerance point on the plateau beyond the doorway, not the sealed room",
          np.hypot(xy[t, 0] - 3.5, xy[t, 1] - 2.5) <= 0.3, str(xy[t]))
    return exit_status()


if __name__ == "__main__":
    sys.exit(main())

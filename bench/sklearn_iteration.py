#!/usr/bin/env python3
"""The scikit-learn twin of the worst-case core iteration: radius selection, Ridge fit and
prediction over the 40 x 20 m grid at 0.25 m; prints the median wall time in microseconds."""
import sys
import time

import numpy as np
from sklearn.linear_model import Ridge


def main():
    if len(sys.argv) != 3:
        print("usage: sklearn_iteration.py SAMPLES_FILE N", file=sys.stderr)
        return 2
    data = np.loadtxt(sys.argv[1])
    n = int(sys.argv[2])
    xy, v = data[:, :2], data[:, 2]
    gx, gy = np.meshgrid(np.arange(0.125, 40, 0.25), np.arange(0.125, 20, 0.25))
    grid = np.column_stack([gx.ravel(), gy.ravel()])
    q = np.array([20.0, 10.0])
    times = []
    for _ in range(n):
        t0 = time.perf_counter()
        sel = np.hypot(xy[:, 0] - q[0], xy[:, 1] - q[1]) <= 5.0
        model = Ridge(alpha=1.0).fit(xy[sel], v[sel])
        pred = model.predict(grid)
        best = grid[int(np.argmax(pred))]
        times.append((time.perf_counter() - t0) * 1e6)
        assert best is not None
    print("%.1f" % float(np.median(times)))
    return 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/python3
"""Reference predictions for tests/common/test_knn.c from scikit-learn.

usage: ref_knn.py IN OUT
IN:  first line "knn K" or "radius R" (R in metres), then "S" and S lines "x y v"
     (samples, metres and target units), then "Q" and Q lines "x y" (queries).
OUT: Q lines "pred ambiguous": the prediction (nan when radius-neighbours finds none)
     and 1 when the answer depends on how ties are broken or on rounding (the k-th and
     (k+1)-th distances, or a distance and the radius, within 1e-5 m).
"""
import sys
import warnings

import numpy as np
from sklearn.neighbors import KNeighborsRegressor, RadiusNeighborsRegressor


def main():
    src, dst = sys.argv[1], sys.argv[2]
    with open(src) as f:
        mode, param = f.readline().split()
        s = int(f.readline())
        xy = np.zeros((s, 2))
        v = np.zeros(s)
        for i in range(s):
            a, b, c = f.readline().split()
            xy[i] = (float(a), float(b))
            v[i] = float(c)
        q = int(f.readline())
        qs = np.array([[float(t) for t in f.readline().split()] for _ in range(q)])
    d = np.sqrt(((qs[:, None, :] - xy[None, :, :]) ** 2).sum(axis=2))
    ds = np.sort(d, axis=1)
    if mode == "knn":
        k = int(param)
        pred = KNeighborsRegressor(n_neighbors=min(k, s), weights="uniform").fit(xy, v).predict(qs)
        amb = (ds[:, k] - ds[:, k - 1] < 1e-5) if k < s else np.zeros(q, bool)
    else:
        r = float(param)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            pred = RadiusNeighborsRegressor(radius=r).fit(xy, v).predict(qs)
        amb = (np.abs(d - r) < 1e-5).any(axis=1)
    with open(dst, "w") as f:
        for p, a in zip(pred, amb):
            f.write("%.9f %d\n" % (p, int(a)))


if __name__ == "__main__":
    main()

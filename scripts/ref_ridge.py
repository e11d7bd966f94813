#!/usr/bin/python3
"""Reference for tests/common/test_ridge.c: scikit-learn's Ridge on the local subset.

usage: ref_ridge.py IN OUT

IN holds data sets, each:
    set N QX_CM QY_CM RADIUS_CM ALPHA NPRED
    N lines "X_CM Y_CM V_Q6"       (integers: centimetres, value in 1/64 dB)
    NPRED lines "PX_Q16 PY_Q16"     (integers: metres in Q16.16)
For each set, OUT gets one line: "none" when no sample lies within RADIUS_CM of the
query (distance <= radius, exact integer test), else the NPRED predictions in dB of
Ridge(alpha=ALPHA).fit(X, y) with X in metres, exactly as the paper (section 5.2.1) uses
scikit-learn: no preprocessing, intercept fitted and not penalised.
"""
import os
import sys

import numpy as np
from sklearn.linear_model import Ridge


def main(argv):
    if len(argv) > 1 and argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0
    if len(argv) != 3:
        sys.exit("usage: ref_ridge.py IN OUT (see --help)")
    with open(argv[1], "r", encoding="ascii") as f:
        toks = f.read().split()
    out = []
    i = 0
    while i < len(toks):
        if toks[i] != "set":
            print(f"{argv[1]}: expected 'set' at token {i}, found {toks[i]!r}", file=sys.stderr)
            return 1
        n, qx, qy, rad = (int(t) for t in toks[i + 1:i + 5])
        alpha = float(toks[i + 5])
        npred = int(toks[i + 6])
        i += 7
        d = np.array(toks[i:i + 3 * n], dtype=np.int64).reshape(n, 3)
        i += 3 * n
        p = np.array(toks[i:i + 2 * npred], dtype=np.int64).reshape(npred, 2)
        i += 2 * npred
        du = d[:, 0] - qx
        dv = d[:, 1] - qy
        sel = d[du * du + dv * dv <= rad * rad]
        if len(sel) == 0:
            out.append("none")
            continue
        X = sel[:, :2].astype(np.float64) / 100.0
        y = sel[:, 2].astype(np.float64) / 64.0
        model = Ridge(alpha=alpha).fit(X, y)
        pred = model.predict(p.astype(np.float64) / 65536.0)
        out.append(" ".join(repr(float(v)) for v in pred))
    with open(argv[2] + ".tmp", "w", encoding="ascii") as f:
        f.write("\n".join(out) + "\n")
    os.replace(argv[2] + ".tmp", argv[2])
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv))
    except OSError as e:  # a missing or unreadable file: one line, not a traceback
        sys.exit("%s: %s: %s" % (os.path.basename(sys.argv[0]), e.filename, e.strerror))

#!/usr/bin/python3
"""Check the path-loss estimate and the bridging point in the seeker statuses of an LCM log.

    tests/host_sim/status_est_check.py LOG.lcmlog pathloss|bridge|none [MAP_W_M MAP_H_M]

Reads the log format (lcm-logger: sync word, event number, time, channel and data lengths)
and decodes rfseek.seeker_status_t by hand in the order of lcm/seeker_status_t.lcm
(big-endian), independently of the C code. With "pathloss": statuses before the first
relearn carry no estimate; after it every status has one, with n and W inside the model's
bounds, a positive area, a non-negative RMS, the source inside the map, and for a greedy
decision with a relearn the model maximum (the goal the seeker chose) within 1.5 m of the
estimated source (the model is flat within 1 m of it). With "bridge" (one fit per node):
the same for the bridging point instead, every greedy goal that point itself, with a
non-negative sigma and a positive area, and no path-loss estimate. With "none": no status
carries either and the fields are zero. Prints PASS/FAIL lines; exits 1 on failure.
"""
import os
import struct
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
from checks import check, exit_status  # noqa: E402


def events(path):
    with open(path, "rb") as f:
        data = f.read()
    i = 0
    while i + 28 <= len(data):
        sync, _num, t, clen, dlen = struct.unpack_from(">IqqII", data, i)
        if sync != 0xEDA1DA01:
            raise ValueError("%s: bad sync word at byte %d" % (path, i))
        i += 28
        ch = data[i:i + clen].decode()
        i += clen
        yield t, ch, data[i:i + dlen]
        i += dlen


def status(b):
    """Decode one rfseek.seeker_status_t (after the 8-byte fingerprint)."""
    o = 8
    m = {}
    m["utime"], m["state"], m["faults"], m["left"], m["right"], m["decided"], \
        m["iteration"], m["decision_utime"], m["kind"] = struct.unpack_from(">qbihhbiqb", b, o)
    o += struct.calcsize(">qbihhbiqb")
    (n,) = struct.unpack_from(">i", b, o)
    m["reason"] = b[o + 4:o + 4 + n - 1].decode()
    o += 4 + n
    keys = ["model_updated", "line_search", "model_valid", "mean_valid", "prev"]
    m.update(zip(keys, struct.unpack_from(">5b", b, o)))
    o += 5
    keys = ["prediction", "mean", "epsilon", "x", "y", "goal_x", "goal_y", "max_x", "max_y",
            "path_len"]
    m.update(zip(keys, struct.unpack_from(">10d", b, o)))
    o += 80
    (m["samples"],) = struct.unpack_from(">i", b, o)
    o += 4
    keys = ["sampled", "near", "hedged", "pinned", "refuted", "plan_wait"]
    m.update(zip(keys, struct.unpack_from(">5bi", b, o)))
    o += 9
    keys = ["est_valid", "est_x", "est_y", "est_n", "est_w", "est_p0", "est_rms", "est_area"]
    m.update(zip(keys, struct.unpack_from(">b7d", b, o)))
    o += 57
    keys = ["bridge_valid", "bridge_x", "bridge_y", "bridge_f", "bridge_sigma", "bridge_area"]
    m.update(zip(keys, struct.unpack_from(">b5d", b, o)))
    o += 41
    if o != len(b):
        raise ValueError("status of %d bytes, decoded %d" % (len(b), o))
    return m


def main(argv):
    if len(argv) not in (3, 5) or argv[2] not in ("pathloss", "bridge", "none"):
        print(__doc__.strip(), file=sys.stderr)
        return 2
    want = argv[2] == "pathloss"
    mw, mh = (float(argv[3]), float(argv[4])) if len(argv) == 5 else (1e9, 1e9)
    try:
        st = [status(d) for _t, ch, d in events(argv[1]) if ch == "RFS_SEEKER_STATUS"]
    except (OSError, ValueError, struct.error, UnicodeDecodeError) as e:
        print("FAIL status_decode: %s" % e)
        return 1
    check("status_count", len(st) > 100, "%d statuses" % len(st))
    est_keys = ["est_x", "est_y", "est_n", "est_w", "est_p0", "est_rms", "est_area"]
    br_keys = ["bridge_x", "bridge_y", "bridge_f", "bridge_sigma", "bridge_area"]
    if argv[2] == "bridge":
        return check_bridge(st, est_keys, br_keys, mw, mh)
    bad = [m for m in st if m["bridge_valid"] or any(m[k] != 0.0 for k in br_keys)]
    check("no_bridging_point", not bad, str(bad[:1]))
    if not want:
        bad = [m for m in st if m["est_valid"] or any(m[k] != 0.0 for k in est_keys)]
        check("no_estimate", not bad, str(bad[:1]))
        return exit_status()
    # The first status of a relearn with its fit done: the decision's own, or the period
    # before it when the choice waits one period after a whole fit (rfs_seek.c, plan_budget).
    first = next((i for i, m in enumerate(st) if m["model_updated"] and m["est_valid"]), None)
    check("a_relearn", first is not None)
    if first is None:
        return 1
    before = [m for m in st[:first] if m["est_valid"] or any(m[k] != 0.0 for k in est_keys)]
    check("no_estimate_before_the_first_fit", not before, str(before[:1]))
    after = st[first:]
    check("estimate_after_the_first_fit", all(m["est_valid"] for m in after),
          "%d of %d without" % (sum(not m["est_valid"] for m in after), len(after)))
    bad = [m for m in after if not (1.5 <= m["est_n"] <= 5.0 and 0.0 <= m["est_w"] <= 15.0 and
                                    m["est_area"] > 0.0 and m["est_rms"] >= 0.0 and
                                    0.0 <= m["est_x"] <= mw and 0.0 <= m["est_y"] <= mh)]
    check("estimate_in_bounds", not bad, str(bad[:1]))
    greedy = [m for m in after if m["decided"] and m["model_updated"] and m["kind"] == 2]
    far = [m for m in greedy
           if ((m["max_x"] - m["est_x"]) ** 2 + (m["max_y"] - m["est_y"]) ** 2) ** 0.5 > 1.5]
    check("greedy_goal_at_the_estimate (%d greedy relearns)" % len(greedy), greedy and not far,
          str(far[:1]))
    last = after[-1]
    print("last estimate: (%.3f, %.3f) n %.3f W %.2f dB P0 %.2f rms %.2f dB area %.1f m^2"
          % (last["est_x"], last["est_y"], last["est_n"], last["est_w"], last["est_p0"],
             last["est_rms"], last["est_area"]))
    return exit_status()


def check_bridge(st, est_keys, br_keys, mw, mh):
    """One fit per node: the bridging point from the first fit on, no path-loss estimate."""
    bad = [m for m in st if m["est_valid"] or any(m[k] != 0.0 for k in est_keys)]
    check("no_path_loss_estimate", not bad, str(bad[:1]))
    first = next((i for i, m in enumerate(st) if m["bridge_valid"]), None)
    check("a_bridging_point", first is not None)
    if first is None:
        return 1
    before = [m for m in st[:first] if any(m[k] != 0.0 for k in br_keys)]
    check("zero_before_the_first_fit", not before, str(before[:1]))
    after = st[first:]
    check("bridging_point_after_the_first_fit", all(m["bridge_valid"] for m in after),
          "%d of %d without" % (sum(not m["bridge_valid"] for m in after), len(after)))
    bad = [m for m in after if not (m["bridge_sigma"] >= 0.0 and m["bridge_area"] > 0.0 and
                                    m["bridge_f"] < 0.0 and 0.0 <= m["bridge_x"] <= mw and
                                    0.0 <= m["bridge_y"] <= mh)]
    check("bridging_point_in_bounds", not bad, str(bad[:1]))
    greedy = [m for m in after if m["decided"] and m["kind"] == 2]
    off = [m for m in greedy if (m["max_x"], m["max_y"]) != (m["bridge_x"], m["bridge_y"])]
    check("greedy_goal_is_the_bridging_point (%d greedy decisions)" % len(greedy),
          greedy and not off, str(off[:1]))
    last = after[-1]
    print("last bridging point: (%.3f, %.3f) f %.2f dB sigma %.2f dB area %.2f m^2"
          % (last["bridge_x"], last["bridge_y"], last["bridge_f"], last["bridge_sigma"],
             last["bridge_area"]))
    return exit_status()


if __name__ == "__main__":
    sys.exit(main(sys.argv))

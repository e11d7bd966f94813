#!/usr/bin/env bash
# status_est.sh - rfseekd puts the path-loss model's estimate in its LCM seeker status
# (and ends a run with a stop command, wheel_stop_check.py):
# a two-process run (rfseek-sim-lcm + rfseekd --model pathloss, udpm:// inside a
# network namespace we create and delete) recorded as an LCM log, decoded by hand in
# tests/host_sim/status_est_check.py; the same inputs replayed with the ridge carry none.
#   tests/host_sim/status_est.sh BUILD        (from the repository root)
set -uo pipefail
build=${1:?usage: status_est.sh BUILD}
d=$build/bin/rfseekd
map=scenarios/maps/office.yaml
w=$(mktemp -d /tmp/rfs_status_est.XXXXXX)
ns=rfsplh$$
trap 'ip netns del "$ns" 2>/dev/null; rm -rf -- "$w"' EXIT
. "$(dirname "$0")/../lib/checks.sh"
if ! ip netns add "$ns" 2>/dev/null; then
    echo "SKIP status_est: cannot create a network namespace (needs root)"
    exit 0
fi
ip netns exec "$ns" ip link set lo up && ip netns exec "$ns" ip route add 224.0.0.0/4 dev lo \
    || { fail "netns setup"; exit 1; }
url='udpm://239.255.76.67:7667?ttl=0'
ip netns exec "$ns" timeout 120 "$d" --map $map --model pathloss --lcm "$url" --can-over-lcm \
    --clock-lcm --log "$w/run.lcmlog" --decisions "$w/live.txt" --idle-exit 3000 2> "$w/d.err" &
dpid=$!
sleep 0.5
ip netns exec "$ns" timeout 120 "$build/bin/rfseek-sim-lcm" scenarios/default.yaml --lcm "$url" \
    --max-time 60 > "$w/summary.json" 2> "$w/sim.err"
src=$?
wait $dpid
drc=$?
ip netns del "$ns"
[ $src -eq 0 ] && [ $drc -eq 0 ] && [ -s "$w/run.lcmlog" ] && pass status_est_two_process_run \
    || fail "status_est_two_process_run (sim rc $src, rfseekd rc $drc: $(head -3 "$w/sim.err" "$w/d.err"))"
# The office map is 36 x 12 m.
/usr/bin/python3 tests/host_sim/status_est_check.py "$w/run.lcmlog" pathloss 36 12 || fails=$((fails + 1))
# Its end: a zero command with Stop after the last step (the motor controller's timeout
# does not have to stop the wheels).
/usr/bin/python3 tests/host_sim/wheel_stop_check.py "$w/run.lcmlog" || fails=$((fails + 1))
"$d" --map $map --model ridge --replay "$w/run.lcmlog" --clock-lcm --lcm memq:// --log "$w/ridge.lcmlog" \
    > /dev/null 2> "$w/r.err" && pass status_est_ridge_replay || fail "status_est_ridge_replay ($(head -2 "$w/r.err"))"
/usr/bin/python3 tests/host_sim/status_est_check.py "$w/ridge.lcmlog" none || fails=$((fails + 1))
# One fit per node under the bridging target: the predicted bridging point in the status.
ip netns add "$ns" 2>/dev/null && ip netns exec "$ns" ip link set lo up \
    && ip netns exec "$ns" ip route add 224.0.0.0/4 dev lo || { fail "netns setup (bridge)"; exit 1; }
ip netns exec "$ns" timeout 120 "$d" --map $map --model pathloss --target bridge --lcm "$url" \
    --can-over-lcm --clock-lcm --log "$w/bridge.lcmlog" --idle-exit 3000 2> "$w/db.err" &
dpid=$!
sleep 0.5
ip netns exec "$ns" timeout 120 "$build/bin/rfseek-sim-lcm" scenarios/bridge.yaml --lcm "$url" \
    --max-time 200 > "$w/bsummary.json" 2> "$w/bsim.err"
src=$?
wait $dpid
drc=$?
ip netns del "$ns"
[ $src -eq 0 ] && [ $drc -eq 0 ] && [ -s "$w/bridge.lcmlog" ] && pass status_est_bridge_run \
    || fail "status_est_bridge_run (sim rc $src, rfseekd rc $drc: $(head -3 "$w/bsim.err" "$w/db.err"))"
/usr/bin/python3 tests/host_sim/status_est_check.py "$w/bridge.lcmlog" bridge 36 12 || fails=$((fails + 1))
# --p0-min reaches the pathloss model: the recorded inputs replayed with the default floor
# written out (-45) decide exactly as without it, with a floor of 0 dBm (20 dB above what
# the simulated 20 dBm node gives at 1 m) differently.
for v in none -45 0; do
    a=(); [ "$v" = none ] || a=(--p0-min "$v")
    "$d" --map $map --model pathloss "${a[@]}" --replay "$w/run.lcmlog" --clock-lcm \
        > "$w/p0$v.txt" 2> "$w/p0$v.err" || fail "status_est_p0_min_replay $v ($(head -2 "$w/p0$v.err"))"
done
[ -s "$w/p0none.txt" ] && cmp -s "$w/p0none.txt" "$w/p0-45.txt" && ! cmp -s "$w/p0none.txt" "$w/p00.txt" \
    && pass status_est_p0_min_replay || fail "status_est_p0_min_replay: decisions $(wc -l < "$w/p0none.txt") / $(wc -l < "$w/p0-45.txt") / $(wc -l < "$w/p00.txt")"
exit $((fails > 0))

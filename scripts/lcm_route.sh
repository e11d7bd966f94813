#!/usr/bin/env bash
# lcm_route.sh - the multicast route LCM's udpm:// provider needs (docs/CAN.md, "Running on
# a robot"): 224.0.0.0/4 through one interface of this network namespace.
usage() {
    cat <<'EOF'
usage: scripts/lcm_route.sh IFACE [--check | --delete]
Route multicast (224.0.0.0/4) through IFACE, as LCM's udpm:// provider needs: lo for
processes on one computer (URL udpm://239.255.76.67:7667?ttl=0), the robot's network
interface for several (ttl=1). Does nothing when the route is there already. Needs root
(CAP_NET_ADMIN), except --check. Not persistent: run it at boot (e.g. a systemd unit).
  --check   exit 0 when the route goes through IFACE, 1 when it does not
  --delete  remove the route through IFACE (nothing when there is none)
  --help    this text
Errors: one line on stderr; exit 1 (interface missing or down, multicast off, the route
through another interface, not root), 2 for bad options.
EOF
}
set -uo pipefail
die() { local m="lcm_route.sh: $*"; echo "${m//$'\n'/?}" >&2; exit 1; }
iface='' mode=add
for a in "$@"; do
    case $a in
    --help | -h) usage; exit 0 ;;
    --check) mode=check ;;
    --delete) mode=delete ;;
    -*) echo "lcm_route.sh: unknown option (see --help): ${a//$'\n'/?}" >&2; exit 2 ;;
    *) [ -z "$iface" ] || { echo "lcm_route.sh: one interface only (see --help)" >&2; exit 2; }
       iface=$a ;;
    esac
done
[ -n "$iface" ] || { echo "lcm_route.sh: IFACE is required (see --help)" >&2; exit 2; }
safe=${iface//$'\n'/?}
command -v ip > /dev/null || die "ip (iproute2) is not installed"

# The interface through which the multicast route goes, empty when there is none.
route_dev() { ip -4 route show exact 224.0.0.0/4 2> /dev/null | sed -n 's/.* dev \([^ ]*\).*/\1/p' | head -1; }

flags=$(ip -o link show dev "$iface" 2> /dev/null) || die "$safe: no such interface"
flags=${flags#*<}
flags=${flags%%>*}
now=$(route_dev)
case $mode in
check)
    [ "$now" = "$iface" ] && { echo "lcm_route.sh: 224.0.0.0/4 dev $safe"; exit 0; }
    echo "lcm_route.sh: 224.0.0.0/4 does not go through $safe${now:+ (it goes through $now)}"
    exit 1 ;;
delete)
    [ "$now" = "$iface" ] || { echo "lcm_route.sh: no multicast route through $safe"; exit 0; }
    err=$(ip route del 224.0.0.0/4 dev "$iface" 2>&1) || die "$safe: ip route del: $err"
    echo "lcm_route.sh: 224.0.0.0/4 dev $safe deleted"
    exit 0 ;;
esac
if [ "$now" = "$iface" ]; then
    echo "lcm_route.sh: 224.0.0.0/4 dev $safe (already there)"
    exit 0
fi
[ -z "$now" ] || die "224.0.0.0/4 goes through $now already: scripts/lcm_route.sh $now --delete first"
[[ ",$flags," == *,UP,* ]] || die "$safe is down: ip link set $safe up"
[[ ",$flags," == *,MULTICAST,* || ",$flags," == *,LOOPBACK,* ]] \
    || die "$safe has multicast off: ip link set $safe multicast on"
[ "$(id -u)" -eq 0 ] || die "adding a route needs root: sudo scripts/lcm_route.sh $safe"
err=$(ip route add 224.0.0.0/4 dev "$iface" 2>&1) || die "$safe: ip route add: $err"
[ "$(route_dev)" = "$iface" ] || die "$safe: the route did not appear in ip route"
echo "lcm_route.sh: 224.0.0.0/4 dev $safe added"

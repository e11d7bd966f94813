#!/usr/bin/env bash
# readme_path.sh BUILD - the README's "From a PNG map and a capture to a run and a video"
# commands, taken from README.md as they stand and run with out/floor in a temporary
# folder, build/ as BUILD and at most 20 frames: every command succeeds, the map read from
# the PNG is the office's (rfseek-map's figures for both alike), the capture's MAC is the
# scenario's source, and the GIF has 20 frames of 960 pixels' width (decoded with Pillow).
set -uo pipefail
build=${1:?usage: readme_path.sh BUILD}
. "$(dirname "$0")/../lib/checks.sh"
t=$(mktemp -d /tmp/rfs_readme.XXXXXX)
trap 'rm -rf -- "$t"' EXIT
sed -n '/^### From a PNG map and a capture/,/^On the robot/p' README.md | sed -n '/^```sh$/,/^```$/p' \
    | sed '1d;$d' > "$t/cmds.sh"
[ "$(grep -c . "$t/cmds.sh")" -ge 6 ] && pass "readme_block ($(grep -c . "$t/cmds.sh") lines)" \
    || fail readme_block "$(cat "$t/cmds.sh")"
sed -i -e "s#out/floor#$t/floor#g" -e "s#build/bin/#$build/bin/#g" -e 's#--animate#--animate --max-frames 20#' "$t/cmds.sh"
if bash -e "$t/cmds.sh" > "$t/out.txt" 2> "$t/err.txt"; then
    pass readme_commands_run
else
    fail readme_commands_run "$(tail -3 "$t/err.txt")"
fi
# The PNG map reads as the PGM it came from.
a=$("$build/bin/rfseek-map" scenarios/maps/office.yaml | grep -E '^(image|core cells|lattice)')
b=$("$build/bin/rfseek-map" "$t/floor/floor.yaml" | grep -E '^(image|core cells|lattice)')
[ -n "$a" ] && [ "$a" = "$b" ] && pass readme_png_map_as_pgm || fail readme_png_map_as_pgm "$b"
mac=$(awk -F'\t' '$9 == "ikeriri-5g" {print $1}' "$t/out.txt")
grep -q "mac: \"$mac\"" "$t/floor/scenario.yaml" && [ "$mac" = 50:0f:80:70:18:d0 ] \
    && pass "readme_capture_mac_in_scenario ($mac)" || fail readme_capture_mac_in_scenario "$mac"
/usr/bin/python3 - "$t/floor/run/run.gif" <<'EOF' && pass readme_gif_20_frames || fail readme_gif_20_frames
import sys
from PIL import Image
im = Image.open(sys.argv[1])
sys.exit(0 if im.n_frames == 20 and im.size[0] == 960 else 1)
EOF
exit $((fails > 0))

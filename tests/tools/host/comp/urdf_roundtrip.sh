#!/bin/sh
# SPDX-License-Identifier: MIT
# URDF in and out (issue 51), for a UR5e-class and an IRB120-class URDF:
#  1. the URDF read as the nominal model (rch_robot_load -> DH with base and
#     flange): its FK at 200 poses equals the URDF's own, read by
#     tests/tools/host/outputs/urdf_fk.py (Python's XML parser, its own matrices), within
#     1e-6 mm (1e-9 m);
#  2. a calibrated model of it (DH perturbed, written and read back) exported
#     as an overlay of the user's URDF (rcal export --nominal-urdf): the
#     overlay's FK, read by urdf_fk.py, equals rcal's within 1e-6 mm; the
#     overlay differs from the URDF only inside <origin> tags of joints;
#     check_urdf accepts it (when liburdfdom-tools is installed).
#   urdf_roundtrip.sh RCAL DUMP SRC WORK
set -eu
RCAL=$1; DUMP=$2; SRC=$3; WORK=$4
mkdir -p "$WORK"
FK="$SRC/tests/tools/host/outputs/urdf_fk.py"
for r in ur5e irb120; do
  U="$SRC/tests/tools/host/comp/data/$r.urdf"
  "$DUMP" "$U" "$WORK/$r.fk.csv"
  python3 "$FK" "$U" "$WORK/$r.fk.csv" 1e-6
  "$DUMP" "$U" "$WORK/$r.cal.csv" 7 "$WORK/$r.cal.json"
  "$RCAL" export --model "$WORK/$r.cal.json" --format urdf --nominal-urdf "$U" --out "$WORK/$r.over.urdf" \
    2> "$WORK/$r.err"
  cat "$WORK/$r.err"
  grep -q "joint origins calibrated" "$WORK/$r.err"
  python3 "$FK" "$WORK/$r.over.urdf" "$WORK/$r.cal.csv" 1e-6
  # the nominal's FK differs from the calibrated one (the check above sees the calibration)
  if python3 "$FK" "$U" "$WORK/$r.cal.csv" 1e-6 >/dev/null; then echo "FAIL: the perturbation is not seen"; exit 1; fi
  python3 - "$U" "$WORK/$r.over.urdf" <<'PY'
import re, sys
a, b = (open(p).read() for p in sys.argv[1:3])
strip = lambda s: re.sub(r'<origin [^>]*>', '<origin>', s)
if strip(a) != strip(b):
    sys.exit("FAIL: the overlay changed bytes outside <origin> tags")
print("overlay: bytes outside <origin> tags unchanged (%d bytes)" % len(b))
PY
  if command -v check_urdf >/dev/null 2>&1; then
    check_urdf "$WORK/$r.over.urdf" > "$WORK/$r.check" 2>&1 || { cat "$WORK/$r.check"; exit 1; }
    grep -q "Successfully Parsed XML" "$WORK/$r.check"
  fi
done
echo "urdf_roundtrip: ok"

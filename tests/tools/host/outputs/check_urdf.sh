#!/bin/sh
# SPDX-License-Identifier: MIT
# check_urdf.sh RCAL SOURCE_DIR SHARED_CSV WORK_DIR
# Debian's check_urdf (package liburdfdom-tools) accepts the URDF that `rcal
# export` writes of the nominal robot, of a calibrated model (simulated data,
# with a tool offset; the real data when present) and with the names of a
# nominal URDF. It must also reject a broken URDF, so that a check_urdf that
# accepts anything cannot pass this test. Exit 77 (skipped) without check_urdf.
set -u
RCAL=$1 SRC=$2 SHARED=$3 WORK=$4
if ! command -v check_urdf >/dev/null 2>&1; then
    echo "SKIP: check_urdf not found (Debian package liburdfdom-tools)"
    exit 77
fi
mkdir -p "$WORK" || exit 1
fail=0
check() { # label urdf
    if out=$(check_urdf "$2" 2>&1) && echo "$out" | grep -q "Successfully Parsed XML"; then
        echo "ok    check_urdf accepts $1"
    else
        echo "FAIL  check_urdf rejects $1:"; echo "$out"; fail=1
    fi
}
export_urdf() { # label model [extra args]
    label=$1 model=$2; shift 2
    if "$RCAL" export --model "$model" --format urdf --out "$WORK/$label.urdf" "$@"; then
        check "$label" "$WORK/$label.urdf"
    else
        echo "FAIL  rcal export $label"; fail=1
    fi
}
export_urdf nominal "$SRC/data/irb120.json"
export_urdf truth "$SRC/data/sim_irb120_truth.json"
"$RCAL" calibrate --data "$SRC/data/sim_irb120.csv" --tool-offset --out "$WORK/cal_tool.json" >/dev/null || fail=1
export_urdf calibrated-sim-tool "$WORK/cal_tool.json"
if [ -f "$SHARED" ]; then
    "$RCAL" calibrate --data "$SHARED" --jumps --dequantize-joints --out "$WORK/cal_real.json" >/dev/null || fail=1
    export_urdf calibrated-real "$WORK/cal_real.json"
else
    echo "      (no real data at $SHARED: that model is left out)"
fi
cat >"$WORK/nominal.urdf" <<'URDF'
<?xml version="1.0"?>
<robot name="abb_irb120">
  <link name="base_link"/>
  <joint name="joint_1" type="revolute"><parent link="base_link"/><child link="link_1"/><limit effort="1" velocity="1"/></joint>
  <joint name="joint_2" type="revolute"><parent link="link_1"/><child link="link_2"/><limit effort="1" velocity="1"/></joint>
  <joint name="joint_3" type="revolute"><parent link="link_2"/><child link="link_3"/><limit effort="1" velocity="1"/></joint>
  <joint name="joint_4" type="revolute"><parent link="link_3"/><child link="link_4"/><limit effort="1" velocity="1"/></joint>
  <joint name="joint_5" type="revolute"><parent link="link_4"/><child link="link_5"/><limit effort="1" velocity="1"/></joint>
  <joint name="joint_6" type="revolute"><parent link="link_5"/><child link="link_6"/><limit effort="1" velocity="1"/></joint>
  <joint name="joint_6-tool0" type="fixed"><parent link="link_6"/><child link="tool0"/></joint>
  <link name="link_1"/><link name="link_2"/><link name="link_3"/><link name="link_4"/>
  <link name="link_5"/><link name="link_6"/><link name="tool0"/>
</robot>
URDF
check "the nominal test URDF itself" "$WORK/nominal.urdf"
export_urdf truth-named "$SRC/data/sim_irb120_truth.json" --nominal-urdf "$WORK/nominal.urdf"
# The control: a URDF cut short must be rejected.
head -n 12 "$WORK/nominal.urdf" >"$WORK/broken.urdf"
if check_urdf "$WORK/broken.urdf" >/dev/null 2>&1; then
    echo "FAIL  check_urdf accepted a truncated URDF: it checks nothing"; fail=1
else
    echo "ok    check_urdf rejects a truncated URDF"
fi
exit $fail

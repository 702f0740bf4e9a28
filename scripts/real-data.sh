#!/usr/bin/env bash
# Runs every command of docs/real-data.md on the recordings in
# ../shared/data/real and writes each report (Markdown, JSON, Bode plot)
# under target/real-data/. Usage: scripts/real-data.sh [MMS_BINARY]
set -euo pipefail
cd "$(dirname "$0")/.."
mms=${1:-target/release/mms}
[ -x "$mms" ] || cargo build --release -p mms-cli
real=../shared/data/real
out=target/real-data
mkdir -p "$out"

run() { # NAME ARGS...: the report into $out/NAME/, its JSON next to it
    local name=$1
    shift
    rm -rf "${out:?}/$name"
    "$mms" "$@" --out "$out/$name"
    "$mms" "$@" --format json >"$out/$name.json"
}

sperte=(--u result:1 --y result:2 --fs 4000)
for rec in setup18_motor_side_v0.3 setup18_motor_side_v0.5 setup18_load_side_v0.5_m2 \
    setup29_load_side_v0.5 session02nov_frf_measurement_0; do
    run "sperte-$rec" identify "$real/sperte/$rec.mat" "${sperte[@]}"
done
for rec in setup18_motor_side_v0.3 setup18_motor_side_v0.5; do
    other=setup18_motor_side_v0.5
    [ "$rec" = "$other" ] && other=setup18_motor_side_v0.3
    run "sperte-$rec-diagnose" diagnose "$real/sperte/$rec.mat" "${sperte[@]}" \
        --model "$out/sperte-$rec/model.toml" --validate "$real/sperte/$other.mat"
done

f16=(--u Force --y Acceleration:1 --period 8192 --output acceleration)
run f16-level1 identify "$real/f16_gvt/F16Data_FullMSine_Level1.mat" "${f16[@]}" --band 4:15 --fit-gain
run f16-levels diagnose "$real/f16_gvt/F16Data_FullMSine_Level1.mat" "${f16[@]}" --band 2:15 \
    --level "$real/f16_gvt/F16Data_FullMSine_Level7.mat"

cat >"$out/emps.toml" <<'EOF'
masses = 1
gap = 0
actuator = [1, 0]
sensor = [1, 0]
output = "position"
gain = 35.15
[parameters]
m1 = 100
[effects]
friction = { viscous_ns_per_m = 200 }
EOF
emps=(--u vir --y qm --fs 1000 --model "$out/emps.toml" --reference qg)
run emps diagnose "$real/emps/DATA_EMPS.mat" "${emps[@]}" --controller kp=kp,kv=kv
run emps-pulses diagnose "$real/emps/DATA_EMPS_PULSES.mat" "${emps[@]}" \
    --controller kp=160.18,kv=243.45,filter=0.5:0.5,saturation=10 --disturbance pulses_N

run robot-arm identify "$real/robot_arm/robot_arm.dat" --u 1 --y 2 --fs 1 --output acceleration \
    --nfft 256 --fit-gain

tue=(--u Data.signals.u --y Data.signals.y --excitation Data.signals.d)
run tue2025-moving identify "$real/tue_motion_2025/motor_side_1rads.mat" "${tue[@]}"
run tue2025-standstill identify "$real/tue_motion_2025/motor_side_stationary.mat" "${tue[@]}"

for y in y1 y2; do
    run "tue2018-$y" identify "$real/tue_motion_2018/scan_10hz_with_feedforward.mat" \
        --u Data.u --y "Data.$y" --band 1:40
done
run tue2018-both identify "$real/tue_motion_2018/scan_10hz_with_feedforward.mat" \
    --u Data.u --y Data.y1@1 --y Data.y2@N --excitation Data.r --band 1:100 --masses 2
run tue2018-both-diagnose diagnose "$real/tue_motion_2018/scan_10hz_with_feedforward.mat" \
    --u Data.u --y Data.y1@1 --y Data.y2@N --excitation Data.r --band 1:100 \
    --model "$out/tue2018-both/model.toml"
run tue2025-operating-points identify "$real/tue_motion_2025/motor_side_stationary.mat" "${tue[@]}" \
    --nfft 10000 --band 1:150 --operating-point "$real/tue_motion_2025/motor_side_1rads.mat"
run tue2025-moving-fine identify "$real/tue_motion_2025/motor_side_1rads.mat" "${tue[@]}" \
    --nfft 10000 --band 1:150
run tue2025-operating-points-diagnose diagnose "$real/tue_motion_2025/motor_side_stationary.mat" \
    "${tue[@]}" --nfft 10000 --band 1:150 --model "$out/tue2025-moving-fine/model.toml" \
    --operating-point "$real/tue_motion_2025/motor_side_1rads.mat"
# One page per recording: `mms report` (identification, then the diagnosis
# with the best fit or the model given), as HTML.
report() { # NAME ARGS...: the HTML report into $out/report-NAME/
    local name=$1
    shift
    rm -rf "${out:?}/report-$name"
    "$mms" report "$@" --format html --out "$out/report-$name"
}
for rec in setup18_motor_side_v0.3 setup18_motor_side_v0.5 setup18_load_side_v0.5_m2 \
    setup29_load_side_v0.5 session02nov_frf_measurement_0; do
    report "sperte-$rec" "$real/sperte/$rec.mat" "${sperte[@]}"
done
report f16-level1 "$real/f16_gvt/F16Data_FullMSine_Level1.mat" "${f16[@]}" --band 4:15 --fit-gain
report emps "$real/emps/DATA_EMPS.mat" "${emps[@]}" --controller kp=kp,kv=kv
report emps-pulses "$real/emps/DATA_EMPS_PULSES.mat" "${emps[@]}" \
    --controller kp=160.18,kv=243.45,filter=0.5:0.5,saturation=10 --disturbance pulses_N
report robot-arm "$real/robot_arm/robot_arm.dat" --u 1 --y 2 --fs 1 --output acceleration \
    --nfft 256 --fit-gain
report tue2025-moving "$real/tue_motion_2025/motor_side_1rads.mat" "${tue[@]}"
report tue2025-standstill "$real/tue_motion_2025/motor_side_stationary.mat" "${tue[@]}"
report tue2018-both "$real/tue_motion_2018/scan_10hz_with_feedforward.mat" \
    --u Data.u --y Data.y1@1 --y Data.y2@N --excitation Data.r --band 1:100 --masses 2
echo "reports in $out"

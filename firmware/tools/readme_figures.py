#!/usr/bin/env python3
"""Checks the measured tables of firmware/README.md against what this run measured.

  readme_figures.py README OPT3_TABLE OPTS_TABLE [M33_TABLE]

OPT3_TABLE, OPTS_TABLE: the output of tools/check_budgets.py at opt-level 3 (with the flash
figures of .ci/firmware.sh) and at opt-level "s" (`figure measured target ceiling verdict`);
M33_TABLE: the same for the Cortex-M33 demo at opt-level 3 (the README's Cortex-M33 table).

Every row of "Instructions and peak stack per call" and "Sizes" is tied below to the figures it
shows; a row the map does not know, or a figure the run did not produce, fails the check, so the
tables cannot drift from the tools. Instruction counts, stack and flash are deterministic for one
compiler: they must be equal when the run's rustc is the one README names ("Measured with ... and
rustc X"), and within 5 % otherwise (a compiler release moves a count by a few per cent; the
budgets in budgets.txt stay the hard limits either way). `size_of` must always be equal.
The demo embeds the expected values it checks; when this run built it against values computed
afresh on this host that differ from the committed src/expected.rs (FIRMWARE_EXPECTED_DIFFERS=1,
set by .ci/firmware.sh: another host's last bits in the f32 run), its flash is another binary's
and is printed, not compared. A flash figure may differ from the README's by up to the binary's
alignment padding between functions (`padding.*`, tools/text_padding.py): the functions are the
same, their order follows symbol hashes that cargo derives from the checkout's absolute path.
The host ns column is not checked (criterion on a shared machine; benches/README.md).
"""
import os
import re
import subprocess
import sys

# Row label (its first cell, up to the first footnote mark) -> the figures of its cells.
# Per-call table: (instructions opt 3, instructions opt "s", stack opt 3, stack opt "s"); a
# cell with "a / b" lists both figures.
CALLS = {
    "`So3::exp`": ("so3_exp",),
    "`So3::log`": ("so3_log",),
    "`So3::compose`": ("so3_compose",),
    "`Se3::exp`": ("se3_exp",),
    "`Se3::log`": ("se3_log",),
    "`Se3::compose`": ("se3_compose",),
    "`Ins::predict`": ("ins_predict",),
    "`Ins::update(GnssPosition)`": ("ins_update_gnss_position",),
    "`Ins::update(GnssVelocity)`": ("ins_update_gnss_velocity",),
    "`Ins::update(Magnetometer)`": ("ins_update_magnetometer",),
    "`Ins::update(GravityDirection)`": ("ins_update_gravity",),
    "`Ins::update(BaroAltitude)`": ("ins_update_baro",),
    "`Ins::update(Heading)`": ("ins_update_heading",),
    "`Ins::update(ZeroVelocity)`": ("ins_update_zero_velocity",),
    "`Ins::update(AccelerometerAtRest)`": ("ins_update_accel_at_rest",),
    "`Ins::update(CameraLandmark)`": ("ins_update_camera",),
    "`Ins::update(CameraLandmark)`, iterated (at most 5)": ("ins_update_camera_iterated",),
    "`Ahrs::predict`": ("ahrs_predict",),
    "`Ahrs::update(Magnetometer)`": ("ahrs_update_magnetometer",),
    "`Ahrs::update(GravityDirection)`": ("ahrs_update_gravity",),
    "`Ahrs::update(Heading)`": ("ahrs_update_heading",),
    "`AttitudeNavigator`, costliest of its": (("nav_stream_max_call",), ("nav_stream",)),
    "`AttitudeNavigator::imu` at rest": ("nav_imu_block_end",),
    "`AttitudeNavigator`, mean per IMU sample": (("nav_stream_per_imu_sample",), ("nav_stream",)),
    "its parts, on the navigator's filter": ("nav_filter_predict",),
    "… `widen_attitude`": ("nav_filter_widen_attitude",),
    "… `update(ZeroRate)`": ("nav_filter_update_zero_rate",),
    "… `update(AccelerometerAtRest)`": ("nav_filter_update_accel",),
    "… `update(MagneticHeading)`": ("nav_filter_update_heading",),
    "`InsNavigator::imu`, a step": (("ins_nav_step_max",), ("ins_nav_step",)),
    "`InsNavigator::imu` with a delayed GNSS position": (
        ("ins_nav_gnss_position_max",), ("ins_nav_gnss_position",)),
    "`InsNavigator::imu` with a delayed GNSS velocity": (
        ("ins_nav_gnss_velocity_max", "ins_nav_magnetometer_max"),
        ("ins_nav_gnss_velocity", "ins_nav_magnetometer")),
    "`InsNavigator::imu`, the call that starts": (("ins_nav_start_max",), ("ins_nav_start",)),
    "`InsNavigator::imu` while aligning": (("ins_nav_aligning_max",), ("ins_nav_aligning",)),
    "`InsNavigator::imu` after an IMU gap": ("ins_nav_imu_after_gap",),
    "`InsNavigator::gnss` / `::magnetometer`": (
        ("ins_nav_gnss_call_max", "ins_nav_magnetometer_call_max"),
        ("ins_nav_gnss_call", "ins_nav_magnetometer_call")),
    "`InsNavigator::estimate`": ("ins_nav_estimate",),
    "`InsNavigator`, mean per IMU sample": (("ins_nav_per_imu_sample",), ("ins_nav",)),
    # The INS navigator's run without a magnetometer (the bank of yaw hypotheses).
    "`InsNavigator::imu` without a magnetometer (heading from the GNSS track": (
        ("ins_nav_no_mag_step_max",), ("ins_nav_no_mag_step",)),
    "`InsNavigator::imu` without a magnetometer, with a delayed GNSS position": (
        ("ins_nav_no_mag_gnss_position_max", "ins_nav_no_mag_gnss_velocity_max"),
        ("ins_nav_no_mag_gnss_position", "ins_nav_no_mag_gnss_velocity")),
    "`InsNavigator::imu` without a magnetometer, the call that starts": (
        ("ins_nav_no_mag_start_max", "ins_nav_no_mag_aligning_max"),
        ("ins_nav_no_mag_start", "ins_nav_no_mag_aligning")),
    "`InsNavigator::gnss` without a magnetometer": (
        ("ins_nav_no_mag_gnss_call_max",), ("ins_nav_no_mag_gnss_call",)),
    "`InsNavigator` without a magnetometer, mean per IMU sample": (
        ("ins_nav_no_mag_per_imu_sample",), ("ins_nav_no_mag",)),
    "`solve_pnp`, 20 points": ("pnp_solve_20",),
    "`scalar::sincos_f32`": ("sincos_f32",),
    "`scalar::sqrt_f32`": ("sqrt_f32",),
    "`scalar::atan2_f32`": ("atan2_f32",),
}
# Sizes table: the figures of its "bytes" cell (opt-3 table keys).
SIZES = {
    "`size_of::<Ins<f32>>()`": ["sizeof.Ins<f32>"],
    "`size_of::<Ahrs<f32>>()`": ["sizeof.Ahrs<f32>"],
    "`size_of::<AttitudeNavigator<f32>>()`": ["sizeof.AttitudeNavigator<f32>"],
    "`size_of::<AttitudeReport<f32>>()` / `AttitudeEstimate<f32>`": [
        "sizeof.AttitudeReport<f32>", "sizeof.AttitudeEstimate<f32>"],
    "`size_of::<InsNavigator<f32>>()`": ["sizeof.InsNavigator<f32>"],
    "`size_of::<InsReport<f32>>()` / `InsEstimate<f32>`": [
        "sizeof.InsReport<f32>", "sizeof.InsEstimate<f32>"],
    "`size_of::<InsState<f32>>()`": ["sizeof.InsState<f32>"],
    "`size_of::<PnpSolution<f32>>()`": ["sizeof.PnpSolution<f32>"],
    "`size_of::<PnpOptions<f32>>()`": ["sizeof.PnpOptions<f32>"],
    "`size_of::<NormalEquations<f32, 6>>()`": ["sizeof.NormalEquations<f32,6>"],
    "`size_of::<Se3<f32>>()` / `So3<f32>`": ["sizeof.Se3<f32>", "sizeof.So3<f32>"],
    "`size_of::<AhrsState<f32>>()`": ["sizeof.AhrsState<f32>"],
    "`size_of::<FilterConfig<f32>>()`": [
        "sizeof.FilterConfig<f32>", "sizeof.UpdateOptions<f32>", "sizeof.UpdateOutcome<f32>"],
    "`size_of::<SolverOptions<f32>>()`": [
        "sizeof.SolverOptions<f32>", "sizeof.Solution<f32,Se3<f32>,6>", "sizeof.Factor<f32,6>"],
    "`size_of::<Triangulation<f32>>()`": [
        "sizeof.Triangulation<f32>", "sizeof.RotationSolution<f32>"],
    "`nopanic` (whole public API, f32), opt \"s\"": ["flash.nopanic_s"],
    "`nopanic`, opt 3": ["flash.nopanic3"],
    "`fp_ahrs`": ["flash.fp_ahrs_s"],
    "`fp_ins`": ["flash.fp_ins_s"],
    "`fp_pnp`": ["flash.fp_pnp_s"],
    "`fp_att_nav`": ["flash.fp_att_nav_s", "flash.fp_att_nav3"],
    "`fp_ins_nav`": ["flash.fp_ins_nav_s", "flash.fp_ins_nav3"],
    "`nopanic` on the Cortex-M0+": ["flash.nopanic_m0_s", "flash.nopanic_m0_3"],
    "`fp_att_nav` / `fp_ins_nav` on the Cortex-M0+": ["flash.fp_att_nav_m0_s", "flash.fp_ins_nav_m0_s"],
    "`nopanic` on the Cortex-M33": ["flash.nopanic_m33_s", "flash.nopanic_m33_3"],
    "`fp_att_nav` / `fp_ins_nav` on the Cortex-M33": ["flash.fp_att_nav_m33_s", "flash.fp_ins_nav_m33_s"],
    "`nopanic` on RISC-V": ["flash.nopanic_rv32_s", "flash.nopanic_rv32_3"],
    "`fp_att_nav` / `fp_ins_nav` on RISC-V": ["flash.fp_att_nav_rv32_s", "flash.fp_ins_nav_rv32_s"],
    "`demo`, opt \"s\" / opt 3": ["flash.demo_s", "flash.demo3", "bss.demo_s"],
}


def measured(path):
    out = {}
    for line in open(path):
        parts = line.split()
        if len(parts) >= 2 and re.fullmatch(r"-?\d+", parts[1]):
            out[parts[0]] = int(parts[1])
    return out


def numbers(cell):
    """The integers of a cell, without parenthesized remarks or footnote marks."""
    cell = re.sub(r"\([^)]*\)", "", cell)
    cell = re.sub(r"[¹²³⁴⁵]", "", cell)
    return [int(n.replace(",", "")) for n in re.findall(r"\d[\d,]*", cell)]


def table(lines, header):
    rows, inside = [], False
    for line in lines:
        if line.startswith(header):
            inside = True
            continue
        if inside:
            if not line.startswith("|"):
                break
            if line.startswith("|---"):
                continue
            rows.append([c.strip() for c in line.strip().strip("|").split("|")])
    return rows


def lookup(label, mapping):
    hits = [k for k in mapping if label.startswith(k)]
    return mapping[max(hits, key=len)] if hits else None


def main():
    readme, opt3, opts = sys.argv[1], measured(sys.argv[2]), measured(sys.argv[3])
    lines = open(readme).read().splitlines()
    named = re.search(r"rustc (\d+\.\d+\.\d+)", "\n".join(lines))
    rustc = subprocess.run(["rustc", "--version"], capture_output=True, text=True).stdout
    exact = bool(named) and f"rustc {named.group(1)} " in rustc + " "
    tolerance = 0.0 if exact else 0.05
    print(f"firmware/README.md figures: {'equal' if exact else 'within 5 %'} "
          f"(README names rustc {named.group(1) if named else '?'}; this run: {rustc.strip()})")
    failures = []

    def compare(where, shown, keys, figures, rel):
        if len(shown) < len(keys):
            failures.append(f"{where}: shows {shown}, expected {len(keys)} figures {keys}")
            return
        for value, key in zip(shown, keys):
            if key not in figures:
                failures.append(f"{where}: {key} was not measured by this run")
                continue
            # A binary's flash includes the alignment padding between its functions, whose
            # layout follows cargo's path-dependent symbol hashes (tools/text_padding.py).
            slack = figures.get(key.replace("flash.", "padding.", 1), 0) if key.startswith("flash.") else 0
            diff = abs(value - figures[key])
            if diff > rel * figures[key] + slack:
                failures.append(f"{where}: README {value:,}, measured {figures[key]:,} ({key})")
            elif diff:
                print(f"  {where}: README {value:,}, measured {figures[key]:,} ({key}; within "
                      f"the {slack} B of alignment padding between functions, whose layout "
                      "follows the checkout's path)")

    def call_keys(label):
        """The icount and stack figures of a per-call row, or None (a failure) if unknown."""
        entry = lookup(label, CALLS)
        if entry is None:
            failures.append(f"row not tied to a figure: {label}")
            return None
        icount, stack = (entry, entry) if isinstance(entry[0], str) else entry
        return [f"icount.{k}" for k in icount], [f"stack.{k}" for k in stack]

    calls = table(lines, "| call | instructions, opt 3 |")
    if not calls:
        failures.append("no 'Instructions and peak stack per call' table")
    for row in calls:
        keys = call_keys(row[0])
        if keys is None:
            continue
        icount, stack = keys
        compare(f"{row[0]} / opt 3", numbers(row[1]), icount, opt3, tolerance)
        compare(f"{row[0]} / opt s", numbers(row[3]), icount, opts, tolerance)
        compare(f"{row[0]} / stack opt 3", numbers(row[4]), stack, opt3, tolerance)
        compare(f"{row[0]} / stack opt s", numbers(row[5]), stack, opts, tolerance)
    sizes = table(lines, "| figure | bytes | budget |")
    if not sizes:
        failures.append("no 'Sizes' table")
    for row in sizes:
        keys = lookup(row[0], SIZES)
        if keys is None:
            failures.append(f"row not tied to a figure: {row[0]}")
            continue
        rel = 0.0 if keys[0].startswith("sizeof.") else tolerance
        if keys[0].startswith("flash.demo") and os.environ.get("FIRMWARE_EXPECTED_DIFFERS") == "1":
            shown = ", ".join(f"{k} {opt3.get(k, '?')}" for k in keys)
            print(f"  {row[0]}: not compared (built against this host's expected values, "
                  f"not the committed ones): {shown}")
            continue
        compare(row[0], numbers(row[1]), keys, opt3, rel)
    other = 0
    if len(sys.argv) > 4:
        m33 = measured(sys.argv[4])
        rows = table(lines, "| call, Cortex-M33 (mps2-an505), opt 3 |")
        if not rows:
            failures.append("no Cortex-M33 table")
        for row in rows:
            keys = call_keys(row[0])
            if keys is None:
                continue
            icount, stack = keys
            compare(f"{row[0]} / Cortex-M33", numbers(row[1]), icount, m33, tolerance)
            compare(f"{row[0]} / stack Cortex-M33", numbers(row[2]), stack, m33, tolerance)
        other = len(rows)
    for f in failures:
        print("  " + f)
    print(f"firmware/README.md: {len(calls) + len(sizes) + other} rows, {len(failures)} disagree")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Hostile inputs for every `backbone` subcommand, run against the CLI's promise (README.md,
section 'Commands'):

  bad input -> before any work: exactly one line on stderr naming the key (and the constraint),
               exit code 2, nothing written (no --out folder created, no file touched);
  a run that stops early -> exit 1, never 0;
  --help on every subcommand -> exit 0;
  memory and time bounded before work starts.

Usage (from the repository root, so that relative scene paths resolve):

  python3 tests/drivers/hostile_inputs.py [--backbone build/bin/backbone] [--only ID,ID...]
                                          [--scratch /tmp/hostile] [--timeout 60] [--verbose]

Each case runs with a fresh `--out SCRATCH/<id>` (where the subcommand takes one), under
`timeout` and an address-space cap of 4 GB (ulimit -v 4000000); its wall time and peak RSS
(wait4) are printed. One line per case, then `N passed, M failed`; exit 1 if any case
misbehaves.

Kinds of cases:
  bad    exit 2, exactly one stderr line naming KEY (as a word), stating a constraint (not just
         "is invalid"), the --out folder absent afterwards, the prepared folders unchanged and
         nothing new in the working directory;
  help   exit 0, usage on stdout, nothing written;
  ok     valid-but-odd input with documented behaviour: exit 0 (and the case's own check);
  fail   a run that can only fail after work: exit 1, never 0, and a message naming KEY.
"""
import argparse
import hashlib
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import threading
import time

S = "problems/contact_bar/scenes/paper.ini"
D = "problems/duffing/scenes/duffing.ini"
I = "problems/impact_oscillator/scenes/impact.ini"
C = "problems/contact_bar/scenes/clearance.ini"
SMALL = ["--branch", "mode1", "--shooting_elements", "20", "--energy_max", "2e-5"]
MEMORY_CAP_KB = 4000000  # ulimit -v
SLOW_SECONDS = 10.0      # a bad input answered later than this was not refused before work

ARGS = None   # parsed command line
SCRATCH = ""  # /tmp/hostile
FX = ""       # SCRATCH/_fixtures


# --------------------------------------------------------------------------------------------
# The table.  c(id, subcommand, arguments, key, kind, **options)
#   arguments: list; "{S}" "{D}" "{I}" "{C}" "{FX}" "{OUT}" are replaced; --out OUT is appended unless the
#              case says out=False or names {OUT} itself.
#   options:   out=False (the subcommand takes no --out / the case must not add it),
#              prep=fn(out) prepares the folder (then it must stay unchanged for `bad`),
#              check=fn(result) -> error text or None (extra checks of ok/fail cases),
#              timeout=seconds (a shorter budget for a case that may not stop by itself),
#              note="..." what is hostile about it.
# --------------------------------------------------------------------------------------------
CASES = []


def c(cid, sub, args, key=None, kind="bad", **kw):
    CASES.append(dict(id=cid, sub=sub, args=args, key=key, kind=kind, **kw))


def prep_copy(src):
    def prep(out):
        shutil.copytree(os.path.join(FX, src), out, symlinks=True)
    return prep


def prep_file(text=b"x\n"):
    def prep(out):
        with open(out, "wb") as f:
            f.write(text)
    return prep


def prep_dir(out):
    os.makedirs(out)


def stdout_has(text):
    def check(r):
        return None if text in r["stdout"] else f"stdout does not say '{text}'"
    return check


def stderr_quotes(value):
    def check(r):
        return None if value in r["stderr"] else f"message does not quote the value given ({value})"
    return check


def summary_names(out_text):
    def check(r):
        path = os.path.join(SCRATCH, "out_existing_run_of_other_problem", "summary.txt")
        try:
            if out_text not in open(path).read():
                return f"summary.txt does not name {out_text}"
        except OSError:
            return "no summary.txt"
        return None
    return check


# ---- top level, version, help ---------------------------------------------------------------
c("top_no_command", None, [], "command", kind="bad", out=False)
c("top_unknown_command", "frobnicate", [], "frobnicate", out=False)
c("top_empty_command", "", [], "command", out=False)
c("top_option_as_command", "--out", ["/tmp/x"], "out", out=False)
c("top_help", "--help", [], kind="help", out=False)
c("top_help_short", "-h", [], kind="help", out=False)
c("version_plain", "version", [], kind="ok", out=False)
c("version_help", "version", ["--help"], kind="help", out=False)
c("version_unknown_option", "version", ["--frobnicate"], "frobnicate", out=False)
c("version_extra_argument", "version", ["extra"], "extra", out=False)
c("version_out", "version", ["--out", "{OUT}"], "out", out=False)
for sub in ["trace", "simulate", "inspect", "bench", "figures", "reproduce"]:
    c(f"{sub}_help", sub, ["--help"], kind="help", out=False)
c("trace_help_scene", "trace", ["{S}", "--help"], kind="help", out=False)
c("trace_help_duffing", "trace", ["{D}", "--help"], kind="help", out=False)
c("simulate_help_scene", "simulate", ["{S}", "--help"], kind="help", out=False)
c("inspect_help_scene", "inspect", ["{S}", "--help"], kind="help", out=False)
c("trace_help_after_keys", "trace", ["{S}", "--branch", "mode2", "--ds", "0.1", "--help"],
  kind="help", out=False)
c("bench_help_after_case", "bench", ["--case", "siconos_bar", "--help"], kind="help", out=False)
c("reproduce_help_after_only", "reproduce", ["--only", "mode1", "--help"], kind="help",
  out=False)
c("figures_help_with_out", "figures", ["--out", "{OUT}", "--help"], kind="help", out=False)

# ---- argument order and command-line syntax ------------------------------------------------
c("trace_no_scene", "trace", [], "SCENE", out=False)
c("trace_key_before_scene", "trace", ["--branch", "mode1", "{S}"], "scene")
c("trace_out_before_scene", "trace", ["--out", "{OUT}", "{S}"], "scene", out=False)
c("trace_two_scenes", "trace", ["{S}", "{S}"] + SMALL, S)
c("trace_key_without_value_last", "trace", ["{S}", "--branch", "mode1", "--out", "{OUT}",
                                             "--gap"], "gap", out=False)
c("trace_key_without_value_middle", "trace", ["{S}", "--gap", "--out", "{OUT}"], "gap",
  out=False)
c("trace_key_twice", "trace", ["{S}", "--gap", "1e-3", "--gap", "2e-3"] + SMALL, "gap")
c("trace_out_twice", "trace", ["{S}", "--out", "{OUT}", "--out", "{OUT}b"] + SMALL, "out",
  out=False)
c("trace_uppercase_key", "trace", ["{S}", "--GAP", "1e-3"] + SMALL, "GAP")
c("trace_single_dash_key", "trace", ["{S}", "-gap", "1e-3"] + SMALL, "gap")
c("trace_stray_value", "trace", ["{S}", "mode1"] + SMALL, "mode1")
c("trace_unknown_key", "trace", ["{S}", "--nosuchkey", "1"] + SMALL, "nosuchkey")
c("trace_simulate_key", "trace", ["{S}", "--periods", "2"] + SMALL, "periods")
c("simulate_trace_key", "simulate", ["{S}", "--shooting_elements", "5"], "shooting_elements")
c("simulate_key_before_scene", "simulate", ["--periods", "1", "{S}"], "scene")
c("simulate_no_scene", "simulate", [], "scene", out=False)
c("trace_equals_syntax", "trace", ["{S}", "--gap=0.001"] + SMALL, kind="ok",
  note="--key=value is boost's long-option syntax: accepted")
c("trace_problem_override", "trace", ["{S}", "--problem", "duffing"] + SMALL, "problem")
c("trace_branch_empty", "trace", ["{S}", "--branch", "", "--energy_max", "2e-5"], "branch")
c("trace_branch_unknown", "trace", ["{S}", "--branch", "mode3x"], "branch")
c("trace_branch_of_other_problem", "trace", ["{D}", "--branch", "mode1"], "branch")
c("trace_contact_key_on_duffing", "trace", ["{D}", "--gap", "1e-3"], "gap")
# The clearance end (problems/contact_bar/scenes/clearance.ini).
c("clearance_gap_back_without_clearance", "trace", ["{S}", "--gap_back", "1e-3"] + SMALL,
  "gap_back")
c("clearance_gap_back_zero", "trace", ["{C}", "--gap_back", "0"] + SMALL, "gap_back")
c("clearance_gap_back_negative", "simulate", ["{C}", "--gap_back", "-1e-3"], "gap_back")
c("clearance_gap_back_nan", "simulate", ["{C}", "--gap_back", "nan"], "gap_back")
c("clearance_back_wall_nearer", "trace", ["{C}", "--branch", "mode1", "--gap_back", "5e-4"],
  "gap_back")
c("clearance_u0_through_back_wall", "simulate", ["{C}", "--u0", "0:0 1:-0.002"], "u0")
c("clearance_follow", "trace", ["{C}", "--branch", "mode1", "--follow", "all"], "follow")
c("clearance_subharmonic", "trace", ["{C}", "--branch", "subharmonic"], "right_end")
c("clearance_free_knots", "trace", ["{C}", "--branch", "mode2", "--free_knots", "1"],
  "free_knots")
c("clearance_end_type_typo", "simulate", ["{C}", "--right_end", "clearence"], "right_end")
c("clearance_left_end_on_trace", "trace", ["{C}", "--branch", "mode1", "--left_end",
                                           "clearance", "--right_end", "fixed"], "left_end")
# The forced impact oscillator and the stability keys.
c("impact_frequency_zero", "trace", ["{I}", "--frequency", "0"], "frequency")
c("impact_frequency_negative", "trace", ["{I}", "--frequency", "-2.8"], "frequency")
c("impact_frequency_resonant", "trace", ["{I}", "--frequency", "2"], "frequency")
c("impact_frequency_nan", "trace", ["{I}", "--frequency", "nan"], "frequency")
c("impact_restitution_zero", "trace", ["{I}", "--restitution", "0"], "restitution")
c("impact_restitution_above_one", "trace", ["{I}", "--restitution", "1.01"], "restitution")
c("impact_wall_beyond_grazing", "trace", ["{I}", "--wall", "0.2"], "wall",
  note="no impact: the event never fires")
c("impact_wall_min_above_wall", "trace", ["{I}", "--wall_min", "0.05"], "wall_min")
c("impact_wall_max_below_wall", "trace", ["{I}", "--wall_max", "-0.05"], "wall_max")
c("impact_grazing_velocity_zero", "trace", ["{I}", "--grazing_velocity", "0"], "grazing_velocity")
c("impact_grazing_gap_negative", "trace", ["{I}", "--grazing_gap", "-1"], "grazing_gap")
c("impact_unknown_parameter", "trace", ["{I}", "--continuation_parameter", "mass"],
  "continuation_parameter")
c("impact_rtol_too_loose", "trace", ["{I}", "--rtol", "0.1"], "rtol")
c("impact_contact_key", "trace", ["{I}", "--gap", "1e-3"], "gap")
c("stability_not_a_bool", "trace", ["{I}", "--stability", "maybe"], "stability")
c("stability_representation_typo", "trace",
  ["{S}", "--branch", "mode1", "--stability", "true", "--stability_representation", "front"],
  "stability_representation")
c("stability_tdbem_check_on_exact_solver", "trace",
  ["{S}", "--branch", "mode1", "--stability", "true", "--stability_tdbem_check", "true",
   "--shooting_solver", "exact"], "stability_tdbem_check")
c("stability_growth_periods_negative", "trace",
  ["{S}", "--branch", "mode1", "--stability", "true", "--stability_growth_periods", "-5"],
  "stability_growth_periods")
c("stability_key_without_stability", "trace",
  ["{S}", "--branch", "mode1", "--stability_representation", "grid"], "stability_representation")
c("stability_grid_key_with_fronts", "trace",
  ["{S}", "--branch", "mode1", "--stability", "true", "--stability_elements", "50"],
  "stability_elements")
c("stability_grid_too_costly", "trace",
  ["{S}", "--branch", "mode1", "--stability", "true", "--stability_representation", "grid",
   "--stability_elements", "2000"], "stability_elements")
c("stability_growth_periods_huge", "trace",
  ["{S}", "--branch", "mode1", "--stability", "true", "--stability_growth_periods", "1e9"],
  "stability_growth_periods")
c("floquet_tolerance_zero", "trace", ["{I}", "--floquet_tolerance", "0"], "floquet_tolerance")
c("floquet_tolerance_huge", "trace", ["{D}", "--floquet_tolerance", "5"], "floquet_tolerance")
c("floquet_trivial_tolerance_nan", "trace", ["{D}", "--floquet_trivial_tolerance", "nan"],
  "floquet_trivial_tolerance")
c("follow_doubling_typo", "trace", ["{I}", "--follow", "doublings"], "follow")
c("impact_key_without_value", "trace", ["{I}", "--wall", "--max_points", "3"], "wall")
c("impact_flag_with_value", "reproduce", ["--quick", "yes", "--out", "{OUT}"], "quick", out=False)

# ---- scene files ----------------------------------------------------------------------------
c("scene_missing_file", "trace", ["/nonexistent/scene.ini"] + SMALL, "scene")
c("scene_empty_path", "trace", [""] + SMALL, "scene")
c("scene_directory", "trace", ["{FX}/scenes"] + SMALL, "scene")
c("scene_dev_null", "trace", ["/dev/null"] + SMALL, "scene")
c("scene_dev_zero", "trace", ["/dev/zero"] + SMALL, "scene")
c("scene_fifo", "trace", ["{FX}/scenes/fifo.ini"] + SMALL, "scene")
c("scene_symlink_loop", "trace", ["{FX}/scenes/loop.ini"] + SMALL, "scene")
c("scene_dangling_symlink", "trace", ["{FX}/scenes/dangling.ini"] + SMALL, "scene")
c("scene_empty_file", "trace", ["{FX}/scenes/empty.ini"] + SMALL, "problem")
c("scene_only_comments", "trace", ["{FX}/scenes/comments.ini"] + SMALL, "problem")
c("scene_semicolon_comment", "trace", ["{FX}/scenes/semicolon.ini"] + SMALL, "; a comment",
  note="';' comments are not part of the format: the line must be named")
c("scene_no_problem", "trace", ["{FX}/scenes/no_problem.ini"] + SMALL, "problem")
c("scene_problem_unknown", "trace", ["{FX}/scenes/problem_unknown.ini"] + SMALL, "problem")
c("scene_problem_empty", "trace", ["{FX}/scenes/problem_empty.ini"] + SMALL, "problem")
c("scene_problem_unicode", "trace", ["{FX}/scenes/problem_unicode.ini"] + SMALL, "problem")
c("scene_problem_duffing_with_bar_keys", "trace", ["{FX}/scenes/duffing_bar_keys.ini"], "gap")
c("scene_problem_twice", "trace", ["{FX}/scenes/problem_twice.ini"] + SMALL, "problem")
c("scene_key_twice", "trace", ["{FX}/scenes/gap_twice.ini"] + SMALL, "gap")
c("scene_key_twice_same_value", "trace", ["{FX}/scenes/gap_twice_same.ini"] + SMALL, "gap")
c("scene_unknown_key", "trace", ["{FX}/scenes/unknown_key.ini"] + SMALL, "frobnicate")
c("scene_unicode_key", "trace", ["{FX}/scenes/unicode_key.ini"] + SMALL, "gäp")
c("scene_uppercase_key", "trace", ["{FX}/scenes/upper_key.ini"] + SMALL, "GAP")
c("scene_line_without_equals", "trace", ["{FX}/scenes/no_equals.ini"] + SMALL, "gap")
c("scene_line_without_key", "trace", ["{FX}/scenes/no_key.ini"] + SMALL, "= 0.001")
c("scene_section_header", "trace", ["{FX}/scenes/section.ini"] + SMALL, "scene")
c("scene_nul_bytes", "trace", ["{FX}/scenes/nul.ini"] + SMALL, "scene")
c("scene_utf16", "trace", ["{FX}/scenes/utf16.ini"] + SMALL, "scene")
c("scene_binary", "trace", ["{FX}/scenes/binary.ini"] + SMALL, "scene")
c("scene_huge_file", "trace", ["{FX}/scenes/huge.ini"] + SMALL, "scene")
c("scene_huge_line", "simulate", ["{FX}/scenes/huge_line.ini"], kind="ok",
  note="a 0.5 MB u0 line of 25001 knots (the file below 1 MiB): read and simulated")
c("scene_value_nan", "trace", ["{FX}/scenes/gap_nan.ini"] + SMALL, "gap")
c("scene_value_inf", "trace", ["{FX}/scenes/length_inf.ini"] + SMALL, "length")
c("scene_value_negative", "trace", ["{FX}/scenes/density_negative.ini"] + SMALL, "density")
c("scene_value_trailing_garbage", "trace", ["{FX}/scenes/gap_garbage.ini"] + SMALL, "gap")
c("scene_value_empty_number", "trace", ["{FX}/scenes/gap_empty.ini"] + SMALL, "gap")
c("scene_value_hex_integer", "trace", ["{FX}/scenes/elements_hex.ini"] + SMALL, "elements")
c("scene_value_float_integer", "trace", ["{FX}/scenes/shooting_float.ini", "--branch", "mode1",
                                         "--energy_max", "2e-5"], "shooting_elements")
c("scene_value_unicode_digits", "trace", ["{FX}/scenes/gap_unicode.ini"] + SMALL, "gap")
c("scene_bool_garbage", "trace", ["{FX}/scenes/verify_garbage.ini"] + SMALL, "verify")
c("scene_cli_overrides_bad_file_value", "trace",
  ["{FX}/scenes/gap_nan.ini", "--gap", "0.001"] + SMALL, kind="ok",
  note="command line > scene file: the file's NaN is overridden")
c("scene_crlf_lines", "trace", ["{FX}/scenes/crlf.ini"] + SMALL, kind="ok",
  note="CRLF line ends of a valid scene")
c("scene_utf8_bom", "trace", ["{FX}/scenes/bom.ini"] + SMALL, kind="ok",
  note="a valid scene behind a UTF-8 byte-order mark")
c("scene_inline_comment", "trace", ["{FX}/scenes/inline_comment.ini"] + SMALL, kind="ok",
  note="'gap = 0.001 # comment'")
c("simulate_scene_of_duffing", "simulate", ["{D}"], "problem")
c("simulate_scene_missing", "simulate", ["/nonexistent.ini"], "scene")
c("simulate_scene_binary", "simulate", ["{FX}/scenes/binary.ini"], "scene")
c("inspect_scene_missing", "inspect", ["/nonexistent.ini", "--orbit",
                                       "{FX}/mode1/orbits.csv:3"], "scene", out=False)

# ---- contact bar scene keys (trace and simulate) --------------------------------------------
for key in ["length", "youngs_modulus", "density", "area"]:
    for tag, val in [("zero", "0"), ("negative", "-1"), ("nan", "nan"), ("inf", "inf")]:
        sub = "simulate" if tag in ("negative", "inf") else "trace"
        extra = [] if sub == "simulate" else SMALL
        c(f"{sub}_{key}_{tag}", sub, ["{S}", f"--{key}", val] + extra, key)
c("trace_length_text", "trace", ["{S}", "--length", "one"] + SMALL, "length")
c("simulate_length_huge", "simulate", ["{S}", "--length", "1e300"], "length",
  note="L/c = 1e300: dt and the wave transit no longer fit a run")
c("simulate_left_end_bogus", "simulate", ["{S}", "--left_end", "glued"], "left_end")
c("simulate_right_end_empty", "simulate", ["{S}", "--right_end", ""], "right_end")
c("trace_right_end_fixed", "trace", ["{S}", "--right_end", "fixed"] + SMALL, "right_end")
c("trace_gap_negative", "trace", ["{S}", "--gap", "-1e-3"] + SMALL, "gap")
c("trace_gap_zero", "trace", ["{S}", "--gap", "0"] + SMALL, "gap")
c("simulate_gap_nan", "simulate", ["{S}", "--gap", "nan"], "gap")
c("simulate_gap_inf", "simulate", ["{S}", "--gap", "inf"], "gap")
c("trace_gap_huge", "trace", ["{S}", "--gap", "1e300"] + SMALL, "gap")
c("simulate_body_force_nan", "simulate", ["{S}", "--body_force", "nan"], "body_force")
c("simulate_body_force_inf", "simulate", ["{S}", "--body_force", "-inf"], "body_force")
c("simulate_u0_not_knots", "simulate", ["{S}", "--u0", "abc"], "u0")
c("simulate_u0_outside_bar", "simulate", ["{S}", "--u0", "0:0 2:-0.01"], "u0")
c("simulate_u0_nan", "simulate", ["{S}", "--u0", "0:nan 1:0"], "u0")
c("simulate_u0_decreasing", "simulate", ["{S}", "--u0", "0.5:0 0.2:0"], "u0")
c("simulate_v0_inf", "simulate", ["{S}", "--v0", "0:inf"], "v0")
c("simulate_v0_half_knot", "simulate", ["{S}", "--v0", "0:0 1"], "v0")
c("trace_u0_nan", "trace", ["{S}", "--u0", "0:nan 1:0"] + SMALL, "u0")
c("trace_u0_outside_bar", "trace", ["{S}", "--u0", "0:0 2:-0.01"] + SMALL, "u0")
c("trace_u0_not_knots", "trace", ["{S}", "--u0", "0:0 1"] + SMALL, "u0")
c("trace_v0_decreasing", "trace", ["{S}", "--v0", "0.5:0 0.2:0"] + SMALL, "v0")
c("simulate_elements_zero", "simulate", ["{S}", "--elements", "0"], "elements")
c("simulate_elements_negative", "simulate", ["{S}", "--elements", "-5"], "elements")
c("simulate_elements_fraction", "simulate", ["{S}", "--elements", "1.5"], "elements")
c("simulate_elements_exponent", "simulate", ["{S}", "--elements", "1e3"], "elements")
c("simulate_elements_overflow", "simulate", ["{S}", "--elements", "99999999999999999999"],
  "elements")
c("simulate_elements_huge", "simulate", ["{S}", "--elements", "2000000000"], "elements")
c("simulate_fem_elements_huge", "simulate", ["{S}", "--method", "fem", "--elements",
                                             "100000000"], "elements")
c("trace_elements_zero", "trace", ["{S}", "--elements", "0"] + SMALL, "elements")
c("simulate_dt_zero", "simulate", ["{S}", "--dt", "0"], "dt")
c("simulate_dt_negative", "simulate", ["{S}", "--dt", "-0.01"], "dt")
c("simulate_dt_nan", "simulate", ["{S}", "--dt", "nan"], "dt")
c("simulate_dt_beyond_transit", "simulate", ["{S}", "--dt", "2"], "dt")
c("simulate_dt_tiny", "simulate", ["{S}", "--dt", "1e-12"], "dt")
c("trace_dt_beyond_transit", "trace", ["{S}", "--dt", "5"] + SMALL, "dt")
c("simulate_contact_bogus", "simulate", ["{S}", "--contact", "sticky"], "contact")
c("trace_contact_bogus", "trace", ["{S}", "--contact", "sticky"] + SMALL, "contact")
c("simulate_period_zero", "simulate", ["{S}", "--period", "0"], "period")
c("simulate_period_inf", "simulate", ["{S}", "--period", "inf"], "period")
c("trace_period_negative", "trace", ["{S}", "--period", "-1"] + SMALL, "period")
c("simulate_history_samples_one", "simulate", ["{S}", "--history_samples", "1"],
  "history_samples")
c("simulate_history_samples_huge", "simulate", ["{S}", "--history_samples", "1000000000"],
  "history_samples")
c("trace_history_samples_one", "trace", ["{S}", "--history_samples", "1"] + SMALL,
  "history_samples")
c("simulate_probes_outside", "simulate", ["{S}", "--probes", "2"], "probes")
c("simulate_probes_nan", "simulate", ["{S}", "--probes", "nan"], "probes")
c("simulate_probes_text", "simulate", ["{S}", "--probes", "middle"], "probes")
c("simulate_probes_many", "simulate", ["{S}", "--probes", " ".join(["0.5"] * 20000)], "probes",
  note="20000 probes: 20000 columns x 2000 rows; should be bounded (or cheap)")
c("trace_probes_outside", "trace", ["{S}", "--probes", "5"] + SMALL, "probes")

# ---- simulate's own keys --------------------------------------------------------------------
c("simulate_method_bogus", "simulate", ["{S}", "--method", "rk4"], "method")
c("simulate_periods_zero", "simulate", ["{S}", "--periods", "0"], "periods")
c("simulate_periods_negative", "simulate", ["{S}", "--periods", "-1"], "periods")
c("simulate_periods_nan", "simulate", ["{S}", "--periods", "nan"], "periods")
c("simulate_periods_huge", "simulate", ["{S}", "--periods", "1e9"], "dt")
c("simulate_exact_periods_huge", "simulate", ["{S}", "--method", "exact", "--periods", "1e7"],
  "periods")
c("simulate_max_steps_zero", "simulate", ["{S}", "--max_steps", "0"], "max_steps")
c("simulate_max_steps_negative", "simulate", ["{S}", "--max_steps", "-1"], "max_steps")
c("simulate_compare_with_value", "simulate", ["{S}", "--compare", "yes"], "yes")
c("simulate_orbit_missing", "simulate", ["{S}", "--orbit", "/nonexistent/orbits.csv:1"],
  "orbit")
c("simulate_orbit_out_of_range", "simulate", ["{S}", "--orbit", "{FX}/mode1/orbits.csv:999"],
  "orbit")
c("simulate_orbit_negative", "simulate", ["{S}", "--orbit", "{FX}/mode1/orbits.csv:-1"],
  "orbit")
c("simulate_orbit_no_index", "simulate", ["{S}", "--orbit", "{FX}/mode1/orbits.csv"], "orbit")
c("simulate_orbit_of_duffing", "simulate", ["{S}", "--orbit", "{FX}/duff/orbits.csv:1"],
  "orbit")
c("simulate_orbit_corrupt", "simulate", ["{S}", "--orbit", "{FX}/bad_orbits/orbits.csv:2"],
  "orbit")

# ---- contact bar shooting keys (trace) ------------------------------------------------------
c("trace_shooting_elements_negative", "trace", ["{S}", "--branch", "mode1",
                                                "--shooting_elements", "-1"],
  "shooting_elements")
c("trace_shooting_elements_huge", "trace", ["{S}", "--branch", "mode1",
                                            "--shooting_elements", "100000"],
  "shooting_elements", note="100000 x 40 passes max_residual_work; the Jacobian does not fit")
c("trace_shooting_elements_large", "trace", ["{S}", "--branch", "mode1",
                                             "--shooting_elements", "20000"],
  "shooting_elements", note="20000 x 40 = 8e5 element-steps; dense Jacobian 40000 x 20000")
c("trace_shooting_elements_slow", "trace", ["{S}", "--branch", "mode1", "--shooting_elements",
                                           "3000", "--max_points", "2"], "shooting_elements",
  timeout=8, note="3000 x 40 passes max_residual_work and max_memory; its dense SVD "
  "(6000 x 3001^2 = 5.4e10 operations) exceeds max_dense_work 2e10")
c("trace_test_elements_bogus", "trace", ["{S}", "--test_elements", "-2"] + SMALL,
  "test_elements")
c("trace_steps_per_period_odd", "trace", ["{S}", "--steps_per_period", "41"] + SMALL,
  "steps_per_period")
c("trace_steps_per_period_zero", "trace", ["{S}", "--steps_per_period", "0"] + SMALL,
  "steps_per_period")
c("trace_steps_per_period_huge", "trace", ["{S}", "--steps_per_period", "100000000"] + SMALL,
  "steps_per_period")
c("trace_shooting_solver_bogus", "trace", ["{S}", "--shooting_solver", "fem"] + SMALL,
  "shooting_solver")
c("trace_start_offset_negative", "trace", ["{S}", "--start_offset", "-0.5"] + SMALL,
  "start_offset")
c("trace_start_offset_nan", "trace", ["{S}", "--start_offset", "nan"] + SMALL, "start_offset")
# At energy_max's default (SMALL would set it): shooting_elements 20 keeps a regressed check short.
c("trace_start_offset_above_energy_max", "trace", ["{S}", "--branch", "mode1", "--start_offset",
                                                   "1e6", "--shooting_elements", "20"], "energy_max")
c("trace_start_guess_bogus", "trace", ["{S}", "--start_guess", "random"] + SMALL,
  "start_guess")
c("trace_free_knots_negative", "trace", ["{S}", "--free_knots", "-2"] + SMALL, "free_knots")
c("trace_free_knots_huge", "trace", ["{S}", "--free_knots", "1000"] + SMALL, "free_knots")
c("trace_knot_nodes_text", "trace", ["{S}", "--branch", "mode2", "--knot_nodes", "abc"],
  "knot_nodes")
c("trace_knot_nodes_decreasing", "trace",
  ["{S}", "--branch", "mode3", "--shooting_elements", "46", "--knot_nodes", "26 10"],
  "knot_nodes")
c("trace_knot_nodes_count", "trace", ["{S}", "--branch", "mode2", "--knot_nodes", "10 20"],
  "knot_nodes")
c("trace_knot_nodes_beyond", "trace", ["{S}", "--branch", "mode2", "--knot_nodes", "20"],
  "knot_nodes")
c("trace_energy_max_nan", "trace", ["{S}", "--branch", "mode1", "--energy_max", "nan"],
  "energy_max")
c("trace_energy_max_negative", "trace", ["{S}", "--branch", "mode1", "--energy_max", "-1"],
  "energy_max")
c("trace_energy_max_below_start", "trace", ["{S}", "--branch", "mode1", "--energy_max", "1e-9"],
  "energy_max", note="the first point (E = 5.5e-7) already lies beyond the bound")
c("trace_amplitude_units_bogus", "trace", ["{S}", "--amplitude_units", "maybe"] + SMALL,
  "amplitude_units")
c("trace_max_residual_work_zero", "trace", ["{S}", "--max_residual_work", "0"] + SMALL,
  "max_residual_work")
c("trace_max_residual_work_negative", "trace", ["{S}", "--max_residual_work", "-1"] + SMALL,
  "max_residual_work")
c("trace_return_tolerance_negative", "trace", ["{S}", "--return_tolerance", "-1"] + SMALL,
  "return_tolerance")
c("trace_return_tolerance_nan", "trace", ["{S}", "--return_tolerance", "nan"] + SMALL,
  "return_tolerance")
c("trace_energy_negative", "trace", ["{S}", "--branch", "subharmonic_continuum", "--energy",
                                     "-1"], "energy")
c("trace_energy_nan", "trace", ["{S}", "--branch", "subharmonic_continuum", "--energy", "nan"],
  "energy")
c("trace_shape_above_one", "trace", ["{S}", "--branch", "subharmonic", "--shape", "2"], "shape")
c("trace_shape_zero", "trace", ["{S}", "--branch", "subharmonic", "--shape", "0",
                               "--max_points", "3"], "shape",
  note="help: shape in (0, 1]; 0 itself degenerates the two-knot chart")
c("trace_shape_negative", "trace", ["{S}", "--branch", "subharmonic", "--shape", "-0.5"],
  "shape")
c("trace_path_rows_bogus", "trace", ["{S}", "--branch", "subharmonic", "--path_rows", "2"],
  "path_rows")
c("trace_path_rows_false", "trace", ["{S}", "--branch", "subharmonic", "--path_rows", "false",
                                     "--max_points", "3"], "path_rows",
  note="help: trace needs the row")
c("trace_dimension_check_bogus", "trace", ["{S}", "--branch", "subharmonic",
                                           "--dimension_check", "perhaps"], "dimension_check")
MANIFOLD = ["{S}", "--branch", "subharmonic_manifold", "--energy_min", "1e-5", "--energy_max",
            "1e-4"]
c("trace_chart_radius_zero", "trace", MANIFOLD + ["--chart_radius", "0"], "chart_radius")
c("trace_chart_radius_negative", "trace", MANIFOLD + ["--chart_radius", "-0.3"], "chart_radius")
c("trace_shape_margin_half", "trace", MANIFOLD + ["--shape_margin", "0.6"], "shape_margin")
c("trace_shape_margin_negative", "trace", MANIFOLD + ["--shape_margin", "-0.1"], "shape_margin")
c("trace_max_charts_zero", "trace", MANIFOLD + ["--max_charts", "0"], "max_charts")
c("trace_max_charts_huge", "trace", MANIFOLD + ["--max_charts", "1000000000000"], "max_charts")
c("trace_manifold_no_energy_window", "trace", ["{S}", "--branch", "subharmonic_manifold"],
  "energy_min")

# ---- duffing keys ---------------------------------------------------------------------------
c("duffing_amplitude_zero", "trace", ["{D}", "--amplitude", "0"], "amplitude")
c("duffing_amplitude_negative", "trace", ["{D}", "--amplitude", "-1"], "amplitude")
c("duffing_amplitude_nan", "trace", ["{D}", "--amplitude", "nan"], "amplitude")
c("duffing_amplitude_huge", "trace", ["{D}", "--amplitude", "1e300"], "amplitude")
c("duffing_amplitude_text", "trace", ["{D}", "--amplitude", "big"], "amplitude")
c("duffing_period_guess_zero", "trace", ["{D}", "--period_guess", "0"], "period_guess")
c("duffing_period_guess_negative", "trace", ["{D}", "--period_guess", "-6"], "period_guess")
c("duffing_period_guess_inf", "trace", ["{D}", "--period_guess", "inf"], "period_guess")
c("duffing_period_guess_huge", "trace", ["{D}", "--period_guess", "1e12"], "period_guess",
  note="CVODE over 1e12 time units: time not bounded unless refused")
c("duffing_rtol_zero", "trace", ["{D}", "--rtol", "0"], "rtol")
c("duffing_rtol_negative", "trace", ["{D}", "--rtol", "-1e-9"], "rtol")
c("duffing_rtol_huge", "trace", ["{D}", "--rtol", "10"], "rtol")
c("duffing_rtol_nan", "trace", ["{D}", "--rtol", "nan"], "rtol")
c("duffing_amplitude_outside_bound", "trace", ["{D}", "--amplitude", "20"], "amplitude",
  note="the scene's bound is amplitude:0.005:10; the start lies beyond it")
c("duffing_bound_empty", "trace", ["{D}", "--bound", "", "--max_points", "5"], kind="ok",
  note="help: empty = unbounded")

# ---- continuation keys ----------------------------------------------------------------------
c("cont_ds_zero", "trace", ["{S}", "--ds", "0"] + SMALL, "ds")
c("cont_ds_negative", "trace", ["{S}", "--ds", "-1"] + SMALL, "ds")
c("cont_ds_nan", "trace", ["{S}", "--ds", "nan"] + SMALL, "ds")
c("cont_ds_inf", "trace", ["{D}", "--ds", "inf"], "ds")
c("cont_ds_text", "trace", ["{D}", "--ds", "small"], "ds")
c("cont_ds_huge", "trace", ["{D}", "--ds", "1e300", "--ds_max", "1e300"], kind="ok",
  note="one step lands on the scene's amplitude bound (2 points)")
c("cont_ds_above_ds_max", "trace", ["{D}", "--ds", "1", "--ds_max", "0.5"], "ds")
c("cont_ds_min_zero", "trace", ["{D}", "--ds_min", "0"], "ds_min")
c("cont_ds_min_negative", "trace", ["{D}", "--ds_min", "-1e-8"], "ds_min")
c("cont_ds_min_above_ds", "trace", ["{D}", "--ds_min", "1"], "ds_min")
c("cont_ds_min_nan", "trace", ["{D}", "--ds_min", "nan"], "ds_min")
c("cont_ds_max_zero", "trace", ["{D}", "--ds_max", "0"], "ds_max")
c("cont_ds_max_negative", "trace", ["{D}", "--ds_max", "-0.5"], "ds_max")
c("cont_ds_max_inf", "trace", ["{D}", "--ds_max", "inf"], "ds_max")
c("cont_max_points_zero", "trace", ["{D}", "--max_points", "0"], "max_points")
c("cont_max_points_negative", "trace", ["{D}", "--max_points", "-5"], "max_points")
c("cont_max_points_overflow", "trace", ["{D}", "--max_points", "99999999999999999999999"],
  "max_points")
c("cont_max_points_fraction", "trace", ["{D}", "--max_points", "2.5"], "max_points")
c("cont_max_points_huge_bounded", "trace", ["{S}", "--max_points", "1000000000"] + SMALL[:-2]
  + ["--energy_max", "2e-5"], kind="ok", note="huge budget, but the energy bound ends it")
c("cont_energy_min_above_max", "trace", ["{S}", "--energy_min", "1", "--energy_max", "0.1",
                                         "--branch", "mode1"], "energy_min")
c("cont_energy_min_nan", "trace", ["{D}", "--energy_min", "nan"], "energy_min")
c("cont_period_min_above_max", "trace", ["{D}", "--period_min", "7", "--period_max", "6"],
  "period_min")
c("cont_period_max_nan", "trace", ["{D}", "--period_max", "nan"], "period_max")
c("cont_bound_unknown_observable", "trace", ["{D}", "--bound", "nosuch:0:1"], "bound")
c("cont_bound_two_fields", "trace", ["{D}", "--bound", "amplitude:1"], "bound")
c("cont_bound_four_fields", "trace", ["{D}", "--bound", "amplitude:0:1:2"], "bound")
c("cont_bound_min_above_max", "trace", ["{D}", "--bound", "amplitude:2:1"], "bound")
c("cont_bound_nan", "trace", ["{D}", "--bound", "amplitude:nan:1"], "bound")
c("cont_bound_text", "trace", ["{D}", "--bound", "amplitude:low:high"], "bound")
c("cont_bound_empty_name", "trace", ["{D}", "--bound", ":0:1"], "bound")
c("cont_method_bogus", "trace", ["{D}", "--method", "newton"], "method")
c("cont_method_empty", "trace", ["{D}", "--method", ""], "method")
c("cont_method_uppercase", "trace", ["{D}", "--method", "ARCLENGTH"], "method")
c("cont_predictor_bogus", "trace", ["{D}", "--predictor", "cubic"], "predictor")
c("cont_newton_bogus", "trace", ["{D}", "--newton", "broyden"], "newton")
c("cont_newton_kinsol_overdetermined", "trace", ["{S}", "--newton", "kinsol"] + SMALL, "newton")
c("cont_formulation_bogus", "trace", ["{D}", "--formulation", "weird"], "formulation")
c("cont_threads_zero", "trace", ["{D}", "--threads", "0"], "threads")
c("cont_threads_negative", "trace", ["{D}", "--threads", "-4"], "threads")
c("cont_threads_huge", "trace", ["{D}", "--threads", "100000"], "threads")
c("cont_follow_bogus", "trace", ["{S}", "--follow", "some"] + SMALL, "follow")
c("cont_follow_zero", "trace", ["{S}", "--follow", "0"] + SMALL, "follow")
c("cont_follow_negative", "trace", ["{S}", "--follow", "-1"] + SMALL, "follow")
c("cont_follow_with_natural", "trace", ["{S}", "--method", "natural", "--follow", "all"] + SMALL,
  "follow", note="help: follow is arclength only")
c("cont_detect_with_natural", "trace", ["{S}", "--method", "natural",
                                        "--detect_branch_points", "true"] + SMALL,
  "detect_branch_points", note="help: detection is arclength only")
c("cont_follow_beyond_located", "trace", ["{S}", "--follow", "99"] + SMALL, "follow",
  kind="fail", note="known only after the run: exit 1 naming --follow")
c("cont_follow_max_points_zero", "trace", ["{S}", "--follow", "all", "--follow_max_points", "0"]
  + SMALL, "follow_max_points")
c("cont_follow_max_points_negative", "trace", ["{S}", "--follow", "all",
                                               "--follow_max_points", "-3"] + SMALL,
  "follow_max_points")
c("cont_max_turn_degrees_negative", "trace", ["{S}", "--max_turn_degrees", "-10"] + SMALL,
  "max_turn_degrees")
c("cont_max_turn_degrees_over_180", "trace", ["{S}", "--max_turn_degrees", "720"] + SMALL,
  "max_turn_degrees")
c("cont_max_turn_degrees_nan", "trace", ["{S}", "--max_turn_degrees", "nan"] + SMALL,
  "max_turn_degrees")
c("cont_newton_tolerance_zero", "trace", ["{D}", "--newton_tolerance", "0"], "newton_tolerance")
c("cont_newton_tolerance_negative", "trace", ["{D}", "--newton_tolerance", "-1e-10"],
  "newton_tolerance")
c("cont_newton_tolerance_nan", "trace", ["{D}", "--newton_tolerance", "nan"],
  "newton_tolerance")
c("cont_newton_max_iterations_zero", "trace", ["{D}", "--newton_max_iterations", "0"],
  "newton_max_iterations")
c("cont_newton_max_iterations_negative", "trace", ["{D}", "--newton_max_iterations", "-1"],
  "newton_max_iterations")
c("cont_newton_max_iterations_huge", "trace", ["{D}", "--newton_max_iterations", "2000000000"],
  kind="ok", note="a cap, not a cost: Newton still stops when it converges or diverges")
c("cont_newton_reuse_jacobian_bogus", "trace", ["{D}", "--newton_reuse_jacobian", "2"],
  "newton_reuse_jacobian")
c("cont_newton_jacobian_check_negative", "trace", ["{D}", "--newton_jacobian_check", "-0.01"],
  "newton_jacobian_check")
c("cont_newton_jacobian_check_nan", "trace", ["{D}", "--newton_jacobian_check", "nan"],
  "newton_jacobian_check")
c("cont_chord_corrections_bogus", "trace", ["{D}", "--chord_corrections", "sometimes"],
  "chord_corrections")
c("cont_natural_parameter_bogus", "trace", ["{D}", "--method", "natural",
                                            "--natural_parameter", "nosuch"],
  "natural_parameter")
c("cont_natural_direction_zero", "trace", ["{D}", "--method", "natural",
                                           "--natural_direction", "0"], "natural_direction")
c("cont_natural_direction_two", "trace", ["{D}", "--method", "natural",
                                          "--natural_direction", "2"], "natural_direction")
c("cont_rank_check_every_negative", "trace", ["{D}", "--rank_check_every", "-1"],
  "rank_check_every")
c("cont_rank_threshold_zero", "trace", ["{D}", "--rank_threshold", "0"], "rank_threshold")
c("cont_rank_threshold_negative", "trace", ["{D}", "--rank_threshold", "-1e-8"],
  "rank_threshold")
c("cont_rank_threshold_above_one", "trace", ["{D}", "--rank_threshold", "2"], "rank_threshold")
c("cont_rank_threshold_nan", "trace", ["{D}", "--rank_threshold", "nan"], "rank_threshold")
c("cont_verify_bogus", "trace", ["{D}", "--verify", "maybe"], "verify")
c("cont_detect_branch_points_bogus", "trace", ["{D}", "--detect_branch_points", "yesplease"],
  "detect_branch_points")
c("cont_locate_in_background_bogus", "trace", ["{D}", "--locate_in_background", "9"],
  "locate_in_background")
c("cont_direction_without_start", "trace", ["{D}", "--direction", "-1"], "direction")

# ---- --resume -------------------------------------------------------------------------------
c("resume_missing_folder", "trace", ["--resume", "{OUT}"], "resume", out=False)
c("resume_no_folder_given", "trace", ["--resume"], "resume", out=False)
c("resume_empty_folder", "trace", ["--resume", "{OUT}"], "resume", out=False, prep=prep_dir)
c("resume_a_file", "trace", ["--resume", "{OUT}"], "resume", out=False, prep=prep_file())
MORE = ["--max_points", "8"]  # the saved run stopped at its budget of 5 points
for name, what in [("state_garbage", "state.txt of text that is no state"),
                   ("state_empty", "an empty state.txt"),
                   ("state_binary", "state.txt of binary bytes"),
                   ("state_nan", "NaN unknowns in every saved state"),
                   ("orbits_garbage", "orbits.csv of text"),
                   ("unknowns_garbage", "unknowns.csv of text"),
                   ("branch_csv_garbage", "branch.csv with a short row")]:
    c(f"resume_{name}", "trace", ["--resume", "{OUT}"] + MORE, "resume", out=False,
      prep=prep_copy(f"short_{name}"), note=what)
c("resume_state_of_another_run", "trace", ["--resume", "{OUT}"] + MORE, kind="ok", out=False,
  prep=prep_copy("short_state_of_another_run"), check=stdout_has("corrected again"),
  note="documented: another scene's state -> the last point corrected again, and said")
c("resume_summary_missing", "trace", ["--resume", "{OUT}"] + MORE, "resume", out=False,
  prep=prep_copy("short_summary_missing"))
c("resume_scene_missing", "trace", ["--resume", "{OUT}"] + MORE, "resume", out=False,
  prep=prep_copy("short_scene_missing"))
c("resume_scene_corrupt", "trace", ["--resume", "{OUT}"] + MORE, "scene.ini", out=False,
  prep=prep_copy("short_scene_corrupt"))
c("resume_with_a_scene", "trace", ["--resume", "{OUT}", "{S}"] + MORE, S, out=False,
  prep=prep_copy("short"))
c("resume_scene_first", "trace", ["{S}", "--resume", "{OUT}"] + MORE, "resume", out=False,
  prep=prep_copy("short"))
c("resume_and_start", "trace", ["--resume", "{OUT}", "--start", "{FX}/mode1:3"] + MORE, "start",
  out=False, prep=prep_copy("short"))
c("resume_and_out", "trace", ["--resume", "{OUT}", "--out", "{OUT}_other"] + MORE, "out",
  out=False, prep=prep_copy("short"))
c("resume_changed_grid", "trace", ["--resume", "{OUT}", "--shooting_elements", "40"] + MORE,
  "resume", out=False, prep=prep_copy("short"))
c("resume_bad_key", "trace", ["--resume", "{OUT}", "--ds", "-1"] + MORE, "ds", out=False,
  prep=prep_copy("short"))
c("resume_budget_already_spent", "trace", ["--resume", "{OUT}"], "max_points", out=False,
  prep=prep_copy("short"), note="5 of 5 points saved: nothing to continue")
c("resume_state_truncated", "trace", ["--resume", "{OUT}"] + MORE, kind="ok", out=False,
  prep=prep_copy("short_state_truncated"),
  note="documented repair: a state line cut as by SIGKILL is dropped, the run continues")
c("resume_valid_contact_bar", "trace", ["--resume", "{OUT}"] + MORE, kind="ok", out=False,
  prep=prep_copy("short"), note="5 points saved: continue to 8")
for name, what in [("garbage", "text that is no list"),
                   ("bad_bracket", "a negative bracket"),
                   ("wrong_size", "a candidate of 3 unknowns on a problem of 21")]:
    c(f"resume_branch_points_{name}", "trace", ["--resume", "{OUT}"] + MORE, "resume",
      out=False, prep=prep_copy(f"detecting_{name}"), note=f"branch_points.txt: {what}")
c("resume_branch_points_list_missing", "trace", ["--resume", "{OUT}"] + MORE, kind="ok",
  out=False, prep=prep_copy("detecting_list_missing"),
  note="no branch_points.txt: the rows of branch_points.csv are kept as they are")
c("resume_valid_more_points", "trace", ["--resume", "{OUT}", "--max_points", "8"], kind="ok",
  out=False, prep=prep_copy("duff"), note="duffing, 5 points saved: continue to 8")

# ---- --start --------------------------------------------------------------------------------
c("start_missing_folder", "trace", ["{S}", "--start", "/nonexistent:3"] + SMALL, "start")
c("start_no_index", "trace", ["{S}", "--start", "{FX}/mode1"] + SMALL, "start")
c("start_index_negative", "trace", ["{S}", "--start", "{FX}/mode1:-1"] + SMALL, "start")
c("start_index_text", "trace", ["{S}", "--start", "{FX}/mode1:abc"] + SMALL, "start")
c("start_index_fraction", "trace", ["{S}", "--start", "{FX}/mode1:2.5"] + SMALL, "start")
c("start_index_out_of_range", "trace", ["{S}", "--start", "{FX}/mode1/orbits.csv:999"] + SMALL,
  "start")
c("start_index_overflow", "trace", ["{S}", "--start", "{FX}/mode1:99999999999999999999"]
  + SMALL, "start")
c("start_empty_folder", "trace", ["{S}", "--start", "{FX}/empty:0"] + SMALL, "start")
c("start_a_file", "trace", ["{S}", "--start", "{FX}/scenes/crlf.ini:0"] + SMALL, "start")
c("start_state_garbage", "trace", ["{S}", "--start", "{FX}/state_garbage:3"] + SMALL, "start")
c("start_state_missing", "trace", ["{S}", "--start", "{FX}/state_missing:3"] + SMALL, kind="ok",
  check=stdout_has("corrected again"),
  note="documented: without a usable state the saved unknowns are corrected again, and said")
c("start_state_binary", "trace", ["{S}", "--start", "{FX}/state_binary:3"] + SMALL, "start")
c("start_state_truncated", "trace", ["{S}", "--start", "{FX}/state_truncated:3"] + SMALL,
  "start")
c("start_state_nan", "trace", ["{S}", "--start", "{FX}/state_nan:3"] + SMALL, "start")
c("start_state_of_another_run", "trace", ["{S}", "--start", "{FX}/state_foreign:3"] + SMALL,
  kind="ok", check=stdout_has("corrected again"),
  note="documented: another scene's state -> corrected again, and said")
c("start_orbits_garbage", "trace", ["{S}", "--start", "{FX}/bad_orbits:3"] + SMALL, "start",
  note="every file of the start folder is checked before a point is read")
c("start_unknowns_garbage", "trace", ["{S}", "--start", "{FX}/bad_unknowns:3"] + SMALL, "start")
c("start_into_its_own_out", "trace", ["{S}", "--start", "{OUT}:3", "--out", "{OUT}"] + SMALL,
  "out",
  prep=prep_copy("mode1"))
c("start_unknowns_missing", "trace", ["{S}", "--start", "{FX}/unknowns_missing:3"] + SMALL,
  "start")
c("start_from_duffing_run", "trace", ["{S}", "--start", "{FX}/duff:2"] + SMALL, "start")
c("start_other_branch", "trace", ["{S}", "--start", "{FX}/mode1:3", "--branch", "mode2",
                                  "--energy_max", "2e-5"], "start")
c("start_other_grid", "trace", ["{S}", "--start", "{FX}/mode1:3", "--branch", "mode1",
                                "--shooting_elements", "40", "--energy_max", "2e-5"], "start")
c("start_direction_zero", "trace", ["{S}", "--start", "{FX}/mode1:3", "--direction", "0"]
  + SMALL, "direction")
c("start_direction_text", "trace", ["{S}", "--start", "{FX}/mode1:3", "--direction", "back"]
  + SMALL, "direction")
c("start_valid_backwards", "trace", ["{S}", "--start", "{FX}/mode1/orbits.csv:5",
                                     "--direction", "-1", "--max_points", "10"] + SMALL[:4],
  kind="ok", note="documented: point 5 of a saved branch, backwards")

# ---- inspect --------------------------------------------------------------------------------
IS = "{FX}/mode1/scene.ini"
c("inspect_no_orbit", "inspect", [IS], "orbit", out=False)
c("inspect_orbit_missing", "inspect", [IS, "--orbit", "/nonexistent/orbits.csv:1"], "orbit",
  out=False)
c("inspect_orbit_out_of_range", "inspect", [IS, "--orbit", "{FX}/mode1/orbits.csv:999"],
  "orbit", out=False)
c("inspect_orbit_no_index", "inspect", [IS, "--orbit", "{FX}/mode1/orbits.csv"], "orbit",
  out=False)
c("inspect_orbit_of_duffing", "inspect", [IS, "--orbit", "{FX}/duff/orbits.csv:1"], "orbit",
  out=False)
c("inspect_orbit_corrupt", "inspect", [IS, "--orbit", "{FX}/bad_unknowns/orbits.csv:2"],
  "orbit", out=False)
c("inspect_branch_bogus", "inspect", [IS, "--orbit", "{FX}/mode1/orbits.csv:3", "--branch",
                                      "mode7x"], "branch", out=False)
c("inspect_out_given", "inspect", [IS, "--orbit", "{FX}/mode1/orbits.csv:3", "--out",
                                   "{OUT}"], "out", out=False)
c("inspect_bad_key", "inspect", [IS, "--orbit", "{FX}/mode1/orbits.csv:3", "--rank_threshold",
                                 "-1"], "rank_threshold", out=False)
c("inspect_other_grid", "inspect", [IS, "--orbit", "{FX}/mode1/orbits.csv:3",
                                    "--shooting_elements", "40"], "orbit", out=False)
c("inspect_valid", "inspect", [IS, "--orbit", "{FX}/mode1/orbits.csv:3"], kind="ok", out=False)

# ---- bench ----------------------------------------------------------------------------------
c("bench_case_unknown", "bench", ["--case", "nope"], "case")
c("bench_problem_unknown", "bench", ["--problem", "nope"], "problem")
c("bench_case_of_other_problem", "bench", ["--problem", "duffing", "--case", "tdbem_scaling"],
  "case")
c("bench_threads_zero", "bench", ["--case", "siconos_bar", "--threads", "0"], "threads")
c("bench_threads_huge", "bench", ["--case", "siconos_bar", "--threads", "100000"], "threads",
  check=stderr_quotes("100000"))
c("bench_threads_negative", "bench", ["--case", "siconos_bar", "--threads", "-1"], "threads",
  check=stderr_quotes("-1"))
c("bench_threads_text", "bench", ["--case", "siconos_bar", "--threads", "many"], "threads")
c("bench_unknown_option", "bench", ["--case", "siconos_bar", "--fast"], "fast")
c("bench_extra_argument", "bench", ["extra", "--case", "siconos_bar"], "extra")
c("bench_case_twice", "bench", ["--case", "siconos_bar", "--case", "lu_legrand"], "case")
c("bench_out_is_file", "bench", ["--case", "siconos_bar"], "out", prep=prep_file())
c("bench_out_in_proc", "bench", ["--case", "siconos_bar", "--out", "/proc/backbone_hostile"],
  "out", out=False)

# ---- figures --------------------------------------------------------------------------------
c("figures_out_missing", "figures", [], "out")
c("figures_out_empty_folder", "figures", [], "out", prep=prep_dir,
  note="a folder holding no traced branch, like a missing one")
c("figures_out_is_file", "figures", [], "out", prep=prep_file())
c("figures_out_in_proc", "figures", ["--out", "/proc/backbone_hostile"], "out", out=False)
c("figures_extra_argument", "figures", ["extra"], "extra", prep=prep_copy("results_mode1"))
c("figures_unknown_option", "figures", ["--dpi", "300"], "dpi", prep=prep_copy("results_mode1"))

# ---- reproduce ------------------------------------------------------------------------------
c("reproduce_only_unknown", "reproduce", ["--only", "nope"], "only")
c("reproduce_only_empty", "reproduce", ["--only", ""], "only")
c("reproduce_quick_with_value", "reproduce", ["--quick", "yes", "--only", "mode1_orbit"],
  "quick")
c("reproduce_extra_argument", "reproduce", ["extra", "--only", "mode1_orbit"], "extra")
c("reproduce_unknown_option", "reproduce", ["--only", "mode1_orbit", "--fast"], "fast")
c("reproduce_only_twice", "reproduce", ["--only", "mode1_orbit", "--only", "duffing"], "only")
c("reproduce_out_is_file", "reproduce", ["--only", "mode1_orbit"], "out", prep=prep_file())
c("reproduce_out_in_proc", "reproduce", ["--only", "mode1_orbit", "--out",
                                         "/proc/backbone_hostile"], "out", out=False)

# ---- output folders -------------------------------------------------------------------------
c("out_is_file_trace", "trace", ["{S}"] + SMALL, "out", prep=prep_file())
c("out_is_file_simulate", "simulate", ["{S}"], "out", prep=prep_file())
c("out_under_a_file", "trace", ["{S}", "--out", "{FX}/afile/sub"] + SMALL, "out", out=False)
c("out_in_proc", "trace", ["{S}", "--out", "/proc/backbone_hostile"] + SMALL, "out", out=False)
c("out_in_sys", "simulate", ["{S}", "--out", "/sys/backbone_hostile"], "out", out=False)
c("out_dev_null", "simulate", ["{S}", "--out", "/dev/null"], "out", out=False)
c("out_empty_string", "trace", ["{S}", "--out", ""] + SMALL, "out", out=False)
c("out_name_too_long", "trace", ["{S}", "--out", "{OUT}/" + "a" * 256] + SMALL, "out",
  out=False)
c("out_path_too_long", "simulate", ["{S}", "--out", "{OUT}/" + "/".join(["b" * 200] * 21)],
  "out", out=False)
c("out_readonly_folder", "simulate", ["{S}", "--out", "{FX}/readonly/sub"], "out", out=False,
  note="an immutable folder (chattr +i): no folder can be created in it, even by root")
c("out_is_symlink_to_file", "trace", ["{S}", "--out", "{FX}/link_to_file"] + SMALL, "out",
  out=False)
c("out_existing_run_of_other_problem", "trace", ["{S}"] + SMALL, kind="ok",
  prep=prep_copy("duff"), check=summary_names("contact_bar"),
  note="a finished run's folder is traced over (its files replaced)")


# --------------------------------------------------------------------------------------------
# Fixtures
# --------------------------------------------------------------------------------------------
def write(path, data):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def release_readonly():
    if os.path.isdir(f"{FX}/readonly"):
        subprocess.run(["chattr", "-i", f"{FX}/readonly"], capture_output=True)


def make_fixtures():
    release_readonly()
    shutil.rmtree(FX, ignore_errors=True)
    os.makedirs(FX)
    bb = ARGS.backbone

    def trace(args, out):
        r = subprocess.run([bb, "trace"] + args + ["--out", out], capture_output=True,
                           timeout=60)
        if r.returncode != 0:
            sys.exit(f"fixture {out}: exit {r.returncode}: {r.stderr.decode(errors='replace')}")

    trace([S] + SMALL, f"{FX}/mode1")
    trace([S, "--branch", "mode1", "--shooting_elements", "20", "--max_points", "5"],
          f"{FX}/short")
    trace([D, "--max_points", "5"], f"{FX}/duff")
    trace([S, "--branch", "mode1", "--shooting_elements", "20", "--max_points", "5",
           "--detect_branch_points", "true"], f"{FX}/detecting")
    for name, text in [("garbage", "hello\nworld\n"),
                       ("bad_bracket", None), ("wrong_size", None)]:
        d = f"{FX}/detecting_{name}"
        shutil.copytree(f"{FX}/detecting", d)
        saved = open(f"{d}/branch_points.txt").read().splitlines()
        if name == "bad_bracket":
            text = "\n".join(saved[:2] + ["bracket=-3 after_point=1 x=1"]) + "\n"
        if name == "wrong_size":
            text = "\n".join(saved[:2] + [
                "bracket=0 after_point=1 arclength=0 test_value=0 sign_change=0 "
                "location_steps=0 jacobian_evaluations=0 residual_evaluations=0 nullity=1 "
                "attached_dimension=0 candidates=0 probed=0 verified_dimension=1 "
                "tangent_angle=nan x=1,2,3 attached_point= attached_points=0 described=0"]) + "\n"
        write(f"{d}/branch_points.txt", text)
    shutil.copytree(f"{FX}/detecting", f"{FX}/detecting_list_missing")
    os.remove(f"{FX}/detecting_list_missing/branch_points.txt")
    def nan_state(d):
        text = open(f"{d}/state.txt").read()
        write(f"{d}/state.txt", re.sub(r"z=[^ ]+", lambda m: "z=" + ",".join(
            "nan" for _ in m.group(0).split(",")), text))

    def truncate_state(point):
        def cut(d):
            lines = open(f"{d}/state.txt").read().splitlines(True)
            keep = [l for l in lines if not re.match(rf"{point} ", l)]
            cut_line = next(l for l in lines if re.match(rf"{point} ", l))
            before = keep[:1 + point]
            write(f"{d}/state.txt", "".join(before) + cut_line[:len(cut_line) // 2])
        return cut

    defects = {
        "state_garbage": lambda d: write(f"{d}/state.txt", "hello\nworld 1 2 3\n"),
        "state_empty": lambda d: write(f"{d}/state.txt", ""),
        "state_missing": lambda d: os.remove(f"{d}/state.txt"),
        "state_binary": lambda d: write(f"{d}/state.txt", bytes(range(256)) * 64),
        "state_nan": nan_state,
        "state_of_another_run": lambda d: shutil.copy(f"{FX}/duff/state.txt",
                                                      f"{d}/state.txt"),
        "summary_missing": lambda d: os.remove(f"{d}/summary.txt"),
        "scene_missing": lambda d: os.remove(f"{d}/scene.ini"),
        "scene_corrupt": lambda d: write(f"{d}/scene.ini", b"\x00\x01garbage = = =\n"),
        "orbits_garbage": lambda d: write(f"{d}/orbits.csv", "point,x,u0\n0,zero,nan\n1,,\n"),
        "unknowns_garbage": lambda d: write(f"{d}/unknowns.csv", "point,z0\n0,zero\n1,nan,\n"),
        "branch_csv_garbage": lambda d: write(f"{d}/branch.csv", "what,is,this\n1,2\n"),
        "unknowns_missing": lambda d: os.remove(f"{d}/unknowns.csv"),
    }
    for name, fn in defects.items():
        for base, prefix in [("mode1", ""), ("short", "short_")]:
            shutil.copytree(f"{FX}/{base}", f"{FX}/{prefix}{name}")
            fn(f"{FX}/{prefix}{name}")
    for base, prefix, point in [("mode1", "", 3), ("short", "short_", 4)]:
        shutil.copytree(f"{FX}/{base}", f"{FX}/{prefix}state_truncated")
        truncate_state(point)(f"{FX}/{prefix}state_truncated")
    # names used by the --start, simulate and inspect cases
    os.rename(f"{FX}/state_of_another_run", f"{FX}/state_foreign")
    os.rename(f"{FX}/orbits_garbage", f"{FX}/bad_orbits")
    os.rename(f"{FX}/unknowns_garbage", f"{FX}/bad_unknowns")
    os.makedirs(f"{FX}/empty")
    write(f"{FX}/afile", "a file\n")
    os.symlink(f"{FX}/afile", f"{FX}/link_to_file")
    os.makedirs(f"{FX}/results_mode1")
    shutil.copytree(f"{FX}/mode1", f"{FX}/results_mode1/mode1")
    os.makedirs(f"{FX}/readonly")
    if subprocess.run(["chattr", "+i", f"{FX}/readonly"], capture_output=True).returncode != 0:
        print("note: chattr +i failed; out_readonly_folder tests a writable folder")

    sc = f"{FX}/scenes"
    os.makedirs(sc)
    paper = open(S, "rb").read()
    os.mkfifo(f"{sc}/fifo.ini")
    os.symlink(f"{sc}/loop.ini", f"{sc}/loop.ini")
    os.symlink(f"{sc}/nowhere.ini", f"{sc}/dangling.ini")
    write(f"{sc}/empty.ini", b"")
    write(f"{sc}/comments.ini", b"# nothing but\n# comments\n\n")
    write(f"{sc}/semicolon.ini", paper + b"; a comment\n")
    write(f"{sc}/no_problem.ini", paper.replace(b"problem = contact_bar\n", b""))
    write(f"{sc}/problem_unknown.ini", paper.replace(b"contact_bar\n", b"string_of_beads\n", 1))
    write(f"{sc}/problem_empty.ini", paper.replace(b"problem = contact_bar", b"problem ="))
    write(f"{sc}/problem_unicode.ini", paper.replace(b"contact_bar\n",
                                                     "contäct_bar\n".encode(), 1))
    write(f"{sc}/duffing_bar_keys.ini", open(D, "rb").read() + b"gap = 0.001\n")
    write(f"{sc}/problem_twice.ini", paper + b"problem = duffing\n")
    write(f"{sc}/gap_twice.ini", paper + b"gap = 0.002\n")
    write(f"{sc}/gap_twice_same.ini", paper + b"gap = 0.001\n")
    write(f"{sc}/unknown_key.ini", paper + b"frobnicate = 1\n")
    write(f"{sc}/unicode_key.ini", paper + "gäp = 0.001\n".encode())
    write(f"{sc}/upper_key.ini", paper + b"GAP = 0.001\n")
    write(f"{sc}/no_equals.ini", paper.replace(b"gap = 0.001", b"gap 0.001"))
    write(f"{sc}/no_key.ini", paper + b"= 0.001\n")
    write(f"{sc}/section.ini", b"[bar]\n" + paper)
    write(f"{sc}/nul.ini", paper.replace(b"gap = 0.001", b"gap = 0.001\x00"))
    write(f"{sc}/utf16.ini", b"\xff\xfe" + paper.decode().encode("utf-16-le"))
    write(f"{sc}/binary.ini", bytes((i * 7919 + 13) % 256 for i in range(4096)))
    write(f"{sc}/huge.ini", paper + b"#" * (2 << 20) + b"\n")
    n = 25000
    write(f"{sc}/huge_line.ini", b"problem = contact_bar\ngap = 0.001\nu0 = " + " ".join(
        f"{i / n!r}:{-0.01 * i / n!r}" for i in range(n + 1)).encode() + b"\n")
    write(f"{sc}/gap_nan.ini", paper.replace(b"gap = 0.001", b"gap = nan"))
    write(f"{sc}/length_inf.ini", paper.replace(b"length = 1", b"length = inf"))
    write(f"{sc}/density_negative.ini", paper.replace(b"density = 1", b"density = -1"))
    write(f"{sc}/gap_garbage.ini", paper.replace(b"gap = 0.001", b"gap = 0.001mm"))
    write(f"{sc}/gap_empty.ini", paper.replace(b"gap = 0.001", b"gap ="))
    write(f"{sc}/elements_hex.ini", paper.replace(b"elements = 100", b"elements = 0x64"))
    write(f"{sc}/shooting_float.ini", paper + b"shooting_elements = 20.5\n")
    write(f"{sc}/gap_unicode.ini", paper.replace(b"gap = 0.001", "gap = ٠.٠٠١".encode()))
    write(f"{sc}/verify_garbage.ini", paper + b"verify = perhaps\n")
    write(f"{sc}/crlf.ini", paper.replace(b"\n", b"\r\n"))
    write(f"{sc}/bom.ini", b"\xef\xbb\xbf" + paper)
    write(f"{sc}/inline_comment.ini", paper.replace(b"gap = 0.001", b"gap = 0.001 # g0"))


# --------------------------------------------------------------------------------------------
# Running and judging
# --------------------------------------------------------------------------------------------
def tree_digest(path):
    """Digest of a file or folder (names, sizes, contents); None if it does not exist."""
    if not os.path.lexists(path):
        return None
    h = hashlib.sha256()
    if os.path.isdir(path) and not os.path.islink(path):
        for root, dirs, files in os.walk(path):
            dirs.sort()
            for name in sorted(files + dirs):
                p = os.path.join(root, name)
                h.update(os.path.relpath(p, path).encode())
                if os.path.isfile(p) and not os.path.islink(p):
                    with open(p, "rb") as f:
                        h.update(f.read())
    else:
        try:
            with open(path, "rb") as f:
                h.update(f.read())
        except OSError:
            h.update(b"?")
    return h.hexdigest()


def cwd_snapshot():
    """Untracked and modified files of the working directory (a run must not write there)."""
    r = subprocess.run(["git", "status", "--porcelain", "--ignored", "-uall"],
                       capture_output=True, text=True)
    return set(r.stdout.splitlines())


def substitute(arg, out):
    return (arg.replace("{S}", S).replace("{D}", D).replace("{I}", I).replace("{C}", C).replace("{FX}", FX)
            .replace("{OUT}", out))


def limits():
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_CAP_KB * 1024, MEMORY_CAP_KB * 1024))
    os.setsid()


def run(argv, timeout):
    start = time.monotonic()
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            stdin=subprocess.DEVNULL, preexec_fn=limits)
    out_chunks, err_chunks = [], []

    def pump(stream, chunks):
        for block in iter(lambda: stream.read(65536), b""):
            if sum(len(x) for x in chunks) < (1 << 20):
                chunks.append(block)
    threads = [threading.Thread(target=pump, args=(proc.stdout, out_chunks)),
               threading.Thread(target=pump, args=(proc.stderr, err_chunks))]
    for t in threads:
        t.start()
    timed_out = False
    while True:
        pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
        if pid:
            break
        if time.monotonic() - start > timeout:
            timed_out = True
            os.killpg(proc.pid, signal.SIGKILL)
            pid, status, usage = os.wait4(proc.pid, 0)
            break
        time.sleep(0.005)
    proc.returncode = 0  # reaped by wait4; keep Popen from waiting again
    for t in threads:
        t.join()
    seconds = time.monotonic() - start
    code = os.waitstatus_to_exitcode(status)
    return dict(code=code, timed_out=timed_out, limit=timeout, seconds=seconds, rss_kb=usage.ru_maxrss,
                stdout=b"".join(out_chunks).decode(errors="replace"),
                stderr=b"".join(err_chunks).decode(errors="replace"))


def names_key(line, key):
    if key is None:
        return True
    return re.search(r"(?<![A-Za-z0-9_])" + re.escape(key) + r"(?![A-Za-z0-9_])", line) is not None


def judge(case, r, out, prepared, before_out, before_fx, before_cwd):
    problems = []
    kind = case["kind"]
    err_lines = [l for l in r["stderr"].splitlines() if l.strip()]
    if r["timed_out"]:
        problems.append(f"still running after {r['limit']:.0f} s (killed)")
    after_cwd = cwd_snapshot()
    if after_cwd != before_cwd:
        problems.append("wrote into the working directory: "
                        + ", ".join(sorted(x[3:] for x in after_cwd - before_cwd))[:200])
    if tree_digest(FX) != before_fx:
        problems.append("changed the fixtures (a folder it was only to read)")
    if kind == "bad":
        if r["code"] != 2:
            problems.append(f"exit {r['code']}, not 2")
        if len(err_lines) != 1:
            problems.append(f"{len(err_lines)} stderr lines, not 1")
        if err_lines and not any(names_key(l, case["key"]) for l in err_lines[:1]):
            problems.append(f"message does not name '{case['key']}'")
        elif err_lines and re.search(r"for option '[^']*' is invalid$", err_lines[0]):
            problems.append("message names the key but no constraint ('is invalid')")
        if prepared:
            if tree_digest(out) != before_out:
                problems.append("changed the prepared folder/file")
        elif os.path.lexists(out):
            problems.append("created " + describe(out))
        if r["seconds"] > SLOW_SECONDS and not r["timed_out"]:
            problems.append(f"took {r['seconds']:.1f} s before answering")
    elif kind == "help":
        if r["code"] != 0:
            problems.append(f"exit {r['code']}, not 0")
        if not r["stdout"].strip():
            problems.append("no usage on stdout")
        if not prepared and os.path.lexists(out):
            problems.append("created " + describe(out))
    elif kind == "ok":
        if r["code"] != 0:
            problems.append(f"exit {r['code']}, not 0: {err_lines[-1] if err_lines else ''}")
    elif kind == "fail":
        if r["code"] != 1:
            problems.append(f"exit {r['code']}, not 1")
        if err_lines and not any(names_key(l, case["key"]) for l in err_lines):
            problems.append(f"no message names '{case['key']}'")
    if "check" in case:
        e = case["check"](r)
        if e:
            problems.append(e)
    return problems


def describe(path):
    if os.path.isdir(path):
        files = []
        for root, _, names in os.walk(path):
            files += [os.path.relpath(os.path.join(root, n), path) for n in names]
        return f"{path} ({len(files)} files: {', '.join(sorted(files)[:8])})"
    return path


def main():
    global ARGS, SCRATCH, FX
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--backbone", default="build/bin/backbone")
    p.add_argument("--scratch", default="/tmp/hostile")
    p.add_argument("--timeout", type=float, default=60.0,
                   help="seconds before a case is killed (at most 60)")
    p.add_argument("--only", default="", help="comma-separated case ids")
    p.add_argument("--verbose", action="store_true", help="print stderr of failing cases")
    p.add_argument("--list", action="store_true", help="list the cases and exit")
    ARGS = p.parse_args()
    ARGS.timeout = min(ARGS.timeout, 60.0)
    ARGS.backbone = os.path.abspath(ARGS.backbone)
    SCRATCH = os.path.abspath(ARGS.scratch)
    FX = os.path.join(SCRATCH, "_fixtures")
    ids = [case["id"] for case in CASES]
    dupes = {i for i in ids if ids.count(i) > 1}
    if dupes:
        sys.exit(f"duplicate case ids: {sorted(dupes)}")
    if ARGS.list:
        for case in CASES:
            print(case["id"], case["sub"], case["kind"], case["key"])
        return 0
    if not os.path.isfile(ARGS.backbone):
        sys.exit(f"no backbone binary at {ARGS.backbone}")
    if not os.path.isfile(S):
        sys.exit("run from the repository root (problems/contact_bar/scenes/paper.ini)")
    release_readonly()
    shutil.rmtree(SCRATCH, ignore_errors=True)
    os.makedirs(SCRATCH)
    make_fixtures()
    wanted = set(filter(None, ARGS.only.split(",")))
    passed = failed = 0
    t0 = time.monotonic()
    for case in CASES:
        if wanted and case["id"] not in wanted:
            continue
        out = os.path.join(SCRATCH, case["id"])
        shutil.rmtree(out, ignore_errors=True)
        prepared = False
        if "prep" in case:
            case["prep"](out)
            prepared = True
        argv = [ARGS.backbone] + ([case["sub"]] if case["sub"] is not None else [])
        argv += [substitute(a, out) for a in case["args"]]
        if case.get("out", True) and not any("{OUT}" in a for a in case["args"]):
            argv += ["--out", out]
        before_out = tree_digest(out)
        before_fx = tree_digest(FX)
        before_cwd = cwd_snapshot()
        r = run(argv, min(ARGS.timeout, case.get("timeout", ARGS.timeout)))
        problems = judge(case, r, out, prepared, before_out, before_fx, before_cwd)
        shown = " ".join(a if len(a) < 60 else a[:40] + f"...({len(a)} chars)" for a in argv[1:])
        first = (r["stderr"].strip().splitlines() or [""])[0][:220]
        stats = f"exit {r['code']}, {r['seconds']:.2f} s, {r['rss_kb'] // 1024} MB"
        if problems:
            failed += 1
            print(f"MISBEHAVES {case['id']}: backbone {shown} -> {stats}; "
                  f"{'; '.join(problems)} | stderr: {first}")
            if ARGS.verbose:
                print("    " + r["stderr"].strip().replace("\n", "\n    ")[:2000])
        else:
            passed += 1
            print(f"behaves    {case['id']}: {stats} | {first}")
        sys.stdout.flush()
    release_readonly()
    print(f"({len(CASES) if not wanted else len(wanted)} cases in {time.monotonic() - t0:.0f} s)")
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

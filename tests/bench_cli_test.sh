#!/usr/bin/env bash
# `vines bench SCENE --json`: one JSON object for the scene's own settings,
# measured against data/reference: the El Centro Kuwabara scene must be within
# 1e-6 of the reference peak with the reference's 18 contacts; the dop853
# baseline alone, and the reference driver in double (dop853-driver); a bad
# option, an unknown baseline and a missing scene are refused with a message;
# an ensemble; CVODE baselines (below).
set -euo pipefail
vines="$1"
src="$2"
out=$("$vines" bench "$src/data/scenes/elcentro_vines.toml" --json --min-time 0.05)
printf '%s\n' "$out" | /usr/bin/python3 -c '
import json, sys
j = json.load(sys.stdin)
for k in ("wall_s_median", "runs", "peak_rel_error", "contacts", "steps", "substeps"):
    assert k in j, "missing key " + k
assert j["runs"] >= 3, j["runs"]
assert 0 < j["wall_s_median"] < 1.0, j["wall_s_median"]
assert j["peak_rel_error"] is not None and j["peak_rel_error"] < 1e-6, j["peak_rel_error"]
assert j["contacts"] == 18, j["contacts"]
print("bench_cli: peak error %.2e, %d contacts, %.3f ms" % (j["peak_rel_error"], j["contacts"], 1e3 * j["wall_s_median"]))
'
# --baseline-methods dop853: the firmware line, then one DOP853 (double) line
# on the record's own 50 Hz points, near the reference at 1e-10.
out=$("$vines" bench "$src/data/scenes/elcentro_vines.toml" --json --min-time 0.01 --baselines 1e-10 \
  --baseline-methods dop853)
printf '%s\n' "$out" | /usr/bin/python3 -c '
import json, sys
ls = json.load(sys.stdin)["lines"]
assert [l["method"] for l in ls] == ["firmware", "dop853"], [l["method"] for l in ls]
d = ls[1]
assert d["scalar"] == "double" and d["sensor_rate_hz"] == 50 and d["contact_rtol"] == 1e-10, d
assert d["peak_rel_error"] is not None and d["peak_rel_error"] < 1e-7, d["peak_rel_error"]
assert d["contacts"] == 18, d["contacts"]
print("bench_cli: dop853 1e-10 peak error %.2e, %.2f ms" % (d["peak_rel_error"], 1e3 * d["wall_s_median"]))
'
# --baseline-methods dop853-driver: the reference's driver in double, as near at 1e-10.
out=$("$vines" bench "$src/data/scenes/elcentro_vines.toml" --json --min-time 0.01 --baselines 1e-10 \
  --baseline-methods dop853-driver)
printf '%s\n' "$out" | /usr/bin/python3 -c '
import json, sys
ls = json.load(sys.stdin)["lines"]
assert [l["method"] for l in ls] == ["firmware", "dop853-driver"], [l["method"] for l in ls]
d = ls[1]
assert d["peak_rel_error"] is not None and d["peak_rel_error"] < 1e-7, d["peak_rel_error"]
assert d["contacts"] == 18, d["contacts"]
print("bench_cli: dop853-driver 1e-10 peak error %.2e, %.2f ms" % (d["peak_rel_error"], 1e3 * d["wall_s_median"]))
'
if "$vines" bench "$src/data/scenes/elcentro_vines.toml" --baseline-methods rk4 2>/tmp/bench_cli_err.txt; then
  echo "bench_cli: --baseline-methods rk4 was accepted" >&2; exit 1
fi
grep -q -- "--baseline-methods" /tmp/bench_cli_err.txt
if "$vines" bench "$src/data/scenes/elcentro_vines.toml" --rates fifty 2>/tmp/bench_cli_err.txt; then
  echo "bench_cli: --rates fifty was accepted" >&2; exit 1
fi
grep -q -- "--rates" /tmp/bench_cli_err.txt
# --ensemble 6: every line over 3 records and 3 initial conditions, each
# against its own long-double reference. The loop's error falls with its
# tolerance (1e-4 -> 1e-10) by orders of magnitude, and at 1e-10 it is near
# the reference on every member, with the same contacts on most.
out=$("$vines" bench "$src/data/scenes/elcentro_vines.toml" --rates 50 --rtols 1e-4,1e-10 --ensemble 6 \
  --no-baselines --min-time 0.01 --json 2>/dev/null)
printf '%s\n' "$out" | /usr/bin/python3 -c '
import json, sys
e = json.load(sys.stdin)["ensemble"]
assert [l["contact_rtol"] for l in e] == [1e-4, 1e-10], e
loose, tight = e
assert all(l["members"] == 6 and l["run_s_mean"] > 0 for l in e), e
assert tight["peak_rel_error"]["p90"] < 1e-8, tight
assert tight["x_r_abs_error"]["p90"] < 1e-8 and tight["E_r_abs_error"]["p90"] < 1e-6, tight
assert tight["contacts_same_share"] >= 0.8, tight
assert loose["peak_rel_error"]["mean"] > 1e3 * tight["peak_rel_error"]["mean"], (loose, tight)
print("bench_cli: ensemble of 6, p90 peak error %.1e at 1e-10, %.1e at 1e-4" %
      (tight["peak_rel_error"]["p90"], loose["peak_rel_error"]["p90"]))
'
if "$vines" bench "$src/data/scenes/elcentro_tmd.toml" --ensemble 4 2>/tmp/bench_cli_err.txt >/dev/null; then
  echo "bench_cli: --ensemble on a TMD scene was accepted" >&2; exit 1
fi
grep -q "elcentro_tmd.toml has no VI NES" /tmp/bench_cli_err.txt
if "$vines" bench /nonexistent.toml --json 2>/tmp/bench_cli_err.txt; then
  echo "bench_cli: a missing scene was accepted" >&2; exit 1
fi
grep -q "nonexistent.toml" /tmp/bench_cli_err.txt
# CVODE baselines: lines of both methods in a build with SUNDIALS; in one
# without (VINES_TEST_CVODE=0), refused (exit 1) saying how to get them.
scene="$src/data/scenes/elcentro_vines.toml"
if [[ ${VINES_TEST_CVODE:?} == 1 ]]; then
  "$vines" bench "$scene" --json --min-time 0.05 --baselines 1e-6 --baseline-methods cvode-adams,cvode-bdf |
    /usr/bin/python3 -c '
import json, sys
methods = sorted(l["method"] for l in json.load(sys.stdin)["lines"])
assert methods == ["cvode-adams", "cvode-bdf", "firmware"], methods'
else
  for args in "--baselines 1e-6" "--baselines 1e-6 --baseline-methods cvode-bdf" ""; do
    status=0
    "$vines" bench "$scene" --min-time 0.05 $args >/dev/null 2>/tmp/bench_cli_err.txt || status=$?
    if [[ $status != 1 ]]; then
      echo "bench_cli: CVODE baselines ($args) in a build without CVODE: exit $status, not 1" >&2; exit 1
    fi
    grep -q "no CVODE.*libsundials-dev" /tmp/bench_cli_err.txt
  done
  "$vines" bench "$scene" --min-time 0.05 --no-baselines >/dev/null
  "$vines" bench "$scene" --min-time 0.05 --baselines 1e-8 --baseline-methods dop853 >/dev/null
fi
echo "bench_cli: ok"

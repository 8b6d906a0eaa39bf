#!/usr/bin/env python3
"""Runs a `vines hil ... --json` command (after `--`) against a board image in
QEMU and checks its report; exit 0 if every check holds, 1 with the reasons.

  hil_check.py [--max-deviation M] [--all-faults] [--expect-overruns]
               [--no-overruns] [--expect-refusal TEXT] [--hybrid-as-host M]
               -- VINES hil ARGS...

--max-deviation M   every step arrived, outputs finite, and no floor more than
                    M metres from the host's offline run of the same scalar
--all-faults        every fault kind the command asks for was injected, and
                    every kind injected was detected and survived
--expect-overruns   the node's deadline monitor counted exactly the steps whose
                    ticks exceed the budget, and at least one
--no-overruns       no step's ticks exceed the budget (the node's count and the
                    telemetry's both zero)
--expect-refusal T  the command fails (exit 1) with T in its message
--hybrid-as-host M  hybrid mode: the same command on the host node (without
                    --node and --image) gives the same table tracking and
                    top-floor response, within M metres
Always: the report names the board node and its worst step's instructions.
Standard library only."""
import json
import subprocess
import sys


FAULT_KINDS = {"drop", "corrupt", "duplicate", "reorder", "late", "nonfinite", "stall", "restart", "saturate"}


def main(argv):
    if "--" not in argv:
        sys.exit(__doc__)
    cut = argv.index("--")
    opts, cmd = argv[1:cut], argv[cut + 1:]
    max_dev = refusal = as_host = None
    all_faults = overruns = no_overruns = False
    i = 0
    while i < len(opts):
        if opts[i] == "--max-deviation":
            max_dev = float(opts[i + 1]); i += 2
        elif opts[i] == "--expect-refusal":
            refusal = opts[i + 1]; i += 2
        elif opts[i] == "--hybrid-as-host":
            as_host = float(opts[i + 1]); i += 2
        elif opts[i] == "--all-faults":
            all_faults = True; i += 1
        elif opts[i] == "--expect-overruns":
            overruns = True; i += 1
        elif opts[i] == "--no-overruns":
            no_overruns = True; i += 1
        else:
            sys.exit(f"hil_check.py: unknown option {opts[i]}")
    print("running:", " ".join(cmd), flush=True)
    p = subprocess.run(cmd, capture_output=True, text=True)
    sys.stderr.write(p.stderr)
    if refusal is not None:
        if p.returncode == 1 and refusal in p.stderr:
            print(f"refused as expected: {p.stderr.strip()}")
            return 0
        print(f"FAIL: expected a refusal mentioning '{refusal}', got exit {p.returncode}")
        return 1
    if p.returncode != 0:
        print(f"FAIL: exit status {p.returncode}")
        return 1
    j = json.loads(p.stdout)
    problems = []
    nd = j["node_deadline"]
    print(f"node {j['node']}: {j['steps']} of {j['samples']} steps, worst step "
          f"{j.get('worst_step_instructions')} instructions at k {j.get('worst_step_k')}, median "
          f"{j.get('median_step_instructions')}; stack {nd['stack_peak_bytes']} B; overruns "
          f"{nd['overruns']} of budget {nd['budget_ticks']} ticks; deviation from offline "
          f"{j['max_deviation_from_offline']:.3g} m; faults injected {j['faults_injected']}, detected "
          f"{j['faults_detected']}, survived {j['faults_survived']}")
    if not j["node"].startswith("qemu:") or "worst_step_instructions" not in j:
        problems.append("the report does not name a board node with its worst step")
    if not j["outputs_finite"]:
        problems.append("outputs not finite")
    if max_dev is not None:
        if j["steps"] != j["samples"]:
            problems.append(f"{j['samples'] - j['steps']} steps missing")
        if not j["max_deviation_from_offline"] <= max_dev:
            problems.append(f"deviation {j['max_deviation_from_offline']:.3g} m > {max_dev:g} m")
    if all_faults:
        for kind, c in j["faults"].items():
            if not (c["injected"] > 0 and c["detected"] == c["injected"] and c["survived"] == c["injected"]):
                problems.append(f"fault {kind}: {c}")
        # Every kind the command asks for (--drop, ..., --saturate) was injected.
        asked = {a[2:] for a in cmd if a[2:] in FAULT_KINDS}
        if not asked or not asked <= set(j["faults"]):
            problems.append(f"asked for {sorted(asked)}, injected {sorted(j['faults'])}")
    if overruns:
        over = j["steps_over_budget"]
        if not (nd["overruns"] > 0 and nd["overruns"] == over):
            problems.append(f"node counted {nd['overruns']} overruns, telemetry shows {over} steps over budget")
    if no_overruns:
        if nd["overruns"] != 0 or j["steps_over_budget"] != 0:
            problems.append(f"{nd['overruns']} steps overran the budget of {nd['budget_ticks']} ticks "
                            f"(telemetry: {j['steps_over_budget']}), worst {nd['worst_ticks']} at k {nd['worst_k']}")
    if as_host is not None:
        problems += compare_hybrid(cmd, j, as_host)
    for m in problems:
        print("FAIL:", m)
    return 1 if problems else 0


def compare_hybrid(cmd, board, tol):
    """The board's hybrid report against the host node's on the same command."""
    host_cmd, skip = [], False
    for a in cmd:
        if skip:
            skip = False
        elif a in ("--node", "--image"):
            skip = True
        elif not a.startswith("--node=") and not a.startswith("--image="):
            host_cmd.append(a)
    p = subprocess.run(host_cmd, capture_output=True, text=True)
    if p.returncode != 0:
        return [f"host run failed (exit {p.returncode}): {p.stderr.strip()}"]
    host = json.loads(p.stdout)
    if "hybrid" not in board or "hybrid" not in host:
        return ["no hybrid report"]
    problems = []
    for key in ("tracking_rms_m", "tracking_peak_m", "peak_top_hybrid_m", "top_diff_from_pure_rms_m"):
        b, h = board["hybrid"][key], host["hybrid"][key]
        print(f"hybrid {key}: board {b:.6g}, host {h:.6g}")
        if not abs(b - h) <= tol:
            problems.append(f"hybrid {key}: board {b:.6g} m, host {h:.6g} m (more than {tol:g} m apart)")
    return problems


if __name__ == "__main__":
    sys.exit(main(sys.argv))

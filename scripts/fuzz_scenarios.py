#!/usr/bin/env python3
"""Bad-input fuzzing of the example scenarios through the CLI (how sessions 47-49 found their input bugs).

Every numeric key (and every element of a numeric array) that `fracflow check FILE --skip-set-up` resolves
for the files in examples/ is set, one at a time, to values far off (1e300, 1e-300, 0, -1e-9, 2^31, -1, 1e9,
1e-12; arrays also emptied, cut to one element or lengthened) and checked with `fracflow check`; then cases
that `check` accepted (and whose key the set-up used) are run for a few seconds of wall time. Each result is
one JSON line, so an interrupted pass resumes where it stopped. What to look for afterwards: check or run
codes other than 0, 2 and 3 (crashes), NaN in series.csv or summary.json, refusals whose message names no
key the user can change, and accepted values that no real material or test has (then read what the run did).

  scripts/fuzz_scenarios.py check --binary build/apps/cli/fracflow --log /tmp/fuzz/check.jsonl
  scripts/fuzz_scenarios.py runs  --binary build/apps/cli/fracflow --log /tmp/fuzz/runs.jsonl \\
                                  --checks /tmp/fuzz/check.jsonl --scratch /tmp/fuzz/run

Copy the binary first (cp build/apps/cli/fracflow /tmp/fuzz/) when you go on building: a rebuild replaces
the file under a running pass. Runs use one thread each; do not start two `runs` passes on one scratch
folder (fracflow refuses the second's folders, and those cases then say nothing). The scratch folder gets
one run folder, `case`, replaced by each run (`--overwrite`); nothing else in it is touched.
"""
import argparse
import json
import os
import random
import re
import subprocess
import sys
import time

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCALARS = ["1e300", "1e-300", "0", "-1e-9", "2147483648", "-1", "1e9", "1e-12"]
ELEMENTS = ["1e300", "-1e300", "0", "-1", "1e-12"]
NUMBER = re.compile(r"-?[0-9.eE+-]+")


def examples():
    folder = os.path.join(REPO, "examples")
    return sorted(os.path.join(folder, f) for f in os.listdir(folder) if f.endswith(".toml"))


def resolved_keys(binary, scenario):
    """(key, value text) of every parameter `check --skip-set-up` prints for the scenario."""
    out = subprocess.run([binary, "check", scenario, "--skip-set-up"], capture_output=True, text=True).stdout
    lines = out.splitlines()
    head = next((i for i, l in enumerate(lines) if l.startswith("key ")), None)
    if head is None:
        return []
    value_col, unit_col = lines[head].index("value"), lines[head].index("unit")
    keys = []
    for line in lines[head + 1:]:
        if not line.strip():
            break
        keys.append((line[:value_col].strip(), line[value_col:unit_col].strip()))
    return keys


def cases(binary):
    todo = []
    for scenario in examples():
        for key, value in resolved_keys(binary, scenario):
            if NUMBER.fullmatch(value):
                todo += [(scenario, key, v) for v in SCALARS]
            elif value.startswith("[") and value.endswith("]"):
                items = [x.strip() for x in value[1:-1].split(",")] if value[1:-1].strip() else []
                if not all(NUMBER.fullmatch(x) for x in items):
                    continue
                if not items:
                    todo += [(scenario, key, "[" + b + "]") for b in ELEMENTS + ["1"]]
                    continue
                for i in range(len(items)):
                    for b in ELEMENTS:
                        changed = list(items)
                        changed[i] = b
                        todo.append((scenario, key, "[" + ", ".join(changed) + "]"))
                todo += [(scenario, key, "[]"), (scenario, key, "[" + items[0] + "]"),
                         (scenario, key, "[" + ", ".join(items + [items[-1]]) + "]")]
    return todo


def done_cases(log):
    done = set()
    if os.path.exists(log):
        with open(log) as f:
            for line in f:
                r = json.loads(line)
                done.add((r["file"], r["key"], r["value"]))
    return done


def notable(lines):
    return [l for l in lines if re.search(r"error|warn|refus", l, re.I)][:8]


def run_checks(a):
    todo = cases(a.binary)
    random.Random(a.seed).shuffle(todo)
    done = done_cases(a.log)
    with open(a.log, "a") as log:
        for scenario, key, value in todo:
            if (scenario, key, value) in done:
                continue
            t0 = time.time()
            try:
                p = subprocess.run([a.binary, "check", scenario, "--set", f"{key}={value}"], capture_output=True,
                                   text=True, timeout=a.timeout)
                code, lines = p.returncode, (p.stdout + p.stderr).splitlines()
            except subprocess.TimeoutExpired:
                code, lines = "timeout", []
            log.write(json.dumps({"file": scenario, "key": key, "value": value, "code": code,
                                  "seconds": round(time.time() - t0, 2), "messages": notable(lines),
                                  "head": lines[:3] if code not in (0, 1, 2) else []}) + "\n")
            log.flush()


def has_nan(path):
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return re.search(r"(?<![A-Za-z])nan(?![A-Za-z])", f.read(), re.I) is not None


def run_runs(a):
    os.makedirs(a.scratch, exist_ok=True)
    folder = os.path.join(a.scratch, "case")
    rng = random.Random(a.seed)
    done = done_cases(a.log)
    while True:
        with open(a.checks) as f:
            accepted = [r for r in map(json.loads, f)
                        if r["code"] == 0 and (r["file"], r["key"], r["value"]) not in done
                        and not r["key"].startswith("output.") and not any("not use" in m for m in r["messages"])]
        if not accepted:
            if a.once:
                return
            time.sleep(30)
            continue
        r = rng.choice(accepted)
        t0 = time.time()
        cmd = [a.binary, "run", r["file"], "--set", f"{r['key']}={r['value']}", "--out", folder, "-j1",
               "--max-wall", str(a.max_wall)]
        if os.path.exists(folder):
            cmd.append("--overwrite")  # fracflow replaces only a run folder it made
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=10 * a.max_wall + 60)
            code, lines = p.returncode, (p.stdout + p.stderr).splitlines()
        except subprocess.TimeoutExpired:
            code, lines = "timeout", []
        with open(a.log, "a") as log:
            log.write(json.dumps({"file": r["file"], "key": r["key"], "value": r["value"], "code": code,
                                  "seconds": round(time.time() - t0, 1), "messages": notable(lines)[-6:],
                                  "series_nan": has_nan(os.path.join(folder, "series.csv")),
                                  "summary_nan": has_nan(os.path.join(folder, "summary.json")),
                                  "summary": os.path.exists(os.path.join(folder, "summary.json")),
                                  "tail": lines[-3:]}) + "\n")
        done.add((r["file"], r["key"], r["value"]))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mode", choices=["check", "runs"])
    ap.add_argument("--binary", required=True, help="a copy of fracflow (see above)")
    ap.add_argument("--log", required=True, help="JSON-lines file to append to (resumes from it)")
    ap.add_argument("--checks", help="runs: the check pass's log, whose accepted cases are run")
    ap.add_argument("--scratch", help="runs: folder for the run folder 'case'")
    ap.add_argument("--max-wall", type=int, default=12, help="runs: seconds of wall time per run")
    ap.add_argument("--timeout", type=int, default=180, help="check: seconds before a check counts as hung")
    ap.add_argument("--seed", type=int, default=49, help="order of the cases")
    ap.add_argument("--once", action="store_true", help="runs: stop when no accepted case is left")
    a = ap.parse_args()
    if a.mode == "runs" and not (a.checks and a.scratch):
        sys.exit("runs needs --checks and --scratch")
    run_checks(a) if a.mode == "check" else run_runs(a)


if __name__ == "__main__":
    main()

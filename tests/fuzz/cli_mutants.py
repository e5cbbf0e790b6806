#!/usr/bin/env python3
# SPDX-License-Identifier: AGPL-3.0-or-later
"""The reader mutants (mutate.py) through the real command line, under ASan + UBSan.

    cli_mutants.py CLI READER MUTANTS_DIR WORK_DIR [--count N] [--jobs J] [--timeout S]

READER gltf runs `CLI bake MUTANT -o DIR --levels 2 --quiet` on each of MUTANTS_DIR/gltf;
READER geo runs `CLI aggregate2d MUTANT -o OUT.geojson --levels 2 --quiet` on each of
MUTANTS_DIR/geo. CLI is the sanitizer build (aggrelod_asan), run with
ASAN_OPTIONS=max_allocation_size_mb=2048:allocator_may_return_null=0:detect_leaks=0 (a request
over 2 GB is a report, not a null pointer) and UBSAN_OPTIONS=halt_on_error=1. A finding is a
run that ends by a signal, prints "ERROR: AddressSanitizer" or "runtime error:", exits with
a status outside 0-3 (docs/command-line.md: 1 usage, 2 bad input or file, 3 baking failed;
4 is an internal error), or outlives its timeout (a hang). Each finding is kept with its
stderr in WORK_DIR/findings/READER; the exit status is 1 if there is any.

The first COUNT mutants in name order run (default 400; the environment variable
AGGRELOD_CLI_MUTANTS overrides --count; 0 or "all": every one): mutate.py cycles through the
seeds and draws the kind of mutation at random, so the first COUNT cover each seed equally.
J runs go in parallel (default 2).
"""
import argparse
import collections
import os
import shutil
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

ASAN_OPTIONS = "max_allocation_size_mb=2048:allocator_may_return_null=0:detect_leaks=0"
UBSAN_OPTIONS = "halt_on_error=1:print_stacktrace=1"
ALLOWED_EXIT = {0, 1, 2, 3}
REPORTS = ("ERROR: AddressSanitizer", "runtime error:")


def run_one(cli, reader, mutant, work, timeout):
    name = os.path.basename(mutant)
    out = os.path.join(work, "out", name)
    if reader == "gltf":
        argv = [cli, "bake", mutant, "-o", out, "--levels", "2", "--quiet"]
    else:
        argv = [cli, "aggregate2d", mutant, "-o", out + ".geojson", "--levels", "2", "--quiet"]
    env = dict(os.environ, ASAN_OPTIONS=ASAN_OPTIONS, UBSAN_OPTIONS=UBSAN_OPTIONS)
    start = time.monotonic()
    try:
        p = subprocess.run(argv, cwd=work, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE, timeout=timeout)
        code, err = p.returncode, p.stderr.decode("utf-8", "replace")
    except subprocess.TimeoutExpired as e:
        code, err = None, (e.stderr or b"").decode("utf-8", "replace")
    seconds = time.monotonic() - start
    shutil.rmtree(out, ignore_errors=True)
    if os.path.exists(out + ".geojson"):
        os.remove(out + ".geojson")
    problem = None
    if code is None:
        problem = "still running after %g s" % timeout
    elif code < 0:
        problem = "killed by signal %d" % -code
    elif any(r in err for r in REPORTS):
        problem = "sanitizer report"
    elif code not in ALLOWED_EXIT:
        problem = "exit status %d" % code
    return name, code, seconds, problem, err, argv


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("cli")
    ap.add_argument("reader", choices=["gltf", "geo"])
    ap.add_argument("mutants")
    ap.add_argument("work")
    ap.add_argument("--count", default="400")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=120)
    a = ap.parse_args()

    source = os.path.join(a.mutants, a.reader)
    mutants = sorted(os.path.join(source, f) for f in os.listdir(source))
    wanted = os.environ.get("AGGRELOD_CLI_MUTANTS") or a.count
    count = 0 if wanted in ("0", "all") else int(wanted)
    if count:
        mutants = mutants[:count]
    if not mutants:
        print("cli_mutants: no mutants in %s (run the fuzz_seeds test first)" % source, file=sys.stderr)
        return 1
    work = os.path.abspath(os.path.join(a.work, a.reader))
    findings = os.path.join(work, "findings")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(os.path.join(work, "out"))
    os.makedirs(findings)

    start = time.monotonic()
    codes = collections.Counter()
    slowest = []
    found = 0
    with ThreadPoolExecutor(max_workers=a.jobs) as pool:
        for name, code, seconds, problem, err, argv in pool.map(
                lambda m: run_one(os.path.abspath(a.cli), a.reader, os.path.abspath(m), work, a.timeout), mutants):
            codes["timeout" if code is None else code] += 1
            slowest.append((seconds, name))
            if problem:
                found += 1
                shutil.copy(os.path.join(source, name), os.path.join(findings, name))
                with open(os.path.join(findings, name + ".stderr"), "w") as f:
                    f.write(" ".join(argv) + "\n" + err)
                tail = "\n    ".join(err.strip().splitlines()[-6:])
                print("FINDING %s: %s\n    %s" % (name, problem, tail))
    wall = time.monotonic() - start
    slowest.sort(reverse=True)
    print("cli_mutants %s: %d runs in %.1f s (%d in parallel), exit statuses %s; slowest %s; %d finding(s)%s" % (
        a.reader, len(mutants), wall, a.jobs, dict(sorted(codes.items(), key=str)),
        ", ".join("%s %.1f s" % (n, s) for s, n in slowest[:3]), found,
        " (kept in %s)" % findings if found else ""))
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())

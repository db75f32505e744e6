#!/usr/bin/python3
"""Runs bench/run_bench.py and compares its results with this machine kind's baseline (bench/README.md).

    bench/compare.py [--baseline FILE] [--margin M] [--results FILE] [--write-baseline] [-- RUN_BENCH_OPTIONS]

Without --results it runs bench/run_bench.py with the options the baseline was measured with
(--rounds 3 --repeat 11 --pin 0 --no-skimage, the baseline's cases) into bench-work/compare, then
compares case by case:

  * cmc33's time over Flying Edges' in the same run (one thread with normals, one thread without,
    and all cores with normals): the ratio cancels most of a machine's drift between runs. A ratio
    more than M above the baseline's (M = --margin, default 0.10, twice that for all cores, whose
    figures drift most on 2 vCPUs) is a regression;
  * cmc33's one-thread time alone, reported beside it (not judged: it moves with the machine);
  * cmc33's peak memory: more than M above the baseline's and more than 2 MiB is a regression;
  * the triangle counts: a different count means the mesh changed (reported, exit status 1).

The baseline is bench/results/baseline-<N>core.jsonl, N this machine's logical CPUs (one baseline
per machine kind); --write-baseline replaces it with this run's results (and its .md beside it).
Exit status: 0 within the margin, 1 a regression, a changed mesh or a failed run, 2 usage.
"""

import argparse
import json
import os
import shutil
import subprocess
import sys

PROG = "compare.py"
REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RESULTS = os.path.join(REPO, "bench", "results")
# run_bench.py's options for the baseline runs: turns and one CPU sample a 2-vCPU VM's drift evenly
BASELINE_OPTIONS = ["--rounds", "3", "--repeat", "11", "--pin", "0", "--no-skimage"]
RSS_SLACK_KIB = 2048


class ArgumentParser(argparse.ArgumentParser):
    def error(self, message):
        print(f"{PROG}: {message} (try --help)", file=sys.stderr)
        sys.exit(2)


def load(path):
    """The records of a run_bench.py results.jsonl, by (case, tool, threads, normals)."""
    records = {}
    try:
        with open(path) as fp:
            for n, line in enumerate(fp, 1):
                if not line.strip():
                    continue
                try:
                    r = json.loads(line)
                except ValueError as e:
                    sys.exit(f"{PROG}: {path}, line {n}: not a JSON record ({e}); expected run_bench.py's results.jsonl")
                records[(r["case"], r["tool"], r.get("requested_threads"), r.get("normals"))] = r
    except OSError as e:
        sys.exit(f"{PROG}: {path}: {e.strerror}; expected run_bench.py's results.jsonl")
    return records


def cases_of(records):
    seen = []
    for case, _, _, _ in records:
        if case not in seen:
            seen.append(case)
    return seen


def compare(base, new, margin):
    """Lines of the comparison table and the number of problems (regressions, changed meshes, failures)."""
    problems = 0
    lines = ["| case | figure | baseline | this run | change | verdict |", "|---|---|--:|--:|--:|---|"]
    for case in cases_of(new):
        if (case, "cmc33", 1, True) not in base:
            lines.append(f"| {case} | – | – | – | – | not in the baseline |")
            continue
        for threads, normals, label, allowed in ((1, True, "cmc33 / FE, 1 thread, normals", margin),
                                                 (1, False, "cmc33 / FE, 1 thread, no normals", margin),
                                                 (0, True, "cmc33 / FE, all cores, normals", 2 * margin)):
            b_a, b_f = base.get((case, "cmc33", threads, normals)), base.get((case, "vtk-fe", threads, normals))
            n_a, n_f = new.get((case, "cmc33", threads, normals)), new.get((case, "vtk-fe", threads, normals))
            if n_a is None and n_f is None:
                continue
            if (n_a and "error" in n_a) or (n_f and "error" in n_f):
                problems += 1
                why = (n_a or {}).get("error") or (n_f or {}).get("error")
                lines.append(f"| {case} | {label} | – | – | – | **failed**: {why} |")
                continue
            if not (b_a and b_f and n_a and n_f and "seconds" in b_a and "seconds" in b_f):
                lines.append(f"| {case} | {label} | – | – | – | no Flying Edges figure to compare with |")
                continue
            old, now = b_a["seconds"] / b_f["seconds"], n_a["seconds"] / n_f["seconds"]
            change = now / old - 1
            verdict = "within the margin"
            if change > allowed:
                verdict = f"**regression** (more than {allowed:.0%})"
                problems += 1
            elif change < -allowed:
                verdict = "faster"
            lines.append(f"| {case} | {label} | {old:.3f} | {now:.3f} | {change:+.1%} | {verdict} |")
        b, n = base.get((case, "cmc33", 1, True)), new.get((case, "cmc33", 1, True))
        if b and n and "seconds" in b and "seconds" in n:
            lines.append(f"| {case} | cmc33 ms, 1 thread, normals | {b['seconds'] * 1e3:.2f} | {n['seconds'] * 1e3:.2f} | "
                         f"{n['seconds'] / b['seconds'] - 1:+.1%} | (not judged: moves with the machine) |")
        if b and n and b.get("peak_rss_kib") and n.get("peak_rss_kib"):
            grow = n["peak_rss_kib"] - b["peak_rss_kib"]
            bad = grow > RSS_SLACK_KIB and n["peak_rss_kib"] > (1 + margin) * b["peak_rss_kib"]
            problems += bad
            lines.append(f"| {case} | cmc33 peak MiB | {b['peak_rss_kib'] / 1024:.0f} | {n['peak_rss_kib'] / 1024:.0f} | "
                         f"{n['peak_rss_kib'] / b['peak_rss_kib'] - 1:+.1%} | {'**regression**' if bad else 'within the margin'} |")
        if b and n and "triangles" in b and "triangles" in n and b["triangles"] != n["triangles"]:
            problems += 1
            lines.append(f"| {case} | cmc33 triangles | {b['triangles']:,} | {n['triangles']:,} | – | **the mesh changed** |")
    return lines, problems


def main(argv):
    p = ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0])
    nproc = os.cpu_count() or 1
    p.add_argument("--baseline", default=os.path.join(RESULTS, f"baseline-{nproc}core.jsonl"),
                   help=f"the baseline's results.jsonl (default bench/results/baseline-{nproc}core.jsonl: this machine's kind)")
    p.add_argument("--margin", type=float, default=0.10,
                   help="the noise margin: a ratio more than this fraction above the baseline's is a regression (default 0.10)")
    p.add_argument("--results", help="compare this results.jsonl instead of running the benchmark")
    p.add_argument("--out", default=os.path.join(REPO, "bench-work", "compare"),
                   help="where run_bench.py writes this run's results (default bench-work/compare)")
    p.add_argument("--write-baseline", action="store_true",
                   help="after the run, make its results this machine kind's baseline (results.jsonl and results.md)")
    p.add_argument("run_bench_options", nargs="*",
                   help="after --: options for run_bench.py, instead of the baseline's (" + " ".join(BASELINE_OPTIONS) + ")")
    args = p.parse_args(argv)
    if not 0 < args.margin < 1:
        p.error(f"--margin {args.margin} is not a fraction in (0, 1)")
    if args.results and args.write_baseline:
        p.error("--write-baseline takes the results of a run of its own; leave out --results")
    have_baseline = os.path.exists(args.baseline)
    if not have_baseline and not args.write_baseline:
        sys.exit(f"{PROG}: {args.baseline}: no baseline for this machine kind ({nproc} logical CPUs); "
                 "expected one made by `bench/compare.py --write-baseline`, or pass --baseline FILE")
    base = load(args.baseline) if have_baseline else {}

    results = args.results
    if results is None:
        options = args.run_bench_options or BASELINE_OPTIONS
        if not args.run_bench_options and base:
            options = options + ["--cases", ",".join(cases_of(base))]
        cmd = [sys.executable, os.path.join(REPO, "bench", "run_bench.py"), "--out", args.out] + options
        results = os.path.join(args.out, "results.jsonl")
        if os.path.exists(results):
            os.remove(results)  # a run that fails must not leave an earlier run's results to compare
        print(f"{PROG}: {' '.join(cmd)}", file=sys.stderr)
        status = subprocess.run(cmd).returncode
        if not os.path.exists(results):
            sys.exit(f"{PROG}: run_bench.py exited with status {status} and wrote no {results}")
    new = load(results)

    problems = 0
    if base:
        lines, problems = compare(base, new, args.margin)
        print(f"# {results} against {args.baseline}\n")
        print("\n".join(lines))
        print(f"\nMargin: {args.margin:.0%} on the one-thread ratios, {2 * args.margin:.0%} on all cores; "
              "cmc33 / FE below 1 is faster than Flying Edges.")
        print(f"{PROG}: {problems} regression(s), changed mesh(es) or failed run(s)" if problems else
              f"{PROG}: no regression beyond the margin")
    if args.write_baseline:
        stem = os.path.splitext(args.baseline)[0]
        shutil.copyfile(results, stem + ".jsonl")
        md = os.path.join(os.path.dirname(results), "results.md")
        if os.path.exists(md):
            shutil.copyfile(md, stem + ".md")
        print(f"{PROG}: {stem}.jsonl is the new baseline", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

"""The ``workbench`` command: one table of verbs, each calling one API function.

Exit codes (all verbs): 0 ok, 1 a claim / certificate failed or is
inconclusive, 2 bad input (design file or arguments) — one message, no
traceback, nothing half-written.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Callable

from .errors import DesignError, ModelError

DESIGNS_DIR = Path("designs")


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # usage + message, exit 2 (no traceback)
        self.print_usage(sys.stderr)
        raise _BadArgs(f"{self.prog}: error: {message}")


class _BadArgs(Exception):
    pass


class _Version(argparse.Action):
    """``workbench --version``: print it and stop (exit 0, no SystemExit)."""

    def __init__(self, option_strings, dest, **kwargs):
        super().__init__(option_strings, dest, nargs=0, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        from . import DISTRIBUTION, version
        raise _Shown(f"workbench {version()} (distribution {DISTRIBUTION})")


class _Shown(Exception):
    pass


def _designs(paths: list[str]) -> list:
    from .design import load_design
    if not paths:
        from .project import find_project
        folder = find_project().designs  # designs/ of the project root, never the package's
        paths = [str(p) for p in sorted(folder.glob("*.toml"))]
        if not paths:
            raise DesignError("<cli>", "DESIGN", str(folder), "a folder with design files")
    return [load_design(p) for p in paths]


# -- verbs ------------------------------------------------------------------------
def _verb(verb: str, path: str, **options) -> int:
    """Run ``verb`` on the design at ``path`` if its kind declares it
    (:mod:`workbench.kinds.capabilities`; otherwise one line, exit 2)."""
    from .design import load_design
    from .kinds.capabilities import run
    return run(load_design(path), verb, **options)


def cmd_synthesize(args) -> int:
    if args.eps:
        for e in args.eps:
            if not (math.isfinite(e) and e > 0):
                raise DesignError("<cli>", "--eps", e, "a positive number")
    return _verb(f"synthesize {args.what}", args.design, eps=args.eps, as_json=args.json)


def cmd_verify(args) -> int:
    from .ci import run_verify, timing_table
    from .report.markdown import fmt, md_table

    run = run_verify(args.designs, changed_since=args.changed_since, progress=not args.json)
    evs = run.evaluations
    extra = {}
    if run.proofs:
        from .prove import verification_rows
        extra = verification_rows(list(run.proofs))
    if args.junit_xml:
        from .junit import write_junit
        from .project import find_project
        write_junit(run, args.junit_xml, name=find_project().name)
    if args.json:
        out = {"designs": [{"design": e.design.name, "path": e.design.path, "ok": e.ok,
                            "claims": [c.to_json() for c in e.claims]} for e in evs]}
        out.update(extra.get("json", {}))
        print(json.dumps(out, indent=2))
    else:
        rows = []
        for e in evs:
            for c in e.claims:
                sev = c.claim.severity
                v = c.verdict.value + (f" (expected; {sev})" if c.claim.expect == "fail" and c.ok
                                       else f" ({sev})" if sev else "")
                rows.append([e.design.name, c.claim.id, f"{c.claim.compare} {fmt(c.claim.value, 6)}",
                             fmt(c.got, 6), v if c.ok else v + " ✗", c.claim.source])
        rows += extra.get("rows", [])
        if rows:
            print(md_table(["design", "claim", "expected", "got", "verdict", "source"], rows))
        else:
            print("no claims to check" + (f" (nothing changed since {args.changed_since})"
                                          if args.changed_since else ""))
        n_bad = sum(not c.ok for e in evs for c in e.claims) + extra.get("bad", 0)
        n = sum(len(e.claims) for e in evs) + len(extra.get("rows", []))
        print(f"\n{n - n_bad} of {n} claims ok" + ("" if not n_bad else f"; {n_bad} not ok"))
    if run.skipped:  # stderr: stdout stays the verdicts only
        print(f"--changed-since {args.changed_since}: {len(run.skipped)} unchanged, not "
              f"checked: {', '.join(run.skipped)}", file=sys.stderr)
    if run.seconds:
        print("\n" + timing_table(run.seconds), file=sys.stderr)
    return 0 if run.ok else 1


def _extra_verifications(args) -> dict:
    """Other claim sources: every claim of proofs/ (workbench.prove), when
    verify runs on everything (no design named)."""
    if getattr(args, "designs", None):
        return {}
    from .prove import verification_rows
    return verification_rows()


def cmd_report(args, *, checked=frozenset(), problems=()) -> int:
    """``checked``: designs whose reports a worker of ``check --jobs``
    already compared (their ``problems``), only the index is checked again."""
    from .report.writer import check_reports, write_reports
    from .verify import evaluate_design, report_files

    jobs = getattr(args, "jobs", None) or 1
    if jobs < 1:
        raise DesignError("<cli>", "--jobs", jobs, "a positive number of processes")
    if jobs > 1:
        from .checkrun import report_parallel
        one = argparse.Namespace(**{**vars(args), "jobs": 1})
        return report_parallel(_designs([] if args.all else args.designs), args, jobs,
                               lambda done, lines: cmd_report(one, checked=done,
                                                              problems=lines))
    from .sim.progress import progress
    designs = _designs([] if args.all else args.designs)
    files = [report_files(evaluate_design(d))
             for d in progress(designs, desc="report", unit="design", enabled=len(designs) > 1)]
    index = args.all or not args.designs
    if index:
        from .prove import report_files
        files += report_files()
    from .reader import display_path
    from .project import find_project
    out = Path(args.out or display_path(find_project().reports))
    if args.check:
        problems = list(problems) + check_reports(
            [f for f in files if f.name not in checked], out, index=False)
        if index:
            problems += check_reports(files, out, index=True, only_index=True)
        for p in problems:
            print(p)
        if not problems:
            print(f"{len(files)} report(s) fresh in {out}/")
        return 1 if problems else 0
    for p in problems:           # the workers' lines of ``report --jobs``
        print(p)
    for p in write_reports(files, out, index=index, skip=checked):
        print(f"wrote {p}")
    return 0


def cmd_check(args) -> int:
    """``workbench verify`` then ``workbench report --all --check`` in one
    process, each study computed once (:mod:`workbench.memo`; the Monte
    Carlo pools start first and run while the other designs are checked);
    then the time of every design's study, slowest first, on stderr. With
    ``--jobs N`` (N > 1) the studies and their report checks run on N
    processes first (:mod:`workbench.checkrun`). Exit code: the larger of the
    two."""
    jobs = args.jobs
    if jobs is None:
        from .sim.batch import available_cpus
        jobs = available_cpus()
    if jobs < 1:
        raise DesignError("<cli>", "--jobs", jobs, "a positive number of processes")
    verify = argparse.Namespace(designs=[], json=False, junit_xml=None, changed_since=None)
    report = argparse.Namespace(designs=[], all=True, check=True, out=args.out)
    if jobs > 1:
        from .checkrun import check_parallel
        return check_parallel(_designs([]), args.out, jobs, lambda: cmd_verify(verify),
                              lambda checked, problems: cmd_report(report, checked=checked,
                                                                   problems=problems))
    from . import kinds
    from .memo import cancel_started, start_studies, study_times

    try:
        start_studies(_designs([]), kinds.REGISTRY)   # the Monte Carlo pools, first
        code = cmd_verify(verify)
        print()
        code = max(code, cmd_report(report))
    finally:
        cancel_started()
    print(study_times_table(study_times()), file=sys.stderr)
    return code


def study_times_table(times) -> str:
    """Markdown table of :func:`workbench.memo.study_times`, slowest first."""
    from .report.markdown import md_table
    rows = [[t.design, t.kind, f"{t.wall:.1f}", f"{t.cpu:.1f}",
             "" if t.since_start is None else f"{t.since_start:.1f}"]
            for t in sorted(times, key=lambda t: -t.wall)]
    total = [["total", "", f"{sum(t.wall for t in times):.1f}",
              f"{sum(t.cpu for t in times):.1f}", ""]]
    return ("\nper-design study time (each computed once; wall and cpu: the study's run in this "
            "process, not its pool workers; a Monte Carlo design's pool starts with `check` and "
            "runs beside the other designs: its wall from that start to its result is the last "
            "column):\n"
            + md_table(["design", "kind", "wall s", "cpu s", "pool: wall s since start"],
                       rows + total, "llrrr"))


def _cmd_prove(args) -> int:
    from .prove import cmd_prove
    return cmd_prove(args)


def _cmd_fit(args) -> int:
    return _verb("fit", args.design, as_json=args.json)


def cmd_init(args) -> int:
    from .scaffold import DEFAULT_REQUIREMENT, init_project
    files = init_project(args.path, papers=args.papers,
                         requirement=DEFAULT_REQUIREMENT if args.requirement is None
                         else args.requirement)
    print(f"wrote {len(files)} files in {args.path}/; next: cd {args.path} && workbench verify")
    return 0


def cmd_new(args) -> int:
    from .project import find_project
    from .scaffold.new import new_design
    path = new_design(args.kind, args.name, args.dir or find_project().designs)
    print(f"wrote {path}; next: workbench verify {path}")
    return 0


def cmd_benchmark(args) -> int:
    return _verb(f"benchmark {args.what}", args.design, as_json=args.json,
                 exact_check=args.exact_check)


def cmd_simulate(args) -> int:
    return _verb("simulate", args.design, case=args.case, dt=args.dt, as_json=args.json,
                 csv=args.csv, plot=args.plot)


def cmd_sweep(args) -> int:
    return _verb("sweep", args.design, samples=args.samples, seed=args.seed,
                 workers=args.workers, figure=args.figure, as_json=args.json,
                 kernel=args.kernel, scheduler=args.scheduler, out=args.out,
                 resume=args.resume, case=args.case)


COMMANDS: dict[str, tuple[str, Callable]] = {
    "simulate": ("simulate one scenario of a design (simulate DESIGN [--case C])",
                 cmd_simulate),
    "sweep": ("Monte Carlo robustness sweep (sweep DESIGN --samples N --seed S)", cmd_sweep),
    "benchmark": ("delay LMIs vs exact margins (benchmark delay [DESIGN] [--json])",
                  cmd_benchmark),
    "synthesize": ("certified LMI synthesis (synthesize delay-bound|sampled DESIGN)",
                   cmd_synthesize),
    "verify": ("evaluate every claim; exit 1 if any is not ok", cmd_verify),
    "fit": ("fit paper 000's brake model to a brake-fit design's synthetic logs", _cmd_fit),
    "report": ("write reports/<design>.md and figures (--check: fail if stale)", cmd_report),
    "check": ("verify + report --all --check in one process, each study computed once",
              cmd_check),
    "prove": ("check the claims of proofs/: PROVED / REFUTED / INCONCLUSIVE", _cmd_prove),
    "init": ("write a project skeleton: designs/, proofs/, reports/, CI files", cmd_init),
    "new": ("write a commented template design (new delay-feedback NAME)", cmd_new),
}


def build_parser() -> argparse.ArgumentParser:
    ap = _Parser(prog="workbench", description="Robust-control design and verification "
                 "workbench for train control.")
    ap.add_argument("--version", action=_Version, help="print the version and exit")
    sub = ap.add_subparsers(dest="command", required=True, parser_class=_Parser)
    p = sub.add_parser("synthesize", help=COMMANDS["synthesize"][0])
    ssub = p.add_subparsers(dest="what", required=True, parser_class=_Parser)
    q = ssub.add_parser("delay-bound", help="problem (60) of paper 003 over eps, with exact margins")
    q.add_argument("design")
    q.add_argument("--eps", type=float, nargs="+", help="eps values (override the design's)")
    q.add_argument("--json", action="store_true")
    q = ssub.add_parser("sampled", help="digital implementation: certified and exact sampling "
                        "bounds of a delay-feedback design's gain")
    q.add_argument("design")
    q.add_argument("--json", action="store_true")
    q.set_defaults(eps=None)
    p = sub.add_parser("fit", help=COMMANDS["fit"][0])
    p.add_argument("design")
    p.add_argument("--json", action="store_true")
    p = sub.add_parser("benchmark", help=COMMANDS["benchmark"][0])
    bsub = p.add_subparsers(dest="what", required=True, parser_class=_Parser)
    q = bsub.add_parser("delay", help="every delay LMI on the benchmark examples")
    q.add_argument("design", nargs="?", default=str(DESIGNS_DIR / "delay-benchmarks.toml"),
                   help="a delay-benchmark design (default: designs/delay-benchmarks.toml)")
    q.add_argument("--json", action="store_true")
    q.add_argument("--exact-check", action="store_true",
                   help="re-check every certificate in exact rational arithmetic")
    p = sub.add_parser("simulate", help=COMMANDS["simulate"][0])
    p.add_argument("design")
    p.add_argument("--case", help="case name (default: the design's first)")
    p.add_argument("--dt", type=float, help="step (s; default: the design's dt)")
    p.add_argument("--json", action="store_true")
    p.add_argument("--csv", metavar="FILE", help="also write the trajectory (t, states, "
                   "controller outputs; switched-run: and the phase) to FILE (antiskid-run: "
                   "every 0.01 s)")
    p.add_argument("--plot", metavar="PNG", help="also plot the states and inputs against "
                   "time to PNG (delay-feedback designs)")
    p = sub.add_parser("sweep", help=COMMANDS["sweep"][0])
    p.add_argument("design")
    p.add_argument("--samples", type=int, required=True)
    p.add_argument("--seed", type=int, required=True)
    p.add_argument("--case", help="scenario (switched-run; default: the design's first) or "
                   "case (stop-accuracy: v<speed>.<controller>; default: every one)")
    p.add_argument("--workers", type=int, help="processes (default: the CPUs granted to this process)")
    p.add_argument("--kernel", help="stepping path: compiled (numba; the default when "
                   "installed) or numpy (the reference)")
    p.add_argument("--scheduler", help="run the chunks on Dask: 'local' (a LocalCluster of "
                   "--workers processes) or a scheduler address, tcp://host:8786")
    p.add_argument("--out", metavar="DIR", help="write each chunk's runs to DIR "
                   "(antiskid-run: chunk-*.npz; switched-run, delay-feedback: "
                   "<scenario>-chunk-*.csv; stop-accuracy: <case>-chunk-*.csv) as it "
                   "finishes; the summaries are read back from the files")
    p.add_argument("--resume", action="store_true",
                   help="with --out: skip the chunks already written in DIR")
    p.add_argument("--figure", help="write the histogram PNG here")
    p.add_argument("--json", action="store_true")
    p = sub.add_parser("verify", help=COMMANDS["verify"][0])
    p.add_argument("designs", nargs="*", help="design files (default: all of designs/)")
    p.add_argument("--json", action="store_true")
    p.add_argument("--junit-xml", metavar="FILE",
                   help="also write one JUnit test case per claim to FILE")
    p.add_argument("--changed-since", metavar="REF",
                   help="only designs and proofs depending on files changed since git REF")
    p = sub.add_parser("report", help=COMMANDS["report"][0])
    p.add_argument("designs", nargs="*", help="design files (default: all of designs/)")
    p.add_argument("--all", action="store_true", help="every design in designs/ and the index")
    p.add_argument("--check", action="store_true", help="exit 1 if a committed report is stale")
    p.add_argument("--out", help="output folder (default: reports/ of the project root)")
    p.add_argument("--jobs", type=int, default=1,
                   help="processes: each design's study and report on one (default 1)")
    p = sub.add_parser("check", help=COMMANDS["check"][0])
    p.add_argument("--out", help="report folder (default: reports/ of the project root)")
    p.add_argument("--jobs", type=int, default=None,
                   help="processes for the studies (default: the CPUs granted to this "
                        "process; 1: everything in this process)")
    p = sub.add_parser("prove", help=COMMANDS["prove"][0])
    p.add_argument("proofs", nargs="*", metavar="PROOF",
                   help="paper (e.g. 003), module of proofs/ or claim id (default: all)")
    p.add_argument("--json", action="store_true")
    p = sub.add_parser("init", help=COMMANDS["init"][0])
    p.add_argument("path", metavar="PATH", help="new or empty folder")
    p.add_argument("--papers", action="store_true",
                   help="copy the shipped designs and proofs of papers 000-004 instead of "
                        "the example")
    p.add_argument("--requirement", help="what the CI files pip-install: "
                   "traincontrol-workbench==VERSION (default: this version), "
                   "git+https://REPOSITORY@COMMIT or a traincontrol_workbench-*.whl path or URL")
    p = sub.add_parser("new", help=COMMANDS["new"][0])
    p.add_argument("kind", metavar="KIND", help="design kind (delay-feedback)")
    p.add_argument("name", metavar="NAME", help="design name (the file stem)")
    p.add_argument("--dir", help="folder (default: designs/ of the project root)")
    return ap


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the exit code (tests call ``main([...])``)."""
    try:
        args = build_parser().parse_args(argv)
    except _BadArgs as exc:
        print(exc, file=sys.stderr)
        return 2
    except _Shown as exc:
        print(exc)
        return 0
    try:
        return COMMANDS[args.command][1](args)
    except (DesignError, ModelError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

"""What each design kind can do on the command line (issue 35, item 3).

A kind declares its capabilities in :data:`CAPABILITIES`: verb -> the
``"module:function"`` that runs it on a loaded design (imported only when
used, as :data:`workbench.kinds.STUDIES`). The verbs of :mod:`workbench.cli`
never test a kind: they call :func:`run`, which finds the function, passes
it the options it takes, and otherwise says what is missing with a
:class:`CapabilityError` (a design error: one line, exit 2):

    designs/x.toml: design x (kind brake-fit) has no simulate: it needs
    [[scenarios]] to simulate (kinds with simulate: antiskid-run, delay-feedback,
    stop-accuracy, switched-run)

A command function has the signature ``f(design, *, option=..., ...) -> int``
(the exit code); an option the user set that it does not take (e.g.
``--plot`` of an ``antiskid-run`` simulate) is the same kind of error.
New capabilities add one line here.
"""
from __future__ import annotations

import importlib
import inspect

from ..errors import DesignError

__all__ = ["CAPABILITIES", "CapabilityError", "NEEDS", "command", "kinds_with", "run",
           "sweep_draws"]

#: kind -> verb -> "module:function" of the command.
CAPABILITIES: dict[str, dict[str, str]] = {
    "delay-feedback": {
        "simulate": "workbench.kinds.delay_feedback.cli:simulate_command",
        "sweep": "workbench.kinds.delay_feedback.cli:sweep_command",
        "synthesize delay-bound": "workbench.kinds.delay_feedback.cli:synthesize_command",
        "synthesize sampled": "workbench.kinds.delay_feedback.sampled_cli:sampled_command"},
    "switched-run": {
        "simulate": "workbench.kinds.switched_run.cli:simulate_command",
        "sweep": "workbench.kinds.switched_run.cli:sweep_command"},
    "stop-accuracy": {
        "simulate": "workbench.kinds.stop_accuracy.cli:simulate_command",
        "sweep": "workbench.kinds.stop_accuracy.cli:sweep_command"},
    "platoon": {"simulate": "workbench.kinds.platoon.cli:simulate_command"},
    "antiskid-run": {
        "simulate": "workbench.papers.p003.antiskid_run:simulate_command",
        "sweep": "workbench.papers.p003.antiskid_run:sweep_command"},
    "antiskid-cruise": {
        "synthesize delay-bound": "workbench.kinds.delay_feedback.cli:loop_sweep_command"},
    "brake-fit": {"fit": "workbench.papers.p000.brake_fit:fit_command"},
    "delay-benchmark": {"benchmark delay": "workbench.benchmark:benchmark_delay"},
    "tracking": {"simulate": "workbench.kinds.tracking.cli:simulate_command"},
}

#: verb -> what a design needs for it (the error's words).
NEEDS: dict[str, str] = {
    "simulate": "[[scenarios]] to simulate",
    "sweep": "a [montecarlo] table and a Monte Carlo sweep of its kind",
    "synthesize delay-bound": "a plant linearised at an operating point with an input delay",
    "synthesize sampled": "a state-feedback gain and its input delay",
    "fit": "synthetic brake logs to fit",
    "benchmark delay": "the delay benchmark examples",
}

#: option -> its command-line flag (when not ``--`` + the name with dashes).
_FLAGS = {"as_json": "--json"}


class CapabilityError(DesignError):
    """A design whose kind (or whose tables) lack what a verb needs.

    The message: ``<file>: design <name> (kind <kind>) has no <verb>: it
    needs <what>``; a :class:`~workbench.errors.DesignError` (exit 2).
    """

    def __init__(self, design, verb: str, needs: str):
        self.path, self.key, self.value = design.path, "design.kind", design.kind
        self.expected = needs
        Exception.__init__(self, f"{design.path}: design {design.name} (kind {design.kind}) "
                                 f"has no {verb}: it needs {needs}")


def kinds_with(verb: str) -> list[str]:
    """The kinds that declare ``verb``, sorted."""
    return sorted(k for k, verbs in CAPABILITIES.items() if verb in verbs)


def command(design, verb: str):
    """The command function of ``verb`` for the design's kind (a
    :class:`CapabilityError` when the kind does not declare it)."""
    target = CAPABILITIES.get(design.kind, {}).get(verb)
    if target is None:
        raise CapabilityError(design, verb, f"{NEEDS.get(verb, 'it')} (kinds with {verb}: "
                              + ", ".join(kinds_with(verb)) + ")")
    module, attr = target.split(":")
    return getattr(importlib.import_module(module), attr)


def run(design, verb: str, **options) -> int:
    """Run ``verb`` on ``design``: the kind's command with the options it
    takes. An option set by the user (not None, not False) that the command
    does not take is a :class:`CapabilityError` naming its flag."""
    fn = command(design, verb)
    takes = inspect.signature(fn).parameters
    for name, value in options.items():
        if name not in takes and value is not None and value is not False:
            flag = _FLAGS.get(name, "--" + name.replace("_", "-"))
            raise CapabilityError(design, f"{verb} {flag}", f"a kind whose {verb} takes "
                                  f"{flag}")
    return fn(design, **{k: v for k, v in options.items() if k in takes})


def sweep_draws(design, samples: int, seed: int, max_samples: int):
    """The design's ``[montecarlo]`` with ``--samples`` and ``--seed`` (a
    :class:`~workbench.features.montecarlo.MonteCarloSpec`); a design
    without the table has no sweep (:class:`CapabilityError`)."""
    from dataclasses import replace
    mc = design.spec.montecarlo
    if mc is None:
        raise CapabilityError(design, "sweep", "a [montecarlo] table (the distributions "
                              "of the plant parameters)")
    if isinstance(samples, bool) or not 2 <= samples <= max_samples:
        raise DesignError("<cli>", "--samples", samples, f"an integer in [2, {max_samples}]")
    if not seed >= 0:
        raise DesignError("<cli>", "--seed", seed, "a non-negative integer")
    return replace(mc, samples=samples, seed=seed)

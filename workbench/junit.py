"""JUnit XML of a ``verify`` run, as GitHub Actions, GitLab CI and Jenkins read it.

One ``<testsuite>`` per design (and per proof module), one ``<testcase>`` per
claim with ``classname`` = the design and ``name`` = ``design::claim-id``.
A case that is not ok (see :mod:`workbench.ci`) carries a ``<failure>`` whose
``message`` gives expected, got, tolerance and source and whose ``type`` is
the verdict (``FAIL``, ``INCONCLUSIVE``, ``REFUTED``, ``PASS`` for an expected
failure that passed). INCONCLUSIVE is a failure, not a skip: a skipped test
leaves a pipeline green, and a claim nobody could decide must not. Expected
failures are passes with their reason in ``<system-out>``.

The document follows the JUnit schema of Jenkins' xUnit plugin (the
structure GitLab and GitHub reporters parse); ``tests/test_junit.py``
validates it against ``tests/data/junit.xsd``.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path


def junit_xml(run, *, name: str = "workbench verify") -> str:
    """The JUnit XML text of a :class:`workbench.ci.VerifyRun` (pure).

    Parameters
    ----------
    run : workbench.ci.VerifyRun
    name : str
        ``name`` of ``<testsuites>`` (the project).
    """
    seconds = dict(run.seconds)
    suites: dict[str, list] = {}
    for case in run.cases:
        suites.setdefault(case.suite, []).append(case)
    cases = run.cases
    root = ET.Element("testsuites", name=name, tests=str(len(cases)),
                      failures=str(sum(not c.ok for c in cases)), errors="0",
                      time=f"{sum(seconds.values()):.3f}")
    for suite, members in suites.items():
        el = ET.SubElement(root, "testsuite", name=suite, tests=str(len(members)),
                           failures=str(sum(not c.ok for c in members)), errors="0",
                           skipped="0", time=f"{seconds.get(suite, 0.0):.3f}")
        for c in members:
            tc = ET.SubElement(el, "testcase", name=c.name, classname=c.suite)
            if not c.ok:
                f = ET.SubElement(tc, "failure", message=c.message, type=c.verdict)
                f.text = c.detail
            if c.out:
                ET.SubElement(tc, "system-out").text = c.out
    ET.indent(root)
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            + ET.tostring(root, encoding="unicode") + "\n")


def write_junit(run, path: str | Path, *, name: str = "workbench verify") -> Path:
    """Write :func:`junit_xml` to ``path`` (folders created); returns the path."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(junit_xml(run, name=name), encoding="utf-8")
    return p

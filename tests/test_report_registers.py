"""Issue 33, done criterion: every committed report has a traceability matrix
and an assumptions table, and every design file has an assumptions register."""
from pathlib import Path

import pytest

REPORTS = sorted(p for p in Path("reports").glob("*.md") if p.stem not in ("README", "HAZARDS"))


@pytest.mark.parametrize("path", REPORTS, ids=lambda p: p.stem)
def test_every_report_has_traceability_and_assumptions(path):
    text = path.read_text(encoding="utf-8")
    assert "\n## Traceability\n" in text
    assert "\n## Assumptions\n" in text
    section = text.split("\n## Assumptions\n", 1)[1].split("\n## ", 1)[0]
    assert "| --- |" in section or "| :--- |" in section, f"{path}: the assumptions section has no table"


def test_there_are_reports():
    assert len(REPORTS) >= 25

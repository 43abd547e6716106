"""report.display_math: the shared ``$$`` block join (general, no paper)."""
from workbench.report.display_math import display_math


def test_display_math_joins_blocks_with_blank_lines():
    assert display_math(["x' = a x", r"y = \frac{1}{2}"]) == (
        "$$\nx' = a x\n$$\n\n$$\ny = \\frac{1}{2}\n$$")


def test_display_math_accepts_generators_and_empty():
    assert display_math(e for e in ["u"]) == "$$\nu\n$$"
    assert display_math([]) == ""

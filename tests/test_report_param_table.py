"""report.param_table: the shared parameter table (general, no paper)."""
from types import SimpleNamespace as Q

from workbench.report.param_table import param_table


def test_param_table_rows_digits_missing_doc_and_extra_rows():
    params = {"k": Q(value=1.234567, unit="N/m", source="toy"),
              "m": Q(value=2.0, unit="kg", source="ours")}
    text = param_table(params, {"k": "spring stiffness"}, 3,
                       [["`x0`", "0.5", "m", "start", "chosen"]])
    lines = text.splitlines()
    assert lines[0].split("|")[1:6] == [" parameter ", " value ", " unit ", " meaning ",
                                        " source "]
    body = [[c.strip() for c in ln.split("|")[1:6]] for ln in lines[2:]]
    assert body == [["`k`", "1.23", "N/m", "spring stiffness", "toy"],
                    ["`m`", "2", "kg", "", "ours"],
                    ["`x0`", "0.5", "m", "start", "chosen"]]

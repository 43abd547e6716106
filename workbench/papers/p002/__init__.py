"""Paper 002: CFDL-MFAC against PID on ATO speed profiles.

Its design (``designs/ato-mfac-pid-002.toml``) is a configuration of the
general kind ``tracking`` (:mod:`workbench.kinds.tracking`): route, profile,
train readings, controllers' grids, tuning rule, comfort limit and claims are
design tables. What stays here is what a design cannot express: the report's
wording of the paper's own questions (:mod:`.mfac_report`: eqs 4-9 typeset, the
diagnosis of eq 9's resets, the CFDL data-model discussion and the closing
verdict per reading), named by the design's ``[analysis] module``.
"""

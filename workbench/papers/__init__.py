"""Paper-specific studies: one sub-package per paper of the seed set
(``p000`` ... ``p004``), each holding the studies, specs and renderers that
only that paper's designs use. General machinery lives in
:mod:`workbench.kinds`, :mod:`workbench.features` and :mod:`workbench.tuning`.
"""

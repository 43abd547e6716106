"""Paper 001: the NTSM platoon is a design of the general kind ``platoon``
(:mod:`workbench.kinds.platoon`); :mod:`.ntsm_analysis` keeps what its design
file cannot express (and says why).
"""

"""Paper 002: CFDL-MFAC against PID on ATO speed profiles (kind ``ato-tracking``).
"""

"""Paper 001: the NTSM platoon (kind ``ntsm-platoon``) and its realism checks.
"""

"""Symbolic steps: linearisation and the proof/claim engine."""

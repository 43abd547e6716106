"""LMI delay criteria, certified bisection and independent re-checks."""
from .core import Bracket, MarginLMI, Outcome, Step, bisect_delay

__all__ = ["Bracket", "MarginLMI", "Outcome", "Step", "bisect_delay"]

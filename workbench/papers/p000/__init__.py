"""Paper 000: station stopping (PID, SMC, SMARC: the ``[analysis]`` module
of the ``stop-accuracy`` design stopping-line5)
and the brake-model fit (kind ``brake-fit``).
"""

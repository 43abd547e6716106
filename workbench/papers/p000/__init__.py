"""Paper 000: station stopping (PID, SMC, SMARC; kind ``station-stopping``)
and the brake-model fit (kind ``brake-fit``).
"""

"""Controller tuning: PID gains from the exact roots of a linearised loop
(:mod:`.pid`) and Pareto fronts of competing objectives (:mod:`.pareto`).
"""

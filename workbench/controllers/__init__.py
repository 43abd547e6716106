"""Controllers: PID, SMC, SMARC, NTSM, MFAC, predictor-based antiskid, fuzzy."""

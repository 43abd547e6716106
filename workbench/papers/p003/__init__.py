"""Paper 003: the antiskid cruise and braking laws (kinds ``antiskid-cruise``,
``antiskid-robust``, ``antiskid-run``): certificates, runs, Monte Carlo,
sampled-data runs, basins and comfort.
"""

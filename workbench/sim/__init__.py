"""Time-domain simulation: delay-differential stepping, scenarios, metrics."""

"""Physical models, each written once as sympy expressions."""

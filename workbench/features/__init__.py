"""General machinery that several designs use: the Monte Carlo of continuous
distributions (:mod:`.montecarlo`), the basin of attraction of a delay-free
loop (:mod:`.basin`, :mod:`.basin_render`) and the sampled-data
implementation check (:mod:`.sampled`); the table that declares a study's
claimable quantities once (:mod:`.quantities`). Nothing here imports a paper
package (:mod:`workbench.papers`).
"""

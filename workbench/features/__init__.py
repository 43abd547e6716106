"""General machinery that several designs use: the Monte Carlo of continuous
distributions (:mod:`.montecarlo`), the basin of attraction of a delay-free
loop (:mod:`.basin`, :mod:`.basin_render`) and the sampled-data
implementation check (:mod:`.sampled`). Nothing here imports a paper
package (:mod:`workbench.papers`).
"""

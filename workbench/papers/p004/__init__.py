"""Paper 004: the closed-loop brake with its ATO stopping (the ``[analysis]``
module of the ``stop-accuracy`` design closed-loop-brake-004).
"""

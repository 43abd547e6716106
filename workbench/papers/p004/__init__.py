"""Paper 004: the closed-loop brake with its ATO stopping (kind ``closed-loop-brake``).
"""

"""Second code paths kept for speed, each tested against the first within a stated tolerance.

The model layer has none: its laws, curves and zone margins are one evaluation each
(the scalar law is the vector law on one state), and their batch-size independence,
edge sets and references are tested in ``test_laws``, ``test_curves`` and ``test_zones``.
"""

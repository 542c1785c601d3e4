"""Samplers: pure functions of a seeded ``numpy.random.Generator`` (plus the scene, for object-relative ones)."""

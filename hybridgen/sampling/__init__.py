"""Samplers: pure functions of a seeded ``numpy.random.Generator`` (plus the scene, for object-relative ones).

May import: ``hybridgen.scene``, the raster view (camera checks count what a pose sees) and the top-level
helpers; never ``config`` (configs hold samplers, not the reverse: tests/test_import_graph.py).
"""

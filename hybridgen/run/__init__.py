"""Executing a config: plan from the modules' declarations, run the steps in this process or as work units on an
executor (process pool, Ray), shard, stage and resume outputs, fingerprint inputs, lock output folders and stop
cleanly on signals.

May import: everything below it (``config``, ``modules``, ``scene``, ``render``, ``io``).
"""

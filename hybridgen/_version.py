"""The package version, single source of truth for pyproject (kept equal by a test) and HDF5 attributes."""
__version__ = "0.1.0"
